//! Main files as AS2FM's reader takes them (`RoamlMain` in
//! `jani_generator/scxml_helpers/roaml_model.py`): everything it reads is accepted, what it
//! ignores is ignored with a warning at its position, a misspelling is an error with
//! "did you mean", and what it refuses is refused.

use std::path::{Path, PathBuf};

use hindsight::verify::model::source::SourceMap;
use hindsight::verify::robot::main_file::{InputKind, MainFile};

fn temp_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("hindsight-main-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// `(warnings, errors)` of `text` read as a main file, each `path:line:col: message`.
fn read(name: &str, text: &str) -> (PathBuf, Result<Vec<String>, Vec<String>>) {
    let d = temp_dir(name);
    let p = d.join("main.xml");
    std::fs::write(&p, text).unwrap();
    let mut sm = SourceMap::new();
    let r = MainFile::parse(&mut sm, &p)
        .map(|m| m.warnings.iter().map(|w| w.to_string()).collect())
        .map_err(|e| e.iter().map(|d| d.to_string()).collect());
    (p, r)
}

fn cleanup(p: &Path) {
    let _ = std::fs::remove_dir_all(p.parent().unwrap());
}

/// Every element, attribute and input type AS2FM's reader reads, in both forms, reads
/// without a warning.
#[test]
fn everything_as2fm_reads_is_accepted() {
    let text = r#"<?xml version="1.0"?>
<roaml xmlns="urn:x">
  <!-- a comment -->
  <parameters>
    <max_time value="100" unit="s"/>
    <max_array_size value="10"/>
    <bt_tick_rate value="5.0"/>
    <bt_tick_if_not_running value="true"/>
  </parameters>
  <data_declarations>
    <input type="xml" src="./types.xml"/>
    <input type="json" src="./types.json"/>
  </data_declarations>
  <behavior_tree>
    <input type="bt.cpp-xml" src="./bt.xml"/>
    <input type="bt-plugin-ascxml" src="./a.ascxml"/>
    <input type="bt-plugin-ros-scxml" src="./b.scxml"/>
  </behavior_tree>
  <node_models>
    <input type="node-ascxml" src="./n.ascxml"/>
    <input id="old" type="ros-scxml" src="./m.scxml"/>
  </node_models>
  <properties>
    <input id="props" type="jani" src="./p.jani"/>
  </properties>
</roaml>
"#;
    let (p, r) = read("all", text);
    assert_eq!(r, Ok(vec![]));
    let mut sm = SourceMap::new();
    let m = MainFile::parse(&mut sm, &p).unwrap();
    assert_eq!(m.node_models[1].kind, InputKind::RosScxml);
    assert_eq!(m.behavior_tree.as_ref().unwrap().plugins.len(), 2);
    assert_eq!(m.params.max_array_size_or_default(), 10);
    cleanup(&p);
    // The older form.
    let (p, r) = read(
        "old",
        "<convince_mc_tc>\n<mc_parameters><max_time value=\"1\" unit=\"ms\"/></mc_parameters>\n</convince_mc_tc>",
    );
    assert_eq!(r, Ok(vec![]));
    cleanup(&p);
}

/// What AS2FM never reads is ignored with a warning naming it, at its position.
#[test]
fn what_as2fm_ignores_is_ignored_with_a_warning() {
    let cases: &[(&str, &str, &str)] = &[
        (
            "rootattr",
            "<roaml version=\"2\">\n<parameters><max_time value=\"1\" unit=\"s\"/></parameters></roaml>",
            ":1:8: attribute `version` on <roaml> is ignored",
        ),
        (
            "element",
            "<roaml>\n<parameters><max_time value=\"1\" unit=\"s\"/></parameters>\n  <description>x</description>\n</roaml>",
            ":3:3: element <description> in <roaml> is ignored",
        ),
        (
            "inputattr",
            "<roaml><parameters><max_time value=\"1\" unit=\"s\"/></parameters>\n<node_models>\n  <input type=\"node-ascxml\" src=\"a\" comment=\"x\"/>\n</node_models></roaml>",
            ":3:37: attribute `comment` on <input> is ignored",
        ),
        (
            "paramattr",
            "<roaml><parameters>\n<max_time value=\"1\" unit=\"s\" note=\"x\"/></parameters></roaml>",
            ":2:30: attribute `note` on <max_time> is ignored",
        ),
        (
            "paramchild",
            "<roaml><parameters>\n<max_time value=\"1\" unit=\"s\"><x/></max_time></parameters></roaml>",
            ":2:30: <x> in <max_time> is ignored",
        ),
        (
            "inputchild",
            "<roaml><parameters><max_time value=\"1\" unit=\"s\"/></parameters>\n<properties><input type=\"jani\" src=\"p\">\n<why/></input></properties></roaml>",
            ":3:1: <why> in <input> is ignored",
        ),
        (
            "text",
            "<roaml><parameters><max_time value=\"1\" unit=\"s\"/></parameters>\n<node_models>stray</node_models></roaml>",
            ":2:14: text in <node_models> is ignored",
        ),
        (
            "both",
            "<roaml><parameters><max_time value=\"1\" unit=\"s\"/></parameters>\n<mc_parameters><max_time value=\"2\" unit=\"s\"/></mc_parameters></roaml>",
            ":2:1: <mc_parameters> is ignored: <parameters> is given",
        ),
    ];
    for (name, text, want) in cases {
        let (p, r) = read(name, text);
        let warnings = r.unwrap_or_else(|e| panic!("{name}: {e:?}"));
        assert_eq!(warnings.len(), 1, "{name}: {warnings:?}");
        assert!(
            warnings[0].starts_with(&p.display().to_string()) && warnings[0].contains(want),
            "{name}: want `{want}`, got {warnings:?}"
        );
        cleanup(&p);
    }
    // `<parameters>` wins over `<mc_parameters>`, as in AS2FM.
    let (p, _) = read(
        "wins",
        "<roaml><mc_parameters><max_time value=\"2\" unit=\"s\"/></mc_parameters>\n<parameters><max_time value=\"1\" unit=\"s\"/></parameters></roaml>",
    );
    let mut sm = SourceMap::new();
    let m = MainFile::parse(&mut sm, &p).unwrap();
    assert_eq!(m.params.max_time_ns.value, 1_000_000_000);
    cleanup(&p);
}

/// A name close to one AS2FM reads is a misspelling: an error with "did you mean".
#[test]
fn a_misspelling_gets_did_you_mean() {
    let cases: &[(&str, &str, &str)] = &[
        (
            "section",
            "<roaml><parameters><max_time value=\"1\" unit=\"s\"/></parameters>\n<node_model/></roaml>",
            ":2:1: unknown element <node_model> in <roaml>; did you mean <node_models>?",
        ),
        (
            "attr",
            "<roaml><parameters><max_time value=\"1\" unit=\"s\"/></parameters>\n<node_models><input tpye=\"node-ascxml\" src=\"a\"/></node_models></roaml>",
            ":2:21: unknown attribute `tpye` on <input>; did you mean `type`?",
        ),
        (
            "param",
            "<roaml><parameters>\n<max_time value=\"1\" unit=\"s\"/><bt_tick_rte value=\"1\"/></parameters></roaml>",
            ":2:31: unknown parameter <bt_tick_rte>; did you mean <bt_tick_rate>?",
        ),
        (
            "unit",
            "<roaml><parameters>\n<max_time value=\"1\" unti=\"s\"/></parameters></roaml>",
            ":2:21: unknown attribute `unti` on <max_time>; did you mean `unit`?",
        ),
    ];
    for (name, text, want) in cases {
        let (p, r) = read(name, text);
        let errs = r.expect_err(name);
        assert!(
            errs[0].starts_with(&p.display().to_string()) && errs[0].contains(want),
            "{name}: want `{want}`, got {errs:?}"
        );
        cleanup(&p);
    }
}

/// The warnings reach the user: `validate` prints them and loads the model.
#[test]
fn validate_prints_the_warnings() {
    let d = temp_dir("cli");
    std::fs::write(
        d.join("n.ascxml"),
        "<ascxml initial=\"s\" version=\"1.0\" name=\"N\" xmlns=\"http://www.w3.org/2005/07/scxml\">\n\
         <ros_topic_publisher name=\"p\" topic=\"/level\" type=\"std_msgs/Int32\"/>\n\
         <ros_time_rate name=\"t\" rate_hz=\"1\"/>\n\
         <state id=\"s\"><ros_rate_callback name=\"t\" target=\"s\"><ros_topic_publish name=\"p\"><field name=\"data\" expr=\"1\"/></ros_topic_publish></ros_rate_callback></state>\n</ascxml>\n",
    )
    .unwrap();
    std::fs::write(
        d.join("p.xml"),
        "<properties>\n  <ports>\n    <ros_topic topic=\"/level\" type=\"std_msgs/Int32\">\n      \
         <state_var id=\"x\" type=\"int32\" field=\"data\" expr=\"0\"/>\n    </ros_topic>\n  </ports>\n  <guarantees>\n    \
         <property id=\"g\" logic=\"pmtl\" expr=\"historically({x &lt;= 1})\"/>\n  </guarantees>\n</properties>\n",
    )
    .unwrap();
    std::fs::write(
        d.join("main.xml"),
        "<roaml>\n<parameters><max_time value=\"3\" unit=\"s\"/></parameters>\n\
         <node_models><input id=\"node\" type=\"node-ascxml\" src=\"./n.ascxml\" owner=\"me\"/></node_models>\n\
         <properties><input id=\"props\" type=\"xml\" src=\"./p.xml\"/></properties>\n</roaml>\n",
    )
    .unwrap();
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_hindsight"))
        .arg("validate")
        .arg(d.join("main.xml"))
        .env_remove("AMENT_PREFIX_PATH")
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{err}");
    assert!(
        err.contains(&format!(
            "warning: {}:3:67: attribute `owner` on <input> is ignored",
            d.join("main.xml").display()
        )),
        "{err}"
    );
    assert!(!err.contains("`id`"), "{err}");
    let _ = std::fs::remove_dir_all(&d);
}
