//! `hindsight replay`: run a spec's or a property file's monitors over a recorded trace (our
//! CSV, or a ROS 2 recording: an MCAP file, a `.db3` file or a rosbag2 folder) and print
//! every verdict.
//!
//! # Properties
//!
//! `PROPS` is a `.hspec` spec or a property file (`properties.xml`, as `verify` reads
//! it). Over a recording, a property file's `<ros_topic>` and `<ros_service>` ports name
//! what they read; a `.hspec` spec's variables are bound with `--bind VAR=/topic.field`
//! (a state variable takes the field; `--bind VAR=/topic` makes `VAR` true at each
//! message of the topic) and `--bind VAR=/service:request.field` / `:response` for a
//! service's recorded events. A variable left unbound keeps its initial value.
//!
//! # Time
//!
//! A CSV row's `time` is in the spec's unit. A recording's message is at its log time
//! (or `--time header`: its `header.stamp`), in nanoseconds since the first message,
//! divided (rounding down) by the spec's unit: the `unit` line of a `.hspec`, or
//! `--time-unit` for a property file (default `1ns`: no rounding), whose bounds with a
//! unit (`within="1" time_unit="s"`, `[6.2s:]`) are converted exactly to it, as `verify`
//! converts them to a model's unit.

use crate::{codegen, monitor_core, ros2};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Instant;

use codegen::Compiled;
use monitor_core::{valuation, Monitor, Value};
use ros2::feed::{Port as BagPort, Read, ServiceSide, TimeSource};

use super::{compile_spec_file, read_file, CliError};
use crate::props::{PortKind, PropertyFile};
use crate::verify::tracefile;

/// Arguments of `hindsight replay`.
#[derive(Debug, clap::Args)]
pub struct ReplayArgs {
    /// The properties: a specification (`.hspec`) or a property file (`.xml`, with
    /// `<ros_topic>` / `<ros_service>` ports over a ROS 2 recording).
    pub spec: PathBuf,
    /// The trace: CSV with a `time` column and one column per variable set; or a ROS 2
    /// recording: an `.mcap` file, a `.db3` file, or a rosbag2 folder (with
    /// `metadata.yaml`).
    pub trace: PathBuf,
    /// Print only points where some verdict changes (and the first point).
    #[arg(long)]
    pub changes: bool,
    /// Print nothing per point; report the time per point on standard error.
    #[arg(long)]
    pub quiet: bool,
    /// A recording's message time: `log` (when it was recorded) or `header` (its
    /// `header.stamp`).
    #[arg(long, value_enum, default_value = "log")]
    pub time: TimeArg,
    /// The time unit of a property file's monitors (`1ns`, `1ms`, `100ms`): CSV times are
    /// in it, a recording's times are rounded down to it. Default `1ns`.
    #[arg(long, value_name = "DURATION")]
    pub time_unit: Option<String>,
    /// For a `.hspec` over a recording: bind variable VAR to `/topic.field.path`,
    /// `/topic` (true at each message), or `/service:request.field` (`:response`).
    #[arg(long = "bind", value_name = "VAR=SOURCE")]
    pub bind: Vec<String>,
    /// A folder of ROS interface packages (DIR/PKG/msg/*.msg) for recordings that do not
    /// embed their types (`.db3`); repeat for more. Searched before the folders beside and
    /// above PROPS, the sourced ROS workspace (AMENT_PREFIX_PATH) and the built-ins.
    #[arg(long = "interfaces", value_name = "DIR")]
    pub interfaces: Vec<PathBuf>,
}

/// Where a recording's message times come from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum TimeArg {
    /// The recording's log (receive) time.
    Log,
    /// The message's `header.stamp`.
    Header,
}

/// Whether `path` is a ROS 2 recording rather than a CSV trace.
fn is_recording(path: &Path) -> bool {
    path.is_dir()
        || matches!(
            path.extension().and_then(|e| e.to_str()),
            Some("mcap" | "db3")
        )
        || path.file_name().is_some_and(|n| n == "metadata.yaml")
}

/// The compiled properties and, for a property file, its ports.
pub(crate) struct Props {
    pub(crate) compiled: Compiled,
    pub(crate) file: Option<PropertyFile>,
}

fn load_props(args: &ReplayArgs) -> Result<Props, CliError> {
    load_props_at(
        &args.spec,
        args.time_unit.as_deref(),
        1,
        !args.bind.is_empty(),
    )
}

/// Loads `PROPS` (a `.hspec` or a property file over ROS names). A property file's unit
/// is `time_unit`, else `default_unit_ns`; `bind` says `--bind` was given (only for a
/// `.hspec`). Shared by `replay` and `monitor --ros2`.
pub(crate) fn load_props_at(
    spec: &Path,
    time_unit: Option<&str>,
    default_unit_ns: u64,
    bind: bool,
) -> Result<Props, CliError> {
    let hspec = spec.extension().is_some_and(|e| e == "hspec");
    if hspec {
        if time_unit.is_some() {
            return Err(CliError::Input(
                "--time-unit is for a property file; a .hspec names its unit with a `unit` line"
                    .into(),
            ));
        }
        return Ok(Props {
            compiled: compile_spec_file(spec)?,
            file: None,
        });
    }
    if bind {
        return Err(CliError::Input(
            "--bind is for a .hspec spec; a property file's ports name their topics".into(),
        ));
    }
    let unit_ns = match time_unit {
        None => default_unit_ns,
        Some(t) => match codegen::duration::parse(t) {
            Ok(ns) if ns > 0 => ns,
            Ok(_) => {
                return Err(CliError::Input(format!(
                    "--time-unit {t}: expected a positive duration (1ns, 1ms, 100ms)"
                )))
            }
            Err(m) => return Err(CliError::Input(format!("--time-unit {t}: {m}"))),
        },
    };
    let file = crate::props::parse_file(spec).map_err(|d| CliError::Input(d.to_string()))?;
    let input = crate::verify::observe::spec_input(&file, Some(unit_ns), |_, _, _, t| t)?;
    let compiled = codegen::compile_input(&input).map_err(|d| CliError::Input(d.to_string()))?;
    if !compiled.warnings().is_empty() {
        eprint!("{}", compiled.warnings());
    }
    Ok(Props {
        compiled,
        file: Some(file),
    })
}

/// A ROS name from the name AS2FM's translation gives it inside event names
/// (`topic_a__b_msg` -> `/a/b`; ROS names never hold `__`).
fn ros_name(mangled: &str) -> String {
    format!("/{}", mangled.replace("__", "/"))
}

/// The recording ports of a property file's ROS ports.
pub(crate) fn file_ports(
    file: &PropertyFile,
    compiled: &Compiled,
) -> Result<Vec<BagPort>, CliError> {
    let shown = file.path.display();
    let mut out = Vec::new();
    for p in &file.ports {
        let here = format!("{shown}:{}:{}: port `{}`", p.at.line, p.at.column, p.id);
        let (topic, service) = if let Some(t) = p
            .event
            .strip_prefix("topic_")
            .and_then(|t| t.strip_suffix("_msg"))
        {
            (ros_name(t), None)
        } else if let Some(s) = p
            .event
            .strip_prefix("srv_")
            .and_then(|t| t.strip_suffix("_request"))
        {
            (ros_name(s), Some(ServiceSide::Request))
        } else if let Some(s) = p
            .event
            .strip_prefix("srv_")
            .and_then(|t| t.strip_suffix("_response"))
        {
            (ros_name(s), Some(ServiceSide::Response))
        } else {
            return Err(CliError::Input(format!(
                "{here}: observes the model message `{}`, not a ROS topic or service; a recording holds only topics (write the port as <ros_topic> or <ros_service>)",
                p.event
            )));
        };
        let read = match &p.kind {
            PortKind::Event => Read::Event,
            PortKind::State { param, .. } => {
                let field = param.strip_prefix("ros_fields__").unwrap_or(param);
                Read::Field(field.replace("__", "."))
            }
            PortKind::Sent | PortKind::Part { .. } => {
                return Err(CliError::Input(format!(
                    "{here}: a JANI port kind, which a recording cannot feed"
                )))
            }
        };
        let var = compiled
            .var_index(&p.id)
            .ok_or_else(|| CliError::Failed(format!("{here}: internal: not compiled")))?;
        out.push(BagPort {
            var,
            ty: compiled.vars()[var].ty,
            topic,
            read,
            service,
            name: p.id.clone(),
        });
    }
    Ok(out)
}

/// The recording ports of `--bind VAR=SOURCE` options.
pub(crate) fn bind_ports(binds: &[String], compiled: &Compiled) -> Result<Vec<BagPort>, CliError> {
    let mut out: Vec<BagPort> = Vec::new();
    for b in binds {
        let bad = |m: &str| CliError::Input(format!("--bind {b}: {m}"));
        let Some((var_name, source)) = b.split_once('=') else {
            return Err(bad(
                "expected VAR=/topic.field, VAR=/topic or VAR=/service:request.field",
            ));
        };
        let Some(var) = compiled.var_index(var_name.trim()) else {
            return Err(bad(&format!(
                "`{}` is not a variable of the spec",
                var_name.trim()
            )));
        };
        if out.iter().any(|p| p.var == var) {
            return Err(bad("the variable is bound twice"));
        }
        let decl = &compiled.vars()[var];
        let source = source.trim();
        if !source.starts_with('/') {
            return Err(bad("a source starts with `/` (a ROS name)"));
        }
        let (topic, service, field) = if let Some((name, rest)) = source.split_once(':') {
            let (side, field) = rest.split_once('.').unwrap_or((rest, ""));
            let side = match side {
                "request" => ServiceSide::Request,
                "response" => ServiceSide::Response,
                _ => return Err(bad("after `:` comes `request` or `response`")),
            };
            (name.to_string(), Some(side), field.to_string())
        } else {
            // The topic runs to the first `.` after its last `/`.
            let last_slash = source.rfind('/').unwrap_or(0);
            match source[last_slash..].find('.') {
                Some(i) => (
                    source[..last_slash + i].to_string(),
                    None,
                    source[last_slash + i + 1..].to_string(),
                ),
                None => (source.to_string(), None, String::new()),
            }
        };
        let read = if field.is_empty() {
            if decl.kind != monitor_core::VarKind::Event {
                return Err(bad(&format!(
                    "`{}` is a state variable: name the field it takes (`{source}.data`)",
                    decl.name
                )));
            }
            Read::Event
        } else {
            Read::Field(field)
        };
        out.push(BagPort {
            var,
            ty: decl.ty,
            topic,
            read,
            service,
            name: decl.name.clone(),
        });
    }
    Ok(out)
}

/// The interface packages for types a recording does not embed: `--interfaces`, the
/// folders beside and above PROPS, the sourced workspace, the built-ins.
pub(crate) struct Packages(pub(crate) crate::robot::interfaces::Interfaces);

/// The interface packages found for `path` (beside and above it, `--interfaces`,
/// `AMENT_PREFIX_PATH`, the built-ins); a package that does not read is an input error.
pub(crate) fn discover_packages(
    path: &Path,
    interfaces: Vec<PathBuf>,
) -> Result<crate::robot::interfaces::Interfaces, CliError> {
    let mut sm = codegen::diag::SourceMap::new();
    let search = crate::robot::interfaces::Search::from_env(interfaces);
    crate::robot::interfaces::Interfaces::discover_with(&mut sm, path, &search).map_err(|errs| {
        CliError::Input(
            errs.iter()
                .map(|d| d.to_string())
                .collect::<Vec<_>>()
                .join("\n"),
        )
    })
}

impl ros2::schema::Definitions for Packages {
    fn message(&self, package: &str, name: &str) -> Option<ros2::interface::MessageDef> {
        use crate::robot::interfaces::InterfaceKind;
        let d = self
            .0
            .get(&format!("{package}/{name}"), InterfaceKind::Message)
            .ok()?;
        d.parts.first().cloned()
    }

    fn service(
        &self,
        package: &str,
        name: &str,
    ) -> Option<(ros2::interface::MessageDef, ros2::interface::MessageDef)> {
        use crate::robot::interfaces::InterfaceKind;
        let d = self
            .0
            .get(&format!("{package}/{name}"), InterfaceKind::Service)
            .ok()?;
        Some((d.parts.first()?.clone(), d.parts.get(1)?.clone()))
    }
}

/// Runs `hindsight replay`: output is CSV `time,PROP,...` with `true`/`false`.
pub fn run(args: &ReplayArgs) -> Result<(), CliError> {
    let props = load_props(args)?;
    let compiled = &props.compiled;
    let program = compiled.program();
    let monitor = Monitor::try_new(program)
        .map_err(|e| CliError::Failed(format!("internal: compiled program rejected: {e}")))?;
    let mut state = vec![0u64; monitor.state_words()];
    let mut vals = vec![Value::Bool(false); program.vars.len()];
    valuation::init(program.vars, &mut vals);
    let mut verdicts = vec![false; monitor.properties()];
    let mut rows: Vec<(u64, Vec<bool>)> = Vec::new();
    let mut points = 0usize;
    let start;
    {
        let mut step = |time: u64,
                        sets: &[(usize, Value)]|
         -> Result<(), monitor_core::StepError> {
            valuation::begin_point(program.vars, &mut vals);
            for &(var, v) in sets {
                vals[var] = v;
            }
            monitor.try_step(&mut state, time, &vals, &mut verdicts)?;
            points += 1;
            if !args.quiet && (!args.changes || rows.last().is_none_or(|(_, v)| *v != verdicts)) {
                rows.push((time, verdicts.clone()));
            }
            Ok(())
        };
        if is_recording(&args.trace) {
            let ports = match &props.file {
                Some(f) => file_ports(f, compiled)?,
                None => bind_ports(&args.bind, compiled)?,
            };
            if ports.is_empty() {
                eprintln!(
                    "warning: {}: no variable reads the recording (a .hspec binds them with --bind VAR=/topic.field): every variable keeps its initial value",
                    args.spec.display()
                );
            }
            let packages = discover_packages(&args.spec, args.interfaces.clone())?;
            let time = match args.time {
                TimeArg::Log => TimeSource::Log,
                TimeArg::Header => TimeSource::Header,
            };
            let tick = compiled.tick_ns().max(1);
            start = Instant::now();
            let summary = ros2::feed::replay(
                &args.trace,
                &ports,
                &Packages(packages),
                time,
                compiled.strings(),
                &mut |p| step(p.time_ns / tick, p.sets),
            )
            .map_err(|e| {
                // Exit 2 naming the file, the topic and the message's index on it.
                CliError::Input(e.map_point(|s| compiled.describe(&s)).to_string())
            })?;
            for p in &ports {
                let topic = p.recorded_topic();
                if !summary.topics.iter().any(|(t, _)| *t == topic) {
                    eprintln!(
                        "warning: {}: no message on `{topic}`: `{}` keeps its initial value",
                        args.trace.display(),
                        p.name
                    );
                }
            }
        } else {
            if args.time != TimeArg::Log || !args.bind.is_empty() || !args.interfaces.is_empty() {
                return Err(CliError::Input(
                    "--time, --bind and --interfaces are for a ROS 2 recording, not a CSV trace"
                        .into(),
                ));
            }
            let text = read_file(&args.trace)?;
            let trace = tracefile::parse_csv(&text, &args.trace.display().to_string(), compiled)?;
            start = Instant::now();
            for (i, p) in trace.iter().enumerate() {
                step(p.time, &p.sets).map_err(|e| {
                    CliError::Input(format!(
                        "{}:{}: point {}: {}",
                        args.trace.display(),
                        p.line,
                        i + 1,
                        compiled.describe(&e)
                    ))
                })?;
            }
        }
    }
    let elapsed = start.elapsed();
    if args.quiet {
        let per = elapsed.as_nanos() as f64 / points.max(1) as f64;
        eprintln!(
            "{points} points, {per:.1} ns per point, {} bytes of state",
            monitor.state_bytes()
        );
        return Ok(());
    }
    let mut out = std::io::BufWriter::new(std::io::stdout().lock());
    let io = |e: std::io::Error| CliError::Failed(format!("standard output: {e}"));
    let names: Vec<&str> = compiled.property_names().collect();
    writeln!(out, "time,{}", names.join(",")).map_err(io)?;
    for (t, v) in rows {
        let cells: Vec<&str> = v
            .iter()
            .map(|b| if *b { "true" } else { "false" })
            .collect();
        writeln!(out, "{t},{}", cells.join(",")).map_err(io)?;
    }
    out.flush().map_err(io)
}
