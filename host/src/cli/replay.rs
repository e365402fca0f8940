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
//! `--time-unit` for a property file (default: the unit a CSV trace names on a leading
//! `# time unit:` line, as `trace` writes it for a model with a unit, else `1ns`: no
//! rounding), whose bounds with a unit (`within="1" time_unit="s"`, `[6.2s:]`) are
//! converted exactly to it, as `verify` converts them to a model's unit.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Instant;

use super::{compile_spec_file, print_spec_warnings, read_file, CliError};
use crate::codegen::{self, Compiled};
use crate::live::recording::{self, bind_ports, file_ports, is_recording, MessageTime, Packages};
use crate::verify::spec::PropertyFile;
use crate::verify::trace_judge::{Keep, TraceJudge};
use crate::verify::{spec, tracefile};

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
    /// in it, a recording's times are rounded down to it. Default: the unit a CSV trace
    /// names on a `# time unit:` line (`hindsight trace` writes it), else `1ns`.
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

/// The compiled properties and, for a property file, its ports.
pub(crate) struct Props {
    pub(crate) compiled: Compiled,
    pub(crate) file: Option<PropertyFile>,
}

fn load_props(args: &ReplayArgs, csv_unit: Option<&str>) -> Result<Props, CliError> {
    let hspec = args.spec.extension().is_some_and(|e| e == "hspec");
    // A trace `hindsight trace` wrote says its unit; a property file's bounds in seconds
    // read it in that unit, unless --time-unit says another (then the times would mean
    // something else: refused).
    let time_unit = match (args.time_unit.as_deref(), csv_unit) {
        (Some(given), Some(written)) if !hspec => {
            let same =
                codegen::duration::parse(given).ok() == codegen::duration::parse(written).ok();
            if !same {
                return Err(CliError::Input(format!(
                    "--time-unit {given}: {} says its times are in units of {written} (its \
                     `# time unit` line); drop --time-unit",
                    args.trace.display()
                )));
            }
            Some(given)
        }
        (None, Some(written)) if !hspec => Some(written),
        (given, _) => given,
    };
    load_props_at(&args.spec, time_unit, 1, !args.bind.is_empty())
}

/// The unit a CSV trace names in a leading `# time unit: 200ms` comment (what `hindsight
/// trace` and `--save-failing` write for a model with a time unit).
fn csv_time_unit(text: &str) -> Option<&str> {
    text.trim_start_matches('\u{feff}')
        .lines()
        .take_while(|l| l.trim_start().starts_with('#') || l.trim().is_empty())
        .find_map(|l| l.trim_start().strip_prefix("# time unit:"))
        .map(str::trim)
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
    let spec::PropertyMonitors { file, compiled } = spec::compile_property_file(spec, unit_ns)?;
    print_spec_warnings(&compiled);
    Ok(Props {
        compiled,
        file: Some(file),
    })
}

/// Runs `hindsight replay`: output is CSV `time,PROP,...` with `true`/`false`.
pub fn run(args: &ReplayArgs) -> Result<(), CliError> {
    let recording = is_recording(&args.trace);
    let csv_text = if recording {
        None
    } else {
        Some(read_file(&args.trace)?)
    };
    let props = load_props(args, csv_text.as_deref().and_then(csv_time_unit))?;
    let compiled = &props.compiled;
    let keep = if args.quiet {
        Keep::Nothing
    } else if args.changes {
        Keep::Changes
    } else {
        Keep::All
    };
    let mut judge = TraceJudge::new(compiled, keep)
        .map_err(|e| CliError::Failed(format!("internal: compiled program rejected: {e}")))?;
    let start;
    if recording {
        let ports = match &props.file {
            Some(f) => file_ports(f, compiled).map_err(|e| {
                if e.is_internal() {
                    CliError::Failed(e.to_string())
                } else {
                    CliError::Input(e.to_string())
                }
            })?,
            None => bind_ports(&args.bind, compiled).map_err(|e| CliError::Input(e.to_string()))?,
        };
        if ports.is_empty() {
            eprintln!(
                "warning: {}: no variable reads the recording (a .hspec binds them with --bind VAR=/topic.field): every variable keeps its initial value",
                args.spec.display()
            );
        }
        let packages = Packages::discover(&args.spec, args.interfaces.clone())
            .map_err(|e| CliError::Input(e.to_string()))?;
        let time = match args.time {
            TimeArg::Log => MessageTime::Log,
            TimeArg::Header => MessageTime::Header,
        };
        start = Instant::now();
        let replayed = recording::replay(
            &args.trace,
            &ports,
            &packages,
            time,
            compiled,
            &mut |t, sets| judge.step(t, sets),
        )
        // Exit 2 naming the file, the topic and the message's index on it.
        .map_err(|e| CliError::Input(e.to_string()))?;
        for (topic, var) in &replayed.silent {
            eprintln!(
                "warning: {}: no message on `{topic}`: `{var}` keeps its initial value",
                args.trace.display(),
            );
        }
    } else {
        if args.time != TimeArg::Log || !args.bind.is_empty() || !args.interfaces.is_empty() {
            return Err(CliError::Input(
                "--time, --bind and --interfaces are for a ROS 2 recording, not a CSV trace".into(),
            ));
        }
        let text = csv_text.unwrap_or_default();
        let name = args.trace.display().to_string();
        let trace = tracefile::parse_csv(&text, &name, compiled)?;
        start = Instant::now();
        judge
            .judge_csv(&trace, &name)
            .map_err(|e| CliError::Input(e.describe(compiled)))?;
    }
    let elapsed = start.elapsed();
    let points = judge.points();
    if args.quiet {
        let per = elapsed.as_nanos() as f64 / points.max(1) as f64;
        eprintln!(
            "{points} points, {per:.1} ns per point, {} bytes of state",
            judge.state_bytes()
        );
        return Ok(());
    }
    let mut out = std::io::BufWriter::new(std::io::stdout().lock());
    let io = |e: std::io::Error| CliError::Failed(format!("standard output: {e}"));
    let names: Vec<&str> = compiled.property_names().collect();
    writeln!(out, "time,{}", names.join(",")).map_err(io)?;
    for (t, v) in judge.rows() {
        let cells: Vec<&str> = v
            .iter()
            .map(|b| if *b { "true" } else { "false" })
            .collect();
        writeln!(out, "{t},{}", cells.join(",")).map_err(io)?;
    }
    out.flush().map_err(io)
}
