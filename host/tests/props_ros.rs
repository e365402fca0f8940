//! Property files over ROS names: `<ros_topic>` / `<ros_service>` ports, patterns, bounds
//! in seconds. The museum guide's requirements written that way must judge every run of
//! the plain translation exactly as the step-bounded SCAN file does.

use std::path::{Path, PathBuf};

use hindsight::verify::observe::PropertySet;
use hindsight::verify::props::{parse_file, PortKind, ANY};
use hindsight::verify::sim::{CompiledModel, RunConfig};
use hindsight::verify::smc::runner::stream;
use hindsight::verify::study::Runner;

fn repo(relative: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("..")
        .join(relative)
}

fn write_props(name: &str, body: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("hindsight-props-ros-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(name);
    std::fs::write(&path, format!("<properties>\n{body}\n</properties>\n")).unwrap();
    path
}

#[test]
fn ros_ports_name_the_translated_messages() {
    let file = parse_file(&repo("examples/museum-guide/properties.xml")).unwrap();
    let port = |id: &str| file.port(id).unwrap();
    assert_eq!(
        port("battery_level").event,
        "topic_BatteryComponent__battery_level_msg"
    );
    assert_eq!(port("battery_level").origin, ANY);
    assert!(matches!(
        &port("battery_level").kind,
        PortKind::State { param, .. } if param == "ros_fields__data"
    ));
    assert_eq!(
        port("alarm").event,
        "srv_NotifyUserComponent__StartAlarm_request"
    );
    assert!(matches!(
        &port("poi_done_name").kind,
        PortKind::State { param, .. } if param == "ros_fields__field_name"
    ));
    // The recurrence pattern becomes the paper's formula with the bound in seconds.
    let recurrence = file
        .guarantees
        .iter()
        .find(|p| p.id == "battery_recurrence")
        .unwrap();
    assert_eq!(
        recurrence.formula.as_str(),
        "H(P[1s:] true -> P[:1s] {battery_published})"
    );
}

#[test]
fn patterns_become_past_time_formulas() {
    let path = write_props(
        "patterns.xml",
        r#"<ports><ros_topic topic_name="object_loc" type="m/Location">
             <state_var id="x" field="pose.x" type="float32" expr="0"/>
             <event_var id="e"/></ros_topic></ports>
           <guarantees>
             <property id="a" pattern="absence" event="e" before="x &gt; 1"/>
             <property id="b" pattern="response" event="x &gt; 1" response="e" within="6200" time_unit="ms"/>
             <property id="c" pattern="precedence" event="e" after="x == 2"/>
             <property id="d" pattern="existence"><event>x == 4.0 &amp;&amp; e</event><scope type="globally"/></property>
             <property id="f" pattern="response" event="x &gt; 1" response="e"/>
           </guarantees>"#,
    );
    let file = parse_file(&path).unwrap();
    let formula = |id: &str| {
        file.guarantees
            .iter()
            .find(|p| p.id == id)
            .unwrap()
            .formula
            .as_str()
            .to_owned()
    };
    assert_eq!(file.port("x").unwrap().event, "topic_object_loc_msg");
    assert!(matches!(
        &file.port("x").unwrap().kind,
        PortKind::State { param, .. } if param == "ros_fields__pose__x"
    ));
    assert_eq!(formula("a"), "H({e} -> P {x > 1})");
    assert_eq!(formula("b"), "H !((!{e}) S[6200ms:] ({x > 1} && !{e}))");
    assert_eq!(formula("c"), "H({e} -> P {x == 2})");
    assert_eq!(formula("d"), "P {x == 4.0 && e}");
    assert_eq!(formula("f"), "H !((!{e}) S ({x > 1} && !{e}))");
}

#[test]
fn bad_ros_ports_and_patterns_name_their_position() {
    let cases = [
        (
            r#"<ports><ros_service service_name="/s" type="t/S" event="call"><event_var id="a"/></ros_service></ports>"#,
            "3:50",
            "\"request\" or \"response\"",
        ),
        (
            r#"<ports><ros_topic topic="/t" type="t/T"><event_var id="a"/></ros_topic></ports>
<guarantees><property id="p" pattern="recurrence" event="a"/></guarantees>"#,
            "4:30",
            "`within`",
        ),
        (
            r#"<ports><ros_topic topic="/t" type="t/T"><event_var id="a"/></ros_topic></ports>
<guarantees><property id="p" pattern="recurrence" event="a" within="1" time_unit="h"/></guarantees>"#,
            "4:72",
            "one of ns, us, ms, s or min",
        ),
        (
            r#"<ports><ros_topic topic="/t" type="t/T"><event_var id="a"/></ros_topic></ports>
<guarantees><property id="p" pattern="eventually" event="a"/></guarantees>"#,
            "4:30",
            "absence, existence",
        ),
        (
            r#"<ports><ros_topic type="t/T"><event_var id="a"/></ros_topic></ports>"#,
            "3:8",
            "topic",
        ),
        (
            r#"<ports><ros_topic topic="/t" type="t/T" durability="durable"><event_var id="a"/></ros_topic></ports>"#,
            "3:41",
            "\"volatile\", \"transient_local\", \"system_default\"",
        ),
        (
            r#"<ports><ros_topic topic="/t" type="t/T" depth="0"><event_var id="a"/></ros_topic></ports>"#,
            "3:41",
            "a count of samples from 1 to 1048576",
        ),
    ];
    for (i, (body, at, expected)) in cases.iter().enumerate() {
        let path = write_props(&format!("bad{i}.xml"), &format!("\n{body}"));
        let err = parse_file(&path).unwrap_err().to_string();
        assert!(err.contains(&format!("bad{i}.xml:{at}")), "case {i}: {err}");
        assert!(err.contains(expected), "case {i}: {err}");
    }
}

/// A `<ros_topic>` names its QoS with ROS 2's names; the reader keeps them, in the order
/// of `QOS_SETTINGS`, for `monitor --ros2`; a port without them has none.
#[test]
fn ros_topics_name_their_qos() {
    let path = write_props(
        "qos.xml",
        r#"<ports>
  <ros_topic topic="/map" type="nav_msgs/OccupancyGrid" depth="1" durability="transient_local" reliability="best_effort" history="keep_last"><event_var id="m"/></ros_topic>
  <ros_topic topic="/t" type="std_msgs/Int32"><event_var id="t"/></ros_topic>
</ports>"#,
    );
    let file = parse_file(&path).unwrap();
    let pairs = |i: usize| -> Vec<(&str, &str)> {
        file.ros_types[i]
            .qos
            .iter()
            .map(|(k, v)| (k.as_str(), v.as_str()))
            .collect()
    };
    assert_eq!(
        pairs(0),
        [
            ("reliability", "best_effort"),
            ("durability", "transient_local"),
            ("history", "keep_last"),
            ("depth", "1"),
        ]
    );
    assert!(pairs(1).is_empty());
}

#[test]
fn ros_named_requirements_in_seconds_judge_like_the_step_bounded_ones() {
    let model = CompiledModel::load(&repo("examples/museum-scxml")).unwrap();
    let plain = parse_file(&repo("examples/museum-scxml/properties.xml")).unwrap();
    let ros = parse_file(&repo("examples/museum-guide/properties.xml")).unwrap();
    let plain = PropertySet::new(&plain, &model).unwrap();
    // The translation's time unit is 100 ms.
    let ros = PropertySet::with_unit(&ros, &model, Some(100_000_000)).unwrap();
    assert_eq!(plain.guarantee_names(), ros.guarantee_names());
    let cfg = RunConfig::default();
    let (a, b) = (
        Runner::new(&model, &plain, &cfg),
        Runner::new(&model, &ros, &cfg),
    );
    for k in 0..12 {
        let x = a.run(k, &mut stream(7, k));
        let y = b.run(k, &mut stream(7, k));
        assert_eq!(x.verdicts, y.verdicts, "run {k}");
    }
    // Not vacuous: one step below the paper's 6.2 s, the alarm response fails in a run.
    let text = std::fs::read_to_string(repo("examples/museum-guide/properties.xml")).unwrap();
    let tight = write_props(
        "tight.xml",
        text.replace("since[6.2s:]", "since[6.1s:]")
            .trim_start_matches(|c| c != '\n')
            .replace("<properties>", "")
            .replace("</properties>", "")
            .as_str(),
    );
    let tight = parse_file(&tight).unwrap();
    let tight = PropertySet::with_unit(&tight, &model, Some(100_000_000)).unwrap();
    let c = Runner::new(&model, &tight, &cfg);
    let alarm = ros
        .guarantee_names()
        .iter()
        .position(|n| n == "alarm_response")
        .unwrap();
    let violated = (0..12).any(|k| {
        let v = c.run(k, &mut stream(7, k)).verdicts[alarm];
        format!("{v:?}") == "False"
    });
    assert!(violated, "6.1 s should be violated in some run");
    // A bound that is not a whole number of 100 ms steps is an error naming the file.
    let path = write_props(
        "odd.xml",
        r#"<ports><ros_topic topic="/BatteryComponent/battery_level" type="std_msgs/Int32"><event_var id="b"/></ros_topic></ports>
<guarantees><property id="p" pattern="recurrence" event="b" within="150" time_unit="ms"/></guarantees>"#,
    );
    let odd = parse_file(&path).unwrap();
    let err = PropertySet::with_unit(&odd, &model, Some(100_000_000))
        .unwrap_err()
        .to_string();
    assert!(err.contains("odd.xml"), "{err}");
}
