//! Emits the Rust emitter's shared test programs into `OUT_DIR/emitted.rs`, with
//! per-program adapters, for `tests/emitted_agree.rs` to compile and run.

use std::fmt::Write as _;
use std::path::PathBuf;

use codegen::emit_rust::{emit_rust, input_fields, EmitOptions};
use monitor_core::Ty;

#[allow(dead_code)]
mod programs {
    include!("../codegen/tests/golden/programs.rs");
}

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-changed=../codegen/tests/golden/programs.rs");
    let out_dir = PathBuf::from(std::env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    let mut out = String::new();
    for (name, program) in programs::all().into_iter().chain(programs::random_all()) {
        let opts = EmitOptions::new(name, "hindsight-tests build.rs");
        let src = emit_rust(&program, &opts).unwrap_or_else(|e| panic!("{name}: {e}"));
        out.push_str(&src);
        out.push_str(&adapter(name, &program));
    }
    std::fs::write(out_dir.join("emitted.rs"), out).expect("write OUT_DIR/emitted.rs");
}

/// `mod <name>_io`: set a variable of the generated `Input` from a `Value`, and
/// check that an `Input` holds a valuation (floats by bits).
fn adapter(name: &str, program: &monitor_core::Program<'_>) -> String {
    let fields = input_fields(program);
    let mut set = String::new();
    let mut same = String::new();
    for (i, (var, field)) in program.vars.iter().zip(&fields).enumerate() {
        let (variant, eq) = match var.ty {
            Ty::Bool => ("Bool", format!("v == input.{field}")),
            Ty::Int => ("Int", format!("v == input.{field}")),
            Ty::Float => ("Float", format!("v.to_bits() == input.{field}.to_bits()")),
            Ty::Str => ("Str", format!("v == input.{field}")),
        };
        writeln!(
            set,
            "            ({i}, Value::{variant}(v)) => input.{field} = v,"
        )
        .unwrap();
        writeln!(
            same,
            "        && matches!(vals.get({i}), Some(&Value::{variant}(v)) if {eq})"
        )
        .unwrap();
    }
    format!(
        r#"
/// Test adapters for the generated module `{name}`.
#[allow(dead_code, unreachable_patterns, unused_variables, clippy::all)]
pub mod {name}_io {{
    use monitor_core::Value;
    use super::{name}::Input;

    /// Sets variable `var` to `value`, which must have its declared type.
    pub fn set(input: &mut Input, var: usize, value: Value) {{
        match (var, value) {{
{set}            _ => panic!("variable {{var}}: value {{value:?}} of the wrong type"),
        }}
    }}

    /// Whether `input` holds exactly `vals`.
    pub fn same(input: &Input, vals: &[Value]) -> bool {{
        vals.len() == {n}
{same}    }}
}}
"#,
        n = program.vars.len()
    )
}
