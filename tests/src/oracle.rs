//! The reference evaluator: Past-MTL verdicts computed straight from `docs/SEMANTICS.md` section 4.
//!
//! This is the oracle every engine (table interpreter, postcard table, generated
//! code) is checked against, so it is written for obviousness, not speed: each
//! operator is evaluated at each point by the textbook definition, over the
//! whole trace, with quantifiers spelled out as loops (quadratic per `S`).
//! It shares no code and no data structure with `codegen` or `monitor-core`.
//!
//! - [`F`]: the formula tree; atoms are indices into [`Point::atoms`].
//! - [`Point`]: one trace point, a timestamp and the truth value of every atom.
//! - [`eval`]: the verdict of a formula at every point of a trace.
//! - [`print`]: the formula as fully parenthesised Rye text, atom `k` as `{ak}`.

use std::fmt::Write as _;

/// A Past-MTL formula over numbered atoms.
///
/// Bounds are inclusive; `hi: None` means no upper bound. A tree with
/// `lo > hi` is not a formula of the language: [`eval`] treats its interval
/// as empty (the operator never finds a witness) and [`print`] prints it as is.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub enum F {
    /// `true`.
    True,
    /// `false`.
    False,
    /// `{ak}`: atom `k` of each point.
    Atom(usize),
    /// `!f`.
    Not(Box<F>),
    /// `f && g`.
    And(Box<F>, Box<F>),
    /// `f || g`.
    Or(Box<F>, Box<F>),
    /// `f -> g`.
    Implies(Box<F>, Box<F>),
    /// `f <-> g`.
    Iff(Box<F>, Box<F>),
    /// `Y f`: previous point, false at the first.
    Y(Box<F>),
    /// `Z f`: previous point, true at the first.
    Z(Box<F>),
    /// `P[lo:hi] f` (once).
    Once {
        /// Lower bound of the distance to the witness.
        lo: u64,
        /// Upper bound, `None` for none.
        hi: Option<u64>,
        /// The operand.
        f: Box<F>,
    },
    /// `H[lo:hi] f` (historically).
    Hist {
        /// Lower bound of the distance to the points looked at.
        lo: u64,
        /// Upper bound, `None` for none.
        hi: Option<u64>,
        /// The operand.
        f: Box<F>,
    },
    /// `l S[lo:hi] r` (since).
    Since {
        /// Lower bound of the distance to the witness.
        lo: u64,
        /// Upper bound, `None` for none.
        hi: Option<u64>,
        /// Must hold at every point after the witness, up to and including now.
        l: Box<F>,
        /// The witness.
        r: Box<F>,
    },
}

/// One trace point: its timestamp (in time units) and the value of every atom.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Point {
    /// The timestamp; timestamps are non-decreasing along a trace.
    pub time: u64,
    /// `atoms[k]` is the truth value of atom `k`; a missing entry is `false`.
    pub atoms: Vec<bool>,
}

impl F {
    /// The number of nodes of the tree.
    pub fn size(&self) -> usize {
        1 + self.children().iter().map(|c| c.size()).sum::<usize>()
    }

    /// The height of the tree (an atom or a constant has depth 1).
    pub fn depth(&self) -> usize {
        1 + self.children().iter().map(|c| c.depth()).max().unwrap_or(0)
    }

    /// The largest atom index used, if any.
    pub fn max_atom(&self) -> Option<usize> {
        match self {
            F::Atom(k) => Some(*k),
            _ => self.children().iter().filter_map(|c| c.max_atom()).max(),
        }
    }

    fn children(&self) -> Vec<&F> {
        match self {
            F::True | F::False | F::Atom(_) => vec![],
            F::Not(f) | F::Y(f) | F::Z(f) | F::Once { f, .. } | F::Hist { f, .. } => vec![f],
            F::And(a, b) | F::Or(a, b) | F::Implies(a, b) | F::Iff(a, b) => vec![a, b],
            F::Since { l, r, .. } => vec![l, r],
        }
    }
}

/// `a <= d <= hi`, with `hi: None` as infinity.
fn within(d: u64, lo: u64, hi: Option<u64>) -> bool {
    lo <= d && hi.is_none_or(|hi| d <= hi)
}

/// The verdict of `f` at every point of `trace`, in order.
///
/// Timestamps must be non-decreasing; the oracle does not check it (a distance
/// `tau_i - tau_j` with `tau_j > tau_i` saturates to 0).
pub fn eval(f: &F, trace: &[Point]) -> Vec<bool> {
    let n = trace.len();
    let tau = |i: usize| trace[i].time;
    match f {
        F::True => vec![true; n],
        F::False => vec![false; n],
        F::Atom(k) => trace
            .iter()
            .map(|p| p.atoms.get(*k).copied().unwrap_or(false))
            .collect(),
        F::Not(a) => eval(a, trace).into_iter().map(|v| !v).collect(),
        F::And(a, b) => zip_with(a, b, trace, |x, y| x && y),
        F::Or(a, b) => zip_with(a, b, trace, |x, y| x || y),
        F::Implies(a, b) => zip_with(a, b, trace, |x, y| !x || y),
        F::Iff(a, b) => zip_with(a, b, trace, |x, y| x == y),
        // Y f: i > 0 and f at i-1.
        F::Y(a) => {
            let v = eval(a, trace);
            (0..n).map(|i| i > 0 && v[i - 1]).collect()
        }
        // Z f: i = 0 or f at i-1.
        F::Z(a) => {
            let v = eval(a, trace);
            (0..n).map(|i| i == 0 || v[i - 1]).collect()
        }
        // P[I] f = true S[I] f.
        F::Once { lo, hi, f } => eval(
            &F::Since {
                lo: *lo,
                hi: *hi,
                l: Box::new(F::True),
                r: f.clone(),
            },
            trace,
        ),
        // H[I] f = !P[I] !f.
        F::Hist { lo, hi, f } => eval(
            &F::Not(Box::new(F::Once {
                lo: *lo,
                hi: *hi,
                f: Box::new(F::Not(f.clone())),
            })),
            trace,
        ),
        // l S[a:b] r at i: there is j <= i with a <= tau_i - tau_j <= b, r at j,
        // and l at every k with j < k <= i.
        F::Since { lo, hi, l, r } => {
            let lv = eval(l, trace);
            let rv = eval(r, trace);
            (0..n)
                .map(|i| {
                    (0..=i).any(|j| {
                        within(tau(i).saturating_sub(tau(j)), *lo, *hi)
                            && rv[j]
                            && (j + 1..=i).all(|k| lv[k])
                    })
                })
                .collect()
        }
    }
}

fn zip_with(a: &F, b: &F, trace: &[Point], op: impl Fn(bool, bool) -> bool) -> Vec<bool> {
    let (x, y) = (eval(a, trace), eval(b, trace));
    x.into_iter().zip(y).map(|(x, y)| op(x, y)).collect()
}

/// `[lo:hi]`, `[lo:]`, or nothing for `[0:]`.
fn bounds(lo: u64, hi: Option<u64>) -> String {
    match (lo, hi) {
        (0, None) => String::new(),
        (lo, None) => format!("[{lo}:]"),
        (lo, Some(hi)) => format!("[{lo}:{hi}]"),
    }
}

/// The formula as Rye text, every operator application in parentheses and
/// atom `k` written `{ak}`: `((({a0}) S[2:4] ({a1})) && (Y true))`.
pub fn print(f: &F) -> String {
    let mut s = String::new();
    print_into(f, &mut s);
    s
}

fn print_into(f: &F, s: &mut String) {
    let bin = |s: &mut String, a: &F, op: &str, b: &F| {
        s.push('(');
        print_into(a, s);
        let _ = write!(s, " {op} ");
        print_into(b, s);
        s.push(')');
    };
    let un = |s: &mut String, op: &str, a: &F| {
        let _ = write!(s, "({op} ");
        print_into(a, s);
        s.push(')');
    };
    match f {
        F::True => s.push_str("true"),
        F::False => s.push_str("false"),
        F::Atom(k) => {
            let _ = write!(s, "{{a{k}}}");
        }
        F::Not(a) => {
            s.push_str("(!");
            print_into(a, s);
            s.push(')');
        }
        F::And(a, b) => bin(s, a, "&&", b),
        F::Or(a, b) => bin(s, a, "||", b),
        F::Implies(a, b) => bin(s, a, "->", b),
        F::Iff(a, b) => bin(s, a, "<->", b),
        F::Y(a) => un(s, "Y", a),
        F::Z(a) => un(s, "Z", a),
        F::Once { lo, hi, f } => un(s, &format!("P{}", bounds(*lo, *hi)), f),
        F::Hist { lo, hi, f } => un(s, &format!("H{}", bounds(*lo, *hi)), f),
        F::Since { lo, hi, l, r } => bin(s, l, &format!("S{}", bounds(*lo, *hi)), r),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn b(f: F) -> Box<F> {
        Box::new(f)
    }

    /// Points with the given timestamps; atom 0 then atom 1 from the strings (`1`/`0`).
    fn trace(times: &[u64], a0: &str, a1: &str) -> Vec<Point> {
        let bit = |s: &str, i: usize| s.as_bytes().get(i) == Some(&b'1');
        times
            .iter()
            .enumerate()
            .map(|(i, &time)| Point {
                time,
                atoms: vec![bit(a0, i), bit(a1, i)],
            })
            .collect()
    }

    fn tf(v: &[bool]) -> String {
        v.iter().map(|&b| if b { 'T' } else { 'F' }).collect()
    }

    #[test]
    fn first_point_yesterday_and_weak_yesterday() {
        let t = trace(&[0, 0, 1], "111", "");
        assert_eq!(tf(&eval(&F::Y(b(F::Atom(0))), &t)), "FTT");
        assert_eq!(tf(&eval(&F::Z(b(F::False)), &t)), "TFF");
    }

    #[test]
    fn since_window_by_hand() {
        // q at 0; p at 1,1,3 and not at 7. {a0} S[2:4] {a1}.
        let t = trace(&[0, 1, 1, 3, 7], "01110", "10000");
        let f = F::Since {
            lo: 2,
            hi: Some(4),
            l: b(F::Atom(0)),
            r: b(F::Atom(1)),
        };
        // i=0: d=0 < 2. i=1,2: d=1. i=3: d=3, p at 1,1,3: T. i=4: p false at 4.
        assert_eq!(tf(&eval(&f, &t)), "FFFTF");
    }

    #[test]
    fn once_and_historically_before_any_witness() {
        let t = trace(&[0, 5, 9], "000", "");
        let p = F::Once {
            lo: 0,
            hi: None,
            f: b(F::Atom(0)),
        };
        let h = F::Hist {
            lo: 3,
            hi: Some(4),
            f: b(F::Atom(0)),
        };
        assert_eq!(tf(&eval(&p, &t)), "FFF");
        // H[3:4]: only point 1 (d=4 from point 2) is in range at i=2: a0 false there.
        assert_eq!(tf(&eval(&h, &t)), "TTF");
    }

    #[test]
    fn printer_is_fully_parenthesised() {
        let f = F::And(
            b(F::Since {
                lo: 2,
                hi: Some(4),
                l: b(F::Atom(0)),
                r: b(F::Not(b(F::Atom(1)))),
            }),
            b(F::Hist {
                lo: 3,
                hi: None,
                f: b(F::Once {
                    lo: 0,
                    hi: None,
                    f: b(F::True),
                }),
            }),
        );
        assert_eq!(print(&f), "(({a0} S[2:4] (!{a1})) && (H[3:] (P true)))");
        assert_eq!(f.size(), 8);
        assert_eq!(f.depth(), 4);
        assert_eq!(f.max_atom(), Some(1));
    }
}
