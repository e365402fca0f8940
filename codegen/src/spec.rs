//! The passes as type states: `Spec<Parsed>` -> `check` -> `Spec<Checked>` -> `size` -> `Spec<Measured>` -> `compile` -> [`Compiled`].
//!
//! Each step consumes the spec and returns `Result<Next, Diagnostics>`, so an
//! unchecked spec cannot reach the sizer and an unsized one cannot be
//! compiled. Warnings travel along: [`Spec::warnings`] at every stage,
//! [`Compiled::warnings`] at the end, and inside the `Diagnostics` of a
//! failure (before the errors).

use monitor_core::VarKind;

use crate::ast::CheckedSpec;
use crate::check;
use crate::compile::Compiled;
use crate::diag::{Diagnostics, PositionRun, Sink, SourceMap, Span};
use crate::lower::{self, Limits, Net};
use crate::parse;
use crate::syntax::{Ident, Prop, SpecSyntax};

/// Where a piece of text starts inside a file: the position of its first character.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Origin {
    /// File name used in diagnostics.
    pub file: String,
    /// 1-based line of the first character.
    pub line: u32,
    /// 1-based column (in characters) of the first character.
    pub col: u32,
}

/// A variable declaration from structured input (such as an XML element).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct DeclInput {
    /// Event or state variable.
    pub kind: VarKind,
    /// The variable's name (an identifier).
    pub name: String,
    /// Its type as in `.hspec` (`int`, `u8`, `float`, `string`, ...); ignored for events.
    pub type_name: String,
    /// The initial value as a literal (`100`, `-2.5`, `"idle"`, `true`); `None` for the default.
    pub init: Option<String>,
    /// Where the declaration is; every problem with it is reported here.
    pub origin: Origin,
}

/// A named formula from structured input, such as an XML attribute.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FormulaInput {
    /// The property's name.
    pub name: String,
    /// The formula text (already unescaped by the host's XML reader).
    pub text: String,
    /// Where the formula's first character is: positions inside it are counted from here
    /// when `positions` is empty.
    pub origin: Origin,
    /// Where each run of `text` comes from in the file, when the text is not a verbatim
    /// copy of one line from `origin` on: after entities (`&lt;` is one character of
    /// `text` but four of the file) or for a formula generated from a tree of elements.
    /// Empty for verbatim text.
    pub positions: Vec<PositionRun>,
}

/// A specification given as parts instead of a `.hspec` file.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct SpecInput {
    /// The time unit literal (`1s`, `100ms`) and where it was written; `None` for 1s.
    pub unit: Option<(String, Origin)>,
    /// The ticks have no known duration (a model whose steps are not tied to a clock):
    /// bounds must be tick counts, and a bound with a unit (`2s`) is an error instead of
    /// being read against the default unit.
    pub untimed: bool,
    /// Variable declarations.
    pub decls: Vec<DeclInput>,
    /// Named formulas.
    pub formulas: Vec<FormulaInput>,
}

/// Stage: parsed, names and types not yet resolved.
#[derive(Clone, Debug)]
pub struct Parsed {
    syntax: SpecSyntax,
}

/// Stage: checked; the [`CheckedSpec`] is available.
#[derive(Clone, Debug)]
pub struct Checked {
    ast: CheckedSpec,
}

/// Stage: lowered to networks, laid out and within the [`Limits`].
#[derive(Clone, Debug)]
pub struct Measured {
    ast: CheckedSpec,
    net: Net,
}

/// A specification at stage `S` ([`Parsed`], [`Checked`] or [`Measured`]).
#[derive(Clone, Debug)]
pub struct Spec<S> {
    sources: SourceMap,
    warnings: Sink,
    stage: S,
}

impl<S> Spec<S> {
    /// The warnings found so far.
    pub fn warnings(&self) -> Diagnostics {
        self.sources.render(self.warnings.clone())
    }

    /// The source texts spans point into.
    pub fn sources(&self) -> &SourceMap {
        &self.sources
    }

    /// Ends a pass: the next stage when `sink` holds no errors, else every diagnostic.
    fn finish<T>(self, mut sink: Sink, next: impl FnOnce(S) -> T) -> Result<Spec<T>, Diagnostics> {
        // Within one pass, report in source order.
        sink.items
            .sort_by_key(|r| (r.span.source, r.span.lo, r.span.hi));
        let mut all = self.warnings;
        all.items.extend(sink.items);
        if all.has_errors() {
            return Err(self.sources.render(all));
        }
        Ok(Spec {
            sources: self.sources,
            warnings: all,
            stage: next(self.stage),
        })
    }
}

impl Spec<Parsed> {
    /// Parses a `.hspec` text; `file` names it in diagnostics.
    pub fn parse(src: &str, file: &str) -> Result<Spec<Parsed>, Diagnostics> {
        let mut sources = SourceMap::default();
        let id = sources.add(file, src.to_string()).0;
        let mut sink = Sink::default();
        let syntax = parse::parse_spec(src, id, &mut sink);
        Self::parsed(sources, sink, syntax)
    }

    fn parsed(
        sources: SourceMap,
        sink: Sink,
        syntax: SpecSyntax,
    ) -> Result<Spec<Parsed>, Diagnostics> {
        let spec = Spec {
            sources,
            warnings: Sink::default(),
            stage: (),
        };
        spec.finish(sink, |()| Parsed { syntax })
    }

    /// Parses a specification given as parts (declarations and named formulas
    /// from XML, say); each problem is reported at its part's [`Origin`].
    pub fn from_input(input: &SpecInput) -> Result<Spec<Parsed>, Diagnostics> {
        let mut sources = SourceMap::default();
        let mut sink = Sink::default();
        let mut syntax = SpecSyntax {
            untimed: input.untimed && input.unit.is_none(),
            ..SpecSyntax::default()
        };
        if let Some((text, o)) = &input.unit {
            let id = sources.add_piece(&o.file, text, o.line, o.col, true);
            if let Some(t) = parse::parse_time(text, id, &mut sink) {
                syntax.units.push(t);
            }
        }
        for d in &input.decls {
            let text = match d.kind {
                VarKind::Event => format!("event {};", d.name),
                VarKind::State => match &d.init {
                    Some(init) => format!("state {}: {} = {};", d.name, d.type_name, init),
                    None => format!("state {}: {};", d.name, d.type_name),
                },
            };
            let o = &d.origin;
            let id = sources.add_piece(&o.file, &text, o.line, o.col, false);
            if let Some(decl) = parse::parse_decl(&text, id, &mut sink) {
                syntax.decls.push(decl);
            }
        }
        for f in &input.formulas {
            let o = &f.origin;
            let id = sources.add_mapped(&o.file, &f.text, (o.line, o.col), &f.positions);
            if let Some(formula) = parse::parse_formula(&f.text, id, &mut sink) {
                let span = Span {
                    source: id,
                    lo: 0,
                    hi: f.text.len() as u32,
                };
                syntax.props.push(Prop {
                    name: Ident {
                        name: f.name.clone(),
                        span,
                    },
                    formula,
                    span,
                });
            }
        }
        Self::parsed(sources, sink, syntax)
    }

    /// Resolves names and types and converts bounds to ticks.
    pub fn check(self) -> Result<Spec<Checked>, Diagnostics> {
        let mut sink = Sink::default();
        let ast = check::check(&self.stage.syntax, &self.sources, &mut sink);
        self.finish(sink, |_| Checked { ast })
    }
}

impl Spec<Checked> {
    /// The checked AST.
    pub fn ast(&self) -> &CheckedSpec {
        &self.stage.ast
    }

    /// Lowers every property to a network, lays out the state and enforces `limits`.
    pub fn size(self, limits: &Limits) -> Result<Spec<Measured>, Diagnostics> {
        let mut sink = Sink::default();
        let net = lower::lower(&self.stage.ast, limits, &mut sink);
        self.finish(sink, |c| Measured { ast: c.ast, net })
    }
}

impl Spec<Measured> {
    /// The checked AST.
    pub fn ast(&self) -> &CheckedSpec {
        &self.stage.ast
    }

    /// Total monitor state in bytes.
    pub fn state_bytes(&self) -> usize {
        (self.stage.net.state_words * 8) as usize
    }

    /// Packages the program and validates it with [`monitor_core::Monitor::try_new`].
    pub fn compile(self) -> Result<Compiled, Diagnostics> {
        let warnings = self.warnings();
        let Measured { ast, net } = self.stage;
        let span = ast.properties.first().map(|p| p.span).unwrap_or_default();
        Compiled::build(ast, net, warnings.clone()).map_err(|m| {
            let mut sink = self.warnings.clone();
            sink.error(span, format!("internal compiler error: {m}"));
            self.sources.render(sink)
        })
    }
}

/// Parses, checks, sizes (default [`Limits`]) and compiles a `.hspec` text.
pub fn compile_spec(src: &str, file: &str) -> Result<Compiled, Diagnostics> {
    Spec::parse(src, file)?
        .check()?
        .size(&Limits::default())?
        .compile()
}

/// Like [`compile_spec`] for a specification given as parts.
pub fn compile_input(input: &SpecInput) -> Result<Compiled, Diagnostics> {
    Spec::from_input(input)?
        .check()?
        .size(&Limits::default())?
        .compile()
}
