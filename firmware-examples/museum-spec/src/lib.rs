//! The museum guide's battery properties as a hand-lowered monitor-core [`Program`], a replay trace, and their byte encodings.
//!
//! # Pipeline
//!
//! Until `hindsight compile` exists, this crate stands in for its output:
//!
//! - [`PROGRAM`]: three Past-MTL properties ([`FORMULAS`]) lowered by hand to
//!   a sequential network (`P[I] f = true S[I] f`, `H f = !(true S !f)`), node
//!   slots laid out as [`monitor_core::layout`] requires (checked by
//!   `Monitor::try_new` in the host check and at start-up in the firmware).
//! - [`TRACE`]: a deterministic replay of a robot whose battery publisher
//!   stalls for a while and which docks twice, computed at compile time into
//!   a `static` array of points (timestamp, one value per variable).
//! - [`trace`]: a small byte format for traces, so that firmware can replay a
//!   trace it was not compiled for; [`table_bytes`] / [`trace_bytes`]
//!   (feature `encode`) write the program and the trace as bytes.
//!
//! The firmware (`monitor-static`, `monitor-table`) and the host check use the
//! same items, so the verdicts they compare come from one source.
//!
//! # Crate features
//!
//! - `encode`: [`table_bytes`] and [`trace_bytes`], for build scripts and host tools (needs `alloc`).
#![no_std]

#[cfg(feature = "encode")]
extern crate alloc;

pub mod trace;

use monitor_core::{Atom, CmpOp, Instr, Node, Op, Program, Property, Ty, Value, Var, VarKind};

/// Number of declared variables (the length of every [`Point::values`]).
pub const VARS: usize = 3;

/// Number of properties, and so of verdicts per point.
pub const PROPS: usize = 3;

/// State words [`PROGRAM`] needs (`Monitor::state_words`), checked by the host test.
pub const STATE_WORDS: usize = 11;

/// The specification each property of [`PROGRAM`] was lowered from, in property order.
pub const FORMULAS: [&str; PROPS] = [
    "H(P[10:] true -> P[:10] {battery_published})",
    "H({dock_requested} -> P[1:20] {battery_level <= 30})",
    "P[:10] {battery_published}",
];

const fn node(op: Op, slot: u32) -> Node {
    Node { op, slot }
}

const fn since(lhs: u16, rhs: u16, lo: u64, hi: Option<u64>) -> Op {
    Op::Since { lhs, rhs, lo, hi }
}

/// The three museum properties, lowered by hand.
///
/// State words: 0 is the last timestamp, 1 the atom bits, 2 the node value
/// bits (19 nodes), then the nodes' own words from word 3 on.
pub static PROGRAM: Program<'static> = Program {
    tick_ns: 1_000_000_000,
    vars: &[
        Var {
            name: "battery_published",
            ty: Ty::Bool,
            kind: VarKind::Event,
            init: Value::Bool(false),
        },
        Var {
            name: "battery_level",
            ty: Ty::Int,
            kind: VarKind::State,
            init: Value::Int(100),
        },
        Var {
            name: "dock_requested",
            ty: Ty::Bool,
            kind: VarKind::Event,
            init: Value::Bool(false),
        },
    ],
    strings: &[],
    instrs: &[
        Instr::Load(0),
        Instr::Load(1),
        Instr::Push(Value::Int(30)),
        Instr::Cmp(CmpOp::Le, Ty::Int),
        Instr::Load(2),
    ],
    atoms: &[
        // {battery_published}
        Atom { start: 0, len: 1 },
        // {battery_level <= 30}
        Atom { start: 1, len: 3 },
        // {dock_requested}
        Atom { start: 4, len: 1 },
    ],
    nodes: &[
        // H(P[10:] true -> P[:10] {battery_published})
        node(Op::Const(true), 0),          // 0: true
        node(since(0, 0, 10, None), 3),    // 1: P[10:] true (oldest witness)
        node(Op::Atom(0), 0),              // 2: {battery_published}
        node(since(0, 2, 0, Some(10)), 4), // 3: P[:10] {battery_published} (newest witness)
        node(Op::Implies(1, 3), 0),        // 4
        node(Op::Not(4), 0),               // 5
        node(since(0, 5, 0, None), 0),     // 6: P !(..) (its own value bit)
        node(Op::Not(6), 0),               // 7: H(..)
        // H({dock_requested} -> P[1:20] {battery_level <= 30})
        node(Op::Const(true), 0),           // 8
        node(Op::Atom(2), 0),               // 9: {dock_requested}
        node(Op::Atom(1), 0),               // 10: {battery_level <= 30}
        node(since(8, 10, 1, Some(20)), 5), // 11: P[1:20]: header + 2 runs = 5 words
        node(Op::Implies(9, 11), 0),        // 12
        node(Op::Not(12), 0),               // 13
        node(since(8, 13, 0, None), 0),     // 14
        node(Op::Not(14), 0),               // 15: H(..)
        // P[:10] {battery_published}
        node(Op::Const(true), 0),             // 16
        node(Op::Atom(0), 0),                 // 17
        node(since(16, 17, 0, Some(10)), 10), // 18
    ],
    props: &[
        Property {
            name: "battery_published_every_10",
            first: 0,
            root: 7,
        },
        Property {
            name: "dock_only_after_low_battery",
            first: 8,
            root: 15,
        },
        Property {
            name: "battery_fresh",
            first: 16,
            root: 18,
        },
    ],
};

/// One point of a replayed trace.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Point {
    /// Timestamp in the program's time unit (seconds here); non-decreasing.
    pub time: u64,
    /// The value of every variable at this point, in [`Program::vars`] order.
    pub values: [Value; VARS],
}

/// Last timestamp of [`TRACE`].
const END: u64 = 120;

/// The battery publisher is silent strictly between these two times.
const STALL: (u64, u64) = (40, 56);

/// Writes point `n` when `out` has room, and returns `n + 1`.
const fn push(
    out: &mut [Point],
    n: usize,
    time: u64,
    published: bool,
    level: i64,
    dock: bool,
) -> usize {
    if n < out.len() {
        out[n] = Point {
            time,
            values: [Value::Bool(published), Value::Int(level), Value::Bool(dock)],
        };
    }
    n + 1
}

/// The museum robot's run, one time unit at a time: a time-advance point
/// every unit, then (at the same timestamp, as super-dense micro-steps) a
/// battery message every 4 units except during the stall, and dock requests at
/// 76 (battery low 4 units earlier) and 118 (no low reading for 39 units).
/// The battery drains 1 % per unit and charges 4 % per unit once docked.
/// Writes as many points as fit into `out` and returns the total count.
const fn simulate(out: &mut [Point]) -> usize {
    let mut n = 0;
    let mut level: i64 = 100;
    let mut published: i64 = 100;
    let mut charging = false;
    let mut t = 0;
    while t <= END {
        n = push(out, n, t, false, published, false);
        if t % 4 == 0 && !(t > STALL.0 && t < STALL.1) {
            published = level;
            n = push(out, n, t, true, published, false);
        }
        if t == 76 || t == 118 {
            n = push(out, n, t, false, published, true);
            charging = true;
        }
        level = if charging {
            if level + 4 > 100 {
                100
            } else {
                level + 4
            }
        } else {
            level - 1
        };
        t += 1;
    }
    n
}

/// Number of points in [`TRACE`].
pub const TRACE_LEN: usize = simulate(&mut []);

/// The replayed trace, computed at compile time (see `simulate`).
pub static TRACE: [Point; TRACE_LEN] = {
    let mut points = [Point {
        time: 0,
        values: [Value::Bool(false); VARS],
    }; TRACE_LEN];
    simulate(&mut points);
    points
};

/// The postcard table of [`PROGRAM`], as `Table::from_bytes` reads it.
#[cfg(feature = "encode")]
pub fn table_bytes() -> alloc::vec::Vec<u8> {
    // Serialising plain data into a Vec cannot fail.
    postcard::to_allocvec(&(monitor_core::table::TABLE_VERSION, &PROGRAM))
        .unwrap_or_else(|e| panic!("encoding the museum table: {e}"))
}

/// [`TRACE`] in the [`trace`] byte format.
#[cfg(feature = "encode")]
pub fn trace_bytes() -> alloc::vec::Vec<u8> {
    // Every point of TRACE has VARS values, so encoding cannot fail.
    trace::encode(TRACE.iter().map(|p| (p.time, &p.values[..])))
        .unwrap_or_else(|e| panic!("encoding the museum trace: {e}"))
}
