//! JANI property files: the Past-MTL they become, their ports, and errors that name the
//! file, line and column.

mod common;

use std::path::Path;

use hindsight::verify::model::ModelSource;
use hindsight::verify::observe::PropertySet;
use hindsight::verify::props::{self, PortKind, ANY};
use hindsight::verify::sim::CompiledModel;

fn model() -> CompiledModel {
    let s = r#"<scxml name="s" initial="a" version="1.0" xmlns="http://www.w3.org/2005/07/scxml">
  <datamodel><data id="n" expr="0"/></datamodel>
  <state id="a"><onentry>
    <send event="topic_level__msg" target="r">
      <param name="ros_fields__data" expr="n"/>
      <param name="name" expr="'ab'"/>
      <param name="list" expr="[1, 2, 3]"/>
      <param name="x" expr="1.5"/>
    </send>
  </onentry></state>
</scxml>"#;
    let r = r#"<scxml name="r" initial="w" version="1.0" xmlns="http://www.w3.org/2005/07/scxml">
  <state id="w"><transition event="topic_level__msg" target="w"/></state>
</scxml>"#;
    CompiledModel::compile(ModelSource::from_texts([("s.scxml", s), ("r.scxml", r)]).unwrap())
        .unwrap()
}

fn read(text: &str) -> Result<props::PropertyFile, String> {
    props::jani::parse_str(text, Path::new("p.jani"), &model()).map_err(|d| d.to_string())
}

fn prop(name: &str, path: &str) -> String {
    format!(
        r#"{{"properties": [{{"name": "{name}", "expression": {{"op": "filter", "fun": "values",
  "values": {{"op": "Pmin", "exp": {path}}}, "states": {{"op": "initial"}}}}}}]}}"#
    )
}

#[test]
fn f_g_and_u_become_past_formulas_judged_at_the_end() {
    let f = read(&prop(
        "f",
        r#"{"op": "F", "exp": {"op": "∧", "left": "topic_level__msg.valid",
             "right": {"op": "≤", "left": "topic_level__msg__ros_fields__data", "right": 0}}}"#,
    ))
    .unwrap();
    assert_eq!(f.guarantees.len(), 1);
    assert_eq!(
        f.guarantees[0].formula.as_str(),
        "P {((topic_level__msg_valid) && ((topic_level__msg__ros_fields__data <= 0)))}"
    );
    // `E.valid` and `E__P` (the event's name contains `__` too) observe every sender.
    assert_eq!(f.ports.len(), 2);
    assert_eq!(f.ports[0].kind, PortKind::Sent);
    assert_eq!(
        (f.ports[0].origin.as_str(), f.ports[0].target.as_str()),
        (ANY, ANY)
    );
    assert!(matches!(&f.ports[1].kind, PortKind::State { param, ty, .. }
        if param == "ros_fields__data" && ty == "int64"));

    let g = read(&prop(
        "g",
        r#"{"op": "G", "exp": {"op": "¬", "exp": "topic_level__msg.valid"}}"#,
    ))
    .unwrap();
    assert_eq!(
        g.guarantees[0].formula.as_str(),
        "H {!(topic_level__msg_valid)}"
    );

    let u = read(&prop(
        "u",
        r#"{"op": "U", "left": {"op": "<", "left": {"op": "abs", "exp": "topic_level__msg__x"}, "right": 2.0},
             "right": {"op": "=", "left": "topic_level__msg__name", "right": {"op": "av", "elements": [97, 98]}}}"#,
    ))
    .unwrap();
    assert_eq!(
        u.guarantees[0].formula.as_str(),
        "P ({(topic_level__msg__name == \"ab\")} && Z H {((topic_level__msg__x < 2.0) && ((-(topic_level__msg__x)) < 2.0))})"
    );
    let t = read(&prop(
        "t",
        r#"{"op": "U", "left": true, "right": "topic_level__msg.valid"}"#,
    ))
    .unwrap();
    assert_eq!(
        t.guarantees[0].formula.as_str(),
        "P {topic_level__msg_valid}"
    );
}

#[test]
fn array_elements_lengths_and_string_characters_are_ports() {
    let f = read(&prop(
        "a",
        r#"{"op": "F", "exp": {"op": "∧",
            "left": {"op": "=", "left": "topic_level__msg__list.d1_len", "right": 3},
            "right": {"op": "=", "left": {"op": "aa", "exp": "topic_level__msg__name", "index": 1}, "right": 98}}}"#,
    ))
    .unwrap();
    assert_eq!(
        f.guarantees[0].formula.as_str(),
        "P {(((topic_level__msg__list_len == 3)) && ((topic_level__msg__name_1 == 98)))}"
    );
    assert!(
        matches!(&f.ports[0].kind, PortKind::Part { param, path, length: true, .. }
        if param == "list" && path.is_empty())
    );
    assert!(
        matches!(&f.ports[1].kind, PortKind::Part { param, path, length: false, ty }
        if param == "name" && path == &[1] && ty == "int64")
    );
    // The compiled monitor accepts them.
    PropertySet::new(&f, &model()).unwrap();
}

#[test]
fn errors_name_file_line_and_column() {
    let e = read("{\"properties\": [\n  {\"name\": 1}\n]}").unwrap_err();
    assert_eq!(
        e,
        "p.jani:2:3: a property needs a string `name`\n      {\"name\": 1}\n      ^"
    );

    let e = read("{\"properties\": [\n  {\"name\" \"x\"}]}").unwrap_err();
    assert_eq!(
        e,
        "p.jani:2:11: malformed JSON: expected `:`\n      {\"name\" \"x\"}]}\n              ^"
    );

    let text = prop("p", r#"{"op": "F", "exp": "nope"}"#);
    let e = read(&text).unwrap_err();
    assert!(
        e.starts_with("p.jani:2:54: `nope` is neither `E.valid` nor `E__P`"),
        "{e}"
    );

    let text = prop(
        "p",
        r#"{"op": "U", "step-bounds": {"lower": 100}, "left": true, "right": true}"#,
    );
    let e = read(&text).unwrap_err();
    assert!(
        e.starts_with("p.jani:2:47: `step-bounds` are not supported"),
        "{e}"
    );

    let e = read(&prop("p", r#"{"op": "F", "exp": 3}"#)).unwrap_err();
    assert_eq!(
        e.lines().next(),
        Some("p.jani:2:54: a state formula must be boolean")
    );
    // The caret stands under the 54th character of the line shown.
    assert_eq!(e.lines().nth(2).map(|l| l.len()), Some(4 + 54));

    let e = read(&prop("p", r#"{"op": "X", "exp": true}"#)).unwrap_err();
    assert!(e.contains("path operator `X` is not supported"), "{e}");

    // Every error is reported, in file order.
    let two = r#"{"properties": [
  {"name": "a", "expression": {"op": "Pmin", "exp": {"op": "F", "exp": "u1"}}},
  {"name": "b", "expression": {"op": "Pmax", "exp": {"op": "G", "exp": "u2"}}}]}"#;
    let e = read(two).unwrap_err();
    let heads: Vec<&str> = e.lines().filter(|l| l.starts_with("p.jani:")).collect();
    assert_eq!(heads.len(), 2, "{e}");
    assert!(
        heads[0].starts_with("p.jani:2:") && heads[1].starts_with("p.jani:3:"),
        "{e}"
    );
}

#[test]
fn the_corpus_property_files_read() {
    let Some(root) = common::corpus_or_skip() else {
        return;
    };
    let root = root.join("as2fm");
    let m = CompiledModel::load(&root.join("plain/ros_example_main")).unwrap();
    let f = props::jani::parse_file(
        &root.join("test_data/ros_example/battery_properties.jani"),
        &m,
    )
    .unwrap();
    let names: Vec<&str> = f.guarantees.iter().map(|g| g.id.as_str()).collect();
    assert_eq!(
        names,
        ["battery_depleted", "battery_over_depleted", "alarm_on"]
    );
    PropertySet::new(&f, &m).unwrap();
}

#[test]
fn no_prefix_or_byte_flip_of_a_real_file_panics() {
    let Some(root) = common::corpus_or_skip() else {
        return;
    };
    let root = root.join("as2fm");
    let m = CompiledModel::load(&root.join("plain/ros_example_main")).unwrap();
    let text = std::fs::read_to_string(root.join("test_data/ros_example/battery_properties.jani"))
        .unwrap();
    let path = Path::new("p.jani");
    for end in (0..text.len()).filter(|&i| text.is_char_boundary(i)) {
        let _ = props::jani::parse_str(&text[..end], path, &m);
    }
    let bytes = text.as_bytes();
    for i in (0..bytes.len()).step_by(3) {
        for b in [b'"', b'{', b'}', b'[', b']', b',', b':', b'\\', b'0', b'x'] {
            let mut v = bytes.to_vec();
            v[i] = b;
            if let Ok(t) = String::from_utf8(v) {
                let _ = props::jani::parse_str(&t, path, &m);
            }
        }
    }
}
