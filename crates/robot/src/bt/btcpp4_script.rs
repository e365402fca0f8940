//! BehaviorTree.CPP 4's script language lowered under [`super::BtSemantics::Btcpp`]:
//! the `Script`, `ScriptCondition` and `Precondition` nodes over integer, boolean,
//! double and string blackboard entries (a double a plugin's `float64` port writes is
//! read, never written: `entries.rs`), with doubles (`/`, real literals) computed as
//! BT.CPP computes them.
//!
//! # Where a script runs
//! In the blackboard machine (`blackboard.rs`), which holds every entry: the node sends
//! `bt_script_<id>_run`, the blackboard machine runs the statements in order on its own
//! variables (one transition: no other machine sees a half-run script) and answers
//! `bt_script_<id>_done`, with the script's value as the boolean `value` for a condition.
//!
//! # The rules (BT.CPP 4.8.2, the real library the tests run, where 4.10's sources say
//! nothing)
//! - Values: `true` and `1` are the same value to the language (`a:=true; b:=a+1` gives
//!   2; `x:=true; x=3` gives 3), so an entry only scripts write is an `int64` holding
//!   booleans as 0 and 1. An entry a plugin port types keeps that type (any integer
//!   type, or `bool`: only a boolean value is assigned to it).
//! - `!e` is `e == 0`; `-`, `+`, `*` over whole numbers are integer arithmetic (BT.CPP
//!   computes in doubles: the same values up to 2^53); comparisons chain (`a < b < c` is
//!   `a < b && b < c`).
//! - Every operator gives a `double`; a literal integer, `true`, `false` and an entry
//!   holding an integer are `int64_t` (4.10 `scripting/operators.hpp`, the `evaluate`
//!   functions; `scripting/any_types.hpp`, `BooleanLiteral`). An entry a script creates
//!   keeps the type of its first value (`ExprAssignment::evaluate`: the first `:=` stores
//!   the value as it is, later ones go through `Any::copyInto`): the blackboard machine's
//!   [`dbl`] flag.
//! - A value cast to bool (`Any::cast<bool>`: a condition, `ScriptCondition`,
//!   Precondition's `if`, an operand of `&&` / `||`, which then throw "Logic operators
//!   are not allowed ...") is, as an integer, 0 or 1, anything else throws; as a double,
//!   true unless 0, throwing when negative (4.8.2: `1+1` and `1/2` are true, `0-1`
//!   throws). `c ? a : b` takes any number, non-zero (NaN too) being true.
//! - `/` and real literals are the model's floats ([`Ty::Real`]) where the value is
//!   compared, tested or cast: `==` within `f32::EPSILON` and each ordering as the
//!   negation of its opposite (`ExprComparison::evaluate`, `IsSame`), so NaN satisfies
//!   `<`, `>`, `<=`, `>=`; never stored; divisors are number literals other than 0
//!   (the model's integers have no negative zero, whose sign BT.CPP's doubles show in
//!   `1/-0.0`).
//! - Reading an entry that holds no value throws ("Variable not found"); so does `+=`,
//!   `-=`, `*=` on one (`:=` creates it), and `=` on one that does not exist: an entry a
//!   port names in `{}` exists from the load until an UnsetBlackboard erases it
//!   ([`exists`]).
//! - `+ -` and `*` group to the right (`10 - 4 - 2` is 8, `1 - 1 + 1` is -1).
//! - Strings (`btcpp4_strings.rs`): a literal, an entry SetBlackboard wrote (BT.CPP 4
//!   stores SetBlackboard's value as text) or one a script assigns strings to is a
//!   [`Ty::Text`], the model expression holding its rank among the tree's texts in byte
//!   order, so two strings compare as their ranks; compared with a number, or as the
//!   condition of `c ? a : b`, a string reads as a number (the text `3` equals 3, `abc`
//!   throws); an arithmetic or logic operator, `-`, `!` over it, or a condition whose
//!   value it is, throws ("Operation not permitted", "Invalid operator for std::string",
//!   "no known safe conversion"). Joining strings (`..`, `+` of two strings, `+=`)
//!   lowers as a table over ranks (`btcpp4_script/join.rs`). Refused: an entry whose
//!   type would change, writing from a script an entry SetBlackboard writes.
//!
//! Where BT.CPP throws, the exception ends the tree's execution: the blackboard machine
//! goes to its `error` state (`bt_script_fault` set), the node never answers, and the
//! tree stops. Refused when the tree is read, each at the script's attribute with the
//! column in the script and why: joins whose texts are unbounded or too many, or that
//! join a number other than a literal (`join.rs`), the bit operators (no bitwise operations in the model), storing a number that need not be
//! whole (`x := 5/2`, `x /= 2`: the model's script entries are integers), a divisor
//! other than a number literal other than 0, a number
//! literal BT.CPP refuses at load, an entry SetBlackboard writes other than as above,
//! an entry of a type other than integer, boolean or `float64`, a script writing a
//! plugin's `float64` port entry, an entry a SubTree maps to a
//! constant.

use super::blackboard::{Blackboard, MACHINE};
use super::btcpp4_skip::SELF_RUNNING;
use super::control::{init_state, n_children, Ctx, FAILURE, RUNNING, SUCCESS};
use super::script::{self, Ex, Stmt, K};
use super::tree::{PortValue, ScriptNode, TreeNode};
use crate::model::source::{Diagnostic, SourceMap, Span};
use crate::model::xml::Element;

mod entries;
mod join;
mod num;

use entries::{assign_text, resolve};
pub(crate) use join::{closure, Overflow, Script, CAP};
pub(crate) use num::{entry_type, float_entries};
use num::{literal, nonzero_literal};

/// The blackboard machine's flag: a script threw.
pub(crate) const FAULT: &str = "bt_script_fault";

/// The blackboard machine's flag: entry `e` holds a value.
pub(crate) fn has(e: &str) -> String {
    format!("bt_has__{e}")
}

/// Whether entry `g` exists (`=` on one that does not throws): it holds a value
/// ([`has`]), or a port names it in `{}` (`Blackboard::declared`: BT.CPP 4 creates it,
/// empty, when it loads the tree; 4.8.2 measured, `tests/bt/btcpp4/loop.toml`) and no
/// UnsetBlackboard erased it since (`bt_gone__<entry>`, kept where one may).
pub(crate) fn exists(bb: &Blackboard, g: &str) -> String {
    if !bb.declared.iter().any(|d| d == g) {
        has(g)
    } else if bb.gone.iter().any(|d| d == g) {
        format!("({} || !{})", has(g), gone(g))
    } else {
        "true".into()
    }
}

/// The blackboard machine's flag: UnsetBlackboard erased entry `e`, which a port created
/// when the tree was loaded ([`exists`]).
pub(crate) fn gone(e: &str) -> String {
    format!("bt_gone__{e}")
}

/// The event asking the blackboard machine to run node `id`'s script.
fn run_event(id: u32) -> String {
    format!("bt_script_{id}_run")
}

/// The blackboard machine's answer to node `id`.
fn done_event(id: u32) -> String {
    format!("bt_script_{id}_done")
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Ty {
    Int,
    Bool,
    /// A string: the model expression is its text's rank among the tree's texts
    /// (`btcpp4_strings.rs`): a literal, an entry a SetBlackboard writes (read from
    /// `bt_sid__<entry>`) or one a script assigns strings to.
    Text,
    /// A `double` that need not be whole (the value of `/`, a real literal, or an
    /// operator over one): a `float64` expression in the model, never stored.
    Real,
}

/// The blackboard machine's flag: entry `e`, created by a script, holds a `double`.
pub(crate) fn dbl(e: &str) -> String {
    format!("bt_dbl__{e}")
}

/// An operator the parser gives and the lowering does not know (none today).
const BITS: &str = "this operator is not modelled";

/// Why a value that need not be whole cannot be stored in an entry of an integer type
/// a port, a Loop node or UnsetBlackboard gives (entries only scripts write hold it:
/// [`float_entries`]).
const STORE_REAL: &str = "the entry has an integer type a port, a Loop node or UnsetBlackboard gives it, and BT.CPP converts a double stored there (throwing unless it is whole), which is not modelled for those entries";

/// `f32::EPSILON`, within which BT.CPP 4.10 counts two doubles equal
/// (`scripting/operators.hpp`, `IsSame`).
const EPS: &str = "1.1920928955078125e-7";

/// A refusal: the byte offset in the script and why.
type Refuse = (usize, String);

/// A translated expression: the model expression, its type, and a model boolean
/// expression saying whether BT.CPP holds it as a `double` (every operator gives one:
/// BT.CPP 4.10 `scripting/operators.hpp`, the `evaluate` functions return
/// `Any(double)`; a literal integer, `true`, `false` and an entry holding an integer are
/// `int64_t`). `Any::cast<bool>` treats the two differently (see [`cast_bool`]).
struct Val {
    x: String,
    t: Ty,
    d: String,
}

fn val(x: String, t: Ty, d: &str) -> Val {
    Val {
        x,
        t,
        d: d.to_string(),
    }
}

/// A script entry: its name in the script, in the tree's terms, its type, and whether
/// a script creates it (BT.CPP then gives it the type of its first value: an
/// `int64_t` or a `double`, kept in [`dbl`]).
type Name = (String, String, Ty, bool);

/// Translates one script of one node to the blackboard machine's expressions.
struct Tr<'a> {
    /// The script's entry names.
    names: &'a [Name],
    /// The tree's texts (`btcpp4_strings.rs`).
    strs: &'a super::btcpp4_strings::Strings,
    /// The blackboard, for which entries exist from the load ([`Tr::exists`]).
    bb: &'a Blackboard,
    /// Conditions under which the statement being translated throws.
    checks: Vec<String>,
}

/// A number as the model's arithmetic takes it (a boolean as 0 or 1).
fn int(x: &str, t: Ty) -> String {
    match t {
        Ty::Int | Ty::Text | Ty::Real => x.to_string(),
        Ty::Bool => format!("({x} ? 1 : 0)"),
    }
}

/// `Any::cast<bool>` of a number (BT.CPP 4.8.2, measured: an `int64_t` is 0 or 1, else
/// it throws, "Implicit casting to bool is not allowed" or, negative, "Value is
/// negative and can't be converted to unsigned"; a `double` is true unless 0 and
/// throws when negative, so `1+1` and `1/2` are true and NaN too): the condition under
/// which it throws and the boolean.
fn cast_bool(v: &Val) -> (Option<String>, String) {
    let x = &v.x;
    match (v.t, v.d.as_str()) {
        (Ty::Bool, _) => (None, x.clone()),
        (_, "true") => (Some(format!("{x} < 0")), format!("({x} != 0)")),
        (_, "false") => (Some(format!("{x} != 0 && {x} != 1")), format!("({x} != 0)")),
        (_, d) => (
            Some(format!(
                "(({d}) && {x} < 0) || (!({d}) && {x} != 0 && {x} != 1)"
            )),
            format!("({x} != 0)"),
        ),
    }
}

/// A comparison of two numbers, one of them possibly not whole, as BT.CPP 4.10 makes it
/// (`scripting/operators.hpp`, `ExprComparison::evaluate`, `IsSame`): `==` within
/// [`EPS`], each ordering the negation of its opposite (NaN is `<`, `>`, `<=` and `>=`
/// anything: 4.8.2 agrees).
fn compare_real(op: &str, l: &str, r: &str) -> String {
    let same = format!("(Math.abs({l} - {r}) <= {EPS})");
    match op {
        "==" => same,
        "!=" => format!("!{same}"),
        "<" => format!("!({l} >= {r})"),
        "<=" => format!("!({l} > {r})"),
        ">" => format!("!({l} <= {r})"),
        _ => format!("!({l} < {r})"),
    }
}

impl Tr<'_> {
    /// Whether entry `g` exists, for `=` ("The blackboard entry [..] doesn't exist"
    /// otherwise): it holds a value, or a port of the tree created it when the tree was
    /// loaded and no UnsetBlackboard erased it since ([`exists`]).
    fn exists(&self, g: &str) -> String {
        exists(self.bb, g)
    }

    fn entry(&self, name: &str) -> (String, Ty, bool) {
        let (_, g, t, dynamic) = self
            .names
            .iter()
            .find(|(n, _, _, _)| n == name)
            .expect("every name was resolved");
        (g.clone(), *t, *dynamic)
    }

    /// `e` is a string by its form (a literal, an entry holding strings, `?:` with a
    /// string on either side: `ex` gives it [`Ty::Text`] or refuses it).
    fn is_text(&self, e: &Ex) -> bool {
        match &e.k {
            K::Str(_) => true,
            K::Name(n) => self.entry(n).1 == Ty::Text,
            K::Ite(_, a, b) => self.is_text(a) || self.is_text(b),
            // A join gives a string (`btcpp4_script/join.rs`).
            K::Bin("..", ..) => true,
            K::Bin("+", a, b) => self.is_text(a) && self.is_text(b),
            _ => false,
        }
    }

    /// The string `v` (the value of `e`) read as a number, as a comparison with a
    /// number and the condition of `?:` read it (`btcpp4_strings.rs`, `as_number`):
    /// where it throws, under `guard`, and the number.
    fn text_number(&mut self, e: &Ex, v: &Val, guard: &str) -> Result<String, Refuse> {
        // The texts the closure says it may hold (`join.rs`), else every text.
        let possible = self.possible_texts(e);
        let texts: Vec<&str> = match (&e.k, &possible) {
            (K::Str(t), _) => vec![t.as_str()],
            (_, Some(ts)) => ts.iter().map(String::as_str).collect(),
            _ => self.strs.texts.iter().map(String::as_str).collect(),
        };
        let (throws, n) = self
            .strs
            .number(&v.x, &texts)
            .map_err(|w| (e.at, w.to_string()))?;
        if let Some(c) = throws {
            self.check(guard, c);
        }
        Ok(n)
    }

    fn check(&mut self, guard: &str, cond: String) {
        self.checks.push(if guard.is_empty() {
            cond
        } else {
            format!("({guard}) && ({cond})")
        });
    }

    /// An operand of an arithmetic or logic operator, `-` or `!`: a string (an entry
    /// SetBlackboard wrote) throws there (BT.CPP 4.8.2: "Operation not permitted",
    /// "Invalid operator for std::string"), so its value no longer matters.
    fn number(&mut self, e: &Ex, guard: &str) -> Result<Val, Refuse> {
        let v = self.ex(e, guard)?;
        if v.t == Ty::Text {
            self.check(guard, "true".into());
            return Ok(val("0".into(), Ty::Int, "false"));
        }
        Ok(v)
    }

    /// Operand of `&&` / `||`: cast to bool as a condition is (BT.CPP 4.10
    /// `ExprBinaryArithmetic::evaluate` casts both with `Any::cast<bool>` and throws
    /// "Logic operators are not allowed ..." where that throws).
    fn logic_operand(&mut self, e: &Ex, guard: &str) -> Result<String, Refuse> {
        let v = self.number(e, guard)?;
        let (throws, b) = cast_bool(&v);
        if let Some(c) = throws {
            self.check(guard, c);
        }
        Ok(b)
    }

    fn ex(&mut self, e: &Ex, guard: &str) -> Result<Val, Refuse> {
        let refuse = |what: &str| Err((e.at, what.to_string()));
        Ok(match &e.k {
            K::Int(n) => val(n.to_string(), Ty::Int, "false"),
            K::Bool(b) => val(b.to_string(), Ty::Bool, "false"),
            K::Number(t) => {
                let (x, ty) = literal(t).map_err(|w| (e.at, w.to_string()))?;
                let d = if ty == Ty::Real { "true" } else { "false" };
                val(x, ty, d)
            }
            // A string: its rank (`btcpp4_strings.rs`).
            K::Str(t) => val(self.strs.id(t).to_string(), Ty::Text, "false"),
            K::Name(n) => {
                let (g, t, dynamic) = self.entry(n);
                // "Variable not found".
                self.check(guard, format!("!{}", has(&g)));
                // A plugin's `double` port entry always holds a double.
                let d = match (dynamic, t) {
                    (true, _) => dbl(&g),
                    (false, Ty::Real) => "true".into(),
                    (false, _) => "false".into(),
                };
                // An entry a SetBlackboard writes keeps its text's rank beside the
                // value other nodes read.
                let x = if t == Ty::Text && !dynamic {
                    super::btcpp4_strings::sid(&g)
                } else {
                    g
                };
                Val { x, t, d }
            }
            K::Un("-", a) => {
                let v = self.number(a, guard)?;
                let t = if v.t == Ty::Real { Ty::Real } else { Ty::Int };
                val(format!("(-{})", int(&v.x, v.t)), t, "true")
            }
            K::Un("!", a) => {
                // `!static_cast<bool>(x)`: exact, so NaN gives 0.
                let v = self.number(a, guard)?;
                match v.t {
                    Ty::Bool => val(format!("(!{})", v.x), Ty::Bool, "true"),
                    _ => val(format!("({} == 0)", v.x), Ty::Bool, "true"),
                }
            }
            K::Un("~", a) => {
                let v = self.number(a, guard)?;
                self.complement(v, guard)
            }
            K::Un(..) => return refuse(BITS),
            K::Bin(op @ ("+" | "-" | "*" | "/"), a, b) => {
                // Two strings: `+` joins them (`join.rs`); the other operators throw
                // ("Operation not permitted"), as does any of them over a string and a
                // number.
                if *op == "+" && self.is_text(a) && self.is_text(b) {
                    return self.join(e, a, b, guard);
                }
                if *op == "/" && !nonzero_literal(b) {
                    // Any other divisor: computed exactly as BT.CPP's double, sign of zero
                    // included (`exact`).
                    let x = self.number(a, guard)?;
                    let y = self.exact_number(b, guard)?;
                    return Ok(val(
                        format!("({} / {})", int(&x.x, x.t), y.x),
                        Ty::Real,
                        "true",
                    ));
                }
                let x = self.number(a, guard)?;
                let y = self.number(b, guard)?;
                // BT.CPP computes in doubles (`ExprBinaryArithmetic::evaluate`); over
                // whole numbers the model's integers give the same values (up to
                // 2^53), `/` and real operands take the model's floats.
                let t = if *op == "/" || x.t == Ty::Real || y.t == Ty::Real {
                    Ty::Real
                } else {
                    Ty::Int
                };
                val(
                    format!("({} {op} {})", int(&x.x, x.t), int(&y.x, y.t)),
                    t,
                    "true",
                )
            }
            K::Bin("..", a, b) => return self.join(e, a, b, guard),
            K::Bin(op @ ("&&" | "||"), a, b) => {
                let x = self.logic_operand(a, guard)?;
                let y = self.logic_operand(b, guard)?;
                val(format!("({x} {op} {y})"), Ty::Bool, "true")
            }
            K::Bin(op @ ("&" | "|" | "^"), a, b) => {
                let x = self.number(a, guard)?;
                let y = self.number(b, guard)?;
                let x = self.int64(x, guard);
                let y = self.int64(y, guard);
                val(format!("({x} {op} {y})"), Ty::Int, "true")
            }
            K::Bin(..) => return refuse(BITS),
            K::Cmp(xs, ops) => {
                // A string compared with a number is read as one (BT.CPP 4.8.2: the text
                // `3` equals 3, `abc` throws); two strings compare as strings, byte by
                // byte: their ranks (`btcpp4_strings.rs`).
                let mut vs = Vec::with_capacity(xs.len());
                for x in xs {
                    vs.push(self.ex(x, guard)?);
                }
                let mut parts: Vec<String> = Vec::with_capacity(ops.len());
                for (i, op) in ops.iter().enumerate() {
                    let (l, r) = (&vs[i], &vs[i + 1]);
                    if l.t == Ty::Text && r.t == Ty::Text {
                        parts.push(format!("{} {op} {}", l.x, r.x));
                        continue;
                    }
                    // A pair is compared only while the ones before it held
                    // (`ExprComparison::evaluate` returns false at the first that
                    // fails; 4.8.2: `2 < 1 < 'a'` is false, `1 < 2 < 'a'` throws).
                    let mut g = guard.to_string();
                    if !parts.is_empty() {
                        let held = parts.join(" && ");
                        g = if g.is_empty() {
                            held
                        } else {
                            format!("({g}) && {held}")
                        };
                    }
                    let side = |tr: &mut Self, v: &Val, x: &Ex| -> Result<(String, bool), Refuse> {
                        Ok(if v.t == Ty::Text {
                            (tr.text_number(x, v, &g)?, false)
                        } else {
                            (int(&v.x, v.t), v.t == Ty::Real)
                        })
                    };
                    let (l, lr) = side(self, l, &xs[i])?;
                    let (r, rr) = side(self, r, &xs[i + 1])?;
                    parts.push(if lr || rr {
                        compare_real(op, &l, &r)
                    } else {
                        format!("{l} {op} {r}")
                    });
                }
                val(format!("({})", parts.join(" && ")), Ty::Bool, "true")
            }
            K::Ite(c, a, b) => {
                // `ExprIf::evaluate`: `cast<double>() != 0`, so any number but 0 (NaN
                // too) is true; a string is read as a number (4.8.2: the text `0` is
                // false).
                let cv = self.ex(c, guard)?;
                let cond = match cv.t {
                    Ty::Bool => cv.x,
                    Ty::Text => format!("({} != 0)", self.text_number(c, &cv, guard)?),
                    Ty::Int | Ty::Real => format!("({} != 0)", cv.x),
                };
                let join = |g: &str, c: &str| {
                    if g.is_empty() {
                        c.to_string()
                    } else {
                        format!("({g}) && {c}")
                    }
                };
                // Only the branch taken is evaluated: its checks only count then.
                let x = self.ex(a, &join(guard, &cond))?;
                let y = self.ex(b, &join(guard, &format!("!{cond}")))?;
                match (x.t == Ty::Text, y.t == Ty::Text) {
                    (true, true) => {
                        return Ok(val(
                            format!("({cond} ? {} : {})", x.x, y.x),
                            Ty::Text,
                            "false",
                        ))
                    }
                    (false, false) => {}
                    _ => {
                        let at = if x.t == Ty::Text { a.at } else { b.at };
                        return Err((at, "a string on one side of `?:` and a number on the other: the value's type would depend on the condition, which is not modelled".into()));
                    }
                }
                let d = match (x.d.as_str(), y.d.as_str()) {
                    (l, r) if l == r => l.to_string(),
                    (l, r) => format!("({cond} ? {l} : {r})"),
                };
                let (xx, t) = if x.t == Ty::Bool && y.t == Ty::Bool {
                    (format!("({cond} ? {} : {})", x.x, y.x), Ty::Bool)
                } else {
                    let t = if x.t == Ty::Real || y.t == Ty::Real {
                        Ty::Real
                    } else {
                        Ty::Int
                    };
                    (
                        format!("({cond} ? {} : {})", int(&x.x, x.t), int(&y.x, y.t)),
                        t,
                    )
                };
                Val { x: xx, t, d }
            }
        })
    }
}

/// A string statement on entry `g` where a plugin's `string` input port reads it
/// (`port`, [`super::btcpp4_strings::Strings::port_entries`]): the rank goes to
/// `bt_sid__g` and the text it stands for to `g`, which the plugins read.
fn to_port(bb: &Blackboard, g: &str, port: bool, mut l: Lowered) -> Lowered {
    if !port {
        return l;
    }
    let sid = super::btcpp4_strings::sid(g);
    let mut assigns = Vec::new();
    for (var, x) in l.assigns {
        if var == g {
            assigns.push((sid.clone(), x));
            assigns.push((g.to_string(), bb.strings.text_of(&sid)));
        } else {
            assigns.push((var, x));
        }
    }
    l.assigns = assigns;
    if l.value.x == g {
        l.value.x = sid;
    }
    l
}

/// One statement: what makes it throw, the assignments, its value.
struct Lowered {
    checks: Vec<String>,
    assigns: Vec<(String, String)>,
    value: Val,
}

fn statement(names: &[Name], bb: &Blackboard, s: &Stmt) -> Result<Lowered, Refuse> {
    let mut tr = Tr {
        names,
        strs: &bb.strings,
        bb,
        checks: Vec::new(),
    };
    if let Some((target, op, at)) = &s.assign {
        if let (g, Ty::Real, false) = tr.entry(target) {
            return Err((*at, format!("a script writing `{g}`, which a plugin's output port types as a double: BT.CPP 4 would store the script's value as it is where the entry holds nothing yet and convert the plugin's later doubles to its type, which is not modelled (read it in scripts; write another entry)")));
        }
        if tr.entry(target).1 == Ty::Real {
            return num::float_statement(tr, target, op, &s.e);
        }
    }
    let v = tr.ex(&s.e, "")?;
    let Some((target, op, at)) = &s.assign else {
        return Ok(Lowered {
            checks: tr.checks,
            assigns: Vec::new(),
            value: v,
        });
    };
    let (g, et, dynamic) = tr.entry(target);
    let (x, t) = (v.x.as_str(), v.t);
    let port_text = bb.strings.port_entries.contains(&g);
    if et == Ty::Text && !dynamic && !port_text {
        return Err((*at, format!("a script writing `{g}`, which a SetBlackboard writes: BT.CPP 4 holds a string there (4.8.2 refuses to assign it a number), which is not modelled")));
    }
    if et == Ty::Text && t == Ty::Text && *op == "+=" {
        return tr
            .plus_assign(&g, v, &s.e, *at)
            .map(|l| to_port(bb, &g, port_text, l));
    }
    if et == Ty::Text || t == Ty::Text {
        let exists = tr.exists(&g);
        return assign_text(tr.checks, &g, &exists, et == Ty::Text, v, op, *at)
            .map(|l| to_port(bb, &g, port_text, l));
    }
    if t == Ty::Real || *op == "/=" {
        return Err((
            *at,
            format!("`{op}` storing a number that need not be whole in `{g}`: {STORE_REAL}"),
        ));
    }
    match *op {
        ":=" => {}
        // "The blackboard entry [..] doesn't exist".
        "=" => tr.checks.push(format!("!{}", tr.exists(&g))),
        // It exists without a value: "The left operand [..] is not initialized".
        _ => tr.checks.push(format!("!{}", has(&g))),
    }
    let new = match (*op, et, t) {
        (":=" | "=", Ty::Int, _) => int(x, t),
        (":=" | "=", Ty::Bool, Ty::Bool) => x.to_string(),
        (":=" | "=", Ty::Bool, _) => {
            return Err((*at, format!("assigning an integer to the boolean entry `{g}` (typed by a port) is not modelled: assign a boolean")))
        }
        (_, Ty::Bool, _) => {
            return Err((*at, format!("`{op}` on the boolean entry `{g}` (typed by a port) is not modelled")))
        }
        (_, Ty::Int, _) => format!("({g} {} {})", &op[..1], int(x, t)),
        (_, Ty::Text | Ty::Real, _) => unreachable!("refused above"),
    };
    let mut assigns = Vec::new();
    if dynamic {
        // BT.CPP 4.10 `ExprAssignment::evaluate`: the first value of an entry a script
        // creates goes in as it is (an `int64_t` or a `double`); later ones are
        // converted to that type (`Any::copyInto`).
        let d = dbl(&g);
        assigns.push((d.clone(), format!("({} ? {d} : {})", has(&g), v.d)));
    }
    assigns.push((g.clone(), new));
    assigns.push((has(&g), "true".into()));
    let d = if dynamic { dbl(&g) } else { "false".into() };
    Ok(Lowered {
        checks: tr.checks,
        assigns,
        value: Val { x: g, t: et, d },
    })
}

/// The body of a blackboard-machine transition that runs `code` (a script of node `n`
/// written at `span`, named `label` in errors) and then does `then(value)`: `value` is
/// the script's value as a boolean expression when `condition` (cast as BT.CPP casts
/// it: 0 or 1, else the script throws), `None` otherwise. `None` after reporting an
/// error.
#[allow(clippy::too_many_arguments)]
pub(super) fn compile(
    sm: &SourceMap,
    n: &TreeNode,
    b: &super::build::B,
    code: &str,
    span: Span,
    label: &str,
    condition: bool,
    then: &dyn Fn(Option<String>) -> Vec<Element>,
    bb: &mut Blackboard,
    errs: &mut Vec<Diagnostic>,
) -> Option<Vec<Element>> {
    // Syntax errors were reported where the tree was read.
    let stmts = script::parse(code).ok()?;
    let names = resolve(sm, n, span, bb, errs)?;
    let mut lowered = Vec::new();
    for s in &stmts {
        match statement(&names, bb, s) {
            Ok(l) => lowered.push(l),
            Err((at, why)) => {
                errs.push(sm.diag(
                    span,
                    format!("{label}: {why} (at column {} of the script)", at + 1),
                ));
                return None;
            }
        }
    }
    let fault = || vec![b.assign(FAULT, "true")];
    // Innermost: what follows, after every statement.
    let last = &lowered.last().expect("a statement").value;
    let mut inner = if condition {
        let (check, value) = match last.t {
            // A string: 4.8.2 throws ("no known safe conversion between [std::string]
            // and [bool]").
            Ty::Text => (Some("true".into()), "false".into()),
            _ => cast_bool(last),
        };
        let rest = then(Some(value));
        match check {
            None => rest,
            Some(c) => vec![b.if_chain(vec![(c, fault())], rest).expect("one branch")],
        }
    } else {
        then(None)
    };
    for l in lowered.into_iter().rev() {
        let mut body: Vec<Element> = l.assigns.iter().map(|(g, e)| b.assign(g, e)).collect();
        // Every assignment is a write (`Entry::sequence_id`, `btcpp4_blackboard.rs`).
        body.extend(
            l.assigns
                .iter()
                .filter_map(|(g, _)| super::btcpp4_blackboard::count_write(bb, *b, g)),
        );
        body.extend(inner);
        inner = if l.checks.is_empty() {
            body
        } else {
            let any = l
                .checks
                .iter()
                .map(|c| format!("({c})"))
                .collect::<Vec<_>>()
                .join(" || ");
            vec![b.if_chain(vec![(any, fault())], body).expect("one branch")]
        };
    }
    Some(inner)
}

/// Lowers the script of port `key` of node `n` into the blackboard machine: the
/// transition on `bt_script_<id>_run` (answering with the value cast to a boolean when
/// `condition`). `false` after reporting an error.
fn lower_script(
    sm: &SourceMap,
    n: &TreeNode,
    ctx: &Ctx,
    key: &str,
    condition: bool,
    bb: &mut Blackboard,
    errs: &mut Vec<Diagnostic>,
) -> bool {
    let node = super::btcpp4::node_name(super::tree::Btcpp4::Script(kind_of(key, condition)));
    let Some(p) = n.port(key) else {
        errs.push(sm.diag(
            n.span,
            format!("{node} needs `{key}` (BehaviorTree.CPP throws \"Missing port [{key}]\")"),
        ));
        return false;
    };
    let code = match &p.value {
        PortValue::Literal(c) => c.clone(),
        PortValue::Blackboard(e) => {
            errs.push(sm.diag(
                p.span,
                format!("`{key}` of {node} must be the script itself; a blackboard entry (`{{{e}}}`) is not supported here"),
            ));
            return false;
        }
    };
    let b = ctx.b;
    let (done, me) = (done_event(n.id), ctx.machine.clone());
    let then = |v: Option<String>| match v {
        Some(v) => vec![b.send_params(&done, &me, &[("value", &v)])],
        None => vec![b.send(&done, &me)],
    };
    let label = format!("`{key}` of {node}");
    let Some(body) = compile(sm, n, &b, &code, p.span, &label, condition, &then, bb, errs) else {
        return false;
    };
    bb.scripts
        .push(b.tr(Some(&run_event(n.id)), None, Some("idle"), body));
    true
}

fn kind_of(key: &str, condition: bool) -> ScriptNode {
    match (key, condition) {
        ("if", _) => ScriptNode::Precondition,
        (_, true) => ScriptNode::Condition,
        _ => ScriptNode::Script,
    }
}

/// Checks node `n` (a Script, ScriptCondition or Precondition) and builds its machine.
pub(super) fn lower(
    sm: &SourceMap,
    k: ScriptNode,
    n: &TreeNode,
    ctx: &Ctx,
    bb: &mut Blackboard,
    errs: &mut Vec<Diagnostic>,
) -> Option<Element> {
    match k {
        ScriptNode::Script => {
            lower_script(sm, n, ctx, "code", false, bb, errs).then(|| script_node(ctx, false))
        }
        ScriptNode::Condition => {
            lower_script(sm, n, ctx, "code", true, bb, errs).then(|| script_node(ctx, true))
        }
        ScriptNode::Precondition => {
            // `PreconditionNode::providedPorts`: `else` defaults to FAILURE, read with
            // `convertFromString<NodeStatus>`.
            let otherwise = match n.port("else").map(|p| (&p.value, p.span)) {
                None => FAILURE,
                Some((PortValue::Literal(v), span)) => match super::control::status_code(v) {
                    Some(s) => s,
                    // `else` is answered only while the child has not started, so the
                    // node is not RUNNING then: SKIPPED with the node IDLE (code 4).
                    None if v.trim() == "SKIPPED" => super::control::SKIPPED,
                    None => {
                        let why =
                            format!("`{}` is not SUCCESS, FAILURE, RUNNING or SKIPPED", v.trim());
                        errs.push(sm.diag(span, format!("`else` of Precondition: {why}")));
                        return None;
                    }
                },
                Some((PortValue::Blackboard(e), span)) => {
                    errs.push(sm.diag(span, format!("`else` of Precondition must be a constant status; a blackboard entry (`{{{e}}}`) is not supported here")));
                    return None;
                }
            };
            lower_script(sm, n, ctx, "if", true, bb, errs).then(|| precondition(ctx, otherwise))
        }
    }
}

/// The machine of a node that is never RUNNING and works in the blackboard machine:
/// idle in `wait_for_tick`, a tick sends `request` to the blackboard machine and goes to
/// `next` (where the node waits for the answer), a halt answers at once.
pub(super) fn asking_machine(ctx: &Ctx, next: &str, request: &str) -> Element {
    let b = &ctx.b;
    let mut m = b.scxml(&ctx.machine, "wait_for_tick");
    m.push(
        b.state("wait_for_tick")
            .with_child(b.tr(
                Some(&ctx.tick_ev()),
                None,
                Some(next),
                vec![b.send(request, MACHINE)],
            ))
            .with_child(b.tr(
                Some(&ctx.halt_ev()),
                None,
                Some("wait_for_tick"),
                vec![ctx.respond_halted()],
            )),
    );
    m
}

/// Script (`condition` false) or ScriptCondition: a tick runs the script in the
/// blackboard machine; Script answers SUCCESS (BT.CPP 4.10 `actions/script_node.h`,
/// `ScriptNode::tick`), ScriptCondition SUCCESS if the value is true, else FAILURE
/// (`actions/script_condition.h`, `ScriptCondition::tick`). Neither is ever RUNNING, so
/// a halt answers at once.
fn script_node(ctx: &Ctx, condition: bool) -> Element {
    let b = &ctx.b;
    let mut m = asking_machine(ctx, "running_script", &run_event(ctx.id));
    let done = done_event(ctx.id);
    let mut r = b.state("running_script");
    if condition {
        r.push(b.tr(
            Some(&done),
            Some("_event.data.value"),
            Some("wait_for_tick"),
            vec![ctx.respond(SUCCESS)],
        ));
        r.push(b.tr(
            Some(&done),
            None,
            Some("wait_for_tick"),
            vec![ctx.respond(FAILURE)],
        ));
    } else {
        r.push(b.tr(
            Some(&done),
            None,
            Some("wait_for_tick"),
            vec![ctx.respond(SUCCESS)],
        ));
    }
    m.push(r);
    m
}

/// Precondition as BT.CPP 4.10 runs it (`decorators/script_precondition.h`,
/// `PreconditionNode::tick`): the `if` script runs only while the child has not started
/// (`_children_running`); false answers `else`; true ticks the child; a finished child
/// is reset (`resetChild`: not RUNNING, so no halt) and the script is due again. A halt
/// (`DecoratorNode::halt`) halts the child if RUNNING and keeps `_children_running`:
/// the next tick goes straight to the child.
fn precondition(ctx: &Ctx, otherwise: u8) -> Element {
    let b = &ctx.b;
    let memo = "children_running";
    let r = super::btcpp::running(ctx, 0);
    let mut m = b.scxml(&ctx.machine, "init");
    m.push(b.datamodel(&[
        ("children_count", "int8", n_children(ctx)),
        (memo, "bool", "false".into()),
        (r.as_str(), "bool", "false".into()),
        (SELF_RUNNING, "bool", "false".into()),
    ]));
    m.push(init_state(ctx, "children_count != 1"));
    let mut w = b
        .state("wait_for_tick")
        .with_child(b.tr(Some(&ctx.tick_ev()), Some(memo), Some("tick_child"), vec![]))
        .with_child(b.tr(
            Some(&ctx.tick_ev()),
            None,
            Some("running_script"),
            vec![b.send(&run_event(ctx.id), MACHINE)],
        ));
    // A halt resets the node's status (`haltNode`); `_children_running` stays.
    for t in ctx.halt_single("halting_child", vec![b.assign(SELF_RUNNING, "false")]) {
        w.push(t);
    }
    m.push(w);
    let done = done_event(ctx.id);
    m.push(
        b.state("running_script")
            .with_child(b.tr(
                Some(&done),
                Some("_event.data.value"),
                Some("tick_child"),
                vec![b.assign(memo, "true")],
            ))
            .with_child(b.tr(
                Some(&done),
                None,
                Some("wait_for_tick"),
                super::btcpp4_skip::else_answer(ctx, otherwise),
            )),
    );
    m.push(super::btcpp4_skip::precondition_halting(ctx));
    let mut t = b.state_entry("tick_child", vec![ctx.tick_child(0)]);
    for s in [SUCCESS, FAILURE, RUNNING] {
        let mut body = Vec::new();
        if s != RUNNING {
            body.push(b.assign(memo, "false"));
        }
        body.push(b.assign(SELF_RUNNING, if s == RUNNING { "true" } else { "false" }));
        body.push(ctx.respond(s));
        t.push(b.tr(
            Some(&ctx.child_resp(0)),
            Some(&format!("_event.data.status == {s}")),
            Some("wait_for_tick"),
            ctx.marked(0, s, body),
        ));
    }
    t.push(super::btcpp4_skip::precondition_child_skipped(ctx));
    m.push(t);
    m.push(b.state("error"));
    m
}
