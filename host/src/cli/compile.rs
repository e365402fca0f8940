//! `hindsight compile`: a spec file to a monitor table, Rust source or the printed IR.

use std::io::Write;
use std::path::PathBuf;

use super::{compile_spec_file, CliError};

/// What `compile` writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Emit {
    /// The postcard table that `monitor_core::table::Table::from_bytes` loads.
    Table,
    /// The compiled networks, one line per node, with state sizes.
    Ir,
}

/// Arguments of `hindsight compile`.
#[derive(Debug, clap::Args)]
pub struct CompileArgs {
    /// The specification (`.hspec`): unit, variables, properties.
    pub spec: PathBuf,
    /// What to produce.
    #[arg(long, value_enum, default_value_t = Emit::Ir)]
    pub emit: Emit,
    /// Output file; standard output when absent.
    #[arg(short, long)]
    pub output: Option<PathBuf>,
}

/// Runs `hindsight compile`.
pub fn run(args: &CompileArgs) -> Result<(), CliError> {
    let compiled = compile_spec_file(&args.spec)?;
    let bytes = match args.emit {
        Emit::Table => compiled.to_table_bytes(),
        Emit::Ir => compiled.ir().into_bytes(),
    };
    match &args.output {
        Some(path) => std::fs::write(path, &bytes)
            .map_err(|e| CliError::Failed(format!("{}: cannot write: {e}", path.display())))?,
        None => std::io::stdout()
            .write_all(&bytes)
            .map_err(|e| CliError::Failed(format!("standard output: {e}")))?,
    }
    Ok(())
}
