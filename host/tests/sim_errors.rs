//! Bad models are errors with file, line and column, never panics (including mutated inputs).

use hindsight::verify::model::{Diagnostics, ModelSource};
use hindsight::verify::sim::{CompiledModel, RunConfig, Simulator};
use rand_core::{Rng, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

fn compile(files: &[(&str, &str)]) -> Result<CompiledModel, Diagnostics> {
    CompiledModel::compile(ModelSource::from_texts(files.iter().copied())?)
}

/// The single error of a one-file model, as `line:column: message`.
fn error(text: &str) -> String {
    let errs = compile(&[("m.scxml", text)]).expect_err("model should be rejected");
    let d = errs.iter().next().unwrap();
    assert_eq!(d.file, "m.scxml");
    format!("{}:{}: {}", d.line, d.col, d.message)
}

const HEAD: &str = r#"<scxml name="M" initial="s" xmlns="http://www.w3.org/2005/07/scxml">"#;

#[test]
fn malformed_xml() {
    let e = error(&format!("{HEAD}\n<state id=\"s\">\n</scxml>"));
    assert!(e.starts_with("3:"), "{e}");
    assert!(e.contains("malformed XML"), "{e}");
    // A bad reference names itself, at its `&`.
    let text = format!("{HEAD}<state id=\"s\" x='&bad;'/></scxml>");
    let col = text.find("&bad;").unwrap() + 1;
    assert_eq!(
        error(&text),
        format!("1:{col}: malformed XML: unknown reference `&bad;`")
    );
}

#[test]
fn unknown_tags_and_attributes() {
    let e = error(&format!(
        "{HEAD}\n  <state id=\"s\">\n    <invoke/>\n  </state>\n</scxml>"
    ));
    assert_eq!(e, "3:5: <invoke> is not supported");
    let e = error(&format!("{HEAD}\n<state id=\"s\" colour=\"red\"/></scxml>"));
    assert!(
        e.starts_with("2:15: unknown attribute `colour` on <state>"),
        "{e}"
    );
    let e = error(&format!(
        "{HEAD}\n<state id=\"s\">\n<onentry><foo/></onentry></state></scxml>"
    ));
    assert_eq!(e, "3:10: unexpected <foo> in executable content");
    let e = error(&format!(
        "{HEAD}\n<state id=\"s\"><state id=\"nested\"/></state></scxml>"
    ));
    assert!(e.contains("nested <state> is not supported"), "{e}");
}

#[test]
fn undefined_names() {
    let e = error(&format!(
        "{HEAD}\n<state id=\"s\"><transition target=\"t\"/></state></scxml>"
    ));
    assert_eq!(e, "2:35: unknown target state `t`");
    let e = error(&format!(
        "{HEAD}\n<state id=\"s\"><onentry><send event=\"e\" target=\"Nobody\"/></onentry></state></scxml>"
    ));
    assert_eq!(
        e,
        "2:48: unknown target machine `Nobody` (no machine has this name)"
    );
    let e = error(&format!(
        "{HEAD}\n<state id=\"s\"><onentry><assign location=\"x\" expr=\"1\"/></onentry></state></scxml>"
    ));
    assert_eq!(e, "2:42: unknown variable `x`");
    let e = error(&format!(
        "{HEAD}\n<datamodel><data id=\"y\" expr=\"1\"/></datamodel>\n<state id=\"s\"><onentry><assign location=\"y\" expr=\"y + z\"/></onentry></state></scxml>"
    ));
    assert_eq!(e, "3:55: unknown variable `z`");
    // A sent parameter's type comes from its expression: when that names an unknown
    // variable, the error says so (not that the type cannot be inferred).
    let e = error(&format!(
        "{HEAD}\n<state id=\"s\"><onentry><send event=\"e\" target=\"M\"><param name=\"p\" expr=\"q + 1\"/></send></onentry>\n<transition event=\"e\" target=\"s\"/></state></scxml>"
    ));
    assert_eq!(e, "2:73: unknown variable `q`");
}

#[test]
fn type_errors() {
    let dm = "<datamodel><!-- TYPE n:int32 --><data id=\"n\" expr=\"0\"/><!-- TYPE f:float64 --><data id=\"f\" expr=\"0\"/></datamodel>";
    let e = error(&format!(
        "{HEAD}\n{dm}\n<state id=\"s\"><onentry><assign location=\"n\" expr=\"f * 2\"/></onentry></state></scxml>"
    ));
    assert_eq!(e, "3:51: the expression has type float but int is expected");
    let e = error(&format!(
        "{HEAD}\n{dm}\n<state id=\"s\"><transition cond=\"n\" target=\"s\"/></state></scxml>"
    ));
    assert_eq!(e, "3:33: the expression has type int but bool is expected");
    let e = error(&format!(
        "{HEAD}\n{dm}\n<state id=\"s\"><transition cond=\"n &gt; 'a'\" target=\"s\"/></state></scxml>"
    ));
    assert!(
        e.starts_with("3:33: operator `>` cannot be applied to int and string"),
        "{e}"
    );
    let e = error(&format!(
        "{HEAD}\n{dm}\n<state id=\"s\"><transition cond=\"n &gt;\" target=\"s\"/></state></scxml>"
    ));
    assert!(e.starts_with("3:39: unexpected end of expression"), "{e}");
}

#[test]
fn params_must_agree_across_senders() {
    let a = r#"<scxml name="A" initial="s"><state id="s"><onentry><send event="e" target="B"><param name="p" expr="'text'"/></send></onentry></state></scxml>"#;
    let b = r#"<scxml name="B" initial="s"><state id="s"><onentry><send event="e" target="B"><param name="p" expr="1"/></send></onentry><transition event="e" target="s"/></state></scxml>"#;
    let errs = compile(&[("a.scxml", a), ("b.scxml", b)]).unwrap_err();
    let d = errs.iter().next().unwrap();
    assert_eq!(d.file, "b.scxml");
    assert!(d.message.contains("int but string is expected"), "{d}");
}

#[test]
fn event_data_outside_an_event_transition() {
    let e = error(&format!(
        "{HEAD}\n<state id=\"s\"><onentry><log expr=\"_event.data.x\"/></onentry></state></scxml>"
    ));
    assert_eq!(
        e,
        "2:47: `_event.data` is only available in a transition that has an `event`"
    );
}

/// Every error is collected, not just the first.
#[test]
fn errors_are_collected() {
    let errs = compile(&[(
        "m.scxml",
        "<scxml name=\"M\" initial=\"nope\">\n<state id=\"s\">\n<transition target=\"a\"/>\n<transition target=\"b\"/>\n</state></scxml>",
    )])
    .unwrap_err();
    let lines: Vec<u32> = errs.iter().map(|d| d.line).collect();
    assert_eq!(lines, vec![1, 3, 4], "{errs}");
}

/// Random byte edits of a real model: always a result, never a panic; valid mutants run.
#[test]
fn mutated_models_never_panic() {
    let base = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/sim/arrays/arrays.scxml"),
    )
    .unwrap();
    let other = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/sim/arrays/sum.scxml"),
    )
    .unwrap();
    let pieces = [
        "<",
        ">",
        "\"",
        "&",
        "&amp;",
        "[",
        "]",
        "(",
        ")",
        ".",
        "_event.",
        "a[",
        "/>",
        "</state>",
        "<if cond=\"",
        "9999999999999999999",
        "'",
        "==",
        "-",
        "!",
    ];
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(42);
    let mut compiled = 0;
    for _ in 0..1500 {
        let mut text = base.clone().into_bytes();
        for _ in 0..1 + rng.next_u32() % 3 {
            let at = (rng.next_u32() as usize) % (text.len() + 1);
            match rng.next_u32() % 3 {
                0 if at < text.len() => {
                    let n = 1 + (rng.next_u32() as usize % 8).min(text.len() - at - 1);
                    text.drain(at..at + n);
                }
                1 => {
                    let p = pieces[rng.next_u32() as usize % pieces.len()];
                    text.splice(at..at, p.bytes());
                }
                _ => {
                    if at < text.len() {
                        text[at] = b"<>&\"'[]()=!x0 "[rng.next_u32() as usize % 14];
                    }
                }
            }
        }
        let Ok(text) = String::from_utf8(text) else {
            continue;
        };
        if let Ok(m) = compile(&[("arrays.scxml", &text), ("sum.scxml", &other)]) {
            compiled += 1;
            let cfg = RunConfig {
                max_steps: 10_000,
                max_time: 100,
                ..RunConfig::default()
            };
            Simulator::new(&m).run(&mut Xoshiro256PlusPlus::seed_from_u64(1), &cfg, &mut ());
        }
    }
    assert!(compiled > 0, "some mutants are still valid models");
}

#[test]
fn mutated_expressions_never_panic() {
    let seeds = [
        "Math.floor(Math.random() * n) + a[i][j].length",
        "x > 3 ? -y : (z == 'a' && !b) || c[0] % 7",
        "_event.data.p.q[1] + 0x1f - .5e3",
        "{'a': [{x: 1, \"y\": -2.5},], b: c.d[0].e}",
    ];
    let alphabet = b"()[]{}.,?:!&|=<>+-*/%'\"0123456789abcxyz_ \\$#";
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(7);
    for _ in 0..5000 {
        let mut t: Vec<u8> = seeds[rng.next_u32() as usize % seeds.len()]
            .bytes()
            .collect();
        for _ in 0..1 + rng.next_u32() % 4 {
            let at = rng.next_u32() as usize % (t.len() + 1);
            let c = alphabet[rng.next_u32() as usize % alphabet.len()];
            if rng.next_u32() % 2 == 0 && at < t.len() {
                t.remove(at);
            } else {
                t.insert(at, c);
            }
        }
        let text = String::from_utf8_lossy(&t);
        if let Err(e) = hindsight::verify::expr::parse_expr(&text) {
            assert!(e.offset as usize <= text.len());
        }
    }
}

/// A variable whose declaration is wrong is reported once, at the declaration: its uses
/// do not add an "unknown variable" each.
#[test]
fn a_failed_declaration_is_reported_once() {
    let text = format!(
        "{HEAD}\n<datamodel><data id=\"a\" expr=\"[]\"/></datamodel>\n<state id=\"s\"><onentry><assign location=\"a[0]\" expr=\"1\"/><send event=\"e\" target=\"M\"><param name=\"n\" expr=\"a.length\"/></send></onentry>\n<transition event=\"e\" cond=\"a.length &gt; 3\" target=\"s\"/></state></scxml>"
    );
    let errs = compile(&[("m.scxml", text.as_str())]).expect_err("rejected");
    let all: Vec<String> = errs
        .iter()
        .map(|d| format!("{}:{}: {}", d.line, d.col, d.message))
        .collect();
    assert_eq!(all.len(), 1, "{all:?}");
    assert!(
        all[0].starts_with("2:12: cannot infer the element type of `a` from its value"),
        "{all:?}"
    );
}
