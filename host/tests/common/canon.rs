//! A plain SCXML machine as text that ignores formatting only, to compare our lowering with
//! AS2FM's plain translation element by element, in order.
//!
//! What is normalised (and nothing else): attribute order; `xmlns*`, `version` and
//! `model_src`; comments, except a `<!-- TYPE x:T -->` before a `<data>`, which becomes its
//! `type` attribute (AS2FM writes types as comments, we as attributes); whitespace and
//! parentheses in expressions, by parsing them and printing the syntax tree back (AS2FM
//! prints every expression again from its own tree); number literals as their value
//! (`1` and `1.0`); and the order of the copies of one `<send>` that differ only in their
//! target (see [`canon`]).

use hindsight::verify::expr::ast::{Expr, ExprKind};
use hindsight::verify::expr::parse_expr;
use hindsight::verify::model::source::SourceMap;
use hindsight::verify::model::xml::{self, Element, Node};
use std::path::Path;

/// Attributes that hold expressions.
const EXPR_ATTRS: [&str; 3] = ["cond", "expr", "location"];

/// `el` and everything below it, one element a line, indented by depth.
///
/// Copies of one `<send>` to several targets, side by side, are sorted by target: AS2FM
/// makes them from a Python `set` of the machines that handle the event
/// (`ScxmlSend.add_events_targets`, scxml_converter/scxml_entries/scxml_send.py, over the
/// `EventsToAutomata` map that `export_plain_scxml_models` builds), whose iteration order
/// changes from one run of the converter to the next (string hashing is randomised), so
/// their order in a plain translation is not a rule to compare against.
pub fn canon(el: &Element) -> String {
    let mut out = String::new();
    go(el, 0, &mut out);
    out
}

fn go(el: &Element, depth: usize, out: &mut String) {
    out.push_str(&"  ".repeat(depth));
    out.push_str(&head(el));
    out.push('\n');
    let mut pending_type: Option<String> = None;
    let mut kids: Vec<Element> = Vec::new();
    for n in &el.children {
        match n {
            Node::Comment(c, _) => {
                if let Some(rest) = c.trim().strip_prefix("TYPE ") {
                    pending_type = rest.split_once(':').map(|(_, t)| t.trim().to_string());
                }
            }
            Node::Element(c) => {
                let mut c = c.clone();
                if c.name == "data" && c.attr("type").is_none() {
                    if let Some(t) = pending_type.take() {
                        c.set_attr("type", t);
                    }
                }
                kids.push(c);
            }
            Node::Text(_) => {}
        }
    }
    // Runs of sends that differ only in `target`, sorted by target.
    let mut i = 0;
    while i < kids.len() {
        let mut j = i + 1;
        if kids[i].name == "send" {
            let key = |e: &Element| {
                let mut e = e.clone();
                e.attrs.retain(|a| a.name != "target");
                canon_body(&e)
            };
            let k = key(&kids[i]);
            while j < kids.len() && kids[j].name == "send" && key(&kids[j]) == k {
                j += 1;
            }
            kids[i..j].sort_by(|a, b| a.attr_value("target").cmp(&b.attr_value("target")));
        }
        i = j;
    }
    for c in &kids {
        go(c, depth + 1, out);
    }
}

fn canon_body(e: &Element) -> String {
    let mut s = String::new();
    go(e, 0, &mut s);
    s
}

/// `name a="v" b="w"` with sorted attributes and normalised expressions.
fn head(el: &Element) -> String {
    let mut attrs: Vec<(String, String)> = el
        .attrs
        .iter()
        .filter(|a| !a.name.starts_with("xmlns") && a.name != "version" && a.name != "model_src")
        .map(|a| {
            let v = if EXPR_ATTRS.contains(&a.name.as_str()) {
                expr_text(&a.value)
            } else {
                a.value.trim().to_string()
            };
            (a.name.clone(), v)
        })
        .collect();
    attrs.sort();
    let mut s = el.name.clone();
    for (k, v) in &attrs {
        s.push_str(&format!(" {k}={v:?}"));
    }
    s
}

/// An expression printed back from its syntax tree, fully parenthesised; text that does not
/// parse is kept without blanks.
pub fn expr_text(text: &str) -> String {
    match parse_expr(text) {
        Ok(e) => print(&e),
        Err(_) => text.chars().filter(|c| !c.is_whitespace()).collect(),
    }
}

fn number(f: f64) -> String {
    format!("{f:?}")
}

fn print(e: &Expr) -> String {
    match &e.kind {
        ExprKind::Int(i) => number(*i as f64),
        ExprKind::Float(f) => number(*f),
        ExprKind::Bool(b) => b.to_string(),
        ExprKind::Str(s) => format!("{s:?}"),
        ExprKind::Array(v) => format!("[{}]", list(v)),
        ExprKind::Object(fs) => {
            let fs: Vec<String> = fs
                .iter()
                .map(|f| format!("{}:{}", f.name, print(&f.value)))
                .collect();
            format!("{{{}}}", fs.join(","))
        }
        ExprKind::Ident(n) => n.clone(),
        ExprKind::Member(o, n, _) => format!("{}.{n}", print(o)),
        ExprKind::Index(a, i) => format!("{}[{}]", print(a), print(i)),
        ExprKind::Call(f, args) => format!("{}({})", print(f), list(args)),
        ExprKind::Unary(op, x) => format!("({op:?} {})", print(x)),
        ExprKind::Binary(op, a, b) => format!("({} {} {})", print(a), op.symbol(), print(b)),
        ExprKind::Cond(c, a, b) => format!("({} ? {} : {})", print(c), print(a), print(b)),
    }
}

fn list(v: &[Expr]) -> String {
    v.iter().map(print).collect::<Vec<_>>().join(",")
}

/// Reads one XML file (panics with the file's name on an error: test input).
pub fn parse_file(path: &Path) -> Element {
    let mut sm = SourceMap::new();
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let id = sm.add(path, text);
    xml::parse(&sm, id).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// Reads XML text (panics with `what` on an error: test input).
pub fn parse_text(what: &str, text: &str) -> Element {
    let mut sm = SourceMap::new();
    let id = sm.add(what, text.to_string());
    xml::parse(&sm, id).unwrap_or_else(|e| panic!("{what}: {e}"))
}

/// The first `n` lines where `a` and `b` differ, side by side (with their line numbers).
pub fn first_differences(a: &str, b: &str, n: usize) -> String {
    let (la, lb): (Vec<&str>, Vec<&str>) = (a.lines().collect(), b.lines().collect());
    let mut out = Vec::new();
    for i in 0..la.len().max(lb.len()) {
        let (x, y) = (la.get(i).copied(), lb.get(i).copied());
        if x != y {
            out.push(format!(
                "line {}:\n  ours:   {}\n  theirs: {}",
                i + 1,
                x.unwrap_or("(none)"),
                y.unwrap_or("(none)")
            ));
            if out.len() == n {
                break;
            }
        }
    }
    out.join("\n")
}
