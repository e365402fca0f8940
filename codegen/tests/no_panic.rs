//! No input string makes the front end panic: random text and random token soups through every stage.

use codegen::{compile_input, compile_spec, DeclInput, FormulaInput, Origin, SpecInput};
use monitor_core::VarKind;
use proptest::prelude::*;

/// Inputs that once broke something (kept as regression cases).
const REGRESSIONS: &[&str] = &[
    "",
    ";",
    "property",
    "property p = ",
    "property p = {",
    "property p = {\"",
    "property p = {'\\",
    "state s: string = \"\\",
    "unit 1.s;",
    "unit .5s;",
    "property p = P[:",
    "property p = P[1:2",
    "property p = é",
    "é; property p = {a};",
    "event a; property p = {a} S[0:0.000000000000000000000000000000000000001s] {a};",
    "event a; property p = P[99999999999999999999999999999999999999999999999999999min] {a};",
    "event a; property p = P[18446744073709551615:18446744073709551615] {a};",
    "event a; property p = P[1:18446744073709551615] {a};",
    "state x: int; property p = {x / 0 == -9223372036854775808};",
    "state x: int; property p = {--9223372036854775808 < x};",
    "state x: float; property p = {x == 1e999999};",
];

#[test]
fn regression_inputs_do_not_panic() {
    for src in REGRESSIONS {
        let _ = compile_spec(src, "r.hspec").map(|c| c.to_table_bytes());
    }
}

const TOKENS: &[&str] = &[
    "event",
    "state",
    "property",
    "unit",
    "a",
    "b",
    "x",
    "s",
    ":",
    ";",
    "=",
    "int",
    "u8",
    "float",
    "string",
    "bool",
    "{",
    "}",
    "(",
    ")",
    "[",
    "]",
    "!",
    "not",
    "&&",
    "and",
    "||",
    "or",
    "->",
    "implies",
    "<->",
    "Y",
    "pre",
    "Z",
    "P",
    "O",
    "once",
    "H",
    "historically",
    "S",
    "since",
    "true",
    "false",
    "0",
    "1",
    "5",
    "2.5",
    "2.5s",
    "100ms",
    "3us",
    "7ns",
    "1min",
    "18446744073709551616",
    "9223372036854775808",
    "\"idle\"",
    "'x'",
    "\"",
    "+",
    "-",
    "*",
    "/",
    "%",
    "==",
    "!=",
    "<",
    "<=",
    ">",
    ">=",
    "#",
    "//",
    "\n",
    " ",
    "\t",
    "é",
    "1e5",
];

fn soup() -> impl Strategy<Value = String> {
    prop::collection::vec(prop::sample::select(TOKENS), 0..60).prop_map(|t| t.join(" "))
}

fn glued_soup() -> impl Strategy<Value = String> {
    prop::collection::vec(prop::sample::select(TOKENS), 0..60).prop_map(|t| t.concat())
}

const FORMULA_TOKENS: &[&str] = &[
    "{a}",
    "{b}",
    "{x > 1}",
    "{s == \"idle\"}",
    "{x + 1.5 < 2}",
    "true",
    "!",
    "&&",
    "||",
    "->",
    "<->",
    "S",
    "S[0:2]",
    "S[1:3]",
    "P",
    "P[2:]",
    "H",
    "H[:4]",
    "O[1:1]",
    "Y",
    "Z",
    "(",
    ")",
];

/// Declarations followed by a soup of formula tokens, so that the later stages get exercised.
fn spec_soup() -> impl Strategy<Value = String> {
    prop::collection::vec(prop::sample::select(FORMULA_TOKENS), 1..30).prop_map(|t| {
        format!(
            "event a; event b; state x: int = 1; state s: string;\nproperty p = {};",
            t.join(" ")
        )
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    #[test]
    fn random_text(s in "\\PC{0,80}") {
        let _ = compile_spec(&s, "r.hspec");
    }

    #[test]
    fn random_bytes_as_text(b in prop::collection::vec(any::<u8>(), 0..80)) {
        let s = String::from_utf8_lossy(&b);
        let _ = compile_spec(&s, "r.hspec");
    }

    #[test]
    fn token_soup(s in soup()) {
        let _ = compile_spec(&s, "r.hspec");
    }

    #[test]
    fn glued_token_soup(s in glued_soup()) {
        let _ = compile_spec(&s, "r.hspec");
    }

    #[test]
    fn formula_soup(s in spec_soup()) {
        if let Ok(c) = compile_spec(&s, "r.hspec") {
            let _ = c.to_table_bytes();
            let _ = c.ir();
        }
    }

    #[test]
    fn structured_input_soup(name in soup(), ty in soup(), init in soup(), f in soup(), unit in soup()) {
        let o = Origin { file: "x.xml".into(), line: 3, col: 4 };
        let input = SpecInput {
            untimed: false,
            unit: Some((unit, o.clone())),
            decls: vec![DeclInput {
                kind: VarKind::State,
                name,
                type_name: ty,
                init: Some(init),
                origin: o.clone(),
            }],
            formulas: vec![FormulaInput {
                name: "p".into(),
                text: f,
                origin: o,
                positions: Vec::new(),
            }],
        };
        if let Err(d) = compile_input(&input) {
            let _ = d.to_string();
        }
    }
}
