//! rosbag2 recordings, read one message at a time: an MCAP file, a SQLite `.db3` file, or
//! a rosbag2 folder (`metadata.yaml` naming its files, read in the order it lists them).
//!
//! # What is read
//!
//! - **MCAP** (the `mcap` crate): every channel's topic, its schema's name (the ROS type,
//!   `pkg/msg/Type`) and, for schema encoding `ros2msg`, its definition text; every
//!   message's log time (rosbag2's receive time) and data, in file order. Channels must
//!   have message encoding `cdr`.
//! - **`.db3`** (rosbag2's `sqlite3` storage, read with `rusqlite`): table `topics`
//!   (`id`, `name`, `type`, `serialization_format`), table `messages` (`topic_id`,
//!   `timestamp`, `data`) in timestamp order, and, where the file has it (rosbag2 Iron
//!   and later, and the `rosbags` writer), table `message_definitions` (`topic_type`,
//!   `encoding`, `encoded_message_definition`) for the definitions; without it a type is
//!   looked up in the interface packages.
//! - **A folder**: `metadata.yaml`'s `rosbag2_bagfile_information` with
//!   `storage_identifier` (`mcap` or `sqlite3`) and `relative_file_paths`.
//!
//! Messages reach the caller in file order (rosbag2 writes in receive order); a
//! connection is one `(topic, type, definition)`, numbered once across all files.

use std::path::{Path, PathBuf};

/// One topic with its type, as recorded.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Connection {
    /// The topic (`/battery`).
    pub topic: String,
    /// The ROS type (`sensor_msgs/msg/BatteryState`).
    pub type_name: String,
    /// The definition in the `ros2msg` format, when the file carries one.
    pub definition: Option<String>,
}

/// One recorded message.
#[derive(Clone, Copy, Debug)]
pub struct Message<'a> {
    /// Index into the connections passed along with it.
    pub conn: usize,
    /// The log (receive) time, in nanoseconds since the epoch.
    pub log_time: u64,
    /// The serialised message (CDR, with its encapsulation header).
    pub data: &'a [u8],
}

/// What a reader calls with each message and the connections known so far; an error
/// stops the reading.
pub type Visit<'v> = dyn FnMut(&[Connection], Message<'_>) -> Result<(), String> + 'v;

/// The files of a recording, in order, and how each is stored.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Recording {
    /// `(file, is MCAP)` in reading order.
    pub files: Vec<(PathBuf, bool)>,
}

impl Recording {
    /// The recording at `path`: an `.mcap` or `.db3` file, a rosbag2 folder, or its
    /// `metadata.yaml`.
    pub fn open(path: &Path) -> Result<Recording, String> {
        let shown = path.display();
        if path.is_dir() {
            let meta = path.join("metadata.yaml");
            if !meta.is_file() {
                return Err(format!(
                    "{shown}: a folder without metadata.yaml is not a rosbag2 recording (name its .mcap or .db3 file instead)"
                ));
            }
            return Self::from_metadata(&meta);
        }
        if path.file_name().is_some_and(|n| n == "metadata.yaml") {
            return Self::from_metadata(path);
        }
        match path.extension().and_then(|e| e.to_str()) {
            Some("mcap") => Ok(Recording {
                files: vec![(path.to_path_buf(), true)],
            }),
            Some("db3") => Ok(Recording {
                files: vec![(path.to_path_buf(), false)],
            }),
            _ => Err(format!(
                "{shown}: not a recording (expected an .mcap or .db3 file or a rosbag2 folder)"
            )),
        }
    }

    fn from_metadata(meta: &Path) -> Result<Recording, String> {
        use yaml_rust2::{Yaml, YamlLoader};
        let shown = meta.display();
        let text =
            std::fs::read_to_string(meta).map_err(|e| format!("{shown}: cannot read: {e}"))?;
        let docs = YamlLoader::load_from_str(&text).map_err(|e| {
            let m = e.marker();
            format!("{shown}:{}:{}: {}", m.line(), m.col() + 1, e.info())
        })?;
        let info = &docs.first().unwrap_or(&Yaml::Null)["rosbag2_bagfile_information"];
        if info.is_badvalue() {
            return Err(format!(
                "{shown}: no `rosbag2_bagfile_information` (is this rosbag2's metadata.yaml?)"
            ));
        }
        let storage = info["storage_identifier"].as_str().unwrap_or("");
        let dir = meta.parent().unwrap_or(Path::new("."));
        let Some(list) = info["relative_file_paths"].as_vec() else {
            return Err(format!("{shown}: no `relative_file_paths` list"));
        };
        let mut files = Vec::new();
        for item in list {
            let Some(rel) = item.as_str() else {
                return Err(format!("{shown}: `relative_file_paths` holds a non-string"));
            };
            let path = dir.join(rel);
            let mcap = match (storage, path.extension().and_then(|e| e.to_str())) {
                ("mcap", _) | (_, Some("mcap")) => true,
                ("sqlite3", _) | (_, Some("db3")) => false,
                _ => {
                    return Err(format!(
                        "{shown}: storage `{storage}` of `{rel}` is neither `mcap` nor `sqlite3`"
                    ))
                }
            };
            files.push((path, mcap));
        }
        if files.is_empty() {
            return Err(format!("{shown}: `relative_file_paths` is empty"));
        }
        Ok(Recording { files })
    }

    /// Calls `visit` with every message, in order, and the connections known so far.
    /// An error from `visit` stops the reading and is returned as is; a file that does
    /// not read is an error naming it and the messages read from it so far.
    pub fn for_each(&self, visit: &mut Visit<'_>) -> Result<(), String> {
        let mut conns = Vec::new();
        for (file, mcap) in &self.files {
            if *mcap {
                read_mcap(file, &mut conns, visit)?;
            } else {
                read_db3(file, &mut conns, visit)?;
            }
        }
        Ok(())
    }
}

/// The index of connection `c` in `conns`, added if new.
fn intern(conns: &mut Vec<Connection>, c: Connection) -> usize {
    match conns.iter().position(|k| *k == c) {
        Some(i) => i,
        None => {
            conns.push(c);
            conns.len() - 1
        }
    }
}

fn read_mcap(
    file: &Path,
    conns: &mut Vec<Connection>,
    visit: &mut Visit<'_>,
) -> Result<(), String> {
    let shown = file.display();
    let bytes = std::fs::read(file).map_err(|e| format!("{shown}: cannot read: {e}"))?;
    mcap_bytes(&bytes, &shown.to_string(), conns, visit)
}

/// The messages of an MCAP file held in memory (`shown` names it in errors), as
/// [`Recording::for_each`] gives them; `conns` collects the connections.
///
/// The `mcap` crate's sans-I/O reader does the container (chunks, compression, the end
/// magic) with a record length limit (a chunk may be 4096 times the file): its convenience iterators set
/// none, and then reserve whatever length a corrupt record inside a chunk claims.
pub fn mcap_bytes(
    bytes: &[u8],
    shown: &str,
    conns: &mut Vec<Connection>,
    visit: &mut Visit<'_>,
) -> Result<(), String> {
    use mcap::records::Record;
    use mcap::sans_io::linear_reader::{LinearReadEvent, LinearReader, LinearReaderOptions};
    check_chunks(bytes).map_err(|e| format!("{shown}: {e}"))?;
    let mut reader = LinearReader::new_with_options(
        LinearReaderOptions::default().with_record_length_limit(record_limit(bytes.len())),
    );
    let mut rest = bytes;
    // Schemas: id -> (name, encoding, text); channels: id -> connection (or the error to
    // give when a message uses the channel).
    let mut schemas: Vec<(u16, String, String, String)> = Vec::new();
    let mut by_channel: Vec<Option<Result<usize, String>>> = Vec::new();
    let mut channels: Vec<(u16, u16, String, String)> = Vec::new();
    let mut n = 0u64;
    while let Some(event) = reader.next_event() {
        let event = event.map_err(|e| format!("{shown}: unreadable after {n} message(s): {e}"))?;
        let (opcode, data) = match event {
            LinearReadEvent::ReadRequest(need) => {
                let k = need.min(rest.len());
                reader.insert(k).copy_from_slice(&rest[..k]);
                reader.notify_read(k);
                rest = &rest[k..];
                continue;
            }
            LinearReadEvent::Record { opcode, data } => (opcode, data),
        };
        let record = mcap::parse_record(opcode, data)
            .map_err(|e| format!("{shown}: unreadable after {n} message(s): {e}"))?;
        match record {
            Record::Schema { header, data } => {
                schemas.retain(|s| s.0 != header.id);
                schemas.push((
                    header.id,
                    header.name,
                    header.encoding,
                    String::from_utf8_lossy(&data).into_owned(),
                ));
            }
            Record::Channel(ch) => {
                channels.retain(|c| c.0 != ch.id);
                channels.push((ch.id, ch.schema_id, ch.topic, ch.message_encoding));
                if let Some(slot) = by_channel.get_mut(ch.id as usize) {
                    *slot = None;
                }
            }
            Record::Message { header, data } => {
                n += 1;
                let id = header.channel_id as usize;
                if by_channel.len() <= id {
                    by_channel.resize(id + 1, None);
                }
                let conn = match &by_channel[id] {
                    Some(c) => c.clone(),
                    None => {
                        let c = connection(header.channel_id, &channels, &schemas, conns);
                        by_channel[id] = Some(c.clone());
                        c
                    }
                }
                .map_err(|e| format!("{shown}: message {n}: {e}"))?;
                visit(
                    conns,
                    Message {
                        conn,
                        log_time: header.log_time,
                        data: &data,
                    },
                )?;
            }
            _ => {}
        }
    }
    Ok(())
}

/// The record length limit for an MCAP file of `len` bytes: a chunk may hold
/// [`MAX_CHUNK_RATIO`] times the whole file uncompressed (and at least 16 MiB).
fn record_limit(len: usize) -> usize {
    len.saturating_mul(MAX_CHUNK_RATIO as usize).max(16 << 20)
}

/// The connection of MCAP channel `id`.
fn connection(
    id: u16,
    channels: &[(u16, u16, String, String)],
    schemas: &[(u16, String, String, String)],
    conns: &mut Vec<Connection>,
) -> Result<usize, String> {
    let Some((_, schema_id, topic, encoding)) = channels.iter().find(|c| c.0 == id) else {
        return Err(format!("it names channel {id}, which was not declared"));
    };
    if encoding != "cdr" {
        return Err(format!(
            "topic `{topic}` has message encoding `{encoding}`; ROS 2 recordings use `cdr`"
        ));
    }
    let (type_name, definition) = match schemas.iter().find(|s| s.0 == *schema_id) {
        Some((_, name, enc, text)) if enc == "ros2msg" => (name.clone(), Some(text.clone())),
        Some((_, name, enc, text)) if enc.is_empty() || text.is_empty() => (name.clone(), None),
        Some((_, _, enc, _)) => {
            return Err(format!(
                "topic `{topic}` has schema encoding `{enc}`; only `ros2msg` is read (the `ros2idl` form is not)"
            ))
        }
        None => {
            return Err(format!(
                "topic `{topic}` has no schema, so its type is unknown"
            ))
        }
    };
    Ok(intern(
        conns,
        Connection {
            topic: topic.clone(),
            type_name,
            definition,
        },
    ))
}

/// Largest ratio of a chunk's uncompressed size to its compressed size that is believed.
const MAX_CHUNK_RATIO: u64 = 4096;

/// Refuses a chunk whose header claims an uncompressed size it cannot hold: the `mcap`
/// crate reserves the claimed size before decompressing, so a corrupt header would make
/// it allocate terabytes. A chunk (MCAP specification, "Chunk" record, opcode `0x06`)
/// is: start and end time (`u64` each), `uncompressed_size` (`u64`), CRC (`u32`),
/// compression (a `u32`-prefixed string), then its records (a `u64`-prefixed byte
/// array). Uncompressed, the sizes must agree; compressed, the claim is capped at
/// [`MAX_CHUNK_RATIO`] times the compressed size (and 1 MiB for tiny chunks). Records
/// that do not parse are left for the reader to report.
fn check_chunks(bytes: &[u8]) -> Result<(), String> {
    let u64_at = |at: usize| -> Option<u64> {
        Some(u64::from_le_bytes(bytes.get(at..at + 8)?.try_into().ok()?))
    };
    let mut at = 8; // the magic
    while at + 9 <= bytes.len() {
        let op = bytes[at];
        let Some(len) = u64_at(at + 1) else { break };
        let body = at + 9;
        // A record cut short is still checked: the reader reserves a chunk's claimed size
        // from its header alone.
        let end = usize::try_from(len)
            .ok()
            .and_then(|l| body.checked_add(l))
            .unwrap_or(usize::MAX);
        if op == 0x06 {
            let Some(claimed) = u64_at(body + 16) else {
                break;
            };
            let c = body + 28;
            let Some(clen) = bytes
                .get(c..c + 4)
                .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize)
            else {
                break;
            };
            let r = c + 4 + clen;
            let Some(stored) = u64_at(r) else { break };
            let compression = bytes.get(c + 4..r).unwrap_or_default();
            let plausible = if compression.is_empty() {
                claimed == stored
            } else {
                claimed <= stored.saturating_mul(MAX_CHUNK_RATIO).max(1 << 20)
            };
            if !plausible {
                return Err(format!(
                    "the chunk at byte {at} claims {claimed} uncompressed bytes from {stored} stored ones: the file is corrupt"
                ));
            }
        }
        if end > bytes.len() {
            break;
        }
        at = end;
    }
    Ok(())
}

fn read_db3(file: &Path, conns: &mut Vec<Connection>, visit: &mut Visit<'_>) -> Result<(), String> {
    use rusqlite::{Connection as Db, OpenFlags};
    let shown = file.display();
    if !file.is_file() {
        return Err(format!("{shown}: no such file"));
    }
    let sql = |e: rusqlite::Error| format!("{shown}: {e}");
    let db = Db::open_with_flags(file, OpenFlags::SQLITE_OPEN_READ_ONLY).map_err(sql)?;
    let tables: Vec<String> = db
        .prepare("SELECT name FROM sqlite_master WHERE type = 'table'")
        .and_then(|mut s| {
            s.query_map([], |r| r.get::<_, String>(0))?
                .collect::<Result<Vec<_>, _>>()
        })
        .map_err(|e| format!("{shown}: not a rosbag2 SQLite file: {e}"))?;
    for t in ["topics", "messages"] {
        if !tables.iter().any(|x| x == t) {
            return Err(format!(
                "{shown}: no table `{t}`: not a rosbag2 SQLite file"
            ));
        }
    }
    let mut definitions: Vec<(String, String)> = Vec::new();
    if tables.iter().any(|x| x == "message_definitions") {
        let mut s = db
            .prepare(
                "SELECT topic_type, encoding, encoded_message_definition FROM message_definitions",
            )
            .map_err(sql)?;
        let rows = s
            .query_map([], |r| {
                Ok((
                    r.get::<_, String>(0)?,
                    r.get::<_, String>(1)?,
                    r.get::<_, String>(2)?,
                ))
            })
            .map_err(sql)?;
        for row in rows {
            let (ty, enc, text) = row.map_err(sql)?;
            if enc == "ros2msg" && !text.trim().is_empty() {
                definitions.push((ty, text));
            }
        }
    }
    // topic id -> connection index.
    let mut by_id: Vec<(i64, usize)> = Vec::new();
    {
        let mut s = db
            .prepare("SELECT id, name, type, serialization_format FROM topics")
            .map_err(sql)?;
        let rows = s
            .query_map([], |r| {
                Ok((
                    r.get::<_, i64>(0)?,
                    r.get::<_, String>(1)?,
                    r.get::<_, String>(2)?,
                    r.get::<_, String>(3)?,
                ))
            })
            .map_err(sql)?;
        for row in rows {
            let (id, topic, type_name, format) = row.map_err(sql)?;
            if format != "cdr" {
                return Err(format!(
                    "{shown}: topic `{topic}` has serialization format `{format}`; ROS 2 recordings use `cdr`"
                ));
            }
            let definition = definitions
                .iter()
                .find(|(t, _)| *t == type_name)
                .map(|(_, d)| d.clone());
            let c = intern(
                conns,
                Connection {
                    topic,
                    type_name,
                    definition,
                },
            );
            by_id.push((id, c));
        }
    }
    let mut s = db
        .prepare("SELECT topic_id, timestamp, data FROM messages ORDER BY timestamp, id")
        .map_err(sql)?;
    let mut rows = s.query([]).map_err(sql)?;
    let mut n = 0u64;
    loop {
        let row = match rows.next() {
            Ok(Some(r)) => r,
            Ok(None) => break,
            Err(e) => return Err(format!("{shown}: unreadable after {n} message(s): {e}")),
        };
        n += 1;
        let bad = |e: rusqlite::Error| format!("{shown}: message {n}: {e}");
        let topic_id: i64 = row.get(0).map_err(bad)?;
        let time: i64 = row.get(1).map_err(bad)?;
        let data = row
            .get_ref(2)
            .map_err(bad)?
            .as_blob()
            .map_err(|e| format!("{shown}: message {n}: {e}"))?;
        let Some(&(_, conn)) = by_id.iter().find(|(id, _)| *id == topic_id) else {
            return Err(format!(
                "{shown}: message {n} has topic id {topic_id}, which table `topics` does not list"
            ));
        };
        let Ok(log_time) = u64::try_from(time) else {
            return Err(format!(
                "{shown}: message {n} (topic `{}`) has a negative timestamp {time}",
                conns[conn].topic
            ));
        };
        visit(
            conns,
            Message {
                conn,
                log_time,
                data,
            },
        )?;
    }
    Ok(())
}
