//! The oracle's own reading of BehaviorTree.CPP 4's script language (`Script`,
//! `ScriptCondition`, `Precondition`, the `_skipIf` ... `_post` attributes) over integer
//! and boolean blackboard entries: a parser and an evaluator written from the language's
//! rules, independently of hindsight's lowering.
//!
//! The rules, as BT.CPP 4 states them (`src/script_parser.cpp`, the grammar `Grammar::stmt`
//! / `Grammar::Expression`; `include/behaviortree_cpp/scripting/operators.hpp`, the
//! `Ast::Expr*::evaluate` functions) and as the real library (4.8.2, the real-library
//! differential `tests/tests/bt_real.rs`) answers them:
//! - a script is statements separated by `;` (a trailing `;` is a syntax error); its value
//!   is the last statement's;
//! - a statement is an assignment `name := e` (creates the entry), `name = e` (the entry
//!   must exist: "doesn't exist, yet"), `name += e`, `-=`, `*=`, or an expression;
//! - precedence, loosest first: `? :` (not chained; its condition is true for any number
//!   but 0), `&&` and `||` (one level, left to right: `true || false && false` is false),
//!   comparisons (`== != < <= > >=`; a
//!   chain `a < b < c` means `a < b && b < c`), `+ -`, `*`, unary `- !`; `+ -` and `*`
//!   group to the right (4.8.2: `10 - 4 - 2` is 8, `1 - 1 + 1` is -1);
//! - `true`/`false` are the numbers 1 and 0 in arithmetic (`-true` is -1, `a:=1; a+=true`
//!   gives 2); comparisons give a boolean; `!x` is `x == 0` for any number;
//! - `&&`/`||` refuse an operand other than 0 or 1 ("Logic operators are not allowed if one
//!   of the operands is not castable to bool"), and a condition (`ScriptCondition`, a
//!   pre-condition) whose value is another number throws "Implicit casting to bool is not
//!   allowed" (`Any::cast<bool>`; 4.8.2 says "Value is negative and can't be converted to
//!   unsigned" for a negative one);
//! - reading a missing entry throws "Variable not found";
//! - `!` does not mix with the arithmetic operators (unary `-`, `+`, `-`, `*`) in one
//!   expression: BT.CPP's grammar puts them in different operator groups (lexy's
//!   `dsl::groups`), and `!f || x > -1` is a syntax error ("operator cannot be mixed with
//!   previous operators") where `!f || (x > -1)` and `x + 1 > y || f` are not. Parentheses
//!   and the `a` of `c ? a : b` start a new expression; `b` continues `c`'s (`!f ? -1 : 2`
//!   is a script, `!f ? 1 : -x` is not).
//!
//! An entry a SetBlackboard wrote holds a string (BT.CPP 4 stores SetBlackboard's value as
//! text), which scripts read ([`Texts`]): compared with a number it is read as one (the
//! text `3` equals 3; `abc` throws "Any failed string to number conversion"), two strings
//! compare as strings, `c ? a : b` reads it as a number, and the arithmetic and logic
//! operators, `-`, `!` and a condition's cast to bool throw (4.8.2's answers). Strings
//! join ([`join`]): `a .. b` over two strings or a string and a number, `+` of two
//! strings and `+=` on an entry holding a string; `..` is an operator group of its own.
//!
//! Values are `int64_t` or `double` as in BT.CPP ([`V::Num`], [`V::Dbl`]): every operator
//! computes in doubles and gives one (4.10 `scripting/operators.hpp`), `/` included
//! (`1/0` is inf, `0/0` NaN), with `==` within `f32::EPSILON` and each ordering the
//! negation of its opposite ([`compare`]); an entry keeps the type of its first value
//! ([`Env`]); a cast to bool ([`truth`]) takes an integer 0 or 1 and a double that is not
//! negative. A double that is not whole stored in an entry is outside the oracle's
//! subset (into an integer entry it throws, as BT.CPP does). `%` (not in the language),
//! string literals and the bit operators are outside the subset: the parser refuses
//! them.

use std::collections::{BTreeMap, BTreeSet};

/// An expression of the subset.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Expr {
    /// An integer literal, or `true` (1) / `false` (0): an `int64_t` in BT.CPP.
    Num(i64),
    /// A real literal (`2.5`, `1e3`): a `double` in BT.CPP; the bits of the `f64` (so
    /// that expressions compare with `Eq`).
    Real(u64),
    /// A blackboard entry.
    Var(String),
    /// `-e`.
    Neg(Box<Expr>),
    /// `!e`.
    Not(Box<Expr>),
    /// `a + b`, `a - b`, `a * b`, `a / b`.
    Arith(char, Box<Expr>, Box<Expr>),
    /// A comparison chain: operands and the operators between them.
    Cmp(Vec<Expr>, Vec<&'static str>),
    /// `a && b` (`true`) or `a || b` (`false`).
    Logic(bool, Box<Expr>, Box<Expr>),
    /// `c ? a : b`.
    Ite(Box<Expr>, Box<Expr>, Box<Expr>),
    /// `~e` ([`bits`]).
    BitNot(Box<Expr>),
    /// `a & b`, `a | b`, `a ^ b` ([`bits`]).
    Bit(char, Box<Expr>, Box<Expr>),
    /// `name op e` with op one of `:=`, `=`, `+=`, `-=`, `*=`, `/=`.
    Assign(String, &'static str, Box<Expr>),
    /// A `'string'` literal: its text.
    Str(String),
    /// `a .. b` ([`join`]).
    Join(Box<Expr>, Box<Expr>),
}

/// A parsed script: its statements.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Program(pub Vec<Expr>);

/// Why a script stopped: BT.CPP throws (`text` is part of its message), or the case is
/// outside what the oracle knows.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Fault {
    /// BT.CPP throws an exception whose message contains this.
    Throws(String),
    /// Not modelled (an overflow, an entry of another type).
    Model(String),
}

#[derive(Clone, Debug, PartialEq)]
enum Tok {
    Num(i64),
    Str(String),
    Real(f64),
    Id(String),
    Op(&'static str),
}

const OPS: [&str; 28] = [
    "..", ":=", "+=", "-=", "*=", "/=", "==", "!=", "<=", ">=", "&&", "||", "=", "<", ">", "+",
    "-", "*", "/", "!", "(", ")", "?", ":", "~", "&", "|", "^",
];

/// A number literal at `s` (BT.CPP 4's `Grammar::Real` and `Grammar::Integer` in
/// `scripting/any_types.hpp`: digits, then `.digits` with an optional exponent, or an
/// exponent, make a `double` read by `std::stod`; digits alone an `int64_t`; a `.` or a
/// letter right after either is an error, so `1.` and `1.5e` are refused, as 4.8.2
/// refuses them). Hexadecimal integers are outside the oracle's subset.
fn number(src: &str, s: usize) -> Result<(Tok, usize), String> {
    let b = src.as_bytes();
    let digits = |mut i: usize| {
        while i < b.len() && b[i].is_ascii_digit() {
            i += 1;
        }
        i
    };
    let mut i = digits(s);
    let int_end = i;
    if i + 1 < b.len() && b[i] == b'.' && b[i + 1].is_ascii_digit() {
        i = digits(i + 1);
    }
    if i < b.len() && (b[i] == b'e' || b[i] == b'E') {
        let mut j = i + 1;
        if j < b.len() && (b[j] == b'+' || b[j] == b'-') {
            j += 1;
        }
        if j < b.len() && b[j].is_ascii_digit() {
            i = digits(j);
        }
    }
    if i < b.len() && (b[i] == b'.' || b[i].is_ascii_alphabetic() || b[i] == b'_') {
        return Err(format!(
            "column {}: invalid suffix on a number literal",
            s + 1
        ));
    }
    if i == int_end {
        let v = src[s..i]
            .parse()
            .map_err(|_| format!("column {}: number too large", s + 1))?;
        return Ok((Tok::Num(v), i));
    }
    // `std::stod` throws `out_of_range` where the value overflows or underflows (4.8.2:
    // `1e400` and `1e-400` fail at load).
    let v: f64 = src[s..i].parse().expect("a real literal");
    let zero = src[s..i]
        .split(['e', 'E'])
        .next()
        .is_some_and(|m| m.bytes().all(|c| c == b'0' || c == b'.'));
    if !v.is_finite() || (!v.is_normal() && !zero) {
        return Err(format!("column {}: number out of range", s + 1));
    }
    Ok((Tok::Real(v), i))
}

fn lex(src: &str) -> Result<Vec<(Tok, usize)>, String> {
    let b = src.as_bytes();
    let mut i = 0;
    let mut out = Vec::new();
    while i < b.len() {
        let c = b[i];
        if c.is_ascii_whitespace() {
            i += 1;
        } else if c == b';' {
            out.push((Tok::Op(";"), i));
            i += 1;
        } else if c.is_ascii_digit() {
            let s = i;
            let (t, end) = number(src, s)?;
            i = end;
            out.push((t, s));
        } else if c == b'\'' {
            // A string literal: everything up to the next `'` (BT.CPP 4
            // `Grammar::StringLiteral`).
            let s = i;
            let end = src[s + 1..]
                .find('\'')
                .ok_or(format!("column {}: unterminated string", s + 1))?;
            out.push((Tok::Str(src[s + 1..s + 1 + end].to_string()), s));
            i = s + end + 2;
        } else if c.is_ascii_alphabetic() || c == b'_' {
            let s = i;
            while i < b.len() && (b[i].is_ascii_alphanumeric() || b[i] == b'_') {
                i += 1;
            }
            out.push((Tok::Id(src[s..i].to_string()), s));
        } else if let Some(op) = OPS.iter().find(|o| src[i..].starts_with(**o)) {
            out.push((Tok::Op(op), i));
            i += op.len();
        } else {
            return Err(format!(
                "column {}: `{}` is not in the script subset",
                i + 1,
                src[i..].chars().next().unwrap_or(' ')
            ));
        }
    }
    Ok(out)
}

struct P {
    toks: Vec<(Tok, usize)>,
    at: usize,
    len: usize,
    /// Per open expression: whether it has a `!` (or a bit operator), an arithmetic
    /// operator, `..`.
    groups: Vec<[bool; 3]>,
}

impl P {
    fn peek(&self) -> Option<&Tok> {
        self.toks.get(self.at).map(|t| &t.0)
    }
    fn col(&self) -> usize {
        self.toks.get(self.at).map_or(self.len, |t| t.1) + 1
    }
    fn eat(&mut self, op: &str) -> bool {
        let hit = matches!(self.peek(), Some(Tok::Op(o)) if *o == op);
        self.at += usize::from(hit);
        hit
    }
    /// Notes an operator of the group `!` (`not`) or arithmetic at the token just
    /// eaten; mixing the two in one expression is a syntax error there.
    fn group(&mut self, not: bool) -> Result<(), String> {
        self.group_of(usize::from(!not))
    }

    /// Notes an operator of group `k` (0: `!`, `~` and the bit operators, 1: the
    /// arithmetic ones, 2: `..`) at the token just eaten; an expression holds one group
    /// only (BT.CPP's `dsl::groups`; 4.8.2 refuses `'a' .. 1 + 2`, `'a' .. -3`,
    /// `'a' .. 1 & 3` at load).
    fn group_of(&mut self, k: usize) -> Result<(), String> {
        let g = self.groups.last_mut().expect("inside an expression");
        let clash = (0..3).any(|o| o != k && g[o]);
        g[k] = true;
        if clash {
            self.at -= 1;
            return self.err("operator cannot be mixed with previous operators");
        }
        Ok(())
    }

    fn err<T>(&self, what: &str) -> Result<T, String> {
        Err(format!("column {}: {what}", self.col()))
    }

    fn stmt(&mut self) -> Result<Expr, String> {
        if let (Some(Tok::Id(name)), Some((Tok::Op(op), _))) =
            (self.peek().cloned(), self.toks.get(self.at + 1))
        {
            if matches!(*op, ":=" | "=" | "+=" | "-=" | "*=" | "/=") {
                let op = *op;
                self.at += 2;
                let e = self.expr()?;
                return Ok(Expr::Assign(name, op, Box::new(e)));
            }
        }
        self.expr()
    }

    fn expr(&mut self) -> Result<Expr, String> {
        self.groups.push([false; 3]);
        let r = self.expr_in();
        self.groups.pop();
        r
    }

    fn expr_in(&mut self) -> Result<Expr, String> {
        let c = self.or()?;
        if self.eat("?") {
            let a = self.expr()?;
            if !self.eat(":") {
                return self.err("expected ':'");
            }
            // The else part continues the condition's expression (its operator groups).
            let b = self.expr_in()?;
            return Ok(Expr::Ite(Box::new(c), Box::new(a), Box::new(b)));
        }
        Ok(c)
    }

    /// `&&` and `||`: one level, read left to right (BT.CPP 4's grammar has them in one
    /// left-associative infix operation, so `true || false && false` is
    /// `(true || false) && false`, false; checked against 4.8.2 by
    /// `script_operators_agree_with_the_library` in `tests/tests/bt_real.rs`).
    fn or(&mut self) -> Result<Expr, String> {
        let mut a = self.cmp()?;
        loop {
            let and = if self.eat("&&") {
                true
            } else if self.eat("||") {
                false
            } else {
                return Ok(a);
            };
            let b = self.cmp()?;
            a = Expr::Logic(and, Box::new(a), Box::new(b));
        }
    }

    fn cmp(&mut self) -> Result<Expr, String> {
        let first = self.join()?;
        let mut xs = vec![first];
        let mut ops = Vec::new();
        while let Some(Tok::Op(op @ ("==" | "!=" | "<" | "<=" | ">" | ">="))) = self.peek() {
            ops.push(*op);
            self.at += 1;
            xs.push(self.join()?);
        }
        Ok(if ops.is_empty() {
            xs.pop().expect("one operand")
        } else {
            Expr::Cmp(xs, ops)
        })
    }

    /// `..`: tighter than the comparisons, grouped to the left, an operator group of its
    /// own (BT.CPP 4.10 `Grammar::Expression`, `string_concat`; 4.8.2: `1 .. 2 .. 'a'`
    /// throws, as `1 .. 2` has no value, and `'a' .. 'b' == 'ab'` holds).
    fn join(&mut self) -> Result<Expr, String> {
        let mut a = self.bit_or()?;
        while self.eat("..") {
            self.group_of(2)?;
            let b = self.bit_or()?;
            a = Expr::Join(Box::new(a), Box::new(b));
        }
        Ok(a)
    }

    /// `|` and `^`: one level, grouped to the left, looser than `&` (BT.CPP 4.10
    /// `Grammar::Expression`, `bit_or` over `bit_and`; 4.8.2: `1 | 1 ^ 1` is 0,
    /// `1 ^ 1 | 1` is 1, `1 | 2 & 4` is 1). The bit operators are `!`'s operator group:
    /// they do not mix with the arithmetic ones (4.8.2 refuses `1 + 2 & 3` and `-1 & 3`
    /// at load).
    fn bit_or(&mut self) -> Result<Expr, String> {
        let mut a = self.bit_and()?;
        loop {
            let op = if self.eat("|") {
                '|'
            } else if self.eat("^") {
                '^'
            } else {
                return Ok(a);
            };
            self.group(true)?;
            let b = self.bit_and()?;
            a = Expr::Bit(op, Box::new(a), Box::new(b));
        }
    }

    /// `&`, grouped to the left.
    fn bit_and(&mut self) -> Result<Expr, String> {
        let mut a = self.add()?;
        while self.eat("&") {
            self.group(true)?;
            let b = self.add()?;
            a = Expr::Bit('&', Box::new(a), Box::new(b));
        }
        Ok(a)
    }

    /// `+` and `-`, grouped to the right: BT.CPP 4.8.2 computes `10 - 4 - 2` as
    /// `10 - (4 - 2)`, 8, and `1 - 1 + 1` as -1 (checked by
    /// `script_operators_agree_with_the_library` in `tests/tests/bt_real.rs`).
    fn add(&mut self) -> Result<Expr, String> {
        let a = self.mul()?;
        let op = if self.eat("+") {
            '+'
        } else if self.eat("-") {
            '-'
        } else {
            return Ok(a);
        };
        self.group(false)?;
        let b = self.add()?;
        Ok(Expr::Arith(op, Box::new(a), Box::new(b)))
    }

    /// `*` and `/`, grouped to the right as `+` and `-` are (4.8.2: `12 / 2 / 3` is 18,
    /// `7 / 2 * 2` is 1.75).
    fn mul(&mut self) -> Result<Expr, String> {
        let a = self.unary()?;
        let op = if self.eat("*") {
            '*'
        } else if self.eat("/") {
            '/'
        } else {
            return Ok(a);
        };
        self.group(false)?;
        let b = self.mul()?;
        Ok(Expr::Arith(op, Box::new(a), Box::new(b)))
    }

    fn unary(&mut self) -> Result<Expr, String> {
        if self.eat("~") {
            self.group(true)?;
            return Ok(Expr::BitNot(Box::new(self.unary()?)));
        }
        if self.eat("-") {
            self.group(false)?;
            return Ok(Expr::Neg(Box::new(self.unary()?)));
        }
        if self.eat("!") {
            self.group(true)?;
            return Ok(Expr::Not(Box::new(self.unary()?)));
        }
        match self.peek().cloned() {
            Some(Tok::Num(v)) => {
                self.at += 1;
                Ok(Expr::Num(v))
            }
            Some(Tok::Real(v)) => {
                self.at += 1;
                Ok(Expr::Real(v.to_bits()))
            }
            Some(Tok::Str(t)) => {
                self.at += 1;
                Ok(Expr::Str(t))
            }
            Some(Tok::Id(id)) => {
                self.at += 1;
                Ok(match id.as_str() {
                    "true" => Expr::Num(1),
                    "false" => Expr::Num(0),
                    _ => Expr::Var(id),
                })
            }
            Some(Tok::Op("(")) => {
                self.at += 1;
                let e = self.expr()?;
                if !self.eat(")") {
                    return self.err("expected ')'");
                }
                Ok(e)
            }
            _ => self.err("expected operand"),
        }
    }
}

/// Parses a script; the error names the column (from 1) where it stopped.
pub fn parse(src: &str) -> Result<Program, String> {
    let toks = lex(src)?;
    let mut p = P {
        toks,
        at: 0,
        len: src.len(),
        groups: Vec::new(),
    };
    let mut out = vec![p.stmt()?];
    while p.eat(";") {
        if p.peek().is_none() {
            // BT.CPP points at the `;`.
            p.at -= 1;
            return p.err("unexpected trailing separator");
        }
        out.push(p.stmt()?);
    }
    if p.peek().is_some() {
        return p.err("expected ';'");
    }
    Ok(Program(out))
}

impl Expr {
    /// Renames every entry (a SubTree's remapping).
    pub fn rename(&mut self, f: &dyn Fn(&str) -> String) {
        match self {
            Expr::Num(_) | Expr::Real(_) | Expr::Str(_) => {}
            Expr::Var(v) => *v = f(v),
            Expr::Neg(a) | Expr::Not(a) | Expr::BitNot(a) => a.rename(f),
            Expr::Arith(_, a, b) | Expr::Logic(_, a, b) | Expr::Bit(_, a, b) | Expr::Join(a, b) => {
                a.rename(f);
                b.rename(f);
            }
            Expr::Cmp(xs, _) => xs.iter_mut().for_each(|x| x.rename(f)),
            Expr::Ite(c, a, b) => {
                c.rename(f);
                a.rename(f);
                b.rename(f);
            }
            Expr::Assign(v, _, e) => {
                *v = f(v);
                e.rename(f);
            }
        }
    }

    fn eval(&self, env: &mut Env<'_>, texts: &Texts) -> Result<V, Fault> {
        let num = |v: V| -> Result<f64, Fault> {
            match v {
                V::Num(n) => exact(n),
                V::Dbl(x) => Ok(x),
                V::Empty => Err(empty()),
                // An arithmetic or logic operator over a string: BT.CPP 4.8.2 throws
                // "Operation not permitted" (`+` of two strings concatenates: not in
                // the oracle's subset).
                V::Text(_) => Err(Fault::Throws("Operation not permitted".into())),
            }
        };
        // Every operator computes in `double` and gives a `double` (BT.CPP 4.10
        // `scripting/operators.hpp`: `ExprUnaryArithmetic::evaluate`,
        // `ExprBinaryArithmetic::evaluate` and `ExprComparison::evaluate` return
        // `Any(double)`); a literal integer and an `int64_t` entry stay integers.
        Ok(V::Dbl(match self {
            Expr::Num(v) => return Ok(V::Num(*v)),
            Expr::Real(bits) => f64::from_bits(*bits),
            Expr::Str(t) => return Ok(V::Text(t.clone())),
            Expr::Var(v) if env.strs.contains_key(v) => {
                if texts.contains_key(v) {
                    return Err(Fault::Model(format!(
                        "a script reads `{v}`, which both a script and a SetBlackboard wrote: not modelled"
                    )));
                }
                return Ok(V::Text(env.strs[v].clone()));
            }
            Expr::Var(v) => match (env.vals.get(v), texts.get(v)) {
                (Some(x), None) if env.dbl.contains(v) => {
                    env.reals.get(v).copied().unwrap_or(*x as f64)
                }
                (Some(x), None) => return Ok(V::Num(*x)),
                (None, Some(Some(t))) => return Ok(V::Text(t.clone())),
                (None, Some(None)) => return Ok(V::Empty),
                (None, None) => return Err(Fault::Throws(format!("Variable not found: {v}"))),
                _ => {
                    return Err(Fault::Model(format!(
                        "a script reads `{v}`, which both a script and a SetBlackboard wrote: not modelled"
                    )))
                }
            },
            Expr::Neg(a) | Expr::Not(a) => {
                let x = match a.eval(env, texts)? {
                    V::Num(x) => exact(x)?,
                    V::Dbl(x) => x,
                    // 4.8.2: "Invalid operator for std::string".
                    V::Text(_) => {
                        return Err(Fault::Throws("Invalid operator for std::string".into()))
                    }
                    V::Empty => return Err(empty()),
                };
                if matches!(self, Expr::Neg(_)) {
                    -x
                } else {
                    // `!static_cast<bool>(x)`: NaN is true, so `!(0/0)` is 0.
                    f64::from(x == 0.0)
                }
            }
            Expr::Arith(op, a, b) => {
                let (a, b) = (a.eval(env, texts)?, b.eval(env, texts)?);
                // `+` of two strings joins them (4.8.2: `'a' + 'b' == 'ab'`); the
                // other operators throw.
                if let ('+', V::Text(x), V::Text(y)) = (op, &a, &b) {
                    return Ok(V::Text(format!("{x}{y}")));
                }
                let (a, b) = (num(a)?, num(b)?);
                let r = match op {
                    '+' => a + b,
                    '-' => a - b,
                    '*' => a * b,
                    // IEEE division: `1/0` is inf, `0/0` NaN, no exception (4.8.2).
                    _ => a / b,
                };
                // Whole operands with a result past 2^53: the lowering's integers would
                // differ from doubles (not in the subset).
                if a.abs() <= LIMIT && b.abs() <= LIMIT && r.is_finite() && r.fract() == 0.0 && r.abs() > LIMIT {
                    return Err(Fault::Model("a whole number beyond 2^53 in a script".into()));
                }
                r
            }
            Expr::Cmp(xs, ops) => {
                // Each operand once, left to right; the chain holds where every pair does.
                let vals = xs
                    .iter()
                    .map(|x| x.eval(env, texts))
                    .collect::<Result<Vec<_>, _>>()?;
                if vals.contains(&V::Empty) {
                    return Err(empty());
                }
                let mut all = true;
                for (i, op) in ops.iter().enumerate() {
                    // The chain stops at the first pair that fails (4.10
                    // `ExprComparison::evaluate`; 4.8.2: `2 < 1 < 'a'` is false, `1 < 2
                    // < 'a'` throws converting `a`).
                    if !all {
                        break;
                    }
                    let as_num = |v: &V| -> Result<Option<f64>, Fault> {
                        Ok(match v {
                            V::Num(n) => Some(exact(*n)?),
                            V::Dbl(x) => Some(*x),
                            V::Text(_) | V::Empty => None,
                        })
                    };
                    all &= match (&vals[i], &vals[i + 1]) {
                        // Two strings compare as strings (4.8.2: `'abc' < 'abd'`; a
                        // SetBlackboard's `3` and `03` differ).
                        (V::Text(a), V::Text(b)) => {
                            let ord = a.cmp(b);
                            match *op {
                                "==" => ord.is_eq(),
                                "!=" => ord.is_ne(),
                                "<" => ord.is_lt(),
                                "<=" => ord.is_le(),
                                ">" => ord.is_gt(),
                                _ => ord.is_ge(),
                            }
                        }
                        // A string and a number: the string read as a number (4.8.2:
                        // the text `3` equals 3, ` 3` and `03` too; `abc` throws).
                        (l, r) => {
                            let l = match as_num(l)? {
                                Some(x) => x,
                                None => text_number(text_of(l))? as f64,
                            };
                            let r = match as_num(r)? {
                                Some(x) => x,
                                None => text_number(text_of(r))? as f64,
                            };
                            compare(op, l, r)
                        }
                    };
                }
                f64::from(all)
            }
            Expr::Logic(and, a, b) => {
                let (a, b) = (a.eval(env, texts)?, b.eval(env, texts)?);
                let cast = |v: V| -> Result<bool, Fault> {
                    match v {
                        V::Text(_) | V::Empty => num(v).map(|_| false),
                        v => truth(&v).map_err(|_| {
                            Fault::Throws(
                                "Logic operators are not allowed if one of the operands is not castable to bool".into(),
                            )
                        }),
                    }
                };
                let (a, b) = (cast(a)?, cast(b)?);
                f64::from(if *and { a && b } else { a || b })
            }
            // The condition of `c ? a : b` is true for any number but 0 (BT.CPP 4's
            // `ExprIf::evaluate` compares it with 0; unlike a node's condition it is not
            // cast to bool): `2 ? 5 : 7` and `-1 ? 5 : 7` give 5 in 4.8.2, and so does
            // `(0/0) ? 5 : 7`; a string is read as a number (the text `0` is false).
            Expr::Ite(c, a, b) => {
                let c = match c.eval(env, texts)? {
                    V::Num(c) => c != 0,
                    V::Dbl(c) => c != 0.0,
                    V::Text(t) => text_number(&t)? != 0,
                    // 4.8.2's message here.
                    V::Empty => {
                        return Err(Fault::Throws(
                            "Any::cast failed because it is empty".into(),
                        ))
                    }
                };
                return if c {
                    a.eval(env, texts)
                } else {
                    b.eval(env, texts)
                };
            }
            Expr::BitNot(_) | Expr::Bit(..) => return bits(self, env, texts),
            Expr::Join(a, b) => {
                let (a, b) = (a.eval(env, texts)?, b.eval(env, texts)?);
                return join(a, b);
            }
            Expr::Assign(v, op, e) => return assign(v, op, e, env, texts),
        }))
    }
}

/// 2^53: up to it every whole number is exact in a `double`.
const LIMIT: f64 = 9_007_199_254_740_992.0;

/// An integer read as a `double` (`Any::cast<double>`, which 4.8.2 refuses past 2^53:
/// "Loss of precision"; outside the oracle's subset).
fn exact(n: i64) -> Result<f64, Fault> {
    if n.unsigned_abs() > 1 << 53 {
        return Err(Fault::Model("an integer beyond 2^53 in arithmetic".into()));
    }
    Ok(n as f64)
}

fn text_of(v: &V) -> &str {
    match v {
        V::Text(t) => t,
        _ => "",
    }
}

/// A comparison of two numbers as BT.CPP 4.10 makes it (`scripting/operators.hpp`,
/// `ExprComparison::evaluate` and `IsSame`): `==` within single precision's epsilon, and
/// each ordering as the negation of its opposite, so that NaN is `<`, `>`, `<=` and `>=`
/// anything (4.8.2: `(0/0) < 1` and `(0/0) >= 1` are both true).
#[allow(clippy::neg_cmp_op_on_partial_ord)] // the negations are BT.CPP's rule for NaN
pub fn compare(op: &str, l: f64, r: f64) -> bool {
    let same = (l - r).abs() <= f64::from(f32::EPSILON);
    match op {
        "==" => same,
        "!=" => !same,
        "<" => !(l >= r),
        "<=" => !(l > r),
        ">" => !(l <= r),
        _ => !(l < r),
    }
}

/// The entries scripts write: the values (booleans as 0 and 1) and which of them hold a
/// `double` (an entry a script created from a `double`, `x := 1 + 1`, keeps that type:
/// BT.CPP 4.10 `ExprAssignment::evaluate` stores the first value as it is and converts
/// the later ones to its type with `Any::copyInto`).
pub struct Env<'a> {
    /// The values.
    pub vals: &'a mut BTreeMap<String, i64>,
    /// The entries holding a `double`.
    pub dbl: &'a mut BTreeSet<String>,
    /// The exact value of each entry holding a `double` (its sign of zero, its fraction,
    /// NaN, infinities); `vals` holds it truncated (0 for NaN).
    pub reals: &'a mut BTreeMap<String, f64>,
    /// The entries holding a string (created from one).
    pub strs: &'a mut BTreeMap<String, String>,
}

/// `v op e`, as BT.CPP 4.10 `ExprAssignment::evaluate` makes it.
fn assign(v: &str, op: &str, e: &Expr, env: &mut Env<'_>, texts: &Texts) -> Result<V, Fault> {
    if texts.contains_key(v) {
        return Err(Fault::Model(format!(
            "a script writes `{v}`, which a SetBlackboard writes: not modelled"
        )));
    }
    let x = match e.eval(env, texts)? {
        V::Empty => {
            return Err(Fault::Model(format!(
                "a script copies an empty entry into `{v}`: not modelled"
            )))
        }
        x => x,
    };
    // Strings (BT.CPP 4.10 `ExprAssignment::evaluate`, and 4.8.2 as measured): an entry
    // created from a string holds strings; a number assigned to it throws, and so do
    // `-=`, `*=`, `/=` with a string and `+=` of a number to it; `+=` of two strings
    // joins them (not in the subset). A string assigned to a number entry is converted
    // (not in the subset); `+=` of one throws ("Any::copyInto fails").
    let holds_text = env.strs.contains_key(v);
    match (&x, holds_text, op) {
        (V::Text(t), false, ":=") if !env.vals.contains_key(v) => {
            env.strs.insert(v.to_string(), t.clone());
            return Ok(x);
        }
        (V::Text(t), true, ":=" | "=") => {
            env.strs.insert(v.to_string(), t.clone());
            return Ok(x);
        }
        // `+=` of two strings joins them (4.8.2: `s := 'a'; s += 'b'` holds `ab`).
        (V::Text(t), true, "+=") => {
            let joined = format!("{}{t}", env.strs[v]);
            env.strs.insert(v.to_string(), joined.clone());
            return Ok(V::Text(joined));
        }
        (V::Text(_), false, ":=" | "=") => {
            return Err(Fault::Model(format!(
                "a string assigned to `{v}`, which holds a number"
            )))
        }
        (V::Text(_), false, "+=") => return Err(Fault::Throws("Any::copyInto fails".into())),
        (V::Text(_), _, _) => {
            return Err(Fault::Throws("Operator not supported for strings".into()))
        }
        (_, true, ":=" | "=") => {
            return Err(Fault::Throws(format!(
                "Error assigning a value to entry [{v}] with type [std::string]"
            )))
        }
        (_, true, _) => {
            return Err(Fault::Throws(
                "This Assignment operator can't be used with a non-numeric type".into(),
            ))
        }
        _ => {}
    }
    let old = env.vals.get(v).copied();
    // The value to store, and whether it is a `double`.
    let (new, dbl) = match (op, old) {
        // The first value goes in as it is.
        (":=", None) => match x {
            V::Num(n) => (V::Num(n), false),
            x => (x, true),
        },
        (_, None) => {
            return Err(Fault::Throws(format!(
                "The blackboard entry [{v}] doesn't exist"
            )))
        }
        (":=" | "=", Some(_)) => (x, env.dbl.contains(v)),
        (_, Some(o)) => {
            let o = if env.dbl.contains(v) {
                env.reals.get(v).copied().unwrap_or(o as f64)
            } else {
                exact(o)?
            };
            let r = match x {
                V::Num(n) => exact(n)?,
                V::Dbl(r) => r,
                _ => unreachable!("refused above"),
            };
            let t = match op {
                "+=" => o + r,
                "-=" => o - r,
                "*=" => o * r,
                _ => o / r,
            };
            (V::Dbl(t), env.dbl.contains(v))
        }
    };
    // `Any::copyInto` an `int64_t` entry: a `double` with a fraction, NaN or infinite
    // throws (4.8.2: "Invalid floating point to integer conversion" for `x:=5; x/=2`).
    let stored = match new {
        V::Num(n) => n,
        // A `double` entry holds any double, exactly (4.8.2: `a := 5/2` holds 2.5,
        // `a := 1.5; a := 7/2` 3.5, `a := 0+0; a /= 0` NaN, `a := 0+0; a := -a` -0.0).
        V::Dbl(r) if dbl => {
            env.vals.insert(v.to_string(), r as i64);
            env.dbl.insert(v.to_string());
            env.reals.insert(v.to_string(), r);
            return Ok(V::Dbl(r));
        }
        V::Dbl(r) if r.is_finite() && r.fract() == 0.0 && r.abs() <= LIMIT => r as i64,
        V::Dbl(r) if r.is_finite() && r.fract() == 0.0 => {
            return Err(Fault::Model(format!(
                "a whole number beyond 2^53 stored in `{v}`"
            )))
        }
        // 4.8.2: `=` and `:=` say "Error assigning a value to entry [a] with type
        // [long]. The right operand has type [double] and can't be converted to [long]"
        // (`a := 1; a := 5/2`), `+=` ... `/=` "Invalid floating point to integer
        // conversion" (`a := 1; a /= 2`).
        V::Dbl(_) if matches!(op, ":=" | "=") => {
            return Err(Fault::Throws(
                "The right operand has type [double] and can't be converted".into(),
            ))
        }
        V::Dbl(_) => {
            return Err(Fault::Throws(
                "Invalid floating point to integer conversion".into(),
            ))
        }
        _ => unreachable!("refused above"),
    };
    // A negative zero in a `double` entry reads back as 0: its sign shows only when
    // dividing by it, and the lowering divides by number literals only (the generator
    // writes no other divisor).
    env.vals.insert(v.to_string(), stored);
    env.reals.remove(v);
    if dbl {
        env.dbl.insert(v.to_string());
        Ok(V::Dbl(stored as f64))
    } else {
        env.dbl.remove(v);
        Ok(V::Num(stored))
    }
}

/// `a .. b` as BT.CPP 4.8.2 makes it (4.10 `scripting/operators.hpp`,
/// `ExprBinaryArithmetic::evaluate`, `concat`: two strings, or a string and a number,
/// joined with `Any::cast<std::string>`), measured through `behaviortreepy`: an
/// `int64_t` joins as its digits (`'a' .. 3` is `a3`, `'a' .. true` `a1`), a `double` as
/// `%f` (`'a' .. 1.5` is `a1.500000`, `'a' .. (1/0)` `ainf`; NaN, `-nan` or `nan` by its
/// sign, is outside the subset); two numbers give no value (4.10's source throws
/// "Operation not permitted", 4.8.2 returns an empty value that throws "not
/// initialized" where it is used: [`V::Empty`]); an operand that holds no value throws.
fn join(a: V, b: V) -> Result<V, Fault> {
    let text = |v: &V| -> Result<Option<String>, Fault> {
        Ok(match v {
            V::Text(t) => Some(t.clone()),
            V::Num(n) => Some(n.to_string()),
            V::Dbl(x) if x.is_nan() => return Err(Fault::Model("a NaN joined to a string".into())),
            V::Dbl(x) if x.is_infinite() => Some(if *x > 0.0 { "inf" } else { "-inf" }.into()),
            V::Dbl(x) => Some(format!("{x:.6}")),
            V::Empty => None,
        })
    };
    if a == V::Empty || b == V::Empty {
        return Err(Fault::Throws(
            "operand of the operator [..] is not initialized".into(),
        ));
    }
    if !matches!(a, V::Text(_)) && !matches!(b, V::Text(_)) {
        return Ok(V::Empty);
    }
    match (text(&a)?, text(&b)?) {
        (Some(x), Some(y)) => Ok(V::Text(format!("{x}{y}"))),
        _ => unreachable!("empty operands throw above"),
    }
}

/// 2^63: a double at or beyond it (in size) is out of `int64_t`'s range.
const I64_END: f64 = 9_223_372_036_854_775_808.0;

/// `~e`, `a & b`, `a | b`, `a ^ b` as BT.CPP 4.10 computes them
/// (`scripting/operators.hpp`: `ExprUnaryArithmetic::evaluate` truncates the double to
/// an `int64_t` for `complement`; `ExprBinaryArithmetic::evaluate` converts both operands
/// with `Any::cast<int64_t>` for `bit_and`, `bit_or`, `bit_xor`, throwing "Binary
/// operators are not allowed if one of the operands is not an integer"); each gives a
/// `double`. As 4.8.2 answers (measured through `behaviortreepy`): `6 & 3` is 2,
/// `(4/2) & 1` 0, `2.5 & 1`, `(0/0) & 1`, `(1/0) & 1` and `1e19 & 1` throw, `9e18 & 1`
/// is 0; `~5` is -6, `~2.5` -3, `~(-2.5)` 1, `~(0/0)` 2^63 (x86's integer for NaN,
/// complemented), `~(1/0)` and `~1e19` throw.
fn bits(e: &Expr, env: &mut Env<'_>, texts: &Texts) -> Result<V, Fault> {
    // A number as `cast<double>` reads it first (`isNumber`); a string throws.
    let number = |v: V, unary: bool| -> Result<(f64, Option<i64>), Fault> {
        match v {
            V::Num(n) => Ok((exact(n)?, Some(n))),
            V::Dbl(x) => Ok((x, None)),
            V::Empty => Err(empty()),
            V::Text(_) if unary => Err(Fault::Throws("Invalid operator for std::string".into())),
            V::Text(_) => Err(Fault::Throws("Operation not permitted".into())),
        }
    };
    let not_int = || {
        Fault::Throws(
            "Binary operators are not allowed if one of the operands is not an integer".into(),
        )
    };
    match e {
        Expr::BitNot(a) => {
            let (x, _) = number(a.eval(env, texts)?, true)?;
            if x.is_nan() {
                return Ok(V::Dbl(I64_END));
            }
            if x.abs() >= I64_END {
                return Err(Fault::Throws(
                    "Number out of range for bitwise operation".into(),
                ));
            }
            Ok(V::Dbl(!(x.trunc() as i64) as f64))
        }
        Expr::Bit(op, a, b) => {
            let (a, b) = (a.eval(env, texts)?, b.eval(env, texts)?);
            let (x, xi) = number(a, false)?;
            let (y, yi) = number(b, false)?;
            let int = |v: f64, i: Option<i64>| match i {
                Some(i) => Ok(i),
                None if v.fract() == 0.0 && v.abs() < I64_END => Ok(v as i64),
                None => Err(not_int()),
            };
            let (l, r) = (int(x, xi)?, int(y, yi)?);
            let v = match op {
                '&' => l & r,
                '|' => l | r,
                _ => l ^ r,
            };
            Ok(V::Dbl(v as f64))
        }
        _ => unreachable!("only the bit operators"),
    }
}

/// The entries a SetBlackboard wrote, as text, for scripts to read (`None`: an entry that
/// exists without a value, see [`V::Empty`]).
pub type Texts = BTreeMap<String, Option<String>>;

/// 4.8.2's exception for an operator over an entry that exists without a value.
fn empty() -> Fault {
    Fault::Throws("is not initialized".into())
}

/// A script value: an integer (booleans as 0 and 1), a `double`, or the text of an
/// entry a SetBlackboard wrote (BT.CPP 4 stores SetBlackboard's value as a string).
#[derive(Clone, Debug, PartialEq)]
pub enum V {
    /// An `int64_t`: a literal, or an entry that holds one.
    Num(i64),
    /// A `double`: what every operator gives, a real literal, an entry that holds one.
    Dbl(f64),
    /// A string.
    Text(String),
    /// An entry that exists but holds no value: one a SetBlackboard `value` port names
    /// (`{k}`; BT.CPP 4.8.2 creates it at load, and literal writes leave it empty) or one
    /// a failed SetBlackboard copy created. An operator over it throws (4.8.2: "The left
    /// operand of the operator [==] is not initialized", "Any::cast failed because it
    /// is empty"); other uses are outside the oracle's subset.
    Empty,
}

/// A string read as a number where a script compares it with one (BT.CPP 4.8.2 reads
/// the SetBlackboard texts `3`, ` 3` and `03` as 3, and throws "Any failed string to
/// number conversion" for `abc`); texts that are not whole numbers are outside the
/// oracle's subset.
fn text_number(t: &str) -> Result<i64, Fault> {
    // 4.8.2 reads a prefix (`3abc` is 3, `0x10` 16, `true` 1, `nan` a NaN): only whole
    // decimal numbers with spaces around them (up to 2^53: beyond, "Loss of precision")
    // and texts that cannot begin a number are in the subset.
    let s = t.trim_matches(' ');
    let digits = s.strip_prefix(['+', '-']).unwrap_or(s);
    if !digits.is_empty() && digits.bytes().all(|c| c.is_ascii_digit()) {
        return match s.parse::<i64>() {
            Ok(n) if n.unsigned_abs() <= 1 << 53 => Ok(n),
            _ => Err(Fault::Model(format!("the text `{t}` read as a number"))),
        };
    }
    // The empty text, spaces, and letters and spaces that do not begin `inf`, `nan`,
    // `true` or `false` (4.8.2: ``, ` `, `abc`, `a b`, `e` throw).
    let words = s.bytes().all(|c| c.is_ascii_alphabetic() || c == b' ');
    match s.bytes().next().map(|c| c.to_ascii_lowercase()) {
        None => {}
        Some(c) if words && !b"intf".contains(&c) => {}
        _ => return Err(Fault::Model(format!("the text `{t}` read as a number"))),
    }
    Err(Fault::Throws(
        "Any failed string to number conversion".into(),
    ))
}

/// `Any::cast<bool>` of a script's value: an integer 0 or 1 only; a `double` is true
/// unless 0, and throws when negative (4.8.2: `ScriptCondition code="1+1"` and `"1/2"`
/// succeed, `"2"` throws "Implicit casting to bool is not allowed", `"0-1"` and
/// `"-1/2"` "Value is negative and can't be converted to unsigned", `"0/0"` succeeds);
/// a string throws (4.8.2: "no known safe conversion between [std::string] and
/// [bool]").
pub fn truth(v: &V) -> Result<bool, Fault> {
    match v {
        V::Dbl(x) if *x < 0.0 => Err(Fault::Throws(
            "Value is negative and can't be converted to unsigned".into(),
        )),
        V::Dbl(x) => Ok(*x != 0.0),
        V::Num(0) => Ok(false),
        V::Num(1) => Ok(true),
        // 4.8.2's message for a negative number (`Any::convert` through an unsigned).
        V::Num(..0) => Err(Fault::Throws(
            "Value is negative and can't be converted to unsigned".into(),
        )),
        V::Num(_) => Err(Fault::Throws(
            "Implicit casting to bool is not allowed".into(),
        )),
        V::Text(_) => Err(Fault::Throws(
            "no known safe conversion between [std::string] and [bool]".into(),
        )),
        V::Empty => Err(Fault::Model("an empty entry as a condition".into())),
    }
}

impl Program {
    /// Renames every entry.
    pub fn rename(&mut self, f: &dyn Fn(&str) -> String) {
        self.0.iter_mut().for_each(|e| e.rename(f));
    }

    /// Runs the statements in order over the entries scripts write (`env`) and the
    /// texts SetBlackboard wrote; the last one's value.
    pub fn run(&self, env: &mut Env<'_>, texts: &Texts) -> Result<V, Fault> {
        let mut last = V::Num(0);
        for s in &self.0 {
            last = s.eval(env, texts)?;
        }
        Ok(last)
    }

    /// Runs it as a condition (`cast<bool>` of its value).
    pub fn holds(&self, env: &mut Env<'_>, texts: &Texts) -> Result<bool, Fault> {
        truth(&self.run(env, texts)?)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(src: &str) -> Result<(i64, BTreeMap<String, i64>), Fault> {
        let (mut vals, mut dbl) = (BTreeMap::new(), BTreeSet::new());
        let mut env = Env {
            vals: &mut vals,
            dbl: &mut dbl,
            reals: &mut BTreeMap::new(),
            strs: &mut BTreeMap::new(),
        };
        match parse(src).expect("parses").run(&mut env, &Texts::new())? {
            V::Num(v) => Ok((v, vals)),
            V::Dbl(v) if v.fract() == 0.0 => Ok((v as i64, vals)),
            v => panic!("not a whole number: {v:?}"),
        }
    }

    /// A script's value and `Any::cast<bool>` of it, as a `ScriptCondition` reads it.
    fn cond(src: &str) -> Result<bool, Fault> {
        let (mut vals, mut dbl) = (BTreeMap::new(), BTreeSet::new());
        let mut env = Env {
            vals: &mut vals,
            dbl: &mut dbl,
            reals: &mut BTreeMap::new(),
            strs: &mut BTreeMap::new(),
        };
        parse(src).expect("parses").holds(&mut env, &Texts::new())
    }

    fn value(src: &str) -> Result<V, Fault> {
        let (mut vals, mut dbl) = (BTreeMap::new(), BTreeSet::new());
        let mut env = Env {
            vals: &mut vals,
            dbl: &mut dbl,
            reals: &mut BTreeMap::new(),
            strs: &mut BTreeMap::new(),
        };
        parse(src).expect("parses").run(&mut env, &Texts::new())
    }

    #[test]
    fn doubles_and_integers_as_the_real_library_casts_them() {
        // Each answer below is what BT.CPP 4.8.2 gave for the same `ScriptCondition`
        // or `Script` (measured through `behaviortreepy`).
        let throws = |r: Result<bool, Fault>, what: &str| {
            assert!(
                matches!(&r, Err(Fault::Throws(t)) if t.contains(what)),
                "{r:?}"
            )
        };
        // An integer literal or an entry holding one: 0 or 1 only.
        throws(cond("3"), "Implicit casting");
        throws(cond("x:=2; x"), "Implicit casting");
        throws(cond("1 ? 2 : 3"), "Implicit casting");
        // Every operator gives a double: true unless 0, negative throws.
        assert_eq!(cond("1+1"), Ok(true));
        assert_eq!(cond("3*1"), Ok(true));
        assert_eq!(cond("x:=1+1; x"), Ok(true));
        assert_eq!(cond("x:=2; x+0"), Ok(true));
        assert_eq!(cond("1 ? 2+0 : 3"), Ok(true));
        assert_eq!(cond("(1 < 2) + 1"), Ok(true));
        throws(cond("0-1"), "negative");
        throws(cond("-3+1"), "negative");
        assert_eq!(cond("5/5"), Ok(true));
        assert_eq!(cond("1/2"), Ok(true));
        assert_eq!(cond("0/2"), Ok(false));
        assert_eq!(cond("0/0"), Ok(true));
        assert_eq!(cond("1/0"), Ok(true));
        assert_eq!(cond("2.5"), Ok(true));
        assert_eq!(cond("0.0"), Ok(false));
        throws(cond("-1/2"), "negative");
        throws(cond("-(1/0)"), "negative");
        assert_eq!(cond("-(0/0)"), Ok(true));
        // `&&` / `||` cast the same way.
        assert_eq!(run("a := (1+1) && true").unwrap().0, 1);
        assert_eq!(run("x := 1+1; a := x && true").unwrap().0, 1);
        assert_eq!(run("a := (1/2) && true").unwrap().0, 1);
        assert_eq!(run("a := (0/0) || false").unwrap().0, 1);
        assert_eq!(run("a := 0.0 || 0.0").unwrap().0, 0);
        for s in [
            "a := 2 && true",
            "x := 2; a := x && true",
            "a := (0-1) && true",
        ] {
            assert!(
                matches!(run(s), Err(Fault::Throws(t)) if t.contains("Logic operators")),
                "{s}"
            );
        }
        // Comparisons of doubles: `==` within float epsilon, NaN on either side of
        // every ordering.
        for (s, v) in [
            ("a := (0/0) < 1", 1),
            ("a := (0/0) > 1", 1),
            ("a := (0/0) <= 1", 1),
            ("a := (0/0) >= 1", 1),
            ("a := (0/0) == 1", 0),
            ("a := (0/0) != 1", 1),
            ("a := (0/0) == (0/0)", 0),
            ("a := (1/0) == (1/0)", 0),
            ("a := (1/0) > 1e308", 1),
            ("a := 1/3 == 0.3333333", 1),
            ("a := 1/3 == 0.333333", 0),
            ("a := 2.5e-1 == 0.25", 1),
            ("a := 1E3 == 1000", 1),
            ("a := 1e+2 == 100", 1),
            ("a := 00.5 == 0.5", 1),
            ("a := 3 > 2.5 > 2", 1),
            ("a := !2.5", 0),
            ("a := !(0/0)", 0),
            ("a := -(1/2) < 0", 1),
            ("a := (0/0) ? 5 : 7", 5),
            ("a := (1/2) ? 5 : 7", 5),
            ("a := 12 / 2 / 3", 18),
            ("x := 1; a := x / 0 < 0", 0),
        ] {
            assert_eq!(run(s).map(|r| r.0), Ok(v), "{s}");
        }
        assert_eq!(value("a := 7 / 2 * 2"), Ok(V::Dbl(1.75)));
        assert_eq!(value("7 / 2 * 2"), Ok(V::Dbl(1.75)));
        assert_eq!(value("1 - 1 / 2"), Ok(V::Dbl(0.5)));
        // Stored into an integer entry, a double must be whole.
        assert_eq!(run("x := 6; x /= 2").unwrap().1["x"], 3);
        assert_eq!(run("x := 6; x := 6 / 2").unwrap().0, 3);
        for s in ["x := 5; x /= 2", "x := 1; x += 0.5"] {
            assert!(
                matches!(run(s), Err(Fault::Throws(t)) if t.contains("Invalid floating point")),
                "{s}"
            );
        }
        for s in ["x := 1; x := 1.5", "x := 1; x := 0/0"] {
            assert!(
                matches!(run(s), Err(Fault::Throws(t)) if t.contains("can't be converted")),
                "{s}"
            );
        }
        // ... and it stays an integer entry; one a double created stays a double one.
        throws(cond("x := 2; x := 2 / 1; x"), "Implicit casting");
        assert_eq!(cond("x := 1 + 1; x := 2; x"), Ok(true));
        // Literals BT.CPP refuses at load.
        for s in [
            "a := 1.",
            "a := 1.5e",
            "a := 1.5.2",
            "a := 1e400",
            "a := 1e-400",
        ] {
            assert!(parse(s).is_err(), "{s}");
        }
    }

    #[test]
    fn bit_operators_and_stored_reals_as_the_real_library_answers() {
        // Each answer below is what BT.CPP 4.8.2 gave for the same script (measured
        // through `behaviortreepy`): the value of `a` (`Dbl` for a double entry).
        let throws = |src: &str, what: &str| {
            assert!(
                matches!(value(src), Err(Fault::Throws(t)) if t.contains(what)),
                "{src}: {:?}",
                value(src)
            )
        };
        for (src, v) in [
            ("a := 6 & 3", 2.0),
            ("a := 6 | 3", 7.0),
            ("a := 6 ^ 3", 5.0),
            ("a := ~5", -6.0),
            ("a := ~0", -1.0),
            ("a := (4/2) & 1", 0.0),
            ("a := ~2.5", -3.0),
            ("a := ~(-2.5)", 1.0),
            ("a := ~(0/0)", 9.223372036854776e18),
            ("a := (0-2) & 7", 6.0),
            ("a := 1 | 1 ^ 1", 0.0),
            ("a := 1 ^ 1 | 1", 1.0),
            ("a := 1 | 2 & 4", 1.0),
            ("a := 6 & 3 | 8", 10.0),
            ("a := 2 & 6 ^ 4", 6.0),
            ("a := 7 & 3 ^ 1 | 8", 10.0),
            ("a := !1 & 1", 0.0),
            ("a := !0 | 2", 3.0),
            ("a := 6 & 3 == 2", 1.0),
            ("a := true & 1", 1.0),
            ("a := ~true", -2.0),
            ("a := 1e18 & 1", 0.0),
            ("a := 9e18 & 1", 0.0),
            ("a := ~ ~ 5", 5.0),
            ("a := 5/2", 2.5),
            ("a := 1.5; a /= 2", 0.75),
            ("a := 1.5; a := 3", 3.0),
            ("a := 1.5; a := 7/2", 3.5),
            ("a := 0+0; a := 1 / a", f64::INFINITY),
            ("a := 2.5; a += 1", 3.5),
            ("a := 2.5; a -= 0.5", 2.0),
            ("a := 2.5; a := true", 1.0),
            ("a := 1e308; a *= 10", f64::INFINITY),
            ("a := 0; b := 1 / -a", f64::NEG_INFINITY),
            ("a := 0; b := 1 / (0 - a)", f64::INFINITY),
            ("a := 0; b := 1 / (a * -1)", f64::NEG_INFINITY),
            ("a := 0.0; b := 1 / -a", f64::NEG_INFINITY),
            ("a := -0.0; b := 1 / a", f64::NEG_INFINITY),
            ("a := 0 * -1; b := 1 / a", f64::NEG_INFINITY),
            ("a := 0 - 0.0; b := 1 / a", f64::INFINITY),
            ("a := 0+0; a := -a; b := 1 / a", f64::NEG_INFINITY),
        ] {
            let got = match value(src) {
                Ok(V::Dbl(x)) => x,
                Ok(V::Num(n)) => n as f64,
                r => panic!("{src}: {r:?}"),
            };
            assert_eq!(got, v, "{src}");
        }
        // An integer entry stores a double converted: whole, or it throws; a negative
        // zero loses its sign there (`1 / a` is then +inf).
        assert_eq!(run("a := 0; a := -a; b := 1 / a > 0").unwrap().0, 1);
        assert_eq!(run("a := 1; a := 2 / 2").unwrap().0, 1);
        assert!(value("a := 0+0; a /= 0").is_ok_and(|v| matches!(v, V::Dbl(x) if x.is_nan())));
        for (src, what) in [
            ("a := 2.5 & 1", "Binary operators are not allowed"),
            ("a := (5/2) & 1", "Binary operators are not allowed"),
            ("a := (0/0) & 1", "Binary operators are not allowed"),
            ("a := (1/0) & 1", "Binary operators are not allowed"),
            ("a := (1e19) & 1", "Binary operators are not allowed"),
            ("a := ~(1/0)", "Number out of range for bitwise operation"),
            ("a := ~1e19", "Number out of range for bitwise operation"),
            ("a := 3 && 1 & 1", "Logic operators"),
            ("a := 1; a := 5/2", "can't be converted"),
            ("a := 1; a := 1/0", "can't be converted"),
            ("a := true; a := 2.5", "can't be converted"),
            ("a := 0; a := 1 / a", "can't be converted"),
            (
                "a := 1; a /= 2",
                "Invalid floating point to integer conversion",
            ),
            (
                "a := 1; a /= 0",
                "Invalid floating point to integer conversion",
            ),
        ] {
            throws(src, what);
        }
        // 4.8.2 refuses these at load: `-`, `+`, `*`, `/` do not mix with `~ & | ^ !`.
        for src in [
            "a := -2 & 7",
            "a := 1 + 2 & 3",
            "a := 1 & 2 + 3",
            "a := ~-1",
            "a := -~1",
            "a := ~1 == -2",
        ] {
            assert!(
                parse(src).is_err_and(|e| e.contains("cannot be mixed")),
                "{src}"
            );
        }
    }

    #[test]
    fn the_real_library_s_answers() {
        // Each answer below is what BT.CPP 4.8.2 gave for the same script.
        let (_, e) = run("a:=3; b:=a*2+1; c:= a<b").unwrap();
        assert_eq!((e["a"], e["b"], e["c"]), (3, 7, 1));
        assert_eq!(run("a:=true; b:=a+1").unwrap().1["b"], 2);
        assert_eq!(run("a:=2; b:=a==2==true").unwrap().1["b"], 0);
        assert_eq!(run("a:=!3").unwrap().0, 0);
        assert_eq!(run("a:=-true").unwrap().0, -1);
        assert_eq!(run("a:=1; b:=(a<2)+(a>0)").unwrap().0, 2);
        assert_eq!(run("a:=1; a+=2; b:=a; b-=5; c:=b; c*=3").unwrap().0, -6);
        assert_eq!(run("a:= true ? 1 : 2").unwrap().0, 1);
        assert_eq!(run("a:= true || false && false").unwrap().0, 0);
        assert_eq!(run("a:= false && true || true").unwrap().0, 1);
        assert_eq!(run("a:= 2 ? 5 : 7").unwrap().0, 5);
        assert_eq!(run("a:= -1 ? 5 : 7").unwrap().0, 5);
        assert_eq!(run("a:= 0 ? 5 : 7").unwrap().0, 7);
        // `+ -` and `*` group to the right.
        assert_eq!(run("a:= 10 - 4 - 2").unwrap().0, 8);
        assert_eq!(run("a:= 16 - 8 - 4 - 2").unwrap().0, 10);
        assert_eq!(run("a:= 1 - 1 + 1").unwrap().0, -1);
        assert_eq!(run("a:= 3 - 2 * 2 - 1").unwrap().0, 0);
        assert_eq!(run("a:= 100; b:= a - 10 - 1 == 91").unwrap().0, 1);
        assert!(matches!(run("a:=3 && 1"), Err(Fault::Throws(t)) if t.contains("Logic operators")));
        assert!(matches!(run("a:=x"), Err(Fault::Throws(t)) if t.contains("Variable not found")));
        assert!(matches!(run("b=2"), Err(Fault::Throws(t)) if t.contains("doesn't exist")));
        let none = Texts::new();
        let (mut vals, mut dbl) = (BTreeMap::new(), BTreeSet::new());
        let mut env = Env {
            vals: &mut vals,
            dbl: &mut dbl,
            reals: &mut BTreeMap::new(),
            strs: &mut BTreeMap::new(),
        };
        assert!(parse("3").unwrap().holds(&mut env, &none).is_err());
        assert!(parse("5-5").unwrap().holds(&mut env, &none) == Ok(false));
    }

    #[test]
    fn joins_as_the_real_library_answers() {
        // Each answer below is what BT.CPP 4.8.2 gave (`behaviortreepy`), `k` written
        // `7` by a SetBlackboard.
        let texts: Texts = [("k".to_string(), Some("7".to_string()))].into();
        let go = |src: &str| {
            let (mut vals, mut dbl) = (BTreeMap::new(), BTreeSet::new());
            let mut env = Env {
                vals: &mut vals,
                dbl: &mut dbl,
                reals: &mut BTreeMap::new(),
                strs: &mut BTreeMap::new(),
            };
            parse(src).expect("parses").run(&mut env, &texts)
        };
        let text = |src: &str, want: &str| assert_eq!(go(src), Ok(V::Text(want.into())), "{src}");
        text("'a' .. 'b'", "ab");
        text("'a' + 'b'", "ab");
        text("'a' .. 3", "a3");
        text("3 .. 'a'", "3a");
        text("'a' .. true", "a1");
        text("'a' .. false", "a0");
        text("'a' .. 1.5", "a1.500000");
        text("'a' .. (1+2)", "a3.000000");
        text("'a' .. (1/3)", "a0.333333");
        text("'a' .. (0-0)", "a0.000000");
        text("'a' .. (1/0)", "ainf");
        text("'a' .. 1e20", "a100000000000000000000.000000");
        text("'a' .. 0.1", "a0.100000");
        text("x := 3; x += 1; 'a' .. x", "a4");
        text("x := 5; x -= 8; 'a' .. x", "a-3");
        text("x := 2.5; 'a' .. x", "a2.500000");
        text("'a' .. 'b' .. 'c'", "abc");
        text("'a' .. 1 .. 2", "a12");
        text("'x' .. (true ? 'a' : 'b')", "xa");
        text("k .. k", "77");
        text("k + k", "77");
        text("'a' .. k", "a7");
        text("s := 'a'; s += 'b'", "ab");
        text("s := 'a'; s += s", "aa");
        text("s := 'a'; s = s .. 'c'", "ac");
        assert_eq!(go("'a' .. 'b' == 'ab'"), Ok(V::Dbl(1.0)));
        assert_eq!(go("'ab' .. 'cd' == 'a' .. 'bcd'"), Ok(V::Dbl(1.0)));
        // Two numbers give no value, which throws where it is used.
        assert_eq!(go("3 .. 4"), Ok(V::Empty));
        let throws = |src: &str, what: &str| {
            assert!(
                matches!(go(src), Err(Fault::Throws(t)) if t.contains(what)),
                "{src}: {:?}",
                go(src)
            )
        };
        throws("1 .. 2 .. 'a'", "is not initialized");
        throws("(3 .. 4) == 1", "is not initialized");
        throws("'a' + 1", "Operation not permitted");
        throws("s := 'a'; s += 3", "can't be used with a non-numeric type");
        throws("s := 3; s += 'a'", "Any::copyInto fails");
        throws("'a' .. u", "Variable not found: u");
        // At load (syntax): `..` mixes with no other operator group.
        for src in [
            "'a' .. 1 + 2",
            "'a' .. -3",
            "-'a' .. 'b'",
            "'a' .. 1 & 3",
            "'a' .. !1",
        ] {
            assert!(parse(src).is_err(), "{src}");
        }
    }

    #[test]
    fn scripts_read_what_setblackboard_wrote_as_text() {
        // Each answer below is what BT.CPP 4.8.2 gave after `SetBlackboard` wrote `k`.
        let mut texts: Texts = [("k", "3"), ("z", "03"), ("s", "abc")]
            .into_iter()
            .map(|(k, v)| (k.to_string(), Some(v.to_string())))
            .collect();
        // An entry a SetBlackboard `value="{e}"` names: created empty at load.
        texts.insert("e".into(), None);
        let go = |src: &str| {
            let (mut vals, mut dbl) = (BTreeMap::new(), BTreeSet::new());
            let mut env = Env {
                vals: &mut vals,
                dbl: &mut dbl,
                reals: &mut BTreeMap::new(),
                strs: &mut BTreeMap::new(),
            };
            parse(src).expect("parses").run(&mut env, &texts)
        };
        let throws = |src: &str, what: &str| {
            assert!(
                matches!(go(src), Err(Fault::Throws(t)) if t.contains(what)),
                "{src}: {:?}",
                go(src)
            )
        };
        assert_eq!(go("y := k == 3"), Ok(V::Dbl(1.0)));
        assert_eq!(go("y := 1 < k < 5"), Ok(V::Dbl(1.0)));
        assert_eq!(go("y := k == 1 + 2"), Ok(V::Dbl(1.0)));
        assert_eq!(go("y := k == true"), Ok(V::Dbl(0.0)));
        assert_eq!(go("y := k ? 1 : 2"), Ok(V::Num(1)));
        assert_eq!(go("y := z == 3"), Ok(V::Dbl(1.0)));
        assert_eq!(go("y := k == z"), Ok(V::Dbl(0.0)));
        throws("y := k + 1", "Operation not permitted");
        throws("y := -k", "Invalid operator");
        throws("y := s == 3", "string to number");
        throws("y := e == 1", "not initialized");
        throws("y := e + 1", "not initialized");
        throws("y := e ? 1 : 2", "Any::cast failed because it is empty");
        let (mut vals, mut dbl) = (BTreeMap::new(), BTreeSet::new());
        let mut env = Env {
            vals: &mut vals,
            dbl: &mut dbl,
            reals: &mut BTreeMap::new(),
            strs: &mut BTreeMap::new(),
        };
        assert!(matches!(
            parse("k").unwrap().holds(&mut env, &texts),
            Err(Fault::Throws(t)) if t.contains("safe conversion")
        ));
    }

    #[test]
    fn syntax_errors_name_the_column() {
        assert_eq!(
            parse("a:=1;").unwrap_err(),
            "column 5: unexpected trailing separator"
        );
        assert_eq!(parse("a:=1 a:=2").unwrap_err(), "column 6: expected ';'");
        assert_eq!(parse("1 + ").unwrap_err(), "column 5: expected operand");
        assert!(parse("a:=5%2").unwrap_err().starts_with("column 5"));
        // Where BT.CPP 4.8.2 put its caret.
        let mixed = "operator cannot be mixed with previous operators";
        assert_eq!(
            parse("a:= !true || -1 < 0").unwrap_err(),
            format!("column 14: {mixed}")
        );
        assert_eq!(
            parse("a:= -1 < 0 || !true").unwrap_err(),
            format!("column 15: {mixed}")
        );
        assert_eq!(
            parse("a:= !true + 1").unwrap_err(),
            format!("column 11: {mixed}")
        );
        assert!(parse("a:= !true || (-1 < 0)").is_ok());
        assert!(parse("a:= !true ? -1 : 2").is_ok());
        assert_eq!(
            parse("x := (!f ? -1 : -x)").unwrap_err(),
            format!("column 17: {mixed}")
        );
        assert!(parse("a:= 1 < -2 && 2 > 1").is_ok());
    }
}
