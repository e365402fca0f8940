//! `hindsight run --external`: node models of the museum guide played by code in this test over iceoryx2 (a battery topic in, an alarm service answered), and the hand-written battery example.

#[path = "live_common/mod.rs"]
mod live_common;

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::Arc;
use std::time::Duration;

use iceoryx2::prelude::*;
use live_common::{example, finish, finish_polling, node, raw_subscriber, unique, Guard};

fn museum() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../examples/museum-guide")
}

/// Plays BatteryComponent (a low level every `period`) and NotifyUserComponent (answers
/// StartAlarm with is_ok = true) until `stop`; counts the requests it answered.
fn play_battery_and_alarm(
    prefix: String,
    level: i64,
    period: Duration,
    stop: Arc<AtomicBool>,
    requests: Arc<AtomicU64>,
) -> std::thread::JoinHandle<()> {
    let (ready_tx, ready_rx) = std::sync::mpsc::channel();
    let player = std::thread::spawn(move || {
        // iceoryx2 ports are not `Send`: the thread makes its own.
        let node = node();
        let battery =
            ServiceName::new(&format!("{prefix}/BatteryComponent/battery_level")).unwrap();
        let publisher = node
            .service_builder(&battery)
            .publish_subscribe::<[u8]>()
            .open_or_create()
            .unwrap()
            .publisher_builder()
            .initial_max_slice_len(16)
            .create()
            .unwrap();
        let alarm = ServiceName::new(&format!("{prefix}/NotifyUserComponent/StartAlarm")).unwrap();
        let server = node
            .service_builder(&alarm)
            .request_response::<[u8], [u8]>()
            .open_or_create()
            .unwrap()
            .server_builder()
            .initial_max_slice_len(16)
            .create()
            .unwrap();
        ready_tx.send(()).unwrap();
        let mut seq = 0u64;
        let mut last: Option<std::time::Instant> = None;
        while !stop.load(Ordering::SeqCst) {
            if last.is_none_or(|t| t.elapsed() >= period) {
                last = Some(std::time::Instant::now());
                let mut p = [0u8; 16];
                p[0..8].copy_from_slice(&level.to_le_bytes());
                p[8..16].copy_from_slice(&seq.to_le_bytes());
                let s = publisher.loan_slice_uninit(16).unwrap();
                s.write_from_slice(&p).send().unwrap();
                seq += 1;
            }
            while let Some(req) = server.receive().unwrap() {
                // StartAlarm's request has no field: 8 bytes of seq.
                assert_eq!(req.payload().len(), 8);
                let n = requests.fetch_add(1, Ordering::SeqCst);
                let mut answer = [0u8; 9];
                answer[0] = 1;
                answer[1..9].copy_from_slice(&n.to_le_bytes());
                let r = req.loan_slice_uninit(9).unwrap();
                r.write_from_slice(&answer).send().unwrap();
            }
            std::thread::sleep(Duration::from_millis(1));
        }
    });
    ready_rx.recv().unwrap();
    player
}

/// The run's mirror of StartAlarm's responses (`.../StartAlarm/response`): is_ok bytes.
fn response_mirror(
    node: &Node<ipc::Service>,
    prefix: &str,
) -> iceoryx2::port::subscriber::Subscriber<ipc::Service, [u8], ()> {
    raw_subscriber(
        node,
        &format!("{prefix}/NotifyUserComponent/StartAlarm/response"),
    )
}

fn run_museum(prefix: &str, extra: &[&str]) -> Guard {
    let child = Command::new(env!("CARGO_BIN_EXE_hindsight"))
        .arg("run")
        .arg(museum())
        .args(["--prefix", prefix, "--seed", "1"])
        .args(extra)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    Guard(Some(child))
}

#[test]
fn a_low_battery_from_a_process_makes_the_model_call_the_alarm_process() {
    let prefix = unique("external");
    let stop = Arc::new(AtomicBool::new(false));
    let requests = Arc::new(AtomicU64::new(0));
    let node = node();
    let mirror = response_mirror(&node, &prefix);
    // 20 % every 50 ms of wall-clock time: every model second at speed 20.
    let player = play_battery_and_alarm(
        prefix.clone(),
        20,
        Duration::from_millis(50),
        stop.clone(),
        requests.clone(),
    );
    let mut run = run_museum(
        &prefix,
        &[
            "--external",
            "BatteryComponent",
            "--external",
            "NotifyUserComponent",
            "--speed",
            "20",
            "--duration",
            "20s",
        ],
    );
    let mut mirrored = Vec::new();
    let (status, err) = finish_polling(&mut run, || {
        while let Some(s) = mirror.receive().unwrap() {
            mirrored.push(s.payload().to_vec());
        }
    });
    stop.store(true, Ordering::SeqCst);
    player.join().unwrap();
    assert!(status.success(), "{err}");
    let n = requests.load(Ordering::SeqCst);
    assert!(n >= 1, "no StartAlarm request reached the process:\n{err}");
    assert!(
        err.contains(&format!(
            "NotifyUserComponent/StartAlarm: {n} requests, {n} answered, 0 unanswered, 0 malformed"
        )),
        "{err}"
    );
    assert!(err.contains("samples posted, 0 malformed, 0 lost"), "{err}");
    // The answers entered the model: the run mirrors the server's responses.
    for (k, m) in mirrored.iter().enumerate() {
        assert_eq!(m.len(), 9, "is_ok + seq");
        assert_eq!(m[0], 1, "is_ok as the process answered");
        assert_eq!(u64::from_le_bytes(m[1..9].try_into().unwrap()), k as u64);
    }
    assert_eq!(mirrored.len() as u64, n, "{err}");
}

#[test]
fn without_a_process_the_battery_stays_silent_and_nobody_is_alarmed() {
    // The component is left out and nobody plays it: the level never falls, no alarm.
    let prefix = unique("external-silent");
    let mut run = run_museum(
        &prefix,
        &[
            "--external",
            "NotifyUserComponent",
            "--speed",
            "50",
            "--duration",
            "20s",
        ],
    );
    let (status, err) = finish(&mut run);
    assert!(status.success(), "{err}");
    assert!(
        err.contains("NotifyUserComponent/StartAlarm: 0 requests"),
        "{err}"
    );
}

#[test]
fn the_hand_written_battery_replaces_its_model() {
    let prefix = unique("external-example");
    let node = node();
    let tap = raw_subscriber(&node, &format!("{prefix}/BatteryComponent/battery_level"));
    let mut run = run_museum(
        &prefix,
        &[
            "--external",
            "BatteryComponent",
            "--speed",
            "20",
            "--duration",
            "10s",
        ],
    );
    let battery = Command::new(example("battery_component"))
        .args(["--prefix", &prefix, "--period", "1s", "--speed", "20"])
        .args(["--count", "8"])
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut battery = Guard(Some(battery));
    // What the process published: 100, 99, ... with seq 0, 1, ...
    let mut got = Vec::new();
    let mut drain = || {
        while let Some(s) = tap.receive().unwrap() {
            let p = s.payload();
            assert_eq!(p.len(), 16);
            got.push((
                i64::from_le_bytes(p[0..8].try_into().unwrap()),
                u64::from_le_bytes(p[8..16].try_into().unwrap()),
            ));
        }
    };
    let (battery_status, battery_err) = finish_polling(&mut battery, &mut drain);
    let (status, err) = finish_polling(&mut run, &mut drain);
    assert!(status.success(), "{err}");
    assert!(battery_status.success(), "{battery_err}");
    assert!(
        err.contains("run: BatteryComponent is played by a process: publishes /BatteryComponent/battery_level"),
        "{err}"
    );
    let want: Vec<(i64, u64)> = (0..8).map(|k| (100 - k as i64, k)).collect();
    assert_eq!(got, want);
    // And the run took them in (all but those published before its subscriber existed).
    let posted: u64 = err
        .lines()
        .find_map(|l| {
            l.strip_prefix(&format!(
                "run: from {prefix}/BatteryComponent/battery_level: "
            ))
            .and_then(|rest| rest.split(' ').next())
            .and_then(|n| n.parse().ok())
        })
        .unwrap_or_else(|| panic!("no inbound report:\n{err}"));
    assert!(posted >= 4, "{posted} posted:\n{err}");
}

const ADDER_MAIN: &str = r#"<roaml>
  <parameters><max_time value="30" unit="s"/></parameters>
  <node_models>
    <input type="ros-scxml" src="./adder.scxml"/>
    <input type="ros-scxml" src="./asker.scxml"/>
  </node_models>
  <properties><input type="xml" src="./props.xml"/></properties>
</roaml>
"#;

const ADDER: &str = r#"<scxml name="Adder" initial="idle" version="1.0" xmlns="http://www.w3.org/2005/07/scxml">
  <ros_service_server service_name="/adder/add" type="example_interfaces/AddTwoInts"/>
  <state id="idle">
    <ros_service_handle_request name="/adder/add" target="idle">
      <ros_service_send_response name="/adder/add">
        <field name="sum" expr="_req.a + _req.b"/>
      </ros_service_send_response>
    </ros_service_handle_request>
  </state>
</scxml>
"#;

const ASKER: &str = r#"<scxml name="Asker" initial="ask" version="1.0" xmlns="http://www.w3.org/2005/07/scxml">
  <ros_service_client service_name="/adder/add" type="example_interfaces/AddTwoInts"/>
  <ros_time_rate name="t" rate_hz="1"/>
  <state id="ask">
    <ros_rate_callback name="t" target="wait">
      <ros_service_send_request name="/adder/add">
        <field name="a" expr="1"/>
        <field name="b" expr="2"/>
      </ros_service_send_request>
    </ros_rate_callback>
  </state>
  <state id="wait">
    <ros_service_handle_response name="/adder/add" target="ask"/>
  </state>
</scxml>
"#;

const ADDER_PROPS: &str = r#"<properties>
  <ports>
    <ros_service service_name="/adder/add" type="example_interfaces/AddTwoInts" event="response">
      <state_var id="sum" type="int64" field="sum" expr="0"/>
    </ros_service>
  </ports>
  <guarantees>
    <property id="small_sums" logic="pmtl" expr="historically({sum &lt; 100})"/>
  </guarantees>
</properties>
"#;

/// Writes a model's files into a fresh scratch folder.
fn model_dir(tag: &str, files: &[(&str, &str)]) -> PathBuf {
    let dir = live_common::scratch(tag);
    for (name, text) in files {
        std::fs::write(dir.join(name), text).unwrap();
    }
    dir
}

/// Runs the model in `dir` for 20 s at speed 10 with node `external` played by this test,
/// which calls `PREFIX/<path>` with each request in turn once the run serves it (`poll`
/// runs meanwhile); returns the answers and the run's stderr.
fn call_while_running(
    dir: &Path,
    external: &str,
    prefix: &str,
    path: &str,
    requests: &[Vec<u8>],
    mut poll: impl FnMut(),
) -> (Vec<Vec<u8>>, String) {
    let node = node();
    let name = ServiceName::new(&format!("{prefix}/{path}")).unwrap();
    let client = node
        .service_builder(&name)
        .request_response::<[u8], [u8]>()
        .open_or_create()
        .unwrap()
        .client_builder()
        .initial_max_slice_len(requests.iter().map(Vec::len).max().unwrap_or(8))
        .create()
        .unwrap();
    let mut run = Guard(Some(
        Command::new(env!("CARGO_BIN_EXE_hindsight"))
            .arg("run")
            .arg(dir)
            .args(["--prefix", prefix, "--external", external])
            .args(["--speed", "10", "--duration", "20s"])
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap(),
    ));
    let mut answers = Vec::new();
    let mut next = 0;
    let mut pending = None;
    let (status, err) = live_common::finish_polling(&mut run, || {
        poll();
        if pending.is_none() && next < requests.len() {
            let r = client.loan_slice_uninit(requests[next].len()).unwrap();
            let sent = r.write_from_slice(&requests[next]).send().unwrap();
            // Before the run's server is up nobody answers: ask again.
            if sent.number_of_server_connections() > 0 {
                pending = Some(sent);
                next += 1;
            }
        }
        if let Some(p) = &pending {
            if let Some(resp) = p.receive().unwrap() {
                answers.push(resp.payload().to_vec());
                drop(resp);
                pending = None;
            }
        }
    });
    assert!(status.success(), "{err}");
    (answers, err)
}

#[test]
fn a_process_calls_a_service_the_model_serves() {
    let dir = model_dir(
        "adder",
        &[
            ("main.xml", ADDER_MAIN),
            ("adder.scxml", ADDER),
            ("asker.scxml", ASKER),
            ("props.xml", ADDER_PROPS),
        ],
    );
    let prefix = unique("external-client");
    // AddTwoInts request: a i64, b i64, seq u64; response: sum i64, seq u64.
    let requests: Vec<Vec<u8>> = (0..3i64)
        .map(|k| {
            let mut p = vec![0u8; 24];
            p[0..8].copy_from_slice(&(k * 100).to_le_bytes());
            p[8..16].copy_from_slice(&7i64.to_le_bytes());
            p[16..24].copy_from_slice(&(k as u64).to_le_bytes());
            p
        })
        .collect();
    let (answers, err) = call_while_running(&dir, "Asker", &prefix, "adder/add", &requests, || {});
    let sums: Vec<i64> = answers
        .iter()
        .map(|b| {
            assert_eq!(b.len(), 16, "sum + seq");
            i64::from_le_bytes(b[0..8].try_into().unwrap())
        })
        .collect();
    assert_eq!(sums, vec![7, 107, 207], "{err}");
    assert!(
        err.contains(&format!(
            "run: serving {prefix}/adder/add: 3 requests from processes, 3 answered"
        )),
        "{err}"
    );
}

/// The layout `hindsight run` uses for one model event, from the library.
fn layout_of_event(
    model: &hindsight::verify::sim::CompiledModel,
    event: &str,
) -> hindsight::live::publish::TopicLayout {
    let (all, _) = hindsight::live::publish::layouts(model);
    all.into_iter()
        .find(|l| l.event_name == event)
        .unwrap_or_else(|| panic!("no layout for {event}"))
}

fn offset(l: &hindsight::live::publish::TopicLayout, field: &str) -> usize {
    l.fields
        .iter()
        .find(|f| f.name == field)
        .unwrap_or_else(|| panic!("{} has no field {field}: {:?}", l.event_name, l.fields))
        .offset
}

/// Plays NavigationComponent for 30 s of the museum at speed 10: accepts every goal, sends
/// three feedbacks and (with `results`) a success; returns the goals and the run's stderr.
fn navigation_session(results: bool) -> (Vec<(i64, i64)>, String) {
    let main = hindsight::verify::robot::load::main_file_of(&museum()).unwrap();
    let (robot, ext) =
        hindsight::verify::robot::load::load_without(&main, &["NavigationComponent".to_string()])
            .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(ext[0].serves_actions.len(), 1);
    let goal = layout_of_event(
        &robot.model,
        "action_NavigationComponent__GoToPoi_goal_handle",
    );
    let feedback = layout_of_event(&robot.model, "action_NavigationComponent__GoToPoi_feedback");
    let result = layout_of_event(&robot.model, "action_NavigationComponent__GoToPoi_result");
    let (goal_id_at, poi_at) = (offset(&goal, "goal_id"), offset(&goal, "poi_number"));
    let (fb_goal, fb_status) = (offset(&feedback, "goal_id"), offset(&feedback, "status"));
    let (res_goal, res_code, res_ok) = (
        offset(&result, "goal_id"),
        offset(&result, "code"),
        offset(&result, "is_ok"),
    );
    let (fb_size, fb_seq, res_size, res_seq) = (
        feedback.size,
        feedback.seq_offset,
        result.size,
        result.seq_offset,
    );

    let prefix = unique("external-action");
    let stop = Arc::new(AtomicBool::new(false));
    let goals = Arc::new(std::sync::Mutex::new(Vec::<(i64, i64)>::new()));
    let (ready_tx, ready_rx) = std::sync::mpsc::channel();
    let navigation = {
        let (prefix, stop, goals) = (prefix.clone(), stop.clone(), goals.clone());
        std::thread::spawn(move || {
            let node = node();
            let svc = |s: &str| {
                ServiceName::new(&format!("{prefix}/NavigationComponent/GoToPoi{s}")).unwrap()
            };
            let server = node
                .service_builder(&svc(""))
                .request_response::<[u8], [u8]>()
                .open_or_create()
                .unwrap()
                .server_builder()
                .initial_max_slice_len(9)
                .create()
                .unwrap();
            let publisher = |s: &str, size: usize| {
                node.service_builder(&svc(s))
                    .publish_subscribe::<[u8]>()
                    .open_or_create()
                    .unwrap()
                    .publisher_builder()
                    .initial_max_slice_len(size)
                    .create()
                    .unwrap()
            };
            let fb_pub = publisher("/feedback", fb_size);
            let res_pub = publisher("/result", res_size);
            ready_tx.send(()).unwrap();
            let (mut fb_seq_n, mut res_seq_n) = (0u64, 0u64);
            // The goal being driven to: (goal_id, feedbacks sent, last feedback time).
            let mut driving: Option<(i64, u32, std::time::Instant)> = None;
            while !stop.load(Ordering::SeqCst) {
                while let Some(req) = server.receive().unwrap() {
                    let p = req.payload();
                    let gid = i64::from_le_bytes(p[goal_id_at..goal_id_at + 8].try_into().unwrap());
                    let poi = i64::from_le_bytes(p[poi_at..poi_at + 8].try_into().unwrap());
                    goals.lock().unwrap().push((gid, poi));
                    let mut answer = [0u8; 9];
                    answer[0] = 1; // accepted
                    let r = req.loan_slice_uninit(9).unwrap();
                    r.write_from_slice(&answer).send().unwrap();
                    driving = Some((gid, 0, std::time::Instant::now()));
                }
                if let Some((gid, n, last)) = driving {
                    // A feedback every 50 ms (0.5 s of model time), the result after three.
                    if last.elapsed() >= Duration::from_millis(50) {
                        if n < 3 || !results {
                            let mut b = vec![0u8; fb_size];
                            b[fb_goal..fb_goal + 8].copy_from_slice(&gid.to_le_bytes());
                            b[fb_status..fb_status + 8].copy_from_slice(&2i64.to_le_bytes());
                            b[fb_seq..fb_seq + 8].copy_from_slice(&fb_seq_n.to_le_bytes());
                            fb_seq_n += 1;
                            let s = fb_pub.loan_slice_uninit(fb_size).unwrap();
                            s.write_from_slice(&b).send().unwrap();
                            driving = Some((gid, n + 1, std::time::Instant::now()));
                        } else {
                            let mut b = vec![0u8; res_size];
                            b[res_goal..res_goal + 8].copy_from_slice(&gid.to_le_bytes());
                            b[res_code..res_code + 8].copy_from_slice(&4i64.to_le_bytes());
                            b[res_ok] = 1;
                            b[res_seq..res_seq + 8].copy_from_slice(&res_seq_n.to_le_bytes());
                            res_seq_n += 1;
                            let s = res_pub.loan_slice_uninit(res_size).unwrap();
                            s.write_from_slice(&b).send().unwrap();
                            driving = None;
                        }
                    }
                }
                std::thread::sleep(Duration::from_millis(1));
            }
        })
    };
    ready_rx.recv().unwrap();
    let mut run = run_museum(
        &prefix,
        &[
            "--external",
            "NavigationComponent",
            "--speed",
            "10",
            "--duration",
            "30s",
        ],
    );
    let (status, err) = finish(&mut run);
    stop.store(true, Ordering::SeqCst);
    navigation.join().unwrap();
    assert!(status.success(), "{err}");
    let goals = goals.lock().unwrap().clone();
    (goals, err)
}

#[test]
fn a_navigation_process_serves_the_museum_s_action() {
    let (goals, err) = navigation_session(true);
    let prefix_line = err
        .lines()
        .find(|l| l.starts_with("run: action "))
        .unwrap_or_else(|| panic!("no action report:\n{err}"))
        .to_string();
    // The tree reached a point of interest with the process's result and sent the next goal.
    assert!(goals.len() >= 2, "goals {goals:?}:\n{err}");
    assert!(
        prefix_line.ends_with(&format!(
            "/NavigationComponent/GoToPoi: {n} goals, {n} answered, 0 unanswered, 0 malformed answers",
            n = goals.len()
        )),
        "{err}"
    );
    assert!(err.contains("GoToPoi/result: "), "{err}");
}

#[test]
fn without_a_result_the_museum_waits_at_its_first_point_of_interest() {
    // Feedback only: the skill keeps answering RUNNING and no second goal is sent.
    let (goals, err) = navigation_session(false);
    assert_eq!(goals.len(), 1, "goals {goals:?}:\n{err}");
}

const MOVER_MAIN: &str = r#"<roaml>
  <parameters><max_time value="30" unit="s"/></parameters>
  <node_models>
    <input type="ros-scxml" src="./mover.scxml"/>
    <input type="ros-scxml" src="./commander.scxml"/>
  </node_models>
  <properties><input type="xml" src="./props.xml"/></properties>
</roaml>
"#;

const MOVER: &str = r#"<scxml name="Mover" initial="idle" version="1.0" xmlns="http://www.w3.org/2005/07/scxml">
  <ros_action_server name="srv" action_name="/mover/move" type="example_interfaces/Fibonacci"/>
  <ros_topic_publisher topic="/moved" type="std_msgs/Int32"/>
  <datamodel><data id="gid" type="int32" expr="0"/><data id="order" type="int32" expr="0"/></datamodel>
  <state id="idle">
    <ros_action_handle_goal name="srv" target="work">
      <assign location="gid" expr="_action.goal_id"/>
      <assign location="order" expr="_goal.order"/>
    </ros_action_handle_goal>
  </state>
  <state id="work">
    <onentry>
      <if cond="order &gt; 0">
        <ros_action_accept_goal name="srv" goal_id="gid"/>
      <else/>
        <ros_action_reject_goal name="srv" goal_id="gid"/>
      </if>
    </onentry>
    <transition target="idle" cond="order &gt; 0">
      <ros_action_succeed name="srv" goal_id="gid"><field name="sequence" expr="[0, 1]"/></ros_action_succeed>
      <ros_topic_publish name="/moved"><field name="data" expr="order"/></ros_topic_publish>
    </transition>
    <transition target="idle" cond="order &lt;= 0"/>
  </state>
</scxml>
"#;

const COMMANDER: &str = r#"<scxml name="Commander" initial="go" version="1.0" xmlns="http://www.w3.org/2005/07/scxml">
  <ros_action_client name="cl" action_name="/mover/move" type="example_interfaces/Fibonacci"/>
  <state id="go">
    <onentry><ros_action_send_goal name="cl"><field name="order" expr="3"/></ros_action_send_goal></onentry>
    <ros_action_handle_goal_response name="cl" accept="wait" reject="done"/>
  </state>
  <state id="wait">
    <ros_action_handle_success_result name="cl" target="done"/>
  </state>
  <state id="done"/>
</scxml>
"#;

const MOVER_PROPS: &str = r#"<properties>
  <ports>
    <ros_topic topic="/moved" type="std_msgs/Int32"><state_var id="x" type="int32" field="data" expr="0"/></ros_topic>
  </ports>
  <guarantees><property id="p" logic="pmtl" expr="historically({x &gt;= 0})"/></guarantees>
</properties>
"#;

#[test]
fn a_process_sends_goals_to_an_action_the_model_serves() {
    let dir = model_dir(
        "mover",
        &[
            ("main.xml", MOVER_MAIN),
            ("mover.scxml", MOVER),
            ("commander.scxml", COMMANDER),
            ("props.xml", MOVER_PROPS),
        ],
    );
    let prefix = unique("external-action-client");
    let node = node();
    let moved = raw_subscriber(&node, &format!("{prefix}/moved"));
    // Fibonacci goal: order i64, then seq; the answer: accepted byte, then seq.
    let requests: Vec<Vec<u8>> = [3i64, 0, 5]
        .iter()
        .enumerate()
        .map(|(k, order)| {
            let mut p = vec![0u8; 16];
            p[0..8].copy_from_slice(&order.to_le_bytes());
            p[8..16].copy_from_slice(&(k as u64).to_le_bytes());
            p
        })
        .collect();
    let mut published = Vec::new();
    let (answers, err) =
        call_while_running(&dir, "Commander", &prefix, "mover/move", &requests, || {
            while let Some(s) = moved.receive().unwrap() {
                published.push(i64::from_le_bytes(s.payload()[0..8].try_into().unwrap()));
            }
        });
    // The model's server accepts a positive order and rejects 0; it reports the orders it
    // carried out on /moved.
    assert!(answers.iter().all(|a| a.len() == 9), "accepted byte + seq");
    let accepted: Vec<u8> = answers.iter().map(|a| a[0]).collect();
    assert_eq!(accepted, vec![1, 0, 1], "{err}");
    assert_eq!(published, vec![3, 5], "{err}");
    assert!(
        err.contains(&format!(
            "run: serving {prefix}/mover/move: 3 requests from processes, 3 answered"
        )),
        "{err}"
    );
}
