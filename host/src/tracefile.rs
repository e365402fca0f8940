//! Trace files: one point per CSV row, the column values applied with event/state semantics.
//!
//! Format: a header `time,NAME,NAME,...` naming declared variables (any subset, any
//! order), then one row per point. `time` is a non-negative integer in the spec's
//! time unit, non-decreasing (equal values are micro-steps). A cell sets its
//! variable at that point; an empty cell leaves a state variable unchanged and an
//! event variable false. Values: `true`/`false` (or `1`/`0`) for booleans,
//! integers, floats, and strings (optionally in double quotes, `""` for a quote).
//! Lines starting with `#` and blank lines are skipped.
//!
//! The columns that `hindsight trace` and `verify --save-failing` add around the
//! variables (`step`, `event`, `origin`, `target`, `params`, `verdict_NAME`) are skipped
//! unless the spec declares a variable of that name, so a recorded run replays as is.

use codegen::Compiled;
use monitor_core::{Ty, Value};

/// One point of a trace: its timestamp and the variables it sets.
#[derive(Clone, Debug, PartialEq)]
pub struct TracePoint {
    /// Timestamp in the spec's time unit.
    pub time: u64,
    /// `(variable index, value)` for every non-empty cell.
    pub sets: Vec<(usize, Value)>,
    /// The row's line in the file, from 1.
    pub line: usize,
}

/// Parses a CSV trace against a compiled spec's variables; errors name `file:line:col`.
pub fn parse_csv(text: &str, file: &str, spec: &Compiled) -> Result<Vec<TracePoint>, String> {
    let mut lines = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty() && !l.trim_start().starts_with('#'));
    let Some((hline, header)) = lines.next() else {
        return Err(format!(
            "{file}:1:1: empty trace: expected a header `time,VAR,...`"
        ));
    };
    let cols = split_row(header).map_err(|(c, m)| format!("{file}:{}:{c}: {m}", hline + 1))?;
    if cols.first().map(|(_, s)| s.trim()) != Some("time") {
        return Err(format!(
            "{file}:{}:1: the first column must be `time`",
            hline + 1
        ));
    }
    // `None` marks a recorder column that is skipped.
    let mut vars: Vec<Option<usize>> = Vec::new();
    for (col, name) in &cols[1..] {
        let name = name.trim();
        match spec.var_index(name) {
            Some(i) if !vars.contains(&Some(i)) => vars.push(Some(i)),
            Some(_) => {
                return Err(format!(
                    "{file}:{}:{col}: column `{name}` repeated",
                    hline + 1
                ))
            }
            None if is_recorder_column(name) => vars.push(None),
            None => {
                return Err(format!(
                    "{file}:{}:{col}: `{name}` is not a variable of the spec",
                    hline + 1
                ))
            }
        }
    }
    let mut points = Vec::new();
    let mut last = 0u64;
    for (lno, line) in lines {
        let at = |c: usize, m: String| format!("{file}:{}:{c}: {m}", lno + 1);
        let cells = split_row(line).map_err(|(c, m)| at(c, m))?;
        if cells.len() != cols.len() {
            return Err(at(
                1,
                format!("{} cells, the header has {}", cells.len(), cols.len()),
            ));
        }
        let (tc, ts) = &cells[0];
        let time: u64 = ts.trim().parse().map_err(|_| {
            at(
                *tc,
                format!(
                    "`{}` is not a timestamp (a non-negative integer)",
                    ts.trim()
                ),
            )
        })?;
        if time < last {
            return Err(at(
                *tc,
                format!("timestamp {time} is before the previous point's {last}"),
            ));
        }
        last = time;
        let mut sets = Vec::new();
        for ((col, cell), &var) in cells[1..].iter().zip(&vars) {
            let Some(var) = var else { continue };
            if cell.trim().is_empty() {
                continue;
            }
            let value = parse_value(cell.trim(), spec, var).map_err(|m| at(*col, m))?;
            sets.push((var, value));
        }
        points.push(TracePoint {
            time,
            sets,
            line: lno + 1,
        });
    }
    Ok(points)
}

/// A column that `hindsight trace` writes beside the variables.
fn is_recorder_column(name: &str) -> bool {
    matches!(name, "step" | "event" | "origin" | "target" | "params")
        || name.starts_with("verdict_")
}

fn parse_value(cell: &str, spec: &Compiled, var: usize) -> Result<Value, String> {
    let decl = &spec.vars()[var];
    let bad = || {
        format!(
            "`{cell}` is not a value of type `{}` for `{}`",
            decl.type_name, decl.name
        )
    };
    match decl.ty {
        Ty::Bool => match cell {
            "true" | "1" => Ok(Value::Bool(true)),
            "false" | "0" => Ok(Value::Bool(false)),
            _ => Err(bad()),
        },
        Ty::Int => cell.parse().map(Value::Int).map_err(|_| bad()),
        Ty::Float => cell.parse().map(Value::Float).map_err(|_| bad()),
        // Strings the spec never mentions get an id past every constant: equal to none.
        Ty::Str => Ok(Value::Str(spec.string_id(cell).unwrap_or(u32::MAX))),
    }
}

/// Splits one CSV row into `(column number, cell)`; quoted cells may hold commas.
fn split_row(line: &str) -> Result<Vec<(usize, String)>, (usize, String)> {
    let mut out = Vec::new();
    let mut chars = line.char_indices().peekable();
    let mut start_col = 1;
    let mut cell = String::new();
    let mut quoted = false;
    let mut was_quoted = false;
    while let Some((i, c)) = chars.next() {
        match c {
            '"' if quoted => {
                if chars.peek().map(|&(_, c)| c) == Some('"') {
                    chars.next();
                    cell.push('"');
                } else {
                    quoted = false;
                }
            }
            '"' if cell.trim().is_empty() && !was_quoted => {
                quoted = true;
                was_quoted = true;
                cell.clear();
            }
            ',' if !quoted => {
                out.push((start_col, std::mem::take(&mut cell)));
                start_col = i + 2;
                was_quoted = false;
            }
            c => cell.push(c),
        }
    }
    if quoted {
        return Err((start_col, "unterminated quoted cell".into()));
    }
    out.push((start_col, cell));
    Ok(out)
}
