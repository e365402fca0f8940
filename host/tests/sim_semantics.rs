//! The simulator's semantics on small models with known behaviour (host/tests/data/sim).

use hindsight::verify::expr::{OwnedValue, Value};
use hindsight::verify::sim::{
    CompiledModel, EndReason, Flow, MachineId, Observer, Quiescence, RunConfig, RunOutcome,
    SentMessage, Simulator, SpinKind, TraceRecorder, TransitionChoice,
};
use rand_core::SeedableRng;
use rand_xoshiro::Xoshiro256PlusPlus;
use std::path::Path;

fn model(name: &str) -> CompiledModel {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/sim")
        .join(name);
    CompiledModel::load(&dir).unwrap_or_else(|e| panic!("{name}: {e}"))
}

fn rng(seed: u64) -> Xoshiro256PlusPlus {
    Xoshiro256PlusPlus::seed_from_u64(seed)
}

/// Runs once and returns the outcome and the recorded sends.
fn run(m: &CompiledModel, seed: u64, cfg: &RunConfig) -> (RunOutcome, TraceRecorder) {
    let mut sim = Simulator::new(m);
    let mut rec = TraceRecorder::new();
    let out = sim.run(&mut rng(seed), cfg, &mut rec);
    (out, rec)
}

/// `(time, event, origin, target)` of every send.
fn sends(m: &CompiledModel, rec: &TraceRecorder) -> Vec<(u64, String, String, String)> {
    rec.rows
        .iter()
        .map(|r| {
            (
                r.time,
                m.event_name(r.event).to_string(),
                m.machine_name(r.origin).to_string(),
                r.target
                    .map_or("NONE".to_string(), |t| m.machine_name(t).to_string()),
            )
        })
        .collect()
}

fn int_param(m: &CompiledModel, rec: &TraceRecorder, event: &str, param: &str) -> Vec<i64> {
    let e = m.event_id(event).unwrap();
    let i = m.param_index(e, param).unwrap();
    rec.rows
        .iter()
        .filter(|r| r.event == e)
        .map(|r| match r.params[i] {
            OwnedValue::Int(v) => v,
            ref v => panic!("{v:?}"),
        })
        .collect()
}

#[test]
fn ping_pong_counts_to_ten() {
    let m = model("ping_pong");
    let (out, rec) = run(&m, 1, &RunConfig::default());
    assert_eq!(out.end, EndReason::Quiescent);
    assert_eq!(out.time, 0, "no delay: everything happens at time 0");
    assert_eq!(
        int_param(&m, &rec, "ping", "n"),
        (0..10).collect::<Vec<_>>()
    );
    assert_eq!(
        int_param(&m, &rec, "pong", "n"),
        (1..=10).collect::<Vec<_>>()
    );
    assert_eq!(int_param(&m, &rec, "finished", "n"), vec![10]);
    // 21 sends and 20 receives (the sink message is not received).
    assert_eq!(rec.rows.len(), 21);
    assert_eq!(out.steps, 41);
    let ping = m.machine_id("Ping").unwrap();
    let sim_state = {
        let mut sim = Simulator::new(&m);
        sim.run(&mut rng(1), &RunConfig::default(), &mut ());
        m.state_name(ping, sim.state_of(ping)).to_string()
    };
    assert_eq!(sim_state, "done");
}

#[test]
fn delayed_sends_block_the_sender_for_the_delay() {
    let m = model("delay");
    let mut times = Vec::new();
    struct Times<'a>(&'a mut Vec<u64>);
    impl Observer for Times<'_> {
        fn on_time(&mut self, t: u64) -> Flow {
            self.0.push(t);
            Flow::Continue
        }
    }
    let mut rec = TraceRecorder::new();
    let mut sim = Simulator::new(&m);
    let out = sim.run(
        &mut rng(3),
        &RunConfig::default(),
        &mut (&mut rec, Times(&mut times)),
    );
    let got: Vec<(u64, String)> = sends(&m, &rec)
        .into_iter()
        .map(|(t, e, _, _)| (t, e))
        .collect();
    // tick at 3, 6, 9, 12; then `late` after `count` = 4 more units.
    assert_eq!(
        got,
        vec![
            (3, "tick".into()),
            (6, "tick".into()),
            (9, "tick".into()),
            (12, "tick".into()),
            (16, "late".into())
        ]
    );
    assert_eq!(
        times,
        (1..=16).collect::<Vec<_>>(),
        "one point per time unit"
    );
    assert_eq!(out.end, EndReason::Quiescent);
    assert_eq!(out.time, 16);
}

#[test]
fn going_quiet_at_the_horizon_ends_at_the_horizon() {
    // The delay model's last send is at 16, after which nothing can ever happen: before
    // the horizon that is quiescence; at it, the run simply lasted its length (a robot
    // model's global timer stops at `max_time`, and its runs must not all read as
    // quiescent, which would hide a real deadlock).
    let m = model("delay");
    let at = |max_time| {
        let cfg = RunConfig {
            max_time,
            ..RunConfig::default()
        };
        let (out, rec) = run(&m, 3, &cfg);
        (out.end, out.time, rec.rows.len())
    };
    assert_eq!(at(17), (EndReason::Quiescent, 16, 5));
    assert_eq!(at(16), (EndReason::MaxTime, 16, 5));
    assert_eq!(at(15), (EndReason::MaxTime, 15, 4));
}

#[test]
fn send_without_target_reaches_every_receiver() {
    let m = model("broadcast");
    let (out, rec) = run(&m, 5, &RunConfig::default());
    assert_eq!(out.end, EndReason::Quiescent);
    let got = sends(&m, &rec);
    assert_eq!(
        got,
        vec![
            (0, "hello".into(), "Sender".into(), "A".into()),
            (0, "hello".into(), "Sender".into(), "B".into()),
        ]
    );
    let mut sim = Simulator::new(&m);
    sim.run(&mut rng(5), &RunConfig::default(), &mut ());
    for name in ["A", "B"] {
        let id = m.machine_id(name).unwrap();
        assert_eq!(sim.var(id, "got"), Some(Value::Int(7)));
    }
}

#[test]
fn targetexpr_names_machines_and_replies_to_origin() {
    let m = model("targetexpr");
    let (out, rec) = run(&m, 2, &RunConfig::default());
    assert_eq!(out.end, EndReason::Quiescent);
    let got = sends(&m, &rec);
    assert!(got.contains(&(0, "req".into(), "Router".into(), "Echo".into())));
    assert!(got.contains(&(0, "req".into(), "Router".into(), "NONE".into())));
    assert!(got.contains(&(0, "rep".into(), "Echo".into(), "Router".into())));
    let router = m.machine_id("Router").unwrap();
    let mut sim = Simulator::new(&m);
    sim.run(&mut rng(2), &RunConfig::default(), &mut ());
    let dest = sim.var(router, "dest").and_then(|v| v.as_str_id()).unwrap();
    assert_eq!(
        m.strings().get(dest),
        "Echo",
        "_event.origin is the sender's name"
    );
    assert_eq!(m.state_name(router, sim.state_of(router)), "end");
}

#[test]
fn arrays_grow_copy_and_travel_in_messages() {
    let m = model("arrays");
    let mut sim = Simulator::new(&m);
    let mut rec = TraceRecorder::new();
    let out = sim.run(&mut rng(9), &RunConfig::default(), &mut rec);
    assert_eq!(out.end, EndReason::Quiescent);
    let arr = m.machine_id("Arr").unwrap();
    let sum = m.machine_id("Sum").unwrap();
    let list = |v: Option<Value<'_>>| -> Vec<f64> {
        match v {
            Some(Value::List(l)) => l.iter().map(|x| x.as_f64().unwrap()).collect(),
            other => panic!("{other:?}"),
        }
    };
    // a = [0,1,4,9,16] was sent, then truncated to 2 elements.
    assert_eq!(list(sim.var(arr, "a")), vec![0.0, 1.0]);
    assert_eq!(list(sim.var(arr, "bounded")), vec![1.0, 4.0]);
    match sim.var(arr, "m") {
        Some(Value::List(rows)) => {
            assert_eq!(rows.len(), 2);
            let Some(Value::List(r1)) = rows.get(1) else {
                panic!()
            };
            // m[1][2] was written past the end: the gap holds the default 0.
            let r1: Vec<f64> = r1.iter().map(|x| x.as_f64().unwrap()).collect();
            assert_eq!(r1, vec![0.0, 0.0, 16.5]);
        }
        other => panic!("{other:?}"),
    }
    assert_eq!(list(sim.var(sum, "copy")), vec![0.0, 1.0, 4.0, 9.0, 16.0]);
    assert_eq!(sim.var(sum, "total"), Some(Value::Int(30)));
    assert_eq!(sim.var(sum, "last_row_len"), Some(Value::Int(3)));
    let ev = m.event_id("data").unwrap();
    let row = rec.rows.iter().find(|r| r.event == ev).unwrap();
    let values = m.param_index(ev, "values").unwrap();
    assert!(matches!(&row.params[values], OwnedValue::List(v) if v.len() == 5));
}

#[test]
fn structs_and_enumerations_from_types_xml() {
    let m = model("structs");
    let mut sim = Simulator::new(&m);
    let out = sim.run(&mut rng(4), &RunConfig::default(), &mut ());
    assert_eq!(out.end, EndReason::Quiescent);
    let v = m.machine_id("Viewer").unwrap();
    assert_eq!(sim.var(v, "blue"), Some(Value::Bool(true)));
    assert_eq!(sim.var(v, "y1"), Some(Value::Int(20)));
    assert_eq!(sim.var(v, "x0"), Some(Value::Float(1.5)));
    assert_eq!(m.types().labels.get("BLUE"), Some(&2));
}

#[test]
fn ternary_operator() {
    let m = model("ternary");
    let (out, rec) = run(&m, 0, &RunConfig::default());
    assert_eq!(out.end, EndReason::Quiescent);
    let e = m.event_id("out").unwrap();
    let p = |n: &str| rec.rows[0].params[m.param_index(e, n).unwrap()].clone();
    assert_eq!(p("f"), OwnedValue::Float(1.0));
    assert_eq!(p("nested"), OwnedValue::Int(3));
    assert_eq!(p("b"), OwnedValue::Bool(true));
    match p("label") {
        OwnedValue::Str(s) => assert_eq!(m.strings().get(s), "even"),
        v => panic!("{v:?}"),
    }
}

#[test]
fn math_random_coin_is_fair() {
    let m = model("coin");
    let heads = m.event_id("heads").unwrap();
    let mut sim = Simulator::new(&m);
    let n = 4000;
    let mut count = 0;
    for seed in 0..n {
        let mut rec = TraceRecorder::new();
        let out = sim.run(&mut rng(seed), &RunConfig::default(), &mut rec);
        assert_eq!(out.end, EndReason::Quiescent);
        assert_eq!(rec.rows.len(), 1);
        count += usize::from(rec.rows[0].event == heads);
    }
    // Binomial(4000, 1/2): sd = 31.6; 5 sd either side.
    let dev = (count as f64 - n as f64 / 2.0).abs();
    assert!(dev < 160.0, "{count} heads out of {n}");
}

#[test]
fn eventless_loop_is_reported_with_machine_and_state() {
    let m = model("spin_eventless");
    let (out, _) = run(&m, 0, &RunConfig::default());
    match out.end {
        EndReason::Spin(s) => {
            assert_eq!(s.kind, SpinKind::EventlessLoop);
            assert_eq!(s.machine_name, "Spinner");
            assert_eq!(s.state_name, "loop");
            assert!(s.location.file.ends_with("spinner.scxml"));
            assert_eq!(s.location.line, 6, "the state's tag: {s}");
            assert!(s.to_string().contains("machine `Spinner` in state `loop`"));
        }
        e => panic!("{e:?}"),
    }
}

#[test]
fn busy_loop_without_time_progress_is_reported() {
    let m = model("spin_no_time");
    let cfg = RunConfig {
        max_steps_per_instant: 10_000,
        ..RunConfig::default()
    };
    let (out, _) = run(&m, 0, &cfg);
    match out.end {
        EndReason::Spin(s) => {
            assert_eq!(s.kind, SpinKind::NoTimeProgress);
            assert!(["Left", "Right"].contains(&s.machine_name.as_str()));
            assert_eq!(s.state_name, "s");
        }
        e => panic!("{e:?}"),
    }
    assert_eq!(out.time, 0);
    assert_eq!(out.steps, 10_000);
}

#[test]
fn max_time_and_max_steps_cut_runs() {
    let m = model("ticker");
    let cfg = RunConfig {
        max_time: 50,
        ..RunConfig::default()
    };
    let (out, rec) = run(&m, 0, &cfg);
    assert_eq!(out.end, EndReason::MaxTime);
    assert_eq!(out.time, 50);
    assert_eq!(rec.rows.len(), 50, "one tick per unit, the last at time 50");
    assert_eq!(rec.rows.last().map(|r| r.time), Some(50));
    let cfg = RunConfig {
        max_steps: 7,
        ..RunConfig::default()
    };
    let (out, rec) = run(&m, 0, &cfg);
    assert_eq!(out.end, EndReason::MaxSteps);
    assert_eq!((out.steps, rec.rows.len(), out.time), (7, 7, 7));
}

#[test]
fn same_seed_same_trace_other_seeds_differ() {
    let m = model("race");
    let trace = |seed| {
        let (_, rec) = run(&m, seed, &RunConfig::default());
        sends(&m, &rec)
    };
    for seed in 0..20 {
        assert_eq!(trace(seed), trace(seed));
    }
    let winners: std::collections::BTreeSet<String> = (0..40)
        .map(|s| {
            trace(s)
                .into_iter()
                .find(|x| x.1.starts_with("winner"))
                .unwrap()
                .1
        })
        .collect();
    assert_eq!(
        winners.into_iter().collect::<Vec<_>>(),
        vec!["winner_p".to_string(), "winner_q".to_string()],
        "both interleavings occur"
    );
    // A reused simulator gives the same run as a fresh one.
    let mut sim = Simulator::new(&m);
    let mut a = TraceRecorder::new();
    let mut b = TraceRecorder::new();
    sim.run(
        &mut rng(11),
        &RunConfig::default(),
        &mut TraceRecorder::new(),
    );
    sim.run(&mut rng(7), &RunConfig::default(), &mut a);
    Simulator::new(&m).run(&mut rng(7), &RunConfig::default(), &mut b);
    assert_eq!(a.rows, b.rows);
}

#[test]
fn transition_choice_document_order_or_random() {
    let m = model("choice");
    let first = m.event_id("first").unwrap();
    let mut sim = Simulator::new(&m);
    let mut picks = [0usize; 2];
    for (i, choice) in [TransitionChoice::DocumentOrder, TransitionChoice::Random]
        .into_iter()
        .enumerate()
    {
        let cfg = RunConfig {
            transitions: choice,
            ..RunConfig::default()
        };
        for seed in 0..200 {
            let mut rec = TraceRecorder::new();
            sim.run(&mut rng(seed), &cfg, &mut rec);
            picks[i] += usize::from(rec.rows[0].event == first);
        }
    }
    assert_eq!(picks[0], 200);
    assert!((60..140).contains(&picks[1]), "{picks:?}");
}

#[test]
fn raised_events_come_before_queued_external_ones() {
    let m = model("internal");
    let mut logs = Vec::new();
    struct Logs<'a>(&'a mut Vec<(String, Option<i64>)>);
    impl Observer for Logs<'_> {
        fn on_log(&mut self, _t: u64, _m: MachineId, label: &str, v: Option<Value<'_>>) {
            self.0.push((label.to_string(), v.and_then(|v| v.as_i64())));
        }
    }
    let mut rec = TraceRecorder::new();
    Simulator::new(&m).run(
        &mut rng(0),
        &RunConfig::default(),
        &mut (&mut rec, Logs(&mut logs)),
    );
    assert_eq!(logs, vec![("entered a".to_string(), Some(0))]);
    // inner (x10+1), then ext: onexit of b (x10+3) before the transition content (x10+2).
    assert_eq!(int_param(&m, &rec, "done", "order"), vec![132]);
}

#[test]
fn run_time_errors_point_at_the_expression() {
    let m = model("run_error");
    let (out, rec) = run(&m, 0, &RunConfig::default());
    assert_eq!(rec.rows.len(), 3);
    match out.end {
        EndReason::Error(e) => {
            let d = &e.diagnostic;
            assert!(Path::new(&d.file).ends_with("oob.scxml"));
            assert_eq!((d.line, d.col), (10, 61), "the index `i`: {d}");
            assert!(
                d.message.contains("index 3 out of bounds (length 3)"),
                "{d}"
            );
        }
        e => panic!("{e:?}"),
    }
}

#[test]
fn observers_see_receives_and_can_stop_a_run() {
    let m = model("ping_pong");
    struct Count {
        sends: usize,
        receives: usize,
        stop_after: usize,
    }
    impl Observer for Count {
        fn on_send(&mut self, _t: u64, msg: &SentMessage<'_>) -> Flow {
            self.sends += 1;
            assert_eq!(msg.param_count(), 1);
            assert!(matches!(msg.param(0), Some(Value::Int(_))));
            if self.sends == self.stop_after {
                Flow::Stop
            } else {
                Flow::Continue
            }
        }
        fn on_receive(&mut self, _t: u64, msg: &SentMessage<'_>) -> Flow {
            self.receives += 1;
            assert_ne!(msg.target_name(), "NONE");
            Flow::Continue
        }
    }
    let mut c = Count {
        sends: 0,
        receives: 0,
        stop_after: 5,
    };
    let out = Simulator::new(&m).run(&mut rng(0), &RunConfig::default(), &mut c);
    assert_eq!(out.end, EndReason::Stopped);
    assert_eq!((c.sends, c.receives), (5, 4));
}

#[test]
fn quiescence_can_keep_time_running_like_scan() {
    let m = model("ping_pong");
    let mut ticks = 0u64;
    struct Ticks<'a>(&'a mut u64);
    impl Observer for Ticks<'_> {
        fn on_time(&mut self, _t: u64) -> Flow {
            *self.0 += 1;
            Flow::Continue
        }
    }
    let cfg = RunConfig {
        max_time: 25,
        quiescence: Quiescence::AdvanceTime,
        ..RunConfig::default()
    };
    let out = Simulator::new(&m).run(&mut rng(0), &cfg, &mut Ticks(&mut ticks));
    assert_eq!(out.end, EndReason::MaxTime);
    assert_eq!((out.time, ticks), (25, 25));
}

#[test]
fn trace_rows_name_event_origin_target_and_params() {
    let m = model("ping_pong");
    let (_, rec) = run(&m, 1, &RunConfig::default());
    let row = |r: &hindsight::verify::sim::TraceRow| {
        let target = r.target.map_or("NONE", |t| m.machine_name(t));
        let params: Vec<String> = r.params.iter().map(|v| format!("{v:?}")).collect();
        (
            r.time,
            m.event_name(r.event).to_string(),
            m.machine_name(r.origin).to_string(),
            target.to_string(),
            params.join(";"),
        )
    };
    let rows: Vec<_> = rec.rows.iter().map(row).collect();
    let want = |e: &str, o: &str, t: &str, n: i64| {
        (
            0,
            e.to_string(),
            o.to_string(),
            t.to_string(),
            format!("Int({n})"),
        )
    };
    assert_eq!(rows[0], want("ping", "Ping", "Pong", 0));
    assert_eq!(rows[1], want("pong", "Pong", "Ping", 1));
    assert_eq!(rows.last(), Some(&want("finished", "Ping", "NONE", 10)));
}

#[test]
fn scan_main_file_lists_processes_types_and_properties() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/sim/spec");
    let m = CompiledModel::load(&dir.join("model.xml")).unwrap();
    assert_eq!(m.machine_count(), 2);
    assert_eq!(m.types().labels.get("GREEN"), Some(&1));
    assert!(m.properties_path().unwrap().ends_with("properties.xml"));
    let (out, rec) = run(&m, 0, &RunConfig::default());
    assert_eq!(out.end, EndReason::Quiescent);
    assert_eq!(rec.rows.len(), 21);
    let err = hindsight::verify::model::load(&dir.join("bad_model.xml")).unwrap_err();
    let msgs: Vec<String> = err
        .iter()
        .map(|d| format!("{}:{}: {}", d.line, d.col, d.message))
        .collect();
    assert_eq!(msgs.len(), 2, "{msgs:?}");
    assert!(
        msgs[0].starts_with("5:43: process `Wrong` names a machine called `Pong`"),
        "{msgs:?}"
    );
    assert!(msgs[1].starts_with("6:45: no such file"), "{msgs:?}");
}

#[test]
fn compiled_models_are_shared_between_threads() {
    fn send_sync<T: Send + Sync>() {}
    fn send<T: Send>() {}
    send_sync::<CompiledModel>();
    send::<Simulator<'static>>();
    let m = model("race");
    let traces: Vec<Vec<(u64, String, String, String)>> = std::thread::scope(|s| {
        let hs: Vec<_> = (0..2)
            .map(|_| {
                s.spawn(|| {
                    let (_, rec) = run(&m, 3, &RunConfig::default());
                    sends(&m, &rec)
                })
            })
            .collect();
        hs.into_iter().map(|h| h.join().unwrap()).collect()
    });
    assert_eq!(traces[0], traces[1]);
    assert!(m
        .dump_machine(m.machine_id("Judge").unwrap())
        .contains("send winner_p to NONE"));
}

/// XML attribute-value normalisation (XML 1.0 sections 2.11 and 3.3.3; AS2FM reads models
/// with lxml, which applies it): a tab or line break written inside an attribute is a
/// space by the time the expression is read (`\r\n` is one), while `&#10;` stays a line
/// break. A string literal written over two lines is therefore `'x y'`.
#[test]
fn attribute_line_breaks_are_spaces_in_expressions() {
    let text = "<scxml name=\"a\" initial=\"s0\" version=\"1.0\" \
        xmlns=\"http://www.w3.org/2005/07/scxml\"><datamodel>\
        <data id=\"s\" expr=\"'x\r\ny'\"/><data id=\"t\" expr=\"'p&#10;q'\"/>\
        <data id=\"crlf_is_space\" expr=\"false\"/><data id=\"ref_is_newline\" expr=\"false\"/>\
        </datamodel><state id=\"s0\"><onentry>\
        <assign location=\"crlf_is_space\" expr=\"s ==\n'x y'\"/>\
        <assign location=\"ref_is_newline\" expr=\"t != 'p q'\"/>\
        </onentry></state></scxml>";
    let src = hindsight::verify::model::ModelSource::from_texts([("a.scxml", text)]).unwrap();
    let m = CompiledModel::compile(src).unwrap();
    let mut sim = Simulator::new(&m);
    sim.run(
        &mut rng(0),
        &RunConfig::default(),
        &mut TraceRecorder::new(),
    );
    let a = m.machine_id("a").unwrap();
    for var in ["crlf_is_space", "ref_is_newline"] {
        assert_eq!(sim.var(a, var), Some(Value::Bool(true)), "{var}");
    }
}

#[test]
fn a_transition_without_target_exits_and_enters_no_state() {
    // SCXML 1.0, section 3.13: a targetless transition's exit set is empty, so neither the
    // state's <onexit> nor its <onentry> runs; its own content does. (SCAN and AS2FM
    // require a target, so the W3C rule is the only one.) The same transition with a
    // target runs both. Found with the W3C test suite's test503.
    let text = |target: &str| {
        format!(
            "<scxml xmlns=\"http://www.w3.org/2005/07/scxml\" version=\"1.0\" name=\"M\" \
             initial=\"s0\" datamodel=\"ecmascript\"><datamodel>\
             <data id=\"exits\" expr=\"0\"/><data id=\"entries\" expr=\"0\"/>\
             <data id=\"body\" expr=\"0\"/></datamodel>\
             <state id=\"s0\"><onentry><assign location=\"entries\" expr=\"entries + 1\"/>\
             <if cond=\"entries == 1\"><raise event=\"foo\"/></if></onentry>\
             <onexit><assign location=\"exits\" expr=\"exits + 1\"/></onexit>\
             <transition event=\"foo\" {target}><assign location=\"body\" expr=\"body + 1\"/>\
             </transition></state></scxml>"
        )
    };
    for (target, want) in [("", (0, 1, 1)), ("target=\"s0\"", (1, 2, 1))] {
        let t = text(target);
        let src =
            hindsight::verify::model::ModelSource::from_texts([("m.scxml", t.as_str())]).unwrap();
        let m = CompiledModel::compile(src).unwrap();
        let mut sim = Simulator::new(&m);
        let out = sim.run(
            &mut rng(0),
            &RunConfig::default(),
            &mut TraceRecorder::new(),
        );
        assert_eq!(out.end, EndReason::Quiescent, "{target}");
        let id = m.machine_id("M").unwrap();
        let got = ["exits", "entries", "body"].map(|v| match sim.var(id, v) {
            Some(Value::Int(n)) => n,
            other => panic!("{v}: {other:?}"),
        });
        assert_eq!((got[0], got[1], got[2]), want, "{target}");
    }
}
