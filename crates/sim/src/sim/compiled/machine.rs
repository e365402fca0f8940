//! One machine's executable content compiled to flat instructions with closures, and its listing.

use super::*;
use crate::expr::ast::Expr;

pub(super) struct MachineCompiler<'b, 's> {
    b: &'b mut Builder<'s>,
    mi: u32,
    events: &'b EventParams,
    code: Vec<Instr>,
    spans: Vec<Span>,
    n_scratch: u32,
}

impl<'b, 's> MachineCompiler<'b, 's> {
    pub(super) fn new(b: &'b mut Builder<'s>, mi: u32, events: &'b EventParams) -> Self {
        MachineCompiler {
            b,
            mi,
            events,
            code: Vec::new(),
            spans: Vec::new(),
            n_scratch: 0,
        }
    }

    fn new_scratch(&mut self) -> u32 {
        self.n_scratch += 1;
        self.n_scratch - 1
    }

    fn emit(&mut self, i: Instr, span: Span) -> u32 {
        self.code.push(i);
        self.spans.push(span);
        self.code.len() as u32 - 1
    }

    /// Parses `src` and hands its syntax tree to `compile` in the scope of this machine
    /// and `event`; a parse or compile error is reported at its file position.
    fn scoped<T>(
        &mut self,
        src: &SrcExpr,
        event: Option<u32>,
        compile: impl FnOnce(&Expr, &Scope<'_>, &mut Strings) -> Result<T, CompileError>,
    ) -> Option<T> {
        let ast = match parse_expr(&src.text) {
            Ok(a) => a,
            Err(pe) => {
                let at = unescaped_offset(&self.b.src.sources, src.span, pe.offset);
                self.b.err(at, pe.message);
                return None;
            }
        };
        let r = {
            let sources = &self.b.src.sources;
            let span = src.span;
            let abs = move |k: u32| unescaped_offset(sources, span, k).lo;
            let scope = Scope {
                vars: &self.b.vars[self.mi as usize],
                event: match event {
                    Some(e) => EventScope::Event {
                        name: &self.events[e as usize].0,
                        params: &self.events[e as usize].1,
                    },
                    None => EventScope::None,
                },
                types: &self.b.types,
                abs: &abs,
            };
            compile(&ast, &scope, &mut self.b.strings)
        };
        match r {
            Ok(t) => Some(t),
            Err(e) => {
                self.b.expr_err(self.mi, src, &e);
                None
            }
        }
    }

    /// Parses and compiles `src` in the scope of this machine and `event`.
    fn typed(&mut self, src: &SrcExpr, event: Option<u32>, expect: Option<&Ty>) -> Option<Typed> {
        self.scoped(src, event, |ast, scope, strings| match expect {
            Some(t) => compile_as(ast, scope, strings, t, "the expression"),
            None => compile(ast, scope, strings, None),
        })
    }

    fn bool_code(&mut self, src: &SrcExpr, event: Option<u32>) -> Option<BoolFn> {
        match self.typed(src, event, Some(&Ty::Bool))?.code {
            Code::Bool(f) => Some(f),
            _ => None,
        }
    }

    fn place(&mut self, src: &SrcExpr, event: Option<u32>) -> Option<Place> {
        self.scoped(src, event, compile_place)
    }

    fn block(&mut self, execs: &[Exec], event: Option<u32>) {
        for (i, x) in execs.iter().enumerate() {
            let before = self.code.len();
            self.exec(x, event);
            if self.code.len() > before && self.expanded_copy(execs, i) {
                if let Some(Instr::Send(sd)) = self.code.last_mut() {
                    sd.expanded_copy = true;
                }
            }
        }
    }

    /// Whether `execs[i]` is a send that repeats the one before it for another target,
    /// in a run whose targets are exactly the event's receivers (AS2FM's expansion of a
    /// broadcast send for SCAN).
    fn expanded_copy(&self, execs: &[Exec], i: usize) -> bool {
        let as_send = |k: usize| match execs.get(k) {
            Some(Exec::Send(s)) if s.delay.is_none() => Some(s),
            _ => None,
        };
        let same = |a: &crate::model::ast::Send, b: &crate::model::ast::Send| {
            a.event.name == b.event.name
                && a.params.len() == b.params.len()
                && a.params
                    .iter()
                    .zip(&b.params)
                    .all(|(p, q)| p.name.name == q.name.name && p.expr.text == q.expr.text)
        };
        let (Some(cur), Some(prev)) = (as_send(i), i.checked_sub(1).and_then(as_send)) else {
            return false;
        };
        if !same(cur, prev) {
            return false;
        }
        let mut start = i - 1;
        while start > 0 && as_send(start - 1).is_some_and(|s| same(s, cur)) {
            start -= 1;
        }
        let mut end = i;
        while as_send(end + 1).is_some_and(|s| same(s, cur)) {
            end += 1;
        }
        let Some(&ev) = self.b.event_index.get(&cur.event.name) else {
            return false;
        };
        let mut targets = BTreeSet::new();
        for k in start..=end {
            let Some(SendTarget::Id(t)) = as_send(k).and_then(|s| s.target.as_ref()) else {
                return false;
            };
            let Some(m) = self
                .b
                .src
                .machines
                .iter()
                .position(|m| m.name.name == t.name)
            else {
                return false;
            };
            if !targets.insert(m as u32) {
                return false;
            }
        }
        targets == self.b.events[ev as usize].receivers
    }

    fn exec(&mut self, x: &Exec, event: Option<u32>) {
        match x {
            Exec::Assign {
                location,
                expr,
                span,
            } => {
                let Some(place) = self.place(location, event) else {
                    return;
                };
                let ty = place.ty.clone();
                let Some(value) = self.typed(expr, event, Some(&ty)) else {
                    return;
                };
                let value = value.code;
                let scratch = self.new_scratch();
                if place.is_whole_var() {
                    let (slot, bound) = (place.var, place.bound);
                    self.emit(
                        Instr::AssignVar {
                            slot,
                            value,
                            bound,
                            scratch,
                        },
                        *span,
                    );
                } else {
                    self.emit(
                        Instr::AssignPlace {
                            place,
                            value,
                            scratch,
                        },
                        *span,
                    );
                }
            }
            Exec::If {
                branches,
                otherwise,
                span,
            } => {
                let mut to_end = Vec::new();
                for (k, (cond, body)) in branches.iter().enumerate() {
                    let c = self.bool_code(cond, event);
                    let at = self.emit(
                        Instr::If {
                            cond: c.unwrap_or_else(|| Box::new(|_| Ok(false))),
                            else_pc: 0,
                        },
                        *span,
                    );
                    self.block(body, event);
                    // The last branch of an `<if>` without `<else>` ends where the
                    // `<if>` does: no jump needed.
                    if k + 1 < branches.len() || !otherwise.is_empty() {
                        to_end.push(self.emit(Instr::Jump(0), *span));
                    }
                    let here = self.code.len() as u32;
                    if let Some(Instr::If { else_pc, .. }) = self.code.get_mut(at as usize) {
                        *else_pc = here;
                    }
                }
                self.block(otherwise, event);
                let end = self.code.len() as u32;
                for j in to_end {
                    if let Some(Instr::Jump(t)) = self.code.get_mut(j as usize) {
                        *t = end;
                    }
                }
            }
            Exec::Raise { event: ev, span } => {
                let id = self.b.event_index.get(&ev.name).copied().unwrap_or(0);
                self.emit(Instr::Raise(id), *span);
            }
            Exec::Log { label, expr, span } => {
                let value = match expr {
                    Some(e) => match self.typed(e, event, None) {
                        Some(t) => Some(t.into_cell_fn()),
                        None => return,
                    },
                    None => None,
                };
                let label = label.clone().unwrap_or_default().into_boxed_str();
                let scratch = self.new_scratch();
                self.emit(
                    Instr::Log {
                        label,
                        value,
                        scratch,
                    },
                    *span,
                );
            }
            Exec::Send(s) => {
                let Some(&ev) = self.b.event_index.get(&s.event.name) else {
                    return;
                };
                let to = match &s.target {
                    Some(SendTarget::Id(t)) => match self.b.machine_index.get(t.name.as_str()) {
                        Some(&m) => SendTo::Machine(m),
                        None if t.name == "NONE" => SendTo::Sink,
                        None if t.name.starts_with("#_") => {
                            // W3C's special targets (`#_internal`, `#_parent`,
                            // `#_scxml_<id>`, `#_<invokeid>`): SCAN's sends name a machine.
                            self.b.err(
                                t.span,
                                format!(
                                    "W3C SCXML's special target `{}` is not supported: a send \
                                     names a machine (this machine's own name sends to its \
                                     external queue; <raise> queues an internal event)",
                                    t.name
                                ),
                            );
                            return;
                        }
                        None => {
                            self.b.err(
                                t.span,
                                format!(
                                    "unknown target machine `{}` (no machine has this name)",
                                    t.name
                                ),
                            );
                            return;
                        }
                    },
                    Some(SendTarget::Expr(e)) => match self.typed(e, event, Some(&Ty::Str)) {
                        Some(Typed {
                            code: Code::Str(f), ..
                        }) => SendTo::Expr(f),
                        _ => return,
                    },
                    None => SendTo::Broadcast(
                        self.b.events[ev as usize]
                            .receivers
                            .iter()
                            .copied()
                            .collect(),
                    ),
                };
                let unit = self.b.src.time_unit_ns;
                let delay = match &s.delay {
                    None | Some(Delay::Const(0, _)) => None,
                    Some(Delay::Const(n, _)) => Some(DelayDef::Const(*n)),
                    Some(Delay::Duration(ns, span)) => match unit {
                        Some(u) if ns % u == 0 => match ns / u {
                            0 => None,
                            n => Some(DelayDef::Const(n)),
                        },
                        Some(u) => {
                            self.b.err(
                                *span,
                                format!(
                                    "delay {} is not a whole number of model time units of {}",
                                    codegen::duration::format(*ns),
                                    codegen::duration::format(u)
                                ),
                            );
                            return;
                        }
                        None => {
                            self.b.err(
                                *span,
                                format!(
                                    "delay {} is a duration: {NO_UNIT}",
                                    codegen::duration::format(*ns)
                                ),
                            );
                            return;
                        }
                    },
                    Some(Delay::Expr(e)) => match self.typed(e, event, Some(&Ty::Int)) {
                        Some(Typed {
                            code: Code::Int(f), ..
                        }) => Some(DelayDef::Expr { f, at: e.span.lo }),
                        _ => return,
                    },
                    Some(Delay::ExprIn(e, ns)) => {
                        let Some(u) = unit else {
                            let suffix = codegen::duration::format(*ns);
                            self.b.err(
                                e.span,
                                format!(
                                    "a delay in `{}` is a duration: {NO_UNIT}",
                                    suffix.trim_start_matches('1')
                                ),
                            );
                            return;
                        };
                        let (ns, at) = (*ns, e.span.lo);
                        match self.typed(e, event, None) {
                            Some(Typed {
                                code: Code::Int(f), ..
                            }) => Some(DelayDef::Scaled { f, ns, unit: u, at }),
                            Some(Typed {
                                code: Code::Float(f),
                                ..
                            }) => Some(DelayDef::ScaledFloat { f, ns, unit: u, at }),
                            Some(_) => {
                                self.b.err(
                                    e.span,
                                    format!(
                                        "a delay in `{}` needs a number before its unit",
                                        codegen::duration::format(ns).trim_start_matches('1')
                                    ),
                                );
                                return;
                            }
                            None => return,
                        }
                    }
                };
                let pdefs = &self.events[ev as usize].1;
                let mut params = Vec::new();
                let mut given = vec![false; pdefs.len()];
                for p in &s.params {
                    let Some(pi) = pdefs.iter().position(|(n, _)| *n == p.name.name) else {
                        continue;
                    };
                    let Some(Some(pty)) = pdefs.get(pi).map(|(_, t)| t.clone()) else {
                        continue; // reported by inference
                    };
                    let f = self.scoped(&p.expr, event, |ast, scope, strings| {
                        compile_cell(ast, scope, strings, &pty, "the expression")
                    });
                    if let Some(f) = f {
                        params.push((pi as u32, f));
                        given[pi] = true;
                    }
                }
                let missing = given
                    .iter()
                    .enumerate()
                    .filter(|(_, g)| !**g)
                    .map(|(i, _)| i as u32)
                    .collect();
                self.emit(
                    Instr::Send(Box::new(SendDef {
                        event: ev,
                        to,
                        delay,
                        params,
                        missing,
                        expanded_copy: false,
                    })),
                    s.span,
                );
            }
        }
    }

    pub(super) fn run(mut self) -> MachineDef {
        let src = self.b.src;
        let m = &src.machines[self.mi as usize];
        let mi = self.mi;
        // States.
        let mut state_index: HashMap<&str, u32> = HashMap::new();
        for (i, s) in m.states.iter().enumerate() {
            if state_index.insert(s.id.name.as_str(), i as u32).is_some() {
                self.b.err(
                    s.id.span,
                    format!("state `{}` is declared twice", s.id.name),
                );
            }
        }
        let initial = match &m.initial {
            Some(id) => match state_index.get(id.name.as_str()) {
                Some(&i) => i,
                None => {
                    self.b
                        .err(id.span, format!("unknown initial state `{}`", id.name));
                    0
                }
            },
            None => 0,
        };
        let mut states: Vec<StateDef> = Vec::new();
        for s in &m.states {
            let entry = self.code.len() as u32;
            self.block(&s.onentry, None);
            self.emit(Instr::CheckEventless, s.span);
            states.push(StateDef {
                name: s.id.name.clone(),
                span: s.span,
                entry,
                eventless: Vec::new(),
                on_event: Vec::new(),
                idle_on_entry: false,
            });
        }
        let mut trans: Vec<TransDef> = Vec::new();
        let mut per_state: Vec<BTreeMap<u32, Vec<u32>>> = vec![BTreeMap::new(); m.states.len()];
        for (si, s) in m.states.iter().enumerate() {
            for t in &s.transitions {
                let target = match &t.target {
                    Some(id) => match state_index.get(id.name.as_str()) {
                        Some(&i) => Some(i),
                        None => {
                            self.b
                                .err(id.span, format!("unknown target state `{}`", id.name));
                            continue;
                        }
                    },
                    None => None,
                };
                let evs: Vec<Option<u32>> = if t.events.is_empty() {
                    vec![None]
                } else {
                    t.events
                        .iter()
                        .map(|e| self.b.event_index.get(&e.name).copied())
                        .collect()
                };
                for (k, ev) in evs.into_iter().enumerate() {
                    if let Some(e) = ev {
                        if self.b.events[e as usize].senders.is_empty() {
                            let name = &t.events[k];
                            let d = src.sources.diag(
                                name.span,
                                format!(
                                    "event `{}` is never sent: this transition of `{}` can never fire",
                                    name.name, m.name.name
                                ),
                            );
                            self.b.warnings.push(d);
                            continue;
                        }
                    }
                    let cond_draws = t.cond.as_ref().is_some_and(|c| c.text.contains("random"));
                    let cond = match &t.cond {
                        Some(c) => match self.bool_code(c, ev) {
                            Some(f) => Some(f),
                            None => continue,
                        },
                        None => None,
                    };
                    let pc = self.code.len() as u32;
                    // A transition without a target exits no state, so the state's
                    // <onexit> does not run (SCXML 1.0, section 3.13: a targetless
                    // transition's exit set is empty). SCAN and AS2FM require a target.
                    if target.is_some() {
                        self.block(&s.onexit, ev);
                    }
                    self.block(&t.body, ev);
                    match target {
                        Some(tg) => self.emit(Instr::Goto(tg), t.span),
                        None => self.emit(Instr::CheckEventless, t.span),
                    };
                    let id = trans.len() as u32;
                    trans.push(TransDef {
                        cond,
                        cond_draws,
                        pc,
                    });
                    match ev {
                        Some(e) => per_state[si].entry(e).or_default().push(id),
                        None => states[si].eventless.push(id),
                    }
                }
            }
        }
        let mut dispatch = Vec::new();
        for (si, map) in per_state.into_iter().enumerate() {
            for (e, ts) in map {
                let start = dispatch.len() as u32;
                dispatch.extend(ts);
                states[si].on_event.push((e, start, dispatch.len() as u32));
            }
        }
        for st in &mut states {
            st.idle_on_entry = st.eventless.is_empty()
                && matches!(
                    self.code.get(st.entry as usize),
                    Some(Instr::CheckEventless)
                );
        }
        thread_jumps(&mut self.code);
        // Datamodel initialisation.
        let vars = self.b.vars[mi as usize].clone();
        let defaults: Vec<Cell> = vars
            .iter()
            .map(|(_, t)| self.b.types.default_cell(t))
            .collect();
        let mut init = Vec::new();
        for d in &m.datamodel {
            let Some(slot) = vars.iter().position(|(n, _)| *n == d.id.name) else {
                continue;
            };
            let Some(e) = &d.expr else { continue };
            // Only earlier variables are visible in an initial value.
            let ty = vars[slot].1.clone();
            let saved = std::mem::take(&mut self.b.vars[mi as usize]);
            self.b.vars[mi as usize] = saved[..slot].to_vec();
            let t = self.typed(e, None, Some(&ty));
            self.b.vars[mi as usize] = saved;
            if let Some(t) = t {
                let bound = match &ty {
                    Ty::Array(_, b) => *b,
                    _ => None,
                };
                let scratch = self.new_scratch();
                init.push((slot as u32, t.into_cell_fn(), bound, d.span, scratch));
            }
        }
        MachineDef {
            name: m.name.name.clone(),
            name_str: self.b.strings.intern(&m.name.name),
            file: FileId::of(m.span),
            vars,
            defaults,
            init,
            states,
            initial,
            trans,
            dispatch,
            code: self.code,
            code_spans: self.spans,
            n_scratch: self.n_scratch,
        }
    }
}

/// Points every jump (and `<if>`'s else branch) that lands on a jump at that jump's final
/// target, so that no step goes through a chain of jumps.
fn thread_jumps(code: &mut [Instr]) {
    let last_of = |code: &[Instr], mut t: u32| {
        // A chain visits each instruction at most once (guards against a cycle).
        for _ in 0..code.len() {
            match code.get(t as usize) {
                Some(Instr::Jump(next)) if *next != t => t = *next,
                _ => break,
            }
        }
        t
    };
    for pc in 0..code.len() {
        let target = match &code[pc] {
            Instr::Jump(t) => *t,
            Instr::If { else_pc, .. } => *else_pc,
            _ => continue,
        };
        let last = last_of(code, target);
        match &mut code[pc] {
            Instr::Jump(t) => *t = last,
            Instr::If { else_pc, .. } => *else_pc = last,
            _ => {}
        }
    }
}

impl CompiledModel {
    /// A readable listing of a machine's compiled code (states, dispatch tables, instructions).
    pub fn dump_machine(&self, m: MachineId) -> String {
        use std::fmt::Write;
        let mut out = String::new();
        let Some(d) = self.machines.get(m.0 as usize) else {
            return out;
        };
        let _ = writeln!(out, "machine {} (initial {})", d.name, d.initial);
        for (i, (n, t)) in d.vars.iter().enumerate() {
            let _ = writeln!(out, "  var {i} {n}: {}", self.types.name(t));
        }
        for (i, s) in d.states.iter().enumerate() {
            let _ = write!(
                out,
                "  state {i} {} entry={} eventless={:?}",
                s.name, s.entry, s.eventless
            );
            for (e, a, b) in &s.on_event {
                let _ = write!(
                    out,
                    " on {}={:?}",
                    self.event_name(EventId(*e)),
                    d.dispatch.get(*a as usize..*b as usize).unwrap_or(&[])
                );
            }
            out.push('\n');
        }
        for (i, t) in d.trans.iter().enumerate() {
            let _ = writeln!(out, "  trans {i} pc={} cond={}", t.pc, t.cond.is_some());
        }
        for (pc, ins) in d.code.iter().enumerate() {
            let text = match ins {
                Instr::AssignVar { slot, .. } => format!("assign var {slot}"),
                Instr::AssignPlace { place, .. } => format!("assign into var {}", place.var),
                Instr::If { else_pc, .. } => format!("if false goto {else_pc}"),
                Instr::Jump(t) => format!("goto {t}"),
                Instr::Send(s) => {
                    let to = match &s.to {
                        SendTo::Machine(t) => self.machine_name(MachineId(*t)).to_string(),
                        SendTo::Sink => "NONE".into(),
                        SendTo::Expr(_) => "<targetexpr>".into(),
                        SendTo::Broadcast(v) => format!("all of {v:?}"),
                    };
                    format!("send {} to {to}", self.event_name(EventId(s.event)))
                }
                Instr::Raise(e) => format!("raise {}", self.event_name(EventId(*e))),
                Instr::Log { label, .. } => format!("log {label}"),
                Instr::Goto(s) => format!("enter state {s}"),
                Instr::CheckEventless => "check eventless".into(),
            };
            let _ = writeln!(out, "  {pc:4}: {text}");
        }
        out
    }
}

/// Why a delay written as a duration cannot be read without the model's time unit.
const NO_UNIT: &str = "it needs the model's time unit: give --time-unit (e.g. 100ms), or \
                       write the delay in model time units";
