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
