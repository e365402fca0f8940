//! A robot model written out as plain SCXML (`hindsight convert`): one file per machine,
//! SCAN's `types.xml` and `model.xml`, and its properties in SCAN's current format, so
//! that other tools (SCAN, AS2FM's checkers) can cross-check hindsight's numbers.
//!
//! Nothing here prints: warnings go to the caller's callback as they are found, and what
//! was written comes back as a [`Converted`].

use std::fmt;
use std::path::{Path, PathBuf};

use codegen::bounds::map_bounds;
use codegen::diag::{Diagnostic, Diagnostics};
use codegen::duration::{parse_steps_or_duration, seconds, StepsOrDuration};

use crate::model::xml::Element;
use crate::props::{self, PortKind, PropertyFile, ANY};
use crate::robot::bt::BtSemantics;
use crate::robot::interfaces::Search;
use crate::robot::load::load_searching_bt;
use crate::robot::main_file::InputKind;
use crate::robot::write::{escape_into, to_xml, types_xml};
use crate::sweep::parse_bound;

/// Why a model was not converted. `Display` gives the message `convert` prints.
#[derive(Debug)]
pub enum ConvertError {
    /// The model, or a property file, does not read.
    Input(Diagnostics),
    /// A property file read as is (JANI) does not read.
    Read(Diagnostic),
    /// `--bt btcpp` for a model without a behavior tree: the semantics' label, the main file.
    NoTree(&'static str, PathBuf),
    /// A property with no SCAN equivalent (its position and why).
    Property(String),
    /// A file could not be written (or the folder created).
    Write(PathBuf, std::io::Error),
}

impl ConvertError {
    /// Whether the input is at fault (exit code 2) rather than the output (1).
    pub fn is_input(&self) -> bool {
        !matches!(self, ConvertError::Write(..))
    }
}

impl fmt::Display for ConvertError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ConvertError::Input(d) => d.fmt(f),
            ConvertError::Read(d) => d.fmt(f),
            ConvertError::NoTree(label, main) => {
                write!(f, "--bt {label}: {} has no behavior tree", main.display())
            }
            ConvertError::Property(m) => f.write_str(m),
            ConvertError::Write(path, e) => write!(f, "{}: {e}", path.display()),
        }
    }
}

impl std::error::Error for ConvertError {}

/// What [`convert`] wrote.
#[derive(Debug)]
pub struct Converted {
    /// How many machines (one `.scxml` file each).
    pub machines: usize,
    /// The property file written (`properties.xml`, or a JANI file's name), if any.
    pub properties: Option<String>,
    /// One model step, as a duration (`0.1s`).
    pub unit: String,
    /// The run length in steps (the main file's `max_time`).
    pub max_time_steps: u64,
}

/// Converts the robot model of main file `main` (its interface packages searched in
/// `interfaces` first, its behavior tree lowered under `bt`) into plain SCXML in folder
/// `out` (created if missing; files of the same names are replaced). Each warning is
/// handed to `warn` when found: the model's, a property file not converted, a port SCAN
/// observes only in part.
pub fn convert(
    main: &Path,
    interfaces: Vec<PathBuf>,
    bt: BtSemantics,
    out: &Path,
    warn: &mut dyn FnMut(String),
) -> Result<Converted, ConvertError> {
    let search = Search::from_env(interfaces);
    let (robot, _) = load_searching_bt(main, &[], &search, bt).map_err(ConvertError::Input)?;
    if bt != BtSemantics::As2fm && robot.main.behavior_tree.is_none() {
        return Err(ConvertError::NoTree(bt.label(), main.to_path_buf()));
    }
    for w in &robot.warnings {
        warn(w.to_string());
    }
    std::fs::create_dir_all(out).map_err(|e| ConvertError::Write(out.to_path_buf(), e))?;
    let write = |name: &str, text: &str| -> Result<(), ConvertError> {
        let path = out.join(name);
        std::fs::write(&path, text).map_err(|e| ConvertError::Write(path, e))
    };

    // The declared data types the machines name, as SCAN's types.xml.
    let has_types = !robot.types.defs.is_empty();
    if has_types {
        write("types.xml", &types_xml(&robot.types))?;
    }

    let mut names = Vec::new();
    for m in &robot.machines {
        let name = m.attr_value("name").unwrap_or("machine").to_string();
        let mut m = m.clone();
        delays_in_steps(&mut m, robot.time_unit_ns);
        write(&format!("{name}.scxml"), &to_xml(&m))?;
        names.push(name);
    }

    // Properties: JANI is tool-neutral and copied as is; ROS-named XML becomes SCAN's
    // current format with machine names and bounds in steps.
    let mut props_written: Option<String> = None;
    for input in &robot.main.properties {
        let file_name = input
            .path
            .file_name()
            .map(|f| f.to_string_lossy().into_owned())
            .unwrap_or_else(|| "properties".into());
        match input.kind {
            InputKind::Jani => {
                let text = codegen::diag::read_source(&input.path).map_err(ConvertError::Read)?;
                write(&file_name, &text)?;
                props_written.get_or_insert(file_name);
            }
            InputKind::PropertiesXml => {
                let file = props::parse_file(&input.path)
                    .map_err(|d| ConvertError::Input(crate::load::props_diagnostics(d)))?;
                let text = scan_properties(&file, &robot.machines, robot.time_unit_ns, warn)?;
                write("properties.xml", &text)?;
                props_written.get_or_insert("properties.xml".into());
            }
            _ => warn(format!(
                "{}: {} property files are not converted",
                input.path.display(),
                input.kind.type_name()
            )),
        }
    }

    let mut model = String::from(
        "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<!-- Written by hindsight convert. -->\n\
         <specification>\n    <model>\n        <processList>\n",
    );
    for n in &names {
        let mut escaped = String::new();
        escape_into(n, &mut escaped);
        model.push_str(&format!(
            "            <process id=\"{escaped}\" moc=\"fsm\" path=\"./{escaped}.scxml\"/>\n"
        ));
    }
    model.push_str("        </processList>\n    </model>\n");
    if has_types {
        model.push_str("    <types path=\"./types.xml\"/>\n");
    }
    if let Some(p) = props_written.as_deref().filter(|p| p.ends_with(".xml")) {
        model.push_str(&format!("    <properties path=\"./{p}\"/>\n"));
    }
    model.push_str("</specification>\n");
    write("model.xml", &model)?;
    Ok(Converted {
        machines: names.len(),
        properties: props_written,
        unit: seconds(robot.time_unit_ns),
        max_time_steps: robot.max_time_steps,
    })
}

/// Writes each `<send delay="1.5s">` in steps of `unit_ns`, as SCAN reads a delay (the
/// model compiled, so each is a whole number of steps; one that is not is left as it is).
/// A `delayexpr` with a unit (`e + 'ms'`) is left too: the steps it gives are known only
/// when it runs.
fn delays_in_steps(e: &mut Element, unit_ns: u64) {
    if e.name == "send" {
        if let Some(a) = e.attrs.iter_mut().find(|a| a.name == "delay") {
            if let Ok(StepsOrDuration::Nanos(ns)) = parse_steps_or_duration(&a.value) {
                if unit_ns > 0 && ns % unit_ns == 0 {
                    a.value = (ns / unit_ns).to_string();
                }
            }
        }
    }
    for c in e.elements_mut() {
        delays_in_steps(c, unit_ns);
    }
}

/// Every `(sender, receiver)` machine pair of `<send event="...">` in the plain machines.
fn senders(machines: &[Element], event: &str) -> Vec<(String, String)> {
    fn walk(el: &Element, machine: &str, event: &str, out: &mut Vec<(String, String)>) {
        for child in el.elements() {
            if child.name == "send" && child.attr_value("event") == Some(event) {
                let target = child.attr_value("target").unwrap_or("NONE").to_string();
                let pair = (machine.to_string(), target);
                if !out.contains(&pair) {
                    out.push(pair);
                }
            }
            walk(child, machine, event, out);
        }
    }
    let mut out = Vec::new();
    for m in machines {
        walk(m, m.attr_value("name").unwrap_or(""), event, &mut out);
    }
    out
}

/// A property file over ROS names as SCAN's current format: `*` endpoints become the
/// machines that send the message, bounds with a unit become steps.
fn scan_properties(
    file: &PropertyFile,
    machines: &[Element],
    unit_ns: u64,
    warn: &mut dyn FnMut(String),
) -> Result<String, ConvertError> {
    let path = file.path.display();
    let esc = |s: &str| {
        let mut o = String::new();
        escape_into(s, &mut o);
        o
    };
    let mut out = String::from(
        "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<!-- Written by hindsight convert from ",
    );
    out.push_str(&esc(&path.to_string()));
    out.push_str(&format!(
        ": ports name machines, bounds are steps of {}. -->\n<properties>\n  <ports>\n",
        seconds(unit_ns)
    ));
    for port in &file.ports {
        let (origin, target) = if port.origin == ANY || port.target == ANY {
            let pairs = senders(machines, &port.event);
            let Some(first) = pairs.first().cloned() else {
                return Err(ConvertError::Property(format!(
                    "{path}:{}:{}: port `{}`: the model sends no `{}`",
                    port.at.line, port.at.column, port.id, port.event
                )));
            };
            if pairs.len() > 1 {
                warn(format!(
                    "{path}:{}:{}: port `{}`: `{}` is sent by {} machine pairs; SCAN's \
                     port observes only {} -> {}",
                    port.at.line,
                    port.at.column,
                    port.id,
                    port.event,
                    pairs.len(),
                    first.0,
                    first.1
                ));
            }
            let origin = if port.origin == ANY {
                first.0
            } else {
                port.origin.clone()
            };
            let target = if port.target == ANY {
                first.1
            } else {
                port.target.clone()
            };
            (origin, target)
        } else {
            (port.origin.clone(), port.target.clone())
        };
        out.push_str(&format!(
            "    <scxml_event_send event=\"{}\" origin=\"{}\" target=\"{}\">\n",
            esc(&port.event),
            esc(&origin),
            esc(&target)
        ));
        match &port.kind {
            PortKind::Event => {
                out.push_str(&format!("      <event_var id=\"{}\"/>\n", esc(&port.id)))
            }
            PortKind::State { param, ty, init } => out.push_str(&format!(
                "      <state_var id=\"{}\" param=\"{}\" type=\"{}\" expr=\"{}\"/>\n",
                esc(&port.id),
                esc(param),
                esc(ty),
                esc(init.as_str())
            )),
            other => {
                return Err(ConvertError::Property(format!(
                    "{path}:{}:{}: port `{}`: {other:?} has no SCAN equivalent",
                    port.at.line, port.at.column, port.id
                )))
            }
        }
        out.push_str("    </scxml_event_send>\n");
    }
    out.push_str("  </ports>\n");
    for (section, list) in [
        ("guarantees", &file.guarantees),
        ("assumes", &file.assumptions),
    ] {
        if list.is_empty() {
            continue;
        }
        out.push_str(&format!("  <{section}>\n"));
        for p in list {
            let at = p.formula.location(0);
            let (formula, _) =
                map_bounds(p.formula.as_str(), |b| to_steps(b, unit_ns)).map_err(|e| {
                    ConvertError::Property(format!(
                        "{path}:{}:{}: `{}`: {e}",
                        at.line, at.column, p.id
                    ))
                })?;
            out.push_str(&format!(
                "    <property id=\"{}\" logic=\"pmtl\" expr=\"{}\"/>\n",
                esc(&p.id),
                esc(&formula)
            ));
        }
        out.push_str(&format!("  </{section}>\n"));
    }
    out.push_str("</properties>\n");
    Ok(out)
}

/// Why a property's bound has no SCAN equivalent ([`to_steps`]).
enum BadBound {
    /// The bound does not read (the reader's message).
    Unread(crate::sweep::SweepError),
    /// A duration that is not a whole number of steps: the bound, the step in ns.
    NotWhole(String, u64),
}

impl fmt::Display for BadBound {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            BadBound::Unread(e) => e.fmt(f),
            BadBound::NotWhole(bound, unit_ns) => write!(
                f,
                "bound `{bound}` is not a whole number of steps of {}",
                seconds(*unit_ns)
            ),
        }
    }
}

/// A bound as written (`62`, `6.2s`) in steps of `unit_ns`.
fn to_steps(bound: &str, unit_ns: u64) -> Result<String, BadBound> {
    match parse_bound(bound).map_err(BadBound::Unread)? {
        StepsOrDuration::Steps(v) => Ok(v.to_string()),
        StepsOrDuration::Nanos(ns) if ns % unit_ns == 0 => Ok((ns / unit_ns).to_string()),
        StepsOrDuration::Nanos(_) => Err(BadBound::NotWhole(bound.to_string(), unit_ns)),
    }
}

#[cfg(test)]
mod tests {
    use super::{delays_in_steps, to_steps};
    use crate::model::xml::Element;
    use crate::model::{xml, SourceMap};

    /// SCAN reads a delay as whole steps: a duration becomes them, steps stay, and what
    /// is not whole (refused by the compile before) or a `delayexpr` is left alone.
    #[test]
    fn durations_of_delays_become_steps() {
        let mut sm = SourceMap::new();
        let text = r#"<scxml name="m"><state id="s"><onentry>
            <send event="a" delay="1.5s"/><send event="b" delay="7"/><send event="c" delay="150ms"/>
            <if cond="true"><send event="d" delay="200ms"/></if>
            <send event="e" delayexpr="x + 'ms'"/></onentry></state></scxml>"#;
        let file = sm.add("m.scxml", text.to_string());
        let mut m = xml::parse(&sm, file).unwrap();
        delays_in_steps(&mut m, 100_000_000);
        fn sends(e: &Element, out: &mut Vec<String>) {
            if e.name == "send" {
                let d = e.attr("delay").or(e.attr("delayexpr")).unwrap();
                out.push(format!("{}={}", d.name, d.value));
            }
            e.elements().for_each(|c| sends(c, out));
        }
        let mut got = Vec::new();
        sends(&m, &mut got);
        assert_eq!(
            got,
            [
                "delay=15",
                "delay=7",
                "delay=150ms",
                "delay=2",
                "delayexpr=x + 'ms'"
            ]
        );
    }

    #[test]
    fn a_bound_becomes_whole_steps_or_says_why_not() {
        let tick = 100_000_000;
        assert_eq!(to_steps("6.2s", tick).ok().as_deref(), Some("62"));
        assert_eq!(to_steps("62", tick).ok().as_deref(), Some("62"));
        let e = to_steps("6.25s", tick).err().map(|e| e.to_string());
        assert_eq!(
            e.as_deref(),
            Some("bound `6.25s` is not a whole number of steps of 0.1s")
        );
        assert!(to_steps("6.2 parsecs", tick).is_err());
    }
}
