//! Differential test: monitor-core's table interpreter against the oracle on random formulas.
//!
//! Independent of `codegen`: each random [`F`] is lowered here by a few lines
//! into a [`Program`] (once = `true S`, historically = `!(true S !f)`), atoms
//! are fed as bits, and every verdict at every point must equal [`oracle::eval`].

use hindsight_tests::gen::{self, FormulaConfig, TraceConfig};
use hindsight_tests::oracle::{self, Point, F};
use monitor_core::layout;
use monitor_core::{Atom, Instr, Monitor, Node, Op, Program, Property, Ty, Value, Var, VarKind};

/// Appends `f`'s nodes in post-order and returns the id of its root.
fn lower(f: &F, ops: &mut Vec<Op>) -> u16 {
    let push = |ops: &mut Vec<Op>, op: Op| {
        ops.push(op);
        (ops.len() - 1) as u16
    };
    let op = match f {
        F::True => Op::Const(true),
        F::False => Op::Const(false),
        F::Atom(k) => Op::Atom(*k as u16),
        F::Not(a) => Op::Not(lower(a, ops)),
        F::And(a, b) => Op::And(lower(a, ops), lower(b, ops)),
        F::Or(a, b) => Op::Or(lower(a, ops), lower(b, ops)),
        F::Implies(a, b) => Op::Implies(lower(a, ops), lower(b, ops)),
        F::Iff(a, b) => Op::Iff(lower(a, ops), lower(b, ops)),
        F::Y(a) => Op::Yesterday(lower(a, ops)),
        F::Z(a) => Op::WeakYesterday(lower(a, ops)),
        F::Once { lo, hi, f } => {
            let t = push(ops, Op::Const(true));
            let r = lower(f, ops);
            Op::Since {
                lhs: t,
                rhs: r,
                lo: *lo,
                hi: *hi,
            }
        }
        F::Hist { lo, hi, f } => {
            let t = push(ops, Op::Const(true));
            let inner = lower(f, ops);
            let r = push(ops, Op::Not(inner));
            let s = push(
                ops,
                Op::Since {
                    lhs: t,
                    rhs: r,
                    lo: *lo,
                    hi: *hi,
                },
            );
            Op::Not(s)
        }
        F::Since { lo, hi, l, r } => Op::Since {
            lhs: lower(l, ops),
            rhs: lower(r, ops),
            lo: *lo,
            hi: *hi,
        },
    };
    push(ops, op)
}

/// The monitor-core verdicts of `f` over `trace`, with `atoms` atoms.
fn run_core(f: &F, trace: &[Point], atoms: usize) -> Vec<bool> {
    let names: Vec<String> = (0..atoms).map(|k| format!("a{k}")).collect();
    let vars: Vec<Var<'_>> = names
        .iter()
        .map(|n| Var {
            name: n,
            ty: Ty::Bool,
            kind: VarKind::State,
            init: Value::Bool(false),
        })
        .collect();
    let instrs: Vec<Instr> = (0..atoms as u16).map(Instr::Load).collect();
    let atom_tab: Vec<Atom> = (0..atoms as u16)
        .map(|k| Atom { start: k, len: 1 })
        .collect();
    let mut ops = Vec::new();
    let root = lower(f, &mut ops);
    let mut word = layout::first_node_word(atoms, ops.len()) as u64;
    let nodes: Vec<Node> = ops
        .iter()
        .map(|op| {
            let words = layout::node_words(op).expect("generated bounds are valid");
            let slot = if words == 0 { 0 } else { word as u32 };
            word += words;
            Node { op: *op, slot }
        })
        .collect();
    let props = [Property {
        name: "p",
        first: 0,
        root,
    }];
    let program = Program {
        tick_ns: 1,
        vars: &vars,
        strings: &[],
        instrs: &instrs,
        atoms: &atom_tab,
        nodes: &nodes,
        props: &props,
    };
    let m = Monitor::try_new(program).expect("lowered program validates");
    let mut state = vec![0u64; m.state_words()];
    m.reset(&mut state).expect("state sized by the monitor");
    let mut out = [false];
    trace
        .iter()
        .map(|p| {
            let mut bits = vec![0u64; atoms.div_ceil(64)];
            for (k, &v) in p.atoms.iter().enumerate() {
                bits[k / 64] |= (v as u64) << (k % 64);
            }
            m.try_step_atoms(&mut state, p.time, &bits, &mut out)
                .expect("monotone time");
            out[0]
        })
        .collect()
}

fn check(seeds: std::ops::Range<u64>, fc: &FormulaConfig, tc: &TraceConfig) {
    for seed in seeds {
        let mut r = gen::rng(seed);
        let f = gen::formula(&mut r, fc);
        let t = gen::trace(&mut r, tc);
        let want = oracle::eval(&f, &t);
        let got = run_core(&f, &t, tc.atoms);
        if let Some(i) = (0..t.len()).find(|&i| want[i] != got[i]) {
            panic!(
                "seed {seed}: {} differs at point {i} (time {}): oracle {}, core {}\ntrace: {:?}",
                oracle::print(&f),
                t[i].time,
                want[i],
                got[i],
                gen::trace_lines(&t[..=i])
            );
        }
    }
}

#[test]
fn core_matches_oracle_on_small_bounds() {
    let fc = FormulaConfig {
        p_large: 0.0,
        ..FormulaConfig::default()
    };
    check(0..1500, &fc, &TraceConfig::default());
}

#[test]
fn core_matches_oracle_with_large_bounds_and_jumps() {
    let fc = FormulaConfig {
        p_large: 0.5,
        large: 300,
        ..FormulaConfig::default()
    };
    let tc = TraceConfig {
        len: 60,
        p_jump: 0.2,
        big_gap: 400,
        max_gap: 40,
        ..TraceConfig::default()
    };
    check(10_000..11_000, &fc, &tc);
}

#[test]
fn core_matches_oracle_on_dense_single_atom_traces() {
    // Mostly-true atoms keep `S` obligations alive for long stretches.
    let fc = FormulaConfig {
        atoms: 1,
        max_depth: 4,
        ..FormulaConfig::default()
    };
    let tc = TraceConfig {
        atoms: 1,
        p_true: 0.85,
        p_repeat: 0.4,
        len: 80,
        ..TraceConfig::default()
    };
    check(20_000..21_000, &fc, &tc);
}
