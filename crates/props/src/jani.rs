//! JANI property files, as AS2FM uses them: `Pmin` / `Pmax` / `P` of `F`, `G` and `U`
//! over the global variables AS2FM declares for every event, read into a
//! [`PropertyFile`] of ports and Past-MTL guarantees.
//!
//! # Variables
//!
//! AS2FM turns each SCXML event `E` into global JANI variables that its `<send>`s set:
//! `E.valid` (false until `E` is first sent, then true for good) and `E__P` for each
//! parameter `P` (the value of the last send; before any, the type's default `0`,
//! `false`, `0.0`, `""`). Event and parameter names may both contain `__`, so a name is
//! resolved against the model: `E__P` must name an event of the model and one of its
//! scalar parameters. Both become ports on every sender and target ([`super::ANY`]):
//! `E.valid` a [`PortKind::Sent`], `E__P` a [`PortKind::State`].
//!
//! # Formulas
//!
//! A property is `{"name", "expression"}`; the expression may be wrapped in
//! `filter` (`fun` `values`, `states` `initial`), then `Pmin`, `Pmax` or `P` of a path
//! formula. Every run is judged at its last point (`docs/SEMANTICS.md` section 4), and on a finite
//! run:
//!
//! | JANI | Past-MTL at the last point |
//! | --- | --- |
//! | `F f` | `P {f}` (f held once) |
//! | `G f` | `H {f}` |
//! | `f U g` | `P ({g} && Z H {f})` (g held once, f at every earlier point) |
//!
//! The min/max of a probability is the same estimate here: the simulator resolves
//! nondeterminism at random. State formulas become one atom each: `∧ ∨ ¬ ⇒`,
//! `= ≠ < ≤ > ≥`, `+ - * / %`, literals, variables; `abs(e)` as an operand of a
//! comparison (unfolded into two comparisons); `av` (an array value) compared with a
//! string parameter, read as the string of those character codes (AS2FM stores strings
//! as code arrays); `aa` with constant indices and `E__P.d1_len` on array and string
//! parameters ([`PortKind::Part`]; a string's elements are its character codes). Step,
//! time and reward bounds, nested path formulas, `.d2_len` and other operators are
//! reported as unsupported, with the file, line and column of the construct.

use std::path::Path;

use super::error::{Diagnostics, PropsError, PropsErrorKind};
use super::source::{Location, SourceFile, SourceText};
use super::{Port, PortKind, Property, PropertyFile, ANY};
use crate::expr::value::Ty;
use crate::model::json::{self, Json, Node};
use crate::sim::{CompiledModel, EventId};

mod expr;
use expr::Rendered;

/// Reads the JANI property file at `path` and resolves its variables against `model`.
pub fn parse_file(path: &Path, model: &CompiledModel) -> Result<PropertyFile, Diagnostics> {
    parse_file_selected(path, model, &mut |_| true)
}

/// [`parse_file`] keeping only the properties whose name `keep` accepts; the others are
/// not read beyond their name (so one using what hindsight does not support, a step
/// bound say, can be left out). `keep` sees every property's name.
pub fn parse_file_selected(
    path: &Path,
    model: &CompiledModel,
    keep: &mut dyn FnMut(&str) -> bool,
) -> Result<PropertyFile, Diagnostics> {
    let fail = |kind| {
        Diagnostics::from(vec![PropsError::error(
            path.display().to_string(),
            (1, 1),
            kind,
        )])
    };
    let text = match codegen::diag::read_source(path) {
        Ok(text) => text,
        Err(d) if d.line == 0 => return Err(fail(PropsErrorKind::Io(d.message))),
        Err(d) => {
            return Err(Diagnostics::from(vec![PropsError::error(
                path.display().to_string(),
                (d.line, d.col),
                PropsErrorKind::Encoding,
            )]))
        }
    };
    parse_str_selected(&text, path, model, keep)
}

/// Reads a JANI property file's text; `path` is only used in errors.
pub fn parse_str(
    text: &str,
    path: &Path,
    model: &CompiledModel,
) -> Result<PropertyFile, Diagnostics> {
    parse_str_selected(text, path, model, &mut |_| true)
}

/// [`parse_str`] keeping only the properties `keep` accepts (see [`parse_file_selected`]).
pub fn parse_str_selected(
    text: &str,
    path: &Path,
    model: &CompiledModel,
    keep: &mut dyn FnMut(&str) -> bool,
) -> Result<PropertyFile, Diagnostics> {
    // Not even the start of a JSON object: not the JANI file it was named as; its text,
    // maybe a secret, is not shown.
    let start = text.trim_start();
    if !start.is_empty() && !start.starts_with('{') {
        return Err(Diagnostics::from(vec![PropsError::error(
            path.display().to_string(),
            (1, 1),
            PropsErrorKind::Json(
                "not a JANI file: it does not start with `{` (its text is not shown)".into(),
            ),
        )]));
    }
    let lines = SourceFile::new(path, text);
    let root = json::parse(text).map_err(|(offset, message)| {
        Diagnostics::from(vec![super::error::error_at(
            path,
            &lines,
            lines.location(offset),
            PropsErrorKind::Json(message),
        )])
    })?;
    let mut r = Reader {
        path,
        lines: &lines,
        model,
        ports: Vec::new(),
        errors: Vec::new(),
    };
    let mut guarantees: Vec<Property> = Vec::new();
    match root.get("properties").map(|p| &p.value) {
        Some(Json::Array(items)) => {
            for item in items {
                let name = item.get("name").and_then(Node::as_str);
                if name.is_some_and(|n| !keep(n)) {
                    continue;
                }
                if let Some(p) = r.property(item) {
                    if let Some(first) = guarantees.iter().find(|g| g.id == p.id) {
                        let first = first.at;
                        r.error(
                            item.offset,
                            PropsErrorKind::Duplicate {
                                what: "property",
                                id: p.id.clone(),
                                first,
                            },
                        );
                    } else {
                        guarantees.push(p);
                    }
                }
            }
        }
        _ => r.jani(root.offset, "expected an object with a `properties` array"),
    }
    if !r.errors.is_empty() {
        let mut errors = r.errors;
        errors.sort_by_key(|e| (e.line, e.col));
        errors.dedup();
        return Err(Diagnostics::from(errors));
    }
    Ok(PropertyFile {
        path: path.to_path_buf(),
        ports: r.ports,
        guarantees,
        assumptions: Vec::new(),
        ros_types: Vec::new(),
    })
}

/// What a JANI variable name refers to in the model.
enum Var {
    Valid(EventId),
    Param(EventId, String, Ty),
}

struct Reader<'r, 'a> {
    path: &'r Path,
    lines: &'r SourceFile<'a>,
    model: &'r CompiledModel,
    ports: Vec<Port>,
    errors: Vec<PropsError>,
}

impl Reader<'_, '_> {
    fn at(&self, offset: usize) -> Location {
        self.lines.location(offset)
    }

    /// The `op` of an operator node (empty when it has none); `None`, with an error at
    /// it, when `op` is there but no string (`"op": 3`), so no message names an empty
    /// operator.
    pub(super) fn op_of(&mut self, node: &Node) -> Option<String> {
        let Some(op) = node.get("op") else {
            return Some(String::new());
        };
        if let Some(s) = op.as_str() {
            return Some(s.to_owned());
        }
        let what = match &op.value {
            Json::Null => "null".to_owned(),
            Json::Bool(b) => b.to_string(),
            Json::Number(n) => format!("the number {n}"),
            Json::Str(s) => s.clone(),
            Json::Array(_) => "an array".to_owned(),
            Json::Object(_) => "an object".to_owned(),
        };
        self.jani(
            op.offset,
            format!("`op` must be a string naming an operator, not {what}"),
        );
        None
    }

    fn error(&mut self, offset: usize, kind: PropsErrorKind) {
        let at = self.at(offset);
        self.errors
            .push(super::error::error_at(self.path, self.lines, at, kind));
    }

    fn jani(&mut self, offset: usize, message: impl Into<String>) {
        self.error(offset, PropsErrorKind::Jani(message.into()));
    }

    fn property(&mut self, node: &Node) -> Option<Property> {
        let Some(name) = node.get("name").and_then(Node::as_str) else {
            self.jani(node.offset, "a property needs a string `name`");
            return None;
        };
        let name = name.to_owned();
        if !super::is_valid_id(&name) {
            let at = node.get("name").map_or(node.offset, |n| n.offset);
            self.jani(
                at,
                format!("property name `{name}` is not {}", super::ID_RULE),
            );
            return None;
        }
        let Some(expr) = node.get("expression") else {
            self.jani(
                node.offset,
                format!("property `{name}` has no `expression`"),
            );
            return None;
        };
        let formula = self.probability(expr)?;
        Some(Property {
            id: name,
            formula,
            at: self.at(node.offset),
            converted: true,
        })
    }

    /// `filter(values, P.. (path), initial)` or `P.. (path)`.
    fn probability(&mut self, node: &Node) -> Option<SourceText> {
        let op = self.op_of(node)?;
        match op.as_str() {
            "filter" => {
                let fun = node.get("fun").and_then(Node::as_str).unwrap_or("");
                if fun != "values" {
                    self.jani(
                        node.offset,
                        format!("filter function `{fun}` is not supported (only `values`)"),
                    );
                    return None;
                }
                if let Some(states) = node.get("states") {
                    if states.get("op").and_then(Node::as_str) != Some("initial") {
                        self.jani(
                            states.offset,
                            "only `\"states\": {\"op\": \"initial\"}` is supported",
                        );
                        return None;
                    }
                }
                match node.get("values") {
                    Some(v) => self.probability(v),
                    None => {
                        self.jani(node.offset, "filter needs `values`");
                        None
                    }
                }
            }
            "Pmin" | "Pmax" | "P" => match node.get("exp") {
                Some(path) => self.path_formula(path),
                None => {
                    self.jani(node.offset, format!("`{op}` needs `exp`"));
                    None
                }
            },
            _ => {
                self.jani(
                    node.offset,
                    format!("`{op}`: only probabilities (`Pmin`, `Pmax`, `P`) are supported"),
                );
                None
            }
        }
    }

    fn check_bounds(&mut self, node: &Node) -> bool {
        if let Json::Object(members) = &node.value {
            for (key, at, _) in members {
                if matches!(
                    key.as_str(),
                    "step-bounds" | "time-bounds" | "reward-bounds"
                ) {
                    self.jani(
                        *at,
                        format!(
                            "`{key}` are not supported: a run's steps and time do not match JANI's"
                        ),
                    );
                    return false;
                }
            }
        }
        true
    }

    fn path_formula(&mut self, node: &Node) -> Option<SourceText> {
        let at = self.at(node.offset);
        let op = self.op_of(node)?;
        let op = op.as_str();
        if !self.check_bounds(node) {
            return None;
        }
        let mut out = SourceText::empty();
        match op {
            "F" | "G" => {
                let Some(f) = node.get("exp") else {
                    self.jani(node.offset, format!("`{op}` needs `exp`"));
                    return None;
                };
                let f = self.atom(f)?;
                out.push_generated(if op == "F" { "P " } else { "H " }, at);
                out.push_source(&f);
            }
            "U" => {
                let (Some(l), Some(r)) = (node.get("left"), node.get("right")) else {
                    self.jani(node.offset, "`U` needs `left` and `right`");
                    return None;
                };
                let left_true = l.value == Json::Bool(true);
                let l = self.atom(l);
                let r = self.atom(r);
                let (l, r) = (l?, r?);
                if left_true {
                    out.push_generated("P ", at);
                    out.push_source(&r);
                } else {
                    out.push_generated("P (", at);
                    out.push_source(&r);
                    out.push_generated(" && Z H ", at);
                    out.push_source(&l);
                    out.push_generated(")", at);
                }
            }
            _ => {
                self.jani(
                    node.offset,
                    format!("path operator `{op}` is not supported (only `F`, `G`, `U`)"),
                );
                return None;
            }
        }
        Some(out)
    }

    /// A state formula as one atom `{...}` (or `true` / `false`).
    fn atom(&mut self, node: &Node) -> Option<SourceText> {
        let at = self.at(node.offset);
        if let Json::Bool(b) = node.value {
            return Some(SourceText::generated(if b { "true" } else { "false" }, at));
        }
        self.wrapped_boolean(
            node,
            node.offset,
            "a state formula must be boolean",
            ["{", "}"],
        )
    }

    /// The boolean expression `node` as plain text between `around[0]` and `around[1]`
    /// (generated at `offset`, where the type `error` is reported if it is not boolean).
    pub(super) fn wrapped_boolean(
        &mut self,
        node: &Node,
        offset: usize,
        error: &str,
        around: [&str; 2],
    ) -> Option<SourceText> {
        let r = self.expr(node)?;
        if r.ty != Ty::Bool {
            self.error(
                offset,
                PropsErrorKind::Type {
                    message: error.into(),
                },
            );
            return None;
        }
        let text = self.plain(node, r)?;
        let at = self.at(offset);
        let mut out = SourceText::empty();
        out.push_generated(around[0], at);
        out.push_source(&text);
        out.push_generated(around[1], at);
        Some(out)
    }

    /// The text of an operand that is not `abs` or an array value.
    fn plain(&mut self, node: &Node, r: Rendered) -> Option<SourceText> {
        if r.abs.is_some() {
            self.jani(
                node.offset,
                "`abs` is supported only as an operand of a comparison",
            );
            return None;
        }
        if r.codes.is_some() {
            self.jani(
                node.offset,
                "an array value is supported only when compared with a string",
            );
            return None;
        }
        Some(r.text)
    }

    fn resolve(&self, name: &str) -> Option<Var> {
        if let Some(event) = name.strip_suffix(".valid") {
            if let Some(e) = self.model.event_id(event) {
                return Some(Var::Valid(e));
            }
        }
        let mut start = 0;
        while let Some(i) = name[start..].find("__") {
            let split = start + i;
            if let Some(e) = self.model.event_id(&name[..split]) {
                let param = &name[split + 2..];
                if let Some(k) = self.model.param_index(e, param) {
                    let ty = self.model.event_params(e)[k].1.clone();
                    return Some(Var::Param(e, param.to_owned(), ty));
                }
            }
            start = split + 1;
        }
        None
    }

    /// The port id for JANI variable `name`, declaring the port on first use.
    fn port(&mut self, name: &str, offset: usize) -> Option<(String, Ty)> {
        let at = self.at(offset);
        if let Some(base) = name.strip_suffix(".d1_len") {
            return self.part_port(base, Vec::new(), true, offset);
        }
        let var = match self.resolve(name) {
            Some(v) => v,
            None => {
                let hint = if name.ends_with(".d1_len") || name.contains(".d") {
                    " (array parameters are not supported)"
                } else {
                    ""
                };
                self.error(
                    offset,
                    PropsErrorKind::Jani(format!(
                        "`{name}` is neither `E.valid` nor `E__P` for an event E of the model and one of its parameters P{hint}"
                    )),
                );
                return None;
            }
        };
        let (event, kind, ty) = match var {
            Var::Valid(e) => (e, PortKind::Sent, Ty::Bool),
            Var::Param(e, param, ty) => {
                let (type_name, init) = match ty {
                    Ty::Bool => ("bool", "false"),
                    Ty::Int => ("int64", "0"),
                    Ty::Float => ("float64", "0.0"),
                    Ty::Str => ("string", "''"),
                    _ => {
                        self.jani(
                            offset,
                            format!("`{name}`: array and struct parameters are not supported"),
                        );
                        return None;
                    }
                };
                (
                    e,
                    PortKind::State {
                        param,
                        ty: type_name.to_owned(),
                        init: SourceText::generated(init, at),
                    },
                    ty,
                )
            }
        };
        Some((self.declare(name, event, kind, at), ty))
    }

    /// The id of the port for `kind` on `event`, declared on first use (named after `name`).
    fn declare(&mut self, name: &str, event: EventId, kind: PortKind, at: Location) -> String {
        let event_name = self.model.event_name(event).to_owned();
        if let Some(p) = self
            .ports
            .iter()
            .find(|p| p.event == event_name && p.kind.same_variable(&kind))
        {
            return p.id.clone();
        }
        let base: String = name
            .chars()
            .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
            .collect();
        let base = if base.starts_with(|c: char| c.is_ascii_digit()) {
            format!("v_{base}")
        } else {
            base
        };
        let mut id = base.clone();
        let mut n = 1;
        while self.ports.iter().any(|p| p.id == id) {
            n += 1;
            id = format!("{base}_{n}");
        }
        self.ports.push(Port {
            id: id.clone(),
            kind,
            event: event_name,
            origin: ANY.to_owned(),
            target: ANY.to_owned(),
            at,
        });
        id
    }

    /// A port on part of an array or string parameter: `path` into it, or its length.
    fn part_port(
        &mut self,
        base: &str,
        path: Vec<u32>,
        length: bool,
        offset: usize,
    ) -> Option<(String, Ty)> {
        let at = self.at(offset);
        let Some(Var::Param(event, param, ty)) = self.resolve(base) else {
            self.jani(
                offset,
                format!("`{base}` is not `E__P` for an event E of the model and an array or string parameter P"),
            );
            return None;
        };
        let mut cur = ty;
        for (k, _) in path.iter().enumerate() {
            cur = match cur {
                Ty::Array(inner, _) => *inner,
                Ty::Str if k + 1 == path.len() && !length => Ty::Int,
                _ => {
                    self.jani(
                        offset,
                        format!("`{base}` has no element at depth {}", k + 1),
                    );
                    return None;
                }
            };
        }
        let (ty, type_name) = if length {
            if !matches!(cur, Ty::Array(..) | Ty::Str) {
                self.jani(
                    offset,
                    format!("`{base}`: only arrays and strings have a length"),
                );
                return None;
            }
            (Ty::Int, "int64")
        } else {
            match cur {
                Ty::Bool => (Ty::Bool, "bool"),
                Ty::Int => (Ty::Int, "int64"),
                Ty::Float => (Ty::Float, "float64"),
                Ty::Str => (Ty::Str, "string"),
                _ => {
                    self.jani(
                        offset,
                        format!("`{base}`: only scalar elements can be observed"),
                    );
                    return None;
                }
            }
        };
        let mut name = base.to_owned();
        for i in &path {
            name.push_str(&format!("_{i}"));
        }
        if length {
            name.push_str("_len");
        }
        let kind = PortKind::Part {
            param,
            path,
            length,
            ty: type_name.to_owned(),
        };
        Some((self.declare(&name, event, kind, at), ty))
    }
}

impl PortKind {
    /// Whether two kinds declare the same variable of one event (same parameter).
    fn same_variable(&self, other: &PortKind) -> bool {
        match (self, other) {
            (PortKind::Sent, PortKind::Sent) | (PortKind::Event, PortKind::Event) => true,
            (PortKind::State { param: a, .. }, PortKind::State { param: b, .. }) => a == b,
            (
                PortKind::Part {
                    param: a,
                    path: pa,
                    length: la,
                    ..
                },
                PortKind::Part {
                    param: b,
                    path: pb,
                    length: lb,
                    ..
                },
            ) => a == b && pa == pb && la == lb,
            _ => false,
        }
    }
}
