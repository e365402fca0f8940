//! Compiles a [`ModelSource`] once into flat tables: interned events, machine and state
//! indices, typed variable slots and per-machine bytecode whose expressions are closures.
//!
//! Semantics fixed here (SCAN's, see the module docs of [`crate::sim`]):
//! a state's code is its `<onentry>` followed by a check of its eventless
//! transitions; a transition's code is the source state's `<onexit>`, the
//! transition's content, then entry into the target. Event parameters are
//! typed per event (every `<send>` of an event must agree; ints widen to
//! floats), from `<!-- TYPE -->` annotations or inferred from the sent
//! expression. A transition on an event nobody sends is dropped with a warning.

use super::ids::{EventId, MachineId, StateId};
use crate::expr::compile::{
    compile, compile_as, compile_cell, compile_place, unknown_param_type, BoolFn, CellFn, Code,
    CompileError, EventScope, FloatFn, IntFn, Place, Scope, StrFn, Typed,
};
use crate::expr::parse_expr;
use crate::expr::value::{Cell, StrId, Strings, StructDef, Ty, TypeTable};
use crate::model::ast::{Delay, Exec, Machine, SendTarget, SrcExpr};
use crate::model::source::unescaped_offset;
use crate::model::types::{TypeDef, TypeExpr};
use crate::model::{Diagnostic, Diagnostics, FileId, ModelSource, SourceMap, Span};
use std::collections::{BTreeMap, BTreeSet, HashMap};
use std::path::{Path, PathBuf};

mod events;
mod machine;
#[cfg(test)]
mod tests;

use machine::MachineCompiler;

/// Where a `<send>` delivers.
pub(crate) enum SendTo {
    /// One machine.
    Machine(u32),
    /// The `NONE` sink: observed, never delivered.
    Sink,
    /// `targetexpr`: a string naming a machine (or `NONE`).
    Expr(StrFn),
    /// No target: every machine with a transition on the event, in machine order.
    Broadcast(Vec<u32>),
}

pub(crate) enum DelayDef {
    Const(u64),
    /// `delayexpr="f"`, `at` the file offset of its text (where a negative delay is told).
    Expr {
        f: IntFn,
        at: u32,
    },
    /// `delayexpr="f + 'ms'"`: `f` counts `ns` nanoseconds, in a model whose unit is
    /// `unit` nanoseconds.
    Scaled {
        f: IntFn,
        ns: u64,
        unit: u64,
        at: u32,
    },
    /// `delayexpr="f + 's'"` with a float `f` (`0.5 + 's'`): as [`DelayDef::Scaled`].
    ScaledFloat {
        f: FloatFn,
        ns: u64,
        unit: u64,
        at: u32,
    },
}

pub(crate) struct SendDef {
    pub event: u32,
    pub to: SendTo,
    pub delay: Option<DelayDef>,
    /// `(parameter index, value)` for each `<param>`.
    pub params: Vec<(u32, CellFn)>,
    /// Parameter indices this send leaves at their default.
    pub missing: Vec<u32>,
    /// One of a run of identical sends, one to each receiver of the event, after the
    /// first: AS2FM's plain export writes its one broadcast send this way, so
    /// [`super::EventSemantics::As2fm`] skips these copies.
    pub expanded_copy: bool,
}

/// One instruction of a machine's code.
pub(crate) enum Instr {
    /// `x = e` for a whole variable; the bound of a bounded array.
    AssignVar {
        slot: u32,
        value: Code,
        bound: Option<u32>,
        /// The instruction's own scratch cell (arrays and structs are built there).
        scratch: u32,
    },
    /// `a[i] = e`, `s.f = e`, ...
    AssignPlace {
        place: Place,
        value: Code,
        scratch: u32,
    },
    /// Jump to `else_pc` when `cond` is false.
    If {
        cond: BoolFn,
        else_pc: u32,
    },
    Jump(u32),
    Send(Box<SendDef>),
    Raise(u32),
    Log {
        label: Box<str>,
        value: Option<CellFn>,
        scratch: u32,
    },
    /// Enter a state: run its entry code.
    Goto(u32),
    /// End of entry code: take the first enabled eventless transition or wait.
    CheckEventless,
}

pub(crate) struct TransDef {
    pub cond: Option<BoolFn>,
    /// The condition may draw random numbers (`Math.random()`): evaluating it twice
    /// is not the same as evaluating it once.
    pub cond_draws: bool,
    /// Start of the transition's code.
    pub pc: u32,
}

pub(crate) struct StateDef {
    pub name: String,
    /// The state's tag.
    pub span: Span,
    /// Start of the entry code.
    pub entry: u32,
    /// Eventless transitions, document order.
    pub eventless: Vec<u32>,
    /// `(event, start, end)` ranges into the machine's `dispatch`, sorted by event.
    pub on_event: Vec<(u32, u32, u32)>,
    /// Entering the state runs no code and it has no eventless transition: a machine
    /// that enters it is idle at once.
    pub idle_on_entry: bool,
}

impl StateDef {
    /// Transitions on `event`, in document order.
    #[inline]
    pub(crate) fn transitions<'a>(&self, event: u32, dispatch: &'a [u32]) -> &'a [u32] {
        // A state handles few events: a scan of a short list costs less than a search.
        let found = if self.on_event.len() <= 8 {
            self.on_event
                .iter()
                .position(|&(e, _, _)| e == event)
                .ok_or(0)
        } else {
            self.on_event.binary_search_by_key(&event, |&(e, _, _)| e)
        };
        match found {
            Ok(i) => {
                let (_, s, e) = self.on_event[i];
                dispatch.get(s as usize..e as usize).unwrap_or(&[])
            }
            Err(_) => &[],
        }
    }
}

pub(crate) struct MachineDef {
    pub name: String,
    pub name_str: StrId,
    pub file: FileId,
    pub vars: Vec<(String, Ty)>,
    pub defaults: Vec<Cell>,
    /// `(slot, initial value, bound, span, scratch cell)` in document order.
    pub init: Vec<(u32, CellFn, Option<u32>, Span, u32)>,
    /// Number of scratch cells the machine's instructions use.
    pub n_scratch: u32,
    pub states: Vec<StateDef>,
    pub initial: u32,
    pub trans: Vec<TransDef>,
    pub dispatch: Vec<u32>,
    pub code: Vec<Instr>,
    /// Span of the element each instruction comes from.
    pub code_spans: Vec<Span>,
}

pub(crate) struct EventDef {
    pub name: String,
    pub name_str: StrId,
    pub params: Vec<(String, Ty)>,
    pub defaults: Vec<Cell>,
    pub receivers: Vec<u32>,
}

/// A model compiled for simulation: flat tables plus the names needed to read runs.
///
/// Build it once with [`CompiledModel::compile`] (or [`CompiledModel::load`]);
/// it is immutable, `Send + Sync`, and shared by any number of
/// [`super::Simulator`]s (one per thread).
pub struct CompiledModel {
    pub(crate) sources: SourceMap,
    pub(crate) strings: Strings,
    pub(crate) types: TypeTable,
    pub(crate) machines: Vec<MachineDef>,
    pub(crate) events: Vec<EventDef>,
    /// Machine index by [`StrId`] of its name (`u32::MAX`: no machine).
    pub(crate) machine_of_str: Vec<u32>,
    pub(crate) none_str: StrId,
    pub(crate) warnings: Vec<Diagnostic>,
    pub(crate) properties: Option<PathBuf>,
    /// The length of one model time unit in nanoseconds, when the model has one
    /// ([`crate::model::ModelSource::time_unit_ns`]).
    pub(crate) time_unit_ns: Option<u64>,
}

impl std::fmt::Debug for CompiledModel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("CompiledModel")
            .field("machines", &self.machines.len())
            .field("events", &self.events.len())
            .field("strings", &self.strings.len())
            .finish()
    }
}

impl CompiledModel {
    /// Reads ([`crate::model::load`]) and compiles a model folder or `model.xml`.
    pub fn load(path: &Path) -> Result<CompiledModel, Diagnostics> {
        CompiledModel::compile(crate::model::load(path)?)
    }

    /// Type-checks and compiles every machine; all errors are returned together.
    pub fn compile(src: ModelSource) -> Result<CompiledModel, Diagnostics> {
        Builder::new(&src).build(src.sources.clone(), src.properties.clone())
    }

    /// Number of machines.
    pub fn machine_count(&self) -> usize {
        self.machines.len()
    }

    /// A machine's name (`""` for an unknown id).
    pub fn machine_name(&self, m: MachineId) -> &str {
        self.machines.get(m.0 as usize).map_or("", |d| &d.name)
    }

    /// The machine with this name.
    pub fn machine_id(&self, name: &str) -> Option<MachineId> {
        let s = self.strings.lookup(name)?;
        match self.machine_of_str.get(s.0 as usize) {
            Some(&i) if i != u32::MAX => Some(MachineId(i)),
            _ => None,
        }
    }

    /// Number of states of a machine.
    pub fn state_count(&self, m: MachineId) -> usize {
        self.machines
            .get(m.0 as usize)
            .map_or(0, |d| d.states.len())
    }

    /// A state's id (`""` for unknown ids).
    pub fn state_name(&self, m: MachineId, s: StateId) -> &str {
        self.machines
            .get(m.0 as usize)
            .and_then(|d| d.states.get(s.0 as usize))
            .map_or("", |s| &s.name)
    }

    /// Number of events.
    pub fn event_count(&self) -> usize {
        self.events.len()
    }

    /// An event's name (`""` for an unknown id).
    pub fn event_name(&self, e: EventId) -> &str {
        self.events.get(e.0 as usize).map_or("", |d| &d.name)
    }

    /// The event with this name.
    pub fn event_id(&self, name: &str) -> Option<EventId> {
        self.events
            .iter()
            .position(|e| e.name == name)
            .map(|i| EventId(i as u32))
    }

    /// An event's parameters `(name, type)`, in [`super::SentMessage::param`] order
    /// (sorted by name).
    pub fn event_params(&self, e: EventId) -> &[(String, Ty)] {
        self.events.get(e.0 as usize).map_or(&[], |d| &d.params)
    }

    /// Index of parameter `name` of event `e`.
    pub fn param_index(&self, e: EventId, name: &str) -> Option<usize> {
        self.event_params(e).iter().position(|(n, _)| n == name)
    }

    /// Where a property reads a message value: parameter `name` of event `e` (its index,
    /// no fields), or a field of a struct parameter, written `param.field.sub` or, as
    /// AS2FM's translation flattens structs, `param__field__sub` (the parameter's index and
    /// the field indices on the way). Fields inside arrays are not reachable this way.
    pub fn param_path(&self, e: EventId, name: &str) -> Option<(usize, Vec<u32>)> {
        if let Some(i) = self.param_index(e, name) {
            return Some((i, Vec::new()));
        }
        for (i, (pname, ty)) in self.event_params(e).iter().enumerate() {
            let Some(rest) = name.strip_prefix(pname.as_str()).and_then(strip_sep) else {
                continue;
            };
            let mut path = Vec::new();
            if self.field_path(ty, rest, &mut path, 0) {
                return Some((i, path));
            }
        }
        None
    }

    /// Appends to `path` the fields that `rest` names inside `ty`; false when it names none.
    fn field_path(&self, ty: &Ty, rest: &str, path: &mut Vec<u32>, depth: usize) -> bool {
        let Ty::Struct(s) = ty else {
            return false;
        };
        let Some(def) = self.types.structs.get(*s as usize) else {
            return false;
        };
        if depth > 64 {
            return false;
        }
        for (fi, (fname, fty)) in def.fields.iter().enumerate() {
            let Some(after) = rest.strip_prefix(fname.as_str()) else {
                continue;
            };
            path.push(fi as u32);
            if after.is_empty() {
                return true;
            }
            if let Some(sub) = strip_sep(after) {
                if self.field_path(fty, sub, path, depth + 1) {
                    return true;
                }
            }
            path.pop();
        }
        false
    }

    /// Machines with a transition on event `e`.
    pub fn event_receivers(&self, e: EventId) -> impl Iterator<Item = MachineId> + '_ {
        self.events
            .get(e.0 as usize)
            .into_iter()
            .flat_map(|d| d.receivers.iter().map(|&m| MachineId(m)))
    }

    /// The model's string table (every string value is one of these).
    pub fn strings(&self) -> &Strings {
        &self.strings
    }

    /// Struct definitions and enumeration labels.
    pub fn types(&self) -> &TypeTable {
        &self.types
    }

    /// Every file read, for turning spans into file/line/column.
    pub fn sources(&self) -> &SourceMap {
        &self.sources
    }

    /// Non-fatal findings (e.g. transitions on events that are never sent).
    pub fn warnings(&self) -> &[Diagnostic] {
        &self.warnings
    }

    /// The properties file named by the model (`model.xml`) or found in its folder.
    pub fn properties_path(&self) -> Option<&Path> {
        self.properties.as_deref()
    }

    /// The length of one model time unit in nanoseconds, when the model has one (a robot
    /// model's, or a plain model's `--time-unit`).
    pub fn time_unit_ns(&self) -> Option<u64> {
        self.time_unit_ns
    }

    /// Total number of instructions, states and transitions (a size measure for reports).
    pub fn size(&self) -> (usize, usize, usize) {
        self.machines.iter().fold((0, 0, 0), |(c, s, t), m| {
            (c + m.code.len(), s + m.states.len(), t + m.trans.len())
        })
    }
}

/// Per event: its name and `(parameter, type if known)` list.
type EventParams = Vec<(String, Vec<(String, Option<Ty>)>)>;

struct EventB {
    name: String,
    params: BTreeMap<String, Option<Ty>>,
    senders: BTreeSet<u32>,
    receivers: BTreeSet<u32>,
}

struct Builder<'s> {
    src: &'s ModelSource,
    errs: Vec<Diagnostic>,
    warnings: Vec<Diagnostic>,
    strings: Strings,
    types: TypeTable,
    machine_index: HashMap<&'s str, u32>,
    vars: Vec<Vec<(String, Ty)>>,
    events: Vec<EventB>,
    event_index: HashMap<String, u32>,
    /// Variables whose declaration was reported as an error: (machine, name). Their uses
    /// are not reported again as unknown variables.
    failed_vars: BTreeSet<(u32, String)>,
    /// The errors a read of a parameter whose type was reported unknown would repeat.
    failed_params: BTreeSet<String>,
}

/// Where a send sits: its machine and the event in scope.
struct Site<'s> {
    machine: u32,
    event: Option<u32>,
    send: &'s crate::model::ast::Send,
}

impl<'s> Builder<'s> {
    fn new(src: &'s ModelSource) -> Self {
        Builder {
            src,
            errs: Vec::new(),
            warnings: Vec::new(),
            strings: Strings::default(),
            types: TypeTable::default(),
            machine_index: HashMap::new(),
            vars: Vec::new(),
            events: Vec::new(),
            event_index: HashMap::new(),
            failed_vars: BTreeSet::new(),
            failed_params: BTreeSet::new(),
        }
    }

    fn err(&mut self, span: Span, msg: impl Into<String>) {
        let d = self.src.sources.diag(span, msg);
        self.errs.push(d);
    }

    /// Reports an expression's compile error in `machine`, unless it only repeats one
    /// already reported: a use of a variable whose declaration failed, or a read of a
    /// parameter whose type was reported as unknown where it is sent.
    fn expr_err(&mut self, machine: u32, src: &SrcExpr, e: &CompileError) {
        let echo = if e.deferred {
            self.failed_params.contains(&e.msg)
        } else {
            e.unknown_variable
                .as_ref()
                .is_some_and(|name| self.failed_vars.contains(&(machine, name.clone())))
        };
        if !echo {
            let d = self.expr_diag(src, e);
            self.errs.push(d);
        }
    }

    fn build(
        mut self,
        sources: SourceMap,
        properties: Option<PathBuf>,
    ) -> Result<CompiledModel, Diagnostics> {
        self.build_types();
        for (i, m) in self.src.machines.iter().enumerate() {
            self.machine_index.insert(m.name.name.as_str(), i as u32);
            self.strings.intern(&m.name.name);
        }
        let none_str = self.strings.intern("NONE");
        for i in 0..self.src.machines.len() {
            let vars = self.build_vars(i);
            self.vars.push(vars);
        }
        self.collect_events();
        self.prefix_warnings();
        self.infer_params();
        let events: EventParams = self
            .events
            .iter()
            .map(|e| {
                (
                    e.name.clone(),
                    e.params
                        .iter()
                        .map(|(n, t)| (n.clone(), t.clone()))
                        .collect(),
                )
            })
            .collect();
        let mut machines = Vec::new();
        for i in 0..self.src.machines.len() {
            let m = MachineCompiler::new(&mut self, i as u32, &events).run();
            machines.push(m);
        }
        let event_defs: Vec<EventDef> = self
            .events
            .iter()
            .map(|e| {
                let params: Vec<(String, Ty)> = e
                    .params
                    .iter()
                    .map(|(n, t)| (n.clone(), t.clone().unwrap_or(Ty::Int)))
                    .collect();
                EventDef {
                    name_str: self.strings.lookup(&e.name).unwrap_or_default(),
                    defaults: params
                        .iter()
                        .map(|(_, t)| self.types.default_cell(t))
                        .collect(),
                    params,
                    name: e.name.clone(),
                    receivers: e.receivers.iter().copied().collect(),
                }
            })
            .collect();
        if !self.errs.is_empty() {
            // A node model lowered into several machines (an action server and its
            // threads) repeats its errors at the same place: say each once.
            let mut seen = BTreeSet::new();
            let mut errs = self.errs;
            errs.retain(|d| seen.insert((d.file.clone(), d.line, d.col, d.message.clone())));
            return Err(Diagnostics::from(errs));
        }
        let mut machine_of_str = vec![u32::MAX; self.strings.len()];
        for (i, m) in machines.iter().enumerate() {
            if let Some(slot) = machine_of_str.get_mut(m.name_str.0 as usize) {
                *slot = i as u32;
            }
        }
        let time_unit_ns = self.src.time_unit_ns;
        Ok(CompiledModel {
            time_unit_ns,
            sources,
            strings: self.strings,
            types: self.types,
            machines,
            events: event_defs,
            machine_of_str,
            none_str,
            warnings: self.warnings,
            properties,
        })
    }

    fn build_types(&mut self) {
        let mut next_label = 0i64;
        // Names first, so that a struct may name a type declared after it.
        let mut structs = Vec::new();
        for (name, def, span) in &self.src.types.defs {
            match def {
                TypeDef::Enumeration { labels } => {
                    for l in labels {
                        if !self.types.labels.contains_key(l) {
                            self.types.labels.insert(l.clone(), next_label);
                            next_label += 1;
                        }
                    }
                    self.types.named.insert(name.clone(), Ty::Int);
                }
                TypeDef::Struct { fields } => {
                    let idx = self.types.structs.len() as u32;
                    self.types.structs.push(StructDef {
                        name: name.clone(),
                        fields: Vec::new(),
                    });
                    self.types.named.insert(name.clone(), Ty::Struct(idx));
                    structs.push((idx, fields, *span));
                }
            }
        }
        for (idx, fields, span) in structs {
            let mut fs = Vec::new();
            for (f, te) in fields {
                if let Some(t) = self.resolve(te, span) {
                    fs.push((f.clone(), t));
                }
            }
            if let Some(d) = self.types.structs.get_mut(idx as usize) {
                d.fields = fs;
            }
        }
        // A struct that contains itself (not through an array) has no finite value.
        let n = self.types.structs.len();
        for start in 0..n {
            let mut seen = vec![false; n];
            let mut stack = vec![start];
            let mut cyclic = false;
            while let Some(i) = stack.pop() {
                for (_, t) in &self.types.structs[i].fields {
                    if let Ty::Struct(j) = t {
                        let j = *j as usize;
                        if j == start {
                            cyclic = true;
                        } else if j < n && !seen[j] {
                            seen[j] = true;
                            stack.push(j);
                        }
                    }
                }
            }
            if cyclic {
                let name = self.types.structs[start].name.clone();
                let span = self
                    .src
                    .types
                    .defs
                    .iter()
                    .find(|(n, _, _)| *n == name)
                    .map(|(_, _, s)| *s);
                if let Some(span) = span {
                    self.err(
                        span,
                        format!("struct `{name}` contains itself (only an array of it may)"),
                    );
                }
                // Break the cycle so that default values stay finite.
                for (_, t) in &mut self.types.structs[start].fields {
                    if matches!(t, Ty::Struct(_)) {
                        *t = Ty::Int;
                    }
                }
            }
        }
    }

    /// `; declared: A, B` (the declared type names), or nothing when there are none.
    fn known_types(&self) -> String {
        let names: Vec<&str> = self
            .src
            .types
            .defs
            .iter()
            .map(|(n, _, _)| n.as_str())
            .collect();
        if names.is_empty() {
            String::new()
        } else {
            format!("; declared: {}", names.join(", "))
        }
    }

    fn resolve(&mut self, te: &TypeExpr, span: Span) -> Option<Ty> {
        match te {
            TypeExpr::Base(b) => Some(match b {
                crate::model::BaseType::Bool => Ty::Bool,
                crate::model::BaseType::Int => Ty::Int,
                crate::model::BaseType::Float => Ty::Float,
                crate::model::BaseType::Str => Ty::Str,
            }),
            TypeExpr::Named(n) => match self.types.named.get(n) {
                Some(t) => Some(t.clone()),
                None => {
                    self.err(
                        span,
                        format!(
                            "unknown type `{n}` (not a base type nor declared in types.xml or the data declarations{})",
                            self.known_types()
                        ),
                    );
                    None
                }
            },
            TypeExpr::Array(t, b) => Some(Ty::Array(Box::new(self.resolve(t, span)?), *b)),
        }
    }

    fn expr_diag(&self, src: &SrcExpr, e: &CompileError) -> Diagnostic {
        self.src.sources.diag(
            unescaped_offset(&self.src.sources, src.span, e.at),
            e.msg.clone(),
        )
    }

    fn build_vars(&mut self, mi: usize) -> Vec<(String, Ty)> {
        let m: &Machine = &self.src.machines[mi];
        let mut vars: Vec<(String, Ty)> = Vec::new();
        for d in &m.datamodel {
            if vars.iter().any(|(n, _)| *n == d.id.name) {
                self.err(
                    d.id.span,
                    format!("variable `{}` is declared twice", d.id.name),
                );
                continue;
            }
            let declared = match &d.ty {
                Some(ann) => match self.resolve(&ann.ty, ann.span) {
                    Some(t) => Some(t),
                    None => {
                        self.failed_vars.insert((mi as u32, d.id.name.clone()));
                        continue;
                    }
                },
                None => None,
            };
            let ty = match (declared, &d.expr) {
                (Some(t), _) => t,
                (None, None) => {
                    self.err(
                        d.span,
                        format!(
                            "variable `{}` has no type and no value: give it a type (`type=\"int32\"`, or `<!-- TYPE {}:int32 -->` before it)",
                            d.id.name, d.id.name
                        ),
                    );
                    self.failed_vars.insert((mi as u32, d.id.name.clone()));
                    continue;
                }
                (None, Some(src)) => {
                    let ast = match parse_expr(&src.text) {
                        Ok(a) => a,
                        Err(pe) => {
                            let at = unescaped_offset(&self.src.sources, src.span, pe.offset);
                            self.err(at, pe.message);
                            self.failed_vars.insert((mi as u32, d.id.name.clone()));
                            continue;
                        }
                    };
                    let sources = &self.src.sources;
                    let span = src.span;
                    let abs = move |k: u32| unescaped_offset(sources, span, k).lo;
                    let scope = Scope {
                        vars: &vars,
                        event: EventScope::None,
                        types: &self.types,
                        abs: &abs,
                    };
                    match compile(&ast, &scope, &mut self.strings, None) {
                        Ok(t) if !contains_unknown(&t.ty) => t.ty,
                        Ok(_) => {
                            self.err(
                                d.span,
                                format!(
                                    "cannot infer the element type of `{}` from its value: give it a type (`type=\"int32[]\"`, or `<!-- TYPE {}:int32[] -->` before it)",
                                    d.id.name, d.id.name
                                ),
                            );
                            self.failed_vars.insert((mi as u32, d.id.name.clone()));
                            continue;
                        }
                        Err(e) => {
                            let diag = self.expr_diag(src, &e);
                            self.errs.push(diag);
                            self.failed_vars.insert((mi as u32, d.id.name.clone()));
                            continue;
                        }
                    }
                }
            };
            vars.push((d.id.name.clone(), ty));
        }
        vars
    }
}

/// The text after a leading field separator (`.` or `__`), if there is one.
fn strip_sep(s: &str) -> Option<&str> {
    s.strip_prefix('.')
        .or_else(|| s.strip_prefix("__"))
        .filter(|r| !r.is_empty())
}

fn contains_unknown(t: &Ty) -> bool {
    match t {
        Ty::Unknown => true,
        Ty::Array(e, _) => contains_unknown(e),
        _ => false,
    }
}

/// Visits every executable element, depth first, in document order.
fn walk<'a>(execs: &'a [Exec], f: &mut dyn FnMut(&'a Exec)) {
    for x in execs {
        f(x);
        if let Exec::If {
            branches,
            otherwise,
            ..
        } = x
        {
            for (_, b) in branches {
                walk(b, f);
            }
            walk(otherwise, f);
        }
    }
}
