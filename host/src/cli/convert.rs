//! `hindsight convert`: a robot model written out as plain SCXML, a SCAN `model.xml` and
//! its properties, so other tools (SCAN, AS2FM's checkers) can cross-check our numbers.

use std::path::PathBuf;

use super::CliError;
use crate::verify::convert::convert;
use crate::verify::load::main_file_of;

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
    let bt = match super::verify::bt_semantics(args.bt, args.bt_tick)?.as_slice() {
        [one] => *one,
        _ => {
            return Err(CliError::Input(
                "--bt both: convert writes one model; give --bt as2fm or --bt btcpp".into(),
            ))
        }
    };
    let out = &args.out;
    if out.exists() && !out.is_dir() {
        return Err(CliError::Input(format!(
            "--out {}: not a folder (the plain machines, model.xml and the properties are \
             written into a folder, created if missing)",
            out.display()
        )));
    }
    let done = convert(&main, args.interfaces.clone(), bt, out, &mut |w| {
        eprintln!("warning: {w}")
    })
    .map_err(|e| {
        if e.is_input() {
            CliError::Input(e.to_string())
        } else {
            CliError::Failed(e.to_string())
        }
    })?;
    let unit = &done.unit;
    eprintln!(
        "wrote {} machines, model.xml{} to {} (one step is {unit}; runs last {} steps)",
        done.machines,
        done.properties
            .as_deref()
            .map_or(String::new(), |p| format!(" and {p}")),
        out.display(),
        done.max_time_steps
    );
    eprintln!(
        "check it: hindsight verify {} --events as2fm --time-unit {unit} --max-time {}",
        out.join("model.xml").display(),
        done.max_time_steps
    );
    Ok(())
}
