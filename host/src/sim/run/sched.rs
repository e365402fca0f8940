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
    /// `uniform`, or `memoryless:ID` / `history:ID` with the id as 16 hex digits: the
    /// text `--scheduler` reads back.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Scheduler::Uniform => f.write_str("uniform"),
            Scheduler::Sampled(s) => write!(f, "{}:{:016x}", s.memory.label(), s.id),
        }
    }
}

impl std::str::FromStr for Scheduler {
    type Err = String;

    /// Reads what [`Scheduler`]'s `Display` writes; a bare hex id is memoryless.
    fn from_str(text: &str) -> Result<Self, String> {
        let t = text.trim();
        if t == "uniform" {
            return Ok(Scheduler::Uniform);
        }
        let (memory, hex) = match t.split_once(':') {
            Some(("memoryless", h)) => (Memory::Memoryless, h),
            Some(("history", h)) => (Memory::History, h),
            Some((k, _)) => {
                return Err(format!(
                    "`{text}`: unknown scheduler kind `{k}` (expected `uniform`, \
                     `memoryless:ID` or `history:ID`, ID 1 to 16 hex digits)"
                ))
            }
            None => (Memory::Memoryless, t),
        };
        let hex = hex.strip_prefix("0x").unwrap_or(hex);
        if hex.is_empty() || hex.len() > 16 {
            return Err(format!(
                "`{text}`: expected `uniform`, `memoryless:ID` or `history:ID`, ID 1 to 16 \
                 hex digits"
            ));
        }
        let id = u64::from_str_radix(hex, 16)
            .map_err(|_| format!("`{text}`: the id `{hex}` is not hexadecimal"))?;
        Ok(Scheduler::Sampled(Sampled { id, memory }))
    }
}

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
            Scheduler::Sampled(s) => self.sampled_step(s, n),
        }
    }

    /// [`Simulator::choose_step`] under a sampled scheduler, kept out of line so that the
    /// uniform path stays as small as it was.
    #[inline(never)]
    fn sampled_step(&mut self, s: Sampled, n: u32) -> u32 {
        let runnable = self.runnable.len();
        self.choose(s, n, |sim, k| {
            let k = k as usize;
            if k < runnable {
                sim.runnable[k] as u64
            } else {
                KEY_EVENT | sim.deliverable[k - runnable] as u64
            }
        })
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
            Scheduler::Sampled(s) => self.sampled_transition(s, m, n),
        }
    }

    #[inline(never)]
    fn sampled_transition(&mut self, s: Sampled, m: usize, n: u32) -> u32 {
        // Machine `m` is in the middle of its step (or of a check whether it can take an
        // event): its record may have changed since it was last marked.
        self.touch(m);
        self.choose(s, n, |sim, k| {
            KEY_TRANSITION | (m as u64) << 40 | sim.enabled[k as usize] as u64
        })
    }

    /// The option in `0..n` whose key (`key(self, k)`) has the largest hash with the
    /// scheduler's id and context: independent of the order options are listed in.
    fn choose(&mut self, s: Sampled, n: u32, key: impl Fn(&Self, u32) -> u64) -> u32 {
        if n <= 1 {
            return 0;
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
        best.0
    }

    /// Marks machine `m`'s cached hash stale: called after every change to its record
    /// (state, position, flags, variables, current message, queues). Under the uniform
    /// scheduler every machine is stale from the run's start, so this is one test.
    #[inline]
    pub(super) fn touch(&mut self, m: usize) {
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
        h = mix(h, r.intq.len() as u64 | (r.extq.len() as u64) << 32);
        // The internal queue holds raised events (no parameters), the external one pool
        // slots.
        for &ev in &r.intq {
            h = mix(h, ev as u64);
        }
        for &slot in &r.extq {
            h = self.hash_message(h, slot);
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
