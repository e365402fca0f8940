//! Building a simulator for a compiled model, and putting it back in its initial state before each run.

use super::*;

impl<'m> Simulator<'m> {
    /// A simulator for `model` (allocates its buffers once).
    pub fn new(model: &'m CompiledModel) -> Self {
        let n = model.machines.len();
        let (rx_first, rx_cases) = receivers::receiver_table(model);
        Simulator {
            model,
            ms: model
                .machines
                .iter()
                .map(|d| MachineRt {
                    state: d.initial,
                    pc: IDLE,
                    waiting: false,
                    blocked: false,
                    awaiting: NO_MSG,
                    wake: 0,
                    bcast: 0,
                    delay_done: false,
                    cur: NO_MSG,
                    cur_event: StrId(0),
                    cur_origin: StrId(0),
                    intq: VecDeque::new(),
                    qhead: NO_MSG,
                    qtail: NO_MSG,
                    qlen: 0,
                    vars: d.defaults.clone(),
                    rpos: NOT_RUNNABLE,
                    moves: 0,
                    changed: 0,
                    dirty: false,
                })
                .collect(),
            // Under EventSemantics::As2fm, slot `e` is event `e`'s global buffer, and
            // each receiver of `e` has its own copy at `rx_base[e] + position`.
            pool: model
                .events
                .iter()
                .enumerate()
                .map(|(e, d)| Slot {
                    event: e as u32,
                    origin: 0,
                    target: u32::MAX,
                    next: NO_MSG,
                    params: d.defaults.clone(),
                })
                .chain(model.events.iter().enumerate().flat_map(|(e, d)| {
                    d.receivers.iter().map(move |&r| Slot {
                        event: e as u32,
                        origin: 0,
                        target: r,
                        next: NO_MSG,
                        params: d.defaults.clone(),
                    })
                }))
                .collect(),
            rx_base: model
                .events
                .iter()
                .scan(model.events.len() as u32, |next, d| {
                    let base = *next;
                    *next += d.receivers.len() as u32;
                    Some(base)
                })
                .collect(),
            rx_first,
            rx_cases,
            reserved: model.events.len()
                + model
                    .events
                    .iter()
                    .map(|d| d.receivers.len())
                    .sum::<usize>(),
            free: vec![Vec::new(); model.events.len()],
            runnable: Vec::with_capacity(n),
            delayed: Vec::with_capacity(n),
            enabled: Vec::new(),
            time: 0,
            steps: 0,
            instant_steps: 0,
            scratch: model
                .machines
                .iter()
                .map(|d| vec![Cell::Int(0); d.n_scratch as usize])
                .collect(),
            idx: [0; MAX_PATH],
            as2fm: false,
            ev_flags: model.events.iter().map(|e| event_flags(&e.name)).collect(),
            pending: vec![false; model.events.len()],
            pending_list: Vec::with_capacity(model.events.len()),
            pending_regular: 0,
            pending_bb_set: 0,
            deliverable: Vec::with_capacity(model.events.len()),
            inbox: Inbox::default(),
            blocked_list: Vec::with_capacity(n),
            ev_scratch: model.events.iter().map(|d| d.defaults.clone()).collect(),
            pure_guards: model
                .machines
                .iter()
                .all(|d| d.trans.iter().all(|t| !t.cond_draws)),
            keep_choices: false,
            clock: 0,
            checked: vec![
                0;
                model
                    .events
                    .iter()
                    .map(|d| d.receivers.len())
                    .sum::<usize>()
            ],
            choice_kept: vec![
                NO_TRANS;
                model
                    .events
                    .iter()
                    .map(|d| d.receivers.len())
                    .sum::<usize>()
            ],
            history: 0,
            sampled: false,
            dirty: Vec::with_capacity(n),
            mhash: vec![0; n],
            mhash_sum: 0,
        }
    }
}

impl Simulator<'_> {
    /// Resets every machine to its initial state and evaluates the datamodel.
    pub(super) fn reset(&mut self, rng: &mut dyn Entropy) -> Result<(), Stop> {
        self.time = 0;
        self.steps = 0;
        self.instant_steps = 0;
        self.history = 0;
        for f in &mut self.free {
            f.clear();
        }
        for i in (self.reserved..self.pool.len()).rev() {
            let ev = self.pool[i].event as usize;
            if let Some(f) = self.free.get_mut(ev) {
                f.push(i as u32);
            }
        }
        self.runnable.clear();
        self.dirty.clear();
        for (m, r) in self.ms.iter_mut().enumerate() {
            r.rpos = NOT_RUNNABLE;
            r.moves = 0;
            r.dirty = true;
            self.dirty.push(m as u32);
        }
        self.mhash.iter_mut().for_each(|h| *h = 0);
        self.mhash_sum = 0;
        self.delayed.clear();
        let model = self.model;
        for (m, def) in model.machines.iter().enumerate() {
            let r = &mut self.ms[m];
            r.state = def.initial;
            r.pc = def
                .states
                .get(def.initial as usize)
                .map_or(IDLE, |s| s.entry);
            r.waiting = false;
            r.blocked = false;
            r.awaiting = NO_MSG;
            r.wake = 0;
            r.bcast = 0;
            r.delay_done = false;
            r.cur = NO_MSG;
            r.cur_event = StrId(0);
            r.cur_origin = StrId(0);
            r.intq.clear();
            r.qhead = NO_MSG;
            r.qtail = NO_MSG;
            r.qlen = 0;
            // Variables with an initial value are overwritten below; resetting them to the
            // default first would throw their buffers away.
            for (i, (v, d)) in r.vars.iter_mut().zip(&def.defaults).enumerate() {
                if !def.init.iter().any(|x| x.0 as usize == i) {
                    v.clone_from(d);
                }
            }
            for (slot, f, bound, span, sc) in &def.init {
                let Some(scratch) = scratch_cell(&mut self.scratch, m, *sc) else {
                    continue;
                };
                let res = {
                    let r = &self.ms[m];
                    let mut env = Env {
                        vars: &r.vars,
                        params: &[],
                        event: StrId(0),
                        origin: StrId(0),
                        rng: &mut *rng,
                        strings: &model.strings,
                    };
                    f(&mut env, scratch)
                };
                if let Err(e) = res {
                    return Err(self.diag_error(m, None, e));
                }
                let scratch = &self.scratch[m][*sc as usize];
                if let (Some(b), Cell::List(v)) = (bound, scratch) {
                    if v.len() > *b as usize {
                        return Err(Stop::End(Box::new(EndReason::Error(RunError {
                            machine: MachineId(m as u32),
                            time: 0,
                            diagnostic: model.sources.diag(
                                *span,
                                format!(
                                    "initial value has {} elements, more than the declared {b}",
                                    v.len()
                                ),
                            ),
                        }))));
                    }
                }
                if let Some(dst) = self.ms[m].vars.get_mut(*slot as usize) {
                    dst.clone_from(scratch);
                }
            }
        }
        self.pending.iter_mut().for_each(|p| *p = false);
        self.checked.iter_mut().for_each(|c| *c = 0);
        self.pending_list.clear();
        self.inbox.items.clear();
        self.pending_regular = 0;
        self.pending_bb_set = 0;
        self.blocked_list.clear();
        for (slot, d) in self.pool.iter_mut().zip(&model.events) {
            for (c, dc) in slot.params.iter_mut().zip(&d.defaults) {
                c.clone_from(dc);
            }
            slot.origin = 0;
        }
        for m in 0..self.ms.len() {
            self.refresh(m);
        }
        Ok(())
    }
}
