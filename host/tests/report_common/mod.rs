//! What the report tests share: the museum's study with one bound too tight (so every run
//! fails it), the pages hindsight writes for it, and what those pages must not contain.
#![allow(dead_code)]

pub use crate::common::hindsight;
use std::path::{Path, PathBuf};

/// A fresh folder under the test target's tmp folder.
pub fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("report-{name}"));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The museum guide's bound for the alarm response, 6.2 s, in ticks of 100 ms less one:
/// every run violates it.
pub const TIGHT_TICKS: u64 = 61;

/// The museum's property file with the alarm response's bound set to 6.1 s.
pub fn tight_properties(dir: &Path) -> PathBuf {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let text = std::fs::read_to_string(root.join("examples/museum-guide/properties.xml")).unwrap();
    assert!(text.contains("since[6.2s:]"));
    let path = dir.join("properties.xml");
    std::fs::write(&path, text.replace("since[6.2s:]", "since[6.1s:]")).unwrap();
    path
}

/// What one museum study wrote: the pages and the files behind them.
pub struct Museum {
    /// `verify --report`'s page.
    pub verify_page: PathBuf,
    /// `verify --json`'s output.
    pub study: serde_json::Value,
    /// The saved failing run of `alarm_response`.
    pub failing_csv: PathBuf,
    /// `hindsight report`'s page from the files.
    pub files_page: PathBuf,
    /// The folder.
    pub dir: PathBuf,
}

/// Runs the museum with the tight bound (3 runs), saving one failing run per property,
/// writing the page with `verify --report` and again with `hindsight report`.
pub fn museum(name: &str) -> Museum {
    let dir = scratch(name);
    let props = tight_properties(&dir);
    let d = |f: &str| dir.join(f).display().to_string();
    let (code, out, err) = hindsight(&[
        "verify",
        "examples/museum-guide",
        &props.display().to_string(),
        "--max-runs",
        "3",
        "--seed",
        "1",
        "--json",
        "--save-failing",
        "1",
        "--out",
        &d("runs"),
        "--report",
        &d("verify.html"),
    ]);
    assert_eq!(code, 0, "{err}");
    std::fs::write(dir.join("study.json"), &out).unwrap();
    let study: serde_json::Value = serde_json::from_str(&out).unwrap();
    let failing_csv = dir.join("runs/alarm_response-run0.csv");
    assert!(failing_csv.is_file(), "{err}");
    let (code, _, err) = hindsight(&[
        "report",
        "--study",
        &d("study.json"),
        &d("runs"),
        "-o",
        &d("files.html"),
    ]);
    assert_eq!(code, 0, "{err}");
    Museum {
        verify_page: dir.join("verify.html"),
        study,
        failing_csv,
        files_page: dir.join("files.html"),
        dir,
    }
}

/// Where the alarm response must first be false in a saved run, read from the run's
/// own columns: `TIGHT_TICKS` after the first alarm (the battery stays low after it, so
/// the next alarm is due within the bound, and it comes at 6.2 s). Returns the time and
/// the index of the first point at that time.
pub fn expected_first_false(csv: &str) -> (u64, usize) {
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let alarm = header.iter().position(|h| *h == "alarm").unwrap();
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    let time = |r: &Vec<&str>| r[0].parse::<u64>().unwrap();
    let first_alarm = rows.iter().find(|r| r[alarm] == "true").map(time).unwrap();
    let due = first_alarm + TIGHT_TICKS;
    let point = rows.iter().position(|r| time(r) >= due).unwrap();
    (time(&rows[point]), point)
}

/// Every reference to something outside the page: URLs, protocol-relative `src`/`href`,
/// CSS imports and `url(...)`, external elements. Empty for a self-contained page.
pub fn external_refs(html: &str) -> Vec<String> {
    let lower = html.to_ascii_lowercase();
    let mut found = Vec::new();
    for needle in [
        "http://",
        "https://",
        "src=\"//",
        "href=\"//",
        "src='//",
        "href='//",
        "@import",
        "url(",
        "<link",
        "<iframe",
        "<img",
        " src=",
    ] {
        if let Some(at) = lower.find(needle) {
            let from = at.saturating_sub(40);
            let to = (at + 60).min(html.len());
            found.push(format!(
                "{needle}: ...{}...",
                html.get(from..to).unwrap_or("?")
            ));
        }
    }
    found
}

/// A saved run's CSV without its leading `# time unit` comment (a robot model's runs
/// name their unit there): the header first, then one line per point, as the page
/// counts them.
pub fn read_run(path: &std::path::Path) -> String {
    let text = std::fs::read_to_string(path).unwrap();
    assert!(
        text.starts_with("# time unit: "),
        "{}",
        &text[..40.min(text.len())]
    );
    text.lines()
        .filter(|l| !l.starts_with('#'))
        .map(|l| format!("{l}\n"))
        .collect()
}
