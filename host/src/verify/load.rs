//! Loading a model and its properties: the first stage of every command that checks a model.
//!
//! [`load`] takes a plain [`LoadOptions`] (the command line builds it from its
//! arguments): a robot model (a main file, or a folder holding `main.xml`) goes
//! through the robot pipeline, anything else is read as plain SCXML; the property
//! file (given, named by the model, or found beside it) is read, filtered by
//! `only` / `skip`, and compiled against the model into a [`PropertySet`].

use std::path::{Path, PathBuf};

use super::observe::PropertySet;
use crate::props;
use crate::robot::load::ExternalComponent;
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
}

/// The event semantics for a property file when none is asked for: AS2FM's for a JANI
/// property file (the model is then AS2FM's plain SCXML), SCAN's queues otherwise.
pub fn default_events(props_path: &Path) -> EventSemantics {
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

/// Finds the property file for a model when none is given.
fn default_props(model: &Path, compiled: &CompiledModel) -> Result<PathBuf, String> {
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
    Err(format!(
        "{}: no property file given and none found (looked for {} and a single .jani file)",
        model.display(),
        p.display()
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
}

impl Loaded {
    /// The run length in model steps: `arg` is model steps (`500`), or a duration
    /// (`100s`) when the model has a time unit; by default the main file's `max_time`,
    /// else 10,000 steps. The caller names its flag in front of an error.
    pub fn max_time(&self, arg: Option<&str>) -> Result<u64, String> {
        use codegen::duration::StepsOrDuration;
        let Some(text) = arg else {
            return Ok(self.default_max_time.unwrap_or(10_000));
        };
        match codegen::duration::parse_steps_or_duration(text)? {
            StepsOrDuration::Steps(v) => Ok(v),
            StepsOrDuration::Nanos(ns) => match self.unit_ns {
                Some(unit) if ns % unit == 0 => Ok(ns / unit),
                Some(unit) => Err(format!(
                    "{} is not a whole number of model steps of {}",
                    text.trim(),
                    codegen::duration::format(unit)
                )),
                None => Err(format!(
                    "{} is a duration but the model has no time unit (give --time-unit, \
                     or the length in steps)",
                    text.trim()
                )),
            },
        }
    }
}

/// Loads the model and its properties: a robot model (a main file, or a folder holding
/// `main.xml`) through the robot pipeline, anything else as plain SCXML.
pub fn load(opts: &LoadOptions) -> Result<Loaded, String> {
    load_without(opts, &[]).map(|(l, _)| l)
}

/// [`load`] without the robot model's node models named in `external`, which processes
/// play instead (`hindsight run --external`); what each declared comes back with it.
pub fn load_without(
    opts: &LoadOptions,
    external: &[String],
) -> Result<(Loaded, Vec<ExternalComponent>), String> {
    if let Some(main) = crate::robot::load::main_file_of(&opts.model) {
        return load_robot(opts, &main, external);
    }
    if let Some(dir) = opts.interfaces.first() {
        return Err(format!(
            "--interfaces {}: {} is not a robot model (a main file, or a folder with \
             main.xml); only a robot model reads ROS interfaces",
            dir.display(),
            opts.model.display()
        ));
    }
    if opts.bt != crate::robot::bt::BtSemantics::As2fm {
        return Err(format!(
            "--bt {}: {} is not a robot model (a main file, or a folder with main.xml); \
             only a robot model's behavior tree has a BehaviorTree.CPP semantics",
            opts.bt.label(),
            opts.model.display()
        ));
    }
    if let Some(name) = external.first() {
        return Err(format!(
            "--external {name}: {} is not a robot model (a main file, or a folder with \
             main.xml); only a robot model's node models can be replaced by processes",
            opts.model.display()
        ));
    }
    let model = &opts.model;
    let unit_ns = opts.time_unit_ns;
    let compiled = CompiledModel::load(model).map_err(|d| d.to_string())?;
    print_warnings(compiled.warnings());
    let props_path = match &opts.props {
        Some(p) => p.to_path_buf(),
        None => default_props(model, &compiled)?,
    };
    let file = read_properties(&props_path, &compiled, opts)?;
    let set = compile_properties(&file, &compiled, unit_ns)?;
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
) -> Result<props::PropertyFile, String> {
    let wanted = |name: &str| {
        (opts.only.is_empty() || opts.only.iter().any(|o| o == name))
            && !opts.skip.iter().any(|s| s == name)
    };
    let unknown_name = |names: &[String]| {
        for (option, given) in [("--only", &opts.only), ("--skip", &opts.skip)] {
            if let Some(missing) = given.iter().find(|n| !names.contains(n)) {
                return Err(format!(
                    "{option} {missing}: {} has no property `{missing}` (properties: {})",
                    path.display(),
                    names.join(", ")
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
            let text = d.to_string();
            // A property using what is not supported need not stop the others.
            let hint = if text.contains("not supported") {
                "\nhint: --skip NAME leaves a property out, --only NAME checks just that one"
            } else {
                ""
            };
            format!("{text}{hint}")
        })?
    } else {
        let mut file = props::parse_file(path).map_err(|d| d.to_string())?;
        let names: Vec<String> = file.guarantees.iter().map(|g| g.id.clone()).collect();
        unknown_name(&names)?;
        file.guarantees.retain(|g| wanted(&g.id));
        file
    };
    if file.guarantees.is_empty() && !(opts.only.is_empty() && opts.skip.is_empty()) {
        return Err(format!(
            "--only/--skip leave no property of {} to check",
            path.display()
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
) -> Result<PropertySet, String> {
    PropertySet::with_unit(file, model, unit_ns).map_err(|e| {
        if unit_ns.is_none() && e.contains("no known duration") {
            format!(
                "{e}\nhint: give the length of one model step with --time-unit (for example \
                 --time-unit 100ms)"
            )
        } else {
            e
        }
    })
}

/// Prints a model's warnings to standard error: the first `codegen::diag::MAX_SHOWN`,
/// then how many more (a file with thousands of ignored attributes stays readable).
fn print_warnings<W: std::fmt::Display>(warnings: impl IntoIterator<Item = W>) {
    let mut more = 0usize;
    for (i, w) in warnings.into_iter().enumerate() {
        if i < codegen::diag::MAX_SHOWN {
            eprintln!("warning: {w}");
        } else {
            more += 1;
        }
    }
    if more > 0 {
        eprintln!("warning: ... and {more} more warnings");
    }
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
) -> Result<(), String> {
    use crate::robot::interfaces::{InterfaceKind, Interfaces};
    if file.ros_types.is_empty() {
        return Ok(());
    }
    let mut sm = crate::model::SourceMap::new();
    // The model loaded, so its interfaces were found and checked already.
    let Ok(interfaces) = Interfaces::discover_with(&mut sm, main, search) else {
        return Ok(());
    };
    let errors: Vec<String> = file
        .ros_types
        .iter()
        .filter_map(|t| {
            let kind = if t.service {
                InterfaceKind::Service
            } else {
                InterfaceKind::Message
            };
            let e = interfaces.get(&t.type_name, kind).err()?;
            Some(format!(
                "{}:{}:{}: port type: {e}",
                file.path.display(),
                t.at.line,
                t.at.column
            ))
        })
        .collect();
    if errors.is_empty() {
        Ok(())
    } else {
        Err(errors.join("\n"))
    }
}

/// Loads a robot model: the main file and everything it names, lowered and compiled; the
/// properties are the file given, else the first one the main file names.
fn load_robot(
    opts: &LoadOptions,
    main: &Path,
    external: &[String],
) -> Result<(Loaded, Vec<ExternalComponent>), String> {
    use crate::robot::main_file::InputKind;
    let search = crate::robot::interfaces::Search::from_env(opts.interfaces.clone());
    let (robot, external) = crate::robot::load::load_searching_bt(main, external, &search, opts.bt)
        .map_err(|d| d.to_string())?;
    if opts.bt != crate::robot::bt::BtSemantics::As2fm && robot.main.behavior_tree.is_none() {
        return Err(format!(
            "--bt {}: {} has no behavior tree",
            opts.bt.label(),
            main.display()
        ));
    }
    print_warnings(&robot.warnings);
    if let Some(given) = opts.time_unit_ns {
        if given != robot.time_unit_ns {
            return Err(format!(
                "--time-unit {}: {} steps by {}, from its timers and max_time",
                codegen::duration::seconds(given),
                main.display(),
                codegen::duration::seconds(robot.time_unit_ns)
            ));
        }
    }
    let props_path = match (&opts.props, robot.main.properties.first()) {
        (Some(p), _) => p.clone(),
        (None, Some(input)) => {
            if input.kind == InputKind::Hspec {
                return Err(format!(
                    "{}: an .hspec file names no messages of the model; write the \
                     properties over ROS names (XML) or give them on the command line",
                    input.path.display()
                ));
            }
            input.path.clone()
        }
        (None, None) => {
            return Err(format!(
                "{}: the main file names no property file; give one after the model",
                main.display()
            ))
        }
    };
    let file = read_properties(&props_path, &robot.model, opts)?;
    check_ros_types(&file, main, &search)?;
    let set = compile_properties(&file, &robot.model, Some(robot.time_unit_ns))?;
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
        },
        external,
    ))
}
