//! The conformance corpus's input syntax: variable declarations, trace points, and their valuation.
//!
//! Declarations are the spec language's (`unit 100ms;`, `event p;`,
//! `state x: int = 0;`, `//` comments). A trace point is
//! `<time>: item item ...` where an item is `name` (an event, or a boolean
//! state set true), `!name` (a boolean state set false) or `name=value` (an
//! integer or float literal, `true`/`false`, or a `"string"`).
//!
//! [`valuations`] applies SCAN's event/state model (`docs/SEMANTICS.md` section 1): an
//! event variable is true only at a point that lists it; a state variable
//! keeps its last value, starting from its declared initial value.
//!
//! Everything is checked: an undeclared name, a value of the wrong type or out
//! of its declared integer range, a repeated item or a timestamp that goes
//! backwards is an [`Error`] with a line and column, never a panic.

use std::fmt;

/// A parse or check error. For declarations `line` is the line of the text;
/// for a trace it is the 1-based index of the point. Columns are 1-based characters.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Error {
    /// Line (declarations) or point number (trace), from 1.
    pub line: usize,
    /// Column, from 1.
    pub column: usize,
    /// What is wrong.
    pub message: String,
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}:{}: {}", self.line, self.column, self.message)
    }
}

impl std::error::Error for Error {}

/// Event or state variable.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// True only at the points that list it.
    Event,
    /// Keeps its last value.
    State,
}

/// A declared type, as written.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Type {
    /// `bool`.
    Bool,
    /// `int`, `i8` .. `i64`, `u8` .. `u64`: values in `min..=max` (`u64` up to
    /// `i64::MAX`, as every integer runs as `i64`).
    Int {
        /// Smallest value.
        min: i128,
        /// Largest value.
        max: i128,
    },
    /// `float`, `f32`, `f64`.
    Float,
    /// `string`.
    Str,
}

impl Type {
    /// The type named `name`, if it is one.
    pub fn from_name(name: &str) -> Option<Type> {
        let int = |bits: u32, signed: bool| {
            if signed {
                Type::Int {
                    min: -(1i128 << (bits - 1)),
                    max: (1i128 << (bits - 1)) - 1,
                }
            } else {
                Type::Int {
                    min: 0,
                    max: (1i128 << bits) - 1,
                }
            }
        };
        Some(match name {
            "bool" => Type::Bool,
            "int" | "i64" => int(64, true),
            "i8" => int(8, true),
            "i16" => int(16, true),
            "i32" => int(32, true),
            "u8" => int(8, false),
            "u16" => int(16, false),
            "u32" => int(32, false),
            // Every integer runs as i64, so u64 values stop at i64::MAX.
            "u64" => int(63, false),
            "float" | "f32" | "f64" => Type::Float,
            "string" => Type::Str,
            _ => return None,
        })
    }
}

/// A value of a variable.
#[derive(Clone, Debug, PartialEq)]
pub enum Val {
    /// A boolean.
    Bool(bool),
    /// An integer (every declared width fits in `i128`).
    Int(i128),
    /// A float.
    Float(f64),
    /// A string.
    Str(String),
}

/// One declared variable.
#[derive(Clone, Debug, PartialEq)]
pub struct VarDecl {
    /// Its name.
    pub name: String,
    /// Event or state.
    pub kind: Kind,
    /// Its type (`Bool` for events).
    pub ty: Type,
    /// The value before any point sets it (`false` for events).
    pub init: Val,
}

/// A parsed declaration block.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct Decls {
    /// The time unit in nanoseconds, when `unit ..;` was given.
    pub unit_ns: Option<u64>,
    /// Variables in declaration order.
    pub vars: Vec<VarDecl>,
}

impl Decls {
    /// Index of the variable `name`.
    pub fn index(&self, name: &str) -> Option<usize> {
        self.vars.iter().position(|v| v.name == name)
    }
}

/// One parsed trace point: its timestamp and the variables it sets, in order.
#[derive(Clone, Debug, PartialEq)]
pub struct TracePoint {
    /// Timestamp in time units.
    pub time: u64,
    /// `(variable index, value)` for every item of the point.
    pub sets: Vec<(usize, Val)>,
}

/// The length of `1` of a unit suffix in nanoseconds.
fn unit_factor(suffix: &str) -> Option<u64> {
    Some(match suffix {
        "ns" => 1,
        "us" => 1_000,
        "ms" => 1_000_000,
        "s" => 1_000_000_000,
        "min" => 60_000_000_000,
        _ => return None,
    })
}

/// Parses a duration such as `100ms`, `2.5s` or `1s` into nanoseconds, exactly.
pub fn parse_duration(text: &str) -> Option<u64> {
    let split = text.find(|c: char| c.is_ascii_alphabetic())?;
    let (num, suffix) = text.split_at(split);
    let factor = unit_factor(suffix)?;
    let (int, frac) = num.split_once('.').unwrap_or((num, ""));
    if int.is_empty() || !int.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    if !frac.bytes().all(|b| b.is_ascii_digit()) || (num.contains('.') && frac.is_empty()) {
        return None;
    }
    let mut value: u128 = int.parse().ok()?;
    let mut scale: u128 = 1;
    for d in frac.bytes() {
        value = value.checked_mul(10)? + u128::from(d - b'0');
        scale = scale.checked_mul(10)?;
    }
    let ns = value.checked_mul(u128::from(factor))?;
    if ns % scale != 0 {
        return None;
    }
    u64::try_from(ns / scale).ok()
}

/// A cursor over one line, tracking the 1-based column.
struct Cur<'a> {
    s: &'a str,
    pos: usize,
    line: usize,
}

impl<'a> Cur<'a> {
    fn column(&self) -> usize {
        self.s[..self.pos].chars().count() + 1
    }
    fn err(&self, message: impl Into<String>) -> Error {
        Error {
            line: self.line,
            column: self.column(),
            message: message.into(),
        }
    }
    fn skip_ws(&mut self) {
        let rest = &self.s[self.pos..];
        self.pos += rest.len() - rest.trim_start().len();
    }
    fn peek(&self) -> Option<char> {
        self.s[self.pos..].chars().next()
    }
    fn eat(&mut self, c: char) -> bool {
        if self.peek() == Some(c) {
            self.pos += c.len_utf8();
            true
        } else {
            false
        }
    }
    fn at_end(&self) -> bool {
        self.pos == self.s.len()
    }
    /// An identifier `[A-Za-z_][A-Za-z0-9_.]*` (dots allow `msg.field` names).
    fn ident(&mut self) -> Option<&'a str> {
        let rest = &self.s[self.pos..];
        let first = rest.chars().next()?;
        if !(first.is_ascii_alphabetic() || first == '_') {
            return None;
        }
        let len = rest
            .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_' || c == '.'))
            .unwrap_or(rest.len());
        self.pos += len;
        Some(&rest[..len])
    }
    /// A run of characters up to whitespace or one of `stops`.
    fn word(&mut self, stops: &[char]) -> &'a str {
        let rest = &self.s[self.pos..];
        let len = rest
            .find(|c: char| c.is_whitespace() || stops.contains(&c))
            .unwrap_or(rest.len());
        self.pos += len;
        &rest[..len]
    }
    /// A literal: `"string"` (with `\"` and `\\`), `true`, `false` or a number.
    fn literal(&mut self, stops: &[char]) -> Result<Lit, Error> {
        let start = self.pos;
        if self.eat('"') {
            let mut out = String::new();
            loop {
                match self.peek() {
                    None => {
                        self.pos = start;
                        return Err(self.err("unterminated string"));
                    }
                    Some('"') => {
                        self.pos += 1;
                        return Ok(Lit::Str(out));
                    }
                    Some('\\') => {
                        self.pos += 1;
                        match self.peek() {
                            Some(c @ ('"' | '\\')) => {
                                out.push(c);
                                self.pos += 1;
                            }
                            _ => return Err(self.err("unknown escape in string")),
                        }
                    }
                    Some(c) => {
                        out.push(c);
                        self.pos += c.len_utf8();
                    }
                }
            }
        }
        let w = self.word(stops);
        let lit = match w {
            "true" => Some(Lit::Bool(true)),
            "false" => Some(Lit::Bool(false)),
            _ => parse_number(w),
        };
        lit.ok_or_else(|| {
            self.pos = start;
            self.err(format!("expected a literal, found `{w}`"))
        })
    }
}

/// A literal as written, before it is typed against a variable.
#[derive(Clone, Debug, PartialEq)]
enum Lit {
    Bool(bool),
    Int(i128),
    Float(f64),
    Str(String),
}

/// `-?[0-9]+` as an integer, or a float literal (`1.5`, `-0.25`, `2e3`).
fn parse_number(w: &str) -> Option<Lit> {
    let digits = w.strip_prefix('-').unwrap_or(w);
    if digits.is_empty() || !digits.starts_with(|c: char| c.is_ascii_digit()) {
        return None;
    }
    if digits.bytes().all(|b| b.is_ascii_digit()) {
        return w.parse().ok().map(Lit::Int);
    }
    let ok = digits
        .bytes()
        .all(|b| b.is_ascii_digit() || matches!(b, b'.' | b'e' | b'E' | b'+' | b'-'));
    if !ok {
        return None;
    }
    w.parse::<f64>()
        .ok()
        .filter(|x| x.is_finite())
        .map(Lit::Float)
}

/// Types `lit` as a value of `ty`: ints must be in range, an int fits a float.
fn typed(lit: Lit, ty: Type) -> Result<Val, String> {
    match (lit, ty) {
        (Lit::Bool(b), Type::Bool) => Ok(Val::Bool(b)),
        (Lit::Int(n), Type::Int { min, max }) if (min..=max).contains(&n) => Ok(Val::Int(n)),
        (Lit::Int(n), Type::Int { .. }) => Err(format!("{n} is out of the declared range")),
        (Lit::Int(n), Type::Float) => Ok(Val::Float(n as f64)),
        (Lit::Float(x), Type::Float) => Ok(Val::Float(x)),
        (Lit::Str(s), Type::Str) => Ok(Val::Str(s)),
        (lit, ty) => Err(format!("{lit:?} is not a value of type {ty:?}")),
    }
}

/// The initial value of a state declared without `= INIT`: `false`, `0`, `0.0` or `""`.
fn default_value(ty: Type) -> Val {
    match ty {
        Type::Bool => Val::Bool(false),
        Type::Int { .. } => Val::Int(0),
        Type::Float => Val::Float(0.0),
        Type::Str => Val::Str(String::new()),
    }
}

/// Parses a declaration block: `unit D;`, `event NAME;`, `state NAME: TYPE [= INIT];`,
/// one or more per line, with `//` and `#` comments.
pub fn parse_decls(text: &str) -> Result<Decls, Error> {
    let mut decls = Decls::default();
    for (n, raw) in text.lines().enumerate() {
        let s = strip_comment(raw);
        let mut c = Cur {
            s,
            pos: 0,
            line: n + 1,
        };
        loop {
            c.skip_ws();
            if c.at_end() {
                break;
            }
            let kw_at = c.pos;
            let kw = c.ident().ok_or_else(|| c.err("expected a declaration"))?;
            c.skip_ws();
            match kw {
                "unit" => {
                    let w = c.word(&[';']);
                    let ns = parse_duration(w).filter(|&ns| ns > 0).ok_or_else(|| {
                        c.pos -= w.len();
                        c.err(format!("`{w}` is not a duration such as 100ms"))
                    })?;
                    if decls.unit_ns.replace(ns).is_some() {
                        c.pos = kw_at;
                        return Err(c.err("a second `unit`"));
                    }
                }
                "event" | "state" => {
                    let name_at = c.pos;
                    let name = c.ident().ok_or_else(|| c.err("expected a name"))?;
                    if decls.index(name).is_some() {
                        c.pos = name_at;
                        return Err(c.err(format!("`{name}` is declared twice")));
                    }
                    let (kind, ty, init) = if kw == "event" {
                        (Kind::Event, Type::Bool, Val::Bool(false))
                    } else {
                        c.skip_ws();
                        if !c.eat(':') {
                            return Err(c.err("expected `:` and a type"));
                        }
                        c.skip_ws();
                        let ty_at = c.pos;
                        let ty_name = c.ident().unwrap_or("");
                        let ty = Type::from_name(ty_name).ok_or_else(|| {
                            c.pos = ty_at;
                            c.err(format!("unknown type `{ty_name}`"))
                        })?;
                        c.skip_ws();
                        let init = if c.eat('=') {
                            c.skip_ws();
                            let lit_at = c.pos;
                            let lit = c.literal(&[';'])?;
                            typed(lit, ty).map_err(|m| {
                                c.pos = lit_at;
                                c.err(m)
                            })?
                        } else {
                            default_value(ty)
                        };
                        (Kind::State, ty, init)
                    };
                    decls.vars.push(VarDecl {
                        name: name.to_string(),
                        kind,
                        ty,
                        init,
                    });
                }
                other => {
                    c.pos = kw_at;
                    return Err(c.err(format!("unknown declaration `{other}`")));
                }
            }
            c.skip_ws();
            if !c.eat(';') {
                return Err(c.err("expected `;`"));
            }
        }
    }
    Ok(decls)
}

/// `line` up to a `//` or `#` that is not inside a string.
fn strip_comment(line: &str) -> &str {
    let mut in_str = false;
    let mut escaped = false;
    for (i, c) in line.char_indices() {
        match c {
            _ if escaped => escaped = false,
            '\\' if in_str => escaped = true,
            '"' => in_str = !in_str,
            '#' if !in_str => return &line[..i],
            '/' if !in_str && line[i..].starts_with("//") => return &line[..i],
            _ => {}
        }
    }
    line
}

/// Parses point number `number` (from 1, used in errors): `<time>: item item ...`.
pub fn parse_point(text: &str, number: usize, decls: &Decls) -> Result<TracePoint, Error> {
    let mut c = Cur {
        s: text,
        pos: 0,
        line: number,
    };
    c.skip_ws();
    let w = c.word(&[':']);
    let time: u64 = w.parse().map_err(|_| {
        c.pos -= w.len();
        c.err(format!("`{w}` is not a timestamp"))
    })?;
    if !c.eat(':') {
        return Err(c.err("expected `:` after the timestamp"));
    }
    let mut sets: Vec<(usize, Val)> = Vec::new();
    loop {
        c.skip_ws();
        if c.at_end() {
            break;
        }
        let item_at = c.pos;
        let negated = c.eat('!');
        let name = c.ident().ok_or_else(|| c.err("expected a variable name"))?;
        let k = decls.index(name).ok_or_else(|| {
            c.pos = item_at;
            c.err(format!("`{name}` is not declared"))
        })?;
        let var = &decls.vars[k];
        let val = if c.eat('=') {
            if negated {
                c.pos = item_at;
                return Err(c.err("`!name=value` is not an item"));
            }
            let lit_at = c.pos;
            let lit = c.literal(&[])?;
            let val = typed(lit, var.ty).map_err(|m| {
                c.pos = lit_at;
                c.err(m)
            })?;
            if var.kind == Kind::Event && val != Val::Bool(true) {
                c.pos = item_at;
                return Err(c.err(format!("event `{name}` can only be sent (true)")));
            }
            val
        } else {
            match (var.kind, var.ty, negated) {
                (Kind::Event, _, false) | (Kind::State, Type::Bool, false) => Val::Bool(true),
                (Kind::State, Type::Bool, true) => Val::Bool(false),
                (Kind::Event, _, true) => {
                    c.pos = item_at;
                    return Err(c.err(format!("event `{name}` cannot be set false")));
                }
                _ => {
                    c.pos = item_at;
                    return Err(c.err(format!("`{name}` is not boolean: write `{name}=value`")));
                }
            }
        };
        if !c.at_end() && !c.peek().is_some_and(char::is_whitespace) {
            return Err(c.err("expected a space between items"));
        }
        if sets.iter().any(|(j, _)| *j == k) {
            c.pos = item_at;
            return Err(c.err(format!("`{name}` is set twice in one point")));
        }
        sets.push((k, val));
    }
    Ok(TracePoint { time, sets })
}

/// Parses every point of a trace; timestamps must not go backwards.
pub fn parse_trace<S: AsRef<str>>(points: &[S], decls: &Decls) -> Result<Vec<TracePoint>, Error> {
    let mut out: Vec<TracePoint> = Vec::with_capacity(points.len());
    for (i, text) in points.iter().enumerate() {
        let p = parse_point(text.as_ref(), i + 1, decls)?;
        if let Some(prev) = out.last() {
            if p.time < prev.time {
                return Err(Error {
                    line: i + 1,
                    column: 1,
                    message: format!("timestamp {} is before {}", p.time, prev.time),
                });
            }
        }
        out.push(p);
    }
    Ok(out)
}

/// The value of every variable at every point (event/state semantics applied).
pub fn valuations(decls: &Decls, trace: &[TracePoint]) -> Vec<Vec<Val>> {
    let mut cur: Vec<Val> = decls.vars.iter().map(|v| v.init.clone()).collect();
    trace
        .iter()
        .map(|p| {
            for (v, d) in cur.iter_mut().zip(&decls.vars) {
                if d.kind == Kind::Event {
                    *v = Val::Bool(false);
                }
            }
            for (k, val) in &p.sets {
                cur[*k] = val.clone();
            }
            cur.clone()
        })
        .collect()
}

/// One conformance case, as written in `tests/conformance/*.toml` (`[[case]]` tables).
#[derive(Clone, Debug, PartialEq, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Case {
    /// Unique name across the corpus.
    pub name: String,
    /// One line: why these verdicts.
    pub rationale: String,
    /// Declarations in the spec syntax ([`parse_decls`]).
    pub decls: String,
    /// The formula in Rye syntax.
    pub formula: String,
    /// The points, in the point syntax ([`parse_point`]).
    pub trace: Vec<String>,
    /// One verdict per point: `T` or `F`.
    pub expect: String,
}

impl Case {
    /// The expected verdicts, or `None` if `expect` holds anything but `T`/`F`.
    pub fn expected(&self) -> Option<Vec<bool>> {
        self.expect
            .chars()
            .map(|c| match c {
                'T' => Some(true),
                'F' => Some(false),
                _ => None,
            })
            .collect()
    }
}

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct CaseFile {
    case: Vec<Case>,
}

/// Every case of every `*.toml` file in `dir`, files in name order, as
/// `(file name, case)`. An unreadable or malformed file is an error naming it.
pub fn load_corpus(dir: &std::path::Path) -> Result<Vec<(String, Case)>, String> {
    let mut files: Vec<_> = std::fs::read_dir(dir)
        .map_err(|e| format!("{}: {e}", dir.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    files.sort();
    let mut out = Vec::new();
    for path in files {
        let text =
            std::fs::read_to_string(&path).map_err(|e| format!("{}: {e}", path.display()))?;
        let file: CaseFile =
            toml::from_str(&text).map_err(|e| format!("{}: {e}", path.display()))?;
        let name = path
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        out.extend(file.case.into_iter().map(|c| (name.clone(), c)));
    }
    Ok(out)
}

/// The corpus directory of this repository (`tests/conformance`).
pub fn corpus_dir() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("conformance")
}

#[cfg(test)]
mod tests {
    use super::*;

    const DECLS: &str = "unit 100ms; // ten points a second\n\
                         # a comment; state no: int = 1;\n\
                         event p;\n\
                         state b: bool = true; state x: u8 = 3;\n\
                         state f: float = 0;\n\
                         state mode: string = \"idle\";\n";

    #[test]
    fn declarations_parse_with_types_and_inits() {
        let d = parse_decls(DECLS).unwrap();
        assert_eq!(d.unit_ns, Some(100_000_000));
        let names: Vec<_> = d.vars.iter().map(|v| v.name.as_str()).collect();
        assert_eq!(names, ["p", "b", "x", "f", "mode"]);
        assert_eq!(d.vars[0].kind, Kind::Event);
        assert_eq!(d.vars[2].ty, Type::Int { min: 0, max: 255 });
        assert_eq!(d.vars[3].init, Val::Float(0.0));
        assert_eq!(d.vars[4].init, Val::Str("idle".into()));
        let d = parse_decls("state s: string; state k: i8; state u: f32; state c: bool; state h: string = \"a#b//c\";").unwrap();
        let inits: Vec<_> = d.vars.iter().map(|v| v.init.clone()).collect();
        assert_eq!(
            inits,
            [
                Val::Str(String::new()),
                Val::Int(0),
                Val::Float(0.0),
                Val::Bool(false),
                Val::Str("a#b//c".into())
            ]
        );
    }

    #[test]
    fn events_fall_back_and_states_hold() {
        let d = parse_decls(DECLS).unwrap();
        let lines = [
            "0: p x=7",
            "0:",
            "2: !b f=2.5 mode=\"go home\"",
            "5: p b x=0 f=-1",
        ];
        let t = parse_trace(&lines, &d).unwrap();
        let v = valuations(&d, &t);
        let col = |k: usize| v.iter().map(|p| p[k].clone()).collect::<Vec<_>>();
        use Val::*;
        assert_eq!(col(0), [Bool(true), Bool(false), Bool(false), Bool(true)]);
        assert_eq!(col(1), [Bool(true), Bool(true), Bool(false), Bool(true)]);
        assert_eq!(col(2), [Int(7), Int(7), Int(7), Int(0)]);
        assert_eq!(col(3), [Float(0.0), Float(0.0), Float(2.5), Float(-1.0)]);
        assert_eq!(col(4)[2], Str("go home".into()));
        assert_eq!(t.iter().map(|p| p.time).collect::<Vec<_>>(), [0, 0, 2, 5]);
    }

    #[test]
    fn bad_input_is_an_error_with_a_position() {
        let d = parse_decls(DECLS).unwrap();
        let err = |s: &str| parse_point(s, 4, &d).unwrap_err();
        assert_eq!(err("3: q").column, 4);
        assert_eq!(err("3: x=256").column, 6);
        assert_eq!(err("3: x=1.5").column, 6);
        assert_eq!(err("3: !p").column, 4);
        assert_eq!(err("3: x").column, 4);
        assert_eq!(err("3: b b").column, 6);
        assert_eq!(err("3: mode=\"open").column, 9);
        assert_eq!(err("t: p").column, 1);
        assert_eq!(err("3 p").column, 2);
        assert_eq!(err("3: q").line, 4);
        let back = parse_trace(&["3:", "2:"], &d).unwrap_err();
        assert_eq!((back.line, back.column), (2, 1));
        let e = parse_decls("event p;\nstate y: int = \"a\";").unwrap_err();
        assert_eq!((e.line, e.column), (2, 16));
        assert_eq!(parse_decls("state z: i9 = 0;").unwrap_err().column, 10);
        assert_eq!(parse_decls("event p").unwrap_err().column, 8);
        assert_eq!(parse_decls("event p; event p;").unwrap_err().column, 16);
        assert_eq!(parse_decls("unit 3;").unwrap_err().column, 6);
        assert_eq!(
            parse_decls("state n: u64 = 9223372036854775808;")
                .unwrap_err()
                .column,
            16
        );
    }

    #[test]
    fn durations_convert_exactly() {
        assert_eq!(parse_duration("2.5s"), Some(2_500_000_000));
        assert_eq!(parse_duration("100ms"), Some(100_000_000));
        assert_eq!(parse_duration("1.5ns"), None);
        assert_eq!(parse_duration("s"), None);
        assert_eq!(parse_duration("1.s"), None);
        assert_eq!(parse_duration("3"), None);
    }
}
