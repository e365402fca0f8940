//! The lowering harness shared by the BT tests: a tree and leaf scripts lowered by
//! hindsight in-process, simulated, and observed as the oracle reports them (root status
//! per tick, leaf ticks and halts in order); plus the comparison with the oracle.

#![allow(dead_code)]

use hindsight::verify::expr::Value;
use hindsight::verify::model::source::{FileId, SourceMap};
use hindsight::verify::model::{xml, Diagnostics, ModelSource};
use hindsight::verify::robot::bt::{self, BtInput, BtSemantics, Halts};
use hindsight::verify::sim::{
    CompiledModel, EndReason, Flow, Observer, RunConfig, SentMessage, Simulator,
};
use hindsight_tests::bt::model;
use hindsight_tests::bt::oracle::{self, LeafEvent, Reading, Scripts};
use hindsight_tests::bt::tree::{self, Kind, Status, Tree};
use rand_core::SeedableRng;
use rand_xoshiro::Xoshiro256PlusPlus;
use std::collections::BTreeSet;

/// Root statuses, one per root tick, and what the leaves received.
pub type Run = (Vec<Status>, Vec<LeafEvent>);

/// Records the root's status per tick and the leaves' ticks and halts. The root's status
/// is the parameter of `status_event` when one is given (a driver that reports executor
/// ticks), else of node 1000's answer to the root machine.
struct Watch<'a> {
    leaves: &'a BTreeSet<u32>,
    status_event: Option<&'a str>,
    statuses: Vec<Status>,
    log: Vec<LeafEvent>,
    bad: Option<String>,
}

impl Watch<'_> {
    fn status(&mut self, msg: &SentMessage<'_>) -> Flow {
        let s = match msg.param(0) {
            Some(Value::Int(1)) => Status::Success,
            Some(Value::Int(2)) => Status::Failure,
            Some(Value::Int(3)) => Status::Running,
            // SKIPPED, the node IDLE (4) or RUNNING (5) afterwards (`--bt btcpp`).
            Some(Value::Int(4 | 5)) => Status::Skipped,
            other => {
                self.bad = Some(format!("root answered {other:?}"));
                return Flow::Stop;
            }
        };
        self.statuses.push(s);
        Flow::Continue
    }
}

impl Observer for Watch<'_> {
    fn on_send(&mut self, _time: u64, msg: &SentMessage<'_>) -> Flow {
        let ev = msg.event_name();
        if self.status_event == Some(ev) {
            return self.status(msg);
        }
        let Some(rest) = ev.strip_prefix("bt_") else {
            return Flow::Continue;
        };
        let Some((id, what)) = rest.split_once('_') else {
            return Flow::Continue;
        };
        let Ok(id) = id.parse::<u32>() else {
            return Flow::Continue;
        };
        match what {
            "tick" if self.leaves.contains(&id) => self.log.push(LeafEvent::Tick(id)),
            "halt" if self.leaves.contains(&id) => self.log.push(LeafEvent::Halt(id)),
            "response"
                if self.status_event.is_none()
                    && id == 1000
                    && msg.target_name().starts_with("bt_root_fsm") =>
            {
                return self.status(msg);
            }
            _ => {}
        }
        Flow::Continue
    }
}

/// How [`lower_and_run`] drives the lowered tree.
pub struct Drive<'a> {
    /// Which children the control nodes halt.
    pub halts: Halts,
    /// Whose rules the tree follows.
    pub semantics: BtSemantics,
    /// The text of the machine that replaces the root machine, given the root machine's
    /// name and node 1000's machine name.
    pub driver: &'a dyn Fn(&str, &str) -> String,
    /// The event whose parameter is the root's status (`None`: node 1000's answers).
    pub status_event: Option<&'a str>,
    /// The run's step limit.
    pub max_steps: u64,
}

/// Lowers `xml` with one plugin per leaf type, replaces the root machine by the driver,
/// runs it once (seed 1): what the harness saw, and how the run ended.
pub fn lower_and_run(
    xml_text: &str,
    scripts: &Scripts,
    drive: &Drive<'_>,
) -> Result<(Run, EndReason), String> {
    let tree = tree::read(xml_text)?;
    let leaves: BTreeSet<u32> = tree
        .nodes
        .iter()
        .filter(|n| matches!(n.kind, Kind::Leaf(_)))
        .map(|n| n.id)
        .collect();
    let mut sm = SourceMap::new();
    let tree_id = sm.add("t.xml", xml_text.to_string());
    let plugins = model::plugins(scripts)
        .into_iter()
        .map(|(n, text)| sm.add(format!("{n}.ascxml"), text))
        .collect();
    let input = BtInput {
        tree: tree_id,
        plugins,
        tick_rate_hz: 1.0,
        tick_if_not_running: true,
        halts: drive.halts,
        semantics: drive.semantics,
    };
    let mut machines = bt::lower(&sm, &input).map_err(|ds| Diagnostics(ds).to_string())?;
    let name = |m: &xml::Element| m.attr_value("name").unwrap_or_default().to_string();
    let (root_name, node_name) = (name(&machines[0]), name(&machines[1]));
    let drv = sm.add("driver.scxml", (drive.driver)(&root_name, &node_name));
    machines[0] = xml::parse(&sm, drv).map_err(|d| d.to_string())?;
    let mut src = ModelSource {
        sources: sm,
        ..ModelSource::default()
    };
    let mut errs = Diagnostics::default();
    for m in &machines {
        src.add_machine_tree(m, FileId(0), &mut errs);
    }
    if !errs.is_empty() {
        return Err(errs.to_string());
    }
    let compiled = CompiledModel::compile(src).map_err(|e| e.to_string())?;
    let mut w = Watch {
        leaves: &leaves,
        status_event: drive.status_event,
        statuses: Vec::new(),
        log: Vec::new(),
        bad: None,
    };
    let cfg = RunConfig {
        max_steps: drive.max_steps,
        ..RunConfig::default()
    };
    let out =
        Simulator::new(&compiled).run(&mut Xoshiro256PlusPlus::seed_from_u64(1), &cfg, &mut w);
    if let Some(b) = w.bad {
        return Err(b);
    }
    Ok(((w.statuses, w.log), out.end))
}

/// Lowers `xml` (AS2FM's semantics) with one plugin per leaf type, ticks the root `ticks`
/// times.
pub fn lowered(
    xml_text: &str,
    scripts: &Scripts,
    ticks: usize,
    halts: Halts,
) -> Result<Run, String> {
    let driver = |root: &str, node: &str| model::driver(root, node, ticks);
    let drive = Drive {
        halts,
        semantics: BtSemantics::default(),
        driver: &driver,
        status_event: None,
        max_steps: 5_000_000,
    };
    lower_and_run(xml_text, scripts, &drive).map(|(run, _)| run)
}

/// The oracle's run of the same case.
pub fn reference(
    xml_text: &str,
    scripts: &Scripts,
    ticks: usize,
    reading: Reading,
) -> Result<Run, String> {
    let tree: Tree = tree::read(xml_text)?;
    oracle::run(&tree, scripts, reading, ticks)
}

/// Where two runs first differ, or `None`.
pub fn diff(a: &Run, b: &Run) -> Option<String> {
    if a.0 != b.0 {
        return Some(format!("root statuses: {:?} against {:?}", a.0, b.0));
    }
    if a.1 != b.1 {
        let i =
            a.1.iter()
                .zip(&b.1)
                .position(|(x, y)| x != y)
                .unwrap_or(a.1.len().min(b.1.len()));
        return Some(format!(
            "leaf events differ at {i} of {}/{}: {:?} against {:?}\n  all: {:?}\n  all: {:?}",
            a.1.len(),
            b.1.len(),
            a.1.get(i),
            b.1.get(i),
            a.1,
            b.1
        ));
    }
    None
}

/// Keeps the halts a leaf receives while RUNNING (its last answer): what BT.CPP's
/// `haltChild` delivers of a log where every reset child is halted.
pub fn running_halts_only(
    log: &[LeafEvent],
    scripts_of: impl Fn(u32, usize) -> Status,
) -> Vec<LeafEvent> {
    let mut ticks: std::collections::BTreeMap<u32, usize> = Default::default();
    let mut running: BTreeSet<u32> = BTreeSet::new();
    let mut out = Vec::new();
    for &e in log {
        match e {
            LeafEvent::Tick(id) => {
                let k = ticks.entry(id).or_default();
                if scripts_of(id, *k) == Status::Running {
                    running.insert(id);
                } else {
                    running.remove(&id);
                }
                *k += 1;
                out.push(e);
            }
            LeafEvent::Halt(id) => {
                if running.remove(&id) {
                    out.push(e);
                }
            }
        }
    }
    out
}

/// A case in text form for a failure message.
pub fn show(xml_text: &str, scripts: &Scripts, ticks: usize) -> String {
    let mut s = format!("ticks = {ticks}\ntree = '''{xml_text}'''\n[scripts]\n");
    for (k, v) in scripts {
        let names: Vec<&str> = v.iter().map(|s| s.name()).collect();
        s += &format!("{k} = {names:?}\n");
    }
    s
}

/// The tick rate of [`lower_and_run_clocked`]: 10 Hz, the oracle's default period
/// (`oracle::PERIOD_MS`).
pub const CLOCKED_RATE_HZ: f64 = 10.0;

/// Lowers `xml` under `semantics` (BT.CPP's) and runs `ticks` executor ticks with the
/// lowered root machine itself, the keeper of the timers of Timeout, Delay and Sleep
/// (`crates/robot/src/bt/btcpp4_time.rs`), ticking at [`CLOCKED_RATE_HZ`] in model time.
///
/// The ROS lowering is not run here, so its timer tags become plain SCXML: each
/// `<ros_rate_callback name="x">` a transition on `ros_time_rate.x`, and a ticker machine
/// plays the global timer, once per unit of the tree's clock (its period, or the tick
/// period without timers) sending the clock's event and then, every tick period, the
/// tick's, `ticks` times. Each answer of the root that ends an executor tick is also sent
/// as `tick_done` (observed as the tick's status).
pub fn lower_and_run_clocked(
    xml_text: &str,
    scripts: &Scripts,
    semantics: BtSemantics,
    ticks: usize,
    max_steps: u64,
) -> Result<(Run, EndReason), String> {
    let tree = tree::read(xml_text)?;
    let leaves: BTreeSet<u32> = tree
        .nodes
        .iter()
        .filter(|n| matches!(n.kind, Kind::Leaf(_)))
        .map(|n| n.id)
        .collect();
    let mut sm = SourceMap::new();
    let tree_id = sm.add("t.xml", xml_text.to_string());
    let plugins = model::plugins(scripts)
        .into_iter()
        .map(|(n, text)| sm.add(format!("{n}.ascxml"), text))
        .collect();
    let input = BtInput {
        tree: tree_id,
        plugins,
        tick_rate_hz: CLOCKED_RATE_HZ,
        tick_if_not_running: true,
        halts: Halts::As2fm,
        semantics,
    };
    let mut machines = bt::lower(&sm, &input).map_err(|ds| Diagnostics(ds).to_string())?;
    let root = &mut machines[0];
    let root_name = root.attr_value("name").unwrap_or_default().to_string();
    // The timers: (name, period in ns); the clock's name ends in `_timers`.
    let mut timers: Vec<(String, u64)> = Vec::new();
    root.children.retain(|c| match c {
        xml::Node::Element(e) if e.name == "ros_time_rate" => {
            let p =
                hindsight::verify::robot::rate::period(e.attr_value("rate_hz").unwrap_or_default())
                    .map(|p| p.period_ns)
                    .unwrap_or(0);
            timers.push((e.attr_value("name").unwrap_or_default().to_string(), p));
            false
        }
        _ => true,
    });
    fn plain(e: &mut xml::Element) {
        if e.name == "ros_rate_callback" {
            let name = e.remove_attr("name").map(|a| a.value).unwrap_or_default();
            e.name = "transition".into();
            e.set_attr("event", format!("ros_time_rate.{name}"));
        }
        for c in e.elements_mut() {
            plain(c);
        }
    }
    plain(root);
    for st in root.elements_mut().filter(|e| e.name == "state") {
        if st.attr_value("id") != Some("wait_tick_res") {
            continue;
        }
        for t in st.elements_mut() {
            if t.name == "transition"
                && t.attr_value("event") == Some("bt_1000_response")
                && t.attr_value("target") != Some("wait_tick_res")
            {
                let mut s = xml::Element::new("send", t.span);
                s.set_attr("event", "tick_done");
                s.set_attr("target", root_name.clone());
                let mut p = xml::Element::new("param", t.span);
                p.set_attr("name", "status");
                p.set_attr("expr", "_event.data.status");
                s.push(p);
                t.push(s);
            }
        }
    }
    let tick = timers
        .iter()
        .find(|t| t.0.ends_with("_tick"))
        .cloned()
        .ok_or("no tick timer")?;
    let clock = timers.iter().find(|t| t.0.ends_with("_timers")).cloned();
    let unit = clock.as_ref().map_or(tick.1, |c| c.1);
    let per = tick.1 / unit;
    let clock_send = clock.map_or(String::new(), |c| {
        format!(
            r#"<send event="ros_time_rate.{}" target="{root_name}"/>"#,
            c.0
        )
    });
    let ticker = format!(
        r#"<scxml xmlns="http://www.w3.org/2005/07/scxml" version="1.0" name="bt_test_ticker" initial="run">
<datamodel><data id="k" type="int32" expr="0"/><data id="n" type="int32" expr="0"/></datamodel>
<state id="run">
<onentry><send event="bt_test_step" target="bt_test_ticker" delay="1"/></onentry>
<transition event="bt_test_step" cond="n &lt; {ticks}" target="run"><assign location="k" expr="k + 1"/>{clock_send}<if cond="k % {per} == 0"><assign location="n" expr="n + 1"/><send event="ros_time_rate.{}" target="{root_name}"/></if></transition>
</state>
</scxml>"#,
        tick.0
    );
    let tk = sm.add("ticker.scxml", ticker);
    machines.push(xml::parse(&sm, tk).map_err(|d| d.to_string())?);
    let mut src = ModelSource {
        sources: sm,
        ..ModelSource::default()
    };
    let mut errs = Diagnostics::default();
    for m in &machines {
        src.add_machine_tree(m, FileId(0), &mut errs);
    }
    if !errs.is_empty() {
        return Err(errs.to_string());
    }
    let compiled = CompiledModel::compile(src).map_err(|e| e.to_string())?;
    let mut w = Watch {
        leaves: &leaves,
        status_event: Some("tick_done"),
        statuses: Vec::new(),
        log: Vec::new(),
        bad: None,
    };
    let cfg = RunConfig {
        max_steps,
        ..RunConfig::default()
    };
    let out =
        Simulator::new(&compiled).run(&mut Xoshiro256PlusPlus::seed_from_u64(1), &cfg, &mut w);
    if let Some(b) = w.bad {
        return Err(b);
    }
    Ok(((w.statuses, w.log), out.end))
}
