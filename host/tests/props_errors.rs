//! Bad property files: every error names the file, line and column, and independent
//! problems are all reported.

mod common;

use std::path::{Path, PathBuf};

use hindsight::verify::props::{
    location, parse_file, parse_str, Location, PropsError, PropsErrorKind,
};

fn errors(text: &str) -> Vec<PropsError> {
    match parse_str(text, Path::new("props.xml")) {
        Ok(file) => panic!("accepted: {file:?}"),
        Err(diagnostics) => diagnostics.0,
    }
}

/// The only error, with its location.
#[track_caller]
fn single(text: &str) -> (Location, PropsErrorKind) {
    let mut all = errors(text);
    assert_eq!(all.len(), 1, "{all:?}");
    let error = all.remove(0);
    assert_eq!(error.file, "props.xml");
    (location(&error), error.message)
}

const PORT: &str =
    r#"<scxml_event_send event="e" origin="a" target="b"><event_var id="ev"/></scxml_event_send>"#;

fn current(ports: &str, guarantees: &str) -> String {
    format!("<properties>\n<ports>\n{ports}\n</ports>\n<guarantees>\n{guarantees}\n</guarantees>\n</properties>\n")
}

#[test]
fn malformed_xml() {
    let (at, kind) = single("<properties>\n  <ports>\n  </port>\n</properties>");
    assert_eq!(at.line, 3);
    assert!(matches!(kind, PropsErrorKind::Xml(_)), "{kind:?}");

    let (at, kind) = single("<properties>\n  <ports>\n</properties>");
    assert!(matches!(kind, PropsErrorKind::Xml(_)));
    assert_eq!(at.line, 3);

    let (at, kind) = single("<properties>\n  <ports>\n");
    assert_eq!(
        (at, kind),
        (
            Location::new(2, 3),
            PropsErrorKind::Xml("<ports> is never closed".to_owned())
        )
    );

    let (at, _) = single("<properties>\n <ports a=\"1\" a=\"2\"/>\n</properties>");
    assert_eq!(at.line, 2);

    let (at, kind) = single("");
    assert_eq!(
        (at, kind),
        (
            Location::new(1, 1),
            PropsErrorKind::Xml("no root element".to_owned())
        )
    );

    let (at, _) = single("<properties/>\n<properties/>");
    assert_eq!(at, Location::new(2, 1));

    let (at, _) = single("<properties/>\n  junk");
    assert_eq!(at, Location::new(2, 3));
}

#[test]
fn deep_nesting_is_an_error_not_a_stack_overflow() {
    // The tree form converts recursively; the one XML tree stops nesting at 256
    // elements, at the first element too deep.
    let head = "<properties><guarantees><guarantee id=\"g\">";
    let depth = 5000;
    let text = format!(
        "{head}{}<true/>{}</guarantee></guarantees></properties>",
        "<not>".repeat(depth),
        "</not>".repeat(depth)
    );
    let (at, kind) = single(&text);
    let column = head.len() + (256 - 3) * "<not>".len() + 1;
    assert_eq!(
        (at, kind),
        (
            Location::new(1, column as u32),
            PropsErrorKind::Xml("elements nested too deeply".to_owned())
        )
    );
}

#[test]
fn bad_references_in_attribute_values() {
    let text = current(PORT, "  <property id=\"p\" expr=\"{ev} &amp&amp; true\"/>");
    let (at, kind) = single(&text);
    // Column of the `&` in line 6.
    assert_eq!(at, Location::new(6, 31));
    assert!(matches!(kind, PropsErrorKind::Xml(message) if message.contains("&")));

    let text = current(PORT, "  <property id=\"p\" expr=\"{ev} &nbsp; true\"/>");
    let (at, kind) = single(&text);
    assert_eq!(at, Location::new(6, 31));
    assert!(matches!(kind, PropsErrorKind::Xml(message) if message.contains("&nbsp;")));
}

#[test]
fn character_references_and_line_breaks_in_formulas() {
    let text = current(
        PORT,
        "  <property id=\"p\" expr=\"{ev}&#10;  -&#x3E;\n    true\"/>",
    );
    let file = parse_str(&text, Path::new("props.xml")).expect("valid");
    let formula = &file.guarantees[0].formula;
    assert_eq!(formula.as_str(), "{ev}\n  ->     true");
    // `true` is on line 7, column 5.
    let offset = formula.as_str().find("true").expect("present");
    assert_eq!(formula.location(offset), Location::new(7, 5));
    let offset = formula.as_str().find('>').expect("present");
    assert_eq!(formula.location(offset), Location::new(6, 38));
}

#[test]
fn unknown_elements_and_attributes() {
    let text = current(
        "  <ros_parameter name=\"/battery\" type=\"std_msgs/Int32\"/>",
        "  <property id=\"p\" expr=\"true\"/>",
    );
    let (at, kind) = single(&text);
    assert_eq!(at, Location::new(3, 3));
    assert_eq!(
        kind,
        PropsErrorKind::UnknownElement {
            name: "ros_parameter".to_owned(),
            parent: "ports".to_owned(),
            expected: "<scxml_event_send>, <ros_topic>, <ros_service> or <port>",
        }
    );

    let text = current(
        PORT,
        "  <property id=\"p\" pattern=\"absence\" event=\"x\" expr=\"true\"/>",
    );
    let (at, kind) = single(&text);
    assert_eq!(at, Location::new(6, 48));
    assert_eq!(
        kind,
        PropsErrorKind::UnknownAttribute {
            element: "property".to_owned(),
            name: "expr".to_owned(),
        }
    );

    let (at, kind) = single("<specification/>");
    assert_eq!(at, Location::new(1, 1));
    assert!(matches!(kind, PropsErrorKind::UnknownElement { parent, .. } if parent.is_empty()));

    let text = current(PORT, "  <property id=\"p\" expr=\"true\">text</property>");
    let (at, kind) = single(&text);
    assert_eq!(at, Location::new(6, 32));
    assert_eq!(
        kind,
        PropsErrorKind::UnexpectedText {
            element: "property".to_owned()
        }
    );
}

#[test]
fn missing_attributes() {
    let text = current(
        "  <scxml_event_send event=\"e\" origin=\"a\">\n    <state_var id=\"x\" param=\"p\" expr=\"0\"/>\n  </scxml_event_send>",
        "",
    );
    let all = errors(&text);
    let found: Vec<(Location, PropsErrorKind)> = all
        .into_iter()
        .map(|error| (location(&error), error.message))
        .collect();
    assert_eq!(
        found,
        [
            (
                Location::new(3, 3),
                PropsErrorKind::MissingAttribute {
                    element: "scxml_event_send".to_owned(),
                    name: "target",
                }
            ),
            (
                Location::new(4, 5),
                PropsErrorKind::MissingAttribute {
                    element: "state_var".to_owned(),
                    name: "type",
                }
            ),
        ]
    );

    let text = current(PORT, "  <property expr=\"true\"/>");
    assert_eq!(
        single(&text),
        (
            Location::new(6, 3),
            PropsErrorKind::MissingAttribute {
                element: "property".to_owned(),
                name: "id",
            }
        )
    );
}

#[test]
fn bad_values_and_duplicates() {
    let text = current(
        &format!("  {PORT}\n  <scxml_event_send event=\"f\" origin=\"a\" target=\"b\"><state_var id=\"ev\" param=\"q\" type=\"int33\" expr=\"0\"/></scxml_event_send>"),
        "  <property id=\"p\" logic=\"ltl\" expr=\"true\"/>\n  <property id=\"p\" expr=\"{ev}\"/>",
    );
    let found: Vec<(Location, PropsErrorKind)> = errors(&text)
        .into_iter()
        .map(|e| (location(&e), e.message))
        .collect();
    assert_eq!(found.len(), 3, "{found:?}");
    assert_eq!(found[0].0, Location::new(4, 82));
    assert!(
        matches!(&found[0].1, PropsErrorKind::BadValue { attribute, value, .. } if attribute == "type" && value == "int33")
    );
    assert_eq!(found[1].0, Location::new(7, 20));
    assert!(
        matches!(&found[1].1, PropsErrorKind::BadValue { attribute, .. } if attribute == "logic")
    );
    assert_eq!(
        found[2],
        (
            Location::new(8, 3),
            PropsErrorKind::Duplicate {
                what: "property",
                id: "p".to_owned(),
                first: Location::new(7, 3),
            }
        )
    );

    // The same variable declared twice (the type error above hid the second one).
    let text = current(&format!("{PORT}\n{PORT}"), "");
    assert_eq!(
        single(&text),
        (
            Location::new(4, 51),
            PropsErrorKind::Duplicate {
                what: "variable",
                id: "ev".to_owned(),
                first: Location::new(3, 51),
            }
        )
    );
}

const TREE_PORTS: &str = r#"<properties>
  <ports>
    <port id="level" type="int32">
      <origin refid="Battery"/>
      <target refid="Skill"/>
      <message event="level_msg" param_name="data" expr="100"/>
    </port>
    <port id="alarm" type="boolean">
      <origin refid="Alarm"/>
      <target refid="Notify"/>
      <message event="alarm_req"/>
    </port>
  </ports>
"#;

fn tree(rest: &str) -> String {
    format!("{TREE_PORTS}{rest}\n</properties>\n")
}

#[test]
fn tree_form_converts_every_operator() {
    let text = tree(
        r#"  <predicates>
    <predicate id="low"><leq><var refid="level"/><const type="int32" expr="30"/></leq></predicate>
    <predicate id="mid"><and><var refid="low"/><greater><sum><var refid="level"/><const type="int32" expr="5"/></sum><opposite><const type="float32" expr="2.5"/></opposite></greater></and></predicate>
    <predicate id="odd"><or><not><equal><mult><var refid="level"/><const type="int32" expr="2"/></mult><const type="int32" expr="4"/></equal></not><implies><less><var refid="level"/><const type="int32" expr="1"/></less><geq><var refid="level"/><const type="int32" expr="0"/></geq></implies></or></predicate>
  </predicates>
  <guarantees>
    <guarantee id="g1"><historically lower_bound="2" upper_bound="9"><or><var refid="mid"/><false/></or></historically></guarantee>
    <guarantee id="g2"><implies><previously upper_bound="30"><true/></previously><once lower_bound="1"><var refid="odd"/></once></implies></guarantee>
    <guarantee id="g3"><and><var refid="alarm"/></and></guarantee>
  </guarantees>
  <assumes>
    <assume id="a1"><since><not><var refid="alarm"/></not><var refid="low"/></since></assume>
  </assumes>"#,
    );
    let file = parse_str(&text, Path::new("props.xml")).unwrap_or_else(|e| panic!("{e}"));
    let formulas: Vec<(&str, &str)> = file
        .guarantees
        .iter()
        .chain(&file.assumptions)
        .map(|p| (p.id.as_str(), p.formula.as_str()))
        .collect();
    assert_eq!(
        formulas,
        [
            (
                "g1",
                "historically[2:9] ({(level <= 30) && ((level + 5) > (-2.5))} || false)"
            ),
            (
                "g2",
                "(once[:30] true) -> \
                 (once[1:] {(!((level * 2) == 4)) || (!(level < 1) || (level >= 0))})"
            ),
            ("g3", "{alarm}"),
            ("a1", "(!{alarm}) since {level <= 30}"),
        ]
    );
}

#[test]
fn tree_form_errors() {
    let cases: [(&str, Location, &str); 9] = [
        (
            r#"<guarantees><guarantee id="g"><var refid="nope"/></guarantee></guarantees>"#,
            Location::new(14, 31),
            "`nope` is neither a declared variable nor a predicate",
        ),
        (
            r#"<guarantees><guarantee id="g"><var refid="level"/></guarantee></guarantees>"#,
            Location::new(14, 31),
            "<var> has integer type, but a formula needs a boolean",
        ),
        (
            r#"<guarantees><guarantee id="g"><since><true/></since></guarantee></guarantees>"#,
            Location::new(14, 31),
            "<since> takes two operands, found 1",
        ),
        (
            r#"<guarantees><guarantee id="g"><since lower_bound="x"><true/><true/></since></guarantee></guarantees>"#,
            Location::new(14, 38),
            "`lower_bound=\"x\"`: expected a non-negative integer (time units)",
        ),
        (
            r#"<guarantees><guarantee id="g"><once lower_bound="5" upper_bound="2"><true/></once></guarantee></guarantees>"#,
            Location::new(14, 53),
            "`upper_bound=\"2\"`: expected at least lower_bound (5)",
        ),
        (
            r#"<predicates><predicate id="p"><less><var refid="q"/><const type="int32" expr="1"/></less></predicate><predicate id="q"><var refid="p"/></predicate></predicates>"#,
            // The reference that closes the loop.
            Location::new(14, 120),
            "predicate `p` refers to itself",
        ),
        (
            r#"<predicates><predicate id="p"><equal><once><true/></once><true/></equal></predicate></predicates>"#,
            Location::new(14, 38),
            "temporal operator <once> inside a predicate or arithmetic expression",
        ),
        (
            r#"<predicates><predicate id="p"><equal><var refid="level"/><const type="int32" expr="3.5"/></equal></predicate></predicates>"#,
            Location::new(14, 84),
            "`expr=\"3.5\"`: expected an integer constant",
        ),
        (
            r#"<guarantees><guarantee id="g"><until><true/><true/></until></guarantee></guarantees>"#,
            Location::new(14, 31),
            "unknown element <until> in <guarantee>",
        ),
    ];
    for (body, at, message) in cases {
        let text = tree(body);
        let found = errors(&text);
        let first = &found[0];
        assert_eq!(location(first), at, "{body}: {found:?}");
        assert!(
            first.message.to_string().starts_with(message),
            "{body}: `{}`",
            first.message
        );
        assert!(first
            .to_string()
            .starts_with(&format!("props.xml:{}:{}: ", at.line, at.column)));
    }
}

#[test]
fn tree_form_port_errors() {
    let text = r#"<properties><ports>
  <port id="level" type="int32"><origin refid="A"/><target refid="B"/><message event="m"/></port>
  <port id="flag" type="boolean"><origin refid="A"/><origin refid="C"/><message event="m"/></port>
</ports></properties>"#;
    let found: Vec<(Location, String)> = errors(text)
        .into_iter()
        .map(|e| (location(&e), e.message.to_string()))
        .collect();
    assert_eq!(
        found,
        [
            (
                Location::new(2, 3),
                "port `level` has no `param_name`, so it is an event variable and must have \
                 type boolean, not int32"
                    .to_owned()
            ),
            (
                Location::new(3, 3),
                "<port> needs a <target> element".to_owned()
            ),
            (
                Location::new(3, 53),
                "<port> has more than one <origin>".to_owned()
            ),
        ]
    );
}

#[test]
fn files_that_cannot_be_read() {
    let dir = std::env::temp_dir().join(format!("hindsight-props-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let missing = dir.join("missing.xml");
    let error = parse_file(&missing).expect_err("no such file");
    assert!(matches!(error.0[0].message, PropsErrorKind::Io(_)));
    assert_eq!(error.0[0].file, missing.display().to_string());

    let latin1 = dir.join("latin1.xml");
    std::fs::write(&latin1, b"<properties>\n  <!-- caf\xe9 -->\n</properties>").expect("write");
    let error = parse_file(&latin1).expect_err("not UTF-8");
    assert_eq!(error.0[0].message, PropsErrorKind::Encoding);
    assert_eq!(location(&error.0[0]), Location::new(2, 11));
    std::fs::remove_dir_all(&dir).expect("clean up");
}

/// Deterministic mutation fuzzing of the two corpus files: whatever the damage, the
/// reader returns a value (never panics), and every error lies inside the text.
#[test]
fn damaged_corpus_files_never_panic() {
    if common::corpus_or_skip().is_none() {
        return;
    }
    use rand_core::{Rng, SeedableRng};
    let root = corpus_root();
    let files = [
        root.join("uc3-plain/properties.xml"),
        root.join("museum-simpar2025/model_scxml/properties.xml"),
    ];
    let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(1);
    let alphabet = b"<>/=\"'&;#x{}() \n\tabz019-_!?:[]";
    for path in files {
        let original = std::fs::read(&path).expect("corpus file");
        for _ in 0..1500 {
            let mut bytes = original.clone();
            for _ in 0..1 + rng.next_u64() % 4 {
                let at = (rng.next_u64() % bytes.len() as u64) as usize;
                match rng.next_u64() % 4 {
                    0 => bytes[at] = alphabet[(rng.next_u64() % alphabet.len() as u64) as usize],
                    1 => {
                        bytes.remove(at);
                    }
                    2 => bytes.insert(
                        at,
                        alphabet[(rng.next_u64() % alphabet.len() as u64) as usize],
                    ),
                    _ => bytes.truncate(at),
                }
                if bytes.is_empty() {
                    bytes.push(b'<');
                }
            }
            let Ok(text) = String::from_utf8(bytes) else {
                continue;
            };
            let lines = text.lines().count().max(1) as u32;
            if let Err(diagnostics) = parse_str(&text, &path) {
                for error in diagnostics.0 {
                    assert!(error.line >= 1 && error.line <= lines + 1, "{error}");
                    assert!(error.col >= 1, "{error}");
                }
            }
        }
    }
}

fn corpus_root() -> PathBuf {
    common::corpus_root()
}
