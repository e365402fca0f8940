//! nom parser for the ECMAScript expression subset used by SCXML models.
//!
//! Grammar, loosest binding first:
//! `cond := or ('?' cond ':' cond)?`, `or := and ('||' and)*`,
//! `and := bor ('&&' bor)*`, `bor := bxor ('|' bxor)*`, `bxor := band ('^' band)*`,
//! `band := eq ('&' eq)*` (ECMAScript's precedence of the bitwise operators),
//! `eq := rel (('=='|'!='|'==='|'!==') rel)*`,
//! `rel := add (('<'|'<='|'>'|'>=') add)*`, `add := mul (('+'|'-') mul)*`,
//! `mul := unary (('*'|'/'|'%') unary)*`, `unary := ('!'|'-'|'+'|'~') unary | postfix`,
//! `postfix := primary ('.' name | '[' cond ']' | '(' args ')')*`,
//! `primary := number | string | true | false | name | '(' cond ')' | '[' items ']'
//!   | '{' (key ':' cond),* '}'` where `key := name | string`. Array and object literals
//! accept a trailing comma, as ECMAScript does.
//! Nesting is limited to [`MAX_NESTING`] so hostile input cannot overflow the stack.

use super::ast::{BinOp, Expr, ExprKind, ObjField, UnOp};
use nom::branch::alt;
use nom::bytes::complete::{tag, take_while, take_while1};
use nom::character::complete::hex_digit1;
use nom::combinator::recognize;
use nom::sequence::pair;
use nom::{IResult, Parser as _};

/// Deepest nesting of sub-expressions accepted.
pub const MAX_NESTING: u32 = 256;

/// A syntax error at a byte offset of the expression text.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ParseError {
    /// Byte offset in the text.
    pub offset: u32,
    /// What was expected or found.
    pub message: String,
}

impl std::fmt::Display for ParseError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{} (at byte {})", self.message, self.offset)
    }
}

impl std::error::Error for ParseError {}

/// Parses a whole expression.
pub fn parse_expr(text: &str) -> Result<Expr, ParseError> {
    let mut p = P {
        len: text.len(),
        depth: 0,
    };
    let rest = p.ws(text);
    if rest.is_empty() {
        return Err(ParseError {
            offset: 0,
            message: "empty expression".into(),
        });
    }
    let (rest, e) = p.cond(rest)?;
    let rest = p.ws(rest);
    if let Some(c) = rest.chars().next() {
        let msg = if rest.starts_with('=') {
            "assignment is not allowed in an expression (use `==` to compare)".to_string()
        } else if rest.starts_with(';') {
            "only a single expression is allowed (no `;`)".to_string()
        } else {
            format!("unexpected `{c}`")
        };
        return Err(p.stray(rest, msg));
    }
    Ok(e)
}

type R<'a, T> = Result<(&'a str, T), ParseError>;

struct P {
    len: usize,
    depth: u32,
}

fn ident_start(c: char) -> bool {
    c.is_ascii_alphabetic() || c == '_' || c == '$'
}

fn ident_char(c: char) -> bool {
    c.is_ascii_alphanumeric() || c == '_' || c == '$'
}

/// Whether `word` is reserved by the expression language, so that it cannot name a
/// variable: the literals `true` and `false`, the ECMAScript words it refuses (`null`,
/// `NaN`, `var`, ...) and ECMAScript's other reserved words (`return`, `default`, `in`,
/// ...). A lowering that names model variables after names of another language
/// (behavior tree entries) renames these.
pub fn is_reserved(word: &str) -> bool {
    is_keyword(word)
        || matches!(
            word,
            "true"
                | "false"
                | "null"
                | "undefined"
                | "NaN"
                | "Infinity"
                | "new"
                | "function"
                | "this"
                | "typeof"
                | "var"
                | "let"
        )
}

/// The other reserved words of ECMAScript (ES2015, strict mode): no expression may use
/// one as a name. SCAN parses expressions with an ECMAScript parser, which refuses them.
fn is_keyword(word: &str) -> bool {
    matches!(
        word,
        "break"
            | "delete"
            | "void"
            | "case"
            | "catch"
            | "class"
            | "const"
            | "continue"
            | "debugger"
            | "default"
            | "do"
            | "else"
            | "enum"
            | "export"
            | "extends"
            | "finally"
            | "for"
            | "if"
            | "import"
            | "in"
            | "instanceof"
            | "return"
            | "super"
            | "switch"
            | "throw"
            | "try"
            | "while"
            | "with"
            | "yield"
            | "await"
            | "static"
            | "implements"
            | "interface"
            | "package"
            | "private"
            | "protected"
            | "public"
    )
}

fn name(i: &str) -> IResult<&str, &str> {
    recognize(pair(take_while1(ident_start), take_while(ident_char))).parse(i)
}

/// A decimal literal: `12`, `1.5`, `1.`, `.5`, with an optional exponent `e-3`.
fn decimal(i: &str) -> IResult<&str, &str> {
    let b = i.as_bytes();
    let digits = |mut k: usize| {
        while k < b.len() && b[k].is_ascii_digit() {
            k += 1;
        }
        k
    };
    let int_end = digits(0);
    let mut end = int_end;
    if b.get(end) == Some(&b'.') {
        end = digits(end + 1);
    }
    if end == 0 || (int_end == 0 && end == 1) {
        return Err(nom::Err::Error(nom::error::Error::new(
            i,
            nom::error::ErrorKind::Digit,
        )));
    }
    if matches!(b.get(end), Some(b'e' | b'E')) {
        let mut k = end + 1;
        if matches!(b.get(k), Some(b'+' | b'-')) {
            k += 1;
        }
        let k2 = digits(k);
        if k2 > k {
            end = k2;
        }
    }
    Ok((&i[end..], &i[..end]))
}

fn hex(i: &str) -> IResult<&str, &str> {
    recognize((alt((tag("0x"), tag("0X"))), hex_digit1)).parse(i)
}

impl P {
    fn off(&self, rest: &str) -> u32 {
        (self.len - rest.len()) as u32
    }

    fn err(&self, rest: &str, message: impl Into<String>) -> ParseError {
        ParseError {
            offset: self.off(rest),
            message: message.into(),
        }
    }

    /// The error where a complete operand is followed by `rest` that continues none of
    /// the grammar: `message`, unless `rest` is an ECMAScript operator this language does
    /// not have (`'a' in _event`), which is named.
    fn stray(&self, rest: &str, message: impl Into<String>) -> ParseError {
        let word = name(rest).map_or("", |(_, n)| n);
        match word {
            "in" | "instanceof" => {
                self.err(rest, format!("the `{word}` operator is not supported"))
            }
            _ => self.err(rest, message),
        }
    }

    fn ws<'a>(&self, i: &'a str) -> &'a str {
        i.trim_start_matches(|c: char| c.is_whitespace())
    }

    fn enter(&mut self, i: &str) -> Result<(), ParseError> {
        self.depth += 1;
        if self.depth > MAX_NESTING {
            Err(self.err(i, "expression nested too deeply"))
        } else {
            Ok(())
        }
    }

    fn node(&self, kind: ExprKind, start: u32, rest: &str) -> Expr {
        Expr {
            kind,
            start,
            end: self.off(rest),
        }
    }

    fn cond<'a>(&mut self, i: &'a str) -> R<'a, Expr> {
        self.enter(i)?;
        let start = self.off(i);
        let (rest, c) = self.or(i)?;
        let r = self.ws(rest);
        let out = if let Some(r) = r.strip_prefix('?') {
            let r = self.ws(r);
            let (r, a) = self.cond(r)?;
            let r = self.ws(r);
            let Some(r) = r.strip_prefix(':') else {
                return Err(self.stray(r, "expected `:` in conditional expression"));
            };
            let r = self.ws(r);
            let (r, b) = self.cond(r)?;
            let e = self.node(
                ExprKind::Cond(Box::new(c), Box::new(a), Box::new(b)),
                start,
                r,
            );
            (r, e)
        } else {
            (rest, c)
        };
        self.depth -= 1;
        Ok(out)
    }

    /// One left-associative level: `next (op next)*` with operators tried in order.
    fn level<'a>(
        &mut self,
        i: &'a str,
        ops: &[(&str, BinOp)],
        next: fn(&mut P, &'a str) -> R<'a, Expr>,
    ) -> R<'a, Expr> {
        // Operators are ordered longest first, so `<` never swallows `<=`.
        let find = |r: &'a str| {
            ops.iter()
                .find(|(s, _)| r.starts_with(s))
                .map(|(s, op)| (&r[s.len()..], *op))
        };
        self.chain(i, find, next)
    }

    /// `next (op next)*`, left-associative, where `find` recognises an operator at the
    /// start of a text and gives the text after it.
    fn chain<'a>(
        &mut self,
        i: &'a str,
        find: impl Fn(&'a str) -> Option<(&'a str, BinOp)>,
        next: fn(&mut P, &'a str) -> R<'a, Expr>,
    ) -> R<'a, Expr> {
        let start = self.off(i);
        let (mut rest, mut lhs) = next(self, i)?;
        // Each operator in a chain nests the tree one level deeper: count them all.
        let depth = self.depth;
        loop {
            let r = self.ws(rest);
            let Some((after, op)) = find(r) else {
                self.depth = depth;
                return Ok((rest, lhs));
            };
            // ECMAScript reads `x ++ 1` as `x++` then `1`, a syntax error; `x + +1` is
            // a sum. Read as the sum it gave a number where JavaScript gives none.
            if matches!(op, BinOp::Add | BinOp::Sub) && (r.starts_with("++") || r.starts_with("--"))
            {
                return Err(self.err(r, "`++`/`--` are not supported"));
            }
            // Operators of ECMAScript this language does not have, said by name rather
            // than as an unexpected second character.
            if op == BinOp::Mul && r.starts_with("**") {
                return Err(self.err(r, "`**` is not supported (use Math.pow(a, b))"));
            }
            if matches!(op, BinOp::Lt | BinOp::Gt) && (r.starts_with("<<") || r.starts_with(">>")) {
                return Err(self.err(r, "the shift operators `<<`, `>>`, `>>>` are not supported"));
            }
            let after = self.ws(after);
            self.enter(after)?;
            let (r2, rhs) = next(self, after)?;
            lhs = self.node(
                ExprKind::Binary(op, Box::new(lhs), Box::new(rhs)),
                start,
                r2,
            );
            rest = r2;
        }
    }

    fn or<'a>(&mut self, i: &'a str) -> R<'a, Expr> {
        self.level(i, &[("||", BinOp::Or)], P::and)
    }

    fn and<'a>(&mut self, i: &'a str) -> R<'a, Expr> {
        self.level(i, &[("&&", BinOp::And)], P::bit_or)
    }

    /// One left-associative level of a bitwise operator, `sym` not followed by `not`
    /// (`|` is not `||`, `&` not `&&`), as in ECMAScript.
    fn bit_level<'a>(
        &mut self,
        i: &'a str,
        sym: char,
        not: char,
        op: BinOp,
        next: fn(&mut P, &'a str) -> R<'a, Expr>,
    ) -> R<'a, Expr> {
        let find = |r: &'a str| {
            r.strip_prefix(sym)
                .filter(|a| !a.starts_with(not))
                .map(|a| (a, op))
        };
        self.chain(i, find, next)
    }

    fn bit_or<'a>(&mut self, i: &'a str) -> R<'a, Expr> {
        self.bit_level(i, '|', '|', BinOp::BitOr, P::bit_xor)
    }

    fn bit_xor<'a>(&mut self, i: &'a str) -> R<'a, Expr> {
        // `^=` is an assignment, which no expression holds: `^` never meets `=` here.
        self.bit_level(i, '^', '=', BinOp::BitXor, P::bit_and)
    }

    fn bit_and<'a>(&mut self, i: &'a str) -> R<'a, Expr> {
        self.bit_level(i, '&', '&', BinOp::BitAnd, P::eq)
    }

    fn eq<'a>(&mut self, i: &'a str) -> R<'a, Expr> {
        self.level(
            i,
            &[
                ("===", BinOp::Eq),
                ("!==", BinOp::Ne),
                ("==", BinOp::Eq),
                ("!=", BinOp::Ne),
            ],
            P::rel,
        )
    }

    fn rel<'a>(&mut self, i: &'a str) -> R<'a, Expr> {
        self.level(
            i,
            &[
                ("<=", BinOp::Le),
                (">=", BinOp::Ge),
                ("<", BinOp::Lt),
                (">", BinOp::Gt),
            ],
            P::add,
        )
    }

    fn add<'a>(&mut self, i: &'a str) -> R<'a, Expr> {
        self.level(i, &[("+", BinOp::Add), ("-", BinOp::Sub)], P::mul)
    }

    fn mul<'a>(&mut self, i: &'a str) -> R<'a, Expr> {
        self.level(
            i,
            &[("*", BinOp::Mul), ("/", BinOp::Div), ("%", BinOp::Rem)],
            P::unary,
        )
    }

    fn unary<'a>(&mut self, i: &'a str) -> R<'a, Expr> {
        let start = self.off(i);
        let op = match i.chars().next() {
            Some('!') if !i.starts_with("!=") => Some(UnOp::Not),
            Some('-') if !i.starts_with("--") => Some(UnOp::Neg),
            Some('+') if !i.starts_with("++") => Some(UnOp::Plus),
            Some('~') => Some(UnOp::BitNot),
            _ => None,
        };
        if i.starts_with("++") || i.starts_with("--") {
            return Err(self.err(i, "`++`/`--` are not supported"));
        }
        match op {
            Some(op) => {
                self.enter(i)?;
                let r = self.ws(&i[1..]);
                let (r, e) = self.unary(r)?;
                self.depth -= 1;
                Ok((r, self.node(ExprKind::Unary(op, Box::new(e)), start, r)))
            }
            None => self.postfix(i),
        }
    }

    fn postfix<'a>(&mut self, i: &'a str) -> R<'a, Expr> {
        let start = self.off(i);
        let (mut rest, mut e) = self.primary(i)?;
        let depth = self.depth;
        loop {
            let r = self.ws(rest);
            if r.starts_with(['.', '[', '(']) {
                self.enter(r)?;
            }
            if let Some(r) = r.strip_prefix('.') {
                let r = self.ws(r);
                let field_at = self.off(r);
                let Ok((r, f)) = name(r) else {
                    return Err(self.err(r, "expected a field name after `.`"));
                };
                e = self.node(
                    ExprKind::Member(Box::new(e), f.to_string(), field_at),
                    start,
                    r,
                );
                rest = r;
            } else if let Some(r) = r.strip_prefix('[') {
                let r = self.ws(r);
                let (r, idx) = self.cond(r)?;
                let r = self.ws(r);
                let Some(r) = r.strip_prefix(']') else {
                    return Err(self.stray(r, "expected `]`"));
                };
                e = self.node(ExprKind::Index(Box::new(e), Box::new(idx)), start, r);
                rest = r;
            } else if let Some(r) = r.strip_prefix('(') {
                let (r, args) = self.list(r, ')', false)?;
                e = self.node(ExprKind::Call(Box::new(e), args), start, r);
                rest = r;
            } else {
                self.depth = depth;
                return Ok((rest, e));
            }
        }
    }

    /// Comma-separated expressions up to `close` (already past the opening bracket); a
    /// trailing comma is accepted when `trailing` (array literals).
    fn list<'a>(&mut self, i: &'a str, close: char, trailing: bool) -> R<'a, Vec<Expr>> {
        let mut items = Vec::new();
        let mut r = self.ws(i);
        if let Some(after) = r.strip_prefix(close) {
            return Ok((after, items));
        }
        loop {
            let (r2, e) = self.cond(r)?;
            items.push(e);
            let r2 = self.ws(r2);
            if let Some(after) = r2.strip_prefix(close) {
                return Ok((after, items));
            }
            let Some(after) = r2.strip_prefix(',') else {
                return Err(self.stray(r2, format!("expected `,` or `{close}`")));
            };
            r = self.ws(after);
            if trailing {
                if let Some(after) = r.strip_prefix(close) {
                    return Ok((after, items));
                }
            }
        }
    }

    /// `key: value` entries up to `}` (already past the `{`); a trailing comma is accepted.
    fn object<'a>(&mut self, i: &'a str) -> R<'a, Vec<ObjField>> {
        let mut fields: Vec<ObjField> = Vec::new();
        let mut r = self.ws(i);
        loop {
            if let Some(after) = r.strip_prefix('}') {
                return Ok((after, fields));
            }
            let at = self.off(r);
            let (r2, key) = match r.chars().next() {
                Some(q @ ('\'' | '"')) => match self.string(r, q)? {
                    (
                        r2,
                        Expr {
                            kind: ExprKind::Str(k),
                            ..
                        },
                    ) => (r2, k),
                    _ => return Err(self.err(r, "expected a field name")),
                },
                Some(c) if ident_start(c) => match name(r) {
                    Ok((r2, n)) => (r2, n.to_string()),
                    Err(_) => return Err(self.err(r, "expected a field name")),
                },
                _ => {
                    return Err(self.err(
                        r,
                        "expected a field name (a name or a quoted string) or `}`",
                    ))
                }
            };
            if fields.iter().any(|f| f.name == key) {
                return Err(ParseError {
                    offset: at,
                    message: format!("field `{key}` is given twice"),
                });
            }
            let r2 = self.ws(r2);
            let Some(r2) = r2.strip_prefix(':') else {
                return Err(self.err(r2, format!("expected `:` after the field name `{key}`")));
            };
            let r2 = self.ws(r2);
            let (r2, value) = self.cond(r2)?;
            fields.push(ObjField {
                name: key,
                at,
                value,
            });
            let r2 = self.ws(r2);
            if let Some(after) = r2.strip_prefix('}') {
                return Ok((after, fields));
            }
            let Some(after) = r2.strip_prefix(',') else {
                return Err(self.stray(r2, "expected `,` or `}`"));
            };
            r = self.ws(after);
        }
    }

    fn primary<'a>(&mut self, i: &'a str) -> R<'a, Expr> {
        let start = self.off(i);
        let Some(c) = i.chars().next() else {
            return Err(self.err(i, "unexpected end of expression"));
        };
        if c == '(' {
            self.enter(i)?;
            let r = self.ws(&i[1..]);
            let (r, e) = self.cond(r)?;
            let r = self.ws(r);
            let Some(r) = r.strip_prefix(')') else {
                return Err(self.stray(r, "expected `)`"));
            };
            self.depth -= 1;
            // Keep the inner node; widen its range to the parentheses.
            return Ok((
                r,
                Expr {
                    kind: e.kind,
                    start,
                    end: self.off(r),
                },
            ));
        }
        if c == '[' {
            self.enter(i)?;
            let (r, items) = self.list(&i[1..], ']', true)?;
            self.depth -= 1;
            return Ok((r, self.node(ExprKind::Array(items), start, r)));
        }
        if c == '{' {
            self.enter(i)?;
            let (r, fields) = self.object(&i[1..])?;
            self.depth -= 1;
            return Ok((r, self.node(ExprKind::Object(fields), start, r)));
        }
        if c == '\'' || c == '"' {
            return self.string(i, c);
        }
        if c.is_ascii_digit() || (c == '.' && i[1..].starts_with(|d: char| d.is_ascii_digit())) {
            return self.number(i);
        }
        if ident_start(c) {
            let Ok((r, n)) = name(i) else {
                return Err(self.err(i, "expected a name"));
            };
            let kind = match n {
                "true" => ExprKind::Bool(true),
                "false" => ExprKind::Bool(false),
                n if is_keyword(n) && !matches!(n, "delete" | "void") => {
                    return Err(self.err(
                        i,
                        format!(
                            "`{n}` is a reserved word of ECMAScript, not a value: an attribute \
                             holds one expression (`x > 0`, not `return x > 0`)"
                        ),
                    ));
                }
                n if is_reserved(n) => {
                    return Err(self.err(i, format!("`{n}` is not supported")));
                }
                _ => ExprKind::Ident(n.to_string()),
            };
            return Ok((r, self.node(kind, start, r)));
        }
        Err(self.err(i, format!("unexpected `{c}`")))
    }

    fn number<'a>(&mut self, i: &'a str) -> R<'a, Expr> {
        let start = self.off(i);
        if let Ok((r, h)) = hex(i) {
            let v = i64::from_str_radix(&h[2..], 16)
                .map_err(|_| self.err(i, "hexadecimal literal too large"))?;
            return Ok((r, self.node(ExprKind::Int(v), start, r)));
        }
        let Ok((r, text)) = decimal(i) else {
            return Err(self.err(i, "malformed number"));
        };
        if r.starts_with(ident_start) {
            return Err(self.err(r, "malformed number"));
        }
        let kind = if text.contains(['.', 'e', 'E']) {
            match text.parse::<f64>() {
                Ok(v) => ExprKind::Float(v),
                Err(_) => return Err(self.err(i, "malformed number")),
            }
        } else {
            match text.parse::<i64>() {
                Ok(v) => ExprKind::Int(v),
                Err(_) => return Err(self.err(i, "integer literal too large")),
            }
        };
        Ok((r, self.node(kind, start, r)))
    }

    fn string<'a>(&mut self, i: &'a str, quote: char) -> R<'a, Expr> {
        let start = self.off(i);
        let mut out = String::new();
        let mut chars = i[1..].char_indices();
        while let Some((k, c)) = chars.next() {
            if c == quote {
                let r = &i[1 + k + 1..];
                return Ok((r, self.node(ExprKind::Str(out), start, r)));
            }
            if c == '\\' {
                match chars.next() {
                    Some((_, 'n')) => out.push('\n'),
                    Some((_, 't')) => out.push('\t'),
                    Some((_, 'r')) => out.push('\r'),
                    Some((_, '0')) => out.push('\0'),
                    Some((_, e @ ('\\' | '\'' | '"'))) => out.push(e),
                    Some((k2, _)) => {
                        return Err(self.err(&i[1 + k2..], "unsupported escape sequence"));
                    }
                    None => break,
                }
            } else {
                out.push(c);
            }
        }
        Err(self.err(i, "unterminated string literal"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn show(e: &Expr) -> String {
        match &e.kind {
            ExprKind::Int(v) => v.to_string(),
            ExprKind::Float(v) => format!("{v:?}"),
            ExprKind::Bool(b) => b.to_string(),
            ExprKind::Str(s) => format!("'{s}'"),
            ExprKind::Array(v) => {
                format!("[{}]", v.iter().map(show).collect::<Vec<_>>().join(","))
            }
            ExprKind::Object(fs) => format!(
                "{{{}}}",
                fs.iter()
                    .map(|f| format!("{}:{}", f.name, show(&f.value)))
                    .collect::<Vec<_>>()
                    .join(",")
            ),
            ExprKind::Ident(n) => n.clone(),
            ExprKind::Member(o, f, _) => format!("{}.{f}", show(o)),
            ExprKind::Index(a, i) => format!("{}[{}]", show(a), show(i)),
            ExprKind::Call(f, a) => format!(
                "{}({})",
                show(f),
                a.iter().map(show).collect::<Vec<_>>().join(",")
            ),
            ExprKind::Unary(op, x) => format!("({op:?} {})", show(x)),
            ExprKind::Binary(op, a, b) => format!("({} {} {})", show(a), op.symbol(), show(b)),
            ExprKind::Cond(c, a, b) => format!("({} ? {} : {})", show(c), show(a), show(b)),
        }
    }

    fn p(t: &str) -> String {
        show(&parse_expr(t).unwrap())
    }

    #[test]
    fn precedence_and_associativity() {
        assert_eq!(p("1 + 2 * 3"), "(1 + (2 * 3))");
        assert_eq!(p("a - b - c"), "((a - b) - c)");
        assert_eq!(
            p("a < b && c >= d || !e"),
            "(((a < b) && (c >= d)) || (Not e))"
        );
        assert_eq!(p("x % 1000 == 0"), "((x % 1000) == 0)");
        assert_eq!(p("a ? b : c ? d : e"), "(a ? b : (c ? d : e))");
        assert_eq!(p("-x * 2"), "((Neg x) * 2)");
        assert_eq!(p("a === b && c !== d"), "((a == b) && (c != d))");
        assert_eq!(p("(1 + 2) * 3"), "((1 + 2) * 3)");
        // A sign after a binary `+`/`-` needs a space, as in ECMAScript, where `x ++ 1`
        // and `x--1` are syntax errors (increments).
        assert_eq!(p("x + +1 - -y"), "((x + (Plus 1)) - (Neg y))");
        assert_eq!(p("x+-1"), "(x + (Neg 1))");
        for (bad, want, at) in [
            ("x ** 2", "`**` is not supported (use Math.pow(a, b))", 2),
            ("x >> 1", "the shift operators", 2),
            ("1 + x << 2", "the shift operators", 6),
            ("x >>> 1", "the shift operators", 2),
            // ECMAScript words this language has no use for: named, not "unexpected".
            ("'name' in _event", "the `in` operator is not supported", 7),
            ("('a' in o) && b", "the `in` operator is not supported", 5),
            ("x instanceof y", "the `instanceof` operator", 2),
            ("c ? a in b : 1", "the `in` operator", 6),
            (
                "return x > 0",
                "`return` is a reserved word of ECMAScript",
                0,
            ),
            ("x == default", "`default` is a reserved word", 5),
            ("void 0", "`void` is not supported", 0),
            ("delete x", "`delete` is not supported", 0),
        ] {
            let e = parse_expr(bad).unwrap_err();
            assert_eq!(
                (e.message.contains(want), e.offset),
                (true, at),
                "{bad}: {e}"
            );
        }
        for (bad, at) in [("x ++ 1", 2), ("x--1", 1), ("(a)++", 3)] {
            let e = parse_expr(bad).unwrap_err();
            assert_eq!(
                (e.message.contains("`++`/`--` are not supported"), e.offset),
                (true, at),
                "{bad}: {e}"
            );
        }
    }

    #[test]
    fn bitwise_operators_bind_as_in_ecmascript() {
        // Loosest first: `||`, `&&`, `|`, `^`, `&`, then equality; each to the left.
        assert_eq!(p("a | b ^ c & d"), "(a | (b ^ (c & d)))");
        assert_eq!(p("a & b | c"), "((a & b) | c)");
        assert_eq!(p("a ^ b ^ c"), "((a ^ b) ^ c)");
        assert_eq!(p("a & b == c"), "(a & (b == c))");
        assert_eq!(p("a || b | c && d & e"), "(a || ((b | c) && (d & e)))");
        assert_eq!(p("~a & ~-1"), "((BitNot a) & (BitNot (Neg 1)))");
        assert_eq!(p("a|b&&c"), "((a | b) && c)");
    }

    #[test]
    fn postfix_literals_and_calls() {
        assert_eq!(p("_event.data.x"), "_event.data.x");
        assert_eq!(p("a[1][i + 1].length"), "a[1][(i + 1)].length");
        assert_eq!(
            p("Math.floor(Math.random() * n)"),
            "Math.floor((Math.random() * n))"
        );
        assert_eq!(p("Math.max(a, -0.5)"), "Math.max(a,(Neg 0.5))");
        assert_eq!(p("[[], [1, 2.5e1]]"), "[[],[1,25.0]]");
        assert_eq!(p("'it\\'s' == \"x\""), "('it's' == 'x')");
        assert_eq!(p(".5 + 0x10"), "(0.5 + 16)");
        assert_eq!(
            p("0.131 + 2.6 + 1e3 + 2.5E-1 + 7."),
            "((((0.131 + 2.6) + 1000.0) + 0.25) + 7.0)"
        );
        assert_eq!(p("!('' == s)"), "(Not ('' == s))");
    }

    #[test]
    fn object_literals() {
        assert_eq!(p("{x: 1, 'y': -2.5}"), "{x:1,y:(Neg 2.5)}");
        assert_eq!(p("{\"a b\": [], }"), "{a b:[]}");
        assert_eq!(p("{}"), "{}");
        assert_eq!(
            p("{'points': [{'x': 1}, {'x': a.b[0]},]}"),
            "{points:[{x:1},{x:a.b[0]}]}"
        );
        assert_eq!(p("[1, 2, ]"), "[1,2]");
        let e = parse_expr("  {ab: 1,  'c': 2}").unwrap();
        assert_eq!((e.start, e.end), (2, 18));
        let ExprKind::Object(fs) = e.kind else {
            panic!()
        };
        assert_eq!((fs[0].at, fs[1].at), (3, 11));
        assert_eq!((fs[1].value.start, fs[1].value.end), (16, 17));
        for (t, at, msg) in [
            ("{x 1}", 3, "expected `:`"),
            ("{x: 1 y: 2}", 6, "expected `,` or `}`"),
            ("{x: 1, x: 2}", 7, "given twice"),
            ("{1: 2}", 1, "expected a field name"),
            ("{x: 1", 5, "expected `,` or `}`"),
            ("{x: }", 4, "unexpected `}`"),
            ("{,}", 1, "expected a field name"),
            ("[1,,]", 3, "unexpected `,`"),
            ("f(1,)", 4, "unexpected `)`"),
        ] {
            let err = parse_expr(t).unwrap_err();
            assert_eq!(err.offset, at, "{t:?}: {err}");
            assert!(err.message.contains(msg), "{t:?}: {err}");
        }
        let deep = "{a:".repeat(10_000) + "1" + &"}".repeat(10_000);
        assert!(parse_expr(&deep).unwrap_err().message.contains("deeply"));
    }

    #[test]
    fn spans_cover_nodes() {
        let e = parse_expr("  ab + cd.ef").unwrap();
        assert_eq!((e.start, e.end), (2, 12));
        match e.kind {
            ExprKind::Binary(_, a, b) => {
                assert_eq!((a.start, a.end), (2, 4));
                assert_eq!((b.start, b.end), (7, 12));
                assert!(matches!(b.kind, ExprKind::Member(_, _, 10)));
            }
            _ => panic!(),
        }
    }

    #[test]
    fn errors_not_panics() {
        for (t, at) in [
            ("", 0),
            ("1 +", 3),
            ("a = 1", 2),
            ("(1", 2),
            ("a[1", 3),
            ("f(1,", 4),
            ("'abc", 0),
            ("1 2", 2),
            ("a &", 3),
            ("a | | b", 4),
            ("99999999999999999999", 0),
            ("x.", 2),
            ("null", 0),
            ("a ? b", 5),
            ("1abc", 1),
            ("#", 0),
        ] {
            let err = parse_expr(t).unwrap_err();
            assert_eq!(err.offset, at, "{t:?}: {err}");
        }
        let deep = "(".repeat(10_000) + "1" + &")".repeat(10_000);
        assert!(parse_expr(&deep).unwrap_err().message.contains("deeply"));
        let deep = "-".repeat(10_000) + "1";
        assert!(parse_expr(&deep).is_err());
        let deep = "!".repeat(10_000) + "1";
        assert!(parse_expr(&deep).is_err());
        let deep = "a".to_string() + &"[0]".repeat(10_000);
        assert!(parse_expr(&deep).is_err());
        let long = vec!["1"; 10_000].join(" + ");
        assert!(parse_expr(&long).is_err());
        let fine = vec!["x"; 100].join(" + ");
        assert!(parse_expr(&fine).is_ok());
    }
}
