//! Source positions for property files: [`Location`] (line, column), a line index over a
//! file's text, and [`SourceText`], a piece of text (formula, initial value) that maps
//! each of its offsets back to where it came from in the file.

use std::fmt;

/// A position in a file: 1-based line and column, columns counted in characters.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Location {
    /// Line, from 1.
    pub line: u32,
    /// Column, from 1, in Unicode scalar values (a tab counts as one).
    pub column: u32,
}

impl Location {
    /// A location.
    pub const fn new(line: u32, column: u32) -> Location {
        Location { line, column }
    }
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}:{}", self.line, self.column)
    }
}

/// Byte offsets of line starts, to turn byte offsets into [`Location`]s.
#[derive(Clone, Debug)]
pub(crate) struct LineIndex<'a> {
    text: &'a str,
    starts: Vec<usize>,
}

impl<'a> LineIndex<'a> {
    pub(crate) fn new(text: &'a str) -> LineIndex<'a> {
        let mut starts = vec![0];
        starts.extend(text.match_indices('\n').map(|(i, _)| i + 1));
        LineIndex { text, starts }
    }

    /// The location of byte `offset` (clamped to the text; a position inside a multi-byte
    /// character counts as that character).
    pub(crate) fn location(&self, offset: usize) -> Location {
        let offset = offset.min(self.text.len());
        let line = self.starts.partition_point(|&start| start <= offset) - 1;
        let start = self.starts[line];
        let column = self.text.as_bytes()[start..offset]
            .iter()
            .filter(|&&b| (b as i8) >= -0x40)
            .count();
        Location::new(
            u32::try_from(line + 1).unwrap_or(u32::MAX),
            u32::try_from(column + 1).unwrap_or(u32::MAX),
        )
    }

    /// The byte offset of `slice` in the indexed text, if it is a sub-slice of it.
    pub(crate) fn offset_of(&self, slice: &[u8]) -> Option<usize> {
        let base = self.text.as_ptr() as usize;
        let at = slice.as_ptr() as usize;
        (at >= base && at + slice.len() <= base + self.text.len()).then(|| at - base)
    }
}

/// Where a run of a [`SourceText`] comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Segment {
    /// Byte offset in the text where the run starts.
    offset: usize,
    /// Location of the run's first character in the file.
    at: Location,
    /// Whether the run is copied from the file character for character on one line (its
    /// columns advance with the text); otherwise it was generated from the element at
    /// `at`, and every offset in it maps to `at`.
    exact: bool,
}

/// Text taken from (or generated from) a file, that maps each byte offset back to a
/// [`Location`] in the file, for error messages.
///
/// Invariant: segments are sorted by offset and the first starts at 0 (unless the text
/// is empty).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SourceText {
    text: String,
    segments: Vec<Segment>,
}

impl SourceText {
    /// Generated text with no file behind it: every offset maps to `at`.
    pub fn generated(text: impl Into<String>, at: Location) -> SourceText {
        let mut source = SourceText::empty();
        source.push_generated(&text.into(), at);
        source
    }

    pub(crate) fn empty() -> SourceText {
        SourceText {
            text: String::new(),
            segments: Vec::new(),
        }
    }

    /// The text.
    pub fn as_str(&self) -> &str {
        &self.text
    }

    /// The file location of the character at byte `offset` of the text (offsets past the
    /// end map to just after the last character).
    pub fn location(&self, offset: usize) -> Location {
        let index = self.segments.partition_point(|s| s.offset <= offset);
        let Some(segment) = index.checked_sub(1).map(|i| self.segments[i]) else {
            return self.segments.first().map_or(Location::new(1, 1), |s| s.at);
        };
        if !segment.exact {
            return segment.at;
        }
        let end = offset.min(self.text.len());
        let chars = self.text.as_bytes()[segment.offset.min(end)..end]
            .iter()
            .filter(|&&b| (b as i8) >= -0x40)
            .count();
        Location::new(
            segment.at.line,
            segment
                .at
                .column
                .saturating_add(u32::try_from(chars).unwrap_or(u32::MAX)),
        )
    }

    /// The position map: where each run of the text starts (byte offset), its location
    /// in the file, and whether it is copied character for character (`true`) or
    /// generated from the element at that location (`false`).
    pub fn runs(&self) -> impl Iterator<Item = (usize, Location, bool)> + '_ {
        self.segments.iter().map(|s| (s.offset, s.at, s.exact))
    }

    /// The part of the text between byte offsets `start` and `end` (char boundaries),
    /// keeping its locations.
    pub(crate) fn slice(&self, start: usize, end: usize) -> SourceText {
        let end = end.min(self.text.len());
        let start = start.min(end);
        let mut out = SourceText {
            text: self.text[start..end].to_owned(),
            segments: Vec::new(),
        };
        for (i, segment) in self.segments.iter().enumerate() {
            let segment_end = self
                .segments
                .get(i + 1)
                .map_or(self.text.len(), |next| next.offset);
            if segment_end <= start || segment.offset >= end {
                continue;
            }
            let from = segment.offset.max(start);
            out.segments.push(Segment {
                offset: from - start,
                at: if segment.exact {
                    self.location(from)
                } else {
                    segment.at
                },
                exact: segment.exact,
            });
        }
        out
    }

    /// Appends text copied from the file, starting at `at`, on one line.
    pub(crate) fn push_exact(&mut self, text: &str, at: Location) {
        self.push(text, at, true);
    }

    /// Appends text generated from the element at `at`.
    pub(crate) fn push_generated(&mut self, text: &str, at: Location) {
        self.push(text, at, false);
    }

    /// Appends another source text, keeping its locations.
    pub(crate) fn push_source(&mut self, other: &SourceText) {
        let base = self.text.len();
        self.text.push_str(&other.text);
        self.segments.extend(other.segments.iter().map(|s| Segment {
            offset: s.offset + base,
            ..*s
        }));
    }

    fn push(&mut self, text: &str, at: Location, exact: bool) {
        if text.is_empty() {
            return;
        }
        let segment = Segment {
            offset: self.text.len(),
            at,
            exact,
        };
        // Merge with the previous segment when it simply continues it.
        let continues = self.segments.last().is_some_and(|last| {
            exact
                && last.exact
                && last.at.line == at.line
                && self.text[last.offset..].chars().count() as u64 + u64::from(last.at.column)
                    == u64::from(at.column)
        });
        if !continues {
            self.segments.push(segment);
        }
        self.text.push_str(text);
    }
}

impl fmt::Display for SourceText {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.text)
    }
}

/// Unescapes an attribute value (`raw` starts at byte `offset` of the file) into a
/// [`SourceText`]: predefined entities and character references are replaced, and tabs
/// and line breaks become spaces (XML attribute-value normalisation). On a bad
/// reference, returns its byte offset in the file and a description.
pub(crate) fn unescape_attribute(
    raw: &str,
    offset: usize,
    lines: &LineIndex<'_>,
) -> Result<SourceText, (usize, String)> {
    let mut out = SourceText::empty();
    let mut rest = raw;
    let mut at = offset;
    while !rest.is_empty() {
        if let Some(after) = rest.strip_prefix('&') {
            let end = after.find(';').filter(|&end| end <= 12).ok_or_else(|| {
                (
                    at,
                    "`&` that does not start a reference (write `&amp;`)".to_owned(),
                )
            })?;
            let name = &after[..end];
            let decoded = crate::model::source::resolve_entity(name);
            let decoded = decoded.ok_or_else(|| (at, format!("unknown reference `&{name};`")))?;
            let mut buffer = [0u8; 4];
            out.push_exact(decoded.encode_utf8(&mut buffer), lines.location(at));
            let consumed = end + 2;
            rest = &rest[consumed..];
            at += consumed;
            continue;
        }
        // A run up to the next reference or line break.
        let run = rest.find(['&', '\n']).map_or(rest.len(), |i| {
            if rest.as_bytes()[i] == b'\n' {
                i + 1
            } else {
                i
            }
        });
        let chunk = &rest[..run];
        let normalised: String = chunk
            .chars()
            .map(|c| {
                if matches!(c, '\t' | '\n' | '\r') {
                    ' '
                } else {
                    c
                }
            })
            .collect();
        out.push_exact(&normalised, lines.location(at));
        rest = &rest[run..];
        at += run;
    }
    Ok(out)
}
