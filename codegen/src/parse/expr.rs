//! Atom expressions inside `{ }`: literals, variables, arithmetic, comparisons and
//! boolean connectives, by binding strength (see the parent module's docs).

use monitor_core::CmpOp;
use nom::branch::alt;
use nom::bytes::complete::tag;
use nom::character::complete::digit1;
use nom::combinator::{opt, recognize};
use nom::sequence::preceded;
use nom::Parser;

use super::{
    at_span, expected, fail_at, is_ident_char, prefixed, sym, too_deep, word, ws, Cx, Fail, PErr, R,
};
use crate::ast::{BinaryOp, UnaryOp};
use crate::syntax::*;

fn mk_bin(cx: &Cx<'_>, op: BinaryOp, l: Expr, r: Expr) -> Result<Expr, Fail> {
    let span = l.span.to(r.span);
    let depth = l.depth.max(r.depth) + 1;
    if depth > MAX_DEPTH {
        return Err(at_span(cx, too_deep(span), span));
    }
    Ok(Expr {
        kind: ExprKind::Binary(op, Box::new(l), Box::new(r)),
        span,
        depth,
    })
}

/// One left-associative level: `next (op next)*`.
fn left_level<'s>(
    cx: &Cx<'s>,
    i: &'s str,
    next: fn(&Cx<'s>, &'s str) -> R<'s, Expr>,
    op: fn(&'s str) -> Option<(&'s str, BinaryOp)>,
) -> R<'s, Expr> {
    let (mut i, mut lhs) = next(cx, i)?;
    loop {
        let (j, _) = ws(i)?;
        let Some((k, o)) = op(j) else {
            return Ok((i, lhs));
        };
        let (k, rhs) = next(cx, k)?;
        lhs = mk_bin(cx, o, lhs, rhs)?;
        i = k;
    }
}

fn word_is<'a>(i: &'a str, w: &str) -> Option<&'a str> {
    match word(i) {
        Ok((r, x)) if x == w => Some(r),
        _ => None,
    }
}

pub(super) fn expr<'s>(cx: &Cx<'s>, i: &'s str) -> R<'s, Expr> {
    left_level(cx, i, and_expr, |i| {
        sym(i, "||")
            .or_else(|| word_is(i, "or"))
            .map(|r| (r, BinaryOp::Or))
    })
}

fn and_expr<'s>(cx: &Cx<'s>, i: &'s str) -> R<'s, Expr> {
    left_level(cx, i, cmp_expr, |i| {
        sym(i, "&&")
            .or_else(|| word_is(i, "and"))
            .map(|r| (r, BinaryOp::And))
    })
}

fn cmp_op(i: &str) -> Option<(&str, CmpOp)> {
    for (s, op) in [
        ("==", CmpOp::Eq),
        ("!=", CmpOp::Ne),
        ("<=", CmpOp::Le),
        (">=", CmpOp::Ge),
        ("<", CmpOp::Lt),
        (">", CmpOp::Gt),
    ] {
        if let Some(r) = sym(i, s) {
            return Some((r, op));
        }
    }
    None
}

fn cmp_expr<'s>(cx: &Cx<'s>, i: &'s str) -> R<'s, Expr> {
    let (i, lhs) = add_expr(cx, i)?;
    let (j, _) = ws(i)?;
    if j.starts_with('=') && !j.starts_with("==") {
        return Err(fail_at(j, 1, "`=` is not a comparison; write `==`".into()));
    }
    let Some((k, op)) = cmp_op(j) else {
        return Ok((i, lhs));
    };
    let (k, rhs) = add_expr(cx, k)?;
    let (l, _) = ws(k)?;
    if cmp_op(l).is_some() {
        return Err(fail_at(
            l,
            1,
            "comparisons cannot be chained; add parentheses".into(),
        ));
    }
    let e = mk_bin(cx, BinaryOp::Cmp(op), lhs, rhs)?;
    Ok((k, e))
}

fn add_expr<'s>(cx: &Cx<'s>, i: &'s str) -> R<'s, Expr> {
    left_level(cx, i, mul_expr, |i| {
        if let Some(r) = sym(i, "+") {
            Some((r, BinaryOp::Add))
        } else if i.starts_with("->") {
            None
        } else {
            sym(i, "-").map(|r| (r, BinaryOp::Sub))
        }
    })
}

fn mul_expr<'s>(cx: &Cx<'s>, i: &'s str) -> R<'s, Expr> {
    left_level(cx, i, unary_expr, |i| {
        [
            ("*", BinaryOp::Mul),
            ("/", BinaryOp::Div),
            ("%", BinaryOp::Rem),
        ]
        .into_iter()
        .find_map(|(s, op)| sym(i, s).map(|r| (r, op)))
    })
}

fn unary_expr<'s>(cx: &Cx<'s>, i: &'s str) -> R<'s, Expr> {
    let (i, _) = ws(i)?;
    let start = i;
    let op = if let Some(r) = sym(i, "-") {
        Some((r, UnaryOp::Neg))
    } else if i.starts_with('!') && !i.starts_with("!=") {
        Some((&i[1..], UnaryOp::Not))
    } else {
        word_is(i, "not").map(|r| (r, UnaryOp::Not))
    };
    if let Some((r, op)) = op {
        return prefixed(cx, start, r, unary_expr, |arg| ExprKind::Unary(op, arg));
    }
    primary_expr(cx, i)
}

pub(super) fn number<'s>(cx: &Cx<'s>, i: &'s str) -> R<'s, Expr> {
    let start = i;
    let (r, int) = digit1(i)?;
    let (r, frac) = opt(preceded(tag("."), digit1)).parse(r)?;
    let exp = recognize((
        alt((tag("e"), tag("E"))),
        opt(alt((tag("+"), tag("-")))),
        digit1::<_, PErr>,
    ))
    .parse(r);
    let (r, exp) = match exp {
        Ok((r2, e)) => (r2, Some(e)),
        Err(_) => (r, None),
    };
    if r.starts_with(|c: char| is_ident_char(c)) {
        return Err(expected(r, "an operator after the number"));
    }
    let text = &start[..start.len() - r.len()];
    let span = cx.span(start, r);
    let kind = if frac.is_some() || exp.is_some() {
        match text.parse::<f64>() {
            Ok(v) => ExprKind::Float(v),
            Err(_) => {
                return Err(fail_at(
                    start,
                    text.len(),
                    format!("invalid number `{text}`"),
                ))
            }
        }
    } else {
        match int.parse::<u64>() {
            Ok(v) => ExprKind::Int(v),
            Err(_) => {
                return Err(fail_at(
                    start,
                    text.len(),
                    format!("integer literal `{text}` does not fit in 64 bits"),
                ))
            }
        }
    };
    Ok((
        r,
        Expr {
            kind,
            span,
            depth: 1,
        },
    ))
}

fn string_lit<'s>(cx: &Cx<'s>, i: &'s str) -> R<'s, Expr> {
    let start = i;
    let mut chars = i.char_indices();
    let quote = match chars.next() {
        Some((_, q @ ('"' | '\''))) => q,
        _ => return Err(expected(i, "a string")),
    };
    let mut out = String::new();
    while let Some((k, c)) = chars.next() {
        if c == quote {
            let r = &i[k + c.len_utf8()..];
            let e = Expr {
                kind: ExprKind::Str(out),
                span: cx.span(start, r),
                depth: 1,
            };
            return Ok((r, e));
        }
        if c == '\\' {
            match chars.next() {
                Some((_, 'n')) => out.push('\n'),
                Some((_, 't')) => out.push('\t'),
                Some((_, e @ ('\\' | '"' | '\''))) => out.push(e),
                Some((k2, e)) => {
                    return Err(fail_at(
                        &i[k..],
                        k2 - k + e.len_utf8(),
                        format!("unknown escape `\\{e}` (use \\\", \\', \\\\, \\n or \\t)"),
                    ))
                }
                None => break,
            }
        } else {
            out.push(c);
        }
    }
    Err(fail_at(start, 1, "unterminated string literal".into()))
}

fn primary_expr<'s>(cx: &Cx<'s>, i: &'s str) -> R<'s, Expr> {
    let start = i;
    if i.starts_with(|c: char| c.is_ascii_digit()) {
        return number(cx, i);
    }
    if i.starts_with(['"', '\'']) {
        return string_lit(cx, i);
    }
    if let Some(r) = sym(i, "(") {
        cx.enter(start)?;
        let (r, mut e) = expr(cx, r)?;
        cx.leave();
        let (r, _) = ws(r)?;
        let r = sym(r, ")").ok_or_else(|| expected(r, "an operator or `)`"))?;
        e.span = cx.span(start, r);
        return Ok((r, e));
    }
    if let Ok((r, w)) = word(i) {
        let kind = match w {
            "true" => ExprKind::Bool(true),
            "false" => ExprKind::Bool(false),
            "and" | "or" | "not" => return Err(expected(i, "an expression")),
            _ => ExprKind::Var(w.to_string()),
        };
        return Ok((
            r,
            Expr {
                kind,
                span: cx.span(start, r),
                depth: 1,
            },
        ));
    }
    Err(expected(i, "an expression"))
}
