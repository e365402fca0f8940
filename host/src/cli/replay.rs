//! `hindsight replay`: run a spec's monitors over a recorded trace and print every verdict.

use std::io::Write;
use std::path::PathBuf;
use std::time::Instant;

use monitor_core::{valuation, Monitor, Value};

use super::{compile_spec_file, read_file, CliError};
use crate::tracefile;

/// Arguments of `hindsight replay`.
#[derive(Debug, clap::Args)]
pub struct ReplayArgs {
    /// The specification (`.hspec`).
    pub spec: PathBuf,
    /// The trace: CSV with a `time` column and one column per variable set.
    pub trace: PathBuf,
    /// Print only points where some verdict changes (and the first point).
    #[arg(long)]
    pub changes: bool,
    /// Print nothing per point; report the time per point on standard error.
    #[arg(long)]
    pub quiet: bool,
}

/// Runs `hindsight replay`: output is CSV `time,PROP,...` with `true`/`false`.
pub fn run(args: &ReplayArgs) -> Result<(), CliError> {
    let compiled = compile_spec_file(&args.spec)?;
    let text = read_file(&args.trace)?;
    let points = tracefile::parse_csv(&text, &args.trace.display().to_string(), &compiled)
        .map_err(CliError::Input)?;
    let program = compiled.program();
    let monitor = Monitor::try_new(program)
        .map_err(|e| CliError::Failed(format!("internal: compiled program rejected: {e}")))?;
    let mut state = vec![0u64; monitor.state_words()];
    let mut vals = vec![Value::Bool(false); program.vars.len()];
    valuation::init(program.vars, &mut vals);
    let mut verdicts = vec![false; monitor.properties()];
    let mut rows: Vec<(u64, Vec<bool>)> =
        Vec::with_capacity(if args.quiet { 0 } else { points.len() });
    let start = Instant::now();
    for (i, p) in points.iter().enumerate() {
        valuation::begin_point(program.vars, &mut vals);
        for &(var, v) in &p.sets {
            vals[var] = v;
        }
        monitor
            .try_step(&mut state, p.time, &vals, &mut verdicts)
            .map_err(|e| {
                CliError::Input(format!(
                    "{}:{}: point {}: {}",
                    args.trace.display(),
                    p.line,
                    i + 1,
                    compiled.describe(&e)
                ))
            })?;
        if !args.quiet && (!args.changes || rows.last().is_none_or(|(_, v)| *v != verdicts)) {
            rows.push((p.time, verdicts.clone()));
        }
    }
    let elapsed = start.elapsed();
    if args.quiet {
        let per = elapsed.as_nanos() as f64 / points.len().max(1) as f64;
        eprintln!(
            "{} points, {per:.1} ns per point, {} bytes of state",
            points.len(),
            monitor.state_bytes()
        );
        return Ok(());
    }
    let mut out = std::io::BufWriter::new(std::io::stdout().lock());
    let io = |e: std::io::Error| CliError::Failed(format!("standard output: {e}"));
    let names: Vec<&str> = compiled.property_names().collect();
    writeln!(out, "time,{}", names.join(",")).map_err(io)?;
    for (t, v) in rows {
        let cells: Vec<&str> = v
            .iter()
            .map(|b| if *b { "true" } else { "false" })
            .collect();
        writeln!(out, "{t},{}", cells.join(",")).map_err(io)?;
    }
    out.flush().map_err(io)
}
