//! A replay trace as bytes, read point by point without allocating: what `monitor-table` replays.
//!
//! Format (postcard encoding throughout): a header `(points: u32, vars: u16)`,
//! then `points` records, each a timestamp `u64` followed by `vars`
//! [`Value`]s in the program's variable order. [`encode`] writes it (feature
//! `encode`); [`Reader`] reads it back, checking the variable count against the
//! program and never panicking on corrupt bytes.

use core::fmt;

use monitor_core::Value;

/// Why trace bytes could not be read.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum TraceError {
    /// The bytes are truncated or not in this format.
    Decode {
        /// Index of the point being read (the header is point 0 too).
        point: u32,
    },
    /// The trace has values for a different number of variables than the program.
    VarCount {
        /// Variables the program declares.
        expected: usize,
        /// Variables per point in the trace.
        found: u16,
    },
    /// Bytes remain after the last point.
    Trailing,
}

impl fmt::Display for TraceError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            TraceError::Decode { point } => write!(f, "trace point {point}: corrupt or truncated"),
            TraceError::VarCount { expected, found } => {
                write!(
                    f,
                    "trace has {found} variables per point, the program {expected}"
                )
            }
            TraceError::Trailing => write!(f, "bytes after the trace's last point"),
        }
    }
}

impl core::error::Error for TraceError {}

/// Reads a trace point by point, borrowing the bytes.
#[derive(Clone, Debug)]
pub struct Reader<'a> {
    rest: &'a [u8],
    points: u32,
    next: u32,
    vars: u16,
}

impl<'a> Reader<'a> {
    /// Reads the header; `vars` is the program's variable count, which every point must match.
    pub fn new(bytes: &'a [u8], vars: usize) -> Result<Self, TraceError> {
        let err = TraceError::Decode { point: 0 };
        let ((points, found), rest) =
            postcard::take_from_bytes::<(u32, u16)>(bytes).map_err(|_| err)?;
        if found as usize != vars {
            return Err(TraceError::VarCount {
                expected: vars,
                found,
            });
        }
        Ok(Reader {
            rest,
            points,
            next: 0,
            vars: found,
        })
    }

    /// Number of points the header announces.
    pub fn points(&self) -> u32 {
        self.points
    }

    /// Reads the next point's values into `values` (at least `vars` long) and
    /// returns its timestamp, or `None` after the last point.
    pub fn next_point(&mut self, values: &mut [Value]) -> Result<Option<u64>, TraceError> {
        let err = TraceError::Decode { point: self.next };
        if self.next == self.points {
            return if self.rest.is_empty() {
                Ok(None)
            } else {
                Err(TraceError::Trailing)
            };
        }
        let Some(values) = values.get_mut(..self.vars as usize) else {
            return Err(TraceError::VarCount {
                expected: values.len(),
                found: self.vars,
            });
        };
        let (time, mut rest) = postcard::take_from_bytes::<u64>(self.rest).map_err(|_| err)?;
        for v in values.iter_mut() {
            let (value, r) = postcard::take_from_bytes::<Value>(rest).map_err(|_| err)?;
            *v = value;
            rest = r;
        }
        self.rest = rest;
        self.next += 1;
        Ok(Some(time))
    }
}

/// Encodes points `(time, values)` in this format; every point must have as
/// many values as the first.
#[cfg(feature = "encode")]
pub fn encode<'v>(
    points: impl ExactSizeIterator<Item = (u64, &'v [Value])>,
) -> Result<alloc::vec::Vec<u8>, TraceError> {
    let mut points = points.peekable();
    let vars = points.peek().map_or(0, |(_, v)| v.len());
    let too_many = TraceError::VarCount {
        expected: vars,
        found: u16::MAX,
    };
    let header = (
        u32::try_from(points.len()).map_err(|_| TraceError::Decode { point: u32::MAX })?,
        u16::try_from(vars).map_err(|_| too_many)?,
    );
    let encode_err = |point| move |_| TraceError::Decode { point };
    let mut out = postcard::to_allocvec(&header).map_err(encode_err(0))?;
    for (i, (time, values)) in points.enumerate() {
        if values.len() != vars {
            return Err(TraceError::VarCount {
                expected: vars,
                found: u16::try_from(values.len()).unwrap_or(u16::MAX),
            });
        }
        let point = i as u32;
        out = postcard::to_extend(&time, out).map_err(encode_err(point))?;
        for v in values {
            out = postcard::to_extend(v, out).map_err(encode_err(point))?;
        }
    }
    Ok(out)
}
