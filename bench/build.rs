//! Compiles every benchmarked formula and emits its Rust monitor into `OUT_DIR/generated.rs`.
//!
//! Module `f{k}` is the monitor of `cases::FORMULAS[k]`; `run_generated` is
//! the dispatch the bench uses, built on the `gen_loop!` macro of `src/lib.rs`.

use std::fmt::Write as _;
use std::path::PathBuf;

use codegen::emit_rust::{emit_rust, EmitOptions};

#[path = "src/cases.rs"]
#[allow(dead_code)]
mod cases;

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-changed=src/cases.rs");
    let out_dir = PathBuf::from(std::env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    let mut out = String::new();
    let mut arms = String::new();
    for (k, formula) in cases::FORMULAS.iter().enumerate() {
        let file = format!("bench case {k}");
        let compiled = codegen::compile_spec(&cases::spec(formula), &file)
            .unwrap_or_else(|d| panic!("{formula}: {d}"));
        let module = format!("f{k}");
        let opts = EmitOptions::new(&module, "hindsight-bench build.rs");
        let src =
            emit_rust(&compiled.program(), &opts).unwrap_or_else(|e| panic!("{formula}: {e}"));
        out.push_str(&src);
        // One function per monitor, never inlined: each loop gets its own code
        // placement instead of sharing one big dispatch function.
        writeln!(
            out,
            "\n/// Runs module `{module}` over `trace`.\n\
             #[inline(never)]\n\
             fn run_{module}(trace: &Trace, sink: &mut impl FnMut(bool)) -> Result<(), RunError> {{\n    \
                 gen_loop!({module}, trace, sink)\n}}"
        )
        .unwrap();
        writeln!(arms, "        {k} => run_{module}(trace, sink),").unwrap();
    }
    write!(
        out,
        "\n/// Runs the generated monitor of `FORMULAS[k]` over `trace` (see `gen_loop!`).\n\
         pub fn run_generated(\n    k: usize,\n    trace: &Trace,\n    sink: &mut impl FnMut(bool),\n) -> Result<(), RunError> {{\n    \
             match k {{\n{arms}        _ => Err(RunError {{ point: 0, message: format!(\"no formula {{k}}\") }}),\n    }}\n}}\n\n\
         /// `size_of` the generated monitor of `FORMULAS[k]`.\n\
         pub fn generated_state_bytes(k: usize) -> usize {{\n    \
             match k {{\n{sizes}        _ => 0,\n    }}\n}}\n",
        sizes = (0..cases::FORMULAS.len())
            .map(|k| format!("        {k} => f{k}::STATE_BYTES,\n"))
            .collect::<String>()
    )
    .unwrap();
    std::fs::write(out_dir.join("generated.rs"), out).expect("write OUT_DIR/generated.rs");
}
