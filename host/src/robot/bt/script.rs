//! The syntax of BehaviorTree.CPP 4's script language (the `code` of `Script` and
//! `ScriptCondition`, Precondition's `if`, the `_skipIf` ... `_post` attributes), checked
//! where a tree is read so that a malformed script is an error at its attribute.
//!
//! The grammar, from BT.CPP 4 (`src/script_parser.cpp`, `Grammar::stmt` and
//! `Grammar::Expression`; `include/behaviortree_cpp/scripting/operators.hpp`) and as the
//! real library 4.8.2 parses it (`tests/tests/bt_real.rs` holds the oracle's own reader
//! to it): statements separated by `;` (no trailing `;`); a statement is `name` followed
//! by one of `:= = += -= *= /=` and an expression, or an expression; expressions have
//! `? :`, `|| &&`, comparisons, `| & ^`, `+ -`, `* /`, the prefixes `- ! ~`, parentheses,
//! numbers, `'strings'`, `true`, `false` and names. `!` does not mix with the arithmetic
//! operators in one expression ("operator cannot be mixed with previous operators");
//! parentheses and the middle part of `c ? a : b` start a new one.
//!
//! hindsight has no model of the language yet: AS2FM has none, and the BT.CPP semantics
//! (`--bt btcpp`) does not lower scripts; [`check`] only finds syntax errors.

/// A syntax error: the byte offset in the script (from 0) and what is wrong.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct SyntaxError {
    /// Byte offset of the token where parsing stopped.
    pub at: usize,
    /// What was expected or refused.
    pub what: String,
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
    Str,
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
            while i < b.len() && (b[i].is_ascii_alphanumeric() || b[i] == b'.') {
                i += 1;
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
            out.push((T::Str, start));
        } else if c.is_ascii_alphabetic() || c == b'_' {
            while i < b.len() && (b[i].is_ascii_alphanumeric() || b[i] == b'_') {
                i += 1;
            }
            out.push((T::Name(&s[start..i]), start));
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

/// The precedence levels of the binary operators, loosest first.
const LEVELS: [&[&str]; 6] = [
    &["||", "&&"],
    &["==", "!=", "<", "<=", ">", ">="],
    &["|", "&", "^"],
    &["+", "-"],
    &["*", "/"],
    &[],
];

struct Parser<'s> {
    toks: Vec<(T<'s>, usize)>,
    pos: usize,
    end: usize,
    /// Per open expression: it has a `!`; it has an arithmetic operator.
    open: Vec<[bool; 2]>,
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

    /// Records an operator of group 0 (`!`) or 1 (arithmetic) at the current token.
    fn note(&mut self, group: usize) -> Result<(), SyntaxError> {
        let g = self.open.last_mut().expect("an open expression");
        g[group] = true;
        if g[1 - group] {
            return self.fail("operator cannot be mixed with previous operators");
        }
        Ok(())
    }

    fn statement(&mut self) -> Result<(), SyntaxError> {
        if let (Some((T::Name(_), _)), Some((T::Sym(op), _))) =
            (self.toks.get(self.pos), self.toks.get(self.pos + 1))
        {
            if [":=", "=", "+=", "-=", "*=", "/="].contains(op) {
                self.pos += 2;
            }
        }
        self.expression()
    }

    fn expression(&mut self) -> Result<(), SyntaxError> {
        self.open.push([false; 2]);
        let r = self.expression_rest();
        self.open.pop();
        r
    }

    /// `binary(0) [? expression : expression_rest]`, in the open expression.
    fn expression_rest(&mut self) -> Result<(), SyntaxError> {
        self.binary(0)?;
        if self.next_is("?") {
            self.pos += 1;
            self.expression()?;
            if !self.next_is(":") {
                return self.fail("expected `:`");
            }
            self.pos += 1;
            self.expression_rest()?;
        }
        Ok(())
    }

    fn binary(&mut self, level: usize) -> Result<(), SyntaxError> {
        if LEVELS[level].is_empty() {
            return self.prefix();
        }
        self.binary(level + 1)?;
        while let Some((T::Sym(op), _)) = self.toks.get(self.pos) {
            if !LEVELS[level].contains(op) {
                break;
            }
            if level >= 3 {
                self.note(1)?;
            }
            self.pos += 1;
            self.binary(level + 1)?;
        }
        Ok(())
    }

    fn prefix(&mut self) -> Result<(), SyntaxError> {
        match self.toks.get(self.pos).map(|t| t.0) {
            Some(T::Sym(op @ ("-" | "!" | "~"))) => {
                self.note(usize::from(op != "!"))?;
                self.pos += 1;
                self.prefix()
            }
            Some(T::Num | T::Str | T::Name(_)) => {
                self.pos += 1;
                Ok(())
            }
            Some(T::Sym("(")) => {
                self.pos += 1;
                self.expression()?;
                if !self.next_is(")") {
                    return self.fail("expected `)`");
                }
                self.pos += 1;
                Ok(())
            }
            _ => self.fail("expected an operand"),
        }
    }
}

/// Checks a script's syntax.
pub(crate) fn check(script: &str) -> Result<(), SyntaxError> {
    let mut p = Parser {
        toks: tokens(script)?,
        pos: 0,
        end: script.len(),
        open: Vec::new(),
    };
    p.statement()?;
    while p.next_is(";") {
        if p.pos + 1 == p.toks.len() {
            return p.fail("unexpected trailing `;`");
        }
        p.pos += 1;
        p.statement()?;
    }
    if p.pos < p.toks.len() {
        return p.fail("expected `;`");
    }
    Ok(())
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

/// For a pre/post-condition attribute (`_skipIf`, ...): `Ok(refusal)` for a well-formed
/// script (not modelled), `Err(syntax error)` for a malformed one; `None` for another
/// attribute.
pub(crate) fn condition_error(attr: &str, value: &str) -> Option<Result<String, String>> {
    if !CONDITION_ATTRS.contains(&attr) {
        return None;
    }
    Some(match check(value) {
        Ok(()) => Ok(format!(
            "`{attr}` (a BehaviorTree.CPP 4 pre/post condition) is not supported: AS2FM has no \
             model of BT.CPP's script language, and the BT.CPP semantics (`--bt btcpp`) does \
             not lower scripts yet"
        )),
        Err(e) => Err(format!(
            "`{attr}`: script syntax error at column {} of the script: {}",
            e.at + 1,
            e.what
        )),
    })
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
            "A := 42; B := 3.14",
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
    }
}
