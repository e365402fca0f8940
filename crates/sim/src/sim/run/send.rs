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
                    // An environment only for a delay that evaluates (the global timer's
                    // `delay="1"` is a constant, and it waits every unit).
                    _ => {
                        let res = {
                            let mut env = env(&self.ms, &self.pool, m, &mut *rng, &model.strings);
                            d.units(&mut env)
                        };
                        match res {
                            Ok(n) => n,
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
    ///
    /// Works over split borrows of the simulator's fields (the sender's record, the pool,
    /// the free lists, the target's record), each taken once.
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
        let Simulator {
            ms,
            pool,
            free,
            runnable,
            dirty,
            time,
            steps,
            instant_steps,
            reserved,
            sampled,
            ..
        } = self;
        let r = &ms[m];
        let mut broadcast_len = 0usize;
        let target: Option<u32> = match &sd.to {
            SendTo::Machine(t) => Some(*t),
            SendTo::Sink => None,
            SendTo::Broadcast(list) => {
                broadcast_len = list.len();
                match list.get(r.bcast as usize) {
                    Some(&t) => Some(t),
                    None => {
                        // Nobody receives this event: nothing is sent.
                        let r = &mut ms[m];
                        r.bcast = 0;
                        r.delay_done = false;
                        r.pc = pc + 1;
                        return Ok(None);
                    }
                }
            }
            SendTo::Expr(f) => {
                let res = {
                    let mut env = env_of(r, params_of(r, pool), &mut *rng, &model.strings);
                    f(&mut env)
                };
                let s = match res {
                    Ok(s) => s,
                    Err(e) => return Err(self.diag_error(m, Some(pc as usize), e)),
                };
                match model.machine_of_str.get(s.0 as usize) {
                    Some(&t) if t != u32::MAX => Some(t),
                    _ if s == model.none_str => None,
                    _ => return Err(self.not_a_machine(m, pc, s)),
                }
            }
        };
        let Some(evdef) = model.events.get(sd.event as usize) else {
            return Err(self.internal(m, pc));
        };
        // Slots are reused per event, so their cells keep their shapes (no allocation).
        let slot = match free.get_mut(sd.event as usize).and_then(|f| f.pop()) {
            Some(s) => s,
            None => {
                pool.push(Slot {
                    event: sd.event,
                    origin: 0,
                    target: 0,
                    next: NO_MSG,
                    params: evdef.defaults.clone(),
                });
                pool.len() as u32 - 1
            }
        };
        let (s, params) = write_and_read(pool, slot as usize, r.cur);
        for &i in &sd.missing {
            if let (Some(dst), Some(d)) =
                (s.params.get_mut(i as usize), evdef.defaults.get(i as usize))
            {
                dst.clone_from(d);
            }
        }
        let res = {
            let mut env = env_of(r, params, &mut *rng, &model.strings);
            eval_params(sd, &mut env, &mut s.params)
        };
        s.event = sd.event;
        s.origin = m as u32;
        s.target = target.unwrap_or(u32::MAX);
        if let Err(e) = res {
            self.free_slot(slot);
            return Err(self.diag_error(m, Some(pc as usize), e));
        }
        *steps += 1;
        *instant_steps += 1;
        let flow = obs.on_send(
            *time,
            &SentMessage {
                model,
                event: EventId(sd.event),
                origin: MachineId(m as u32),
                target: target.map(MachineId),
                params: &s.params,
            },
        );
        match target {
            Some(t) => {
                let t = t as usize;
                s.next = NO_MSG;
                let q = &mut ms[t];
                let tail = q.qtail;
                q.qtail = slot;
                q.qlen += 1;
                if tail == NO_MSG {
                    q.qhead = slot;
                } else if let Some(prev) = pool.get_mut(tail as usize) {
                    prev.next = slot;
                }
                touch_in(ms, dirty, *sampled, t);
                refresh_in(ms, runnable, t);
            }
            None => {
                // The `NONE` sink: the slot is free again at once (never a reserved one:
                // those exist only under `EventSemantics::As2fm`).
                if slot as usize >= *reserved {
                    if let Some(f) = free.get_mut(sd.event as usize) {
                        f.push(slot);
                    }
                }
            }
        }
        let r = &mut ms[m];
        if broadcast_len > 0 && (r.bcast as usize) + 1 < broadcast_len {
            r.bcast += 1;
        } else {
            r.bcast = 0;
            r.delay_done = false;
            r.pc = pc + 1;
        }
        Ok(Some(flow))
    }

    /// The error of a `targetexpr` that named no machine (nor `NONE`).
    #[cold]
    fn not_a_machine(&self, m: usize, pc: u32, s: StrId) -> Stop {
        let model = self.model;
        let def = &model.machines[m];
        let span = def
            .code_spans
            .get(pc as usize)
            .copied()
            .unwrap_or(def.file.at(0));
        Stop::End(Box::new(EndReason::Error(RunError {
            machine: MachineId(m as u32),
            time: self.time,
            diagnostic: model.sources.diag(
                span,
                format!(
                    "targetexpr evaluated to `{}`, which is not a machine",
                    model.strings.get(s)
                ),
            ),
        })))
    }
}

impl DelayDef {
    /// The model time units this delay waits, its expression evaluated in `env`.
    fn units(&self, env: &mut Env<'_>) -> Result<u64, EvalError> {
        match self {
            DelayDef::Const(n) => Ok(*n),
            DelayDef::Expr { f, at } => f(env).and_then(|v| delay_units(v, None, *at)),
            DelayDef::Scaled { f, ns, unit, at } => {
                f(env).and_then(|v| delay_units(v, Some((*ns, *unit)), *at))
            }
            DelayDef::ScaledFloat { f, ns, unit, at } => {
                f(env).and_then(|v| float_delay_units(v, *ns, *unit, *at))
            }
        }
    }
}

/// The units an integer `delayexpr` that gave `v` waits: `v` itself, or with `scale`
/// `(ns, unit)` (`d + 'ms'`) the duration `v` times `ns` in units of `unit` ns. A
/// negative delay, or a duration between two units, is an error at `at`.
fn delay_units(v: i64, scale: Option<(u64, u64)>, at: u32) -> Result<u64, EvalError> {
    let err = |kind| EvalError { at, kind };
    let n =
        u64::try_from(v).map_err(|_| err(EvalErrorKind::NegativeDelay((v as f64).to_bits())))?;
    let Some((ns, unit)) = scale else {
        return Ok(n);
    };
    let total = n.checked_mul(ns).ok_or(err(EvalErrorKind::Overflow))?;
    if total % unit != 0 {
        return Err(err(EvalErrorKind::DelaySteps { ns: total, unit }));
    }
    Ok(total / unit)
}

/// The units `v` of `ns` nanoseconds make in a model whose unit is `unit` ns (a float
/// `delayexpr`: `0.5 + 's'`). The product is rounded to the nanosecond (`0.1 * 1e9` is
/// not exactly 10^8 in floats); a negative or non-finite delay, or one between two units,
/// is an error at `at`.
fn float_delay_units(v: f64, ns: u64, unit: u64, at: u32) -> Result<u64, EvalError> {
    let err = |kind| EvalError { at, kind };
    if v < 0.0 {
        return Err(err(EvalErrorKind::NegativeDelay(v.to_bits())));
    }
    let total = (v * ns as f64).round();
    if !total.is_finite() || total >= u64::MAX as f64 {
        return Err(err(EvalErrorKind::NoInteger(v.to_bits())));
    }
    let total = total as u64;
    if total % unit != 0 {
        return Err(err(EvalErrorKind::DelaySteps { ns: total, unit }));
    }
    Ok(total / unit)
}
