//! Behavior trees: a BehaviorTree.cpp XML tree and its SCXML leaf plugins lowered to
//! one machine per tree node, plus the machine that ticks the root and the blackboard.
//!
//! # What comes out
//!
//! The machines of AS2FM's translation, with its names, so probabilities and traces can
//! be compared one to one:
//! Both `BTCPP_format` 3 and 4 are read (`tree.rs`); the machines are the same for both,
//! AS2FM's, whose node models do not depend on the format.
//!
//! - `bt_root_fsm_<tree file stem>` ticks node 1000 (`bt_1000_tick`) at every event of
//!   the ROS timer `<stem>_tick` (a `<ros_time_rate>` / `<ros_rate_callback>` pair the
//!   ROS lowering turns into time) and waits for `bt_1000_response`. Without
//!   `tick_if_not_running` it stops ticking after the first answer that is not RUNNING.
//! - `BT_plugin_<id>_<name>` for every node, numbered 1000, 1001, ... in depth-first
//!   pre-order, named after the node's `name` attribute or else its type. Built-in nodes
//!   (Sequence, ReactiveSequence, SequenceWithMemory, Fallback, ReactiveFallback,
//!   Parallel, IfThenElse, Inverter, ForceSuccess, ForceFailure, Repeat,
//!   RetryUntilSuccessful, AlwaysSuccess, AlwaysFailure, SetBlackboard,
//!   BlackboardCheckInt / Double / String / Bool) are generated (`control.rs` and the
//!   files it dispatches to, `blackboard.rs`; under BT.CPP's rules also BT.CPP 4's own
//!   nodes, `btcpp4.rs`, and Timeout, Delay, Sleep and TryCatch, `btcpp4_time.rs`, whose
//!   timers the root machine keeps, UnsetBlackboard and the entry-updated nodes,
//!   `btcpp4_blackboard.rs`, and the Loop nodes, `btcpp4_loop.rs`); leaves are instances of their plugin
//!   (`plugin.rs`) and keep their ROS tags for the ROS lowering.
//! - `bt_blackboard_fsm` when the tree names `{entries}`.
//!
//! A parent ticks a child with `bt_<id>_tick`; the child answers `bt_<id>_response` with
//! `status` 1 (SUCCESS), 2 (FAILURE) or 3 (RUNNING). Halting is `bt_<id>_halt`, answered
//! by `bt_<id>_halt_response` (to every child, as AS2FM does; [`Halts::WhenNeeded`] only
//! where a halt can change something). SubTrees (which AS2FM rejects) are inlined; their
//! blackboard entries are private unless remapped or `_autoremap="true"`.
//!
//! Every generated element carries the span of the tree node or plugin tag it comes from.

mod blackboard;
mod btcpp;
mod btcpp4;
mod btcpp4_blackboard;
mod btcpp4_conds;
mod btcpp4_loop;
mod btcpp4_script;
mod btcpp4_skip;
mod btcpp4_strings;
mod btcpp4_subtree;
mod btcpp4_switch;
mod btcpp4_time;
mod build;
mod control;
mod decorators;
mod notes;
mod parallel;
mod plugin;
mod script;
mod sequences;
mod tree;

use crate::model::source::{Diagnostic, FileId, SourceMap};
use crate::model::xml::{self, Element};
use build::B;
use control::Ctx;
use control::HaltEffect;
use tree::{Control, Kind, PortValue};

/// What the main file says about the behavior tree.
#[derive(Clone, Debug, PartialEq)]
pub struct BtInput {
    /// The BehaviorTree.cpp XML file.
    pub tree: FileId,
    /// The plugin files (`.ascxml`, or `.scxml` with BT tags), one node type each.
    pub plugins: Vec<FileId>,
    /// How often the root is ticked, in ticks per second (`bt_tick_rate`).
    pub tick_rate_hz: f64,
    /// Whether the root is ticked again after it answered SUCCESS or FAILURE
    /// (`bt_tick_if_not_running`).
    pub tick_if_not_running: bool,
    /// Which children the built-in control nodes halt (AS2FM's semantics only; under
    /// BT.CPP's a node halts exactly its RUNNING children).
    pub halts: Halts,
    /// Whose rules the built-in nodes and the root machine follow.
    pub semantics: BtSemantics,
}

/// Whose rules the tree's built-in nodes follow where AS2FM's SCXML models of them and
/// what BehaviorTree.CPP 4 executes differ (README, "BT semantics").
///
/// The machines, their names and the `bt_<id>_tick` / `bt_<id>_response` /
/// `bt_<id>_halt` events are the same under both, so traces and properties read the same
/// names; what differs is which halts are sent, Parallel's counting, SequenceWithMemory's
/// memory, and the wake-up yields of BT.CPP 4 (`btcpp.rs`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum BtSemantics {
    /// AS2FM's node models (`*.ascxml` of its `bt_nodes`), one for one: the reference
    /// probabilities of the corpus come from them.
    #[default]
    As2fm,
    /// BehaviorTree.CPP 4 as it runs a tree created from XML, ticked by `tick`.
    Btcpp {
        /// How the executor ticks the root.
        tick: BtTick,
    },
}

/// How BehaviorTree.CPP's executor ticks the root (BT.CPP 4 `bt_factory.cpp`,
/// `Tree::tickRoot`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum BtTick {
    /// `Tree::tickOnce()` (what `tickWhileRunning` and the ROS 2 executors call): while
    /// the root answers RUNNING and a node emitted the wake-up signal since the signal was
    /// last taken, the root is ticked again at once.
    #[default]
    Once,
    /// `Tree::tickExactlyOnce()`: one tick of the root per timer event, wake-ups ignored.
    ExactlyOnce,
}

impl BtSemantics {
    /// The name on the command line: `as2fm`, `btcpp` (`tickOnce`) or
    /// `btcpp-exactly-once`.
    pub fn label(self) -> &'static str {
        match self {
            BtSemantics::As2fm => "as2fm",
            BtSemantics::Btcpp { tick: BtTick::Once } => "btcpp",
            BtSemantics::Btcpp {
                tick: BtTick::ExactlyOnce,
            } => "btcpp-exactly-once",
        }
    }

    /// The semantics [`BtSemantics::label`] names (`None`: no such label).
    pub fn from_label(label: &str) -> Option<Self> {
        [
            BtSemantics::As2fm,
            BtSemantics::Btcpp { tick: BtTick::Once },
            BtSemantics::Btcpp {
                tick: BtTick::ExactlyOnce,
            },
        ]
        .into_iter()
        .find(|b| b.label() == label)
    }
}

/// Which children a built-in control node halts when it finishes or is halted.
///
/// Both give the same ROS messages (topics, services, actions) in the same order at the
/// same times under one schedule (`host/tests/bt_halts.rs`); they differ in the
/// `bt_<id>_halt` / `bt_<id>_halt_response` messages between tree nodes. They do not
/// give the same verdict probabilities: the simulator picks uniformly among the machines
/// that can move, so a tree that takes fewer steps to reach a leaf wins more of the
/// races it runs against other machines at the same instant. On the museum guide,
/// [`Halts::WhenNeeded`] makes the GoToPoi skill see a navigation result one tick late
/// in about 3 runs of 100 (`hindsight verify --seed 1` finds the alarm response at
/// 6.2 s holding with probability 0.986 instead of 1), which moves its threshold from
/// 6.2 s to 6.3 s; hence AS2FM's rule is the default.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Halts {
    /// Every child, each with a halt round trip, as AS2FM's translation does: the
    /// machines are AS2FM's one for one.
    #[default]
    As2fm,
    /// Only the children a halt can change: BehaviorTree.cpp halts only RUNNING
    /// children, and halting an idle child whose halt runs no user code (a leaf plugin
    /// without `<bt_halt>`, a built-in node over such children) changes nothing. Control
    /// nodes remember which such children last answered RUNNING; a child with user halt
    /// code (or SequenceWithMemory, which keeps its place across answers) is halted
    /// whenever AS2FM halts it. On the museum guide: 29 % fewer trace points per run
    /// (50,500 against 70,900), and 1.3 times the runs per second (`benches/museum.rs`).
    WhenNeeded,
}

/// The name of the machine that ticks the tree read from `tree`: `bt_root_fsm_<stem>`.
pub(crate) fn root_machine_name(sm: &SourceMap, tree: FileId) -> String {
    format!("bt_root_fsm_{}", stem(sm, tree))
}

fn stem(sm: &SourceMap, tree: FileId) -> String {
    let s = sm
        .source(tree)
        .and_then(|f| f.path().file_stem())
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "bt".into());
    s.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect()
}

/// Lowers the tree and its plugins to SCXML element trees: the root machine first, then
/// one machine per node in id order, then the blackboard machine if any. Plugins keep
/// their ROS tags; the root machine's timer is a ROS timer tag. Every error is returned,
/// each with the file, line and column it is about.
pub fn lower(sm: &SourceMap, input: &BtInput) -> Result<Vec<Element>, Vec<Diagnostic>> {
    let mut errs = Vec::new();
    let mut plugins: Vec<plugin::Plugin> = Vec::new();
    for &f in &input.plugins {
        match plugin::read(sm, f) {
            Ok(p) => {
                if let Some(q) = plugins.iter().find(|q| q.name == p.name) {
                    let at = sm.diag(q.root.span, "");
                    errs.push(sm.diag(
                        p.root.span,
                        format!(
                            "two plugins are called `{}` (the other is {}:{}:{})",
                            p.name, at.file, at.line, at.col
                        ),
                    ));
                }
                plugins.push(p);
            }
            Err(ds) => errs.extend(ds),
        }
    }
    let root_el = xml::parse(sm, input.tree).map_err(|d| vec![d])?;
    if !(input.tick_rate_hz.is_finite() && input.tick_rate_hz > 0.0) {
        errs.push(sm.diag(
            root_el.span,
            format!(
                "the tree's tick rate must be a positive number of ticks per second, not {}",
                input.tick_rate_hz
            ),
        ));
    }
    let tree = match tree::read(sm, &root_el, &plugins) {
        Ok(t) => t,
        Err(ds) => {
            errs.extend(ds);
            return Err(errs);
        }
    };
    let root_name = root_machine_name(sm, input.tree);
    let mut bb = blackboard::Blackboard::default();
    // Entry types first (plugins' ports, BlackboardCheck's values, SetBlackboard's
    // constants), so every node knows the type of what it reads and writes.
    blackboard::type_entries(sm, &tree, &plugins, &mut bb, &mut errs);
    // Then the entries the entry-updated nodes watch and the Loop nodes write.
    if input.semantics != BtSemantics::As2fm {
        btcpp4_blackboard::prepare(sm, &tree, &mut bb, &mut errs);
        btcpp4_strings::prepare(&tree, &mut bb);
    }
    let effects = halt_effects(&tree, &plugins);
    // The clock of the timed nodes (Timeout, Delay, Sleep), kept by the root machine.
    let clock = match input.semantics {
        BtSemantics::As2fm => None,
        BtSemantics::Btcpp { .. } => btcpp4_time::clock(
            sm,
            &tree,
            &control::format_rate(input.tick_rate_hz),
            &mut errs,
        ),
    };
    let mut out = Vec::with_capacity(tree.nodes.len() + 2);
    let root_b = B {
        at: tree.nodes[0].span,
    };
    let timer = format!("{}_tick", stem(sm, input.tree));
    let btcpp = input.semantics != BtSemantics::As2fm;
    // Under BT.CPP's rules a node with pre/post conditions talks to its parent through
    // its conditions' machine (`btcpp4_conds.rs`); the root to the root machine too.
    let wrapped = |i: usize| btcpp && btcpp4_conds::wrapped(&tree, i);
    let root_node = if wrapped(0) {
        (
            btcpp4_conds::stem(&tree.nodes[0]),
            btcpp4_conds::machine_name(&tree.nodes[0]),
        )
    } else {
        (tree.nodes[0].id.to_string(), tree.nodes[0].machine.clone())
    };
    let root_node = (root_node.0.as_str(), root_node.1.as_str());
    out.push(control::root_machine(
        root_b,
        &root_name,
        &timer,
        input.tick_rate_hz,
        root_node,
        input.tick_if_not_running,
        input.semantics == BtSemantics::Btcpp { tick: BtTick::Once },
    ));
    if btcpp {
        errs.extend(btcpp4_skip::refusals(sm, &tree));
    }
    // A stateful leaf (`btcpp.rs`, "Leaves"): a leaf plugin that may answer RUNNING, or
    // Sleep.
    let stateful = |c: usize| match tree.nodes[c].kind {
        Kind::Plugin(p) => !plugins[p].ticks_children && plugins[p].may_run,
        Kind::Control(c) => c == Control::Btcpp4(tree::Btcpp4::Sleep),
    };
    // Where BT.CPP may tick a node again without resetting it (`btcpp4_skip.rs`,
    // `stale`): whether its own machine keeps what a reset clears, and whether its
    // parent halts it (or its conditions' machine) at every reset.
    let skips = if btcpp {
        btcpp4_skip::may_skip(&tree)
    } else {
        Vec::new()
    };
    let inner_told = |i: usize| btcpp && btcpp4_skip::resets_matter(&tree, &skips, i);
    let told = |i: usize| btcpp && btcpp4_skip::stale(&tree, i) && (wrapped(i) || inner_told(i));
    for (idx, n) in tree.nodes.iter().enumerate() {
        let refused = btcpp4_conds::refusals(sm, &tree, idx, btcpp);
        if !refused.is_empty() {
            errs.extend(refused);
            continue;
        }
        let (parent, halt_target) = match n.parent {
            Some(p) => (tree.nodes[p].machine.clone(), tree.nodes[p].machine.clone()),
            None => (root_name.clone(), "NONE".to_string()),
        };
        let outer = (parent.clone(), halt_target.clone());
        let (parent, halt_target) = if wrapped(idx) {
            let w = btcpp4_conds::machine_name(n);
            (w.clone(), w)
        } else {
            (parent, halt_target)
        };
        let ctx = Ctx {
            b: B { at: n.span },
            id: n.id,
            machine: n.machine.clone(),
            parent,
            halt_target,
            children: n
                .children
                .iter()
                .map(|&c| {
                    if wrapped(c) {
                        (
                            btcpp4_conds::stem(&tree.nodes[c]),
                            btcpp4_conds::machine_name(&tree.nodes[c]),
                        )
                    } else {
                        (tree.nodes[c].id.to_string(), tree.nodes[c].machine.clone())
                    }
                })
                .collect(),
            effects: match input.semantics {
                BtSemantics::As2fm => (input.halts == Halts::WhenNeeded)
                    .then(|| n.children.iter().map(|&c| effects[c]).collect()),
                BtSemantics::Btcpp { .. } => Some(vec![HaltEffect::WhenRunning; n.children.len()]),
            },
            btcpp: input.semantics != BtSemantics::As2fm,
            wake: (input.semantics == BtSemantics::Btcpp { tick: BtTick::Once })
                .then(|| root_name.clone()),
            stateful: if input.semantics == BtSemantics::As2fm {
                Vec::new()
            } else {
                // A stateful leaf with pre/post conditions: its conditions' machine
                // answers for it where it is ticked again without a reset.
                n.children
                    .iter()
                    .map(|&c| stateful(c) && !wrapped(c) && !btcpp4_subtree::body_reset(&tree, c))
                    .collect()
            },
            stale: inner_told(idx),
            resets: n.children.iter().map(|&c| told(c)).collect(),
        };
        if let (Kind::Control(Control::Btcpp4(k)), BtSemantics::As2fm) = (n.kind, input.semantics) {
            errs.push(sm.diag(n.span, btcpp4::as2fm_refusal(k)));
            continue;
        }
        let timed = match n.kind {
            Kind::Control(Control::Btcpp4(k)) if btcpp4_time::handles(k) => Some(k),
            _ => None,
        };
        let m = match (n.kind, timed) {
            // The timed nodes need the tree's clock (their conditions' machine below).
            (_, Some(k)) => {
                btcpp4_time::lower(sm, k, n, &ctx, &root_name, clock.as_ref(), &mut errs)
            }
            (Kind::Plugin(i), None) => Some(plugin::instance(
                sm,
                &plugins[i],
                n,
                &ctx,
                &mut bb,
                &mut errs,
            )),
            (Kind::Control(c), None) => {
                // A leaf plugin is a stateful action under BT.CPP's rules (see
                // `btcpp.rs`); only IfThenElse can tick one that was not reset.
                let stale_condition = c == Control::IfThenElse
                    && n.children.len() == 2
                    && ctx.stateful.first() == Some(&true);
                if stale_condition {
                    Some(parallel::if_then_else(&ctx, true))
                } else {
                    builtin(sm, c, n, &ctx, &mut bb, &mut errs)
                }
            }
        };
        if let Some(m) = m {
            out.push(m);
        }
        if wrapped(idx) {
            let outer = Ctx {
                parent: outer.0,
                halt_target: outer.1,
                stale: told(idx),
                ..ctx.clone()
            };
            let inner = btcpp4_conds::Inner {
                stateful: stateful(idx),
                forward: inner_told(idx),
            };
            if let Some(w) = btcpp4_conds::wrapper(sm, n, &outer, inner, &mut bb, &mut errs) {
                out.push(w);
            }
        }
    }
    if let Some(c) = &clock {
        let stem = stem(sm, input.tree);
        btcpp4_time::add_clock(root_b, &mut out[0], c, &format!("{stem}_timers"), &timer);
    }
    if let Some(m) = bb.machine(root_b) {
        out.push(m);
    }
    if errs.is_empty() {
        Ok(out)
    } else {
        Err(errs)
    }
}

/// Where the tree's runs under AS2FM's node models and under BehaviorTree.CPP 4 are known
/// to differ (`notes.rs`): one note per construction, at the node. Empty when the tree
/// or a plugin cannot be read ([`lower`] reports that).
pub(crate) fn semantics_notes(sm: &SourceMap, input: &BtInput) -> Vec<Diagnostic> {
    let Some((root, plugins)) = parsed(sm, input) else {
        return Vec::new();
    };
    match tree::read(sm, &root, &plugins) {
        Ok(t) => notes::notes(sm, &t, &plugins),
        Err(_) => Vec::new(),
    }
}

/// The tree document and the plugins of `input`, read for the notes and warnings
/// (`None` when one cannot be read: [`lower`] reports that).
fn parsed(sm: &SourceMap, input: &BtInput) -> Option<(Element, Vec<plugin::Plugin>)> {
    let plugins = (input.plugins.iter())
        .map(|&f| plugin::read(sm, f).ok())
        .collect::<Option<Vec<_>>>()?;
    Some((xml::parse(sm, input.tree).ok()?, plugins))
}

/// Under `--bt btcpp` ([`BtSemantics::Btcpp`]), where the tree is not one BehaviorTree.CPP 4
/// runs as written, so the BT.CPP number is for a tree 4.x would not load: a document in
/// `BTCPP_format="3"` (3.8's format; the lowering applies 4's rules), and each
/// BlackboardCheck node (3.8's; 4.8.2 refuses it at load, "Node not recognized"), which
/// is lowered as AS2FM's model of it. Warnings, one per place; empty under AS2FM's
/// semantics or when the tree cannot be read ([`lower`] reports that).
pub(crate) fn btcpp_warnings(sm: &SourceMap, input: &BtInput) -> Vec<Diagnostic> {
    if input.semantics == BtSemantics::As2fm {
        return Vec::new();
    }
    let Some((root, plugins)) = parsed(sm, input) else {
        return Vec::new();
    };
    let mut out: Vec<Diagnostic> = Vec::new();
    if root.attr_value("BTCPP_format").map(str::trim) == Some("3") {
        out.push(sm.diag(root.span, "`--bt btcpp` runs this BTCPP_format 3 tree (BehaviorTree.CPP 3.8's format) by BehaviorTree.CPP 4's rules, which differ from 3.8's (3.8's SequenceStar goes back to its first child when halted, its Parallel recounts finished children in child order: README, \"Where AS2FM's models and BehaviorTree.CPP differ\"); 4.x reads 3.8's names such as SequenceStar only when built with USE_BTCPP3_OLD_NAMES").warning());
    }
    let Ok(tree) = tree::read(sm, &root, &plugins) else {
        return out;
    };
    for n in &tree.nodes {
        if let Kind::Control(Control::BlackboardCheck(t)) = n.kind {
            let d = sm.diag(n.span, format!("{}: BehaviorTree.CPP 4 does not register this BehaviorTree.CPP 3 node (4.8.2 refuses the tree at load, \"Node not recognized\"), so `--bt btcpp` lowers AS2FM's model of it; in a BT.CPP 4 tree, a Precondition or a ScriptCondition compares an entry", t.node_name())).warning();
            if !out
                .iter()
                .any(|o| o.file == d.file && o.line == d.line && o.col == d.col)
            {
                out.push(d);
            }
        }
    }
    out
}

/// What halting each node (by index) does when it is idle; children come after their
/// parent in pre-order, so one pass from the end sees every child first.
fn halt_effects(tree: &tree::Tree, plugins: &[plugin::Plugin]) -> Vec<HaltEffect> {
    let mut out = vec![HaltEffect::Always; tree.nodes.len()];
    for (i, n) in tree.nodes.iter().enumerate().rev() {
        let worst = n
            .children
            .iter()
            .map(|&c| out[c])
            .max_by_key(|e| match e {
                HaltEffect::Never => 0,
                HaltEffect::WhenRunning => 1,
                HaltEffect::Always => 2,
            })
            .unwrap_or(HaltEffect::Never);
        out[i] = match n.kind {
            Kind::Plugin(p) => {
                let p = &plugins[p];
                if p.has_halt || p.ticks_children {
                    HaltEffect::Always
                } else {
                    HaltEffect::Never
                }
            }
            Kind::Control(c) => match c {
                Control::AlwaysSuccess | Control::AlwaysFailure | Control::SetBlackboard => {
                    HaltEffect::Never
                }
                // No variables: halting one does what halting its child does.
                Control::Inverter | Control::ForceSuccess | Control::ForceFailure => worst,
                // Answers its mismatch status without ticking (or halting) its child,
                // which may still be running then.
                // Halts its child before answering a mismatch (unless halting it never
                // changes anything), so when idle its child is idle too.
                Control::BlackboardCheck(_) => worst,
                Control::SequenceWithMemory => HaltEffect::Always,
                // Refused under AS2FM's rules, the only ones that read this.
                Control::Btcpp4(_) => HaltEffect::Always,
                Control::Sequence
                | Control::Fallback
                | Control::ReactiveSequence
                | Control::ReactiveFallback
                | Control::Parallel
                | Control::IfThenElse
                | Control::Repeat
                | Control::RetryUntilSuccessful => match worst {
                    HaltEffect::Always => HaltEffect::Always,
                    _ => HaltEffect::WhenRunning,
                },
            },
        };
    }
    out
}

/// An integer attribute of a built-in node.
fn int_param(
    sm: &SourceMap,
    n: &tree::TreeNode,
    keys: &[&str],
    errs: &mut Vec<Diagnostic>,
) -> Option<(i64, crate::model::source::Span)> {
    let p = keys.iter().find_map(|k| n.port(k))?;
    match &p.value {
        PortValue::Literal(v) => match v.trim().parse::<i64>() {
            Ok(x) => Some((x, p.span)),
            Err(_) => {
                errs.push(sm.diag(
                    p.span,
                    format!("`{}` must be a whole number, not `{v}`", p.key),
                ));
                None
            }
        },
        PortValue::Blackboard(b) => {
            errs.push(sm.diag(
                p.span,
                format!("`{}` must be a constant; blackboard entries (`{{{b}}}`) are not supported here", p.key),
            ));
            None
        }
    }
}

fn builtin(
    sm: &SourceMap,
    c: Control,
    n: &tree::TreeNode,
    ctx: &Ctx,
    bb: &mut blackboard::Blackboard,
    errs: &mut Vec<Diagnostic>,
) -> Option<Element> {
    let count = n.children.len() as i64;
    match c {
        Control::Parallel => {
            let ok_before = errs.len();
            let mut th = |keys: &[&str], default: i64, what: &str| -> (i64, bool) {
                // BT.CPP 4's name and 3's (AS2FM's) for one threshold: one of them only.
                if let (Some(_), Some(b)) = (n.port(keys[0]), n.port(keys[1])) {
                    errs.push(sm.diag(
                        b.span,
                        format!("`{}` and `{}` are the same threshold (BehaviorTree.CPP 4's and 3's name): give one", keys[0], keys[1]),
                    ));
                }
                let (v, span) = int_param(sm, n, keys, errs).unwrap_or((default, n.span));
                let neg = v < 0;
                let v = if neg { count + v + 1 } else { v };
                if v < 1 || v > count {
                    errs.push(sm.diag(
                        span,
                        format!("the {what} threshold must be between 1 and the number of children ({count})"),
                    ));
                }
                (v, neg)
            };
            let (s, s_neg) = th(&["success_count", "success_threshold"], -1, "success");
            let (f, _) = th(&["failure_count", "failure_threshold"], 1, "failure");
            (errs.len() == ok_before).then(|| {
                if ctx.btcpp {
                    btcpp::parallel(ctx, s, f, s_neg)
                } else {
                    control::machine(c, ctx, &[s, f])
                }
            })
        }
        Control::Repeat | Control::RetryUntilSuccessful => {
            let key = if c == Control::Repeat {
                "num_cycles"
            } else {
                "num_attempts"
            };
            match int_param(sm, n, &[key], errs) {
                Some((v, span)) if v < -1 || v > i8::MAX as i64 => {
                    errs.push(sm.diag(
                        span,
                        format!("`{key}` must be -1 (forever) or between 0 and 127"),
                    ));
                    None
                }
                Some((v, _)) if ctx.btcpp => {
                    Some(btcpp::repeat(ctx, v, c == Control::RetryUntilSuccessful))
                }
                Some((v, _)) => Some(control::machine(c, ctx, &[v])),
                None => {
                    if n.port(key).is_none() {
                        errs.push(sm.diag(n.span, format!("this node needs `{key}`")));
                    }
                    None
                }
            }
        }
        Control::SetBlackboard => blackboard::lower_set(sm, n, ctx, bb, errs),
        Control::BlackboardCheck(t) => blackboard::lower_check(sm, t, n, ctx, bb, errs),
        Control::SequenceWithMemory if ctx.btcpp => Some(btcpp::sequence_with_memory(ctx)),
        Control::Btcpp4(k) => btcpp4::lower(sm, k, n, ctx, bb, errs),
        _ => Some(control::machine(c, ctx, &[])),
    }
}
