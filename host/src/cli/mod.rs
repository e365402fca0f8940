//! The `hindsight` subcommands, one module each; `main.rs` only parses arguments and dispatches.

pub mod compile;
pub mod convert;
pub mod monitor;
pub mod monitor_ros2;
pub mod progress;
pub mod replay;
pub mod report;
pub mod run;
pub mod sweep;
pub mod verify;

use std::collections::BTreeSet;
use std::fmt;

use codegen::diag::{Diagnostic, Diagnostics, Severity};

use crate::codegen;
use crate::verify::load::ExternalComponent;
use crate::verify::load::{LoadError, LoadOptions, Loaded};

/// How a subcommand failed, mapped to the documented exit codes.
#[derive(Debug)]
pub enum CliError {
    /// Bad input (a file that does not parse, a bad argument): exit code 2.
    Input(String),
    /// Anything else that stopped the command (I/O on output): exit code 1.
    Failed(String),
    /// Stopped by Ctrl-C or SIGTERM after printing what it had (`verify`'s partial
    /// study): exit code 130, the shell's code for a SIGINT.
    Interrupted(String),
}

impl CliError {
    /// The process exit code for this error.
    pub fn exit_code(&self) -> u8 {
        match self {
            CliError::Input(_) => 2,
            CliError::Failed(_) => 1,
            CliError::Interrupted(_) => 130,
        }
    }
}

impl fmt::Display for CliError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            CliError::Input(m) | CliError::Failed(m) | CliError::Interrupted(m) => {
                f.write_str(m.trim_end())
            }
        }
    }
}

/// Errors in the files read: exit code 2.
impl From<Diagnostics> for CliError {
    fn from(d: Diagnostics) -> CliError {
        CliError::Input(d.to_string())
    }
}

/// An error in a file read: exit code 2.
impl From<Diagnostic> for CliError {
    fn from(d: Diagnostic) -> CliError {
        CliError::Input(d.to_string())
    }
}

/// A model or property file that does not load, or an option that does not fit it:
/// exit code 2.
impl From<LoadError> for CliError {
    fn from(e: LoadError) -> CliError {
        CliError::Input(e.to_string())
    }
}

/// Prints warnings to standard error, each as `warning: file:line:col: message` and its
/// source line: the first `codegen::diag::MAX_SHOWN`, then how many more (a file with
/// thousands of ignored attributes stays readable). The libraries return warnings;
/// this is where the commands print them.
pub fn print_warnings(warnings: &Diagnostics) {
    print_new_warnings(warnings, &mut BTreeSet::new());
}

/// [`print_warnings`] for those not in `said` (their printed text), adding them to it: a
/// command that compiles the same file more than once (`sweep`, once per property) says
/// each warning once.
pub fn print_new_warnings(warnings: &Diagnostics, said: &mut BTreeSet<String>) {
    let mut shown = 0usize;
    let mut more = 0usize;
    for w in warnings {
        let text = warning_text(w);
        if !said.insert(text.clone()) {
            continue;
        }
        if shown < codegen::diag::MAX_SHOWN {
            eprintln!("warning: {text}");
            shown += 1;
        } else {
            more += 1;
        }
    }
    if more > 0 {
        eprintln!("warning: ... and {more} more warnings");
    }
}

/// A warning as [`print_new_warnings`] prints it after `warning: ` (and keeps it in
/// `said`): the position first, then the message and its source line.
pub fn warning_text(w: &Diagnostic) -> String {
    Diagnostic {
        severity: Severity::Error,
        ..w.clone()
    }
    .to_string()
}

/// Loads a model and its properties ([`crate::verify::load::load`]) and prints the
/// warnings found on the way.
pub fn load_model(opts: &LoadOptions) -> Result<Loaded, CliError> {
    let loaded = crate::verify::load::load(opts)?;
    print_warnings(&loaded.warnings);
    Ok(loaded)
}

/// [`load_model`] without the node models named in `external`
/// ([`crate::verify::load::load_without`]).
pub fn load_model_without(
    opts: &LoadOptions,
    external: &[String],
) -> Result<(Loaded, Vec<ExternalComponent>), CliError> {
    let (loaded, components) = crate::verify::load::load_without(opts, external)?;
    print_warnings(&loaded.warnings);
    Ok((loaded, components))
}

/// A count of runs given on the command line: a whole number, at least 1 (a study of
/// no runs estimates nothing).
pub fn run_count(s: &str) -> Result<u64, String> {
    match s.trim().parse::<u64>() {
        Ok(0) => Err("must be at least 1 (a study of no runs estimates nothing)".into()),
        Ok(n) => Ok(n),
        Err(e) => Err(format!("not a whole number of runs ({e})")),
    }
}

/// `--max-steps`: a whole number, at least 1 (a run cut before its first step judges
/// nothing, and a study of such runs would stop after 1,000 of them saying so).
pub fn step_limit(s: &str) -> Result<u64, String> {
    match s.trim().parse::<u64>() {
        Ok(0) => Err("must be at least 1 (a run cut before its first step judges nothing)".into()),
        Ok(n) => Ok(n),
        Err(e) => Err(format!("not a whole number of steps ({e})")),
    }
}

/// `--threads`: 0 (every core) up to [`crate::verify::smc::MAX_THREADS`]. A study's numbers
/// do not depend on the count, and each worker is an OS thread: a count past that is a
/// typo, not a wish (`--threads 100000000` tried to start as many).
pub fn thread_count(s: &str) -> Result<usize, String> {
    let max = crate::verify::smc::MAX_THREADS;
    match s.trim().parse::<usize>() {
        Ok(n) if n <= max => Ok(n),
        Ok(n) => Err(format!(
            "{n} worker threads: at most {max} (0 uses every core; the numbers do not depend on it)"
        )),
        Err(e) => Err(format!("not a whole number of threads ({e})")),
    }
}

/// Reads a whole text file (a spec, trace, study, log or config) with the project's one
/// source reader, `codegen::diag::read_source`: a folder, FIFO or device is refused
/// without being opened, a UTF-8 byte order mark is dropped, and a byte that is not
/// UTF-8 is reported at its `file:line:col`.
pub fn read_file(path: &std::path::Path) -> Result<String, CliError> {
    codegen::diag::read_source(path).map_err(|d| CliError::Input(d.to_string()))
}

/// Writes `bytes` to `path` whole or not at all: into a temporary file in the same
/// folder, then renamed over `path` (a rename within a folder is atomic), so a write
/// that is interrupted (Ctrl-C, a full disk, a file-size limit) leaves any earlier file
/// at `path` as it was and never a truncated one.
pub fn write_whole(path: &std::path::Path, bytes: &[u8]) -> std::io::Result<()> {
    let name = path
        .file_name()
        .ok_or_else(|| std::io::Error::other("not a file name"))?;
    let mut tmp_name = std::ffi::OsString::from(".");
    tmp_name.push(name);
    tmp_name.push(format!(".tmp-{}", std::process::id()));
    let tmp = path.with_file_name(tmp_name);
    let written = std::fs::write(&tmp, bytes).and_then(|()| std::fs::rename(&tmp, path));
    if written.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    written
}

/// Compiles a `.hspec` file ([`crate::verify::spec::compile_spec_file`]), printing its
/// warnings to stderr.
pub fn compile_spec_file(path: &std::path::Path) -> Result<codegen::Compiled, CliError> {
    let compiled = crate::verify::spec::compile_spec_file(path)?;
    print_spec_warnings(&compiled);
    Ok(compiled)
}

/// Prints a compiled spec's warnings to stderr, as `compile`, `replay` and `monitor` do.
pub fn print_spec_warnings(compiled: &codegen::Compiled) {
    if !compiled.warnings().is_empty() {
        eprint!("{}", compiled.warnings());
    }
}
