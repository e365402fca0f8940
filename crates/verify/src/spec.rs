//! Properties compiled on their own, without a model: a `.hspec` spec or a property file
//! over ROS names, for `hindsight compile`, `replay` and `monitor --ros2`, and what
//! `compile` makes of a spec (a table, the printed IR or Rust source); and a model's
//! guarantees compiled alone for the on-line monitor ([`guarantees`]).
//!
//! Nothing here prints: a compiled spec carries its warnings
//! ([`codegen::Compiled::warnings`]) for the caller to show.

use std::path::{Path, PathBuf};

use codegen::diag::Diagnostics;
use codegen::emit_rust::{emit_rust, EmitError, EmitOptions};
use codegen::Compiled;

use crate::load::Loaded;
pub use crate::props::PropertyFile;

/// Reads and compiles a `.hspec` spec with the project's one source reader
/// ([`codegen::diag::read_source`]); errors name `file:line:col`.
pub fn compile_spec_file(path: &Path) -> Result<Compiled, Diagnostics> {
    let src = codegen::diag::read_source(path)?;
    codegen::compile_spec(&src, &path.display().to_string())
}

/// A property file compiled for replay or live judging: its ports and formulas and the
/// compiled monitors.
pub struct PropertyMonitors {
    /// The file as read (its ports name what each variable reads).
    pub file: PropertyFile,
    /// The monitors, one variable per port, in time units of `unit_ns`.
    pub compiled: Compiled,
}

/// Reads a property file and compiles its guarantees and assumptions with time unit
/// `unit_ns`: bounds with a unit (`within="1" time_unit="s"`, `[6.2s:]`) are converted
/// exactly to it, as `verify` converts them to a model's unit
/// (`crate::observe::spec_input`).
pub fn compile_property_file(path: &Path, unit_ns: u64) -> Result<PropertyMonitors, Diagnostics> {
    let file = crate::props::parse_file(path).map_err(crate::load::props_diagnostics)?;
    let input = crate::observe::spec_input(&file, Some(unit_ns), |_, _, _, t| t)?;
    let compiled = codegen::compile_input(&input)?;
    Ok(PropertyMonitors { file, compiled })
}

/// What `hindsight compile` writes for a spec.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Output {
    /// The postcard table that `monitor_core::table::Table::from_bytes` loads.
    Table,
    /// The compiled networks, one line per node, with state sizes.
    Ir,
    /// A `core`-only Rust module named `module`, its header naming `command` as what
    /// reproduces it.
    Rust {
        /// The module's name (an identifier: [`module_name`] makes one from a path).
        module: String,
        /// The command line written in the generated file's header.
        command: String,
    },
}

/// The bytes of `output` for a compiled spec; only Rust source can fail (a module name
/// that is not an identifier).
pub fn emit(compiled: &Compiled, output: &Output) -> Result<Vec<u8>, EmitError> {
    Ok(match output {
        Output::Table => compiled.to_table_bytes(),
        Output::Ir => compiled.ir().into_bytes(),
        Output::Rust { module, command } => {
            let opts = EmitOptions::new(module.clone(), command.clone());
            emit_rust(&compiled.program(), &opts)?.into_bytes()
        }
    })
}

/// A module name from a spec path: the file stem's ASCII letters and digits,
/// lower-cased, words joined by single `_`; a leading digit gets `m_` before
/// it, a Rust keyword gets `_monitor` after it, nothing left gives `monitor`.
///
/// ```
/// use hindsight_verify::spec::module_name;
/// use std::path::{Path, PathBuf};
///
/// assert_eq!(module_name(Path::new("specs/Museum-Guide v2.hspec")), "museum_guide_v2");
/// assert_eq!(module_name(Path::new("2024_run.hspec")), "m_2024_run");
/// assert_eq!(module_name(Path::new("type.hspec")), "type_monitor");
/// ```
pub fn module_name(spec: &Path) -> String {
    let stem = spec
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let mut name = String::new();
    for word in stem
        .split(|c: char| !c.is_ascii_alphanumeric())
        .filter(|w| !w.is_empty())
    {
        if !name.is_empty() {
            name.push('_');
        }
        name.push_str(&word.to_ascii_lowercase());
    }
    if name.is_empty() {
        return "monitor".into();
    }
    if name.starts_with(|c: char| c.is_ascii_digit()) {
        name.insert_str(0, "m_");
    }
    if codegen::emit_rust::is_rust_keyword(&name) {
        name.push_str("_monitor");
    }
    name
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn module_names_are_identifiers() {
        let cases = [
            ("specs/museum.hspec", "museum"),
            ("Museum-Guide v2.hspec", "museum_guide_v2"),
            ("2024_run.hspec", "m_2024_run"),
            ("type.hspec", "type_monitor"),
            ("__.hspec", "monitor"),
            ("a__b.hspec", "a_b"),
        ];
        for (path, want) in cases {
            assert_eq!(module_name(Path::new(path)), want, "{path}");
        }
    }
}

/// Why a model's guarantees cannot be monitored on-line.
#[derive(Debug)]
pub enum GuaranteesError {
    /// The model has no time unit, so the monitor's clock has no tick.
    NoTimeUnit(PathBuf),
    /// The property file has no guarantee.
    NoGuarantee(PathBuf),
    /// The guarantees do not compile alone.
    Compile(Diagnostics),
}

impl std::fmt::Display for GuaranteesError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            GuaranteesError::NoTimeUnit(model) => write!(
                f,
                "{}: the model has no time unit, so the monitor's clock has no tick; give the \
                 length of one model step with --time-unit (for example --time-unit 100ms)",
                model.display()
            ),
            GuaranteesError::NoGuarantee(file) => {
                write!(f, "{}: no guarantee to monitor", file.display())
            }
            GuaranteesError::Compile(d) => write!(f, "{d}"),
        }
    }
}

impl std::error::Error for GuaranteesError {}

/// The guarantees of a loaded model's property file compiled into one spec, exactly as
/// `verify` compiles them: its variables are the ports' ids and its tick is the model's
/// time unit (`model` names the model in the error when it has none). Assumptions are not
/// monitored: they are left out, and their count comes back beside the spec (their
/// warnings are among the whole file's, which the load returned).
pub fn guarantees(loaded: Loaded, model: &Path) -> Result<(Compiled, usize), GuaranteesError> {
    let Some(unit_ns) = loaded.unit_ns else {
        return Err(GuaranteesError::NoTimeUnit(model.into()));
    };
    if loaded.file.guarantees.is_empty() {
        return Err(GuaranteesError::NoGuarantee(loaded.props_path));
    }
    let left_out = loaded.file.assumptions.len();
    if left_out == 0 {
        return Ok((loaded.set.compiled().clone(), 0));
    }
    let mut file = loaded.file;
    file.assumptions.clear();
    let set = crate::observe::PropertySet::with_unit(&file, &loaded.model, Some(unit_ns))
        .map_err(GuaranteesError::Compile)?;
    Ok((set.compiled().clone(), left_out))
}
