//! Pre/post conditions on a `<SubTree>` node (BT.CPP 4), in the oracle's reader.
//!
//! The rules, each measured in the real library (4.8.2, `tests/tests/bt_real.rs` and
//! `tests/bt/btcpp4/subtree.toml`) and read in BT.CPP 4.10's sources:
//! - the SubTree node is a node of its own, a decorator over the body
//!   (`decorators/subtree_node.cpp`, `SubTreeNode`): `TreeNode::executeTick` runs its
//!   conditions around the whole body as around any node;
//! - its `_failureIf` ... `_onHalted` attributes are conditions, not ports it remaps
//!   (`xml_parsing.cpp`, `createNodeFromXML` takes them as conditions for every
//!   element, and `recursivelyCreateSubtree` skips names that are not allowed port
//!   names), and they run in the caller's blackboard (`createNodeFromXML` gives the
//!   SubTree node the blackboard of the tree it is written in; the body gets the new
//!   one): a name in them is the caller's, whatever the SubTree remaps or `_autoremap`;
//! - `SubTreeNode::tick` sets the node RUNNING when IDLE before ticking the body, passes
//!   the body's answer on, and resets the body once it finished: a body that answers
//!   SKIPPED leaves the SubTree node RUNNING (its parent then halts it, which runs its
//!   `_onHalted`, and its `_failureIf`, `_successIf`, `_skipIf` are not checked again
//!   until then).
//!
//! A SubTree without conditions stays inlined ([`super::tree`]).

use super::script;
use super::tree::{Conds, El, POST, PRE};

/// Whether attribute `name` is a pre/post condition.
fn is_cond(name: &str) -> bool {
    PRE.contains(&name) || POST.contains(&name)
}

/// `el` without its condition attributes (format 4 only: BT.CPP 3 has none, and its
/// reader treats them as remapped names).
pub fn without_conds(el: &El, v3: bool) -> El {
    let mut out = el.clone();
    if !v3 {
        out.attrs.retain(|k, _| !is_cond(k));
    }
    out
}

/// The conditions written on `<SubTree>` element `el`, their names renamed by `global`
/// (the caller's scope), or `None` when it has none (or the tree is format 3).
pub fn conds(el: &El, v3: bool, global: &dyn Fn(&str) -> String) -> Result<Option<Conds>, String> {
    if v3 || !el.attrs.keys().any(|k| is_cond(k)) {
        return Ok(None);
    }
    let mut c = Conds::default();
    for (names, slots) in [(&PRE, &mut c.pre), (&POST, &mut c.post)] {
        for (name, slot) in names.iter().zip(slots.iter_mut()) {
            if let Some(v) = el.attrs.get(*name) {
                let mut p = script::parse(v).map_err(|e| format!("SubTree {name}: {e}"))?;
                p.rename(global);
                *slot = Some(p);
            }
        }
    }
    Ok(Some(c))
}

/// After node `n` answered `s`: a SubTree's body root that finished is IDLE again under
/// BT.CPP's rules (4.10 `SubTreeNode::tick` and 3.8 `SubtreeNode::tick` reset the child
/// once it is no longer RUNNING: `resetChild`, its status only, as it is not RUNNING).
/// Where BT.CPP ticks the SubTree again without a reset (the condition of a two-child
/// IfThenElse or of a WhileDoElse) the body starts afresh: a leaf runs again, its
/// pre-conditions are checked again (4.8.2 measured, `tests/bt/btcpp4/subtree.toml`),
/// where an inlined body would answer its finished status again.
pub fn reset_finished_body(
    tree: &super::tree::Tree,
    btcpp: bool,
    n: usize,
    s: super::tree::Status,
    status: &mut [Option<super::tree::Status>],
) {
    use super::tree::Status;
    if btcpp && tree.nodes[n].subtree_body && matches!(s, Status::Success | Status::Failure) {
        status[n] = None;
    }
}
