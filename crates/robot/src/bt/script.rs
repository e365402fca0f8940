//! The syntax of BehaviorTree.CPP 4's script language (the `code` of `Script` and
//! `ScriptCondition`, Precondition's `if`, the `_skipIf` ... `_post` attributes), checked
//! where a tree is read so that a malformed script is an error at its attribute.
//!
//! The grammar, from BT.CPP 4 (`src/script_parser.cpp`, `Grammar::stmt` and
//! `Grammar::Expression`; `include/behaviortree_cpp/scripting/operators.hpp`) and as the
//! real library 4.8.2 parses it (`tests/tests/bt_real.rs` holds the oracle's own reader
//! to it): statements separated by `;` (no trailing `;`); a statement is `name` followed
//! by one of `:= = += -= *= /=` and an expression, or an expression; expressions have
//! `? :`, `|| &&`, comparisons, `| ^`, `&`, `+ -`, `* /`, the prefixes `- ! ~`,
//! parentheses, numbers, `'strings'`, `true`, `false` and names. `! ~ & | ^` do not mix
//! with the arithmetic operators `- + * /` in one expression ("operator cannot be mixed
//! with previous operators"); parentheses and the middle part of `c ? a : b` start a new
//! one.
//!
//! [`parse`] gives the statements as a tree ([`Stmt`], [`Ex`]); `&&` and `||` are one
//! level, read left to right (BT.CPP 4.8.2: `true || false && false` is false), `+ -`
//! and `* /` group to the right (4.8.2: `10 - 4 - 2` is 8, `1 - 1 + 1` is -1), and
//! `c ? a : b ? ...` is refused ("operator cannot be chained"), as the real library
//! does. AS2FM has no model of the language; the BT.CPP semantics (`--bt btcpp`) lowers
//! its integer, boolean and (where not stored) double part (`btcpp4_script.rs`).

/// A syntax error: the byte offset in the script (from 0) and what is wrong.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct SyntaxError {
    /// Byte offset of the token where parsing stopped.
    pub at: usize,
    /// What was expected or refused.
    pub what: String,
}

impl std::fmt::Display for SyntaxError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "script syntax error at column {} of the script: {}",
            self.at + 1,
            self.what
        )
    }
}

/// An expression and the byte offset (in the script) where it starts.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Ex {
    /// Byte offset of its first token.
    pub at: usize,
    /// What it is.
    pub k: K,
}

/// The kinds of expression.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum K {
    /// A decimal integer literal.
    Int(i64),
    /// `true` / `false`.
    Bool(bool),
    /// Another number literal (real, hexadecimal, too large), as written.
    Number(String),
    /// A `'string'`: its text, between the quotes.
    Str(String),
    /// A blackboard entry.
    Name(String),
    /// A prefix operator (`-`, `!`, `~`) and its operand.
    Un(&'static str, Box<Ex>),
    /// A binary operator (`+ - * / | & ^ && || ..`).
    Bin(&'static str, Box<Ex>, Box<Ex>),
    /// A comparison chain: operands and the operators between them (`a < b < c` is
    /// `a < b && b < c`).
    Cmp(Vec<Ex>, Vec<&'static str>),
    /// `c ? a : b`.
    Ite(Box<Ex>, Box<Ex>, Box<Ex>),
}

/// A statement: an optional assignment (`entry`, operator, offset of the entry) and its
/// expression.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Stmt {
    /// `Some((entry, ":=" | "=" | "+=" | "-=" | "*=" | "/=", offset))` for an assignment.
    pub assign: Option<(String, &'static str, usize)>,
    /// The expression (the right-hand side of an assignment).
    pub e: Ex,
}

/// The pre/post-condition attributes BT.CPP 4 reads on every node (`tree_node.h`,
/// `PreCondNames`, `PostCondNames`).
pub(crate) const CONDITION_ATTRS: [&str; 8] = [
    "_failureIf",
    "_successIf",
    "_skipIf",
    "_while",
    "_onHalted",
    "_onFailure",
    "_onSuccess",
    "_post",
];

#[derive(Clone, Copy, PartialEq, Eq, Debug)]
enum T<'s> {
    Num,
    Str(&'s str),
    Name(&'s str),
    Sym(&'static str),
}

const SYMS: [&str; 27] = [
    ":=", "+=", "-=", "*=", "/=", "==", "!=", "<=", ">=", "&&", "||", "=", "<", ">", "+", "-", "*",
    "/", "!", "~", "&", "|", "^", "(", ")", "?", ":",
];

fn tokens(s: &str) -> Result<Vec<(T<'_>, usize)>, SyntaxError> {
    let b = s.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        let c = b[i];
        let start = i;
        if c.is_ascii_whitespace() {
            i += 1;
            continue;
        }
        if c == b';' {
            out.push((T::Sym(";"), i));
            i += 1;
        } else if c.is_ascii_digit() {
            // A number runs on through letters and `.`, and a sign right after the `e`
            // of a decimal exponent (`2.5e-1`; BT.CPP 4 `scripting/any_types.hpp`,
            // `Grammar::Real`): the lowering reads what it holds.
            let hex = s[i..].starts_with("0x") || s[i..].starts_with("0X");
            while i < b.len() && (b[i].is_ascii_alphanumeric() || b[i] == b'.') {
                let exp = !hex && (b[i] == b'e' || b[i] == b'E');
                i += 1;
                if exp
                    && i + 1 < b.len()
                    && (b[i] == b'+' || b[i] == b'-')
                    && b[i + 1].is_ascii_digit()
                {
                    i += 1;
                }
            }
            out.push((T::Num, start));
        } else if c == b'\'' {
            i += 1;
            while i < b.len() && b[i] != b'\'' {
                i += 1;
            }
            if i == b.len() {
                return Err(SyntaxError {
                    at: start,
                    what: "unterminated string".into(),
                });
            }
            i += 1;
            out.push((T::Str(&s[start + 1..i - 1]), start));
        } else if c.is_ascii_alphabetic() || c == b'_' {
            while i < b.len() && (b[i].is_ascii_alphanumeric() || b[i] == b'_') {
                i += 1;
            }
            out.push((T::Name(&s[start..i]), start));
        } else if s[i..].starts_with("..") {
            // BT.CPP 4.8.2 joins strings with `..` (`btcpp4_script/join.rs`).
            i += 2;
            out.push((T::Sym(".."), start));
        } else if let Some(sym) = SYMS.iter().find(|x| s[i..].starts_with(**x)) {
            i += sym.len();
            out.push((T::Sym(sym), start));
        } else {
            return Err(SyntaxError {
                at: start,
                what: format!("unexpected `{}`", s[i..].chars().next().unwrap_or('?')),
            });
        }
    }
    Ok(out)
}

/// The precedence levels of the binary operators, loosest first: `| ^` one level and
/// `&` tighter, each grouping to the left (BT.CPP 4.8.2: `1 | 1 ^ 1` is 0, `1 ^ 1 | 1`
/// is 1, `1 | 2 & 4` is 1; 4.10 `scripting/operators.hpp`, `Grammar::Expression`,
/// `bit_or` and `bit_and`).
const LEVELS: [&[&str]; 8] = [
    &["||", "&&"],
    &["==", "!=", "<", "<=", ">", ">="],
    &[".."],
    &["|", "^"],
    &["&"],
    &["+", "-"],
    &["*", "/"],
    &[],
];

/// The first level of the arithmetic operators in [`LEVELS`]; the levels before it
/// and after the comparisons are the bit operators, which share an operator group with
/// `!` and `~` (BT.CPP's `dsl::groups<math_sum, bit_or>`: an expression holds one group
/// or the other, "operator cannot be mixed with previous operators").
const ARITH: usize = 5;

/// The level of `..` in [`LEVELS`]: an operator group of its own, tighter than the
/// comparisons and grouping to the left (4.10 `scripting/operators.hpp`,
/// `Grammar::Expression`, `string_concat`). 4.8.2, measured: `'a' .. 'b' == 'ab'` holds,
/// `1 .. 2 .. 'a'` throws (`1 .. 2` has no value), and `'a' .. 1 + 2`, `'a' .. -3`,
/// `'a' .. !1`, `'a' .. 1 & 3`, `-'a' .. 'b'` and `'a' .. 'b' + 'c'` are refused at
/// load: `..` mixes with neither the arithmetic nor the bit operators nor `-`, `!`, `~`
/// (`'a' .. (1 + 2)` is a script).
const CONCAT: usize = 2;

struct Parser<'s> {
    toks: Vec<(T<'s>, usize)>,
    pos: usize,
    end: usize,
    src: &'s str,
    /// Per open expression: it has a `!`, `~` or bit operator; it has an arithmetic
    /// operator; it has `..`.
    open: Vec<[bool; 3]>,
}

impl<'s> Parser<'s> {
    fn at(&self) -> usize {
        self.toks.get(self.pos).map_or(self.end, |t| t.1)
    }

    fn next_is(&self, sym: &str) -> bool {
        matches!(self.toks.get(self.pos), Some((T::Sym(x), _)) if *x == sym)
    }

    fn fail<R>(&self, what: &str) -> Result<R, SyntaxError> {
        Err(SyntaxError {
            at: self.at(),
            what: what.into(),
        })
    }

    /// Records an operator of group 0 (`! ~ & | ^`), 1 (arithmetic) or 2 (`..`) at the
    /// current token.
    fn note(&mut self, group: usize) -> Result<(), SyntaxError> {
        let g = self.open.last_mut().expect("an open expression");
        g[group] = true;
        if (0..3).any(|o| o != group && g[o]) {
            return self.fail("operator cannot be mixed with previous operators");
        }
        Ok(())
    }

    fn statement(&mut self) -> Result<Stmt, SyntaxError> {
        let mut assign = None;
        if let (Some((T::Name(n), at)), Some((T::Sym(op), _))) =
            (self.toks.get(self.pos), self.toks.get(self.pos + 1))
        {
            if let Some(op) = [":=", "=", "+=", "-=", "*=", "/="]
                .into_iter()
                .find(|o| o == op)
            {
                assign = Some((n.to_string(), op, *at));
                self.pos += 2;
            }
        }
        let e = self.expression()?;
        Ok(Stmt { assign, e })
    }

    fn expression(&mut self) -> Result<Ex, SyntaxError> {
        self.open.push([false; 3]);
        let r = self.expression_rest();
        self.open.pop();
        r
    }

    /// `binary(0) [? expression : binary(0)]`, in the open expression; a second `?`
    /// is refused as BT.CPP refuses it ("operator cannot be chained").
    fn expression_rest(&mut self) -> Result<Ex, SyntaxError> {
        let c = self.binary(0)?;
        if !self.next_is("?") {
            return Ok(c);
        }
        self.pos += 1;
        let a = self.expression()?;
        if !self.next_is(":") {
            return self.fail("expected `:`");
        }
        self.pos += 1;
        let b = self.binary(0)?;
        if self.next_is("?") {
            return self.fail("operator cannot be chained");
        }
        let at = c.at;
        Ok(Ex {
            at,
            k: K::Ite(Box::new(c), Box::new(a), Box::new(b)),
        })
    }

    fn binary(&mut self, level: usize) -> Result<Ex, SyntaxError> {
        if LEVELS[level].is_empty() {
            return self.prefix();
        }
        let first = self.binary(level + 1)?;
        let at = first.at;
        let mut acc = first;
        let mut chain: Vec<Ex> = Vec::new();
        let mut ops: Vec<&'static str> = Vec::new();
        while let Some((T::Sym(op), _)) = self.toks.get(self.pos) {
            let Some(op) = LEVELS[level].iter().copied().find(|o| o == op) else {
                break;
            };
            if level == CONCAT {
                self.note(2)?;
            } else if level > CONCAT {
                self.note(usize::from(level >= ARITH))?;
            }
            self.pos += 1;
            if level >= ARITH {
                // `+ -` and `* /` group to the right: BT.CPP 4.8.2 computes
                // `10 - 4 - 2` as `10 - (4 - 2)`, 8, and `12 / 2 / 3` as 18 (the oracle's
                // `script_operators_agree_with_the_library` holds it to the library).
                let rhs = self.binary(level)?;
                return Ok(Ex {
                    at,
                    k: K::Bin(op, Box::new(acc), Box::new(rhs)),
                });
            }
            let rhs = self.binary(level + 1)?;
            if level == 1 {
                // Comparisons chain.
                if chain.is_empty() {
                    chain.push(acc.clone());
                }
                chain.push(rhs);
                ops.push(op);
            } else {
                acc = Ex {
                    at,
                    k: K::Bin(op, Box::new(acc), Box::new(rhs)),
                };
            }
        }
        if !ops.is_empty() {
            return Ok(Ex {
                at,
                k: K::Cmp(chain, ops),
            });
        }
        Ok(acc)
    }

    fn prefix(&mut self) -> Result<Ex, SyntaxError> {
        let at = self.at();
        match self.toks.get(self.pos).map(|t| t.0) {
            Some(T::Sym(op @ ("-" | "!" | "~"))) => {
                // `!` and `~` are one group (`bit_prefix`), `-` the other.
                self.note(usize::from(op == "-"))?;
                self.pos += 1;
                let e = self.prefix()?;
                Ok(Ex {
                    at,
                    k: K::Un(op, Box::new(e)),
                })
            }
            Some(T::Num) => {
                self.pos += 1;
                let end = self.toks.get(self.pos).map_or(self.end, |t| t.1);
                let text = self.src[at..end].trim();
                let k = if text.bytes().all(|c| c.is_ascii_digit()) {
                    text.parse::<i64>()
                        .map_or_else(|_| K::Number(text.to_string()), K::Int)
                } else {
                    K::Number(text.to_string())
                };
                Ok(Ex { at, k })
            }
            Some(T::Str(t)) => {
                self.pos += 1;
                Ok(Ex {
                    at,
                    k: K::Str(t.to_string()),
                })
            }
            Some(T::Name(n)) => {
                self.pos += 1;
                let k = match n {
                    "true" => K::Bool(true),
                    "false" => K::Bool(false),
                    _ => K::Name(n.to_string()),
                };
                Ok(Ex { at, k })
            }
            Some(T::Sym("(")) => {
                self.pos += 1;
                let e = self.expression()?;
                if !self.next_is(")") {
                    return self.fail("expected `)`");
                }
                self.pos += 1;
                Ok(e)
            }
            _ => self.fail("expected an operand"),
        }
    }
}

/// Parses a script into its statements.
pub(crate) fn parse(script: &str) -> Result<Vec<Stmt>, SyntaxError> {
    let mut p = Parser {
        toks: tokens(script)?,
        pos: 0,
        end: script.len(),
        src: script,
        open: Vec::new(),
    };
    let mut out = vec![p.statement()?];
    while p.next_is(";") {
        if p.pos + 1 == p.toks.len() {
            return p.fail("unexpected trailing `;`");
        }
        p.pos += 1;
        out.push(p.statement()?);
    }
    if p.pos < p.toks.len() {
        return p.fail("expected `;`");
    }
    Ok(out)
}

/// The entry names a well-formed script uses, in order of first use (none for a
/// malformed one).
pub(crate) fn names(script: &str) -> Vec<String> {
    fn walk(e: &Ex, out: &mut Vec<String>) {
        match &e.k {
            K::Name(n) if !out.contains(n) => out.push(n.clone()),
            K::Un(_, a) => walk(a, out),
            K::Bin(_, a, b) => {
                walk(a, out);
                walk(b, out);
            }
            K::Cmp(xs, _) => xs.iter().for_each(|x| walk(x, out)),
            K::Ite(c, a, b) => {
                walk(c, out);
                walk(a, out);
                walk(b, out);
            }
            _ => {}
        }
    }
    let mut out = Vec::new();
    for s in parse(script).unwrap_or_default() {
        if let Some((n, _, _)) = &s.assign {
            if !out.contains(n) {
                out.push(n.clone());
            }
        }
        walk(&s.e, &mut out);
    }
    out
}

/// Checks a script's syntax.
pub(crate) fn check(script: &str) -> Result<(), SyntaxError> {
    parse(script).map(|_| ())
}

/// The error for script port `port` of built-in node `node` (`Script` / `ScriptCondition`
/// `code`, `Precondition` `if`) if the script is malformed.
pub(crate) fn port_error(node: &str, port: &str, value: &str) -> Option<String> {
    let is_script = matches!(
        (node, port),
        ("Script" | "ScriptCondition", "code") | ("Precondition", "if")
    );
    let e = check(value).err().filter(|_| is_script)?;
    Some(format!(
        "`{port}` of <{node}>: script syntax error at column {} of the script: {}",
        e.at + 1,
        e.what
    ))
}

/// For a pre/post-condition attribute (`_skipIf`, ...): `Ok(())` for a well-formed
/// script, `Err(syntax error)` for a malformed one; `None` for another attribute.
pub(crate) fn condition_error(attr: &str, value: &str) -> Option<Result<(), SyntaxError>> {
    if !CONDITION_ATTRS.contains(&attr) {
        return None;
    }
    Some(check(value))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at(s: &str) -> usize {
        check(s).expect_err(s).at
    }

    #[test]
    fn scripts_btcpp_accepts() {
        for s in [
            "x:=0; y:=1; f:=true",
            "a := 3; b := a*2+1; c := a<b",
            "msg := 'hello world'",
            "A := 42; B := 3.14; C := 2.5e-1 < 1E+3",
            "x := 0xe-1",
            "a := !true || 1 > 2",
            "a := !true || (-1 < 0)",
            "a := !true ? -1 : 2",
            "a := 1 < -2 && 2 > 1",
            "x += 1; y -= 2; z *= 3",
            "-x <= -1 && 3 != y || f",
        ] {
            assert_eq!(check(s), Ok(()), "{s}");
        }
    }

    #[test]
    fn syntax_errors_where_btcpp_puts_them() {
        // The offsets BT.CPP 4.8.2's messages point at (column - 1).
        assert_eq!(at("a:=1;"), 4);
        assert_eq!(at("a:=1 a:=2"), 5);
        assert_eq!(at("1 + "), 4);
        assert_eq!(at("a:= !true || -1 < 0"), 13);
        assert_eq!(at("a:= -1 < 0 || !true"), 14);
        assert_eq!(at("a:= !true + 1"), 10);
        assert_eq!(at("x := (!f ? -1 : -x)"), 16);
        assert_eq!(at("a := 'open"), 5);
        // `~ & | ^` are `!`'s group: they do not mix with `- + * /` (4.8.2 refuses each
        // of these at load).
        for s in [
            "a := 1 + 2 & 3",
            "a := 1 & 2 + 3",
            "a := -1 & 3",
            "a := ~-1",
            "a := -~1",
            "a := ~1 == -2",
        ] {
            assert!(check(s).is_err(), "{s}");
        }
        for s in [
            "a := !1 & 1",
            "a := ~ ~ 5",
            "a := (1 + 2) & 3",
            "a := 6 & 3 == 2",
            "a := 3 && 1 & 1",
        ] {
            assert_eq!(check(s), Ok(()), "{s}");
        }
    }

    #[test]
    fn joins_group_as_btcpp_does() {
        // 4.8.2 refuses each of these at load: `..` mixes with no other operator group.
        for s in [
            "s := 'a' .. 1 + 2",
            "s := 1 + 2 .. 'a'",
            "s := 'a' .. -3",
            "s := -'a' .. 'b'",
            "s := 'a' .. !1",
            "s := 'a' .. 1 & 3",
            "s := 'a' .. 'b' | 'c'",
            "s := 'a' .. 'b' + 'c'",
            "s := 'a' + 'b' .. 'c'",
            "s := 'a' ... 'b'",
        ] {
            assert!(check(s).is_err(), "{s}");
        }
        for s in [
            "s := 'a'..'b'",
            "s := 'a' .. (1 + 2)",
            "s := 'a' .. (-3)",
            "s := 'a' .. 'b' == 'ab' && true",
            "s := true ? 'a' .. 'b' : 'c'",
        ] {
            assert_eq!(check(s), Ok(()), "{s}");
        }
        // Left to right (4.8.2: `1 .. 2 .. 'a'` throws, `1 .. 2` having no value), and
        // tighter than the comparisons.
        let s = parse("1 .. 2 .. 'a' == 'x'").unwrap();
        let K::Cmp(xs, _) = &s[0].e.k else {
            panic!("a comparison")
        };
        assert!(matches!(&xs[0].k, K::Bin("..", l, _) if matches!(l.k, K::Bin("..", ..))));
    }

    #[test]
    fn bit_operators_group_as_btcpp_does() {
        // 4.8.2: `1 | 2 & 4` is 1 (`&` tighter), `1 | 1 ^ 1` is 0 (one level, left).
        let s = parse("1 | 2 & 4").unwrap();
        assert!(matches!(&s[0].e.k, K::Bin("|", _, r) if matches!(r.k, K::Bin("&", ..))));
        let s = parse("1 | 1 ^ 1").unwrap();
        assert!(matches!(&s[0].e.k, K::Bin("^", l, _) if matches!(l.k, K::Bin("|", ..))));
    }

    #[test]
    fn and_and_or_are_one_level_read_left_to_right() {
        // BT.CPP 4.8.2: `true || false && false` is false, so it reads
        // `(true || false) && false`.
        let s = parse("a := true || false && false").unwrap();
        let K::Bin("&&", l, _) = &s[0].e.k else {
            panic!("{:?}", s[0].e)
        };
        assert!(matches!(l.k, K::Bin("||", ..)));
        assert_eq!(s[0].assign.as_ref().map(|a| a.1), Some(":="));
        // Comparisons chain; `?:` does not ("operator cannot be chained", at the second
        // `?`).
        let s = parse("1 < x <= 3").unwrap();
        assert!(matches!(&s[0].e.k, K::Cmp(xs, ops) if xs.len() == 3 && ops == &["<", "<="]));
        assert_eq!(at("x := 2 ? 3 : 4 ? 5 : 6"), 15);
        assert_eq!(names("y := x + 1; f = !g"), ["y", "x", "f", "g"]);
        // `-` groups to the right: `a - b - c` is `a - (b - c)`.
        let s = parse("10 - 4 - 2").unwrap();
        let K::Bin("-", l, r) = &s[0].e.k else {
            panic!("{:?}", s[0].e)
        };
        assert_eq!(l.k, K::Int(10));
        assert!(matches!(&r.k, K::Bin("-", a, b) if a.k == K::Int(4) && b.k == K::Int(2)));
    }
}
