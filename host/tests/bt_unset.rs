//! BehaviorTree.CPP 4's UnsetBlackboard in a tree: lowered under `--bt btcpp` over an
//! entry only scripts use; refused with file:line:col under AS2FM's semantics, inside a
//! SubTree, with `key` in braces, and over an entry a SetBlackboard writes. The queue
//! nodes BT.CPP does not register are refused, saying why. (What the lowered node does
//! is held to the oracle by `tests/tests/bt_btcpp_lowering.rs`.) A SetBlackboard copying
//! an entry is refused under `--bt btcpp` at its `value` (BT.CPP 4 does not copy as
//! AS2FM's model does) and copies under AS2FM's semantics.

mod common;

use common::bt::{lower_act as lower, BTCPP};
use hindsight::verify::robot::bt::BtSemantics;

#[test]
fn unset_lowers_under_btcpp_over_a_script_entry() {
    let body = "<Sequence>\n<Script code=\"x:=1\"/>\n<UnsetBlackboard key=\"x\"/>\n<Script code=\"x:=2\"/>\n</Sequence>";
    lower(body, "", BTCPP).expect("lowers");
    let e = lower(body, "", BtSemantics::As2fm).expect_err("AS2FM has no model");
    assert!(
        e.contains("tree.xml:5:1: `UnsetBlackboard` is a BehaviorTree.CPP 4 node that AS2FM has no model of"),
        "{e}"
    );
}

#[test]
fn unset_is_refused_where_it_is_not_modelled() {
    let e = lower(
        "<SubTree ID=\"S\" _autoremap=\"true\"/>",
        "<BehaviorTree ID=\"S\">\n<UnsetBlackboard key=\"x\"/>\n</BehaviorTree>\n",
        BTCPP,
    )
    .expect_err("inside a SubTree");
    assert!(
        e.contains("tree.xml:6:23: UnsetBlackboard inside a SubTree is not modelled"),
        "{e}"
    );
    let e = lower("<UnsetBlackboard key=\"{x}\"/>", "", BTCPP).expect_err("braces");
    assert!(
        e.contains("tree.xml:3:23: `key` of UnsetBlackboard is the entry's name"),
        "{e}"
    );
    let e = lower(
        "<Sequence>\n<SetBlackboard output_key=\"k\" value=\"1\"/>\n<UnsetBlackboard key=\"k\"/>\n</Sequence>",
        "",
        BTCPP,
    )
    .expect_err("a SetBlackboard entry");
    assert!(
        e.contains("tree.xml:5:23: UnsetBlackboard erases `k`, which a SetBlackboard writes"),
        "{e}"
    );
}

#[test]
fn the_queue_nodes_are_refused_saying_why() {
    // BT.CPP 4's factory does not register them (`tests/bt_loop.rs` has the Loop nodes
    // and the entry-updated nodes, which `--bt btcpp` lowers).
    let node = "<PopFromQueue queue=\"{q}\"/>";
    let e = lower(node, "", BTCPP).expect_err(node);
    assert!(
        e.contains("tree.xml:3:1: ") && e.contains("does not register it"),
        "{node}: {e}"
    );
}

#[test]
fn a_set_blackboard_copy_is_refused_under_btcpp_and_copies_under_as2fm() {
    let body = "<Sequence><SetBlackboard output_key=\"a\" value=\"5\"/><SetBlackboard output_key=\"b\" value=\"{a}\"/><Act/></Sequence>";
    let e = lower(body, "", BTCPP).expect_err("refused");
    assert!(
        e.contains("tree.xml:3:89: SetBlackboard copying `{a}` under `--bt btcpp`")
            && e.contains("a copy of an entry that holds no value answers FAILURE")
            && e.contains("a Script `b := a` copies a value"),
        "{e}"
    );
    lower(body, "", BtSemantics::As2fm).unwrap_or_else(|e| panic!("AS2FM's model copies: {e}"));
}
