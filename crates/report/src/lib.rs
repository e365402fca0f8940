//! One self-contained HTML page for a study, its sweeps and its failing runs.
//!
//! In: a [`ReportData`] (built from a study in memory by `verify --report` / `sweep
//! --report`, or from the files `verify --json`, `sweep --json` and `--save-failing`
//! write, by `hindsight report`). Out: [`render`]'s page, which fetches nothing: styles,
//! the script that draws the timelines, the charts (SVG) and the runs (JSON) are inline,
//! and a Content-Security-Policy forbids any load. The study and the sweeps are plain
//! HTML, readable without the script; each failing run is drawn by `page.js` (plain
//! JavaScript and SVG, no build step) as a timeline with zoom, pan and a point's state.
//!
//! # Crate
//!
//! `hindsight-report` depends on `hindsight-verify` (the study's result it shows, and the
//! one markup escaper, `model::xml::escape`) and `codegen` (the CSV reader and
//! diagnostics); `hindsight-live` uses its script and styles ([`PAGE_JS`], [`PAGE_CSS`])
//! for the live page, and `hindsight`'s command line writes its pages.
//!
//! A failing run, as `verify --save-failing` writes it, on a page:
//!
//! ```
//! use hindsight_report::{render, ReportData, Run};
//!
//! let csv = "time,step,event,origin,target,params,x,verdict_safe\n\
//!            0,init,,,,,0,true\n\
//!            5,send,go,a,b,,3,false\n";
//! let run = Run::from_csv("safe-run7.csv", csv).unwrap();
//! assert_eq!((run.property.as_deref(), run.run), (Some("safe"), Some(7)));
//! assert_eq!(run.first_false()[0].time, 5);
//! let page = render(&ReportData { title: "museum".into(), runs: vec![run], ..Default::default() });
//! assert!(page.starts_with("<!DOCTYPE html>") && page.contains("<title>museum"));
//!
//! // A bad file is a diagnostic naming file:line:col, not a panic.
//! let err = Run::from_csv("bad.csv", "time,oops\n").unwrap_err();
//! assert!(err.to_string().starts_with("bad.csv:1:1:"), "{err}");
//! ```

// `pub` only where another crate can reach it: internals are `pub(crate)` (issue 27).
#![warn(unreachable_pub)]

pub mod data;
mod html;
pub mod plot;

pub use data::{PropertyRow, ReportData, Run, Study, Sweep};

/// The script that draws a run's timeline (plain JavaScript and SVG, no build step),
/// inlined in every report page and, before its own script, in the live page.
pub const PAGE_JS: &str = include_str!("page.js");

/// The styles of a report page, shared with the live page.
pub const PAGE_CSS: &str = include_str!("page.css");

/// The page for `data`.
pub fn render(data: &ReportData) -> String {
    html::page(data)
}
