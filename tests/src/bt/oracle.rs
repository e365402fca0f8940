//! The reference executor of BehaviorTree.CPP: a direct tick-by-tick interpreter of a
//! [`Tree`] whose leaves follow scripts, recording every tick and halt a leaf receives.
//!
//! Two readings, for the nodes where AS2FM's SCXML models of the built-in nodes and
//! BehaviorTree.CPP disagree ([`Reading`]). Each rule cites the function that decides it:
//! BT.CPP v4.10 (`src/controls/*.cpp`, `src/decorators/*.cpp`, `control_node.cpp`,
//! `decorator_node.cpp`) and AS2FM's `*.ascxml` node models.

use super::tree::{CheckType, Kind, Operand, Status, Tree};
use std::collections::BTreeMap;

/// Whose rules the oracle follows where AS2FM and BT.CPP differ.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Reading {
    /// AS2FM's node models (`as2fm-bt-nodes/*.ascxml`): a parent halts every child it
    /// resets, running or not, and each halted node runs its own halt; Parallel ticks every
    /// child on every tick; Repeat halts its child after each finished attempt;
    /// SequenceWithMemory forgets its place when halted.
    #[default]
    As2fm,
    /// BehaviorTree.CPP 4.10: `ControlNode::haltChild` / `DecoratorNode::resetChild` halt
    /// a child only while it is RUNNING (else they just reset its status); Parallel skips
    /// children that finished; SequenceWithMemory keeps its place when halted.
    Btcpp,
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

/// The executor's state: per node its last status (`None`: IDLE) and its variables.
pub struct Oracle<'t> {
    tree: &'t Tree,
    scripts: &'t Scripts,
    reading: Reading,
    status: Vec<Option<Status>>,
    /// Child index (sequences, IfThenElse) or attempt count (Repeat, Retry).
    idx: Vec<i64>,
    /// Parallel's finished children (BT.CPP reading) and counts.
    done: Vec<Vec<bool>>,
    counts: Vec<(i64, i64)>,
    /// Ticks each leaf instance received.
    leaf_ticks: Vec<usize>,
    /// Entries as the text written (BT.CPP converts where a port reads).
    bb: BTreeMap<String, String>,
    /// Every tick and halt leaves received, in order.
    pub log: Vec<LeafEvent>,
}

impl<'t> Oracle<'t> {
    /// A tree with every node idle.
    pub fn new(tree: &'t Tree, scripts: &'t Scripts, reading: Reading) -> Self {
        let n = tree.nodes.len();
        Oracle {
            tree,
            scripts,
            reading,
            status: vec![None; n],
            idx: vec![0; n],
            done: tree
                .nodes
                .iter()
                .map(|x| vec![false; x.children.len()])
                .collect(),
            counts: vec![(0, 0); n],
            leaf_ticks: vec![0; n],
            bb: BTreeMap::new(),
            log: Vec::new(),
        }
    }

    /// One tick of the root. Like `Tree::tickRoot` (v4 `bt_factory.cpp`), a finished root
    /// is ticked again from where its own rules left it.
    pub fn tick_root(&mut self) -> Result<Status, String> {
        self.tick(0)
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
    fn tick(&mut self, n: usize) -> Result<Status, String> {
        let s = self.tick_inner(n)?;
        self.status[n] = Some(s);
        Ok(s)
    }

    /// `ControlNode::haltChild` / `DecoratorNode::resetChild`: BT.CPP halts the child
    /// only while RUNNING, then resets its status; AS2FM's `bt_halt_child` halts it
    /// whatever it last answered.
    fn halt_child(&mut self, c: usize) {
        if self.reading == Reading::As2fm || self.status[c] == Some(Status::Running) {
            self.halt(c);
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
            Kind::Leaf(_) => self.log.push(LeafEvent::Halt(self.tree.nodes[n].id)),
            Kind::AlwaysSuccess | Kind::AlwaysFailure | Kind::SetBlackboard(..) => {}
            // v4 `SequenceWithMemory::halt` keeps `current_child_idx_`; AS2FM's
            // `sequence_with_memory.ascxml` (and v3.8 `SequenceStarNode::halt`) reset it.
            Kind::SequenceWithMemory => {
                if self.reading == Reading::As2fm {
                    self.idx[n] = 0;
                }
                self.reset_children(n);
            }
            // `ParallelNode::halt` clears; AS2FM's counts restart on every tick anyway.
            Kind::Parallel(..) => {
                self.done[n].iter_mut().for_each(|d| *d = false);
                self.counts[n] = (0, 0);
                self.reset_children(n);
            }
            // `SequenceNode::halt`, `FallbackNode::halt`, `IfThenElseNode::halt`,
            // `RepeatNode::halt`, `RetryNode::halt`: the index or count back to 0.
            _ => {
                self.idx[n] = 0;
                self.reset_children(n);
            }
        }
        self.status[n] = None;
    }

    fn tick_inner(&mut self, n: usize) -> Result<Status, String> {
        use Status::*;
        let kind = &self.tree.nodes[n].kind;
        match kind {
            Kind::Leaf(ty) => {
                self.log.push(LeafEvent::Tick(self.tree.nodes[n].id));
                let script = self
                    .scripts
                    .get(ty)
                    .filter(|s| !s.is_empty())
                    .ok_or(format!("no script for leaf {ty}"))?;
                let s = script[self.leaf_ticks[n] % script.len()];
                self.leaf_ticks[n] += 1;
                Ok(s)
            }
            Kind::Sequence => self.sequence(n, Success, Failure),
            Kind::Fallback => self.sequence(n, Failure, Success),
            Kind::SequenceWithMemory => self.sequence_with_memory(n),
            Kind::ReactiveSequence => self.reactive(n, Success, Failure),
            Kind::ReactiveFallback => self.reactive(n, Failure, Success),
            &Kind::Parallel(s, f) => self.parallel(n, s, f),
            Kind::IfThenElse => self.if_then_else(n),
            Kind::Inverter => self.decorate(n, |s| match s {
                Success => Failure,
                Failure => Success,
                Running => Running,
            }),
            Kind::ForceSuccess => self.decorate(n, |s| if s == Running { s } else { Success }),
            Kind::ForceFailure => self.decorate(n, |s| if s == Running { s } else { Failure }),
            &Kind::Repeat(max) => self.repeat(n, max, Success),
            &Kind::Retry(max) => self.repeat(n, max, Failure),
            Kind::AlwaysSuccess => Ok(Success),
            Kind::AlwaysFailure => Ok(Failure),
            // v4 `SetBlackboardNode::tick`: a `{other}` value copies that entry.
            Kind::SetBlackboard(key, v) => {
                let v = self.value(v)?;
                self.bb.insert(key.clone(), v);
                Ok(Success)
            }
            Kind::Check(ty, a, b, mismatch) => {
                let mismatch = *mismatch;
                let c = self.child(n, 0);
                // v3.8 `BlackboardPreconditionNode::tick`; AS2FM's
                // `blackboard_check_int.ascxml` halts the child on a mismatch.
                if self.same(*ty, a, b)? {
                    self.tick(c)
                } else {
                    self.halt_child(c);
                    Ok(mismatch)
                }
            }
        }
    }

    /// `SequenceNode::tick` (`cont` SUCCESS) and `FallbackNode::tick` (`cont` FAILURE);
    /// AS2FM's `sequence.ascxml` / `fallback.ascxml` halt every child on finishing.
    fn sequence(&mut self, n: usize, cont: Status, stop: Status) -> Result<Status, String> {
        while (self.idx[n] as usize) < self.n_children(n) {
            let c = self.child(n, self.idx[n] as usize);
            match self.tick(c)? {
                Status::Running => return Ok(Status::Running),
                s if s == stop => {
                    self.reset_children(n);
                    self.idx[n] = 0;
                    return Ok(stop);
                }
                _ => self.idx[n] += 1,
            }
        }
        self.reset_children(n);
        self.idx[n] = 0;
        Ok(cont)
    }

    /// `SequenceWithMemory::tick`: a failure keeps the index. v4 then halts the children
    /// from the failed one on (`haltChild(i)` for `i >= current_child_idx_`); AS2FM's
    /// `halt_current_child` state halts the failed child alone.
    fn sequence_with_memory(&mut self, n: usize) -> Result<Status, String> {
        let len = self.n_children(n);
        while (self.idx[n] as usize) < len {
            let at = self.idx[n] as usize;
            let c = self.child(n, at);
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
                Status::Success => self.idx[n] += 1,
            }
        }
        self.reset_children(n);
        self.idx[n] = 0;
        Ok(Status::Success)
    }

    /// `ReactiveSequence::tick` / `ReactiveFallback::tick` (and AS2FM's
    /// `reactive_sequence.ascxml` / `reactive_fallback.ascxml`): every tick starts at the
    /// first child; a RUNNING child halts all the others.
    fn reactive(&mut self, n: usize, cont: Status, stop: Status) -> Result<Status, String> {
        let len = self.n_children(n);
        for i in 0..len {
            let c = self.child(n, i);
            match self.tick(c)? {
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
        Ok(cont)
    }

    /// `ParallelNode::tick` (v4: finished children are not ticked again, counts build up
    /// across ticks, FAILURE also when success can no longer be reached) against AS2FM's
    /// `parallel.ascxml` (every child ticked on every tick, counts from zero, the
    /// thresholds checked after each child).
    fn parallel(&mut self, n: usize, s: i64, f: i64) -> Result<Status, String> {
        let len = self.n_children(n) as i64;
        let th = |t: i64| if t < 0 { (len + t + 1).max(0) } else { t };
        let (s, f) = (th(s), th(f));
        if self.reading == Reading::As2fm {
            self.counts[n] = (0, 0);
        }
        for i in 0..len as usize {
            if !self.done[n][i] {
                let c = self.child(n, i);
                match self.tick(c)? {
                    Status::Success => {
                        self.counts[n].0 += 1;
                        self.done[n][i] = self.reading == Reading::Btcpp;
                    }
                    Status::Failure => {
                        self.counts[n].1 += 1;
                        self.done[n][i] = self.reading == Reading::Btcpp;
                    }
                    Status::Running => {}
                }
            }
            let (sc, fc) = self.counts[n];
            let fail = match self.reading {
                Reading::As2fm => fc >= f,
                Reading::Btcpp => len - fc < s || fc == f,
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
        Ok(Status::Running)
    }

    /// `IfThenElseNode::tick` (AS2FM's `if_then_else.ascxml` alike): the condition while
    /// no branch runs; a two-child node whose condition fails answers FAILURE without
    /// resetting anything.
    fn if_then_else(&mut self, n: usize) -> Result<Status, String> {
        if self.idx[n] == 0 {
            let c = self.child(n, 0);
            match self.tick(c)? {
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

    /// Inverter / ForceSuccess / ForceFailure (`InverterNode::tick`, ...): v4 resets a
    /// finished child's status (`resetChild`, no halt since it is not RUNNING); AS2FM's
    /// models do nothing to it.
    fn decorate(&mut self, n: usize, map: fn(Status) -> Status) -> Result<Status, String> {
        let c = self.child(n, 0);
        let s = self.tick(c)?;
        if s != Status::Running && self.reading == Reading::Btcpp {
            self.halt_child(c);
        }
        Ok(map(s))
    }

    /// `RepeatNode::tick` (`again` SUCCESS) and `RetryNode::tick` (`again` FAILURE): the
    /// child is ticked again in the same tick until the count is used up. v4 calls
    /// `resetChild()` after every finished attempt (a no-op halt: the child is not
    /// RUNNING). AS2FM's `repeat_node.ascxml` halts the child after each attempt
    /// (`bt_halt_child` in `tick_child`); its `retry_node.ascxml` never does.
    fn repeat(&mut self, n: usize, max: i64, again: Status) -> Result<Status, String> {
        let stop = if again == Status::Success {
            Status::Failure
        } else {
            Status::Success
        };
        let c = self.child(n, 0);
        let halts = self.reading == Reading::Btcpp || again == Status::Success;
        let mut spins = 0;
        while max == -1 || self.idx[n] < max {
            // -1 repeats without end: a child that never stops would hang BT.CPP too.
            spins += 1;
            if spins > 10_000 {
                return Err("a Repeat/Retry of -1 never stops within one tick".into());
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
}

/// Runs `ticks` root ticks: the root's status at each and the leaves' log.
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
