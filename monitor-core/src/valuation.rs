//! Event and state variables over a trace: what a variable's value is at each point.
//!
//! A state variable keeps the last value written to it, starting from its
//! declared initial value; an event variable is `true` only at the point where
//! it is set and falls back to `false` at the next point, even at the same
//! timestamp. Callers keep one `[Value]` per program and call [`begin_point`]
//! before applying each point's updates.

use crate::program::{Value, Var, VarKind};

/// Writes every variable's initial value into `vals` (lengths must match; extra entries are left).
pub fn init(vars: &[Var<'_>], vals: &mut [Value]) {
    for (v, d) in vals.iter_mut().zip(vars) {
        *v = d.init;
    }
}

/// Starts a new point: every event variable becomes `false`, state variables keep their values.
pub fn begin_point(vars: &[Var<'_>], vals: &mut [Value]) {
    for (v, d) in vals.iter_mut().zip(vars) {
        if d.kind == VarKind::Event {
            *v = Value::Bool(false);
        }
    }
}
