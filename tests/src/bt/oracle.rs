//! The reference executor of BehaviorTree.CPP: a direct tick-by-tick interpreter of a
//! [`Tree`] whose leaves follow scripts, recording every tick and halt a leaf receives.
//!
//! Three readings, for the nodes where AS2FM's SCXML models of the built-in nodes and
//! BehaviorTree.CPP disagree ([`Reading`]), and for BT.CPP the executor's options
//! ([`Options`]: whether nodes have the wake-up signal, `tickOnce` or
//! `tickExactlyOnce`). Each rule cites the function that decides it: BT.CPP 4.10
//! (`src/controls/*.cpp`, `src/decorators/*.cpp`, `control_node.cpp`,
//! `decorator_node.cpp`, `bt_factory.cpp`), BT.CPP 3.8 (the same files of the v3
//! sources), and AS2FM's `*.ascxml` node models. Where the library the real-library
//! differential runs (4.8.2, `tests/tests/bt_real.rs`) differs from 4.10, the comment says
//! so.
//!
//! Timeout, Delay and Sleep run their timers on a virtual clock: root tick `k` begins at
//! `k * Options::period_ms` ms, and a timer due by then fires first
//! (`Oracle::begin_tick`; docs/SEMANTICS.md, "Timers of the tree").

use super::script::{Fault, Program};
use super::tree::{CheckType, Kind, Operand, Status, Tree};
use std::collections::BTreeMap;

/// Whose rules the oracle follows where AS2FM and BT.CPP differ.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Reading {
    /// AS2FM's node models (`as2fm-bt-nodes/*.ascxml`): a parent halts every child it
    /// resets, running or not, and each halted node runs its own halt; Parallel ticks every
    /// child on every tick; Repeat halts its child after each finished attempt;
    /// SequenceWithMemory forgets its place when halted; a leaf answers every tick.
    #[default]
    As2fm,
    /// BehaviorTree.CPP 4: `ControlNode::haltChild` / `DecoratorNode::resetChild` halt
    /// a child only while it is RUNNING (else they just reset its status); Parallel skips
    /// children that finished; SequenceWithMemory keeps its place when halted; a leaf is a
    /// `StatefulActionNode`; with [`Options::from_xml`], the wake-up yields.
    Btcpp,
    /// BehaviorTree.CPP 3.8: as 4 without wake-ups, but `SequenceStarNode::halt` resets
    /// its index and `ParallelNode::tick` recounts every child in child order on each tick.
    Btcpp3,
}

/// How the executor ticks the root (BT.CPP 4 `Tree::tickOnce` / `Tree::tickExactlyOnce`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum TickMode {
    /// `tickExactlyOnce`: one `executeTick` of the root per tick.
    #[default]
    ExactlyOnce,
    /// `tickOnce`: the root ticked again while it answers RUNNING and a wake-up is pending
    /// (what `tickWhileRunning` and the ROS 2 executors call).
    Once,
}

/// Leaf callbacks one root tick may make before it counts as a livelock.
pub const BUDGET: usize = 1000;

/// Node ticks one root tick may make before it counts as a hang (a loop no leaf is in).
pub const HANG: usize = 2_000_000;

/// The executor's period unless an [`Options`] says otherwise: 100 ms (10 Hz).
pub const PERIOD_MS: u64 = 100;

/// The reading and, for BT.CPP 4, how the tree was built and is ticked.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Options {
    /// Whose rules.
    pub reading: Reading,
    /// The factory built the tree from XML (`createTreeFromText`), as opposed to nodes
    /// built by hand as BT.CPP's own unit tests do: every node has the wake-up signal
    /// (`Tree::initialize`, `TreeNode::requiresWakeUp`), and the entries ports name in
    /// `{}` were created at load. BT.CPP 4 only.
    pub from_xml: bool,
    /// How the root is ticked.
    pub mode: TickMode,
    /// Leaf callbacks per root tick before [`End::Livelock`].
    pub budget: usize,
    /// The executor's period in milliseconds: root tick `k` (from 0) begins at virtual
    /// time `k * period_ms`, the clock of the timers of Timeout, Delay and Sleep.
    pub period_ms: u64,
}

impl Options {
    /// `reading` on nodes built by hand, ticked exactly once per tick.
    pub fn of(reading: Reading) -> Self {
        Options {
            reading,
            from_xml: false,
            mode: TickMode::ExactlyOnce,
            budget: BUDGET,
            period_ms: PERIOD_MS,
        }
    }

    /// BT.CPP 4 on a tree `createTreeFromText` built, ticked in `mode`.
    pub fn xml4(mode: TickMode) -> Self {
        Options {
            reading: Reading::Btcpp,
            from_xml: true,
            mode,
            budget: BUDGET,
            period_ms: PERIOD_MS,
        }
    }
}

/// What a leaf received.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum LeafEvent {
    /// A tick of the leaf with this node id.
    Tick(u32),
    /// A halt of the leaf with this node id.
    Halt(u32),
}

/// The scripts of the leaf types: on its k-th tick (from 0) an instance answers
/// `script[k % len]`; halts do not move it.
pub type Scripts = BTreeMap<String, Vec<Status>>;

/// How a run ended early.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum End {
    /// BT.CPP refuses the tree when loading it: the name of the leaf type ("ID [..]
    /// already registered") it refuses, or the names of the 3.x-only nodes, `|` between
    /// them ("Node not recognized", "Unknown node type": which one it names first depends
    /// on the stage of loading that meets it).
    Refused(String),
    /// BT.CPP throws during root tick `tick` (from 0); `text` is part of its message.
    Error {
        /// The root tick.
        tick: usize,
        /// What the exception's message contains.
        text: String,
    },
    /// Root tick `tick` makes more than [`Options::budget`] leaf callbacks (it never
    /// returns in BT.CPP); the log stops where that tick began.
    Livelock {
        /// The root tick.
        tick: usize,
    },
    /// Root tick `tick` loops forever with no leaf callback at all.
    Hang {
        /// The root tick.
        tick: usize,
    },
}

/// A run: root status per tick until it ended, the leaves' log, and how it ended early.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Outcome {
    /// Root status of each finished tick.
    pub statuses: Vec<Status>,
    /// Every tick and halt leaves received, in order.
    pub log: Vec<LeafEvent>,
    /// `None` when every tick ran.
    pub end: Option<End>,
    /// The script entries at the end (BT.CPP 4; booleans as 0 and 1), the SubTrees'
    /// private ones left out.
    pub vars: BTreeMap<String, i64>,
}

/// Why a tick stopped: BT.CPP's own outcome, or a case the oracle cannot run.
#[derive(Debug)]
enum Stop {
    /// BT.CPP throws.
    Error(String),
    /// Too many leaf callbacks.
    Livelock,
    /// Too many node ticks.
    Hang,
    /// Not a BT.CPP fact: the case is outside what the oracle knows.
    Model(String),
}

impl From<String> for Stop {
    fn from(s: String) -> Self {
        Stop::Model(s)
    }
}

/// The built-in node names BT.CPP 4 registers (`BehaviorTreeFactory`'s constructor in
/// `bt_factory.cpp`) among those the oracle knows; the others (`SequenceStar`,
/// `RetryUntilSuccesful`, `BlackboardCheck*`) are 3.x names that 4 refuses at load.
const V4_NAMES: &[&str] = &[
    "Sequence",
    "ReactiveSequence",
    "SequenceWithMemory",
    "Fallback",
    "ReactiveFallback",
    "Parallel",
    "IfThenElse",
    "Inverter",
    "ForceSuccess",
    "ForceFailure",
    "Repeat",
    "RetryUntilSuccessful",
    "AlwaysSuccess",
    "AlwaysFailure",
    "SetBlackboard",
    "AsyncSequence",
    "AsyncFallback",
    "ParallelAll",
    "WhileDoElse",
    "KeepRunningUntilFailure",
    "RunOnce",
    "Switch2",
    "Switch3",
    "Switch4",
    "Switch5",
    "Switch6",
    "Script",
    "ScriptCondition",
    "Precondition",
    "Timeout",
    "Delay",
    "Sleep",
    "UnsetBlackboard",
    "LoopInt",
    "LoopBool",
    "LoopDouble",
    "LoopString",
    "WasEntryUpdated",
    "SkipUnlessUpdated",
    "WaitValueUpdate",
];

/// The other built-in nodes BT.CPP 4.8.2 registers: a scripted leaf cannot take their
/// names (`registerBuilder`: "ID [..] already registered"). (4.10 adds `TryCatch`.)
const V4_OTHERS: &[&str] = &["SubTree"];

/// What BT.CPP 4's factory refuses at load, if anything: a leaf type that has the
/// name of a built-in node of 4 (`registerBuilder`: "ID [..] already registered"; the
/// harness registers every scripted type first), or a built-in node of 3.x only, in any
/// `<BehaviorTree>` of the document, used or not ("Node not recognized", `VerifyXML`).
pub fn btcpp4_refuses(tree: &Tree, scripts: &Scripts) -> Option<String> {
    if let Some(t) = scripts
        .keys()
        .find(|t| V4_NAMES.contains(&t.as_str()) || V4_OTHERS.contains(&t.as_str()))
    {
        return Some(t.clone());
    }
    let known = |t: &str| {
        super::tree::NODES
            .iter()
            .any(|(names, _, _)| names.contains(&t))
    };
    let refused: Vec<&str> = tree
        .names
        .iter()
        .map(|t| t.as_str())
        .filter(|t| known(t) && !V4_NAMES.contains(t))
        .collect();
    if refused.is_empty() && tree.reactive_async {
        return Some("A ReactiveSequence cannot have more than one async child".into());
    }
    // An entry the `value` ports of two Loop nodes of different item types name: "The
    // creation of the tree failed because the port [..] was initially created with type
    // [..] and, later type [..] was used somewhere else" (4.8.2, found against it).
    let mut typed = BTreeMap::new();
    for x in &tree.nodes {
        if let Kind::Loop(ty, _, Some(v), _) = &x.kind {
            if *typed.entry(v.as_str()).or_insert(*ty) != *ty && refused.is_empty() {
                return Some("was initially created with type".into());
            }
        }
    }
    (!refused.is_empty()).then(|| refused.join("|"))
}

/// The executor's state: per node its last status (`None`: IDLE) and its variables.
pub struct Oracle<'t> {
    tree: &'t Tree,
    scripts: &'t Scripts,
    opts: Options,
    reading: Reading,
    status: Vec<Option<Status>>,
    /// Child index (sequences, IfThenElse) or attempt count (Repeat, Retry).
    idx: Vec<i64>,
    /// Parallel's finished children (BT.CPP readings) and counts.
    done: Vec<Vec<bool>>,
    /// 3.8 Parallel: the status a finished child keeps (`child_node->status()`), which
    /// for a SubTree is the SubtreeNode's own: its body was reset when it finished.
    kept: Vec<Vec<Option<Status>>>,
    counts: Vec<(i64, i64)>,
    /// Ticks each leaf instance received.
    leaf_ticks: Vec<usize>,
    /// RunOnce: the status its child finished with (`returned_status_`).
    once: Vec<Option<Status>>,
    /// Entries as the text written (BT.CPP converts where a port reads).
    bb: BTreeMap<String, String>,
    /// Literal writes of each entry so far (BT.CPP 4 SetBlackboard copies).
    writes: BTreeMap<String, usize>,
    /// Entries a failed BT.CPP 4 copy created typed `BT::Any`.
    any_typed: std::collections::BTreeSet<String>,
    /// Entries a SetBlackboard `value` port names (BT.CPP 4 creates them at load).
    at_load: std::collections::BTreeSet<String>,
    /// A wake-up signal is pending (`WakeUpSignal::emitSignal`, consumed by `waitFor`).
    pending: bool,
    /// Leaf callbacks and node ticks in the current root tick.
    calls: usize,
    node_ticks: usize,
    /// Every tick and halt leaves received, in order.
    pub log: Vec<LeafEvent>,
    /// The entries scripts read and write (booleans as 0 and 1).
    pub vars: BTreeMap<String, i64>,
    /// Those of them that hold a `double` (`script::Env`).
    dbl: std::collections::BTreeSet<String>,
    /// Their exact values (`script::Env::reals`).
    reals: BTreeMap<String, f64>,
    /// The entries UnsetBlackboard erased (a port's entry then no longer exists until
    /// written again).
    erased: std::collections::BTreeSet<String>,
    /// The entries scripts created from a string, and their texts (`script::Env`).
    pub strs: BTreeMap<String, String>,
    /// Sequences and fallbacks: children skipped so far (`skipped_count_`).
    skipped: Vec<usize>,
    /// A script a halt ran threw: surfaced when the tick returns.
    fault: Option<String>,
    /// Precondition: its child has started (`_children_running`).
    memo: Vec<bool>,
    /// Virtual time in milliseconds: the start of the current root tick.
    now: u64,
    /// Root ticks begun.
    root_ticks: u64,
    /// Timeout, Delay, Sleep: when the node's timer is due, if one is running.
    due: Vec<Option<u64>>,
    /// Timeout `child_halted_`, Delay `delay_complete_`, Sleep `timer_waiting_`.
    flag: Vec<bool>,
    /// Timeout `timeout_started_`, Delay `delay_started_`.
    started: Vec<bool>,
    /// TryCatch `in_catch_`.
    in_catch: Vec<bool>,
    /// Each entry's update counter (BT.CPP 4 `Blackboard::Entry::sequence_id`): 0 when
    /// the entry is created, one more at every write; an entry unset and created again
    /// counts from 0 (docs/SEMANTICS.md, "Entries that may be unset").
    seq: BTreeMap<String, u64>,
    /// The entry-updated nodes' `sequence_id_` (the counter they saw last).
    seen: Vec<u64>,
    /// `EntryUpdatedDecorator::still_executing_child_`; LoopNode `child_running_`.
    child_running: Vec<bool>,
    /// LoopNode `current_queue_`: the items left.
    queue: Vec<std::collections::VecDeque<String>>,
}

impl From<Fault> for Stop {
    fn from(f: Fault) -> Self {
        match f {
            Fault::Throws(t) => Stop::Error(t),
            Fault::Model(t) => Stop::Model(t),
        }
    }
}

impl<'t> Oracle<'t> {
    /// A tree with every node idle, read as `reading` on nodes built by hand.
    pub fn new(tree: &'t Tree, scripts: &'t Scripts, reading: Reading) -> Self {
        Self::with(tree, scripts, Options::of(reading))
    }

    /// A tree with every node idle.
    pub fn with(tree: &'t Tree, scripts: &'t Scripts, opts: Options) -> Self {
        let n = tree.nodes.len();
        Oracle {
            tree,
            scripts,
            opts,
            reading: opts.reading,
            status: vec![None; n],
            idx: vec![0; n],
            done: tree
                .nodes
                .iter()
                .map(|x| vec![false; x.children.len()])
                .collect(),
            kept: tree
                .nodes
                .iter()
                .map(|x| vec![None; x.children.len()])
                .collect(),
            counts: vec![(0, 0); n],
            leaf_ticks: vec![0; n],
            once: vec![None; n],
            bb: BTreeMap::new(),
            writes: BTreeMap::new(),
            any_typed: Default::default(),
            at_load: tree
                .nodes
                .iter()
                .filter_map(|x| match &x.kind {
                    Kind::SetBlackboard(_, Operand::Entry(e)) => Some(e.clone()),
                    _ => None,
                })
                .collect(),
            pending: false,
            calls: 0,
            node_ticks: 0,
            log: Vec::new(),
            vars: BTreeMap::new(),
            dbl: Default::default(),
            reals: BTreeMap::new(),
            erased: Default::default(),
            strs: BTreeMap::new(),
            skipped: vec![0; n],
            fault: None,
            memo: vec![false; n],
            now: 0,
            root_ticks: 0,
            due: vec![None; n],
            flag: vec![false; n],
            started: vec![false; n],
            in_catch: vec![false; n],
            seq: BTreeMap::new(),
            seen: vec![0; n],
            child_running: vec![false; n],
            queue: vec![Default::default(); n],
        }
    }

    fn btcpp(&self) -> bool {
        self.reading != Reading::As2fm
    }

    /// One tick of the root.
    ///
    /// AS2FM: a finished root is ticked again from where its own rules left it. BT.CPP 4
    /// `Tree::tickRoot` (`bt_factory.cpp`): under `tickOnce` (not `tickExactlyOnce`) the
    /// root is ticked again while it answers RUNNING and `wake_up_->waitFor(0)` finds a
    /// signal (which it consumes); a finished root gets `rootNode()->resetStatus()` (its
    /// own status only). A signal left pending by a tick that finished stays for the next
    /// one. BT.CPP 3.8 `Tree::tickRoot` (`bt_factory.h`) resets a finished root's status.
    pub fn tick_root(&mut self) -> Result<Status, String> {
        self.begin_tick();
        self.tick_root_stop().map_err(|e| match e {
            Stop::Error(t) => format!("BT.CPP throws: {t}"),
            Stop::Livelock => "livelock: the tick never returns".into(),
            Stop::Hang => "hang: the tick never returns".into(),
            Stop::Model(t) => t,
        })
    }

    /// Moves the virtual clock to the start of the next root tick (`k * period_ms` for
    /// root tick `k`), firing first, in order, every timer due by then (ties in node
    /// order).
    ///
    /// The rule (docs/SEMANTICS.md, "Timers of the tree"): BT.CPP's `TimerQueue` runs a
    /// timer's callback on its own thread at the wall-clock time it is due, between the
    /// executor's ticks, and the callback's effects (Delay's `delay_complete_`, Sleep's
    /// `timer_waiting_`, Timeout halting its RUNNING child, each emitting the wake-up
    /// signal) are what the next tick sees. A timer due exactly at a tick races with it
    /// in the real library; here it fires first.
    fn begin_tick(&mut self) {
        let t = self.root_ticks * self.opts.period_ms;
        self.root_ticks += 1;
        while let Some(n) = (0..self.due.len())
            .filter(|&n| self.due[n].is_some_and(|d| d <= t))
            .min_by_key(|&n| (self.due[n], n))
        {
            self.now = self.due[n].unwrap_or(t);
            self.fire(n);
        }
        self.now = t;
    }

    /// Node `n`'s timer callback (`aborted` false).
    fn fire(&mut self, n: usize) {
        self.due[n] = None;
        match self.tree.nodes[n].kind {
            // `DelayNode::tick`'s callback: `delay_complete_ = true`, wake-up.
            Kind::Delay(_) => {
                self.flag[n] = true;
                self.wake_up();
            }
            // `SleepNode::onStart`'s callback: wake-up, `timer_waiting_ = false`.
            Kind::Sleep(_) => {
                self.flag[n] = false;
                self.wake_up();
            }
            // `TimeoutNode::tick`'s callback: a RUNNING child is halted (`haltChild`, on
            // the timer's thread), `child_halted_` set, wake-up; otherwise nothing.
            Kind::Timeout(_) => {
                let c = self.child(n, 0);
                if self.status[c] == Some(Status::Running) {
                    self.flag[n] = true;
                    self.halt_child(c);
                    self.wake_up();
                }
            }
            _ => {}
        }
    }

    /// `TreeNode::emitWakeUpSignal`: only nodes of a tree built from XML have the signal.
    fn wake_up(&mut self) {
        if self.opts.from_xml {
            self.pending = true;
        }
    }

    fn tick_root_stop(&mut self) -> Result<Status, Stop> {
        self.calls = 0;
        self.node_ticks = 0;
        let mut s = self.tick(0)?;
        if self.btcpp() {
            if self.opts.mode == TickMode::Once {
                while s == Status::Running && std::mem::take(&mut self.pending) {
                    s = self.tick(0)?;
                }
            }
            // `Tree::tickRoot`: only a finished root is reset.
            if matches!(s, Status::Success | Status::Failure) {
                self.status[0] = None;
            }
        }
        Ok(s)
    }

    fn child(&self, n: usize, i: usize) -> usize {
        self.tree.nodes[n].children[i]
    }

    fn n_children(&self, n: usize) -> usize {
        self.tree.nodes[n].children.len()
    }

    fn value(&self, o: &Operand) -> Result<String, String> {
        match o {
            Operand::Lit(v) => Ok(v.clone()),
            Operand::Entry(e) => self
                .bb
                .get(e)
                .cloned()
                .ok_or(format!("blackboard entry {e} read before written")),
        }
    }

    /// v3.8 `blackboard_precondition.h`: both sides converted to the node's type
    /// (`convertFromString`), then `IsSame` -- `==`, for doubles `|a - b| <= EPS` with
    /// `EPS` the float epsilon.
    fn same(&self, ty: CheckType, a: &Operand, b: &Operand) -> Result<bool, String> {
        let (a, b) = (self.value(a)?, self.value(b)?);
        let bad = |v: &str| format!("`{v}` is not a {ty:?}");
        Ok(match ty {
            CheckType::Int => {
                let p = |v: &str| v.trim().parse::<i64>().map_err(|_| bad(v));
                p(&a)? == p(&b)?
            }
            CheckType::Double => {
                let p = |v: &str| v.trim().parse::<f64>().map_err(|_| bad(v));
                (p(&a)? - p(&b)?).abs() <= f64::from(f32::EPSILON)
            }
            CheckType::String => a == b,
            CheckType::Bool => {
                let p = |v: &str| match v.trim() {
                    "true" | "True" | "1" => Ok(true),
                    "false" | "False" | "0" => Ok(false),
                    _ => Err(bad(v)),
                };
                p(&a)? == p(&b)?
            }
        })
    }

    /// `TreeNode::executeTick`: the node's tick, its answer kept as its status.
    fn tick(&mut self, n: usize) -> Result<Status, Stop> {
        if self.btcpp() {
            self.node_ticks += 1;
            if self.node_ticks > HANG {
                return Err(Stop::Hang);
            }
        }
        let conds = &self.tree.nodes[n].conds;
        if conds.any() && self.reading != Reading::Btcpp {
            return Err(Stop::Model("pre/post conditions are BT.CPP 4's".into()));
        }
        let s = match self.pre_conditions(n)? {
            Some(s) => s,
            None => {
                let s = self.tick_inner(n)?;
                // RunOnce answers its `then_skip` SKIPPED before `setStatus`.
                let kind = &self.tree.nodes[n].kind;
                let keeps_status = matches!(
                    kind,
                    Kind::Precondition(..) | Kind::Switch(..) | Kind::Loop(..) | Kind::Updated(..)
                ) || (matches!(kind, Kind::RunOnce(true))
                    && self.once[n].is_some());
                let sets_running = !keeps_status;
                if s == Status::Skipped && sets_running {
                    // The controls and decorators set themselves RUNNING first
                    // (`setStatus(NodeStatus::RUNNING)` in their `tick`; not
                    // `PreconditionNode`, `SwitchNode`, `EntryUpdatedDecorator`, nor
                    // `LoopNode`, which does it only before ticking its child), and `executeTick` does not
                    // store SKIPPED: such a node stays RUNNING (and a reset halts it).
                    self.status[n] = Some(Status::Running);
                }
                s
            }
        };
        if let Some(f) = self.fault.take() {
            return Err(Stop::Model(format!(
                "a script a halt ran threw ({f}): not modelled"
            )));
        }
        // `TreeNode::checkPostConditions`, for a finished answer only
        // (`isStatusCompleted`): `_onSuccess` or `_onFailure`, then `_post`.
        let post = &self.tree.nodes[n].conds.post;
        if matches!(s, Status::Success | Status::Failure) {
            let which = if s == Status::Success { 2 } else { 1 };
            for p in [&post[which], &post[3]].into_iter().flatten() {
                self.run_program(p)?;
            }
        }
        if s == Status::Skipped && !self.takes_skipped(n) {
            return Err(Stop::Model(format!(
                "SKIPPED reaches the parent of {}, which the oracle does not model for it",
                self.tree.nodes[n].id
            )));
        }
        // "preserve the IDLE state if skipped" (`TreeNode::executeTick`).
        if s != Status::Skipped {
            self.status[n] = Some(s);
        }
        super::subtree_cond::reset_finished_body(self.tree, self.btcpp(), n, s, &mut self.status);
        Ok(s)
    }

    /// `TreeNode::checkPreConditions` (4.10 and 4.8.2): in the order `_failureIf`,
    /// `_successIf`, `_skipIf`, `_while`; the first three only while the node is IDLE (a
    /// true one answers FAILURE, SUCCESS, SKIPPED without ticking it), `_while` also
    /// while RUNNING: false when IDLE skips the node, false when RUNNING halts it
    /// (`haltNode`, so its `_onHalted` runs) and answers SKIPPED.
    fn pre_conditions(&mut self, n: usize) -> Result<Option<Status>, Stop> {
        let tree = self.tree;
        for (i, p) in tree.nodes[n].conds.pre.iter().enumerate() {
            let Some(p) = p else { continue };
            match self.status[n] {
                None => {
                    let holds = self.holds(p)?;
                    match (i, holds) {
                        (0, true) => return Ok(Some(Status::Failure)),
                        (1, true) => return Ok(Some(Status::Success)),
                        (2, true) | (3, false) => return Ok(Some(Status::Skipped)),
                        _ => {}
                    }
                }
                Some(Status::Running) if i == 3 => {
                    let holds = self.holds(p)?;
                    if !holds {
                        self.halt_node(n);
                        return Ok(Some(Status::Skipped));
                    }
                }
                _ => {}
            }
        }
        Ok(None)
    }

    /// Whether node `n`'s parent (if any) is one whose handling of a SKIPPED child the
    /// oracle models: every BT.CPP 4 node (`BlackboardCheck*` is 3.x's).
    fn takes_skipped(&self, n: usize) -> bool {
        let parent = self.tree.nodes.iter().find(|p| p.children.contains(&n));
        parent.is_none_or(|p| !matches!(p.kind, Kind::Check(..)))
    }

    /// `TreeNode::haltNode`: the node's `halt()`, then its `_onHalted` script.
    fn halt_node(&mut self, n: usize) {
        self.halt(n);
        if let Some(p) = &self.tree.nodes[n].conds.post[0] {
            if let Err(f) = self.run_program(p) {
                self.fault.get_or_insert(format!("{f:?}"));
            }
        }
    }

    /// A script run over the entries; every assignment it makes counts as a write of
    /// its entry (`Blackboard::Entry::sequence_id`: the real library counts `x := 0`
    /// twice in `x := 0; x := 0`, and `x += 0` too, but not a read).
    /// An assignment other than `:=` to an entry that does not exist (UnsetBlackboard
    /// erased it) throws before its right side is read ("The blackboard entry [..]
    /// doesn't exist", as 4.8.2 answers).
    fn run_program(&mut self, p: &Program) -> Result<super::script::V, Fault> {
        use super::script::Expr;
        let texts = self.texts();
        let mut last = super::script::V::Num(0);
        for s in &p.0 {
            let mut s = s.clone();
            if let Expr::Assign(v, op, e) = &s {
                if *op != ":=" && !self.vars.contains_key(v) && !self.strs.contains_key(v) {
                    // An entry a port created when the tree was loaded exists without a
                    // value (4.8.2, `tests/bt/btcpp4/loop.toml`): `=` stores as `:=`
                    // does, `+=` ... find it empty.
                    if !self.declared(v) || self.erased.contains(v) {
                        return Err(Fault::Throws(format!(
                            "The blackboard entry [{v}] doesn't exist"
                        )));
                    }
                    if *op != "=" {
                        return Err(Fault::Throws("is not initialized".into()));
                    }
                    s = Expr::Assign(v.clone(), ":=", e.clone());
                }
            }
            let fresh = match &s {
                Expr::Assign(v, _, _)
                    if !self.vars.contains_key(v) && !self.strs.contains_key(v) =>
                {
                    Some(v.clone())
                }
                _ => None,
            };
            let mut env = super::script::Env {
                vals: &mut self.vars,
                dbl: &mut self.dbl,
                reals: &mut self.reals,
                strs: &mut self.strs,
            };
            last = match Program(vec![s.clone()]).run(&mut env, &texts) {
                Ok(v) => v,
                // `v := e` with `v` missing creates `v` without a value before reading
                // `e`: an `e` that reads `v` throws, with the message of the operator
                // that met the empty value (4.8.2: "The right operand of the operator
                // [:=] is not initialized", "ExprUnaryArithmetic: undefined", ...).
                Err(Fault::Throws(t))
                    if fresh
                        .as_ref()
                        .is_some_and(|v| t == format!("Variable not found: {v}")) =>
                {
                    return Err(Fault::Throws("Error in script".into()));
                }
                // A Loop's `value` entry exists from the load, without a value until
                // the first pop (its port creates it: 4.8.2 "The left operand of the
                // operator [==] is not initialized").
                Err(Fault::Throws(t)) if self.loop_value(&t) => {
                    return Err(Fault::Throws("is not initialized".into()));
                }
                Err(f) => return Err(f),
            };
            if let Expr::Assign(v, ..) = &s {
                *self.seq.entry(v.clone()).or_default() += 1;
            }
        }
        Ok(last)
    }

    /// Whether a port of the tree names entry `v` in `{}` (a Loop's `value`, a leaf's
    /// `out` or `in`): BT.CPP creates it, without a value, when it loads the tree.
    fn declared(&self, v: &str) -> bool {
        self.tree.nodes.iter().any(|x| {
            x.out.as_deref() == Some(v)
                || x.input.as_deref() == Some(v)
                || matches!(&x.kind, Kind::Loop(_, _, Some(e), _) if e == v)
        })
    }

    /// Whether `t` is "Variable not found" for an entry a Loop node's `value` names.
    fn loop_value(&self, t: &str) -> bool {
        let Some(v) = t.strip_prefix("Variable not found: ") else {
            return false;
        };
        self.tree
            .nodes
            .iter()
            .any(|x| matches!(&x.kind, Kind::Loop(_, _, Some(e), _) if e == v))
    }

    /// A script run as a condition.
    fn holds(&mut self, p: &Program) -> Result<bool, Fault> {
        super::script::truth(&self.run_program(p)?)
    }

    /// A script node's program run once over the entries.
    fn script(&mut self, p: &Program) -> Result<super::script::V, Stop> {
        Ok(self.run_program(p)?)
    }

    /// What scripts read of the entries SetBlackboard wrote: the text, or `None` for an
    /// entry BT.CPP 4.8.2 holds without a value (one a copy names or made, see
    /// [`Self::set_blackboard`]).
    fn texts(&self) -> super::script::Texts {
        let odd = |k: &String| self.any_typed.contains(k) || self.at_load.contains(k);
        let mut t: super::script::Texts = self
            .bb
            .iter()
            .map(|(k, v)| (k.clone(), (!odd(k)).then(|| v.clone())))
            .collect();
        for k in self.any_typed.iter().chain(&self.at_load) {
            t.insert(k.clone(), None);
        }
        t
    }

    /// `ControlNode::haltChild` / `DecoratorNode::resetChild`: BT.CPP halts the child
    /// only while RUNNING, then resets its status; AS2FM's `bt_halt_child` halts it
    /// whatever it last answered.
    fn halt_child(&mut self, c: usize) {
        if self.reading == Reading::As2fm || self.status[c] == Some(Status::Running) {
            self.halt_node(c);
        }
        self.status[c] = None;
    }

    /// `ControlNode::resetChildren`, or AS2FM's `reset_children` state: every child in
    /// order.
    fn reset_children(&mut self, n: usize) {
        for i in 0..self.n_children(n) {
            let c = self.child(n, i);
            self.halt_child(c);
        }
    }

    /// The node's own `halt()`.
    fn halt(&mut self, n: usize) {
        match &self.tree.nodes[n].kind {
            // `StatefulActionNode::halt` calls `onHalted` (only ever reached while
            // RUNNING in BT.CPP, see `halt_child`).
            Kind::Leaf(_) => self.log.push(LeafEvent::Halt(self.tree.nodes[n].id)),
            Kind::AlwaysSuccess
            | Kind::AlwaysFailure
            | Kind::SetBlackboard(..)
            | Kind::Script(_)
            | Kind::ScriptCondition(_) => {}
            // v4 `SequenceWithMemory::halt` keeps `current_child_idx_`; AS2FM's
            // `sequence_with_memory.ascxml` and v3.8 `SequenceStarNode::halt` reset it.
            Kind::SequenceWithMemory => {
                if self.reading != Reading::Btcpp {
                    self.idx[n] = 0;
                }
                self.reset_children(n);
            }
            // `TimeoutNode::halt`, `DelayNode::halt`: not started, every timer cancelled
            // (`cancelAll`), then `DecoratorNode::halt` resets the child.
            Kind::Timeout(_) | Kind::Delay(_) => {
                self.started[n] = false;
                self.due[n] = None;
                self.reset_children(n);
            }
            // `SleepNode::onHalted`: not waiting, the timer cancelled.
            Kind::Sleep(_) => {
                self.flag[n] = false;
                self.due[n] = None;
            }
            &Kind::TryCatch(catch_on_halt) => self.halt_try_catch(n, catch_on_halt),
            Kind::Unset(_) | Kind::EntryUpdated(_) => {}
            // 4.10 `EntryUpdatedDecorator::halt`: not executing the child, then
            // `DecoratorNode::halt`, which halts a RUNNING child. The real library
            // (4.8.2) leaves the child alone, as found against it: it stays RUNNING
            // without a halt, and the next time the decorator ticks it, it goes on.
            // `sequence_id_` is kept.
            Kind::Updated(..) => self.child_running[n] = false,
            // `LoopNode` has no `halt` of its own (`DecoratorNode::halt`): its queue is
            // dropped at its next IDLE tick.
            Kind::Loop(..) => {
                self.child_running[n] = false;
                self.reset_children(n);
            }
            // `ParallelNode::halt` / `ParallelAllNode::halt` clear; AS2FM's counts restart
            // on every tick anyway.
            Kind::Parallel(..) | Kind::ParallelAll(_) => {
                self.done[n].iter_mut().for_each(|d| *d = false);
                self.counts[n] = (0, 0);
                self.reset_children(n);
            }
            // `SequenceNode::halt`, `FallbackNode::halt`, `IfThenElseNode::halt`,
            // `RepeatNode::halt`, `RetryNode::halt`: the index or count back to 0;
            // `SwitchNode::halt`: `running_child_ = -1`; `RunOnceNode` (DecoratorNode::halt)
            // keeps `already_ticked_`.
            _ => {
                self.idx[n] = 0;
                self.skipped[n] = 0;
                self.reset_children(n);
            }
        }
        self.status[n] = None;
    }

    fn tick_inner(&mut self, n: usize) -> Result<Status, Stop> {
        use Status::*;
        let kind = &self.tree.nodes[n].kind;
        match kind {
            Kind::Leaf(ty) => {
                // A scripted leaf that may answer RUNNING is a `StatefulActionNode` (the
                // real-library harness registers it so): `StatefulActionNode::tick`
                // calls `onStart` when IDLE, `onRunning` when RUNNING, and otherwise
                // answers its last status without calling anything (a finished leaf its
                // parent did not reset, e.g. a 2-child IfThenElse's failed condition).
                // One that never does is synchronous (the harness registers a
                // `SyncActionNode`, as a condition is a `ConditionNode`): every tick runs
                // it (4.10 `action_node.cpp`, `SyncActionNode::executeTick`).
                let stateful = self
                    .scripts
                    .get(ty)
                    .is_some_and(|s| s.contains(&Status::Running));
                if self.btcpp() {
                    if let Some(s @ (Success | Failure)) = self.status[n] {
                        if stateful {
                            return Ok(s);
                        }
                    }
                    self.calls += 1;
                    if self.calls > self.opts.budget {
                        return Err(Stop::Livelock);
                    }
                }
                self.log.push(LeafEvent::Tick(self.tree.nodes[n].id));
                let script = self
                    .scripts
                    .get(ty)
                    .filter(|s| !s.is_empty())
                    .ok_or(format!("no script for leaf {ty}"))?;
                let k = self.leaf_ticks[n];
                let mut s = script[k % script.len()];
                self.leaf_ticks[n] += 1;
                // A leaf reading a string (`model::has_in_text`): SUCCESS while its
                // entry holds IN_TEXT (`getInput<std::string>`).
                if let Some(key) = &self.tree.nodes[n].input {
                    if super::model::has_in_text(ty)
                        && self.strs.get(key).map(String::as_str) == Some(super::model::IN_TEXT)
                    {
                        s = Success;
                    }
                }
                // A leaf with an `out` port (`model::plugin`): `setOutput<double>` of
                // its k-th value, which `Blackboard::set` stores as a LoopDouble's item
                // is (both write through `setOutput`).
                if let Some(key) = self.tree.nodes[n].out.clone() {
                    let values = super::model::OUT_VALUES;
                    self.write_output(
                        &key,
                        super::tree::LoopType::Double,
                        values[k % values.len()],
                    )?;
                }
                Ok(s)
            }
            Kind::Sequence => self.sequence(n, Success, Failure, false),
            Kind::Fallback => self.sequence(n, Failure, Success, false),
            _ if !self.btcpp() && self.tree.nodes[n].kind.btcpp4_only() => Err(Stop::Model(
                format!("{} has no AS2FM model", self.tree.nodes[n].tag),
            )),
            Kind::Timeout(_) | Kind::Delay(_) | Kind::Sleep(_) | Kind::TryCatch(_)
                if self.reading != Reading::Btcpp =>
            {
                Err(Stop::Model(format!(
                    "{} is modelled in BT.CPP 4's reading only",
                    self.tree.nodes[n].tag
                )))
            }
            &Kind::Timeout(ms) => self.timeout(n, ms),
            &Kind::Delay(ms) => self.delay(n, ms),
            &Kind::Sleep(ms) => Ok(self.sleep(n, ms)),
            Kind::TryCatch(_) => self.try_catch(n),
            Kind::AsyncSequence => self.sequence(n, Success, Failure, true),
            Kind::AsyncFallback => self.sequence(n, Failure, Success, true),
            &Kind::ParallelAll(f) => self.parallel_all(n, f),
            Kind::WhileDoElse => self.while_do_else(n),
            Kind::KeepRunningUntilFailure => self.keep_running(n),
            &Kind::RunOnce(skip) => self.run_once(n, skip),
            Kind::Switch(v, cases) => {
                let (v, cases) = (v.clone(), cases.clone());
                self.switch(n, &v, &cases)
            }
            Kind::SequenceWithMemory => self.sequence_with_memory(n),
            Kind::ReactiveSequence => self.reactive(n, Success, Failure),
            Kind::ReactiveFallback => self.reactive(n, Failure, Success),
            &Kind::Parallel(s, f) if self.reading == Reading::Btcpp3 => self.parallel3(n, s, f),
            &Kind::Parallel(s, f) => self.parallel(n, s, f),
            Kind::IfThenElse => self.if_then_else(n),
            // 4.10 `SubTreeNode::tick`: the body's answer passed on, the body reset
            // once it finished, the node RUNNING (set when IDLE) after a SKIPPED.
            Kind::SubTree => self.decorate(n, |s| s),
            Kind::Inverter => self.decorate(n, |s| match s {
                Success => Failure,
                Failure => Success,
                s => s,
            }),
            Kind::ForceSuccess => self.decorate(n, |s| match s {
                Running | Skipped => s,
                _ => Success,
            }),
            Kind::ForceFailure => self.decorate(n, |s| match s {
                Running | Skipped => s,
                _ => Failure,
            }),
            &Kind::Repeat(max) if self.btcpp() => self.repeat_btcpp(n, max, Success),
            &Kind::Retry(max) if self.btcpp() => self.repeat_btcpp(n, max, Failure),
            &Kind::Repeat(max) => self.repeat(n, max, Success),
            &Kind::Retry(max) => self.repeat(n, max, Failure),
            Kind::AlwaysSuccess => Ok(Success),
            Kind::AlwaysFailure => Ok(Failure),
            // `ScriptNode::tick`: runs the code, SUCCESS.
            Kind::Script(p) => {
                self.script(p)?;
                Ok(Success)
            }
            // `ScriptCondition::tick`: `cast<bool>` of the code's value.
            Kind::ScriptCondition(p) => {
                let v = self.script(p)?;
                Ok(if super::script::truth(&v)? {
                    Success
                } else {
                    Failure
                })
            }
            Kind::Precondition(p, otherwise) => {
                let otherwise = *otherwise;
                self.precondition(n, p, otherwise)
            }
            Kind::SetBlackboard(key, v) => self.set_blackboard(key, v),
            // `UnsetBlackboardNode::tick`: `blackboard->unset(key)` erases the entry (a
            // missing one is no error), SUCCESS.
            Kind::Unset(key) => {
                self.erased.insert(key.clone());
                self.vars.remove(key);
                self.reals.remove(key);
                self.strs.remove(key);
                self.bb.remove(key);
                self.seq.remove(key);
                Ok(Success)
            }
            Kind::EntryUpdated(e) => {
                let e = e.clone();
                Ok(if self.updated(n, &e) {
                    Success
                } else {
                    Failure
                })
            }
            Kind::Updated(e, otherwise) => {
                let (e, otherwise) = (e.clone(), *otherwise);
                self.entry_updated_decorator(n, &e, otherwise)
            }
            Kind::Loop(ty, items, value, if_empty) => {
                let (ty, value, if_empty) = (*ty, value.clone(), *if_empty);
                let items = items.clone();
                self.loop_node(n, ty, &items, value.as_deref(), if_empty)
            }
            Kind::Check(ty, a, b, mismatch, numeric) => {
                let (ty, mut mismatch, numeric) = (*ty, *mismatch, *numeric);
                let c = self.child(n, 0);
                // v3.8 `BlackboardPreconditionNode::tick`: `getInput("return_on_mismatch")`
                // converts with `convertFromString<NodeStatus>`, which knows the names
                // only; AS2FM's numbers fail to convert and the default FAILURE stays.
                if numeric && self.btcpp() {
                    mismatch = Failure;
                }
                if self.same(ty, a, b)? {
                    // v3.8: `return child_node_->executeTick()`; the child is not reset.
                    self.tick(c)
                } else {
                    // v3.8: `haltChild()` only if the child is RUNNING (a finished child
                    // keeps its status). AS2FM's `blackboard_check_int.ascxml` halts the
                    // child on every mismatch.
                    if !self.btcpp() || self.status[c] == Some(Running) {
                        self.halt_child(c);
                    }
                    Ok(mismatch)
                }
            }
        }
    }

    /// Whether entry `e` was written since node `n` last looked (4.10
    /// `updated_action.cpp`, `EntryUpdatedAction::tick`, and `updated_decorator.cpp`,
    /// `EntryUpdatedDecorator::tick`): the entry's `sequence_id` against the one the node
    /// kept (0 at first), which it then keeps; a missing entry is not updated and leaves
    /// the kept one alone. An entry is missing until a script or an output writes it
    /// ([`Oracle::seq`]); one a port names in `{}` exists from load with counter 0, which
    /// answers the same.
    fn updated(&mut self, n: usize, e: &str) -> bool {
        let exists =
            self.vars.contains_key(e) || self.strs.contains_key(e) || self.bb.contains_key(e);
        if !exists {
            return false;
        }
        let now = self.seq.get(e).copied().unwrap_or(0);
        let before = std::mem::replace(&mut self.seen[n], now);
        before != now
    }

    /// `EntryUpdatedDecorator::tick` (4.10 `updated_decorator.cpp`): a child still
    /// RUNNING is ticked again without looking at the entry; otherwise, not updated
    /// answers `otherwise` (SKIPPED for `SkipUnlessUpdated`, RUNNING for
    /// `WaitValueUpdate`) and updated ticks the child.
    fn entry_updated_decorator(
        &mut self,
        n: usize,
        e: &str,
        otherwise: Status,
    ) -> Result<Status, Stop> {
        let c = self.child(n, 0);
        if !self.child_running[n] && !self.updated(n, e) {
            return Ok(otherwise);
        }
        let s = self.tick(c)?;
        self.child_running[n] = s == Status::Running;
        // `DecoratorNode::executeTick` (4.10 `decorator_node.cpp`): after the tick a
        // finished child's status is reset (no halt), so a leaf runs again next time.
        if matches!(s, Status::Success | Status::Failure) {
            self.status[c] = None;
        }
        Ok(s)
    }

    /// `LoopNode<T>::tick` (4.10 `decorators/loop_node.h`) over a queue written in the
    /// tree: when IDLE, a fresh copy of the queue and no child running; unless the child
    /// is RUNNING, the front item is popped and written to `value`; nothing popped and
    /// no child running answers `if_empty` (without ticking the child or leaving IDLE);
    /// else the node goes RUNNING and ticks the child, resets a finished child, answers
    /// FAILURE on its FAILURE and RUNNING otherwise.
    fn loop_node(
        &mut self,
        n: usize,
        ty: super::tree::LoopType,
        items: &[String],
        value: Option<&str>,
        if_empty: Status,
    ) -> Result<Status, Stop> {
        if self.status[n].is_none() {
            self.child_running[n] = false;
            self.queue[n] = items.iter().cloned().collect();
        }
        let mut popped = false;
        if !self.child_running[n] {
            if let Some(item) = self.queue[n].pop_front() {
                popped = true;
                if let Some(key) = value {
                    self.write_output(key, ty, &item)?;
                }
            }
        }
        if !popped && !self.child_running[n] {
            return Ok(if_empty);
        }
        self.status[n] = Some(Status::Running);
        let c = self.child(n, 0);
        let s = self.tick(c)?;
        self.child_running[n] = s == Status::Running;
        if matches!(s, Status::Success | Status::Failure) {
            self.halt_child(c);
        }
        Ok(if s == Status::Failure {
            Status::Failure
        } else {
            Status::Running
        })
    }

    /// `setOutput("value", item)`: the entry written (one more on its counter). An entry
    /// scripts use holds a number: an int or bool item is written as one (a bool as 0 or
    /// 1, as the real library reads it back), a double into an entry holding an integer
    /// only if it is whole ("Invalid floating point to integer conversion" otherwise), a
    /// string throws ("Any::copyInto fails"), all as found against the real library
    /// (4.8.2). A double into an entry holding a double, or holding nothing yet (the
    /// port created it empty when the tree was loaded; `Any::copyInto` into an empty
    /// `Any` stores the value as it is), is stored as a double, which scripts then read
    /// (4.8.2, `tests/bt/btcpp4/loop.toml`). Any other entry keeps the text.
    fn write_output(
        &mut self,
        key: &str,
        ty: super::tree::LoopType,
        item: &str,
    ) -> Result<(), Stop> {
        use super::tree::LoopType;
        let number = matches!(ty, LoopType::Int | LoopType::Bool);
        if ty == LoopType::String && self.loop_string(key, item) {
            return Ok(());
        }
        if number || ty == LoopType::Double || self.vars.contains_key(key) {
            let v = match ty {
                LoopType::Int => item
                    .parse::<i64>()
                    .map_err(|_| Stop::Model(format!("queue item {item}")))?,
                LoopType::Bool => i64::from(matches!(item, "true" | "1")),
                LoopType::Double => {
                    let d: f64 = item
                        .parse()
                        .map_err(|_| Stop::Model(format!("queue item {item}")))?;
                    if self.dbl.contains(key) || !self.vars.contains_key(key) {
                        self.vars.insert(key.to_string(), d as i64);
                        self.dbl.insert(key.to_string());
                        self.reals.insert(key.to_string(), d);
                        *self.seq.entry(key.to_string()).or_default() += 1;
                        return Ok(());
                    }
                    if d.fract() != 0.0 {
                        return Err(Stop::Error(
                            "Invalid floating point to integer conversion".into(),
                        ));
                    }
                    d as i64
                }
                LoopType::String => return Err(Stop::Error("Any::copyInto fails".into())),
            };
            self.vars.insert(key.to_string(), v);
            self.reals.remove(key);
        } else {
            self.bb.insert(key.to_string(), item.to_string());
        }
        *self.seq.entry(key.to_string()).or_default() += 1;
        Ok(())
    }

    /// A LoopString's item written into `key` when the entry holds strings for scripts
    /// (`true`; one more on its counter): BT.CPP 4 creates the entry as a `std::string`
    /// when it loads the tree (4.10 `src/xml_parsing.cpp`,
    /// `XMLParser::PImpl::createNodeFromXML`: a remapped port's entry gets the port's
    /// type, here `OutputPort<std::string>("value")`), so scripts compare it as a
    /// string and store strings in it (4.8.2, measured). `false` where a script holds a
    /// number there (the write throws).
    fn loop_string(&mut self, key: &str, item: &str) -> bool {
        if self.vars.contains_key(key) {
            return false;
        }
        self.strs.insert(key.to_string(), item.to_string());
        *self.seq.entry(key.to_string()).or_default() += 1;
        true
    }

    /// `PreconditionNode::tick` (4.10; 4.8.2 alike, as the real-library differential
    /// finds): the `if` script only while the child has not started
    /// (`_children_running`); false answers `else`; true ticks the child, and a finished
    /// child is reset and the script is due again. A halt (`DecoratorNode::halt`) does
    /// not clear `_children_running`: after one, the next tick skips the script.
    fn precondition(&mut self, n: usize, p: &Program, otherwise: Status) -> Result<Status, Stop> {
        if !self.memo[n] {
            self.memo[n] = self.holds(p)?;
        }
        if !self.memo[n] {
            return Ok(otherwise);
        }
        let c = self.child(n, 0);
        let s = self.tick(c)?;
        if matches!(s, Status::Success | Status::Failure) {
            self.halt_child(c);
            self.memo[n] = false;
        }
        Ok(s)
    }

    /// `SetBlackboard`. v4 `SetBlackboardNode::tick`: a `{other}` value copies that
    /// entry. The real library (4.8.2) breaks on the string entries `SetBlackboard`
    /// writes, as found against it (`tests/bt/real/set_blackboard.toml`): an entry some
    /// SetBlackboard's `value` port names in `{}` is created at load (typed for any
    /// type); its first literal write succeeds but leaves it typed `BT::Any` and without a
    /// value a copy can read, and every later literal write throws ("Can't convert string
    /// [..] to type [BT::Any]", the `parseString` in `SetBlackboardNode::tick`). So a copy
    /// always answers FAILURE (`out_value.empty()`), creating its destination typed
    /// `BT::Any` if it did not exist (a literal write to it then throws). 3.8
    /// `SetBlackboard::tick` copies the value (`dst_entry->value = src_entry->value`).
    fn set_blackboard(&mut self, key: &str, v: &Operand) -> Result<Status, Stop> {
        if self.reading == Reading::Btcpp && self.opts.from_xml {
            let written = self.writes.get(key).copied().unwrap_or(0);
            let at_load = self.at_load.contains(key);
            match v {
                Operand::Entry(_) => {
                    if written == 0 && !at_load {
                        self.any_typed.insert(key.to_string());
                    }
                    return Ok(Status::Failure);
                }
                Operand::Lit(_) if self.any_typed.contains(key) || (at_load && written > 0) => {
                    return Err(Stop::Error("Can't convert string".into()));
                }
                Operand::Lit(_) => {}
            }
        }
        let v = self.value(v)?;
        self.bb.insert(key.to_string(), v);
        *self.writes.entry(key.to_string()).or_default() += 1;
        *self.seq.entry(key.to_string()).or_default() += 1;
        Ok(Status::Success)
    }

    /// `SequenceNode::tick` (`cont` SUCCESS) and `FallbackNode::tick` (`cont` FAILURE);
    /// AS2FM's `sequence.ascxml` / `fallback.ascxml` halt every child on finishing. Only
    /// the `AsyncSequence` / `AsyncFallback` registrations (`asynch_`) yield on a
    /// wake-up, as SequenceWithMemory does.
    fn sequence(
        &mut self,
        n: usize,
        cont: Status,
        stop: Status,
        asynch: bool,
    ) -> Result<Status, Stop> {
        let len = self.n_children(n);
        // 4.10 `SequenceNode::tick`: the count of skipped children restarts when the node
        // was not active (`!isStatusActive(status())`: IDLE); a skipped child is passed
        // over; every child skipped answers SKIPPED.
        if self.status[n].is_none() {
            self.skipped[n] = 0;
        }
        while (self.idx[n] as usize) < len {
            let c = self.child(n, self.idx[n] as usize);
            let prev = self.status[c];
            match self.tick(c)? {
                Status::Running => return Ok(Status::Running),
                s if s == stop => {
                    self.reset_children(n);
                    self.idx[n] = 0;
                    return Ok(stop);
                }
                Status::Skipped => {
                    self.idx[n] += 1;
                    self.skipped[n] += 1;
                }
                _ => {
                    self.idx[n] += 1;
                    if asynch && (self.idx[n] as usize) < len && self.yields(prev) {
                        return Ok(Status::Running);
                    }
                }
            }
        }
        let all_skipped = self.skipped[n] == len;
        self.reset_children(n);
        self.idx[n] = 0;
        self.skipped[n] = 0;
        Ok(if all_skipped { Status::Skipped } else { cont })
    }

    /// `SequenceWithMemory::tick`: a failure keeps the index. BT.CPP (4 and 3.8
    /// `SequenceStarNode::tick`) then halts the children from the failed one on
    /// (`haltChild(i)` for `i >= current_child_idx_`); AS2FM's `halt_current_child` state
    /// halts the failed child alone. BT.CPP 4 with the wake-up signal: a child that was
    /// IDLE before this tick and succeeds while more children remain makes it emit the
    /// signal and answer RUNNING (`requiresWakeUp() && prev_status == IDLE`).
    fn sequence_with_memory(&mut self, n: usize) -> Result<Status, Stop> {
        let len = self.n_children(n);
        // Skipped children as in `sequence` (4.10 `SequenceWithMemory::tick`).
        if self.status[n].is_none() {
            self.skipped[n] = 0;
        }
        while (self.idx[n] as usize) < len {
            let at = self.idx[n] as usize;
            let c = self.child(n, at);
            let prev = self.status[c];
            match self.tick(c)? {
                Status::Running => return Ok(Status::Running),
                Status::Failure => {
                    let last = if self.reading == Reading::As2fm {
                        at + 1
                    } else {
                        len
                    };
                    for i in at..last {
                        let c = self.child(n, i);
                        self.halt_child(c);
                    }
                    return Ok(Status::Failure);
                }
                Status::Success => {
                    self.idx[n] += 1;
                    if (self.idx[n] as usize) < len && self.yields(prev) {
                        return Ok(Status::Running);
                    }
                }
                Status::Skipped => {
                    self.idx[n] += 1;
                    self.skipped[n] += 1;
                }
            }
        }
        let all_skipped = self.skipped[n] == len;
        self.reset_children(n);
        self.idx[n] = 0;
        self.skipped[n] = 0;
        Ok(if all_skipped {
            Status::Skipped
        } else {
            Status::Success
        })
    }

    /// Whether a node yields after a child that was `prev` before the tick finished
    /// (BT.CPP 4 `requiresWakeUp() && prev_status == NodeStatus::IDLE`), emitting the
    /// wake-up signal (`emitWakeUpSignal`) if so.
    fn yields(&mut self, prev: Option<Status>) -> bool {
        let y = self.reading == Reading::Btcpp && self.opts.from_xml && prev.is_none();
        if y {
            self.pending = true;
        }
        y
    }

    /// `ParallelAllNode::tick` (4.10): every child not yet finished is ticked; once all
    /// have finished, `haltChildren()` and FAILURE if at least `max_failures` failed
    /// (negative counts from the end), else SUCCESS; throws when `max_failures` exceeds
    /// the children ("Number of children is less than threshold").
    fn parallel_all(&mut self, n: usize, f: i64) -> Result<Status, Stop> {
        let len = self.n_children(n);
        let th = if f < 0 {
            (len as i64 + f + 1).max(0)
        } else {
            f
        };
        if (len as i64) < th {
            return Err(Stop::Error(
                "Number of children is less than threshold".into(),
            ));
        }
        // A skipped child counts as finished for this tick only (`skipped_count`); all
        // skipped: SKIPPED, nothing cleared.
        let mut skipped = 0;
        for i in 0..len {
            if self.done[n][i] {
                continue;
            }
            let c = self.child(n, i);
            match self.tick(c)? {
                Status::Success => self.done[n][i] = true,
                Status::Failure => {
                    self.done[n][i] = true;
                    self.counts[n].1 += 1;
                }
                Status::Running => {}
                Status::Skipped => skipped += 1,
            }
        }
        if skipped == len {
            return Ok(Status::Skipped);
        }
        if skipped + self.done[n].iter().filter(|d| **d).count() >= len {
            self.reset_children(n);
            self.done[n].iter_mut().for_each(|d| *d = false);
            let failed = self.counts[n].1 >= th;
            self.counts[n] = (0, 0);
            return Ok(if failed {
                Status::Failure
            } else {
                Status::Success
            });
        }
        Ok(Status::Running)
    }

    /// `WhileDoElseNode::tick` (4.10): the condition on every tick; SUCCESS halts the
    /// else branch (`haltChild(2)`) and ticks the do branch, FAILURE halts the do branch
    /// and ticks the else branch (with two children, FAILURE); a finished answer resets
    /// every child (the condition stays as it finished while a branch runs).
    fn while_do_else(&mut self, n: usize) -> Result<Status, Stop> {
        let len = self.n_children(n);
        let cond = self.child(n, 0);
        let s = match self.tick(cond)? {
            // 4.10 `WhileDoElseNode::tick`: a skipped condition leaves the answer IDLE;
            // the children are reset and `executeTick`'s `setStatus(IDLE)` throws.
            Status::Skipped => {
                self.reset_children(n);
                return Err(Stop::Error(
                    "you are not allowed to set manually the status to IDLE".into(),
                ));
            }
            Status::Running => return Ok(Status::Running),
            Status::Success => {
                if len == 3 {
                    let e = self.child(n, 2);
                    self.halt_child(e);
                }
                let d = self.child(n, 1);
                self.tick(d)?
            }
            Status::Failure if len == 3 => {
                let d = self.child(n, 1);
                self.halt_child(d);
                let e = self.child(n, 2);
                self.tick(e)?
            }
            Status::Failure => Status::Failure,
        };
        if s != Status::Running {
            self.reset_children(n);
        }
        Ok(s)
    }

    /// `TimeoutNode::tick` (4.10 `decorators/timeout_node.cpp`): the first tick starts the
    /// timer (none when `msec` is 0) and clears `child_halted_`; once the timer halted the
    /// child the tick answers FAILURE without ticking it; otherwise the child's answer,
    /// a finished one cancelling the timer and resetting the child.
    fn timeout(&mut self, n: usize, ms: u64) -> Result<Status, Stop> {
        if !self.started[n] {
            self.started[n] = true;
            self.flag[n] = false;
            if ms > 0 {
                self.due[n] = Some(self.now + ms);
            }
        }
        if self.flag[n] {
            self.started[n] = false;
            return Ok(Status::Failure);
        }
        let c = self.child(n, 0);
        let s = self.tick(c)?;
        if matches!(s, Status::Success | Status::Failure) {
            self.started[n] = false;
            self.due[n] = None;
            self.halt_child(c);
        }
        Ok(s)
    }

    /// `DelayNode::tick` (4.10 `decorators/delay_node.cpp`): the first tick starts the
    /// timer and answers RUNNING; once it fired (`delay_complete_`) every tick ticks the
    /// child, a finished answer ending the delay and resetting the child.
    /// (`delay_aborted_` is never set in 4.10: its branch is dead.)
    fn delay(&mut self, n: usize, ms: u64) -> Result<Status, Stop> {
        if !self.started[n] {
            self.flag[n] = false;
            self.started[n] = true;
            self.due[n] = Some(self.now + ms);
        }
        if !self.flag[n] {
            return Ok(Status::Running);
        }
        let c = self.child(n, 0);
        let s = self.tick(c)?;
        if matches!(s, Status::Success | Status::Failure) {
            self.started[n] = false;
            self.halt_child(c);
        }
        Ok(s)
    }

    /// `SleepNode` (4.10 `actions/sleep_node.cpp`), a `StatefulActionNode`: `onStart`
    /// answers SUCCESS for 0 ms, else starts the timer and answers RUNNING; `onRunning`
    /// answers RUNNING until the timer fired, then SUCCESS; a finished Sleep its parent
    /// did not reset answers that status again (`StatefulActionNode::tick`).
    fn sleep(&mut self, n: usize, ms: u64) -> Status {
        match self.status[n] {
            Some(s @ (Status::Success | Status::Failure)) => s,
            Some(Status::Running) if self.flag[n] => Status::Running,
            Some(Status::Running) => Status::Success,
            _ if ms == 0 => Status::Success,
            _ => {
                self.flag[n] = true;
                self.due[n] = Some(self.now + ms);
                Status::Running
            }
        }
    }

    /// `TryCatchNode::tick` (4.10 `controls/try_catch_node.cpp`): the children but the
    /// last are a Sequence (the try block); a FAILURE there resets the children and ticks
    /// the last child (the catch) in the same tick, which keeps being ticked while
    /// RUNNING and whose finished answer (either) resets the children and answers
    /// FAILURE. The whole try block skipped answers SKIPPED.
    fn try_catch(&mut self, n: usize) -> Result<Status, Stop> {
        use Status::*;
        let len = self.n_children(n);
        // `if(!isStatusActive(status()))`: a node its parent reset starts afresh.
        if self.status[n].is_none() {
            self.skipped[n] = 0;
            self.in_catch[n] = false;
        }
        self.status[n] = Some(Running);
        let tries = len as i64 - 1;
        loop {
            if self.in_catch[n] {
                let c = self.child(n, len - 1);
                if self.tick(c)? == Running {
                    return Ok(Running);
                }
                self.reset_children(n);
                self.idx[n] = 0;
                self.in_catch[n] = false;
                return Ok(Failure);
            }
            while self.idx[n] < tries {
                let c = self.child(n, self.idx[n] as usize);
                match self.tick(c)? {
                    Running => return Ok(Running),
                    Success => self.idx[n] += 1,
                    Skipped => {
                        self.idx[n] += 1;
                        self.skipped[n] += 1;
                    }
                    // `return tick()`: into the catch at once.
                    Failure => {
                        self.reset_children(n);
                        self.idx[n] = 0;
                        self.in_catch[n] = true;
                        break;
                    }
                }
            }
            if self.in_catch[n] {
                continue;
            }
            let all_skipped = self.skipped[n] as i64 == tries;
            self.reset_children(n);
            self.idx[n] = 0;
            self.skipped[n] = 0;
            return Ok(if all_skipped { Skipped } else { Success });
        }
    }

    /// `TryCatchNode::halt` (4.10): with `catch_on_halt`, halted while in the try block,
    /// it halts the try children, ticks the catch child once (halting it if it answers
    /// RUNNING); then forgets its place and `ControlNode::halt` resets the children.
    fn halt_try_catch(&mut self, n: usize, catch_on_halt: bool) {
        let len = self.n_children(n);
        if catch_on_halt && !self.in_catch[n] && self.status[n].is_some() && len >= 2 {
            for i in 0..len - 1 {
                let c = self.child(n, i);
                self.halt_child(c);
            }
            let c = self.child(n, len - 1);
            match self.tick(c) {
                Ok(Status::Running) => self.halt_child(c),
                Ok(_) => {}
                Err(e) => {
                    self.fault.get_or_insert(format!("{e:?}"));
                }
            }
        }
        self.idx[n] = 0;
        self.skipped[n] = 0;
        self.in_catch[n] = false;
        self.reset_children(n);
    }

    /// `KeepRunningUntilFailureNode::tick` (4.10): a finished child is reset; its
    /// SUCCESS is RUNNING, its FAILURE FAILURE.
    fn keep_running(&mut self, n: usize) -> Result<Status, Stop> {
        let c = self.child(n, 0);
        let s = self.tick(c)?;
        // A skipped child: `return status()`, the RUNNING it set itself.
        if matches!(s, Status::Running | Status::Skipped) {
            return Ok(Status::Running);
        }
        self.halt_child(c);
        Ok(if s == Status::Success {
            Status::Running
        } else {
            Status::Failure
        })
    }

    /// `RunOnceNode::tick` (4.10): once the child has finished (then reset), the node
    /// answers, without ticking it, SKIPPED with `then_skip` (`skip`, the default), else
    /// that status, for ever; a halt (`DecoratorNode::halt`) does not forget it.
    fn run_once(&mut self, n: usize, skip: bool) -> Result<Status, Stop> {
        if let Some(s) = self.once[n] {
            return Ok(if skip { Status::Skipped } else { s });
        }
        let c = self.child(n, 0);
        let s = self.tick(c)?;
        // A skipped child is not a finished one (`isStatusCompleted`).
        if matches!(s, Status::Success | Status::Failure) {
            self.once[n] = Some(s);
            self.halt_child(c);
        }
        Ok(s)
    }

    /// `SwitchNode::tick` (4.10): the first `case_i` equal to `variable` picks child i,
    /// none (or no variable) the last; a child that ran on an earlier tick and is not
    /// the one picked is halted (`haltChild(running_child_)`); a finished answer resets
    /// every child.
    fn switch(&mut self, n: usize, v: &Operand, cases: &[String]) -> Result<Status, Stop> {
        let value = self.value(v).ok();
        let pick = value
            .and_then(|v| cases.iter().position(|c| *c == v))
            .unwrap_or(cases.len());
        // `running_child_` + 1 (0: none).
        let running = self.idx[n] - 1;
        if running >= 0 && running as usize != pick {
            let c = self.child(n, running as usize);
            self.halt_child(c);
        }
        let c = self.child(n, pick);
        let s = self.tick(c)?;
        if s == Status::Skipped {
            // 4.10 `SwitchNode::tick`: `running_child_ = -1`, SKIPPED, nothing reset.
            self.idx[n] = 0;
        } else if s == Status::Running {
            self.idx[n] = pick as i64 + 1;
        } else {
            self.reset_children(n);
            self.idx[n] = 0;
        }
        Ok(s)
    }

    /// `ReactiveSequence::tick` / `ReactiveFallback::tick` (and AS2FM's
    /// `reactive_sequence.ascxml` / `reactive_fallback.ascxml`): every tick starts at the
    /// first child; a RUNNING child halts all the others.
    fn reactive(&mut self, n: usize, cont: Status, stop: Status) -> Result<Status, Stop> {
        let len = self.n_children(n);
        // 4.10 `ReactiveSequence::tick`: a skipped child is reset (`haltChild`, so it
        // can be skipped again); every child skipped answers SKIPPED.
        let mut all_skipped = true;
        for i in 0..len {
            let c = self.child(n, i);
            let s = self.tick(c)?;
            all_skipped &= s == Status::Skipped;
            match s {
                Status::Skipped => self.halt_child(c),
                Status::Running => {
                    for j in (0..len).filter(|&j| j != i) {
                        let o = self.child(n, j);
                        self.halt_child(o);
                    }
                    return Ok(Status::Running);
                }
                s if s == stop => {
                    self.reset_children(n);
                    return Ok(stop);
                }
                _ => {}
            }
        }
        self.reset_children(n);
        Ok(if all_skipped { Status::Skipped } else { cont })
    }

    /// `ParallelNode::tick` (v4: finished children are not ticked again, counts build up
    /// across ticks, FAILURE also when success can no longer be reached, both checked
    /// after each child) against AS2FM's `parallel.ascxml` (every child ticked on every
    /// tick, counts from zero, the thresholds checked after each child). v4 throws when a
    /// threshold exceeds the children ("Number of children is less than threshold").
    fn parallel(&mut self, n: usize, s: i64, f: i64) -> Result<Status, Stop> {
        let raw_s = s;
        let len = self.n_children(n) as i64;
        let th = |t: i64| if t < 0 { (len + t + 1).max(0) } else { t };
        let (s, f) = (th(s), th(f));
        if self.btcpp() && (s > len || f > len) {
            return Err(Stop::Error(
                "Number of children is less than threshold".into(),
            ));
        }
        if self.reading == Reading::As2fm {
            self.counts[n] = (0, 0);
        }
        let btcpp = self.btcpp();
        // 4.10 `ParallelNode::tick`: children skipped in this tick count towards a
        // success threshold written negative; every child skipped answers SKIPPED.
        let mut skipped = 0;
        for i in 0..len as usize {
            if !self.done[n][i] {
                let c = self.child(n, i);
                match self.tick(c)? {
                    Status::Success => {
                        self.counts[n].0 += 1;
                        self.done[n][i] = btcpp;
                    }
                    Status::Failure => {
                        self.counts[n].1 += 1;
                        self.done[n][i] = btcpp;
                    }
                    Status::Running => {}
                    Status::Skipped => skipped += 1,
                }
            }
            let (sc, fc) = self.counts[n];
            let sc = if raw_s < 0 { sc + skipped } else { sc };
            let fail = if btcpp {
                len - fc < s || fc == f
            } else {
                fc >= f
            };
            if sc >= s || fail {
                self.done[n].iter_mut().for_each(|d| *d = false);
                self.counts[n] = (0, 0);
                self.reset_children(n);
                return Ok(if sc >= s {
                    Status::Success
                } else {
                    Status::Failure
                });
            }
        }
        Ok(if skipped == len {
            Status::Skipped
        } else {
            Status::Running
        })
    }

    /// v3.8 `ParallelNode::tick`: every tick counts from zero over all children in
    /// order; a child in the skip list (finished on an earlier tick) is not ticked but
    /// counts with its kept status; after each child, SUCCESS once the successes equal
    /// the threshold, FAILURE once the failures exceed `children - success threshold` or
    /// equal the failure threshold.
    fn parallel3(&mut self, n: usize, s: i64, f: i64) -> Result<Status, Stop> {
        let len = self.n_children(n) as i64;
        let th = |t: i64| if t < 0 { (len + t + 1).max(0) } else { t };
        let (s, f) = (th(s), th(f));
        if s > len || f > len {
            return Err(Stop::Error(
                "Number of children is less than threshold".into(),
            ));
        }
        let (mut sc, mut fc) = (0, 0);
        for i in 0..len as usize {
            let c = self.child(n, i);
            let st = if self.done[n][i] {
                self.kept[n][i].ok_or_else(|| Stop::Model("skipped child is idle".into()))?
            } else {
                self.tick(c)?
            };
            if matches!(st, Status::Success | Status::Failure) {
                self.kept[n][i] = Some(st);
            }
            match st {
                Status::Skipped => return Err(Stop::Model("SKIPPED: not modelled here".into())),
                Status::Success => {
                    self.done[n][i] = true;
                    sc += 1;
                    if sc == s {
                        self.done[n].iter_mut().for_each(|d| *d = false);
                        self.reset_children(n);
                        return Ok(Status::Success);
                    }
                }
                Status::Failure => {
                    self.done[n][i] = true;
                    fc += 1;
                    if fc > len - s || fc == f {
                        self.done[n].iter_mut().for_each(|d| *d = false);
                        self.reset_children(n);
                        return Ok(Status::Failure);
                    }
                }
                Status::Running => {}
            }
        }
        Ok(Status::Running)
    }

    /// `IfThenElseNode::tick` (AS2FM's `if_then_else.ascxml` alike): the condition while
    /// no branch runs; a two-child node whose condition fails answers FAILURE without
    /// resetting anything.
    fn if_then_else(&mut self, n: usize) -> Result<Status, Stop> {
        if self.idx[n] == 0 {
            let c = self.child(n, 0);
            match self.tick(c)? {
                // 4.10 `IfThenElseNode::tick`: a skipped condition reaches its last line.
                Status::Skipped => {
                    return Err(Stop::Error(
                        "Something unexpected happened in IfThenElseNode".into(),
                    ))
                }
                Status::Running => return Ok(Status::Running),
                Status::Success => self.idx[n] = 1,
                Status::Failure if self.n_children(n) == 3 => self.idx[n] = 2,
                Status::Failure => return Ok(Status::Failure),
            }
        }
        let c = self.child(n, self.idx[n] as usize);
        let s = self.tick(c)?;
        if s != Status::Running {
            self.reset_children(n);
            self.idx[n] = 0;
        }
        Ok(s)
    }

    /// Inverter / ForceSuccess / ForceFailure (`InverterNode::tick`, ...): BT.CPP resets
    /// a finished child's status (`resetChild`, no halt since it is not RUNNING); AS2FM's
    /// models do nothing to it.
    fn decorate(&mut self, n: usize, map: fn(Status) -> Status) -> Result<Status, Stop> {
        let c = self.child(n, 0);
        let s = self.tick(c)?;
        // 4.10 `InverterNode::tick`, `ForceSuccessNode::tick`: SKIPPED passes through,
        // the child not reset.
        if matches!(s, Status::Success | Status::Failure) && self.btcpp() {
            self.halt_child(c);
        }
        Ok(map(s))
    }

    /// AS2FM's `repeat_node.ascxml` (`again` SUCCESS) and `retry_node.ascxml` (`again`
    /// FAILURE): the child is ticked again in the same tick until the count is used up;
    /// the Repeat halts the child after each attempt (`bt_halt_child` in `tick_child`),
    /// the Retry never does.
    fn repeat(&mut self, n: usize, max: i64, again: Status) -> Result<Status, Stop> {
        let stop = if again == Status::Success {
            Status::Failure
        } else {
            Status::Success
        };
        let c = self.child(n, 0);
        let halts = again == Status::Success;
        let mut spins = 0;
        while max == -1 || self.idx[n] < max {
            // -1 repeats without end: a child that never stops would hang BT.CPP too.
            spins += 1;
            if spins > 10_000 {
                return Err(Stop::Model(
                    "a Repeat/Retry of -1 never stops within one tick".into(),
                ));
            }
            let s = self.tick(c)?;
            if s == Status::Running {
                return Ok(Status::Running);
            }
            if s == stop {
                self.idx[n] = 0;
                if halts {
                    self.halt_child(c);
                }
                return Ok(stop);
            }
            self.idx[n] += 1;
            if halts {
                self.halt_child(c);
            }
        }
        self.idx[n] = 0;
        Ok(again)
    }

    /// `RepeatNode::tick` (`again` SUCCESS) and `RetryNode::tick` (`again` FAILURE), 4.10
    /// and 3.8: while the count allows (`count < max || max == -1`) the child is ticked;
    /// `again` counts an attempt and resets the child (`resetChild`), the other finished
    /// status resets count and child and is the answer, RUNNING is the answer. BT.CPP 4
    /// with the wake-up signal: after an `again` from a child that was IDLE before, with
    /// attempts left, the node emits the signal and answers RUNNING.
    fn repeat_btcpp(&mut self, n: usize, max: i64, again: Status) -> Result<Status, Stop> {
        let c = self.child(n, 0);
        let mut more = self.idx[n] < max || max == -1;
        while more {
            let prev = self.status[c];
            match self.tick(c)? {
                Status::Running => return Ok(Status::Running),
                s if s == again => {
                    self.idx[n] += 1;
                    more = self.idx[n] < max || max == -1;
                    self.halt_child(c);
                    if more && self.yields(prev) {
                        return Ok(Status::Running);
                    }
                }
                // 4.10 `RepeatNode::tick` / `RetryNode::tick`: a skipped child is reset
                // and the node is skipped too, its count kept.
                Status::Skipped => {
                    self.halt_child(c);
                    return Ok(Status::Skipped);
                }
                s => {
                    self.idx[n] = 0;
                    self.halt_child(c);
                    return Ok(s);
                }
            }
        }
        self.idx[n] = 0;
        Ok(again)
    }
}

/// Runs `ticks` root ticks of nodes built by hand: the root's status at each and the
/// leaves' log; any early end is an error.
pub fn run(
    tree: &Tree,
    scripts: &Scripts,
    reading: Reading,
    ticks: usize,
) -> Result<(Vec<Status>, Vec<LeafEvent>), String> {
    let mut o = Oracle::new(tree, scripts, reading);
    let mut out = Vec::with_capacity(ticks);
    for _ in 0..ticks {
        out.push(o.tick_root()?);
    }
    Ok((out, o.log))
}

/// Runs up to `ticks` root ticks under `opts`, stopping where BT.CPP would throw or never
/// return. `Err` only for a case the oracle cannot run (a leaf without a script, an entry
/// read before it is written).
pub fn run_with(
    tree: &Tree,
    scripts: &Scripts,
    opts: Options,
    ticks: usize,
) -> Result<Outcome, String> {
    let mut o = Oracle::with(tree, scripts, opts);
    let mut statuses = Vec::with_capacity(ticks);
    let mut end = None;
    for tick in 0..ticks {
        o.begin_tick();
        let mark = o.log.len();
        match o.tick_root_stop() {
            Ok(s) => statuses.push(s),
            Err(Stop::Model(e)) => return Err(e),
            Err(Stop::Error(text)) => {
                end = Some(End::Error { tick, text });
                break;
            }
            Err(Stop::Livelock) => {
                o.log.truncate(mark);
                end = Some(End::Livelock { tick });
                break;
            }
            Err(Stop::Hang) => {
                o.log.truncate(mark);
                end = Some(End::Hang { tick });
                break;
            }
        }
    }
    // An entry holding a double that is not whole is left out: the real-library harness
    // reads entries as integers (`get_int` fails there).
    let reals = o.reals;
    let vars = o
        .vars
        .into_iter()
        .filter(|(k, _)| !k.starts_with("__st"))
        .filter(|(k, _)| {
            reals
                .get(k)
                .is_none_or(|r| r.fract() == 0.0 && r.abs() <= 9.0e15)
        })
        .collect();
    Ok(Outcome {
        statuses,
        log: o.log,
        end,
        vars,
    })
}
