//! Writing a ROS 2 recording: an MCAP file in the ROS 2 profile (`ros2msg` schemas,
//! `cdr` messages), as `ros2 bag record` writes one. `hindsight monitor --ros2 --record`
//! keeps what it received this way, so `hindsight replay`, the `mcap` tools and the
//! rosbag2 readers read it back.

use std::collections::BTreeMap;
use std::io::BufWriter;
use std::path::Path;

/// Why an MCAP file could not be written: the file and what failed.
#[derive(Debug)]
pub enum WriteError {
    /// The file could not be created.
    Create {
        /// The file.
        path: String,
        /// Why.
        error: std::io::Error,
    },
    /// The MCAP writer failed (a write, the summary).
    Mcap {
        /// The file.
        path: String,
        /// Why.
        error: mcap::McapError,
    },
}

impl std::fmt::Display for WriteError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            WriteError::Create { path, error } => write!(f, "{path}: cannot write: {error}"),
            WriteError::Mcap { path, error } => write!(f, "{path}: {error}"),
        }
    }
}

impl std::error::Error for WriteError {}

/// An MCAP file being written.
pub struct McapWriter {
    writer: mcap::Writer<BufWriter<std::fs::File>>,
    path: String,
}

impl McapWriter {
    /// Creates (or truncates) `path`.
    pub fn create(path: &Path) -> Result<McapWriter, WriteError> {
        let shown = path.display().to_string();
        let f = std::fs::File::create(path).map_err(|error| WriteError::Create {
            path: shown.clone(),
            error,
        })?;
        let writer = mcap::WriteOptions::new()
            .profile("ros2")
            .library("hindsight")
            .create(BufWriter::new(f))
            .map_err(|error| WriteError::Mcap {
                path: shown.clone(),
                error,
            })?;
        Ok(McapWriter {
            writer,
            path: shown,
        })
    }

    fn err(&self, error: mcap::McapError) -> WriteError {
        WriteError::Mcap {
            path: self.path.clone(),
            error,
        }
    }

    /// Adds topic `topic` of ROS type `type_name` (`std_msgs/msg/Int32`) defined by
    /// `ros2msg` (see [`crate::schema::Schema::ros2msg_text`]); returns its channel.
    pub fn add_topic(
        &mut self,
        topic: &str,
        type_name: &str,
        ros2msg: &str,
    ) -> Result<u16, WriteError> {
        let schema = self
            .writer
            .add_schema(type_name, "ros2msg", ros2msg.as_bytes())
            .map_err(|e| self.err(e))?;
        self.writer
            .add_channel(schema, topic, "cdr", &BTreeMap::new())
            .map_err(|e| self.err(e))
    }

    /// Writes one message (its CDR bytes with their 4-byte header) received at
    /// `log_time` nanoseconds since the Unix epoch.
    pub fn write(
        &mut self,
        channel: u16,
        sequence: u32,
        log_time: u64,
        data: &[u8],
    ) -> Result<(), WriteError> {
        let header = mcap::records::MessageHeader {
            channel_id: channel,
            sequence,
            log_time,
            publish_time: log_time,
        };
        self.writer
            .write_to_known_channel(&header, data)
            .map_err(|e| self.err(e))
    }

    /// Writes the summary and flushes: the file is complete.
    pub fn finish(mut self) -> Result<(), WriteError> {
        self.writer.finish().map_err(|e| self.err(e))?;
        Ok(())
    }
}
