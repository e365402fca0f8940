//! Source positions for property files: [`Location`] (line, column), the file as the one
//! [`SourceMap`] holds it, and [`SourceText`], a piece of text (formula, initial value)
//! that maps each of its offsets back to where it came from in the file. Lines, columns,
//! carets and the position map are codegen's ([`codegen::diag`]), the one source
//! foundation every reader positions through.

use std::fmt;
use std::path::Path;

use codegen::diag::{locate_in_runs, FileId, PositionRun, Snippet, SourceMap};

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

/// A property file's text in the project's one [`SourceMap`] (as its only source,
/// [`FileId`] 0, the id the XML tree's spans carry): byte offsets become [`Location`]s
/// and locations carets through the map, as for every other reader.
#[derive(Clone, Debug)]
pub(crate) struct SourceFile<'a> {
    text: &'a str,
    map: SourceMap,
    id: FileId,
}

impl<'a> SourceFile<'a> {
    pub(crate) fn new(path: &Path, text: &'a str) -> SourceFile<'a> {
        let mut map = SourceMap::new();
        let id = map.add(path, text.to_owned());
        SourceFile { text, map, id }
    }

    /// The location of byte `offset` (clamped to the text; a position inside a multi-byte
    /// character counts as that character).
    pub(crate) fn location(&self, offset: usize) -> Location {
        let offset = u32::try_from(offset).unwrap_or(u32::MAX);
        let at = self.map.locate(self.id.at(offset));
        Location::new(at.line, at.col)
    }

    /// The source line and caret of location `at`.
    pub(crate) fn snippet(&self, at: Location) -> Snippet {
        self.map.snippet_at(self.id, at.line, at.column)
    }

    /// The file's text.
    pub(crate) fn text(&self) -> &'a str {
        self.text
    }
}

/// Text taken from (or generated from) a file, that maps each byte offset back to a
/// [`Location`] in the file, for error messages: the text and its position map
/// ([`PositionRun`]s), the map codegen reads a formula's positions from.
///
/// Invariant: runs are sorted by offset and the first starts at 0 (unless the text
/// is empty).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SourceText {
    text: String,
    runs: Vec<PositionRun>,
}

fn run(offset: usize, at: Location, exact: bool) -> PositionRun {
    PositionRun {
        offset: u32::try_from(offset).unwrap_or(u32::MAX),
        line: at.line,
        col: at.column,
        exact,
    }
}

fn run_location(run: &PositionRun) -> Location {
    Location::new(run.line, run.col)
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
            runs: Vec::new(),
        }
    }

    /// The text.
    pub fn as_str(&self) -> &str {
        &self.text
    }

    /// The file location of the character at byte `offset` of the text (offsets past the
    /// end map to just after the last character).
    pub fn location(&self, offset: usize) -> Location {
        match locate_in_runs(&self.text, &self.runs, offset) {
            Some((line, column)) => Location::new(line, column),
            None => Location::new(1, 1),
        }
    }

    /// The position map: where each run of the text starts (byte offset), its location
    /// in the file, and whether it is copied character for character (`exact`) or
    /// generated from the element at that location.
    pub fn runs(&self) -> &[PositionRun] {
        &self.runs
    }

    /// The part of the text between byte offsets `start` and `end` (char boundaries),
    /// keeping its locations.
    pub(crate) fn slice(&self, start: usize, end: usize) -> SourceText {
        let end = end.min(self.text.len());
        let start = start.min(end);
        let mut out = SourceText {
            text: self.text[start..end].to_owned(),
            runs: Vec::new(),
        };
        for (i, r) in self.runs.iter().enumerate() {
            let run_end = self
                .runs
                .get(i + 1)
                .map_or(self.text.len(), |next| next.offset as usize);
            let offset = r.offset as usize;
            if run_end <= start || offset >= end {
                continue;
            }
            let from = offset.max(start);
            let at = if r.exact {
                self.location(from)
            } else {
                run_location(r)
            };
            out.runs.push(run(from - start, at, r.exact));
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
        let base = u32::try_from(self.text.len()).unwrap_or(u32::MAX);
        self.text.push_str(&other.text);
        self.runs.extend(other.runs.iter().map(|r| PositionRun {
            offset: r.offset.saturating_add(base),
            ..*r
        }));
    }

    fn push(&mut self, text: &str, at: Location, exact: bool) {
        if text.is_empty() {
            return;
        }
        // Merge with the previous run when it simply continues it.
        let continues = self.runs.last().is_some_and(|last| {
            exact
                && last.exact
                && last.line == at.line
                && self
                    .text
                    .get(last.offset as usize..)
                    .map_or(0, |t| t.chars().count()) as u64
                    + u64::from(last.col)
                    == u64::from(at.column)
        });
        if !continues {
            self.runs.push(run(self.text.len(), at, exact));
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
/// reference, returns its byte offset in the file and what is wrong with it.
pub(crate) fn unescape_attribute(
    raw: &str,
    offset: usize,
    lines: &SourceFile<'_>,
) -> Result<SourceText, (usize, crate::model::source::BadReference)> {
    let mut out = SourceText::empty();
    let mut rest = raw;
    let mut at = offset;
    while !rest.is_empty() {
        if let Some(decoded) = crate::model::source::reference(rest) {
            let (decoded, consumed) = decoded.map_err(|e| (at, e))?;
            let mut buffer = [0u8; 4];
            out.push_exact(decoded.encode_utf8(&mut buffer), lines.location(at));
            rest = &rest[consumed..];
            at += consumed;
            continue;
        }
        // A tab or line break is one space (`\r\n` one): the model reader's rule.
        if let Some(consumed) = crate::model::source::normalised_space(rest) {
            out.push_exact(" ", lines.location(at));
            rest = &rest[consumed..];
            at += consumed;
            continue;
        }
        // A run up to the next reference, tab or line break, copied as it is.
        let run = rest
            .find(crate::model::source::ATTR_SPECIAL)
            .unwrap_or(rest.len());
        out.push_exact(&rest[..run], lines.location(at));
        rest = &rest[run..];
        at += run;
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn attribute_line_breaks_become_one_space_each_and_keep_their_positions() {
        let file = "<p formula=\"{a}\r\n  S {b}\tor\n{c}&#10;\"/>";
        let start = file.find('{').unwrap();
        let raw = &file[start..file.rfind('"').unwrap()];
        let lines = SourceFile::new(Path::new("p.xml"), file);
        let out = unescape_attribute(raw, start, &lines).unwrap();
        // `\r\n` is one line break: one space, not two; `&#10;` stays a line break.
        assert_eq!(out.as_str(), "{a}   S {b} or {c}\n");
        let at = |needle: &str| out.location(out.as_str().find(needle).unwrap());
        assert_eq!(at("{a}"), Location::new(1, 13));
        assert_eq!(at("S {b}"), Location::new(2, 3));
        assert_eq!(at("{c}"), Location::new(3, 1));
    }
}
