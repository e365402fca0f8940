//! The run-time half of hindsight's Past-MTL monitors: `no_std`, no `alloc`, fixed memory.
//!
//! # Pipeline
//!
//! A specification (variables, atoms, Past-MTL formulas) is parsed, checked
//! and compiled on the host by `hindsight-codegen` into a [`Program`]: atom
//! bytecode plus one *sequential network* per formula, nodes in topological
//! order. This crate only runs programs:
//!
//! 1. **Get a program**: generated Rust source builds one from `static` arrays,

// `pub` only where another crate can reach it: internals are `pub(crate)` (issue 27).
#![warn(unreachable_pub)]
#![cfg_attr(
    feature = "postcard",
    doc = "   or [`table::Table::from_bytes`] (feature `postcard`) decodes one from bytes."
)]
#![cfg_attr(
    not(feature = "postcard"),
    doc = "   or `table::Table::from_bytes` (feature `postcard`) decodes one from bytes."
)]
//! 2. **Validate**: [`Monitor::try_new`] checks every index, type, bound and
//!    state slot once, so that stepping cannot panic or misbehave.
//!    [`Monitor::try_new_planned`] also decides once what each node and atom
//!    does at every point, into a plan of `N` entries held in a `Monitor<'_, N>`
//!    (faster steps, same results; `plan.rs`).
//! 3. **Allocate state**: [`Monitor::state_words`] `u64` words, owned by the
//!    caller (a `static`, the stack, a `Vec` on the host); [`Monitor::reset`].
//! 4. **Step**: [`Monitor::try_step`] once per trace point with the variables'
//!    values ([`valuation`] keeps event/state semantics), or
//!    [`Monitor::try_step_atoms`] with precomputed atom bits. Each call writes
//!    one verdict per property; a timestamp that goes backwards is an
//!    [`StepError`], never a wrong verdict.
//!
//! Work per point is constant (amortised for windowed `S[a:b]`, whose runs are
//! each pushed and expired once) and memory is fixed by the formula's bounds
//! ([`layout`]).
//!
//! # Crate features
//!
//! - `serde`: `Serialize`/`Deserialize` for every program type.
#![cfg_attr(
    feature = "postcard",
    doc = "- `postcard`: [`table::Table`], a validated postcard loader (implies `serde`)."
)]
#![cfg_attr(
    not(feature = "postcard"),
    doc = "- `postcard`: `table::Table`, a validated postcard loader (implies `serde`)."
)]
//! - `defmt`: `defmt::Format` for the error types.
//! - `float` (default): atoms over `float` values. Without it a program with a
//!   float atom is rejected ([`TableError::Feature`]) and no soft-float routine
//!   is linked into the step.
//! - `compact`: one interpreter loop for programs of every size and one atom
//!   stack machine (its full depth) without its shortcuts: a smaller step for
//!   firmware, same results.
//! - `int-div` (default): integer `/` and `%` in atoms (64-bit division, a
//!   library routine on 32-bit cores); without it such a program is rejected.
#![no_std]
#![forbid(unsafe_code)]

pub mod analysis;
pub mod error;
mod expr;
pub mod layout;
mod monitor;
mod plan;
pub mod program;
#[cfg(feature = "postcard")]
pub mod table;
pub mod valuation;

#[cfg(feature = "defmt")]
mod defmt_impls;

pub use error::{StepError, TableError};
pub use expr::MAX_STACK;
pub use monitor::{Monitor, MAX_IDS};
pub use program::{
    Atom, CmpOp, Instr, Node, NodeId, NumTy, Op, Program, Property, Ty, Value, Var, VarKind,
};
