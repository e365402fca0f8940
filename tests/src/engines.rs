//! Running a compiled spec through monitor-core's engines, and comparing verdicts with expectations.
//!
//! - [`values`]: the corpus's valuations ([`Val`]) as `monitor_core::Value`s of a
//!   compiled spec (strings that are no constant get fresh ids, distinct per text).
//! - [`run_monitor`]: a trace through a [`Monitor`], one result per point.
//! - [`run_interpreter`] / [`run_table`]: the program as built by codegen, and as
//!   loaded back from its postcard table with [`Table::from_bytes`].
//! - [`first_difference`]: where an engine's results leave the expected verdicts.

use std::collections::HashMap;

use codegen::Compiled;
use monitor_core::table::Table;
use monitor_core::{Monitor, Program, StepError, TableError, Value};

use crate::trace::{Decls, Val};

/// An engine's result at one point: the verdicts of every property, or its error.
pub type Verdicts = Result<Vec<bool>, StepError>;

/// Capacity of the tables the tests load (every vector of a table holds at most this many items).
pub const TABLE_CAPACITY: usize = 1024;

/// The valuations `vals` (in `decls` order) as values of `compiled`'s variables, in its order.
///
/// A string equal to a constant of the spec gets that constant's id; every
/// other distinct text gets its own id past the constants, so two variables
/// holding the same unknown text still compare equal.
pub fn values(
    compiled: &Compiled,
    decls: &Decls,
    vals: &[Vec<Val>],
) -> Result<Vec<Vec<Value>>, String> {
    let order = var_order(compiled, decls)?;
    let mut extra: HashMap<String, u32> = HashMap::new();
    let constants = compiled.strings().len() as u32;
    let mut id = |s: &str| match compiled.string_id(s) {
        Some(id) => id,
        None => {
            let next = constants + extra.len() as u32;
            *extra.entry(s.to_string()).or_insert(next)
        }
    };
    vals.iter()
        .map(|point| {
            order
                .iter()
                .map(|&k| {
                    Ok(match &point[k] {
                        Val::Bool(b) => Value::Bool(*b),
                        Val::Int(n) => Value::Int(
                            i64::try_from(*n).map_err(|_| format!("{n} does not fit an i64"))?,
                        ),
                        Val::Float(x) => Value::Float(*x),
                        Val::Str(s) => Value::Str(id(s)),
                    })
                })
                .collect()
        })
        .collect()
}

/// For each variable of `compiled`, in order, its index in `decls`.
pub fn var_order(compiled: &Compiled, decls: &Decls) -> Result<Vec<usize>, String> {
    let order: Vec<usize> = compiled
        .vars()
        .iter()
        .map(|v| {
            decls
                .index(&v.name)
                .ok_or_else(|| format!("codegen variable `{}` is not in the declarations", v.name))
        })
        .collect::<Result<_, _>>()?;
    if order.len() != decls.vars.len() {
        return Err(format!(
            "codegen has {} variables, the declarations {}",
            order.len(),
            decls.vars.len()
        ));
    }
    Ok(order)
}

/// Runs one trace through `monitor` from a fresh state: one result per point.
pub fn run_monitor(monitor: &Monitor<'_>, times: &[u64], vals: &[Vec<Value>]) -> Vec<Verdicts> {
    let mut state = vec![0u64; monitor.state_words()];
    let mut verdicts = vec![false; monitor.properties()];
    // A fresh buffer is the reset state; `reset` is exercised by callers that reuse one.
    times
        .iter()
        .zip(vals)
        .map(|(&t, v)| {
            monitor
                .try_step(&mut state, t, v, &mut verdicts)
                .map(|()| verdicts.clone())
        })
        .collect()
}

/// Runs one trace through the table interpreter on `program`.
pub fn run_interpreter(
    program: Program<'_>,
    times: &[u64],
    vals: &[Vec<Value>],
) -> Result<Vec<Verdicts>, TableError> {
    Ok(run_monitor(&Monitor::try_new(program)?, times, vals))
}

/// Loads `bytes` with [`Table::from_bytes`] and runs one trace through it.
pub fn run_table(
    bytes: &[u8],
    times: &[u64],
    vals: &[Vec<Value>],
) -> Result<Vec<Verdicts>, TableError> {
    let table = load_table(bytes)?;
    Ok(run_monitor(&table.monitor()?, times, vals))
}

/// A postcard table loaded into a box (the fixed-capacity vectors are large).
pub fn load_table(bytes: &[u8]) -> Result<Box<Table<'_, TABLE_CAPACITY>>, TableError> {
    Table::<TABLE_CAPACITY>::from_bytes(bytes).map(Box::new)
}

/// The first point where `got` (one result per point, property `prop`) differs
/// from `want`, with what the engine said there; `None` when they agree
/// everywhere (a result list of another length differs at its end).
pub fn first_difference(got: &[Verdicts], prop: usize, want: &[bool]) -> Option<(usize, String)> {
    let n = got.len().max(want.len());
    (0..n).find_map(|i| {
        let said = match got.get(i) {
            None => return Some((i, "no result".to_string())),
            Some(Err(e)) => return Some((i, format!("error {e:?}"))),
            Some(Ok(v)) => match v.get(prop) {
                Some(&b) => b,
                None => return Some((i, format!("{} verdicts", v.len()))),
            },
        };
        match want.get(i) {
            Some(&w) if w == said => None,
            _ => Some((i, tf(&[said]))),
        }
    })
}

/// Verdicts as a `T`/`F` string, as the corpus writes them.
pub fn tf(v: &[bool]) -> String {
    v.iter().map(|&b| if b { 'T' } else { 'F' }).collect()
}

/// One property's verdicts (`?` at a point with an error), for messages.
pub fn tf_results(got: &[Verdicts], prop: usize) -> String {
    got.iter()
        .map(|r| match r.as_ref().ok().and_then(|v| v.get(prop)) {
            Some(true) => 'T',
            Some(false) => 'F',
            None => '?',
        })
        .collect()
}
