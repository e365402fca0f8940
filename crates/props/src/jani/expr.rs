//! JANI state expressions (`∧ ∨ ¬ ⇒`, comparisons, arithmetic, `abs`, array values)
//! rendered as Rye atom text that keeps the position of every node.

use super::super::error::PropsErrorKind;
use super::super::source::SourceText;
use super::Reader;
use crate::expr::value::Ty;
use crate::model::json::{Json, Node};

/// A rendered state expression: its text (with locations) and its type.
pub(super) struct Rendered {
    pub(super) text: SourceText,
    pub(super) ty: Ty,
    /// An `abs(e)` whose operand this is: only a comparison may use it.
    pub(super) abs: Option<SourceText>,
    /// An array value's elements (only a string comparison may use it).
    pub(super) codes: Option<Vec<i64>>,
}

impl Reader<'_, '_> {
    fn leaf(&self, text: &str, ty: Ty, offset: usize) -> Rendered {
        Rendered {
            text: SourceText::generated(text, self.at(offset)),
            ty,
            abs: None,
            codes: None,
        }
    }

    fn operand<'n>(&mut self, node: &'n Node, key: &str) -> Option<&'n Node> {
        let op = node.get("op").and_then(Node::as_str).unwrap_or("");
        let found = node.get(key);
        if found.is_none() {
            self.jani(node.offset, format!("`{op}` needs `{key}`"));
        }
        found
    }

    pub(super) fn expr(&mut self, node: &Node) -> Option<Rendered> {
        let at = self.at(node.offset);
        match &node.value {
            Json::Bool(b) => {
                Some(self.leaf(if *b { "true" } else { "false" }, Ty::Bool, node.offset))
            }
            Json::Number(n) => {
                let ty = if n.contains(['.', 'e', 'E']) {
                    Ty::Float
                } else {
                    Ty::Int
                };
                Some(self.leaf(n, ty, node.offset))
            }
            Json::Str(name) => {
                let (id, ty) = self.port(name, node.offset)?;
                Some(self.leaf(&id, ty, node.offset))
            }
            Json::Object(_) => {
                let op = self.op_of(node)?;
                match op.as_str() {
                    "∧" | "∨" | "⇒" => {
                        let l = self.operand(node, "left");
                        let r = self.operand(node, "right");
                        let (l, r) = (l?, r?);
                        let (lr, rr) = (self.expr(l), self.expr(r));
                        let (lr, rr) = (lr?, rr?);
                        if lr.ty != Ty::Bool || rr.ty != Ty::Bool {
                            self.error(
                                node.offset,
                                PropsErrorKind::Type {
                                    message: format!("`{op}` takes booleans"),
                                },
                            );
                            return None;
                        }
                        let (lt, rt) = (self.plain(l, lr)?, self.plain(r, rr)?);
                        let mut out = SourceText::empty();
                        out.push_generated(if op == "⇒" { "(!(" } else { "((" }, at);
                        out.push_source(&lt);
                        out.push_generated(
                            match op.as_str() {
                                "∧" => ") && (",
                                _ => ") || (",
                            },
                            at,
                        );
                        out.push_source(&rt);
                        out.push_generated("))", at);
                        Some(Rendered {
                            text: out,
                            ty: Ty::Bool,
                            abs: None,
                            codes: None,
                        })
                    }
                    "¬" => {
                        let e = self.operand(node, "exp")?;
                        let out = self.wrapped_boolean(
                            e,
                            node.offset,
                            "`¬` takes a boolean",
                            ["!(", ")"],
                        )?;
                        Some(Rendered {
                            text: out,
                            ty: Ty::Bool,
                            abs: None,
                            codes: None,
                        })
                    }
                    "=" | "≠" | "<" | "≤" | ">" | "≥" => self.comparison(node, &op),
                    "+" | "-" | "*" | "/" | "%" => {
                        let l = self.operand(node, "left");
                        let r = self.operand(node, "right");
                        let (l, r) = (l?, r?);
                        let (lr, rr) = (self.expr(l), self.expr(r));
                        let (lr, rr) = (lr?, rr?);
                        let numeric = |t: &Ty| matches!(t, Ty::Int | Ty::Float);
                        if !numeric(&lr.ty) || !numeric(&rr.ty) {
                            self.error(
                                node.offset,
                                PropsErrorKind::Type {
                                    message: format!("`{op}` takes numbers"),
                                },
                            );
                            return None;
                        }
                        let ty = if op == "/" || lr.ty == Ty::Float || rr.ty == Ty::Float {
                            Ty::Float
                        } else {
                            Ty::Int
                        };
                        let (lt, rt) = (self.plain(l, lr)?, self.plain(r, rr)?);
                        let mut out = SourceText::empty();
                        out.push_generated("(", at);
                        out.push_source(&lt);
                        out.push_generated(&format!(" {op} "), at);
                        out.push_source(&rt);
                        out.push_generated(")", at);
                        Some(Rendered {
                            text: out,
                            ty,
                            abs: None,
                            codes: None,
                        })
                    }
                    "abs" => {
                        let e = self.operand(node, "exp")?;
                        let r = self.expr(e)?;
                        if !matches!(r.ty, Ty::Int | Ty::Float) {
                            self.error(
                                node.offset,
                                PropsErrorKind::Type {
                                    message: "`abs` takes a number".into(),
                                },
                            );
                            return None;
                        }
                        let ty = r.ty.clone();
                        let t = self.plain(e, r)?;
                        let mut neg = SourceText::empty();
                        neg.push_generated("(-(", at);
                        neg.push_source(&t);
                        neg.push_generated("))", at);
                        Some(Rendered {
                            text: t,
                            ty,
                            abs: Some(neg),
                            codes: None,
                        })
                    }
                    "av" => {
                        let Some(Json::Array(items)) = node.get("elements").map(|n| &n.value)
                        else {
                            self.jani(node.offset, "`av` needs an `elements` array");
                            return None;
                        };
                        let mut codes = Vec::new();
                        for it in items {
                            match &it.value {
                                Json::Number(n) => {
                                    match n.parse::<i64>() {
                                        Ok(c) => codes.push(c),
                                        Err(_) => {
                                            self.jani(it.offset, "array values are supported only as character codes");
                                            return None;
                                        }
                                    }
                                }
                                _ => {
                                    self.jani(
                                        it.offset,
                                        "array values are supported only as character codes",
                                    );
                                    return None;
                                }
                            }
                        }
                        Some(Rendered {
                            text: SourceText::empty(),
                            ty: Ty::Str,
                            abs: None,
                            codes: Some(codes),
                        })
                    }
                    "aa" => {
                        let mut path = Vec::new();
                        let mut cur = node;
                        while cur.get("op").and_then(Node::as_str) == Some("aa") {
                            let index = match cur.get("index").map(|n| &n.value) {
                                Some(Json::Number(n)) => n.parse::<u32>().ok(),
                                _ => None,
                            };
                            let Some(index) = index else {
                                self.jani(cur.offset, "`aa` is supported only with a constant non-negative integer `index`");
                                return None;
                            };
                            path.push(index);
                            let Some(exp) = cur.get("exp") else {
                                self.jani(cur.offset, "`aa` needs `exp`");
                                return None;
                            };
                            cur = exp;
                        }
                        path.reverse();
                        let Some(base) = cur.as_str() else {
                            self.jani(cur.offset, "`aa` is supported only on an event parameter");
                            return None;
                        };
                        let (id, ty) = self.part_port(base, path, false, cur.offset)?;
                        Some(self.leaf(&id, ty, node.offset))
                    }
                    "" => {
                        self.jani(node.offset, "an expression object needs `op`");
                        None
                    }
                    _ => {
                        self.jani(node.offset, format!("operator `{op}` is not supported"));
                        None
                    }
                }
            }
            _ => {
                self.jani(
                    node.offset,
                    "expected a variable, a constant or an operator object",
                );
                None
            }
        }
    }

    fn comparison(&mut self, node: &Node, op: &str) -> Option<Rendered> {
        let at = self.at(node.offset);
        let l = self.operand(node, "left");
        let r = self.operand(node, "right");
        let (l, r) = (l?, r?);
        let (lr, rr) = (self.expr(l), self.expr(r));
        let (mut lr, mut rr) = (lr?, rr?);
        let sym = match op {
            "=" => "==",
            "≠" => "!=",
            "≤" => "<=",
            "≥" => ">=",
            other => other,
        };
        // A string compared with an array of character codes.
        for left in [true, false] {
            let (a, b_ty) = if left {
                (&mut lr, rr.ty.clone())
            } else {
                (&mut rr, lr.ty.clone())
            };
            if let (Some(codes), Ty::Str) = (&a.codes, b_ty) {
                let s: Option<String> = codes
                    .iter()
                    .map(|&c| u32::try_from(c).ok().and_then(char::from_u32))
                    .collect();
                let Some(s) = s else {
                    self.jani(
                        node.offset,
                        "the array value is not a string's character codes",
                    );
                    return None;
                };
                let quoted = format!("\"{}\"", s.replace('\\', "\\\\").replace('"', "\\\""));
                a.text = SourceText::generated(quoted, at);
                a.codes = None;
            }
        }
        let numeric = |t: &Ty| matches!(t, Ty::Int | Ty::Float);
        let fits =
            (numeric(&lr.ty) && numeric(&rr.ty)) || (lr.ty == rr.ty && matches!(op, "=" | "≠"));
        if !fits || lr.codes.is_some() || rr.codes.is_some() {
            self.error(
                node.offset,
                PropsErrorKind::Type {
                    message: format!("`{op}` cannot compare these operands"),
                },
            );
            return None;
        }
        if lr.abs.is_some() && rr.abs.is_some() {
            self.jani(
                node.offset,
                "`abs` on both sides of a comparison is not supported",
            );
            return None;
        }
        // abs(e) op c: both signs of e compared, joined by && for < and <=, || otherwise.
        let (abs_side_left, abs) = match (lr.abs.take(), rr.abs.take()) {
            (Some(n), None) => (true, Some(n)),
            (None, Some(n)) => (false, Some(n)),
            _ => (true, None),
        };
        let cmp = |l: &SourceText, r: &SourceText| {
            let mut out = SourceText::empty();
            out.push_generated("(", at);
            out.push_source(l);
            out.push_generated(&format!(" {sym} "), at);
            out.push_source(r);
            out.push_generated(")", at);
            out
        };
        let text = match abs {
            None => cmp(&lr.text, &rr.text),
            Some(neg) => {
                let (first, second) = if abs_side_left {
                    (cmp(&lr.text, &rr.text), cmp(&neg, &rr.text))
                } else {
                    (cmp(&lr.text, &rr.text), cmp(&lr.text, &neg))
                };
                // |e| < c  <=>  e < c && -e < c (on the abs side); |e| > c  <=>  e > c || -e > c.
                let small = if abs_side_left {
                    matches!(op, "<" | "≤")
                } else {
                    matches!(op, ">" | "≥")
                };
                let join = match op {
                    "=" => " || ",
                    "≠" => " && ",
                    _ if small => " && ",
                    _ => " || ",
                };
                let mut out = SourceText::empty();
                out.push_generated("(", at);
                out.push_source(&first);
                out.push_generated(join, at);
                out.push_source(&second);
                out.push_generated(")", at);
                out
            }
        };
        Some(Rendered {
            text,
            ty: Ty::Bool,
            abs: None,
            codes: None,
        })
    }
}
