//! Benchmark support for hindsight's monitors: the seeded traces, the benchmarked
//! formulas, and one measured loop per engine (`benches/monitors.rs` times them).
//!
//! # Pipeline
//!
//! 1. `build.rs` compiles every formula of [`FORMULAS`] (spec from [`spec`]) and
//!    emits its Rust monitor as module `f{k}` into `OUT_DIR/generated.rs`,
//!    included here.
//! 2. [`Trace::generate`] draws a deterministic trace: timestamps are the point
//!    index, `p`, `q`, `r` are independent with probabilities 0.1, 0.1, 0.3 from
//!    a seeded xorshift64* (mirrored by `scripts/compare_python.py`).
//! 3. [`run_baseline`], [`run_interpreter`] and [`run_generated`] feed the trace
//!    to nothing (reading the trace and computing the atoms only), to
//!    [`monitor_core::Monitor::try_step`], and to the generated monitor; each
//!    hands every verdict to a sink, so one loop serves both timing (a counter)
//!    and checking (a vector).
//!
//! # Crate features
//!
//! None.

mod cases;
pub mod floor;

pub use cases::{spec, FORMULAS};

use monitor_core::{Monitor, Value};

/// Plan room of the benchmarked interpreter (`Monitor<'_, PLAN>`): nodes and atoms.
pub const PLAN: usize = 64;

/// Seed of the benchmark traces (any non-zero value works; this one is fixed).
pub const SEED: u64 = 0x9E37_79B9_7F4A_7C15;

/// `p` is true when a draw is below this: probability 0.1 (to within 2^-64).
pub const P_BELOW: u64 = u64::MAX / 10;
/// `q`: probability 0.1.
pub const Q_BELOW: u64 = u64::MAX / 10;
/// `r`: probability 0.3.
pub const R_BELOW: u64 = u64::MAX / 10 * 3;

/// A xorshift64* generator (Vigna 2016): tiny, fast and easy to mirror in Python.
#[derive(Clone, Debug)]
pub struct XorShift64Star(u64);

impl XorShift64Star {
    /// A generator from a seed; a zero seed (a fixed point of xorshift) becomes 1.
    pub fn new(seed: u64) -> Self {
        XorShift64Star(if seed == 0 { 1 } else { seed })
    }

    /// The next 64-bit draw.
    pub fn next_u64(&mut self) -> u64 {
        let mut x = self.0;
        x ^= x >> 12;
        x ^= x << 25;
        x ^= x >> 27;
        self.0 = x;
        x.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }
}

/// A benchmark trace: point `i` has timestamp `i` and the values of `p`, `q`, `r`.
#[derive(Clone, Debug)]
pub struct Trace {
    /// Bit 0: `p`, bit 1: `q`, bit 2: `r`.
    pub(crate) bits: Vec<u8>,
}

impl Trace {
    /// `points` points drawn from `seed`: three draws per point, for `p`, `q`, `r` in that order.
    pub fn generate(points: usize, seed: u64) -> Self {
        let mut rng = XorShift64Star::new(seed);
        let bits = (0..points)
            .map(|_| {
                let p = rng.next_u64() < P_BELOW;
                let q = rng.next_u64() < Q_BELOW;
                let r = rng.next_u64() < R_BELOW;
                p as u8 | (q as u8) << 1 | (r as u8) << 2
            })
            .collect();
        Trace { bits }
    }

    /// The number of points.
    pub fn len(&self) -> usize {
        self.bits.len()
    }

    /// Whether the trace has no point.
    pub fn is_empty(&self) -> bool {
        self.bits.is_empty()
    }

    /// `(p, q, r)` at point `i`, `None` past the end.
    pub fn point(&self, i: usize) -> Option<(bool, bool, bool)> {
        self.bits.get(i).map(|&b| unpack(b))
    }

    /// How many points have `p`, `q`, `r` true.
    pub fn counts(&self) -> [usize; 3] {
        let mut c = [0; 3];
        for &b in &self.bits {
            for (k, n) in c.iter_mut().enumerate() {
                *n += (b >> k & 1) as usize;
            }
        }
        c
    }

    /// The trace as CSV for `hindsight replay` (`time,p,q,r`, every cell set).
    pub fn to_csv(&self) -> String {
        let mut s = String::with_capacity(self.bits.len() * 24 + 16);
        s.push_str("time,p,q,r\n");
        for (i, &b) in self.bits.iter().enumerate() {
            let (p, q, r) = unpack(b);
            s.push_str(&format!("{i},{},{},{}\n", p as u8, q as u8, r as u8));
        }
        s
    }
}

#[inline(always)]
pub(crate) fn unpack(b: u8) -> (bool, bool, bool) {
    (b & 1 != 0, b & 2 != 0, b & 4 != 0)
}

/// A loop over the trace that failed: the point and the monitor's error.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RunError {
    /// Index of the point that was not judged.
    pub point: usize,
    /// The error, as printed.
    pub message: String,
}

impl std::fmt::Display for RunError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "point {}: {}", self.point, self.message)
    }
}

impl std::error::Error for RunError {}

/// The floor every monitor pays: reads each point and computes its atoms
/// (forced into memory with `black_box`), then hands a boolean of them to `sink`.
#[inline(never)]
pub fn run_baseline(trace: &Trace, sink: &mut impl FnMut(bool)) {
    for &b in &trace.bits {
        let (p, q, r) = unpack(b);
        let [p, q, r] = std::hint::black_box([p, q, r]);
        sink(p && !q || r);
    }
}

/// A compiled formula ready for the interpreter.
pub struct Interpreted {
    pub(crate) compiled: codegen::Compiled,
}

impl Interpreted {
    /// Compiles `FORMULAS[k]`-like text (a formula over `p`, `q`, `r`).
    pub fn new(formula: &str) -> Result<Self, codegen::Diagnostics> {
        let compiled = codegen::compile_spec(&spec(formula), "bench")?;
        Ok(Interpreted { compiled })
    }

    /// The state size in bytes that the compiler reports (the interpreter's buffer).
    pub fn state_bytes(&self) -> usize {
        self.compiled.state_bytes()
    }

    /// Runs [`Monitor::try_step`] over `trace` from a fresh state, each verdict to
    /// `sink`: atoms are computed by the interpreter from the variables' values.
    /// The monitor is planned ([`PLAN`] entries, every bench formula fits).
    #[inline(never)]
    pub fn run(&self, trace: &Trace, sink: &mut impl FnMut(bool)) -> Result<(), RunError> {
        self.run_with::<PLAN>(trace, sink)
    }

    /// [`Interpreted::run`] with an unplanned monitor (`Monitor<'_>`, as built by
    /// [`Monitor::try_new`]).
    #[inline(never)]
    pub fn run_unplanned(
        &self,
        trace: &Trace,
        sink: &mut impl FnMut(bool),
    ) -> Result<(), RunError> {
        self.run_with::<0>(trace, sink)
    }

    #[inline(always)]
    fn run_with<const N: usize>(
        &self,
        trace: &Trace,
        sink: &mut impl FnMut(bool),
    ) -> Result<(), RunError> {
        let monitor = self.monitor::<N>()?;
        let mut state = vec![0u64; monitor.state_words()];
        monitor.reset(&mut state).map_err(|e| error_at(0, &e))?;
        let mut verdict = [false];
        for (i, &b) in trace.bits.iter().enumerate() {
            let (p, q, r) = unpack(b);
            let vals = [Value::Bool(p), Value::Bool(q), Value::Bool(r)];
            monitor
                .try_step(&mut state, i as u64, &vals, &mut verdict)
                .map_err(|e| error_at(i, &e))?;
            sink(verdict[0]);
        }
        Ok(())
    }

    /// Like [`Interpreted::run`] with [`Monitor::try_step_atoms`]: the caller computes
    /// the atoms, so this measures the temporal network alone.
    #[inline(never)]
    pub fn run_atoms(&self, trace: &Trace, sink: &mut impl FnMut(bool)) -> Result<(), RunError> {
        let monitor = self.monitor::<PLAN>()?;
        let mut state = vec![0u64; monitor.state_words()];
        monitor.reset(&mut state).map_err(|e| error_at(0, &e))?;
        // Atom k is the k-th distinct atom of the formula, in compile order.
        let order = self.atom_vars()?;
        let mut verdict = [false];
        for (i, &b) in trace.bits.iter().enumerate() {
            let mut bits = 0u64;
            for (k, &var) in order.iter().enumerate() {
                bits |= ((b >> var & 1) as u64) << k;
            }
            monitor
                .try_step_atoms(&mut state, i as u64, &[bits], &mut verdict)
                .map_err(|e| error_at(i, &e))?;
            sink(verdict[0]);
        }
        Ok(())
    }

    fn monitor<const N: usize>(&self) -> Result<Monitor<'_, N>, RunError> {
        Monitor::try_new_planned(self.compiled.program()).map_err(|e| error_at(0, &e))
    }

    /// For each atom, the trace bit it reads (0: `p`, 1: `q`, 2: `r`): every atom of
    /// a benchmark formula is a bare variable, so its code is one load.
    fn atom_vars(&self) -> Result<Vec<u8>, RunError> {
        let program = self.compiled.program();
        program
            .atoms
            .iter()
            .enumerate()
            .map(|(k, a)| match program.instrs.get(a.start as usize) {
                Some(monitor_core::Instr::Load(v)) if a.len == 1 && *v < 3 => Ok(*v as u8),
                _ => Err(RunError {
                    point: 0,
                    message: format!("atom {k} is not a bare `p`, `q` or `r`"),
                }),
            })
            .collect()
    }
}

fn error_at(point: usize, e: &dyn std::fmt::Display) -> RunError {
    RunError {
        point,
        message: e.to_string(),
    }
}

/// Runs generated module `$m` over `$trace` with sink `$sink`; a `?`-able result.
macro_rules! gen_loop {
    ($m:ident, $trace:expr, $sink:expr) => {{
        // Boxed: a large window (P[100000:100000]) is megabytes.
        let mut monitor = Box::new($m::Monitor::new());
        let mut input = $m::Input::new();
        let mut result = Ok(());
        for (i, &b) in $trace.bits.iter().enumerate() {
            let (p, q, r) = unpack(b);
            input.p = p;
            input.q = q;
            input.r = r;
            match monitor.step(i as u64, &input) {
                Ok([v]) => $sink(v),
                Err(e) => {
                    result = Err(RunError {
                        point: i,
                        message: format!("{e:?}"),
                    });
                    break;
                }
            }
        }
        result
    }};
}

/// The generated monitors, one module `f{k}` per formula of [`FORMULAS`].
#[allow(missing_docs, dead_code)]
pub mod generated {
    use super::{unpack, RunError, Trace};
    include!(concat!(env!("OUT_DIR"), "/generated.rs"));
}

pub use generated::{generated_state_bytes, run_generated};

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn generator_matches_the_python_mirror() {
        // The first draws from SEED, as computed by the independent Python
        // implementation in scripts/compare_python.py (`xorshift64star`).
        let mut rng = XorShift64Star::new(SEED);
        let draws = [rng.next_u64(), rng.next_u64(), rng.next_u64()];
        assert_eq!(
            draws,
            [
                0x0d83_b3e2_9a21_487a,
                0x54c4_4c79_f1fe_9d67,
                0xa845_f342_007a_0e78
            ]
        );
        assert_eq!(
            XorShift64Star::new(0).next_u64(),
            XorShift64Star::new(1).next_u64()
        );
    }

    #[test]
    fn trace_has_the_requested_probabilities() {
        let n = 200_000;
        let trace = Trace::generate(n, SEED);
        assert_eq!(trace.len(), n);
        for (count, p) in trace.counts().into_iter().zip([0.1, 0.1, 0.3]) {
            let sigma = (n as f64 * p * (1.0 - p)).sqrt();
            let dev = (count as f64 - n as f64 * p).abs();
            assert!(dev < 4.0 * sigma, "{count} of {n} for probability {p}");
        }
        // Deterministic: the same seed gives the same trace.
        assert_eq!(
            Trace::generate(1000, SEED).to_csv(),
            Trace::generate(1000, SEED).to_csv()
        );
    }

    #[test]
    fn csv_has_a_header_and_one_row_per_point() {
        let trace = Trace::generate(50, SEED);
        let csv = trace.to_csv();
        let mut lines = csv.lines();
        assert_eq!(lines.next(), Some("time,p,q,r"));
        for (i, line) in lines.enumerate() {
            let (p, q, r) = trace.point(i).expect("a point per row");
            assert_eq!(line, format!("{i},{},{},{}", p as u8, q as u8, r as u8));
        }
        assert_eq!(csv.lines().count(), 51);
    }

    #[test]
    fn engines_agree_on_every_formula() {
        // A big stack: the generated P[100000:100000] monitor is 1.6 MB and an
        // unoptimised `Box::new` builds it on the stack first.
        let worker = std::thread::Builder::new()
            .stack_size(64 << 20)
            .spawn(|| {
                let trace = Trace::generate(3000, SEED ^ 0x5555);
                for (k, f) in FORMULAS.iter().enumerate() {
                    let interp = Interpreted::new(f).expect("benchmark formulas compile");
                    let (mut a, mut b, mut c) = (Vec::new(), Vec::new(), Vec::new());
                    interp.run(&trace, &mut |v| a.push(v)).expect("try_step");
                    interp
                        .run_atoms(&trace, &mut |v| b.push(v))
                        .expect("try_step_atoms");
                    run_generated(k, &trace, &mut |v| c.push(v)).expect("generated");
                    assert_eq!(a.len(), trace.len(), "{f}");
                    assert_eq!(a, b, "{f}: try_step vs try_step_atoms");
                    assert_eq!(a, c, "{f}: try_step vs generated");
                }
            })
            .expect("spawn");
        worker.join().expect("no engine panicked");
    }

    #[test]
    fn point_interval_state_grows_with_the_bound_only() {
        // `P[b:b]` keeps b + 1 runs of two words: 16 bytes more per unit of b,
        // in the table and in the generated monitor alike.
        let bytes = |b: u64| {
            let f = format!("P[{b}:{b}] {{p}}");
            let k = FORMULAS.iter().position(|g| *g == f).expect("benchmarked");
            let table = Interpreted::new(&f).expect("compiles").state_bytes();
            (table, generated_state_bytes(k))
        };
        let (t10, g10) = bytes(10);
        let (t1000, g1000) = bytes(1000);
        assert_eq!(t1000 - t10, 16 * 990);
        assert_eq!(g1000 - g10, 16 * 990);
    }

    #[test]
    fn a_formula_outside_the_trace_variables_is_an_error() {
        assert!(Interpreted::new("H({s})").is_err());
        let k = FORMULAS.len();
        let trace = Trace::generate(10, SEED);
        assert!(run_generated(k, &trace, &mut |_| {}).is_err());
    }
}
