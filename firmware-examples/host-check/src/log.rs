//! Decoding a firmware's defmt stream and reading its log lines (`start`, `property`, `verdict`, `final`, `done`, `error`).

use defmt_decoder::{DecodeError, Table};

/// Decodes a raw defmt stream with the defmt table of `elf` into one message per frame.
pub fn decode(elf: &[u8], stream: &[u8]) -> Result<Vec<String>, String> {
    let table = Table::parse(elf)
        .map_err(|e| format!("reading the defmt table: {e}"))?
        .ok_or("the image has no defmt table")?;
    let mut decoder = table.new_stream_decoder();
    decoder.received(stream);
    let mut messages = Vec::new();
    loop {
        match decoder.decode() {
            Ok(frame) => messages.push(frame.display_message().to_string()),
            // The stream ends after the last complete frame.
            Err(DecodeError::UnexpectedEof) => break,
            Err(DecodeError::Malformed) => {
                return Err(format!(
                    "malformed defmt frame after {} messages (last: {:?})",
                    messages.len(),
                    messages.last()
                ))
            }
        }
    }
    Ok(messages)
}

/// The `start` line.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Start {
    /// Image name.
    pub name: String,
    /// Number of properties.
    pub props: usize,
    /// Number of trace points the image will replay.
    pub points: u32,
    /// Monitor state size in bytes.
    pub state_bytes: usize,
}

/// A `verdict` line: property `prop`'s verdict at `point` differs from the one before.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Change {
    /// Property index.
    pub prop: usize,
    /// Point index, from 0.
    pub point: u32,
    /// The point's timestamp.
    pub time: u64,
    /// The new verdict.
    pub value: bool,
}

/// The `final` line: every verdict is final after `point`, and the image stopped stepping.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Final {
    /// The last point stepped, from 0.
    pub point: u32,
    /// Its timestamp.
    pub time: u64,
}

/// The `done` line.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Done {
    /// Points replayed.
    pub points: u32,
    /// Stack high-water mark of the whole run, in bytes.
    pub stack: u32,
    /// Of which the set-up (decoding, validating) used this much.
    pub setup_stack: u32,
    /// And the replay this much (frames live at its start included).
    pub replay_stack: u32,
}

/// Everything a firmware logged.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Log {
    /// Every message, in order.
    pub messages: Vec<String>,
    /// The `start` line, if any.
    pub start: Option<Start>,
    /// Property names from the `property` lines, by index.
    pub properties: Vec<String>,
    /// Every `verdict` line, in order.
    pub changes: Vec<Change>,
    /// The `final` line, if any.
    pub finality: Option<Final>,
    /// The `done` line, if any.
    pub done: Option<Done>,
    /// Every `error` line.
    pub errors: Vec<String>,
}

/// The value of `key=` among `fields`, parsed.
fn field<T: std::str::FromStr>(line: &str, key: &str) -> Result<T, String> {
    let prefix = format!("{key}=");
    let raw = line
        .split_whitespace()
        .find_map(|f| f.strip_prefix(&prefix))
        .ok_or_else(|| format!("no `{key}=` in log line {line:?}"))?;
    raw.parse()
        .map_err(|_| format!("bad `{key}={raw}` in log line {line:?}"))
}

impl Log {
    /// Reads decoded messages; other messages are kept in [`Log::messages`] only.
    pub fn parse(messages: Vec<String>) -> Result<Log, String> {
        let mut log = Log::default();
        for line in &messages {
            let mut words = line.split_whitespace();
            match words.next() {
                Some("start") => {
                    log.start = Some(Start {
                        name: words.next().unwrap_or_default().to_string(),
                        props: field(line, "props")?,
                        points: field(line, "points")?,
                        state_bytes: field(line, "state_bytes")?,
                    })
                }
                Some("property") => {
                    let index: usize = words
                        .next()
                        .and_then(|w| w.parse().ok())
                        .ok_or_else(|| format!("bad property line {line:?}"))?;
                    if index != log.properties.len() {
                        return Err(format!("property lines out of order at {line:?}"));
                    }
                    log.properties.push(words.collect::<Vec<_>>().join(" "));
                }
                Some("verdict") => log.changes.push(Change {
                    prop: field(line, "prop")?,
                    point: field(line, "point")?,
                    time: field(line, "time")?,
                    value: field(line, "value")?,
                }),
                Some("final") => {
                    log.finality = Some(Final {
                        point: field(line, "point")?,
                        time: field(line, "time")?,
                    })
                }
                Some("done") => {
                    log.done = Some(Done {
                        points: field(line, "points")?,
                        stack: field(line, "stack")?,
                        setup_stack: field(line, "setup_stack")?,
                        replay_stack: field(line, "replay_stack")?,
                    })
                }
                Some("error") => log.errors.push(line.clone()),
                _ => {}
            }
        }
        log.messages = messages;
        Ok(log)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_each_line_kind() {
        let lines = [
            "start monitor-static props=2 points=3 state_bytes=88",
            "property 0 first",
            "property 1 second",
            "verdict prop=0 point=0 time=0 value=true",
            "verdict prop=1 point=2 time=7 value=false",
            "replayed events=1 level_sum=3",
            "final point=2 time=7",
            "done points=3 stack=412 setup_stack=412 replay_stack=300",
        ];
        let log = Log::parse(lines.iter().map(|s| s.to_string()).collect()).unwrap();
        assert_eq!(
            log.start,
            Some(Start {
                name: "monitor-static".into(),
                props: 2,
                points: 3,
                state_bytes: 88
            })
        );
        assert_eq!(log.properties, ["first", "second"]);
        assert_eq!(
            log.changes[1],
            Change {
                prop: 1,
                point: 2,
                time: 7,
                value: false
            }
        );
        assert_eq!(
            log.done,
            Some(Done {
                points: 3,
                stack: 412,
                setup_stack: 412,
                replay_stack: 300
            })
        );
        assert_eq!(log.finality, Some(Final { point: 2, time: 7 }));
        assert!(log.errors.is_empty());
        assert_eq!(log.messages.len(), 8);
    }

    #[test]
    fn rejects_a_garbled_verdict() {
        let err = Log::parse(vec!["verdict prop=x point=0 time=0 value=true".into()]).unwrap_err();
        assert!(err.contains("prop=x"), "{err}");
    }
}
