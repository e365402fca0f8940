//! Loading a model and its properties: the first stage of every command that checks a model.
//!
//! [`load`] takes a plain [`LoadOptions`] (the command line builds it from its
//! arguments): a robot model (a main file, or a folder holding `main.xml`) goes
//! through the robot pipeline, anything else is read as plain SCXML; the property
//! file (given, named by the model, or found beside it) is read, filtered by
//! `only` / `skip`, and compiled against the model into a [`PropertySet`].
//!
//! Nothing here prints: a failure is a [`LoadError`] (the files' located
//! [`Diagnostics`], or an option that does not fit the model), and the warnings of every
//! reader on the way are returned in [`Loaded::warnings`] for the command to print.

use std::fmt;
use std::path::{Path, PathBuf};

use codegen::diag::{Diagnostic, Diagnostics};
use codegen::duration::DurationError;

use super::observe::PropertySet;
use crate::props;
// A robot model's components and main file, as callers name them.
pub use crate::robot::load::{main_file_of, ExternalComponent};
use crate::sim::{CompiledModel, EventSemantics};

/// What to load: the model, its property file and how to read them.
#[derive(Clone, Debug, Default)]
pub struct LoadOptions {
    /// The model: a robot main file or a folder holding `main.xml`; a folder of plain
    /// .scxml machines, a SCAN model.xml, or one .scxml file.
    pub model: PathBuf,
    /// The property file; default: the one the main file or model.xml names, else
    /// MODEL/properties.xml, else the single .jani file beside the model.
    pub props: Option<PathBuf>,
    /// The length of one model time step in nanoseconds (a robot model has its own and
    /// must agree).
    pub time_unit_ns: Option<u64>,
    /// How sends are delivered; default: AS2FM's for robot models and `.jani` property
    /// files, SCAN's queues otherwise.
    pub events: Option<EventSemantics>,
    /// Check only these guarantees (by name; empty: all).
    pub only: Vec<String>,
    /// Leave these guarantees out (by name).
    pub skip: Vec<String>,
    /// Folders of ROS interface packages for a robot model (`--interfaces`), searched
    /// before the folders beside and above the model, `AMENT_PREFIX_PATH` and the
    /// built-ins.
    pub interfaces: Vec<PathBuf>,
    /// Whose rules a robot model's behavior tree follows (`--bt`); anything but AS2FM's
    /// needs a robot model with a behavior tree.
    pub bt: crate::robot::bt::BtSemantics,
    /// A model without a property file (none given, and none found beside a plain model
    /// or named by a robot model's main file) loads with no properties instead of
    /// failing ([`Loaded::no_props`] says why): for `validate` and `trace`, which are of
    /// use on a model alone.
    pub props_optional: bool,
}

/// The event semantics for a property file when none is asked for: AS2FM's for a JANI
/// property file (the model is then AS2FM's plain SCXML), SCAN's queues otherwise.
pub(crate) fn default_events(props_path: &Path) -> EventSemantics {
    if is_jani(props_path) {
        EventSemantics::As2fm
    } else {
        EventSemantics::Queues
    }
}

fn is_jani(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("jani"))
}

/// Why a model and its properties could not be loaded.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum LoadError {
    /// What is wrong in the files (model, main file, property file), each problem
    /// located at its `file:line:col` (or its file), with what the user can do about it
    /// when there is something (`--skip`, `--time-unit`).
    Files {
        /// The problems, in the order found.
        diagnostics: Diagnostics,
        /// One line of advice printed after them, without its `hint: `.
        hint: Option<&'static str>,
    },
    /// An option that does not fit the model (`--bt`, `--only`, `--time-unit`, ...).
    Option {
        /// The option as given (`--only p9`).
        flag: String,
        /// Why it does not fit.
        message: String,
    },
}

impl LoadError {
    fn option(flag: impl Into<String>, message: impl Into<String>) -> LoadError {
        LoadError::Option {
            flag: flag.into(),
            message: message.into(),
        }
    }

    fn about_file(path: &Path, message: impl Into<String>) -> LoadError {
        Diagnostic::about_file(path.display().to_string(), message.into()).into()
    }
}

impl From<Diagnostics> for LoadError {
    fn from(diagnostics: Diagnostics) -> LoadError {
        LoadError::Files {
            diagnostics,
            hint: None,
        }
    }
}

impl From<Diagnostic> for LoadError {
    fn from(d: Diagnostic) -> LoadError {
        Diagnostics::from(d).into()
    }
}

/// `file:line:col: message` for each problem (then `hint: ...`), or `FLAG: message`.
impl fmt::Display for LoadError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            LoadError::Files { diagnostics, hint } => {
                write!(f, "{diagnostics}")?;
                match hint {
                    Some(h) => write!(f, "\nhint: {h}"),
                    None => Ok(()),
                }
            }
            LoadError::Option { flag, message } => write!(f, "{flag}: {message}"),
        }
    }
}

impl std::error::Error for LoadError {}

/// Why a run length ([`Loaded::max_time`]) is not a number of model steps; the caller
/// names its flag in front.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum MaxTimeError {
    /// Neither steps nor a duration.
    Unreadable(DurationError),
    /// A duration that is not a whole number of the model's steps (of `unit_ns`).
    NotWholeSteps {
        /// The duration as written.
        text: String,
        /// The model's step in nanoseconds.
        unit_ns: u64,
    },
    /// A duration for a model without a time unit.
    NoTimeUnit(String),
    /// Zero (as written): every run would end before model time moves, and each
    /// property would be judged on the first instant alone.
    Zero(String),
}

impl fmt::Display for MaxTimeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            MaxTimeError::Unreadable(e) => write!(f, "{e}"),
            MaxTimeError::NotWholeSteps { text, unit_ns } => write!(
                f,
                "{text} is not a whole number of model steps of {}",
                codegen::duration::format(*unit_ns)
            ),
            MaxTimeError::NoTimeUnit(text) => write!(
                f,
                "{text} is a duration but the model has no time unit (give --time-unit, \
                 or the length in steps)"
            ),
            MaxTimeError::Zero(text) => write!(
                f,
                "{text} would end every run before model time moves, and judge each \
                 property on the first instant alone: give a positive length"
            ),
        }
    }
}

impl std::error::Error for MaxTimeError {}

/// Finds the property file for a model when none is given.
fn default_props(model: &Path, compiled: &CompiledModel) -> Result<PathBuf, LoadError> {
    if let Some(p) = compiled.properties_path() {
        return Ok(p.to_path_buf());
    }
    let dir = if model.is_dir() {
        model.to_path_buf()
    } else {
        model.parent().map(Path::to_path_buf).unwrap_or_default()
    };
    let p = dir.join("properties.xml");
    if p.is_file() {
        return Ok(p);
    }
    // A folder with exactly one JANI file (AS2FM's models keep their properties there).
    let mut jani: Vec<PathBuf> = std::fs::read_dir(&dir)
        .map(|rd| {
            rd.filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| p.is_file() && is_jani(p))
                .collect()
        })
        .unwrap_or_default();
    if jani.len() == 1 {
        return Ok(jani.remove(0));
    }
    Err(LoadError::about_file(
        model,
        format!(
            "no property file given and none found (looked for {} and a single .jani file)",
            p.display()
        ),
    ))
}

/// A model with its properties, compiled: everything `validate` checks.
pub struct Loaded {
    /// The simulator's model.
    pub model: CompiledModel,
    /// The property file as read.
    pub file: props::PropertyFile,
    /// Its guarantees and assumptions, compiled and resolved against the model.
    pub set: PropertySet,
    /// Where the properties came from.
    pub props_path: PathBuf,
    /// The length of one model time step in nanoseconds, when known.
    pub unit_ns: Option<u64>,
    /// The run length the model asks for (a robot main file's `max_time`), in steps.
    pub default_max_time: Option<u64>,
    /// Where a robot model's behavior tree runs differently under AS2FM's node models and
    /// BehaviorTree.CPP 4 (`file:line:col: what`), for `validate`.
    pub bt_notes: Vec<String>,
    /// How sends are delivered.
    pub events: EventSemantics,
    /// What the readers found questionable without refusing it (attributes AS2FM
    /// ignores, an integer port read as a float, ...), in the order found: the command
    /// prints them.
    pub warnings: Diagnostics,
    /// The options it was loaded with: a study records them so that its runs can be
    /// replayed from its JSON ([`crate::replay::Replay`]).
    pub options: LoadOptions,
    /// Why the model was loaded with no properties ([`LoadOptions::props_optional`]):
    /// where a property file was looked for. `props_path` is then empty.
    pub no_props: Option<String>,
}

impl Loaded {
    /// The note for runs of `max_time` steps of which `quiescent` of `runs` (seed `seed`)
    /// went quiet before the time horizon, when that means a deadlock: `None` when none
    /// did or it does not.
    ///
    /// A robot model's global timer runs until its main file's `max_time`, so a run no
    /// longer than that which went quiet is stuck (the simulator ends a run that went
    /// quiet at its horizon as `MaxTime`, see `docs/SEMANTICS.md` section 2). A plain
    /// model may simply stop its timer, as AS2FM's translations do, a run longer than
    /// the model's own length outlives its timer, and a robot model without timers has
    /// no global timer and ends when its machines are done: none gets the note.
    pub fn deadlock_note(
        &self,
        max_time: u64,
        quiescent: u64,
        runs: u64,
        seed: u64,
    ) -> Option<String> {
        let own_length = self.default_max_time.is_some_and(|d| max_time <= d);
        let clock = self
            .model
            .machine_id(crate::robot::ros::GLOBAL_TIMER)
            .is_some();
        if !own_length || !clock || quiescent == 0 {
            return None;
        }
        let mut replay = format!(
            "hindsight trace {} --run K --seed {seed}",
            self.options.model.display()
        );
        match self.options.bt {
            crate::robot::bt::BtSemantics::As2fm => {}
            crate::robot::bt::BtSemantics::Btcpp { tick } => {
                replay.push_str(" --bt btcpp");
                if tick == crate::robot::bt::BtTick::ExactlyOnce {
                    replay.push_str(" --bt-tick exactly-once");
                }
            }
        }
        if Some(max_time) != self.default_max_time {
            replay.push_str(&format!(" --max-time {max_time}"));
        }
        Some(format!(
            "note: {quiescent} of {runs} runs went quiet before the time horizon (nothing \
             could move and no timer was pending: a deadlock); `{replay}` says how run K \
             ended"
        ))
    }

    /// The run length in model steps: `arg` is model steps (`500`), or a duration
    /// (`100s`) when the model has a time unit; by default the main file's `max_time`,
    /// else 10,000 steps. The caller names its flag in front of an error.
    pub fn max_time(&self, arg: Option<&str>) -> Result<u64, MaxTimeError> {
        use codegen::duration::StepsOrDuration;
        let Some(text) = arg else {
            return Ok(self.default_max_time.unwrap_or(10_000));
        };
        let steps = match codegen::duration::parse_steps_or_duration(text)
            .map_err(MaxTimeError::Unreadable)?
        {
            StepsOrDuration::Steps(v) => v,
            StepsOrDuration::Nanos(ns) => match self.unit_ns {
                Some(unit) if ns % unit == 0 => ns / unit,
                Some(unit_ns) => {
                    return Err(MaxTimeError::NotWholeSteps {
                        text: text.trim().to_owned(),
                        unit_ns,
                    })
                }
                None => return Err(MaxTimeError::NoTimeUnit(text.trim().to_owned())),
            },
        };
        if steps == 0 {
            return Err(MaxTimeError::Zero(text.trim().to_owned()));
        }
        Ok(steps)
    }
}

/// Loads the model and its properties: a robot model (a main file, or a folder holding
/// `main.xml`) through the robot pipeline, anything else as plain SCXML.
pub fn load(opts: &LoadOptions) -> Result<Loaded, LoadError> {
    load_without(opts, &[]).map(|(l, _)| l)
}

/// [`load`] without the robot model's node models named in `external`, which processes
/// play instead (`hindsight run --external`); what each declared comes back with it.
pub fn load_without(
    opts: &LoadOptions,
    external: &[String],
) -> Result<(Loaded, Vec<ExternalComponent>), LoadError> {
    if let Some(main) = crate::robot::load::main_file_of(&opts.model) {
        return load_robot(opts, &main, external);
    }
    if let Some(dir) = opts.interfaces.first() {
        return Err(LoadError::option(
            format!("--interfaces {}", dir.display()),
            format!(
                "{} is not a robot model (a main file, or a folder with main.xml); only a \
                 robot model reads ROS interfaces",
                opts.model.display()
            ),
        ));
    }
    if opts.bt != crate::robot::bt::BtSemantics::As2fm {
        return Err(LoadError::option(
            format!("--bt {}", opts.bt.label()),
            format!(
                "{} is not a robot model (a main file, or a folder with main.xml); only a \
                 robot model's behavior tree has a BehaviorTree.CPP semantics",
                opts.model.display()
            ),
        ));
    }
    if let Some(name) = external.first() {
        return Err(LoadError::option(
            format!("--external {name}"),
            format!(
                "{} is not a robot model (a main file, or a folder with main.xml); only a \
                 robot model's node models can be replaced by processes",
                opts.model.display()
            ),
        ));
    }
    let model = &opts.model;
    let unit_ns = opts.time_unit_ns;
    // The time unit converts the durations of `<send delay>` into steps.
    let mut source = crate::model::load(model)?;
    source.time_unit_ns = unit_ns;
    let compiled = CompiledModel::compile(source)?;
    let mut warnings = as_warnings(compiled.warnings());
    let (props_path, no_props) = match &opts.props {
        Some(p) => (p.to_path_buf(), None),
        None => match default_props(model, &compiled) {
            Ok(p) => (p, None),
            Err(LoadError::Files { diagnostics, .. }) if opts.props_optional => {
                let why = diagnostics.iter().map(|d| d.message.clone()).collect();
                (PathBuf::new(), Some(why))
            }
            Err(e) => return Err(e),
        },
    };
    let file = match no_props {
        None => read_properties(&props_path, &compiled, opts)?,
        Some(_) => no_properties(),
    };
    let set = compile_properties(&file, &compiled, unit_ns)?;
    warnings.extend(set.warnings().clone());
    let events = opts.events.unwrap_or_else(|| default_events(&props_path));
    Ok((
        Loaded {
            model: compiled,
            file,
            set,
            props_path,
            unit_ns,
            default_max_time: None,
            events,
            bt_notes: Vec::new(),
            warnings,
            options: opts.clone(),
            no_props,
        },
        Vec::new(),
    ))
}

/// Reads a property file: JANI (`.jani`) or SCAN XML (with ROS ports and patterns).
/// Reads the property file, keeping the guarantees `--only` / `--skip` select.
fn read_properties(
    path: &Path,
    model: &CompiledModel,
    opts: &LoadOptions,
) -> Result<props::PropertyFile, LoadError> {
    let wanted = |name: &str| {
        (opts.only.is_empty() || opts.only.iter().any(|o| o == name))
            && !opts.skip.iter().any(|s| s == name)
    };
    let unknown_name = |names: &[String]| {
        for (option, given) in [("--only", &opts.only), ("--skip", &opts.skip)] {
            if let Some(missing) = given.iter().find(|n| !names.contains(n)) {
                return Err(LoadError::option(
                    format!("{option} {missing}"),
                    format!(
                        "{} has no property `{missing}` (properties: {})",
                        path.display(),
                        names.join(", ")
                    ),
                ));
            }
        }
        Ok(())
    };
    let file = if is_jani(path) {
        // The reader sees every property's name, skipped or not.
        let mut names = Vec::new();
        let read = props::jani::parse_file_selected(path, model, &mut |name| {
            names.push(name.to_string());
            wanted(name)
        });
        // A misspelt name comes before what the properties it kept say (a file that is
        // not JSON at all names nothing: its own error comes first then).
        if read.is_ok() || !names.is_empty() {
            unknown_name(&names)?;
        }
        read.map_err(|d| {
            // A property using what is not supported need not stop the others.
            let hint = d
                .to_string()
                .contains("not supported")
                .then_some("--skip NAME leaves a property out, --only NAME checks just that one");
            LoadError::Files {
                diagnostics: props_diagnostics(d),
                hint,
            }
        })?
    } else {
        let mut file =
            props::parse_file(path).map_err(|d| LoadError::from(props_diagnostics(d)))?;
        let names: Vec<String> = file.guarantees.iter().map(|g| g.id.clone()).collect();
        unknown_name(&names)?;
        file.guarantees.retain(|g| wanted(&g.id));
        file
    };
    if file.guarantees.is_empty() && !(opts.only.is_empty() && opts.skip.is_empty()) {
        return Err(LoadError::option(
            "--only/--skip",
            format!("no property of {} is left to check", path.display()),
        ));
    }
    Ok(file)
}

/// Compiles a property file against a model; a bound with a unit on a model without one
/// gets a hint.
fn compile_properties(
    file: &props::PropertyFile,
    model: &CompiledModel,
    unit_ns: Option<u64>,
) -> Result<PropertySet, LoadError> {
    PropertySet::with_unit(file, model, unit_ns).map_err(|diagnostics| {
        let no_unit = unit_ns.is_none()
            && diagnostics
                .iter()
                .any(|d| d.message.contains("no known duration"));
        LoadError::Files {
            diagnostics,
            hint: no_unit.then_some(
                "give the length of one model step with --time-unit (for example \
                 --time-unit 100ms)",
            ),
        }
    })
}

/// A property reader's errors, their kinds as messages.
pub(crate) fn props_diagnostics(d: props::Diagnostics) -> Diagnostics {
    d.into_iter()
        .map(|e| e.map(|kind| kind.to_string()))
        .collect::<Vec<_>>()
        .into()
}

/// A reader's warnings (kept as diagnostics of their own) as warnings.
fn as_warnings(found: &[Diagnostic]) -> Diagnostics {
    found
        .iter()
        .cloned()
        .map(Diagnostic::warning)
        .collect::<Vec<_>>()
        .into()
}

/// Checks that every ROS type the property file's ports name is an interface the robot
/// model `main` can see (found as the model's own are: `--interfaces`, beside and above
/// it, the ROS workspace, the built-ins), of the port's kind; errors at the `type`
/// attribute. A port's type is not otherwise used (its messages are found by name), so
/// a typo here would pass silently.
fn check_ros_types(
    file: &props::PropertyFile,
    main: &Path,
    search: &crate::robot::interfaces::Search,
) -> Result<(), Diagnostics> {
    use crate::robot::interfaces::{InterfaceKind, Interfaces};
    if file.ros_types.is_empty() {
        return Ok(());
    }
    let mut sm = crate::model::SourceMap::new();
    // The model loaded, so its interfaces were found and checked already.
    let Ok(interfaces) = Interfaces::discover_with(&mut sm, main, search) else {
        return Ok(());
    };
    let errors: Vec<Diagnostic> = file
        .ros_types
        .iter()
        .filter_map(|t| {
            let kind = if t.service {
                InterfaceKind::Service
            } else {
                InterfaceKind::Message
            };
            let e = interfaces.get(&t.type_name, kind).err()?;
            Some(Diagnostic::error(
                file.path.display().to_string(),
                (t.at.line, t.at.column),
                format!("port type: {e}"),
            ))
        })
        .collect();
    Diagnostics(errors).into_result(())
}

/// Loads a robot model: the main file and everything it names, lowered and compiled; the
/// properties are the file given, else the first one the main file names.
fn load_robot(
    opts: &LoadOptions,
    main: &Path,
    external: &[String],
) -> Result<(Loaded, Vec<ExternalComponent>), LoadError> {
    use crate::robot::main_file::InputKind;
    let search = crate::robot::interfaces::Search::from_env(opts.interfaces.clone());
    let (robot, external) =
        crate::robot::load::load_searching_bt(main, external, &search, opts.bt)?;
    if opts.bt != crate::robot::bt::BtSemantics::As2fm && robot.main.behavior_tree.is_none() {
        return Err(LoadError::option(
            format!("--bt {}", opts.bt.label()),
            format!("{} has no behavior tree", main.display()),
        ));
    }
    let mut warnings = as_warnings(&robot.warnings);
    if let Some(given) = opts.time_unit_ns {
        if given != robot.time_unit_ns {
            return Err(LoadError::option(
                format!("--time-unit {}", codegen::duration::seconds(given)),
                format!(
                    "{} steps by {}, from its timers and max_time",
                    main.display(),
                    codegen::duration::seconds(robot.time_unit_ns)
                ),
            ));
        }
    }
    let mut no_props = None;
    let props_path = match (&opts.props, robot.main.properties.first()) {
        (Some(p), _) => p.clone(),
        (None, Some(input)) => {
            if input.kind == InputKind::Hspec {
                return Err(LoadError::about_file(
                    &input.path,
                    "an .hspec file names no messages of the model; write the properties \
                     over ROS names (XML) or give them on the command line",
                ));
            }
            input.path.clone()
        }
        (None, None) if opts.props_optional => {
            no_props = Some(format!(
                "{}: the main file names no property file",
                main.display()
            ));
            PathBuf::new()
        }
        (None, None) => {
            return Err(LoadError::about_file(
                main,
                "the main file names no property file; give one after the model",
            ))
        }
    };
    let file = match &no_props {
        None => read_properties(&props_path, &robot.model, opts)?,
        Some(_) => no_properties(),
    };
    check_ros_types(&file, main, &search)?;
    let set = compile_properties(&file, &robot.model, Some(robot.time_unit_ns))?;
    warnings.extend(set.warnings().clone());
    warnings.extend(unitless_bounds(&file, robot.time_unit_ns));
    Ok((
        Loaded {
            model: robot.model,
            file,
            set,
            props_path,
            unit_ns: Some(robot.time_unit_ns),
            default_max_time: Some(robot.max_time_steps),
            bt_notes: robot.bt_notes.iter().map(|d| d.to_string()).collect(),
            // The lowering is AS2FM's translation; its sends mean what AS2FM's JANI means.
            events: opts.events.unwrap_or(EventSemantics::As2fm),
            warnings,
            options: opts.clone(),
            no_props,
        },
        external,
    ))
}

/// A warning at each time bound of a robot model's properties written without a unit
/// (`once[8:]`): it counts model steps, and a robot model's step is the common period of
/// its timers (`robot::ros::gen`, `global_timer`), which the user never writes and which
/// changes when a timer does (a 5 Hz timer made 10 Hz halves every such bound).
fn unitless_bounds(file: &props::PropertyFile, unit_ns: u64) -> Diagnostics {
    let mut out = Vec::new();
    for p in file.guarantees.iter().chain(&file.assumptions) {
        for (at, bound) in codegen::bounds::unitless_ends(p.formula.as_str()) {
            let here = p.formula.location(at);
            let steps: u64 = bound.parse().unwrap_or(0);
            out.push(Diagnostic::warning(Diagnostic::error(
                file.path.display().to_string(),
                (here.line, here.column),
                format!(
                    "property `{}`: the bound `{bound}` has no unit, so it counts model steps, \
                     here of {} (the common period of the model's timers): {bound} steps = {}; \
                     write it as a duration so that it keeps its meaning when a timer changes",
                    p.id,
                    codegen::duration::seconds(unit_ns),
                    codegen::duration::seconds(steps.saturating_mul(unit_ns)),
                ),
            )));
        }
    }
    out.into()
}

/// The property file of a model loaded without one ([`LoadOptions::props_optional`]).
fn no_properties() -> props::PropertyFile {
    props::PropertyFile {
        path: PathBuf::new(),
        ports: Vec::new(),
        guarantees: Vec::new(),
        assumptions: Vec::new(),
        ros_types: Vec::new(),
    }
}
