//! What `hindsight run` connects before the first step: the topics, services and actions
//! the run publishes, those that processes playing node models (`--external`) take over,
//! over iceoryx2 ([`Wiring`], [`Bridges`]) or over DDS ([`dds_services`], [`DdsPlan`],
//! [`topic_qos`]).
//!
//! Nothing here prints: what a run should warn about comes back as `warnings`, in the
//! order it was found.

use std::collections::BTreeMap;
use std::fmt;
use std::path::{Path, PathBuf};

use codegen::diag::SourceMap;
use iceoryx2::prelude::*;

use crate::inject::{
    Answer, GoalBridge, GoalRoute, ServiceBridge, ServiceServers, TopicSubscriber,
};
use crate::props::ros::{action_event, service_client_event, service_event, topic_event};
use crate::publish::{layout_of, layouts, name_from_ports, TopicLayout, TopicPublisher, WireKind};
use crate::publish_dds::{declared_types, plan, Route};
use crate::recording::{PackageErrors, Packages};
use crate::robot::load::ExternalComponent;
use crate::serve_dds::ServiceRoute;
use crate::sim::CompiledModel;
use crate::LiveError;
use ros2::dds::{DdsError, Qos};

type Ipc = ipc::Service;

/// What a process playing `c` speaks, for the start of a run: `publishes /a; calls /s`,
/// or `no ROS interface`.
pub fn describe(c: &ExternalComponent) -> String {
    let parts = [
        ("publishes", &c.publishes),
        ("subscribes to", &c.subscribes),
        ("serves", &c.serves),
        ("calls", &c.calls),
        ("serves action", &c.serves_actions),
        ("calls action", &c.calls_actions),
    ];
    let said: Vec<String> = parts
        .iter()
        .filter(|(_, l)| !l.is_empty())
        .map(|(verb, l)| {
            let names: Vec<&str> = l.iter().map(|(n, _)| n.as_str()).collect();
            format!("{verb} {}", names.join(", "))
        })
        .collect();
    if said.is_empty() {
        "no ROS interface".to_string()
    } else {
        said.join("; ")
    }
}

/// The payload layout of every ROS message event of `model` (topics, service requests
/// and responses, action messages), each named after the property file's `ports` where
/// one reads it, and the warnings about fields a layout leaves out.
pub fn topic_layouts(
    model: &CompiledModel,
    ports: &[crate::props::Port],
) -> (Vec<TopicLayout>, Vec<String>) {
    let (mut topics, warnings) = layouts(model);
    name_from_ports(&mut topics, model, ports);
    (topics, warnings)
}

/// How a run over iceoryx2 is wired to the processes that play node models.
pub struct Wiring {
    /// The layouts the run publishes (taken out of them: those processes publish).
    pub topics: Vec<TopicLayout>,
    /// The topics the processes publish, read by the run.
    pub inbound: Vec<TopicLayout>,
    /// The services the processes serve: `(service path, request layout, response
    /// layout)`; their mirrors stay in `topics`.
    pub served: Vec<(String, TopicLayout, TopicLayout)>,
    /// The services and actions the processes call: `(path, the client's request or goal
    /// layout, how the model's answer is sent back)`.
    pub called: Vec<(String, TopicLayout, Answer)>,
    /// The goal routes of the actions the processes serve.
    pub routes: Vec<GoalRoute>,
    /// What is not bridged, and why, in the order found.
    pub warnings: Vec<String>,
}

impl Wiring {
    /// Splits `topics` (every layout of `model`) between the run and the processes of
    /// `external`, and finds the services and actions to bridge.
    pub fn plan(
        model: &CompiledModel,
        mut topics: Vec<TopicLayout>,
        external: &[ExternalComponent],
    ) -> Wiring {
        let mut warnings = Vec::new();
        let inbound = inbound_layouts(&mut topics, external, &mut warnings);
        let served = bridged_services(&topics, external, &mut warnings);
        let called = called_services(model, external, &mut warnings);
        let routes = goal_routes(model, &topics, external, &mut warnings);
        Wiring {
            topics,
            inbound,
            served,
            called,
            routes,
            warnings,
        }
    }
}

/// The layouts of the topics the external components publish, taken out of `topics` (the
/// run does not publish them: their processes do).
fn inbound_layouts(
    topics: &mut Vec<TopicLayout>,
    external: &[ExternalComponent],
    warnings: &mut Vec<String>,
) -> Vec<TopicLayout> {
    let mut inbound = Vec::new();
    for c in external {
        // A served action's feedback and results are topics its process publishes.
        let action_topics = c.serves_actions.iter().flat_map(|(a, _)| {
            ["feedback", "result"].map(|part| (action_event(a, part), format!("{a}/{part}")))
        });
        for (event, topic) in c
            .publishes
            .iter()
            .map(|(t, _)| (topic_event(t), t.clone()))
            .chain(action_topics)
        {
            match topics.iter().position(|l| l.event_name == event) {
                Some(i) => inbound.push(topics.remove(i)),
                None => warnings.push(format!(
                    "--external {}: nothing in the model subscribes to {topic}; \
                     its samples are not read",
                    c.name
                )),
            }
        }
    }
    inbound
}

/// The services the external components serve: `(service path, request layout, response
/// layout)`. Their mirrors stay in `topics`: the run publishes requests and responses.
fn bridged_services(
    topics: &[TopicLayout],
    external: &[ExternalComponent],
    warnings: &mut Vec<String>,
) -> Vec<(String, TopicLayout, TopicLayout)> {
    let mut out = Vec::new();
    for c in external {
        for (service, _) in &c.serves {
            let find = |response: bool| {
                let event = service_event(service, response);
                topics.iter().find(|l| l.event_name == event).cloned()
            };
            match (find(false), find(true)) {
                (Some(req), Some(resp)) => {
                    out.push((service.trim_start_matches('/').to_string(), req, resp))
                }
                _ => warnings.push(format!(
                    "--external {}: nothing in the model calls {service}; it is not \
                     bridged",
                    c.name
                )),
            }
        }
    }
    out
}

/// The services and actions the external components call: `(service or action path, the
/// client's request or goal layout, how the model's answer is sent back)`.
fn called_services(
    model: &CompiledModel,
    external: &[ExternalComponent],
    said: &mut Vec<String>,
) -> Vec<(String, TopicLayout, Answer)> {
    let mut out = Vec::new();
    let mut warnings = Vec::new();
    for c in external {
        for (service, _) in &c.calls {
            let event =
                |response| model.event_id(&service_client_event(service, &c.name, response));
            let path = service.trim_start_matches('/').to_string();
            match (event(false), event(true)) {
                (Some(req), Some(resp)) => out.push((
                    path.clone(),
                    layout_of(model, req, path.clone(), WireKind::Request, &mut warnings),
                    Answer::Layout(layout_of(
                        model,
                        resp,
                        path,
                        WireKind::Response,
                        &mut warnings,
                    )),
                )),
                _ => said.push(format!(
                    "--external {}: nothing in the model serves {service}; it is not \
                     bridged",
                    c.name
                )),
            }
        }
        for (action, _) in &c.calls_actions {
            let event = |part: &str| {
                model.event_id(&action_event(action, &format!("{part}_client_{}", c.name)))
            };
            let path = action.trim_start_matches('/').to_string();
            match (
                event("goal_req"),
                event("goal_accept"),
                event("goal_reject"),
            ) {
                (Some(goal), Some(accept), Some(reject)) => out.push((
                    path.clone(),
                    layout_of(model, goal, path, WireKind::Goal, &mut warnings),
                    Answer::Goal { accept, reject },
                )),
                _ => said.push(format!(
                    "--external {}: nothing in the model serves {action}; it is not \
                     bridged",
                    c.name
                )),
            }
        }
    }
    said.extend(warnings);
    out
}

/// The goal routes of the actions the external components serve.
fn goal_routes(
    model: &CompiledModel,
    topics: &[TopicLayout],
    external: &[ExternalComponent],
    warnings: &mut Vec<String>,
) -> Vec<GoalRoute> {
    let mut out = Vec::new();
    for c in external {
        for (action, _) in &c.serves_actions {
            let goal = topics
                .iter()
                .find(|l| l.event_name == action_event(action, "goal_handle"));
            let with_id = |part: &str| {
                let e = model.event_id(&action_event(action, part))?;
                Some((e, model.param_index(e, "goal_id")?))
            };
            let goal_id = goal.and_then(|g| model.param_index(g.event, "goal_id"));
            match (
                goal,
                goal_id,
                with_id("goal_accepted"),
                with_id("goal_rejected"),
            ) {
                (Some(goal), Some(goal_id), Some(accepted), Some(rejected)) => {
                    out.push(GoalRoute {
                        path: action.trim_start_matches('/').to_string(),
                        goal: goal.clone(),
                        goal_id,
                        accepted,
                        rejected,
                    })
                }
                _ => warnings.push(format!(
                    "--external {}: nothing in the model sends goals to {action}; \
                     it is not bridged",
                    c.name
                )),
            }
        }
    }
    out
}

/// The iceoryx2 ends of a run: its node, the publisher of its topics and the bridges to
/// the processes of [`Wiring`].
pub struct Bridges {
    /// The run's publisher.
    pub publisher: TopicPublisher,
    /// The topics the processes publish.
    pub inbound: TopicSubscriber,
    /// The services the processes serve.
    pub services: ServiceBridge,
    /// The services and actions the processes call.
    pub servers: ServiceServers,
    /// The actions the processes serve.
    pub goals: GoalBridge,
}

/// The run's iceoryx2 node, handling termination requests itself (SIGINT and SIGTERM stop
/// the run at its next step).
pub fn node() -> Result<Node<Ipc>, LiveError> {
    NodeBuilder::new()
        .signal_handling_mode(SignalHandlingMode::HandleTerminationRequests)
        .create::<Ipc>()
        .map_err(|e| LiveError::ipc("node", e))
}

impl Bridges {
    /// Opens the publisher and the bridges of `wiring` on `node`, every service under
    /// `prefix`.
    pub fn open(
        node: &Node<Ipc>,
        model: &CompiledModel,
        wiring: Wiring,
        prefix: &str,
    ) -> Result<Bridges, LiveError> {
        Ok(Bridges {
            publisher: TopicPublisher::new(node, model, wiring.topics, prefix)?,
            inbound: TopicSubscriber::new(node, wiring.inbound, prefix)?,
            services: ServiceBridge::new(node, model.event_count(), wiring.served, prefix)?,
            servers: ServiceServers::new(node, model.event_count(), wiring.called, prefix)?,
            goals: GoalBridge::new(node, wiring.routes, prefix)?,
        })
    }
}

/// The services the external components call that are served to ROS 2 clients over
/// DDS, and the warnings about everything else they do, which is not bridged over DDS.
pub fn dds_services(
    model: &CompiledModel,
    external: &[ExternalComponent],
) -> (Vec<ServiceRoute>, Vec<String>) {
    let mut routes = Vec::new();
    let mut warnings = Vec::new();
    for c in external {
        for (what, list) in [
            ("publishes", &c.publishes),
            ("subscribes to", &c.subscribes),
            ("serves", &c.serves),
            ("serves action", &c.serves_actions),
            ("calls action", &c.calls_actions),
        ] {
            for (name, _) in list.iter() {
                warnings.push(format!(
                    "--external {}: it {what} {name}, which is not bridged over DDS \
                     (only the services it calls are served to ROS 2 clients)",
                    c.name
                ));
            }
        }
        for (service, ty) in &c.calls {
            let event =
                |response| model.event_id(&service_client_event(service, &c.name, response));
            match (event(false), event(true)) {
                (Some(request), Some(response)) => routes.push(ServiceRoute {
                    service: service.clone(),
                    type_name: ty.clone(),
                    request,
                    response,
                }),
                _ => warnings.push(format!(
                    "--external {}: nothing in the model serves {service}; it is not \
                     served on DDS",
                    c.name
                )),
            }
        }
    }
    (routes, warnings)
}

/// The DDS writers of `run --ros2`: one per topic and per service of the model, typed by
/// what the robot model's main file and node models declare.
pub struct DdsPlan {
    /// The writers' routes.
    pub routes: Vec<Route>,
    /// The interface packages the types were found in.
    pub packages: Packages,
    /// What is not published, and why.
    pub warnings: Vec<String>,
}

impl DdsPlan {
    /// Reads the main file at `main_path` for the types its node models declare, finds the
    /// interface packages (`interfaces` first), and plans a writer per ROS message event
    /// of `model`.
    pub fn new(
        main_path: &Path,
        interfaces: Vec<PathBuf>,
        model: &CompiledModel,
    ) -> Result<DdsPlan, PackageErrors> {
        let mut sm = SourceMap::new();
        let main =
            crate::robot::main_file::MainFile::read(&mut sm, main_path).map_err(PackageErrors)?;
        let types = declared_types(&main);
        let packages = Packages::discover_in(&mut sm, main_path, interfaces)?;
        let (routes, warnings) = plan(model, &types, &packages);
        Ok(DdsPlan {
            routes,
            packages,
            warnings,
        })
    }
}

/// A `--qos TOPIC=SETTINGS` option of `run --ros2` that does not apply.
#[derive(Debug)]
pub enum QosError {
    /// Not `TOPIC=SETTINGS`.
    Syntax(String),
    /// A topic the run does not publish.
    NotPublished {
        /// The option as given.
        flag: String,
        /// The topic.
        topic: String,
    },
    /// Settings that do not read.
    Settings {
        /// The option as given.
        flag: String,
        /// Why.
        error: DdsError,
    },
}

impl fmt::Display for QosError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            QosError::Syntax(q) => write!(
                f,
                "--qos {q}: expected /topic=reliability=best_effort,durability=transient_local,..."
            ),
            QosError::NotPublished { flag, topic } => {
                write!(f, "--qos {flag}: the run does not publish `{topic}`")
            }
            QosError::Settings { flag, error } => write!(f, "--qos {flag}: {error}"),
        }
    }
}

impl std::error::Error for QosError {}

/// The writers' QoS that `--qos` options set, over ROS 2's default, per topic the run
/// publishes (`routes`).
pub fn topic_qos(flags: &[String], routes: &[Route]) -> Result<BTreeMap<String, Qos>, QosError> {
    let mut qos: BTreeMap<String, Qos> = BTreeMap::new();
    for q in flags {
        let Some((topic, settings)) = q.split_once('=') else {
            return Err(QosError::Syntax(q.clone()));
        };
        let topic = topic.trim();
        if !routes.iter().any(|r| r.topic == topic) {
            return Err(QosError::NotPublished {
                flag: q.clone(),
                topic: topic.to_string(),
            });
        }
        let entry = qos
            .entry(topic.to_string())
            .or_insert_with(Qos::ros_default);
        *entry = entry
            .with_list(settings)
            .map_err(|error| QosError::Settings {
                flag: q.clone(),
                error,
            })?;
    }
    Ok(qos)
}
