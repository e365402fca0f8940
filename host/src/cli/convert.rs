//! `hindsight convert`: a robot model written out as plain SCXML, a SCAN `model.xml` and
//! its properties, so other tools (SCAN, AS2FM's checkers) can cross-check our numbers.

use std::path::PathBuf;

use super::CliError;
use crate::codegen::bounds::map_bounds;
use crate::codegen::duration::{seconds, StepsOrDuration};
use crate::model::xml::Element;
use crate::props::{self, PortKind, PropertyFile, ANY};
use crate::robot::interfaces::Search;
use crate::robot::load::{load_searching_bt, main_file_of};
use crate::robot::main_file::InputKind;
use crate::robot::write::{escape_into, to_xml, types_xml};
use crate::verify::sweep::parse_bound;

/// Arguments of `hindsight convert`.
#[derive(Debug, clap::Args)]
pub struct ConvertArgs {
    /// The robot model: a main file (`<roaml>` or `<convince_mc_tc>`) or a folder holding
    /// `main.xml`.
    pub model: PathBuf,
    /// The folder to write into (created if missing; files of the same names are replaced).
    #[arg(long, short)]
    pub out: PathBuf,
    /// A folder of ROS interface packages, searched first (repeat for more); as for `verify`.
    #[arg(long = "interfaces", value_name = "DIR")]
    pub interfaces: Vec<PathBuf>,
    /// Whose rules the behavior tree's machines follow: `as2fm` (the default) or `btcpp`;
    /// as for `verify`.
    #[arg(long = "bt", value_enum, default_value_t = super::verify::BtArg::As2fm)]
    pub bt: super::verify::BtArg,
    /// BehaviorTree.CPP's tick mode under --bt btcpp: `once` or `exactly-once`; as for
    /// `verify`.
    #[arg(long = "bt-tick", value_enum, value_name = "MODE")]
    pub bt_tick: Option<super::verify::BtTickArg>,
}

/// Runs `hindsight convert`.
pub fn run(args: &ConvertArgs) -> Result<(), CliError> {
    let main = main_file_of(&args.model).ok_or_else(|| {
        CliError::Input(format!(
            "{}: not a robot model (a main file with <roaml> or <convince_mc_tc>, or a \
             folder holding main.xml)",
            args.model.display()
        ))
    })?;
    let search = Search::from_env(args.interfaces.clone());
    let bt = match super::verify::bt_semantics(args.bt, args.bt_tick)?.as_slice() {
        [one] => *one,
        _ => {
            return Err(CliError::Input(
                "--bt both: convert writes one model; give --bt as2fm or --bt btcpp".into(),
            ))
        }
    };
    let (robot, _) =
        load_searching_bt(&main, &[], &search, bt).map_err(|d| CliError::Input(d.to_string()))?;
    if bt != crate::robot::bt::BtSemantics::As2fm && robot.main.behavior_tree.is_none() {
        return Err(CliError::Input(format!(
            "--bt {}: {} has no behavior tree",
            bt.label(),
            main.display()
        )));
    }
    for w in &robot.warnings {
        eprintln!("warning: {w}");
    }
    let out = &args.out;
    std::fs::create_dir_all(out)
        .map_err(|e| CliError::Failed(format!("{}: {e}", out.display())))?;
    let write = |name: &str, text: &str| -> Result<(), CliError> {
        let path = out.join(name);
        std::fs::write(&path, text)
            .map_err(|e| CliError::Failed(format!("{}: {e}", path.display())))
    };

    // The declared data types the machines name, as SCAN's types.xml.
    let has_types = !robot.types.defs.is_empty();
    if has_types {
        write("types.xml", &types_xml(&robot.types))?;
    }

    let mut names = Vec::new();
    for m in &robot.machines {
        let name = m.attr_value("name").unwrap_or("machine").to_string();
        write(&format!("{name}.scxml"), &to_xml(m))?;
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
                let text = super::read_file(&input.path)?;
                write(&file_name, &text)?;
                props_written.get_or_insert(file_name);
            }
            InputKind::PropertiesXml => {
                let file =
                    props::parse_file(&input.path).map_err(|d| CliError::Input(d.to_string()))?;
                let text = scan_properties(&file, &robot.machines, robot.time_unit_ns)?;
                write("properties.xml", &text)?;
                props_written.get_or_insert("properties.xml".into());
            }
            _ => eprintln!(
                "warning: {}: {} property files are not converted",
                input.path.display(),
                input.kind.type_name()
            ),
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

    let unit = seconds(robot.time_unit_ns);
    eprintln!(
        "wrote {} machines, model.xml{} to {} (one step is {unit}; runs last {} steps)",
        names.len(),
        props_written
            .as_deref()
            .map_or(String::new(), |p| format!(" and {p}")),
        out.display(),
        robot.max_time_steps
    );
    eprintln!(
        "check it: hindsight verify {} --events as2fm --time-unit {unit} --max-time {}",
        out.join("model.xml").display(),
        robot.max_time_steps
    );
    Ok(())
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
) -> Result<String, CliError> {
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
                return Err(CliError::Input(format!(
                    "{path}:{}:{}: port `{}`: the model sends no `{}`",
                    port.at.line, port.at.column, port.id, port.event
                )));
            };
            if pairs.len() > 1 {
                eprintln!(
                    "warning: {path}:{}:{}: port `{}`: `{}` is sent by {} machine pairs; SCAN's \
                     port observes only {} -> {}",
                    port.at.line,
                    port.at.column,
                    port.id,
                    port.event,
                    pairs.len(),
                    first.0,
                    first.1
                );
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
                return Err(CliError::Input(format!(
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
                    CliError::Input(format!("{path}:{}:{}: `{}`: {e}", at.line, at.column, p.id))
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

/// A bound as written (`62`, `6.2s`) in steps of `unit_ns`.
fn to_steps(bound: &str, unit_ns: u64) -> Result<String, String> {
    match parse_bound(bound).map_err(|e| e.to_string())? {
        StepsOrDuration::Steps(v) => Ok(v.to_string()),
        StepsOrDuration::Nanos(ns) if ns % unit_ns == 0 => Ok((ns / unit_ns).to_string()),
        StepsOrDuration::Nanos(_) => Err(format!(
            "bound `{bound}` is not a whole number of steps of {}",
            seconds(unit_ns)
        )),
    }
}
