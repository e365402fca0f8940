//! A `<send>`: its delay (under both semantics), then under SCAN's the message into its target's queue.

use super::*;

/// Pool slot `w`, to write a message into, and the parameters of slot `cur` (a machine's
/// current message, `NO_MSG`: none), which the message's expressions read meanwhile.
/// A free slot is never a current message; if it were, it would read as empty.
#[inline(always)]
fn write_and_read(pool: &mut [Slot], w: usize, cur: u32) -> (&mut Slot, &[Cell]) {
    let c = cur as usize;
    if cur == NO_MSG || c == w {
        (&mut pool[w], &[])
    } else if c < w {
        let (lo, hi) = pool.split_at_mut(w);
        (&mut hi[0], &lo[c].params)
    } else {
        let (lo, hi) = pool.split_at_mut(c);
        (&mut lo[w], &hi[0].params)
    }
}

impl Simulator<'_> {
    /// Starts the delay of a delayed send not yet delayed: the machine waits `n` units
    /// (true), or the send goes on now (false: no delay, or the delay is over).
    #[inline(always)]
    pub(super) fn start_delay(
        &mut self,
        m: usize,
        pc: u32,
        sd: &SendDef,
        rng: &mut dyn Entropy,
    ) -> Result<bool, Stop> {
        let model = self.model;
        if let Some(d) = &sd.delay {
            if !self.ms[m].delay_done {
                let n = match d {
                    DelayDef::Const(n) => *n,
                    DelayDef::Expr(f) => {
                        let res = {
                            let mut env = env(&self.ms, &self.pool, m, &mut *rng, &model.strings);
                            f(&mut env)
                        };
                        match res {
                            Ok(v) => v.max(0) as u64,
                            Err(e) => return Err(self.diag_error(m, Some(pc as usize), e)),
                        }
                    }
                };
                if n > 0 {
                    let r = &mut self.ms[m];
                    r.delay_done = true;
                    r.waiting = true;
                    r.wake = self.time.saturating_add(n);
                    self.delayed.push(m as u32);
                    self.refresh(m);
                    return Ok(true);
                }
            }
        }
        Ok(false)
    }

    /// [`EventSemantics::Queues`]: evaluates the send's target and parameters, reports the
    /// send and appends the message to its target's queue (one target per call for a
    /// broadcast). `None`: nobody receives the event, the machine goes on at once.
    #[inline]
    pub(super) fn queue_send<O: Observer + ?Sized>(
        &mut self,
        m: usize,
        pc: u32,
        sd: &SendDef,
        rng: &mut dyn Entropy,
        obs: &mut O,
    ) -> Result<Option<Flow>, Stop> {
        let model = self.model;
        let def = &model.machines[m];
        let mut broadcast_len = 0usize;
        let target: Option<u32> = match &sd.to {
            SendTo::Machine(t) => Some(*t),
            SendTo::Sink => None,
            SendTo::Broadcast(list) => {
                broadcast_len = list.len();
                match list.get(self.ms[m].bcast as usize) {
                    Some(&t) => Some(t),
                    None => {
                        // Nobody receives this event: nothing is sent.
                        let r = &mut self.ms[m];
                        r.bcast = 0;
                        r.delay_done = false;
                        r.pc = pc + 1;
                        return Ok(None);
                    }
                }
            }
            SendTo::Expr(f) => {
                let res = {
                    let mut env = env(&self.ms, &self.pool, m, &mut *rng, &model.strings);
                    f(&mut env)
                };
                let s = match res {
                    Ok(s) => s,
                    Err(e) => return Err(self.diag_error(m, Some(pc as usize), e)),
                };
                match model.machine_of_str.get(s.0 as usize) {
                    Some(&t) if t != u32::MAX => Some(t),
                    _ if s == model.none_str => None,
                    _ => {
                        let span = def
                            .code_spans
                            .get(pc as usize)
                            .copied()
                            .unwrap_or(def.file.at(0));
                        return Err(Stop::End(Box::new(EndReason::Error(RunError {
                            machine: MachineId(m as u32),
                            time: self.time,
                            diagnostic: model.sources.diag(
                                span,
                                format!(
                                    "targetexpr evaluated to `{}`, which is not a machine",
                                    model.strings.get(s)
                                ),
                            ),
                        }))));
                    }
                }
            }
        };
        let Some(evdef) = model.events.get(sd.event as usize) else {
            return Err(self.diag_error(
                m,
                Some(pc as usize),
                EvalError {
                    at: 0,
                    kind: EvalErrorKind::Internal,
                },
            ));
        };
        // Slots are reused per event, so their cells keep their shapes (no allocation).
        let slot = match self.free.get_mut(sd.event as usize).and_then(|f| f.pop()) {
            Some(s) => s,
            None => {
                self.pool.push(Slot {
                    event: sd.event,
                    origin: 0,
                    target: 0,
                    params: evdef.defaults.clone(),
                });
                self.pool.len() as u32 - 1
            }
        };
        let res = {
            let r = &self.ms[m];
            let (s, params) = write_and_read(&mut self.pool, slot as usize, r.cur);
            for &i in &sd.missing {
                if let (Some(dst), Some(d)) =
                    (s.params.get_mut(i as usize), evdef.defaults.get(i as usize))
                {
                    dst.clone_from(d);
                }
            }
            let mut env = env_of(r, params, &mut *rng, &model.strings);
            let res = eval_params(sd, &mut env, &mut s.params);
            s.event = sd.event;
            s.origin = m as u32;
            s.target = target.unwrap_or(u32::MAX);
            res
        };
        if let Err(e) = res {
            self.free_slot(slot);
            return Err(self.diag_error(m, Some(pc as usize), e));
        }
        self.steps += 1;
        self.instant_steps += 1;
        let flow = obs.on_send(
            self.time,
            &SentMessage {
                model,
                event: EventId(sd.event),
                origin: MachineId(m as u32),
                target: target.map(MachineId),
                params: &self.pool[slot as usize].params,
            },
        );
        match target {
            Some(t) => {
                self.ms[t as usize].extq.push_back(slot);
                self.touch(t as usize);
                self.refresh(t as usize);
            }
            None => self.free_slot(slot),
        }
        let r = &mut self.ms[m];
        if broadcast_len > 0 && (r.bcast as usize) + 1 < broadcast_len {
            r.bcast += 1;
        } else {
            r.bcast = 0;
            r.delay_done = false;
            r.pc = pc + 1;
        }
        Ok(Some(flow))
    }
}
