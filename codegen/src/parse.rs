//! Parsing `.hspec` specification files and Rye (SCAN / Reelay) Past-MTL formulas, with nom.
//!
//! # The `.hspec` format
//!
//! A specification is a sequence of statements, each ended by `;`. Whitespace
//! is free; `#` and `//` start a comment that runs to the end of the line.
//!
//! ```text
//! # comment, also // comment
//! unit 100ms;                      // optional; the spec's time unit (default: 1s)
//! event alarm;                     // event variable (bool, true only at its point)
//! state battery_level: int = 100;  // state variable with type and initial value
//! state mode: string = "idle";
//! property absence = H({battery_level >= 30} -> H(!{alarm}));
//! ```
//!
//! - `unit T;` at most once: the length of one tick, a time literal with a
//!   unit (`1s`, `100ms`, `2.5us`) that is a whole number of nanoseconds.
//!   Timestamps and unit-less bounds count ticks.
//! - `event NAME;` an event variable: a `bool` that is true only at the point of its message.
//! - `state NAME: TYPE = INIT;` a state variable; `= INIT` is optional (default
//!   `0`, `0.0`, `false`, `""`). Types: `bool`; `int`, `i8` .. `i64`, `u8` ..
//!   `u64` (all run as 64-bit signed; the initial value must fit the declared
//!   width); `float`, `f32`, `f64`; `string`. The initial value is a literal,
//!   optionally negated.
//! - `property NAME = FORMULA;` a named Past-MTL formula.
//!
//! Variables are declared once, property names are unique, and a variable
//! must be declared (anywhere in the file) before the spec compiles.
//!
//! # Formulas
//!
//! ```text
//! true  false  {atom}  (f)
//! !f  not f      Y f  pre f      Z f      P[I] f  O[I] f  once[I] f      H[I] f  historically[I] f
//! f S[I] g  f since[I] g      f && g  f and g      f || g  f or g      f -> g  f implies g      f <-> g
//! ```
//!
//! Binding, tightest first: prefix operators; `S`; `&&`; `||`; `->`; `<->`.
//! `S`, `&&`, `||` and `<->` group to the left, `->` to the right
//! (`a -> b -> c` is `a -> (b -> c)`). So `!{a} S {b} && {c} -> {d}` is
//! `((!{a}) S {b}) && {c}) -> {d}`. SCAN instead reads every binary operator
//! with the same precedence, left to right; a chain that mixes operators and
//! would be read differently by SCAN is accepted with a warning that prints
//! both readings: add parentheses to silence it.
//!
//! Bounds `I` are `[a:b]`, `[a:]` or `[:b]` (missing `a` is 0, missing `b` is
//! infinity), both ends inclusive. An end is a whole number of ticks (`62`) or
//! a literal with a unit (`2.5s`, `100ms`, `3us`, `7ns`, `1min`) that must be a
//! whole number of ticks. `I` may be left out: no bound.
//!
//! # Atoms
//!
//! Inside `{ }` is a boolean expression over declared variables: literals
//! (`42`, `2.5`, `1e-3`, `"idle"` or `'idle'` with `\"`, `\\`, `\n`, `\t`
//! escapes, `true`, `false`), variables, `( )`, unary `-`, `!` / `not`,
//! `* / %`, `+ -`, comparisons `== != < <= > >=` (not chained), `&&` / `and`,
//! `||` / `or`, in that binding order (tightest first). A bare boolean
//! variable `{alarm}` is an atom.

use std::cell::{Cell, RefCell};

use nom::branch::alt;
use nom::bytes::complete::{tag, take_while};
use nom::character::complete::{digit1, multispace1, satisfy};
use nom::combinator::{opt, recognize};
use nom::error::{ErrorKind, ParseError};
use nom::multi::many0_count;
use nom::sequence::preceded;
use nom::{IResult, Parser};

use monitor_core::VarKind;

use crate::diag::{Sink, Span};
use crate::syntax::*;

mod expr;
use expr::expr;

/// Deepest nesting of parentheses and prefix operators the parser follows.
const MAX_NESTING: u32 = 64;

/// A parse failure: where (as the length of the remaining input), how long, and what.
#[derive(Clone, Debug)]
pub(crate) struct PErr {
    rest_len: usize,
    len: usize,
    msg: String,
}

impl<'a> ParseError<&'a str> for PErr {
    fn from_error_kind(input: &'a str, _kind: ErrorKind) -> Self {
        PErr {
            rest_len: input.len(),
            len: 0,
            msg: String::new(),
        }
    }

    fn append(_: &'a str, _: ErrorKind, other: Self) -> Self {
        other
    }
}

type R<'a, T> = IResult<&'a str, T, PErr>;
type Fail = nom::Err<PErr>;

/// Parsing context: the whole text (for offsets), its source id, nesting, warnings.
struct Cx<'s> {
    base: &'s str,
    src: u32,
    nesting: Cell<u32>,
    warnings: RefCell<Sink>,
}

impl<'s> Cx<'s> {
    fn new(base: &'s str, src: u32) -> Self {
        Cx {
            base,
            src,
            nesting: Cell::new(0),
            warnings: RefCell::new(Sink::default()),
        }
    }

    fn off(&self, rest: &str) -> u32 {
        (self.base.len().saturating_sub(rest.len())) as u32
    }

    /// The span from `from` (a suffix of the input) up to `to` (a shorter suffix).
    fn span(&self, from: &str, to: &str) -> Span {
        Span {
            source: self.src,
            lo: self.off(from),
            hi: self.off(to),
        }
    }

    fn enter(&self, at: &str) -> Result<(), Fail> {
        let n = self.nesting.get() + 1;
        if n > MAX_NESTING {
            return Err(fail_at(
                at,
                1,
                format!("nested too deeply (more than {MAX_NESTING} levels of parentheses or prefix operators)"),
            ));
        }
        self.nesting.set(n);
        Ok(())
    }

    fn leave(&self) {
        self.nesting.set(self.nesting.get().saturating_sub(1));
    }

    fn err_span(&self, e: &PErr) -> Span {
        let lo = self.base.len().saturating_sub(e.rest_len) as u32;
        Span {
            source: self.src,
            lo,
            hi: lo + e.len as u32,
        }
    }
}

fn fail_at(at: &str, len: usize, msg: String) -> Fail {
    nom::Err::Failure(PErr {
        rest_len: at.len(),
        len,
        msg,
    })
}

/// Describes the next token of `i` for messages, with its length in bytes.
fn found(i: &str) -> (String, usize) {
    if i.is_empty() {
        return ("end of input".into(), 0);
    }
    if let Ok((_, w)) = word(i) {
        return (format!("`{w}`"), w.len());
    }
    if let Ok((_, d)) = digit1::<_, PErr>(i) {
        return (format!("`{d}`"), d.len());
    }
    let c = i.chars().next().unwrap_or(' ');
    (format!("`{c}`"), c.len_utf8())
}

fn expected(i: &str, what: &str) -> Fail {
    let (f, len) = found(i);
    fail_at(i, len, format!("expected {what}, found {f}"))
}

fn is_ident_start(c: char) -> bool {
    c.is_ascii_alphabetic() || c == '_'
}

fn is_ident_char(c: char) -> bool {
    c.is_ascii_alphanumeric() || c == '_'
}

/// Whitespace and comments.
fn ws(i: &str) -> R<'_, ()> {
    let comment = alt((
        preceded(tag("#"), take_while(|c| c != '\n')),
        preceded(tag("//"), take_while(|c| c != '\n')),
    ));
    let (i, _) = many0_count(alt((multispace1, comment))).parse(i)?;
    Ok((i, ()))
}

/// An identifier-like word.
fn word(i: &str) -> R<'_, &str> {
    recognize((satisfy(is_ident_start), take_while(is_ident_char))).parse(i)
}

/// `sym` at the start of `i`, returning the rest.
fn sym<'a>(i: &'a str, s: &str) -> Option<&'a str> {
    tag::<_, _, PErr>(s).parse(i).ok().map(|(r, _)| r)
}

/// `sym` or an error naming it.
fn expect_sym<'a>(i: &'a str, s: &str) -> Result<&'a str, Fail> {
    sym(i, s).ok_or_else(|| expected(i, &format!("`{s}`")))
}

// ---------------------------------------------------------------- time literals and bounds

fn time_lit<'s>(cx: &Cx<'s>, i: &'s str) -> R<'s, TimeLit> {
    let start = i;
    let (i, int) =
        digit1::<_, PErr>(i).map_err(|_| expected(i, "a time (like `5`, `2.5s` or `100ms`)"))?;
    let (i, frac) = match opt(preceded(tag("."), digit1::<_, PErr>)).parse(i) {
        Ok((r, f)) => (r, f.unwrap_or("")),
        Err(_) => (i, ""),
    };
    let (i, unit) = match word(i) {
        Ok((r, w)) => match TimeUnit::from_suffix(w) {
            Some(u) => (r, Some(u)),
            None => {
                return Err(fail_at(
                    i,
                    w.len(),
                    format!(
                        "unknown time unit `{w}` (use {})",
                        crate::duration::UNITS_TEXT
                    ),
                ))
            }
        },
        Err(_) => (i, None),
    };
    let lit = TimeLit {
        int: int.to_string(),
        frac: frac.to_string(),
        unit,
        span: cx.span(start, i),
    };
    Ok((i, lit))
}

/// `[a:b]`, `[a:]`, `[:b]`, after optional whitespace; `None` when there is no `[`.
fn opt_bound<'s>(cx: &Cx<'s>, i: &'s str) -> R<'s, Option<Bound>> {
    let (j, _) = ws(i)?;
    let Some(k) = sym(j, "[") else {
        return Ok((i, None));
    };
    let start = j;
    let (k, _) = ws(k)?;
    let (k, lo) = if k.starts_with(':') {
        (k, None)
    } else {
        let (k, t) = time_lit(cx, k)?;
        (k, Some(t))
    };
    let (k, _) = ws(k)?;
    let k = sym(k, ":").ok_or_else(|| expected(k, "`:` in the bound `[lo:hi]`"))?;
    let (k, _) = ws(k)?;
    let (k, hi) = if k.starts_with(']') {
        (k, None)
    } else {
        let (k, t) = time_lit(cx, k)?;
        (k, Some(t))
    };
    let (k, _) = ws(k)?;
    let k = sym(k, "]").ok_or_else(|| expected(k, "`]` closing the bound"))?;
    let span = cx.span(start, k);
    Ok((k, Some(Bound { lo, hi, span })))
}

// ---------------------------------------------------------------- formulas

fn infix_op<'s>(cx: &Cx<'s>, i: &'s str) -> Result<Option<(&'s str, InfixOp)>, Fail> {
    for (s, op) in [
        ("&&", InfixOp::And),
        ("||", InfixOp::Or),
        ("->", InfixOp::Implies),
        ("<->", InfixOp::Iff),
    ] {
        if let Some(r) = sym(i, s) {
            return Ok(Some((r, op)));
        }
    }
    let Ok((r, w)) = word(i) else {
        return Ok(None);
    };
    Ok(Some(match w {
        "and" => (r, InfixOp::And),
        "or" => (r, InfixOp::Or),
        "implies" => (r, InfixOp::Implies),
        "S" | "since" => {
            let (r, b) = opt_bound(cx, r)?;
            (r, InfixOp::Since(b))
        }
        _ => return Ok(None),
    }))
}

fn prefix_op<'s>(cx: &Cx<'s>, i: &'s str) -> Result<Option<(&'s str, PrefixOp)>, Fail> {
    if let Some(r) = sym(i, "!") {
        return Ok(Some((r, PrefixOp::Not)));
    }
    let Ok((r, w)) = word(i) else {
        return Ok(None);
    };
    Ok(Some(match w {
        "not" => (r, PrefixOp::Not),
        "Y" | "pre" => (r, PrefixOp::Yesterday),
        "Z" => (r, PrefixOp::WeakYesterday),
        "P" | "O" | "once" => {
            let (r, b) = opt_bound(cx, r)?;
            (r, PrefixOp::Once(b))
        }
        "H" | "historically" => {
            let (r, b) = opt_bound(cx, r)?;
            (r, PrefixOp::Historically(b))
        }
        _ => return Ok(None),
    }))
}

fn too_deep(span: Span) -> Fail {
    nom::Err::Failure(PErr {
        rest_len: usize::MAX,
        len: span.hi.saturating_sub(span.lo) as usize,
        msg: format!("nested too deeply (the tree is more than {MAX_DEPTH} levels high)"),
    })
}

/// Fixes up a too-deep error created without a position.
fn at_span(cx: &Cx<'_>, e: Fail, span: Span) -> Fail {
    match e {
        nom::Err::Failure(mut p) if p.rest_len == usize::MAX => {
            p.rest_len = cx.base.len().saturating_sub(span.lo as usize);
            nom::Err::Failure(p)
        }
        e => e,
    }
}

fn unary<'s>(cx: &Cx<'s>, i: &'s str) -> R<'s, Formula> {
    let (i, _) = ws(i)?;
    let start = i;
    if let Some((r, op)) = prefix_op(cx, i)? {
        return prefixed(cx, start, r, unary, |arg| FormulaKind::Prefix(op, arg));
    }
    primary(cx, i)
}

/// The node of a prefix operator written at `start`: its operand parsed from `r` by
/// `operand` (one nesting level deeper), within the height limit, made by `kind`.
fn prefixed<'s, K>(
    cx: &Cx<'s>,
    start: &'s str,
    r: &'s str,
    operand: impl FnOnce(&Cx<'s>, &'s str) -> R<'s, Node<K>>,
    kind: impl FnOnce(Box<Node<K>>) -> K,
) -> R<'s, Node<K>> {
    cx.enter(start)?;
    let (r, arg) = operand(cx, r)?;
    cx.leave();
    let span = cx.span(start, r);
    let depth = arg.depth + 1;
    if depth > MAX_DEPTH {
        return Err(at_span(cx, too_deep(span), span));
    }
    let kind = kind(Box::new(arg));
    Ok((r, Node { kind, span, depth }))
}

fn primary<'s>(cx: &Cx<'s>, i: &'s str) -> R<'s, Formula> {
    let start = i;
    if let Some(r) = sym(i, "{") {
        let (r, e) = expr(cx, r)?;
        let (r, _) = ws(r)?;
        let r = sym(r, "}").ok_or_else(|| expected(r, "`}` closing the atom"))?;
        let f = Formula {
            depth: 1,
            span: cx.span(start, r),
            kind: FormulaKind::Atom(e),
        };
        return Ok((r, f));
    }
    if let Some(r) = sym(i, "(") {
        cx.enter(start)?;
        let (r, mut f) = formula(cx, r)?;
        cx.leave();
        let (r, _) = ws(r)?;
        let r = sym(r, ")").ok_or_else(|| expected(r, "a binary operator or `)`"))?;
        // The parenthesised formula's span covers the parentheses.
        f.span = cx.span(start, r);
        return Ok((r, f));
    }
    if let Ok((r, w)) = word(i) {
        match w {
            "true" | "false" => {
                let f = Formula {
                    kind: FormulaKind::Const(w == "true"),
                    span: cx.span(start, r),
                    depth: 1,
                };
                return Ok((r, f));
            }
            "and" | "or" | "implies" | "S" | "since" => {}
            _ => {
                return Err(fail_at(
                    i,
                    w.len(),
                    format!(
                        "expected a formula, found `{w}` (atoms are written in braces: `{{{w}}}`)"
                    ),
                ))
            }
        }
    }
    Err(expected(i, "a formula"))
}

/// A chain `f op f op f ...`, grouped by precedence (see the module docs).
fn formula<'s>(cx: &Cx<'s>, i: &'s str) -> R<'s, Formula> {
    let (mut i, first) = unary(cx, i)?;
    let mut operands = vec![first];
    let mut ops: Vec<(InfixOp, Span)> = Vec::new();
    loop {
        let (j, _) = ws(i)?;
        let Some((k, op)) = infix_op(cx, j)? else {
            break;
        };
        let op_span = cx.span(j, k);
        if operands.len() >= MAX_DEPTH as usize {
            return Err(fail_at(
                j,
                op_span.hi.saturating_sub(op_span.lo) as usize,
                format!("too many binary operators in one chain (more than {MAX_DEPTH}); add parentheses"),
            ));
        }
        let (k, rhs) = unary(cx, k)?;
        operands.push(rhs);
        ops.push((op, op_span));
        i = k;
    }
    if ops.is_empty() {
        return Ok((i, operands.pop().unwrap_or_else(|| unreachable_formula(cx))));
    }
    let ours = group(&ops, 0, ops.len());
    let scan = left_fold(ops.len());
    if ours != scan {
        let text = |s: Span| cx.base.get(s.lo as usize..s.hi as usize).unwrap_or("");
        let leaves: Vec<&str> = operands.iter().map(|f| text(f.span)).collect();
        let opt: Vec<&str> = ops.iter().map(|(_, s)| text(*s)).collect();
        let whole = operands[0].span.to(operands[operands.len() - 1].span);
        cx.warnings.borrow_mut().warn(
            whole,
            format!(
                "binary operators of different precedence without parentheses: this is read as `{}`, \
                 but SCAN (equal precedence, left to right) reads `{}`; add parentheses",
                render(&ours, &leaves, &opt, true),
                render(&scan, &leaves, &opt, true)
            ),
        );
    }
    let mut slots: Vec<Option<Formula>> = operands.into_iter().map(Some).collect();
    let f = build(cx, &ours, &mut slots, &ops)?;
    Ok((i, f))
}

/// Never reached (a chain has at least one operand); keeps the parser panic-free.
fn unreachable_formula(cx: &Cx<'_>) -> Formula {
    Formula {
        kind: FormulaKind::Const(false),
        span: Span {
            source: cx.src,
            lo: 0,
            hi: 0,
        },
        depth: 1,
    }
}

/// How a chain of operands is grouped: leaves are operand indices, nodes operator indices.
#[derive(Debug, PartialEq, Eq)]
enum Shape {
    Leaf(usize),
    Node(usize, Box<Shape>, Box<Shape>),
}

/// Groups operands `lo..=hi` (operators `lo..hi`) by precedence and associativity.
fn group(ops: &[(InfixOp, Span)], lo: usize, hi: usize) -> Shape {
    if lo == hi {
        return Shape::Leaf(lo);
    }
    let min = ops[lo..hi]
        .iter()
        .map(|(o, _)| o.precedence())
        .min()
        .unwrap_or(0);
    let at_min = (lo..hi).filter(|&k| ops[k].0.precedence() == min);
    let right = ops[lo..hi]
        .iter()
        .any(|(o, _)| o.precedence() == min && o.right_assoc());
    // The loosest operator is the root: the last one for left grouping, the first for right.
    let split = if right { at_min.min() } else { at_min.max() };
    let k = split.unwrap_or(lo);
    Shape::Node(
        k,
        Box::new(group(ops, lo, k)),
        Box::new(group(ops, k + 1, hi)),
    )
}

/// SCAN's reading: every operator equal, left to right.
fn left_fold(n_ops: usize) -> Shape {
    let mut s = Shape::Leaf(0);
    for k in 0..n_ops {
        s = Shape::Node(k, Box::new(s), Box::new(Shape::Leaf(k + 1)));
    }
    s
}

fn render(s: &Shape, leaves: &[&str], ops: &[&str], top: bool) -> String {
    match s {
        Shape::Leaf(i) => leaves.get(*i).copied().unwrap_or("").to_string(),
        Shape::Node(k, l, r) => {
            let inner = format!(
                "{} {} {}",
                render(l, leaves, ops, false),
                ops.get(*k).copied().unwrap_or(""),
                render(r, leaves, ops, false)
            );
            if top {
                inner
            } else {
                format!("({inner})")
            }
        }
    }
}

fn build(
    cx: &Cx<'_>,
    s: &Shape,
    slots: &mut [Option<Formula>],
    ops: &[(InfixOp, Span)],
) -> Result<Formula, Fail> {
    match s {
        Shape::Leaf(i) => Ok(slots
            .get_mut(*i)
            .and_then(Option::take)
            .unwrap_or_else(|| unreachable_formula(cx))),
        Shape::Node(k, l, r) => {
            let l = build(cx, l, slots, ops)?;
            let r = build(cx, r, slots, ops)?;
            let span = l.span.to(r.span);
            let depth = l.depth.max(r.depth) + 1;
            if depth > MAX_DEPTH {
                return Err(at_span(cx, too_deep(span), span));
            }
            let op = ops.get(*k).map_or(InfixOp::And, |(o, _)| o.clone());
            Ok(Formula {
                kind: FormulaKind::Infix(op, Box::new(l), Box::new(r)),
                span,
                depth,
            })
        }
    }
}

// ---------------------------------------------------------------- statements

fn ident<'s>(cx: &Cx<'s>, i: &'s str, what: &str) -> R<'s, Ident> {
    let (r, w) = word(i).map_err(|_| expected(i, what))?;
    Ok((
        r,
        Ident {
            name: w.to_string(),
            span: cx.span(i, r),
        },
    ))
}

enum Stmt {
    Unit(TimeLit),
    Decl(Decl),
    Prop(Prop),
}

fn statement<'s>(cx: &Cx<'s>, i: &'s str) -> R<'s, Stmt> {
    let start = i;
    let (r, kw) = word(i).map_err(|_| expected(i, "`unit`, `event`, `state` or `property`"))?;
    let (r, _) = ws(r)?;
    match kw {
        "unit" => {
            let (r, t) = time_lit(cx, r)?;
            let (r, _) = ws(r)?;
            let r = expect_sym(r, ";")?;
            Ok((r, Stmt::Unit(t)))
        }
        "event" => {
            let (r, name) = ident(cx, r, "a variable name")?;
            let (r, _) = ws(r)?;
            let r = expect_sym(r, ";")?;
            let d = Decl {
                kind: VarKind::Event,
                name,
                ty: None,
                init: None,
                span: cx.span(start, r),
            };
            Ok((r, Stmt::Decl(d)))
        }
        "state" => {
            let (r, name) = ident(cx, r, "a variable name")?;
            let (r, _) = ws(r)?;
            let r = expect_sym(r, ":")?;
            let (r, _) = ws(r)?;
            let (r, ty) = ident(cx, r, "a type name")?;
            let (r, _) = ws(r)?;
            let (r, init) = match sym(r, "=") {
                Some(r) => {
                    let (r, _) = ws(r)?;
                    let (r, e) = expr(cx, r)?;
                    let (r, _) = ws(r)?;
                    (r, Some(e))
                }
                None => (r, None),
            };
            let r = sym(r, ";").ok_or_else(|| expected(r, "`=` or `;`"))?;
            let d = Decl {
                kind: VarKind::State,
                name,
                ty: Some(ty),
                init,
                span: cx.span(start, r),
            };
            Ok((r, Stmt::Decl(d)))
        }
        "property" => {
            let (r, name) = ident(cx, r, "a property name")?;
            let (r, _) = ws(r)?;
            let r = expect_sym(r, "=")?;
            let (r, formula) = formula(cx, r)?;
            let (r, _) = ws(r)?;
            let r = sym(r, ";").ok_or_else(|| expected(r, "a binary operator or `;`"))?;
            let p = Prop {
                name,
                formula,
                span: cx.span(start, r),
            };
            Ok((r, Stmt::Prop(p)))
        }
        _ => Err(fail_at(
            start,
            kw.len(),
            format!("expected `unit`, `event`, `state` or `property`, found `{kw}`"),
        )),
    }
}

fn report(cx: &Cx<'_>, e: Fail, sink: &mut Sink) -> usize {
    let p = match e {
        nom::Err::Error(p) | nom::Err::Failure(p) => p,
        nom::Err::Incomplete(_) => PErr {
            rest_len: 0,
            len: 0,
            msg: "unexpected end of input".into(),
        },
    };
    let span = cx.err_span(&p);
    let msg = if p.msg.is_empty() {
        "syntax error".to_string()
    } else {
        p.msg
    };
    sink.error(span, msg);
    span.lo as usize
}

fn drain_warnings(cx: &Cx<'_>, sink: &mut Sink) {
    sink.items.append(&mut cx.warnings.borrow_mut().items);
}

/// Parses a whole `.hspec` text (source `src`), collecting errors into `sink`
/// and recovering at the next `;` after each.
pub(crate) fn parse_spec(text: &str, src: u32, sink: &mut Sink) -> SpecSyntax {
    let cx = Cx::new(text, src);
    let mut out = SpecSyntax::default();
    let mut i = text;
    loop {
        i = match ws(i) {
            Ok((r, _)) => r,
            Err(_) => i,
        };
        if i.is_empty() {
            break;
        }
        cx.nesting.set(0);
        match statement(&cx, i) {
            Ok((r, s)) => {
                match s {
                    Stmt::Unit(t) => out.units.push(t),
                    Stmt::Decl(d) => out.decls.push(d),
                    Stmt::Prop(p) => out.props.push(p),
                }
                i = r;
            }
            Err(e) => {
                let at = report(&cx, e, sink).min(text.len());
                // Resume after the next `;` at or after the error.
                let from = floor_char(text, at);
                i = match text[from..].find(';') {
                    Some(k) => &text[from + k + 1..],
                    None => "",
                };
            }
        }
        drain_warnings(&cx, sink);
    }
    drain_warnings(&cx, sink);
    out
}

fn floor_char(text: &str, mut i: usize) -> usize {
    while i > 0 && !text.is_char_boundary(i) {
        i -= 1;
    }
    i
}

/// Parses one formula that makes up the whole of `text` (source `src`).
pub(crate) fn parse_formula(text: &str, src: u32, sink: &mut Sink) -> Option<Formula> {
    let cx = Cx::new(text, src);
    let res = formula(&cx, text).and_then(|(r, f)| {
        let (r, _) = ws(r)?;
        if r.is_empty() {
            Ok(f)
        } else {
            Err(expected(r, "a binary operator or the end of the formula"))
        }
    });
    drain_warnings(&cx, sink);
    match res {
        Ok(f) => Some(f),
        Err(e) => {
            report(&cx, e, sink);
            None
        }
    }
}

/// Parses one statement that makes up the whole of `text` (used for declarations
/// built from structured input).
pub(crate) fn parse_decl(text: &str, src: u32, sink: &mut Sink) -> Option<Decl> {
    let cx = Cx::new(text, src);
    let res = statement(&cx, text).and_then(|(r, s)| {
        let (r, _) = ws(r)?;
        match s {
            Stmt::Decl(d) if r.is_empty() => Ok(d),
            _ => Err(expected(r, "the end of the declaration")),
        }
    });
    match res {
        Ok(d) => Some(d),
        Err(e) => {
            report(&cx, e, sink);
            None
        }
    }
}

/// Parses a time literal that makes up the whole of `text`.
pub(crate) fn parse_time(text: &str, src: u32, sink: &mut Sink) -> Option<TimeLit> {
    let cx = Cx::new(text, src);
    let res = ws(text)
        .and_then(|(r, _)| time_lit(&cx, r))
        .and_then(|(r, t)| {
            let (r, _) = ws(r)?;
            if r.is_empty() {
                Ok(t)
            } else {
                Err(expected(r, "the end of the time literal"))
            }
        });
    match res {
        Ok(t) => Some(t),
        Err(e) => {
            report(&cx, e, sink);
            None
        }
    }
}
