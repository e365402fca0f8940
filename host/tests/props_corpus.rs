//! Reads the two real SCAN property files of the shared corpus, one in each format, and
//! checks ports, formulas and the mapping of formula offsets back to file positions.

mod common;

use std::path::PathBuf;

use hindsight::verify::props::{parse_file, Location, PortKind, PropertyFile};

fn corpus_root() -> PathBuf {
    common::corpus_root()
}

fn corpus(relative: &str) -> PathBuf {
    corpus_root().join(relative)
}

fn read(relative: &str) -> (PropertyFile, String) {
    let path = corpus(relative);
    let text = std::fs::read_to_string(&path).expect("corpus file is readable");
    match parse_file(&path) {
        Ok(file) => (file, text),
        Err(errors) => panic!("{errors}"),
    }
}

/// 1-based location of the first occurrence of `needle` at or after line `from_line`.
fn find(text: &str, from_line: u32, needle: &str) -> Location {
    for (i, line) in text.lines().enumerate().skip(from_line as usize - 1) {
        if let Some(byte) = line.find(needle) {
            let column = line[..byte].chars().count() + 1;
            return Location::new(i as u32 + 1, column as u32);
        }
    }
    panic!("`{needle}` not found");
}

/// The five predefined XML entities, replaced by hand.
fn unescape(raw: &str) -> String {
    raw.replace("&lt;", "<")
        .replace("&gt;", ">")
        .replace("&quot;", "\"")
        .replace("&apos;", "'")
        .replace("&amp;", "&")
}

#[test]
fn current_format_uc3() {
    if common::corpus_or_skip().is_none() {
        return;
    }
    let (file, text) = read("uc3-plain/properties.xml");
    let ids: Vec<&str> = file.ports.iter().map(|p| p.id.as_str()).collect();
    assert_eq!(
        ids,
        [
            "battery_low_alarm",
            "battery_level",
            "battery_published",
            "is_at_charging_station",
            "people_following_published",
            "poi_selected",
            "bb_field",
            "bb_value",
            "poi_done",
            "connected_to_network"
        ]
    );
    let level = file.port("battery_level").expect("declared");
    assert_eq!(level.event, "topic_BatteryComponent__battery_level_msg");
    assert_eq!(level.origin, "BatteryComponent");
    assert_eq!(level.target, "BatteryChargingSkill");
    let PortKind::State { param, ty, init } = &level.kind else {
        panic!("battery_level is a state variable");
    };
    assert_eq!(
        (param.as_str(), ty.as_str(), init.as_str()),
        ("ros_fields__percentage", "int32", "100")
    );
    assert_eq!(
        init.location(0),
        find(&text, 1, "100\" param=\"ros_fields__percentage")
    );
    let published = file.port("battery_published").expect("declared");
    assert_eq!(published.kind, PortKind::Event);
    assert_eq!(published.event, level.event);
    let PortKind::State { ty, init, .. } = &file.port("bb_field").expect("declared").kind else {
        panic!("bb_field is a state variable");
    };
    assert_eq!((ty.as_str(), init.as_str()), ("string", "''"));

    assert_eq!(file.guarantees.len(), 19);
    assert!(file.assumptions.is_empty());
    // Every formula is its `expr` attribute, unescaped.
    for property in &file.guarantees {
        assert!(!property.converted);
        let line = text
            .lines()
            .nth(property.at.line as usize - 1)
            .expect("line exists");
        let raw = line
            .split_once("expr=\"")
            .and_then(|(_, rest)| rest.rsplit_once("\"/>"))
            .map(|(raw, _)| raw)
            .expect("property line with expr");
        assert_eq!(property.formula.as_str(), unescape(raw), "{}", property.id);
        assert!(line.contains(&format!("id=\"{}\"", property.id)));
    }
    // Offsets map back to the file, entities included.
    let property = &file.guarantees[0];
    assert_eq!(property.id, "noAlarmWithHighBattery");
    assert_eq!(
        property.at,
        find(&text, 1, "<property id=\"noAlarmWithHighBattery\"")
    );
    let formula = property.formula.as_str();
    for needle in [
        "historically",
        "battery_level",
        "30 ",
        "is_at_charging_station",
        "battery_low_alarm",
    ] {
        let offset = formula.find(needle).expect("in formula");
        let expected = find(&text, property.at.line, needle);
        assert_eq!(property.formula.location(offset), expected, "{needle}");
    }
    // `&gt;` and `&amp;&amp;` map to themselves.
    let offset = formula.find('>').expect("has >");
    assert_eq!(
        property.formula.location(offset),
        find(&text, property.at.line, "&gt;")
    );
    let offset = formula.find("&&").expect("has &&");
    assert_eq!(
        property.formula.location(offset),
        find(&text, property.at.line, "&amp;&amp;")
    );
}

#[test]
fn tree_format_museum() {
    if common::corpus_or_skip().is_none() {
        return;
    }
    let (file, text) = read("museum-simpar2025/model_scxml/properties.xml");
    let summary: Vec<(&str, bool)> = file
        .ports
        .iter()
        .map(|p| (p.id.as_str(), p.kind == PortKind::Event))
        .collect();
    assert_eq!(
        summary,
        [
            ("battery_level_published", true),
            ("battery_level", false),
            ("alarm", true),
            ("current_poi", false),
            ("poi_done_name", false),
            ("poi_done_value", false),
            ("visitors_presence_published", true)
        ]
    );
    let alarm = file.port("alarm").expect("declared");
    assert_eq!(alarm.origin, "AlarmSkill");
    assert_eq!(alarm.target, "srv_handler_NotifyUserComponent__StartAlarm");
    assert_eq!(
        alarm.event,
        "srv_NotifyUserComponent__StartAlarm_req_client_AlarmSkill"
    );
    assert_eq!(alarm.at, find(&text, 1, "<port id=\"alarm\""));
    let PortKind::State { param, ty, init } = &file.port("current_poi").expect("declared").kind
    else {
        panic!("current_poi is a state variable");
    };
    assert_eq!(
        (param.as_str(), ty.as_str(), init.as_str()),
        ("ros_fields__poi_number", "int32", "0")
    );

    // The only guarantee not commented out: the paper's requirement 2 with t1 = 62.
    assert_eq!(file.guarantees.len(), 1);
    let property = &file.guarantees[0];
    assert_eq!(property.id, "battery_alarm_response");
    assert!(property.converted);
    assert_eq!(
        property.formula.as_str(),
        "historically (({alarm} -> (once {battery_level <= 30})) && \
         (!((!{alarm}) since[62:] {battery_level <= 30})))"
    );
    assert_eq!(
        property.at,
        find(&text, 1, "<guarantee id=\"battery_alarm_response\"")
    );
    // Pieces map to the elements that produced them.
    let formula = property.formula.as_str();
    let at = |needle: &str| {
        property
            .formula
            .location(formula.find(needle).expect("in formula"))
    };
    assert_eq!(
        at("historically"),
        find(&text, property.at.line, "<historically>")
    );
    assert_eq!(
        at("since"),
        find(&text, property.at.line, "<since lower_bound=\"62\">")
    );
    // `battery_level` comes from the `low_battery` predicate, `30` from its constant.
    let predicate = find(&text, 1, "<predicate id=\"low_battery\">");
    assert_eq!(
        at("battery_level"),
        find(&text, predicate.line, "battery_level\"/>")
    );
    assert_eq!(at("30"), find(&text, predicate.line, "30\"/>"));
    assert_eq!(at("alarm}"), find(&text, property.at.line, "alarm\"/>"));
}
