//! Small builders for the SCXML element trees the behavior-tree lowering generates.
//!
//! Every element built here carries one span: the tree node (or plugin tag) it was made
//! from, so an error found later in a generated machine names the user's file.

use crate::model::source::Span;
use crate::model::xml::Element;

/// Builds elements that all carry the span `at`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct B {
    /// Where every element built comes from.
    pub at: Span,
}

impl B {
    /// An element `name` with `attrs`.
    pub(crate) fn el(&self, name: &str, attrs: &[(&str, &str)]) -> Element {
        let mut e = Element::new(name, self.at);
        for (k, v) in attrs {
            e.set_attr(k, *v);
        }
        e
    }

    /// `<scxml name initial version="1.0" model_src="" xmlns>`.
    pub(crate) fn scxml(&self, name: &str, initial: &str) -> Element {
        self.el(
            "scxml",
            &[
                ("name", name),
                ("version", "1.0"),
                ("model_src", ""),
                ("initial", initial),
                ("xmlns", "http://www.w3.org/2005/07/scxml"),
            ],
        )
    }

    /// A `<datamodel>` with one typed `<data>` per `(id, type, expr)`, typed by
    /// `<!-- TYPE id:type -->` comments as AS2FM writes them.
    pub(crate) fn datamodel(&self, vars: &[(&str, &str, String)]) -> Element {
        let mut dm = self.el("datamodel", &[]);
        for (id, ty, expr) in vars {
            dm.push_comment(format!(" TYPE {id}:{ty} "));
            dm.push(self.el("data", &[("id", id), ("expr", expr)]));
        }
        dm
    }

    /// `<state id>`.
    pub(crate) fn state(&self, id: &str) -> Element {
        self.el("state", &[("id", id)])
    }

    /// `<state id>` whose `<onentry>` holds `body`.
    pub(crate) fn state_entry(&self, id: &str, body: Vec<Element>) -> Element {
        let mut s = self.state(id);
        let mut on = self.el("onentry", &[]);
        for b in body {
            on.push(b);
        }
        s.push(on);
        s
    }

    /// A `<transition>` with optional event, cond and target, and `body`.
    pub(crate) fn tr(
        &self,
        event: Option<&str>,
        cond: Option<&str>,
        target: Option<&str>,
        body: Vec<Element>,
    ) -> Element {
        let mut t = self.el("transition", &[]);
        if let Some(e) = event {
            t.set_attr("event", e);
        }
        if let Some(c) = cond {
            t.set_attr("cond", c);
        }
        if let Some(g) = target {
            t.set_attr("target", g);
        }
        for b in body {
            t.push(b);
        }
        t
    }

    /// `<assign location expr>`.
    pub(crate) fn assign(&self, location: &str, expr: &str) -> Element {
        self.el("assign", &[("location", location), ("expr", expr)])
    }

    /// `<send event target>` without parameters.
    pub(crate) fn send(&self, event: &str, target: &str) -> Element {
        self.el("send", &[("event", event), ("target", target)])
    }

    /// `<send event target><param name expr/>...</send>`.
    pub(crate) fn send_params(
        &self,
        event: &str,
        target: &str,
        params: &[(&str, &str)],
    ) -> Element {
        let mut s = self.send(event, target);
        for (n, e) in params {
            s.push(self.el("param", &[("name", n), ("expr", e)]));
        }
        s
    }

    /// `<if cond=c0>b0<elseif cond=c1/>b1...<else/>other</if>`; `None` when `branches`
    /// is empty and `otherwise` too.
    pub(crate) fn if_chain(
        &self,
        branches: Vec<(String, Vec<Element>)>,
        otherwise: Vec<Element>,
    ) -> Option<Element> {
        let mut it = branches.into_iter();
        let (c0, b0) = it.next()?;
        let mut el = self.el("if", &[("cond", &c0)]);
        for b in b0 {
            el.push(b);
        }
        for (c, body) in it {
            el.push(self.el("elseif", &[("cond", &c)]));
            for b in body {
                el.push(b);
            }
        }
        if !otherwise.is_empty() {
            el.push(self.el("else", &[]));
            for b in otherwise {
                el.push(b);
            }
        }
        Some(el)
    }

    /// `<if cond>body</if>`.
    pub(crate) fn if_then(&self, cond: &str, body: Vec<Element>) -> Element {
        let mut el = self.el("if", &[("cond", cond)]);
        for b in body {
            el.push(b);
        }
        el
    }
}
