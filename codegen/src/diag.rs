//! Diagnostics of every reader in the project: positions in source text and one rendering, `file:line:col: message` with the source line and a caret.
//!
//! This module is the source foundation that the host's readers (models, robot
//! models, property files) share with the formula compiler, so positions are
//! computed and problems are printed in one place:
//!
//! - a [`SourceMap`] holds every text that positions point into, each a [`Source`]
//!   with its file: a whole file a reader read (a model's SCXML, a `.msg`, a
//!   `.hspec`) or a piece of text placed inside a file (a formula from an XML
//!   attribute, at the [`crate::Origin`] of its first character). A [`Span`] is a
//!   byte range in one source ([`FileId`]); [`Source::line_col`] is the one way a
//!   byte offset becomes the file's line and column;
//! - [`LineIndex`] turns a byte offset of a text into a 1-based line and a column
//!   counted in characters, and gives the line's text for the caret;
//! - [`PositionRun`]s map text that is not a verbatim copy of its file (a formula
//!   after XML entities, one generated from a tree of elements) back to the file
//!   ([`locate_in_runs`]);
//! - [`Diagnostic`] is one located problem, its payload a message or a structured
//!   kind (the property reader's), rendered the same way whatever the payload;
//!   [`Diagnostics`] collects them in the order found.
//!
//! Spans are 12 bytes; a line and column are computed only when a diagnostic is
//! made. Inside the compiler every parsed node keeps a span; passes collect problems
//! instead of stopping at the first one and hand back [`Diagnostics`]: located,
//! already rendered, independent of the sources.

use std::fmt;
use std::path::{Path, PathBuf};

/// A byte range `lo..hi` in source number `source` (a [`FileId`]) of a [`SourceMap`]:
/// the one span type of the project.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub struct Span {
    /// Index of the source in its [`SourceMap`].
    pub source: u32,
    /// First byte.
    pub lo: u32,
    /// One past the last byte (`lo == hi` for an empty span, e.g. at the end of input).
    pub hi: u32,
}

impl Span {
    /// The empty span at byte `offset` of source (file) `source`: a position.
    pub fn at(source: u32, offset: u32) -> Span {
        Span {
            source,
            lo: offset,
            hi: offset,
        }
    }

    /// The span `delta` bytes further in the same source, same length.
    pub fn shifted(self, delta: u32) -> Span {
        Span {
            source: self.source,
            lo: self.lo.saturating_add(delta),
            hi: self.hi.saturating_add(delta),
        }
    }

    /// The smallest span covering `self` and `other` (same source assumed).
    pub fn to(self, other: Span) -> Span {
        Span {
            source: self.source,
            lo: self.lo.min(other.lo),
            hi: self.hi.max(other.hi),
        }
    }
}

/// A resolved position: file name, 1-based line and 1-based column (in characters).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Location {
    /// File name as given to the parser.
    pub file: String,
    /// 1-based line (0 for a span whose source is not in the map).
    pub line: u32,
    /// 1-based column, counted in characters (0 when `line` is).
    pub col: u32,
}

/// Where a run of a source's text comes from in its file: the map that keeps every
/// column right when text was unescaped (`&lt;` became `<`) or generated from elements.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PositionRun {
    /// Byte offset in the text where the run starts.
    pub offset: u32,
    /// 1-based line of the run's first character in the file.
    pub line: u32,
    /// 1-based column (in characters) of the run's first character in the file.
    pub col: u32,
    /// `true` when the run is copied character for character from one line of the file
    /// (its columns advance with the text); `false` when it was generated from the
    /// element at `line`:`col`, so every offset in it resolves there.
    pub exact: bool,
}

/// Index of a source in a [`SourceMap`] (a span's `source`): in `host` a file the
/// model reader read, in the compiler a `.hspec` file or a piece of one.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct FileId(pub u32);

impl FileId {
    /// The source that `span` is in.
    pub fn of(span: Span) -> FileId {
        FileId(span.source)
    }

    /// The empty span at byte `offset` of this source.
    pub fn at(self, offset: u32) -> Span {
        Span::at(self.0, offset)
    }
}

/// One text that spans point into, and where it is in its file: either a whole file
/// (its first character at line 1, column 1) or a piece of text placed somewhere
/// inside a file, such as a formula taken from an XML attribute.
#[derive(Clone, Debug)]
pub struct Source {
    path: PathBuf,
    text: String,
    /// Where lines start in `text`: line and column inside the text, in O(log lines).
    lines: LineIndex,
    place: Place,
}

/// Where a source's text sits in its file.
#[derive(Clone, Debug)]
struct Place {
    /// 1-based line and column of the text's first character.
    line: u32,
    col: u32,
    /// `false` for text synthesised from structured input: every position in it
    /// resolves to `line`:`col`, since its columns do not exist in the file.
    exact: bool,
    /// A position map, when the text is not a verbatim copy of the file from
    /// `line`:`col` on (a formula after XML entities, or one generated from a tree):
    /// sorted by offset, the first at 0. Empty: count forward from `line`:`col`.
    runs: Vec<PositionRun>,
}

impl Place {
    /// A whole file.
    const WHOLE: Place = Place {
        line: 1,
        col: 1,
        exact: true,
        runs: Vec::new(),
    };
}

impl Source {
    /// The file the text is (in), as given to the reader.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The source's text.
    pub fn text(&self) -> &str {
        &self.text
    }

    /// 1-based line and column (in characters) in the file of byte `offset` of the
    /// text, clamped to it; an offset inside a multi-byte character counts as that
    /// character. The one way a position is computed, for files and pieces alike.
    pub fn line_col(&self, offset: u32) -> (u32, u32) {
        let text = self.text.as_str();
        let at = floor_boundary(text, offset as usize);
        let place = &self.place;
        if let Some(mapped) = locate_in_runs(text, &place.runs, at) {
            return mapped;
        }
        if !place.exact {
            return (place.line, place.col);
        }
        let (line, col) = self.lines.line_col(text, at);
        if line == 1 {
            (place.line, place.col.saturating_add(col - 1))
        } else {
            (place.line.saturating_add(line - 1), col)
        }
    }
}

/// The texts that spans point into, with where each is in its file: every file a
/// reader read, and every piece of text the compiler parsed.
#[derive(Clone, Debug, Default)]
pub struct SourceMap {
    sources: Vec<Source>,
}

impl SourceMap {
    /// An empty map.
    pub fn new() -> Self {
        Self::default()
    }

    fn push(&mut self, path: PathBuf, text: String, place: Place) -> FileId {
        self.sources.push(Source {
            path,
            lines: LineIndex::new(&text),
            text,
            place,
        });
        FileId(u32::try_from(self.sources.len() - 1).unwrap_or(u32::MAX))
    }

    /// Adds the whole text of the file at `path` and returns its id.
    pub fn add(&mut self, path: impl Into<PathBuf>, text: String) -> FileId {
        self.push(path.into(), text, Place::WHOLE)
    }

    /// Adds a piece of text whose first character is at `line`:`col` of file `name`.
    /// `exact == false` marks synthesised text (every position in it is `line`:`col`).
    pub(crate) fn add_piece(
        &mut self,
        name: &str,
        text: &str,
        line: u32,
        col: u32,
        exact: bool,
    ) -> u32 {
        let place = Place {
            line: line.max(1),
            col: col.max(1),
            exact,
            runs: Vec::new(),
        };
        self.push(name.into(), text.to_string(), place).0
    }

    /// Adds a piece whose positions come from the map `runs` (see [`PositionRun`]);
    /// with no runs, it starts at `line`:`col` like [`SourceMap::add_piece`].
    pub(crate) fn add_mapped(
        &mut self,
        name: &str,
        text: &str,
        (line, col): (u32, u32),
        runs: &[PositionRun],
    ) -> u32 {
        let mut runs = runs.to_vec();
        runs.sort_by_key(|r| r.offset);
        let place = Place {
            line: line.max(1),
            col: col.max(1),
            exact: true,
            runs,
        };
        self.push(name.into(), text.to_string(), place).0
    }

    /// The source with this id.
    pub fn source(&self, id: FileId) -> Option<&Source> {
        self.sources.get(id.0 as usize)
    }

    /// All sources, in the order they were added.
    pub fn sources(&self) -> &[Source] {
        &self.sources
    }

    /// The text of source `id`.
    pub fn text(&self, id: u32) -> Option<&str> {
        self.source(FileId(id)).map(Source::text)
    }

    /// The source text a span covers (empty for a span that does not resolve).
    pub fn slice(&self, span: Span) -> &str {
        self.text(span.source)
            .and_then(|t| t.get(span.lo as usize..span.hi as usize))
            .unwrap_or("")
    }

    /// File, line and column of the start of `span` (line and column 0 when its
    /// source is not in the map).
    pub fn locate(&self, span: Span) -> Location {
        match self.source(FileId::of(span)) {
            Some(src) => {
                let (line, col) = src.line_col(span.lo);
                Location {
                    file: src.path.display().to_string(),
                    line,
                    col,
                }
            }
            None => Location {
                file: UNKNOWN.into(),
                line: 0,
                col: 0,
            },
        }
    }

    /// The source line of `line`:`col` (1-based, in characters) of the whole file `id`
    /// and a caret under that column, for a problem found as a position rather than a
    /// span (empty when the file or line is not there).
    pub fn snippet_at(&self, id: FileId, line: u32, col: u32) -> Snippet {
        match self.source(id) {
            Some(src) => Snippet::at_line_col(&src.text, &src.lines, line, col),
            None => Snippet::default(),
        }
    }

    /// Renders one problem at `span`, carets under the span (cut at its line's end);
    /// a problem about the whole of an `<unknown>` file when the span's source is
    /// not in the map.
    pub fn diagnostic(&self, severity: Severity, span: Span, message: String) -> Diagnostic {
        let Some(src) = self.source(FileId::of(span)) else {
            let mut d = Diagnostic::about_file(UNKNOWN, message);
            d.severity = severity;
            return d;
        };
        let Location { file, line, col } = self.locate(span);
        let mut d = Diagnostic::error(file, (line, col), message).with_snippet(Snippet::of(
            &src.text,
            span.lo as usize,
            span.hi as usize,
        ));
        d.severity = severity;
        d
    }

    /// An error at the start of `span`, one caret under it.
    pub fn diag(&self, span: Span, message: impl Into<String>) -> Diagnostic {
        self.diagnostic(
            Severity::Error,
            Span::at(span.source, span.lo),
            message.into(),
        )
    }

    /// Renders every collected problem.
    pub(crate) fn render(&self, sink: Sink) -> Diagnostics {
        Diagnostics(
            sink.items
                .into_iter()
                .map(|r| self.diagnostic(r.severity, r.span, r.message))
                .collect(),
        )
    }
}

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
pub(crate) fn decode_source(mut bytes: Vec<u8>) -> Result<String, ((u32, u32), String)> {
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

/// The file name of a span whose source is not in its map.
const UNKNOWN: &str = "<unknown>";

/// The file position (line, column) of byte `at` of `text`, whose position map is
/// `runs` (sorted by offset; an offset before the first run counts in the first run);
/// `None` without a map. The one reading of a [`PositionRun`] map: the compiler's
/// sources and the property reader's formulas both resolve through it.
pub fn locate_in_runs(text: &str, runs: &[PositionRun], at: usize) -> Option<(u32, u32)> {
    let i = runs.partition_point(|r| r.offset as usize <= at);
    let run = runs.get(i.saturating_sub(1))?;
    if !run.exact {
        return Some((run.line.max(1), run.col.max(1)));
    }
    let at = floor_boundary(text, at);
    let from = floor_boundary(text, run.offset as usize).min(at);
    let chars = u32::try_from(text[from..at].chars().count()).unwrap_or(u32::MAX);
    Some((run.line.max(1), run.col.max(1).saturating_add(chars)))
}

/// Where lines start in a text, to turn byte offsets into 1-based lines and columns
/// counted in characters (a tab counts as one), and to find a line's text for the
/// caret. Holds only the offsets, so the owner of the text keeps it.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct LineIndex {
    starts: Vec<u32>,
    /// Per line, `true` when it holds only ASCII: its columns are byte counts, found
    /// without reading the line (so a thousand problems on one long line cost a
    /// thousand lookups, not a thousand scans of the line).
    ascii: Vec<bool>,
}

impl LineIndex {
    /// The index of `text`.
    pub fn new(text: &str) -> LineIndex {
        let mut starts = vec![0u32];
        let mut ascii = Vec::new();
        let mut line_ascii = true;
        for (i, b) in text.bytes().enumerate() {
            line_ascii &= b.is_ascii();
            if b == b'\n' {
                starts.push(u32::try_from(i + 1).unwrap_or(u32::MAX));
                ascii.push(line_ascii);
                line_ascii = true;
            }
        }
        ascii.push(line_ascii);
        LineIndex { starts, ascii }
    }

    /// 1-based line and column of byte `offset` of `text` (the indexed text), clamped
    /// to the text; an offset inside a multi-byte character counts as that character.
    pub fn line_col(&self, text: &str, offset: usize) -> (u32, u32) {
        let offset = floor_boundary(text, offset);
        let line = self
            .starts
            .partition_point(|&s| s as usize <= offset)
            .saturating_sub(1);
        let start = self.starts.get(line).map_or(0, |&s| s as usize).min(offset);
        let column = if self.ascii.get(line) == Some(&true) {
            offset - start
        } else {
            text.get(start..offset).map_or(0, |s| s.chars().count())
        };
        (
            u32::try_from(line + 1).unwrap_or(u32::MAX),
            u32::try_from(column + 1).unwrap_or(u32::MAX),
        )
    }

    /// Byte offset where 1-based line `line` starts, if the text has it.
    pub fn line_start(&self, line: u32) -> Option<usize> {
        let i = usize::try_from(line).ok()?.checked_sub(1)?;
        self.starts.get(i).map(|&s| s as usize)
    }
}

/// The source line a diagnostic shows, and where its carets go.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Snippet {
    /// The line's text (no line break).
    pub line: String,
    /// 0-based character column of the first caret.
    pub caret_col: usize,
    /// Number of carets (at least 1).
    pub caret_len: usize,
}

impl Snippet {
    /// The line of `text` holding byte `lo`, with carets under `lo..hi` (cut at the
    /// line's end). A line longer than [`SNIPPET_WIDTH`] characters is cut to that
    /// many around `lo`, `...` marking each cut: the work and the text are bounded
    /// whatever the line's length.
    pub fn of(text: &str, lo: usize, hi: usize) -> Snippet {
        const HALF: usize = SNIPPET_WIDTH / 2;
        let lo = floor_boundary(text, lo);
        let hi = floor_boundary(text, hi.max(lo));
        // At most HALF characters before `lo` (4 bytes each at most), up to the line start.
        let back = floor_boundary(text, lo.saturating_sub(4 * HALF));
        let before = &text[back..lo];
        let before = before.rfind('\n').map_or(before, |p| &before[p + 1..]);
        let skip = before.chars().count().saturating_sub(HALF);
        let start = lo - before.len() + before.char_indices().nth(skip).map_or(0, |(i, _)| i);
        let cut_before = start > 0 && text.as_bytes()[start - 1] != b'\n';
        // At most SNIPPET_WIDTH - HALF characters from `lo` on, up to the line end.
        let ahead = &text[lo..floor_boundary(text, lo + 4 * (SNIPPET_WIDTH - HALF))];
        let ahead = ahead.find('\n').map_or(ahead, |p| &ahead[..p]);
        let ahead = match ahead.char_indices().nth(SNIPPET_WIDTH - HALF) {
            Some((i, _)) => &ahead[..i],
            None => ahead,
        };
        let end = lo + ahead.len();
        let cut_after = end < text.len() && !matches!(text.as_bytes()[end], b'\n' | b'\r');
        let mut line = String::new();
        if cut_before {
            line.push_str("...");
        }
        line.push_str(text[start..end].trim_end_matches('\r'));
        if cut_after {
            line.push_str("...");
        }
        Snippet {
            line,
            caret_col: text[start..lo].chars().count() + if cut_before { 3 } else { 0 },
            caret_len: text[lo..hi.min(end)].chars().count().max(1),
        }
    }

    /// The caret at 1-based `line` and character column `col` of `text`, as `index`
    /// (of `text`) finds them (empty when the text has no such line).
    pub fn at_line_col(text: &str, index: &LineIndex, line: u32, col: u32) -> Snippet {
        let Some(start) = index.line_start(line).filter(|&s| s <= text.len()) else {
            return Snippet::default();
        };
        let rest = &text[start..];
        let skip = col.saturating_sub(1) as usize;
        let lo = rest
            .char_indices()
            .nth(skip)
            .map_or(rest.find('\n').unwrap_or(rest.len()), |(i, _)| i);
        Snippet::of(text, start + lo, start + lo)
    }
}

/// The most characters of a source line a diagnostic shows: a longer line is cut
/// around the problem.
pub const SNIPPET_WIDTH: usize = 200;

/// The most characters of a message a diagnostic prints: a longer one (a message
/// quoting a huge attribute) is cut in the middle.
pub(crate) const MESSAGE_WIDTH: usize = 1000;

/// The most diagnostics a list prints; the rest are counted (`... and N more`).
pub const MAX_SHOWN: usize = 20;

/// `text`, cut in the middle to at most about `width` characters.
fn clipped(text: &str, width: usize) -> std::borrow::Cow<'_, str> {
    let n = text.chars().count();
    if n <= width {
        return text.into();
    }
    let head: String = text.chars().take(width / 2).collect();
    let tail: String = text.chars().skip(n - width / 2).collect();
    format!(
        "{head} ... ({} characters cut) ... {tail}",
        n - 2 * (width / 2)
    )
    .into()
}

/// The largest char boundary of `text` at or before byte `i` (clamped to its length).
pub fn floor_boundary(text: &str, mut i: usize) -> usize {
    i = i.min(text.len());
    while !text.is_char_boundary(i) {
        i -= 1;
    }
    i
}

/// How bad a diagnostic is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Severity {
    /// Compilation continues; the result may not mean what the author intended.
    Warning,
    /// Compilation fails.
    Error,
}

impl fmt::Display for Severity {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Severity::Warning => "warning",
            Severity::Error => "error",
        })
    }
}

/// One located problem. Its payload `message` is a sentence (no trailing period) or a
/// structured kind that displays as one (the property reader's `PropsErrorKind`, which
/// callers match on); the position and its rendering are the same for every payload.
///
/// Rendered as `file:line:col: message` (`file:line:col: warning: message` for a
/// warning), followed by the source line and a caret line when the source is known,
/// and as `file: message` for a problem about a whole file (`line == 0`).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Diagnostic<M = String> {
    /// Error or warning.
    pub severity: Severity,
    /// What is wrong.
    pub message: M,
    /// The file the problem is in.
    pub file: String,
    /// 1-based line (0 for a problem about the whole file, such as a missing file).
    pub line: u32,
    /// 1-based column, in characters (0 when `line` is).
    pub col: u32,
    /// The line of source text the problem is on (empty when unknown).
    pub source_line: String,
    /// 0-based character column of the caret in `source_line`.
    pub caret_col: usize,
    /// Number of carets (at least 1).
    pub caret_len: usize,
}

impl<M> Diagnostic<M> {
    /// An error at `line`:`col` of `file`, with no source line.
    pub fn error(file: impl Into<String>, (line, col): (u32, u32), message: M) -> Self {
        Diagnostic {
            severity: Severity::Error,
            message,
            file: file.into(),
            line,
            col,
            source_line: String::new(),
            caret_col: 0,
            caret_len: 1,
        }
    }

    /// An error about the whole file `file` (it cannot be read, it is missing, ...).
    pub fn about_file(file: impl Into<String>, message: M) -> Self {
        Self::error(file, (0, 0), message)
    }

    /// The same problem showing `snippet` under its first line.
    pub fn with_snippet(mut self, snippet: Snippet) -> Self {
        self.source_line = snippet.line;
        self.caret_col = snippet.caret_col;
        self.caret_len = snippet.caret_len;
        self
    }

    /// The same problem as a warning.
    pub fn warning(mut self) -> Self {
        self.severity = Severity::Warning;
        self
    }

    /// The same problem with its payload turned by `f` (a kind into its message).
    pub fn map<N>(self, f: impl FnOnce(M) -> N) -> Diagnostic<N> {
        Diagnostic {
            severity: self.severity,
            message: f(self.message),
            file: self.file,
            line: self.line,
            col: self.col,
            source_line: self.source_line,
            caret_col: self.caret_col,
            caret_len: self.caret_len,
        }
    }
}

impl<M: fmt::Display> fmt::Display for Diagnostic<M> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let message = self.message.to_string();
        let message = clipped(&message, MESSAGE_WIDTH);
        let file = clipped(&self.file, MESSAGE_WIDTH);
        if self.line == 0 {
            return write!(f, "{file}: {message}");
        }
        write!(f, "{file}:{}:{}: ", self.line, self.col)?;
        if self.severity == Severity::Warning {
            write!(f, "{}: ", self.severity)?;
        }
        write!(f, "{message}")?;
        if self.source_line.is_empty() {
            return Ok(());
        }
        // Snippets are cut when made; a line set by hand is cut here (at its end).
        let line: String = self.source_line.chars().take(SNIPPET_WIDTH + 6).collect();
        let pad: String = line
            .chars()
            .take(self.caret_col)
            .map(|c| if c == '\t' { '\t' } else { ' ' })
            .collect();
        let carets = self.caret_len.clamp(1, SNIPPET_WIDTH + 6);
        write!(f, "\n    {line}\n    {pad}{}", "^".repeat(carets))
    }
}

impl<M: fmt::Display + fmt::Debug> std::error::Error for Diagnostic<M> {}

/// Every problem a pass found, errors and warnings, in the order found.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Diagnostics<M = String>(pub Vec<Diagnostic<M>>);

impl<M> Default for Diagnostics<M> {
    fn default() -> Self {
        Diagnostics(Vec::new())
    }
}

impl<M> Diagnostics<M> {
    /// No diagnostics.
    pub fn new() -> Self {
        Self::default()
    }

    /// `true` when at least one item is an error.
    pub fn has_errors(&self) -> bool {
        self.0.iter().any(|d| d.severity == Severity::Error)
    }

    /// Number of items (errors and warnings).
    pub fn len(&self) -> usize {
        self.0.len()
    }

    /// `true` when there is nothing to report.
    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }

    /// All items, in the order found.
    pub fn iter(&self) -> std::slice::Iter<'_, Diagnostic<M>> {
        self.0.iter()
    }

    /// Only the errors.
    pub fn errors(&self) -> impl Iterator<Item = &Diagnostic<M>> {
        self.0.iter().filter(|d| d.severity == Severity::Error)
    }

    /// Only the warnings.
    pub fn warnings(&self) -> impl Iterator<Item = &Diagnostic<M>> {
        self.0.iter().filter(|d| d.severity == Severity::Warning)
    }

    /// Adds one item.
    pub fn push(&mut self, d: Diagnostic<M>) {
        self.0.push(d);
    }

    /// Appends every item of `other`.
    pub fn extend(&mut self, other: Diagnostics<M>) {
        self.0.extend(other.0);
    }

    /// `Ok(v)` when empty, `Err(self)` otherwise.
    pub fn into_result<T>(self, v: T) -> Result<T, Diagnostics<M>> {
        if self.0.is_empty() {
            Ok(v)
        } else {
            Err(self)
        }
    }
}

impl<M> From<Vec<Diagnostic<M>>> for Diagnostics<M> {
    fn from(items: Vec<Diagnostic<M>>) -> Self {
        Diagnostics(items)
    }
}

impl<M> From<Diagnostic<M>> for Diagnostics<M> {
    fn from(d: Diagnostic<M>) -> Self {
        Diagnostics(vec![d])
    }
}

/// The first [`MAX_SHOWN`] items, one after the other, then how many more there are
/// (`... and 9980 more: 9980 errors, 0 warnings`).
impl<M: fmt::Display> fmt::Display for Diagnostics<M> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, d) in self.0.iter().take(MAX_SHOWN).enumerate() {
            if i > 0 {
                writeln!(f)?;
            }
            write!(f, "{d}")?;
        }
        if let Some(rest) = self.0.get(MAX_SHOWN..).filter(|r| !r.is_empty()) {
            let errors = rest
                .iter()
                .filter(|d| d.severity == Severity::Error)
                .count();
            write!(
                f,
                "\n... and {} more: {errors} errors, {} warnings",
                rest.len(),
                rest.len() - errors
            )?;
        }
        Ok(())
    }
}

impl<M: fmt::Display + fmt::Debug> std::error::Error for Diagnostics<M> {}

impl<M> IntoIterator for Diagnostics<M> {
    type Item = Diagnostic<M>;
    type IntoIter = std::vec::IntoIter<Diagnostic<M>>;
    fn into_iter(self) -> Self::IntoIter {
        self.0.into_iter()
    }
}

impl<'a, M> IntoIterator for &'a Diagnostics<M> {
    type Item = &'a Diagnostic<M>;
    type IntoIter = std::slice::Iter<'a, Diagnostic<M>>;
    fn into_iter(self) -> Self::IntoIter {
        self.0.iter()
    }
}

/// A problem before rendering: severity, span, message.
#[derive(Clone, Debug)]
pub(crate) struct Raw {
    pub severity: Severity,
    pub span: Span,
    pub message: String,
}

/// Collects problems during a pass.
#[derive(Clone, Debug, Default)]
pub(crate) struct Sink {
    pub items: Vec<Raw>,
}

impl Sink {
    /// Records an error.
    pub fn error(&mut self, span: Span, message: impl Into<String>) {
        self.items.push(Raw {
            severity: Severity::Error,
            span,
            message: message.into(),
        });
    }

    /// Records a warning.
    pub fn warn(&mut self, span: Span, message: impl Into<String>) {
        self.items.push(Raw {
            severity: Severity::Warning,
            span,
            message: message.into(),
        });
    }

    /// `true` when an error was recorded.
    pub fn has_errors(&self) -> bool {
        self.items.iter().any(|r| r.severity == Severity::Error)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lines_and_character_columns() {
        let text = "ab\ncdé\nx";
        let index = LineIndex::new(text);
        assert_eq!(index.line_col(text, 0), (1, 1));
        assert_eq!(index.line_col(text, 4), (2, 2));
        // After the two-byte `é`, and inside it (counts as the character).
        assert_eq!(index.line_col(text, 7), (2, 4));
        assert_eq!(index.line_col(text, 6), (2, 3));
        assert_eq!(index.line_col(text, 8), (3, 1));
        assert_eq!(index.line_col(text, 99), (3, 2));
        assert_eq!(index.line_start(3), Some(8));
        assert_eq!(index.line_start(4), None);
        assert_eq!(index.line_start(0), None);
    }

    #[test]
    fn one_rendering_for_every_payload() {
        let text = "<a>\n  <b x=\"1\"/>\r\n</a>";
        let index = LineIndex::new(text);
        let at = text.find("x=").unwrap();
        let mut sm = SourceMap::new();
        let file = sm.add("m.xml", text.to_string());
        let d = sm.diag(file.at(at as u32).to(file.at(at as u32 + 3)), "bad `x`");
        assert_eq!(
            d.to_string(),
            "m.xml:2:6: bad `x`\n      <b x=\"1\"/>\n         ^"
        );
        let w = d.clone().warning();
        assert!(w.to_string().starts_with("m.xml:2:6: warning: bad `x`\n"));
        // A caret found from a line and column gives the same snippet.
        let by_line = Snippet::at_line_col(text, &index, 2, 6);
        assert_eq!(by_line, Snippet::of(text, at, at));
        assert_eq!(Snippet::at_line_col(text, &index, 9, 1), Snippet::default());
        let whole: Diagnostic = Diagnostic::about_file("m.xml", "cannot read".into());
        assert_eq!(whole.to_string(), "m.xml: cannot read");
        let kind = d.map(|m| m.len());
        assert_eq!(kind.message, 7);
        assert_eq!((kind.line, kind.col), (2, 6));
    }

    #[test]
    fn one_map_for_whole_files_and_placed_pieces() {
        let mut sm = SourceMap::new();
        let file = sm.add("a.scxml", "ab\ncdé\nx".to_string());
        // A formula from an attribute at 4:3 of `m.xml`, continued on the next line.
        let piece = FileId(sm.add_piece("m.xml", "p é\n  q", 4, 3, true));
        let made = FileId(sm.add_piece("m.xml", "event e;", 9, 5, false));
        let runs = [PositionRun {
            offset: 0,
            line: 2,
            col: 7,
            exact: true,
        }];
        let mapped = FileId(sm.add_mapped("m.xml", "a < b", (1, 1), &runs));
        let at = |id: FileId, k: u32| {
            let l = sm.locate(id.at(k));
            (l.file, l.line, l.col)
        };
        assert_eq!(at(file, 7), ("a.scxml".into(), 2, 4));
        assert_eq!(at(file, 99), ("a.scxml".into(), 3, 2));
        assert_eq!(
            sm.diag(file.at(8), "m").to_string(),
            "a.scxml:3:1: m\n    x\n    ^"
        );
        assert_eq!(at(piece, 2), ("m.xml".into(), 4, 5));
        // After the two-byte `é`: columns count characters.
        assert_eq!(at(piece, 4), ("m.xml".into(), 4, 6));
        assert_eq!(at(piece, 7), ("m.xml".into(), 5, 3));
        assert_eq!(at(made, 6), ("m.xml".into(), 9, 5));
        assert_eq!(at(mapped, 4), ("m.xml".into(), 2, 11));
        assert_eq!(sm.sources().len(), 4);
        assert_eq!(sm.source(piece).map(|s| s.line_col(2)), Some((4, 5)));
        // One rendering: carets under the span for the compiler, one caret for `diag`.
        let q = piece.at(7).to(piece.at(8));
        assert_eq!(
            sm.diagnostic(Severity::Warning, q, "unused".into())
                .to_string(),
            "m.xml:5:3: warning: unused\n      q\n      ^"
        );
        let word = file.at(3).to(file.at(7));
        assert_eq!(
            sm.diagnostic(Severity::Error, word, "m".into()).caret_len,
            3
        );
        assert_eq!(sm.diag(word, "m").caret_len, 1);
        // A span of no source in the map is about an unknown file, with no position.
        let lost = sm.diag(FileId(9).at(0), "gone");
        assert_eq!(lost.to_string(), "<unknown>: gone");
        assert_eq!(sm.locate(FileId(9).at(0)).line, 0);
        assert_eq!(sm.slice(word), "cdé");
    }

    #[test]
    fn long_lines_and_long_lists_are_cut() {
        // A problem in the middle of a 100 000-character line shows 200 characters
        // around it, the caret under the problem.
        let mut text = "é".repeat(50_000);
        let at = text.len();
        text.push_str("BAD");
        text.push_str(&"x".repeat(50_000));
        text.push_str("\nnext");
        let s = Snippet::of(&text, at, at + 3);
        assert!(
            s.line.starts_with("...é") && s.line.ends_with("x..."),
            "{s:?}"
        );
        assert_eq!(s.line.chars().count(), SNIPPET_WIDTH + 6);
        let under: String = s.line.chars().skip(s.caret_col).take(3).collect();
        assert_eq!((under.as_str(), s.caret_len), ("BAD", 3));
        // Short lines are whole, without marks.
        let s = Snippet::of("ab\ncd\r\nef", 4, 4);
        assert_eq!((s.line.as_str(), s.caret_col), ("cd", 1));
        // Columns of a long ASCII line come without reading it.
        let mut sm = SourceMap::new();
        let line = format!("{}BAD", "y".repeat(70_000));
        let file = sm.add("m.xml", line.clone());
        assert_eq!(sm.locate(file.at(70_000)).col, 70_001);
        // A huge message is cut in the middle.
        let d = sm.diag(file.at(70_000), format!("bad `{line}`"));
        let shown = d.to_string();
        assert!(shown.len() < 3 * MESSAGE_WIDTH, "{}", shown.len());
        assert!(shown.contains("characters cut"));
        // A list shows its first MAX_SHOWN items and counts the rest.
        let all: Diagnostics = (0..50)
            .map(|i| sm.diag(file.at(i), format!("problem {i}")))
            .collect::<Vec<_>>()
            .into();
        let shown = all.to_string();
        assert!(shown.contains("problem 19") && !shown.contains("problem 20"));
        assert!(
            shown.ends_with("... and 30 more: 30 errors, 0 warnings"),
            "{shown}"
        );
    }

    #[test]
    fn runs_map_offsets_back_to_the_file() {
        // `a &lt; b` unescaped to `a < b`: the run after the entity starts at column 11.
        let runs = [
            PositionRun {
                offset: 0,
                line: 4,
                col: 3,
                exact: true,
            },
            PositionRun {
                offset: 2,
                line: 4,
                col: 5,
                exact: true,
            },
            PositionRun {
                offset: 3,
                line: 4,
                col: 9,
                exact: true,
            },
            PositionRun {
                offset: 5,
                line: 7,
                col: 1,
                exact: false,
            },
        ];
        let text = "a < b and";
        assert_eq!(locate_in_runs(text, &runs, 0), Some((4, 3)));
        assert_eq!(locate_in_runs(text, &runs, 4), Some((4, 10)));
        assert_eq!(locate_in_runs(text, &runs, 8), Some((7, 1)));
        assert_eq!(locate_in_runs(text, &[], 1), None);
    }

    #[test]
    fn sources_are_regular_utf8_files() {
        let dir = std::env::temp_dir().join(format!("diag-read-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let bom = dir.join("bom.txt");
        std::fs::write(&bom, b"\xEF\xBB\xBFa\nb").unwrap();
        assert_eq!(read_source(&bom).unwrap(), "a\nb");
        let bad = dir.join("bad.txt");
        std::fs::write(&bad, b"ok\nab\xC3\xA9c\xFFd").unwrap();
        let d = read_source(&bad).unwrap_err();
        assert_eq!((d.line, d.col), (2, 5));
        assert!(d.message.contains("byte 0xFF"), "{d}");
        let cut = dir.join("cut.txt");
        std::fs::write(&cut, b"x\xC3").unwrap();
        assert!(read_source(&cut)
            .unwrap_err()
            .message
            .contains("ends inside"));
        let d = read_source(&dir).unwrap_err();
        assert_eq!(
            d.to_string(),
            format!("{}: is a directory, not a file", dir.display())
        );
        assert!(read_source(&dir.join("none"))
            .unwrap_err()
            .message
            .contains("not found"));
        #[cfg(unix)]
        assert_eq!(
            not_a_source_file(Path::new("/dev/zero")).as_deref(),
            Some("is a character device, not a regular file")
        );
        let _ = std::fs::remove_dir_all(&dir);
    }
}
