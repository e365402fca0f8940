//! The contract floor: [`monitor_core::Monitor::try_step`]'s work for one formula,
//! `P[0:100] {p}`, written by hand with nothing interpreted.
//!
//! An interpreter reads its program from memory; this function has the formula
//! in its code, like the generated monitor. Unlike the generated monitor it keeps
//! `try_step`'s contract: the same arguments (`&mut [u64]` state, `&[Value]`
//! variables, `&mut [bool]` verdicts), the same checks before anything is written
//! (state, variable and verdict counts, every variable's type, the timestamp), and
//! the same state, word for word, so that `Monitor::verdict`, `node_value` and
//! `last_time` read it as they read the interpreter's. What it costs over the
//! generated code is the contract's price; what `try_step` costs over it is the
//! price of interpreting. The bench prints both.

use monitor_core::Value;

use crate::{unpack, RunError, Trace};

/// The benchmarked formula this floor computes (`FORMULAS[4]`).
pub const FORMULA: &str = "P[0:100] {p}";

/// The interpreter's state words for [`FORMULA`]: the time word (last time + 1),
/// the atom word, the value word (node `n0` the constant `true`, `n1` atom `{p}`,
/// `n2` the `Since`) and the `Since`'s own word (1 + the time `p` was last true).
pub const WORDS: usize = 4;

/// What an interpreter reads from its program rather than its code: the shape of
/// a point, where `{p}` and the `Since` are, the bound. The loop gets them
/// through `black_box`, so that no check is decided at compile time (an
/// interpreter cannot decide them either); they then stay in registers, as
/// an interpreter's decoded fields may.
#[derive(Clone, Copy, Debug)]
pub struct Shape {
    /// State words.
    pub words: usize,
    /// Declared variables, every one boolean.
    pub vars: usize,
    /// Properties.
    pub props: usize,
    /// The variable of atom `{p}`.
    pub p: usize,
    /// The `Since`'s own word.
    pub slot: usize,
    /// Its upper bound.
    pub hi: u64,
}

/// [`FORMULA`]'s shape.
pub const SHAPE: Shape = Shape {
    words: WORDS,
    vars: 3,
    props: 1,
    p: 0,
    slot: 3,
    hi: 100,
};

/// A point [`step`] refused: the state, variables or verdicts of another
/// shape, a variable of another type, or a timestamp out of order.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct WrongShape;

/// The step: `Err` with nothing written when the point has the wrong shape.
#[inline(always)]
pub fn step(
    k: &Shape,
    state: &mut [u64],
    time: u64,
    vars: &[Value],
    verdicts: &mut [bool],
) -> Result<(), WrongShape> {
    let ok = (state.len() == k.words)
        & (state.len() > k.slot)
        & (vars.len() == k.vars)
        & (verdicts.len() == k.props)
        & (k.props == 1)
        & (time.wrapping_add(1) >= state.first().copied().unwrap_or(0))
        & (time != u64::MAX);
    if !ok || !vars.iter().all(|v| matches!(v, Value::Bool(_))) {
        return Err(WrongShape);
    }
    let p = matches!(vars.get(k.p), Some(Value::Bool(true)));
    let t1 = time + 1;
    let w = if p { t1 } else { state[k.slot] };
    let v = w != 0 && t1 - w <= k.hi;
    state[k.slot] = w;
    state[1] = p as u64;
    state[2] = 1 | (p as u64) << 1 | (v as u64) << 2;
    state[0] = t1;
    verdicts[0] = v;
    Ok(())
}

/// [`step`] over `trace` from a fresh state, each verdict to `sink`: the loop of
/// [`crate::Interpreted::run`] with the interpreter replaced.
#[inline(never)]
pub fn run(trace: &Trace, sink: &mut impl FnMut(bool)) -> Result<(), RunError> {
    let k = std::hint::black_box(SHAPE);
    let mut state = std::hint::black_box(vec![0u64; k.words]);
    let mut verdict = [false];
    for (i, &b) in trace.bits.iter().enumerate() {
        let (p, q, r) = unpack(b);
        let vals = [Value::Bool(p), Value::Bool(q), Value::Bool(r)];
        step(&k, &mut state, i as u64, &vals, &mut verdict).map_err(|WrongShape| RunError {
            point: i,
            message: "the point has the wrong shape".into(),
        })?;
        sink(verdict[0]);
    }
    std::hint::black_box(&state);
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Interpreted, SEED};
    use monitor_core::Monitor;

    #[test]
    fn the_floor_keeps_the_interpreters_state_word_for_word() {
        let interp = Interpreted::new(FORMULA).expect("compiles");
        let program = interp.compiled.program();
        let monitor: Monitor<'_, 64> = Monitor::try_new_planned(program).expect("valid");
        assert_eq!(monitor.state_words(), WORDS);
        let (mut a, mut b) = (vec![0u64; WORDS], vec![0u64; WORDS]);
        monitor.reset(&mut a).expect("reset");
        let trace = Trace::generate(2000, SEED ^ 0x77);
        let (mut va, mut vb) = ([false], [false]);
        let mut trues = 0;
        for i in 0..trace.len() {
            // Gaps in time, so that the bound is crossed both ways.
            let t = (i as u64) * 7 / 3;
            let (p, q, r) = trace.point(i).expect("in range");
            let vals = [Value::Bool(p), Value::Bool(q), Value::Bool(r)];
            monitor.try_step(&mut a, t, &vals, &mut va).expect("step");
            step(&SHAPE, &mut b, t, &vals, &mut vb).expect("floor");
            assert_eq!((a.as_slice(), va), (b.as_slice(), vb), "point {i}");
            trues += va[0] as usize;
        }
        assert!(trues > 0 && trues < trace.len(), "both verdicts seen");
    }

    #[test]
    fn the_floor_refuses_what_the_interpreter_refuses_and_writes_nothing() {
        let mut s = vec![0u64; WORDS];
        let b = [Value::Bool(true), Value::Bool(false), Value::Bool(false)];
        let mut v = [false];
        step(&SHAPE, &mut s, 10, &b, &mut v).expect("a good point");
        let before = s.clone();
        let bad_type = [Value::Bool(true), Value::Int(1), Value::Bool(false)];
        assert!(step(&SHAPE, &mut s, 11, &bad_type, &mut v).is_err());
        assert!(step(&SHAPE, &mut s, 11, &b[..2], &mut v).is_err());
        assert!(step(&SHAPE, &mut s, 11, &b, &mut [false; 2]).is_err());
        assert!(step(&SHAPE, &mut s[..3], 11, &b, &mut v).is_err());
        assert!(step(&SHAPE, &mut s, 9, &b, &mut v).is_err());
        assert!(step(&SHAPE, &mut s, u64::MAX, &b, &mut v).is_err());
        assert_eq!(s, before);
        step(&SHAPE, &mut s, 10, &b, &mut v).expect("the same time again");
    }
}
