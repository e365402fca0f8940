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
    compile, compile_as, compile_place, unknown_param_type, BoolFn, CellFn, Code, CompileError,
    EventScope, IntFn, Place, Scope, StrFn, Typed,
};
use crate::expr::parse_expr;
use crate::expr::value::{Cell, StrId, Strings, StructDef, Ty, TypeTable};
use crate::model::ast::{Delay, Exec, Machine, SendTarget, SrcExpr};
use crate::model::types::{TypeDef, TypeExpr};
use crate::model::{Diagnostic, Diagnostics, FileId, ModelSource, SourceMap, Span};
use std::collections::{BTreeMap, BTreeSet, HashMap};
use std::path::{Path, PathBuf};

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
    Expr(IntFn),
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
    pub fn transitions<'a>(&self, event: u32, dispatch: &'a [u32]) -> &'a [u32] {
        match self.on_event.binary_search_by_key(&event, |&(e, _, _)| e) {
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
    pub senders: Vec<u32>,
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

    /// All machine ids.
    pub fn machine_ids(&self) -> impl Iterator<Item = MachineId> {
        (0..self.machines.len() as u32).map(MachineId)
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

    /// A machine's datamodel variables `(name, type)`, by slot.
    pub fn machine_vars(&self, m: MachineId) -> &[(String, Ty)] {
        self.machines.get(m.0 as usize).map_or(&[], |d| &d.vars)
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

    /// Machines that send event `e` (`<send>` or `<raise>`).
    pub fn event_senders(&self, e: EventId) -> impl Iterator<Item = MachineId> + '_ {
        self.events
            .get(e.0 as usize)
            .into_iter()
            .flat_map(|d| d.senders.iter().map(|&m| MachineId(m)))
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

    /// The id of a string if the model contains it (a string the model never
    /// mentions can never be equal to a model value).
    pub fn str_id(&self, s: &str) -> Option<StrId> {
        self.strings.lookup(s)
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
                    senders: e.senders.iter().copied().collect(),
                    receivers: e.receivers.iter().copied().collect(),
                }
            })
            .collect();
        if !self.errs.is_empty() {
            // A node model lowered into several machines (an action server and its
            // threads) repeats its errors at the same place: say each once.
            let mut seen = BTreeSet::new();
            let mut errs = self.errs;
            errs.retain(|d| seen.insert((d.path.clone(), d.line, d.column, d.message.clone())));
            return Err(Diagnostics(errs));
        }
        let mut machine_of_str = vec![u32::MAX; self.strings.len()];
        for (i, m) in machines.iter().enumerate() {
            if let Some(slot) = machine_of_str.get_mut(m.name_str.0 as usize) {
                *slot = i as u32;
            }
        }
        Ok(CompiledModel {
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
            self.src.sources.unescaped_offset(src.span, e.at),
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
                            let at = self.src.sources.unescaped_offset(src.span, pe.offset);
                            self.err(at, pe.message);
                            self.failed_vars.insert((mi as u32, d.id.name.clone()));
                            continue;
                        }
                    };
                    let sources = &self.src.sources;
                    let span = src.span;
                    let abs = move |k: u32| sources.unescaped_offset(span, k).offset;
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

    fn event(&mut self, name: &str) -> u32 {
        if let Some(&i) = self.event_index.get(name) {
            return i;
        }
        let i = self.events.len() as u32;
        self.events.push(EventB {
            name: name.to_string(),
            params: BTreeMap::new(),
            senders: BTreeSet::new(),
            receivers: BTreeSet::new(),
        });
        self.event_index.insert(name.to_string(), i);
        self.strings.intern(name);
        i
    }

    fn collect_events(&mut self) {
        let src = self.src;
        for (mi, m) in src.machines.iter().enumerate() {
            let mi = mi as u32;
            for s in &m.states {
                for t in &s.transitions {
                    for e in &t.events {
                        let id = self.event(&e.name);
                        self.events[id as usize].receivers.insert(mi);
                    }
                }
            }
            let visit = |execs: &[Exec], b: &mut Builder<'_>| {
                walk(execs, &mut |x| match x {
                    Exec::Send(s) => {
                        let id = b.event(&s.event.name) as usize;
                        b.events[id].senders.insert(mi);
                        for p in &s.params {
                            b.events[id]
                                .params
                                .entry(p.name.name.clone())
                                .or_insert(None);
                        }
                    }
                    Exec::Raise { event, .. } => {
                        let id = b.event(&event.name) as usize;
                        b.events[id].senders.insert(mi);
                        b.events[id].receivers.insert(mi);
                    }
                    _ => {}
                });
            };
            for s in &m.states {
                visit(&s.onentry, self);
                visit(&s.onexit, self);
                for t in &s.transitions {
                    visit(&t.body, self);
                }
            }
        }
    }

    /// Every `<send>` with the event in scope where it is compiled.
    fn sites(&self) -> Vec<Site<'s>> {
        let src = self.src;
        let mut out = Vec::new();
        for (mi, m) in src.machines.iter().enumerate() {
            let mi = mi as u32;
            for s in &m.states {
                walk(&s.onentry, &mut |x| {
                    if let Exec::Send(send) = x {
                        out.push(Site {
                            machine: mi,
                            event: None,
                            send,
                        });
                    }
                });
                for t in &s.transitions {
                    let evs: Vec<Option<u32>> = if t.events.is_empty() {
                        vec![None]
                    } else {
                        t.events
                            .iter()
                            .map(|e| self.event_index.get(&e.name).copied())
                            .collect()
                    };
                    for ev in evs {
                        for block in [&s.onexit, &t.body] {
                            walk(block, &mut |x| {
                                if let Exec::Send(send) = x {
                                    out.push(Site {
                                        machine: mi,
                                        event: ev,
                                        send,
                                    });
                                }
                            });
                        }
                    }
                }
            }
        }
        out
    }

    /// Infers every event parameter's type from annotations and sent expressions (fixpoint).
    fn infer_params(&mut self) {
        let sites = self.sites();
        // Annotations first.
        for site in &sites {
            let Some(&ev) = self.event_index.get(&site.send.event.name) else {
                continue;
            };
            for p in &site.send.params {
                if let Some(ann) = &p.ty {
                    if let Some(t) = self.resolve(&ann.ty, ann.span) {
                        self.merge_param(ev, &p.name.name, t);
                    }
                }
            }
        }
        let mut parsed: Vec<Vec<Option<crate::expr::ast::Expr>>> = sites
            .iter()
            .map(|s| {
                s.send
                    .params
                    .iter()
                    .map(|p| parse_expr(&p.expr.text).ok())
                    .collect()
            })
            .collect();
        for _round in 0..64 {
            let mut changed = false;
            for (si, site) in sites.iter().enumerate() {
                let Some(&ev) = self.event_index.get(&site.send.event.name) else {
                    continue;
                };
                for (pi, p) in site.send.params.iter().enumerate() {
                    if p.ty.is_some() {
                        continue;
                    }
                    let Some(Some(ast)) = parsed.get(si).and_then(|v| v.get(pi)) else {
                        continue;
                    };
                    if let Ok(t) = self.compile_in_site(site, ast) {
                        changed |= self.merge_param(ev, &p.name.name, t.ty);
                    }
                }
            }
            if !changed {
                break;
            }
        }
        parsed.clear();
        // Report parameters whose type is still unknown, at their first send.
        let mut reported = BTreeSet::new();
        for site in &sites {
            let Some(&ev) = self.event_index.get(&site.send.event.name) else {
                continue;
            };
            for p in &site.send.params {
                let t = self.events[ev as usize]
                    .params
                    .get(&p.name.name)
                    .cloned()
                    .flatten();
                let bad = match &t {
                    None => true,
                    Some(t) => contains_unknown(t),
                };
                if bad && reported.insert((ev, p.name.name.clone())) {
                    // Why the type is unknown: a syntax error, an expression that does
                    // not compile (an unknown variable, say), or one whose type says
                    // nothing (`[]`). Reads of the parameter elsewhere would only echo it.
                    self.failed_params
                        .insert(unknown_param_type(&p.name.name, &site.send.event.name));
                    match parse_expr(&p.expr.text) {
                        Err(pe) => {
                            let at = self.src.sources.unescaped_offset(p.expr.span, pe.offset);
                            self.err(at, pe.message);
                        }
                        Ok(ast) => match self.compile_in_site(site, &ast) {
                            Err(e) => self.expr_err(site.machine, &p.expr, &e),
                            Ok(_) => {
                                let msg = format!(
                                    "cannot infer the type of parameter `{}` of event `{}` from its value: give the <param> a type (`type=\"int32\"`, or `<!-- TYPE {}:int32 -->` before it)",
                                    p.name.name, site.send.event.name, p.name.name
                                );
                                self.err(p.span, msg);
                            }
                        },
                    }
                }
            }
        }
    }

    /// Compiles a parameter expression of `site` in its machine's scope (the event's
    /// parameters as inferred so far), for the error it gives.
    fn compile_in_site(
        &mut self,
        site: &Site<'_>,
        ast: &crate::expr::ast::Expr,
    ) -> Result<Typed, CompileError> {
        let scope_params: Vec<(String, Option<Ty>)> = match site.event {
            Some(e) => self.events[e as usize]
                .params
                .iter()
                .map(|(n, t)| (n.clone(), t.clone()))
                .collect(),
            None => Vec::new(),
        };
        let ename = site.event.map(|e| self.events[e as usize].name.clone());
        let abs = |k: u32| k;
        let scope = Scope {
            vars: &self.vars[site.machine as usize],
            event: match &ename {
                Some(n) => EventScope::Event {
                    name: n,
                    params: &scope_params,
                },
                None => EventScope::None,
            },
            types: &self.types,
            abs: &abs,
        };
        compile(ast, &scope, &mut self.strings, None)
    }

    /// Merges a sent type into a parameter's type; true when it changed.
    fn merge_param(&mut self, ev: u32, name: &str, t: Ty) -> bool {
        let Some(slot) = self.events[ev as usize].params.get_mut(name) else {
            return false;
        };
        match slot {
            None => {
                *slot = Some(t);
                true
            }
            Some(u) => match crate::expr::compile::unify(u, &t) {
                Some(w) if w != *u => {
                    *u = w;
                    true
                }
                // Equal, or a conflict reported when the send is compiled.
                _ => false,
            },
        }
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

struct MachineCompiler<'b, 's> {
    b: &'b mut Builder<'s>,
    mi: u32,
    events: &'b EventParams,
    code: Vec<Instr>,
    spans: Vec<Span>,
    n_scratch: u32,
}

impl<'b, 's> MachineCompiler<'b, 's> {
    fn new(b: &'b mut Builder<'s>, mi: u32, events: &'b EventParams) -> Self {
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

    /// Parses and compiles `src` in the scope of this machine and `event`.
    fn typed(&mut self, src: &SrcExpr, event: Option<u32>, expect: Option<&Ty>) -> Option<Typed> {
        let ast = match parse_expr(&src.text) {
            Ok(a) => a,
            Err(pe) => {
                let at = self.b.src.sources.unescaped_offset(src.span, pe.offset);
                self.b.err(at, pe.message);
                return None;
            }
        };
        let r = {
            let sources = &self.b.src.sources;
            let span = src.span;
            let abs = move |k: u32| sources.unescaped_offset(span, k).offset;
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
            match expect {
                Some(t) => compile_as(&ast, &scope, &mut self.b.strings, t, "the expression"),
                None => compile(&ast, &scope, &mut self.b.strings, None),
            }
        };
        match r {
            Ok(t) => Some(t),
            Err(e) => {
                self.b.expr_err(self.mi, src, &e);
                None
            }
        }
    }

    fn bool_code(&mut self, src: &SrcExpr, event: Option<u32>) -> Option<BoolFn> {
        match self.typed(src, event, Some(&Ty::Bool))?.code {
            Code::Bool(f) => Some(f),
            _ => None,
        }
    }

    fn place(&mut self, src: &SrcExpr, event: Option<u32>) -> Option<Place> {
        let ast = match parse_expr(&src.text) {
            Ok(a) => a,
            Err(pe) => {
                let at = self.b.src.sources.unescaped_offset(src.span, pe.offset);
                self.b.err(at, pe.message);
                return None;
            }
        };
        let r = {
            let sources = &self.b.src.sources;
            let span = src.span;
            let abs = move |k: u32| sources.unescaped_offset(span, k).offset;
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
            compile_place(&ast, &scope, &mut self.b.strings)
        };
        match r {
            Ok(p) => Some(p),
            Err(e) => {
                self.b.expr_err(self.mi, src, &e);
                None
            }
        }
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
                let delay = match &s.delay {
                    None | Some(Delay::Const(0, _)) => None,
                    Some(Delay::Const(n, _)) => Some(DelayDef::Const(*n)),
                    Some(Delay::Expr(e)) => match self.typed(e, event, Some(&Ty::Int)) {
                        Some(Typed {
                            code: Code::Int(f), ..
                        }) => Some(DelayDef::Expr(f)),
                        _ => return,
                    },
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
                    if let Some(t) = self.typed(&p.expr, event, Some(&pty)) {
                        params.push((pi as u32, t.into_cell_fn()));
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

    fn run(mut self) -> MachineDef {
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
                    self.block(&s.onexit, ev);
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
            file: m.span.file,
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

#[cfg(test)]
mod tests {
    use super::*;

    fn compile_texts(files: &[(&str, &str)]) -> Result<CompiledModel, Diagnostics> {
        CompiledModel::compile(ModelSource::from_texts(files.iter().copied())?)
    }

    #[test]
    fn tables_and_param_inference() {
        let m = compile_texts(&[
            (
                "a.scxml",
                r#"<scxml name="A" initial="s"><datamodel><data id="x" expr="1.5"/></datamodel>
                <state id="s"><onentry><send event="ev" target="B"><param name="v" expr="x"/><param name="n" expr="3"/></send></onentry></state></scxml>"#,
            ),
            (
                "b.scxml",
                r#"<scxml name="B" initial="w"><datamodel><!-- TYPE y:float64 --><data id="y"/></datamodel>
                <state id="w"><transition event="ev" target="w"><assign location="y" expr="_event.data.v + _event.data.n"/>
                <send event="fwd" target="NONE"><param name="k" expr="_event.data.n"/></send></transition></state></scxml>"#,
            ),
        ])
        .unwrap();
        assert_eq!(m.machine_count(), 2);
        let ev = m.event_id("ev").unwrap();
        assert_eq!(
            m.event_params(ev),
            &[("n".to_string(), Ty::Int), ("v".to_string(), Ty::Float)]
        );
        assert_eq!(m.param_index(ev, "v"), Some(1));
        let fwd = m.event_id("fwd").unwrap();
        assert_eq!(m.event_params(fwd), &[("k".to_string(), Ty::Int)]);
        assert_eq!(m.machine_id("B"), Some(MachineId(1)));
        assert_eq!(m.event_senders(ev).collect::<Vec<_>>(), vec![MachineId(0)]);
        assert_eq!(
            m.event_receivers(ev).collect::<Vec<_>>(),
            vec![MachineId(1)]
        );
    }

    #[test]
    fn errors_are_collected_with_positions() {
        let err = compile_texts(&[(
            "bad.scxml",
            "<scxml name=\"A\" initial=\"s\">\n<datamodel><data id=\"x\" expr=\"0\"/></datamodel>\n<state id=\"s\">\n<transition event=\"e\" target=\"nowhere\"/>\n<transition target=\"s\" cond=\"x &amp;&amp; true\"/>\n<onentry><send event=\"e\" target=\"Ghost\"/><assign location=\"x\" expr=\"'str'\"/></onentry>\n</state></scxml>",
        )])
        .unwrap_err();
        let msgs: Vec<String> = err.iter().map(|d| d.to_string()).collect();
        assert!(
            msgs.iter().any(|m| m.starts_with("bad.scxml:4:31:")
                && m.contains("unknown target state `nowhere`")),
            "{msgs:#?}"
        );
        assert!(msgs.iter().any(|m| m.starts_with("bad.scxml:5:30:") && m.contains("cannot be applied to int")), "{msgs:#?}");
        assert!(
            msgs.iter().any(|m| m.starts_with("bad.scxml:6:34:")
                && m.contains("unknown target machine `Ghost`")),
            "{msgs:#?}"
        );
        assert!(
            msgs.iter()
                .any(|m| m.contains("string but int is expected")),
            "{msgs:#?}"
        );
    }
}
