//! Build script: compiles `museum.hspec` with hindsight-codegen and turns `museum-run0.csv` (a run of the museum model) into the replay trace.
//!
//! Writes into `OUT_DIR`:
//! - `museum.rs`: the generated monitor, module `museum` (`codegen::emit_rust`).
//! - `museum.postcard`: the same program as a postcard table
//!   (`Compiled::to_table_bytes`, read by `monitor_core::table::Table`).
//! - `final.postcard`: `final.hspec` as a postcard table, properties whose
//!   verdicts all become final on the run (for `monitor-final`).
//! - `museum_data.rs`: the spec's shape as the compiler reports it (variable
//!   and property counts, formulas, state bytes in total and per property),
//!   the trace as a `static` array of points, and `input`, which fills the
//!   generated monitor's `Input` from a point.
//!
//! The CSV is what `hindsight trace` prints (see the comment line at its top):
//! a `time` column and one column per variable; other columns (the recorded
//! verdicts) are ignored here. Every variable of the spec must have a column.
//! An empty cell leaves a state variable unchanged and an event false. A bad
//! spec or CSV fails the build with codegen's diagnostic
//! (`file:line:col: message` and the line with a caret).

use std::fmt::Write as _;
use std::fs;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use codegen::emit_rust::{emit_rust, input_fields, EmitOptions};
use codegen::{Compiled, Diagnostic, LineIndex, Snippet};
use monitor_core::{Ty, Value, VarKind};

const SPEC: &str = "museum.hspec";
/// Properties that all become final on the run: `monitor-final`'s table.
const FINAL_SPEC: &str = "final.hspec";
const TRACE: &str = "museum-run0.csv";

fn main() -> ExitCode {
    match run() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("{e}");
            ExitCode::FAILURE
        }
    }
}

fn run() -> Result<(), String> {
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-changed={SPEC}");
    println!("cargo:rerun-if-changed={FINAL_SPEC}");
    println!("cargo:rerun-if-changed={TRACE}");
    let out = PathBuf::from(std::env::var_os("OUT_DIR").ok_or("OUT_DIR is not set")?);
    let read = |f: &str| fs::read_to_string(f).map_err(|e| format!("{f}: {e}"));

    let compiled = codegen::compile_spec(&read(SPEC)?, SPEC).map_err(|d| d.to_string())?;
    let program = compiled.program();
    let command = format!("museum-spec/build.rs from {SPEC}");
    let source = emit_rust(&program, &EmitOptions::new("museum", command))
        .map_err(|e| format!("{SPEC}: {e}"))?;
    let points = parse_trace(&read(TRACE)?, TRACE, &compiled)?;

    write(&out.join("museum.rs"), source.as_bytes())?;
    write(&out.join("museum.postcard"), &compiled.to_table_bytes())?;
    let finals =
        codegen::compile_spec(&read(FINAL_SPEC)?, FINAL_SPEC).map_err(|d| d.to_string())?;
    let final_program = finals.program();
    let (ours, theirs) = (program.vars, final_program.vars);
    if ours.len() != theirs.len()
        || ours
            .iter()
            .zip(theirs.iter())
            .any(|(a, b)| (a.name, a.ty) != (b.name, b.ty))
    {
        return Err(format!(
            "{FINAL_SPEC}: declare the variables of {SPEC}, in its order (the trace's columns)"
        ));
    }
    write(&out.join("final.postcard"), &finals.to_table_bytes())?;
    write(
        &out.join("museum_data.rs"),
        data(&compiled, &points).as_bytes(),
    )
}

fn write(path: &Path, bytes: &[u8]) -> Result<(), String> {
    fs::write(path, bytes).map_err(|e| format!("{}: {e}", path.display()))
}

/// `msg` at `line`:`col` (from 1) of `text`, the contents of `file`, as codegen
/// renders every diagnostic: `file:line:col: msg` and the line with a caret.
fn error(file: &str, text: &str, line: usize, col: usize, msg: impl std::fmt::Display) -> String {
    let index = LineIndex::new(text);
    let (line, col) = (line as u32, col as u32);
    Diagnostic::error(file, (line, col), msg.to_string())
        .with_snippet(Snippet::at_line_col(text, &index, line, col))
        .to_string()
}

/// The CSV's points, one per data row, each with a value for every spec variable in declaration order.
fn parse_trace(
    text: &str,
    file: &str,
    compiled: &Compiled,
) -> Result<Vec<(u64, Vec<Value>)>, String> {
    let mut rows = text
        .lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l))
        .filter(|(_, l)| !l.starts_with('#') && !l.trim().is_empty());
    let (header_line, header) = rows
        .next()
        .ok_or_else(|| error(file, text, 1, 1, "no header row"))?;
    let names: Vec<&str> = header.split(',').map(str::trim).collect();
    if names.first() != Some(&"time") {
        return Err(error(
            file,
            text,
            header_line,
            1,
            "the first column must be `time`",
        ));
    }
    let vars = compiled.vars();
    let columns = vars
        .iter()
        .map(|v| {
            names.iter().position(|n| *n == v.name).ok_or_else(|| {
                error(
                    file,
                    text,
                    header_line,
                    1,
                    format!("no column for variable `{}` of {SPEC}", v.name),
                )
            })
        })
        .collect::<Result<Vec<usize>, String>>()?;

    let mut state: Vec<Value> = vars.iter().map(|v| v.init).collect();
    let mut last_time = 0;
    let mut points = Vec::new();
    for (line, row) in rows {
        let cells: Vec<&str> = row.split(',').collect();
        // Column (from 1, in characters) of each cell.
        let mut starts = Vec::with_capacity(cells.len());
        let mut at = 1;
        for c in &cells {
            starts.push(at);
            at += c.chars().count() + 1;
        }
        if cells.len() != names.len() {
            return Err(error(
                file,
                text,
                line,
                1,
                format!("{} cells, the header has {}", cells.len(), names.len()),
            ));
        }
        let time: u64 = cells[0]
            .trim()
            .parse()
            .map_err(|e| error(file, text, line, 1, format!("time {:?}: {e}", cells[0])))?;
        if time < last_time {
            return Err(error(
                file,
                text,
                line,
                1,
                format!("time {time} is before the previous point's {last_time}"),
            ));
        }
        last_time = time;
        for ((var, &col), value) in vars.iter().zip(&columns).zip(state.iter_mut()) {
            let cell = cells[col].trim();
            if var.kind == VarKind::Event {
                *value = Value::Bool(false);
            }
            if cell.is_empty() {
                continue;
            }
            let bad = |what: &str| {
                error(
                    file,
                    text,
                    line,
                    starts[col],
                    format!("`{}`: {what} {cell:?}", var.name),
                )
            };
            *value = match var.ty {
                Ty::Bool => Value::Bool(cell.parse().map_err(|_| bad("not a bool:"))?),
                Ty::Int => Value::Int(cell.parse().map_err(|_| bad("not an integer:"))?),
                Ty::Float => Value::Float(cell.parse().map_err(|_| bad("not a number:"))?),
                Ty::Str => Value::Str(
                    compiled
                        .string_id(cell)
                        .unwrap_or(compiled.strings().len() as u32),
                ),
            };
        }
        points.push((time, state.clone()));
    }
    if points.is_empty() {
        return Err(error(
            file,
            text,
            header_line,
            1,
            "no points after the header",
        ));
    }
    Ok(points)
}

fn value(v: &Value) -> String {
    match v {
        Value::Bool(b) => format!("Value::Bool({b})"),
        Value::Int(i) => format!("Value::Int({i})"),
        Value::Float(x) => format!("Value::Float(f64::from_bits({:#x}))", x.to_bits()),
        Value::Str(s) => format!("Value::Str({s})"),
    }
}

/// `museum_data.rs`: constants from the compiler, the trace, and the `Input` adapter.
fn data(compiled: &Compiled, points: &[(u64, Vec<Value>)]) -> String {
    let vars = compiled.vars();
    let props = compiled.properties();
    let list = |items: Vec<String>| items.join(", ");
    let mut s = String::new();
    let _ = write!(
        s,
        "// Generated by museum-spec/build.rs from {SPEC} and {TRACE}; do not edit.\n\n\
         /// Number of declared variables (the length of every [`Point::values`]).\n\
         pub const VARS: usize = {nvars};\n\
         /// Number of properties, and so of verdicts per point.\n\
         pub const PROPS: usize = {nprops};\n\
         /// The variables' names, in declaration order.\n\
         pub const VAR_NAMES: [&str; VARS] = [{var_names}];\n\
         /// Each property's formula, printed by the compiler, in property order.\n\
         pub const FORMULAS: [&str; PROPS] = [{formulas}];\n\
         /// Monitor state in bytes as the compiler lays it out (`Monitor::state_bytes` of [`TABLE`]'s program).\n\
         pub const STATE_BYTES: usize = {state};\n\
         /// State bytes owned by each property's nodes, as the compiler reports them (the shared words are not included).\n\
         pub const PROPERTY_STATE_BYTES: [usize; PROPS] = [{prop_bytes}];\n\
         /// Number of points in [`TRACE`].\n\
         pub const TRACE_LEN: usize = {npoints};\n\n\
         /// The replayed run ({TRACE}), one point per row.\n\
         pub static TRACE: [Point; TRACE_LEN] = [\n",
        nvars = vars.len(),
        nprops = props.len(),
        var_names = list(vars.iter().map(|v| format!("{:?}", v.name)).collect()),
        formulas = list(
            compiled
                .checked()
                .properties
                .iter()
                .map(|p| format!("{:?}", codegen::print::formula(&p.formula, compiled.checked())))
                .collect()
        ),
        state = compiled.state_bytes(),
        prop_bytes = list(props.iter().map(|p| p.state_bytes.to_string()).collect()),
        npoints = points.len(),
    );
    for (time, values) in points {
        let _ = writeln!(
            s,
            "    Point {{ time: {time}, values: [{}] }},",
            list(values.iter().map(value).collect())
        );
    }
    s.push_str("];\n\n");

    let fields = input_fields(&compiled.program());
    let mut sets = String::new();
    for (i, (var, field)) in vars.iter().zip(&fields).enumerate() {
        let variant = match var.ty {
            Ty::Bool => "Bool",
            Ty::Int => "Int",
            Ty::Float => "Float",
            Ty::Str => "Str",
        };
        let _ = writeln!(
            sets,
            "    if let Value::{variant}(v) = values[{i}] {{\n        input.{field} = v;\n    }}"
        );
    }
    let _ = write!(
        s,
        "/// The generated monitor's input holding `values` (a value of the wrong type leaves its field at the initial value).\n\
         pub fn input(values: &[Value; VARS]) -> museum::Input {{\n    \
             let mut input = museum::Input::new();\n{sets}    input\n}}\n"
    );
    s
}
