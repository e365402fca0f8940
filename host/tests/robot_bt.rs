//! Behavior trees lowered natively: every corpus tree lowers; the bt_* cases have the
//! machines, states, transitions and messages of AS2FM's translation; models without ROS
//! tags (after a small test-only topic/timer shim) simulate to AS2FM's expected verdicts;
//! bad trees and plugins are errors with positions.

mod common;

use hindsight::verify::model::source::{FileId, SourceMap};
use hindsight::verify::model::xml::{self, Element, Node};
use hindsight::verify::model::{Diagnostics, ModelSource};
use hindsight::verify::robot::bt::{self, BtInput, Halts};
use hindsight::verify::robot::write;
use hindsight::verify::sim::{CompiledModel, Flow, Observer, RunConfig, SentMessage, Simulator};
use rand_core::SeedableRng;
use rand_xoshiro::Xoshiro256PlusPlus;
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

fn corpus() -> PathBuf {
    common::corpus_root()
}

/// What a main file says about its tree (a minimal reader for this test; the real one is
/// the main-file reader).
struct Case {
    tree: PathBuf,
    plugins: Vec<PathBuf>,
    rate: f64,
    tick_if_not_running: bool,
}

fn read_main(main: &Path) -> Case {
    let mut sm = SourceMap::new();
    let id = sm.add(main, std::fs::read_to_string(main).unwrap());
    let root = xml::parse(&sm, id).unwrap();
    let dir = main.parent().unwrap();
    let mut case = Case {
        tree: PathBuf::new(),
        plugins: Vec::new(),
        rate: 1.0,
        tick_if_not_running: false,
    };
    for sec in root.elements() {
        for e in sec.elements() {
            match (sec.name.as_str(), e.name.as_str()) {
                ("parameters" | "mc_parameters", "bt_tick_rate") => {
                    case.rate = e.attr_value("value").unwrap().parse().unwrap()
                }
                ("parameters" | "mc_parameters", "bt_tick_if_not_running") => {
                    case.tick_if_not_running = e.attr_value("value") == Some("true")
                }
                ("behavior_tree", "input") => {
                    let src = dir.join(e.attr_value("src").unwrap());
                    if e.attr_value("type") == Some("bt.cpp-xml") {
                        case.tree = src;
                    } else {
                        case.plugins.push(src);
                    }
                }
                _ => {}
            }
        }
    }
    case
}

fn lower_case(case: &Case) -> (SourceMap, FileId, Vec<Element>) {
    lower_case_with(case, Halts::As2fm)
}

fn lower_case_with(case: &Case, halts: Halts) -> (SourceMap, FileId, Vec<Element>) {
    let mut sm = SourceMap::new();
    let tree = sm.add(&case.tree, std::fs::read_to_string(&case.tree).unwrap());
    let plugins = case
        .plugins
        .iter()
        .map(|p| sm.add(p, std::fs::read_to_string(p).unwrap()))
        .collect();
    let input = BtInput {
        tree,
        plugins,
        tick_rate_hz: case.rate,
        tick_if_not_running: case.tick_if_not_running,
        halts,
        semantics: Default::default(),
    };
    match bt::lower(&sm, &input) {
        Ok(m) => (sm, tree, m),
        Err(ds) => panic!("{}:\n{}", case.tree.display(), Diagnostics(ds)),
    }
}

/// Main files with a behavior tree, and AS2FM's plain translation when the corpus has it.
fn bt_mains() -> Vec<(PathBuf, Option<PathBuf>)> {
    let c = corpus();
    let as2fm = c.join("as2fm");
    let mut out = Vec::new();
    let expected: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(as2fm.join("expected.json")).unwrap())
            .unwrap();
    let mut plain_of: BTreeMap<PathBuf, PathBuf> = BTreeMap::new();
    for (k, v) in expected.as_object().unwrap() {
        plain_of.insert(
            as2fm.join(v["main"].as_str().unwrap()),
            as2fm.join("plain").join(k),
        );
    }
    for (main, case) in [
        ("main_test_fallback.xml", "bt_fallback"),
        ("main_test_ifthenelse_else.xml", "bt_ifthenelse_else"),
        ("main_test_ifthenelse_then.xml", "bt_ifthenelse_then"),
        ("main_test_parallel_failure.xml", "bt_parallel_failure"),
        ("main_test_parallel_running.xml", "bt_parallel_running"),
        ("main_test_parallel_success.xml", "bt_parallel_success"),
        ("main_test_reactive_fallback.xml", "bt_reactive_fallback"),
        ("main_test_reactive_sequence.xml", "bt_reactive_sequence"),
        ("main_test_repeat.xml", "bt_repeat"),
        ("main_test_sequence.xml", "bt_sequence"),
    ] {
        plain_of.insert(
            as2fm.join("test_data/bt_test_models").join(main),
            as2fm.join("plain").join(case),
        );
    }
    let mut stack = vec![
        as2fm.join("test_data"),
        as2fm.join("examples"),
        c.join("museum-simpar2025/model-high-level"),
    ];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else if p.extension().is_some_and(|x| x == "xml") {
                let text = std::fs::read_to_string(&p).unwrap();
                if text.contains("<behavior_tree>") {
                    let plain = plain_of.get(&p).cloned().filter(|d| d.is_dir());
                    out.push((p, plain));
                }
            }
        }
    }
    out.sort();
    out
}

fn has_ros_tag(el: &Element) -> bool {
    el.name.starts_with("ros_") || el.elements().any(has_ros_tag)
}

fn has_prefixed(el: &Element, prefix: &str) -> bool {
    el.name.starts_with(prefix) || el.elements().any(|c| has_prefixed(c, prefix))
}

fn is_bt_machine(name: &str) -> bool {
    name.starts_with("BT_plugin_")
        || name.starts_with("bt_root_fsm_")
        || name == "bt_blackboard_fsm"
}

#[test]
fn every_corpus_tree_lowers_to_the_machines_as2fm_makes() {
    if common::corpus_or_skip().is_none() {
        return;
    }
    let mains = bt_mains();
    assert!(mains.len() >= 20, "found {} main files", mains.len());
    let mut compared = 0;
    for (main, plain) in &mains {
        let case = read_main(main);
        let (sm, _, machines) = lower_case(&case);
        let names: BTreeSet<String> = machines
            .iter()
            .map(|m| m.attr_value("name").unwrap().to_string())
            .collect();
        assert_eq!(names.len(), machines.len(), "{}", main.display());
        // No BT tag is left; ROS tags are, for the ROS lowering.
        for m in &machines {
            assert!(!has_prefixed(m, "bt_"), "{}", main.display());
        }
        // Machines without ROS tags are plain SCXML already and read as such; written out
        // and read back they are the same.
        for m in &machines {
            if !has_ros_tag(m) {
                let mut src = ModelSource {
                    sources: sm.clone(),
                    ..ModelSource::default()
                };
                let mut errs = Diagnostics::default();
                src.add_machine_tree(m, FileId(0), &mut errs);
                assert!(errs.is_empty(), "{}: {errs}", main.display());
                let text = write::to_xml(m);
                let mut sm2 = SourceMap::new();
                let id = sm2.add("m.scxml", text.clone());
                let back = xml::parse(&sm2, id).unwrap();
                assert_eq!(write::to_xml(&back), text);
            }
        }
        if let Some(plain) = plain {
            let theirs: BTreeSet<String> = std::fs::read_dir(plain)
                .unwrap()
                .map(|e| {
                    e.unwrap()
                        .path()
                        .file_stem()
                        .unwrap()
                        .to_string_lossy()
                        .into_owned()
                })
                .filter(|n| is_bt_machine(n))
                .collect();
            assert_eq!(names, theirs, "{}", main.display());
            compared += 1;
        }
    }
    assert!(
        compared >= 20,
        "compared {compared} cases with AS2FM's machine names"
    );
}

// ---------------------------------------------------------------------------------------
// A test-only ROS shim: topic publishers and the tick timer as plain SCXML, the way AS2FM
// translates them, so BT cases can be simulated before the ROS lowering exists here.

/// Global time unit of the shim: milliseconds.
const MS_PER_S: u64 = 1000;

fn topic_event(topic: &str) -> String {
    format!(
        "topic_{}_msg",
        topic.trim_start_matches('/').replace('/', "__")
    )
}

/// Rewrites `ros_topic_publisher` / `ros_topic_publish` / `ros_time_rate` /
/// `ros_rate_callback` to plain SCXML; returns the timers (name, rate).
fn shim(m: &mut Element, timers: &mut Vec<(String, String, f64)>) {
    let machine = m.attr_value("name").unwrap().to_string();
    let mut topics: BTreeMap<String, String> = BTreeMap::new();
    m.children.retain(|n| match n {
        Node::Element(e) if e.name == "ros_topic_publisher" && e.attr("topic").is_some() => {
            let topic = e.attr_value("topic").unwrap();
            topics.insert(e.attr_value("name").unwrap_or(topic).into(), topic.into());
            false
        }
        Node::Element(e) if e.name == "ros_time_rate" => {
            timers.push((
                machine.clone(),
                e.attr_value("name").unwrap().into(),
                e.attr_value("rate_hz").unwrap().parse().unwrap(),
            ));
            false
        }
        _ => true,
    });
    fn walk(e: &mut Element, topics: &BTreeMap<String, String>) {
        for c in e.elements_mut() {
            match c.name.as_str() {
                "ros_topic_publish"
                    if c.attr_value("name")
                        .or(c.attr_value("topic"))
                        .is_some_and(|n| topics.contains_key(n)) =>
                {
                    let topic = &topics[c.attr_value("name").or(c.attr_value("topic")).unwrap()];
                    let mut s = Element::new("send", c.span)
                        .with_attr("event", topic_event(topic))
                        .with_attr("target", "NONE");
                    for f in c.elements() {
                        s.push(
                            Element::new("param", f.span)
                                .with_attr(
                                    "name",
                                    format!(
                                        "ros_fields__{}",
                                        f.attr_value("name").unwrap().replace('.', "__")
                                    ),
                                )
                                .with_attr("expr", f.attr_value("expr").unwrap()),
                        );
                    }
                    *c = s;
                }
                "ros_rate_callback" => {
                    c.name = "transition".into();
                    let n = c.remove_attr("name").unwrap().value;
                    c.set_attr("event", format!("ros_time_rate.{n}"));
                    walk(c, topics);
                }
                _ => walk(c, topics),
            }
        }
    }
    walk(m, &topics);
}

/// The timer machine: every period, sends each timer's event to its machine.
fn timer_machine(timers: &[(String, String, f64)], max_time_s: u64) -> String {
    let mut sends = String::new();
    let mut step = 0u64;
    for (_, _, rate) in timers {
        let period = (MS_PER_S as f64 / rate).round() as u64;
        step = if step == 0 { period } else { gcd(step, period) };
    }
    for (machine, name, rate) in timers {
        let period = (MS_PER_S as f64 / rate).round() as u64;
        sends += &format!(
            "<if cond=\"current_time % {period} == 0\"><send event=\"ros_time_rate.{name}\" target=\"{machine}\"/></if>"
        );
    }
    let max = max_time_s * MS_PER_S;
    format!(
        r#"<scxml name="autogenerated_global_timer" initial="idle">
  <datamodel><data id="current_time" type="int64" expr="0"/></datamodel>
  <state id="idle">
    <onentry><send event="global_timer_tick_event" target="autogenerated_global_timer" delay="{step}"/></onentry>
    <transition event="global_timer_tick_event" cond="current_time &lt; {max}" target="idle">
      <assign location="current_time" expr="current_time + {step}"/>{sends}
    </transition>
    <transition event="global_timer_tick_event" target="timeout"/>
  </state>
  <state id="timeout"/>
</scxml>"#
    )
}

fn gcd(a: u64, b: u64) -> u64 {
    if b == 0 {
        a
    } else {
        gcd(b, a % b)
    }
}

/// The lowered case with the shim applied: (source map, machines).
fn shimmed_with(case: &Case, halts: Halts) -> (SourceMap, Vec<Element>) {
    let (mut sm, _, mut machines) = lower_case_with(case, halts);
    let mut timers = Vec::new();
    for m in &mut machines {
        shim(m, &mut timers);
    }
    let text = timer_machine(&timers, 100);
    let id = sm.add("autogenerated_global_timer.scxml", text);
    machines.push(xml::parse(&sm, id).unwrap());
    (sm, machines)
}

fn compile(sm: SourceMap, machines: &[Element]) -> CompiledModel {
    let mut src = ModelSource {
        sources: sm,
        ..ModelSource::default()
    };
    let mut errs = Diagnostics::default();
    for m in machines {
        src.add_machine_tree(m, FileId(0), &mut errs);
    }
    assert!(errs.is_empty(), "{errs}");
    CompiledModel::compile(src).unwrap_or_else(|e| panic!("{e}"))
}

// ---------------------------------------------------------------------------------------
// A machine's shape, for the checks below. The machine-by-machine comparison with AS2FM's
// plain translations is tests/convert_vs_as2fm.rs's (ordered, every machine of every case).

/// A machine reduced to what its behaviour depends on: per state, the transitions
/// (event, condition without spaces and parentheses, target) and every message sent
/// (event, target, parameter names), as sorted multisets; and the variables with their
/// initial values.
#[derive(Debug, PartialEq, Eq)]
struct Shape {
    vars: BTreeSet<(String, String)>,
    states: BTreeMap<String, StateShape>,
}

/// A state's transitions `(event, cond, target)` and messages sent, both sorted.
type StateShape = (Vec<(String, String, String)>, Vec<String>);

fn norm(s: &str) -> String {
    if let Ok(f) = s.trim().parse::<f64>() {
        return f.to_string();
    }
    s.chars()
        .filter(|c| !c.is_whitespace() && *c != '(' && *c != ')')
        .collect()
}

fn sends(e: &Element, out: &mut Vec<String>) {
    for c in e.elements() {
        if c.name == "send" {
            let params: Vec<String> = c
                .elements()
                .map(|p| {
                    format!(
                        "{}={}",
                        p.attr_value("name").unwrap(),
                        norm(p.attr_value("expr").unwrap_or(""))
                    )
                })
                .collect();
            let event = c.attr_value("event").unwrap();
            // Topic messages go to their subscribers in AS2FM; the test shim has none.
            let target = if event.starts_with("topic_") {
                "*"
            } else {
                c.attr_value("target").unwrap_or("")
            };
            out.push(format!("{}->{}({})", event, target, params.join(",")));
        } else {
            sends(c, out);
        }
    }
}

/// AS2FM's `lo<__RAND__&&__RAND__<=hi` as `prob:<hi - lo>`.
fn prob_share(cond: &str) -> String {
    let Some(at) = cond.find("<__RAND__&&__RAND__<=") else {
        return cond.to_string();
    };
    let head = &cond[..at];
    let (prefix, lo) = match head.rfind("&&") {
        Some(i) => (&head[..i + 2], &head[i + 2..]),
        None => ("", head),
    };
    let hi = &cond[at + "<__RAND__&&__RAND__<=".len()..];
    let (lo, hi): (f64, f64) = (lo.parse().unwrap(), hi.parse().unwrap());
    format!("{prefix}prob:{:.6}", hi - lo)
}

fn shape(m: &Element) -> Shape {
    let mut vars = BTreeSet::new();
    let mut states = BTreeMap::new();
    for c in m.elements() {
        if c.name == "datamodel" {
            for d in c.elements() {
                if d.attr_value("id") == Some("__RAND__") {
                    continue; // AS2FM's lowering of <target prob>; ours is the reader's
                }
                vars.insert((
                    d.attr_value("id").unwrap().to_string(),
                    norm(d.attr_value("expr").unwrap_or("")),
                ));
            }
        }
        if c.name == "state" {
            let mut ts = Vec::new();
            let mut ss = Vec::new();
            for t in c.elements() {
                if t.name == "transition" {
                    let event = t.attr_value("event").unwrap_or("").to_string();
                    let cond = norm(t.attr_value("cond").unwrap_or(""));
                    let targets: Vec<&Element> =
                        t.elements().filter(|e| e.name == "target").collect();
                    if targets.is_empty() {
                        ts.push((
                            event.clone(),
                            prob_share(&cond),
                            t.attr_value("target").unwrap_or("").to_string(),
                        ));
                    }
                    for g in targets {
                        let p: f64 = g.attr_value("prob").unwrap().parse().unwrap();
                        let share = format!("prob:{p:.6}");
                        let cond = if cond.is_empty() {
                            share
                        } else {
                            format!("{cond}&&{share}")
                        };
                        ts.push((event.clone(), cond, g.attr_value("id").unwrap().to_string()));
                    }
                }
                sends(t, &mut ss);
            }
            ts.sort();
            ss.sort();
            states.insert(c.attr_value("id").unwrap().to_string(), (ts, ss));
        }
    }
    Shape { vars, states }
}

// ---------------------------------------------------------------------------------------
// Simulation against the verdicts AS2FM's tests expect.

/// The last value of every message parameter (`<event>__<param>`), and which events were
/// ever sent (`<event>.valid`): the variables AS2FM's JANI properties talk about.
#[derive(Default)]
struct LastValues {
    ints: BTreeMap<String, i64>,
    sent: BTreeSet<String>,
    /// How many times each event was sent.
    counts: BTreeMap<String, u64>,
}

type Prop = fn(&LastValues) -> bool;

/// A property: its name, its test, and whether it must hold in every run (else in none).
type Check<'a> = (&'a str, Prop, bool);

/// Watches one run: which `F` properties held at some point.
struct Eventually<'a> {
    vals: LastValues,
    props: &'a [(&'a str, Prop, bool)],
    held: Vec<bool>,
}

impl Observer for Eventually<'_> {
    fn on_send(&mut self, _time: u64, msg: &SentMessage<'_>) -> Flow {
        let ev = msg.event_name();
        self.vals.sent.insert(ev.to_string());
        *self.vals.counts.entry(ev.to_string()).or_default() += 1;
        let params = msg.model().event_params(msg.event());
        for (i, (name, _)) in params.iter().enumerate() {
            if let Some(v) = msg.param(i).and_then(|v| v.as_i64()) {
                self.vals.ints.insert(format!("{ev}__{name}"), v);
            }
        }
        for (k, (_, p, _)) in self.props.iter().enumerate() {
            if !self.held[k] && p(&self.vals) {
                self.held[k] = true;
            }
        }
        if self.held.iter().all(|h| *h) {
            Flow::Stop
        } else {
            Flow::Continue
        }
    }
}

fn int(v: &LastValues, k: &str) -> i64 {
    v.ints.get(k).copied().unwrap_or(0)
}

fn valid(v: &LastValues, ev: &str) -> bool {
    v.sent.contains(ev)
}

fn root_is(v: &LastValues, s: i64) -> bool {
    int(v, "bt_1000_response__status") == s
}

fn regular(v: &LastValues) -> bool {
    root_is(v, 1)
        && int(v, "topic_tick_count_0_msg__ros_fields__data") == 1
        && int(v, "topic_tick_count_1_msg__ros_fields__data") == 3
        && int(v, "topic_tick_count_2_msg__ros_fields__data") == 1
        && int(v, "topic_reset_count_0_msg__ros_fields__data") == 1
        && int(v, "topic_reset_count_1_msg__ros_fields__data") == 1
        && int(v, "topic_reset_count_2_msg__ros_fields__data") == 1
}

fn then_10(v: &LastValues) -> bool {
    int(v, "topic_tick_count_then_msg__ros_fields__data") == 10
        && !valid(v, "topic_tick_count_else_msg")
}

fn else_10(v: &LastValues) -> bool {
    int(v, "topic_tick_count_else_msg__ros_fields__data") == 10
        && !valid(v, "topic_tick_count_then_msg")
}

fn ten_zero_none_one(v: &LastValues) -> bool {
    int(v, "topic_tick_count_0_msg__ros_fields__data") == 10
        && !valid(v, "topic_tick_count_1_msg")
        && int(v, "topic_reset_count_0_msg__ros_fields__data") == 10
        && int(v, "topic_reset_count_1_msg__ros_fields__data") == 10
}

fn repeats(v: &LastValues) -> bool {
    int(v, "topic_tick_count_0_msg__ros_fields__data") == 4
        && int(v, "topic_reset_count_0_msg__ros_fields__data") == 4
        && root_is(v, 1)
}

/// Runs `runs` seeds of the case and returns, per property, how many runs it held in;
/// the same with both halting rules (checked here).
fn simulate(main: &Path, props: &[(&str, Prop, bool)], runs: u64) -> Vec<u64> {
    let exact = simulate_with(main, props, runs, Halts::As2fm);
    let fast = simulate_with(main, props, runs, Halts::WhenNeeded);
    assert_eq!(exact, fast, "{}: halting rules disagree", main.display());
    exact
}

fn simulate_with(main: &Path, props: &[(&str, Prop, bool)], runs: u64, halts: Halts) -> Vec<u64> {
    let case = read_main(main);
    let (sm, machines) = shimmed_with(&case, halts);
    let model = compile(sm, &machines);
    let cfg = RunConfig {
        max_time: 100 * MS_PER_S + 1,
        ..RunConfig::default()
    };
    count_runs(&model, &cfg, main, props, runs)
}

/// The same for AS2FM's plain translation in `dir` (its global timer ends the run).
fn simulate_plain(dir: &Path, props: &[(&str, Prop, bool)], runs: u64) -> Vec<u64> {
    let model = CompiledModel::load(dir).unwrap_or_else(|e| panic!("{e}"));
    let cfg = RunConfig {
        max_time: 10_000_000,
        ..RunConfig::default()
    };
    count_runs(&model, &cfg, dir, props, runs)
}

fn count_runs(
    model: &CompiledModel,
    cfg: &RunConfig,
    main: &Path,
    props: &[(&str, Prop, bool)],
    runs: u64,
) -> Vec<u64> {
    let mut sim = Simulator::new(model);
    let mut counts = vec![0; props.len()];
    for seed in 0..runs {
        let mut obs = Eventually {
            vals: LastValues::default(),
            props,
            held: vec![false; props.len()],
        };
        let out = sim.run(&mut Xoshiro256PlusPlus::seed_from_u64(seed), cfg, &mut obs);
        assert!(
            !matches!(
                out.end,
                hindsight::verify::sim::EndReason::Error(_)
                    | hindsight::verify::sim::EndReason::Spin(_)
            ),
            "{}: {:?}",
            main.display(),
            out.end
        );
        for (k, h) in obs.held.iter().enumerate() {
            counts[k] += u64::from(*h);
        }
    }
    counts
}

#[test]
fn bt_cases_simulate_to_the_verdicts_as2fm_expects() {
    if common::corpus_or_skip().is_none() {
        return;
    }
    let bt = corpus().join("as2fm/test_data/bt_test_models");
    let cases: Vec<(&str, Vec<Check>)> = vec![
        (
            "main_test_sequence.xml",
            vec![("regular_bt_test", regular as Prop, true)],
        ),
        (
            "main_test_fallback.xml",
            vec![("regular_bt_test", regular, true)],
        ),
        (
            "main_test_ifthenelse_then.xml",
            vec![
                ("tree_success", |v| root_is(v, 1), true),
                ("counter_then_10", then_10, true),
                ("counter_else_10", else_10, false),
            ],
        ),
        (
            "main_test_ifthenelse_else.xml",
            vec![
                ("tree_success", |v| root_is(v, 1), true),
                ("counter_then_10", then_10, false),
                ("counter_else_10", else_10, true),
            ],
        ),
        (
            // Despite its name and comment, this tree has two failing children of three with
            // failure_threshold 2: the Parallel fails (in AS2FM's translation as well).
            "main_test_parallel_success.xml",
            vec![
                ("parallel_success_test", |v| root_is(v, 1), false),
                ("parallel_failure_test", |v| root_is(v, 2), true),
                (
                    "parallel_success_status_action_child_test",
                    |v| int(v, "bt_1001_response__status") == 2,
                    true,
                ),
            ],
        ),
        (
            "main_test_parallel_failure.xml",
            vec![
                ("parallel_failure_test", |v| root_is(v, 2), true),
                ("parallel_success_test", |v| root_is(v, 1), false),
                (
                    "parallel_failure_status_action_child_test",
                    |v| int(v, "bt_1001_response__status") == 2,
                    true,
                ),
            ],
        ),
        (
            "main_test_parallel_running.xml",
            vec![
                ("parallel_running_test", |v| root_is(v, 3), true),
                ("parallel_failure_test", |v| root_is(v, 2), false),
                (
                    "parallel_running_status_action_child_test",
                    |v| int(v, "bt_1001_response__status") == 3,
                    true,
                ),
            ],
        ),
        (
            "main_test_reactive_sequence.xml",
            vec![("ten_tick_zero_no_tick_one", ten_zero_none_one, true)],
        ),
        (
            "main_test_reactive_fallback.xml",
            vec![("ten_tick_zero_no_tick_one", ten_zero_none_one, true)],
        ),
        (
            "main_test_repeat.xml",
            vec![("repeats_and_success", repeats, true)],
        ),
    ];
    for (main, props) in &cases {
        let counts = simulate(&bt.join(main), props, 5);
        let plain = corpus().join("as2fm/plain").join(format!(
            "bt_{}",
            main.trim_start_matches("main_test_")
                .trim_end_matches(".xml")
        ));
        let theirs = simulate_plain(&plain, props, 5);
        assert_eq!(counts, theirs, "{main}: ours vs AS2FM's translation");
        for ((name, _, expect), n) in props.iter().zip(&counts) {
            let want = if *expect { 5 } else { 0 };
            assert_eq!(*n, want, "{main} {name}: held in {n} of 5 runs");
        }
    }
}

#[test]
fn blackboard_cases_reach_tree_success_as_expected_json_says() {
    if common::corpus_or_skip().is_none() {
        return;
    }
    // Both cases' only property is `Pmin F bt_1000_response__status == 1`.
    let as2fm = corpus().join("as2fm");
    let expected: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(as2fm.join("expected.json")).unwrap())
            .unwrap();
    for (key, runs) in [
        ("blackboard_test_main", 3),
        ("grid_robot_blackboard_simple_main", 40),
    ] {
        let case = &expected[key];
        let want = &case["expected"][0];
        assert_eq!(want["property"], "tree_success");
        let (p, tol) = (
            want["probability"].as_f64().unwrap(),
            want["tolerance"].as_f64().unwrap(),
        );
        let main = as2fm.join(case["main"].as_str().unwrap());
        let props: [Check; 1] = [("tree_success", |v| root_is(v, 1), true)];
        let counts = simulate(&main, &props, runs);
        let theirs = simulate_plain(&as2fm.join("plain").join(key), &props, runs);
        assert_eq!(counts, theirs, "{key}: ours vs AS2FM's translation");
        let est = counts[0] as f64 / runs as f64;
        if tol == 0.0 {
            assert_eq!(est, p, "{key}: held in {} of {runs} runs", counts[0]);
        } else {
            assert!((est - p).abs() <= tol, "{key}: {est} vs {p}");
        }
    }
}

// ---------------------------------------------------------------------------------------
// Small trees written here: SubTrees, defaults, and errors with positions.

const COUNT: &str = r#"<ascxml name="Count" initial="s">
  <bt_declare_port_in key="n" type="int8"/>
  <bt_declare_port_out key="out" type="int32"/>
  <datamodel><data id="k" type="int8"><expr><bt_get_input key="n"/></expr></data></datamodel>
  <state id="s">
    <bt_tick target="s"><bt_return_status status="SUCCESS"/></bt_tick>
    <bt_halt target="s"><bt_return_halted/></bt_halt>
  </state>
</ascxml>"#;

/// Lowers `tree` (named `t.xml`) with plugins `p0.ascxml`, `p1.ascxml`, ...
fn lower_texts(
    tree: &str,
    plugins: &[&str],
) -> Result<Vec<Element>, Vec<hindsight::verify::model::Diagnostic>> {
    let mut sm = SourceMap::new();
    let t = sm.add("t.xml", tree.to_string());
    let plugins = plugins
        .iter()
        .enumerate()
        .map(|(i, p)| sm.add(format!("p{i}.ascxml"), p.to_string()))
        .collect();
    bt::lower(
        &sm,
        &BtInput {
            tree: t,
            plugins,
            tick_rate_hz: 2.0,
            tick_if_not_running: true,
            halts: Halts::As2fm,
            semantics: Default::default(),
        },
    )
}

/// 1-based line and column of the first `needle` in `text`.
fn pos(text: &str, needle: &str) -> (u32, u32) {
    let at = text
        .find(needle)
        .unwrap_or_else(|| panic!("{needle} not in text"));
    let line = text[..at].matches('\n').count() as u32 + 1;
    let col = (at - text[..at].rfind('\n').map_or(0, |i| i + 1)) as u32 + 1;
    (line, col)
}

/// The single error of lowering, checked to be in `file` at the position of `needle`
/// in `text`, with `words` in its message.
fn one_error(tree: &str, plugins: &[&str], file: &str, text: &str, needle: &str, words: &str) {
    let errs = lower_texts(tree, plugins).expect_err("an error");
    assert_eq!(errs.len(), 1, "{errs:?}");
    let e = &errs[0];
    assert_eq!(Path::new(&e.file), Path::new(file), "{e:?}");
    assert_eq!((e.line, e.col), pos(text, needle), "{e:?}");
    assert!(e.message.contains(words), "{}", e.message);
}

fn wrap(body: &str) -> String {
    format!(
        "<root BTCPP_format=\"4\">\n<BehaviorTree ID=\"Main\">\n{body}\n</BehaviorTree>\n</root>"
    )
}

fn names(ms: &[Element]) -> Vec<String> {
    ms.iter()
        .map(|m| m.attr_value("name").unwrap().to_string())
        .collect()
}

#[test]
fn subtrees_are_inlined_in_pre_order_with_remapped_blackboard_entries() {
    let tree = r#"<root BTCPP_format="4" main_tree_to_execute="Main">
  <BehaviorTree ID="Main">
    <Sequence>
      <SubTree ID="Twice" out="{total}"/>
      <Action ID="Count" name="last" n="1" out="{total}"/>
    </Sequence>
  </BehaviorTree>
  <BehaviorTree ID="Twice">
    <Sequence name="twice">
      <Count n="2" out="{out}"/>
      <Count n="3" out="{scratch}"/>
    </Sequence>
  </BehaviorTree>
</root>"#;
    let ms = lower_texts(tree, &[COUNT]).unwrap();
    assert_eq!(
        names(&ms),
        [
            "bt_root_fsm_t",
            "BT_plugin_1000_Sequence",
            "BT_plugin_1001_twice",
            "BT_plugin_1002_Count",
            "BT_plugin_1003_Count",
            "BT_plugin_1004_last",
            "bt_blackboard_fsm",
        ]
    );
    // `out` is remapped to the caller's `total`; `scratch` stays private to the instance.
    let bb = shape(ms.last().unwrap());
    let vars: Vec<&str> = bb.vars.iter().map(|(v, _)| v.as_str()).collect();
    assert_eq!(vars, ["Twice_1_scratch", "total"]);
    // With `_autoremap`, the SubTree's names are the caller's.
    let shared = tree.replace(
        "out=\"{total}\"/>\n      <Action",
        "_autoremap=\"true\"/>\n      <Action",
    );
    let ms2 = lower_texts(&shared, &[COUNT]).unwrap();
    let bb2 = shape(ms2.last().unwrap());
    let vars2: Vec<&str> = bb2.vars.iter().map(|(v, _)| v.as_str()).collect();
    assert_eq!(vars2, ["out", "scratch", "total"]);
    // The port constant became the data's initial value.
    let count = shape(&ms[3]);
    assert!(count.vars.contains(&("k".to_string(), "2".to_string())));
    // Every machine reads back as plain SCXML except the root (its ROS timer).
    let mut src = ModelSource::default();
    let mut errs = Diagnostics::default();
    for m in &ms[1..] {
        src.add_machine_tree(m, FileId(0), &mut errs);
    }
    assert!(errs.is_empty(), "{errs}");
}

#[test]
fn a_subtree_that_includes_itself_is_an_error() {
    let tree = "<root main_tree_to_execute=\"A\">\n<BehaviorTree ID=\"A\">\n<SubTree ID=\"A\"/>\n</BehaviorTree>\n</root>";
    let errs = lower_texts(tree, &[]).unwrap_err();
    assert!(errs[0].message.contains("include itself"), "{errs:?}");
}

#[test]
fn the_root_machine_ticks_on_a_ros_timer_and_stops_unless_told_otherwise() {
    let tree = wrap("<AlwaysSuccess/>");
    let mut sm = SourceMap::new();
    let t = sm.add("my_tree.xml", tree);
    for (again, states) in [(true, 1), (false, 2)] {
        let ms = bt::lower(
            &sm,
            &BtInput {
                tree: t,
                plugins: vec![],
                tick_rate_hz: 10.0,
                tick_if_not_running: again,
                halts: Halts::As2fm,
                semantics: Default::default(),
            },
        )
        .unwrap();
        let root = &ms[0];
        assert_eq!(root.attr_value("name"), Some("bt_root_fsm_my_tree"));
        let timer = root.elements().find(|e| e.name == "ros_time_rate").unwrap();
        assert_eq!(timer.attr_value("name"), Some("my_tree_tick"));
        assert_eq!(timer.attr_value("rate_hz"), Some("10.0"));
        let wait = &shape(root).states["wait_tick_res"].0;
        assert_eq!(wait.len(), states, "{wait:?}");
    }
}

#[test]
fn plugins_without_halt_answer_halts_in_every_state() {
    // The older format (the museum's plugins) has no <bt_halt>.
    let old = r#"<scxml name="Old" initial="a">
  <state id="a"><bt_tick target="b"/></state>
  <state id="b"><transition target="a"><bt_return_status status="FAILURE"/></transition></state>
</scxml>"#;
    let ms = lower_texts(&wrap("<Inverter><Old/></Inverter>"), &[old]).unwrap();
    let s = shape(&ms[2]);
    for st in ["a", "b"] {
        let (ts, sends) = &s.states[st];
        assert!(ts.contains(&("bt_1001_halt".into(), String::new(), String::new())));
        assert!(sends.contains(&"bt_1001_halt_response->BT_plugin_1000_Inverter()".to_string()));
    }
}

#[test]
fn unknown_nodes_and_plugins_are_errors_at_their_position() {
    let t = wrap("<Sequence>\n  <Frobnicate/>\n</Sequence>");
    one_error(
        &t,
        &[COUNT],
        "t.xml",
        &t,
        "<Frobnicate",
        "unknown node `Frobnicate`",
    );
    let t = wrap("<ManualSelector>\n<AlwaysSuccess/>\n</ManualSelector>");
    one_error(
        &t,
        &[],
        "t.xml",
        &t,
        "<ManualSelector",
        "`ManualSelector` is not supported",
    );
    let t = wrap("<Action ID=\"Nope\" n=\"1\"/>");
    one_error(&t, &[COUNT], "t.xml", &t, "Nope", "plugins: Count");
    let t = wrap("<RateController hz=\"1\"><Count n=\"1\"/></RateController>");
    one_error(
        &t,
        &[COUNT],
        "t.xml",
        &t,
        "<RateController",
        "`RateController` is a control or decorator node of Nav2",
    );
    // Under an unknown node, every unknown node is named at once (a tree written for
    // another executor lacks many), the known ones (Sequence, Count, a SubTree) are not.
    let t = wrap(
        "<Recovery>\n<Pipeline>\n<Sequence><Count n=\"1\"/><Rate><Spin/></Rate></Sequence>\n\
         <Action ID=\"Wait\"/><SubTree ID=\"Gone\"/></Pipeline>\n</Recovery>",
    );
    let errs = lower_texts(&t, &[COUNT]).expect_err("errors");
    let got: Vec<(u32, u32, &str)> = errs
        .iter()
        .map(|e| (e.line, e.col, e.message.split(':').next().unwrap_or("")))
        .collect();
    let at = |needle| pos(&t, needle);
    assert_eq!(
        got,
        [
            ("<Recovery", "unknown node `Recovery`"),
            ("<Pipeline", "unknown node `Pipeline`"),
            ("<Rate", "unknown node `Rate`"),
            ("<Spin", "unknown node `Spin`"),
            ("Wait", "unknown node `Wait`"),
        ]
        .map(|(n, m)| (at(n).0, at(n).1, m))
        .to_vec(),
        "{errs:?}"
    );
}

#[test]
fn ports_are_checked_against_the_plugin() {
    let t = wrap("<Count n=\"300\"/>");
    one_error(&t, &[COUNT], "t.xml", &t, "300", "not a valid int8");
    let t = wrap("<Count n=\"x\"/>");
    one_error(&t, &[COUNT], "t.xml", &t, "x\"", "not a valid int8");
    let t = wrap("<Count n=\"1\" speed=\"2\"/>");
    one_error(&t, &[COUNT], "t.xml", &t, "2\"", "no port `speed`");
    let t = wrap("<Count n=\"1\" out=\"5\"/>");
    one_error(&t, &[COUNT], "t.xml", &t, "5\"", "output port");
    // A port the plugin reads but the tree does not set: at the tree node.
    let t = wrap("<Count/>");
    one_error(&t, &[COUNT], "t.xml", &t, "<Count", "needs port `n`");
    // One blackboard entry used with two types.
    let other = COUNT
        .replace("name=\"Count\"", "name=\"Str\"")
        .replace("\"int32\"", "\"string\"");
    let t =
        wrap("<Sequence>\n<Count n=\"1\" out=\"{v}\"/>\n<Str n=\"1\" out=\"{v}\"/>\n</Sequence>");
    let errs = lower_texts(&t, &[COUNT, &other]).unwrap_err();
    assert_eq!(errs.len(), 1, "{errs:?}");
    assert!(
        errs[0].message.contains("used as string here but as int32"),
        "{errs:?}"
    );
}

#[test]
fn bad_plugin_tags_are_errors_in_the_plugin_file() {
    let bad = COUNT.replace("<bt_return_halted/>", "<bt_frob/>");
    let t = wrap("<Count n=\"1\"/>");
    one_error(
        &t,
        &[&bad],
        "p0.ascxml",
        &bad,
        "<bt_frob",
        "unknown BT tag <bt_frob>",
    );
    let bad = COUNT.replace("status=\"SUCCESS\"", "status=\"DONE\"");
    one_error(
        &t,
        &[&bad],
        "p0.ascxml",
        &bad,
        "DONE",
        "unknown status `DONE`",
    );
    let bad = COUNT.replace("<bt_get_input key=\"n\"/>", "<bt_get_input key=\"m\"/>");
    one_error(
        &t,
        &[&bad],
        "p0.ascxml",
        &bad,
        "<bt_get_input",
        "port `m` is not declared",
    );
    let bad = COUNT.replace("type=\"int8\"/>", "type=\"int7\"/>");
    let errs = lower_texts(&t, &[&bad]).unwrap_err();
    assert_eq!((errs[0].line, errs[0].col), pos(&bad, "int7"), "{errs:?}");
}

#[test]
fn bad_control_node_attributes_are_errors() {
    let t = wrap("<Repeat>\n<AlwaysSuccess/>\n</Repeat>");
    one_error(&t, &[], "t.xml", &t, "<Repeat", "needs `num_cycles`");
    let t = wrap("<Repeat num_cycles=\"many\">\n<AlwaysSuccess/>\n</Repeat>");
    one_error(&t, &[], "t.xml", &t, "many", "whole number");
    let t = wrap("<Parallel success_count=\"3\">\n<AlwaysSuccess/>\n<AlwaysSuccess/>\n</Parallel>");
    one_error(
        &t,
        &[],
        "t.xml",
        &t,
        "3\"",
        "between 1 and the number of children (2)",
    );
    let t = wrap("<Inverter>\n<AlwaysSuccess/>\n<AlwaysFailure/>\n</Inverter>");
    one_error(
        &t,
        &[],
        "t.xml",
        &t,
        "<Inverter",
        "needs 1 children, found 2",
    );
    let t = wrap("<Sequence colour=\"red\">\n<AlwaysSuccess/>\n</Sequence>");
    one_error(&t, &[], "t.xml", &t, "colour", "unknown attribute `colour`");
    let t = wrap("<Sequence _skipIf=\"x\">\n<AlwaysSuccess/>\n</Sequence>");
    one_error(&t, &[], "t.xml", &t, "_skipIf", "not supported");
}

#[test]
fn probabilistic_targets_in_a_plugin_split_the_runs_by_their_shares() {
    // Like uc1's BackUp: fails with probability 0.25. Ticked once (the root stops after
    // the first answer), so the tree succeeds in about 75% of the runs.
    let coin = r#"<ascxml name="Coin" initial="s">
  <state id="s">
    <bt_tick>
      <target id="s" prob="0.25"><bt_return_status status="FAILURE"/></target>
      <target id="s" prob="0.75"><bt_return_status status="SUCCESS"/></target>
    </bt_tick>
    <bt_halt target="s"><bt_return_halted/></bt_halt>
  </state>
</ascxml>"#;
    let tree = wrap("<Coin/>");
    let mut sm = SourceMap::new();
    let t = sm.add("coin_tree.xml", tree);
    let p = sm.add("coin.ascxml", coin.to_string());
    let mut ms = bt::lower(
        &sm,
        &BtInput {
            tree: t,
            plugins: vec![p],
            tick_rate_hz: 1.0,
            tick_if_not_running: false,
            halts: Halts::As2fm,
            semantics: Default::default(),
        },
    )
    .unwrap();
    let mut timers = Vec::new();
    for m in &mut ms {
        shim(m, &mut timers);
    }
    let id = sm.add("timer.scxml", timer_machine(&timers, 5));
    ms.push(xml::parse(&sm, id).unwrap());
    let model = compile(sm, &ms);
    let props: [Check; 2] = [
        ("success", |v| root_is(v, 1), true),
        ("failure", |v| root_is(v, 2), true),
    ];
    let cfg = RunConfig {
        max_time: 6 * MS_PER_S,
        ..RunConfig::default()
    };
    let n = 4000;
    let counts = count_runs(&model, &cfg, Path::new("coin"), &props, n);
    assert_eq!(counts[0] + counts[1], n, "every run answers exactly once");
    let p = counts[0] as f64 / n as f64;
    // 4000 runs: the standard error is under 0.007.
    assert!((p - 0.75).abs() < 0.03, "success rate {p}");
}

#[test]
fn custom_control_plugins_tick_and_hear_their_children() {
    // A two-child fallback written as a plugin, choosing its child with an expression.
    let try_each = r#"<ascxml name="TryEach" initial="idle">
  <datamodel><data id="i" type="int8" expr="0"/></datamodel>
  <state id="idle">
    <bt_tick target="wait"><assign location="i" expr="0"/><bt_tick_child id="i"/></bt_tick>
    <bt_halt target="halting"><bt_halt_child id="0"/></bt_halt>
  </state>
  <state id="halting">
    <bt_child_halted id="0" target="idle"><bt_return_halted/></bt_child_halted>
  </state>
  <state id="wait">
    <bt_child_status id="i" cond="_bt.status == SUCCESS" target="idle"><bt_return_status status="SUCCESS"/></bt_child_status>
    <bt_child_status id="i" cond="_bt.status == FAILURE &amp;&amp; i == 0" target="wait"><assign location="i" expr="1"/><bt_tick_child id="i"/></bt_child_status>
    <bt_child_status id="i" cond="_bt.status != SUCCESS &amp;&amp; i == 1" target="idle"><bt_return_status status="FAILURE"/></bt_child_status>
  </state>
</ascxml>"#;
    for (children, expect) in [
        ("<AlwaysFailure/><AlwaysSuccess/>", 1),
        ("<AlwaysFailure/><AlwaysFailure/>", 2),
        ("<AlwaysSuccess/><AlwaysFailure/>", 1),
    ] {
        let mut sm = SourceMap::new();
        let t = sm.add(
            "custom.xml",
            wrap(&format!("<TryEach>{children}</TryEach>")),
        );
        let p = sm.add("try_each.ascxml", try_each.to_string());
        let mut ms = bt::lower(
            &sm,
            &BtInput {
                tree: t,
                plugins: vec![p],
                tick_rate_hz: 1.0,
                tick_if_not_running: false,
                halts: Halts::As2fm,
                semantics: Default::default(),
            },
        )
        .unwrap_or_else(|e| panic!("{}", Diagnostics(e)));
        let wait = &shape(&ms[1]).states["wait"].0;
        assert_eq!(wait.len(), 6, "one transition per child and tag: {wait:?}");
        let mut timers = Vec::new();
        for m in &mut ms {
            shim(m, &mut timers);
        }
        let id = sm.add("timer.scxml", timer_machine(&timers, 3));
        ms.push(xml::parse(&sm, id).unwrap());
        let model = compile(sm, &ms);
        let props: [Check; 1] = [(
            "answer",
            |v| v.ints.contains_key("bt_1000_response__status"),
            true,
        )];
        let cfg = RunConfig {
            max_time: 4 * MS_PER_S,
            ..RunConfig::default()
        };
        let mut sim = Simulator::new(&model);
        let mut obs = Eventually {
            vals: LastValues::default(),
            props: &props,
            held: vec![false],
        };
        sim.run(&mut Xoshiro256PlusPlus::seed_from_u64(1), &cfg, &mut obs);
        assert_eq!(
            int(&obs.vals, "bt_1000_response__status"),
            expect,
            "{children}"
        );
    }
    // A leaf plugin given children is an error at the node.
    let t = wrap("<Count n=\"1\">\n<AlwaysSuccess/>\n</Count>");
    one_error(&t, &[COUNT], "t.xml", &t, "<Count", "leaf plugin");
}

#[test]
fn blackboard_reads_outside_transitions_are_errors() {
    let reader = r#"<ascxml name="R" initial="s">
  <bt_declare_port_in key="v" type="int32"/>
  <datamodel><data id="x" type="int32" expr="0"/></datamodel>
  <state id="s">
    <onentry><assign location="x"><expr><bt_get_input key="v"/></expr></assign></onentry>
    <bt_tick target="s"><bt_return_status status="SUCCESS"/></bt_tick>
    <bt_halt target="s"><bt_return_halted/></bt_halt>
  </state>
</ascxml>"#;
    // A constant is fine anywhere.
    let ms = lower_texts(&wrap("<R v=\"3\"/>"), &[reader]).unwrap();
    assert!(write::to_xml(&ms[1]).contains("<assign location=\"x\" expr=\"3\"/>"));
    let t = wrap("<R v=\"{e}\"/>");
    one_error(
        &t,
        &[reader],
        "p0.ascxml",
        reader,
        "<onentry",
        "only transitions can read the blackboard",
    );
    let in_data = reader.replace(
        "<data id=\"x\" type=\"int32\" expr=\"0\"/>",
        "<data id=\"x\" type=\"int32\"><expr><bt_get_input key=\"v\"/></expr></data>",
    ).replace("<onentry><assign location=\"x\"><expr><bt_get_input key=\"v\"/></expr></assign></onentry>", "");
    one_error(
        &t,
        &[&in_data],
        "p0.ascxml",
        &in_data,
        "<datamodel",
        "only transitions can read the blackboard",
    );
}

const FAIL_N: &str = r#"<ascxml name="FailN" initial="s">
  <bt_declare_port_in key="n" type="int8"/>
  <ros_topic_publisher name="pub" topic="ticks" type="std_msgs/Int16"/>
  <datamodel>
    <data id="c" type="int16" expr="0"/>
    <data id="n" type="int8"><expr><bt_get_input key="n"/></expr></data>
  </datamodel>
  <state id="s">
    <bt_tick target="s">
      <assign location="c" expr="c + 1"/>
      <ros_topic_publish name="pub"><field name="data" expr="c"/></ros_topic_publish>
      <if cond="c &gt; n"><bt_return_status status="SUCCESS"/><else/><bt_return_status status="FAILURE"/></if>
    </bt_tick>
    <bt_halt target="s"><bt_return_halted/></bt_halt>
  </state>
</ascxml>"#;

/// Runs `body` (with the FailN plugin: fails `n` times, then succeeds) for `seconds`
/// ticks at 1 Hz and returns what was sent; with either halting rule, which must send
/// the same messages but halts.
fn run_small(body: &str, again: bool, seconds: u64) -> LastValues {
    let a = run_small_with(body, again, seconds, Halts::As2fm);
    let b = run_small_with(body, again, seconds, Halts::WhenNeeded);
    let no_halts = |v: &LastValues| -> (BTreeMap<String, i64>, BTreeMap<String, u64>) {
        let keep = |k: &String| !k.contains("_halt");
        (
            v.ints
                .iter()
                .filter(|(k, _)| keep(k))
                .map(|(k, x)| (k.clone(), *x))
                .collect(),
            v.counts
                .iter()
                .filter(|(k, _)| keep(k))
                .map(|(k, x)| (k.clone(), *x))
                .collect(),
        )
    };
    assert_eq!(no_halts(&a), no_halts(&b), "{body}");
    a
}

fn run_small_with(body: &str, again: bool, seconds: u64, halts: Halts) -> LastValues {
    let mut sm = SourceMap::new();
    let t = sm.add("small.xml", wrap(body));
    let p = sm.add("fail_n.ascxml", FAIL_N.to_string());
    let mut ms = bt::lower(
        &sm,
        &BtInput {
            tree: t,
            plugins: vec![p],
            tick_rate_hz: 1.0,
            tick_if_not_running: again,
            halts,
            semantics: Default::default(),
        },
    )
    .unwrap_or_else(|e| panic!("{}", Diagnostics(e)));
    let mut timers = Vec::new();
    for m in &mut ms {
        shim(m, &mut timers);
    }
    let id = sm.add("timer.scxml", timer_machine(&timers, seconds));
    ms.push(xml::parse(&sm, id).unwrap());
    let model = compile(sm, &ms);
    let props: [Check; 1] = [("never", |_| false, false)];
    let cfg = RunConfig {
        max_time: (seconds + 1) * MS_PER_S,
        ..RunConfig::default()
    };
    let mut sim = Simulator::new(&model);
    let mut obs = Eventually {
        vals: LastValues::default(),
        props: &props,
        held: vec![false],
    };
    let out = sim.run(&mut Xoshiro256PlusPlus::seed_from_u64(7), &cfg, &mut obs);
    assert!(
        !matches!(
            out.end,
            hindsight::verify::sim::EndReason::Error(_)
                | hindsight::verify::sim::EndReason::Spin(_)
        ),
        "{body}: {:?}",
        out.end
    );
    obs.vals
}

#[test]
fn nodes_without_an_as2fm_reference_behave_as_behaviortree_cpp_says() {
    let answers = |v: &LastValues| v.counts.get("bt_1000_response").copied().unwrap_or(0);
    // RetryUntilSuccessful: fails twice, succeeds on the third attempt, in one tick.
    let v = run_small(
        "<RetryUntilSuccessful num_attempts=\"3\"><FailN n=\"2\"/></RetryUntilSuccessful>",
        false,
        3,
    );
    assert_eq!((root_is(&v, 1), answers(&v)), (true, 1));
    assert_eq!(int(&v, "topic_ticks_msg__ros_fields__data"), 3);
    // Two attempts are not enough.
    let v = run_small(
        "<RetryUntilSuccessful num_attempts=\"2\"><FailN n=\"2\"/></RetryUntilSuccessful>",
        false,
        3,
    );
    assert_eq!(
        (root_is(&v, 2), int(&v, "topic_ticks_msg__ros_fields__data")),
        (true, 2)
    );
    // ForceSuccess / ForceFailure.
    let v = run_small("<ForceSuccess><FailN n=\"5\"/></ForceSuccess>", false, 3);
    assert!(root_is(&v, 1));
    let v = run_small("<ForceFailure><FailN n=\"0\"/></ForceFailure>", false, 3);
    assert!(root_is(&v, 2));
    // SequenceWithMemory resumes at the failed child: the first child is ticked once.
    let v = run_small(
        "<SequenceWithMemory><AlwaysSuccess/><FailN n=\"1\"/></SequenceWithMemory>",
        true,
        2,
    );
    assert_eq!(v.counts["bt_1001_response"], 1);
    assert_eq!(v.counts["bt_1000_response"], 2);
    assert!(root_is(&v, 1));
    // A plain Sequence starts again from the first child.
    let v = run_small(
        "<Sequence><AlwaysSuccess/><FailN n=\"1\"/></Sequence>",
        true,
        2,
    );
    assert_eq!(v.counts["bt_1001_response"], 2);
    // SetBlackboard then BlackboardCheckInt.
    for (value, status) in [("7", 1), ("8", 2)] {
        let v = run_small(
            &format!(
                "<Sequence><SetBlackboard output_key=\"x\" value=\"{value}\"/>\
                 <BlackboardCheckInt value_A=\"{{x}}\" value_B=\"7\"><AlwaysSuccess/></BlackboardCheckInt></Sequence>"
            ),
            false,
            2,
        );
        assert!(root_is(&v, status), "value {value}");
    }
    // Parallel with BehaviorTree.cpp's default thresholds: all must succeed, one failure fails.
    let v = run_small(
        "<Parallel><AlwaysSuccess/><FailN n=\"0\"/></Parallel>",
        false,
        2,
    );
    assert!(root_is(&v, 1));
    let v = run_small(
        "<Parallel><AlwaysSuccess/><FailN n=\"1\"/></Parallel>",
        false,
        2,
    );
    assert!(root_is(&v, 2));
}

#[test]
fn damaged_inputs_are_errors_never_panics() {
    if common::corpus_or_skip().is_none() {
        return;
    }
    // Every corpus tree and plugin, cut short at many points, and swapped around.
    let mut seen = 0;
    for (main, _) in bt_mains().iter().take(12) {
        let case = read_main(main);
        let tree = std::fs::read_to_string(&case.tree).unwrap();
        let plugins: Vec<String> = case
            .plugins
            .iter()
            .map(|p| std::fs::read_to_string(p).unwrap())
            .collect();
        let refs: Vec<&str> = plugins.iter().map(|s| s.as_str()).collect();
        for cut in (0..tree.len()).step_by(37) {
            if tree.is_char_boundary(cut) {
                let _ = lower_texts(&tree[..cut], &refs);
                seen += 1;
            }
        }
        for (i, p) in plugins.iter().enumerate() {
            for cut in (0..p.len()).step_by(53) {
                if p.is_char_boundary(cut) {
                    let mut damaged = refs.clone();
                    damaged[i] = &p[..cut];
                    let _ = lower_texts(&tree, &damaged);
                    seen += 1;
                }
            }
            // A plugin given as the tree, the tree given as a plugin.
            assert!(lower_texts(p, &[&tree]).is_err());
        }
    }
    assert!(seen > 500, "{seen} damaged inputs");
}
