//! The robot-model readers against the corpus: every ROS interface file parses, flattened
//! messages match the parameter names and types of AS2FM's plain translations, every
//! main file reads, and bad input gives a diagnostic at the right file, line and column.

mod common;

use hindsight::verify::model::source::SourceMap;
use hindsight::verify::robot::interfaces::{InterfaceKind, Interfaces};
use hindsight::verify::robot::types::{FlatField, InterfaceLookup};
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

fn corpus() -> PathBuf {
    common::corpus_root()
}

/// Every file under `dir` whose name ends with one of `exts`, sorted.
fn files_under(dir: &Path, exts: &[&str]) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else if p
                .extension()
                .and_then(|x| x.to_str())
                .is_some_and(|x| exts.contains(&x))
            {
                out.push(p);
            }
        }
    }
    out.sort();
    out
}

/// Every main file of the corpus (the ones AS2FM reads: `<roaml>` or `<convince_mc_tc>`).
fn main_files() -> Vec<PathBuf> {
    let c = corpus();
    let mut out = Vec::new();
    for root in [
        c.join("as2fm/test_data"),
        c.join("as2fm/examples"),
        c.join("museum-simpar2025/model-high-level"),
    ] {
        for p in files_under(&root, &["xml"]) {
            let text = std::fs::read_to_string(&p).unwrap();
            let head = text.trim_start_matches("<?xml version=\"1.0\" encoding=\"UTF-8\"?>");
            let head = head.trim_start();
            if head.starts_with("<roaml") || head.starts_with("<convince_mc_tc") {
                out.push(p);
            }
        }
    }
    out
}

fn all(fields: &[FlatField]) -> Vec<(String, String)> {
    fields
        .iter()
        .map(|f| (f.param_name(), f.scxml_type.clone()))
        .collect()
}

#[test]
fn every_corpus_interface_file_parses() {
    if common::corpus_or_skip().is_none() {
        return;
    }
    let c = corpus();
    let mut count = 0;
    for root in [
        c.join("as2fm/ros_support_interfaces"),
        c.join("museum-simpar2025/model-high-level/Interfaces"),
    ] {
        for p in files_under(&root, &["msg", "srv", "action"]) {
            let kind = InterfaceKind::from_dir(p.extension().unwrap().to_str().unwrap()).unwrap();
            let pkg = p.parent().unwrap().parent().unwrap();
            let pkg = pkg.file_name().unwrap().to_str().unwrap();
            let name = p.file_stem().unwrap().to_str().unwrap();
            let mut sm = SourceMap::new();
            let mut ifs = Interfaces::with_builtins();
            let text = std::fs::read_to_string(&p).unwrap();
            ifs.add_text(&mut sm, &p, text, pkg, kind, name)
                .unwrap_or_else(|e| panic!("{}: {e:?}", p.display()));
            count += 1;
        }
    }
    assert_eq!(count, 44 + 16, "interface files in the corpus");
}

#[test]
fn every_main_file_discovers_its_interfaces() {
    if common::corpus_or_skip().is_none() {
        return;
    }
    let mains = main_files();
    assert_eq!(mains.len(), 43, "main files in the corpus");
    let mut resolved = 0;
    for main in &mains {
        let mut sm = SourceMap::new();
        let ifs = Interfaces::discover(&mut sm, main, &[])
            .unwrap_or_else(|e| panic!("{}: {e:?}", main.display()));
        // Every type a model of the case names resolves.
        let dir = main.parent().unwrap();
        let case_dir = if dir.file_name().is_some_and(|n| n == "Main") {
            dir.parent().unwrap()
        } else {
            dir
        };
        for model in files_under(case_dir, &["ascxml", "scxml"]) {
            let text = std::fs::read_to_string(&model).unwrap();
            for (tag, kind) in [
                ("ros_topic_publisher", InterfaceKind::Message),
                ("ros_topic_subscriber", InterfaceKind::Message),
                ("ros_service_server", InterfaceKind::Service),
                ("ros_service_client", InterfaceKind::Service),
                ("ros_action_server", InterfaceKind::Action),
                ("ros_action_client", InterfaceKind::Action),
            ] {
                for chunk in text.split(&format!("<{tag}")).skip(1) {
                    let head = &chunk[..chunk.find('>').unwrap()];
                    let Some(i) = head.find("type=\"") else {
                        continue;
                    };
                    let ty = &head[i + 6..];
                    let ty = &ty[..ty.find('"').unwrap()];
                    let r = match kind {
                        InterfaceKind::Message => ifs.message(ty).map(|_| ()),
                        InterfaceKind::Service => ifs.service(ty).map(|_| ()),
                        InterfaceKind::Action => ifs.action(ty).map(|_| ()),
                    };
                    r.unwrap_or_else(|e| panic!("{} ({}): {e}", model.display(), main.display()));
                    resolved += 1;
                }
            }
        }
    }
    assert!(resolved >= 218, "{resolved} type references resolved");
}

/// Every `<!-- TYPE ros_fields__x:T -->` and `<param name="ros_fields__x">` in AS2FM's plain
/// translations is a flattened field (name and type) of some interface the corpus uses.
#[test]
fn flattening_matches_the_plain_translations() {
    if common::corpus_or_skip().is_none() {
        return;
    }
    let c = corpus();
    let mut sm = SourceMap::new();
    let ifs = Interfaces::discover(
        &mut sm,
        &c.join("as2fm/test_data/nested_data_ros/main.xml"),
        &[],
    )
    .unwrap();
    let mut known: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for def in ifs.iter() {
        let name = format!("{}/{}", def.package, def.name);
        let parts = match def.kind {
            InterfaceKind::Message => vec![ifs.message(&name).unwrap()],
            InterfaceKind::Service => {
                let s = ifs.service(&name).unwrap();
                vec![s.request, s.response]
            }
            InterfaceKind::Action => {
                let a = ifs.action(&name).unwrap();
                vec![a.goal, a.result, a.feedback]
            }
        };
        for part in parts {
            for (p, t) in all(&part) {
                known.entry(p).or_default().insert(t);
            }
        }
    }
    let mut typed = 0;
    let mut params = 0;
    for f in files_under(&c.join("as2fm/plain"), &["scxml"]) {
        let text = std::fs::read_to_string(&f).unwrap();
        for chunk in text.split("<!-- TYPE ros_fields__").skip(1) {
            let body = &chunk[..chunk.find(" -->").unwrap()];
            let (name, ty) = body.split_once(':').unwrap();
            let name = format!("ros_fields__{name}");
            let types = known
                .get(&name)
                .unwrap_or_else(|| panic!("{}: no interface has {name}", f.display()));
            assert!(
                types.contains(ty),
                "{}: {name} is {ty}, ours {types:?}",
                f.display()
            );
            typed += 1;
        }
        for chunk in text.split("name=\"ros_fields__").skip(1) {
            let name = format!("ros_fields__{}", &chunk[..chunk.find('"').unwrap()]);
            assert!(
                known.contains_key(&name),
                "{}: no interface has {name}",
                f.display()
            );
            params += 1;
        }
    }
    assert!(typed >= 50, "{typed} typed fields checked");
    assert!(params >= 100, "{params} parameters checked");
}

#[test]
fn nested_and_array_messages_flatten() {
    if common::corpus_or_skip().is_none() {
        return;
    }
    let c = corpus();
    let mut sm = SourceMap::new();
    let ifs = Interfaces::discover(
        &mut sm,
        &c.join("as2fm/test_data/nested_data_ros/main.xml"),
        &[],
    )
    .unwrap();
    let f = |t: &str| all(&ifs.message(t).unwrap());
    let s = |a: &str, b: &str| (a.to_string(), b.to_string());
    assert_eq!(
        f("nested_interfaces/InternalObj"),
        vec![
            s("ros_fields__i_obj__i", "int32"),
            s("ros_fields__i_obj__text", "string")
        ]
    );
    assert_eq!(
        f("nested_interfaces/msg/InternalArrStatic"),
        vec![
            s("ros_fields__i_arr__i", "int32[8]"),
            s("ros_fields__i_arr__text", "string[8]")
        ]
    );
    assert_eq!(
        f("nested_interfaces/InternalArrDynamic"),
        vec![
            s("ros_fields__i_arr__i", "int32[]"),
            s("ros_fields__i_arr__text", "string[]")
        ]
    );
    let stat = ifs.message("nested_interfaces/InternalArrStatic").unwrap();
    assert_eq!(stat[0].default, "[0, 0, 0, 0, 0, 0, 0, 0]");
    assert_eq!(stat[1].dotted(), "i_arr.text");
    let twist = ifs.message("geometry_msgs/Twist").unwrap();
    assert_eq!(
        twist.iter().map(|f| f.param_name()).collect::<Vec<_>>(),
        [
            "ros_fields__linear__x",
            "ros_fields__linear__y",
            "ros_fields__linear__z",
            "ros_fields__angular__x",
            "ros_fields__angular__y",
            "ros_fields__angular__z"
        ]
    );
    assert_eq!(twist[0].default, "0.0");
    let pose = ifs.message("geometry_msgs/msg/PoseStamped").unwrap();
    assert_eq!(
        all(&pose)[..3],
        [
            s("ros_fields__header__stamp__sec", "int32"),
            s("ros_fields__header__stamp__nanosec", "uint32"),
            s("ros_fields__header__frame_id", "string")
        ]
    );
    assert_eq!(pose.last().unwrap().default, "1.0", "quaternion w");
    let fib = ifs.action("example_interfaces/action/Fibonacci").unwrap();
    assert_eq!(all(&fib.goal), vec![s("ros_fields__order", "int32")]);
    assert_eq!(all(&fib.result), vec![s("ros_fields__sequence", "int32[]")]);
    assert_eq!(fib.result[0].default, "[]");
    let add = ifs.service("example_interfaces/AddTwoInts").unwrap();
    assert_eq!(all(&add.response), vec![s("ros_fields__sum", "int64")]);
    assert!(ifs.message("std_msgs/Empty").unwrap().is_empty());
    let cov = ifs.message("std_msgs/Int32MultiArray").unwrap();
    assert_eq!(
        all(&cov)[0],
        s("ros_fields__layout__dim__label", "string[]")
    );
    assert_eq!(
        ifs.constants("navigation_interfaces_dummy/NavigationStatus")
            .unwrap()[2],
        ("NAVIGATION_STATUS_MOVING".to_string(), "2".to_string())
    );
}

#[test]
fn unknown_types_list_close_names() {
    let ifs = Interfaces::with_builtins();
    let e = ifs.message("std_msgs/Int33").unwrap_err().to_string();
    assert!(e.contains("std_msgs/Int32"), "{e}");
    assert!(e.contains("no message type `std_msgs/Int33`"), "{e}");
    let e = ifs
        .message("example_interfaces/AddTwoInts")
        .unwrap_err()
        .to_string();
    assert!(e.contains("is a service"), "{e}");
    let e = ifs
        .service("example_interfaces/msg/AddTwoInts")
        .unwrap_err()
        .to_string();
    assert!(e.contains("names a message"), "{e}");
    let e = ifs.message("geometry_msgs/Twst").unwrap_err().to_string();
    assert!(e.ends_with("did you mean geometry_msgs/Twist?"), "{e}");
    let e = ifs.message("Int32").unwrap_err().to_string();
    assert!(e.contains("std_msgs/Int32"), "{e}");
    // An unknown package: no far-fetched names, the places searched instead.
    let e = ifs.action("zzz_pkg/Qqqqqqq").unwrap_err().to_string();
    assert!(e.contains("no package `zzz_pkg` was found"), "{e}");
    assert!(!e.contains("did you mean"), "{e}");
    assert!(e.contains("searched, in this order"), "{e}");
    // A misspelt package still gets close names.
    let e = ifs.message("std_msg/Int32").unwrap_err().to_string();
    assert!(
        e.contains("did you mean") && e.contains("std_msgs/Int32"),
        "{e}"
    );
}

fn temp_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("hindsight-ifaces-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn write(path: &Path, text: &str) {
    std::fs::create_dir_all(path.parent().unwrap()).unwrap();
    std::fs::write(path, text).unwrap();
}

#[test]
fn interface_errors_point_at_the_file() {
    let d = temp_dir("errs");
    write(&d.join("main.xml"), "<roaml/>");
    let bad = d.join("ros_support_interfaces/my_msgs/msg/Bad.msg");
    write(&bad, "# header\nint32 x\nfloat64[3 y\n");
    let unknown = d.join("ros_support_interfaces/my_msgs/srv/Ask.srv");
    write(&unknown, "int32 a\n---\n  my_msgs/Reply r\n");
    let mut sm = SourceMap::new();
    let errs = Interfaces::discover(&mut sm, &d.join("main.xml"), &[]).unwrap_err();
    let texts: Vec<String> = errs.iter().map(|e| e.to_string()).collect();
    // Errors are collected: the syntax error, and the nested type no file defines.
    assert_eq!(texts.len(), 2, "{texts:?}");
    assert!(
        texts[0].starts_with(&format!("{}:3:8: malformed array size", bad.display())),
        "{texts:?}"
    );
    // Fixed, the unknown nested type is reported at its field.
    write(&bad, "int32 x\n");
    let mut sm = SourceMap::new();
    let errs = Interfaces::discover(&mut sm, &d.join("main.xml"), &[]).unwrap_err();
    assert_eq!(errs.len(), 1);
    let t = errs[0].to_string();
    assert!(
        t.starts_with(&format!("{}:3:3: ", unknown.display())),
        "{t}"
    );
    assert!(t.contains("no message type `my_msgs/Reply`"), "{t}");
    // Fixed again, everything resolves, and the package's own types are found.
    write(
        &d.join("ros_support_interfaces/my_msgs/msg/Reply.msg"),
        "Bad b\nint32[<=3] c\n",
    );
    let mut sm = SourceMap::new();
    let ifs = Interfaces::discover(&mut sm, &d.join("main.xml"), &[]).unwrap();
    let ask = ifs.service("my_msgs/Ask").unwrap();
    assert_eq!(
        all(&ask.response),
        vec![
            ("ros_fields__r__b__x".to_string(), "int32".to_string()),
            ("ros_fields__r__c".to_string(), "int32[3]".to_string())
        ]
    );
    // A message that contains itself is an error, not a stack overflow.
    write(
        &d.join("ros_support_interfaces/my_msgs/msg/Loop.msg"),
        "int32 a\nLoop next\n",
    );
    let mut sm = SourceMap::new();
    let errs = Interfaces::discover(&mut sm, &d.join("main.xml"), &[]).unwrap_err();
    assert!(
        errs[0]
            .to_string()
            .contains("Loop.msg:2:1: message `my_msgs/Loop` contains itself"),
        "{errs:?}"
    );
    // An extra folder that does not exist.
    let mut sm = SourceMap::new();
    let errs = Interfaces::discover(&mut sm, &d.join("main.xml"), &[d.join("nope")]).unwrap_err();
    assert!(errs[0].to_string().contains("does not exist"), "{errs:?}");
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn every_main_file_reads() {
    if common::corpus_or_skip().is_none() {
        return;
    }
    use hindsight::verify::robot::main_file::{InputKind, MainFile, MainForm};
    let mains = main_files();
    let mut inputs = 0;
    for main in &mains {
        let mut sm = SourceMap::new();
        let museum = main.to_string_lossy().contains("museum-simpar2025");
        let m = if museum {
            // The case study's main files name a properties.jani that its repository lacks.
            let m = MainFile::parse(&mut sm, main).unwrap();
            let missing = m.missing_files(&sm);
            assert_eq!(missing.len(), 1, "{missing:?}");
            assert!(
                missing[0]
                    .message
                    .ends_with("Main/../Properties/properties.jani` not found"),
                "{missing:?}"
            );
            let line = if main.ends_with("main.xml") { 35 } else { 22 };
            assert_eq!((missing[0].line, missing[0].col), (line, 33));
            assert_eq!(MainFile::read(&mut sm, main).unwrap_err(), missing);
            m
        } else {
            MainFile::read(&mut sm, main).unwrap_or_else(|e| panic!("{}: {e:?}", main.display()))
        };
        assert_eq!(m.form == MainForm::ConvinceMcTc, museum);
        assert!(m.params.max_time_ns.value > 0, "{}", main.display());
        inputs += m.inputs().count();
        if let Some(bt) = &m.behavior_tree {
            assert_eq!(bt.tree.kind, InputKind::BtCppXml);
            assert!(bt.plugins.iter().all(|p| matches!(
                p.kind,
                InputKind::BtPluginAscxml | InputKind::BtPluginRosScxml
            )));
        }
    }
    assert!(inputs > 150, "{inputs} inputs");

    let c = corpus();
    let mut sm = SourceMap::new();
    let uc3 = MainFile::read(
        &mut sm,
        &c.join("as2fm/test_data/uc3_museum_guide/Main/main.xml"),
    )
    .unwrap();
    assert_eq!(uc3.params.max_time_ns.value, 100_000_000_000);
    assert_eq!(uc3.params.max_array_size_or_default(), 100, "the default");
    let rate = uc3.params.bt_tick_rate.as_ref().unwrap().value;
    assert_eq!(
        (rate.hz, rate.period_ns, rate.exact),
        (10.0, 100_000_000, true)
    );
    assert!(uc3.params.tick_if_not_running());
    assert!(uc3.params.max_array_size.is_none(), "commented out");
    let bt = uc3.behavior_tree.as_ref().unwrap();
    assert_eq!(bt.plugins.len(), 2);
    assert_eq!(bt.plugins[0].src, "../Plugins/ROS2Condition.ascxml");
    assert!(bt.plugins[0]
        .path
        .ends_with("Main/../Plugins/ROS2Condition.ascxml"));
    assert_eq!(uc3.node_models.len(), 17);
    assert_eq!(uc3.properties[0].kind, InputKind::Jani);
    let d = sm.diag(uc3.properties[0].span, "here");
    assert_eq!((d.line, d.col), (38, 33));

    let uc2 = MainFile::read(
        &mut sm,
        &c.join("as2fm/test_data/uc2_assembly/Main/main.xml"),
    )
    .unwrap();
    let rate = uc2.params.bt_tick_rate.as_ref().unwrap().value;
    assert_eq!(rate.period_ns, 2_000_000_000);
    assert_eq!(uc2.params.max_array_size.as_ref().unwrap().value, 10);
    assert!(!uc2.params.tick_if_not_running(), "the default");

    let ds = MainFile::read(
        &mut sm,
        &c.join("as2fm/test_data/data_structs/main_json_def.xml"),
    )
    .unwrap();
    assert_eq!(ds.data_declarations[0].kind, InputKind::DataJson);
    assert!(ds.behavior_tree.is_none());
}

/// Writes `text` as a main file in a fresh folder and reads it; the errors as text. A
/// `<parameters>` element with a `max_time` is added on the first line when `text` has none.
fn main_errors(name: &str, text: &str) -> (PathBuf, Vec<String>) {
    use hindsight::verify::robot::main_file::MainFile;
    let d = temp_dir(name);
    let p = d.join("main.xml");
    let text = if text.contains("<parameters>") {
        text.to_string()
    } else {
        text.replacen(
            "<roaml>",
            "<roaml><parameters><max_time value=\"1\" unit=\"s\"/></parameters>",
            1,
        )
    };
    write(&p, &text);
    write(&d.join("bt.xml"), "<root/>");
    let mut sm = SourceMap::new();
    let errs = match MainFile::read(&mut sm, &p) {
        Ok(_) => Vec::new(),
        Err(e) => e.iter().map(|d| d.to_string()).collect(),
    };
    (p, errs)
}

#[test]
fn main_file_errors_point_at_the_input() {
    let cases: &[(&str, &str, &str)] = &[
        (
            "unit",
            "<roaml>\n  <parameters>\n    <max_time value=\"10\" unit=\"days\"/>\n  </parameters>\n</roaml>",
            ":3:32: unknown time unit `days`",
        ),
        (
            "inexact",
            "<roaml><parameters>\n<max_time value=\"1.5\" unit=\"ns\"/></parameters></roaml>",
            ":2:18: `1.5` is finer than a nanosecond",
        ),
        (
            "nounit",
            "<roaml><parameters>\n  <max_time value=\"1\"/></parameters></roaml>",
            ":2:3: <max_time> needs a `unit`",
        ),
        (
            "zero",
            "<roaml><parameters>\n  <max_time value=\"0.0\" unit=\"s\"/></parameters></roaml>",
            ":2:20: max_time must be positive",
        ),
        (
            "missing",
            "<roaml>\n<node_models>\n  <input type=\"node-ascxml\" src=\"./nope.ascxml\" />\n</node_models>\n</roaml>",
            ":3:34: node-ascxml file `",
        ),
        (
            "element",
            "<roaml>\n  <parameter/>\n</roaml>",
            ":2:3: unknown element <parameter> in <roaml>",
        ),
        (
            "param",
            "<roaml><parameters>\n <max_tme value=\"1\"/></parameters></roaml>",
            ":2:2: unknown parameter <max_tme>",
        ),
        (
            "attr",
            "<roaml><node_models>\n <input type=\"node-ascxml\" scr=\"a\"/></node_models></roaml>",
            ":2:28: unknown attribute `scr` on <input>",
        ),
        (
            "kind",
            "<roaml><node_models>\n <input type=\"jani\" src=\"a\"/></node_models></roaml>",
            ":2:15: unknown input type `jani` in <node_models>",
        ),
        (
            "twotrees",
            "<roaml><behavior_tree>\n <input type=\"bt.cpp-xml\" src=\"bt.xml\"/>\n <input type=\"bt.cpp-xml\" src=\"bt.xml\"/>\n</behavior_tree></roaml>",
            ":3:2: a behavior tree has exactly one bt.cpp-xml input",
        ),
        (
            "notree",
            "<roaml>\n<behavior_tree>\n</behavior_tree></roaml>",
            ":2:1: <behavior_tree> needs one",
        ),
        (
            "rate",
            "<roaml><parameters>\n<bt_tick_rate value=\"0\"/></parameters></roaml>",
            ":2:22: bt_tick_rate must be a positive number",
        ),
        (
            "bool",
            "<roaml><parameters>\n<bt_tick_if_not_running value=\"yes\"/></parameters></roaml>",
            ":2:32: bt_tick_if_not_running must be true or false",
        ),
        (
            "size",
            "<roaml><parameters>\n<max_array_size value=\"-3\"/></parameters></roaml>",
            ":2:24: max_array_size must be a positive whole number",
        ),
        (
            "twice",
            "<roaml>\n<properties/>\n<properties/>\n</roaml>",
            ":3:1: <properties> is given twice (first on line 2)",
        ),
        (
            "nomax",
            "<roaml><parameters>\n<bt_tick_rate value=\"1\"/></parameters></roaml>",
            ":1:8: the parameters need <max_time",
        ),
        (
            "noparams",
            "<roaml>\n<!-- without <parameters> -->\n</roaml>",
            ":1:1: <roaml> needs <parameters> with <max_time",
        ),
        (
            "root",
            "<scxml/>",
            ":1:1: expected a main file",
        ),
        (
            "xml",
            "<roaml>\n<properties>\n</roaml>",
            "main.xml:3:",
        ),
    ];
    for (name, text, want) in cases {
        let (p, errs) = main_errors(name, text);
        // A misspelt `src` is also a missing `src`: two errors, the first the spelling.
        let n = if *name == "attr" { 2 } else { 1 };
        assert_eq!(errs.len(), n, "{name}: {errs:?}");
        assert!(
            errs[0].starts_with(&p.display().to_string()) && errs[0].contains(want),
            "{name}: want `{want}`, got {errs:?}"
        );
        let _ = std::fs::remove_dir_all(p.parent().unwrap());
    }
    // Errors are collected, not stopped at the first.
    let (p, errs) = main_errors(
        "many",
        "<roaml><parameters>\n<max_time value=\"x\" unit=\"s\"/>\n<bt_tick_rate value=\"y\"/>\n</parameters></roaml>",
    );
    assert_eq!(errs.len(), 2, "{errs:?}");
    let _ = std::fs::remove_dir_all(p.parent().unwrap());
}

/// Every data declaration a corpus main file names reads; the JSON and XML forms of the
/// data_structs case declare the same types.
#[test]
fn data_declarations_read() {
    if common::corpus_or_skip().is_none() {
        return;
    }
    use hindsight::verify::model::types::{TypeDef, TypeDefs};
    use hindsight::verify::robot::datatypes::{
        read_data_declarations, read_main_declarations, DataFormat,
    };
    use hindsight::verify::robot::main_file::MainFile;
    let mut read = 0;
    for main in main_files() {
        let mut sm = SourceMap::new();
        let m = MainFile::parse(&mut sm, &main).unwrap();
        let defs = read_main_declarations(&mut sm, &m)
            .unwrap_or_else(|e| panic!("{}: {e:?}", main.display()));
        assert_eq!(defs.defs.is_empty(), m.data_declarations.is_empty());
        read += usize::from(!defs.defs.is_empty());
    }
    assert_eq!(read, 4);
    let shape = |defs: &TypeDefs| -> Vec<(String, Vec<(String, String)>)> {
        let mut v: Vec<_> = defs
            .defs
            .iter()
            .map(|(n, d, _)| match d {
                TypeDef::Struct { fields } => (
                    n.clone(),
                    fields
                        .iter()
                        .map(|(f, t)| (f.clone(), t.to_string()))
                        .collect(),
                ),
                TypeDef::Enumeration { .. } => (n.clone(), Vec::new()),
            })
            .collect();
        v.sort();
        v
    };
    let dir = corpus().join("as2fm/test_data/data_structs");
    let mut sm = SourceMap::new();
    let x =
        read_data_declarations(&mut sm, &[(&dir.join("my_types.xml"), DataFormat::Xml)]).unwrap();
    let j =
        read_data_declarations(&mut sm, &[(&dir.join("my_types.json"), DataFormat::Json)]).unwrap();
    assert_eq!(shape(&x), shape(&j));
    assert_eq!(
        shape(&j)[1],
        (
            "Polygon".to_string(),
            vec![("points".to_string(), "Point2D[]".to_string())]
        )
    );
    assert_eq!(
        shape(&j)[0]
            .1
            .iter()
            .map(|(f, _)| f.as_str())
            .collect::<Vec<_>>(),
        ["frame", "x", "y"],
        "written order"
    );
}

#[test]
fn data_declaration_errors_point_at_the_type() {
    use hindsight::verify::robot::datatypes::{read_data_declarations, DataFormat};
    let d = temp_dir("data");
    let x = d.join("t.xml");
    write(
        &x,
        "<types>\n  <struct id=\"A\">\n    <member id=\"b\" type=\"B[]\"/>\n  </struct>\n</types>\n",
    );
    let mut sm = SourceMap::new();
    let e = read_data_declarations(&mut sm, &[(&x, DataFormat::Xml)]).unwrap_err();
    assert_eq!(e.len(), 1);
    assert!(
        e[0].to_string()
            .starts_with(&format!("{}:3:26: type `B` is not declared", x.display())),
        "{e:?}"
    );
    let j = d.join("t.json");
    write(&j, "{\"title\": \"A\", \"type\": \"object\",\n \"properties\": {\"b\": {\"type\": \"float\"}}}");
    let e = read_data_declarations(&mut sm, &[(&j, DataFormat::Json)]).unwrap_err();
    assert!(
        e[0].to_string()
            .starts_with(&format!("{}:2:31: unsupported type `float`", j.display())),
        "{e:?}"
    );
    write(&j, "{\"title\": \"A\",\n \"type\": \"object\" \"x\"}");
    let e = read_data_declarations(&mut sm, &[(&j, DataFormat::Json)]).unwrap_err();
    assert!(
        e[0].to_string()
            .starts_with(&format!("{}:2:19: expected `,` or `}}`", j.display())),
        "{e:?}"
    );
    let _ = std::fs::remove_dir_all(&d);
}

/// A main file given by a relative path finds the interfaces folder above it, and the
/// interface files keep relative paths in diagnostics.
#[test]
fn discovery_from_a_relative_path() {
    let Some(root) = common::corpus_or_skip() else {
        return;
    };
    // The corpus as seen from the working folder: up to their common ancestor, then down.
    let here = std::env::current_dir().unwrap().canonicalize().unwrap();
    let root = root.canonicalize().unwrap();
    let common_dir = here.ancestors().find(|d| root.starts_with(d)).unwrap();
    let up = here.components().count() - common_dir.components().count();
    let rel = PathBuf::from("../".repeat(up))
        .join(root.strip_prefix(common_dir).unwrap())
        .join("as2fm/test_data/uc3_museum_guide/Main/main.xml");
    let mut sm = SourceMap::new();
    let ifs = Interfaces::discover(&mut sm, &rel, &[]).unwrap();
    assert_eq!(
        all(&ifs
            .service("bt_interfaces_dummy/srv/TickAction")
            .unwrap()
            .response),
        vec![
            ("ros_fields__status".to_string(), "int8".to_string()),
            ("ros_fields__is_ok".to_string(), "bool".to_string())
        ]
    );
    assert!(sm.sources().iter().all(|f| f.path().is_relative()));
    assert_eq!(
        sm.sources().len(),
        44,
        "every file of ros_support_interfaces"
    );
}

/// A deep diamond of messages (2^20 leaves) is refused quickly, not expanded; one nested
/// deeper than 32 levels too.
#[test]
fn huge_messages_are_refused() {
    let d = temp_dir("huge");
    write(&d.join("main.xml"), "<roaml/>");
    for k in 0..20 {
        write(
            &d.join(format!("interfaces/big_msgs/msg/M{k}.msg")),
            &format!("M{n} a\nM{n} b\n", n = k + 1),
        );
    }
    write(&d.join("interfaces/big_msgs/msg/M20.msg"), "int32 x\n");
    for k in 0..40 {
        write(
            &d.join(format!("interfaces/deep_msgs/msg/D{k}.msg")),
            &format!("D{} a\n", k + 1),
        );
    }
    write(&d.join("interfaces/deep_msgs/msg/D40.msg"), "int32 x\n");
    let mut sm = SourceMap::new();
    let ifs = Interfaces::discover(&mut sm, &d.join("main.xml"), &[]).unwrap();
    let e = ifs.message("big_msgs/M0").unwrap_err().to_string();
    assert!(e.contains("more than 10000 leaf fields"), "{e}");
    assert_eq!(ifs.message("big_msgs/M17").unwrap().len(), 8);
    let e = ifs.message("deep_msgs/D0").unwrap_err().to_string();
    assert!(e.contains("nest deeper than 32 levels"), "{e}");
    assert_eq!(ifs.message("deep_msgs/D10").unwrap()[0].path.len(), 31);
    let _ = std::fs::remove_dir_all(&d);
}

/// Printing a definition and reading it back gives the same definition, for every built-in
/// and corpus interface and for one that uses every feature.
#[test]
fn printed_definitions_read_back() {
    if common::corpus_or_skip().is_none() {
        return;
    }
    use hindsight::verify::robot::interfaces::{parse_interface, InterfaceDef};
    let strip = |d: &InterfaceDef| {
        let mut d = d.clone();
        d.file = None;
        for p in &mut d.parts {
            for f in &mut p.fields {
                f.span = hindsight::verify::model::source::FileId(0).at(0);
            }
            for c in &mut p.constants {
                c.span = hindsight::verify::model::source::FileId(0).at(0);
            }
        }
        d
    };
    let mut sm = SourceMap::new();
    let mut ifs = Interfaces::discover(
        &mut sm,
        &corpus().join("as2fm/test_data/uc3_museum_guide/Main/main.xml"),
        &[],
    )
    .unwrap();
    let all_features = "# every feature\nstring NAME=robot # unquoted\nint8 FAST=-3\n\
        byte b 7\nchar c\nwstring w \"w\\\"q\"\nstring<=5 s 'a#b'\nfloat32[3] v [1, 2.5, -0]\n\
        uint64[<=2] u [18446744073709551615]\nbool[] flags [true, false]\n\
        builtin_interfaces/Time t\nInternal i\n---\nint32 r\n---\n";
    ifs.add_text(
        &mut sm,
        Path::new("all.action"),
        all_features.to_string(),
        "nested_interfaces",
        InterfaceKind::Action,
        "All",
    )
    .unwrap();
    let mut n = 0;
    for def in ifs.iter() {
        let text = def.to_string();
        let f = sm.add("printed", text.clone());
        let back = parse_interface(&sm, f, &def.package, &def.name, def.kind)
            .unwrap_or_else(|e| panic!("{}:\n{text}\n{e:?}", def.full_name()));
        assert_eq!(strip(&back), strip(def), "{}:\n{text}", def.full_name());
        n += 1;
    }
    assert!(n > 100, "{n} definitions");
    let all = ifs
        .get("nested_interfaces/All", InterfaceKind::Action)
        .unwrap();
    assert_eq!(
        all.to_string(),
        "string NAME='robot'\nint8 FAST=-3\nbyte b 7\nchar c\nwstring w 'w\"q'\n\
         string<=5 s 'a#b'\nfloat32[3] v [1.0, 2.5, -0.0]\nuint64[<=2] u [18446744073709551615]\n\
         bool[] flags [true, false]\nbuiltin_interfaces/Time t\nnested_interfaces/Internal i\n\
         ---\nint32 r\n---\n"
    );
}
