//! `EventSemantics::As2fm` on small models: targets ignored, all receivers at once,
//! senders blocked while their event is pending, discards, and deadlocks.

use hindsight::verify::model::ModelSource;
use hindsight::verify::sim::{
    CompiledModel, EndReason, EventSemantics, Flow, Observer, RunConfig, SentMessage, Simulator,
};
use rand_core::SeedableRng;
use rand_xoshiro::Xoshiro256PlusPlus;

fn model(files: &[(&str, &str)]) -> CompiledModel {
    CompiledModel::compile(ModelSource::from_texts(files.iter().copied()).unwrap()).unwrap()
}

fn scxml(name: &str, body: &str) -> String {
    format!(
        r#"<scxml name="{name}" initial="s0" version="1.0" xmlns="http://www.w3.org/2005/07/scxml">{body}</scxml>"#
    )
}

/// Every send and receive as `send e a->b` / `recv e a->b`.
#[derive(Default)]
struct Log(Vec<String>);

impl Observer for Log {
    fn on_send(&mut self, _: u64, m: &SentMessage<'_>) -> Flow {
        self.0.push(format!(
            "send {} {}->{}",
            m.event_name(),
            m.origin_name(),
            m.target_name()
        ));
        Flow::Continue
    }
    fn on_receive(&mut self, _: u64, m: &SentMessage<'_>) -> Flow {
        self.0.push(format!(
            "recv {} {}->{}",
            m.event_name(),
            m.origin_name(),
            m.target_name()
        ));
        Flow::Continue
    }
}

fn run(m: &CompiledModel, events: EventSemantics, seed: u64) -> (EndReason, Vec<String>) {
    let cfg = RunConfig {
        events,
        ..RunConfig::default()
    };
    let mut log = Log::default();
    let out = Simulator::new(m).run(&mut Xoshiro256PlusPlus::seed_from_u64(seed), &cfg, &mut log);
    (out.end, log.0)
}

#[test]
fn a_send_reaches_every_machine_with_a_transition_on_it_at_once() {
    let a = scxml(
        "a",
        r#"<state id="s0"><onentry><send event="e" target="b"><param name="x" expr="1"/></send></onentry></state>"#,
    );
    let b = scxml(
        "b",
        r#"<datamodel><data id="got" expr="0"/></datamodel>
           <state id="s0"><transition event="e" target="s1"><assign location="got" expr="_event.data.x"/></transition></state>
           <state id="s1"/>"#,
    );
    let c = scxml(
        "c",
        r#"<state id="s0"><transition event="e" target="s1"/></state><state id="s1"/>"#,
    );
    let m = model(&[("a.scxml", &a), ("b.scxml", &b), ("c.scxml", &c)]);
    let (end, log) = run(&m, EventSemantics::As2fm, 1);
    assert_eq!(end, EndReason::Quiescent);
    assert_eq!(log, ["send e a->b", "recv e a->b", "recv e a->c"]);
    let (_, queues) = run(&m, EventSemantics::Queues, 1);
    assert_eq!(queues, ["send e a->b", "recv e a->b"]);
}

#[test]
fn a_second_send_waits_until_the_first_is_taken() {
    // With queues, `a` could send both before `b` takes one; here it cannot.
    let a = scxml(
        "a",
        r#"<state id="s0"><onentry>
             <send event="e" target="b"/><send event="e" target="b"/><send event="done" target="NONE"/>
           </onentry></state>"#,
    );
    let b = scxml(
        "b",
        r#"<state id="s0"><transition event="e" target="s0"/></state>"#,
    );
    let m = model(&[("a.scxml", &a), ("b.scxml", &b)]);
    let mut queues_overtook = false;
    for seed in 0..20 {
        let (_, log) = run(&m, EventSemantics::As2fm, seed);
        assert_eq!(
            log[..3],
            ["send e a->b", "recv e a->b", "send e a->b"],
            "seed {seed}"
        );
        assert_eq!(log.len(), 5, "seed {seed}: {log:?}");
        let (_, log) = run(&m, EventSemantics::Queues, seed);
        queues_overtook |= log[1] == "send e a->b";
    }
    assert!(
        queues_overtook,
        "the queue semantics never sent twice in a row"
    );
}

#[test]
fn unhandled_events_are_discarded_unless_synchronised() {
    // `b` waits in `s0` with no transition on `topic` or `bt_1_tick` (it has them in `s1`).
    let b = scxml(
        "b",
        r#"<state id="s0"><transition event="never" target="s1"/></state>
           <state id="s1"><transition event="topic" target="s1"/><transition event="bt_1_tick" target="s1"/></state>"#,
    );
    let never = scxml(
        "n",
        r#"<state id="s0"><transition event="x" target="s0"><send event="never" target="b"/></transition></state>"#,
    );
    let topic = scxml(
        "a",
        r#"<state id="s0"><onentry><send event="topic" target="b"/><send event="topic" target="b"/></onentry></state>"#,
    );
    let m = model(&[("a.scxml", &topic), ("b.scxml", &b), ("n.scxml", &never)]);
    let (end, log) = run(&m, EventSemantics::As2fm, 0);
    assert_eq!(end, EndReason::Quiescent);
    assert_eq!(
        log,
        [
            "send topic a->b",
            "recv topic a->b",
            "send topic a->b",
            "recv topic a->b"
        ]
    );
    // A BT tick is synchronised: nobody may drop it, so it stays pending and the second
    // send never happens (JANI's deadlock ends the run).
    let tick = scxml(
        "a",
        r#"<state id="s0"><onentry><send event="bt_1_tick" target="b"/><send event="bt_1_tick" target="b"/></onentry></state>"#,
    );
    let m = model(&[("a.scxml", &tick), ("b.scxml", &b), ("n.scxml", &never)]);
    let (end, log) = run(&m, EventSemantics::As2fm, 0);
    assert_eq!(end, EndReason::Quiescent);
    assert_eq!(log, ["send bt_1_tick a->b"]);
}

#[test]
fn receivers_keep_the_data_they_took() {
    // `a` overwrites `e`'s parameters with its second send while `b` is still running its
    // transition: `b` must see the value it received.
    let a = scxml(
        "a",
        r#"<state id="s0"><onentry>
             <send event="e" target="b"><param name="x" expr="1"/></send>
             <send event="e" target="b"><param name="x" expr="2"/></send>
           </onentry></state>"#,
    );
    let b = scxml(
        "b",
        r#"<datamodel><data id="first" expr="0"/></datamodel>
           <state id="s0"><transition event="e" target="s1">
             <send event="ack" target="NONE"/>
             <assign location="first" expr="_event.data.x"/>
             <send event="seen" target="NONE"><param name="v" expr="first"/></send>
           </transition></state>
           <state id="s1"><transition event="e" target="s1"/></state>"#,
    );
    let m = model(&[("a.scxml", &a), ("b.scxml", &b)]);
    struct Seen(Vec<i64>);
    impl Observer for Seen {
        fn on_send(&mut self, _: u64, m: &SentMessage<'_>) -> Flow {
            if m.event_name() == "seen" {
                if let Some(hindsight::verify::expr::Value::Int(v)) = m.param(0) {
                    self.0.push(v);
                }
            }
            Flow::Continue
        }
    }
    let cfg = RunConfig {
        events: EventSemantics::As2fm,
        ..RunConfig::default()
    };
    let mut sim = Simulator::new(&m);
    for seed in 0..30 {
        let mut seen = Seen(Vec::new());
        sim.run(
            &mut Xoshiro256PlusPlus::seed_from_u64(seed),
            &cfg,
            &mut seen,
        );
        assert_eq!(seen.0, [1], "seed {seed}");
    }
}

#[test]
fn per_target_copies_of_one_broadcast_are_sent_once() {
    // AS2FM's plain export writes one broadcast as one send per receiver.
    let a = scxml(
        "a",
        r#"<state id="s0"><onentry>
             <send event="e" target="b"><param name="x" expr="1"/></send>
             <send event="e" target="c"><param name="x" expr="1"/></send>
           </onentry></state>"#,
    );
    let b = scxml(
        "b",
        r#"<state id="s0"><transition event="e" target="s0"/></state>"#,
    );
    let c = scxml(
        "c",
        r#"<state id="s0"><transition event="e" target="s0"/></state>"#,
    );
    let m = model(&[("a.scxml", &a), ("b.scxml", &b), ("c.scxml", &c)]);
    let (_, log) = run(&m, EventSemantics::As2fm, 0);
    assert_eq!(log, ["send e a->b", "recv e a->b", "recv e a->c"]);
}

#[test]
fn a_deadlock_before_the_horizon_is_quiescence_at_it_the_horizon() {
    // `a` waits 5 units, then sends a BT tick twice: `b` cannot take it (no transition on
    // it in `s0`, and nobody may drop a tick), so the run deadlocks at time 5.
    let b = scxml(
        "b",
        r#"<state id="s0"><transition event="never" target="s1"/></state>
           <state id="s1"><transition event="bt_1_tick" target="s1"/></state>"#,
    );
    let a = scxml(
        "a",
        r#"<state id="s0"><onentry><send event="go" target="a" delay="5"/></onentry>
             <transition event="go" target="s1"/></state>
           <state id="s1"><onentry><send event="bt_1_tick" target="b"/><send event="bt_1_tick" target="b"/></onentry></state>"#,
    );
    let never = scxml(
        "n",
        r#"<state id="s0"><transition event="x" target="s0"><send event="never" target="b"/></transition></state>"#,
    );
    let m = model(&[("a.scxml", &a), ("b.scxml", &b), ("n.scxml", &never)]);
    let end_at = |max_time| {
        let cfg = RunConfig {
            events: EventSemantics::As2fm,
            max_time,
            ..RunConfig::default()
        };
        let out = Simulator::new(&m).run(&mut Xoshiro256PlusPlus::seed_from_u64(0), &cfg, &mut ());
        (out.end, out.time)
    };
    assert_eq!(end_at(6), (EndReason::Quiescent, 5));
    assert_eq!(end_at(5), (EndReason::MaxTime, 5));
}
