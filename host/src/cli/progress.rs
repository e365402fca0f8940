//! Progress drawn on standard error: a study's bar (or a line now and then on a log) and
//! `hindsight run`'s one-line progress. The libraries report progress as values
//! (`smc::Progress`, `live::pace::RunProgress`); this module is where they are printed.

use std::io::{IsTerminal, Write};
use std::time::Instant;

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

use crate::verify::study::Progress;
use crate::verify::study::{log_line, message, LOG_EVERY};

/// Draws a study's [`Progress`] reports on standard error: as a bar when it is a terminal,
/// else (a log, a CI job) as one plain line every [`LOG_EVERY`] of a study that lasts
/// longer, so that a long study is never silent.
///
/// ```no_run
/// # use hindsight::cli::progress::TerminalProgress;
/// let mut bar = TerminalProgress::stderr();
/// // run_study(&config, &rules, run, &mut |p| bar.update(p));
/// ```
#[derive(Debug)]
pub struct TerminalProgress {
    bar: Option<ProgressBar>,
    /// Log mode: when the last line was written (the study's start before the first).
    log: Option<Instant>,
}

impl TerminalProgress {
    /// A bar on standard error if it is a terminal, log lines otherwise.
    pub fn stderr() -> TerminalProgress {
        if !std::io::stderr().is_terminal() {
            return TerminalProgress {
                bar: None,
                log: Some(Instant::now()),
            };
        }
        let bar = ProgressBar::with_draw_target(None, ProgressDrawTarget::stderr());
        let style = ProgressStyle::with_template("{bar:30} {pos}/{len} runs  {msg}")
            .unwrap_or_else(|_| ProgressStyle::default_bar());
        bar.set_style(style);
        TerminalProgress {
            bar: Some(bar),
            log: None,
        }
    }

    /// A bar that never draws.
    pub fn hidden() -> TerminalProgress {
        TerminalProgress {
            bar: None,
            log: None,
        }
    }

    /// Shows one report; clears the bar after the final one.
    pub fn update(&mut self, progress: &Progress<'_>) {
        if let Some(last) = &mut self.log {
            if !progress.finished && last.elapsed() >= LOG_EVERY {
                *last = Instant::now();
                eprintln!("{}", log_line(progress));
            }
            return;
        }
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
        bar.set_message(message(progress));
    }
}

/// One line that replaces itself on a terminal (`tty`: `\r` before it, no line break)
/// and stands on its own line otherwise; `hindsight run`'s progress.
pub fn draw_line(line: &str, tty: bool) {
    let mut err = std::io::stderr().lock();
    let _ = if tty {
        write!(err, "\r{line}")
    } else {
        writeln!(err, "{line}")
    };
    let _ = err.flush();
}
