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

/// The windows of `formula` whose two ends are both written and neither is zero, as
/// written (`[1s:3s]`): an edit that gives every nonzero end one value (a sweep) makes
/// each of them `[X:X]`. Empty for a formula that does not parse.
pub fn two_sided_windows(formula: &str) -> Vec<String> {
    let mut sink = Sink::default();
    let Some(tree) = parse::parse_formula(formula, 0, &mut sink) else {
        return Vec::new();
    };
    let text = |t: &TimeLit| formula.get(t.span.lo as usize..t.span.hi as usize);
    let zero = |t: &TimeLit| text(t).is_some_and(is_zero_end);
    let mut out = Vec::new();
    each_bound(&tree, &mut |b| {
        if let (Some(lo), Some(hi)) = (&b.lo, &b.hi) {
            if !zero(lo) && !zero(hi) {
                let text = formula.get(b.span.lo as usize..b.span.hi as usize);
                out.push(text.unwrap_or_default().to_string());
            }
        }
    });
    out
}

/// The bound ends of `formula` written without a unit and not zero (`8` in `P[8:]`), with
/// their byte offsets, in text order: on a model whose step no one wrote down (a robot
/// model's), each counts steps of a length the timers set. Empty for a formula that does
/// not parse.
pub fn unitless_ends(formula: &str) -> Vec<(usize, String)> {
    let mut sink = Sink::default();
    let Some(tree) = parse::parse_formula(formula, 0, &mut sink) else {
        return Vec::new();
    };
    let mut out = Vec::new();
    each_bound(&tree, &mut |b| {
        for t in [&b.lo, &b.hi].into_iter().flatten() {
            let (lo, hi) = (t.span.lo as usize, t.span.hi as usize);
            match formula.get(lo..hi) {
                Some(text) if t.unit.is_none() && !is_zero_end(text) => {
                    out.push((lo, text.to_string()))
                }
                _ => {}
            }
        }
    });
    out.sort_unstable();
    out
}

/// Whether a bound end as written (`0`, `0s`, `0.0ms`, `62`) is zero: the start of a
/// window that starts now, not a bound a sweep moves.
pub fn is_zero_end(end: &str) -> bool {
    matches!(
        crate::duration::parse_steps_or_duration(end),
        Ok(crate::duration::StepsOrDuration::Steps(0) | crate::duration::StepsOrDuration::Nanos(0))
    )
}

/// The byte ranges of every bound end in `formula`, in any order.
fn collect(formula: &Formula, out: &mut Vec<(usize, usize)>) {
    each_bound(formula, &mut |b| {
        let ends = [&b.lo, &b.hi].into_iter().flatten();
        out.extend(ends.map(|t: &TimeLit| (t.span.lo as usize, t.span.hi as usize)));
    });
}

/// Calls `f` on every written bound of `formula`'s temporal operators.
fn each_bound(formula: &Formula, f: &mut impl FnMut(&Bound)) {
    match &formula.kind {
        FormulaKind::Const(_) | FormulaKind::Atom(_) => {}
        FormulaKind::Prefix(op, sub) => {
            match op {
                PrefixOp::Once(Some(b)) | PrefixOp::Historically(Some(b)) => f(b),
                PrefixOp::Once(None)
                | PrefixOp::Historically(None)
                | PrefixOp::Not
                | PrefixOp::Yesterday
                | PrefixOp::WeakYesterday => {}
            }
            each_bound(sub, f);
        }
        FormulaKind::Infix(op, l, r) => {
            match op {
                InfixOp::Since(Some(b)) => f(b),
                InfixOp::Since(None)
                | InfixOp::And
                | InfixOp::Or
                | InfixOp::Implies
                | InfixOp::Iff => {}
            }
            each_bound(l, f);
            each_bound(r, f);
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
    fn two_sided_windows_are_those_with_two_nonzero_ends() {
        assert_eq!(two_sided_windows("P[1s:3s] {a} && H[0:2] {b}"), ["[1s:3s]"]);
        assert!(two_sided_windows("P[0:5s] {a} && {b} S[6.2s:] {c} && H[:3] {d}").is_empty());
        assert!(two_sided_windows("P[0.0s:5s] {a}").is_empty());
        assert!(two_sided_windows("P[1:2 {a}").is_empty());
    }

    #[test]
    fn unitless_ends_are_the_bare_nonzero_ones_in_text_order() {
        let f = "H[0:2] {x > 1} && {b} S[62:] {c} && P[1s:5] {d} && P {e}";
        let got = unitless_ends(f);
        let at = |n: &str| f.find(n).unwrap();
        assert_eq!(
            got,
            [
                (at("2]"), "2".to_string()),
                (at("62"), "62".to_string()),
                (at("5]"), "5".to_string()),
            ]
        );
        assert!(unitless_ends("P[0:0.0ms] {a}").is_empty());
        assert!(unitless_ends("P[1:2 {a}").is_empty());
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
