//! Progress of SMC studies as text: the line a log gets now and then, and the message
//! beside a bar. The crate prints nothing: a study hands each [`Progress`] report to its
//! caller's callback, and `hindsight`'s command line draws them (`cli/progress.rs`: a bar
//! on a terminal, [`log_line`] every [`LOG_EVERY`] otherwise).

use std::time::Duration;

use super::runner::Progress;

/// How often a study's progress is worth a line when it cannot be drawn as a bar (a log,
/// a CI job), so that a long study is never silent.
pub const LOG_EVERY: Duration = Duration::from_secs(30);

/// One progress line for a log: `progress: 120/490 runs  2/5 properties done  elapsed
/// 1:00  left ~3:05`.
pub fn log_line(progress: &Progress<'_>) -> String {
    let expected = progress
        .expected_runs
        .map_or(String::new(), |e| format!("/{}", e.max(progress.runs)));
    format!(
        "progress: {}{expected} runs  {}",
        progress.runs,
        message(progress)
    )
}

/// Properties done, time spent and time left: `2/5 properties done  elapsed 1:00  left
/// ~3:05`.
pub fn message(progress: &Progress<'_>) -> String {
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
