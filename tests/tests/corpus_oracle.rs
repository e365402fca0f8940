//! Cross-checks the hand-computed conformance corpus against the oracle, independently of codegen.
//!
//! Every case's expectations were worked out by hand from `docs/SEMANTICS.md` sections 1 and 4;
//! here the oracle recomputes them. To stay independent of `codegen`, this file
//! carries its own small formula and atom-expression parser. It is strict on
//! purpose: binary operators of different kinds may not be mixed without
//! parentheses, only `&&`/`||` may be chained, and a temporal unary operator
//! (`Y`, `Z`, `P`, `O`, `H` and word forms) may not be the bare operand of a
//! binary one. So the corpus never depends on a precedence table, which the
//! engines are free to choose (it is tested elsewhere).

use std::collections::{BTreeSet, HashMap};

use hindsight_tests::oracle::{self, Point, F};
use hindsight_tests::trace::{self, Decls, Val};

// ---------------------------------------------------------------- atom expressions

#[derive(Clone, Debug, PartialEq)]
enum E {
    Lit(V),
    Var(usize),
    Not(Box<E>),
    Neg(Box<E>),
    Bin(&'static str, Box<E>, Box<E>),
}

#[derive(Clone, Debug, PartialEq)]
enum V {
    B(bool),
    I(i64),
    X(f64),
    S(String),
}

struct ExprParser<'a> {
    s: &'a [u8],
    pos: usize,
    decls: &'a Decls,
}

impl ExprParser<'_> {
    fn ws(&mut self) {
        while self
            .s
            .get(self.pos)
            .is_some_and(|c| c.is_ascii_whitespace())
        {
            self.pos += 1;
        }
    }
    fn op(&mut self, ops: &[&'static str]) -> Option<&'static str> {
        self.ws();
        let rest = &self.s[self.pos..];
        // Longest first, and `!` is not `!=`.
        let mut best: Option<&'static str> = None;
        for &o in ops {
            if rest.starts_with(o.as_bytes()) && best.is_none_or(|b| o.len() > b.len()) {
                best = Some(o);
            }
        }
        let o = best?;
        let follows = rest.get(o.len()).copied();
        if (o == "!" || o == "<" || o == ">") && follows == Some(b'=') {
            return None;
        }
        if o == "=" {
            return None;
        }
        self.pos += o.len();
        Some(o)
    }
    fn or(&mut self) -> Result<E, String> {
        let mut l = self.and()?;
        while let Some(o) = self.op(&["||"]) {
            l = E::Bin(o, Box::new(l), Box::new(self.and()?));
        }
        Ok(l)
    }
    fn and(&mut self) -> Result<E, String> {
        let mut l = self.cmp()?;
        while let Some(o) = self.op(&["&&"]) {
            l = E::Bin(o, Box::new(l), Box::new(self.cmp()?));
        }
        Ok(l)
    }
    fn cmp(&mut self) -> Result<E, String> {
        let l = self.add()?;
        if let Some(o) = self.op(&["==", "!=", "<=", ">=", "<", ">"]) {
            return Ok(E::Bin(o, Box::new(l), Box::new(self.add()?)));
        }
        Ok(l)
    }
    fn add(&mut self) -> Result<E, String> {
        let mut l = self.mul()?;
        while let Some(o) = self.op(&["+", "-"]) {
            l = E::Bin(o, Box::new(l), Box::new(self.mul()?));
        }
        Ok(l)
    }
    fn mul(&mut self) -> Result<E, String> {
        let mut l = self.unary()?;
        while let Some(o) = self.op(&["*", "/", "%"]) {
            l = E::Bin(o, Box::new(l), Box::new(self.unary()?));
        }
        Ok(l)
    }
    fn unary(&mut self) -> Result<E, String> {
        if self.op(&["!"]).is_some() {
            return Ok(E::Not(Box::new(self.unary()?)));
        }
        if self.op(&["-"]).is_some() {
            return Ok(E::Neg(Box::new(self.unary()?)));
        }
        self.primary()
    }
    fn primary(&mut self) -> Result<E, String> {
        self.ws();
        let rest = &self.s[self.pos..];
        let Some(&c) = rest.first() else {
            return Err("expression ends early".into());
        };
        if c == b'(' {
            self.pos += 1;
            let e = self.or()?;
            if self.op(&[")"]).is_none() {
                return Err("expected `)` in atom".into());
            }
            return Ok(e);
        }
        if c == b'"' {
            let end = rest[1..]
                .iter()
                .position(|&b| b == b'"')
                .ok_or("open string")?;
            let s = String::from_utf8_lossy(&rest[1..1 + end]).into_owned();
            self.pos += end + 2;
            return Ok(E::Lit(V::S(s)));
        }
        let len = rest
            .iter()
            .position(|&b| !(b.is_ascii_alphanumeric() || b == b'_' || b == b'.'))
            .unwrap_or(rest.len());
        let w = std::str::from_utf8(&rest[..len]).map_err(|e| e.to_string())?;
        if w.is_empty() {
            return Err(format!("unexpected `{}` in atom", c as char));
        }
        self.pos += len;
        if c.is_ascii_digit() {
            if let Ok(n) = w.parse::<i64>() {
                return Ok(E::Lit(V::I(n)));
            }
            return w
                .parse::<f64>()
                .map(|x| E::Lit(V::X(x)))
                .map_err(|_| format!("bad number `{w}`"));
        }
        match w {
            "true" => Ok(E::Lit(V::B(true))),
            "false" => Ok(E::Lit(V::B(false))),
            _ => self
                .decls
                .index(w)
                .map(E::Var)
                .ok_or_else(|| format!("`{w}` is not declared")),
        }
    }
}

fn parse_expr(text: &str, decls: &Decls) -> Result<E, String> {
    let mut p = ExprParser {
        s: text.as_bytes(),
        pos: 0,
        decls,
    };
    let e = p.or()?;
    p.ws();
    if p.pos != p.s.len() {
        return Err(format!("trailing text in atom `{text}`"));
    }
    Ok(e)
}

fn eval_expr(e: &E, vals: &[Val]) -> Result<V, String> {
    Ok(match e {
        E::Lit(v) => v.clone(),
        E::Var(k) => match &vals[*k] {
            Val::Bool(b) => V::B(*b),
            Val::Int(n) => V::I(i64::try_from(*n).map_err(|_| "int beyond i64")?),
            Val::Float(x) => V::X(*x),
            Val::Str(s) => V::S(s.clone()),
        },
        E::Not(a) => match eval_expr(a, vals)? {
            V::B(b) => V::B(!b),
            v => return Err(format!("! of {v:?}")),
        },
        E::Neg(a) => match eval_expr(a, vals)? {
            V::I(n) => V::I(n.checked_neg().ok_or("overflow")?),
            V::X(x) => V::X(-x),
            v => return Err(format!("- of {v:?}")),
        },
        E::Bin(op, a, b) => {
            let (a, b) = (eval_expr(a, vals)?, eval_expr(b, vals)?);
            // Mixed int/float arithmetic and comparison is done in float.
            let (a, b) = match (a, b) {
                (V::I(a), V::X(b)) => (V::X(a as f64), V::X(b)),
                (V::X(a), V::I(b)) => (V::X(a), V::X(b as f64)),
                ab => ab,
            };
            binary(op, a, b)?
        }
    })
}

fn binary(op: &str, a: V, b: V) -> Result<V, String> {
    use std::cmp::Ordering;
    let ord: Option<Ordering> = match (&a, &b) {
        (V::I(x), V::I(y)) => x.partial_cmp(y),
        (V::X(x), V::X(y)) => x.partial_cmp(y),
        (V::B(x), V::B(y)) if matches!(op, "==" | "!=") => x.partial_cmp(y),
        (V::S(x), V::S(y)) if matches!(op, "==" | "!=") => x.partial_cmp(y),
        _ => None,
    };
    let cmp = |want: fn(Ordering) -> bool| Ok(V::B(ord.is_some_and(want)));
    match op {
        "==" => return cmp(|o| o == Ordering::Equal),
        "!=" => return Ok(V::B(ord != Some(Ordering::Equal))),
        "<" => return cmp(|o| o == Ordering::Less),
        "<=" => return cmp(|o| o != Ordering::Greater),
        ">" => return cmp(|o| o == Ordering::Greater),
        ">=" => return cmp(|o| o != Ordering::Less),
        _ => {}
    }
    Ok(match (op, a, b) {
        ("&&", V::B(x), V::B(y)) => V::B(x && y),
        ("||", V::B(x), V::B(y)) => V::B(x || y),
        ("+", V::I(x), V::I(y)) => V::I(x.checked_add(y).ok_or("overflow")?),
        ("-", V::I(x), V::I(y)) => V::I(x.checked_sub(y).ok_or("overflow")?),
        ("*", V::I(x), V::I(y)) => V::I(x.checked_mul(y).ok_or("overflow")?),
        ("/", V::I(x), V::I(y)) => V::I(x.checked_div(y).ok_or("division by zero")?),
        ("%", V::I(x), V::I(y)) => V::I(x.checked_rem(y).ok_or("division by zero")?),
        ("+", V::X(x), V::X(y)) => V::X(x + y),
        ("-", V::X(x), V::X(y)) => V::X(x - y),
        ("*", V::X(x), V::X(y)) => V::X(x * y),
        ("/", V::X(x), V::X(y)) => V::X(x / y),
        ("%", V::X(x), V::X(y)) => V::X(x % y),
        (op, a, b) => return Err(format!("{a:?} {op} {b:?} is ill-typed")),
    })
}

// ---------------------------------------------------------------- formulas

#[derive(Clone, Debug, PartialEq)]
enum Tok {
    True,
    False,
    Atom(String),
    LParen,
    RParen,
    Not,
    Bin(&'static str),
    Since(u64, Option<u64>),
    Unary(char, u64, Option<u64>),
}

fn bound(text: &str, unit_ns: Option<u64>) -> Result<u64, String> {
    if text.bytes().all(|b| b.is_ascii_digit()) {
        return text.parse().map_err(|_| format!("bad bound `{text}`"));
    }
    let ns = trace::parse_duration(text).ok_or(format!("bad bound `{text}`"))?;
    let unit = unit_ns.ok_or("a bound with a unit needs `unit`")?;
    if ns % unit != 0 {
        return Err(format!("`{text}` is not a whole number of units"));
    }
    Ok(ns / unit)
}

fn lex(text: &str, unit_ns: Option<u64>) -> Result<Vec<Tok>, String> {
    let s = text.as_bytes();
    let mut i = 0;
    let mut out = Vec::new();
    while i < s.len() {
        let rest = &text[i..];
        let c = s[i];
        if c.is_ascii_whitespace() {
            i += 1;
            continue;
        }
        if c == b'{' {
            let mut j = i + 1;
            let mut in_str = false;
            while j < s.len() && (in_str || s[j] != b'}') {
                if s[j] == b'"' {
                    in_str = !in_str;
                }
                j += 1;
            }
            if j == s.len() {
                return Err("unclosed `{`".into());
            }
            out.push(Tok::Atom(text[i + 1..j].trim().to_string()));
            i = j + 1;
            continue;
        }
        let sym = ["<->", "->", "&&", "||", "(", ")", "!"]
            .into_iter()
            .find(|o| rest.starts_with(o));
        if let Some(o) = sym {
            out.push(match o {
                "(" => Tok::LParen,
                ")" => Tok::RParen,
                "!" => Tok::Not,
                o => Tok::Bin(o),
            });
            i += o.len();
            continue;
        }
        let len = rest
            .find(|c: char| !c.is_ascii_alphanumeric())
            .unwrap_or(rest.len());
        let w = &rest[..len];
        i += len;
        // An interval follows its operator directly.
        let mut lo = 0;
        let mut hi = None;
        let temporal = matches!(
            w,
            "Y" | "Z" | "O" | "P" | "H" | "S" | "pre" | "once" | "historically" | "since"
        );
        if temporal && s.get(i) == Some(&b'[') {
            let close = text[i..].find(']').ok_or("unclosed `[`")? + i;
            let (a, b) = text[i + 1..close]
                .split_once(':')
                .ok_or("interval without `:`")?;
            if !a.is_empty() {
                lo = bound(a, unit_ns)?;
            }
            if !b.is_empty() {
                hi = Some(bound(b, unit_ns)?);
            }
            if matches!(w, "Y" | "Z" | "pre") {
                return Err(format!("`{w}` takes no interval"));
            }
            if hi.is_some_and(|h| h < lo) {
                return Err(format!("empty interval in `{text}`"));
            }
            i = close + 1;
        }
        out.push(match w {
            "true" => Tok::True,
            "false" => Tok::False,
            "Y" | "pre" => Tok::Unary('Y', 0, None),
            "Z" => Tok::Unary('Z', 0, None),
            "O" | "P" | "once" => Tok::Unary('P', lo, hi),
            "H" | "historically" => Tok::Unary('H', lo, hi),
            "S" | "since" => Tok::Since(lo, hi),
            _ => return Err(format!("unexpected `{w}` at byte {i}")),
        });
    }
    Ok(out)
}

struct FormulaParser<'a> {
    toks: Vec<Tok>,
    pos: usize,
    /// Atom texts in order of first use; `F::Atom(k)` is `atoms[k]`.
    atoms: Vec<String>,
    decls: &'a Decls,
    exprs: Vec<E>,
}

impl FormulaParser<'_> {
    fn peek(&self) -> Option<&Tok> {
        self.toks.get(self.pos)
    }
    fn next(&mut self) -> Option<Tok> {
        let t = self.toks.get(self.pos).cloned();
        self.pos += 1;
        t
    }

    /// A chain of binary operators: one kind only, and only `&&`/`||` repeat.
    fn binary(&mut self) -> Result<F, String> {
        let (mut l, mut bare) = self.unary()?;
        let mut kind: Option<Tok> = None;
        while let Some(t @ (Tok::Bin(_) | Tok::Since(..))) = self.peek().cloned() {
            self.pos += 1;
            if let Some(k) = &kind {
                let chainable = matches!(k, Tok::Bin("&&" | "||"));
                if *k != t || !chainable {
                    return Err(format!("`{t:?}` after `{k:?}` needs parentheses"));
                }
            }
            let (r, r_bare) = self.unary()?;
            if bare || r_bare {
                return Err(
                    "a temporal unary operand of a binary operator needs parentheses".into(),
                );
            }
            let (l0, r) = (Box::new(l), Box::new(r));
            l = match &t {
                Tok::Bin("&&") => F::And(l0, r),
                Tok::Bin("||") => F::Or(l0, r),
                Tok::Bin("->") => F::Implies(l0, r),
                Tok::Bin(_) => F::Iff(l0, r),
                Tok::Since(lo, hi) => F::Since {
                    lo: *lo,
                    hi: *hi,
                    l: l0,
                    r,
                },
                _ => unreachable!("only binary tokens enter the loop"),
            };
            bare = false;
            kind = Some(t);
        }
        Ok(l)
    }

    /// A unary formula and whether it is a bare temporal unary application.
    fn unary(&mut self) -> Result<(F, bool), String> {
        match self.next() {
            Some(Tok::Not) => {
                let (f, bare) = self.unary()?;
                Ok((F::Not(Box::new(f)), bare))
            }
            Some(Tok::Unary(op, lo, hi)) => {
                let (f, _) = self.unary()?;
                let f = Box::new(f);
                let g = match op {
                    'Y' => F::Y(f),
                    'Z' => F::Z(f),
                    'P' => F::Once { lo, hi, f },
                    _ => F::Hist { lo, hi, f },
                };
                Ok((g, true))
            }
            Some(Tok::True) => Ok((F::True, false)),
            Some(Tok::False) => Ok((F::False, false)),
            Some(Tok::Atom(text)) => {
                let k = match self.atoms.iter().position(|a| *a == text) {
                    Some(k) => k,
                    None => {
                        self.exprs.push(parse_expr(&text, self.decls)?);
                        self.atoms.push(text);
                        self.atoms.len() - 1
                    }
                };
                Ok((F::Atom(k), false))
            }
            Some(Tok::LParen) => {
                let f = self.binary()?;
                match self.next() {
                    Some(Tok::RParen) => Ok((f, false)),
                    t => Err(format!("expected `)`, found {t:?}")),
                }
            }
            t => Err(format!("expected a formula, found {t:?}")),
        }
    }
}

/// The formula and one parsed atom expression per `F::Atom` index.
fn parse_formula(text: &str, decls: &Decls) -> Result<(F, Vec<E>), String> {
    let mut p = FormulaParser {
        toks: lex(text, decls.unit_ns)?,
        pos: 0,
        atoms: Vec::new(),
        decls,
        exprs: Vec::new(),
    };
    let f = p.binary()?;
    if p.pos != p.toks.len() {
        return Err(format!("trailing tokens from {:?}", p.peek()));
    }
    Ok((f, p.exprs))
}

// ---------------------------------------------------------------- the checks

/// The oracle's verdicts for a case, or why the case is malformed.
fn oracle_verdicts(case: &trace::Case) -> Result<Vec<bool>, String> {
    let decls = trace::parse_decls(&case.decls).map_err(|e| format!("decls {e}"))?;
    let points = trace::parse_trace(&case.trace, &decls).map_err(|e| format!("trace {e}"))?;
    let (f, exprs) = parse_formula(&case.formula, &decls)?;
    let mut trace = Vec::new();
    for (p, vals) in points.iter().zip(trace::valuations(&decls, &points)) {
        let mut atoms = Vec::new();
        for e in &exprs {
            match eval_expr(e, &vals)? {
                V::B(b) => atoms.push(b),
                v => return Err(format!("atom is {v:?}, not boolean")),
            }
        }
        trace.push(Point {
            time: p.time,
            atoms,
        });
    }
    Ok(oracle::eval(&f, &trace))
}

fn corpus() -> Vec<(String, trace::Case)> {
    trace::load_corpus(&trace::corpus_dir()).unwrap_or_else(|e| panic!("{e}"))
}

fn tf(v: &[bool]) -> String {
    v.iter().map(|&b| if b { 'T' } else { 'F' }).collect()
}

#[test]
fn hand_computed_verdicts_agree_with_the_oracle() {
    let mut failures = Vec::new();
    for (file, case) in corpus() {
        let want = case.expected();
        match (oracle_verdicts(&case), want) {
            (Err(e), _) => failures.push(format!("{file} {}: {e}", case.name)),
            (_, None) => failures.push(format!("{file} {}: expect is not T/F", case.name)),
            (Ok(got), Some(want)) if got != want => failures.push(format!(
                "{file} {}: {}\n    expect {}\n    oracle {}",
                case.name,
                case.formula,
                case.expect,
                tf(&got)
            )),
            _ => {}
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn cases_are_well_formed_and_named_once() {
    let cases = corpus();
    assert!(cases.len() >= 170, "only {} cases", cases.len());
    let mut names = BTreeSet::new();
    let mut per_file: HashMap<&str, usize> = HashMap::new();
    for (file, c) in &cases {
        assert!(
            names.insert(c.name.as_str()),
            "duplicate case name {}",
            c.name
        );
        assert!(!c.rationale.trim().is_empty(), "{}: no rationale", c.name);
        assert!(
            !c.rationale.contains('\n'),
            "{}: rationale is one line",
            c.name
        );
        assert_eq!(
            c.trace.len(),
            c.expect.len(),
            "{}: one verdict per point",
            c.name
        );
        assert!(!c.trace.is_empty(), "{}: empty trace", c.name);
        *per_file.entry(file).or_default() += 1;
    }
    for want in [
        "booleans.toml",
        "yesterday.toml",
        "since_unbounded.toml",
        "since_upto.toml",
        "since_atleast.toml",
        "since_window.toml",
        "once.toml",
        "historically.toml",
        "nested.toml",
        "events_states.toml",
        "superdense.toml",
        "first_points.toml",
        "atoms.toml",
        "units.toml",
    ] {
        assert!(
            per_file.get(want).is_some_and(|&n| n > 0),
            "{want} has no case"
        );
    }
}

/// Which operator / interval shapes the corpus exercises.
fn shapes(f: &F, out: &mut BTreeSet<String>) {
    let shape = |lo: u64, hi: Option<u64>| match (lo, hi) {
        (0, None) => "unbounded",
        (0, Some(_)) => "[0:b]",
        (_, None) => "[a:]",
        (a, Some(b)) if a == b => "[a:a]",
        _ => "[a:b]",
    };
    match f {
        F::True | F::False => {
            out.insert("const".into());
        }
        F::Atom(_) => {}
        F::Not(a) => {
            out.insert("!".into());
            shapes(a, out);
        }
        F::And(a, b) | F::Or(a, b) | F::Implies(a, b) | F::Iff(a, b) => {
            let op = match f {
                F::And(..) => "&&",
                F::Or(..) => "||",
                F::Implies(..) => "->",
                _ => "<->",
            };
            out.insert(op.into());
            shapes(a, out);
            shapes(b, out);
        }
        F::Y(a) | F::Z(a) => {
            out.insert(if matches!(f, F::Y(_)) { "Y" } else { "Z" }.into());
            shapes(a, out);
        }
        F::Once { lo, hi, f } => {
            out.insert(format!("P{}", shape(*lo, *hi)));
            shapes(f, out);
        }
        F::Hist { lo, hi, f } => {
            out.insert(format!("H{}", shape(*lo, *hi)));
            shapes(f, out);
        }
        F::Since { lo, hi, l, r } => {
            out.insert(format!("S{}", shape(*lo, *hi)));
            shapes(l, out);
            shapes(r, out);
        }
    }
}

#[test]
fn corpus_covers_every_operator_and_interval_shape() {
    let mut seen = BTreeSet::new();
    let mut kinds = BTreeSet::new();
    for (_, case) in corpus() {
        let decls = trace::parse_decls(&case.decls).unwrap_or_else(|e| panic!("{e}"));
        if let Ok((f, _)) = parse_formula(&case.formula, &decls) {
            shapes(&f, &mut seen);
        }
        for v in &decls.vars {
            kinds.insert(format!("{:?}/{:?}", v.kind, v.ty));
        }
    }
    let mut missing = Vec::new();
    for op in ["!", "&&", "||", "->", "<->", "Y", "Z", "const"] {
        if !seen.contains(op) {
            missing.push(op.to_string());
        }
    }
    for op in ["P", "H", "S"] {
        for sh in ["unbounded", "[0:b]", "[a:]", "[a:a]", "[a:b]"] {
            let k = format!("{op}{sh}");
            if !seen.contains(&k) {
                missing.push(k);
            }
        }
    }
    assert!(missing.is_empty(), "not covered: {missing:?}");
    assert!(kinds.iter().any(|k| k.starts_with("Event")));
    assert!(kinds.contains("State/Float") && kinds.contains("State/Str"));
}

#[test]
fn the_cross_check_parser_rejects_ambiguous_text() {
    let decls = trace::parse_decls("event p; event q; event r;").unwrap();
    for bad in [
        "{p} && {q} || {r}",
        "{p} S {q} S {r}",
        "P {p} && {q}",
        "{p} -> {q} -> {r}",
        "{p} S {q} && {r}",
        "Y[1:2] {p}",
        "P[3:2] {p}",
        "P[1s] {p}",
    ] {
        assert!(parse_formula(bad, &decls).is_err(), "accepted `{bad}`");
    }
    let (f, atoms) = parse_formula("(P[2:] {p}) && !{q} && {p}", &decls).unwrap();
    assert_eq!(oracle::print(&f), "(((P[2:] {a0}) && (!{a1})) && {a0})");
    assert_eq!(atoms.len(), 2);
}
