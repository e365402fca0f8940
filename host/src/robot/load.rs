//! From a main file to a compiled model: every stage of the robot pipeline in order.

use std::path::{Path, PathBuf};

use super::bt::{self, BtInput, Halts};
use super::datatypes::read_main_declarations;
use super::interfaces::Interfaces;
use super::main_file::{Input, MainFile};
use super::ros::{self, RosInput};
use crate::model::xml::{self, Element};
use crate::model::{Diagnostic, Diagnostics, ModelSource, SourceMap, TypeDefs};
use crate::sim::CompiledModel;

/// A robot model, lowered to plain SCXML and compiled.
pub struct RobotModel {
    /// The main file as read.
    pub main: MainFile,
    /// The plain machines, in model order (what `hindsight convert` writes).
    pub machines: Vec<Element>,
    /// The declared data types the machines name (what `hindsight convert` writes as
    /// `types.xml`, with [`super::write::types_xml`]).
    pub types: TypeDefs,
    /// The compiled model the simulator runs.
    pub model: CompiledModel,
    /// Nanoseconds in one model time step.
    pub time_unit_ns: u64,
    /// The run length in model steps: `max_time` plus the step at which the global
    /// timer stops, so that every event due at `max_time` is delivered.
    pub max_time_steps: u64,
}

/// The main file a path stands for: the path itself if it is an XML file whose root is
/// `<roaml>` or `<convince_mc_tc>`, or the `main.xml` of a folder (or, if the folder has
/// no `main.xml`, its only `.xml` file with such a root). `None`: not a robot model.
pub fn main_file_of(path: &Path) -> Option<PathBuf> {
    if path.is_file() {
        return is_main_file(path).then(|| path.to_path_buf());
    }
    if !path.is_dir() {
        return None;
    }
    let main = path.join("main.xml");
    if main.is_file() {
        return is_main_file(&main).then_some(main);
    }
    let mut found: Vec<PathBuf> = std::fs::read_dir(path)
        .ok()?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "xml") && is_main_file(p))
        .collect();
    found.sort();
    (found.len() == 1).then(|| found.remove(0))
}

/// Whether the XML file's root element is a robot main file's.
fn is_main_file(path: &Path) -> bool {
    let Ok(text) = std::fs::read_to_string(path) else {
        return false;
    };
    // The first element after the prolog and comments.
    let mut rest = text.as_str();
    loop {
        let Some(i) = rest.find('<') else {
            return false;
        };
        rest = &rest[i..];
        if rest.starts_with("<?") {
            rest = rest.find("?>").map_or("", |j| &rest[j + 2..]);
        } else if rest.starts_with("<!--") {
            rest = rest.find("-->").map_or("", |j| &rest[j + 3..]);
        } else if rest.starts_with("<!") {
            rest = rest.find('>').map_or("", |j| &rest[j + 1..]);
        } else {
            let name: String = rest[1..]
                .chars()
                .take_while(|c| c.is_alphanumeric() || *c == '_')
                .collect();
            return name == "roaml" || name == "convince_mc_tc";
        }
    }
}

/// Reads and parses one SCXML input; errors go to `errs`.
fn read_xml(sm: &mut SourceMap, input: &Input, errs: &mut Vec<Diagnostic>) -> Option<Element> {
    let text = match std::fs::read_to_string(&input.path) {
        Ok(t) => t,
        Err(e) => {
            errs.push(sm.diag(input.span, format!("cannot read {}: {e}", input.src)));
            return None;
        }
    };
    let id = sm.add(input.path.clone(), text);
    match xml::parse(sm, id) {
        Ok(e) => Some(e),
        Err(d) => {
            errs.push(d);
            None
        }
    }
}

fn fail(ds: Vec<Diagnostic>) -> Diagnostics {
    Diagnostics(ds)
}

/// Reads a main file and everything it names, lowers the behavior tree and the ROS tags,
/// and compiles the plain machines. Every error names the user's file, line and column.
/// Control nodes halt their children as AS2FM's translation does ([`Halts::As2fm`]).
pub fn load(main_path: &Path) -> Result<RobotModel, Diagnostics> {
    load_with(main_path, Halts::default())
}

/// [`load`] with the halting rule of the tree's control nodes chosen:
/// [`Halts::WhenNeeded`] runs faster, with the same ROS messages under one schedule but
/// other verdict probabilities where the model races (see [`Halts`]).
pub fn load_with(main_path: &Path, halts: Halts) -> Result<RobotModel, Diagnostics> {
    let mut sm = SourceMap::new();
    let main = MainFile::read(&mut sm, main_path).map_err(fail)?;

    let types = read_main_declarations(&mut sm, &main).map_err(fail)?;
    let interfaces = Interfaces::discover(&mut sm, main_path, &[]).map_err(fail)?;

    let mut errs = Vec::new();
    let mut machines = Vec::new();
    if let Some(tree) = &main.behavior_tree {
        let file_of = |sm: &mut SourceMap, input: &Input| {
            let text = std::fs::read_to_string(&input.path).ok()?;
            Some(sm.add(input.path.clone(), text))
        };
        let tree_id = file_of(&mut sm, &tree.tree);
        let plugins: Option<Vec<_>> = tree.plugins.iter().map(|p| file_of(&mut sm, p)).collect();
        match (tree_id, plugins) {
            (Some(tree_id), Some(plugins)) => {
                let input = BtInput {
                    tree: tree_id,
                    plugins,
                    tick_rate_hz: main.params.bt_tick_rate_hz(),
                    tick_if_not_running: main.params.tick_if_not_running(),
                    halts,
                };
                match bt::lower(&sm, &input) {
                    Ok(ms) => machines.extend(ms),
                    Err(ds) => errs.extend(ds),
                }
            }
            _ => errs.push(sm.diag(tree.span, "cannot read the behavior tree or a plugin")),
        }
    }
    for input in &main.node_models {
        if let Some(e) = read_xml(&mut sm, input, &mut errs) {
            machines.push(e);
        }
    }
    if !errs.is_empty() {
        return Err(fail(errs));
    }

    let max_time_ns = main.params.max_time_ns.value;
    let max_array_size = main.params.max_array_size_or_default();
    let out = ros::lower(
        &sm,
        RosInput {
            machines,
            interfaces: &interfaces,
            max_time_ns,
            max_array_size,
        },
    )
    .map_err(fail)?;

    let mut src = ModelSource {
        sources: sm,
        types: types.clone(),
        ..ModelSource::default()
    };
    let mut errs = Diagnostics::default();
    for m in &out.machines {
        src.add_machine_tree(m, m.span.file, &mut errs);
    }
    src.check_names(&mut errs);
    if !errs.is_empty() {
        return Err(errs);
    }
    let model = CompiledModel::compile(src)?;
    let unit = out.time_unit_ns.max(1);
    Ok(RobotModel {
        main,
        machines: out.machines,
        types,
        model,
        time_unit_ns: unit,
        max_time_steps: max_time_ns / unit + 1,
    })
}
