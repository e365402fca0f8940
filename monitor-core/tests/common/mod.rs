//! Hand-built programs shared by monitor-core's integration tests.
#![allow(dead_code)] // Each test binary uses part of the shared helpers.

use monitor_core::{Atom, Instr, Node, Op, Program, Property, Ty, Value, Var, VarKind};

/// Variables `p` and `q`, both events.
pub static VARS: [Var<'static>; 2] = [
    Var {
        name: "p",
        ty: Ty::Bool,
        kind: VarKind::Event,
        init: Value::Bool(false),
    },
    Var {
        name: "q",
        ty: Ty::Bool,
        kind: VarKind::Event,
        init: Value::Bool(false),
    },
];

/// Atoms `{p}` and `{q}`.
pub static INSTRS: [Instr; 2] = [Instr::Load(0), Instr::Load(1)];
/// The two atoms.
pub static ATOMS: [Atom; 2] = [Atom { start: 0, len: 1 }, Atom { start: 1, len: 1 }];

/// Builds the nodes of `{p} S[lo:hi] {q}` as the single property, slots laid out canonically.
pub fn since_nodes(lo: u64, hi: Option<u64>) -> [Node; 3] {
    let first = monitor_core::layout::first_node_word(2, 3) as u32;
    let words = monitor_core::layout::node_words(&Op::Since {
        lhs: 0,
        rhs: 1,
        lo,
        hi,
    })
    .unwrap();
    [
        Node {
            op: Op::Atom(0),
            slot: 0,
        },
        Node {
            op: Op::Atom(1),
            slot: 0,
        },
        Node {
            op: Op::Since {
                lhs: 0,
                rhs: 1,
                lo,
                hi,
            },
            slot: if words == 0 { 0 } else { first },
        },
    ]
}

/// The one property over `since_nodes`.
pub static PROPS: [Property<'static>; 1] = [Property {
    name: "s",
    first: 0,
    root: 2,
}];

/// A program over the given nodes with the shared variables and atoms.
pub fn program(nodes: &[Node]) -> Program<'_> {
    Program {
        tick_ns: 1_000_000,
        vars: &VARS,
        strings: &[],
        instrs: &INSTRS,
        atoms: &ATOMS,
        nodes,
        props: &PROPS,
    }
}

/// A small deterministic generator (xorshift64*), enough for test traces.
pub struct Rng(pub u64);

impl Rng {
    /// The next 64 random bits.
    pub fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }
    /// True with probability `num / 100`.
    pub fn chance(&mut self, num: u64) -> bool {
        self.next() % 100 < num
    }
}
