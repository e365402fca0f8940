//! Parser and checker behaviour through the public API: precedence, word forms, bounds, units, warnings, errors with positions.

use codegen::ast::{CheckedSpec, FormulaKind, Interval};
use codegen::{
    print, DeclInput, Diagnostics, FormulaInput, Origin, PositionRun, Severity, Spec, SpecInput,
};
use monitor_core::{Ty, Value, VarKind};

const DECLS: &str = "event a; event b; event c; event d;\n";

fn checked(src: &str) -> (CheckedSpec, Diagnostics) {
    let spec = Spec::parse(src, "t.hspec")
        .and_then(|s| s.check())
        .unwrap_or_else(|d| panic!("unexpected errors:\n{d}"));
    let w = spec.warnings();
    (spec.ast().clone(), w)
}

/// The fully parenthesised reading of one formula over events a..d, and its warnings.
fn reading(formula: &str) -> (String, Diagnostics) {
    let (ast, w) = checked(&format!("{DECLS}property p = {formula};"));
    (print::formula(&ast.properties[0].formula, &ast), w)
}

fn errors(src: &str) -> Vec<(u32, u32, String)> {
    let d = match Spec::parse(src, "e.hspec").and_then(|s| s.check()) {
        Ok(_) => panic!("expected errors for {src:?}"),
        Err(d) => d,
    };
    d.errors()
        .map(|e| (e.line, e.col, e.message.clone()))
        .collect()
}

fn interval(formula: &str, unit: &str) -> Result<Interval, Diagnostics> {
    let src = format!("{unit}{DECLS}property p = {formula};");
    let spec = Spec::parse(&src, "t.hspec")?.check()?;
    let f = &spec.ast().properties[0].formula;
    Ok(match &f.kind {
        FormulaKind::Once(iv, _) | FormulaKind::Historically(iv, _) => *iv,
        FormulaKind::Since(iv, _, _) => *iv,
        k => panic!("not a temporal formula: {k:?}"),
    })
}

#[test]
fn precedence_without_warning_when_scan_agrees() {
    for (src, want) in [
        ("{a} && {b} || {c}", "(({a} && {b}) || {c})"),
        ("{a} S {b} && {c}", "(({a} S {b}) && {c})"),
        ("{a} && {b} && {c}", "(({a} && {b}) && {c})"),
        ("{a} -> {b} <-> {c}", "(({a} -> {b}) <-> {c})"),
        ("!{a} S {b}", "(!{a} S {b})"),
        ("H {a} -> {b}", "(H {a} -> {b})"),
        ("Y Z {a} || {b}", "(Y Z {a} || {b})"),
        ("{a} || ({b} && {c})", "({a} || ({b} && {c}))"),
        ("{a} S {b} S {c}", "(({a} S {b}) S {c})"),
    ] {
        let (got, w) = reading(src);
        assert_eq!(got, want, "{src}");
        assert!(w.is_empty(), "{src}: unexpected warning {w}");
    }
}

#[test]
fn precedence_with_warning_when_scan_differs() {
    for (src, want, ours, scan) in [
        (
            "{a} || {b} && {c}",
            "({a} || ({b} && {c}))",
            "{a} || ({b} && {c})",
            "({a} || {b}) && {c}",
        ),
        (
            "{a} -> {b} -> {c}",
            "({a} -> ({b} -> {c}))",
            "{a} -> ({b} -> {c})",
            "({a} -> {b}) -> {c}",
        ),
        (
            "{a} && {b} S {c}",
            "({a} && ({b} S {c}))",
            "{a} && ({b} S {c})",
            "({a} && {b}) S {c}",
        ),
        (
            "{a} <-> {b} -> {c}",
            "({a} <-> ({b} -> {c}))",
            "{a} <-> ({b} -> {c})",
            "({a} <-> {b}) -> {c}",
        ),
        (
            "{a} or {b} and {c} implies {d}",
            "(({a} || ({b} && {c})) -> {d})",
            "({a} or ({b} and {c})) implies {d}",
            "(({a} or {b}) and {c}) implies {d}",
        ),
    ] {
        let (got, w) = reading(src);
        assert_eq!(got, want, "{src}");
        let ws: Vec<_> = w.iter().collect();
        assert_eq!(ws.len(), 1, "{src}: {w}");
        assert_eq!(ws[0].severity, Severity::Warning);
        assert!(
            ws[0].message.contains(&format!("`{ours}`")),
            "{src}: {}",
            ws[0].message
        );
        assert!(
            ws[0].message.contains(&format!("`{scan}`")),
            "{src}: {}",
            ws[0].message
        );
        assert_eq!((ws[0].line, ws[0].col), (2, 14), "{src}");
    }
}

#[test]
fn word_forms_equal_symbols() {
    for (words, symbols) in [
        ("not {a}", "!{a}"),
        ("{a} and {b}", "{a} && {b}"),
        ("{a} or {b}", "{a} || {b}"),
        ("{a} implies {b}", "{a} -> {b}"),
        ("pre {a}", "Y {a}"),
        ("once {a}", "P {a}"),
        ("O[1:2] {a}", "P[1:2] {a}"),
        ("once[1:2] {a}", "P[1:2] {a}"),
        ("historically[:3] {a}", "H[0:3] {a}"),
        ("{a} since[2:] {b}", "{a} S[2:] {b}"),
        ("{a} since {b}", "{a} S {b}"),
        ("{a && !b}", "{a and not b}"),
        ("{a || b}", "{a or b}"),
    ] {
        assert_eq!(reading(words).0, reading(symbols).0, "{words}");
    }
}

#[test]
fn every_bound_shape() {
    let iv = |lo, hi| Interval { lo, hi };
    for (f, want) in [
        ("P[2:5] {a}", iv(2, Some(5))),
        ("P[2:] {a}", iv(2, None)),
        ("P[:5] {a}", iv(0, Some(5))),
        ("P {a}", Interval::ALWAYS),
        ("P [ 2 : 5 ] {a}", iv(2, Some(5))),
        ("P[0:0] {a}", iv(0, Some(0))),
        ("H[3:3] {a}", iv(3, Some(3))),
        ("{a} S[1:4] {b}", iv(1, Some(4))),
        ("{a} S [7:] {b}", iv(7, None)),
        ("P[0:18446744073709551615] {a}", iv(0, Some(u64::MAX))),
    ] {
        assert_eq!(interval(f, "").unwrap(), want, "{f}");
    }
}

#[test]
fn unit_conversion_is_exact() {
    let hi = |f: &str, unit: &str| interval(f, unit).map(|i| i.hi);
    assert_eq!(hi("P[:2.5s] {a}", "unit 100ms;"), Ok(Some(25)));
    assert_eq!(hi("P[:100ms] {a}", "unit 100ms;"), Ok(Some(1)));
    assert_eq!(hi("P[:1min] {a}", ""), Ok(Some(60)));
    assert_eq!(hi("P[:2.5us] {a}", "unit 1ns;"), Ok(Some(2500)));
    assert_eq!(hi("P[:5s] {a}", "unit 2.5s;"), Ok(Some(2)));
    assert_eq!(hi("P[:62] {a}", "unit 100ms;"), Ok(Some(62)));
    assert_eq!(hi("P[:0.300s] {a}", "unit 100ms;"), Ok(Some(3)));
    assert_eq!(
        hi("P[:1.50000000000000000000s] {a}", "unit 500ms;"),
        Ok(Some(3))
    );
    assert_eq!(hi("P[:3us] {a}", "unit 1us;"), Ok(Some(3)));
    for (f, unit) in [
        ("P[:150ms] {a}", "unit 100ms;"),
        ("P[:1500ms] {a}", ""),
        ("P[:1us] {a}", "unit 1ms;"),
        ("P[:2.5] {a}", ""),
        ("P[:18446744073709551616] {a}", ""),
        ("P[:18446744073709551616s] {a}", "unit 1ns;"),
        (
            "P[:99999999999999999999999999999999999999999999min] {a}",
            "",
        ),
        ("P[:1s] {a}", "unit 0.4s;"),
    ] {
        let d = interval(f, unit).expect_err(f);
        assert!(d.has_errors(), "{f}");
        assert!(
            d.errors()
                .all(|e| e.message.contains("whole number") || e.message.contains("too large")),
            "{f}: {d}"
        );
    }
}

#[test]
fn unit_statement() {
    let tick = |src: &str| {
        Spec::parse(src, "u.hspec")
            .and_then(|s| s.check())
            .map(|s| s.ast().tick_ns)
    };
    assert_eq!(tick("event a;"), Ok(1_000_000_000));
    assert_eq!(tick("unit 100ms;"), Ok(100_000_000));
    assert_eq!(tick("unit 2.5us;"), Ok(2_500));
    assert_eq!(tick("unit 1min;"), Ok(60_000_000_000));
    for bad in [
        "unit 1;",
        "unit 0ms;",
        "unit 0.5ns;",
        "unit 1s; unit 2s;",
        "unit 5m;",
    ] {
        assert!(tick(bad).is_err(), "{bad}");
    }
}

#[test]
fn rejects_since_since_with_position() {
    let e = errors("event p; event q;\nproperty x = {p} since since {q};");
    assert_eq!(e.len(), 1, "{e:?}");
    assert_eq!((e[0].0, e[0].1), (2, 24));
    assert!(e[0].2.contains("found `since`"), "{}", e[0].2);
    let e = errors("event p; event q;\nproperty x = {p} S S {q};");
    assert_eq!((e[0].0, e[0].1), (2, 20));
}

#[test]
fn rejects_empty_bounds_with_position() {
    let e = errors("event a;\nproperty x = P[5:2] {a};");
    assert_eq!(e.len(), 1);
    assert_eq!((e[0].0, e[0].1), (2, 15));
    assert!(e[0].2.contains("empty interval"), "{}", e[0].2);
    let e = errors("unit 1ms;\nevent a;\nproperty x = {a} S[1s:999ms] {a};");
    assert_eq!((e[0].0, e[0].1), (3, 19));
}

#[test]
fn checker_errors_are_collected_with_positions() {
    let src = "\
event a;
state b: u8 = 300;
state a: int;
state s: string = \"idle\";
property p = {c > 1} && {s < \"x\"};
property p = {b + 1};
property q = {b + true} || {9223372036854775808 > b};
";
    let e = errors(src);
    let at: Vec<(u32, u32)> = e.iter().map(|(l, c, _)| (*l, *c)).collect();
    assert_eq!(
        at,
        vec![
            (2, 15),
            (3, 7),
            (5, 15),
            (5, 26),
            (6, 10),
            (6, 15),
            (7, 15),
            (7, 29)
        ],
        "{e:#?}"
    );
    assert!(e[0].2.contains("does not fit in u8"));
    assert!(
        e[1].2.contains("declared twice (first at e.hspec:1:1)"),
        "{}",
        e[1].2
    );
    assert!(e[2].2.contains("unknown variable `c`"));
    assert!(e[3].2.contains("orders numbers only"));
    assert!(
        e[4].2.contains("defined twice (first at e.hspec:5:10)"),
        "{}",
        e[4].2
    );
    assert!(e[5].2.contains("must be a boolean"));
    assert!(e[6].2.contains("needs two numbers"));
    assert!(e[7].2.contains("larger than the largest int"));
}

#[test]
fn an_integer_division_by_a_literal_zero_is_refused_where_written() {
    let e = errors(
        "state x: int = 0;\nstate y: float = 0.0;\n\
         property p = {x / 0 > 1};\nproperty q = {1 < x % (0)} || {y / 0 > 1};\n",
    );
    let at: Vec<(u32, u32)> = e.iter().map(|(l, c, _)| (*l, *c)).collect();
    // The float division (`y / 0`, 0 converted to a float) is IEEE: not an error.
    assert_eq!(at, vec![(3, 19), (4, 23)], "{e:#?}");
    assert!(e[0].2.contains("integer `/` by 0"), "{}", e[0].2);
    assert!(e[1].2.contains("integer `%` by 0"), "{}", e[1].2);
    // A divisor that is not the literal 0 is left to the step.
    assert!(Spec::parse(
        "state x: int = 0;\nproperty p = {x / (x - x) > 1};\n",
        "e.hspec"
    )
    .and_then(|s| s.check())
    .is_ok());
}

#[test]
fn parse_errors_recover_at_the_next_statement() {
    let src =
        "event a;\nproperty x = {a} &&;\nproperty y = ({a};\nfoo bar;\nproperty z = {a} {a};\n";
    let d = Spec::parse(src, "r.hspec").expect_err("bad");
    let lines: Vec<u32> = d.errors().map(|e| e.line).collect();
    assert_eq!(lines, vec![2, 3, 4, 5], "{d}");
}

#[test]
fn types_of_declarations() {
    let (ast, _) = checked(
        "event e;\nstate i: i8 = -128;\nstate u: u64 = 9223372036854775807;\nstate f: f32 = 2;\nstate g: float = -2.5;\nstate s: string = 'a\\'b';\nstate t: bool = true;\nstate z: int;\nstate y: string;\nproperty p = {e};",
    );
    let got: Vec<(&str, Ty, VarKind, Value, &str)> = ast
        .vars
        .iter()
        .map(|v| (v.name.as_str(), v.ty, v.kind, v.init, v.type_name.as_str()))
        .collect();
    assert_eq!(
        got,
        vec![
            ("e", Ty::Bool, VarKind::Event, Value::Bool(false), "bool"),
            ("i", Ty::Int, VarKind::State, Value::Int(-128), "i8"),
            ("u", Ty::Int, VarKind::State, Value::Int(i64::MAX), "u64"),
            ("f", Ty::Float, VarKind::State, Value::Float(2.0), "f32"),
            ("g", Ty::Float, VarKind::State, Value::Float(-2.5), "float"),
            ("s", Ty::Str, VarKind::State, Value::Str(0), "string"),
            ("t", Ty::Bool, VarKind::State, Value::Bool(true), "bool"),
            ("z", Ty::Int, VarKind::State, Value::Int(0), "int"),
            ("y", Ty::Str, VarKind::State, Value::Str(1), "string"),
        ]
    );
    assert_eq!(ast.strings, vec!["a'b".to_string(), String::new()]);
    for bad in [
        "state x: u8 = -1;",
        "state x: i8 = 128;",
        "state x: u64 = 9223372036854775808;",
        "state x: int = 1.5;",
        "state x: bool = 1;",
        "state x: string = 1;",
        "state x: word;",
        "state x: int = y;",
        "state and: int;",
    ] {
        assert!(errors(bad).len() == 1, "{bad}");
    }
}

#[test]
fn int_float_mix_inserts_conversions() {
    let (ast, _) = checked("state x: int; state f: float; property p = {x + 1 < f * 2};");
    let s = format!("{:?}", ast.properties[0].formula);
    assert_eq!(s.matches("ToFloat").count(), 2, "{s}");
    let (ast, _) = checked("property p = {-9223372036854775808 < 0};");
    assert!(format!("{:?}", ast.properties[0].formula).contains("Int(-9223372036854775808)"));
}

#[test]
fn diagnostics_render_with_source_line_and_carets() {
    let d = Spec::parse("event a;\nproperty p =\n\t{a} && {zz};", "r.hspec")
        .and_then(|s| s.check())
        .expect_err("unknown variable");
    assert_eq!(
        d.to_string(),
        "r.hspec:3:10: unknown variable `zz`\n    \t{a} && {zz};\n    \t        ^^"
    );
    assert!(d.has_errors());
    let e: &dyn std::error::Error = &d;
    assert!(e.to_string().starts_with("r.hspec:3:10"));
}

fn origin(line: u32, col: u32) -> Origin {
    Origin {
        file: "props.xml".into(),
        line,
        col,
    }
}

/// A formula whose text is not a verbatim copy of the file: the position map puts every
/// problem at its character in the file, after entities and in generated text.
#[test]
fn position_maps_keep_columns_right() {
    let run = |offset, line, col, exact| PositionRun {
        offset,
        line,
        col,
        exact,
    };
    let input = |text: &str, positions: Vec<PositionRun>| SpecInput {
        decls: vec![DeclInput {
            kind: VarKind::State,
            name: "x".into(),
            type_name: "int".into(),
            init: None,
            origin: origin(2, 5),
        }],
        formulas: vec![FormulaInput {
            name: "p".into(),
            text: text.into(),
            origin: origin(5, 10),
            positions,
        }],
        ..SpecInput::default()
    };
    let first = |input: &SpecInput| {
        let d = Spec::from_input(input)
            .and_then(|s| s.check())
            .expect_err("unknown variable");
        let e = d.errors().next().expect("an error");
        (e.line, e.col)
    };
    // The file holds `{x &lt; 3} && {nope}` from 5:10: `nope` is at column 25, not at
    // the 22 that counting the unescaped text forward would give.
    let text = "{x < 3} && {nope}";
    let entities = vec![
        run(0, 5, 10, true),
        run(3, 5, 13, true),
        run(4, 5, 17, true),
    ];
    assert_eq!(first(&input(text, entities)), (5, 25));
    assert_eq!(first(&input(text, Vec::new())), (5, 22));
    // Tree form: `(` and `) && (` generated from elements, the atoms copied from
    // attributes on other lines.
    let text = "({x < 3}) && ({nope})";
    let tree = vec![
        run(0, 4, 3, false),
        run(1, 5, 20, true),
        run(8, 4, 3, false),
        run(14, 6, 21, true),
        run(20, 4, 3, false),
    ];
    assert_eq!(first(&input(text, tree)), (6, 22));
}

#[test]
fn structured_input_reports_at_origins() {
    let input = SpecInput {
        untimed: false,
        unit: Some(("100ms".into(), origin(2, 11))),
        decls: vec![
            DeclInput {
                kind: VarKind::State,
                name: "level".into(),
                type_name: "int".into(),
                init: Some("100".into()),
                origin: origin(3, 5),
            },
            DeclInput {
                kind: VarKind::Event,
                name: "alarm".into(),
                type_name: String::new(),
                init: None,
                origin: origin(4, 5),
            },
        ],
        formulas: vec![
            FormulaInput {
                name: "ok".into(),
                text: "H({level >= 30} -> !{alarm})".into(),
                origin: origin(10, 20),
                positions: Vec::new(),
            },
            FormulaInput {
                name: "bad".into(),
                text: "P[0:1s] {level}".into(),
                origin: origin(12, 30),
                positions: Vec::new(),
            },
            FormulaInput {
                name: "bad2".into(),
                text: "{alarm} &&\n   {nope}".into(),
                origin: origin(14, 7),
                positions: Vec::new(),
            },
        ],
    };
    let d = Spec::from_input(&input)
        .and_then(|s| s.check())
        .expect_err("bad atoms");
    let at: Vec<(String, u32, u32)> = d.iter().map(|e| (e.file.clone(), e.line, e.col)).collect();
    assert_eq!(
        at,
        vec![("props.xml".into(), 12, 39), ("props.xml".into(), 15, 5)],
        "{d}"
    );
    // A declaration's problems are reported at the declaration.
    let mut bad_decl = input.clone();
    bad_decl.formulas.truncate(1);
    bad_decl.decls[0].init = Some("1.5".into());
    bad_decl.decls[1].name = "al arm".into();
    let d = Spec::from_input(&bad_decl)
        .and_then(|s| s.check())
        .expect_err("bad decls");
    let at: Vec<(u32, u32)> = d.iter().map(|e| (e.line, e.col)).collect();
    assert_eq!(at, vec![(4, 5)], "{d}");
    bad_decl.decls[1].name = "alarm".into();
    let d = Spec::from_input(&bad_decl)
        .and_then(|s| s.check())
        .expect_err("bad init");
    let at: Vec<(u32, u32)> = d.iter().map(|e| (e.line, e.col)).collect();
    assert_eq!(at, vec![(3, 5)], "{d}");
    // The good formula alone compiles, with the unit given.
    let mut good = input.clone();
    good.formulas.truncate(1);
    let c = codegen::compile_input(&good).unwrap_or_else(|d| panic!("{d}"));
    assert_eq!(c.tick_ns(), 100_000_000);
}

#[test]
fn deep_nesting_is_an_error_not_a_crash() {
    for src in [
        format!(
            "event a; property p = {}{{a}}{};",
            "(".repeat(10_000),
            ")".repeat(10_000)
        ),
        format!("event a; property p = {}{{a}};", "!".repeat(10_000)),
        format!("event a; property p = {}{{a}};", "H ".repeat(10_000)),
        format!("event a; property p = {{a}}{};", " && {a}".repeat(10_000)),
        format!(
            "event a; property p = {{{}a{}}};",
            "(".repeat(10_000),
            ")".repeat(10_000)
        ),
        format!("event a; property p = {{{}a}};", "!".repeat(10_000)),
        format!(
            "state x: int; property p = {{x{} > 0}};",
            " + x".repeat(10_000)
        ),
    ] {
        let d = codegen::compile_spec(&src, "deep.hspec").expect_err("too deep");
        assert!(
            d.errors()
                .any(|e| e.message.contains("deep") || e.message.contains("chain")),
            "{d}"
        );
    }
}

#[test]
fn untimed_input_takes_tick_counts_and_rejects_units() {
    let input = |formula: &str| SpecInput {
        untimed: true,
        unit: None,
        decls: vec![DeclInput {
            kind: VarKind::Event,
            name: "a".into(),
            type_name: String::new(),
            init: None,
            origin: origin(1, 1),
        }],
        formulas: vec![FormulaInput {
            name: "p".into(),
            text: formula.into(),
            origin: origin(7, 3),
            positions: Vec::new(),
        }],
    };
    assert!(codegen::compile_input(&input("H(P[:10] {a})")).is_ok());
    let err = codegen::compile_input(&input("H(P[:1s] {a})"))
        .unwrap_err()
        .to_string();
    assert!(err.contains("props.xml:7:8"), "{err}");
    assert!(err.contains("no known duration"), "{err}");
}
