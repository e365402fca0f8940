//! Schedulers: who resolves the choices a model leaves open (which ready machine moves,
//! which pending event is delivered, which of several enabled transitions fires).
//!
//! Every such choice of a run goes through [`Simulator::choose`]. The [`Scheduler`] of
//! [`RunConfig::scheduler`] decides it:
//! - [`Scheduler::Uniform`] (the default) draws uniformly at random from the run's
//!   stream, as SCAN does;
//! - [`Scheduler::Sampled`] is one deterministic scheduler out of 2^64, named by its id:
//!   the option it picks is the one with the largest hash of the id, a context and the
//!   option's identity (a machine, an event, a transition). The context is the model's
//!   current state ([`Memory::Memoryless`]) or the state and every choice made so far in
//!   the run ([`Memory::History`]). This is lightweight scheduler sampling (Legay,
//!   Sedwards, Traonouez, "Scalable verification of Markov decision processes", 2014;
//!   D'Argenio, Legay, Sedwards, Traonouez, "Smart sampling for lightweight verification
//!   of Markov decision processes", STTT 17(4), 2015): a scheduler is a few integers, not
//!   a table over states.
//!
//! A sampled scheduler draws nothing from the run's stream, so the model's own random
//! choices (`Math.random()`) see the same stream whatever the scheduler does, and a
//! scheduler id plus a run index reproduces a run exactly.
//!
//! # Choices put back to uniform
//!
//! [`Sampled::uniform`] puts one kind of choice back to the uniform scheduler, to see
//! which choices a sampled scheduler's probability comes from (`verify --schedulers`
//! names them). The scheduler first picks as it would; if its pick is of an overridden
//! kind, the choice within that kind is redrawn from the run's stream:
//! - [`PutBack::machines`]: when a machine step is picked, which machine moves is uniform
//!   among the runnable machines;
//! - [`PutBack::events`]: when a delivery is picked, which pending event is delivered is
//!   uniform among the deliverable events ([`EventSemantics::As2fm`]);
//! - [`PutBack::transitions`]: which enabled transition fires is uniform;
//! - [`PutBack::machine`] (`m`): when a machine step is picked and `m` is one of `k`
//!   runnable machines, `m` moves with probability `1/k`, as under the uniform
//!   scheduler, and otherwise the scheduler picks among the others: machine `m`'s
//!   position in the order is uniform, the rest of the order the scheduler's;
//! - [`PutBack::event`] (`e`): the same for pending event `e` among the deliveries.
//!
//! Whether a machine moves or an event is delivered stays the scheduler's choice. A
//! choice the override does not touch draws nothing, so the runs are the witness's own
//! until the first overridden choice. Under [`Memory::History`] the history records the
//! scheduler's own pick.
//!
//! The state a memoryless scheduler sees: every machine's state, position in its
//! executable content, flags, the time left on its delay, its variables, the message it
//! is processing and its queues (events, origins, targets and parameters), and the
//! pending events with their parameters ([`EventSemantics::As2fm`]). The clock itself is
//! left out, so a memoryless scheduler cannot count instants: it is a function of the
//! model's discrete state, as a memoryless scheduler of an MDP is.
//!
//! The hash is kept incrementally ([`Simulator::touch`]): each machine's record has a
//! cached hash, recomputed at a choice only if the record changed since the last one, and
//! the machines' hashes are summed, so a choice costs what changed (on UC3's 278 machines,
//! one or two of them), not the whole model. (Until this was incremental the whole state
//! was hashed at each choice, with another mix: the option a given id picks in a given
//! state changed with it, so witness ids printed before then name other schedulers now.)

use super::*;

/// How the nondeterministic choices of a run are resolved.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum Scheduler {
    /// Uniformly at random, from the run's stream (the default).
    #[default]
    Uniform,
    /// One deterministic scheduler, named by its id.
    Sampled(Sampled),
}

/// A sampled deterministic scheduler: an id and what its choices may depend on.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Sampled {
    /// The scheduler's id: any 64-bit number names one.
    pub id: u64,
    /// What a choice depends on besides the id.
    pub memory: Memory,
    /// Choices put back to uniform (none: the scheduler decides every choice).
    pub uniform: PutBack,
}

/// Which choices of a [`Sampled`] scheduler are put back to uniform (see the module doc).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub struct PutBack {
    /// Which runnable machine moves.
    pub machines: bool,
    /// Which deliverable event is delivered.
    pub events: bool,
    /// Which enabled transition of a machine fires.
    pub transitions: bool,
    /// This machine's position among the machines that move.
    pub machine: Option<u32>,
    /// This event's position among the deliveries.
    pub event: Option<u32>,
}

impl PutBack {
    /// Whether nothing is put back.
    pub fn is_none(&self) -> bool {
        *self == PutBack::default()
    }
}

/// What a sampled scheduler's choice depends on.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum Memory {
    /// The current state only: the same state always gets the same choice.
    #[default]
    Memoryless,
    /// The current state and every state and choice before it in the run.
    History,
}

impl Memory {
    /// The word the command line and the scheduler's name use.
    pub fn label(self) -> &'static str {
        match self {
            Memory::Memoryless => "memoryless",
            Memory::History => "history",
        }
    }
}

impl std::fmt::Display for Scheduler {
    /// `uniform`, or `memoryless:ID` / `history:ID` with the id as 16 hex digits, then
    /// what is put back to uniform (`+machines`, `+events`, `+transitions`,
    /// `+machine=M`, `+event=E`, by index): the text `--scheduler` reads back.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Scheduler::Uniform => f.write_str("uniform"),
            Scheduler::Sampled(s) => {
                write!(f, "{}:{:016x}", s.memory.label(), s.id)?;
                let u = &s.uniform;
                for (on, word) in [
                    (u.machines, "+machines"),
                    (u.events, "+events"),
                    (u.transitions, "+transitions"),
                ] {
                    if on {
                        f.write_str(word)?;
                    }
                }
                if let Some(m) = u.machine {
                    write!(f, "+machine={m}")?;
                }
                if let Some(e) = u.event {
                    write!(f, "+event={e}")?;
                }
                Ok(())
            }
        }
    }
}

impl std::str::FromStr for Scheduler {
    type Err = BadScheduler;

    /// Reads what [`Scheduler`]'s `Display` writes; a bare hex id is memoryless.
    fn from_str(text: &str) -> Result<Self, BadScheduler> {
        let bad = |why| BadScheduler {
            text: text.to_string(),
            why,
        };
        let t = text.trim();
        if t == "uniform" {
            return Ok(Scheduler::Uniform);
        }
        let mut parts = t.split('+');
        let t = parts.next().unwrap_or_default();
        let mut uniform = PutBack::default();
        for part in parts {
            let index = |v: &str| {
                v.parse::<u32>().map_err(|_| {
                    bad(SchedulerWhy::NotAnIndex {
                        part: part.to_string(),
                        value: v.to_string(),
                    })
                })
            };
            match part.split_once('=') {
                None if part == "machines" => uniform.machines = true,
                None if part == "events" => uniform.events = true,
                None if part == "transitions" => uniform.transitions = true,
                Some(("machine", v)) => uniform.machine = Some(index(v)?),
                Some(("event", v)) => uniform.event = Some(index(v)?),
                _ => return Err(bad(SchedulerWhy::UnknownOverride(part.to_string()))),
            }
        }
        let (memory, hex) = match t.split_once(':') {
            Some(("memoryless", h)) => (Memory::Memoryless, h),
            Some(("history", h)) => (Memory::History, h),
            Some((k, _)) => return Err(bad(SchedulerWhy::UnknownKind(k.to_string()))),
            None => (Memory::Memoryless, t),
        };
        let hex = hex.strip_prefix("0x").unwrap_or(hex);
        if hex.is_empty() || hex.len() > 16 {
            return Err(bad(SchedulerWhy::IdLength));
        }
        let id =
            u64::from_str_radix(hex, 16).map_err(|_| bad(SchedulerWhy::NotHex(hex.to_string())))?;
        Ok(Scheduler::Sampled(Sampled {
            id,
            memory,
            uniform,
        }))
    }
}

/// A text that names no [`Scheduler`] (as `--scheduler` reads it): the text and why.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct BadScheduler {
    /// The text as given.
    pub text: String,
    /// What is wrong with it.
    pub why: SchedulerWhy,
}

/// What is wrong with a scheduler's text ([`BadScheduler`]).
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum SchedulerWhy {
    /// `+part`'s value is not an index.
    NotAnIndex {
        /// The put-back (`machine=x`).
        part: String,
        /// Its value (`x`).
        value: String,
    },
    /// A put-back of no known form (the text after `+`).
    UnknownOverride(String),
    /// A kind before `:` other than `memoryless` and `history`.
    UnknownKind(String),
    /// The id is empty or longer than 16 digits.
    IdLength,
    /// The id (without `0x`) is not hexadecimal.
    NotHex(String),
}

impl std::fmt::Display for BadScheduler {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let text = &self.text;
        match &self.why {
            SchedulerWhy::NotAnIndex { part, value } => {
                write!(f, "`{text}`: `+{part}`: `{value}` is not an index")
            }
            SchedulerWhy::UnknownOverride(part) => write!(
                f,
                "`{text}`: unknown override `+{part}` (expected `+machines`, \
                 `+events`, `+transitions`, `+machine=M` or `+event=E`)"
            ),
            SchedulerWhy::UnknownKind(k) => write!(
                f,
                "`{text}`: unknown scheduler kind `{k}` (expected `uniform`, \
                 `memoryless:ID` or `history:ID`, ID 1 to 16 hex digits)"
            ),
            SchedulerWhy::IdLength => write!(
                f,
                "`{text}`: expected `uniform`, `memoryless:ID` or `history:ID`, ID 1 to 16 \
                 hex digits"
            ),
            SchedulerWhy::NotHex(hex) => write!(f, "`{text}`: the id `{hex}` is not hexadecimal"),
        }
    }
}

impl std::error::Error for BadScheduler {}

/// Mixes `v` into `h`: the finaliser of SplitMix64 (Steele, Lea, Flood, "Fast splittable
/// pseudorandom number generators", OOPSLA 2014) over `h` rotated plus `v`, so that
/// equal words at different positions hash differently.
#[inline]
pub fn mix(h: u64, v: u64) -> u64 {
    let mut z = h.rotate_left(23) ^ v.wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

fn hash_cell(h: u64, c: &Cell) -> u64 {
    match c {
        Cell::Bool(b) => mix(h, 1 + *b as u64),
        Cell::Int(v) => mix(mix(h, 3), *v as u64),
        Cell::Float(v) => mix(mix(h, 4), v.to_bits()),
        Cell::Str(s) => mix(mix(h, 5), s.0 as u64),
        Cell::List(l) => {
            let mut h = mix(mix(h, 6), l.len() as u64);
            for c in l.iter() {
                h = hash_cell(h, c);
            }
            h
        }
    }
}

/// The identity of option `k` of a step choice: a machine, or (past the runnable
/// machines) a pending event.
const KEY_EVENT: u64 = 1 << 32;
/// The identity of an enabled transition of machine `m`: `KEY_TRANSITION | m << 40 | t`.
const KEY_TRANSITION: u64 = 2 << 32;

impl Simulator<'_> {
    /// Option `k` of the step choice in `0..n` (`n` runnable machines, then the
    /// deliverable events), as `cfg.scheduler` picks it.
    #[inline]
    pub(super) fn choose_step(&mut self, n: u32, rng: &mut dyn Entropy, cfg: &RunConfig) -> u32 {
        match cfg.scheduler {
            Scheduler::Uniform => below(rng, n),
            Scheduler::Sampled(s) => self.sampled_step(s, n, rng),
        }
    }

    /// [`Simulator::choose_step`] under a sampled scheduler, kept out of line so that the
    /// uniform path stays as small as it was.
    #[inline(never)]
    fn sampled_step(&mut self, s: Sampled, n: u32, rng: &mut dyn Entropy) -> u32 {
        let runnable = self.runnable.len();
        let key = |sim: &Self, k: u32| {
            let k = k as usize;
            if k < runnable {
                sim.runnable[k] as u64
            } else {
                KEY_EVENT | sim.deliverable[k - runnable] as u64
            }
        };
        let (pick, context) = self.choose(s, n, key);
        let u = s.uniform;
        if u.is_none() {
            return pick;
        }
        // The kind the scheduler picked: machines `0..runnable` or events `runnable..n`.
        let runnable = runnable as u32;
        let (group, all, one) = if pick < runnable {
            (0..runnable, u.machines, u.machine.map(|m| m as u64))
        } else {
            (runnable..n, u.events, u.event.map(|e| KEY_EVENT | e as u64))
        };
        let back = |sim: &Self, k: u32| all || one == Some(key(sim, k));
        self.put_back(pick, context, group, back, key, rng)
    }

    /// The choice in `group` (which holds the scheduler's `pick`) once the options for
    /// which `back` holds are put back to uniform: each of them is taken with probability
    /// `1 / group.len()`, as under the uniform scheduler; otherwise the scheduler's
    /// favourite (largest hash with `context`) among the others is.
    fn put_back(
        &self,
        pick: u32,
        context: u64,
        group: std::ops::Range<u32>,
        back: impl Fn(&Self, u32) -> bool,
        key: impl Fn(&Self, u32) -> u64,
        rng: &mut dyn Entropy,
    ) -> u32 {
        let size = group.len() as u32;
        let uniform: Vec<u32> = group.clone().filter(|&k| back(self, k)).collect();
        if size < 2 || uniform.is_empty() {
            return pick;
        }
        let u = below(rng, size) as usize;
        if let Some(&k) = uniform.get(u) {
            return k;
        }
        if !back(self, pick) {
            return pick;
        }
        group
            .filter(|&k| !back(self, k))
            .max_by_key(|&k| (mix(context, key(self, k)), std::cmp::Reverse(k)))
            .unwrap_or(pick)
    }

    /// Which of the `n` enabled transitions of machine `m` (in `self.enabled`) fires.
    #[inline]
    pub(super) fn choose_transition(
        &mut self,
        m: usize,
        n: u32,
        rng: &mut dyn Entropy,
        cfg: &RunConfig,
    ) -> u32 {
        match cfg.scheduler {
            Scheduler::Uniform => below(rng, n),
            Scheduler::Sampled(s) => self.sampled_transition(s, m, n, rng),
        }
    }

    #[inline(never)]
    fn sampled_transition(&mut self, s: Sampled, m: usize, n: u32, rng: &mut dyn Entropy) -> u32 {
        // Machine `m` is in the middle of its step (or of a check whether it can take an
        // event): its record may have changed since it was last marked.
        self.touch(m);
        let (pick, _) = self.choose(s, n, |sim, k| {
            KEY_TRANSITION | (m as u64) << 40 | sim.enabled[k as usize] as u64
        });
        if s.uniform.transitions && n > 1 {
            return below(rng, n);
        }
        pick
    }

    /// The option in `0..n` whose key (`key(self, k)`) has the largest hash with the
    /// scheduler's id and context: independent of the order options are listed in.
    /// Returns it and the context (`0` when there was no choice).
    fn choose(&mut self, s: Sampled, n: u32, key: impl Fn(&Self, u32) -> u64) -> (u32, u64) {
        if n <= 1 {
            return (0, 0);
        }
        let state = self.state_hash();
        let context = match s.memory {
            Memory::Memoryless => mix(s.id, state),
            Memory::History => mix(mix(s.id, self.history), state),
        };
        let mut best = (0u32, 0u64, 0u64);
        for k in 0..n {
            let id = key(self, k);
            let score = mix(context, id);
            if k == 0 || score > best.1 {
                best = (k, score, id);
            }
        }
        if s.memory == Memory::History {
            self.history = mix(mix(self.history, state), best.2);
        }
        (best.0, context)
    }

    /// Marks machine `m`'s cached hash stale: called after every change to its record
    /// (state, position, flags, variables, current message, queues). Under the uniform
    /// scheduler every machine is stale from the run's start (nothing hashes it), so this
    /// tests one flag of the simulator and does not reach the record.
    #[inline(always)]
    pub(super) fn touch(&mut self, m: usize) {
        if !self.sampled {
            return;
        }
        let r = &mut self.ms[m];
        if !r.dirty {
            r.dirty = true;
            self.dirty.push(m as u32);
        }
    }

    /// The global buffer of event `e` changed ([`EventSemantics::As2fm`]): the machines
    /// whose current message is that buffer (set while checking whether they can take
    /// `e`) hash it, so their hashes are stale.
    #[inline]
    pub(super) fn touch_readers(&mut self, e: usize) {
        if !self.sampled {
            return;
        }
        let model = self.model;
        for &r in &model.events[e].receivers {
            if self.ms[r as usize].cur == e as u32 {
                self.touch(r as usize);
            }
        }
    }

    /// A hash of the model's current state (see the module doc for what it covers), kept
    /// incrementally: each machine's record is hashed again only when it changed since the
    /// last choice (see [`Simulator::touch`]), and the machines' hashes are combined by a
    /// wrapping sum, so a choice costs the changed machines, the delays and the pending
    /// events, not the whole model. The hash is a function of the state alone: the same
    /// state always hashes the same, whatever the path to it (checked against a hash from
    /// scratch in debug builds).
    fn state_hash(&mut self) -> u64 {
        while let Some(m) = self.dirty.pop() {
            let m = m as usize;
            self.ms[m].dirty = false;
            let h = self.machine_hash(m);
            self.mhash_sum = self.mhash_sum.wrapping_sub(self.mhash[m]).wrapping_add(h);
            self.mhash[m] = h;
        }
        let h = self.combine(self.mhash_sum);
        debug_assert_eq!(
            h,
            self.combine(
                (0..self.ms.len()).fold(0u64, |s, m| s.wrapping_add(self.machine_hash(m)))
            ),
            "the incremental state hash missed a change"
        );
        h
    }

    /// The state hash from the machines' part `sum`: adds the time left on each delay
    /// (not in the machines' cached hashes, as it changes with the clock) and the pending
    /// events in the order they were sent.
    fn combine(&self, sum: u64) -> u64 {
        let mut waits = 0u64;
        for &m in &self.delayed {
            let r = &self.ms[m as usize];
            waits =
                waits.wrapping_add(mix(mix(0x3a17, m as u64), r.wake.saturating_sub(self.time)));
        }
        let mut h = mix(mix(0x5eed, sum), waits);
        if self.as2fm {
            h = mix(h, self.pending_list.len() as u64);
            for &e in &self.pending_list {
                h = self.hash_message(mix(h, e as u64), e);
            }
        }
        h
    }

    /// The hash of machine `m`'s record, its index included: state, position, flags, the
    /// message it is processing and its queues, and its variables.
    fn machine_hash(&self, m: usize) -> u64 {
        let r = &self.ms[m];
        let mut h = mix(0x6d61_6368, m as u64);
        h = mix(h, r.state as u64 | (r.pc as u64) << 32);
        let flags = r.waiting as u64
            | (r.blocked as u64) << 1
            | (r.delay_done as u64) << 2
            | (r.bcast as u64) << 3
            | (r.awaiting as u64) << 32;
        h = mix(h, flags);
        if r.cur != NO_MSG {
            h = mix(h, r.cur_event.0 as u64 | (r.cur_origin.0 as u64) << 32);
            h = self.hash_message(h, r.cur);
        }
        h = mix(h, r.intq.len() as u64 | (r.qlen as u64) << 32);
        // The internal queue holds raised events (no parameters), the external one pool
        // slots.
        for &ev in &r.intq {
            h = mix(h, ev as u64);
        }
        let mut slot = r.qhead;
        while slot != NO_MSG {
            h = self.hash_message(h, slot);
            slot = self.pool.get(slot as usize).map_or(NO_MSG, |s| s.next);
        }
        for c in &r.vars {
            h = hash_cell(h, c);
        }
        h
    }

    fn hash_message(&self, mut h: u64, slot: u32) -> u64 {
        if let Some(s) = self.pool.get(slot as usize) {
            h = mix(h, s.event as u64 | (s.origin as u64) << 32);
            h = mix(h, s.target as u64);
            for c in &s.params {
                h = hash_cell(h, c);
            }
        }
        h
    }
}
