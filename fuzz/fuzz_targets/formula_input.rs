//! Fuzz target: one formula from structured input (as the XML readers pass it), with fixed declarations.
#![no_main]

use codegen::{DeclInput, FormulaInput, Origin, SpecInput};
use libfuzzer_sys::fuzz_target;
use monitor_core::VarKind;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let origin = Origin {
        file: "fuzz.xml".into(),
        line: 7,
        col: 12,
    };
    let decl = |kind, name: &str, ty: &str, init: Option<&str>| DeclInput {
        kind,
        name: name.into(),
        type_name: ty.into(),
        init: init.map(Into::into),
        origin: origin.clone(),
    };
    let input = SpecInput {
        untimed: false,
        unit: Some(("100ms".into(), origin.clone())),
        decls: vec![
            decl(VarKind::Event, "a", "bool", None),
            decl(VarKind::State, "x", "int", Some("3")),
            decl(VarKind::State, "f", "float", Some("-2.5")),
            decl(VarKind::State, "s", "string", Some("\"idle\"")),
        ],
        formulas: vec![FormulaInput {
            name: "p".into(),
            text: text.into(),
            origin,
            positions: Vec::new(),
        }],
    };
    if let Err(d) = codegen::compile_input(&input) {
        let _ = d.to_string();
    }
});
