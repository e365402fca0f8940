//! Build script: puts the target board's memory map on the linker path as `memory.x` (`memory-mps2-an386.x`, or `memory-microbit.x` for thumbv6m) and writes the monitor table and replay trace that `monitor-table` embeds.
//!
//! Writes into `OUT_DIR`:
//! - `table.postcard`: the postcard table (`Table::from_bytes` format). The
//!   file named by `HINDSIGHT_TABLE` when set (`hindsight compile SPEC --emit
//!   table -o FILE` writes one), else museum-spec's table, which its build
//!   script compiles from `museum.hspec` with hindsight-codegen.
//! - `trace.bin`: the replay trace in museum-spec's `trace` format; the file
//!   named by `HINDSIGHT_TRACE` when set, else museum-spec's recorded run of
//!   the museum model.
//! - `table_info.rs`: the `Store` type sized exactly for the table (one
//!   capacity per vector) and constants (state words, properties, variables,
//!   nodes), so the firmware allocates exactly what it needs.
//! - `final.postcard`, `final_info.rs`: the same for museum-spec's
//!   `FINAL_TABLE`, whose verdicts all become final on the run (`monitor-final`).
//!
//! Both inputs are validated here with the host build of monitor-core, so a
//! bad table fails the build rather than the device; so does a table whose
//! atoms need floats or integer division when the firmware's `float` /
//! `int-div` feature is off.

use std::env;
use std::error::Error;
use std::fs;
use std::path::{Path, PathBuf};

use monitor_core::table::Table;

/// Generous decode capacity for the validation on the host; the firmware uses the exact size.
const HOST_CAPACITY: usize = 4096;

fn input(var: &str, default: impl FnOnce() -> Vec<u8>) -> Result<Vec<u8>, Box<dyn Error>> {
    println!("cargo:rerun-if-env-changed={var}");
    match env::var_os(var) {
        Some(path) => {
            println!("cargo:rerun-if-changed={}", PathBuf::from(&path).display());
            fs::read(&path)
                .map_err(|e| format!("{var}={}: {e}", PathBuf::from(&path).display()).into())
        }
        None => Ok(default()),
    }
}

fn main() -> Result<(), Box<dyn Error>> {
    // A decoded `Table<HOST_CAPACITY>` is several hundred KiB and moves by value.
    std::thread::Builder::new()
        .stack_size(256 << 20)
        .spawn(|| run().map_err(|e| e.to_string()))?
        .join()
        .map_err(|_| "build script thread panicked")??;
    Ok(())
}

fn run() -> Result<(), Box<dyn Error>> {
    let out = PathBuf::from(env::var_os("OUT_DIR").ok_or("OUT_DIR is not set")?);
    // The board QEMU runs each target on: mps2-an386 (Cortex-M4F), microbit (Cortex-M0).
    let target = env::var("TARGET").unwrap_or_default();
    let memory = if target.starts_with("thumbv6m") {
        "memory-microbit.x"
    } else {
        "memory-mps2-an386.x"
    };
    // Not named `memory.x` in the package: the linker would find it in its
    // working directory before this one.
    fs::copy(memory, out.join("memory.x"))?;
    println!("cargo:rustc-link-search={}", out.display());
    println!("cargo:rerun-if-changed={memory}");
    println!("cargo:rerun-if-changed=build.rs");

    let table_bytes = input("HINDSIGHT_TABLE", museum_spec::table_bytes)?;
    let trace_bytes = input("HINDSIGHT_TRACE", museum_spec::trace_bytes)?;

    fs::write(out.join("trace.bin"), &trace_bytes)?;
    embed(&out, "table", &table_bytes, &trace_bytes)?;
    embed(&out, "final", museum_spec::FINAL_TABLE, &trace_bytes)?;
    Ok(())
}

/// Validates table `bytes` (and that `trace` reads back with its variables)
/// and writes `<name>.postcard` and `<name>_info.rs` (the `Store` sized
/// exactly for it, state words, properties, variables, nodes).
fn embed(out: &Path, name: &str, bytes: &[u8], trace: &[u8]) -> Result<(), Box<dyn Error>> {
    let table = Table::<HOST_CAPACITY>::from_bytes(bytes)
        .map_err(|e| format!("monitor table {name}: {e}"))?;
    let program = table.program();
    let monitor = table
        .monitor()
        .map_err(|e| format!("monitor table {name}: {e}"))?;
    // The firmware's monitor-core has only the arithmetic its features ask for.
    let needs = monitor_core::analysis::arithmetic(&program);
    for (needed, feature) in [(needs.float, "float"), (needs.int_div, "int-div")] {
        let var = format!("CARGO_FEATURE_{}", feature.to_uppercase().replace('-', "_"));
        if needed && env::var_os(&var).is_none() {
            return Err(format!(
                "monitor table {name}: its atoms need {feature} arithmetic: build the firmware with `--features {feature}`"
            )
            .into());
        }
    }
    // The whole trace must read back with this program's variables.
    let mut reader = museum_spec::trace::Reader::new(trace, program.vars.len())
        .map_err(|e| format!("replay trace for {name}: {e}"))?;
    let mut values = vec![monitor_core::Value::Bool(false); program.vars.len()];
    while reader
        .next_point(&mut values)
        .map_err(|e| format!("replay trace for {name}: {e}"))?
        .is_some()
    {}

    fs::write(out.join(format!("{name}.postcard")), bytes)?;
    fs::write(
        out.join(format!("{name}_info.rs")),
        format!(
            "// Generated by build.rs from the monitor table; do not edit.\n\
             /// Storage of exactly this table's size (variables, strings, instructions, atoms, nodes, properties).\n\
             pub type Store = monitor_core::table::Store<'static, {}, {}, {}, {}, {}, {}>;\n\
             /// State words the monitor needs.\n\
             pub const STATE_WORDS: usize = {};\n\
             /// Properties (verdicts per point).\n\
             pub const PROPS: usize = {};\n\
             /// Declared variables (values per point).\n\
             pub const VARS: usize = {};\n\
             /// Nodes (one finality slot each).\n\
             pub const NODES: usize = {};\n",
            program.vars.len(),
            program.strings.len(),
            program.instrs.len(),
            program.atoms.len(),
            program.nodes.len(),
            program.props.len(),
            monitor.state_words(),
            monitor.properties(),
            program.vars.len(),
            program.nodes.len(),
        ),
    )?;
    Ok(())
}
