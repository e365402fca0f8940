//! A node model replaced by messages from outside the run: `load_without` leaves the component's behaviour out and the simulator posts what an [`Observer`] brings in.

use std::path::Path;

use hindsight::verify::robot::load::{load_without, main_file_of};
use hindsight::verify::sim::{
    EventId, EventSemantics, Flow, Inbox, Observer, Quiescence, RunConfig, Scalar, SentMessage,
    Simulator, EXTERNAL,
};
use rand_xoshiro::rand_core::SeedableRng;
use rand_xoshiro::Xoshiro256PlusPlus;

fn museum() -> std::path::PathBuf {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/museum-guide");
    main_file_of(&dir).unwrap()
}

const BATTERY: &str = "topic_BatteryComponent__battery_level_msg";
const ALARM: &str = "srv_NotifyUserComponent__StartAlarm_request";

/// Plays the battery: posts `levels[k]` at model time `at[k]`; records when the model
/// published the battery topic itself and when it asked for the alarm.
struct FakeBattery {
    battery: EventId,
    alarm: EventId,
    script: Vec<(u64, i64)>,
    posted: Vec<(u64, i64)>,
    model_published: usize,
    alarms: Vec<u64>,
}

impl Observer for FakeBattery {
    fn on_send(&mut self, time: u64, msg: &SentMessage<'_>) -> Flow {
        if msg.event() == self.battery {
            if msg.origin() == EXTERNAL {
                let level = match msg.param(0) {
                    Some(hindsight::verify::expr::Value::Int(v)) => v,
                    other => panic!("battery level {other:?}"),
                };
                self.posted.push((time, level));
            } else {
                self.model_published += 1;
            }
        }
        if msg.event() == self.alarm {
            self.alarms.push(time);
        }
        Flow::Continue
    }

    fn inputs(&mut self, time: u64, inbox: &mut Inbox) {
        while let Some(&(at, level)) = self.script.first() {
            if at > time {
                break;
            }
            inbox.push(self.battery, vec![(0, Scalar::Int(level))]);
            self.script.remove(0);
        }
    }
}

fn run_with(script: Vec<(u64, i64)>) -> FakeBattery {
    let (robot, external) = load_without(&museum(), &["BatteryComponent".to_string()])
        .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(external.len(), 1);
    assert_eq!(
        external[0].publishes,
        vec![(
            "/BatteryComponent/battery_level".to_string(),
            "std_msgs/Int32".to_string()
        )]
    );
    let model = &robot.model;
    let battery = model.event_id(BATTERY).unwrap();
    assert_eq!(
        model.event_params(battery).len(),
        1,
        "the topic keeps its field"
    );
    let mut obs = FakeBattery {
        battery,
        alarm: model.event_id(ALARM).unwrap(),
        script,
        posted: Vec::new(),
        model_published: 0,
        alarms: Vec::new(),
    };
    let cfg = RunConfig {
        max_time: 300,
        events: EventSemantics::As2fm,
        quiescence: Quiescence::AdvanceTime,
        ..RunConfig::default()
    };
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(7);
    Simulator::new(model).run(&mut rng, &cfg, &mut obs);
    obs
}

#[test]
fn a_low_level_from_outside_raises_the_alarm_and_the_model_never_publishes_the_battery() {
    let obs = run_with(vec![(1, 100), (10, 90), (20, 20), (30, 19)]);
    assert_eq!(
        obs.model_published, 0,
        "the left-out component still publishes"
    );
    assert_eq!(obs.posted, vec![(1, 100), (10, 90), (20, 20), (30, 19)]);
    let first = *obs
        .alarms
        .first()
        .expect("a level of 20 % raises the alarm");
    assert!(
        first > 20 && first <= 20 + 62,
        "alarm at {first}, the level fell at 20"
    );
}

#[test]
fn without_a_low_level_there_is_no_alarm() {
    let obs = run_with(vec![(1, 100), (10, 90), (20, 80)]);
    assert!(obs.alarms.is_empty(), "alarm at {:?}", obs.alarms);
    assert_eq!(obs.posted.len(), 3);
}

#[test]
fn two_messages_at_one_instant_are_both_posted_in_order() {
    // The second waits until the first was taken (AS2FM: one pending message per event).
    // Both within the same instant: the second goes in as soon as the model is idle.
    let obs = run_with(vec![(5, 50), (5, 40)]);
    assert_eq!(obs.posted, vec![(5, 50), (5, 40)]);
    // A flood (ten per unit) never falls behind: each unit's messages go in at that unit.
    let flood: Vec<(u64, i64)> = (1..=20u64)
        .flat_map(|t| (0..10).map(move |k| (t, 100 - k)))
        .collect();
    let obs = run_with(flood.clone());
    assert_eq!(obs.posted, flood);
}

#[test]
fn an_unknown_component_is_refused_and_every_kind_of_node_is_described() {
    let e = match load_without(&museum(), &["NoSuchNode".to_string()]) {
        Err(e) => e.to_string(),
        Ok(_) => panic!("an unknown name loads"),
    };
    assert!(e.contains("no node model is called `NoSuchNode`"), "{e}");
    assert!(e.contains("BatteryComponent"), "lists the node models: {e}");
    // An action client can be: its process sends the goals.
    let (_, ext) = load_without(&museum(), &["GoToPoiActionSkill".to_string()])
        .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(
        ext[0].calls_actions,
        vec![(
            "/NavigationComponent/GoToPoi".to_string(),
            "navigation_interfaces_dummy/GoToPoi".to_string()
        )]
    );
    // An action server can be: its threads go, goals go to the process.
    let (_, ext) = load_without(&museum(), &["NavigationComponent".to_string()])
        .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(
        ext[0].serves_actions,
        vec![(
            "/NavigationComponent/GoToPoi".to_string(),
            "navigation_interfaces_dummy/GoToPoi".to_string()
        )]
    );
    // A service client can be: the process calls the model's server.
    let (_, ext) =
        load_without(&museum(), &["AlarmSkill".to_string()]).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(
        ext[0].calls,
        vec![(
            "/NotifyUserComponent/StartAlarm".to_string(),
            "notify_user_interfaces_dummy/StartAlarm".to_string()
        )]
    );
    // A service server can be: its requests go to the process.
    let (_, ext) = load_without(&museum(), &["NotifyUserComponent".to_string()])
        .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(
        ext[0].serves,
        vec![(
            "/NotifyUserComponent/StartAlarm".to_string(),
            "notify_user_interfaces_dummy/StartAlarm".to_string()
        )]
    );
}
