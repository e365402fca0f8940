//! Diagnostics of every reader in the project: positions in source text and one rendering, `file:line:col: message` with the source line and a caret.
//!
//! This module is the source foundation that the host's readers (models, robot
//! models, property files) share with the formula compiler, so positions are
//! computed and problems are printed in one place:
//!
//! - [`LineIndex`] turns a byte offset of a text into a 1-based line and a column
//!   counted in characters, and gives the line's text for the caret;
//! - [`PositionRun`]s map text that is not a verbatim copy of its file (a formula
//!   after XML entities, one generated from a tree of elements) back to the file
//!   ([`locate_in_runs`]);
//! - [`Diagnostic`] is one located problem, its payload a message or a structured
//!   kind (the property reader's), rendered the same way whatever the payload;
//!   [`Diagnostics`] collects them in the order found.
//!
//! Inside the compiler every parsed node keeps a [`Span`]: a byte range in one
//! source of a [`SourceMap`]. A source is either a whole `.hspec` file (line 1,
//! column 1) or a piece of text that starts somewhere inside another file, such as
//! a formula taken from an XML attribute: its [`crate::Origin`] gives the file,
//! line and column of its first character, so positions point into that file.
//! Passes collect problems instead of stopping at the first one and hand back a
//! [`Diagnostics`]: located, already rendered, independent of the sources.

use std::fmt;

/// A byte range `lo..hi` in source number `source` of a [`SourceMap`]: the one span
/// type of the project (in `host`, `source` is a file of the model's source map).
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
    /// 1-based line.
    pub line: u32,
    /// 1-based column, counted in characters.
    pub col: u32,
}

#[derive(Clone, Debug)]
struct Source {
    name: String,
    text: String,
    line: u32,
    col: u32,
    /// `false` for text synthesised from structured input: every position in it
    /// resolves to the origin itself, since its columns do not exist in the file.
    exact: bool,
    /// A position map, when the text is not a verbatim copy of the file from
    /// `line`:`col` on (a formula after XML entities, or one generated from a tree):
    /// sorted by offset, the first at 0. Empty: count forward from `line`:`col`.
    runs: Vec<PositionRun>,
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

/// The texts that spans point into, with where each starts in its file.
#[derive(Clone, Debug, Default)]
pub struct SourceMap {
    sources: Vec<Source>,
}

impl SourceMap {
    /// Adds a source whose first character is at `line`:`col` of file `name`.
    /// `exact == false` marks synthesised text (see [`Location`]).
    pub(crate) fn add(&mut self, name: &str, text: &str, line: u32, col: u32, exact: bool) -> u32 {
        self.sources.push(Source {
            name: name.to_string(),
            text: text.to_string(),
            line: line.max(1),
            col: col.max(1),
            exact,
            runs: Vec::new(),
        });
        (self.sources.len() - 1) as u32
    }

    /// Adds a source whose positions come from the map `runs` (see [`PositionRun`]);
    /// with no runs, it starts at `line`:`col` like [`SourceMap::add`].
    pub(crate) fn add_mapped(
        &mut self,
        name: &str,
        text: &str,
        (line, col): (u32, u32),
        runs: &[PositionRun],
    ) -> u32 {
        let id = self.add(name, text, line, col, true);
        let mut runs = runs.to_vec();
        runs.sort_by_key(|r| r.offset);
        if let Some(src) = self.sources.last_mut() {
            src.runs = runs;
        }
        id
    }

    /// The text of source `id`.
    pub fn text(&self, id: u32) -> Option<&str> {
        self.sources.get(id as usize).map(|s| s.text.as_str())
    }

    /// The source text a span covers (empty for a span that does not resolve).
    pub fn slice(&self, span: Span) -> &str {
        self.text(span.source)
            .and_then(|t| t.get(span.lo as usize..span.hi as usize))
            .unwrap_or("")
    }

    /// File, line and column of the start of `span`.
    pub fn locate(&self, span: Span) -> Location {
        self.resolve(span).0
    }

    /// Location plus the source line, the caret's 0-based character column in it and its length.
    fn resolve(&self, span: Span) -> (Location, Option<Snippet>) {
        let Some(src) = self.sources.get(span.source as usize) else {
            let loc = Location {
                file: "<unknown>".into(),
                line: 1,
                col: 1,
            };
            return (loc, None);
        };
        let text = src.text.as_str();
        let lo = floor_boundary(text, span.lo as usize);
        let snippet = Snippet::of(text, lo, span.hi as usize);
        let (line, col) = if let Some(at) = locate_in_runs(text, &src.runs, lo) {
            at
        } else if src.exact {
            let newlines = text[..lo].matches('\n').count() as u32;
            let col = if newlines == 0 {
                src.col.saturating_add(snippet.caret_col as u32)
            } else {
                snippet.caret_col as u32 + 1
            };
            (src.line.saturating_add(newlines), col)
        } else {
            (src.line, src.col)
        };
        let loc = Location {
            file: src.name.clone(),
            line,
            col,
        };
        (loc, Some(snippet))
    }

    /// Renders one problem at `span`.
    pub(crate) fn diagnostic(&self, severity: Severity, span: Span, message: String) -> Diagnostic {
        let (loc, snippet) = self.resolve(span);
        let snippet = snippet.unwrap_or_default();
        Diagnostic {
            severity,
            message,
            file: loc.file,
            line: loc.line,
            col: loc.col,
            source_line: snippet.line,
            caret_col: snippet.caret_col,
            caret_len: snippet.caret_len,
        }
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
}

impl LineIndex {
    /// The index of `text`.
    pub fn new(text: &str) -> LineIndex {
        let mut starts = vec![0u32];
        starts.extend(
            text.bytes()
                .enumerate()
                .filter(|&(_, b)| b == b'\n')
                .map(|(i, _)| u32::try_from(i + 1).unwrap_or(u32::MAX)),
        );
        LineIndex { starts }
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
        let column = text.get(start..offset).map_or(0, |s| s.chars().count());
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
    /// line's end).
    pub fn of(text: &str, lo: usize, hi: usize) -> Snippet {
        let lo = floor_boundary(text, lo);
        let hi = floor_boundary(text, hi.max(lo));
        let line_start = text[..lo].rfind('\n').map_or(0, |p| p + 1);
        let line_end = text[lo..].find('\n').map_or(text.len(), |p| lo + p);
        Snippet {
            line: text[line_start..line_end]
                .trim_end_matches('\r')
                .to_string(),
            caret_col: text[line_start..lo].chars().count(),
            caret_len: text[lo..hi.min(line_end)].chars().count().max(1),
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

fn floor_boundary(text: &str, mut i: usize) -> usize {
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

    /// An error at byte `offset` of `text`, the whole text of `file` indexed by
    /// `index`: the position and the caret both come from the offset.
    pub fn in_text(
        file: impl Into<String>,
        text: &str,
        index: &LineIndex,
        offset: usize,
        message: M,
    ) -> Self {
        Self::error(file, index.line_col(text, offset), message)
            .with_snippet(Snippet::of(text, offset, offset))
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
        if self.line == 0 {
            return write!(f, "{}: {}", self.file, self.message);
        }
        write!(f, "{}:{}:{}: ", self.file, self.line, self.col)?;
        if self.severity == Severity::Warning {
            write!(f, "{}: ", self.severity)?;
        }
        write!(f, "{}", self.message)?;
        if self.source_line.is_empty() {
            return Ok(());
        }
        let pad: String = self
            .source_line
            .chars()
            .take(self.caret_col)
            .map(|c| if c == '\t' { '\t' } else { ' ' })
            .collect();
        write!(
            f,
            "\n    {}\n    {}{}",
            self.source_line,
            pad,
            "^".repeat(self.caret_len.max(1))
        )
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

impl<M: fmt::Display> fmt::Display for Diagnostics<M> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, d) in self.0.iter().enumerate() {
            if i > 0 {
                writeln!(f)?;
            }
            write!(f, "{d}")?;
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
        let d = Diagnostic::in_text("m.xml", text, &index, at, "bad `x`");
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
}
