//! Trace files: one point per CSV row, the column values applied with event/state semantics.
//!
//! Format: a header `time,NAME,NAME,...` naming declared variables (any subset, any
//! order), then one row per point. `time` is a non-negative integer in the spec's
//! time unit, non-decreasing (equal values are micro-steps). A cell sets its
//! variable at that point; an empty cell leaves a state variable unchanged and an
//! event variable false. Values: `true`/`false` (or `1`/`0`) for booleans,
//! integers, floats, and strings (optionally in double quotes, `""` for a quote).
//! Lines starting with `#` and blank lines are skipped. Quoting is the project's one CSV
//! grammar (`codegen::csv`, RFC 4180). A float cell must be finite: `NaN`, `inf` are
//! refused at their `file:line:col`.
//!
//! The columns that `hindsight trace` and `verify --save-failing` add around the
//! variables (`step`, `event`, `origin`, `target`, `params`, `verdict_NAME`) are skipped
//! unless the spec declares a variable of that name, so a recorded run replays as is.

use codegen::diag::Diagnostic;
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
/// Rows are read by the project's one CSV grammar ([`codegen::csv::records`], RFC 4180
/// quoting, what `trace` and `verify --save-failing` write); a UTF-8 byte order mark is
/// dropped.
pub fn parse_csv(text: &str, file: &str, spec: &Compiled) -> Result<Vec<TracePoint>, Diagnostic> {
    let err =
        |line: usize, col: usize, m: String| Diagnostic::error(file, (line as u32, col as u32), m);
    // Comments (`#` first) and blank lines are no rows.
    let mut rows = codegen::csv::rows(file, text)?.into_iter();
    let Some(header) = rows.next() else {
        return Err(err(
            1,
            1,
            "empty trace: expected a header `time,VAR,...`".into(),
        ));
    };
    let hline = header.line;
    let cols = header.fields;
    if cols.first().map(|(s, _)| s.trim()) != Some("time") {
        return Err(err(hline, 1, "the first column must be `time`".into()));
    }
    // `None` marks a recorder column that is skipped.
    let mut vars: Vec<Option<usize>> = Vec::new();
    for (name, col) in &cols[1..] {
        let name = name.trim();
        match spec.var_index(name) {
            Some(i) if !vars.contains(&Some(i)) => vars.push(Some(i)),
            Some(_) => return Err(err(hline, *col, format!("column `{name}` repeated"))),
            None if is_recorder_column(name) => vars.push(None),
            None => {
                return Err(err(
                    hline,
                    *col,
                    format!("`{name}` is not a variable of the spec"),
                ))
            }
        }
    }
    let mut points = Vec::new();
    let mut last = 0u64;
    for row in rows {
        let lno = row.line;
        let at = |c: usize, m: String| err(lno, c, m);
        let cells = row.fields;
        if cells.len() != cols.len() {
            return Err(at(
                1,
                format!("{} cells, the header has {}", cells.len(), cols.len()),
            ));
        }
        let (ts, tc) = &cells[0];
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
        for ((cell, col), &var) in cells[1..].iter().zip(&vars) {
            let Some(var) = var else { continue };
            if cell.trim().is_empty() {
                continue;
            }
            let value = parse_value(cell.trim(), spec, var)
                .map_err(|b| at(*col, bad_cell(b, cell.trim(), spec, var)))?;
            sets.push((var, value));
        }
        points.push(TracePoint {
            time,
            sets,
            line: lno,
        });
    }
    Ok(points)
}

/// A column that `hindsight trace` writes beside the variables.
fn is_recorder_column(name: &str) -> bool {
    matches!(name, "step" | "event" | "origin" | "target" | "params")
        || name.starts_with("verdict_")
}

/// Why a cell is no value of its column's variable.
enum BadCell {
    /// Not a literal of the variable's type.
    OfType,
    /// A NaN or an infinity for a float variable.
    NotFinite,
}

fn parse_value(cell: &str, spec: &Compiled, var: usize) -> Result<Value, BadCell> {
    match spec.vars()[var].ty {
        Ty::Bool => match cell {
            "true" | "1" => Ok(Value::Bool(true)),
            "false" | "0" => Ok(Value::Bool(false)),
            _ => Err(BadCell::OfType),
        },
        Ty::Int => cell.parse().map(Value::Int).map_err(|_| BadCell::OfType),
        // A trace records measurements: a NaN or an infinity is a broken sensor or
        // logger, not a value to judge silently (every comparison with NaN is false).
        Ty::Float => match cell.parse::<f64>() {
            Ok(x) if x.is_finite() => Ok(Value::Float(x)),
            Ok(_) => Err(BadCell::NotFinite),
            Err(_) => Err(BadCell::OfType),
        },
        // Strings the spec never mentions get an id past every constant: equal to none.
        Ty::Str => Ok(Value::Str(spec.string_id(cell).unwrap_or(u32::MAX))),
    }
}

/// What is wrong with `cell` for variable `var`, in words.
fn bad_cell(why: BadCell, cell: &str, spec: &Compiled, var: usize) -> String {
    let decl = &spec.vars()[var];
    match why {
        BadCell::OfType => format!(
            "`{cell}` is not a value of type `{}` for `{}`",
            decl.type_name, decl.name
        ),
        BadCell::NotFinite => format!(
            "`{cell}` for `{}` is not a finite number: NaN and infinities are refused \
             (every comparison with NaN is false, so a verdict over it would mean nothing)",
            decl.name
        ),
    }
}
