//! The sidecar's live page (`monitor --serve`): a browser connected while the museum runs
//! sees the verdicts arrive in the report's timeline (a verdict lane per property, its
//! changes at the times of the verdict lines), the page's lines are the verdict file's,
//! and stopping the monitor loses no verdict line. The browser is headless Chromium
//! (installed by `.ci/run`, driven by `browser/mod.rs`); without it, and outside CI, the
//! browser part is skipped with a note.

#[path = "live_common/mod.rs"]
mod live_common;

mod browser;

use std::io::{Read, Write};
use std::net::TcpStream;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use browser::{chromium, shot_path, Browser};
use live_common::{finish, hindsight, museum, museum_config, scratch, unique, Guard};

/// A plain GET, status line and all, for the server's own routes.
fn get(addr: &str, path: &str) -> String {
    let mut s = TcpStream::connect(addr).unwrap();
    write!(s, "GET {path} HTTP/1.1\r\nHost: {addr}\r\n\r\n").unwrap();
    let mut text = String::new();
    s.read_to_string(&mut text).unwrap();
    text
}

/// What the page shows: verdict lines received, each row's property and verdict, the
/// timeline's points, and per verdict lane its changes (time, verdict), the colours
/// drawn in it and the time of its first-false mark. Points keep arriving (heartbeats) and
/// the page draws them on the next animation frame, so this draws what the page holds first:
/// the drawing and the counts are then of one moment.
const PAGE_STATE: &str = "(function () { \
    var tl = document.getElementById('timeline-live').hindsightTimeline; \
    tl.draw(); \
    return JSON.stringify({lines: +tl.el.getAttribute('data-lines'), \
    errors: +document.getElementById('errors').textContent, \
    median: +document.getElementById('delay-median').textContent, \
    max: +document.getElementById('delay-max').textContent, \
    points: tl.n, follow: tl.el.getAttribute('data-follow'), \
    rows: Array.from(document.querySelectorAll('tr[data-property]')).map(function (r) { \
      return [r.getAttribute('data-property'), r.getAttribute('data-verdict'), \
        r.getAttribute('data-first-false')]; }), \
    lanes: tl.lanes.filter(function (l) { return l.kind === 'verdict'; }).map(function (l) { \
      var g = tl.el.querySelector('g.lane[data-kind=verdict][data-name=' + l.name + ']'); \
      var mark = tl.el.querySelector('g.ff-mark[data-property=' + l.name + ']'); \
      return {name: l.name, changes: l.ch.map(function (k) { return [tl.run.time[k], l.get(k)]; }), \
        fills: Array.from(g.querySelectorAll('rect')).slice(1).map(function (r) { \
          return r.getAttribute('fill'); }), \
        mark: mark && +mark.getAttribute('data-time')}; })}); })()";

/// The colour of points of different verdicts that share a pixel (`report/page.js`, `MIXED`).
const MIXED: &str = "#e69f00";

/// The colour of each verdict in a verdict lane (`report/page.js`, `VERDICT_FILL`).
fn fill(verdict: &str) -> &'static str {
    match verdict {
        "true" => "#59a14f",
        "false" => "#d62728",
        "currently_true" => "#8fd694",
        "currently_false" => "#f08a8a",
        _ => "#bbbbbb",
    }
}

/// Per property, its verdict changes among `lines`: (time, verdict), a later line at the
/// same time replacing the earlier one (both land on the same point).
fn changes(lines: &[serde_json::Value], property: &str) -> Vec<(u64, String)> {
    let mut out: Vec<(u64, String)> = Vec::new();
    for l in lines.iter().filter(|l| l["property"] == property) {
        let (t, v) = (l["time"].as_u64().unwrap(), l["verdict"].as_str().unwrap());
        if out.last().is_some_and(|(lt, _)| *lt == t) {
            out.pop();
        }
        if out.last().is_none_or(|(_, lv)| lv != v) {
            out.push((t, v.to_string()));
        }
    }
    out
}

#[test]
fn the_live_page_shows_the_verdicts_as_they_arrive() {
    let dir = scratch("live-page");
    let prefix = unique("live-page");
    let config = museum_config(&dir, &prefix);
    let verdicts = dir.join("verdicts.jsonl");
    let err_path = dir.join("monitor.err");
    let mut monitor = Guard(Some(
        hindsight()
            .arg("monitor")
            .arg("--model")
            .arg(museum())
            .arg("--config")
            .arg(&config)
            .args(["--speed", "10", "--from-first-message", "--serve", ":0"])
            .arg("-o")
            .arg(&verdicts)
            .stdout(Stdio::null())
            .stderr(std::fs::File::create(&err_path).unwrap())
            .spawn()
            .unwrap(),
    ));
    let t = Instant::now();
    let addr = loop {
        let log = std::fs::read_to_string(&err_path).unwrap_or_default();
        if log.contains("monitor: ready") {
            let at = log.find("live page at http://").expect(&log) + "live page at http://".len();
            break log[at..at + log[at..].find('/').unwrap()].to_string();
        }
        assert!(t.elapsed() < Duration::from_secs(30), "never ready: {log}");
        std::thread::sleep(Duration::from_millis(10));
    };
    // Loopback unless told otherwise.
    assert!(addr.starts_with("127.0.0.1:"), "{addr}");
    let page = get(&addr, "/");
    assert!(page.starts_with("HTTP/1.1 200 OK"), "{page}");
    for p in ["battery_recurrence", "alarm_response", "poi_response"] {
        assert!(page.contains(p), "{p} not on the page");
    }
    assert!(!page.contains("http://") && !page.contains("https://"));
    assert!(get(&addr, "/nothing").starts_with("HTTP/1.1 404"));

    // The browser connects before the system starts, and stays while it runs.
    let mut browser = chromium().map(|c| {
        let mut b = Browser::start(&c, &dir.join("profile"));
        b.open(&format!("http://{addr}/"));
        b.wait_for(
            "document.getElementById('status').textContent === 'live'",
            Duration::from_secs(30),
        );
        b
    });
    let mut run = Guard(Some(
        hindsight()
            .arg("run")
            .arg(museum())
            .args(["--prefix", &prefix, "--seed", "2", "--speed", "10"])
            .args(["--duration", "60s"])
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap(),
    ));
    // While the system runs (6 s of wall-clock time), the timeline already shows verdicts.
    let during = browser.as_mut().map(|b| {
        b.wait_for(
            "document.getElementById('timeline-live').hindsightTimeline.lanes.some(function (l) { \
               return l.kind === 'verdict' && l.ch.length > 0 && l.get(l.ch[l.ch.length - 1]) !== 'unknown'; })",
            Duration::from_secs(30),
        );
        b.eval("document.getElementById('timeline-live').hindsightTimeline.n")
            .as_u64()
            .unwrap()
    });
    let (status, _) = finish(&mut run);
    assert!(status.success());
    let served_body = |addr: &str| {
        let t = get(addr, "/verdicts.jsonl");
        t[t.find("\r\n\r\n").unwrap() + 4..].to_string()
    };
    // Once the system stops, its recurrence properties turn false on the sidecar's
    // heartbeats, about 1 s of model time (0.1 s of wall clock) after the run's end: wait
    // for those lines, so that the page is checked with a false verdict in it however
    // fast the run's process exited.
    let turned_false = |body: &str| {
        body.lines().any(|l| {
            serde_json::from_str::<serde_json::Value>(l)
                .is_ok_and(|v| v["verdict"] == "false" || v["verdict"] == "currently_false")
        })
    };
    let deadline = Instant::now() + Duration::from_secs(30);
    while !turned_false(&served_body(&addr)) && Instant::now() < deadline {
        std::thread::sleep(Duration::from_millis(50));
    }
    // The page catches up with every line served so far.
    let so_far = served_body(&addr).lines().count();
    assert!(so_far >= 5, "{so_far} verdict lines");
    let state = browser.as_mut().map(|b| {
        b.wait_for(
            &format!("+document.getElementById('lines').textContent >= {so_far}"),
            Duration::from_secs(30),
        );
        // The view followed the run to its end (no zoom or pan happened).
        b.wait_for(
            "document.getElementById('timeline-live').getAttribute('data-follow') === 'on'",
            Duration::from_secs(5),
        );
        let state: serde_json::Value =
            serde_json::from_str(b.eval(PAGE_STATE).as_str().unwrap()).unwrap();
        b.screenshot(&shot_path("live-page.png"));
        follow_the_end(b);
        let kept = a_page_that_keeps_50_points(b, &addr, &state);
        (state, kept)
    });
    let served = served_body(&addr);

    // Stopping loses no line: everything served is in the file, and the file is whole.
    let pid = monitor.0.as_ref().unwrap().id().to_string();
    assert!(Command::new("kill")
        .args(["-TERM", &pid])
        .status()
        .unwrap()
        .success());
    let (status, _) = finish(&mut monitor);
    assert!(status.success());
    let file = std::fs::read_to_string(&verdicts).unwrap();
    assert!(file.starts_with(&served), "served lines are not the file's");
    let lines: Vec<serde_json::Value> = file
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();

    let (Some((state, kept)), Some(b)) = (state, browser) else {
        return;
    };
    assert!(b.errors.is_empty(), "page errors: {:?}", b.errors);
    assert_eq!(state["errors"], 0, "{state}");
    // Nothing but the page and its event stream was fetched.
    for u in &b.requests {
        assert!(u.starts_with(&format!("http://{addr}/")), "fetched {u}");
    }
    let shown = state["lines"].as_u64().unwrap() as usize;
    assert!(
        shown >= so_far && shown <= lines.len(),
        "{shown} of {}",
        lines.len()
    );
    // Each row shows the last verdict of its property among the lines the page had.
    for row in state["rows"].as_array().unwrap() {
        let p = row[0].as_str().unwrap();
        let last = lines[..shown].iter().rev().find(|w| w["property"] == p);
        assert_eq!(
            row[1].as_str(),
            last.and_then(|l| l["verdict"].as_str()),
            "{p}: {state}"
        );
    }
    // The timeline: every property's lane changes where its verdict lines change it, at
    // their times (the points before its first line are unknown), shows the colour of
    // each of those verdicts, and marks the first false one.
    let during = during.unwrap();
    let points = state["points"].as_u64().unwrap();
    assert!(
        during < points,
        "the page had {during} of {points} points when it first showed a verdict"
    );
    let lanes = state["lanes"].as_array().unwrap();
    assert_eq!(lanes.len(), state["rows"].as_array().unwrap().len());
    for lane in lanes {
        let p = lane["name"].as_str().unwrap();
        let mut got: Vec<(u64, String)> = lane["changes"]
            .as_array()
            .unwrap()
            .iter()
            .map(|c| (c[0].as_u64().unwrap(), c[1].as_str().unwrap().to_string()))
            .collect();
        if got.first().is_some_and(|(_, v)| v == "unknown") {
            got.remove(0);
        }
        let want = changes(&lines[..shown], p);
        assert_eq!(got, want, "{p}: {state}");
        let fills: Vec<&str> = lane["fills"]
            .as_array()
            .unwrap()
            .iter()
            .map(|f| f.as_str().unwrap())
            .collect();
        // A verdict that lasts less than a pixel is drawn merged with its neighbours in
        // the mixed colour (`report/page.js`, `Timeline.prototype.bands`).
        for (_, v) in &want {
            assert!(
                fills.contains(&fill(v)) || fills.contains(&MIXED),
                "{p}: no {v} drawn in {fills:?}"
            );
        }
        let first_false = want
            .iter()
            .find(|(_, v)| v == "false" || v == "currently_false");
        assert_eq!(
            lane["mark"].as_u64(),
            first_false.map(|(t, _)| *t),
            "{p}: {state}"
        );
    }
    assert!(
        lanes.iter().any(|l| l["mark"].as_u64().is_some()),
        "no property turned false: {state}"
    );
    the_kept_lanes_follow_the_lines(&kept, &lines);
    println!(
        "verdict to page: median {} ms, max {} ms over {shown} lines",
        state["median"], state["max"]
    );
    assert!(state["max"].as_u64().unwrap() < 5_000, "{state}");
}

/// The timeline's view as `[start, end, run end, points]`.
const VIEW: &str =
    "(function () { var tl = document.getElementById('timeline-live').hindsightTimeline; \
    return [tl.view[0], tl.view[1], tl.tEnd, tl.n]; })()";

/// Waits until the live timeline has more points than `n` (the sidecar's heartbeats
/// keep adding points after the system stopped); its view then.
fn grown(b: &mut Browser, n: u64) -> Vec<f64> {
    b.wait_for(
        &format!("document.getElementById('timeline-live').hindsightTimeline.n > {n}"),
        Duration::from_secs(30),
    );
    let v = b.eval(VIEW);
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}

/// A zoom stops the view from following the run's end, and keeps it while points are
/// added; the "follow the end" button starts following again.
fn follow_the_end(b: &mut Browser) {
    let follow = "document.getElementById('timeline-live').getAttribute('data-follow')";
    assert_eq!(b.eval(follow), "on");
    b.eval("document.querySelector('[data-act=in]').click()");
    assert_eq!(b.eval(follow), "off");
    let before = b.eval(VIEW);
    let before: Vec<f64> = serde_json::from_value(before).unwrap();
    let after = grown(b, before[3] as u64);
    assert_eq!(after[..2], before[..2], "the zoomed view moved");
    assert!(after[1] < after[2], "{after:?}");
    b.eval("document.querySelector('[data-act=follow]').click()");
    assert_eq!(b.eval(follow), "on");
    let now: Vec<f64> = serde_json::from_value(b.eval(VIEW)).unwrap();
    let later = grown(b, now[3] as u64);
    // Following: the view ends at the run's end, with the zoomed span.
    assert_eq!(later[1], later[2], "{later:?}");
    assert!(later[1] > after[1], "{later:?} after {after:?}");
    assert!(
        (later[1] - later[0] - (before[1] - before[0])).abs() < 1e-6,
        "{later:?} {before:?}"
    );
}

/// The page opened with `?keep=50` once the run is over (the server's history gives it
/// every point so far): it holds the last 50 points at most, says it dropped the others,
/// and its verdict table still shows each property's first false time, that of a point
/// it no longer holds, as the page that kept everything (`full`) does. What it showed.
fn a_page_that_keeps_50_points(
    b: &mut Browser,
    addr: &str,
    full: &serde_json::Value,
) -> serde_json::Value {
    b.open(&format!("http://{addr}/?keep=50"));
    let lines = full["lines"].as_u64().unwrap();
    b.wait_for(
        &format!("+document.getElementById('lines').textContent >= {lines}"),
        Duration::from_secs(30),
    );
    // The heartbeats add points until every first false time shown is of a dropped point
    // (a verdict line may be written well after its time, so that can take a while).
    b.wait_for(
        "(function () { var tl = document.getElementById('timeline-live').hindsightTimeline; \
         var ff = Array.from(document.querySelectorAll('tr[data-first-false]')); \
         return ff.length > 0 && ff.every(function (r) { \
           return +r.getAttribute('data-first-false') < tl.run.time[0] * tl.run.step_seconds; }); })()",
        Duration::from_secs(30),
    );
    let kept: serde_json::Value = serde_json::from_str(
        b.eval(
            "(function () { var tl = document.getElementById('timeline-live').hindsightTimeline; \
             var note = document.getElementById('kept'); \
             return JSON.stringify({points: tl.n, columns: tl.run.time.length, \
               dropped: +tl.el.getAttribute('data-dropped'), note: note.hidden ? '' : note.textContent, \
               first_kept: tl.run.time[0] * tl.run.step_seconds, t0: tl.run.time[0], \
               view: document.querySelector('.tools .view').textContent, \
               step: tl.run.step_seconds, \
               lines: +tl.el.getAttribute('data-lines'), \
               lanes: tl.lanes.filter(function (l) { return l.kind === 'verdict'; }).map(function (l) { \
                 return {name: l.name, last: l.get(tl.n - 1), \
                   changes: l.ch.map(function (k) { return [tl.run.time[k], l.get(k)]; })}; }), \
               rows: Array.from(document.querySelectorAll('tr[data-property]')).map(function (r) { \
                 return [r.getAttribute('data-property'), r.getAttribute('data-first-false'), \
                   r.getAttribute('data-verdict')]; })}); })()",
        )
        .as_str()
        .unwrap(),
    )
    .unwrap();
    let points = kept["points"].as_u64().unwrap();
    assert!(points <= 50 && points == kept["columns"], "{kept}");
    let dropped = kept["dropped"].as_u64().unwrap();
    assert!(
        points + dropped >= full["points"].as_u64().unwrap(),
        "{kept} {full}"
    );
    assert!(
        kept["note"].as_str().unwrap().starts_with(&format!(
            "Showing the last 50 points at most ({dropped} older "
        )),
        "{kept}"
    );
    // Point numbers count from the run's first point, dropped ones included (the view's
    // text is of the last frame drawn: heartbeats may have added points since).
    let of: u64 = kept["view"]
        .as_str()
        .unwrap()
        .rsplit(" of ")
        .next()
        .and_then(|n| n.trim_end_matches(')').parse().ok())
        .unwrap_or_else(|| panic!("{kept}"));
    assert!(of > dropped && of <= points + dropped, "{kept}");
    let first_kept = kept["first_kept"].as_f64().unwrap();
    let mut before = 0;
    for (k, f) in kept["rows"]
        .as_array()
        .unwrap()
        .iter()
        .zip(full["rows"].as_array().unwrap())
    {
        assert_eq!(k[0], f[0]);
        if let Some(ff) = f[2].as_str() {
            assert_eq!(k[1].as_str(), Some(ff), "{kept} {full}");
            before += usize::from(ff.parse::<f64>().unwrap() < first_kept);
        }
    }
    assert!(
        before > 0,
        "no first false before the points kept: {kept} {full}"
    );
    kept
}

/// The lanes the page that keeps 50 points rebuilt from them: each changes where the
/// verdict lines it had change its property after its first point's time, and ends at
/// the verdict its row shows; each row's first false time is that of the lines.
fn the_kept_lanes_follow_the_lines(kept: &serde_json::Value, lines: &[serde_json::Value]) {
    let (t0, shown) = (
        kept["t0"].as_u64().unwrap(),
        kept["lines"].as_u64().unwrap(),
    );
    let shown = &lines[..shown as usize];
    let step = kept["step"].as_f64().unwrap();
    let rows = kept["rows"].as_array().unwrap();
    for (lane, row) in kept["lanes"].as_array().unwrap().iter().zip(rows) {
        let p = lane["name"].as_str().unwrap();
        assert_eq!(row[0], p);
        let first_false = shown.iter().find(|l| {
            l["property"] == p && matches!(l["verdict"].as_str(), Some("false" | "currently_false"))
        });
        let ff = row[1].as_str().map(|f| f.parse::<f64>().unwrap());
        let want = first_false.map(|l| l["time"].as_u64().unwrap() as f64 * step);
        assert!(
            ff.is_some() == want.is_some()
                && ff.zip(want).is_none_or(|(a, b)| (a - b).abs() < 1e-6),
            "{p}: first false {ff:?}, lines say {want:?}"
        );
        assert_eq!(lane["last"], row[2], "{p}: {kept}");
        let got: Vec<(u64, String)> = lane["changes"]
            .as_array()
            .unwrap()
            .iter()
            .map(|c| (c[0].as_u64().unwrap(), c[1].as_str().unwrap().to_string()))
            .filter(|(t, _)| *t > t0)
            .collect();
        let want: Vec<(u64, String)> = changes(shown, p)
            .into_iter()
            .filter(|(t, _)| *t > t0)
            .collect();
        assert_eq!(got, want, "{p}: {kept}");
    }
}

#[test]
fn a_bad_serve_address_exits_2() {
    let out = hindsight()
        .args(["monitor", "--model"])
        .arg(museum())
        .args(["--config", "nothing.toml", "--serve", "nowhere"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("--serve"), "{err}");
}
