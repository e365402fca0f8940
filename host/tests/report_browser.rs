//! The report in a real browser: headless Chromium (the driver of `browser/mod.rs`) opens
//! the pages hindsight writes for the museum (a failing bound with its saved run, and a
//! sweep), with every host name unresolvable, and the test reads the DOM after the
//! scripts ran, the console, every request, and a screenshot (kept in
//! `target/screenshots/`).
//!
//! Chromium is `$CHROMIUM` or `/usr/bin/chromium` (`.ci/run` installs it). Without it the
//! tests say why and pass, unless `CI` is set: then a missing browser is a failure.

mod browser;
mod common;
mod report_common;

use std::path::Path;
use std::time::Duration;

use browser::{chromium, shot_path, Browser};
use report_common::{expected_first_false, hindsight, scratch};

/// What the browser made of a page.
struct Opened {
    /// The DOM after the scripts ran.
    dom: String,
}

/// Opens `page` (with `fragment`) once its script has drawn, checks that the console
/// stayed silent and nothing but the file itself was requested, and keeps a screenshot
/// named `shot`.
fn open(b: &mut Browser, page: &Path, fragment: &str, shot: &str) -> Opened {
    let file = format!("file://{}", page.canonicalize().unwrap().display());
    b.errors.clear();
    b.requests.clear();
    b.open(&format!("{file}{fragment}"));
    b.wait_for(
        "document.body.hasAttribute('data-rendered')",
        Duration::from_secs(60),
    );
    let dom = b.dom();
    let png = shot_path(&format!("{shot}.png"));
    b.screenshot(&png);
    assert!(
        std::fs::metadata(&png).unwrap().len() > 10_000,
        "{}",
        png.display()
    );
    assert_eq!(b.errors, Vec::<String>::new(), "console errors");
    for u in &b.requests {
        assert!(u.starts_with(&file) || u == "about:blank", "fetched {u}");
    }
    Opened { dom }
}

/// A browser for the test, or `None` when the test may skip.
fn browser(tag: &str) -> Option<Browser> {
    chromium().map(|c| Browser::start(&c, &scratch(&format!("profile-{tag}"))))
}

/// The value of `name` in the first tag that contains `marker`.
fn attr_in_tag(dom: &str, marker: &str, name: &str) -> Option<String> {
    let at = dom.find(marker)?;
    let start = dom[..=at].rfind('<')?;
    let tag = &dom[start..start + dom[start..].find('>')?];
    let key = format!("{name}=\"");
    let v = tag.find(&key)? + key.len();
    Some(tag[v..v + tag[v..].find('"')?].to_string())
}

#[test]
fn the_museum_report_renders_in_chromium_without_errors_or_fetches() {
    let Some(mut browser) = browser("museum") else {
        return;
    };
    let m = report_common::museum("browser");
    let csv = report_common::read_run(&m.failing_csv);
    let (due_time, due_point) = expected_first_false(&csv);
    let opened = open(&mut browser, &m.verify_page, "", "museum-report");
    let dom = &opened.dom;
    assert_eq!(
        attr_in_tag(dom, "<body", "data-errors").as_deref(),
        Some("0")
    );
    assert_eq!(
        attr_in_tag(dom, "<body", "data-rendered").as_deref(),
        Some("1")
    );
    // The script drew the timeline: a lane per variable and verdict, and the mark where
    // the tight property first turned false, at the time the run's own columns give.
    let timeline = &dom[dom.find("id=\"timeline-0\"").unwrap()..];
    assert!(timeline.contains("<svg"), "timeline drawn");
    for lane in ["battery_level", "alarm", "absence", "visitors_recurrence"] {
        assert!(timeline.contains(&format!(">{lane}")), "lane {lane}");
    }
    let mark = "class=\"ff-mark\" data-property=\"alarm_response\"";
    assert_eq!(
        attr_in_tag(dom, mark, "data-time"),
        Some(due_time.to_string())
    );
    assert_eq!(
        attr_in_tag(dom, mark, "data-point"),
        Some(due_point.to_string())
    );
    // Every property with its probability, as the study reported it.
    for p in m.study["properties"].as_array().unwrap() {
        let name = p["property"].as_str().unwrap();
        let row = &dom[dom.find(&format!("id=\"prop-{name}\"")).unwrap()..];
        let row = &row[..row.find("</tr>").unwrap()];
        let prob = format!("{:.4}", p["probability"].as_f64().unwrap());
        assert!(row.contains(&format!(">{prob}<")), "{name} {prob}: {row}");
    }

    // A link to the first false point selects it: the state panel shows that point.
    let opened = open(
        &mut browser,
        &m.verify_page,
        &format!("#run-0-point-{due_point}"),
        "museum-report-first-false",
    );
    let dom = &opened.dom;
    assert_eq!(
        attr_in_tag(dom, "<body", "data-errors").as_deref(),
        Some("0")
    );
    let state = &dom[dom.find("id=\"state-0\"").unwrap()..];
    let state = &state[..state.find("</table>").expect("state panel filled")];
    assert!(
        state.contains(&format!(
            "{due_point} of {} (pinned)",
            csv.lines().count() - 1
        )),
        "{state}"
    );
    assert!(
        state.contains(&format!("{} s", due_time as f64 / 10.0)),
        "{state}"
    );
    assert!(
        state.contains("alarm_response</a></th><td class=\"f\">false"),
        "{state}"
    );
    assert!(
        state.contains("absence</a></th><td class=\"t\">true"),
        "{state}"
    );
    assert!(dom.contains("class=\"cursor\""), "cursor drawn");
    // The messages around it as a sequence chart, the last send at or before it marked.
    let last_send = csv
        .lines()
        .skip(1)
        .take(due_point + 1)
        .enumerate()
        .filter(|(_, l)| l.split(',').nth(1) == Some("send"))
        .map(|(k, _)| k)
        .last()
        .unwrap();
    let seq = &dom[dom
        .find("<div class=\"seq\">")
        .expect("sequence chart drawn")..];
    let seq = &seq[..seq.find("</svg>").unwrap()];
    assert_eq!(seq.matches("<g class=\"seq-msg").count(), 40);
    assert_eq!(
        attr_in_tag(seq, "class=\"seq-msg selected\"", "data-point"),
        Some(last_send.to_string())
    );
    // The behavior tree at that point: every node the run's messages name, each with the
    // status its last tick, answer or halt before the point gives.
    let want = bt_statuses(&csv, due_point);
    assert!(want.len() > 10, "{want:?}");
    let distinct: std::collections::BTreeSet<&String> = want.values().collect();
    assert!(distinct.len() >= 2, "{want:?}");
    let tree = &dom[dom.find("<div class=\"bt\">").expect("tree drawn")..];
    let tree = &tree[..tree.find("</svg>").unwrap()];
    assert_eq!(tree.matches("class=\"bt-node\"").count(), want.len());
    for (id, status) in &want {
        let marker = format!("class=\"bt-node\" data-node=\"{id}\"");
        assert_eq!(
            attr_in_tag(tree, &marker, "data-status").as_deref(),
            Some(status.as_str()),
            "node {id}"
        );
    }
}

/// Each behavior-tree node's status at `point`, read from the run's CSV: the last
/// `bt_<id>_tick` (ticked), `bt_<id>_response` (its status: 1 success, 2 failure,
/// 3 running) or `bt_<id>_halt` (idle) sent up to that point.
fn bt_statuses(csv: &str, point: usize) -> std::collections::BTreeMap<String, String> {
    let mut out = std::collections::BTreeMap::new();
    for (k, line) in csv.lines().skip(1).enumerate() {
        let cells: Vec<&str> = line.split(',').collect();
        if cells[1] != "send" {
            continue;
        }
        let Some(rest) = cells[2].strip_prefix("bt_") else {
            continue;
        };
        let Some((id, kind)) = rest.split_once('_') else {
            continue;
        };
        let status = match kind {
            "tick" => "ticked".to_string(),
            "halt" => "idle".to_string(),
            "response" => match cells[5].trim_start_matches("status=") {
                "1" => "success".into(),
                "2" => "failure".into(),
                "3" => "running".into(),
                other => panic!("status {other}"),
            },
            _ => continue,
        };
        let entry = out
            .entry(id.to_string())
            .or_insert_with(|| "idle".to_string());
        if k <= point {
            *entry = status;
        }
    }
    out
}

#[test]
fn a_sweep_report_renders_in_chromium() {
    let Some(mut browser) = browser("sweep") else {
        return;
    };
    let dir = scratch("browser-sweep");
    let page = dir.join("sweep.html");
    let (code, _, err) = hindsight(&[
        "sweep",
        "examples/museum-guide",
        "--from",
        "0.1s",
        "--to",
        "7s",
        "--step",
        "0.3s",
        "--runs",
        "2",
        "--report",
        &page.display().to_string(),
    ]);
    assert_eq!(code, 0, "{err}");
    let opened = open(&mut browser, &page, "", "museum-sweep");
    let dom = &opened.dom;
    assert_eq!(
        attr_in_tag(dom, "<body", "data-errors").as_deref(),
        Some("0")
    );
    assert_eq!(
        attr_in_tag(dom, "<body", "data-rendered").as_deref(),
        Some("0")
    );
    assert!(dom.contains("<svg class=\"chart\""));
    // Four bounded requirements, each with its threshold (the paper's Table II, on a
    // grid of 0.3 s: 6.4 s is the first value at or above 6.2 s).
    for (name, threshold) in [
        ("alarm_response", "6.4s"),
        ("battery_recurrence", "1s"),
        ("poi_response", "0.4s"),
        ("visitors_recurrence", "1s"),
    ] {
        let row = &dom[dom.find(&format!("<tr data-property=\"{name}\"")).unwrap()..];
        let row = &row[..row.find("</tr>").unwrap()];
        assert!(
            row.contains(&format!("<td class=\"threshold\">{threshold}</td>")),
            "{name}: {row}"
        );
    }
}
