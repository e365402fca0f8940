//! From a main file to a compiled model: every stage of the robot pipeline in order.

use std::path::{Path, PathBuf};

use super::bt::{self, BtInput, BtSemantics, Halts};
use super::datatypes::read_main_declarations;
use super::interfaces::{Interfaces, Search};
use super::main_file::{Input, MainFile};
use super::ros::{self, RosInput};
use super::types::InterfaceLookup;
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
    /// What was read but ignored, as AS2FM ignores it (the main file's
    /// [`MainFile::warnings`]); a command prints them.
    pub warnings: Vec<Diagnostic>,
    /// Where the behavior tree's runs under AS2FM's node models and under
    /// BehaviorTree.CPP 4 are known to differ (`bt::semantics_notes`); `validate`
    /// prints them.
    pub bt_notes: Vec<Diagnostic>,
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
    // Through the one source reader: a FIFO named `*.xml` in the folder is never opened.
    let Ok(text) = codegen::diag::read_source(path) else {
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
    let text = match codegen::diag::read_source(&input.path) {
        Ok(t) => t,
        Err(d) => {
            errs.push(d);
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
    Diagnostics::from(ds)
}

/// A node model left out of the model because a real process plays it
/// (`hindsight run --external NAME`): the ROS topics that process publishes into the run
/// and those it listens to.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ExternalComponent {
    /// The node model's `name`.
    pub name: String,
    /// Topics it publishes: `(topic, ROS type)`, e.g. `("/BatteryComponent/battery_level", "std_msgs/Int32")`.
    pub publishes: Vec<(String, String)>,
    /// Topics it subscribes to.
    pub subscribes: Vec<(String, String)>,
    /// Services it serves: `(service, ROS type)`; the process answers their requests.
    pub serves: Vec<(String, String)>,
    /// Services it calls: `(service, ROS type)`; the model answers the process.
    pub calls: Vec<(String, String)>,
    /// Actions it serves: `(action, ROS type)`; the process takes the goals, publishes
    /// feedback and results.
    pub serves_actions: Vec<(String, String)>,
    /// Actions it calls: `(action, ROS type)`; the process sends goals, the model's server
    /// accepts or rejects them.
    pub calls_actions: Vec<(String, String)>,
}

/// Reads a main file and everything it names, lowers the behavior tree and the ROS tags,
/// and compiles the plain machines. Every error names the user's file, line and column.
/// Control nodes halt their children as AS2FM's translation does ([`Halts::As2fm`]).
/// Interfaces are looked for beside and above the model, in the sourced ROS workspace
/// (`AMENT_PREFIX_PATH`) and among the built-ins ([`super::interfaces::discover`]).
pub fn load(main_path: &Path) -> Result<RobotModel, Diagnostics> {
    load_full(
        main_path,
        &[],
        Halts::default(),
        BtSemantics::default(),
        &Search::from_env(Vec::new()),
    )
    .map(|(m, _)| m)
}

/// [`load`] with the halting rule of the tree's control nodes chosen:
/// [`Halts::WhenNeeded`] runs faster, with the same ROS messages under one schedule but
/// other verdict probabilities where the model races (see [`Halts`]).
pub fn load_with(main_path: &Path, halts: Halts) -> Result<RobotModel, Diagnostics> {
    load_full(
        main_path,
        &[],
        halts,
        BtSemantics::default(),
        &Search::from_env(Vec::new()),
    )
    .map(|(m, _)| m)
}

/// What a node model declares that a process replacing it must speak (topics, services
/// and actions, either side), or an error at a declaration without its required
/// attributes.
fn external_component(
    sm: &SourceMap,
    root: &Element,
    name: &str,
) -> Result<ExternalComponent, Diagnostic> {
    let mut c = ExternalComponent {
        name: name.to_string(),
        publishes: Vec::new(),
        subscribes: Vec::new(),
        serves: Vec::new(),
        calls: Vec::new(),
        serves_actions: Vec::new(),
        calls_actions: Vec::new(),
    };
    for el in root.elements() {
        // Each declaration's name attribute, and its lists: the side that provides
        // (publisher, server), then the side that uses (subscriber, client).
        let (attr, provides, uses) = match el.name.as_str() {
            "ros_topic_publisher" | "ros_topic_subscriber" => {
                ("topic", &mut c.publishes, &mut c.subscribes)
            }
            "ros_service_server" | "ros_service_client" => {
                ("service_name", &mut c.serves, &mut c.calls)
            }
            "ros_action_server" | "ros_action_client" => {
                ("action_name", &mut c.serves_actions, &mut c.calls_actions)
            }
            _ => continue,
        };
        let key = el.required(sm, attr)?.value.trim().to_string();
        let ty = el.required(sm, "type")?.value.trim().to_string();
        if el.name.ends_with("_publisher") || el.name.ends_with("_server") {
            provides.push((key, ty));
        } else {
            uses.push((key, ty));
        }
    }
    Ok(c)
}

/// The node model a process plays, reduced to what the model still needs from it: its
/// datamodel, its topic publishers and service servers, and one copy of each
/// `<ros_topic_publish>` under a transition that never fires, so the topics keep their
/// message fields (a message's fields are those its senders give) while nothing in the
/// model publishes them. Each served service keeps one of its request handlers, disabled
/// (`cond="false"`), for the response's fields, and gets one that takes a request and
/// does nothing: the process answers it. Each called service keeps one of its requests
/// under the transition that never fires, for the request's fields, and gets a response
/// handler that takes the answer and does nothing: the process gets it. Each served
/// action takes goals and does nothing (its threads are left out), and sends, under the
/// transition that never fires, an accept, a reject, a feedback and a result whose fields
/// are the interface's defaults: the process answers and reports instead. Each called
/// action sends a goal under that transition and takes every answer, feedback and
/// result, doing nothing: the process sends goals and reads the answers.
fn inert_stub(root: &Element, interfaces: &Interfaces) -> Element {
    fn first<'e>(el: &'e Element, tag: &str, alias: &str) -> Option<&'e Element> {
        el.elements().find_map(|c| {
            if c.name == tag && c.attr_value("name") == Some(alias) {
                Some(c)
            } else {
                first(c, tag, alias)
            }
        })
    }
    fn publishes<'e>(el: &'e Element, out: &mut Vec<&'e Element>) {
        for c in el.elements() {
            if c.name == "ros_topic_publish" {
                let name = c.attr_value("name");
                if !out.iter().any(|p| p.attr_value("name") == name) {
                    out.push(c);
                }
            } else {
                publishes(c, out);
            }
        }
    }
    let mut found = Vec::new();
    publishes(root, &mut found);
    let mut stub = Element::new(root.name.clone(), root.span);
    stub.attrs = root.attrs.clone();
    stub.set_attr("initial", "external");
    let mut state = Element::new("state", root.span).with_attr("id", "external");
    let mut requests = Vec::new();
    let mut requests_owned = Vec::new();
    for c in root.elements() {
        if matches!(
            c.name.as_str(),
            "datamodel"
                | "ros_topic_publisher"
                | "ros_service_server"
                | "ros_service_client"
                | "ros_action_server"
                | "ros_action_client"
        ) {
            stub.push(c.clone());
        }
        // Tags name a declaration by its `name`, else by the service or action name.
        let alias = c
            .attr_value("name")
            .or(c.attr_value("service_name"))
            .or(c.attr_value("action_name"));
        if let ("ros_service_client", Some(alias)) = (c.name.as_str(), alias) {
            requests.extend(first(root, "ros_service_send_request", alias));
            state.push(
                Element::new("ros_service_handle_response", c.span)
                    .with_attr("name", alias)
                    .with_attr("target", "external"),
            );
        }
        if let ("ros_action_client", Some(alias)) = (c.name.as_str(), alias) {
            let goal = c
                .attr_value("type")
                .and_then(|t| interfaces.action(t.trim()).ok())
                .unwrap_or_default()
                .goal;
            let mut send = Element::new("ros_action_send_goal", c.span).with_attr("name", alias);
            for f in &goal {
                send.push(
                    Element::new("field", c.span)
                        .with_attr("name", f.dotted())
                        .with_attr("expr", f.default.clone()),
                );
            }
            requests_owned.push(send);
            state.push(
                Element::new("ros_action_handle_goal_response", c.span)
                    .with_attr("name", alias)
                    .with_attr("accept", "external")
                    .with_attr("reject", "external"),
            );
            for tag in [
                "ros_action_handle_feedback",
                "ros_action_handle_success_result",
                "ros_action_handle_aborted_result",
                "ros_action_handle_canceled_result",
            ] {
                state.push(
                    Element::new(tag, c.span)
                        .with_attr("name", alias)
                        .with_attr("target", "external"),
                );
            }
        }
        if let ("ros_action_server", Some(alias)) = (c.name.as_str(), alias) {
            state.push(
                Element::new("ros_action_handle_goal", c.span)
                    .with_attr("name", alias)
                    .with_attr("target", "external"),
            );
            let fields = c
                .attr_value("type")
                .and_then(|t| interfaces.action(t.trim()).ok())
                .unwrap_or_default();
            let with_fields = |tag: &str, list: &[crate::types::FlatField]| {
                let mut e = Element::new(tag, c.span)
                    .with_attr("name", alias)
                    .with_attr("goal_id", "0");
                for f in list {
                    e.push(
                        Element::new("field", c.span)
                            .with_attr("name", f.dotted())
                            .with_attr("expr", f.default.clone()),
                    );
                }
                e
            };
            requests_owned.push(with_fields("ros_action_accept_goal", &[]));
            requests_owned.push(with_fields("ros_action_reject_goal", &[]));
            requests_owned.push(with_fields("ros_action_feedback", &fields.feedback));
            requests_owned.push(with_fields("ros_action_succeed", &fields.result));
            requests_owned.push(with_fields("ros_action_aborted", &fields.result));
        }
        if c.name == "ros_service_server" {
            let Some(alias) = alias else {
                continue;
            };
            if let Some(h) = first(root, "ros_service_handle_request", alias) {
                let mut disabled = h.clone();
                disabled.set_attr("cond", "false");
                disabled.set_attr("target", "external");
                state.push(disabled);
            }
            state.push(
                Element::new("ros_service_handle_request", c.span)
                    .with_attr("name", alias)
                    .with_attr("target", "external"),
            );
        }
    }
    let mut never = Element::new("transition", root.span)
        .with_attr("cond", "false")
        .with_attr("target", "external");
    for p in found.into_iter().chain(requests) {
        never.push(p.clone());
    }
    for p in requests_owned {
        never.push(p);
    }
    state.push(never);
    stub.push(state);
    stub
}

/// [`load`], leaving out the node models named in `external` (their `<scxml name>`):
/// the model runs without their behaviour (an inert stub), and what each declared is
/// returned so that a process can take its place. An unknown name is an error.
pub fn load_without(
    main_path: &Path,
    external: &[String],
) -> Result<(RobotModel, Vec<ExternalComponent>), Diagnostics> {
    load_full(
        main_path,
        external,
        Halts::default(),
        BtSemantics::default(),
        &Search::from_env(Vec::new()),
    )
}

/// [`load_without`] with the interface search given (`--interfaces` folders and the
/// workspace prefixes; [`Search::from_env`] reads `AMENT_PREFIX_PATH`) and the behavior
/// tree lowered under `semantics`.
pub fn load_searching_bt(
    main_path: &Path,
    external: &[String],
    search: &Search,
    semantics: BtSemantics,
) -> Result<(RobotModel, Vec<ExternalComponent>), Diagnostics> {
    load_full(main_path, external, Halts::default(), semantics, search)
}

fn load_full(
    main_path: &Path,
    external: &[String],
    halts: Halts,
    semantics: BtSemantics,
    search: &Search,
) -> Result<(RobotModel, Vec<ExternalComponent>), Diagnostics> {
    let mut sm = SourceMap::new();
    let main = MainFile::read(&mut sm, main_path).map_err(fail)?;

    let types = read_main_declarations(&mut sm, &main).map_err(fail)?;
    let interfaces = Interfaces::discover_with(&mut sm, main_path, search).map_err(fail)?;

    let mut errs = Vec::new();
    // The tree's machines go after the node models, in the order AS2FM collects them
    // (`generate_plain_scxml_models_and_timers`, jani_generator/scxml_helpers/
    // top_level_interpreter.py: the node models in main-file order, then `bt_converter`'s
    // root and plugins): the ROS lowering numbers timers and clients in this order.
    let mut tree_machines = Vec::new();
    let mut bt_notes = Vec::new();
    let mut bt_warnings = Vec::new();
    if let Some(tree) = &main.behavior_tree {
        let file_of = |sm: &mut SourceMap, input: &Input, errs: &mut Vec<Diagnostic>| {
            match codegen::diag::read_source(&input.path) {
                Ok(text) => Some(sm.add(input.path.clone(), text)),
                Err(d) => {
                    errs.push(d);
                    None
                }
            }
        };
        let tree_id = file_of(&mut sm, &tree.tree, &mut errs);
        let plugins: Option<Vec<_>> = tree
            .plugins
            .iter()
            .map(|p| file_of(&mut sm, p, &mut errs))
            .collect();
        match (tree_id, plugins) {
            (Some(tree_id), Some(plugins)) => {
                let input = BtInput {
                    tree: tree_id,
                    plugins,
                    tick_rate_hz: main.params.bt_tick_rate_hz(),
                    tick_if_not_running: main.params.tick_if_not_running(),
                    halts,
                    semantics,
                };
                bt_notes = bt::semantics_notes(&sm, &input);
                bt_warnings = bt::btcpp_warnings(&sm, &input);
                match bt::lower(&sm, &input) {
                    Ok(ms) => tree_machines = ms,
                    Err(ds) => errs.extend(ds),
                }
            }
            _ => errs.push(sm.diag(tree.span, "cannot read the behavior tree or a plugin")),
        }
    }
    let mut left_out = Vec::new();
    let mut machines = Vec::new();
    let mut delay_warnings = Vec::new();
    for input in &main.node_models {
        if let Some(e) = read_xml(&mut sm, input, &mut errs) {
            delayed_sends(&sm, &e, &mut delay_warnings);
            let name = e.attr_value("name").unwrap_or("").trim().to_string();
            if external.contains(&name) {
                match external_component(&sm, &e, &name) {
                    Ok(c) => left_out.push(c),
                    Err(d) => errs.push(d),
                }
                machines.push(inert_stub(&e, &interfaces));
            } else {
                machines.push(e);
            }
        }
    }
    if errs.is_empty() {
        for name in external {
            if !left_out.iter().any(|c| &c.name == name) {
                let known: Vec<&str> = machines
                    .iter()
                    .filter_map(|m| m.attr_value("name"))
                    .collect();
                errs.push(crate::model::about_file(
                    main_path,
                    format!(
                        "--external {name}: no node model is called `{name}` (node models: {})",
                        known.join(", ")
                    ),
                ));
            }
        }
    }
    if !errs.is_empty() {
        return Err(fail(errs));
    }

    machines.extend(tree_machines);
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
        src.add_machine_tree(m, crate::model::FileId::of(m.span), &mut errs);
    }
    src.check_names(&mut errs);
    if !errs.is_empty() {
        return Err(errs);
    }
    let unit = out.time_unit_ns.max(1);
    src.time_unit_ns = Some(unit);
    let model = CompiledModel::compile(src)?;
    let mut warnings = main.warnings.clone();
    warnings.extend(bt_warnings);
    warnings.extend(delay_warnings);
    Ok((
        RobotModel {
            main,
            machines: out.machines,
            types,
            model,
            time_unit_ns: unit,
            max_time_steps: max_time_ns / unit + 1,
            warnings,
            bt_notes,
        },
        left_out,
    ))
}

/// Warns at each `<send>` of a node model with a `delay` or `delayexpr`: AS2FM's reader
/// keeps a send's event, target and parameters only (`scxml_converter/scxml_entries/
/// scxml_send.py`, `ScxmlSend::from_xml_tree`), so AS2FM's numbers ignore the delay,
/// while hindsight waits for it; and under AS2FM's events time stops while an event is
/// pending (`docs/SEMANTICS.md` section 3), so a request to a machine that waits there
/// ends the run as a deadlock.
fn delayed_sends(sm: &SourceMap, e: &Element, out: &mut Vec<Diagnostic>) {
    if e.name == "send" {
        if let Some(a) = e.attr("delay").or_else(|| e.attr("delayexpr")) {
            out.push(sm.diag(
                a.name_span,
                format!(
                    "`{}` on <send>: AS2FM drops it (its reader keeps a send's event, \
                     target and parameters), hindsight waits for it; a request to this \
                     machine while it waits is a deadlock under --events as2fm, where time \
                     stops while an event is pending: wait with a <ros_time_rate> timer",
                    a.name
                ),
            ));
        }
    }
    for c in e.elements() {
        delayed_sends(sm, c, out);
    }
}
