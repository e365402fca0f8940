//! One self-contained HTML page for a study, its sweeps and its failing runs.
//!
//! In: a [`ReportData`] (built from a study in memory by `verify --report` / `sweep
//! --report`, or from the files `verify --json`, `sweep --json` and `--save-failing`
//! write, by `hindsight report`). Out: [`render`]'s page, which fetches nothing: styles,
//! the script that draws the timelines, the charts (SVG) and the runs (JSON) are inline,
//! and a Content-Security-Policy forbids any load. The study and the sweeps are plain
//! HTML, readable without the script; each failing run is drawn by `page.js` (plain
//! JavaScript and SVG, no build step) as a timeline with zoom, pan and a point's state.

pub mod data;
pub mod html;
pub mod plot;

pub use data::{PropertyRow, ReportData, Run, Study, Sweep};

/// The page for `data`.
pub fn render(data: &ReportData) -> String {
    html::page(data)
}
