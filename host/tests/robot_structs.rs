//! User-declared struct types in robot models: the AS2FM corpus cases with structs load,
//! compile and run to the verdicts `expected.json` gives, sending the same values as AS2FM's
//! plain translation (which flattens every struct into one variable per leaf field); bad
//! object literals and struct declarations are errors with file, line and column.

mod common;

use hindsight::verify::expr::{OwnedValue, Strings, Ty, TypeTable};
use hindsight::verify::robot::load::{load, RobotModel};
use hindsight::verify::sim::{
    CompiledModel, EndReason, EventSemantics, Flow, Observer, RunConfig, SentMessage, Simulator,
};
use rand_core::SeedableRng;
use rand_xoshiro::Xoshiro256PlusPlus;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

fn corpus() -> PathBuf {
    common::corpus_root().join("as2fm")
}

/// The main file of an `expected.json` case, and its expected probabilities by property.
fn case(name: &str) -> (PathBuf, BTreeMap<String, f64>) {
    let text = std::fs::read_to_string(corpus().join("expected.json")).unwrap();
    let doc: serde_json::Value = serde_json::from_str(&text).unwrap();
    let c = &doc[name];
    let probs = c["expected"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| {
            (
                e["property"].as_str().unwrap().to_string(),
                e["probability"].as_f64().unwrap(),
            )
        })
        .collect();
    (corpus().join(c["main"].as_str().unwrap()), probs)
}

fn load_case(name: &str) -> RobotModel {
    let (main, _) = case(name);
    load(&main).unwrap_or_else(|e| panic!("{name}:\n{e}"))
}

fn config(m: &RobotModel) -> RunConfig {
    RunConfig {
        max_time: m.max_time_steps,
        ..RunConfig::default()
    }
}

/// The leaf paths of a type, as AS2FM names its flattened variables (`points__x`).
fn leaves(types: &TypeTable, ty: &Ty, path: &mut Vec<String>, out: &mut Vec<Vec<String>>) {
    match ty {
        Ty::Struct(s) => {
            for (f, t) in &types.structs[*s as usize].fields {
                path.push(f.clone());
                leaves(types, t, path, out);
                path.pop();
            }
        }
        Ty::Array(t, _) => leaves(types, t, path, out),
        _ => out.push(path.clone()),
    }
}

/// The column of leaf `path` in a value: arrays of structs become arrays of the leaf.
fn column(types: &TypeTable, ty: &Ty, v: &OwnedValue, path: &[String]) -> OwnedValue {
    match (ty, v) {
        (Ty::Struct(s), OwnedValue::List(fields)) => {
            let def = &types.structs[*s as usize];
            let i = def.fields.iter().position(|(n, _)| *n == path[0]).unwrap();
            column(types, &def.fields[i].1, &fields[i], &path[1..])
        }
        (Ty::Array(t, _), OwnedValue::List(items)) => {
            OwnedValue::List(items.iter().map(|it| column(types, t, it, path)).collect())
        }
        _ => v.clone(),
    }
}

/// A value as text: numbers as floats (AS2FM's `0` default of a float is an int), strings
/// resolved.
fn render(v: &OwnedValue, strings: &Strings) -> String {
    match v {
        OwnedValue::Int(i) => format!("{:?}", *i as f64),
        OwnedValue::Float(f) => format!("{f:?}"),
        OwnedValue::Bool(b) => b.to_string(),
        OwnedValue::Str(s) => format!("{:?}", strings.get(*s)),
        OwnedValue::List(items) => format!(
            "[{}]",
            items
                .iter()
                .map(|i| render(i, strings))
                .collect::<Vec<_>>()
                .join(",")
        ),
    }
}

/// One sent message: time, event, origin, target and the parameters flattened as AS2FM
/// flattens them (`polygon__points__x` = `[0.1,0.3]`).
type Flat = (u64, String, String, String, BTreeMap<String, String>);

fn flatten(msg: &SentMessage<'_>) -> Flat {
    let model = msg.model();
    let types = model.types();
    let mut params = BTreeMap::new();
    for (i, (name, ty)) in model.event_params(msg.event()).iter().enumerate() {
        let v = OwnedValue::from(msg.param(i).unwrap());
        let mut paths = Vec::new();
        leaves(types, ty, &mut Vec::new(), &mut paths);
        for p in paths {
            let key = std::iter::once(name.clone())
                .chain(p.iter().cloned())
                .collect::<Vec<_>>()
                .join("__");
            params.insert(key, render(&column(types, ty, &v, &p), model.strings()));
        }
    }
    (
        0,
        msg.event_name().to_string(),
        msg.origin_name().to_string(),
        msg.target_name().to_string(),
        params,
    )
}

/// Every message of a run, flattened.
#[derive(Default)]
struct Sends(Vec<Flat>);

impl Observer for Sends {
    fn on_send(&mut self, time: u64, msg: &SentMessage<'_>) -> Flow {
        let mut f = flatten(msg);
        f.0 = time;
        self.0.push(f);
        Flow::Continue
    }
}

fn run(model: &CompiledModel, cfg: &RunConfig, seed: u64) -> Vec<Flat> {
    let mut obs = Sends::default();
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    let out = Simulator::new(model).run(&mut rng, cfg, &mut obs);
    assert!(
        !matches!(out.end, EndReason::Error(_) | EndReason::Spin(_)),
        "{:?}",
        out.end
    );
    obs.0
}

fn param<'a>(m: &'a Flat, name: &str) -> &'a str {
    m.4.get(name)
        .unwrap_or_else(|| panic!("no parameter {name} in {m:?}"))
}

fn plain(name: &str) -> CompiledModel {
    CompiledModel::load(&corpus().join("plain").join(name)).unwrap_or_else(|e| panic!("{e}"))
}

/// `data_structs` (types from XML and from a JSON schema): the sender keeps a point, a
/// polygon and an array of polygons and sends them whole; the receiver's check reads
/// fields, elements and lengths of what it received and reports `success`.
#[test]
fn data_structs_send_whole_structs_and_reach_success() {
    if common::corpus_or_skip().is_none() {
        return;
    }
    for name in ["data_structs_main_xml_def", "data_structs_main_json_def"] {
        let (_, expected) = case(name);
        assert_eq!(expected["success"], 1.0, "{name}");
        let m = load_case(name);
        let cfg = config(&m);
        for seed in 0..5 {
            let sends = run(&m.model, &cfg, seed);
            // Pmin(F success.valid) = 1: every run sends `success`.
            assert!(
                sends.iter().any(|s| s.1 == "success"),
                "{name} seed {seed}: no success"
            );
            let data: Vec<&Flat> = sends.iter().filter(|s| s.1 == "data").collect();
            // One message per entry into `increase`: the initial one and 100 increments.
            assert_eq!(data.len(), 101, "{name}");
            let first = data[0];
            assert_eq!(param(first, "point__frame"), "\"world\"");
            assert_eq!(param(first, "point__x"), "0.42");
            assert_eq!(param(first, "polygon__points__x"), "[0.1,0.3]");
            assert_eq!(
                param(first, "polygons__polygons__points__frame"),
                "[[],[\"world1\",\"world?\"]]"
            );
            let last = data[100];
            assert_eq!(
                param(last, "polygon__points__frame"),
                "[\"world1\",\"world\"]"
            );
            assert_eq!(param(last, "polygons__polygons__points__y"), {
                "[[],[2.0,104.0],[0.2,3.14]]"
            });
            let x: f64 = param(last, "point__x").parse().unwrap();
            assert!((x - 100.42).abs() < 1e-9, "{x}");
        }
    }
}

/// The same runs as AS2FM's plain translation: every message, at the same time, with the
/// same values once our structs are flattened into its per-leaf parameters.
#[test]
fn struct_cases_send_what_the_plain_translation_sends() {
    if common::corpus_or_skip().is_none() {
        return;
    }
    for name in [
        "data_structs_main_xml_def",
        "data_structs_main_json_def",
        "array_of_data_structs_main",
    ] {
        let m = load_case(name);
        let p = plain(name);
        let cfg = config(&m);
        for seed in 0..3 {
            let ours = run(&m.model, &cfg, seed);
            let theirs = run(&p, &cfg, seed);
            assert_eq!(ours.len(), theirs.len(), "{name} seed {seed}");
            for (k, (a, b)) in ours.iter().zip(&theirs).enumerate() {
                assert_eq!(a, b, "{name} seed {seed}: message {k}");
            }
        }
    }
}

/// `array_of_data_structs`: points sent one at a time as struct parameters, stored at
/// `recv_points[latest_id]` (growing the array); `success` carries the check as `data`.
#[test]
fn array_of_structs_grows_by_element_and_checks_true() {
    if common::corpus_or_skip().is_none() {
        return;
    }
    let name = "array_of_data_structs_main";
    let (_, expected) = case(name);
    assert_eq!(expected["success"], 1.0);
    let m = load_case(name);
    let cfg = config(&m);
    for seed in 0..5 {
        let sends = run(&m.model, &cfg, seed);
        let data: Vec<&Flat> = sends.iter().filter(|s| s.1 == "data").collect();
        assert_eq!(data.len(), 2);
        assert_eq!(param(data[0], "point__frame"), "\"world_a\"");
        assert_eq!(param(data[1], "point__y"), "-4.0");
        // Pmin(F (success.valid && success.data)) = 1.
        let success: Vec<&Flat> = sends.iter().filter(|s| s.1 == "success").collect();
        assert_eq!(success.len(), 1, "seed {seed}");
        assert_eq!(param(success[0], "data"), "true", "seed {seed}");
    }
}

/// `overarching_tutorial` with locations: the world keeps locations as structs written as
/// object literals; `butter_at_table` is `F (object_loc.x == 4 && y == 2 && parent ==
/// 'world')` on the `/object_loc` topic, with probability 1.
#[test]
fn overarching_tutorial_brings_the_butter_to_the_table() {
    if common::corpus_or_skip().is_none() {
        return;
    }
    let name = "overarching_tutorial_main_locations";
    let (_, expected) = case(name);
    assert_eq!(expected["butter_at_table"], 1.0);
    let m = load_case(name);
    let cfg = config(&m);
    let runs = 20;
    let mut held = 0;
    let mut start_places = std::collections::BTreeSet::new();
    for seed in 0..runs {
        let sends = run(&m.model, &cfg, seed);
        let locs: Vec<&Flat> = sends
            .iter()
            .filter(|s| s.1 == "topic_object_loc_msg")
            .collect();
        assert!(!locs.is_empty(), "seed {seed}");
        start_places.insert((
            param(locs[0], "ros_fields__x").to_string(),
            param(locs[0], "ros_fields__y").to_string(),
        ));
        if locs.iter().any(|l| {
            param(l, "ros_fields__x") == "4.0"
                && param(l, "ros_fields__y") == "2.0"
                && param(l, "ros_fields__parent") == "\"world\""
        }) {
            held += 1;
        }
    }
    assert_eq!(held, runs);
    // The object starts at one of the three places the world draws (fridge, dining
    // table, kitchen table), and over 20 runs more than one of them occurs.
    for (x, y) in &start_places {
        assert!(
            [("1.0", "-2.0"), ("-2.0", "-2.0"), ("-4.0", "-2.0")]
                .contains(&(x.as_str(), y.as_str())),
            "{x},{y}"
        );
    }
    assert!(start_places.len() > 1, "{start_places:?}");
}

/// A fresh folder with the given files; returns the main file's path.
fn write_case(tag: &str, files: &[(&str, &str)]) -> PathBuf {
    let dir = std::env::temp_dir().join(format!(
        "hindsight-robot-structs-{}-{tag}",
        std::process::id()
    ));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    for (name, text) in files {
        std::fs::write(dir.join(name), text).unwrap();
    }
    dir.join("main.xml")
}

const MAIN: &str = r#"<roaml>
    <parameters><max_time value="10" unit="s" /></parameters>
    <data_declarations><input type="xml" src="./types.xml" /></data_declarations>
    <node_models><input type="node-ascxml" src="./node.ascxml" /></node_models>
</roaml>"#;

const TYPES: &str = r#"<types>
    <struct id="Line"><member id="a" type="Point" /><member id="b" type="Point" /></struct>
    <struct id="Point"><member id="x" type="float32" /><member id="y" type="int32" /></struct>
</types>"#;

fn node(datamodel: &str, body: &str) -> String {
    format!(
        "<ascxml initial=\"s\" version=\"1.0\" name=\"node\" xmlns=\"http://www.w3.org/2005/07/scxml\">\n\
         <datamodel>\n{datamodel}\n</datamodel>\n\
         <state id=\"s\">\n{body}\n</state>\n</ascxml>"
    )
}

/// Loads a one-node model; the error text, or `None` when it loads.
fn load_err(tag: &str, types: &str, datamodel: &str, body: &str) -> Option<String> {
    let main = write_case(
        tag,
        &[
            ("main.xml", MAIN),
            ("types.xml", types),
            ("node.ascxml", &node(datamodel, body)),
        ],
    );
    let r = load(&main).err().map(|e| e.to_string());
    let _ = std::fs::remove_dir_all(main.parent().unwrap());
    r
}

#[test]
fn a_struct_may_name_a_type_declared_after_it_and_literals_nest() {
    let ok = load_err(
        "nest",
        TYPES,
        r#"<data id="l" type="Line" expr="{a: {x: 1, y: 2}, 'b': {'y': -1, 'x': 0.5}}" />"#,
        r#"<onentry><assign location="l.b" expr="{x: l.a.x + 1, y: l.a.y}" /><send event="e"><param name="l" expr="l" /></send></onentry>"#,
    );
    assert_eq!(ok, None);
}

/// An object literal sent as a parameter takes the parameter's declared type (`<param
/// type>`); without one, the error at the literal says where a struct type can come from.
#[test]
fn object_literal_parameters_need_a_declared_type() {
    let dm = r#"<data id="p" type="Point" expr="{x: 1, y: 2}" />"#;
    let typed = r#"<onentry><send event="e"><param name="q" type="Point" expr="{x: p.x, y: 3}" /></send></onentry>"#;
    assert_eq!(load_err("param-typed", TYPES, dm, typed), None);
    let untyped =
        r#"<onentry><send event="e"><param name="q" expr="{x: p.x, y: 3}" /></send></onentry>"#;
    let err = load_err("param-untyped", TYPES, dm, untyped).expect("untyped literal parameter");
    assert!(
        err.contains("node.ascxml:6:48:")
            && err.contains("struct type of this object literal is not known")
            && err.contains("a typed parameter"),
        "{err}"
    );
}

#[test]
fn bad_object_literals_are_errors_at_their_field() {
    // (datamodel, body, where: line:column, what)
    let cases = [
        (
            r#"<data id="p" type="Point" expr="{x: 1}" />"#,
            "",
            "node.ascxml:3:33",
            "no value for field `y`",
        ),
        (
            r#"<data id="p" type="Point" expr="{x: 1, y: 2, z: 3}" />"#,
            "",
            "node.ascxml:3:46",
            "type Point has no field `z` (its fields: x, y)",
        ),
        (
            r#"<data id="p" type="Point" expr="{x: 'one', y: 2}" />"#,
            "",
            "node.ascxml:3:37",
            "field `x` of Point has type string but float is expected",
        ),
        (
            r#"<data id="l" type="Line" expr="{a: {x: 1, y: 2}, b: {x: 1, y: 2.5}}" />"#,
            "",
            "node.ascxml:3:63",
            "field `y` of Point has type float but int is expected",
        ),
        (
            r#"<data id="p" expr="{x: 1, y: 2}" />"#,
            "",
            "node.ascxml:3:20",
            "struct type of this object literal is not known",
        ),
        (
            r#"<data id="p" type="Point" expr="{x: 1, y: 2}" />"#,
            r#"<onentry><assign location="p.x" expr="{x: 1, y: 2}" /></onentry>"#,
            "node.ascxml:6:39",
            "an object literal is not a value of type float",
        ),
        (
            r#"<data id="p" type="Point" expr="{x: 1, y: 2}" />"#,
            r#"<onentry><assign location="p.z" expr="1" /></onentry>"#,
            "node.ascxml:6:30",
            "type Point has no field `z`",
        ),
        (
            r#"<data id="p" type="Point" expr="{x: 1, x: 2}" />"#,
            "",
            "node.ascxml:3:40",
            "field `x` is given twice",
        ),
        (
            r#"<data id="p" type="Pointt" expr="{x: 1, y: 2}" />"#,
            "",
            "node.ascxml:3:20",
            "unknown type `Pointt` (not a base type nor declared in types.xml or the data declarations; declared: Line, Point)",
        ),
    ];
    for (i, (dm, body, at, what)) in cases.iter().enumerate() {
        let err = load_err(&format!("bad{i}"), TYPES, dm, body)
            .unwrap_or_else(|| panic!("{dm} {body}: loads"));
        assert!(
            err.contains(&format!("{at}: ")) && err.contains(what),
            "{dm} {body}:\n{err}"
        );
    }
}

#[test]
fn a_struct_that_contains_itself_is_an_error() {
    let types = r#"<types>
    <struct id="A"><member id="b" type="B" /></struct>
    <struct id="B"><member id="a" type="A" /><member id="n" type="int32" /></struct>
    <struct id="List"><member id="next" type="List[]" /></struct>
</types>"#;
    let err = load_err(
        "cycle",
        types,
        r#"<data id="n" type="int32" expr="0" />"#,
        "",
    )
    .expect("a cycle is an error");
    assert!(
        err.contains("types.xml:2:5: struct `A` contains itself"),
        "{err}"
    );
    assert!(!err.contains("`List`"), "{err}");
}

#[global_allocator]
static GLOBAL: common::alloc::Counting = common::alloc::Counting;

/// Struct values live in buffers reused between steps and runs: once warm, whole runs of
/// the struct cases (copying structs, sending them, growing arrays of structs) allocate
/// nothing.
#[test]
fn struct_runs_allocate_nothing_once_warm() {
    if common::corpus_or_skip().is_none() {
        return;
    }
    for name in [
        "data_structs_main_xml_def",
        "array_of_data_structs_main",
        "overarching_tutorial_main_locations",
    ] {
        let m = load_case(name);
        for events in [EventSemantics::Queues, EventSemantics::As2fm] {
            let cfg = RunConfig {
                events,
                ..config(&m)
            };
            let mut sim = Simulator::new(&m.model);
            for seed in 0..3 {
                sim.run(&mut Xoshiro256PlusPlus::seed_from_u64(seed), &cfg, &mut ());
            }
            for seed in 0..3 {
                let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
                let before = common::alloc::count();
                let out = sim.run(&mut rng, &cfg, &mut ());
                let n = common::alloc::count() - before;
                assert!(out.steps > 0);
                assert_eq!(
                    n, 0,
                    "{name} {events:?} run {seed}: {n} allocations in {} steps",
                    out.steps
                );
            }
        }
    }
}

/// What `hindsight convert` would write (the lowered machines and the declared types as
/// `types.xml`) reads back as a plain model folder that runs exactly like the robot model.
#[test]
fn converted_struct_models_read_back_and_run_the_same() {
    if common::corpus_or_skip().is_none() {
        return;
    }
    use hindsight::verify::robot::write::{to_xml, types_xml};
    for name in ["data_structs_main_json_def", "array_of_data_structs_main"] {
        let m = load_case(name);
        let dir = std::env::temp_dir().join(format!(
            "hindsight-robot-structs-{}-convert-{name}",
            std::process::id()
        ));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join("types.xml"), types_xml(&m.types)).unwrap();
        for el in &m.machines {
            let file = format!("{}.scxml", el.attr_value("name").unwrap());
            std::fs::write(dir.join(file), to_xml(el)).unwrap();
        }
        let back = CompiledModel::load(&dir).unwrap_or_else(|e| panic!("{name}: {e}"));
        let cfg = config(&m);
        for seed in 0..2 {
            assert_eq!(run(&m.model, &cfg, seed), run(&back, &cfg, seed), "{name}");
        }
        let _ = std::fs::remove_dir_all(&dir);
    }
}

/// SCAN property ports read fields of struct parameters, written `point.x` or as AS2FM
/// flattens them (`point__y`); a field the struct does not have is an error.
#[test]
fn property_ports_read_struct_fields() {
    if common::corpus_or_skip().is_none() {
        return;
    }
    use hindsight::verify::observe::PropertySet;
    use hindsight::verify::props::parse_str;
    use hindsight::verify::smc::runner::stream;
    use hindsight::verify::study::Runner;
    let m = load_case("data_structs_main_xml_def");
    let props = |px: &str| {
        format!(
            r#"<properties><ports>
  <scxml_event_send event="data" origin="sender" target="receiver">
    <state_var id="px" param="{px}" type="float64" expr="0"/>
    <state_var id="py" param="point__y" type="float64" expr="0"/>
    <state_var id="frame" param="point.frame" type="string" expr="''"/>
  </scxml_event_send>
</ports><guarantees>
  <property id="reaches_100" logic="pmtl" expr="once {{px &gt;= 100 &amp;&amp; py &gt; 3.1 &amp;&amp; frame == 'world'}}"/>
  <property id="stays_below_50" logic="pmtl" expr="historically {{px &lt; 50}}"/>
</guarantees></properties>"#
        )
    };
    let file = parse_str(&props("point.x"), Path::new("structs.xml")).unwrap();
    let set = PropertySet::new(&file, &m.model).unwrap();
    let cfg = config(&m);
    let runner = Runner::new(&m.model, &set, &cfg);
    for k in 0..3 {
        let v = runner.run(k, &mut stream(7, k)).verdicts;
        assert_eq!(format!("{v:?}"), "[True, False]", "run {k}");
    }
    let file = parse_str(&props("point.z"), Path::new("structs.xml")).unwrap();
    let err = PropertySet::new(&file, &m.model).unwrap_err().to_string();
    assert!(
        err.contains("structs.xml:3:") && err.contains("no parameter `point.z`"),
        "{err}"
    );
}

/// `hindsight convert` on a model with data declarations writes them as `types.xml`, named
/// by `model.xml`; the converted model runs like the robot model.
#[test]
fn convert_cli_writes_the_declared_types() {
    if common::corpus_or_skip().is_none() {
        return;
    }
    let (main, _) = case("data_structs_main_json_def");
    let out = std::env::temp_dir().join(format!(
        "hindsight-robot-structs-{}-convert-cli",
        std::process::id()
    ));
    let _ = std::fs::remove_dir_all(&out);
    let status = std::process::Command::new(env!("CARGO_BIN_EXE_hindsight"))
        .arg("convert")
        .arg(&main)
        .arg("--out")
        .arg(&out)
        .output()
        .expect("run hindsight");
    assert!(
        status.status.success(),
        "{}",
        String::from_utf8_lossy(&status.stderr)
    );
    let spec = std::fs::read_to_string(out.join("model.xml")).unwrap();
    assert!(spec.contains("<types path=\"./types.xml\"/>"), "{spec}");
    let back = CompiledModel::load(&out.join("model.xml")).unwrap_or_else(|e| panic!("{e}"));
    let m = load(&main).unwrap();
    let cfg = config(&m);
    assert_eq!(run(&m.model, &cfg, 0), run(&back, &cfg, 0));
    let _ = std::fs::remove_dir_all(&out);
}

/// Mutated struct models (literals, paths, declarations) load or fail with a diagnostic,
/// and those that load run, without a panic.
#[test]
fn mutated_struct_models_never_panic() {
    use rand_core::Rng;
    let seeds = [
        r#"<data id="l" type="Line" expr="{a: {x: 1, y: 2}, 'b': {'y': -1, 'x': 0.5}}" />
<data id="ls" type="Line[]" expr="[{a: {x: 0, y: 0}, b: {x: 1, y: 1}},]" />"#,
        r#"<onentry><assign location="ls[1].b" expr="l.a" /><assign location="ls.a" expr="ls.b" /><send event="e"><param name="n" expr="ls.length + ls[0].a.y" /><param name="v" expr="ls[0]" /></send></onentry>"#,
    ];
    let alphabet = b"{}[]().,:'\"ablsxyLinePot0123456789-_ ";
    assert_eq!(load_err("mutant-seed", TYPES, seeds[0], seeds[1]), None);
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(11);
    let (mut loaded, mut ran) = (0, 0);
    for k in 0..300 {
        let which = rng.next_u32() as usize % 2;
        let mut t: Vec<u8> = seeds[which].bytes().collect();
        for _ in 0..1 + rng.next_u32() % 3 {
            let at = rng.next_u32() as usize % (t.len() + 1);
            let c = alphabet[rng.next_u32() as usize % alphabet.len()];
            if rng.next_u32() % 2 == 0 && at < t.len() {
                t.remove(at);
            } else {
                t.insert(at, c);
            }
        }
        let text = String::from_utf8_lossy(&t).into_owned();
        let (dm, body) = if which == 0 {
            (text, seeds[1].to_string())
        } else {
            (seeds[0].to_string(), text)
        };
        let main = write_case(
            &format!("mutant{k}"),
            &[
                ("main.xml", MAIN),
                ("types.xml", TYPES),
                ("node.ascxml", &node(&dm, &body)),
            ],
        );
        if let Ok(m) = load(&main) {
            loaded += 1;
            let cfg = RunConfig {
                max_steps: 1_000,
                ..config(&m)
            };
            Simulator::new(&m.model).run(&mut Xoshiro256PlusPlus::seed_from_u64(1), &cfg, &mut ());
            ran += 1;
        }
        let _ = std::fs::remove_dir_all(main.parent().unwrap());
    }
    assert!(loaded > 0 && ran == loaded, "{loaded} loaded");
}
