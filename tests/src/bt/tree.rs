//! The oracle's own reader of BehaviorTree.CPP XML (formats 3 and 4): a flat node list in
//! depth-first pre-order with SubTrees inlined, numbered from 1000 as AS2FM numbers them.
//!
//! Written independently of hindsight's reader: it uses quick-xml directly and knows the
//! built-in nodes only through [`NODES`], the one table to extend for a new node kind.

use super::script::{self, Program};
use quick_xml::events::{BytesStart, Event};
use quick_xml::Reader;
use std::collections::BTreeMap;

/// A status a node answers.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Status {
    /// SUCCESS.
    Success,
    /// FAILURE.
    Failure,
    /// RUNNING.
    Running,
    /// SKIPPED (BT.CPP 4: a pre-condition skipped the node, or every child of a control
    /// was skipped; `TreeNode::executeTick` keeps the node's own status as it was).
    Skipped,
}

impl Status {
    /// `SUCCESS`, `FAILURE`, `RUNNING` (or the first letter).
    pub fn parse(s: &str) -> Option<Status> {
        match s.trim() {
            "SUCCESS" | "S" => Some(Status::Success),
            "FAILURE" | "F" => Some(Status::Failure),
            "RUNNING" | "R" => Some(Status::Running),
            "SKIPPED" => Some(Status::Skipped),
            _ => None,
        }
    }
    /// The status name.
    pub fn name(self) -> &'static str {
        match self {
            Status::Success => "SUCCESS",
            Status::Failure => "FAILURE",
            Status::Running => "RUNNING",
            Status::Skipped => "SKIPPED",
        }
    }
    /// The code AS2FM's translation sends: 1, 2, 3 (and 4 for SKIPPED, which AS2FM
    /// does not have).
    pub fn code(self) -> i64 {
        match self {
            Status::Success => 1,
            Status::Failure => 2,
            Status::Running => 3,
            Status::Skipped => 4,
        }
    }
}

/// One side of a blackboard comparison, or the value SetBlackboard writes.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Operand {
    /// Text written in the tree (BT.CPP keeps a SetBlackboard value as a string and
    /// converts it where a port reads it: `convertFromString`).
    Lit(String),
    /// A blackboard entry (after SubTree remapping).
    Entry(String),
}

/// Which `BlackboardCheck*` node: the type both sides are read as.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CheckType {
    /// `BlackboardCheckInt`.
    Int,
    /// `BlackboardCheckDouble`: equal within `f32::EPSILON`.
    Double,
    /// `BlackboardCheckString`.
    String,
    /// `BlackboardCheckBool`.
    Bool,
}

/// What a node is.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Kind {
    /// A scripted leaf of the named type.
    Leaf(String),
    /// `Sequence`.
    Sequence,
    /// `ReactiveSequence`.
    ReactiveSequence,
    /// `SequenceWithMemory` (format 3: `SequenceStar`).
    SequenceWithMemory,
    /// `Fallback`.
    Fallback,
    /// `ReactiveFallback`.
    ReactiveFallback,
    /// Success and failure thresholds as written (negative counts from the end).
    Parallel(i64, i64),
    /// `IfThenElse`.
    IfThenElse,
    /// `Inverter`.
    Inverter,
    /// `ForceSuccess`.
    ForceSuccess,
    /// `ForceFailure`.
    ForceFailure,
    /// `Repeat` with `num_cycles`.
    Repeat(i64),
    /// `RetryUntilSuccessful` with `num_attempts`.
    Retry(i64),
    /// `AlwaysSuccess`.
    AlwaysSuccess,
    /// `AlwaysFailure`.
    AlwaysFailure,
    /// `SetBlackboard`: the entry and the text written, or the entry copied.
    SetBlackboard(String, Operand),
    /// `AsyncSequence` (BT.CPP 4).
    AsyncSequence,
    /// `AsyncFallback` (BT.CPP 4).
    AsyncFallback,
    /// `ParallelAll` with `max_failures` as written (BT.CPP 4).
    ParallelAll(i64),
    /// `WhileDoElse` (BT.CPP 4).
    WhileDoElse,
    /// `KeepRunningUntilFailure` (BT.CPP 4).
    KeepRunningUntilFailure,
    /// `RunOnce` and its `then_skip` (BT.CPP 4; true, the default, answers SKIPPED once
    /// the child has run).
    RunOnce(bool),
    /// `Switch2` ... `Switch6`: the `variable` and the `case_1..N` values (BT.CPP 4).
    Switch(Operand, Vec<String>),
    /// `BlackboardCheckInt/Double/String/Bool`: `value_A`, `value_B`,
    /// `return_on_mismatch`, and whether that was written as one of AS2FM's numbers.
    Check(CheckType, Operand, Operand, Status, bool),
    /// `Script` with its `code` (BT.CPP 4).
    Script(Program),
    /// `ScriptCondition` with its `code` (BT.CPP 4).
    ScriptCondition(Program),
    /// `Precondition` with its `if` script and `else` status (BT.CPP 4).
    Precondition(Program, Status),
    /// `Timeout` with `msec` (BT.CPP 4; a timer in virtual time, see the oracle).
    Timeout(u64),
    /// `Delay` with `delay_msec` (BT.CPP 4).
    Delay(u64),
    /// `Sleep` with `msec` (BT.CPP 4).
    Sleep(u64),
    /// `TryCatch` with `catch_on_halt` (BT.CPP 4.10 only: 4.8.2 does not know it).
    TryCatch(bool),
    /// `UnsetBlackboard` with its `key` (a name, BT.CPP 4).
    Unset(String),
    /// `WasEntryUpdated` with its `entry` (after remapping, BT.CPP 4).
    EntryUpdated(String),
    /// `SkipUnlessUpdated` (SKIPPED) and `WaitValueUpdate` (RUNNING): the `entry` and
    /// what the node answers when it was not updated (BT.CPP 4).
    Updated(String, Status),
    /// `LoopInt`, `LoopDouble`, `LoopString`, `LoopBool` over a queue written in the
    /// tree (`queue="1;2;3"`): the type, the items as text, the `value` entry, `if_empty`
    /// (BT.CPP 4).
    Loop(LoopType, Vec<String>, Option<String>, Status),
    /// A `<SubTree>` node that carries pre/post conditions (BT.CPP 4 `SubTreeNode`, a
    /// decorator over the body): kept as a node of its own so that its conditions wrap
    /// the body, run in the caller's blackboard (`subtree_cond.rs`). A SubTree without
    /// conditions is inlined.
    SubTree,
}

/// The item type of a `Loop<T>` node.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LoopType {
    /// `LoopInt`.
    Int,
    /// `LoopDouble`.
    Double,
    /// `LoopString`.
    String,
    /// `LoopBool`.
    Bool,
}

impl Kind {
    /// A BT.CPP 4 node AS2FM has no model of (the lowering does not take it).
    pub fn btcpp4_only(&self) -> bool {
        matches!(
            self,
            Kind::AsyncSequence
                | Kind::AsyncFallback
                | Kind::ParallelAll(_)
                | Kind::WhileDoElse
                | Kind::KeepRunningUntilFailure
                | Kind::RunOnce(_)
                | Kind::Switch(..)
                | Kind::Script(_)
                | Kind::ScriptCondition(_)
                | Kind::Precondition(..)
                | Kind::Timeout(_)
                | Kind::Delay(_)
                | Kind::Sleep(_)
                | Kind::TryCatch(_)
                | Kind::Unset(_)
                | Kind::EntryUpdated(_)
                | Kind::Updated(..)
                | Kind::Loop(..)
                | Kind::SubTree
        )
    }
}

/// A node of the flattened tree.
#[derive(Clone, Debug)]
pub struct Node {
    /// 1000, 1001, ... in pre-order.
    pub id: u32,
    /// The number BT.CPP 4 gives the node (`TreeNode::UID`): it counts from 1 in the order
    /// the factory creates nodes, depth-first pre-order with each SubTree node (which the
    /// flat tree drops) before its body.
    pub uid: u32,
    /// The element name as written (`SequenceStar`, `BlackboardCheckInt`, a leaf type).
    pub tag: String,
    /// What it is.
    pub kind: Kind,
    /// Indices into [`Tree::nodes`].
    pub children: Vec<usize>,
    /// Its pre- and post-condition scripts (BT.CPP 4).
    pub conds: Conds,
    /// The root of a SubTree's body: BT.CPP's `SubTreeNode::tick` resets it once it
    /// finished (`subtree_cond.rs`).
    pub subtree_body: bool,
    /// A leaf's `out` port: the entry (after SubTree remapping) where it writes a double
    /// at every callback ([`super::model::OUT_VALUES`]).
    pub out: Option<String>,
    /// A leaf's `in` port (a `float64` input, `super::model::has_in`): the entry it
    /// names, which BT.CPP creates, empty, when it loads the tree.
    pub input: Option<String>,
}

/// The scripts of a node's pre/post-condition attributes (BT.CPP 4 `tree_node.h`,
/// `PreCondNames` and `PostCondNames`, in the order `TreeNode::checkPreConditions` checks
/// them and the enum `PostCond` numbers them).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Conds {
    /// `_failureIf`, `_successIf`, `_skipIf`, `_while`.
    pub pre: [Option<Program>; 4],
    /// `_onHalted`, `_onFailure`, `_onSuccess`, `_post`.
    pub post: [Option<Program>; 4],
}

/// The pre-condition attributes, in [`Conds::pre`] order.
pub const PRE: [&str; 4] = ["_failureIf", "_successIf", "_skipIf", "_while"];
/// The post-condition attributes, in [`Conds::post`] order.
pub const POST: [&str; 4] = ["_onHalted", "_onFailure", "_onSuccess", "_post"];

impl Conds {
    /// Whether the node has any.
    pub fn any(&self) -> bool {
        self.pre.iter().chain(&self.post).any(|p| p.is_some())
    }
}

/// A flattened tree; node 0 is the root.
#[derive(Clone, Debug, Default)]
pub struct Tree {
    /// The nodes, pre-order.
    pub nodes: Vec<Node>,
    /// Every node element's name (an `Action`'s `ID`) in every `<BehaviorTree>` of the
    /// document, used or not, in document order: BT.CPP checks them all at load.
    pub names: Vec<String>,
    /// Some `<ReactiveSequence>` of the document has two `<AsyncSequence>` children,
    /// which BT.CPP 4.8.2 refuses at load ("A ReactiveSequence cannot have more than one
    /// async child", found against the real library).
    pub reactive_async: bool,
}

fn reactive_async(el: &El) -> bool {
    let asyncs = el
        .children
        .iter()
        .filter(|c| c.name == "AsyncSequence")
        .count();
    (el.name == "ReactiveSequence" && asyncs > 1) || el.children.iter().any(reactive_async)
}

fn names(el: &El, out: &mut Vec<String>) {
    let name = match el.name.as_str() {
        "Action" | "Condition" | "Control" | "Decorator" => {
            el.attrs.get("ID").cloned().unwrap_or_default()
        }
        n => n.to_string(),
    };
    out.push(name);
    for c in &el.children {
        names(c, out);
    }
}

/// How many children a kind takes: (least, most).
type Arity = (usize, usize);
/// Builds a kind from the node's attributes (already remapped: `{entry}` values name the
/// caller's entries).
type Make = fn(&Attrs) -> Result<Kind, String>;
type Attrs = BTreeMap<String, String>;

const ANY: usize = usize::MAX;

/// Every built-in node the oracle knows: the XML names (format 3 and 4), arity, builder.
pub const NODES: &[(&[&str], Arity, Make)] = &[
    (&["Sequence"], (1, ANY), |_| Ok(Kind::Sequence)),
    (&["ReactiveSequence"], (1, ANY), |_| {
        Ok(Kind::ReactiveSequence)
    }),
    (&["SequenceWithMemory", "SequenceStar"], (1, ANY), |_| {
        Ok(Kind::SequenceWithMemory)
    }),
    (&["Fallback"], (1, ANY), |_| Ok(Kind::Fallback)),
    (&["ReactiveFallback"], (1, ANY), |_| {
        Ok(Kind::ReactiveFallback)
    }),
    (&["Parallel"], (1, ANY), |a| {
        Ok(Kind::Parallel(
            int_or(a, &["success_count", "success_threshold"], -1)?,
            int_or(a, &["failure_count", "failure_threshold"], 1)?,
        ))
    }),
    (&["IfThenElse"], (2, 3), |_| Ok(Kind::IfThenElse)),
    (&["Inverter"], (1, 1), |_| Ok(Kind::Inverter)),
    (&["ForceSuccess"], (1, 1), |_| Ok(Kind::ForceSuccess)),
    (&["ForceFailure"], (1, 1), |_| Ok(Kind::ForceFailure)),
    (&["Repeat"], (1, 1), |a| {
        Ok(Kind::Repeat(int(a, "num_cycles")?))
    }),
    (
        &["RetryUntilSuccessful", "RetryUntilSuccesful"],
        (1, 1),
        |a| Ok(Kind::Retry(int(a, "num_attempts")?)),
    ),
    (&["AsyncSequence"], (1, ANY), |_| Ok(Kind::AsyncSequence)),
    (&["AsyncFallback"], (1, ANY), |_| Ok(Kind::AsyncFallback)),
    (&["ParallelAll"], (1, ANY), |a| {
        Ok(Kind::ParallelAll(int_or(a, &["max_failures"], 1)?))
    }),
    (&["WhileDoElse"], (2, 3), |_| Ok(Kind::WhileDoElse)),
    (&["KeepRunningUntilFailure"], (1, 1), |_| {
        Ok(Kind::KeepRunningUntilFailure)
    }),
    // `RunOnceNode::providedPorts`: `then_skip` defaults to true.
    (&["RunOnce"], (1, 1), |a| {
        match a.get("then_skip").map(|s| s.trim()) {
            Some("false") => Ok(Kind::RunOnce(false)),
            None | Some("true") => Ok(Kind::RunOnce(true)),
            Some(o) => Err(format!("bad then_skip {o}")),
        }
    }),
    (&["Switch2"], (3, 3), |a| switch(a, 2)),
    (&["Switch3"], (4, 4), |a| switch(a, 3)),
    (&["Switch4"], (5, 5), |a| switch(a, 4)),
    (&["Switch5"], (6, 6), |a| switch(a, 5)),
    (&["Switch6"], (7, 7), |a| switch(a, 6)),
    (&["Script"], (0, 0), |a| Ok(Kind::Script(code(a, "code")?))),
    (&["ScriptCondition"], (0, 0), |a| {
        Ok(Kind::ScriptCondition(code(a, "code")?))
    }),
    // `PreconditionNode::providedPorts`: `else` defaults to FAILURE.
    (&["Precondition"], (1, 1), |a| {
        let e = match a.get("else") {
            None => Status::Failure,
            Some(s) => Status::parse(s).ok_or(format!("bad else {s}"))?,
        };
        Ok(Kind::Precondition(code(a, "if")?, e))
    }),
    // The ports are `unsigned` milliseconds (`TimeoutNode::providedPorts`,
    // `DelayNode::providedPorts`, `SleepNode::providedPorts`).
    (&["Timeout"], (1, 1), |a| {
        Ok(Kind::Timeout(msec(a, "msec")?))
    }),
    (&["Delay"], (1, 1), |a| {
        Ok(Kind::Delay(msec(a, "delay_msec")?))
    }),
    // Without `msec`, BT.CPP's own unit tests' `Sleep` test node (a scripted leaf here;
    // the built-in would throw "Missing parameter [msec]" at its first tick).
    (&["Sleep"], (0, 0), |a| match a.contains_key("msec") {
        true => Ok(Kind::Sleep(msec(a, "msec")?)),
        false => Ok(Kind::Leaf("Sleep".into())),
    }),
    // `TryCatchNode::providedPorts`: `catch_on_halt` defaults to false.
    (&["TryCatch"], (2, ANY), |a| {
        match a.get("catch_on_halt").map(|s| s.trim()) {
            None | Some("false") => Ok(Kind::TryCatch(false)),
            Some("true") => Ok(Kind::TryCatch(true)),
            Some(v) => Err(format!("bad catch_on_halt {v}")),
        }
    }),
    // `UnsetBlackboardNode::providedPorts`: `key`, a string (the entry's name; `{x}`
    // would read x's value as the name).
    (&["UnsetBlackboard"], (0, 0), |a| {
        let k = a.get("key").ok_or("missing `key`")?;
        match entry(k) {
            Some(_) => Err("UnsetBlackboard with `key` in {}: not modelled".into()),
            None => Ok(Kind::Unset(k.trim().to_string())),
        }
    }),
    // `EntryUpdatedAction` / `EntryUpdatedDecorator`: `entry`, with or without braces
    // (`isBlackboardPointer` strips them); [`Flat::node`] writes it braced.
    (&["WasEntryUpdated"], (0, 0), |a| {
        Ok(Kind::EntryUpdated(updated_entry(a)?))
    }),
    (&["SkipUnlessUpdated"], (1, 1), |a| {
        Ok(Kind::Updated(updated_entry(a)?, Status::Skipped))
    }),
    (&["WaitValueUpdate"], (1, 1), |a| {
        Ok(Kind::Updated(updated_entry(a)?, Status::Running))
    }),
    (&["LoopInt"], (1, 1), |a| loop_node(a, LoopType::Int)),
    (&["LoopDouble"], (1, 1), |a| loop_node(a, LoopType::Double)),
    (&["LoopString"], (1, 1), |a| loop_node(a, LoopType::String)),
    (&["LoopBool"], (1, 1), |a| loop_node(a, LoopType::Bool)),
    (&["AlwaysSuccess"], (0, 0), |_| Ok(Kind::AlwaysSuccess)),
    (&["AlwaysFailure"], (0, 0), |_| Ok(Kind::AlwaysFailure)),
    (&["SetBlackboard"], (0, 0), |a| {
        let key = a
            .get("output_key")
            .ok_or("SetBlackboard needs output_key")?;
        let key = entry(key).unwrap_or(key.trim()).to_string();
        Ok(Kind::SetBlackboard(key, operand(a, "value")?))
    }),
    (&["BlackboardCheckInt"], (1, 1), |a| {
        check(a, CheckType::Int)
    }),
    (&["BlackboardCheckDouble"], (1, 1), |a| {
        check(a, CheckType::Double)
    }),
    (&["BlackboardCheckString"], (1, 1), |a| {
        check(a, CheckType::String)
    }),
    (&["BlackboardCheckBool"], (1, 1), |a| {
        check(a, CheckType::Bool)
    }),
];

fn entry(v: &str) -> Option<&str> {
    v.trim().strip_prefix('{')?.strip_suffix('}')
}

/// A script port: the text parsed (entries renamed to the caller's by [`Flat::node`]).
fn code(a: &Attrs, k: &str) -> Result<Program, String> {
    let v = a.get(k).ok_or(format!("missing `{k}`"))?;
    script::parse(v).map_err(|e| format!("`{k}`: {e}"))
}

fn int(a: &Attrs, k: &str) -> Result<i64, String> {
    let v = a.get(k).ok_or(format!("missing `{k}`"))?;
    v.trim()
        .parse()
        .map_err(|_| format!("`{k}` is not a number: {v}"))
}

/// A duration port in milliseconds (an `unsigned` in BT.CPP).
fn msec(a: &Attrs, k: &str) -> Result<u64, String> {
    let v = int(a, k)?;
    u64::try_from(v).map_err(|_| format!("`{k}` is negative: {v}"))
}

fn int_or(a: &Attrs, ks: &[&str], d: i64) -> Result<i64, String> {
    match ks.iter().find(|k| a.contains_key(**k)) {
        Some(k) => int(a, k),
        None => Ok(d),
    }
}

fn operand(a: &Attrs, k: &str) -> Result<Operand, String> {
    let v = a.get(k).ok_or(format!("missing `{k}`"))?;
    Ok(match entry(v) {
        Some(e) => Operand::Entry(e.to_string()),
        None => Operand::Lit(v.trim().to_string()),
    })
}

/// The `entry` port of the entry-updated nodes (braced by [`Flat::node`]).
fn updated_entry(a: &Attrs) -> Result<String, String> {
    let v = a.get("entry").ok_or("missing `entry`")?;
    Ok(entry(v).unwrap_or(v.trim()).to_string())
}

/// The nodes whose `entry` port names an entry with or without braces.
const UPDATED: [&str; 3] = ["WasEntryUpdated", "SkipUnlessUpdated", "WaitValueUpdate"];

/// A `Loop<T>` node (4.10 `decorators/loop_node.h`). The queue is a literal: the
/// constructor converts it (`convertFromString<SharedQueue<T>>`: `splitString` on `;`,
/// each part converted, a part that does not convert refuses the tree at load; 4.8.2
/// drops a last empty part, as found against the real library). `if_empty` defaults to
/// SUCCESS; `value` is an output (unset: nothing written).
fn loop_node(a: &Attrs, ty: LoopType) -> Result<Kind, String> {
    let q = a.get("queue").ok_or("missing `queue`")?;
    if entry(q).is_some() {
        return Err("a Loop node over a queue entry: not modelled".into());
    }
    let mut parts: Vec<&str> = q.split(';').collect();
    if parts.last() == Some(&"") {
        parts.pop();
    }
    let items = parts
        .iter()
        .map(|p| {
            let ok = match ty {
                LoopType::Int => p.parse::<i32>().is_ok(),
                LoopType::Double => p.parse::<f64>().is_ok(),
                LoopType::String => true,
                LoopType::Bool => matches!(*p, "true" | "false" | "1" | "0"),
            };
            ok.then(|| p.to_string())
                .ok_or(format!("queue item `{p}` is not a {ty:?}"))
        })
        .collect::<Result<_, _>>()?;
    let value = a.get("value").map(|v| match entry(v) {
        Some(e) => Ok(e.to_string()),
        None => Err(format!("`value` {v} is not an entry")),
    });
    let if_empty = match a.get("if_empty") {
        None => Status::Success,
        Some(s) => Status::parse(s).ok_or(format!("bad if_empty {s}"))?,
    };
    Ok(Kind::Loop(ty, items, value.transpose()?, if_empty))
}

/// A `SwitchN` node: `variable` and `case_1` ... `case_N` (each a literal).
fn switch(a: &Attrs, n: usize) -> Result<Kind, String> {
    let cases = (1..=n)
        .map(|i| {
            let k = format!("case_{i}");
            a.get(&k)
                .map(|v| v.trim().to_string())
                .ok_or(format!("missing `{k}`"))
        })
        .collect::<Result<_, _>>()?;
    Ok(Kind::Switch(operand(a, "variable")?, cases))
}

/// A `BlackboardCheck*` node. `return_on_mismatch` defaults to FAILURE (v3.8
/// `BlackboardPreconditionNode::tick`, `default_return_status`); besides the names it
/// takes AS2FM's numbers 1, 2, 3 (`bt_utils.py`, `BtResponse`).
fn check(a: &Attrs, ty: CheckType) -> Result<Kind, String> {
    let raw = a.get("return_on_mismatch").map(|s| s.trim());
    let mismatch = match raw {
        None => Status::Failure,
        Some("1") => Status::Success,
        Some("2") => Status::Failure,
        Some("3") => Status::Running,
        Some(s) => Status::parse(s).ok_or(format!("bad return_on_mismatch {s}"))?,
    };
    let numeric = matches!(raw, Some("1" | "2" | "3"));
    Ok(Kind::Check(
        ty,
        operand(a, "value_A")?,
        operand(a, "value_B")?,
        mismatch,
        numeric,
    ))
}

/// A bare XML element.
#[derive(Clone, Debug, Default)]
pub struct El {
    /// The element name.
    pub name: String,
    /// Its attributes, unescaped.
    pub attrs: BTreeMap<String, String>,
    /// Its child elements (text is dropped).
    pub children: Vec<El>,
}

impl El {
    /// The element as XML text (attribute values escaped).
    pub fn write(&self, out: &mut String) {
        out.push('<');
        out.push_str(&self.name);
        for (k, v) in &self.attrs {
            let v = v
                .replace('&', "&amp;")
                .replace('<', "&lt;")
                .replace('>', "&gt;")
                .replace('"', "&quot;");
            out.push_str(&format!(" {k}=\"{v}\""));
        }
        if self.children.is_empty() {
            out.push_str("/>");
            return;
        }
        out.push('>');
        for c in &self.children {
            c.write(out);
        }
        out.push_str(&format!("</{}>", self.name));
    }
}

fn start(e: &BytesStart<'_>) -> Result<El, String> {
    let mut el = El {
        name: e.name().as_ref().to_string(),
        ..El::default()
    };
    for a in e.attributes() {
        let a = a.map_err(|e| e.to_string())?;
        let k = a.key.as_ref().to_string();
        let raw: &str = &a.value;
        let v = quick_xml::escape::unescape(raw)
            .map_err(|e| e.to_string())?
            .into_owned();
        el.attrs.insert(k, v);
    }
    Ok(el)
}

/// The document's root element.
pub fn parse_xml(text: &str) -> Result<El, String> {
    let mut r = Reader::from_str(text);
    let mut stack = vec![El::default()];
    loop {
        match r.read_event().map_err(|e| e.to_string())? {
            Event::Start(e) => stack.push(start(&e)?),
            Event::Empty(e) => {
                let el = start(&e)?;
                stack.last_mut().expect("document").children.push(el);
            }
            Event::End(_) => {
                let el = stack.pop().expect("balanced");
                stack.last_mut().ok_or("unbalanced")?.children.push(el);
            }
            Event::Eof => break,
            _ => {}
        }
    }
    let doc = stack.pop().ok_or("empty")?;
    doc.children.into_iter().next().ok_or("no root".into())
}

/// Reads a tree: the `main_tree_to_execute`, else the first `<BehaviorTree>`.
pub fn read(text: &str) -> Result<Tree, String> {
    let root = parse_xml(text)?;
    let trees: BTreeMap<&str, &El> = root
        .children
        .iter()
        .filter(|c| c.name == "BehaviorTree")
        .map(|c| (c.attrs.get("ID").map_or("", |s| s.as_str()), c))
        .collect();
    let main = match root.attrs.get("main_tree_to_execute") {
        Some(id) => *trees.get(id.as_str()).ok_or(format!("no tree {id}"))?,
        None => root
            .children
            .iter()
            .find(|c| c.name == "BehaviorTree")
            .ok_or("no <BehaviorTree>")?,
    };
    let v3 = root.attrs.get("BTCPP_format").map(|f| f.trim()) == Some("3");
    let mut r = Flat {
        v3,
        trees,
        tree: Tree::default(),
        scopes: vec![Scope::default()],
        instances: 0,
        uids: 0,
    };
    let body = main.children.first().ok_or("empty <BehaviorTree>")?;
    r.node(body, None)?;
    for t in root.children.iter().filter(|c| c.name == "BehaviorTree") {
        for c in &t.children {
            names(c, &mut r.tree.names);
            r.tree.reactive_async |= reactive_async(c);
        }
    }
    Ok(r.tree)
}

/// How a SubTree instance names its entries in the caller's terms.
#[derive(Default)]
struct Scope {
    remap: BTreeMap<String, String>,
    autoremap: bool,
    prefix: String,
}

struct Flat<'a> {
    /// `BTCPP_format="3"`: a plain `<SubTree>` maps names to the caller's names.
    v3: bool,
    trees: BTreeMap<&'a str, &'a El>,
    tree: Tree,
    scopes: Vec<Scope>,
    instances: usize,
    /// BT.CPP UIDs handed out so far (SubTree nodes included).
    uids: u32,
}

impl Flat<'_> {
    /// The global name of entry `e` in the innermost scope.
    fn global(&self, e: &str, depth: usize) -> String {
        let s = &self.scopes[depth];
        if depth == 0 {
            return e.to_string();
        }
        match s.remap.get(e) {
            Some(outer) => self.global(outer, depth - 1),
            None if s.autoremap => self.global(e, depth - 1),
            None => format!("{}{e}", s.prefix),
        }
    }

    fn node(&mut self, el: &El, parent: Option<usize>) -> Result<(), String> {
        if el.name == "SubTree" || (self.v3 && el.name == "SubTreePlus") {
            return self.subtree(el, parent);
        }
        let depth = self.scopes.len() - 1;
        let mut attrs = el.attrs.clone();
        if el.name == "UnsetBlackboard" && depth > 0 {
            // `Blackboard::unset` erases the SubTree's own entry only, which a remapped
            // key may or may not be: not modelled.
            return Err("UnsetBlackboard inside a SubTree: not modelled".into());
        }
        for (k, v) in attrs.iter_mut() {
            let updated = k == "entry" && UPDATED.contains(&el.name.as_str());
            if (k == "output_key" || updated) && entry(v).is_none() {
                *v = format!("{{{}}}", v.trim());
            }
            if let Some(e) = entry(v) {
                *v = format!("{{{}}}", self.global(e, depth));
            }
        }
        let ty = match el.name.as_str() {
            "Action" | "Condition" | "Control" | "Decorator" => {
                attrs.get("ID").cloned().ok_or("node without ID")?
            }
            n => n.to_string(),
        };
        let kind = match NODES
            .iter()
            .find(|(names, _, _)| names.contains(&ty.as_str()))
        {
            Some((_, (lo, hi), make)) => {
                let n = el.children.len();
                if n < *lo || n > *hi {
                    return Err(format!("{ty}: {n} children"));
                }
                make(&attrs)?
            }
            None if el.children.is_empty() => Kind::Leaf(ty.clone()),
            None => return Err(format!("unknown node {ty}")),
        };
        // Script entries are named in the SubTree's terms: rename them as `{entry}` ports
        // are (BT.CPP 4 `Blackboard::getEntry` / `createEntry` follow the remapping).
        let rename = |p: &mut Program| p.rename(&|v: &str| self.global(v, depth));
        let mut kind = kind;
        match &mut kind {
            Kind::Script(p) | Kind::ScriptCondition(p) | Kind::Precondition(p, _) => rename(p),
            _ => {}
        }
        let mut conds = Conds::default();
        for (names, slots) in [(&PRE, &mut conds.pre), (&POST, &mut conds.post)] {
            for (name, slot) in names.iter().zip(slots.iter_mut()) {
                if let Some(v) = el.attrs.get(*name) {
                    let mut p = script::parse(v).map_err(|e| format!("{name}: {e}"))?;
                    rename(&mut p);
                    *slot = Some(p);
                }
            }
        }
        let port = |key: &str| match (&kind, attrs.get(key).and_then(|v| entry(v))) {
            (Kind::Leaf(_), Some(e)) => Some(e.to_string()),
            _ => None,
        };
        let (out, input) = (port("out"), port("in"));
        let i = self.tree.nodes.len();
        self.uids += 1;
        self.tree.nodes.push(Node {
            id: 1000 + i as u32,
            uid: self.uids,
            tag: ty,
            kind,
            children: Vec::new(),
            conds,
            subtree_body: false,
            out,
            input,
        });
        if let Some(p) = parent {
            self.tree.nodes[p].children.push(i);
        }
        for c in &el.children {
            self.node(c, Some(i))?;
        }
        Ok(())
    }

    fn subtree(&mut self, el: &El, parent: Option<usize>) -> Result<(), String> {
        let with_conds = el;
        let el = &super::subtree_cond::without_conds(el, self.v3);
        if self.scopes.len() > 16 {
            return Err("SubTrees nested too deep".into());
        }
        let id = el.attrs.get("ID").ok_or("SubTree without ID")?;
        // The SubTree node itself takes a UID in BT.CPP 4 (it is a node there).
        self.uids += 1;
        let body = *self.trees.get(id.as_str()).ok_or(format!("no tree {id}"))?;
        let mut scope = Scope {
            prefix: format!("__st{}.", self.instances),
            ..Scope::default()
        };
        self.instances += 1;
        // v4 `SubTree`: `_autoremap`, `{outer}` values. v3.8 (`xml_parsing.cpp`,
        // `XMLParser::Pimpl::recursivelyCreateTree`): a plain `SubTree` shares everything
        // with `__shared_blackboard` and maps `inner="outer"` by name; `SubTreePlus` has
        // `__autoremap` and `{outer}` values.
        let (flag, by_name) = match (self.v3, el.name.as_str()) {
            (true, "SubTree") => ("__shared_blackboard", true),
            (true, _) => ("__autoremap", false),
            (false, _) => ("_autoremap", false),
        };
        for (k, v) in &el.attrs {
            match k.as_str() {
                "ID" | "name" => {}
                f if f == flag => scope.autoremap = matches!(v.trim(), "true" | "1"),
                _ => {
                    let outer = match entry(v) {
                        Some(e) => e,
                        None if by_name => v.trim(),
                        None => return Err(format!("SubTree port {k}={v}: not an entry")),
                    };
                    scope.remap.insert(k.clone(), outer.to_string());
                }
            }
        }
        // A format-4 SubTree with pre/post conditions is a node of its own
        // (`subtree_cond.rs`): its conditions read the caller's names.
        let parent = match self.subtree_node(with_conds, parent)? {
            Some(i) => Some(i),
            None => parent,
        };
        self.scopes.push(scope);
        let first = body.children.first().ok_or("empty <BehaviorTree>")?;
        let at = self.tree.nodes.len();
        let r = self.node(first, parent);
        self.scopes.pop();
        if let Some(b) = self.tree.nodes.get_mut(at) {
            b.subtree_body = true;
        }
        r
    }
}

impl Flat<'_> {
    /// The node a format-4 `<SubTree>` with pre/post conditions becomes (BT.CPP 4
    /// `xml_parsing.cpp`, `XMLParser::PImpl::createNodeFromXML`: the SubTree node is
    /// created with the caller's blackboard and takes its `_skipIf` ... `_onHalted`
    /// attributes as conditions, not as remapped ports), pushed under `parent`, with the
    /// UID counted for the SubTree; `None` when it has none (the body is inlined).
    fn subtree_node(&mut self, el: &El, parent: Option<usize>) -> Result<Option<usize>, String> {
        let conds = super::subtree_cond::conds(el, self.v3, &|v: &str| {
            self.global(v, self.scopes.len() - 1)
        })?;
        let Some(conds) = conds else {
            return Ok(None);
        };
        let i = self.tree.nodes.len();
        self.tree.nodes.push(Node {
            id: 1000 + i as u32,
            uid: self.uids,
            tag: "SubTree".into(),
            kind: Kind::SubTree,
            children: Vec::new(),
            conds,
            subtree_body: false,
            out: None,
            input: None,
        });
        if let Some(p) = parent {
            self.tree.nodes[p].children.push(i);
        }
        Ok(Some(i))
    }
}
