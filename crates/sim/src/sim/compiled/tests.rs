//! Unit tests of model compilation: tables, parameter inference, collected errors.

use super::*;

fn compile_texts(files: &[(&str, &str)]) -> Result<CompiledModel, Diagnostics> {
    CompiledModel::compile(ModelSource::from_texts(files.iter().copied())?)
}

#[test]
fn tables_and_param_inference() {
    let m = compile_texts(&[
        (
            "a.scxml",
            r#"<scxml name="A" initial="s"><datamodel><data id="x" expr="1.5"/></datamodel>
            <state id="s"><onentry><send event="ev" target="B"><param name="v" expr="x"/><param name="n" expr="3"/></send></onentry></state></scxml>"#,
        ),
        (
            "b.scxml",
            r#"<scxml name="B" initial="w"><datamodel><!-- TYPE y:float64 --><data id="y"/></datamodel>
            <state id="w"><transition event="ev" target="w"><assign location="y" expr="_event.data.v + _event.data.n"/>
            <send event="fwd" target="NONE"><param name="k" expr="_event.data.n"/></send></transition></state></scxml>"#,
        ),
    ])
    .unwrap();
    assert_eq!(m.machine_count(), 2);
    let ev = m.event_id("ev").unwrap();
    assert_eq!(
        m.event_params(ev),
        &[("n".to_string(), Ty::Int), ("v".to_string(), Ty::Float)]
    );
    assert_eq!(m.param_index(ev, "v"), Some(1));
    let fwd = m.event_id("fwd").unwrap();
    assert_eq!(m.event_params(fwd), &[("k".to_string(), Ty::Int)]);
    assert_eq!(m.machine_id("B"), Some(MachineId(1)));
    assert_eq!(
        m.event_receivers(ev).collect::<Vec<_>>(),
        vec![MachineId(1)]
    );
}

#[test]
fn errors_are_collected_with_positions() {
    let err = compile_texts(&[(
        "bad.scxml",
        "<scxml name=\"A\" initial=\"s\">\n<datamodel><data id=\"x\" expr=\"0\"/></datamodel>\n<state id=\"s\">\n<transition event=\"e\" target=\"nowhere\"/>\n<transition target=\"s\" cond=\"x &amp;&amp; true\"/>\n<onentry><send event=\"e\" target=\"Ghost\"/><assign location=\"x\" expr=\"'str'\"/></onentry>\n</state></scxml>",
    )])
    .unwrap_err();
    let msgs: Vec<String> = err.iter().map(|d| d.to_string()).collect();
    assert!(
        msgs.iter()
            .any(|m| m.starts_with("bad.scxml:4:31:")
                && m.contains("unknown target state `nowhere`")),
        "{msgs:#?}"
    );
    assert!(
        msgs.iter()
            .any(|m| m.starts_with("bad.scxml:5:30:") && m.contains("cannot be applied to int")),
        "{msgs:#?}"
    );
    assert!(
        msgs.iter()
            .any(|m| m.starts_with("bad.scxml:6:34:")
                && m.contains("unknown target machine `Ghost`")),
        "{msgs:#?}"
    );
    assert!(
        msgs.iter()
            .any(|m| m.contains("string but int is expected")),
        "{msgs:#?}"
    );
}

/// The times at which `a.scxml` (one machine sending `e` to itself, then `f` after its
/// delay) sends, compiled with a time unit of `unit` ns; or the errors, as text.
fn delayed_sends(send: &str, unit: Option<u64>) -> Result<Vec<u64>, String> {
    use crate::sim::{RunConfig, Simulator, TraceRecorder};
    use rand_core::SeedableRng;
    let text = format!(
        r#"<scxml name="A" initial="s"><datamodel><data id="d" expr="300"/><data id="neg" expr="-2"/><data id="q" expr="0.25"/></datamodel>
        <state id="s"><onentry><send event="e" target="NONE"/>{send}</onentry></state></scxml>"#
    );
    let mut src =
        ModelSource::from_texts([("a.scxml", text.as_str())]).map_err(|d| d.to_string())?;
    src.time_unit_ns = unit;
    let model = CompiledModel::compile(src).map_err(|d| d.to_string())?;
    let mut trace = TraceRecorder::new();
    let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(1);
    let out = Simulator::new(&model).run(&mut rng, &RunConfig::default(), &mut trace);
    if let crate::sim::EndReason::Error(e) = out.end {
        return Err(e.diagnostic.to_string());
    }
    Ok(trace.rows.iter().map(|r| r.time).collect())
}

/// SCXML writes delays as CSS2 durations (`delay="1s"`, `delayexpr="d + 'ms'"`): with the
/// model's time unit they become whole units, without one they are an error, and a
/// delay between two units, or a negative one, is an error at the send, not rounded.
#[test]
fn durations_in_delays_become_model_time_units() {
    const MS100: Option<u64> = Some(100_000_000);
    let send = |attr: &str| format!(r#"<send event="f" target="NONE" {attr}/>"#);
    for (attr, unit, times) in [
        (r#"delay="1s""#, MS100, vec![0, 10]),
        (r#"delay="4""#, None, vec![0, 4]),
        (r#"delay="0ms""#, MS100, vec![0, 0]),
        (r#"delayexpr="d + 'ms'""#, MS100, vec![0, 3]),
        (
            r#"delayexpr="d*2 + &quot;ms&quot;""#,
            Some(1_000_000),
            vec![0, 600],
        ),
        (
            r#"delayexpr="(d + 1) * 10 + 'us'""#,
            Some(10_000),
            vec![0, 301],
        ),
        (r#"delayexpr="d""#, None, vec![0, 300]),
        // A float counts its unit too, rounded to the nanosecond (0.1 s is not exact).
        (r#"delayexpr="q * 2 + 's'""#, MS100, vec![0, 5]),
        (r#"delayexpr="0.1 + 's'""#, MS100, vec![0, 1]),
    ] {
        assert_eq!(delayed_sends(&send(attr), unit), Ok(times), "{attr}");
    }
    for (attr, unit, want) in [
        (
            r#"delay="1s""#,
            None,
            "a.scxml:2:100: delay 1s is a duration: it needs the model's time unit",
        ),
        (
            r#"delayexpr="d + 'ms'""#,
            None,
            "a.scxml:2:104: a delay in `ms` is a duration: it needs the model's time unit",
        ),
        (
            r#"delay="150ms""#,
            MS100,
            "a.scxml:2:100: delay 150ms is not a whole number of model time units of 100ms",
        ),
        (
            r#"delay="1sec""#,
            MS100,
            "delay `1sec` is neither a whole number of model time units nor a duration",
        ),
        (
            r#"delayexpr="(d + 1) + 'ms'""#,
            MS100,
            "a.scxml:2:104: a delay of 301ms is not a whole number of model time units of 100ms",
        ),
        (
            r#"delayexpr="neg""#,
            None,
            "a.scxml:2:104: the delay is negative (-2)",
        ),
        (
            r#"delayexpr="neg + 'ms'""#,
            MS100,
            "the delay is negative (-2)",
        ),
        (
            r#"delayexpr="-q + 's'""#,
            MS100,
            "the delay is negative (-0.25)",
        ),
        (
            r#"delayexpr="q + 's'""#,
            MS100,
            "a delay of 250ms is not a whole number",
        ),
        (
            r#"delayexpr="(q > 0) + 's'""#,
            MS100,
            "a delay in `s` needs a number before its unit",
        ),
        // Only a unit ends the sum: anything else stays a (refused) string concatenation.
        (
            r#"delayexpr="d + 'sec'""#,
            MS100,
            "string concatenation is not supported",
        ),
    ] {
        let err = delayed_sends(&send(attr), unit).unwrap_err();
        assert!(err.contains(want), "{attr}: {err}");
    }
}

#[test]
fn a_transition_on_a_prefix_of_a_dotted_event_is_warned_about() {
    // W3C SCXML's `foo` would take `foo.bar`; hindsight (as SCAN and AS2FM) does not.
    // Warned where `foo.bar` reaches the machine (its own raise, a send naming it), not
    // where it goes elsewhere, nor where the transition lists it too.
    let m = compile_texts(&[
        (
            "a.scxml",
            r#"<scxml name="A" initial="s"><state id="s">
            <onentry><raise event="foo.bar"/><send event="err.io" target="B"/><send event="foo" target="A"/></onentry>
            <transition event="foo" target="s"/><transition event="err" target="s"/>
            <transition event="foo foo.bar" target="s"/></state></scxml>"#,
        ),
        (
            "b.scxml",
            r#"<scxml name="B" initial="w"><state id="w"><transition event="err" target="w"/>
            <transition event="err.io" target="w"/></state></scxml>"#,
        ),
    ])
    .unwrap();
    let warned: Vec<(String, u32, u32)> = m
        .warnings()
        .iter()
        .filter(|d| d.message.contains("matches event names exactly"))
        .map(|d| (d.file.clone(), d.line, d.col))
        .collect();
    assert_eq!(
        warned,
        vec![
            ("a.scxml".to_string(), 3, 32),
            ("b.scxml".to_string(), 1, 62)
        ],
        "{:?}",
        m.warnings()
    );
    assert!(m.warnings()[0]
        .message
        .starts_with("event `foo.bar`, sent to `A`, is not taken by this `foo` transition"));
}

#[test]
fn a_w3c_special_target_is_named_as_such() {
    let errs = compile_texts(&[(
        "a.scxml",
        r##"<scxml name="A" initial="s"><state id="s"><onentry><send event="e" target="#_internal"/></onentry>
        <transition event="e" target="s"/></state></scxml>"##,
    )])
    .unwrap_err();
    assert!(
        errs.to_string()
            .contains("a.scxml:1:76: W3C SCXML's special target `#_internal` is not supported"),
        "{errs}"
    );
}
