//! codegen's checked AST seen by the oracle: formulas converted to [`F`], atoms evaluated by tree walking.
//!
//! The conformance test compiles each case with `codegen` and must also judge
//! it with the [`crate::oracle`]. [`to_oracle`] turns the checked formula into
//! an oracle tree whose atom `k` is the `k`-th atom occurrence (left to right,
//! no sharing, so nothing depends on codegen's deduplication), and
//! [`eval_atom`] computes an atom's truth value straight from the expression
//! semantics documented in [`codegen::ast`]: integer arithmetic on `i64` with
//! overflow and division by zero as errors, division truncating toward zero,
//! `%` with the dividend's sign, IEEE floats (every comparison with NaN false
//! except `!=`), strings compared by their text, `&&`/`||` evaluating both sides.
//! It shares no code with the monitor-core stack machine.

use std::fmt;

use codegen::ast::{BinaryOp, CheckedSpec, Expr, ExprKind, Formula, FormulaKind, UnaryOp};
use monitor_core::{CmpOp, Value};

use crate::oracle::{Point, F};
use crate::trace::Val;

/// The oracle tree of a checked formula, and the expression of each of its atoms.
pub fn to_oracle(f: &Formula) -> (F, Vec<Expr>) {
    let mut atoms = Vec::new();
    let tree = convert(f, &mut atoms);
    (tree, atoms)
}

fn convert(f: &Formula, atoms: &mut Vec<Expr>) -> F {
    let mut c = |g: &Formula| Box::new(convert(g, atoms));
    match &f.kind {
        FormulaKind::Const(true) => F::True,
        FormulaKind::Const(false) => F::False,
        FormulaKind::Atom(e) => {
            atoms.push(e.clone());
            F::Atom(atoms.len() - 1)
        }
        FormulaKind::Not(a) => F::Not(c(a)),
        FormulaKind::And(a, b) => F::And(c(a), c(b)),
        FormulaKind::Or(a, b) => F::Or(c(a), c(b)),
        FormulaKind::Implies(a, b) => F::Implies(c(a), c(b)),
        FormulaKind::Iff(a, b) => F::Iff(c(a), c(b)),
        FormulaKind::Yesterday(a) => F::Y(c(a)),
        FormulaKind::WeakYesterday(a) => F::Z(c(a)),
        FormulaKind::Once(i, a) => F::Once {
            lo: i.lo,
            hi: i.hi,
            f: c(a),
        },
        FormulaKind::Historically(i, a) => F::Hist {
            lo: i.lo,
            hi: i.hi,
            f: c(a),
        },
        FormulaKind::Since(i, l, r) => {
            let l = c(l);
            F::Since {
                lo: i.lo,
                hi: i.hi,
                l,
                r: c(r),
            }
        }
    }
}

/// Why an atom has no truth value at a point.
#[derive(Clone, Debug, PartialEq)]
pub enum AtomError {
    /// Integer overflow or division by zero: the engines report `StepError::Arithmetic`.
    Arithmetic(String),
    /// The expression or the valuation is not what the checker promises (a test bug).
    Malformed(String),
}

impl fmt::Display for AtomError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            AtomError::Arithmetic(m) => write!(f, "arithmetic error: {m}"),
            AtomError::Malformed(m) => write!(f, "malformed atom: {m}"),
        }
    }
}

impl std::error::Error for AtomError {}

/// A value during evaluation; strings are their text.
#[derive(Clone, Debug, PartialEq)]
enum V {
    B(bool),
    I(i64),
    X(f64),
    S(String),
}

/// The truth value of atom `e` when variable `i` of `spec` has value `vals[i]`.
pub fn eval_atom(e: &Expr, spec: &CheckedSpec, vals: &[Val]) -> Result<bool, AtomError> {
    match eval(e, spec, vals)? {
        V::B(b) => Ok(b),
        v => Err(AtomError::Malformed(format!("atom has value {v:?}"))),
    }
}

fn eval(e: &Expr, spec: &CheckedSpec, vals: &[Val]) -> Result<V, AtomError> {
    let bad = |m: String| Err(AtomError::Malformed(m));
    let overflow = |what: &str| AtomError::Arithmetic(what.to_string());
    Ok(match &e.kind {
        ExprKind::Const(Value::Bool(b)) => V::B(*b),
        ExprKind::Const(Value::Int(n)) => V::I(*n),
        ExprKind::Const(Value::Float(x)) => V::X(*x),
        ExprKind::Const(Value::Str(i)) => match spec.strings.get(*i as usize) {
            Some(s) => V::S(s.clone()),
            None => return bad(format!("string constant {i} is not interned")),
        },
        ExprKind::Var(i) => match vals.get(*i as usize) {
            Some(Val::Bool(b)) => V::B(*b),
            Some(Val::Int(n)) => match i64::try_from(*n) {
                Ok(n) => V::I(n),
                Err(_) => return bad(format!("variable {i} = {n} is beyond i64")),
            },
            Some(Val::Float(x)) => V::X(*x),
            Some(Val::Str(s)) => V::S(s.clone()),
            None => return bad(format!("variable {i} has no value")),
        },
        ExprKind::Unary(op, a) => match (op, eval(a, spec, vals)?) {
            (UnaryOp::Not, V::B(b)) => V::B(!b),
            (UnaryOp::Neg, V::I(n)) => V::I(n.checked_neg().ok_or_else(|| overflow("-i64::MIN"))?),
            (UnaryOp::Neg, V::X(x)) => V::X(-x),
            (op, v) => return bad(format!("{op:?} of {v:?}")),
        },
        ExprKind::ToFloat(a) => match eval(a, spec, vals)? {
            V::I(n) => V::X(n as f64),
            v => return bad(format!("int-to-float of {v:?}")),
        },
        ExprKind::Binary(op, a, b) => {
            // Both sides are always evaluated, so an error on either side is reported.
            let (x, y) = (eval(a, spec, vals)?, eval(b, spec, vals)?);
            match (op, x, y) {
                (BinaryOp::And, V::B(x), V::B(y)) => V::B(x && y),
                (BinaryOp::Or, V::B(x), V::B(y)) => V::B(x || y),
                (BinaryOp::Cmp(c), x, y) => {
                    V::B(compare(*c, &x, &y).ok_or_else(|| {
                        AtomError::Malformed(format!("{x:?} {} {y:?}", op.symbol()))
                    })?)
                }
                (op, V::I(x), V::I(y)) => {
                    let r = match op {
                        BinaryOp::Add => x.checked_add(y),
                        BinaryOp::Sub => x.checked_sub(y),
                        BinaryOp::Mul => x.checked_mul(y),
                        // Rust's integer `/` truncates toward zero and `%` takes
                        // the dividend's sign, as the language defines them.
                        BinaryOp::Div => x.checked_div(y),
                        BinaryOp::Rem => x.checked_rem(y),
                        _ => return bad(format!("{x} {} {y}", op.symbol())),
                    };
                    V::I(r.ok_or_else(|| overflow(&format!("{x} {} {y}", op.symbol())))?)
                }
                (op, V::X(x), V::X(y)) => V::X(match op {
                    BinaryOp::Add => x + y,
                    BinaryOp::Sub => x - y,
                    BinaryOp::Mul => x * y,
                    BinaryOp::Div => x / y,
                    BinaryOp::Rem => x % y,
                    _ => return bad(format!("{x} {} {y}", op.symbol())),
                }),
                (op, x, y) => return bad(format!("{x:?} {} {y:?}", op.symbol())),
            }
        }
    })
}

/// `x op y`, or `None` when the operands cannot be compared by `op`.
fn compare(op: CmpOp, x: &V, y: &V) -> Option<bool> {
    use std::cmp::Ordering::{Equal, Greater, Less};
    let ord = match (x, y) {
        (V::I(x), V::I(y)) => Some(x.cmp(y)),
        // NaN is unordered: every comparison is false except `!=`.
        (V::X(x), V::X(y)) => x.partial_cmp(y),
        (V::B(x), V::B(y)) if matches!(op, CmpOp::Eq | CmpOp::Ne) => Some(x.cmp(y)),
        (V::S(x), V::S(y)) if matches!(op, CmpOp::Eq | CmpOp::Ne) => Some(x.cmp(y)),
        _ => return None,
    };
    Some(match op {
        CmpOp::Eq => ord == Some(Equal),
        CmpOp::Ne => ord != Some(Equal),
        CmpOp::Lt => ord == Some(Less),
        CmpOp::Le => matches!(ord, Some(Less | Equal)),
        CmpOp::Gt => ord == Some(Greater),
        CmpOp::Ge => matches!(ord, Some(Greater | Equal)),
    })
}

/// The oracle's trace: at each point, every atom of `atoms` evaluated over
/// that point's valuation (`vals[i]` in `spec.vars` order). An atom error is
/// returned with the index of its point.
pub fn oracle_points(
    spec: &CheckedSpec,
    atoms: &[Expr],
    times: &[u64],
    vals: &[Vec<Val>],
) -> Result<Vec<Point>, (usize, AtomError)> {
    times
        .iter()
        .zip(vals)
        .enumerate()
        .map(|(i, (&time, v))| {
            let atoms = atoms
                .iter()
                .map(|a| eval_atom(a, spec, v))
                .collect::<Result<Vec<bool>, _>>()
                .map_err(|e| (i, e))?;
            Ok(Point { time, atoms })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spec(src: &str) -> codegen::Compiled {
        codegen::compile_spec(src, "t.hspec").unwrap_or_else(|d| panic!("{d}"))
    }

    fn atom(c: &codegen::Compiled) -> Vec<Expr> {
        to_oracle(&c.checked().properties[0].formula).1
    }

    #[test]
    fn formulas_convert_with_one_atom_per_occurrence() {
        let c = spec("event p; event q; property x = ({p} S[2:5] Y {q}) && H[3:] {p} || Z O {p};");
        let (f, atoms) = to_oracle(&c.checked().properties[0].formula);
        assert_eq!(
            crate::oracle::print(&f),
            "((({a0} S[2:5] (Y {a1})) && (H[3:] {a2})) || (Z (P {a3})))"
        );
        assert_eq!(atoms.len(), 4);
    }

    #[test]
    fn integer_semantics_truncate_and_report_overflow() {
        let c =
            spec("state x: int = 0; state y: int = 0; property d = {x / y == -1 && x % y == -1};");
        let a = &atom(&c)[0];
        let ev = |x: i128, y: i128| eval_atom(a, c.checked(), &[Val::Int(x), Val::Int(y)]);
        assert_eq!(ev(-3, 2), Ok(true));
        assert_eq!(ev(3, 2), Ok(false));
        assert!(matches!(ev(1, 0), Err(AtomError::Arithmetic(_))));
        let min = i64::MIN as i128;
        assert!(matches!(ev(min, -1), Err(AtomError::Arithmetic(_))));
    }

    #[test]
    fn floats_nan_and_mixed_ints() {
        let c = spec("state f: float = 0.0; state n: int = 0; property p = {f != f || n + 1 > f};");
        let a = &atom(&c)[0];
        let ev = |f: f64, n: i128| eval_atom(a, c.checked(), &[Val::Float(f), Val::Int(n)]);
        assert_eq!(ev(f64::NAN, 0), Ok(true));
        assert_eq!(ev(1.5, 0), Ok(false));
        assert_eq!(ev(1.5, 1), Ok(true));
    }

    #[test]
    fn strings_compare_by_text() {
        let c = spec("state m: string = \"idle\"; state k: string = \"\"; property p = {m == \"go\" || m == k};");
        let a = &atom(&c)[0];
        let ev =
            |m: &str, k: &str| eval_atom(a, c.checked(), &[Val::Str(m.into()), Val::Str(k.into())]);
        assert_eq!(ev("go", "x"), Ok(true));
        assert_eq!(ev("other", "other"), Ok(true));
        assert_eq!(ev("other", "else"), Ok(false));
    }
}
