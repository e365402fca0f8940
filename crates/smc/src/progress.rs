//! Progress of SMC studies: a bar on a terminal (indicatif), a line now and then on a log.

use std::io::IsTerminal;
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

use super::runner::Progress;

/// Draws [`Progress`] reports on standard error: as a bar when it is a terminal, else
/// (a log, a CI job) as one plain line every [`LOG_EVERY`] of a study that lasts longer,
/// so that a long study is never silent.
///
/// ```no_run
/// # use hindsight_smc::progress::TerminalProgress;
/// let mut bar = TerminalProgress::stderr();
/// // run_study(&config, &rules, run, &mut |p| bar.update(p));
/// ```
#[derive(Debug)]
pub struct TerminalProgress {
    bar: Option<ProgressBar>,
    /// Log mode: when the last line was written (the study's start before the first).
    log: Option<Instant>,
}

/// How often a study writes a progress line when standard error is not a terminal.
pub const LOG_EVERY: Duration = Duration::from_secs(30);

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

/// One progress line for a log: `progress: 120/490 runs  2/5 properties done  elapsed
/// 1:00  left ~3:05`.
fn log_line(progress: &Progress<'_>) -> String {
    let expected = progress
        .expected_runs
        .map_or(String::new(), |e| format!("/{}", e.max(progress.runs)));
    format!(
        "progress: {}{expected} runs  {}",
        progress.runs,
        message(progress)
    )
}

/// Properties done, time spent and time left.
fn message(progress: &Progress<'_>) -> String {
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
    message
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_log_line_says_runs_properties_and_time() {
        let p = Progress {
            runs: 120,
            elapsed: Duration::from_secs(61),
            eta: Some(Duration::from_secs(3 * 3600 + 5)),
            expected_runs: Some(490),
            properties: &[],
            finished: false,
        };
        assert_eq!(
            log_line(&p),
            "progress: 120/490 runs  elapsed 1:01  left ~3:00:05"
        );
        let p = Progress {
            expected_runs: None,
            eta: None,
            ..p
        };
        assert_eq!(log_line(&p), "progress: 120 runs  elapsed 1:01");
    }
}
