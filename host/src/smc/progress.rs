//! A progress bar for SMC studies on a terminal (indicatif), silent otherwise.

use std::io::IsTerminal;
use std::time::Duration;

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

use super::runner::Progress;

/// Draws [`Progress`] reports as a bar on standard error, only when standard error is a
/// terminal; otherwise every call does nothing.
///
/// ```no_run
/// # use hindsight::smc::progress::TerminalProgress;
/// let mut bar = TerminalProgress::stderr();
/// // run_study(&config, &rules, run, &mut |p| bar.update(p));
/// ```
#[derive(Debug)]
pub struct TerminalProgress {
    bar: Option<ProgressBar>,
}

impl TerminalProgress {
    /// A bar on standard error if it is a terminal.
    pub fn stderr() -> TerminalProgress {
        if !std::io::stderr().is_terminal() {
            return TerminalProgress::hidden();
        }
        let bar = ProgressBar::with_draw_target(None, ProgressDrawTarget::stderr());
        let style = ProgressStyle::with_template("{bar:30} {pos}/{len} runs  {msg}")
            .unwrap_or_else(|_| ProgressStyle::default_bar());
        bar.set_style(style);
        TerminalProgress { bar: Some(bar) }
    }

    /// A bar that never draws.
    pub fn hidden() -> TerminalProgress {
        TerminalProgress { bar: None }
    }

    /// Whether anything is drawn.
    pub fn is_visible(&self) -> bool {
        self.bar.is_some()
    }

    /// Shows one report; clears the bar after the final one.
    pub fn update(&mut self, progress: &Progress<'_>) {
        let Some(bar) = &self.bar else {
            return;
        };
        if progress.finished {
            bar.finish_and_clear();
            return;
        }
        if let Some(expected) = progress.expected_runs {
            bar.set_length(expected.max(progress.runs));
        }
        bar.set_position(progress.runs);
        let done = progress
            .properties
            .iter()
            .filter(|p| p.stopped_at.is_some())
            .count();
        let mut message = String::new();
        if !progress.properties.is_empty() {
            message.push_str(&format!(
                "{done}/{} properties done  ",
                progress.properties.len()
            ));
        }
        message.push_str(&format!("elapsed {}", clock(progress.elapsed)));
        if let Some(eta) = progress.eta {
            message.push_str(&format!("  left ~{}", clock(eta)));
        }
        bar.set_message(message);
    }
}

/// `h:mm:ss` or `m:ss`.
fn clock(duration: Duration) -> String {
    let seconds = duration.as_secs();
    let (hours, minutes, seconds) = (seconds / 3600, seconds / 60 % 60, seconds % 60);
    if hours > 0 {
        format!("{hours}:{minutes:02}:{seconds:02}")
    } else {
        format!("{minutes}:{seconds:02}")
    }
}
