//! Diagnostics: spans into sources, errors and warnings rendered as `file:line:col: error: message` with a caret line.
//!
//! Every parsed node keeps a [`Span`]: a byte range in one source of a
//! [`SourceMap`]. A source is either a whole `.hspec` file (line 1, column 1)
//! or a piece of text that starts somewhere inside another file, such as a
//! formula taken from an XML attribute: its [`crate::Origin`] gives the file,
//! line and column of its first character, so positions point into that file.
//!
//! Passes collect problems instead of stopping at the first one and hand back
//! a [`Diagnostics`]: located, already rendered, independent of the sources.

use std::fmt;

/// A byte range `lo..hi` in source number `source` of a [`SourceMap`].
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
    fn resolve(&self, span: Span) -> (Location, Option<(String, usize, usize)>) {
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
        let hi = floor_boundary(text, (span.hi as usize).max(lo));
        let line_start = text[..lo].rfind('\n').map_or(0, |p| p + 1);
        let line_end = text[lo..].find('\n').map_or(text.len(), |p| lo + p);
        let newlines = text[..lo].matches('\n').count() as u32;
        let caret_col = text[line_start..lo].chars().count();
        let caret_len = text[lo..hi.min(line_end)].chars().count().max(1);
        let line_text = text[line_start..line_end]
            .trim_end_matches('\r')
            .to_string();
        let loc = if let Some(run) = run_at(&src.runs, lo) {
            let col = if run.exact {
                let from = floor_boundary(text, run.offset as usize).min(lo);
                run.col
                    .max(1)
                    .saturating_add(text[from..lo].chars().count() as u32)
            } else {
                run.col.max(1)
            };
            Location {
                file: src.name.clone(),
                line: run.line.max(1),
                col,
            }
        } else if src.exact {
            let col = if newlines == 0 {
                src.col.saturating_add(caret_col as u32)
            } else {
                caret_col as u32 + 1
            };
            Location {
                file: src.name.clone(),
                line: src.line.saturating_add(newlines),
                col,
            }
        } else {
            Location {
                file: src.name.clone(),
                line: src.line,
                col: src.col,
            }
        };
        (loc, Some((line_text, caret_col, caret_len)))
    }

    /// Renders one problem at `span`.
    pub(crate) fn diagnostic(&self, severity: Severity, span: Span, message: String) -> Diagnostic {
        let (loc, snippet) = self.resolve(span);
        let (source_line, caret_col, caret_len) = snippet.unwrap_or_default();
        Diagnostic {
            severity,
            message,
            file: loc.file,
            line: loc.line,
            col: loc.col,
            source_line,
            caret_col,
            caret_len,
        }
    }

    /// Renders every collected problem.
    pub(crate) fn render(&self, sink: Sink) -> Diagnostics {
        Diagnostics {
            items: sink
                .items
                .into_iter()
                .map(|r| self.diagnostic(r.severity, r.span, r.message))
                .collect(),
        }
    }
}

/// The run of a position map that byte `at` falls in (the first run for an offset
/// before it; `None` without a map).
fn run_at(runs: &[PositionRun], at: usize) -> Option<PositionRun> {
    let i = runs.partition_point(|r| r.offset as usize <= at);
    runs.get(i.saturating_sub(1)).copied()
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

/// One located problem.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Diagnostic {
    /// Error or warning.
    pub severity: Severity,
    /// What is wrong, in one sentence (no trailing period).
    pub message: String,
    /// The file the problem is in.
    pub file: String,
    /// 1-based line.
    pub line: u32,
    /// 1-based column, in characters.
    pub col: u32,
    /// The line of source text the problem is on (may be empty when unknown).
    pub source_line: String,
    /// 0-based character column of the caret in `source_line`.
    pub caret_col: usize,
    /// Number of carets (at least 1).
    pub caret_len: usize,
}

impl fmt::Display for Diagnostic {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{}:{}:{}: {}: {}",
            self.file, self.line, self.col, self.severity, self.message
        )?;
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

/// Every problem a pass found, errors and warnings, in the order found.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Diagnostics {
    items: Vec<Diagnostic>,
}

impl Diagnostics {
    /// No diagnostics.
    pub fn new() -> Self {
        Self::default()
    }

    /// `true` when at least one item is an error.
    pub fn has_errors(&self) -> bool {
        self.items.iter().any(|d| d.severity == Severity::Error)
    }

    /// Number of items (errors and warnings).
    pub fn len(&self) -> usize {
        self.items.len()
    }

    /// `true` when there is nothing to report.
    pub fn is_empty(&self) -> bool {
        self.items.is_empty()
    }

    /// All items, in the order found.
    pub fn iter(&self) -> std::slice::Iter<'_, Diagnostic> {
        self.items.iter()
    }

    /// Only the errors.
    pub fn errors(&self) -> impl Iterator<Item = &Diagnostic> {
        self.items.iter().filter(|d| d.severity == Severity::Error)
    }

    /// Only the warnings.
    pub fn warnings(&self) -> impl Iterator<Item = &Diagnostic> {
        self.items
            .iter()
            .filter(|d| d.severity == Severity::Warning)
    }

    /// Appends every item of `other`.
    pub fn extend(&mut self, other: Diagnostics) {
        self.items.extend(other.items);
    }
}

impl fmt::Display for Diagnostics {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, d) in self.items.iter().enumerate() {
            if i > 0 {
                writeln!(f)?;
            }
            write!(f, "{d}")?;
        }
        Ok(())
    }
}

impl std::error::Error for Diagnostics {}

impl IntoIterator for Diagnostics {
    type Item = Diagnostic;
    type IntoIter = std::vec::IntoIter<Diagnostic>;
    fn into_iter(self) -> Self::IntoIter {
        self.items.into_iter()
    }
}

impl<'a> IntoIterator for &'a Diagnostics {
    type Item = &'a Diagnostic;
    type IntoIter = std::slice::Iter<'a, Diagnostic>;
    fn into_iter(self) -> Self::IntoIter {
        self.items.iter()
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
