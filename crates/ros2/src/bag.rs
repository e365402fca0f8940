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

/// What the storage layer (the `mcap` crate or SQLite) reported.
#[derive(Debug)]
pub enum StorageError {
    /// The `mcap` crate's error.
    Mcap(mcap::McapError),
    /// SQLite's error.
    Sqlite(rusqlite::Error),
    /// A `.db3` column of another type than rosbag2 writes.
    Column(rusqlite::types::FromSqlError),
}

impl std::fmt::Display for StorageError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            StorageError::Mcap(e) => write!(f, "{e}"),
            StorageError::Sqlite(e) => write!(f, "{e}"),
            StorageError::Column(e) => write!(f, "{e}"),
        }
    }
}

/// Why a message's MCAP channel gives no connection (the file and the message index are
/// in the [`BagError::Channel`] holding it).
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum ChannelError {
    /// The message names a channel no record declared.
    Undeclared(u16),
    /// The channel's message encoding is not `cdr`.
    Encoding {
        /// The topic.
        topic: String,
        /// Its message encoding.
        encoding: String,
    },
    /// The channel's schema encoding is neither `ros2msg` nor empty.
    SchemaEncoding {
        /// The topic.
        topic: String,
        /// Its schema encoding.
        encoding: String,
    },
    /// The channel has no schema.
    NoSchema {
        /// The topic.
        topic: String,
    },
}

impl std::fmt::Display for ChannelError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ChannelError::Undeclared(id) => {
                write!(f, "it names channel {id}, which was not declared")
            }
            ChannelError::Encoding { topic, encoding } => write!(
                f,
                "topic `{topic}` has message encoding `{encoding}`; ROS 2 recordings use `cdr`"
            ),
            ChannelError::SchemaEncoding { topic, encoding } => write!(
                f,
                "topic `{topic}` has schema encoding `{encoding}`; only `ros2msg` is read (the `ros2idl` form is not)"
            ),
            ChannelError::NoSchema { topic } => {
                write!(f, "topic `{topic}` has no schema, so its type is unknown")
            }
        }
    }
}

/// A recording that cannot be read: every variant names the file (as given, or
/// `<mcap>` for bytes in memory) and, where a message is at fault, its index in the file
/// (from 1) or the number of messages read before the fault.
#[derive(Debug)]
pub enum BagError {
    /// A folder without `metadata.yaml`.
    NoMetadata {
        /// The folder.
        file: String,
    },
    /// Neither `.mcap`, `.db3`, a folder nor `metadata.yaml`.
    NotARecording {
        /// The path.
        file: String,
    },
    /// The file does not read.
    Read {
        /// The file.
        file: String,
        /// Why.
        error: std::io::Error,
    },
    /// `metadata.yaml` is not YAML.
    Yaml {
        /// The file.
        file: String,
        /// 1-based line.
        line: usize,
        /// 1-based column.
        col: usize,
        /// What the YAML reader says.
        what: String,
    },
    /// `metadata.yaml` is YAML but not rosbag2's.
    Metadata {
        /// The file.
        file: String,
        /// What is missing or wrong.
        problem: MetadataError,
    },
    /// An MCAP chunk claims an uncompressed size it cannot hold.
    CorruptChunk {
        /// The file.
        file: String,
        /// The chunk's record offset in bytes.
        at: usize,
        /// The uncompressed size it claims.
        claimed: u64,
        /// The bytes it stores.
        stored: u64,
    },
    /// The container does not read after `after` messages.
    Unreadable {
        /// The file.
        file: String,
        /// Messages read before.
        after: u64,
        /// The storage layer's error.
        error: StorageError,
    },
    /// Message `index` of an MCAP file has no usable channel.
    Channel {
        /// The file.
        file: String,
        /// The message's index in the file, from 1.
        index: u64,
        /// Why.
        error: ChannelError,
    },
    /// A `.db3` path that is not a file.
    NoSuchFile {
        /// The path.
        file: String,
    },
    /// A `.db3` file that is not rosbag2's SQLite layout.
    NotSqliteBag {
        /// The file.
        file: String,
        /// The missing table, or `None` when the schema does not read.
        table: Option<&'static str>,
        /// SQLite's error, when it gave one.
        error: Option<rusqlite::Error>,
    },
    /// A `.db3` topic with another serialization format than `cdr`.
    Format {
        /// The file.
        file: String,
        /// The topic.
        topic: String,
        /// Its format.
        format: String,
    },
    /// Message `index` of a `.db3` file does not read.
    Row {
        /// The file.
        file: String,
        /// The message's index in the file, from 1.
        index: u64,
        /// SQLite's error.
        error: StorageError,
    },
    /// Message `index` of a `.db3` file names a topic id table `topics` lacks.
    TopicId {
        /// The file.
        file: String,
        /// The message's index in the file, from 1.
        index: u64,
        /// The id.
        topic_id: i64,
    },
    /// Message `index` of a `.db3` file has a negative timestamp.
    NegativeTime {
        /// The file.
        file: String,
        /// The message's index in the file, from 1.
        index: u64,
        /// Its topic.
        topic: String,
        /// The timestamp.
        time: i64,
    },
}

/// What is wrong with a `metadata.yaml`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum MetadataError {
    /// No `rosbag2_bagfile_information`.
    NoInformation,
    /// No `relative_file_paths` list.
    NoFiles,
    /// `relative_file_paths` holds a non-string.
    NonString,
    /// A file whose storage is neither `mcap` nor `sqlite3`.
    Storage {
        /// `storage_identifier`.
        storage: String,
        /// The file.
        file: String,
    },
    /// `relative_file_paths` is empty.
    Empty,
}

impl std::fmt::Display for MetadataError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            MetadataError::NoInformation => {
                f.write_str("no `rosbag2_bagfile_information` (is this rosbag2's metadata.yaml?)")
            }
            MetadataError::NoFiles => f.write_str("no `relative_file_paths` list"),
            MetadataError::NonString => f.write_str("`relative_file_paths` holds a non-string"),
            MetadataError::Storage { storage, file } => write!(
                f,
                "storage `{storage}` of `{file}` is neither `mcap` nor `sqlite3`"
            ),
            MetadataError::Empty => f.write_str("`relative_file_paths` is empty"),
        }
    }
}

impl BagError {
    /// The file the error is about.
    pub fn file(&self) -> &str {
        match self {
            BagError::NoMetadata { file }
            | BagError::NotARecording { file }
            | BagError::Read { file, .. }
            | BagError::Yaml { file, .. }
            | BagError::Metadata { file, .. }
            | BagError::CorruptChunk { file, .. }
            | BagError::Unreadable { file, .. }
            | BagError::Channel { file, .. }
            | BagError::NoSuchFile { file }
            | BagError::NotSqliteBag { file, .. }
            | BagError::Format { file, .. }
            | BagError::Row { file, .. }
            | BagError::TopicId { file, .. }
            | BagError::NegativeTime { file, .. } => file,
        }
    }
}

impl std::fmt::Display for BagError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let file = self.file();
        match self {
            BagError::NoMetadata { .. } => write!(
                f,
                "{file}: a folder without metadata.yaml is not a rosbag2 recording (name its .mcap or .db3 file instead)"
            ),
            BagError::NotARecording { .. } => write!(
                f,
                "{file}: not a recording (expected an .mcap or .db3 file or a rosbag2 folder)"
            ),
            BagError::Read { error, .. } => write!(f, "{file}: cannot read: {error}"),
            BagError::Yaml { line, col, what, .. } => write!(f, "{file}:{line}:{col}: {what}"),
            BagError::Metadata { problem, .. } => write!(f, "{file}: {problem}"),
            BagError::CorruptChunk {
                at,
                claimed,
                stored,
                ..
            } => write!(
                f,
                "{file}: the chunk at byte {at} claims {claimed} uncompressed bytes from {stored} stored ones: the file is corrupt"
            ),
            BagError::Unreadable { after, error, .. } => {
                write!(f, "{file}: unreadable after {after} message(s): {error}")
            }
            BagError::Channel { index, error, .. } => {
                write!(f, "{file}: message {index}: {error}")
            }
            BagError::NoSuchFile { .. } => write!(f, "{file}: no such file"),
            BagError::NotSqliteBag {
                table: Some(t), ..
            } => write!(f, "{file}: no table `{t}`: not a rosbag2 SQLite file"),
            BagError::NotSqliteBag { error, .. } => {
                write!(f, "{file}: not a rosbag2 SQLite file")?;
                match error {
                    Some(e) => write!(f, ": {e}"),
                    None => Ok(()),
                }
            }
            BagError::Format { topic, format, .. } => write!(
                f,
                "{file}: topic `{topic}` has serialization format `{format}`; ROS 2 recordings use `cdr`"
            ),
            BagError::Row { index, error, .. } => write!(f, "{file}: message {index}: {error}"),
            BagError::TopicId {
                index, topic_id, ..
            } => write!(
                f,
                "{file}: message {index} has topic id {topic_id}, which table `topics` does not list"
            ),
            BagError::NegativeTime {
                index, topic, time, ..
            } => write!(
                f,
                "{file}: message {index} (topic `{topic}`) has a negative timestamp {time}"
            ),
        }
    }
}

impl std::error::Error for BagError {}

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
/// (of the caller's type `E`, which holds the reader's [`BagError`]s too) stops the
/// reading.
pub type Visit<'v, E> = dyn FnMut(&[Connection], Message<'_>) -> Result<(), E> + 'v;

/// The files of a recording, in order, and how each is stored.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Recording {
    /// `(file, is MCAP)` in reading order.
    pub files: Vec<(PathBuf, bool)>,
}

impl Recording {
    /// The recording at `path`: an `.mcap` or `.db3` file, a rosbag2 folder, or its
    /// `metadata.yaml`.
    pub fn open(path: &Path) -> Result<Recording, BagError> {
        let file = path.display().to_string();
        if path.is_dir() {
            let meta = path.join("metadata.yaml");
            if !meta.is_file() {
                return Err(BagError::NoMetadata { file });
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
            _ => Err(BagError::NotARecording { file }),
        }
    }

    fn from_metadata(meta: &Path) -> Result<Recording, BagError> {
        use yaml_rust2::{Yaml, YamlLoader};
        let shown = meta.display().to_string();
        let text = std::fs::read_to_string(meta).map_err(|error| BagError::Read {
            file: shown.clone(),
            error,
        })?;
        let docs = YamlLoader::load_from_str(&text).map_err(|e| {
            let m = e.marker();
            BagError::Yaml {
                file: shown.clone(),
                line: m.line(),
                col: m.col() + 1,
                what: e.info().to_string(),
            }
        })?;
        let bad = |problem| BagError::Metadata {
            file: shown.clone(),
            problem,
        };
        let info = &docs.first().unwrap_or(&Yaml::Null)["rosbag2_bagfile_information"];
        if info.is_badvalue() {
            return Err(bad(MetadataError::NoInformation));
        }
        let storage = info["storage_identifier"].as_str().unwrap_or("");
        let dir = meta.parent().unwrap_or(Path::new("."));
        let Some(list) = info["relative_file_paths"].as_vec() else {
            return Err(bad(MetadataError::NoFiles));
        };
        let mut files = Vec::new();
        for item in list {
            let Some(rel) = item.as_str() else {
                return Err(bad(MetadataError::NonString));
            };
            let path = dir.join(rel);
            let mcap = match (storage, path.extension().and_then(|e| e.to_str())) {
                ("mcap", _) | (_, Some("mcap")) => true,
                ("sqlite3", _) | (_, Some("db3")) => false,
                _ => {
                    return Err(bad(MetadataError::Storage {
                        storage: storage.to_string(),
                        file: rel.to_string(),
                    }))
                }
            };
            files.push((path, mcap));
        }
        if files.is_empty() {
            return Err(bad(MetadataError::Empty));
        }
        Ok(Recording { files })
    }

    /// Calls `visit` with every message, in order, and the connections known so far.
    /// An error from `visit` stops the reading and is returned as is; a file that does
    /// not read is an error naming it and the messages read from it so far.
    pub fn for_each<E: From<BagError>>(&self, visit: &mut Visit<'_, E>) -> Result<(), E> {
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

fn read_mcap<E: From<BagError>>(
    file: &Path,
    conns: &mut Vec<Connection>,
    visit: &mut Visit<'_, E>,
) -> Result<(), E> {
    let shown = file.display().to_string();
    let bytes = std::fs::read(file).map_err(|error| BagError::Read {
        file: shown.clone(),
        error,
    })?;
    mcap_bytes(&bytes, &shown, conns, visit)
}

/// The messages of an MCAP file held in memory (`shown` names it in errors), as
/// [`Recording::for_each`] gives them; `conns` collects the connections.
///
/// The `mcap` crate's sans-I/O reader does the container (chunks, compression, the end
/// magic) with a record length limit (a chunk may be 4096 times the file): its convenience iterators set
/// none, and then reserve whatever length a corrupt record inside a chunk claims.
pub(crate) fn mcap_bytes<E: From<BagError>>(
    bytes: &[u8],
    shown: &str,
    conns: &mut Vec<Connection>,
    visit: &mut Visit<'_, E>,
) -> Result<(), E> {
    use mcap::records::Record;
    use mcap::sans_io::linear_reader::{LinearReadEvent, LinearReader, LinearReaderOptions};
    check_chunks(bytes, shown)?;
    let mut reader = LinearReader::new_with_options(
        LinearReaderOptions::default().with_record_length_limit(record_limit(bytes.len())),
    );
    let mut rest = bytes;
    // Schemas: id -> (name, encoding, text); channels: id -> connection (or the error to
    // give when a message uses the channel).
    let mut schemas: Vec<(u16, String, String, String)> = Vec::new();
    let mut by_channel: Vec<Option<Result<usize, ChannelError>>> = Vec::new();
    let mut channels: Vec<(u16, u16, String, String)> = Vec::new();
    let mut n = 0u64;
    while let Some(event) = reader.next_event() {
        let unreadable = |e| BagError::Unreadable {
            file: shown.to_string(),
            after: n,
            error: StorageError::Mcap(e),
        };
        let event = event.map_err(unreadable)?;
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
        let record = mcap::parse_record(opcode, data).map_err(unreadable)?;
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
                .map_err(|error| BagError::Channel {
                    file: shown.to_string(),
                    index: n,
                    error,
                })?;
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
) -> Result<usize, ChannelError> {
    let Some((_, schema_id, topic, encoding)) = channels.iter().find(|c| c.0 == id) else {
        return Err(ChannelError::Undeclared(id));
    };
    if encoding != "cdr" {
        return Err(ChannelError::Encoding {
            topic: topic.clone(),
            encoding: encoding.clone(),
        });
    }
    let (type_name, definition) = match schemas.iter().find(|s| s.0 == *schema_id) {
        Some((_, name, enc, text)) if enc == "ros2msg" => (name.clone(), Some(text.clone())),
        Some((_, name, enc, text)) if enc.is_empty() || text.is_empty() => (name.clone(), None),
        Some((_, _, enc, _)) => {
            return Err(ChannelError::SchemaEncoding {
                topic: topic.clone(),
                encoding: enc.clone(),
            })
        }
        None => {
            return Err(ChannelError::NoSchema {
                topic: topic.clone(),
            })
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
fn check_chunks(bytes: &[u8], shown: &str) -> Result<(), BagError> {
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
                return Err(BagError::CorruptChunk {
                    file: shown.to_string(),
                    at,
                    claimed,
                    stored,
                });
            }
        }
        if end > bytes.len() {
            break;
        }
        at = end;
    }
    Ok(())
}

fn read_db3<E: From<BagError>>(
    file: &Path,
    conns: &mut Vec<Connection>,
    visit: &mut Visit<'_, E>,
) -> Result<(), E> {
    use rusqlite::{Connection as Db, OpenFlags};
    let shown = file.display().to_string();
    if !file.is_file() {
        return Err(BagError::NoSuchFile { file: shown }.into());
    }
    // Before the first message: SQLite refused the file or a query of its tables.
    let sql = |e: rusqlite::Error| BagError::Unreadable {
        file: shown.clone(),
        after: 0,
        error: StorageError::Sqlite(e),
    };
    let db = Db::open_with_flags(file, OpenFlags::SQLITE_OPEN_READ_ONLY).map_err(sql)?;
    let tables: Vec<String> = db
        .prepare("SELECT name FROM sqlite_master WHERE type = 'table'")
        .and_then(|mut s| {
            s.query_map([], |r| r.get::<_, String>(0))?
                .collect::<Result<Vec<_>, _>>()
        })
        .map_err(|e| BagError::NotSqliteBag {
            file: shown.clone(),
            table: None,
            error: Some(e),
        })?;
    for t in ["topics", "messages"] {
        if !tables.iter().any(|x| x == t) {
            return Err(BagError::NotSqliteBag {
                file: shown.clone(),
                table: Some(t),
                error: None,
            }
            .into());
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
                return Err(BagError::Format {
                    file: shown.clone(),
                    topic,
                    format,
                }
                .into());
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
            Err(e) => {
                return Err(BagError::Unreadable {
                    file: shown.clone(),
                    after: n,
                    error: StorageError::Sqlite(e),
                }
                .into())
            }
        };
        n += 1;
        let bad = |error| BagError::Row {
            file: shown.clone(),
            index: n,
            error,
        };
        let topic_id: i64 = row.get(0).map_err(|e| bad(StorageError::Sqlite(e)))?;
        let time: i64 = row.get(1).map_err(|e| bad(StorageError::Sqlite(e)))?;
        let data = row
            .get_ref(2)
            .map_err(|e| bad(StorageError::Sqlite(e)))?
            .as_blob()
            .map_err(|e| bad(StorageError::Column(e)))?;
        let Some(&(_, conn)) = by_id.iter().find(|(id, _)| *id == topic_id) else {
            return Err(BagError::TopicId {
                file: shown.clone(),
                index: n,
                topic_id,
            }
            .into());
        };
        let Ok(log_time) = u64::try_from(time) else {
            return Err(BagError::NegativeTime {
                file: shown.clone(),
                index: n,
                topic: conns[conn].topic.clone(),
                time,
            }
            .into());
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
