//! Reads one `.scxml` file (the flat subset SCAN accepts) into a [`Machine`], collecting every error.

use super::ast::*;
use super::source::{unescaped_offset, Diagnostic, FileId, SourceMap, Span};
use super::types::{parse_type_comment, TypeAnn, TypeError, TypeExpr};
use super::xml::{self, Element, Node};
use codegen::duration::StepsOrDuration;

/// Reads the SCXML file `file` (already in `sm`) into a machine.
pub(crate) fn read_machine(sm: &SourceMap, file: FileId) -> Result<Machine, Vec<Diagnostic>> {
    let root = xml::parse(sm, file).map_err(|d| vec![d])?;
    read_machine_tree(sm, &root, file)
}

/// Reads a machine from an element tree already in memory (a lowered robot model).
///
/// `file` names the machine when the root has no `name`; spans in `root` may point into
/// any file of `sm` (a generated element carries the span of what it was made from).
pub(crate) fn read_machine_tree(
    sm: &SourceMap,
    root: &Element,
    file: FileId,
) -> Result<Machine, Vec<Diagnostic>> {
    let mut r = Reader {
        sm,
        errs: Vec::new(),
        uses_rand: false,
    };
    let m = r.machine(root, file);
    if r.errs.is_empty() {
        Ok(m)
    } else {
        Err(r.errs)
    }
}

struct Reader<'a> {
    sm: &'a SourceMap,
    errs: Vec<Diagnostic>,
    /// Whether a state has probabilistic targets, so the machine needs [`RAND`].
    uses_rand: bool,
}

/// The variable holding a state's random draw for its `<target prob>` transitions.
const RAND: &str = "__RAND__";

/// A pending `<!-- TYPE name:type -->` annotation.
type Pending = Option<(String, Result<TypeExpr, TypeError>, Span)>;

impl Reader<'_> {
    fn err(&mut self, span: Span, msg: impl Into<String>) {
        self.errs.push(self.sm.diag(span, msg));
    }

    fn ident(&self, a: &xml::Attr) -> Ident {
        Ident {
            name: a.value.trim().to_string(),
            span: a.value_span,
        }
    }

    fn src(&self, a: &xml::Attr) -> SrcExpr {
        SrcExpr {
            text: a.value.clone(),
            span: a.value_span,
        }
    }

    fn required_ident(&mut self, el: &Element, name: &str) -> Option<Ident> {
        match el.required(self.sm, name) {
            Ok(a) if a.value.trim().is_empty() => {
                self.err(a.value_span, format!("attribute `{name}` is empty"));
                None
            }
            Ok(a) => Some(self.ident(a)),
            Err(d) => {
                self.errs.push(d);
                None
            }
        }
    }

    /// The `event` a `<send>` or `<raise>` names: one name, no blanks. A transition's
    /// `event="a b"` lists two events, so a sent `a b` could never be taken.
    fn sent_event(&mut self, el: &Element) -> Option<Ident> {
        let ev = self.required_ident(el, "event")?;
        if ev.name.contains(char::is_whitespace) {
            self.err(
                ev.span,
                format!(
                    "event `{}` has blanks: an event name is one word (a transition's \
                     `event=\"a b\"` lists two events)",
                    ev.name
                ),
            );
            return None;
        }
        Some(ev)
    }

    fn required_src(&mut self, el: &Element, name: &str) -> Option<SrcExpr> {
        match el.required(self.sm, name) {
            Ok(a) => Some(self.src(a)),
            Err(d) => {
                self.errs.push(d);
                None
            }
        }
    }

    fn check(&mut self, el: &Element, allowed: &[&str]) {
        el.check_attrs(self.sm, allowed, &mut self.errs);
    }

    fn text_not_allowed(&mut self, el: &Element) {
        for n in &el.children {
            if let Node::Text(span) = n {
                self.err(*span, format!("unexpected text inside <{}>", el.name));
            }
        }
    }

    fn machine(&mut self, root: &Element, file: FileId) -> Machine {
        if root.name != "scxml" {
            self.err(
                root.span,
                format!("expected an <scxml> root element, found <{}>", root.name),
            );
        }
        self.check(
            root,
            &[
                "name",
                "initial",
                "version",
                "datamodel",
                "binding",
                "model_src",
            ],
        );
        if let Some(dm) = root.attr("datamodel") {
            if dm.value != "ecmascript" {
                self.err(
                    dm.value_span,
                    format!("unsupported datamodel `{}` (only ecmascript)", dm.value),
                );
            }
        }
        let name = match root.attr("name") {
            Some(a) => self.ident(a),
            None => {
                let stem = self
                    .sm
                    .source(file)
                    .and_then(|f| f.path().file_stem())
                    .map(|s| s.to_string_lossy().into_owned())
                    .unwrap_or_default();
                Ident {
                    name: stem,
                    span: root.span,
                }
            }
        };
        let initial = root.attr("initial").map(|a| self.ident(a));
        let mut m = Machine {
            name,
            initial,
            datamodel: Vec::new(),
            states: Vec::new(),
            span: root.span,
        };
        self.text_not_allowed(root);
        for el in root.elements() {
            match el.name.as_str() {
                "datamodel" => self.datamodel(el, &mut m.datamodel),
                "state" | "final" => {
                    if let Some(s) = self.state(el) {
                        m.states.push(s);
                    }
                }
                "parallel" | "history" | "initial" | "invoke" => self.err(
                    el.span,
                    format!("<{}> is not supported: machines must be flat", el.name),
                ),
                "script" => self.err(el.span, "<script> is not supported"),
                other => self.err(el.span, format!("unexpected <{other}> in <scxml>")),
            }
        }
        if m.states.is_empty() {
            self.err(root.span, "the machine has no state");
        }
        if self.uses_rand {
            m.datamodel.push(Data {
                id: Ident {
                    name: RAND.into(),
                    span: root.span,
                },
                ty: Some(TypeAnn {
                    ty: TypeExpr::Base(super::types::BaseType::Float),
                    span: root.span,
                }),
                expr: Some(SrcExpr {
                    text: "0.0".into(),
                    span: root.span,
                }),
                span: root.span,
            });
        }
        m
    }

    fn datamodel(&mut self, el: &Element, out: &mut Vec<Data>) {
        self.check(el, &[]);
        self.text_not_allowed(el);
        let mut pending: Pending = None;
        for node in &el.children {
            match node {
                Node::Comment(text, span) => {
                    if let Some((n, t)) = parse_type_comment(text) {
                        pending = Some((n, t, *span));
                    }
                }
                Node::Text(_) => {}
                Node::Element(d) if d.name == "data" => {
                    self.check(d, &["id", "expr", "type", "src"]);
                    if let Some(src) = d.attr("src") {
                        self.err(src.name_span, "<data src> is not supported");
                    }
                    let Some(id) = self.required_ident(d, "id") else {
                        continue;
                    };
                    let mut ty = self.type_attr(d);
                    if let Some((n, t, span)) = pending.take() {
                        if n == id.name && ty.is_none() {
                            ty = self.type_ann(t, span);
                        }
                    }
                    if d.children.iter().any(|c| !matches!(c, Node::Comment(..))) {
                        self.err(d.span, "<data> content is not supported; use `expr`");
                    }
                    out.push(Data {
                        id,
                        ty,
                        expr: d.attr("expr").map(|a| self.src(a)),
                        span: d.span,
                    });
                }
                Node::Element(other) => self.err(
                    other.span,
                    format!("unexpected <{}> in <datamodel>", other.name),
                ),
            }
        }
    }

    fn type_ann(&mut self, t: Result<TypeExpr, TypeError>, span: Span) -> Option<TypeAnn> {
        match t {
            Ok(ty) => Some(TypeAnn { ty, span }),
            Err(m) => {
                self.err(span, m.to_string());
                None
            }
        }
    }

    fn type_attr(&mut self, el: &Element) -> Option<TypeAnn> {
        let a = el.attr("type")?;
        let t = TypeExpr::parse(&a.value);
        self.type_ann(t, a.value_span)
    }

    /// A constant delay `text` written in attribute `a`: whole model time units, or a
    /// duration (`codegen::duration`, the one reader of both).
    fn delay_text(&mut self, text: &str, a: &crate::model::xml::Attr) -> Option<Delay> {
        match codegen::duration::parse_steps_or_duration(text) {
            Ok(StepsOrDuration::Steps(n)) => Some(Delay::Const(n, a.value_span)),
            Ok(StepsOrDuration::Nanos(ns)) => Some(Delay::Duration(ns, a.value_span)),
            Err(e) => {
                self.err(
                    a.value_span,
                    format!(
                        "delay `{text}` is neither a whole number of model time units nor a \
                         duration (`500ms`, `1.5s`): {e}"
                    ),
                );
                None
            }
        }
    }

    fn state(&mut self, el: &Element) -> Option<State> {
        match el.attr("initial") {
            // A compound state's: say so once, not as a stray attribute.
            Some(a) => {
                self.check(el, &["id", "initial"]);
                self.err(
                    a.name_span,
                    "nested states are not supported: machines must be flat (`initial` on a \
                     <state> names one of its child states)",
                );
            }
            None => self.check(el, &["id"]),
        }
        self.text_not_allowed(el);
        let id = self.required_ident(el, "id")?;
        let mut s = State {
            id,
            onentry: Vec::new(),
            onexit: Vec::new(),
            transitions: Vec::new(),
            is_final: el.name == "final",
            span: el.span,
        };
        let mut prob = false;
        for c in el.elements() {
            match c.name.as_str() {
                "onentry" => {
                    self.check(c, &[]);
                    let mut v = self.block(c, 0);
                    s.onentry.append(&mut v);
                }
                "onexit" => {
                    self.check(c, &[]);
                    let mut v = self.block(c, 0);
                    s.onexit.append(&mut v);
                }
                "transition" => {
                    if s.is_final {
                        self.err(c.span, "a <final> state cannot have transitions");
                    }
                    if c.elements().any(|t| t.name == "target") {
                        let mut ts = self.probabilistic(c);
                        if !ts.is_empty() {
                            prob = true;
                        }
                        s.transitions.append(&mut ts);
                    } else if let Some(t) = self.transition(c) {
                        s.transitions.push(t);
                    }
                }
                "state" | "parallel" | "final" | "history" | "initial" => self.err(
                    c.span,
                    format!(
                        "nested <{}> is not supported: machines must be flat",
                        c.name
                    ),
                ),
                "datamodel" => self.err(c.span, "a <datamodel> must be a child of <scxml>"),
                "invoke" => self.err(c.span, "<invoke> is not supported"),
                "donedata" => self.err(c.span, "<donedata> is not supported"),
                other => self.err(c.span, format!("unexpected <{other}> in <{}>", el.name)),
            }
        }
        if prob {
            // One draw per entry decides every probabilistic transition of the state.
            s.onentry.insert(
                0,
                Exec::Assign {
                    location: SrcExpr {
                        text: RAND.into(),
                        span: el.span,
                    },
                    expr: SrcExpr {
                        text: "Math.random()".into(),
                        span: el.span,
                    },
                    span: el.span,
                },
            );
            self.uses_rand = true;
        }
        Some(s)
    }

    /// A transition whose content is `<target id prob>` children: one transition per
    /// target, taken when the state's draw `__RAND__` (uniform in [0, 1), made on entry)
    /// falls in the target's share, as AS2FM translates them. When the shares add up to
    /// less than 1, the rest takes no transition.
    fn probabilistic(&mut self, el: &Element) -> Vec<Transition> {
        self.check(el, &["event", "cond"]);
        let Some(base) = self.transition_head(el) else {
            return Vec::new();
        };
        let mut out = Vec::new();
        let mut lo = 0.0f64;
        for c in el.elements() {
            if c.name != "target" {
                self.err(
                    c.span,
                    format!(
                        "<{}> beside <target> children: put it inside each <target>",
                        c.name
                    ),
                );
                continue;
            }
            self.check(c, &["id", "prob"]);
            let Some(id) = self.required_ident(c, "id") else {
                continue;
            };
            let Some(pa) = c.attr("prob") else {
                self.err(c.span, "<target> is missing the required attribute `prob`");
                continue;
            };
            let p = match pa.value.trim().parse::<f64>() {
                Ok(p) if (0.0..=1.0).contains(&p) => p,
                _ => {
                    self.err(
                        pa.value_span,
                        format!(
                            "`prob` must be a number between 0 and 1, not `{}`",
                            pa.value
                        ),
                    );
                    continue;
                }
            };
            let hi = lo + p;
            if hi > 1.0 + 1e-9 {
                self.err(
                    pa.value_span,
                    format!("the targets' probabilities add up to {hi}, more than 1"),
                );
            }
            let range = format!("{RAND} >= {lo:?} && {RAND} < {hi:?}");
            let text = match &base.cond {
                Some(c) => format!("({}) && ({range})", c.text),
                None => range,
            };
            out.push(Transition {
                events: base.events.clone(),
                cond: Some(SrcExpr {
                    text,
                    span: pa.value_span,
                }),
                target: Some(id),
                body: self.block(c, 0),
                span: c.span,
            });
            lo = hi;
        }
        out
    }

    fn transition(&mut self, el: &Element) -> Option<Transition> {
        self.check(el, &["event", "cond", "target"]);
        let mut t = self.transition_head(el)?;
        t.target = match el.attr("target") {
            Some(a) if a.value.split_whitespace().count() > 1 => {
                self.err(a.value_span, "a transition may have only one target");
                None
            }
            Some(a) => Some(self.ident(a)),
            None => None,
        };
        t.body = self.block(el, 0);
        Some(t)
    }

    /// A transition's events and condition (no target, no content yet).
    fn transition_head(&mut self, el: &Element) -> Option<Transition> {
        let events = match el.attr("event") {
            Some(a) => {
                let mut v = Vec::new();
                let mut off = 0u32;
                for part in a.value.split(' ') {
                    if !part.trim().is_empty() {
                        v.push(Ident {
                            name: part.trim().to_string(),
                            span: unescaped_offset(self.sm, a.value_span, off),
                        });
                    }
                    off += part.len() as u32 + 1;
                }
                if v.is_empty() {
                    self.err(a.value_span, "empty `event` attribute");
                }
                if v.iter().any(|e| e.name.contains('*')) {
                    self.err(a.value_span, "wildcard events are not supported");
                }
                v
            }
            None => Vec::new(),
        };
        Some(Transition {
            events,
            cond: el.attr("cond").map(|a| self.src(a)),
            target: None,
            body: Vec::new(),
            span: el.span,
        })
    }

    /// Executable content of `el`'s children.
    fn block(&mut self, el: &Element, depth: usize) -> Vec<Exec> {
        self.text_not_allowed(el);
        let mut out = Vec::new();
        let mut pending: Pending = None;
        for node in &el.children {
            match node {
                Node::Comment(text, span) => {
                    if let Some((n, t)) = parse_type_comment(text) {
                        pending = Some((n, t, *span));
                    }
                }
                Node::Text(_) => {}
                Node::Element(c) => {
                    if let Some(e) = self.exec(c, depth, &mut pending) {
                        out.push(e);
                    }
                }
            }
        }
        out
    }

    fn exec(&mut self, el: &Element, depth: usize, pending: &mut Pending) -> Option<Exec> {
        if depth > 64 {
            self.err(el.span, "executable content nested too deeply");
            return None;
        }
        match el.name.as_str() {
            "assign" => {
                self.check(el, &["location", "expr"]);
                self.text_not_allowed(el);
                let location = self.required_src(el, "location")?;
                let expr = self.required_src(el, "expr")?;
                Some(Exec::Assign {
                    location,
                    expr,
                    span: el.span,
                })
            }
            "raise" => {
                self.check(el, &["event"]);
                let event = self.sent_event(el)?;
                Some(Exec::Raise {
                    event,
                    span: el.span,
                })
            }
            "log" => {
                self.check(el, &["label", "expr"]);
                Some(Exec::Log {
                    label: el.attr("label").map(|a| a.value.clone()),
                    expr: el.attr("expr").map(|a| self.src(a)),
                    span: el.span,
                })
            }
            "send" => self.send(el, pending),
            "if" => {
                self.check(el, &["cond"]);
                self.text_not_allowed(el);
                let cond = self.required_src(el, "cond")?;
                let mut branches = vec![(cond, Vec::new())];
                let mut otherwise = Vec::new();
                let mut in_else = false;
                let mut inner: Pending = None;
                for node in &el.children {
                    let c = match node {
                        Node::Element(c) => c,
                        Node::Comment(text, span) => {
                            if let Some((n, t)) = parse_type_comment(text) {
                                inner = Some((n, t, *span));
                            }
                            continue;
                        }
                        Node::Text(_) => continue,
                    };
                    match c.name.as_str() {
                        "elseif" => {
                            self.check(c, &["cond"]);
                            if in_else {
                                self.err(c.span, "<elseif> after <else>");
                            }
                            if let Some(cond) = self.required_src(c, "cond") {
                                branches.push((cond, Vec::new()));
                            }
                            if c.elements().next().is_some() {
                                self.err(
                                    c.span,
                                    "<elseif> must be empty (`<elseif cond=\"..\"/>`)",
                                );
                            }
                        }
                        "else" => {
                            self.check(c, &[]);
                            if in_else {
                                self.err(c.span, "more than one <else>");
                            }
                            in_else = true;
                            if c.elements().next().is_some() {
                                self.err(c.span, "<else> must be empty (`<else/>`)");
                            }
                        }
                        _ => {
                            if let Some(e) = self.exec(c, depth + 1, &mut inner) {
                                if in_else {
                                    otherwise.push(e);
                                } else if let Some(last) = branches.last_mut() {
                                    last.1.push(e);
                                }
                            }
                        }
                    }
                }
                Some(Exec::If {
                    branches,
                    otherwise,
                    span: el.span,
                })
            }
            "elseif" | "else" => {
                self.err(el.span, format!("<{}> outside <if>", el.name));
                None
            }
            "script" => {
                self.err(el.span, "<script> is not supported");
                None
            }
            "cancel" | "foreach" => {
                self.err(el.span, format!("<{}> is not supported", el.name));
                None
            }
            other => {
                self.err(
                    el.span,
                    format!("unexpected <{other}> in executable content"),
                );
                None
            }
        }
    }

    fn send(&mut self, el: &Element, pending: &mut Pending) -> Option<Exec> {
        self.check(
            el,
            &[
                "event",
                "target",
                "targetexpr",
                "delay",
                "delayexpr",
                "type",
            ],
        );
        self.text_not_allowed(el);
        if let Some(t) = el.attr("type") {
            let v = t.value.trim();
            if !(v == "scxml" || v.ends_with("SCXMLEventProcessor")) {
                self.err(t.value_span, format!("unsupported send type `{v}`"));
            }
        }
        let event = self.sent_event(el);
        let target = match (el.attr("target"), el.attr("targetexpr")) {
            (Some(a), None) => Some(SendTarget::Id(self.ident(a))),
            (None, Some(a)) => Some(SendTarget::Expr(self.src(a))),
            (None, None) => None,
            (Some(_), Some(b)) => {
                self.err(b.name_span, "<send> has both `target` and `targetexpr`");
                None
            }
        };
        // `delayexpr="'50ms'"`, a constant CSS2 duration (the W3C tests write them so),
        // reads as `delay="50ms"`.
        let constant = el
            .attr("delayexpr")
            .filter(|_| el.attr("delay").is_none())
            .and_then(|a| string_literal(&a.value).map(|text| (text, a)));
        let delay = match (el.attr("delay"), el.attr("delayexpr")) {
            _ if constant.is_some() => constant.and_then(|(text, a)| self.delay_text(text, a)),
            // Whole steps, or a duration (`codegen::duration`, the one reader of both).
            (Some(a), None) => self.delay_text(&a.value, a),
            (None, Some(a)) => Some(match unit_suffix(&a.value) {
                Some((len, ns)) => Delay::ExprIn(
                    SrcExpr {
                        text: a.value[..len].to_string(),
                        span: a.value_span,
                    },
                    ns,
                ),
                None => Delay::Expr(self.src(a)),
            }),
            (None, None) => None,
            (Some(_), Some(b)) => {
                self.err(b.name_span, "<send> has both `delay` and `delayexpr`");
                None
            }
        };
        let mut params = Vec::new();
        // An annotation right before the <send> is for its first param (AS2FM writes them inside).
        let mut local: Pending = pending.take();
        for node in &el.children {
            match node {
                Node::Comment(text, span) => {
                    if let Some((n, t)) = parse_type_comment(text) {
                        local = Some((n, t, *span));
                    }
                }
                Node::Text(_) => {}
                Node::Element(p) if p.name == "param" => {
                    self.check(p, &["name", "expr", "location", "type"]);
                    let Some(name) = self.required_ident(p, "name") else {
                        continue;
                    };
                    let expr = match (p.attr("expr"), p.attr("location")) {
                        (Some(a), None) | (None, Some(a)) => self.src(a),
                        (Some(_), Some(b)) => {
                            self.err(b.name_span, "<param> has both `expr` and `location`");
                            continue;
                        }
                        (None, None) => {
                            self.err(p.span, "<param> needs `expr` or `location`");
                            continue;
                        }
                    };
                    let mut ty = self.type_attr(p);
                    if let Some((n, t, span)) = local.take() {
                        if n == name.name && ty.is_none() {
                            ty = self.type_ann(t, span);
                        }
                    }
                    if params.iter().any(|q: &Param| q.name.name == name.name) {
                        self.err(name.span, format!("param `{}` is given twice", name.name));
                        continue;
                    }
                    params.push(Param {
                        name,
                        expr,
                        ty,
                        span: p.span,
                    });
                }
                Node::Element(c) if c.name == "content" => {
                    self.err(c.span, "<content> is not supported; use <param>");
                }
                Node::Element(c) => {
                    self.err(c.span, format!("unexpected <{}> in <send>", c.name));
                }
            }
        }
        Some(Exec::Send(Send {
            event: event?,
            target,
            delay,
            params,
            span: el.span,
        }))
    }
}

/// The text of `text` when it is one string literal (`'50ms'`, `"2s"`), else `None`.
fn string_literal(text: &str) -> Option<&str> {
    let t = text.trim();
    let quote = t.chars().next().filter(|&c| c == '\'' || c == '"')?;
    let body = t[1..].strip_suffix(quote)?;
    (!body.contains(quote)).then_some(body)
}

/// `e + 'ms'` (or `"ms"`, any unit of `codegen::duration`): the length of `e`'s text and
/// the unit in nanoseconds. SCXML writes a computed delay as a CSS2 duration string, and
/// this is how a model builds one; the expression language has no string concatenation
/// otherwise, so `e` (a number) counts units of the suffix.
fn unit_suffix(text: &str) -> Option<(usize, u64)> {
    let t = text.trim_end();
    let quote = t.chars().last().filter(|&c| c == '\'' || c == '"')?;
    let body = &t[..t.len() - 1];
    let open = body.rfind(quote)?;
    let unit = codegen::duration::TimeUnit::from_suffix(&body[open + 1..])?;
    let before = body[..open].trim_end();
    let plus = before.strip_suffix('+')?;
    if plus.trim().is_empty() {
        return None;
    }
    Some((plus.len(), unit.nanos()))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read(text: &str) -> Result<Machine, Vec<Diagnostic>> {
        let mut sm = SourceMap::new();
        let f = sm.add("m.scxml", text.to_string());
        read_machine(&sm, f)
    }

    #[test]
    fn reads_the_subset() {
        let m = read(
            r#"<scxml name="M" initial="a" xmlns="http://www.w3.org/2005/07/scxml">
  <datamodel>
    <!-- TYPE x:int32 -->
    <data id="x" expr="0"/>
    <data id="y" type="float64"/>
  </datamodel>
  <state id="a">
    <onentry><raise event="go"/></onentry>
    <transition event="go tick" cond="x &lt; 3" target="b">
      <assign location="x" expr="x + 1"/>
      <if cond="x == 1"><log label="one"/><elseif cond="x == 2"/><log expr="x"/><else/><raise event="z"/></if>
      <send event="e" target="M" delay="2">
        <!-- TYPE p:float32 -->
        <param name="p" expr="x"/>
        <param name="q" location="y"/>
      </send>
    </transition>
  </state>
  <final id="b"/>
</scxml>"#,
        )
        .unwrap();
        assert_eq!(m.name.name, "M");
        assert_eq!(m.datamodel.len(), 2);
        assert!(m.datamodel[0].ty.is_some() && m.datamodel[1].ty.is_some());
        assert_eq!(m.states.len(), 2);
        let t = &m.states[0].transitions[0];
        assert_eq!(t.events.len(), 2);
        assert_eq!(t.events[1].name, "tick");
        assert_eq!(t.cond.as_ref().unwrap().text, "x < 3");
        match &t.body[1] {
            Exec::If {
                branches,
                otherwise,
                ..
            } => {
                assert_eq!(branches.len(), 2);
                assert_eq!(branches[1].1.len(), 1);
                assert_eq!(otherwise.len(), 1);
            }
            e => panic!("{e:?}"),
        }
        match &t.body[2] {
            Exec::Send(s) => {
                assert!(matches!(s.delay, Some(Delay::Const(2, _))));
                assert!(s.params[0].ty.is_some());
                assert!(s.params[1].ty.is_none());
            }
            e => panic!("{e:?}"),
        }
        assert!(m.states[1].is_final);
    }

    #[test]
    fn errors_have_positions() {
        let text = "<scxml name=\"M\">\n  <state id=\"a\" bogus=\"1\">\n    <parallel/>\n  </state>\n</scxml>";
        let errs = read(text).unwrap_err();
        assert_eq!(errs.len(), 2, "{errs:?}");
        assert_eq!((errs[0].line, errs[0].col), (2, 17));
        assert!(errs[0].message.contains("bogus"));
        assert_eq!((errs[1].line, errs[1].col), (3, 5));
    }

    #[test]
    fn probabilistic_targets_become_ranges_of_one_draw_per_entry() {
        let m = read(
            r#"<scxml name="M" initial="a"><state id="a">
  <transition event="go" cond="x > 0"><target id="a" prob="0.25"><raise event="p"/></target><target id="b" prob="0.75"/></transition>
</state><state id="b"/></scxml>"#,
        )
        .unwrap();
        let a = &m.states[0];
        assert_eq!(a.transitions.len(), 2);
        let conds: Vec<&str> = a
            .transitions
            .iter()
            .map(|t| t.cond.as_ref().unwrap().text.as_str())
            .collect();
        assert_eq!(
            conds,
            [
                "(x > 0) && (__RAND__ >= 0.0 && __RAND__ < 0.25)",
                "(x > 0) && (__RAND__ >= 0.25 && __RAND__ < 1.0)"
            ]
        );
        assert_eq!(a.transitions[0].target.as_ref().unwrap().name, "a");
        assert_eq!(a.transitions[0].body.len(), 1);
        assert_eq!(a.transitions[1].events[0].name, "go");
        assert!(
            matches!(&a.onentry[0], Exec::Assign { location, .. } if location.text == "__RAND__")
        );
        assert_eq!(m.datamodel.last().unwrap().id.name, "__RAND__");
        assert!(m.states[1].onentry.is_empty());
    }

    #[test]
    fn bad_probabilistic_targets_are_errors() {
        let errs = read(
            r#"<scxml name="M"><state id="a"><transition target="a"><target id="a" prob="0.7"/><target id="a" prob="0.7"/><target id="a" prob="x"/><assign location="y" expr="1"/></transition></state></scxml>"#,
        )
        .unwrap_err();
        let msgs: Vec<&str> = errs.iter().map(|e| e.message.as_str()).collect();
        assert_eq!(errs.len(), 4, "{msgs:?}");
        assert!(msgs[0].contains("unknown attribute `target`"), "{msgs:?}");
        assert!(msgs[1].contains("more than 1"), "{msgs:?}");
        assert!(msgs[2].contains("between 0 and 1"), "{msgs:?}");
        assert!(msgs[3].contains("beside <target>"), "{msgs:?}");
    }

    /// A sent or raised event is one word: a transition reads `event="a b"` as two.
    #[test]
    fn a_sent_event_with_blanks_is_refused() {
        let errs = read(
            r#"<scxml name="M"><state id="a"><onentry><send event="a b" target="M"/><raise event=" c	d "/></onentry>
            <transition event="a b" target="a"/></state></scxml>"#,
        )
        .unwrap_err();
        let msgs: Vec<String> = errs.iter().map(|d| d.to_string()).collect();
        assert_eq!(msgs.len(), 2, "{msgs:#?}");
        assert!(
            msgs[0].starts_with("m.scxml:1:53: event `a b` has blanks"),
            "{msgs:#?}"
        );
        // XML normalises the tab of an attribute value to a space.
        assert!(msgs[1].contains("event `c d` has blanks"), "{msgs:#?}");
    }

    #[test]
    fn bad_delay_and_missing_attrs() {
        let errs = read(
            r#"<scxml name="M"><state id="a"><onentry><send target="M" delay="soon"/><assign location="x"/></onentry></state></scxml>"#,
        )
        .unwrap_err();
        assert_eq!(errs.len(), 3, "{errs:?}");
    }

    #[test]
    fn a_constant_delayexpr_reads_as_a_delay() {
        // W3C's `delayexpr="'50ms'"` (a string literal) is `delay="50ms"`; a bad one is
        // the same error as a bad `delay`, at the attribute's value.
        let m = read(
            r#"<scxml name="M" initial="a"><state id="a"><onentry>
            <send event="e" target="M" delayexpr="'50ms'"/><send event="f" target="M" delayexpr=" &quot;3&quot; "/>
            </onentry></state></scxml>"#,
        )
        .unwrap();
        let delays: Vec<String> = m.states[0]
            .onentry
            .iter()
            .map(|x| match x {
                Exec::Send(s) => format!("{:?}", s.delay),
                other => panic!("{other:?}"),
            })
            .collect();
        assert!(
            delays[0].starts_with("Some(Duration(50000000,"),
            "{delays:?}"
        );
        assert!(delays[1].starts_with("Some(Const(3,"), "{delays:?}");
        let errs = read(
            r#"<scxml name="M" initial="a"><state id="a"><onentry><send event="e" target="M" delayexpr="'soon'"/></onentry></state></scxml>"#,
        )
        .unwrap_err();
        assert!(
            errs[0]
                .to_string()
                .starts_with("m.scxml:1:90: delay `soon` is neither"),
            "{errs:?}"
        );
    }

    #[test]
    fn a_compound_state_is_refused_at_its_initial_attribute() {
        let errs = read(
            r#"<scxml name="M" initial="a"><state id="a" initial="b"><state id="b"/></state></scxml>"#,
        )
        .unwrap_err();
        let msgs: Vec<String> = errs.iter().map(|d| d.to_string()).collect();
        assert!(
            msgs[0].starts_with("m.scxml:1:43: nested states are not supported"),
            "{msgs:#?}"
        );
        assert!(
            !msgs.iter().any(|m| m.contains("unknown attribute")),
            "{msgs:#?}"
        );
    }
}
