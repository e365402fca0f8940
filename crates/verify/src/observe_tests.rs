//! Tests of the judge: skipped points against a monitor stepped at every point.

use super::{same_value, Judge, PropertySet};
use monitor_core::{analysis, valuation, Monitor, Value};

/// The fact [`super::Judge`] relies on to skip repeated points: without `Y` / `Z`, a
/// step at the same time with the same values leaves the state bit for bit unchanged.
#[test]
fn repeated_point_leaves_the_state_unchanged() {
    let formulas = [
        "H({p} -> P {q})",
        "{p} S {q}",
        "{p} S[3:] {q}",
        "{p} S[:4] {q}",
        "{p} S[2:5] {q}",
        "!{p} S[1:1] ({q} && {n > 2})",
        "H(P[10:] true -> P[:10] {q})",
        "H(({p} -> P {n <= 3}) && !((!{p}) S[6:] {n <= 3}))",
        "P[0:3] ({p} || H[0:2] !{q})",
    ];
    let mut x = 0x9e37_79b9_7f4a_7c15u64;
    let mut next = move || {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        x
    };
    let mut repeats = 0;
    for f in formulas {
        let src = format!("event p;\nevent q;\nstate n: i64 = 0;\nproperty f = {f};\n");
        let c = codegen::compile_spec(&src, "t.hspec").unwrap();
        let m = Monitor::try_new(c.program()).unwrap();
        assert!(analysis::repeat_is_noop(m.program()));
        for _ in 0..40 {
            let mut st = vec![0; m.state_words()];
            let mut vals = vec![Value::Bool(false); c.program().vars.len()];
            valuation::init(c.program().vars, &mut vals);
            let mut out = [false];
            let mut t = 0;
            for _ in 0..80 {
                t += next() % 3;
                valuation::begin_point(c.program().vars, &mut vals);
                let r = next();
                vals[0] = Value::Bool(r % 4 == 0);
                vals[1] = Value::Bool(r % 5 == 0);
                if r % 7 == 0 {
                    vals[2] = Value::Int((r % 6) as i64);
                }
                m.try_step(&mut st, t, &vals, &mut out).unwrap();
                let (before, verdict) = (st.clone(), out[0]);
                // The same point again, once or twice.
                for _ in 0..1 + next() % 2 {
                    m.try_step(&mut st, t, &vals, &mut out).unwrap();
                    assert_eq!(st, before, "{f} at {t}");
                    assert_eq!(out[0], verdict, "{f} at {t}");
                    repeats += 1;
                }
            }
        }
    }
    assert!(repeats > 1000);
}

/// The judge steps each property only where it is due. Oracle: one monitor of the whole
/// program stepped at every point, its variables kept by [`valuation::begin_point`];
/// after every point the judge's values, verdicts, every node's value and finality,
/// and whether the run is decided must equal the oracle's. Random points at repeated
/// and advancing times (sometimes by several units, so that windows expire while a
/// property is skipped) write random values (often the value already held, often
/// none) to variables each read by some properties only. Returns the points where the
/// whole point repeated the last one and the others.
fn against_whole_program(guarantees: &str, seed: u64, runs: usize) -> (usize, usize) {
    use crate::sim::{CompiledModel, Flow};
    let machine = "<scxml name=\"a\" initial=\"s0\" version=\"1.0\" \
        xmlns=\"http://www.w3.org/2005/07/scxml\"><datamodel>\
        <data id=\"x\" type=\"int32\" expr=\"0\"/></datamodel>\
        <state id=\"s0\"><onentry><send event=\"e\" target=\"b\">\
        <param name=\"v\" expr=\"x\"/></send></onentry></state></scxml>";
    let sink = "<scxml name=\"b\" initial=\"s0\" version=\"1.0\" \
        xmlns=\"http://www.w3.org/2005/07/scxml\"><state id=\"s0\"/></scxml>";
    let model = CompiledModel::compile(
        crate::model::ModelSource::from_texts([("a.scxml", machine), ("b.scxml", sink)]).unwrap(),
    )
    .unwrap();
    let props = format!(
        "<properties><ports>\
        <scxml_event_send event=\"e\" origin=\"a\" target=\"b\">\
        <event_var id=\"p\"/><event_var id=\"q\"/><event_var id=\"r\"/>\
        <state_var id=\"n\" param=\"v\" type=\"int32\" expr=\"0\"/>\
        <state_var id=\"m\" param=\"v\" type=\"int32\" expr=\"1\"/>\
        </scxml_event_send></ports><guarantees>{guarantees}</guarantees></properties>"
    );
    let file = crate::props::parse_str(&props, std::path::Path::new("p.xml")).unwrap();
    let set = PropertySet::new(&file, &model).unwrap();
    let mut judge = Judge::new(&set).unwrap();
    let program = set.compiled().program();
    let oracle = Monitor::try_new(program).unwrap();
    let var = |name: &str| set.compiled().var_index(name).unwrap();
    let (p, q, r, n, m) = (var("p"), var("q"), var("r"), var("n"), var("m"));
    let mut x = seed;
    let mut next = move || {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        x
    };
    let (mut repeats, mut steps) = (0, 0);
    for _ in 0..runs {
        let mut st = vec![0; oracle.state_words()];
        let mut vals = vec![Value::Bool(false); program.vars.len()];
        valuation::init(program.vars, &mut vals);
        let mut out = vec![false; oracle.properties()];
        let mut finals = vec![None; program.nodes.len()];
        let mut flow = judge.start();
        let mut t = 0;
        let mut last: Option<(u64, Vec<Value>)> = None;
        for point in 0..150 {
            if point > 0 {
                let r0 = next();
                t += [0, 0, 0, 0, 1, 1, 2, 7][(r0 % 8) as usize];
                judge.begin();
                valuation::begin_point(program.vars, &mut vals);
                let mut writes = Vec::new();
                for (k, v) in [p, q, r].into_iter().enumerate() {
                    if r0 >> (8 + 3 * k) & 7 == 0 {
                        writes.push((v, Value::Bool(true)));
                    }
                }
                if r0 >> 20 & 3 == 0 {
                    writes.push((n, Value::Int((r0 >> 22) as i64 % 4)));
                }
                if r0 >> 30 & 3 == 0 {
                    writes.push((m, Value::Int((r0 >> 32) as i64 % 3)));
                }
                for (v, value) in writes {
                    judge.write(v, value);
                    vals[v] = value;
                }
                flow = judge.step(t);
            }
            oracle.try_step(&mut st, t, &vals, &mut out).unwrap();
            analysis::settle(
                &program,
                |k| oracle.node_value(&st, k).unwrap(),
                &mut finals,
            );
            let decided = (0..out.len()).all(|k| analysis::settled(&program, &finals, k).is_some());
            assert_eq!(judge.values(), &vals[..]);
            assert_eq!(judge.verdicts(), &out[..], "at time {t}");
            for k in 0..program.nodes.len() as u16 {
                let node = (judge.node_value(k), judge.finals[k as usize]);
                let want = (oracle.node_value(&st, k), finals[k as usize]);
                assert_eq!(node, want, "node {k} at time {t}, point {point}");
            }
            assert_eq!(flow == Flow::Stop, decided, "at time {t}");
            match &last {
                Some((lt, lv)) if *lt == t && *lv == vals => repeats += 1,
                _ => steps += 1,
            }
            last = Some((t, vals.clone()));
            if decided {
                break;
            }
        }
    }
    (repeats, steps)
}

/// Random formulas over the variables, one property each: every kind of node, timed
/// and untimed, `Y` / `Z`, and properties reading disjoint variables.
#[test]
fn skipped_properties_keep_the_verdicts_of_a_whole_program_step() {
    let formulas = [
        "historically({p} -&gt; once {n &gt; 2})",
        "{q} since[1:3] {n == 1}",
        "once[0:2] ({p} &amp;&amp; !{q})",
        "!{p} since[2:] {n &lt; 2}",
        "historically({m == 0} -&gt; once[:5] {r})",
        "{r} since {m == 2}",
        "Y {q} || Z({m == 1})",
        "historically(!{r} || Y once[3:6] {p})",
        "({n == 3} &lt;-&gt; {m &gt;= 1}) || once[4:4] {q}",
        "historically((once[5:] true) -&gt; once[:5] {r})",
        "!({n &gt; 0} since[0:] {p})",
        "historically({m &lt;= 1})",
    ];
    let mut x = 0x2545_f491_4f6c_dd1du64;
    let (mut repeats, mut steps) = (0, 0);
    for _ in 0..40 {
        // Two to five of the formulas, picked at random.
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        let count = 2 + (x % 4) as usize;
        let guarantees: String = (0..count)
            .map(|k| {
                let f = formulas[(x >> (8 + 4 * k)) as usize % formulas.len()];
                format!("<property id=\"g{k}\" logic=\"pmtl\" expr=\"{f}\"/>")
            })
            .collect();
        let (a, b) = against_whole_program(&guarantees, x | 1, 8);
        repeats += a;
        steps += b;
    }
    // Both kinds of point came many times.
    assert!(repeats > 1000 && steps > 1000, "{repeats} {steps}");
}

/// Every formula alone and all at once, so that each is judged as a whole program too.
#[test]
fn each_formula_alone_and_all_together() {
    let formulas = [
        "historically({p} -&gt; once {n &gt; 2})",
        "{q} since[1:3] {n == 1}",
        "Y {q} || Z({m == 1})",
        "historically((once[5:] true) -&gt; once[:5] {r})",
    ];
    let mut all = String::new();
    for (k, f) in formulas.iter().enumerate() {
        let one = format!("<property id=\"g{k}\" logic=\"pmtl\" expr=\"{f}\"/>");
        against_whole_program(&one, 0x9e37_79b9_7f4a_7c15 + k as u64, 10);
        all.push_str(&one);
    }
    let (repeats, steps) = against_whole_program(&all, 0x1234_5678_9abc_def1, 30);
    assert!(repeats > 200 && steps > 200, "{repeats} {steps}");
}

#[test]
fn floats_compare_bit_for_bit() {
    assert!(same_value(Value::Float(0.0), Value::Float(0.0)));
    assert!(!same_value(Value::Float(0.0), Value::Float(-0.0)));
    assert!(same_value(Value::Float(f64::NAN), Value::Float(f64::NAN)));
    assert!(!same_value(Value::Int(1), Value::Float(1.0)));
    assert!(!same_value(Value::Bool(false), Value::Int(0)));
}

#[test]
fn a_port_on_an_event_the_model_lacks_names_it_as_written_with_the_closest() {
    use crate::sim::CompiledModel;
    let machine = "<scxml name=\"a\" initial=\"s0\" version=\"1.0\" \
        xmlns=\"http://www.w3.org/2005/07/scxml\"><state id=\"s0\"><onentry>\
        <send event=\"topic_robot__result_msg\" target=\"a\"/><send event=\"done\" target=\"a\"/>\
        </onentry></state></scxml>";
    let model = CompiledModel::compile(
        crate::model::ModelSource::from_texts([("a.scxml", machine)]).unwrap(),
    )
    .unwrap();
    let errors = |event: &str| {
        let props = format!(
            "<properties><ports><scxml_event_send event=\"{event}\" origin=\"a\" target=\"a\">\
             <event_var id=\"p\"/></scxml_event_send></ports><guarantees>\
             <property id=\"g\" logic=\"pmtl\" expr=\"historically(true)\"/></guarantees></properties>"
        );
        let file = crate::props::parse_str(&props, std::path::Path::new("p.xml")).unwrap();
        match PropertySet::new(&file, &model) {
            Ok(_) => panic!("{event}: no error"),
            Err(d) => d.to_string(),
        }
    };
    // A ROS port's event is its topic: said so, with the topic the model does publish.
    let e = errors("topic_robot__reslt_msg");
    assert!(
        e.contains("port `p`: no node model publishes topic `/robot/reslt` (did you mean topic `/robot/result`?)"),
        "{e}"
    );
    let e = errors("dome");
    assert!(
        e.contains("the model sends no event `dome` (did you mean event `done`?)"),
        "{e}"
    );
    let e = errors("something_else_entirely");
    assert!(
        e.ends_with("the model sends no event `something_else_entirely`"),
        "{e}"
    );
}
