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

mod read;

pub use read::{not_a_source_file, read_source};

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
    /// line's end). A line longer than `SNIPPET_WIDTH` characters is cut to that
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
pub(crate) const SNIPPET_WIDTH: usize = 200;

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
    pub(crate) fn error(&mut self, span: Span, message: impl Into<String>) {
        self.items.push(Raw {
            severity: Severity::Error,
            span,
            message: message.into(),
        });
    }

    /// Records a warning.
    pub(crate) fn warn(&mut self, span: Span, message: impl Into<String>) {
        self.items.push(Raw {
            severity: Severity::Warning,
            span,
            message: message.into(),
        });
    }

    /// `true` when an error was recorded.
    pub(crate) fn has_errors(&self) -> bool {
        self.items.iter().any(|r| r.severity == Severity::Error)
    }
}

#[cfg(test)]
mod tests;
