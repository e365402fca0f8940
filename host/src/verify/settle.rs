//! Deciding soundly, at a point, that a property's verdict can no longer change.
//!
//! A run may stop early only when every verdict is final. The rules, applied
//! bottom-up over the network with the current node values:
//! - a constant is final;
//! - `!`, `&&`, `||`, `->`, `<->` are final when their operands decide them
//!   (`false && _` is final as soon as one side is final `false`);
//! - `Y a` / `Z a` is final `v` when `a` is final `v` and the node is `v` now;
//! - `f S[a:] g` with no upper bound is final `true` once it is true while `f`
//!   is final `true`: its witness never expires and never resets;
//! - `f S g` (no bounds at all) is final `false` once it is false while `g` is
//!   final `false`: nothing can start a witness again.
//!
//! Anything else (atoms, bounded windows such as `H[0:5] P {tick}`) is never
//! final, so an early verdict is only ever one the rest of the run could not change.

use monitor_core::{Monitor, Op};

/// Per-node finality over one program, with a reusable scratch buffer.
#[derive(Clone, Debug)]
pub struct Settler {
    scratch: Vec<Option<bool>>,
}

impl Settler {
    /// A settler for `monitor`'s program.
    pub fn new(monitor: &Monitor<'_>) -> Self {
        Settler {
            scratch: vec![None; monitor.program().nodes.len()],
        }
    }

    /// Computes, for the state after the last point, every node's final value
    /// (`None`: may still change). Call [`Settler::property`] afterwards.
    pub fn update(&mut self, monitor: &Monitor<'_>, state: &[u64]) {
        let nodes = monitor.program().nodes;
        for (i, node) in nodes.iter().enumerate() {
            let s = &self.scratch;
            let now = monitor.node_value(state, i as u16).unwrap_or(false);
            let get = |n: u16| s.get(n as usize).copied().flatten();
            let v = match node.op {
                Op::Const(c) => Some(c),
                Op::Atom(_) => None,
                Op::Not(a) => get(a).map(|a| !a),
                Op::And(a, b) => match (get(a), get(b)) {
                    (Some(false), _) | (_, Some(false)) => Some(false),
                    (Some(true), Some(true)) => Some(true),
                    _ => None,
                },
                Op::Or(a, b) => match (get(a), get(b)) {
                    (Some(true), _) | (_, Some(true)) => Some(true),
                    (Some(false), Some(false)) => Some(false),
                    _ => None,
                },
                Op::Implies(a, b) => match (get(a), get(b)) {
                    (Some(false), _) | (_, Some(true)) => Some(true),
                    (Some(true), Some(false)) => Some(false),
                    _ => None,
                },
                Op::Iff(a, b) => match (get(a), get(b)) {
                    (Some(x), Some(y)) => Some(x == y),
                    _ => None,
                },
                Op::Yesterday(a) | Op::WeakYesterday(a) => match get(a) {
                    Some(v) if v == now => Some(v),
                    _ => None,
                },
                Op::Since { lhs, rhs, lo, hi } => {
                    if hi.is_none() && now && get(lhs) == Some(true) {
                        Some(true)
                    } else if lo == 0 && hi.is_none() && !now && get(rhs) == Some(false) {
                        Some(false)
                    } else {
                        None
                    }
                }
            };
            self.scratch[i] = v;
        }
    }

    /// The final verdict of property `prop` as of the last [`Settler::update`], if final.
    pub fn property(&self, monitor: &Monitor<'_>, prop: usize) -> Option<bool> {
        let root = monitor.program().props.get(prop)?.root;
        self.scratch.get(root as usize).copied().flatten()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use monitor_core::{valuation, Value};

    /// Runs `formula` over points `(time, p)` and returns, per point, (verdict, final?).
    fn run(formula: &str, points: &[(u64, bool)]) -> Vec<(bool, Option<bool>)> {
        let src = format!("event p;\nproperty f = {formula};\n");
        let c = codegen::compile_spec(&src, "t.hspec").unwrap();
        let m = Monitor::try_new(c.program()).unwrap();
        let mut st = vec![0; m.state_words()];
        let mut vals = vec![Value::Bool(false)];
        valuation::init(c.program().vars, &mut vals);
        let mut s = Settler::new(&m);
        let mut out = [false];
        points
            .iter()
            .map(|&(t, p)| {
                vals[0] = Value::Bool(p);
                m.try_step(&mut st, t, &vals, &mut out).unwrap();
                s.update(&m, &st);
                (out[0], s.property(&m, 0))
            })
            .collect()
    }

    #[test]
    fn historically_false_and_once_true_are_final() {
        let r = run("H(!{p})", &[(0, false), (1, true), (2, false)]);
        assert_eq!(
            r,
            vec![(true, None), (false, Some(false)), (false, Some(false))]
        );
        let r = run(
            "P[3:] {p}",
            &[(0, true), (1, false), (3, false), (9, false)],
        );
        assert_eq!(r[..2], [(false, None), (false, None)]);
        assert_eq!(r[2..], [(true, Some(true)), (true, Some(true))]);
    }

    #[test]
    fn bounded_operators_are_never_final_early() {
        // H[0:5] P {p}: false at first, true later; never declared final.
        let pts: Vec<_> = (0..12).map(|t| (t, t >= 1)).collect();
        let r = run("H[0:5] P {p}", &pts);
        assert!(r.iter().all(|(_, f)| f.is_none()), "{r:?}");
        assert!(!r[0].0 && r[11].0);
        let r = run("P[0:2] {p}", &[(0, true), (1, false), (5, false)]);
        assert!(r.iter().all(|(_, f)| f.is_none()), "{r:?}");
    }

    #[test]
    fn final_verdicts_never_change_on_random_traces() {
        let formulas = [
            "H({p} -> Y {p})",
            "P[2:] ({p} && Y {p})",
            "H(P[3:] true -> P[:3] {p})",
            "!(!{p} S {p}) || H !{p}",
            "(Z {p}) S[1:] {p}",
            "H(!{p}) || P[0:4] {p}",
        ];
        let mut x = 0x9e37_79b9_7f4a_7c15u64;
        let mut settled = 0;
        for f in formulas {
            for _ in 0..50 {
                let mut t = 0;
                let pts: Vec<_> = (0..60)
                    .map(|_| {
                        x ^= x << 13;
                        x ^= x >> 7;
                        x ^= x << 17;
                        t += x % 3;
                        (t, x % 5 == 0)
                    })
                    .collect();
                let r = run(f, &pts);
                if let Some(k) = r.iter().position(|(_, s)| s.is_some()) {
                    settled += 1;
                    let v = r[k].1.unwrap();
                    assert!(
                        r[k..].iter().all(|(o, s)| *o == v && *s == Some(v)),
                        "{f}: {r:?}"
                    );
                }
            }
        }
        // The check above was exercised: many runs settled before their end.
        assert!(settled > 100, "{settled}");
    }
}
