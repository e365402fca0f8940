//! Reading source files: the one reader of every text file the project parses
//! ([`read_source`]), refusing what is not a regular file before opening it
//! ([`not_a_source_file`]) and locating the first byte that is not UTF-8.

use std::path::Path;

use super::{Diagnostic, LineIndex};

/// Why `path` cannot be read as a source file, or `None` when it is a regular file
/// (symbolic links followed): `not found`, `is a directory, not a file`, `is a FIFO
/// (named pipe), not a regular file`, ... Decided from the file's metadata, before
/// opening it, so a FIFO never blocks the reader and a device is never read.
pub fn not_a_source_file(path: &Path) -> Option<String> {
    match std::fs::metadata(path) {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Some("not found".into()),
        Err(e) => Some(format!("cannot read: {e}")),
        Ok(m) if m.is_file() => None,
        Ok(m) if m.is_dir() => Some("is a directory, not a file".into()),
        Ok(m) => Some(format!("is {}, not a regular file", special_kind(&m))),
    }
}

#[cfg(unix)]
fn special_kind(m: &std::fs::Metadata) -> &'static str {
    use std::os::unix::fs::FileTypeExt;
    let t = m.file_type();
    if t.is_fifo() {
        "a FIFO (named pipe)"
    } else if t.is_char_device() {
        "a character device"
    } else if t.is_block_device() {
        "a block device"
    } else if t.is_socket() {
        "a socket"
    } else {
        "a special file"
    }
}

#[cfg(not(unix))]
fn special_kind(_: &std::fs::Metadata) -> &'static str {
    "a special file"
}

/// Reads the source file at `path` as UTF-8 text: the one reader of every text file
/// the project parses (models, robot models and their inputs, property files, specs,
/// traces, ROS interfaces). A file that is not a regular file is refused before it is
/// opened ([`not_a_source_file`]); a UTF-8 byte order mark is dropped (editors on
/// Windows write one); a byte that is not UTF-8 is an error at its line and column
/// (counted in characters, as every position), saying which byte. The error is about
/// the file and shows none of its text.
pub fn read_source(path: &Path) -> Result<String, Diagnostic> {
    let name = || path.display().to_string();
    if let Some(why) = not_a_source_file(path) {
        return Err(Diagnostic::about_file(name(), why));
    }
    let bytes = std::fs::read(path)
        .map_err(|e| Diagnostic::about_file(name(), format!("cannot read: {e}")))?;
    decode_source(bytes).map_err(|(at, message)| Diagnostic::error(name(), at, message))
}

/// `bytes` as text, without a leading UTF-8 byte order mark; `Err` gives the line and
/// column of the first byte that is not UTF-8, and what is wrong.
fn decode_source(mut bytes: Vec<u8>) -> Result<String, ((u32, u32), String)> {
    if bytes.starts_with(b"\xEF\xBB\xBF") {
        bytes.drain(..3);
    }
    String::from_utf8(bytes).map_err(|e| {
        let bytes = e.as_bytes();
        let valid = e.utf8_error().valid_up_to();
        let prefix = std::str::from_utf8(&bytes[..valid]).unwrap_or_default();
        let at = LineIndex::new(prefix).line_col(prefix, valid);
        let why = match e.utf8_error().error_len() {
            Some(_) => format!(
                "not UTF-8 text: byte 0x{:02X} does not belong here (save the file as UTF-8)",
                bytes[valid]
            ),
            None => {
                "not UTF-8 text: the file ends inside a character (save it as UTF-8)".to_owned()
            }
        };
        (at, why)
    })
}
