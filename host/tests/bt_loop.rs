//! BehaviorTree.CPP 4's entry-updated nodes (WasEntryUpdated, SkipUnlessUpdated,
//! WaitValueUpdate) and Loop nodes (LoopInt, LoopBool, LoopDouble, LoopString) in a tree:
//! lowered under `--bt btcpp` (the counters and the queue's index in the model), refused
//! with file:line:col under AS2FM's semantics and where BT.CPP's behaviour is not modelled,
//! each saying why. (What the lowered nodes do is held to the oracle and the real library
//! by `tests/tests/bt_btcpp_lowering.rs`.)

mod common;

use common::bt::{lower_act as lower, BTCPP};
use hindsight::verify::model::xml::Element;
use hindsight::verify::robot::bt::BtSemantics;

/// The `<data>` ids of machine `name`.
fn data(ms: &[Element], name: &str) -> Vec<String> {
    let m = ms
        .iter()
        .find(|m| m.attr_value("name") == Some(name))
        .unwrap_or_else(|| panic!("no machine {name}"));
    m.elements()
        .filter(|e| e.name == "datamodel")
        .flat_map(|d| d.elements())
        .filter_map(|d| d.attr_value("id").map(str::to_string))
        .collect()
}

#[test]
fn the_nodes_lower_under_btcpp_and_not_under_as2fm() {
    let body = "<Sequence>\n<Script code=\"x:=1\"/>\n<LoopInt queue=\"1;2;3\" value=\"{x}\">\n\
                <WaitValueUpdate entry=\"x\"><Act/></WaitValueUpdate>\n</LoopInt>\n\
                <SkipUnlessUpdated entry=\"{y}\"><WasEntryUpdated entry=\"x\"/></SkipUnlessUpdated>\n\
                <LoopString queue=\"a;b\" value=\"{s}\"><LoopBool queue=\"true;0\" value=\"{b}\">\
                <LoopDouble queue=\"1.5;2\" value=\"{d}\"><Act/></LoopDouble></LoopBool></LoopString>\n</Sequence>";
    let ms = lower(body, "", BTCPP).expect("lowers");
    // The counters of the watched entries and each node's last seen one, in the
    // blackboard machine.
    let bb = data(&ms, "bt_blackboard_fsm");
    for v in [
        "bt_seq__x",
        "bt_seq__y",
        "bt_seen__1003",
        "bt_seen__1005",
        "bt_seen__1006",
    ] {
        assert!(bb.iter().any(|d| d == v), "{v} in {bb:?}");
    }
    let e = lower(body, "", BtSemantics::As2fm).expect_err("AS2FM has no model");
    for (at, node) in [
        ("5:1", "LoopInt"),
        ("6:1", "WaitValueUpdate"),
        ("8:1", "SkipUnlessUpdated"),
    ] {
        assert!(
            e.contains(&format!(
                "tree.xml:{at}: `{node}` is a BehaviorTree.CPP 4 node that AS2FM has no model of"
            )),
            "{node}: {e}"
        );
    }
}

#[test]
fn what_is_not_modelled_is_refused_at_its_place() {
    for (body, want) in [
        (
            "<LoopInt queue=\"{q}\"><Act/></LoopInt>",
            "tree.xml:3:17: `queue` of LoopInt is the entry `{q}`",
        ),
        (
            "<LoopInt queue=\"1; 2\"><Act/></LoopInt>",
            "tree.xml:3:17: item 2 of the `queue` of LoopInt: ` 2` is not a whole number",
        ),
        (
            "<LoopBool queue=\"yes\"><Act/></LoopBool>",
            "tree.xml:3:18: item 1 of the `queue` of LoopBool: `yes` is not a boolean",
        ),
        (
            "<LoopInt queue=\"1\" if_empty=\"IDLE\"><Act/></LoopInt>",
            "tree.xml:3:30: `if_empty` of LoopInt: `IDLE` is not SUCCESS",
        ),
        (
            "<LoopInt queue=\"1\" value=\"x\"><Act/></LoopInt>",
            "tree.xml:3:27: `value` of LoopInt is an output",
        ),
        (
            "<Sequence><Script code=\"x:=0\"/><LoopString queue=\"7\" value=\"{x}\"><Act/></LoopString></Sequence>",
            "assigning a number to `x`, which holds strings (a script or a LoopString writes them)",
        ),
        (
            "<IfThenElse><LoopInt _failureIf=\"true\" queue=\"1\"><Act/></LoopInt><Act/></IfThenElse>",
            "`_failureIf` on LoopInt as the condition of a two-child IfThenElse",
        ),
        (
            "<Sequence><Script code=\"t:='a'\"/><LoopInt queue=\"1\" value=\"{t}\"><Act/></LoopInt></Sequence>",
            "tree.xml:3:60: `value` of LoopInt writes its items to `t`, which is int64 at tree.xml:3:60 (a script): a script assigns strings to that entry",
        ),
        (
            // `x` only UnsetBlackboard names: an integer entry, not a float (a script's
            // `x` lowers, the LoopDouble storing into it as BT.CPP does).
            "<Sequence><UnsetBlackboard key=\"x\"/><LoopDouble queue=\"1.5\" value=\"{x}\"><Act/></LoopDouble></Sequence>",
            "Invalid floating point to integer conversion",
        ),
        (
            "<Sequence><SetBlackboard output_key=\"k\" value=\"1\"/><LoopInt queue=\"1\" value=\"{k}\"><Act/></LoopInt></Sequence>",
            "which a SetBlackboard writes too",
        ),
        (
            "<BlackboardCheckInt value_A=\"{k}\" value_B=\"1\"><LoopInt queue=\"1\"><Act/></LoopInt></BlackboardCheckInt>",
            "tree.xml:3:47: LoopInt: its parent, a BlackboardCheck, is a BehaviorTree.CPP 3 node",
        ),
        (
            "<WasEntryUpdated/>",
            "tree.xml:3:1: WasEntryUpdated needs `entry`",
        ),
        (
            "<SkipUnlessUpdated entry=\"a b\"><Act/></SkipUnlessUpdated>",
            "tree.xml:3:27: `entry` of SkipUnlessUpdated must name a blackboard entry",
        ),
    ] {
        let e = lower(body, "", BTCPP).expect_err(body);
        assert!(e.contains(want), "{body}:\n{e}");
    }
    // A SubTree's constant has no counter in the model.
    let e = lower(
        "<SubTree ID=\"S\" x=\"5\"/>",
        "<BehaviorTree ID=\"S\">\n<WasEntryUpdated entry=\"x\"/>\n</BehaviorTree>\n",
        BTCPP,
    )
    .expect_err("a constant");
    assert!(
        e.contains("tree.xml:6:25: `entry` of WasEntryUpdated must name a blackboard entry"),
        "{e}"
    );
}
