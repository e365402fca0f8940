//! One step of a machine: the interpreter of its compiled code, and the choice among its enabled transitions.

use super::*;

/// Evaluates `code`: a scalar is returned, an array or struct is written into `scratch`.
fn eval_code(
    code: &Code,
    env: &mut Env<'_>,
    scratch: &mut Cell,
) -> Result<Option<Cell>, EvalError> {
    Ok(Some(match code {
        Code::Bool(f) => Cell::Bool(f(env)?),
        Code::Int(f) => Cell::Int(f(env)?),
        Code::Float(f) => Cell::Float(f(env)?),
        Code::Str(f) => Cell::Str(f(env)?),
        Code::Comp(f) => {
            f(env, scratch)?;
            return Ok(None);
        }
    }))
}

impl Simulator<'_> {
    /// Evaluates the guards of `list` (transitions of machine `m`) and picks one.
    pub(super) fn select(
        &mut self,
        m: usize,
        def: &MachineDef,
        list: &[u32],
        rng: &mut dyn Entropy,
        cfg: &RunConfig,
    ) -> Result<Option<u32>, Stop> {
        if list.is_empty() {
            return Ok(None);
        }
        self.enabled.clear();
        let doc_order = cfg.transitions == TransitionChoice::DocumentOrder;
        // Unguarded transitions first, without an environment; from the first guard on,
        // one environment serves every guard left (building it per guard cost as much
        // as a simple guard, building it for a list without guards was wasted).
        let mut rest = list;
        while let Some((&t, tail)) = rest.split_first() {
            let Some(td) = def.trans.get(t as usize) else {
                rest = tail;
                continue;
            };
            if td.cond.is_some() {
                break;
            }
            if doc_order {
                return Ok(Some(t));
            }
            self.enabled.push(t);
            rest = tail;
        }
        if !rest.is_empty() {
            let mut failed = None;
            {
                let mut env = env(&self.ms, &self.pool, m, &mut *rng, &self.model.strings);
                for &t in rest {
                    let Some(td) = def.trans.get(t as usize) else {
                        continue;
                    };
                    let ok = match &td.cond {
                        None => true,
                        Some(c) => match c(&mut env) {
                            Ok(b) => b,
                            Err(e) => {
                                failed = Some((td.pc, e));
                                break;
                            }
                        },
                    };
                    if ok {
                        if doc_order {
                            return Ok(Some(t));
                        }
                        self.enabled.push(t);
                    }
                }
            }
            if let Some((pc, e)) = failed {
                return Err(self.diag_error(m, Some(pc as usize), e));
            }
        }
        match self.enabled.len() {
            0 => Ok(None),
            1 => Ok(Some(self.enabled[0])),
            n => {
                let k = self.choose_transition(m, n as u32, rng, cfg);
                Ok(Some(self.enabled[k as usize]))
            }
        }
    }

    /// The transitions of machine `m` in its current state on `event`, or its eventless
    /// ones (`None`), in document order.
    pub(super) fn candidates<'d>(
        &self,
        m: usize,
        def: &'d MachineDef,
        event: Option<u32>,
    ) -> &'d [u32] {
        match (def.states.get(self.ms[m].state as usize), event) {
            (Some(st), Some(e)) => st.transitions(e, &def.dispatch),
            (Some(st), None) => &st.eventless,
            (None, _) => &[],
        }
    }

    /// One step of machine `m`: runs until it communicates once or has nothing to do.
    pub(super) fn step<O: Observer + ?Sized>(
        &mut self,
        m: usize,
        rng: &mut dyn Entropy,
        cfg: &RunConfig,
        obs: &mut O,
    ) -> Result<Flow, Stop> {
        let model = self.model;
        let def = &model.machines[m];
        let mut internal = 0u32;
        loop {
            let pc = self.ms[m].pc;
            if pc == IDLE {
                match self.take_event(m, rng, cfg, obs, &mut internal)? {
                    Some(flow) => return Ok(flow),
                    None => continue,
                }
            }
            let Some(instr) = def.code.get(pc as usize) else {
                return Err(self.diag_error(
                    m,
                    None,
                    EvalError {
                        at: 0,
                        kind: EvalErrorKind::Internal,
                    },
                ));
            };
            match instr {
                Instr::AssignVar {
                    slot,
                    value,
                    bound,
                    scratch: sc,
                } => {
                    let Some(scratch) = scratch_cell(&mut self.scratch, m, *sc) else {
                        return Err(self.internal(m, pc));
                    };
                    let res = {
                        let mut env = env(&self.ms, &self.pool, m, &mut *rng, &model.strings);
                        eval_code(value, &mut env, scratch)
                    };
                    let scratch = &self.scratch[m][*sc as usize];
                    let scalar = match res {
                        Ok(v) => v,
                        Err(e) => return Err(self.diag_error(m, Some(pc as usize), e)),
                    };
                    let Some(dst) = self.ms[m].vars.get_mut(*slot as usize) else {
                        return Err(self.internal(m, pc));
                    };
                    match scalar {
                        Some(v) => *dst = v,
                        None => {
                            if let (Some(b), Cell::List(v)) = (bound, scratch) {
                                if v.len() > *b as usize {
                                    return Err(self.too_long(m, pc, *b));
                                }
                            }
                            dst.clone_from(scratch);
                        }
                    }
                    self.ms[m].pc = pc + 1;
                }
                Instr::AssignPlace {
                    place,
                    value,
                    scratch: sc,
                } => {
                    let Some(scratch) = scratch_cell(&mut self.scratch, m, *sc) else {
                        return Err(self.internal(m, pc));
                    };
                    let res = {
                        let mut env = env(&self.ms, &self.pool, m, &mut *rng, &model.strings);
                        place
                            .eval_indices(&mut env, &mut self.idx)
                            .and_then(|()| eval_code(value, &mut env, scratch))
                    };
                    let scratch = &self.scratch[m][*sc as usize];
                    let stored = match res {
                        Ok(Some(v)) => place.store(&mut self.ms[m].vars, &self.idx, &v),
                        Ok(None) => place.store(&mut self.ms[m].vars, &self.idx, scratch),
                        Err(e) => Err(e),
                    };
                    if let Err(e) = stored {
                        return Err(self.diag_error(m, Some(pc as usize), e));
                    }
                    self.ms[m].pc = pc + 1;
                }
                Instr::If { cond, else_pc } => {
                    let res = {
                        let mut env = env(&self.ms, &self.pool, m, &mut *rng, &model.strings);
                        cond(&mut env)
                    };
                    match res {
                        Ok(true) => self.ms[m].pc = pc + 1,
                        Ok(false) => self.ms[m].pc = *else_pc,
                        Err(e) => return Err(self.diag_error(m, Some(pc as usize), e)),
                    }
                }
                Instr::Jump(t) => self.ms[m].pc = *t,
                Instr::Raise(ev) => {
                    self.ms[m].intq.push_back(*ev);
                    self.ms[m].pc = pc + 1;
                }
                Instr::Log {
                    label,
                    value,
                    scratch: sc,
                } => {
                    let Some(scratch) = scratch_cell(&mut self.scratch, m, *sc) else {
                        return Err(self.internal(m, pc));
                    };
                    let mut has = false;
                    if let Some(f) = value {
                        let res = {
                            let mut env = env(&self.ms, &self.pool, m, &mut *rng, &model.strings);
                            f(&mut env, scratch)
                        };
                        if let Err(e) = res {
                            return Err(self.diag_error(m, Some(pc as usize), e));
                        }
                        has = true;
                    }
                    let scratch = &self.scratch[m][*sc as usize];
                    let v = if has { Some(Value::of(scratch)) } else { None };
                    obs.on_log(self.time, MachineId(m as u32), label, v);
                    self.ms[m].pc = pc + 1;
                }
                Instr::Goto(s) => {
                    let r = &mut self.ms[m];
                    r.state = *s;
                    r.pc = match def.states.get(*s as usize) {
                        // What its entry code would do: check no eventless transition.
                        Some(st) if st.idle_on_entry => IDLE,
                        Some(st) => st.entry,
                        None => IDLE,
                    };
                }
                Instr::CheckEventless => {
                    let list = self.candidates(m, def, None);
                    // No eventless transition (most states' entry code ends so): idle
                    // without the call.
                    if list.is_empty() {
                        self.ms[m].pc = IDLE;
                        continue;
                    }
                    match self.select(m, def, list, rng, cfg)? {
                        Some(t) => {
                            internal += 1;
                            if internal > cfg.max_eventless {
                                return Err(self.spin(m, SpinKind::EventlessLoop));
                            }
                            self.ms[m].pc = def.trans[t as usize].pc;
                        }
                        None => self.ms[m].pc = IDLE,
                    }
                }
                Instr::Send(sd) => {
                    // A delayed send blocks its machine for the delay (as in SCAN), then sends.
                    if self.start_delay(m, pc, sd, rng)? {
                        return Ok(Flow::Continue);
                    }
                    if self.as2fm {
                        if sd.expanded_copy {
                            self.ms[m].pc = pc + 1;
                            continue;
                        }
                        return self.as2fm_send(m, pc, sd, rng, obs);
                    }
                    match self.queue_send(m, pc, sd, rng, obs)? {
                        Some(flow) => return Ok(flow),
                        None => continue,
                    }
                }
            }
        }
    }
}
