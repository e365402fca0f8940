//! The property layer: SCAN ports resolved against a compiled model, and an observer that
//! turns every simulation point into a monitor step.
//!
//! [`PropertySet::new`] compiles a property file's guarantees and assumptions into one
//! monitor program (its ports become the spec's event and state variables) and resolves
//! each port's message, origin, target and parameter to the model's ids once. A
//! [`Judge`] then observes one run: at every point `docs/SEMANTICS.md` section 1 defines (the
//! initial state, every send, every receive, every time advance) it clears the event
//! variables, applies the ports of a sent message, and steps the monitors. When every
//! verdict is final ([`monitor_core::analysis::settle`]) it stops the run.

use codegen::diag::{Diagnostic, Diagnostics};
use codegen::{Compiled, DeclInput, FormulaInput, Origin, SpecInput};
use monitor_core::{analysis, layout, valuation, Monitor, Ty, Value, VarKind};

use crate::expr::Value as SimValue;
use crate::props::{PortKind, PropertyFile, ANY};
use crate::sim::{CompiledModel, Flow, MachineId, Observer, SentMessage};
use crate::smc::{RunEnd, RunOutcome, Verdict};

use super::split::Split;
use ports::{missing_param, no_such_event};

mod ports;

/// One port resolved to model ids.
#[derive(Clone, Debug)]
struct Port {
    /// `None`: any sender.
    origin: Option<MachineId>,
    /// `None`: any target; `Some(None)`: the `NONE` sink.
    target: Option<Option<MachineId>>,
    /// The spec variable it sets.
    var: usize,
    /// What it sets the variable to.
    value: PortValue,
}

/// What a port writes when its message is sent.
#[derive(Clone, Debug)]
enum PortValue {
    /// `true` (event variables, and the sent-once flag).
    True,
    /// A message parameter.
    Param(usize),
    /// An element (or, with `length`, the length) inside a message parameter.
    Part {
        param: usize,
        path: Box<[u32]>,
        length: bool,
    },
}

/// Guarantees and assumptions compiled to one program, with their ports resolved.
#[derive(Debug)]
pub struct PropertySet {
    compiled: Compiled,
    guarantees: Vec<String>,
    assumptions: usize,
    /// Ports by event id.
    by_event: Vec<Vec<Port>>,
    /// Model string id -> spec string id (`u32::MAX`: equal to no constant).
    strings: Vec<u32>,
    /// What compiling found questionable ([`PropertySet::warnings`]).
    warnings: Diagnostics,
    /// The program cut into one program per property (`Split`).
    split: Split,
}

/// Maps a SCAN port type to a spec type name.
fn spec_type(scan: &str) -> Option<&'static str> {
    crate::model::types::Scalar::from_name(scan).map(crate::model::types::Scalar::spec_name)
}

/// The type a state port holds: the declared one (`written` in the file, `declared` as
/// the spec language names it), except that an integer port reading a floating-point
/// parameter takes it as a float (with a warning pushed on `warnings`), as SCAN does:
/// SCAN's port holds the parameter's value whatever type the port declares, and
/// truncating it would change what the property's comparisons see.
fn widened(
    model: &CompiledModel,
    port: &crate::props::Port,
    param: &str,
    (written, declared): (&str, &'static str),
    file: &str,
    warnings: &mut Diagnostics,
) -> &'static str {
    let float = model
        .event_id(&port.event)
        .and_then(|e| model.param_path(e, param).map(|(i, _)| (e, i)))
        .and_then(|(e, i)| model.event_params(e).get(i))
        .is_some_and(|(_, t)| matches!(t, crate::expr::value::Ty::Float));
    if float && declared.starts_with(['i', 'u']) {
        warnings.push(
            Diagnostic::error(
                file,
                (port.at.line, port.at.column),
                format!(
                    "port `{}` is declared {written} but `{param}` is a float: it is read as \
                     a float (f64), as SCAN reads it",
                    port.id
                ),
            )
            .warning(),
        );
        "f64"
    } else {
        declared
    }
}

/// The spec a property file compiles to: one variable per port (event variables `bool`,
/// state variables of their declared type, or what `state_type(port, param, written,
/// declared)` makes of it), one formula per guarantee and then per assumption, and the
/// time unit `unit_ns` (`None`: untimed). Used by [`PropertySet::with_unit`] and by
/// `hindsight replay` over a recording, so a property file means the same to both.
pub(crate) fn spec_input(
    props: &PropertyFile,
    unit_ns: Option<u64>,
    mut state_type: impl FnMut(&crate::props::Port, &str, &str, &'static str) -> &'static str,
) -> Result<SpecInput, Diagnostics> {
    let file = props.path.display().to_string();
    let origin = |line: u32, col: u32| Origin {
        file: file.clone(),
        line,
        col,
    };
    let mut errors = Vec::new();
    let mut decls = Vec::new();
    for p in &props.ports {
        let at = origin(p.at.line, p.at.column);
        // A part or state port's declared type, as the spec language names it.
        let declared = match &p.kind {
            PortKind::Part { ty, .. } | PortKind::State { ty, .. } => match spec_type(ty) {
                Some(t) => Some((ty, t)),
                None => {
                    errors.push(Diagnostic::error(
                        file.as_str(),
                        (p.at.line, p.at.column),
                        format!("port `{}`: unsupported type `{ty}`", p.id),
                    ));
                    continue;
                }
            },
            PortKind::Event | PortKind::Sent => None,
        };
        let (kind, type_name, init) = match (&p.kind, declared) {
            (PortKind::Sent, _) => (
                VarKind::State,
                "bool".to_string(),
                Some("false".to_string()),
            ),
            (PortKind::Part { .. }, Some((_, t))) => (VarKind::State, t.to_string(), None),
            (PortKind::State { init, param, .. }, Some((ty, t))) => (
                VarKind::State,
                state_type(p, param, ty, t).to_string(),
                Some(init.as_str().to_string()),
            ),
            _ => (VarKind::Event, "bool".to_string(), None),
        };
        decls.push(DeclInput {
            kind,
            name: p.id.clone(),
            type_name,
            init,
            origin: at,
        });
    }
    let formula = |p: &crate::props::Property, name: String| {
        let at = p.formula.location(0);
        FormulaInput {
            name,
            text: p.formula.as_str().to_string(),
            origin: origin(at.line, at.column),
            positions: p.formula.runs().to_vec(),
        }
    };
    let mut formulas: Vec<FormulaInput> = props
        .guarantees
        .iter()
        .map(|p| formula(p, p.id.clone()))
        .collect();
    // Assumption names cannot clash with guarantees: property ids are unique.
    formulas.extend(props.assumptions.iter().map(|p| formula(p, p.id.clone())));
    if !errors.is_empty() {
        return Err(Diagnostics(errors));
    }
    Ok(SpecInput {
        unit: unit_ns.map(|ns| (codegen::duration::format(ns), origin(1, 1))),
        untimed: unit_ns.is_none(),
        decls,
        formulas,
    })
}

impl PropertySet {
    /// Compiles `props` and resolves its ports against `model`. Every error names the
    /// property file's line and column; warnings are kept in [`PropertySet::warnings`].
    pub fn new(props: &PropertyFile, model: &CompiledModel) -> Result<PropertySet, Diagnostics> {
        Self::with_unit(props, model, None)
    }

    /// Like [`PropertySet::new`] for a model whose time unit is `unit_ns` nanoseconds:
    /// bounds with a unit (`6.2s`, `200ms`) are converted exactly to model steps, and a
    /// bound that is not a whole number of steps is an error.
    pub fn with_unit(
        props: &PropertyFile,
        model: &CompiledModel,
        unit_ns: Option<u64>,
    ) -> Result<PropertySet, Diagnostics> {
        let file = props.path.display().to_string();
        let mut errors = Vec::new();
        let mut warnings = Diagnostics::new();
        let input = spec_input(props, unit_ns, |p, param, written, declared| {
            widened(model, p, param, (written, declared), &file, &mut warnings)
        })?;
        let compiled = codegen::compile_input(&input)?;
        warnings.extend(compiled.warnings().clone());

        let mut by_event = vec![Vec::new(); model.event_count()];
        for p in &props.ports {
            let here = |message: String| {
                Diagnostic::error(
                    file.as_str(),
                    (p.at.line, p.at.column),
                    format!("port `{}`: {message}", p.id),
                )
            };
            let Some(event) = model.event_id(&p.event) else {
                errors.push(here(no_such_event(model, &p.event)));
                continue;
            };
            let origin = match model.machine_id(&p.origin) {
                Some(m) => Some(m),
                None if p.origin == ANY => None,
                None => {
                    errors.push(here(format!("no machine `{}` in the model", p.origin)));
                    continue;
                }
            };
            let target = match model.machine_id(&p.target) {
                Some(m) => Some(Some(m)),
                None if p.target == "NONE" => Some(None),
                None if p.target == ANY => None,
                None => {
                    errors.push(here(format!("no machine `{}` in the model", p.target)));
                    continue;
                }
            };
            let value = match &p.kind {
                PortKind::Event | PortKind::Sent => PortValue::True,
                PortKind::Part {
                    param,
                    path,
                    length,
                    ..
                } => match model.param_path(event, param) {
                    // Struct fields first (`point.xs`), then the indices given.
                    Some((i, mut fields)) => PortValue::Part {
                        param: i,
                        path: {
                            fields.extend(path);
                            fields.into_boxed_slice()
                        },
                        length: *length,
                    },
                    None => {
                        errors.push(here(missing_param(model, event, param)));
                        continue;
                    }
                },
                PortKind::State { param, .. } => match model.param_path(event, param) {
                    Some((i, fields)) if fields.is_empty() => PortValue::Param(i),
                    // A field of a struct parameter (`point.x`, `point__x`).
                    Some((i, fields)) => PortValue::Part {
                        param: i,
                        path: fields.into_boxed_slice(),
                        length: false,
                    },
                    None => {
                        errors.push(here(missing_param(model, event, param)));
                        continue;
                    }
                },
            };
            let var = compiled
                .var_index(&p.id)
                .ok_or_else(|| here("not compiled".to_owned()))?;
            by_event[event.0 as usize].push(Port {
                origin,
                target,
                var,
                value,
            });
        }
        if !errors.is_empty() {
            return Err(Diagnostics(errors));
        }
        let table = model.strings();
        let strings = (0..table.len() as u32)
            .map(|i| {
                let s = table.get(crate::expr::StrId(i));
                // Model strings quoted like SCXML literals may carry their quotes.
                let bare = s.trim_matches(|c| c == '\'' || c == '"');
                compiled
                    .string_id(s)
                    .or_else(|| compiled.string_id(bare))
                    .unwrap_or(u32::MAX)
            })
            .collect();
        Ok(PropertySet {
            split: Split::new(&compiled.program()),
            guarantees: props.guarantees.iter().map(|p| p.id.clone()).collect(),
            assumptions: props.assumptions.len(),
            compiled,
            by_event,
            strings,
            warnings,
        })
    }

    /// What compiling the file found questionable without refusing it (an integer port
    /// read as a float, operators SCAN groups differently): the caller decides how to
    /// print them.
    pub fn warnings(&self) -> &Diagnostics {
        &self.warnings
    }

    /// The guarantees' ids, in file order (one verdict each).
    pub fn guarantee_names(&self) -> &[String] {
        &self.guarantees
    }

    /// The compiled monitors (guarantees first, then assumptions).
    pub fn compiled(&self) -> &Compiled {
        &self.compiled
    }
}

/// Why the judge stopped a run: the run's failure, reported with its run index
/// (`study::ModelFailure`).
#[derive(Debug, Clone, PartialEq)]
pub enum RunError {
    /// A message's parameter is not a value of the property variable's type.
    Payload {
        /// The model time of the message.
        time: u64,
        /// The event.
        event: String,
        /// The machine that sent it.
        origin: String,
        /// The machine it was sent to.
        target: String,
        /// The property variable.
        var: String,
        /// The variable's type.
        ty: Ty,
    },
    /// The monitor refused a step.
    Step {
        /// The point's time.
        time: u64,
        /// `Compiled::describe` of the monitor's error.
        what: String,
    },
}

impl std::fmt::Display for RunError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            RunError::Payload {
                time,
                event,
                origin,
                target,
                var,
                ty,
            } => write!(
                f,
                "time {time}: `{event}` from {origin} to {target}: parameter for `{var}` is not a {ty:?}"
            ),
            RunError::Step { time, what } => write!(f, "monitor step at time {time}: {what}"),
        }
    }
}

/// Judges one run: an [`Observer`] stepping the monitors at every point.
///
/// Each property is its own monitor (`verify::split`), stepped only at the points where the
/// step can change its state: where a variable its atoms read changed, at every new
/// time if it has a bounded `S`, and at every point if it has a `Y` / `Z`. At any
/// other point its state, and so its verdict and finality, is exactly what a step
/// would leave (see `Judge::step`), so the verdicts are those of stepping every
/// property at every point.
pub struct Judge<'a> {
    set: &'a PropertySet,
    /// One per part of `PropertySet::split`, planned for up to 256 nodes and atoms
    /// (what does not depend on the point is decided once per run; a larger property is
    /// stepped unplanned, with the same results).
    monitors: Vec<Monitor<'a, 256>>,
    /// The parts' states, one after the other from `offsets[p]`.
    state: Vec<u64>,
    offsets: Vec<usize>,
    vals: Vec<Value>,
    verdicts: Vec<bool>,
    /// Per node, its final value as of the last point ([`analysis::settle`]).
    finals: Vec<Option<bool>>,
    /// The first error (a payload of the wrong type, a monitor step refused).
    pub error: Option<RunError>,
    decided: bool,
    /// The time of the last point.
    last_time: u64,
    /// The parts some of whose variables may differ from their last step (bit `p % 64`
    /// for part `p`): set by every write that changes a value, cleared by a step. Tracked
    /// per write, so that telling a point that changes nothing costs nothing per variable.
    dirty: u64,
    /// The event variables that may hold `true`: the ones the next point clears.
    raised: Vec<usize>,
    /// Per part, where its node value words lie in `state` (`layout`: after the header
    /// and the atom bits).
    value_words: Vec<std::ops::Range<usize>>,
    /// Per part, its node value words as of its last [`analysis::settle`], one part
    /// after the other as in `value_words` (shifted to start at 0).
    settled_values: Vec<u64>,
    /// The parts whose `finals` must be computed at their next step whatever their
    /// values (bit `p % 64`): every part at a run's initial point, since `finals` still
    /// holds the last run's.
    stale: u64,
}

/// The monitor refused the program codegen compiled: a bug, not bad input.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct JudgeError(pub monitor_core::TableError);

impl std::fmt::Display for JudgeError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "internal: compiled program rejected: {}", self.0)
    }
}

impl std::error::Error for JudgeError {}

impl<'a> Judge<'a> {
    /// A judge for `set`, before the run's initial point.
    pub fn new(set: &'a PropertySet) -> Result<Judge<'a>, JudgeError> {
        let whole = set.compiled.program();
        // The whole program passes first: its errors are the ones to report.
        Monitor::<0>::try_new(whole).map_err(JudgeError)?;
        let mut monitors = Vec::with_capacity(set.split.parts.len());
        let mut offsets = vec![0];
        for part in &set.split.parts {
            let m = Monitor::try_new_planned(part.program(&whole)).map_err(JudgeError)?;
            offsets.push(offsets.last().copied().unwrap_or(0) + m.state_words());
            monitors.push(m);
        }
        let vars = whole.vars;
        let mut vals = vec![Value::Bool(false); vars.len()];
        valuation::init(vars, &mut vals);
        let value_words: Vec<_> = monitors
            .iter()
            .zip(&offsets)
            .map(|(m, &at)| {
                let (atoms, nodes) = (m.program().atoms.len(), m.program().nodes.len());
                at + layout::HEADER_WORDS + layout::bit_words(atoms)
                    ..at + layout::first_node_word(atoms, nodes)
            })
            .collect();
        let words = value_words.iter().map(|r| r.len()).sum();
        Ok(Judge {
            set,
            finals: vec![None; whole.nodes.len()],
            state: vec![0; offsets.last().copied().unwrap_or(0)],
            offsets,
            verdicts: vec![false; whole.props.len()],
            monitors,
            error: None,
            decided: false,
            last_time: 0,
            dirty: set.split.all(),
            raised: Vec::new(),
            vals,
            value_words,
            settled_values: vec![0; words],
            stale: set.split.all(),
        })
    }

    /// Puts the judge back before a run's initial point and judges that point (time 0).
    pub fn start(&mut self) -> Flow {
        let vars = self.set.compiled.program().vars;
        valuation::init(vars, &mut self.vals);
        self.raised.clear();
        self.raised.extend(
            (0..vars.len()).filter(|&v| vars[v].kind == VarKind::Event && !is_false(self.vals[v])),
        );
        // Every part steps at the initial point, and settles.
        self.dirty = self.set.split.all();
        self.stale = self.set.split.all();
        self.state.fill(0);
        self.error = None;
        self.decided = false;
        self.last_time = 0;
        self.step(0)
    }

    /// The property variables' values at the last point.
    pub fn values(&self) -> &[Value] {
        &self.vals
    }

    /// Every property's verdict at the last point (guarantees, then assumptions).
    pub fn verdicts(&self) -> &[bool] {
        &self.verdicts
    }

    /// The value of node `node` of the whole program at the last point.
    fn node_value(&self, node: u16) -> Option<bool> {
        let (p, local) = self.set.split.locate(node)?;
        let st = self.state.get(self.offsets[p]..self.offsets[p + 1])?;
        self.monitors[p].node_value(st, local)
    }

    /// For property `prop`, the subformula that explains its verdict at the last point
    /// ([`analysis::culprit`]) in surface syntax (bounds in ticks), with its value then.
    pub fn culprit(&self, prop: usize) -> Option<(String, bool)> {
        let program = self.set.compiled.program();
        let root = program.props.get(prop)?.root;
        let value = |n| self.node_value(n);
        let n = analysis::culprit(&program, root, value);
        Some((
            codegen::print::node_formula(&self.set.compiled, n),
            value(n)?,
        ))
    }

    /// The property set this judge works for.
    pub fn set(&self) -> &'a PropertySet {
        self.set
    }

    /// Judges the point at `time`: steps the parts that are due. Always inlined into the
    /// observer's calls: at most points of a run no part is due, and for them the call
    /// cost more than the test.
    ///
    /// Skipping a part that is not due is exact, not an approximation:
    /// - its variables hold the values of its last step (a write that changes one marks
    ///   its readers `dirty`), so its atoms have the same values;
    /// - without `Y` / `Z` every node's update is idempotent at one time with the same
    ///   inputs (atoms are pure, `S` keeps or resets the same witness, windows expire
    ///   nothing more and extend the newest run to the same time:
    ///   [`analysis::repeat_is_noop`]), so the state after the step would be bit for bit
    ///   the one before it, and so the verdicts and their finality;
    /// - without a bounded `S` no node reads the time (an unbounded `S` is one bit, the
    ///   connectives are pure), so that holds at a later time too; a part with one steps
    ///   at every new time, one with a `Y` / `Z` at every point.
    #[inline(always)]
    fn step(&mut self, time: u64) -> Flow {
        let split = &self.set.split;
        let mut due = self.dirty | split.always;
        if time != self.last_time {
            if time < self.last_time || time == u64::MAX {
                return self.time_error(time);
            }
            self.last_time = time;
            due |= split.timed;
        }
        if due == 0 {
            return Flow::Continue;
        }
        self.step_now(time, due)
    }

    /// A point whose time went back: the error stepping it would give.
    #[cold]
    #[inline(never)]
    fn time_error(&mut self, time: u64) -> Flow {
        let e = if time == u64::MAX {
            monitor_core::StepError::TimeOutOfRange
        } else {
            monitor_core::StepError::TimeWentBackwards {
                last: self.last_time,
                now: time,
            }
        };
        self.fail(time, e)
    }

    #[cold]
    #[inline(never)]
    fn fail(&mut self, time: u64, e: monitor_core::StepError) -> Flow {
        self.error = Some(RunError::Step {
            time,
            what: self.set.compiled.describe(&e),
        });
        Flow::Stop
    }

    /// Steps the parts in `due` (bit `p % 64` for part `p`) at `time` and settles what
    /// became final.
    ///
    /// A part whose node values are those of its last settle is not settled again: a
    /// node's finality ([`analysis::node_final`]) is a function of its value and of its
    /// children's finality, so a part's `finals` are a function of its node values
    /// alone, and settling the same values gives the same `finals`. Most timed steps
    /// (a bounded `S` stepped at a new time) change no value. Whether every verdict is
    /// final is asked after a step that settled a part with a final verdict: verdicts
    /// can only have all become final at a step that changed some part's `finals`, so
    /// the run stops at the same point as when every stepped part was settled.
    #[inline(never)]
    fn step_now(&mut self, time: u64, due: u64) -> Flow {
        self.dirty = 0;
        let split = &self.set.split;
        let whole = self.set.compiled.program();
        let mut newly_final = false;
        let mut kept = 0;
        for (p, part) in split.parts.iter().enumerate() {
            let words = self.value_words[p].clone();
            let saved = kept..kept + words.len();
            kept = saved.end;
            let bit = 1u64 << (p % 64);
            if due & bit == 0 {
                continue;
            }
            let m = &self.monitors[p];
            let st = &mut self.state[self.offsets[p]..self.offsets[p + 1]];
            let props = part.first_prop..part.first_prop + m.properties();
            if let Err(e) = m.try_step(st, time, &self.vals, &mut self.verdicts[props.clone()]) {
                return self.fail(time, part.global_error(e));
            }
            let now = &self.state[words];
            let before = &mut self.settled_values[saved];
            if self.stale & bit == 0 && now == &*before {
                continue;
            }
            self.stale &= !bit;
            before.copy_from_slice(now);
            let finals = &mut self.finals[part.first_node..part.first_node + part.node_count()];
            let st = &self.state[self.offsets[p]..self.offsets[p + 1]];
            analysis::settle(
                m.program(),
                |n| m.node_value(st, n).unwrap_or(false),
                finals,
            );
            newly_final |= props
                .clone()
                .any(|k| analysis::settled(&whole, &self.finals, k).is_some());
        }
        if newly_final
            && (0..self.verdicts.len())
                .all(|k| analysis::settled(&whole, &self.finals, k).is_some())
        {
            self.decided = true;
            return Flow::Stop;
        }
        Flow::Continue
    }

    /// Starts a point: every event variable becomes `false`
    /// ([`valuation::begin_point`]'s rule), touching only the ones that were raised.
    #[inline(always)]
    fn begin(&mut self) {
        if self.raised.is_empty() {
            return;
        }
        for v in self.raised.drain(..) {
            if !is_false(self.vals[v]) {
                self.vals[v] = Value::Bool(false);
                self.dirty |= self.set.split.readers[v];
            }
        }
    }

    /// Writes variable `var` of this point.
    fn write(&mut self, var: usize, value: Value) {
        if same_value(self.vals[var], value) {
            return;
        }
        self.vals[var] = value;
        self.dirty |= self.set.split.readers[var];
        if self.set.compiled.program().vars[var].kind == VarKind::Event {
            self.raised.push(var);
        }
    }
    fn convert(&self, v: SimValue<'_>, ty: Ty) -> Option<Value> {
        Some(match (v, ty) {
            (SimValue::Bool(b), Ty::Bool) => Value::Bool(b),
            (SimValue::Int(i), Ty::Int) => Value::Int(i),
            (SimValue::Int(i), Ty::Float) => Value::Float(i as f64),
            (SimValue::Float(f), Ty::Float) => Value::Float(f),
            (SimValue::Str(s), Ty::Str) => Value::Str(
                self.set
                    .strings
                    .get(s.0 as usize)
                    .copied()
                    .unwrap_or(u32::MAX),
            ),
            _ => return None,
        })
    }

    /// The element at `path` inside `v` (a string's characters are their codes), or its
    /// length; the type's zero when `v` has no such element.
    fn part(
        &self,
        v: SimValue<'_>,
        path: &[u32],
        length: bool,
        ty: Ty,
        model: &CompiledModel,
    ) -> Option<Value> {
        let zero = match ty {
            Ty::Bool => Value::Bool(false),
            Ty::Float => Value::Float(0.0),
            _ => Value::Int(0),
        };
        let mut cur = v;
        for (k, &i) in path.iter().enumerate() {
            cur = match cur {
                SimValue::List(l) => match l.get(i as usize) {
                    Some(x) => x,
                    None => return Some(zero),
                },
                SimValue::Str(s) if k + 1 == path.len() && !length => {
                    let code = model.strings().get(s).chars().nth(i as usize);
                    return Some(code.map_or(zero, |c| Value::Int(c as i64)));
                }
                _ => return None,
            };
        }
        if length {
            return match cur {
                SimValue::List(l) => Some(Value::Int(l.len() as i64)),
                SimValue::Str(s) => Some(Value::Int(model.strings().get(s).chars().count() as i64)),
                _ => None,
            };
        }
        self.convert(cur, ty)
    }

    /// The run's outcome from the verdicts at its last point and why it ended.
    pub fn outcome(&self, end: RunEnd, steps: u64, time: u64) -> RunOutcome {
        let g = self.set.guarantees.len();
        let judged = |p: usize| -> Verdict {
            match analysis::settled(&self.set.compiled.program(), &self.finals, p) {
                Some(v) => v.into(),
                // A run cut short is judged only where the verdict was already final.
                None if end == RunEnd::StepLimit => Verdict::Unknown,
                None => self.verdicts[p].into(),
            }
        };
        let verdicts = (0..g).map(judged).collect();
        let mut assumptions = Verdict::True;
        for a in g..g + self.set.assumptions {
            match judged(a) {
                Verdict::False => {
                    assumptions = Verdict::False;
                    break;
                }
                Verdict::Unknown => assumptions = Verdict::Unknown,
                Verdict::True => {}
            }
        }
        RunOutcome {
            verdicts,
            assumptions,
            end: if self.decided { RunEnd::Decided } else { end },
            steps,
            time,
        }
    }
}

/// Whether two values are identical (floats bit for bit, so `-0.0` differs from `0.0`
/// and a NaN equals itself: the atoms see exactly the same input).
fn same_value(a: Value, b: Value) -> bool {
    match (a, b) {
        (Value::Bool(x), Value::Bool(y)) => x == y,
        (Value::Int(x), Value::Int(y)) => x == y,
        (Value::Float(x), Value::Float(y)) => x.to_bits() == y.to_bits(),
        (Value::Str(x), Value::Str(y)) => x == y,
        _ => false,
    }
}

fn is_false(v: Value) -> bool {
    same_value(v, Value::Bool(false))
}

impl Judge<'_> {
    /// Applies the ports of `msg` (there is at least one for its event) to this point's
    /// variables; `Flow::Stop` with [`Judge::error`] set when a parameter has not the
    /// port's type. Out of line: most messages have no port, and for them `on_send` is
    /// the test of an empty list and a step.
    #[inline(never)]
    fn apply_ports(&mut self, time: u64, msg: &SentMessage<'_>, ports: &[Port]) -> Flow {
        for port in ports {
            if port.origin.is_some_and(|o| o != msg.origin())
                || port.target.is_some_and(|t| t != msg.target())
            {
                continue;
            }
            let decl = &self.set.compiled.program().vars[port.var];
            let value = match &port.value {
                PortValue::True => Some(Value::Bool(true)),
                PortValue::Param(i) => msg.param(*i).and_then(|v| self.convert(v, decl.ty)),
                PortValue::Part {
                    param,
                    path,
                    length,
                } => msg
                    .param(*param)
                    .and_then(|v| self.part(v, path, *length, decl.ty, msg.model())),
            };
            match value {
                Some(v) => self.write(port.var, v),
                None => {
                    self.error = Some(RunError::Payload {
                        time,
                        event: msg.event_name().to_string(),
                        origin: msg.origin_name().to_string(),
                        target: msg.target_name().to_string(),
                        var: decl.name.to_string(),
                        ty: decl.ty,
                    });
                    return Flow::Stop;
                }
            }
        }
        Flow::Continue
    }
}

impl Observer for Judge<'_> {
    #[inline]
    fn on_send(&mut self, time: u64, msg: &SentMessage<'_>) -> Flow {
        self.begin();
        let set = self.set;
        let ports = set
            .by_event
            .get(msg.event().0 as usize)
            .map_or(&[][..], Vec::as_slice);
        if !ports.is_empty() && self.apply_ports(time, msg, ports) == Flow::Stop {
            return Flow::Stop;
        }
        self.step(time)
    }

    #[inline]
    fn on_receive(&mut self, time: u64, _msg: &SentMessage<'_>) -> Flow {
        self.begin();
        self.step(time)
    }

    fn on_time(&mut self, time: u64) -> Flow {
        self.begin();
        self.step(time)
    }
}

#[cfg(test)]
#[path = "observe_tests.rs"]
mod tests;
