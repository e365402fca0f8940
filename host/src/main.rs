//! The `hindsight` command line: parses arguments, dispatches to `hindsight::cli`, maps errors to exit codes.

use std::process::ExitCode;

use clap::{Parser, Subcommand};
use hindsight::cli;

/// Check Past-MTL properties of robot models off-line (statistical model checking)
/// and on-line (runtime monitors), with the same compiled monitors.
///
/// Exit codes: 0 done; 1 failed for another reason (I/O); 2 bad input (a model,
/// property, spec or trace that does not parse or check, or a bad argument).
#[derive(Debug, Parser)]
#[command(name = "hindsight", version, about, long_about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Compile a spec (.hspec) into a monitor table, Rust source, or print its networks.
    ///
    /// Example: `hindsight compile examples/specs/museum.hspec --emit rust -o museum.rs`
    Compile(cli::compile::CompileArgs),
    /// Run a spec's monitors over a CSV trace and print the verdict at every point.
    ///
    /// Example: `hindsight replay examples/specs/museum.hspec trace.csv --changes`
    Replay(cli::replay::ReplayArgs),
    /// Estimate each guarantee's probability on a model (statistical model checking).
    ///
    /// The model is a robot model (a main file with a BehaviorTree.cpp tree and SCXML
    /// with ROS 2 tags, or a folder holding main.xml), a folder of plain .scxml machines
    /// (what AS2FM emits, what SCAN reads) or a SCAN model.xml; properties are SCAN XML
    /// (current or tree form, ports over ROS names, patterns) or JANI.
    /// Runs are seeded (run k uses xoshiro256++ stream k) and consumed in run order, so the
    /// same --seed gives the same numbers on any number of threads. A run stops early only
    /// when every verdict can no longer change. Progress goes to standard error: a bar on a
    /// terminal, a line every 30 s on a log (none with --json).
    ///
    /// Example: `hindsight verify examples/museum-scxml --seed 7`
    Verify(cli::verify::VerifyArgs),
    /// Check that a model and its properties load and compile, without simulating.
    ///
    /// A model with no property file (none given, none found) is checked alone.
    ///
    /// Example: `hindsight validate examples/museum-scxml`
    Validate(cli::verify::ValidateArgs),
    /// Success rate of each bounded guarantee as its time bounds sweep a range: CSV, the
    /// thresholds, and an SVG chart.
    ///
    /// Every bound in a guarantee's formula takes each swept value (steps, or durations
    /// like 6.2s when the model has a time unit), all values judged on the same runs; the
    /// threshold is the smallest bound from which every run succeeds.
    ///
    /// Example: `hindsight sweep examples/museum-guide --from 0.1s --to 7s --svg sweep.svg`
    Sweep(cli::sweep::SweepArgs),
    /// Write one self-contained HTML page from a study's JSON, sweeps' JSON and failing runs.
    ///
    /// Example: `hindsight report --study study.json failing-runs/ -o report.html`
    Report(cli::report::ReportArgs),
    /// Combine the partial results of `verify --shard I/N --runs R` into one report.
    ///
    /// Example: `hindsight merge part-0.json part-1.json`
    Merge(cli::verify::MergeArgs),
    /// Replay one run of a study (run k of --seed) and print every point as CSV: time,
    /// step, event, origin, target, parameters, every property variable and verdict.
    ///
    /// A model with no property file has a trace too: its messages alone.
    ///
    /// Example: `hindsight trace examples/museum-scxml --run 3 --seed 1 -o run3.csv`
    Trace(cli::verify::TraceArgs),
    /// Write a robot model (main file, behavior tree, SCXML with ROS tags) as the plain
    /// SCXML machines hindsight simulates, a SCAN model.xml and the properties (ROS names
    /// resolved to machines, bounds in steps; JANI files copied), for other tools.
    ///
    /// Example: `hindsight convert examples/museum-guide --out museum-plain`
    Convert(cli::convert::ConvertArgs),
    /// Monitor a running system on-line: tap iceoryx2 services, judge every sample, report verdicts.
    ///
    /// Example: `hindsight monitor --model examples/museum-guide --config museum.toml --record in.jsonl`
    Monitor(cli::monitor::MonitorArgs),
    /// Run one seeded simulation of a model live, paced in wall-clock time, publishing its
    /// ROS messages over iceoryx2 (for `hindsight monitor`); real processes can play its
    /// node models (--external).
    ///
    /// Example: `hindsight run examples/museum-guide --speed 10 --prefix museum`
    Run(cli::run::RunArgs),
}

/// Ends the process quietly (exit code 1, the documented code for I/O) when printing to
/// standard output or error fails, as when a reader closed the pipe (`hindsight ... |
/// head -1`): the `print!` family panics then, and a panic's message and exit code 101
/// would claim a bug. Every other panic keeps the default report.
fn quiet_on_closed_output() {
    let default = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        let payload = info.payload();
        let message = payload
            .downcast_ref::<String>()
            .map(String::as_str)
            .or_else(|| payload.downcast_ref::<&str>().copied())
            .unwrap_or("");
        // std's message for a failed `print!`/`eprint!` ("failed printing to stdout: ...").
        if message.starts_with("failed printing to std") {
            std::process::exit(1);
        }
        default(info);
    }));
}

fn main() -> ExitCode {
    quiet_on_closed_output();
    let cli = match Cli::try_parse() {
        Ok(c) => c,
        Err(e) => {
            let code = if e.use_stderr() { 2 } else { 0 };
            let _ = e.print();
            return ExitCode::from(code);
        }
    };
    let result = match &cli.command {
        Command::Compile(a) => cli::compile::run(a),
        Command::Replay(a) => cli::replay::run(a),
        Command::Verify(a) => cli::verify::run(a),
        Command::Validate(a) => cli::verify::validate(a),
        Command::Sweep(a) => cli::sweep::run(a),
        Command::Report(a) => cli::report::run(a),
        Command::Merge(a) => cli::verify::merge(a),
        Command::Trace(a) => cli::verify::trace(a),
        Command::Convert(a) => cli::convert::run(a),
        Command::Monitor(a) => cli::monitor::run(a),
        Command::Run(a) => cli::run::run(a),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            // A closed standard error must not turn bad input (2) into a crash.
            use std::io::Write;
            let _ = writeln!(std::io::stderr(), "{e}");
            ExitCode::from(e.exit_code())
        }
    }
}
