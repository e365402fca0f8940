//! What `hindsight convert` writes for every AS2FM corpus case, compared with AS2FM's own
//! plain translation of the case machine by machine: the same machines, and in each the
//! same elements in the same order (transitions, sends, parameters), formatting aside
//! (`common::canon`). The differences that remain are listed in [`KNOWN`], each with its
//! reason.

mod common;

use common::canon::{canon, first_differences, parse_file, parse_text};
use std::collections::BTreeMap;
use std::path::PathBuf;

/// Every corpus case with a plain translation: (folder under `plain/`, main file).
fn cases() -> Vec<(String, PathBuf)> {
    let as2fm = common::corpus("as2fm");
    let expected: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(as2fm.join("expected.json")).unwrap())
            .unwrap();
    let mut out: Vec<(String, PathBuf)> = expected
        .as_object()
        .unwrap()
        .iter()
        .map(|(k, v)| (k.clone(), as2fm.join(v["main"].as_str().unwrap())))
        .collect();
    // The behavior-tree node tests: one main file each, beside the others.
    for name in [
        "fallback",
        "ifthenelse_else",
        "ifthenelse_then",
        "parallel_failure",
        "parallel_running",
        "parallel_success",
        "reactive_fallback",
        "reactive_sequence",
        "repeat",
        "sequence",
    ] {
        out.push((
            format!("bt_{name}"),
            as2fm.join(format!("test_data/bt_test_models/main_test_{name}.xml")),
        ));
    }
    out
}

/// The machines of one plain translation folder, by name.
fn plain_machines(case: &str) -> BTreeMap<String, String> {
    let dir = common::corpus("as2fm/plain").join(case);
    let mut out = BTreeMap::new();
    for e in std::fs::read_dir(&dir).unwrap() {
        let p = e.unwrap().path();
        if p.extension().is_some_and(|x| x == "scxml") {
            let root = parse_file(&p);
            out.insert(root.attr_value("name").unwrap().to_string(), canon(&root));
        }
    }
    out
}

/// What `hindsight convert` writes for `main`, read back, by machine name.
fn converted(main: &std::path::Path) -> Result<BTreeMap<String, String>, String> {
    let robot = hindsight::verify::robot::load::load(main).map_err(|d| d.to_string())?;
    let mut out = BTreeMap::new();
    for m in &robot.machines {
        let name = m.attr_value("name").unwrap().to_string();
        let text = hindsight::verify::robot::write::to_xml(m);
        out.insert(name.clone(), canon(&parse_text(&name, &text)));
    }
    Ok(out)
}

/// Why a struct-typed variable differs.
const STRUCTS: &str = "AS2FM flattens a struct-typed variable into one variable per field \
    (`p__x`; an array of structs into one array per field) for its JANI back end; hindsight \
    keeps struct values, which its expression language has: the same data in one variable";
/// Why a thread's result or feedback `<param>` differs.
const ARRAY_PARAM: &str = "hindsight writes the interface's type on a `<param>` of an array \
    field (`type=\"int32[]\"`), so that an empty array literal has an element type when the \
    plain file is read back; AS2FM's plain file leaves it out";
/// The differences that remain: (case, machine, why). A machine `*` is a case we refuse.
const KNOWN: &[(&str, &str, &str)] = &[
    ("array_of_data_structs_main", "receiver", STRUCTS),
    ("array_of_data_structs_main", "sender", STRUCTS),
    ("data_structs_main_json_def", "receiver", STRUCTS),
    ("data_structs_main_json_def", "sender", STRUCTS),
    ("data_structs_main_xml_def", "receiver", STRUCTS),
    ("data_structs_main_xml_def", "sender", STRUCTS),
    (
        "fibonacci_action_example_main",
        "fibonacci_thread_0",
        ARRAY_PARAM,
    ),
    (
        "fibonacci_action_example_main",
        "fibonacci_thread_1",
        ARRAY_PARAM,
    ),
    (
        "fibonacci_action_single_thread_main",
        "fibonacci_thread_0",
        ARRAY_PARAM,
    ),
    ("overarching_tutorial_main_locations", "world", STRUCTS),
    (
        "string_msg_comparison_main",
        "*",
        "it publishes example_interfaces/String on a topic it subscribes as \
         nested_interfaces/Internal and reads `_msg.data`, which the subscribed type does not \
         have; AS2FM accepts it, hindsight reports both at their positions",
    ),
];

#[test]
fn convert_equals_as2fm_plain_translation_machine_by_machine() {
    if common::corpus_or_skip().is_none() {
        return;
    }
    let mut found: Vec<(String, String)> = Vec::new();
    let mut report = String::new();
    let mut compared = 0;
    for (case, main) in cases() {
        let theirs = plain_machines(&case);
        let ours = match converted(&main) {
            Ok(m) => m,
            Err(e) => {
                report.push_str(&format!("== {case}: refused\n{e}\n"));
                found.push((case.clone(), "*".to_string()));
                continue;
            }
        };
        let names = |m: &BTreeMap<String, String>| m.keys().cloned().collect::<Vec<_>>();
        assert_eq!(names(&ours), names(&theirs), "{case}: machines");
        for (name, a) in &ours {
            let b = &theirs[name];
            compared += 1;
            if a != b {
                report.push_str(&format!(
                    "== {case} / {name}\n{}\n",
                    first_differences(a, b, 4)
                ));
                found.push((case.clone(), name.clone()));
            }
        }
    }
    eprintln!("{report}");
    eprintln!("compared {compared} machines, {} differ", found.len());
    assert!(compared >= 280, "compared {compared} machines");
    let mut known: Vec<(String, String)> = KNOWN
        .iter()
        .map(|(c, m, _)| (c.to_string(), m.to_string()))
        .collect();
    known.sort();
    found.sort();
    assert_eq!(
        found, known,
        "the differences are not the known ones:\n{report}"
    );
}

/// AS2FM's global timer sends the timers' events in the order its caller collected the
/// timers: every node model's (main-file order), then the behavior tree's tick
/// (`make_global_timer_scxml` over `generate_plain_scxml_models_and_timers`'s list). On the
/// quick-start battery monitor the drainer's timer comes before the tree's tick.
#[test]
fn the_trees_tick_comes_after_the_node_models_timers() {
    if common::corpus_or_skip().is_none() {
        return;
    }
    let main = common::corpus("as2fm/examples/quick_start_battery_monitor/main.xml");
    let robot = hindsight::verify::robot::load::load(&main).unwrap();
    let timer = robot
        .machines
        .iter()
        .find(|m| m.attr_value("name") == Some("autogenerated_global_timer"))
        .unwrap();
    let text = canon(timer);
    let at = |ev: &str| {
        text.find(&format!("event=\"{ev}\""))
            .unwrap_or_else(|| panic!("{ev} in\n{text}"))
    };
    assert!(
        at("topic_clock_msg") < at("ros_time_rate.my_timer"),
        "{text}"
    );
    assert!(
        at("ros_time_rate.my_timer") < at("ros_time_rate.bt_tick"),
        "{text}"
    );
}
