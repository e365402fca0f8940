//! Atom expressions rebuilt from the stack bytecode as Rust (or as formula text for
//! docs), with the fewest parentheses the binding strengths allow.

use monitor_core::{CmpOp, Instr, NumTy, Op, Program, Ty, Value};

use super::names::Names;
use super::out::doc_text;

/// What a stack value is, for naming string constants after their variable.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Kind {
    Other,
    StrVar(u16),
    StrConst(u32),
}

/// Rust code (checked, non-short-circuit) or the specification-like text for docs.
#[derive(Clone, Copy, PartialEq, Eq)]
pub(super) enum Mode {
    Rust,
    Doc,
}

// Binding strength of an expression's outermost operator (Rust's precedence order).
pub(super) const P_ATOM: u8 = 100;
pub(super) const P_UNARY: u8 = 90;
pub(super) const P_CAST: u8 = 85;
pub(super) const P_MUL: u8 = 80;
pub(super) const P_ADD: u8 = 70;
pub(super) const P_BITAND: u8 = 50;
pub(super) const P_BITOR: u8 = 40;
pub(super) const P_CMP: u8 = 30;
pub(super) const P_LAND: u8 = 20;
pub(super) const P_LOR: u8 = 10;

pub(super) struct Ex {
    pub(super) text: String,
    pub(super) prec: u8,
    pub(super) kind: Kind,
}

impl Ex {
    pub(super) fn new(text: String, prec: u8) -> Self {
        Ex {
            text,
            prec,
            kind: Kind::Other,
        }
    }

    /// The text, parenthesised when `paren`.
    pub(super) fn wrapped(&self, paren: bool) -> String {
        if paren {
            format!("({})", self.text)
        } else {
            self.text.clone()
        }
    }
}

pub(super) struct Rendered {
    pub(super) text: String,
    pub(super) fallible: bool,
}

pub(super) struct RenderedAtom {
    /// Rust expression; contains `?` when `fallible`.
    pub(super) rust: String,
    /// Uses checked integer arithmetic, so it is computed by a function returning `Option`.
    pub(super) fallible: bool,
    /// Specification-like text for docs.
    pub(super) doc: String,
    /// Reads a variable.
    pub(super) loads: bool,
}

pub(super) fn float_text(x: f64, mode: Mode) -> (String, u8) {
    let rust = mode == Mode::Rust;
    if x.is_nan() {
        (if rust { "f64::NAN" } else { "NaN" }.into(), P_ATOM)
    } else if x == f64::INFINITY {
        (if rust { "f64::INFINITY" } else { "inf" }.into(), P_ATOM)
    } else if x == f64::NEG_INFINITY {
        let t = if rust { "f64::NEG_INFINITY" } else { "-inf" };
        (t.into(), if rust { P_ATOM } else { P_UNARY })
    } else {
        // `{:?}` is the shortest text that reads back as the same bits (sign of zero included).
        let t = format!("{x:?}{}", if rust { "f64" } else { "" });
        let prec = if t.starts_with('-') { P_UNARY } else { P_ATOM };
        (t, prec)
    }
}

pub(super) fn cmp_symbol(op: CmpOp) -> &'static str {
    match op {
        CmpOp::Eq => "==",
        CmpOp::Ne => "!=",
        CmpOp::Lt => "<",
        CmpOp::Le => "<=",
        CmpOp::Gt => ">",
        CmpOp::Ge => ">=",
    }
}

/// Rebuilds one atom as an expression tree; `None` when the code does not check.
pub(super) fn render(
    code: &[Instr],
    p: &Program<'_>,
    names: &Names,
    mode: Mode,
) -> Option<Rendered> {
    let rust = mode == Mode::Rust;
    let mut stack: Vec<Ex> = Vec::new();
    let mut fallible = false;
    for ins in code {
        let ex = match *ins {
            Instr::Push(Value::Bool(b)) => Ex::new(b.to_string(), P_ATOM),
            Instr::Push(Value::Int(v)) => {
                if v == i64::MIN && rust {
                    Ex::new("i64::MIN".into(), P_ATOM)
                } else {
                    let t = format!("{v}{}", if rust { "i64" } else { "" });
                    Ex::new(t, if v < 0 { P_UNARY } else { P_ATOM })
                }
            }
            Instr::Push(Value::Float(x)) => {
                let (t, prec) = float_text(x, mode);
                Ex::new(t, prec)
            }
            Instr::Push(Value::Str(k)) => {
                let t = match (names.strs.get(k as usize), p.strings.get(k as usize)) {
                    (Some(c), Some(s)) => {
                        if rust {
                            c.clone()
                        } else {
                            format!("{s:?}")
                        }
                    }
                    _ if rust => format!("{k}u32"),
                    _ => format!("string#{k}"),
                };
                Ex {
                    text: t,
                    prec: P_ATOM,
                    kind: Kind::StrConst(k),
                }
            }
            Instr::Load(n) => {
                let var = p.vars.get(n as usize)?;
                let text = if rust {
                    format!("input.{}", names.fields.get(n as usize)?)
                } else {
                    var.name.to_string()
                };
                let kind = if var.ty == Ty::Str {
                    Kind::StrVar(n)
                } else {
                    Kind::Other
                };
                Ex {
                    text,
                    prec: P_ATOM,
                    kind,
                }
            }
            Instr::Not => {
                let a = stack.pop()?;
                Ex::new(format!("!{}", a.wrapped(a.prec < P_UNARY)), P_UNARY)
            }
            Instr::Neg(NumTy::Int) if rust => {
                let a = stack.pop()?;
                fallible = true;
                let t = format!("{}.checked_neg()?", a.wrapped(a.prec < P_ATOM));
                Ex::new(t, P_ATOM)
            }
            Instr::Neg(_) => {
                let a = stack.pop()?;
                // `--x` would read as a double negation: wrap every unary operand.
                Ex::new(format!("-{}", a.wrapped(a.prec <= P_UNARY)), P_UNARY)
            }
            Instr::ToFloat if rust => {
                let a = stack.pop()?;
                Ex::new(format!("{} as f64", a.wrapped(a.prec < P_CAST)), P_CAST)
            }
            Instr::ToFloat => {
                let a = stack.pop()?;
                Ex::new(format!("float({})", a.text), P_ATOM)
            }
            Instr::And | Instr::Or => {
                let b = stack.pop()?;
                let a = stack.pop()?;
                let and = matches!(ins, Instr::And);
                let (sym, prec) = match (rust, and) {
                    (true, true) => ("&", P_BITAND),
                    (true, false) => ("|", P_BITOR),
                    (false, true) => ("&&", P_LAND),
                    (false, false) => ("||", P_LOR),
                };
                let t = format!(
                    "{} {sym} {}",
                    a.wrapped(a.prec < prec),
                    b.wrapped(b.prec <= prec)
                );
                Ex::new(t, prec)
            }
            Instr::Add(n) | Instr::Sub(n) | Instr::Mul(n) | Instr::Div(n) | Instr::Rem(n) => {
                let b = stack.pop()?;
                let a = stack.pop()?;
                let (sym, method, prec) = match ins {
                    Instr::Add(_) => ("+", "checked_add", P_ADD),
                    Instr::Sub(_) => ("-", "checked_sub", P_ADD),
                    Instr::Mul(_) => ("*", "checked_mul", P_MUL),
                    Instr::Div(_) => ("/", "checked_div", P_MUL),
                    _ => ("%", "checked_rem", P_MUL),
                };
                if rust && n == NumTy::Int {
                    fallible = true;
                    let t = format!("{}.{method}({})?", a.wrapped(a.prec < P_ATOM), b.text);
                    Ex::new(t, P_ATOM)
                } else {
                    // A cast on the right could end up before a `<` (`a - x as f64 < b`
                    // reads `f64<` as generics): wrap it; on the left an operator follows.
                    let t = format!(
                        "{} {sym} {}",
                        a.wrapped(a.prec < prec),
                        b.wrapped(b.prec <= prec || b.prec == P_CAST)
                    );
                    Ex::new(t, prec)
                }
            }
            Instr::Cmp(op, _) => {
                let mut b = stack.pop()?;
                let mut a = stack.pop()?;
                if rust {
                    let (ka, kb) = (a.kind, b.kind);
                    for (x, y) in [(&mut a, kb), (&mut b, ka)] {
                        if let (Kind::StrConst(k), Kind::StrVar(v)) = (x.kind, y) {
                            if let Some(alias) = names.aliases.get(&(v, k)) {
                                x.text = alias.clone();
                            }
                        }
                    }
                }
                // `x as f64 < y` would parse `<` as generics: casts are wrapped too.
                let paren = |e: &Ex| e.prec < P_ADD || e.prec == P_CAST;
                let t = format!(
                    "{} {} {}",
                    a.wrapped(paren(&a)),
                    cmp_symbol(op),
                    b.wrapped(paren(&b))
                );
                Ex::new(t, P_CMP)
            }
        };
        stack.push(ex);
    }
    let top = stack.pop()?;
    if !stack.is_empty() {
        return None;
    }
    Some(Rendered {
        text: top.text,
        fallible,
    })
}

/// The formula text of each node for docs, children by node number when long.
pub(super) fn node_texts(p: &Program<'_>, atoms: &[RenderedAtom]) -> Vec<String> {
    const LONG: usize = 100;
    let mut texts: Vec<(String, u8)> = Vec::with_capacity(p.nodes.len());
    let child = |texts: &[(String, u8)], c: u16, min: u8| -> String {
        match texts.get(c as usize) {
            Some((t, _)) if t.len() > LONG => format!("n{c}"),
            Some((t, prec)) if *prec < min => format!("({t})"),
            Some((t, _)) => t.clone(),
            None => format!("n{c}"),
        }
    };
    for n in p.nodes {
        let item = match n.op {
            Op::Const(b) => (b.to_string(), P_ATOM),
            Op::Atom(a) => match atoms.get(a as usize) {
                Some(r) => (format!("{{{}}}", r.doc), P_ATOM),
                None => (format!("atom{a}"), P_ATOM),
            },
            Op::Not(a) => (format!("!{}", child(&texts, a, P_UNARY)), P_UNARY),
            Op::Yesterday(a) => (format!("Y {}", child(&texts, a, P_UNARY)), P_UNARY),
            Op::WeakYesterday(a) => (format!("Z {}", child(&texts, a, P_UNARY)), P_UNARY),
            Op::And(a, b) | Op::Or(a, b) | Op::Implies(a, b) | Op::Iff(a, b) => {
                let (sym, prec) = match n.op {
                    Op::And(..) => ("&&", 50),
                    Op::Or(..) => ("||", 40),
                    Op::Implies(..) => ("->", 30),
                    _ => ("<->", 20),
                };
                let t = format!(
                    "{} {sym} {}",
                    child(&texts, a, prec + 1),
                    child(&texts, b, prec + 1)
                );
                (t, prec)
            }
            Op::Since { lhs, rhs, lo, hi } => {
                let bound = match (lo, hi) {
                    (0, None) => String::new(),
                    (lo, None) => format!("[{lo}:]"),
                    (lo, Some(hi)) => format!("[{lo}:{hi}]"),
                };
                let t = format!(
                    "{} S{bound} {}",
                    child(&texts, lhs, 61),
                    child(&texts, rhs, 61)
                );
                (t, 60)
            }
        };
        texts.push(item);
    }
    texts.into_iter().map(|(t, _)| doc_text(&t)).collect()
}

pub(super) fn value_doc(p: &Program<'_>, v: Value) -> String {
    match v {
        Value::Bool(b) => b.to_string(),
        Value::Int(i) => i.to_string(),
        Value::Float(x) => float_text(x, Mode::Doc).0,
        Value::Str(k) => match p.strings.get(k as usize) {
            Some(s) => format!("{s:?}"),
            None => format!("string#{k}"),
        },
    }
}
