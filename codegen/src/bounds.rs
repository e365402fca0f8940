//! Changing the time bounds of a formula (`P[0:5s]` to `P[0:6s]`): the edit `hindsight
//! sweep` and `hindsight convert` make, done on the parsed tree so that only the bound
//! literals the parser found change, never text inside atoms or strings.

use crate::diag::Sink;
use crate::parse;
use crate::syntax::{Bound, Formula, FormulaKind, InfixOp, PrefixOp, TimeLit};

/// Replaces the text of every bound end in `formula` (each `a` and `b` of `[a:b]`, as
/// written: `62`, `2.5s`) by `f` of it; returns the new text and how many ends were
/// replaced. A formula that does not parse is returned unchanged with 0 replaced (its
/// compilation reports the error with its position).
pub fn map_bounds<E>(
    formula: &str,
    mut f: impl FnMut(&str) -> Result<String, E>,
) -> Result<(String, usize), E> {
    let mut sink = Sink::default();
    let Some(tree) = parse::parse_formula(formula, 0, &mut sink) else {
        return Ok((formula.to_string(), 0));
    };
    let mut ends = Vec::new();
    collect(&tree, &mut ends);
    ends.sort_unstable();
    let mut out = String::with_capacity(formula.len());
    let mut at = 0;
    for &(lo, hi) in &ends {
        let (Some(before), Some(end)) = (formula.get(at..lo), formula.get(lo..hi)) else {
            continue;
        };
        out.push_str(before);
        out.push_str(&f(end)?);
        at = hi;
    }
    out.push_str(formula.get(at..).unwrap_or(""));
    Ok((out, ends.len()))
}

/// The byte ranges of every bound end in `formula`, in any order.
fn collect(formula: &Formula, out: &mut Vec<(usize, usize)>) {
    let mut bound = |b: &Option<Bound>| {
        let ends = b.iter().flat_map(|b| [&b.lo, &b.hi]).flatten();
        out.extend(ends.map(|t: &TimeLit| (t.span.lo as usize, t.span.hi as usize)));
    };
    match &formula.kind {
        FormulaKind::Const(_) | FormulaKind::Atom(_) => {}
        FormulaKind::Prefix(op, sub) => {
            match op {
                PrefixOp::Once(b) | PrefixOp::Historically(b) => bound(b),
                PrefixOp::Not | PrefixOp::Yesterday | PrefixOp::WeakYesterday => {}
            }
            collect(sub, out);
        }
        FormulaKind::Infix(op, l, r) => {
            match op {
                InfixOp::Since(b) => bound(b),
                InfixOp::And | InfixOp::Or | InfixOp::Implies | InfixOp::Iff => {}
            }
            collect(l, out);
            collect(r, out);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn set(formula: &str, to: &str) -> (String, usize) {
        map_bounds(formula, |_| Ok::<_, ()>(to.to_string())).unwrap()
    }

    #[test]
    fn only_bound_ends_change() {
        assert_eq!(set("P[0:5s] {a}", "7"), ("P[7:7] {a}".into(), 2));
        assert_eq!(
            set("H[:10]({x > 2} S[3:] {b})", "9"),
            ("H[:9]({x > 2} S[9:] {b})".into(), 2)
        );
        // Brackets inside atoms and strings are not bounds.
        assert_eq!(
            set("{s == \"[1:2]\"} && O {t}", "9"),
            ("{s == \"[1:2]\"} && O {t}".into(), 0)
        );
        assert_eq!(
            set("once[2.5ms:1min] {a}", "1s"),
            ("once[1s:1s] {a}".into(), 2)
        );
        // Not a formula: unchanged.
        assert_eq!(set("P[0:5 {a}", "7"), ("P[0:5 {a}".into(), 0));
    }

    #[test]
    fn errors_stop_the_edit() {
        let r = map_bounds("P[0:5s] {a}", |b| {
            if b == "5s" {
                Err(b.to_string())
            } else {
                Ok(b.to_string())
            }
        });
        assert_eq!(r, Err("5s".to_string()));
    }
}
