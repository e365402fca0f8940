//! `hindsight compile`: a spec file to a monitor table, Rust source or the printed IR.

use std::io::Write;
use std::path::PathBuf;

use super::{compile_spec_file, CliError};
use crate::verify::spec::{emit, module_name, Output};

/// What `compile` writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Emit {
    /// The postcard table that `monitor_core::table::Table::from_bytes` loads.
    Table,
    /// The compiled networks, one line per node, with state sizes.
    Ir,
    /// A `core`-only Rust module (straight-line monitor code) to `include!`.
    Rust,
}

impl Emit {
    /// The value as written on the command line.
    fn flag(self) -> &'static str {
        match self {
            Emit::Table => "table",
            Emit::Ir => "ir",
            Emit::Rust => "rust",
        }
    }
}

/// Arguments of `hindsight compile`.
#[derive(Debug, clap::Args)]
pub struct CompileArgs {
    /// The specification (`.hspec`): unit, variables, properties.
    pub spec: PathBuf,
    /// What to produce.
    #[arg(long, value_enum, default_value_t = Emit::Ir)]
    pub emit: Emit,
    /// Name of the generated Rust module (`--emit rust`); default: the spec
    /// file's stem as a lower-case identifier (`museum.hspec` -> `museum`).
    #[arg(long, value_name = "NAME")]
    pub module: Option<String>,
    /// Output file; standard output when absent.
    #[arg(short, long)]
    pub output: Option<PathBuf>,
}

/// Runs `hindsight compile`.
pub fn run(args: &CompileArgs) -> Result<(), CliError> {
    if args.module.is_some() && args.emit != Emit::Rust {
        return Err(CliError::Input(
            "--module only applies to --emit rust".into(),
        ));
    }
    let compiled = compile_spec_file(&args.spec)?;
    let output = match args.emit {
        Emit::Table => Output::Table,
        Emit::Ir => Output::Ir,
        Emit::Rust => Output::Rust {
            module: match &args.module {
                Some(m) => m.clone(),
                None => module_name(&args.spec),
            },
            command: command_line(args),
        },
    };
    let bytes = emit(&compiled, &output)
        .map_err(|e| CliError::Input(format!("{}: {e}", args.spec.display())))?;
    match &args.output {
        Some(path) => std::fs::write(path, &bytes)
            .map_err(|e| CliError::Failed(format!("{}: cannot write: {e}", path.display())))?,
        None => std::io::stdout()
            .write_all(&bytes)
            .map_err(|e| CliError::Failed(format!("standard output: {e}")))?,
    }
    Ok(())
}

/// The command that reproduces this output, for the generated file's header.
///
/// Built from the parsed arguments rather than the raw process arguments so
/// that the header (and so the file) does not depend on how the binary was
/// invoked.
fn command_line(args: &CompileArgs) -> String {
    let mut cmd = format!(
        "hindsight compile {} --emit {}",
        shell_word(&args.spec.display().to_string()),
        args.emit.flag()
    );
    if let Some(m) = &args.module {
        cmd.push_str(" --module ");
        cmd.push_str(&shell_word(m));
    }
    if let Some(o) = &args.output {
        cmd.push_str(" -o ");
        cmd.push_str(&shell_word(&o.display().to_string()));
    }
    cmd
}

/// `s` quoted for a POSIX shell when it holds anything but plain path characters.
fn shell_word(s: &str) -> String {
    let plain = !s.is_empty()
        && s.chars()
            .all(|c| c.is_ascii_alphanumeric() || "-_./:=+,@%".contains(c));
    if plain {
        s.to_string()
    } else {
        format!("'{}'", s.replace('\'', r"'\''"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shell_words_quote_only_when_needed() {
        assert_eq!(shell_word("specs/a.hspec"), "specs/a.hspec");
        assert_eq!(shell_word("my spec.hspec"), "'my spec.hspec'");
        assert_eq!(shell_word("it's"), r"'it'\''s'");
    }
}
