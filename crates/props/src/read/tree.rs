//! The tree form of property files (`<Once>`, `<LessThan>`, `<predicate>` elements)
//! converted into Rye formula text that keeps the position of every element.

use std::collections::HashMap;

use super::super::error::PropsErrorKind;
use super::super::source::{Location, SourceText};
use super::super::{Port, PortKind, Property};
use super::{FileReader, Ty};
use crate::model::xml::Element;

/// A value-level expression of the tree form, as text.
struct Term {
    text: SourceText,
    ty: Ty,
    /// Whether the text needs parentheses when it is an operand.
    compound: bool,
}

impl Term {
    fn nested(&self) -> SourceText {
        if !self.compound {
            return self.text.clone();
        }
        let mut out = SourceText::empty();
        let at = self.text.location(0);
        out.push_generated("(", at);
        out.push_source(&self.text);
        out.push_generated(")", at);
        out
    }
}

/// What a variable id refers to.
#[derive(Clone, Copy)]
struct VarInfo {
    ty: Ty,
}

/// Where a predicate stands during conversion.
enum PredicateState<'e> {
    Pending(&'e Element),
    Converting,
    Done(Option<(SourceText, Ty, bool)>),
}

/// Converts tree-form formulas and predicates into Rye text.
pub(super) struct Converter<'r, 'p, 'a, 'e> {
    reader: &'r mut FileReader<'p, 'a>,
    variables: HashMap<String, VarInfo>,
    predicates: HashMap<&'a str, PredicateState<'e>>,
    order: Vec<&'a str>,
}

impl<'r, 'p, 'a, 'e> Converter<'r, 'p, 'a, 'e> {
    pub(super) fn new(
        reader: &'r mut FileReader<'p, 'a>,
        ports: &[Port],
        predicates: &[&'e Element],
    ) -> Self {
        let mut variables = HashMap::new();
        for port in ports {
            let ty = match &port.kind {
                PortKind::Event | PortKind::Sent => Ty::Bool,
                PortKind::State { ty, .. } | PortKind::Part { ty, .. } => {
                    Ty::of(ty).unwrap_or(Ty::Int)
                }
            };
            variables.entry(port.id.clone()).or_insert(VarInfo { ty });
        }
        let mut table: HashMap<&'a str, PredicateState<'e>> = HashMap::new();
        let mut order = Vec::new();
        let mut first_at: HashMap<&'a str, Location> = HashMap::new();
        for &predicate in predicates {
            reader.check_attrs(predicate, &["id"]);
            let Some(id_attr) = FileReader::attr(predicate, "id") else {
                reader.error(
                    reader.at(predicate.span),
                    PropsErrorKind::MissingAttribute {
                        element: "predicate".to_owned(),
                        name: "id",
                    },
                );
                continue;
            };
            let id = reader.raw(id_attr);
            if let Some(&first) = first_at.get(id) {
                reader.error(
                    reader.at(predicate.span),
                    PropsErrorKind::Duplicate {
                        what: "predicate",
                        id: id.to_owned(),
                        first,
                    },
                );
                continue;
            }
            if variables.contains_key(id) {
                reader.error(
                    reader.at(predicate.span),
                    PropsErrorKind::Type {
                        message: format!("predicate `{id}` has the name of a variable"),
                    },
                );
                continue;
            }
            first_at.insert(id, reader.at(predicate.span));
            table.insert(id, PredicateState::Pending(predicate));
            order.push(id);
        }
        Converter {
            reader,
            variables,
            predicates: table,
            order,
        }
    }

    /// Converts the predicates no property used, so their errors are reported too.
    pub(super) fn finish(&mut self) {
        for id in self.order.clone() {
            self.predicate(id);
        }
    }

    pub(super) fn tree_property(&mut self, element: &'e Element) -> Option<Property> {
        self.reader.check_attrs(element, &["id"]);
        let id = self.reader.required_id(element);
        let body = self.only_child(element)?;
        let mut formula = self.formula(body, &element.name)?;
        // The top level needs no parentheses.
        formula = strip_outer(formula);
        Some(Property {
            id: id?,
            formula,
            at: self.reader.at(element.span),
            converted: true,
        })
    }

    fn only_child(&mut self, element: &'e Element) -> Option<&'e Element> {
        let mut children = element.elements();
        if let (Some(only), None) = (children.next(), children.next()) {
            Some(only)
        } else {
            self.reader.error(
                self.reader.at(element.span),
                PropsErrorKind::Arity {
                    element: element.name.clone(),
                    expected: "exactly one element",
                    found: element.elements().count(),
                },
            );
            None
        }
    }

    fn operands(
        &mut self,
        element: &'e Element,
        expected: &'static str,
        ok: impl Fn(usize) -> bool,
    ) -> Option<Vec<&'e Element>> {
        let children: Vec<&'e Element> = element.elements().collect();
        if ok(children.len()) {
            Some(children)
        } else {
            self.reader.error(
                self.reader.at(element.span),
                PropsErrorKind::Arity {
                    element: element.name.clone(),
                    expected,
                    found: element.elements().count(),
                },
            );
            None
        }
    }

    /// The `[a:b]` interval of a temporal element's `lower_bound` / `upper_bound`.
    fn interval(&mut self, element: &'e Element) -> Option<String> {
        self.reader
            .check_attrs(element, &["lower_bound", "upper_bound"]);
        let mut bound = |name: &'static str| -> Result<Option<u64>, ()> {
            let Some((value, at)) = self.reader.optional(element, name) else {
                return Ok(None);
            };
            match value.as_str().trim().parse::<u64>() {
                Ok(number) => Ok(Some(number)),
                Err(_) => {
                    self.reader.error(
                        at,
                        PropsErrorKind::BadValue {
                            attribute: name.to_owned(),
                            value: value.as_str().to_owned(),
                            expected: "a non-negative integer (time units)".to_owned(),
                        },
                    );
                    Err(())
                }
            }
        };
        let lower = bound("lower_bound");
        let upper = bound("upper_bound");
        let (Ok(lower), Ok(upper)) = (lower, upper) else {
            return None;
        };
        if let (Some(lower), Some(upper)) = (lower, upper) {
            if lower > upper {
                let at = FileReader::attr(element, "upper_bound")
                    .map_or(self.reader.at(element.span), |a| {
                        self.reader.at(a.name_span)
                    });
                self.reader.error(
                    at,
                    PropsErrorKind::BadValue {
                        attribute: "upper_bound".to_owned(),
                        value: upper.to_string(),
                        expected: format!("at least lower_bound ({lower})"),
                    },
                );
                return None;
            }
        }
        Some(match (lower, upper) {
            (None, None) => String::new(),
            (Some(lower), None) => format!("[{lower}:]"),
            (None, Some(upper)) => format!("[:{upper}]"),
            (Some(lower), Some(upper)) => format!("[{lower}:{upper}]"),
        })
    }

    /// A formula: self-delimited Rye text (an atom, a constant, or in parentheses).
    fn formula(&mut self, element: &'e Element, parent: &str) -> Option<SourceText> {
        let at = self.reader.at(element.span);
        let mut out = SourceText::empty();
        match element.name.as_str() {
            "true" | "false" => {
                self.reader.check_attrs(element, &[]);
                self.operands(element, "no operands", |n| n == 0)?;
                out.push_generated(&element.name, at);
            }
            "not" => {
                self.reader.check_attrs(element, &[]);
                let operand = self.only_child(element)?;
                let inner = self.formula(operand, &element.name)?;
                out.push_generated("(!", at);
                out.push_source(&inner);
                out.push_generated(")", at);
            }
            "and" | "or" | "implies" => {
                self.reader.check_attrs(element, &[]);
                let (symbol, operands) = if element.name == "implies" {
                    (" -> ", self.operands(element, "two operands", |n| n == 2)?)
                } else {
                    let symbol = if element.name == "and" {
                        " && "
                    } else {
                        " || "
                    };
                    (
                        symbol,
                        self.operands(element, "at least one operand", |n| n >= 1)?,
                    )
                };
                let parts: Vec<Option<SourceText>> = operands
                    .iter()
                    .map(|child| self.formula(child, &element.name))
                    .collect();
                let parts: Vec<SourceText> = parts.into_iter().collect::<Option<_>>()?;
                if let [only] = parts.as_slice() {
                    return Some(only.clone());
                }
                out.push_generated("(", at);
                for (i, part) in parts.iter().enumerate() {
                    if i > 0 {
                        out.push_generated(symbol, at);
                    }
                    out.push_source(part);
                }
                out.push_generated(")", at);
            }
            "historically" | "previously" | "once" => {
                let interval = self.interval(element);
                let operand = self.only_child(element);
                let inner = self.formula(operand?, &element.name)?;
                let word = if element.name == "historically" {
                    "historically"
                } else {
                    "once"
                };
                out.push_generated(&format!("({word}{} ", interval?), at);
                out.push_source(&inner);
                out.push_generated(")", at);
            }
            "since" => {
                let interval = self.interval(element);
                let operands = self.operands(element, "two operands", |n| n == 2)?;
                let left = self.formula(operands[0], &element.name);
                let right = self.formula(operands[1], &element.name);
                let (interval, left, right) = (interval?, left?, right?);
                out.push_generated("(", at);
                out.push_source(&left);
                out.push_generated(&format!(" since{interval} "), at);
                out.push_source(&right);
                out.push_generated(")", at);
            }
            _ => {
                let term = self.term(element, parent)?;
                if term.ty != Ty::Bool {
                    self.reader.error(
                        at,
                        PropsErrorKind::Type {
                            message: format!(
                                "<{}> has {} type, but a formula needs a boolean",
                                element.name,
                                term.ty.name()
                            ),
                        },
                    );
                    return None;
                }
                out.push_generated("{", at);
                out.push_source(&term.text);
                out.push_generated("}", at);
            }
        }
        Some(out)
    }

    /// A predicate's converted text and type, converting it on first use.
    fn predicate(&mut self, id: &'a str) -> Option<(SourceText, Ty, bool)> {
        match self.predicates.get(id) {
            Some(PredicateState::Done(done)) => return done.clone(),
            Some(PredicateState::Converting) | None => return None,
            Some(PredicateState::Pending(_)) => {}
        }
        let Some(PredicateState::Pending(element)) =
            self.predicates.insert(id, PredicateState::Converting)
        else {
            return None;
        };
        let result = self.only_child(element).and_then(|body| {
            let term = self.term(body, &element.name)?;
            Some((term.text, term.ty, term.compound))
        });
        self.predicates
            .insert(id, PredicateState::Done(result.clone()));
        result
    }

    /// A value-level expression.
    fn term(&mut self, element: &'e Element, parent: &str) -> Option<Term> {
        let at = self.reader.at(element.span);
        let name = element.name.as_str();
        let mut text = SourceText::empty();
        match name {
            "var" => {
                self.reader.check_attrs(element, &["refid"]);
                self.operands(element, "no operands", |n| n == 0)?;
                let (refid, _) = self.reader.required(element, "refid")?;
                let id = refid.as_str().to_owned();
                if let Some(info) = self.variables.get(&id).copied() {
                    text.push_source(&refid);
                    return Some(Term {
                        text,
                        ty: info.ty,
                        compound: false,
                    });
                }
                let known = self.predicates.get_key_value(id.as_str()).map(|(k, _)| *k);
                let Some(key) = known else {
                    self.reader
                        .error(at, PropsErrorKind::UnknownReference { id });
                    return None;
                };
                if matches!(self.predicates.get(key), Some(PredicateState::Converting)) {
                    self.reader.error(at, PropsErrorKind::Cycle { id });
                    return None;
                }
                let (text, ty, compound) = self.predicate(key)?;
                return Some(Term { text, ty, compound });
            }
            "const" => {
                self.reader.check_attrs(element, &["type", "expr"]);
                self.operands(element, "no operands", |n| n == 0)?;
                let ty = self.reader.declared_type(element);
                let (value, _) = self.reader.required(element, "expr")?;
                let value_at = value.location(0);
                let (_, ty) = ty?;
                let raw = value.as_str().trim();
                let valid = match ty {
                    Ty::Bool => matches!(raw, "true" | "false"),
                    Ty::Int => raw.parse::<i64>().is_ok(),
                    Ty::Float => raw.parse::<f64>().is_ok_and(f64::is_finite),
                    Ty::Str => !value.as_str().contains(['\'', '\\']),
                };
                if !valid {
                    self.reader.error(
                        value_at,
                        PropsErrorKind::BadValue {
                            attribute: "expr".to_owned(),
                            value: value.as_str().to_owned(),
                            expected: format!("{} constant", ty.with_article()),
                        },
                    );
                    return None;
                }
                if ty == Ty::Str {
                    text.push_generated(&format!("'{}'", value.as_str()), value_at);
                } else {
                    text.push_generated(raw, value_at);
                }
                return Some(Term {
                    text,
                    ty,
                    compound: false,
                });
            }
            "true" | "false" => {
                self.reader.check_attrs(element, &[]);
                self.operands(element, "no operands", |n| n == 0)?;
                text.push_generated(name, at);
                return Some(Term {
                    text,
                    ty: Ty::Bool,
                    compound: false,
                });
            }
            _ => {}
        }
        self.reader.check_attrs(element, &[]);
        let (operands, symbol, compare) = match name {
            "equal" => (
                self.operands(element, "two operands", |n| n == 2)?,
                " == ",
                true,
            ),
            "less" => (
                self.operands(element, "two operands", |n| n == 2)?,
                " < ",
                true,
            ),
            "leq" => (
                self.operands(element, "two operands", |n| n == 2)?,
                " <= ",
                true,
            ),
            "greater" => (
                self.operands(element, "two operands", |n| n == 2)?,
                " > ",
                true,
            ),
            "geq" => (
                self.operands(element, "two operands", |n| n == 2)?,
                " >= ",
                true,
            ),
            "sum" => (
                self.operands(element, "at least one operand", |n| n >= 1)?,
                " + ",
                false,
            ),
            "mult" => (
                self.operands(element, "at least one operand", |n| n >= 1)?,
                " * ",
                false,
            ),
            "and" => (
                self.operands(element, "at least one operand", |n| n >= 1)?,
                " && ",
                false,
            ),
            "or" => (
                self.operands(element, "at least one operand", |n| n >= 1)?,
                " || ",
                false,
            ),
            "implies" => (
                self.operands(element, "two operands", |n| n == 2)?,
                " || ",
                false,
            ),
            "opposite" | "not" => {
                let operand = self.only_child(element)?;
                let inner = self.term(operand, &element.name)?;
                let (symbol, ok) = if name == "not" {
                    ("!", inner.ty == Ty::Bool)
                } else {
                    ("-", inner.ty.numeric())
                };
                if !ok {
                    self.type_error(element, &[inner.ty]);
                    return None;
                }
                text.push_generated(symbol, at);
                text.push_source(&inner.nested());
                return Some(Term {
                    text,
                    ty: inner.ty,
                    compound: true,
                });
            }
            "historically" | "previously" | "once" | "since" => {
                self.reader.error(
                    at,
                    PropsErrorKind::Type {
                        message: format!(
                            "temporal operator <{name}> inside a predicate or arithmetic \
                             expression"
                        ),
                    },
                );
                return None;
            }
            _ => {
                self.reader.error(
                    at,
                    PropsErrorKind::UnknownElement {
                        name: name.to_owned(),
                        parent: parent.to_owned(),
                        expected: "an operator (not, and, or, implies, historically, \
                                   previously, once, since, equal, less, leq, greater, geq, \
                                   sum, mult, opposite) or <var>, <const>, <true>, <false>",
                    },
                );
                return None;
            }
        };
        let terms: Vec<Option<Term>> = operands
            .iter()
            .map(|child| self.term(child, &element.name))
            .collect();
        let terms: Vec<Term> = terms.into_iter().collect::<Option<_>>()?;
        let types: Vec<Ty> = terms.iter().map(|t| t.ty).collect();
        let ty = match name {
            "equal" if types[0] == types[1] || (types[0].numeric() && types[1].numeric()) => {
                Some(Ty::Bool)
            }
            "less" | "leq" | "greater" | "geq" if types.iter().all(|t| t.numeric()) => {
                Some(Ty::Bool)
            }
            "sum" | "mult" if types.iter().all(|t| t.numeric()) => {
                Some(if types.contains(&Ty::Float) {
                    Ty::Float
                } else {
                    Ty::Int
                })
            }
            "and" | "or" | "implies" if types.iter().all(|&t| t == Ty::Bool) => Some(Ty::Bool),
            _ => None,
        };
        let Some(ty) = ty else {
            self.type_error(element, &types);
            return None;
        };
        if terms.len() == 1 && !compare {
            return terms.into_iter().next();
        }
        for (i, term) in terms.iter().enumerate() {
            if i > 0 {
                text.push_generated(symbol, at);
            }
            if name == "implies" && i == 0 {
                text.push_generated("!", at);
            }
            text.push_source(&term.nested());
        }
        Some(Term {
            text,
            ty,
            compound: true,
        })
    }

    fn type_error(&mut self, element: &Element, types: &[Ty]) {
        let found: Vec<&str> = types.iter().map(|t| t.name()).collect();
        self.reader.error(
            self.reader.at(element.span),
            PropsErrorKind::Type {
                message: format!(
                    "<{}> cannot take operands of type {}",
                    element.name,
                    found.join(", ")
                ),
            },
        );
    }
}

/// Drops one pair of parentheses around the whole text, if there is one.
fn strip_outer(text: SourceText) -> SourceText {
    let s = text.as_str();
    if !(s.starts_with('(') && s.ends_with(')')) {
        return text;
    }
    // The first parenthesis must close at the very end.
    let mut depth = 0usize;
    let mut in_atom = false;
    for (i, c) in s.char_indices() {
        match c {
            '{' => in_atom = true,
            '}' => in_atom = false,
            '(' if !in_atom => depth += 1,
            ')' if !in_atom => {
                depth = depth.saturating_sub(1);
                if depth == 0 && i + 1 != s.len() {
                    return text;
                }
            }
            _ => {}
        }
    }
    text.slice(1, s.len() - 1)
}
