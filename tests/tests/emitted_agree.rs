//! Emitted Rust monitors agree with the table interpreter on every point.
//!
//! `build.rs` emits the hand-built programs of `codegen/tests/golden/programs.rs`
//! with `codegen::emit_rust`; this test compiles them (`include!`) and runs
//! seeded random traces through both the generated code and
//! `monitor_core::Monitor`, requiring identical verdicts and identical errors on
//! every point: repeated and backwards timestamps, `u64::MAX`, integer
//! overflow, NaN, resets, timestamps near the top of the range.

use monitor_core::{valuation, Monitor, Program, StepError, Ty, Value, VarKind};

#[allow(dead_code)]
mod programs {
    include!("../../codegen/tests/golden/programs.rs");
}

include!(concat!(env!("OUT_DIR"), "/emitted.rs"));

/// A small deterministic generator (xorshift64*), enough for test traces.
struct Rng(u64);

impl Rng {
    fn new(seed: u64) -> Self {
        Rng(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1)
    }

    fn next(&mut self) -> u64 {
        let mut x = self.0;
        x ^= x >> 12;
        x ^= x << 25;
        x ^= x >> 27;
        self.0 = x;
        x.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }

    /// Uniform in `0..n` (n > 0), good enough for tests.
    fn below(&mut self, n: u64) -> u64 {
        self.next() % n
    }

    /// True with probability `percent / 100`.
    fn chance(&mut self, percent: u64) -> bool {
        self.below(100) < percent
    }

    fn pick<T: Copy>(&mut self, items: &[T]) -> T {
        items[self.below(items.len() as u64) as usize]
    }
}

const INTS: &[i64] = &[
    0,
    1,
    -1,
    2,
    -3,
    3,
    7,
    30,
    31,
    100,
    -100,
    i64::MAX,
    i64::MIN,
    i64::MAX - 1,
    i64::MIN + 1,
    1 << 32,
    -(1 << 32),
    3_037_000_500,
];

const FLOATS: &[f64] = &[
    0.0,
    -0.0,
    1.5,
    -1.5,
    f64::NAN,
    f64::INFINITY,
    f64::NEG_INFINITY,
    1e300,
    -1e300,
    1e-300,
    2.5,
    3.0,
];

/// A random value of type `ty`; extreme numbers with probability `extremes` percent.
fn random_value(rng: &mut Rng, ty: Ty, strings: usize, extremes: u64) -> Value {
    match ty {
        Ty::Bool => Value::Bool(rng.chance(50)),
        Ty::Int if rng.chance(extremes) => Value::Int(rng.pick(INTS)),
        Ty::Int => Value::Int(rng.below(101) as i64 - 50),
        Ty::Float if rng.chance(extremes) => Value::Float(rng.pick(FLOATS)),
        Ty::Float => Value::Float((rng.below(401) as f64 - 200.0) / 4.0),
        Ty::Str => Value::Str(rng.below(strings as u64 + 3) as u32),
    }
}

/// A generated monitor module, seen through one interface.
trait Generated {
    type Input;
    fn new_input() -> Self::Input;
    fn begin_point(input: &mut Self::Input);
    fn set(input: &mut Self::Input, var: usize, value: Value);
    fn same(input: &Self::Input, vals: &[Value]) -> bool;
    fn boxed() -> Box<Self>;
    fn reset(&mut self);
    fn last_time(&self) -> Option<u64>;
    fn step(&mut self, time: u64, input: &Self::Input) -> Result<Vec<bool>, StepError>;
}

macro_rules! generated {
    ($module:ident, $io:ident) => {
        impl Generated for $module::Monitor {
            type Input = $module::Input;
            fn new_input() -> Self::Input {
                $module::Input::new()
            }
            fn begin_point(input: &mut Self::Input) {
                input.begin_point();
            }
            fn set(input: &mut Self::Input, var: usize, value: Value) {
                $io::set(input, var, value);
            }
            fn same(input: &Self::Input, vals: &[Value]) -> bool {
                $io::same(input, vals)
            }
            fn boxed() -> Box<Self> {
                Box::new($module::Monitor::new())
            }
            fn reset(&mut self) {
                $module::Monitor::reset(self);
            }
            fn last_time(&self) -> Option<u64> {
                $module::Monitor::last_time(self)
            }
            fn step(&mut self, time: u64, input: &Self::Input) -> Result<Vec<bool>, StepError> {
                match $module::Monitor::step(self, time, input) {
                    Ok(v) => Ok(v.to_vec()),
                    Err($module::StepError::TimeWentBackwards { last, now }) => {
                        Err(StepError::TimeWentBackwards { last, now })
                    }
                    Err($module::StepError::TimeOutOfRange) => Err(StepError::TimeOutOfRange),
                    Err($module::StepError::Arithmetic { atom }) => {
                        Err(StepError::Arithmetic { atom })
                    }
                }
            }
        }
    };
}

generated!(minimal, minimal_io);
generated!(logic, logic_io);
generated!(ints, ints_io);
generated!(floats, floats_io);
generated!(strings, strings_io);
generated!(windows, windows_io);
generated!(random_1, random_1_io);
generated!(random_2, random_2_io);
generated!(random_3, random_3_io);
generated!(random_4, random_4_io);
generated!(random_5, random_5_io);
generated!(random_6, random_6_io);

/// How a trace is drawn.
#[derive(Clone, Copy, Debug)]
struct Shape {
    /// First timestamp.
    start: u64,
    /// Percent chance that a state variable changes at a point.
    change: u64,
    /// Percent chance that an event is sent at a point.
    events: u64,
    /// Timestamps advance by exactly one unit (fills wide windows).
    dense: bool,
    /// Percent chance that a new number is an extreme one (overflow, NaN, infinities).
    extremes: u64,
}

/// What one run covered, so that a test can insist the interesting cases happened.
#[derive(Default, Debug)]
struct Seen {
    points: usize,
    equal_times: usize,
    backwards: usize,
    out_of_range: usize,
    arithmetic: usize,
    true_verdicts: usize,
}

/// Runs `points` random points through the interpreter and the generated
/// monitor `M`, asserting identical results on every point.
fn agree<M: Generated>(program: &Program<'_>, seed: u64, points: usize, shape: Shape) -> Seen {
    let monitor = Monitor::try_new(*program).expect("test program is valid");
    let mut state = vec![0u64; monitor.state_words()];
    monitor.reset(&mut state).expect("state has the right size");
    let mut vals = vec![Value::Bool(false); program.vars.len()];
    valuation::init(program.vars, &mut vals);
    let mut verdicts = vec![false; monitor.properties()];

    let mut generated = M::boxed();
    let mut input = M::new_input();
    assert!(M::same(&input, &vals), "initial values differ");

    let mut rng = Rng::new(seed);
    let mut seen = Seen::default();
    let mut time = shape.start;
    let mut last_ok: Option<u64> = None;
    for point in 0..points {
        valuation::begin_point(program.vars, &mut vals);
        M::begin_point(&mut input);
        for (i, var) in program.vars.iter().enumerate() {
            let value = match var.kind {
                VarKind::Event if rng.chance(shape.events) => Value::Bool(true),
                VarKind::State if rng.chance(shape.change) => {
                    random_value(&mut rng, var.ty, program.strings.len(), shape.extremes)
                }
                _ => continue,
            };
            vals[i] = value;
            M::set(&mut input, i, value);
        }
        assert!(
            M::same(&input, &vals),
            "seed {seed} point {point}: inputs differ"
        );

        let roll = rng.below(1000);
        let t = if roll < 15 && time > 0 {
            // Backwards (when something was judged at `time`, an error).
            time - 1 - rng.below(time.min(5))
        } else if roll < 20 {
            u64::MAX
        } else if shape.dense {
            time.saturating_add(1)
        } else if roll < 300 {
            time
        } else if roll < 950 {
            time.saturating_add(1 + rng.below(3))
        } else {
            time.saturating_add(4 + rng.below(1200))
        };
        if t != u64::MAX && t >= time {
            time = t;
        }

        let expected = monitor
            .try_step(&mut state, t, &vals, &mut verdicts)
            .map(|()| verdicts.clone());
        let got = generated.step(t, &input);
        assert_eq!(
            got, expected,
            "seed {seed} point {point} time {t} (last judged {last_ok:?}), {shape:?}, values {vals:?}"
        );
        match expected {
            Ok(v) => {
                if last_ok == Some(t) {
                    seen.equal_times += 1;
                }
                last_ok = Some(t);
                seen.true_verdicts += v.iter().filter(|b| **b).count();
            }
            Err(StepError::TimeWentBackwards { .. }) => seen.backwards += 1,
            Err(StepError::TimeOutOfRange) => seen.out_of_range += 1,
            Err(StepError::Arithmetic { .. }) => seen.arithmetic += 1,
            Err(e) => panic!("unexpected interpreter error {e:?}"),
        }
        assert_eq!(generated.last_time(), last_ok);
        seen.points += 1;

        if rng.below(700) == 0 {
            monitor.reset(&mut state).expect("state has the right size");
            generated.reset();
            last_ok = None;
        }
    }
    seen
}

/// Runs a program under several trace shapes and seeds; returns the combined coverage.
fn agree_all<M: Generated>(program: &Program<'_>) -> Seen {
    agree_all_with::<M>(program, 50)
}

/// [`agree_all`] with extreme numbers drawn `extremes` percent of the time.
fn agree_all_with<M: Generated>(program: &Program<'_>, extremes: u64) -> Seen {
    let mut total = Seen::default();
    for seed in 1..=12u64 {
        let shape = Shape {
            start: match seed % 4 {
                0 => 0,
                1 => u64::MAX - 3000,
                _ => seed * 1000,
            },
            change: [10, 30, 70][seed as usize % 3],
            events: [20, 50, 95][seed as usize % 3],
            dense: seed % 3 == 0,
            extremes,
        };
        let s = agree::<M>(program, seed, 3000, shape);
        total.points += s.points;
        total.equal_times += s.equal_times;
        total.backwards += s.backwards;
        total.out_of_range += s.out_of_range;
        total.arithmetic += s.arithmetic;
        total.true_verdicts += s.true_verdicts;
    }
    assert!(total.equal_times > 0, "no equal timestamps: {total:?}");
    assert!(total.backwards > 0, "no backwards timestamps: {total:?}");
    assert!(total.out_of_range > 0, "no u64::MAX timestamps: {total:?}");
    assert!(total.true_verdicts > 0, "no true verdict: {total:?}");
    total
}

#[test]
fn minimal_agrees() {
    agree_all::<minimal::Monitor>(&programs::minimal());
}

#[test]
fn logic_agrees() {
    agree_all::<logic::Monitor>(&programs::logic());
}

#[test]
fn ints_agree() {
    let seen = agree_all::<ints::Monitor>(&programs::ints());
    assert!(seen.arithmetic > 0, "no overflow was exercised: {seen:?}");
}

#[test]
fn floats_agree() {
    agree_all::<floats::Monitor>(&programs::floats());
}

#[test]
fn strings_agree() {
    agree_all::<strings::Monitor>(&programs::strings());
}

#[test]
fn windows_agree() {
    agree_all::<windows::Monitor>(&programs::windows());
}

/// Random atoms: every operator nested in every position, errors included.
#[test]
fn random_atoms_agree() {
    let runs = [
        agree_all_with::<random_1::Monitor>(&programs::random(1), 5),
        agree_all_with::<random_2::Monitor>(&programs::random(2), 5),
        agree_all_with::<random_3::Monitor>(&programs::random(3), 5),
        agree_all_with::<random_4::Monitor>(&programs::random(4), 5),
        agree_all_with::<random_5::Monitor>(&programs::random(5), 5),
        agree_all_with::<random_6::Monitor>(&programs::random(6), 5),
    ];
    let arithmetic: usize = runs.iter().map(|s| s.arithmetic).sum();
    assert!(arithmetic > 0, "no overflow was exercised: {runs:?}");
    for s in &runs {
        assert!(s.arithmetic * 4 < s.points, "too few points judged: {s:?}");
    }
    for (name, p) in programs::random_all() {
        assert!(p.instrs.len() > 6 * 3, "{name}: expressions too small");
    }
}

/// `true S[1000:1000] req` with `req` at every unit fills all 1001 runs.
#[test]
fn full_capacity_window_agrees() {
    let program = programs::windows();
    let monitor = Monitor::try_new(program).expect("valid");
    let mut state = vec![0u64; monitor.state_words()];
    let mut verdicts = vec![false; monitor.properties()];
    let mut vals = vec![Value::Bool(false); program.vars.len()];
    valuation::init(program.vars, &mut vals);
    let mut generated = Box::new(windows::Monitor::new());
    let mut input = windows::Input::new();
    for t in 0..3000u64 {
        valuation::begin_point(program.vars, &mut vals);
        input.begin_point();
        let req = t < 1500 || t % 7 == 0;
        vals[0] = Value::Bool(req);
        input.req = req;
        monitor
            .try_step(&mut state, t, &vals, &mut verdicts)
            .expect("in order");
        let got = generated.step(t, &input).expect("in order");
        assert_eq!(got.to_vec(), verdicts, "time {t}");
        let big = got[windows::PROP_BIG];
        assert_eq!(
            big,
            t >= 1000 && (t < 2500 || (t - 1000) % 7 == 0),
            "time {t}"
        );
    }
    const { assert!(windows::STATE_BYTES >= 1001 * 16) };
}

/// A backwards timestamp and `u64::MAX` are errors that change nothing.
#[test]
fn rejected_points_leave_the_monitor_unchanged() {
    let mut m = logic::Monitor::new();
    let mut input = logic::Input::new();
    input.go = true;
    let first = m.step(5, &input).expect("first point");
    let before = m.clone();
    assert_eq!(
        m.step(4, &input),
        Err(logic::StepError::TimeWentBackwards { last: 5, now: 4 })
    );
    assert_eq!(
        m.step(u64::MAX, &input),
        Err(logic::StepError::TimeOutOfRange)
    );
    assert_eq!(m.last_time(), Some(5));
    // Same timestamp again: a new micro-step, judged like by the untouched copy.
    let mut copy = before;
    assert_eq!(m.step(5, &input), copy.step(5, &input));
    assert_eq!(first.len(), logic::PROPERTIES);
}

#[test]
fn overflow_is_reported_with_its_atom() {
    let mut m = ints::Monitor::new();
    let mut input = ints::Input::new();
    input.delta = 0;
    // battery / delta with delta == 0: atom 3 is the first to fail.
    assert_eq!(
        m.step(0, &input),
        Err(ints::StepError::Arithmetic { atom: 3 })
    );
    assert_eq!(m.last_time(), None);
    // battery * battery overflows even though `tick` is false (no short-circuit).
    input.delta = 1;
    input.battery = i64::MAX;
    assert_eq!(
        m.step(0, &input),
        Err(ints::StepError::Arithmetic { atom: 1 })
    );
    input.battery = 1 << 40;
    assert_eq!(
        m.step(0, &input),
        Err(ints::StepError::Arithmetic { atom: 6 })
    );
}

#[test]
fn string_constants_are_named_after_their_variables() {
    assert_eq!(strings::MODE_IDLE, strings::STR_IDLE);
    assert_eq!(strings::STRINGS[strings::STR_DOCKED as usize], "docked");
    assert_eq!(strings::string_id("moving"), Some(strings::STR_MOVING));
    assert_eq!(strings::string_id("flying"), None);
    let input = strings::Input::new();
    assert_eq!(input.mode, strings::MODE_IDLE);
    assert_eq!(input.next_mode, strings::NEXT_MODE_MOVING);
}
