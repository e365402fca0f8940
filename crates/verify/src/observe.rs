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
use monitor_core::{analysis, valuation, Monitor, Ty, Value, VarKind};

use crate::expr::Value as SimValue;
use crate::props::{PortKind, PropertyFile, ANY};
use crate::sim::{CompiledModel, EventId, Flow, MachineId, Observer, SentMessage};
use crate::smc::{RunEnd, RunOutcome, Verdict};

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
pub fn spec_input(
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
        let (kind, type_name, init) = match &p.kind {
            PortKind::Event => (VarKind::Event, "bool".to_string(), None),
            PortKind::Sent => (
                VarKind::State,
                "bool".to_string(),
                Some("false".to_string()),
            ),
            PortKind::Part { ty, .. } => match spec_type(ty) {
                Some(t) => (VarKind::State, t.to_string(), None),
                None => {
                    errors.push(Diagnostic::error(
                        file.as_str(),
                        (p.at.line, p.at.column),
                        format!("port `{}`: unsupported type `{ty}`", p.id),
                    ));
                    continue;
                }
            },
            PortKind::State { ty, init, param } => match spec_type(ty) {
                Some(t) => (
                    VarKind::State,
                    state_type(p, param, ty, t).to_string(),
                    Some(init.as_str().to_string()),
                ),
                None => {
                    errors.push(Diagnostic::error(
                        file.as_str(),
                        (p.at.line, p.at.column),
                        format!("port `{}`: unsupported type `{ty}`", p.id),
                    ));
                    continue;
                }
            },
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
                errors.push(here(format!("the model sends no event `{}`", p.event)));
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

/// Judges one run: an [`Observer`] stepping the monitors at every point.
pub struct Judge<'a> {
    set: &'a PropertySet,
    /// Planned for up to 256 nodes and atoms (what does not depend on the point is
    /// decided once per run; a larger spec is stepped unplanned, with the same results).
    monitor: Monitor<'a, 256>,
    state: Vec<u64>,
    vals: Vec<Value>,
    verdicts: Vec<bool>,
    /// Per node, its final value as of the last point ([`analysis::settle`]).
    finals: Vec<Option<bool>>,
    /// The first error (a payload of the wrong type, a timestamp going back).
    pub error: Option<String>,
    decided: bool,
    /// The program has no `Y` / `Z` node: a point equal to the last one stepped (same
    /// time, same values) leaves the monitor state and verdicts exactly as they are.
    repeat_is_noop: bool,
    /// The time of the last point stepped (`None` before the first).
    last_time: Option<u64>,
    /// Some value may differ from the last point stepped: set by every write that
    /// changes a value, cleared by a step. Tracked per write, so that telling a
    /// repeated point costs nothing per variable.
    changed: bool,
    /// The event variables that may hold `true`: the ones the next point clears.
    raised: Vec<usize>,
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
        let monitor = Monitor::try_new_planned(set.compiled.program()).map_err(JudgeError)?;
        let vars = monitor.program().vars;
        let mut vals = vec![Value::Bool(false); vars.len()];
        valuation::init(vars, &mut vals);
        let repeat_is_noop = analysis::repeat_is_noop(monitor.program());
        Ok(Judge {
            set,
            finals: vec![None; monitor.program().nodes.len()],
            state: vec![0; monitor.state_words()],
            verdicts: vec![false; monitor.properties()],
            monitor,
            error: None,
            decided: false,
            repeat_is_noop,
            last_time: None,
            changed: true,
            raised: Vec::new(),
            vals,
        })
    }

    /// Puts the judge back before a run's initial point and judges that point (time 0).
    pub fn start(&mut self) -> Flow {
        let vars = self.monitor.program().vars;
        valuation::init(vars, &mut self.vals);
        self.raised.clear();
        self.raised.extend(
            (0..vars.len()).filter(|&v| vars[v].kind == VarKind::Event && !is_false(self.vals[v])),
        );
        self.changed = true;
        self.state.fill(0);
        self.error = None;
        self.decided = false;
        self.last_time = None;
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

    /// For property `prop`, the subformula that explains its verdict at the last point
    /// ([`analysis::culprit`]) in surface syntax (bounds in ticks), with its value then.
    pub fn culprit(&self, prop: usize) -> Option<(String, bool)> {
        let program = self.monitor.program();
        let root = program.props.get(prop)?.root;
        let value = |n| self.monitor.node_value(&self.state, n);
        let n = analysis::culprit(program, root, value);
        Some((
            codegen::print::node_formula(&self.set.compiled, n),
            value(n)?,
        ))
    }

    /// The property set this judge works for.
    pub fn set(&self) -> &'a PropertySet {
        self.set
    }

    /// Judges the point at `time`, unless it repeats the last one stepped (see
    /// [`Judge::step_now`]). Always inlined into the observer's calls: most points of a
    /// run repeat the last one, and for them the call cost more than the test.
    #[inline(always)]
    fn step(&mut self, time: u64) -> Flow {
        if self.repeat_is_noop && self.last_time == Some(time) && !self.changed {
            return Flow::Continue;
        }
        self.step_now(time)
    }

    /// Steps the monitors at `time` and settles what became final.
    #[inline(never)]
    fn step_now(&mut self, time: u64) -> Flow {
        // Skipping a repeated point is exact, not an approximation: without `Y` / `Z`
        // every node's update is idempotent at one time with the same inputs (atoms are
        // pure, `S` keeps or resets the same witness, windows expire nothing more and
        // extend the newest run to the same time), so the state after the step would be
        // bit for bit the one before it, and so the verdicts and their finality. Most
        // points of a run (messages that set no port) repeat the last one.
        self.last_time = Some(time);
        self.changed = false;
        if let Err(e) = self
            .monitor
            .try_step(&mut self.state, time, &self.vals, &mut self.verdicts)
        {
            self.error = Some(format!(
                "monitor step at time {time}: {}",
                self.set.compiled.describe(&e)
            ));
            return Flow::Stop;
        }
        let (m, st) = (&self.monitor, &self.state);
        analysis::settle(
            m.program(),
            |n| m.node_value(st, n).unwrap_or(false),
            &mut self.finals,
        );
        let all = (0..self.verdicts.len())
            .all(|p| analysis::settled(m.program(), &self.finals, p).is_some());
        if all {
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
                self.changed = true;
            }
        }
    }

    /// Writes variable `var` of this point.
    fn write(&mut self, var: usize, value: Value) {
        if same_value(self.vals[var], value) {
            return;
        }
        self.vals[var] = value;
        self.changed = true;
        if self.monitor.program().vars[var].kind == VarKind::Event {
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
            match analysis::settled(self.monitor.program(), &self.finals, p) {
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

impl Observer for Judge<'_> {
    fn on_send(&mut self, time: u64, msg: &SentMessage<'_>) -> Flow {
        self.begin();
        let ports = self.set.by_event.get(msg.event().0 as usize);
        for port in ports.into_iter().flatten() {
            if port.origin.is_some_and(|o| o != msg.origin())
                || port.target.is_some_and(|t| t != msg.target())
            {
                continue;
            }
            let decl = &self.monitor.program().vars[port.var];
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
                    self.error = Some(format!(
                        "time {time}: `{}` from {} to {}: parameter for `{}` is not a {:?}",
                        msg.event_name(),
                        msg.origin_name(),
                        msg.target_name(),
                        decl.name,
                        decl.ty
                    ));
                    return Flow::Stop;
                }
            }
        }
        self.step(time)
    }

    fn on_receive(&mut self, time: u64, _msg: &SentMessage<'_>) -> Flow {
        self.begin();
        self.step(time)
    }

    fn on_time(&mut self, time: u64) -> Flow {
        self.begin();
        self.step(time)
    }
}

/// Why `param` cannot be read from `event`: a ROS message field (`ros_fields__a__b`, a
/// port over a topic or service) is named as the user wrote it, with the fields there are.
fn missing_param(model: &CompiledModel, event: EventId, param: &str) -> String {
    let params = model.event_params(event);
    match param.strip_prefix("ros_fields__") {
        Some(field) => {
            let fields: Vec<String> = params
                .iter()
                .filter_map(|(n, _)| n.strip_prefix("ros_fields__"))
                .map(|f| f.replace("__", "."))
                .collect();
            format!(
                "the message has no field `{}` (fields: {})",
                field.replace("__", "."),
                if fields.is_empty() {
                    "none".to_string()
                } else {
                    fields.join(", ")
                }
            )
        }
        None => {
            let names: Vec<&str> = params.iter().map(|(n, _)| n.as_str()).collect();
            format!(
                "event `{}` has no parameter `{param}` (parameters: {})",
                model.event_name(event),
                if names.is_empty() {
                    "none".to_string()
                } else {
                    names.join(", ")
                }
            )
        }
    }
}

#[cfg(test)]
mod tests {
    use super::{same_value, Judge, PropertySet};
    use monitor_core::{analysis, valuation, Monitor, Value};

    /// The fact [`super::Judge`] relies on to skip repeated points: without `Y` / `Z`, a
    /// step at the same time with the same values leaves the state bit for bit unchanged.
    #[test]
    fn repeated_point_leaves_the_state_unchanged() {
        let formulas = [
            "H({p} -> P {q})",
            "{p} S {q}",
            "{p} S[3:] {q}",
            "{p} S[:4] {q}",
            "{p} S[2:5] {q}",
            "!{p} S[1:1] ({q} && {n > 2})",
            "H(P[10:] true -> P[:10] {q})",
            "H(({p} -> P {n <= 3}) && !((!{p}) S[6:] {n <= 3}))",
            "P[0:3] ({p} || H[0:2] !{q})",
        ];
        let mut x = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = move || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            x
        };
        let mut repeats = 0;
        for f in formulas {
            let src = format!("event p;\nevent q;\nstate n: i64 = 0;\nproperty f = {f};\n");
            let c = codegen::compile_spec(&src, "t.hspec").unwrap();
            let m = Monitor::try_new(c.program()).unwrap();
            assert!(analysis::repeat_is_noop(m.program()));
            for _ in 0..40 {
                let mut st = vec![0; m.state_words()];
                let mut vals = vec![Value::Bool(false); c.program().vars.len()];
                valuation::init(c.program().vars, &mut vals);
                let mut out = [false];
                let mut t = 0;
                for _ in 0..80 {
                    t += next() % 3;
                    valuation::begin_point(c.program().vars, &mut vals);
                    let r = next();
                    vals[0] = Value::Bool(r % 4 == 0);
                    vals[1] = Value::Bool(r % 5 == 0);
                    if r % 7 == 0 {
                        vals[2] = Value::Int((r % 6) as i64);
                    }
                    m.try_step(&mut st, t, &vals, &mut out).unwrap();
                    let (before, verdict) = (st.clone(), out[0]);
                    // The same point again, once or twice.
                    for _ in 0..1 + next() % 2 {
                        m.try_step(&mut st, t, &vals, &mut out).unwrap();
                        assert_eq!(st, before, "{f} at {t}");
                        assert_eq!(out[0], verdict, "{f} at {t}");
                        repeats += 1;
                    }
                }
            }
        }
        assert!(repeats > 1000);
    }

    /// The judge tells a repeated point by tracking writes, not by comparing every
    /// variable. Oracle: a monitor of the same program stepped at every point, its
    /// variables kept by [`valuation::begin_point`]; after every point the judge's
    /// verdicts, values and state must equal the oracle's. Random points at repeated and
    /// advancing times write random values (often the value already held, often none).
    #[test]
    fn tracked_writes_skip_exactly_the_repeated_points() {
        use crate::sim::{CompiledModel, Flow};
        let machine = "<scxml name=\"a\" initial=\"s0\" version=\"1.0\" \
            xmlns=\"http://www.w3.org/2005/07/scxml\"><datamodel>\
            <data id=\"x\" type=\"int32\" expr=\"0\"/></datamodel>\
            <state id=\"s0\"><onentry><send event=\"e\" target=\"b\">\
            <param name=\"v\" expr=\"x\"/></send></onentry></state></scxml>";
        let sink = "<scxml name=\"b\" initial=\"s0\" version=\"1.0\" \
            xmlns=\"http://www.w3.org/2005/07/scxml\"><state id=\"s0\"/></scxml>";
        let model = CompiledModel::compile(
            crate::model::ModelSource::from_texts([("a.scxml", machine), ("b.scxml", sink)])
                .unwrap(),
        )
        .unwrap();
        let props = "<properties><ports>\
            <scxml_event_send event=\"e\" origin=\"a\" target=\"b\">\
            <event_var id=\"p\"/><event_var id=\"q\"/>\
            <state_var id=\"n\" param=\"v\" type=\"int32\" expr=\"0\"/>\
            </scxml_event_send></ports><guarantees>\
            <property id=\"g1\" logic=\"pmtl\" expr=\"historically({p} -> once {n &gt; 2})\"/>\
            <property id=\"g2\" logic=\"pmtl\" expr=\"{q} since[1:3] {n == 1}\"/>\
            <property id=\"g3\" logic=\"pmtl\" expr=\"once[0:2] ({p} &amp;&amp; !{q})\"/>\
            <property id=\"g4\" logic=\"pmtl\" expr=\"!{p} since[2:] {n &lt; 2}\"/>\
            </guarantees></properties>";
        let file = crate::props::parse_str(props, std::path::Path::new("p.xml")).unwrap();
        let set = PropertySet::new(&file, &model).unwrap();
        let mut judge = Judge::new(&set).unwrap();
        let program = set.compiled().program();
        let oracle = Monitor::try_new(program).unwrap();
        let var = |name: &str| set.compiled().var_index(name).unwrap();
        let (p, q, n) = (var("p"), var("q"), var("n"));
        let mut x = 0x2545_f491_4f6c_dd1du64;
        let mut next = move || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            x
        };
        let (mut repeats, mut steps) = (0, 0);
        for _ in 0..30 {
            let mut st = vec![0; oracle.state_words()];
            let mut vals = vec![Value::Bool(false); program.vars.len()];
            valuation::init(program.vars, &mut vals);
            let mut out = vec![false; oracle.properties()];
            assert_eq!(judge.start(), Flow::Continue);
            oracle.try_step(&mut st, 0, &vals, &mut out).unwrap();
            let mut t = 0;
            let mut last = (0, vals.clone());
            for _ in 0..120 {
                let r = next();
                t += [0, 0, 0, 1, 2][(r % 5) as usize];
                judge.begin();
                valuation::begin_point(program.vars, &mut vals);
                let mut writes = Vec::new();
                if r >> 8 & 3 == 0 {
                    writes.push((p, Value::Bool(true)));
                }
                if r >> 10 & 3 == 0 {
                    writes.push((q, Value::Bool(true)));
                }
                if r >> 12 & 3 == 0 {
                    writes.push((n, Value::Int((r >> 14) as i64 % 4)));
                }
                for (v, value) in writes {
                    judge.write(v, value);
                    vals[v] = value;
                }
                let repeat = t == last.0 && vals == last.1;
                last = (t, vals.clone());
                let flow = judge.step(t);
                oracle.try_step(&mut st, t, &vals, &mut out).unwrap();
                assert_eq!(judge.values(), &vals[..]);
                assert_eq!(judge.state, st, "at time {t}");
                assert_eq!(judge.verdicts(), &out[..], "at time {t}");
                if repeat {
                    repeats += 1;
                } else {
                    steps += 1;
                }
                if flow == Flow::Stop {
                    break;
                }
            }
        }
        // Both kinds of point came many times.
        assert!(repeats > 200 && steps > 200, "{repeats} {steps}");
    }

    #[test]
    fn floats_compare_bit_for_bit() {
        assert!(same_value(Value::Float(0.0), Value::Float(0.0)));
        assert!(!same_value(Value::Float(0.0), Value::Float(-0.0)));
        assert!(same_value(Value::Float(f64::NAN), Value::Float(f64::NAN)));
        assert!(!same_value(Value::Int(1), Value::Float(1.0)));
        assert!(!same_value(Value::Bool(false), Value::Int(0)));
    }
}
