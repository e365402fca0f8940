//! One step of a machine: the interpreter of its compiled code, and the choice among its enabled transitions.
//!
//! The interpreter ([`run_code`]) and the guards' evaluation ([`enabled_of`]) are
//! functions over split borrows, not `&mut self` methods: a step holds its machine's
//! record, its scratch cells and its current message's parameters as separate borrows
//! for as long as it runs straight-line code, so each instruction reads them through
//! registers instead of re-indexing `self.ms[m]` (which reloaded the vector's pointer
//! and length and checked the bound after every closure call). The step goes back to
//! `&mut self` only where it communicates or needs the whole simulator (a send, taking
//! an event, a scheduler's choice among several enabled transitions).

use super::*;

/// Evaluates `code`: a scalar is returned, an array or struct is written into `scratch`.
#[inline(always)]
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

/// A failure inside straight-line code: the instruction (`None`: none to blame) and why.
pub(super) type Fault = (Option<u32>, EvalError);

#[inline(always)]
fn fault(pc: u32, kind: EvalErrorKind) -> Fault {
    (Some(pc), EvalError { at: 0, kind })
}

/// Where [`run_code`] stopped: what the step does next needs more than the machine.
enum Stopped<'d> {
    /// The machine is idle: it takes its next event (or stays idle).
    Idle,
    /// At a `CheckEventless` (at `pc`) whose state has eventless transitions `list`.
    Eventless(&'d [u32]),
    /// At a send (at `pc`).
    Send(u32, &'d SendDef),
}

/// Runs machine `r`'s straight-line code from its `pc` until it is idle, reaches a send
/// or an eventless check that has transitions to choose from, or fails. `params` are its
/// current message's parameters, `scratch` its scratch cells.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn run_code<'d, O: Observer + ?Sized>(
    def: &'d MachineDef,
    m: usize,
    r: &mut MachineRt,
    params: &[Cell],
    scratch: &mut [Cell],
    idx: &mut [i64; MAX_PATH],
    rng: &mut dyn Entropy,
    strings: &Strings,
    time: u64,
    obs: &mut O,
) -> Result<Stopped<'d>, Fault> {
    let code = &def.code[..];
    loop {
        let pc = r.pc;
        if pc == IDLE {
            return Ok(Stopped::Idle);
        }
        let Some(instr) = code.get(pc as usize) else {
            return Err((
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
                let Some(cell) = scratch.get_mut(*sc as usize) else {
                    return Err(fault(pc, EvalErrorKind::Internal));
                };
                let res = {
                    let mut env = env_of(r, params, &mut *rng, strings);
                    eval_code(value, &mut env, cell)
                };
                let scalar = res.map_err(|e| (Some(pc), e))?;
                let Some(dst) = r.vars.get_mut(*slot as usize) else {
                    return Err(fault(pc, EvalErrorKind::Internal));
                };
                match scalar {
                    Some(v) => *dst = v,
                    None => {
                        if let (Some(b), Cell::List(v)) = (bound, &*cell) {
                            if v.len() > *b as usize {
                                return Err(fault(pc, EvalErrorKind::TooLong { bound: *b }));
                            }
                        }
                        dst.clone_from(cell);
                    }
                }
                r.pc = pc + 1;
            }
            Instr::AssignPlace {
                place,
                value,
                scratch: sc,
            } => {
                let Some(cell) = scratch.get_mut(*sc as usize) else {
                    return Err(fault(pc, EvalErrorKind::Internal));
                };
                let res = {
                    let mut env = env_of(r, params, &mut *rng, strings);
                    place
                        .eval_indices(&mut env, idx)
                        .and_then(|()| eval_code(value, &mut env, cell))
                };
                let stored = match res {
                    Ok(Some(v)) => place.store(&mut r.vars, idx, &v),
                    Ok(None) => place.store(&mut r.vars, idx, cell),
                    Err(e) => Err(e),
                };
                stored.map_err(|e| (Some(pc), e))?;
                r.pc = pc + 1;
            }
            Instr::If { cond, else_pc } => {
                let res = {
                    let mut env = env_of(r, params, &mut *rng, strings);
                    cond(&mut env)
                };
                r.pc = if res.map_err(|e| (Some(pc), e))? {
                    pc + 1
                } else {
                    *else_pc
                };
            }
            Instr::Jump(t) => r.pc = *t,
            Instr::Raise(ev) => {
                r.intq.push_back(*ev);
                r.pc = pc + 1;
            }
            Instr::Log {
                label,
                value,
                scratch: sc,
            } => {
                let Some(cell) = scratch.get_mut(*sc as usize) else {
                    return Err(fault(pc, EvalErrorKind::Internal));
                };
                let mut has = false;
                if let Some(f) = value {
                    let res = {
                        let mut env = env_of(r, params, &mut *rng, strings);
                        f(&mut env, cell)
                    };
                    res.map_err(|e| (Some(pc), e))?;
                    has = true;
                }
                let v = if has { Some(Value::of(cell)) } else { None };
                obs.on_log(time, MachineId(m as u32), label, v);
                r.pc = pc + 1;
            }
            Instr::Goto(s) => {
                r.state = *s;
                r.pc = match def.states.get(*s as usize) {
                    // What its entry code would do: check no eventless transition.
                    Some(st) if st.idle_on_entry => IDLE,
                    Some(st) => st.entry,
                    None => IDLE,
                };
            }
            Instr::CheckEventless => {
                let list = match def.states.get(r.state as usize) {
                    Some(st) => &st.eventless[..],
                    None => &[],
                };
                // No eventless transition (most states' entry code ends so): idle
                // without a choice.
                if list.is_empty() {
                    r.pc = IDLE;
                    return Ok(Stopped::Idle);
                }
                return Ok(Stopped::Eventless(list));
            }
            Instr::Send(sd) => return Ok(Stopped::Send(pc, sd)),
        }
    }
}

/// What the guards of a transition list left.
pub(super) enum Enabled {
    /// No transition is enabled.
    None,
    /// This one fires (the first enabled one in document order, or the only one).
    One(u32),
    /// Several are (in `enabled`, in document order): the scheduler picks one.
    Many(u32),
}

/// Evaluates the guards of `list` (transitions of `def`) for machine record `r` whose
/// current message has parameters `params`; collects the enabled ones into `enabled`
/// unless `doc_order` (the first enabled one fires). An error names the failing
/// transition's code position.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub(super) fn enabled_of(
    def: &MachineDef,
    r: &MachineRt,
    params: &[Cell],
    list: &[u32],
    enabled: &mut Vec<u32>,
    rng: &mut dyn Entropy,
    strings: &Strings,
    doc_order: bool,
) -> Result<Enabled, Fault> {
    enabled.clear();
    // Unguarded transitions first, without an environment; from the first guard on, one
    // environment serves every guard left (building it per guard cost as much as a
    // simple guard, building it for a list without guards was wasted).
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
            return Ok(Enabled::One(t));
        }
        enabled.push(t);
        rest = tail;
    }
    if !rest.is_empty() {
        let mut env = env_of(r, params, rng, strings);
        for &t in rest {
            let Some(td) = def.trans.get(t as usize) else {
                continue;
            };
            let ok = match &td.cond {
                None => true,
                Some(c) => c(&mut env).map_err(|e| (Some(td.pc), e))?,
            };
            if ok {
                if doc_order {
                    return Ok(Enabled::One(t));
                }
                enabled.push(t);
            }
        }
    }
    Ok(match enabled.len() {
        0 => Enabled::None,
        1 => Enabled::One(enabled[0]),
        n => Enabled::Many(n as u32),
    })
}

impl Simulator<'_> {
    /// Evaluates the guards of `list` (transitions of machine `m`) and picks one.
    #[inline]
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
        let res = {
            let r = &self.ms[m];
            enabled_of(
                def,
                r,
                params_of(r, &self.pool),
                list,
                &mut self.enabled,
                &mut *rng,
                &self.model.strings,
                cfg.transitions == TransitionChoice::DocumentOrder,
            )
        };
        self.pick_enabled(m, res, rng, cfg)
    }

    /// The transition that fires after [`enabled_of`]: the scheduler's pick when several
    /// are enabled.
    #[inline(always)]
    fn pick_enabled(
        &mut self,
        m: usize,
        res: Result<Enabled, Fault>,
        rng: &mut dyn Entropy,
        cfg: &RunConfig,
    ) -> Result<Option<u32>, Stop> {
        match res {
            Ok(Enabled::None) => Ok(None),
            Ok(Enabled::One(t)) => Ok(Some(t)),
            Ok(Enabled::Many(n)) => {
                let k = self.choose_transition(m, n, rng, cfg);
                Ok(Some(self.enabled[k as usize]))
            }
            Err((pc, e)) => Err(self.diag_error(m, pc.map(|p| p as usize), e)),
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
        let doc_order = cfg.transitions == TransitionChoice::DocumentOrder;
        let mut internal = 0u32;
        loop {
            if self.ms[m].pc == IDLE {
                match self.take_event(m, rng, cfg, obs, &mut internal)? {
                    Some(flow) => return Ok(flow),
                    None => continue,
                }
            }
            // Straight-line code over split borrows: the record, the scratch cells and
            // the current message's parameters are held for the whole stretch.
            let (stopped, choice) = {
                let Simulator {
                    ms,
                    pool,
                    scratch,
                    idx,
                    enabled,
                    time,
                    ..
                } = self;
                let r = &mut ms[m];
                let params = params_of(r, pool);
                let sc = match scratch.get_mut(m) {
                    Some(v) => &mut v[..],
                    None => &mut [],
                };
                let stopped = run_code(def, m, r, params, sc, idx, rng, &model.strings, *time, obs);
                let choice = match &stopped {
                    Ok(Stopped::Eventless(list)) => Some(enabled_of(
                        def,
                        r,
                        params,
                        list,
                        enabled,
                        &mut *rng,
                        &model.strings,
                        doc_order,
                    )),
                    _ => None,
                };
                (stopped, choice)
            };
            match stopped {
                Err((pc, e)) => return Err(self.diag_error(m, pc.map(|p| p as usize), e)),
                Ok(Stopped::Idle) => continue,
                Ok(Stopped::Eventless(_)) => {
                    let Some(choice) = choice else { continue };
                    match self.pick_enabled(m, choice, rng, cfg)? {
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
                Ok(Stopped::Send(pc, sd)) => {
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
