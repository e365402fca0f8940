//! BehaviorTree.CPP 4's Loop nodes (LoopInt, LoopBool, LoopDouble, LoopString) over a
//! queue written in the tree, lowered under [`super::BtSemantics::Btcpp`]
//! (docs/SEMANTICS.md, "Entries that may be unset, update counters, and queues").
//!
//! The rules, BT.CPP 4.10 `include/behaviortree_cpp/decorators/loop_node.h`:
//! - `LoopNode` constructor: a `queue` that is not `{entry}` is converted when the tree
//!   is loaded (`convertFromString<SharedQueue<T>>`: split on `;`, each part converted;
//!   a part that does not convert refuses the tree). BT.CPP 4.8.2, the library the tests
//!   run, drops a last empty part (`"1;2;"` is two items).
//! - `LoopNode<T>::tick`: ticked IDLE, the node starts from a fresh copy of the queue
//!   with no child running; unless the child is RUNNING it pops the front item and
//!   writes it to `value` (`setOutput`); nothing popped and no child running answers
//!   `if_empty` (default SUCCESS) without ticking the child or setting its own status;
//!   otherwise the node sets itself RUNNING and ticks the child, resets a finished one
//!   (`resetChild`), and answers FAILURE on its FAILURE and RUNNING otherwise (a
//!   skipped child too). A halt (`DecoratorNode::halt`) halts a RUNNING child and leaves
//!   the node IDLE.
//!
//! The queue is the literal: the machine keeps the index of the next item
//! (`queue_pos`, at most the literal's length, nothing to overflow) and sends each item
//! to the blackboard machine as a write of `value` (`bt_blackboard_set_<entry>`, which
//! counts as an update, `btcpp4_blackboard.rs`). "IDLE" is "did not answer RUNNING
//! last" (`loop_active`), which holds wherever the parent resets a finished child before
//! ticking it again. Where BT.CPP may tick the node again without resetting it (the
//! condition of a two-child IfThenElse or of a WhileDoElse, `btcpp4_skip.rs`, `stale`)
//! a finished answer leaves it active too (`loop_finished`), so the next tick goes on
//! with the rest of its queue, and the parent halts it at every reset, which makes it
//! IDLE. A LoopString whose `value` entry a script names writes there its item's rank
//! among the tree's texts (`btcpp4_strings.rs`): BT.CPP creates that entry as a
//! `std::string` when it loads the tree, so the scripts read a string
//! ([`script_strings`]). A LoopDouble whose `value` entry a script names stores its items
//! there as BT.CPP does, through the blackboard machine, which may throw ([`Store`]).
//! Refused: a Loop under a BlackboardCheck (BT.CPP 3's node), a
//! queue held in an entry (`queue="{q}"`), an item that BT.CPP would not convert, a
//! number written into an entry scripts assign strings to, `_failureIf` / `_successIf`
//! on a Loop in such a place (BT.CPP then pops the queue its last run left), and a
//! `value` entry whose type is not the node's item type (the node's port types an entry
//! no one else types).

use super::blackboard::{register, set_event, Blackboard, Entry, MACHINE};
use super::btcpp4_strings::Strings;
use super::control::{Ctx, FAILURE, IS_SKIPPED, RUNNING, SKIPPED, SKIPPED_RUNNING, SUCCESS};
use super::tree::{Btcpp4, Control, Kind, LoopType, PortValue, Tree, TreeNode};
use crate::model::source::{Diagnostic, SourceMap};
use crate::model::types::Scalar;
use crate::model::xml::Element;

/// The node's name in a tree.
pub(super) fn loop_name(t: LoopType) -> &'static str {
    match t {
        LoopType::Int => "LoopInt",
        LoopType::Bool => "LoopBool",
        LoopType::Double => "LoopDouble",
        LoopType::String => "LoopString",
    }
}

/// The type `OutputPort<T>("value")` gives an entry no one else types.
fn port_type(t: LoopType) -> &'static str {
    match t {
        LoopType::Int => "int32",
        LoopType::Bool => "bool",
        LoopType::Double => "float64",
        LoopType::String => "string",
    }
}

/// What a Loop node's `value` port says when it types an entry (for errors).
fn why(t: LoopType) -> String {
    format!("port `value` of {}", loop_name(t))
}

/// What a script gives an entry only scripts type (`btcpp4_script.rs`, `resolve`).
const SCRIPT: &str = "a script";

/// Before the nodes are lowered: types the entry Loop node `i` writes (after the ports
/// of plugins and BlackboardChecks and SetBlackboard's constants, before scripts), and
/// refuses a Loop node under a BlackboardCheck (BT.CPP 3's node). An entry a script
/// (or UnsetBlackboard) names is a script's, `int64`, as `btcpp4_script.rs` types it:
/// the Loop writes numbers there (found against 4.8.2, docs/SEMANTICS.md); any other
/// takes the port's type.
pub(super) fn prepare(
    sm: &SourceMap,
    tree: &Tree,
    i: usize,
    t: LoopType,
    bb: &mut Blackboard,
    errs: &mut Vec<Diagnostic>,
) {
    let n = &tree.nodes[i];
    if super::btcpp4_skip::under_check(tree, i) {
        errs.push(sm.diag(
            n.span,
            format!("{}: {}", loop_name(t), super::btcpp4_skip::BB_CHECK),
        ));
    }
    // Where BT.CPP may tick the node again without resetting it (`btcpp4_skip.rs`,
    // `stale`), a `_failureIf` / `_successIf` that answers while it is IDLE leaves its
    // status FAILURE / SUCCESS without running `LoopNode::tick`: the next tick finds it
    // not IDLE and pops from the queue its last run left, none before its first run
    // (4.8.2 measured: `<IfThenElse><LoopInt _failureIf="true" queue="1">..` answers
    // FAILURE, then SUCCESS from `if_empty`). The model starts a fresh queue there.
    if super::btcpp4_skip::stale(tree, i) {
        for c in &n.conds {
            if c.attr == "_failureIf" || c.attr == "_successIf" {
                errs.push(sm.diag(
                    c.name_span,
                    format!("`{}` on {} as the condition of a two-child IfThenElse or of a WhileDoElse: when it answers, BehaviorTree.CPP keeps that status and ticks the Loop next time without a reset, popping the queue its last run left (none before its first run), which is not modelled", c.attr, loop_name(t)),
                ));
            }
        }
    }
    if let Some(p) = n.port("value") {
        if let PortValue::Blackboard(g) = &p.value {
            if !bb.declared.contains(g) {
                bb.declared.push(g.clone());
            }
            if bb.entry(g).is_none() && scripted(tree, g) {
                bb.entries.push(Entry {
                    name: g.clone(),
                    ty: super::btcpp4_script::entry_type(bb, g).into(),
                    span: p.span,
                    why: SCRIPT.into(),
                });
                if !bb.script_entries.contains(g) {
                    bb.script_entries.push(g.clone());
                }
            } else if bb.entry(g).is_none() {
                register(sm, bb, g, port_type(t), p.span, &why(t), errs);
            }
        }
    }
}

/// The parts of a queue written in the tree: split on `;` (`splitString`), 4.8.2 dropping
/// a last empty part (`"1;2;"` is two items).
fn parts(q: &str) -> Vec<&str> {
    let mut parts: Vec<&str> = q.split(';').collect();
    if parts.last() == Some(&"") {
        parts.pop();
    }
    parts
}

/// Before the scripts' strings are interned (`btcpp4_strings.rs`, `prepare`): each
/// LoopString whose `value` is an entry a script names, with the texts of its queue.
/// BT.CPP 4 creates that entry as a `std::string` when it loads the tree (the node's
/// `OutputPort<std::string>("value")`, BT.CPP 4.10 `src/xml_parsing.cpp`,
/// `XMLParser::PImpl::createNodeFromXML`, creates a remapped entry with the port's
/// type), so it holds strings: a script compares it as a string, a script's string is
/// stored there, and a number assigned to it throws (4.8.2, measured:
/// `tests/tests/bt_real.rs`, `loop_strings_in_scripts_agree_with_the_real_library`).
/// Entries a SetBlackboard writes are left out (the lowering refuses them, [`lower`]).
pub(super) fn script_strings(tree: &Tree, bb: &Blackboard) -> Vec<(String, Vec<String>)> {
    let mut out = Vec::new();
    for n in &tree.nodes {
        if n.kind != Kind::Control(Control::Btcpp4(Btcpp4::Loop(LoopType::String))) {
            continue;
        }
        let (Some(PortValue::Blackboard(g)), Some(PortValue::Literal(q))) = (
            n.port("value").map(|p| &p.value),
            n.port("queue").map(|p| &p.value),
        ) else {
            continue;
        };
        if bb.texts.contains(g) || !scripted(tree, g) {
            continue;
        }
        out.push((
            g.clone(),
            parts(q).into_iter().map(str::to_string).collect(),
        ));
    }
    out
}

/// Whether a script of the tree names entry `g`.
fn scripted(tree: &Tree, g: &str) -> bool {
    tree.nodes.iter().any(|m| {
        m.script_names
            .iter()
            .any(|(_, v)| matches!(v, PortValue::Blackboard(x) if x == g))
    })
}

/// Item `s` of a queue as `convertFromString<T>` reads it (a whole number, `true` or
/// `false`, a decimal number with a point, a string's model expression); `Err` says why
/// BT.CPP refuses it.
fn item(t: LoopType, s: &str) -> Result<String, BadItem> {
    match t {
        // `convertFromString<int>`: a whole number in range, nothing around it.
        LoopType::Int => {
            let digits = s.strip_prefix('-').unwrap_or(s);
            if !digits.is_empty()
                && digits.chars().all(|c| c.is_ascii_digit())
                && s.parse::<i32>().is_ok()
            {
                Ok(s.to_string())
            } else {
                Err(BadItem::NotInt(s.to_string()))
            }
        }
        // `convertFromString<bool>`.
        LoopType::Bool => match s {
            "1" | "true" | "True" | "TRUE" => Ok("true".into()),
            "0" | "false" | "False" | "FALSE" => Ok("false".into()),
            _ => Err(BadItem::NotBool(s.to_string())),
        },
        LoopType::Double => {
            let numeric = !s.is_empty()
                && s.chars()
                    .all(|c| c.is_ascii_digit() || matches!(c, '.' | 'e' | 'E' | '-' | '+'));
            match s.parse::<f64>() {
                Ok(x) if numeric && x.is_finite() => {
                    let d = format!("{x}");
                    Ok(if d.contains('.') { d } else { format!("{d}.0") })
                }
                _ => Err(BadItem::NotDouble(s.to_string())),
            }
        }
        LoopType::String => Ok(super::plugin::literal_expr(s, "string")),
    }
}

/// Item `x` (as [`item`] reads it; `raw`, as the queue writes it) written into entry
/// `e`: its model expression, or why that is not modelled.
fn written(t: LoopType, raw: &str, x: &str, e: &Entry, strs: &Strings) -> Result<String, BadItem> {
    if strs.holds(&e.name) {
        // An entry holding strings that scripts read (see [`script_strings`]): a
        // LoopString's item is stored as its text's rank (`btcpp4_strings.rs`).
        return match t {
            LoopType::String => Ok(strs.id(raw).to_string()),
            _ => Err(BadItem::NumberInText),
        };
    }
    let s = Scalar::from_name(e.ty.trim());
    if float_entry(e) {
        // A script's entry kept as a float (`btcpp4_script/num.rs`): every number goes
        // in as one, the blackboard machine deciding what BT.CPP stores ([`Store`]).
        return match t {
            LoopType::Int => Ok(format!("{x}.0")),
            LoopType::Bool => Ok(if x == "true" { "1.0" } else { "0.0" }.into()),
            LoopType::Double => Ok(x.to_string()),
            LoopType::String => Err(BadItem::StringInNumber),
        };
    }
    if e.why == SCRIPT {
        // A script's entry holds a number: an int or a bool item is written as one
        // (true is 1), a double only when whole (BT.CPP throws "Invalid floating point
        // to integer conversion" otherwise), a string throws ("Any::copyInto fails").
        return match t {
            LoopType::Int => Ok(x.to_string()),
            LoopType::Bool => Ok(if x == "true" { "1" } else { "0" }.into()),
            LoopType::Double => match x.parse::<f64>() {
                Ok(d) if d.fract() == 0.0 && d.abs() < 9.0e15 => Ok(format!("{}", d as i64)),
                _ => Err(BadItem::NotWhole(x.to_string())),
            },
            LoopType::String => Err(BadItem::StringInNumber),
        };
    }
    let fits = match t {
        LoopType::Int => s.is_some_and(|s| s.int_range().is_some()),
        LoopType::Bool => s == Some(Scalar::Bool),
        LoopType::Double => matches!(s, Some(Scalar::F32 | Scalar::F64)),
        LoopType::String => s == Some(Scalar::Str),
    };
    if fits {
        Ok(x.to_string())
    } else {
        Err(BadItem::Unmodelled(port_type(t)))
    }
}

/// Whether `e` is an entry only scripts and Loop nodes write that the model keeps as a
/// float beside its `bt_dbl__` flag (`btcpp4_script/num.rs`, `float_entries`: among
/// them every entry a LoopDouble writes and a script names).
fn float_entry(e: &Entry) -> bool {
    e.why == SCRIPT && e.ty == "float64"
}

/// A Loop's write into a float entry ([`float_entry`]), which the blackboard machine
/// makes as BT.CPP 4.10 `LoopNode<T>::tick` does it (`setOutput`, `Blackboard::set`,
/// then `Any::copyInto` into the entry's value): into an entry holding nothing (the
/// port created it empty when the tree was loaded, or UnsetBlackboard erased it) the
/// item goes in as it is, so the entry then holds a `double` for a LoopDouble and an
/// integer for a LoopInt or LoopBool; into an entry holding a `double` any item is
/// converted to one; into an entry holding an integer a double must be whole, else
/// BT.CPP throws ("Invalid floating point to integer conversion", 4.8.2 measured:
/// `tests/bt/btcpp4/loop.toml`). The node waits for the machine's answer before it
/// ticks its child, so a throw stops the tree before the child runs, as BT.CPP's does.
#[derive(Clone, Copy, Debug)]
struct Store {
    /// The item is a `double` (a LoopDouble's).
    dbl: bool,
    /// The item converts to an integer (`int64_t`) without a throw.
    whole: bool,
}

impl Store {
    fn of(t: LoopType, x: &str) -> Store {
        match t {
            LoopType::Double => Store {
                dbl: true,
                whole: x
                    .parse::<f64>()
                    .is_ok_and(|d| d.fract() == 0.0 && d.abs() < 9.223_372_036_854_776e18),
            },
            _ => Store {
                dbl: false,
                whole: true,
            },
        }
    }
}

/// The event Loop node `id` sends the blackboard machine to store an item in a float
/// entry ([`Store`]), with the item (`value`) and what it is (`dbl`, `whole`).
fn store_event(id: u32) -> String {
    format!("bt_loop_{id}_store")
}

/// The blackboard machine's answer to Loop node `id`: the item is stored.
fn stored_event(id: u32) -> String {
    format!("bt_loop_{id}_stored")
}

/// The blackboard machine's transition that stores Loop node `id`'s items in float
/// entry `g` and answers `me` ([`Store`]).
fn store_transition(b: super::build::B, bb: &Blackboard, id: u32, g: &str, me: &str) -> Element {
    use super::btcpp4_script::{dbl, has, FAULT};
    let (h, d) = (has(g), dbl(g));
    let mut body = vec![
        b.assign(&d, &format!("({h} ? {d} : _event.data.dbl)")),
        b.assign(g, "_event.data.value"),
        b.assign(&h, "true"),
    ];
    body.extend(super::btcpp4_blackboard::count_write(bb, b, g));
    body.push(b.send(&stored_event(id), me));
    let throws = format!("{h} && !{d} && !_event.data.whole");
    let chain = b
        .if_chain(vec![(throws, vec![b.assign(FAULT, "true")])], body)
        .expect("one branch");
    b.tr(Some(&store_event(id)), None, Some("idle"), vec![chain])
}

/// Why [`item`] refuses a queue's item or [`written`] does not model writing it.
#[derive(Debug, Clone, PartialEq, Eq)]
enum BadItem {
    /// Not a whole number of 32 bits (the item).
    NotInt(String),
    /// Not a boolean.
    NotBool(String),
    /// Not a finite decimal number.
    NotDouble(String),
    /// A number not whole, written into an entry a script holds a number in.
    NotWhole(String),
    /// A string written into an entry a script holds a number in.
    StringInNumber,
    /// A number written into an entry a script assigns strings to.
    NumberInText,
    /// An item of this type in an entry of another.
    Unmodelled(&'static str),
}

impl std::fmt::Display for BadItem {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            BadItem::NotInt(s) => write!(f, "`{s}` is not a whole number of 32 bits"),
            BadItem::NotBool(s) => write!(f, "`{s}` is not a boolean (true, false, 1, 0)"),
            BadItem::NotDouble(s) => write!(f, "`{s}` is not a finite decimal number"),
            BadItem::NotWhole(x) => write!(f, "the item {x} is not whole, and BehaviorTree.CPP throws writing it into an entry a script holds a number in (\"Invalid floating point to integer conversion\"): not modelled"),
            BadItem::StringInNumber => f.write_str("BehaviorTree.CPP throws writing a string into an entry a script holds a number in (\"Any::copyInto fails\"): not modelled"),
            BadItem::NumberInText => f.write_str("a script assigns strings to that entry, which BehaviorTree.CPP 4 creates with the Loop's item type when it loads the tree (`OutputPort<T>(\"value\")`), and then converts the script's text to it (4.8.2: \"Can't convert string [a] to integer\"): not modelled"),
            BadItem::Unmodelled(ty) => write!(f, "a {ty} item in that entry is not modelled"),
        }
    }
}

/// Checks Loop node `n` and builds its machine.
pub(super) fn lower(
    sm: &SourceMap,
    t: LoopType,
    n: &TreeNode,
    ctx: &Ctx,
    bb: &mut Blackboard,
    errs: &mut Vec<Diagnostic>,
) -> Option<Element> {
    let name = loop_name(t);
    let before = errs.len();
    let mut raw: Vec<&str> = Vec::new();
    let items: Vec<String> = match n.port("queue").map(|p| (&p.value, p.span)) {
        None => {
            errs.push(sm.diag(n.span, format!("{name} needs `queue`")));
            return None;
        }
        Some((PortValue::Blackboard(q), span)) => {
            errs.push(sm.diag(
                span,
                format!("`queue` of {name} is the entry `{{{q}}}`: a queue held in the blackboard is not modelled; write the items in the tree (`queue=\"1;2;3\"`). In BT.CPP 4.8.2 the port types `{q}` as a queue when the tree loads, every text written there (SetBlackboard, a script) becomes a fresh queue at the write (an item that does not convert throws there), and the node pops that queue in place: a restart without a new write finds it empty, a write while it loops replaces what is left (4.10 converts a text at its first pop instead, into a copy of its own)"),
            ));
            return None;
        }
        Some((PortValue::Literal(q), span)) => {
            let mut out = Vec::new();
            for (k, p) in parts(q).into_iter().enumerate() {
                match item(t, p) {
                    Ok(x) => {
                        out.push(x);
                        raw.push(p);
                    }
                    Err(why) => errs.push(sm.diag(
                        span,
                        format!("item {} of the `queue` of {name}: {why}, so BehaviorTree.CPP refuses the tree when it loads it (`convertFromString`)", k + 1),
                    )),
                }
            }
            out
        }
    };
    // `InputPort<NodeStatus>("if_empty", NodeStatus::SUCCESS, ..)`, read with
    // `convertFromString<NodeStatus>`.
    let if_empty = match n.port("if_empty").map(|p| (&p.value, p.span)) {
        None => SUCCESS,
        Some((PortValue::Literal(v), span)) => match v.trim() {
            "SKIPPED" => SKIPPED,
            s => match super::control::status_code(s) {
                Some(c) => c,
                None => {
                    errs.push(sm.diag(
                        span,
                        format!("`if_empty` of {name}: `{s}` is not SUCCESS, FAILURE, RUNNING or SKIPPED"),
                    ));
                    SUCCESS
                }
            },
        },
        Some((PortValue::Blackboard(e), span)) => {
            errs.push(sm.diag(
                span,
                format!("`if_empty` of {name} must be a constant status; a blackboard entry (`{{{e}}}`) is not supported here"),
            ));
            SUCCESS
        }
    };
    let value = match n.port("value").map(|p| (&p.value, p.span)) {
        None => None,
        Some((PortValue::Literal(v), span)) => {
            errs.push(sm.diag(
                span,
                format!(
                    "`value` of {name} is an output: write the entry it goes to, `{{{}}}`",
                    v.trim()
                ),
            ));
            None
        }
        Some((PortValue::Blackboard(g), span)) => match bb.entry(g).cloned() {
            // `prepare` typed it or reported why not.
            None => None,
            Some(_) if bb.texts.contains(g) => {
                errs.push(sm.diag(
                    span,
                    format!("`value` of {name} writes `{g}`, which a SetBlackboard writes too: BehaviorTree.CPP 4 holds SetBlackboard's text there, which is not modelled"),
                ));
                None
            }
            Some(e) => {
                let mut exprs = Vec::with_capacity(items.len());
                let float = float_entry(&e);
                for (x, r) in items.iter().zip(&raw) {
                    match written(t, r, x, &e, &bb.strings) {
                        Ok(v) => exprs.push((v, float.then(|| Store::of(t, x)))),
                        Err(why) => {
                            let at = sm.diag(e.span, "");
                            errs.push(sm.diag(
                                span,
                                format!("`value` of {name} writes its items to `{g}`, which is {} at {}:{}:{} ({}): {why}", e.ty, at.file, at.line, at.col, e.why),
                            ));
                            break;
                        }
                    }
                }
                Some((g.clone(), exprs))
            }
        },
    };
    (errs.len() == before).then(|| {
        let writes: Vec<Option<Write>> = value.map_or_else(
            || vec![None; items.len()],
            |(g, xs)| {
                xs.into_iter()
                    .map(|(value, store)| {
                        Some(Write {
                            entry: g.clone(),
                            value,
                            store,
                        })
                    })
                    .collect()
            },
        );
        if let Some(Some(w)) = writes
            .iter()
            .find(|w| w.as_ref().is_some_and(|w| w.store.is_some()))
        {
            bb.scripts
                .push(store_transition(ctx.b, bb, ctx.id, &w.entry, &ctx.machine));
        }
        machine(ctx, &writes, if_empty)
    })
}

/// One item's write into the `value` entry.
#[derive(Clone, Debug)]
struct Write {
    entry: String,
    /// The item's model expression.
    value: String,
    /// `Some` for a float entry: the blackboard machine stores it and answers
    /// ([`Store`]); `None`: sent as any other write of the entry.
    store: Option<Store>,
}

/// The Loop node's machine over the queue's items: each item's write, if `value` is
/// given.
fn machine(ctx: &Ctx, items: &[Option<Write>], if_empty: u8) -> Element {
    let b = &ctx.b;
    let (pos, cr, active, fin) = (
        "queue_pos",
        "loop_child_running",
        "loop_active",
        "loop_finished",
    );
    let len = items.len();
    let mut m = b.scxml(&ctx.machine, "wait_for_tick");
    let mut data = vec![
        (pos, "int32", "0".to_string()),
        (cr, "bool", "false".to_string()),
        (active, "bool", "false".to_string()),
    ];
    if ctx.stale {
        data.push((fin, "bool", "false".to_string()));
    }
    // A finished answer (`done`) or not: IDLE afterwards, except where BT.CPP may tick
    // the node again without a reset (`Ctx::stale`), where it keeps its finished
    // status until the parent's reset (a halt).
    let finished = |done: bool| {
        if ctx.stale {
            vec![
                b.assign(active, "true"),
                b.assign(fin, if done { "true" } else { "false" }),
            ]
        } else if done {
            vec![b.assign(active, "false")]
        } else {
            Vec::new()
        }
    };
    let flags = ctx.running_data();
    data.extend(flags.iter().map(|(v, t, e)| (v.as_str(), *t, e.clone())));
    m.push(b.datamodel(&data));
    // Ticked IDLE: a fresh copy of the queue, no child running.
    let mut w = b.state("wait_for_tick").with_child(b.tr(
        Some(&ctx.tick_ev()),
        Some(&format!("!{active}")),
        Some("popping"),
        vec![b.assign(pos, "0"), b.assign(cr, "false")],
    ));
    w.push(b.tr(Some(&ctx.tick_ev()), None, Some("popping"), vec![]));
    // `DecoratorNode::halt`: the child halted if RUNNING, the node IDLE.
    let finished_clear = if ctx.stale {
        vec![b.assign(fin, "false")]
    } else {
        Vec::new()
    };
    let r = ctx.running_var(0);
    if let Some(r) = &r {
        w.push(
            b.tr(
                Some(&ctx.halt_ev()),
                Some(&format!("!{r}")),
                Some("wait_for_tick"),
                [
                    vec![b.assign(active, "false")],
                    finished_clear.clone(),
                    vec![ctx.respond_halted()],
                ]
                .concat(),
            ),
        );
    }
    w.push(b.tr(
        Some(&ctx.halt_ev()),
        None,
        Some("halting_child"),
        [vec![b.assign(active, "false")], finished_clear.clone()].concat(),
    ));
    m.push(w);
    let mut p = b.state("popping");
    // Pop the front item into `value`.
    let mut pop = Vec::new();
    // A store into a float entry waits for the blackboard machine's answer ([`Store`]).
    let stores = items.iter().flatten().any(|w| w.store.is_some());
    let writes = items
        .iter()
        .enumerate()
        .filter_map(|(i, w)| {
            let w = w.as_ref()?;
            let send = match w.store {
                None => b.send_params(&set_event(&w.entry), MACHINE, &[("value", &w.value)]),
                Some(s) => b.send_params(
                    &store_event(ctx.id),
                    MACHINE,
                    &[
                        ("value", &w.value),
                        ("dbl", if s.dbl { "true" } else { "false" }),
                        ("whole", if s.whole { "true" } else { "false" }),
                    ],
                ),
            };
            Some((format!("{pos} == {i}"), vec![send]))
        })
        .collect();
    pop.extend(b.if_chain(writes, Vec::new()));
    pop.push(b.assign(pos, &format!("{pos} + 1")));
    pop.push(b.assign(active, "true"));
    pop.extend(finished_clear.clone());
    p.push(b.tr(
        None,
        Some(&format!("!{cr} && {pos} < {len}")),
        Some(if stores { "storing" } else { "tick_child" }),
        pop,
    ));
    p.push(b.tr(
        None,
        Some(cr),
        Some("tick_child"),
        [vec![b.assign(active, "true")], finished_clear.clone()].concat(),
    ));
    // Nothing popped, no child running: `if_empty`, the node's status left as it was
    // (a SKIPPED is not stored, `TreeNode::executeTick`).
    // Where BT.CPP may tick the node again without a reset (`Ctx::stale`), a finished
    // answer leaves it non-IDLE (`loop_finished`): only the parent's reset (a halt)
    // makes it IDLE again, and a SKIPPED then is 4 (its status is not RUNNING).
    let running_now = if ctx.stale {
        format!("{active} && !{fin}")
    } else {
        active.to_string()
    };
    let empty = match if_empty {
        SKIPPED => vec![b
            .if_chain(
                vec![(running_now, vec![ctx.respond(SKIPPED_RUNNING)])],
                vec![ctx.respond(SKIPPED)],
            )
            .expect("one branch")],
        RUNNING => [
            finished(false),
            vec![b.assign(active, "true"), ctx.respond(RUNNING)],
        ]
        .concat(),
        s => [finished(true), vec![ctx.respond(s)]].concat(),
    };
    p.push(b.tr(None, None, Some("wait_for_tick"), empty));
    m.push(p);
    if stores {
        m.push(b.state("storing").with_child(b.tr(
            Some(&stored_event(ctx.id)),
            None,
            Some("tick_child"),
            vec![],
        )));
    }
    let mut t = b.state_entry("tick_child", vec![ctx.tick_child(0)]);
    for (s, answer) in [(SUCCESS, RUNNING), (FAILURE, FAILURE), (RUNNING, RUNNING)] {
        let mut body = vec![b.assign(cr, if s == RUNNING { "true" } else { "false" })];
        body.extend(finished(s == FAILURE));
        body.push(ctx.respond(answer));
        t.push(b.tr(
            Some(&ctx.child_resp(0)),
            Some(&format!("_event.data.status == {s}")),
            Some("wait_for_tick"),
            ctx.marked(0, s, body),
        ));
    }
    // A skipped child: not RUNNING to the node, RUNNING (code 5) to its halts.
    let mut body: Vec<Element> = ctx.mark_skipped(0).into_iter().collect();
    body.push(b.assign(cr, "false"));
    body.push(ctx.respond(RUNNING));
    t.push(b.tr(
        Some(&ctx.child_resp(0)),
        Some(IS_SKIPPED),
        Some("wait_for_tick"),
        body,
    ));
    m.push(t);
    m.push(ctx.halting_child_state());
    m
}
