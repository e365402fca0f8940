//! Properties judged over ROS 2 recordings (`hindsight replay` over an MCAP file, a `.db3`
//! file or a rosbag2 folder) and the ports that read topics and services, which the live
//! DDS monitor (`monitor --ros2`, [`crate::readers`]) shares.
//!
//! A property file's `<ros_topic>` / `<ros_service>` ports ([`file_ports`]) or a `.hspec`
//! spec's `--bind VAR=SOURCE` options ([`bind_ports`]) say which variable reads which
//! topic or service field; [`Packages`] are the interface packages for types a recording
//! does not embed; [`replay`] turns each message into a point and hands it to the caller's
//! monitor. Nothing here prints: what a caller warns about comes back as values
//! ([`Replayed::silent`]).

use std::fmt;
use std::path::{Path, PathBuf};

use codegen::diag::{Diagnostic, SourceMap};
use codegen::Compiled;
use monitor_core::{StepError, Value};
use ros2::feed::{Port, Read, ReplayError, ServiceSide, TimeSource};

use crate::props::{PortKind, PropertyFile};
use crate::robot::interfaces::{InterfaceKind, Interfaces, Search};

/// Whether `path` is a ROS 2 recording (a folder, an `.mcap` or `.db3` file, or a
/// rosbag2 `metadata.yaml`) rather than a CSV trace.
///
/// ```
/// use hindsight_live::recording::is_recording;
/// use std::path::Path;
///
/// assert!(is_recording(Path::new("run.mcap")));
/// assert!(is_recording(Path::new("bag/metadata.yaml")));
/// assert!(!is_recording(Path::new("run.csv")));
/// ```
pub fn is_recording(path: &Path) -> bool {
    path.is_dir()
        || matches!(
            path.extension().and_then(|e| e.to_str()),
            Some("mcap" | "db3")
        )
        || path.file_name().is_some_and(|n| n == "metadata.yaml")
}

/// A ROS name from the name AS2FM's translation gives it inside event names
/// (`topic_a__b_msg` -> `/a/b`; ROS names never hold `__`).
fn ros_name(mangled: &str) -> String {
    format!("/{}", mangled.replace("__", "/"))
}

/// A property file's port that no recording can feed.
#[derive(Debug)]
pub enum PortError {
    /// The port observes a model message, not a ROS topic or service.
    NotRos {
        /// `file:line:col: port `id``.
        here: String,
        /// The model message.
        event: String,
    },
    /// A JANI port kind (a sent message, an array part).
    Jani {
        /// `file:line:col: port `id``.
        here: String,
    },
    /// The port's variable is not in the compiled spec (an internal fault).
    NotCompiled {
        /// `file:line:col: port `id``.
        here: String,
    },
}

impl PortError {
    /// Whether the fault is the program's rather than the file's.
    pub fn is_internal(&self) -> bool {
        matches!(self, PortError::NotCompiled { .. })
    }
}

impl fmt::Display for PortError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            PortError::NotRos { here, event } => write!(
                f,
                "{here}: observes the model message `{event}`, not a ROS topic or service; a recording holds only topics (write the port as <ros_topic> or <ros_service>)"
            ),
            PortError::Jani { here } => {
                write!(f, "{here}: a JANI port kind, which a recording cannot feed")
            }
            PortError::NotCompiled { here } => write!(f, "{here}: internal: not compiled"),
        }
    }
}

impl std::error::Error for PortError {}

/// The recording ports of a property file's ROS ports (`compiled` from the same file).
pub fn file_ports(file: &PropertyFile, compiled: &Compiled) -> Result<Vec<Port>, PortError> {
    let shown = file.path.display();
    let mut out = Vec::new();
    for p in &file.ports {
        let here = format!("{shown}:{}:{}: port `{}`", p.at.line, p.at.column, p.id);
        let side = |prefix: &str, suffix: &str| {
            p.event
                .strip_prefix(prefix)
                .and_then(|t| t.strip_suffix(suffix))
                .map(ros_name)
        };
        let (topic, service) = if let Some(t) = side("topic_", "_msg") {
            (t, None)
        } else if let Some(s) = side("srv_", "_request") {
            (s, Some(ServiceSide::Request))
        } else if let Some(s) = side("srv_", "_response") {
            (s, Some(ServiceSide::Response))
        } else {
            return Err(PortError::NotRos {
                here,
                event: p.event.clone(),
            });
        };
        let read = match &p.kind {
            PortKind::Event => Read::Event,
            PortKind::State { param, .. } => {
                let field = param.strip_prefix("ros_fields__").unwrap_or(param);
                Read::Field(field.replace("__", "."))
            }
            PortKind::Sent | PortKind::Part { .. } => return Err(PortError::Jani { here }),
        };
        let Some(var) = compiled.var_index(&p.id) else {
            return Err(PortError::NotCompiled { here });
        };
        out.push(Port {
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

/// A `--bind VAR=SOURCE` option that does not bind.
#[derive(Debug)]
pub struct BindError {
    /// The option's value as given.
    pub bind: String,
    /// What is wrong with it.
    pub problem: BindProblem,
}

/// What is wrong with a `--bind` option.
#[derive(Debug)]
pub enum BindProblem {
    /// Not `VAR=SOURCE`.
    Syntax,
    /// `VAR` is not a variable of the spec.
    NoVariable(String),
    /// The variable is bound twice.
    Twice,
    /// The source is not a ROS name.
    NotRosName,
    /// After `:` comes neither `request` nor `response`.
    Side,
    /// A state variable bound to a whole topic.
    NeedsField {
        /// The variable.
        var: String,
        /// The source as given.
        source: String,
    },
}

impl fmt::Display for BindError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "--bind {}: ", self.bind)?;
        match &self.problem {
            BindProblem::Syntax => {
                f.write_str("expected VAR=/topic.field, VAR=/topic or VAR=/service:request.field")
            }
            BindProblem::NoVariable(v) => write!(f, "`{v}` is not a variable of the spec"),
            BindProblem::Twice => f.write_str("the variable is bound twice"),
            BindProblem::NotRosName => f.write_str("a source starts with `/` (a ROS name)"),
            BindProblem::Side => f.write_str("after `:` comes `request` or `response`"),
            BindProblem::NeedsField { var, source } => write!(
                f,
                "`{var}` is a state variable: name the field it takes (`{source}.data`)"
            ),
        }
    }
}

impl std::error::Error for BindError {}

/// The recording ports of `--bind VAR=SOURCE` options over a `.hspec` spec's variables:
/// `VAR=/topic.field.path` (the field), `VAR=/topic` (an event variable, true at each
/// message) or `VAR=/service:request.field` (`:response`).
///
/// ```
/// use hindsight_live::recording::bind_ports;
///
/// let spec = codegen::compile_spec("unit 1ms; state v: int = 0; property p = H({v < 9});", "t.hspec")
///     .unwrap();
/// let ports = bind_ports(&["v=/battery/level.data".to_string()], &spec).unwrap();
/// assert_eq!(ports[0].topic, "/battery/level");
/// let err = bind_ports(&["v=/battery".to_string()], &spec).unwrap_err();
/// assert_eq!(
///     err.to_string(),
///     "--bind v=/battery: `v` is a state variable: name the field it takes (`/battery.data`)"
/// );
/// ```
pub fn bind_ports(binds: &[String], compiled: &Compiled) -> Result<Vec<Port>, BindError> {
    let mut out: Vec<Port> = Vec::new();
    for b in binds {
        let bad = |problem| BindError {
            bind: b.clone(),
            problem,
        };
        let Some((var_name, source)) = b.split_once('=') else {
            return Err(bad(BindProblem::Syntax));
        };
        let Some(var) = compiled.var_index(var_name.trim()) else {
            return Err(bad(BindProblem::NoVariable(var_name.trim().to_string())));
        };
        if out.iter().any(|p| p.var == var) {
            return Err(bad(BindProblem::Twice));
        }
        let decl = &compiled.vars()[var];
        let source = source.trim();
        if !source.starts_with('/') {
            return Err(bad(BindProblem::NotRosName));
        }
        let (topic, service, field) = if let Some((name, rest)) = source.split_once(':') {
            let (side, field) = rest.split_once('.').unwrap_or((rest, ""));
            let side = match side {
                "request" => ServiceSide::Request,
                "response" => ServiceSide::Response,
                _ => return Err(bad(BindProblem::Side)),
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
                return Err(bad(BindProblem::NeedsField {
                    var: decl.name.clone(),
                    source: source.to_string(),
                }));
            }
            Read::Event
        } else {
            Read::Field(field)
        };
        out.push(Port {
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

/// The interface packages for types a recording (or a DDS topic) does not embed:
/// `--interfaces`, the folders beside and above a file, the sourced workspace, the
/// built-ins ([`Packages::discover`]).
pub struct Packages(pub Interfaces);

/// Interface packages that do not read: every error, in order.
#[derive(Debug)]
pub struct PackageErrors(pub Vec<Diagnostic>);

impl fmt::Display for PackageErrors {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let all: Vec<String> = self.0.iter().map(|d| d.to_string()).collect();
        f.write_str(&all.join("\n"))
    }
}

impl std::error::Error for PackageErrors {}

impl Packages {
    /// The interface packages found for `path`: `interfaces` first, then beside and
    /// above it, `AMENT_PREFIX_PATH`, the built-ins.
    pub fn discover(path: &Path, interfaces: Vec<PathBuf>) -> Result<Packages, PackageErrors> {
        Packages::discover_in(&mut SourceMap::new(), path, interfaces)
    }

    /// [`Packages::discover`] with the files read kept in `sm`.
    pub(crate) fn discover_in(
        sm: &mut SourceMap,
        path: &Path,
        interfaces: Vec<PathBuf>,
    ) -> Result<Packages, PackageErrors> {
        let search = Search::from_env(interfaces);
        Interfaces::discover_with(sm, path, &search)
            .map(Packages)
            .map_err(PackageErrors)
    }
}

impl ros2::schema::Definitions for Packages {
    fn message(&self, package: &str, name: &str) -> Option<ros2::interface::MessageDef> {
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
        let d = self
            .0
            .get(&format!("{package}/{name}"), InterfaceKind::Service)
            .ok()?;
        Some((d.parts.first()?.clone(), d.parts.get(1)?.clone()))
    }
}

/// Where a recording's message times come from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MessageTime {
    /// The recording's log (receive) time.
    Log,
    /// The message's `header.stamp`.
    Header,
}

/// The caller's monitor in [`replay`]: one point at a time (in the spec's unit) and the
/// `(variable, value)` pairs it sets.
pub type StepPoint<'a> = dyn FnMut(u64, &[(usize, Value)]) -> Result<(), StepError> + 'a;

/// What [`replay`] read.
pub struct Replayed {
    /// `(topic, variable)` of each port whose topic has no message in the recording: the
    /// variable keeps its initial value.
    pub silent: Vec<(String, String)>,
}

/// Replays the recording at `path` through `ports`: one point per message, at its time
/// (nanoseconds since the first message) divided by `compiled`'s unit, handed to `step`
/// with the variables it sets. An error names the file, the topic and the message's
/// index on it; a point `step` refuses is described as `compiled` wrote its atoms.
pub fn replay(
    path: &Path,
    ports: &[Port],
    packages: &Packages,
    time: MessageTime,
    compiled: &Compiled,
    step: &mut StepPoint<'_>,
) -> Result<Replayed, ReplayError<String>> {
    let time = match time {
        MessageTime::Log => TimeSource::Log,
        MessageTime::Header => TimeSource::Header,
    };
    let tick = compiled.tick_ns().max(1);
    let summary = ros2::feed::replay(path, ports, packages, time, compiled.strings(), &mut |p| {
        step(p.time_ns / tick, p.sets)
    })
    .map_err(|e| e.map_point(|s| compiled.describe(&s)))?;
    let silent = ports
        .iter()
        .filter_map(|p| {
            let topic = p.recorded_topic();
            let heard = summary.topics.iter().any(|(t, _)| *t == topic);
            (!heard).then(|| (topic, p.name.clone()))
        })
        .collect();
    Ok(Replayed { silent })
}
