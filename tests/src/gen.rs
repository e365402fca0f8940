//! Seeded random formulas and traces for differential tests against the [`crate::oracle`].
//!
//! Everything is drawn from a [`Xoshiro256PlusPlus`] stream, so a seed names a
//! case exactly: a failing seed reproduces on any machine. Formulas cover every
//! operator and every interval shape (`[0:b]`, `[a:]`, `[a:b]`, `[a:a]`, none)
//! with small bounds (which the traces' small gaps hit often) and large ones;
//! traces repeat timestamps (super-dense micro-steps) and jump far now and then.

use rand_core::{Rng, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

use crate::oracle::{Point, F};

/// The generator type every helper here takes.
pub type Gen = Xoshiro256PlusPlus;

/// A generator for `seed`.
pub fn rng(seed: u64) -> Gen {
    Xoshiro256PlusPlus::seed_from_u64(seed)
}

/// A uniform integer in `lo..=hi` (`lo <= hi`); the modulo bias is irrelevant here.
pub fn range(rng: &mut Gen, lo: u64, hi: u64) -> u64 {
    let span = hi - lo;
    if span == u64::MAX {
        return rng.next_u64();
    }
    lo + rng.next_u64() % (span + 1)
}

/// `true` with probability `p` (clamped to `[0, 1]`).
pub fn chance(rng: &mut Gen, p: f64) -> bool {
    // 53 random bits give a uniform float in [0, 1).
    let x = (rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64;
    x < p
}

/// How formulas are drawn.
#[derive(Clone, Debug)]
pub struct FormulaConfig {
    /// Height of the tallest tree (an atom has depth 1); at least 1.
    pub max_depth: usize,
    /// Atoms are `{a0}` .. `{a(atoms-1)}`; at least 1.
    pub atoms: usize,
    /// Largest "small" bound (small bounds are hit often by small gaps).
    pub small: u64,
    /// Largest "large" bound. Keep `[a:a]` windows affordable: their monitor
    /// holds `a + 1` runs, so this also caps the state size.
    pub large: u64,
    /// Probability that a bound is large rather than small.
    pub p_large: f64,
}

impl Default for FormulaConfig {
    fn default() -> Self {
        FormulaConfig {
            max_depth: 6,
            atoms: 3,
            small: 6,
            large: 1000,
            p_large: 0.2,
        }
    }
}

/// How traces are drawn.
#[derive(Clone, Debug)]
pub struct TraceConfig {
    /// Number of points.
    pub len: usize,
    /// Atoms per point.
    pub atoms: usize,
    /// Probability that an atom is true at a point.
    pub p_true: f64,
    /// Probability that a point repeats the previous timestamp.
    pub p_repeat: f64,
    /// Largest ordinary gap between distinct timestamps (at least 1).
    pub max_gap: u64,
    /// Probability of a long jump (up to `big_gap`) instead of an ordinary gap.
    pub p_jump: f64,
    /// Largest long jump.
    pub big_gap: u64,
    /// Timestamp of the first point.
    pub start: u64,
}

impl Default for TraceConfig {
    fn default() -> Self {
        TraceConfig {
            len: 40,
            atoms: 3,
            p_true: 0.5,
            p_repeat: 0.25,
            max_gap: 3,
            p_jump: 0.05,
            big_gap: 600,
            start: 0,
        }
    }
}

/// One bound: small or large per `cfg`.
fn bound(rng: &mut Gen, cfg: &FormulaConfig) -> u64 {
    if chance(rng, cfg.p_large) {
        range(rng, cfg.small + 1, cfg.large.max(cfg.small + 1))
    } else {
        range(rng, 0, cfg.small)
    }
}

/// An interval `(lo, hi)` of a random shape: `[0:b]`, `[a:]`, `[a:b]`, `[a:a]` or none.
pub fn interval(rng: &mut Gen, cfg: &FormulaConfig) -> (u64, Option<u64>) {
    match range(rng, 0, 4) {
        0 => (0, None),
        1 => (0, Some(bound(rng, cfg))),
        2 => (bound(rng, cfg).max(1), None),
        3 => {
            let a = bound(rng, cfg);
            (a, Some(a))
        }
        _ => {
            let (x, y) = (bound(rng, cfg), bound(rng, cfg));
            (x.min(y), Some(x.max(y)))
        }
    }
}

/// A random formula of depth at most `cfg.max_depth`.
pub fn formula(rng: &mut Gen, cfg: &FormulaConfig) -> F {
    formula_at(rng, cfg, cfg.max_depth.max(1))
}

fn formula_at(rng: &mut Gen, cfg: &FormulaConfig, depth: usize) -> F {
    // Leaves get likelier as the budget shrinks, so sizes vary.
    if depth <= 1 || chance(rng, 0.15) {
        return match range(rng, 0, 9) {
            0 => F::True,
            1 => F::False,
            _ => F::Atom(range(rng, 0, cfg.atoms.max(1) as u64 - 1) as usize),
        };
    }
    let op = range(rng, 0, 11);
    let f = Box::new(formula_at(rng, cfg, depth - 1));
    let sub = |rng: &mut Gen| Box::new(formula_at(rng, cfg, depth - 1));
    match op {
        0 => F::Not(f),
        1 => F::And(f, sub(rng)),
        2 => F::Or(f, sub(rng)),
        3 => F::Implies(f, sub(rng)),
        4 => F::Iff(f, sub(rng)),
        5 => F::Y(f),
        6 => F::Z(f),
        7 | 8 => {
            let (lo, hi) = interval(rng, cfg);
            F::Once { lo, hi, f }
        }
        9 => {
            let (lo, hi) = interval(rng, cfg);
            F::Hist { lo, hi, f }
        }
        _ => {
            let r = sub(rng);
            let (lo, hi) = interval(rng, cfg);
            F::Since { lo, hi, l: f, r }
        }
    }
}

/// A random trace: non-decreasing timestamps with repeats and jumps, random atoms.
pub fn trace(rng: &mut Gen, cfg: &TraceConfig) -> Vec<Point> {
    let mut time = cfg.start;
    (0..cfg.len)
        .map(|i| {
            if i > 0 && !chance(rng, cfg.p_repeat) {
                let gap = if chance(rng, cfg.p_jump) {
                    range(rng, cfg.max_gap.max(1), cfg.big_gap.max(cfg.max_gap).max(1))
                } else {
                    range(rng, 1, cfg.max_gap.max(1))
                };
                time = time.saturating_add(gap);
            }
            let atoms = (0..cfg.atoms).map(|_| chance(rng, cfg.p_true)).collect();
            Point { time, atoms }
        })
        .collect()
}

/// Declarations for atoms `a0 .. a(n-1)` as boolean state variables (initially false).
pub fn decls(atoms: usize) -> String {
    (0..atoms)
        .map(|k| format!("state a{k}: bool = false;\n"))
        .collect()
}

/// The spec of formula `f` over atoms `a0 .. a(atoms-1)`: [`decls`] and one
/// property `p` whose formula is `f` printed by [`crate::oracle::print`].
pub fn spec(f: &F, atoms: usize) -> String {
    format!(
        "{}property p = {};\n",
        decls(atoms),
        crate::oracle::print(f)
    )
}

/// Seed of the differential test's fixed formula set (see [`diff_formula`]).
pub const DIFF_SEED: u64 = 0x6869_6e64_7369_6768;

/// Atoms of the differential test's formulas.
pub const DIFF_ATOMS: usize = 3;

/// Formula `k` of the differential test's fixed set: `tests/build.rs` emits
/// code for formulas `0..count`, and the test draws them again to judge them.
/// Depth up to 6, every operator and every interval shape ([`FormulaConfig::default`]).
pub fn diff_formula(k: usize) -> F {
    let cfg = FormulaConfig {
        atoms: DIFF_ATOMS,
        ..FormulaConfig::default()
    };
    formula(&mut rng(DIFF_SEED.wrapping_add(k as u64)), &cfg)
}

/// A trace in the corpus point syntax over the variables of [`decls`]: every
/// point sets every atom, `a0` for true and `!a0` for false.
pub fn trace_lines(trace: &[Point]) -> Vec<String> {
    trace
        .iter()
        .map(|p| {
            let mut s = format!("{}:", p.time);
            for (k, &v) in p.atoms.iter().enumerate() {
                s.push_str(if v { " a" } else { " !a" });
                s.push_str(&k.to_string());
            }
            s
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn same_seed_same_draws() {
        let (fc, tc) = (FormulaConfig::default(), TraceConfig::default());
        let draw = |seed| {
            let mut r = rng(seed);
            (formula(&mut r, &fc), trace(&mut r, &tc))
        };
        assert_eq!(draw(7), draw(7));
        assert_ne!(draw(7), draw(8));
    }

    #[test]
    fn formulas_respect_depth_atoms_and_bounds() {
        let cfg = FormulaConfig::default();
        let mut r = rng(1);
        let mut shapes = [false; 5];
        for _ in 0..500 {
            let f = formula(&mut r, &cfg);
            assert!(f.depth() <= cfg.max_depth);
            assert!(f.max_atom().is_none_or(|k| k < cfg.atoms));
            let (lo, hi) = interval(&mut r, &cfg);
            assert!(hi.is_none_or(|hi| lo <= hi && hi <= cfg.large));
            let shape = match (lo, hi) {
                (0, None) => 0,
                (0, Some(_)) => 1,
                (_, None) => 2,
                (a, Some(b)) if a == b => 3,
                _ => 4,
            };
            shapes[shape] = true;
        }
        assert_eq!(shapes, [true; 5], "every interval shape is drawn");
    }

    #[test]
    fn traces_are_monotone_with_repeats() {
        let cfg = TraceConfig::default();
        let t = trace(&mut rng(3), &cfg);
        assert_eq!(t.len(), cfg.len);
        assert!(t.windows(2).all(|w| w[0].time <= w[1].time));
        assert!(t.windows(2).any(|w| w[0].time == w[1].time));
        assert!(t.iter().all(|p| p.atoms.len() == cfg.atoms));
    }

    #[test]
    fn trace_lines_use_the_point_syntax() {
        let t = vec![Point {
            time: 4,
            atoms: vec![true, false],
        }];
        assert_eq!(trace_lines(&t), vec!["4: a0 !a1".to_string()]);
        assert_eq!(decls(1), "state a0: bool = false;\n");
    }
}
