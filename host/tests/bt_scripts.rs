//! BehaviorTree.CPP 4's script language in a tree: a malformed script (`Script`'s `code`,
//! `Precondition`'s `if`, a `_skipIf` ... `_post` attribute) is an error at its
//! attribute's file:line:col naming the column in the script; a well-formed one is
//! refused under AS2FM's semantics, saying that AS2FM has no model of it and to use
//! `--bt btcpp`, which lowers it (or refuses, at the attribute, what it does not model
//! yet).

mod common;

use common::bt::{lower_act, lower_doc, BTCPP};
use hindsight::verify::robot::bt::{BtSemantics, BtTick};

/// The errors lowering `body` gives under `semantics`.
fn errors(body: &str, semantics: BtSemantics) -> String {
    match lower_act(body, "", semantics) {
        Ok(_) => panic!("lowered: {body}"),
        Err(e) => e,
    }
}

const BOTH: [BtSemantics; 2] = [
    BtSemantics::As2fm,
    BtSemantics::Btcpp { tick: BtTick::Once },
];

#[test]
fn a_malformed_script_is_an_error_at_its_attribute() {
    for sem in BOTH {
        // Line 4 is the body's second line; the value starts after `code="`.
        let e = errors("<Sequence>\n<Script code=\"a:=1;\"/>\n</Sequence>", sem);
        assert!(
            e.contains("tree.xml:4:15: `code` of <Script>: script syntax error at column 5 of the script: unexpected trailing `;`"),
            "{e}"
        );
        let e = errors(
            "<Sequence>\n<Act _skipIf=\"!f || x > -1\"/>\n</Sequence>",
            sem,
        );
        assert!(
            e.contains("tree.xml:4:15: `_skipIf`: script syntax error at column 11 of the script: operator cannot be mixed with previous operators"),
            "{e}"
        );
        let e = errors("<Precondition if=\"x +\">\n<Act/>\n</Precondition>", sem);
        assert!(
            e.contains("tree.xml:3:19: `if` of <Precondition>: script syntax error at column 4"),
            "{e}"
        );
    }
}

#[test]
fn a_well_formed_condition_is_refused_saying_why() {
    let e = errors(
        "<Sequence>\n<Act _onSuccess=\"x += 1\"/>\n</Sequence>",
        BtSemantics::As2fm,
    );
    assert!(
        e.contains("tree.xml:4:6: `_onSuccess` (a BehaviorTree.CPP 4 pre/post condition) is not supported: AS2FM has no model"),
        "{e}"
    );
    assert!(e.contains("`--bt btcpp`"), "{e}");
    let e = errors(
        "<Sequence>\n<Script code=\"x := 1\"/>\n</Sequence>",
        BtSemantics::As2fm,
    );
    assert!(
        e.contains(
            "tree.xml:4:1: `Script` is a BehaviorTree.CPP 4 node that AS2FM has no model of"
        ),
        "{e}"
    );
    assert!(e.contains("`--bt btcpp`"), "{e}");
    // Under BT.CPP's rules: what is not modelled yet, at the attribute.
    let btcpp = BtSemantics::Btcpp { tick: BtTick::Once };
    let e = errors(
        "<BlackboardCheckInt value_A=\"{k}\" value_B=\"1\">\n<Sequence>\n<Act _skipIf=\"true\"/>\n</Sequence>\n</BlackboardCheckInt>",
        btcpp,
    );
    assert!(
        e.contains("tree.xml:4:1: this node may answer SKIPPED (BehaviorTree.CPP 4): its parent, a BlackboardCheck, is a BehaviorTree.CPP 3 node"),
        "{e}"
    );
}

#[test]
fn scripts_the_btcpp_lowering_cannot_model_are_refused_saying_why() {
    // At the attribute (line 3, the value of `code` at column 15), with the column in the
    // script and the reason.
    let btcpp = BtSemantics::Btcpp { tick: BtTick::Once };
    for (code, col, why) in [
        (
            "y := 1; x := 'a' .. y",
            21,
            "a number that is not a literal",
        ),
        ("x := 'a'; x := 1", 11, "which holds strings"),
        ("x := 1 == 'a3'", 11, "reads a prefix of a text as a number"),
        ("x := 1. &lt; 2", 6, "not one BT.CPP 4 reads"),
        ("x := 1e400 &gt; 0", 6, "out of a double's range"),
    ] {
        let e = errors(&format!("<Script code=\"{code}\"/>"), btcpp);
        assert!(
            e.contains("tree.xml:3:15: `code` of Script: ")
                && e.contains(why)
                && e.contains(&format!("(at column {col} of the script)")),
            "{code}: {e}"
        );
    }
    // What is lowered: doubles compared, tested and cast, hexadecimal and exponents.
    for code in [
        "x := 5 / 2 &gt; 2",
        "x := (1e308 * 10 - 1e308 * 10) &lt; 1 ? 1 : 2",
        "x := 1; x += x / -2.5 &lt; 0",
        "x := 2.5e-1 == 0.25 &amp;&amp; 0x10 == 16",
        "x := 0; x += 1 / 2 &gt; 0.4",
        // Stored reals (a `float64` entry), the bit operators, any divisor.
        "x := 5 / 2",
        "x := 1; x /= 2",
        "x := 2.5 &gt; 1 ? 0.5 : 1",
        "x := 1 &amp; 3 | ~2 ^ 1",
        "y := 0; x := 1 / y &gt; 0",
        "x := 1 / 0 &gt; 0; z := 1 / -x",
        "x := 'abc' &lt; 'abd' &amp;&amp; ' 3' == 3",
    ] {
        if let Err(e) = lower_act(&format!("<Script code=\"{code}\"/>"), "", btcpp) {
            panic!("{code}: {e}");
        }
    }
}

/// A leaf whose `float64` port `out` writes 1.5 and answers SUCCESS.
const WRITER: &str = r#"<ascxml xmlns="http://www.w3.org/2005/07/scxml" initial="s" version="1.0" name="Gauge">
<bt_declare_port_out key="out" type="float64"/>
<state id="s"><bt_tick target="s"><bt_set_output key="out" expr="1.5"/><bt_return_status status="SUCCESS"/></bt_tick></state>
</ascxml>"#;

/// Lowers `body` under BT.CPP's rules with the `Gauge` plugin: the errors, if any.
fn with_gauge(body: &str) -> Result<(), String> {
    lower_doc(body, "", &[("gauge.ascxml", WRITER)], BTCPP).map(|_| ())
}

#[test]
fn scripts_read_a_double_a_plugin_port_writes_and_may_not_write_it() {
    // Read: compared, in arithmetic, stored into an entry only scripts write (a float).
    for code in [
        "level &gt; 0.3",
        "level * 2 - 1 &lt; 0.5",
        "y := level / 2; y &gt; 0",
    ] {
        let body = format!(
            "<Sequence><Gauge out=\"{{level}}\"/><ScriptCondition code=\"{code}\"/></Sequence>"
        );
        with_gauge(&body).unwrap_or_else(|e| panic!("{code}: {e}"));
    }
    // Written by a script: refused at the script, with the column of the assignment.
    let e = with_gauge(
        "<Sequence><Gauge out=\"{level}\"/><Script code=\"x := 1; level := 0.5\"/></Sequence>",
    )
    .expect_err("a script writing the port's entry");
    assert!(
        e.contains("tree.xml:3:47: `code` of Script: a script writing `level`, which a plugin's output port types as a double")
            && e.contains("(at column 9 of the script)"),
        "{e}"
    );
}

/// A leaf whose `float64` input port `speed` it only reads, answering SUCCESS.
const READER: &str = r#"<ascxml xmlns="http://www.w3.org/2005/07/scxml" initial="s" version="1.0" name="Drive">
<bt_declare_port_in key="speed" type="float64"/>
<state id="s"><bt_tick target="s"><bt_return_status status="SUCCESS"/></bt_tick></state>
</ascxml>"#;

#[test]
fn scripts_write_a_double_only_plugin_input_ports_name() {
    // A script setting an action's parameter: `:=` and, as the port created the entry
    // when the tree was loaded, `=` too; then read back in a condition.
    for code in [
        "speed := 0.5",
        "speed = 1.5",
        "speed := 2; speed = speed / 4",
        "speed = 0.25; speed &lt; 1",
    ] {
        let body =
            format!("<Sequence><Script code=\"{code}\"/><Drive speed=\"{{speed}}\"/></Sequence>");
        lower_doc(&body, "", &[("drive.ascxml", READER)], BTCPP)
            .unwrap_or_else(|e| panic!("{code}: {e}"));
    }
    // Once another plugin's output port writes the entry too, a script may not.
    let e = lower_doc(
        "<Sequence><Gauge out=\"{speed}\"/><Script code=\"speed := 0.5\"/><Drive speed=\"{speed}\"/></Sequence>",
        "",
        &[("gauge.ascxml", WRITER), ("drive.ascxml", READER)],
        BTCPP,
    )
    .expect_err("a script writing an entry a plugin's output port writes");
    assert!(
        e.contains("a script writing `speed`, which a plugin's output port types as a double"),
        "{e}"
    );
}

/// A leaf with a port `k` of direction `dir` and type `ty`.
fn port_plugin(dir: &str, ty: &str) -> String {
    format!(
        r#"<ascxml xmlns="http://www.w3.org/2005/07/scxml" initial="s" version="1.0" name="P">
<bt_declare_port_{dir} key="k" type="{ty}"/>
<state id="s"><bt_tick target="s"><bt_return_status status="SUCCESS"/></bt_tick></state>
</ascxml>"#
    )
}

#[test]
fn scripts_write_a_text_only_plugin_string_input_ports_name() {
    let lower = |dir: &str, ty: &str, code: &str| {
        let body = format!("<Sequence><Script code=\"{code}\"/><P k=\"{{e}}\"/></Sequence>");
        lower_doc(&body, "", &[("p.ascxml", &port_plugin(dir, ty))], BTCPP)
    };
    for code in [
        "e := 'go'",
        "e = 'go'",
        "e := 'a'; e := e == 'a' ? 'b' : 'c'",
        "e := 'go'; e += 'al'",
    ] {
        lower("in", "string", code).unwrap_or_else(|e| panic!("{code}: {e}"));
    }
    // A string where a plugin writes (it may write any text) or a port types numbers.
    for (dir, ty) in [("out", "string"), ("in", "int32"), ("in", "bool")] {
        let e = lower(dir, ty, "e := 'go'").expect_err("refused");
        assert!(
            e.contains(&format!("a script assigns a string to the entry `e`, which is {ty} at tree.xml:3:43 (port `k` of plugin `P`)"))
                && e.contains("modelled only where `string` input ports alone name it"),
            "{dir} {ty}: {e}"
        );
    }
    // A number into it: the entry holds strings.
    let e = lower("in", "string", "e := 'go'; e := 3").expect_err("refused");
    assert!(
        e.contains("assigning a number to `e`, which holds strings"),
        "{e}"
    );
}
