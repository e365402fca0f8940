//! Delivering messages: an idle machine takes its next event, and AS2FM's pending messages
//! (one per event, broadcast to every receiver, senders blocking while it is pending),
//! including the messages that processes post from outside.

use super::*;

impl Simulator<'_> {
    /// An idle machine `m` takes its next event: an internal one first (`None`: go on
    /// stepping), else the oldest queued message (one point, reported to `obs`), else
    /// nothing (the machine stays idle).
    #[inline]
    pub(super) fn take_event<O: Observer + ?Sized>(
        &mut self,
        m: usize,
        rng: &mut dyn Entropy,
        cfg: &RunConfig,
        obs: &mut O,
        internal: &mut u32,
    ) -> Result<Option<Flow>, Stop> {
        let model = self.model;
        let def = &model.machines[m];
        if let Some(ev) = self.ms[m].intq.pop_front() {
            self.release(m);
            self.ms[m].cur_event = model
                .events
                .get(ev as usize)
                .map_or(StrId(0), |e| e.name_str);
            self.ms[m].cur_origin = def.name_str;
            let list = self.candidates(m, def, Some(ev));
            if let Some(t) = self.select(m, def, list, rng, cfg)? {
                self.ms[m].pc = def.trans[t as usize].pc;
            }
            *internal += 1;
            if *internal > cfg.max_eventless {
                return Err(self.spin(m, SpinKind::EventlessLoop));
            }
            return Ok(None);
        }
        let slot = self.ms[m].qhead;
        if slot != NO_MSG {
            let (event, origin, target, next) = {
                let s = &self.pool[slot as usize];
                (s.event, s.origin, s.target, s.next)
            };
            let q = &mut self.ms[m];
            q.qhead = next;
            q.qlen -= 1;
            if next == NO_MSG {
                q.qtail = NO_MSG;
            }
            self.release(m);
            self.take_current(m, slot, event, origin);
            self.steps += 1;
            self.instant_steps += 1;
            let flow = obs.on_receive(
                self.time,
                &SentMessage {
                    model,
                    event: EventId(event),
                    origin: MachineId(origin),
                    target: (target != u32::MAX).then_some(MachineId(target)),
                    params: &self.pool[slot as usize].params,
                },
            );
            let list = self.candidates(m, def, Some(event));
            if let Some(t) = self.select(m, def, list, rng, cfg)? {
                self.ms[m].pc = def.trans[t as usize].pc;
            }
            self.refresh(m);
            return Ok(Some(flow));
        }
        self.refresh(m);
        Ok(Some(Flow::Continue))
    }

    /// Makes the message in pool slot `slot` (event `event`, from machine `origin`)
    /// machine `m`'s current one: what `_event` and its name and origin read.
    #[inline]
    fn take_current(&mut self, m: usize, slot: u32, event: u32, origin: u32) {
        let model = self.model;
        self.touch(m);
        let r = &mut self.ms[m];
        r.cur = slot;
        r.cur_event = model
            .events
            .get(event as usize)
            .map_or(StrId(0), |e| e.name_str);
        r.cur_origin = model
            .machines
            .get(origin as usize)
            .map_or(StrId(0), |d| d.name_str);
    }

    /// Whether a blocked machine's send (or awaited rendezvous) can go on now.
    pub(super) fn send_possible(&self, m: usize) -> bool {
        let r = &self.ms[m];
        if r.awaiting != NO_MSG {
            return !self.pending[r.awaiting as usize];
        }
        match self.model.machines[m].code.get(r.pc as usize) {
            Some(Instr::Send(sd)) => self.send_enabled(sd.event),
            _ => true,
        }
    }

    /// [`EventSemantics::As2fm`]: whether event `e` may be sent now.
    pub(super) fn send_enabled(&self, e: u32) -> bool {
        let bb_blocked = self.ev_flags[e as usize] & EV_BB_REQ != 0 && self.pending_bb_set > 0;
        !self.pending[e as usize] && !bb_blocked
    }

    /// What receiver `r` (receiver slot `i`, see [`receivers::receiver_table`]) does with
    /// pending event `e` now: `Some(Some(t))` fires transition `t`, `Some(None)` discards
    /// it, `None` cannot take it yet. Points the receiver's `_event` at the event's global
    /// buffer.
    pub(super) fn receive_choice(
        &mut self,
        r: u32,
        e: u32,
        i: usize,
        rng: &mut dyn Entropy,
        cfg: &RunConfig,
    ) -> Result<Option<Option<u32>>, Stop> {
        let model = self.model;
        let m = r as usize;
        let rt = &self.ms[m];
        if rt.pc != IDLE || rt.blocked || rt.waiting || !rt.intq.is_empty() {
            return Ok(None);
        }
        let def = &model.machines[m];
        let state = rt.state as usize;
        if state >= def.states.len() {
            return Ok(None);
        }
        // The state's transitions on `e` and the drop rule, worked out once per model.
        let case = self.rx_cases[self.rx_first[i] as usize + state];
        let list = &def.dispatch[case.start as usize..case.end as usize];
        // What `take_current` does, with the event known to exist.
        let origin = self.pool[e as usize].origin;
        let rt = &mut self.ms[m];
        rt.cur = e;
        rt.cur_event = model.events[e as usize].name_str;
        rt.cur_origin = model
            .machines
            .get(origin as usize)
            .map_or(StrId(0), |d| d.name_str);
        self.touch(m);
        if let Some(t) = self.select(m, def, list, rng, cfg)? {
            return Ok(Some(Some(t)));
        }
        Ok(case.discard.then_some(None))
    }

    /// Whether pending event `e` can be delivered now (every receiver can take it).
    pub(super) fn deliverable_now(
        &mut self,
        e: u32,
        rng: &mut dyn Entropy,
        cfg: &RunConfig,
    ) -> Result<bool, Stop> {
        if self.ev_flags[e as usize] & EV_TIMER != 0 && self.pending_regular > 0 {
            return Ok(false);
        }
        let model = self.model;
        let base = self.rx_base[e as usize] as usize - model.events.len();
        for (k, &r) in model.events[e as usize].receivers.iter().enumerate() {
            if self.receive_choice(r, e, base + k, rng, cfg)?.is_none() {
                return Ok(false);
            }
        }
        Ok(true)
    }

    /// [`Simulator::deliverable_now`] for a run that keeps receivers' choices: a
    /// receiver's choice is computed again only when it changed since (or the event was
    /// sent again). Receivers are gone through in the same order up to the first that
    /// cannot take the event, so the same guards run at the same iterations, with the
    /// same results and errors: a guard reads only its machine and the event.
    pub(super) fn deliverable_kept(
        &mut self,
        e: u32,
        rng: &mut dyn Entropy,
        cfg: &RunConfig,
    ) -> Result<bool, Stop> {
        let ei = e as usize;
        if self.ev_flags[ei] & EV_TIMER != 0 && self.pending_regular > 0 {
            return Ok(false);
        }
        let model = self.model;
        let base = self.rx_base[ei] as usize - model.events.len();
        for (k, &r) in model.events[ei].receivers.iter().enumerate() {
            let at = self.checked[base + k];
            let choice = if at != 0 && self.ms[r as usize].changed < at {
                self.choice_kept[base + k]
            } else {
                let c = match self.receive_choice(r, e, base + k, rng, cfg)? {
                    Some(Some(t)) => t,
                    Some(None) => NO_TRANS,
                    None => CANNOT_TAKE,
                };
                self.checked[base + k] = self.clock;
                self.choice_kept[base + k] = c;
                c
            };
            if choice == CANNOT_TAKE {
                return Ok(false);
            }
        }
        Ok(true)
    }

    /// Delivers pending event `e` to all its receivers at once (one point each).
    pub(super) fn deliver<O: Observer + ?Sized>(
        &mut self,
        e: u32,
        rng: &mut dyn Entropy,
        cfg: &RunConfig,
        obs: &mut O,
    ) -> Result<Flow, Stop> {
        let model = self.model;
        let mut flow = Flow::Continue;
        let origin = self.pool[e as usize].origin;
        for (k, &r) in model.events[e as usize].receivers.iter().enumerate() {
            let m = r as usize;
            let choice = if self.keep_choices {
                // Computed at this iteration by `deliverable_kept`; set `_event` as
                // `receive_choice` does.
                let kept =
                    self.choice_kept[self.rx_base[e as usize] as usize - model.events.len() + k];
                let rt = &mut self.ms[m];
                rt.cur_event = model.events[e as usize].name_str;
                rt.cur_origin = model
                    .machines
                    .get(origin as usize)
                    .map_or(StrId(0), |d| d.name_str);
                (kept != NO_TRANS).then_some(kept)
            } else {
                let i = self.rx_base[e as usize] as usize - model.events.len() + k;
                self.receive_choice(r, e, i, rng, cfg)?.flatten()
            };
            self.ms[m].changed = self.clock;
            // The receiver keeps its own copy: JANI assigns it with the receive itself.
            let rx = self.rx_base[e as usize] as usize + k;
            let (global, copy) = self.pool.split_at_mut(rx);
            assign_cells(&mut copy[0].params, &global[e as usize].params);
            copy[0].origin = origin;
            self.ms[m].cur = rx as u32;
            self.steps += 1;
            self.instant_steps += 1;
            self.ms[m].moves = self.ms[m].moves.saturating_add(1);
            let f = obs.on_receive(
                self.time,
                &SentMessage {
                    model,
                    event: EventId(e),
                    origin: MachineId(origin),
                    target: Some(MachineId(r)),
                    params: &self.pool[e as usize].params,
                },
            );
            if f == Flow::Stop {
                flow = Flow::Stop;
            }
            if let Some(t) = choice {
                self.ms[m].pc = model.machines[m].trans[t as usize].pc;
                self.refresh(m);
            }
            self.touch(m);
        }
        self.pending[e as usize] = false;
        if let Some(i) = self.pending_list.iter().position(|&x| x == e) {
            self.pending_list.remove(i);
        }
        let flags = self.ev_flags[e as usize];
        if flags & EV_TIMER == 0 {
            self.pending_regular = self.pending_regular.saturating_sub(1);
        }
        if flags & EV_BB_SET != 0 {
            self.pending_bb_set = self.pending_bb_set.saturating_sub(1);
        }
        let mut i = 0;
        while i < self.blocked_list.len() {
            let m = self.blocked_list[i] as usize;
            if self.send_possible(m) {
                self.ms[m].changed = self.clock;
                self.ms[m].blocked = false;
                self.ms[m].awaiting = NO_MSG;
                self.touch(m);
                self.blocked_list.swap_remove(i);
                self.refresh(m);
            } else {
                i += 1;
            }
        }
        Ok(flow)
    }

    /// Posts the messages of [`Self::inbox`] whose events are not pending, oldest first,
    /// as [`Self::as2fm_send`] does for a machine's send; the rest wait until the model is
    /// idle again at this instant, or for the next unit.
    pub(super) fn post_inputs<O: Observer + ?Sized>(&mut self, obs: &mut O) -> Flow {
        let model = self.model;
        let mut flow = Flow::Continue;
        let mut left = std::mem::take(&mut self.inbox.items);
        let mut i = 0;
        while i < left.len() {
            let e = left[i].0 .0 as usize;
            if e >= model.events.len() {
                left.remove(i);
                continue;
            }
            if !self.send_enabled(e as u32) {
                i += 1;
                continue;
            }
            let Some((_, params)) = left.remove(i) else {
                break;
            };
            let slot = &mut self.pool[e];
            for (c, d) in slot.params.iter_mut().zip(&model.events[e].defaults) {
                c.clone_from(d);
            }
            for (k, v) in params {
                let Some(c) = slot.params.get_mut(k) else {
                    continue;
                };
                // Only a value of the parameter's own kind replaces its default.
                match (c, v) {
                    (Cell::Bool(b), Scalar::Bool(x)) => *b = x,
                    (Cell::Int(b), Scalar::Int(x)) => *b = x,
                    (Cell::Float(b), Scalar::Float(x)) => *b = x,
                    (Cell::Float(b), Scalar::Int(x)) => *b = x as f64,
                    _ => {}
                }
            }
            slot.origin = EXTERNAL.0;
            slot.target = u32::MAX;
            self.touch_readers(e);
            self.steps += 1;
            self.instant_steps += 1;
            let f = obs.on_send(
                self.time,
                &SentMessage {
                    model,
                    event: EventId(e as u32),
                    origin: EXTERNAL,
                    target: None,
                    params: &self.pool[e].params,
                },
            );
            if f == Flow::Stop {
                flow = Flow::Stop;
            }
            if !model.events[e].receivers.is_empty() {
                self.pending[e] = true;
                let base = self.rx_base[e] as usize - model.events.len();
                self.checked[base..base + model.events[e].receivers.len()].fill(0);
                self.pending_list.push(e as u32);
                let flags = self.ev_flags[e];
                if flags & EV_TIMER == 0 {
                    self.pending_regular += 1;
                }
                if flags & EV_BB_SET != 0 {
                    self.pending_bb_set += 1;
                }
            }
        }
        self.inbox.items = left;
        flow
    }

    /// A `<send>` under [`EventSemantics::As2fm`]: blocks while its event is pending,
    /// else writes the event's global parameters and makes it pending.
    pub(super) fn as2fm_send<O: Observer + ?Sized>(
        &mut self,
        m: usize,
        pc: u32,
        sd: &SendDef,
        rng: &mut dyn Entropy,
        obs: &mut O,
    ) -> Result<Flow, Stop> {
        let model = self.model;
        let e = sd.event as usize;
        if !self.send_enabled(sd.event) {
            self.ms[m].blocked = true;
            self.blocked_list.push(m as u32);
            self.refresh(m);
            return Ok(Flow::Continue);
        }
        // The new parameters are evaluated into the event's scratch buffer (the old ones
        // stay readable meanwhile), then the two buffers change places.
        let res = {
            let out = &mut self.ev_scratch[e];
            for &i in &sd.missing {
                if let (Some(dst), Some(cur)) =
                    (out.get_mut(i as usize), self.pool[e].params.get(i as usize))
                {
                    dst.clone_from(cur);
                }
            }
            let mut env = env(&self.ms, &self.pool, m, &mut *rng, &model.strings);
            eval_params(sd, &mut env, out)
        };
        if let Err(err) = res {
            return Err(self.diag_error(m, Some(pc as usize), err));
        }
        std::mem::swap(&mut self.pool[e].params, &mut self.ev_scratch[e]);
        let declared = match &sd.to {
            SendTo::Machine(t) => *t,
            _ => u32::MAX,
        };
        self.pool[e].origin = m as u32;
        self.pool[e].target = declared;
        self.touch_readers(e);
        self.steps += 1;
        self.instant_steps += 1;
        let flow = obs.on_send(
            self.time,
            &SentMessage {
                model,
                event: EventId(sd.event),
                origin: MachineId(m as u32),
                target: (declared != u32::MAX).then_some(MachineId(declared)),
                params: &self.pool[e].params,
            },
        );
        let r = &mut self.ms[m];
        r.bcast = 0;
        r.delay_done = false;
        r.pc = pc + 1;
        if !model.events[e].receivers.is_empty() {
            let flags = self.ev_flags[e];
            self.pending[e] = true;
            // New parameters: every receiver's choice is computed again.
            let base = self.rx_base[e] as usize - model.events.len();
            self.checked[base..base + model.events[e].receivers.len()].fill(0);
            self.pending_list.push(sd.event);
            if flags & EV_TIMER != 0 {
                r.blocked = true;
                r.awaiting = sd.event;
                self.blocked_list.push(m as u32);
            } else {
                self.pending_regular += 1;
            }
            if flags & EV_BB_SET != 0 {
                self.pending_bb_set += 1;
            }
            self.refresh(m);
        }
        Ok(flow)
    }
}
