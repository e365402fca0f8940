//! The HTML report's content: every property with its probability and formula, the first
//! false point of a failing run at the right time, sweeps with thresholds, no reference to
//! anything outside the page, and bad input named by file and line.

mod common;
mod report_common;

use report_common::{expected_first_false, external_refs, hindsight, museum, scratch};

/// The text of the table row `<tr id="prop-NAME" ...>...</tr>`.
fn property_row<'a>(html: &'a str, name: &str) -> &'a str {
    let start = html
        .find(&format!("<tr id=\"prop-{name}\""))
        .unwrap_or_else(|| panic!("no row for {name}"));
    let end = html[start..].find("</tr>").unwrap() + start;
    &html[start..end]
}

/// The `<li>` announcing where `name` first turns false in the page's first run.
fn first_false_item<'a>(html: &'a str, name: &str) -> &'a str {
    let start = html
        .find(&format!("data-property=\"{name}\" data-point="))
        .unwrap_or_else(|| panic!("no first false point for {name}"));
    let end = html[start..].find("</li>").unwrap() + start;
    &html[start..end]
}

fn attr(tag: &str, name: &str) -> String {
    let key = format!("{name}=\"");
    let at = tag.find(&key).unwrap() + key.len();
    tag[at..at + tag[at..].find('"').unwrap()].to_string()
}

#[test]
fn a_museum_study_page_shows_every_property_and_where_the_failing_run_turned_false() {
    let m = museum("page");
    let csv = report_common::read_run(&m.failing_csv);
    let (due_time, due_point) = expected_first_false(&csv);
    for (page, from_memory) in [(&m.verify_page, true), (&m.files_page, false)] {
        let html = std::fs::read_to_string(page).unwrap();
        let props = m.study["properties"].as_array().unwrap();
        assert_eq!(props.len(), 5);
        for p in props {
            let name = p["property"].as_str().unwrap();
            let row = property_row(&html, name);
            let prob = format!("{:.4}", p["probability"].as_f64().unwrap());
            assert!(
                row.contains(&format!("<td class=\"prob\">{prob}</td>")),
                "{name}: {prob} in {row}"
            );
            let interval = format!(
                "[{:.4}, {:.4}]",
                p["lower"].as_f64().unwrap(),
                p["upper"].as_f64().unwrap()
            );
            assert!(row.contains(&interval), "{name}: {interval} in {row}");
            // The formula as written (from the study, or from the file the JSON names).
            assert!(row.contains("<div class=\"formula\"><code>"), "{row}");
        }
        // Every run failed the tight bound, none the others.
        assert!(property_row(&html, "alarm_response").contains("<td class=\"prob\">0.0000</td>"));
        let alarm = property_row(&html, "alarm_response");
        assert!(alarm.contains("since[6.1s:]"), "{alarm}");
        // As compiled: the bound in ticks of 100 ms.
        assert_eq!(alarm.contains("as compiled"), from_memory, "{alarm}");
        if from_memory {
            assert!(alarm.contains("S[61:]"), "{alarm}");
        }
        assert!(
            alarm.contains("href=\"#run-0\""),
            "linked to its failing run: {alarm}"
        );
        // How runs ended and the settings.
        assert!(html.contains("<b>3</b> runs:"), "runs");
        assert!(html.contains("examples/museum-guide"));
        // The failing run: the tight property is false from the first alarm plus 6.1 s.
        let item = first_false_item(&html, "alarm_response");
        assert_eq!(attr(item, "data-time"), due_time.to_string(), "{item}");
        assert_eq!(attr(item, "data-point"), due_point.to_string(), "{item}");
        let seconds = format!("t = {} s", due_time as f64 / 10.0);
        assert!(item.contains(&seconds), "{item} has {seconds}");
        assert!(item.contains("href=\"#prop-alarm_response\""), "{item}");
        // From memory, the subformula that failed: the response window, true there
        // (61 ticks without an alarm since a low battery); files carry no node values.
        assert_eq!(item.contains("class=\"culprit\""), from_memory, "{item}");
        if from_memory {
            assert!(
                item.contains("(!{alarm} S[61:] {battery_level &lt;= 30})</code> was true"),
                "{item}"
            );
        }
        // The run is embedded for the timeline, with every point.
        let points = csv.lines().count() - 1;
        assert!(html.contains(&format!("{points} points over")), "{points}");
        assert!(html.contains("id=\"timeline-0\""));
        assert_eq!(
            external_refs(&html),
            Vec::<String>::new(),
            "{}",
            page.display()
        );
        // The data cannot close its script element early.
        let data_start = html.find("id=\"hindsight-runs\">").unwrap();
        let data_end = html[data_start..].find("</script>").unwrap() + data_start;
        assert!(!html[data_start..data_end].contains('<'));
    }
}

#[test]
fn a_passing_study_page_has_every_property_and_no_failing_run() {
    let dir = scratch("passing");
    let out = dir.join("report.html");
    let (code, _, err) = hindsight(&[
        "verify",
        "examples/museum-guide",
        "--max-runs",
        "2",
        "--report",
        &out.display().to_string(),
    ]);
    assert_eq!(code, 0, "{err}");
    let html = std::fs::read_to_string(&out).unwrap();
    for name in [
        "absence",
        "alarm_response",
        "battery_recurrence",
        "poi_response",
        "visitors_recurrence",
    ] {
        let row = property_row(&html, name);
        assert!(row.contains("<td class=\"prob\">1.0000</td>"), "{row}");
        assert!(row.contains("as compiled"), "{row}");
    }
    assert!(!html.contains("Failing runs"));
    assert!(html.contains("id=\"hindsight-runs\">[]</script>"));
    assert_eq!(external_refs(&html), Vec::<String>::new());
}

#[test]
fn a_sweep_page_draws_the_curves_and_names_the_thresholds() {
    let dir = scratch("sweep");
    let out = dir.join("sweep.html");
    let (code, _, err) = hindsight(&[
        "sweep",
        "examples/museum-guide",
        "--property",
        "alarm_response",
        "--from",
        "6.0s",
        "--to",
        "6.4s",
        "--runs",
        "2",
        "--report",
        &out.display().to_string(),
    ]);
    assert_eq!(code, 0, "{err}");
    let html = std::fs::read_to_string(&out).unwrap();
    assert!(html.contains("<svg class=\"chart\""));
    assert_eq!(html.matches("<polyline").count(), 1);
    // Five bounds, each with its interval bar and point.
    assert_eq!(html.matches("<circle").count(), 5);
    assert!(html.contains("threshold 6.2s"), "legend");
    assert!(html.contains("<td class=\"threshold\">6.2s</td>"));
    assert!(html.contains("bound (s)"));
    assert_eq!(external_refs(&html), Vec::<String>::new());
    // `hindsight report --sweep` reads what `sweep --json` prints into the same chart.
    let (code, json, err) = hindsight(&[
        "sweep",
        "examples/museum-guide",
        "--property",
        "alarm_response",
        "--from",
        "6.0s",
        "--to",
        "6.4s",
        "--runs",
        "2",
        "--json",
    ]);
    assert_eq!(code, 0, "{err}");
    std::fs::write(dir.join("sweep.json"), json).unwrap();
    let again = dir.join("again.html");
    let (code, _, err) = hindsight(&[
        "report",
        "--sweep",
        &dir.join("sweep.json").display().to_string(),
        "-o",
        &again.display().to_string(),
    ]);
    assert_eq!(code, 0, "{err}");
    let html2 = std::fs::read_to_string(&again).unwrap();
    let chart = |h: &str| h[h.find("<svg").unwrap()..h.find("</svg>").unwrap()].to_string();
    assert_eq!(chart(&html), chart(&html2));
}

#[test]
fn bad_report_inputs_name_the_file_and_line() {
    let dir = scratch("bad");
    let csv = dir.join("p-run0.csv");
    std::fs::write(
        &csv,
        "time,step,event,origin,target,params,x,verdict_p\n0,init,,,,,1,true\n2,time,,,,,1,maybe\n",
    )
    .unwrap();
    let out = dir.join("r.html").display().to_string();
    let (code, _, err) = hindsight(&["report", &csv.display().to_string(), "-o", &out]);
    assert_eq!(code, 2);
    assert!(
        err.contains("p-run0.csv:3:14: verdict `maybe`: expected true or false"),
        "{err}"
    );
    let json = dir.join("study.json");
    std::fs::write(&json, "{\"model\": 3}").unwrap();
    let (code, _, err) = hindsight(&["report", "--study", &json.display().to_string(), "-o", &out]);
    assert_eq!(code, 2);
    assert!(err.contains("study.json:1:"), "{err}");
    assert!(err.contains("not the JSON of `verify --json`"), "{err}");
    let (code, _, err) = hindsight(&["report", "-o", &out]);
    assert_eq!(code, 2);
    assert!(err.contains("nothing to show"), "{err}");
    assert!(!std::path::Path::new(&out).exists());
}

#[test]
fn an_online_sweep_names_its_recorded_runs() {
    // What `sweep --online a.jsonl --online b.jsonl --json` prints, in model units.
    let dir = scratch("online");
    let json = dir.join("online.json");
    std::fs::write(
        &json,
        r#"{"runs": 2, "logs": ["a.jsonl", "b.jsonl"], "confidence": 0.95, "properties": [
            {"property": "p", "threshold": "3", "points": [
                {"bound": "2", "successes": 0, "failures": 2, "unknown": 0, "probability": 0.0, "lower": 0.0, "upper": 0.84},
                {"bound": "3", "successes": 2, "failures": 0, "unknown": 0, "probability": 1.0, "lower": 0.16, "upper": 1.0}]}]}"#,
    )
    .unwrap();
    let out = dir.join("r.html");
    let (code, _, err) = hindsight(&[
        "report",
        "--sweep",
        &json.display().to_string(),
        "-o",
        &out.display().to_string(),
    ]);
    assert_eq!(code, 0, "{err}");
    let html = std::fs::read_to_string(&out).unwrap();
    assert!(html.contains("(2 recorded runs)"), "title");
    assert!(html.contains("bound (model time units)"));
    assert!(html.contains("<td class=\"threshold\">3</td>"));
    assert_eq!(html.matches("<circle").count(), 2);
}
