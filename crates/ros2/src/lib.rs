//! hindsight's ROS 2 layer: interface definitions (`.msg` / `.srv` / `.action`, and the
//! standard packages built in), the CDR reader and writer (`cdr`, `cdr_write`), and rosbag2 recordings (MCAP files and
//! SQLite `.db3` files, alone or as a folder with `metadata.yaml`), and live topics over
//! DDS (module `dds`, cargo feature `dds`).
//!
//! The pipeline from a recording to a monitor's input:
//!
//! ```text
//! bag::Recording (MCAP / .db3 / folder)  --one message at a time-->  (connection, time, bytes)
//!      |  connection's type: schema::Schema (embedded ros2msg text, or interface packages)
//!      v
//! cdr::Decoder (only the fields a property reads, each into a slot)  -->  feed::Feed points
//! ```
//!
//! This crate does not depend on `hindsight` (the binary's crate depends on it); it uses
//! only `codegen`'s source map and scalar names and `monitor-core`'s values.

// `pub` only where another crate can reach it: internals are `pub(crate)` (issue 27).
#![warn(unreachable_pub)]

pub mod bag;
pub mod cdr;
pub mod cdr_write;
#[cfg(feature = "dds")]
pub mod dds;
pub mod feed;
pub mod interface;
pub mod schema;
pub mod write;
