//! The numeric part of BehaviorTree.CPP 4's script language that needs BT.CPP's doubles
//! exactly (`--bt btcpp`): the bit operators `~ & | ^`, divisors other than a number
//! literal, and entries that hold a number that need not be whole (`x := 5/2`,
//! `x /= 2`, `x := 2.5`), which become the model's `float64` variables.
//!
//! The rules, from BT.CPP 4.10 `include/behaviortree_cpp/scripting/operators.hpp` and as
//! the real library 4.8.2 answers them (measured through `behaviortreepy`; the oracle's
//! `bit_operators_and_stored_reals_as_the_real_library_answers` keeps the answers):
//! - `a & b`, `a | b`, `a ^ b` (`ExprBinaryArithmetic::evaluate`) convert both operands
//!   with `Any::cast<int64_t>`, which throws for a double that is not whole, NaN, an
//!   infinity or one out of the 64-bit range (4.8.2: `2.5 & 1`, `(0/0) & 1`, `1e19 & 1`
//!   throw, `(4/2) & 1` is 0, `9e18 & 1` is 0); the result is a `double`.
//! - `~a` (`ExprUnaryArithmetic::evaluate`, `complement`) truncates the double toward
//!   zero (`~2.5` is -3, `~(-2.5)` is 1); 4.8.2 throws for an infinity or a value out
//!   of the 64-bit range (`~(1/0)`, `~1e19`) and gives 2^63 for NaN (`~(0/0)` is
//!   9.223372036854776e18: the complement of the integer x86 makes of NaN).
//! - Every operator computes in doubles (`lhs_v.cast<double>()`), so `1 / -x` with `x`
//!   an integer entry holding 0 is -inf (4.8.2) while the model's integer `-x` is 0, whose
//!   float is +0: a divisor other than a number literal is computed here in the model's
//!   floats from its leaves up ([`Tr::exact`]), as BT.CPP computes it.
//! - An entry a script creates takes the type of its first value (`ExprAssignment::evaluate`:
//!   the first `:=` stores the `Any` as it is); a later value is converted to that type
//!   (`Any::copyInto`): into an `int64_t` entry a double must be whole (4.8.2: `a := 1;
//!   a := 5/2` and `a := 1; a /= 2` throw "Invalid floating point to integer
//!   conversion"; `a := 1; a := 2/2` stores 1), into a `double` entry anything goes
//!   (`a := 1.5; a := 3` holds 3.0, `a := 0+0; a /= 0` NaN). The model keeps such an
//!   entry as a `float64` variable beside its `bt_dbl__` flag (which says whether BT.CPP
//!   holds a `double` or an `int64_t`); an `int64_t` entry's value is stored without a
//!   sign of zero (`a := 0; a := -a` then `1/a` is +inf, `a := 0+0; a := -a` then
//!   `1/a` is -inf).
//!
//! Which entries are floats is decided before any script is lowered
//! ([`float_entries`]): an entry a LoopDouble writes and a script names (the Loop may
//! store a double there, `btcpp4_loop.rs`, `Store`), an entry only scripts create that
//! some script may store a double that need not be whole in (`/=`, or a value with `/`,
//! a real literal, or a float entry in it), and every entry only scripts create when
//! some script divides by something other than a number literal (any double stored then
//! may be a negative zero).

use super::super::blackboard::Blackboard;
use super::super::script::{self, Ex, K};
use super::super::tree::{Btcpp4, Control, Kind, LoopType, PortValue, Tree};
use super::{dbl, has, int, val, Lowered, Refuse, Tr, Ty, Val};

/// 2^63: a double at or beyond it (in size) is out of `int64_t`'s range.
const I64_END: &str = "9223372036854775808.0";

/// The model type of an entry only scripts create: `float64` for one [`float_entries`]
/// chose, else `int64`.
pub(crate) fn entry_type(bb: &Blackboard, g: &str) -> &'static str {
    if bb.floats.iter().any(|f| f == g) {
        "float64"
    } else {
        "int64"
    }
}

/// A node's map from script names to entries (`TreeNode::script_names`).
type Names<'t> = &'t [(String, PortValue)];

/// The scripts of the tree, each with its node's name-to-entry map.
fn scripts(tree: &Tree) -> Vec<(Vec<script::Stmt>, Names<'_>)> {
    let mut out = Vec::new();
    for n in &tree.nodes {
        let mut codes: Vec<&str> = n.conds.iter().map(|c| c.code.as_str()).collect();
        if matches!(n.kind, Kind::Control(Control::Btcpp4(Btcpp4::Script(_)))) {
            for key in ["code", "if"] {
                if let Some(PortValue::Literal(c)) = n.port(key).map(|p| &p.value) {
                    codes.push(c);
                }
            }
        }
        for c in codes {
            if let Ok(stmts) = script::parse(c) {
                out.push((stmts, n.script_names.as_slice()));
            }
        }
    }
    out
}

/// Calls `f` on `e` and every expression in it.
fn walk(e: &Ex, f: &mut dyn FnMut(&Ex)) {
    f(e);
    match &e.k {
        K::Un(_, a) => walk(a, f),
        K::Bin(_, a, b) => {
            walk(a, f);
            walk(b, f);
        }
        K::Cmp(xs, _) => xs.iter().for_each(|x| walk(x, f)),
        K::Ite(c, a, b) => {
            walk(c, f);
            walk(a, f);
            walk(b, f);
        }
        _ => {}
    }
}

/// Before any script is lowered: the entries only scripts create that are to be the
/// model's floats (the module's documentation says which), into `bb.floats`.
pub(crate) fn float_entries(tree: &Tree, bb: &mut Blackboard) {
    let entry = |names: &[(String, PortValue)], n: &str| {
        names
            .iter()
            .find(|(k, _)| k == n)
            .and_then(|(_, v)| match v {
                PortValue::Blackboard(g) => Some(g.clone()),
                PortValue::Literal(_) => None,
            })
    };
    // Only scripts create it: no port, BlackboardCheck, SetBlackboard or Loop types it.
    let scripts_only =
        |bb: &Blackboard, g: &str| bb.entry(g).is_none() && !bb.texts.iter().any(|t| t == g);
    let all = scripts(tree);
    let mut any_divisor = false;
    // (entry, operator, value, names)
    let mut writes = Vec::new();
    for (stmts, names) in &all {
        for s in stmts {
            walk(&s.e, &mut |x| {
                if let K::Bin("/", _, b) = &x.k {
                    any_divisor |= !nonzero_literal(b);
                }
            });
            if let Some((t, op, _)) = &s.assign {
                if let Some(g) = entry(names, t) {
                    writes.push((g, *op, &s.e, *names));
                }
            }
        }
    }
    // Every entry a LoopDouble writes and a script names: the Loop may store a double
    // there (`btcpp4_loop.rs`, `Store`).
    let mut floats: Vec<String> = Vec::new();
    let named = |g: &str| {
        all.iter().any(|(_, names)| {
            names
                .iter()
                .any(|(_, v)| matches!(v, PortValue::Blackboard(x) if x == g))
        })
    };
    for n in &tree.nodes {
        if n.kind != Kind::Control(Control::Btcpp4(Btcpp4::Loop(LoopType::Double))) {
            continue;
        }
        if let Some(PortValue::Blackboard(g)) = n.port("value").map(|p| &p.value) {
            if named(g) && scripts_only(bb, g) && !floats.contains(g) {
                floats.push(g.clone());
            }
        }
    }
    loop {
        let mut grew = false;
        for (g, op, e, names) in &writes {
            if floats.contains(g) || !scripts_only(bb, g) {
                continue;
            }
            let mut real = any_divisor || *op == "/=";
            walk(e, &mut |x| {
                real |= match &x.k {
                    K::Bin("/", ..) => true,
                    K::Number(t) => literal(t).is_ok_and(|(_, ty)| ty == Ty::Real),
                    K::Name(n) => {
                        entry(names, n).is_some_and(|h| floats.contains(&h) || port_double(bb, &h))
                    }
                    _ => false,
                }
            });
            if real {
                floats.push(g.clone());
                grew = true;
            }
        }
        if !grew {
            break;
        }
    }
    bb.floats = floats;
}

/// Whether entry `g` is a `double` a plugin's port types (scripts read it as one).
fn port_double(bb: &Blackboard, g: &str) -> bool {
    bb.entry(g)
        .is_some_and(|e| e.why != "a script" && e.ty.trim() == "float64")
}

impl Tr<'_> {
    /// `e` as BT.CPP's `double` of it, exactly (the sign of a zero included), as a model
    /// `float64` expression; `d` says whether BT.CPP holds a `double` (else an
    /// `int64_t`, whose double has no negative zero).
    pub(super) fn exact(&mut self, e: &Ex, guard: &str) -> Result<Val, Refuse> {
        let flt = |v: Val| -> Val {
            let x = match v.t {
                Ty::Real => v.x,
                Ty::Bool => format!("({} ? 1.0 : 0.0)", v.x),
                // An integer is never a negative zero: `+ 0.0` makes it a float as it is.
                Ty::Int | Ty::Text => format!("({} + 0.0)", v.x),
            };
            Val {
                x,
                t: Ty::Real,
                d: v.d,
            }
        };
        Ok(match &e.k {
            K::Un("-", a) => {
                let x = self.exact_number(a, guard)?;
                val(format!("(-{})", x.x), Ty::Real, "true")
            }
            K::Bin(op @ ("+" | "-" | "*" | "/"), a, b) => {
                if self.is_text(a) && self.is_text(b) {
                    // `ex` refuses it with why.
                    return self.ex(e, guard).map(flt);
                }
                let x = self.exact_number(a, guard)?;
                let y = self.exact_number(b, guard)?;
                val(format!("({} {op} {})", x.x, y.x), Ty::Real, "true")
            }
            K::Ite(c, a, b) => {
                if [a, b].into_iter().any(|x| self.is_text(x)) {
                    return self.ex(e, guard).map(flt);
                }
                let cv = self.ex(c, guard)?;
                let cond = match cv.t {
                    Ty::Bool => cv.x,
                    _ => format!("({} != 0)", cv.x),
                };
                let join = |g: &str, c: &str| {
                    if g.is_empty() {
                        c.to_string()
                    } else {
                        format!("({g}) && {c}")
                    }
                };
                let x = self.exact(a, &join(guard, &cond))?;
                let y = self.exact(b, &join(guard, &format!("!{cond}")))?;
                let d = if x.d == y.d {
                    x.d.clone()
                } else {
                    format!("({cond} ? {} : {})", x.d, y.d)
                };
                Val {
                    x: format!("({cond} ? {} : {})", x.x, y.x),
                    t: Ty::Real,
                    d,
                }
            }
            // Literals, entries, and the operators whose value is never a negative zero
            // (comparisons, `!`, `&&`, `||`, the bit operators).
            _ => flt(self.ex(e, guard)?),
        })
    }

    /// An operand of an arithmetic operator, exactly: a SetBlackboard's text throws
    /// there (as in [`Tr::number`]).
    pub(super) fn exact_number(&mut self, e: &Ex, guard: &str) -> Result<Val, Refuse> {
        if self.is_text(e) {
            self.number(e, guard)?;
            return Ok(val("0.0".into(), Ty::Real, "false"));
        }
        self.exact(e, guard)
    }

    /// `Any::cast<int64_t>` of an operand of `& | ^`: a double that is not whole, NaN, an
    /// infinity or out of range throws ("Binary operators are not allowed if one of the
    /// operands is not an integer").
    pub(super) fn int64(&mut self, v: Val, guard: &str) -> String {
        match v.t {
            Ty::Real => {
                let x = &v.x;
                self.check(
                    guard,
                    format!("!({x} % 1 == 0 && Math.abs({x}) < {I64_END})"),
                );
                format!("Math.trunc({x})")
            }
            _ => int(&v.x, v.t),
        }
    }

    /// `~v`: the complement of the value truncated toward zero; an infinity or a value
    /// out of range throws, NaN gives 2^63 (4.8.2).
    pub(super) fn complement(&mut self, v: Val, guard: &str) -> Val {
        match v.t {
            Ty::Real => {
                let x = &v.x;
                self.check(guard, format!("{x} == {x} && !(Math.abs({x}) < {I64_END})"));
                val(
                    format!("({x} != {x} ? {I64_END} : (~Math.trunc({x}) + 0.0))"),
                    Ty::Real,
                    "true",
                )
            }
            _ => val(format!("(~{})", int(&v.x, v.t)), Ty::Int, "true"),
        }
    }
}

/// `target op e` for a float entry ([`float_entries`]): BT.CPP 4.10
/// `ExprAssignment::evaluate`. The first `:=` gives the entry the type of its value
/// (the `bt_dbl__` flag); `op=` computes in doubles; a value stored into an `int64_t`
/// entry must be whole and in range (else it throws) and loses the sign of a zero.
pub(super) fn float_statement(
    mut tr: Tr<'_>,
    target: &str,
    op: &str,
    e: &Ex,
) -> Result<Lowered, Refuse> {
    let (g, _, _) = tr.entry(target);
    if tr.is_text(e) {
        return Err((e.at, format!("assigning a SetBlackboard's text to `{g}`: BT.CPP 4 copies the string, and strings in scripts are not modelled yet")));
    }
    let v = tr.exact(e, "")?;
    let (h, d) = (has(&g), dbl(&g));
    match op {
        ":=" => {}
        // "The blackboard entry [..] doesn't exist".
        "=" => tr.checks.push(format!("!{}", tr.exists(&g))),
        // "The left operand [..] is not initialized".
        _ => tr.checks.push(format!("!{h}")),
    }
    let new = match op {
        ":=" | "=" => v.x.clone(),
        _ => format!("({g} {} {})", &op[..1], v.x),
    };
    // An `int64_t` entry after this statement: it held one, or `:=` creates it from one.
    let int_entry = format!("(({h} && !{d}) || (!{h} && !({})))", v.d);
    tr.checks.push(format!(
        "{int_entry} && !(({new}) % 1 == 0 && Math.abs({new}) < {I64_END})"
    ));
    let assigns = vec![
        (d.clone(), format!("({h} ? {d} : {})", v.d)),
        (
            g.clone(),
            format!("({int_entry} ? (({new}) + 0.0) : {new})"),
        ),
        (h, "true".into()),
    ];
    Ok(Lowered {
        checks: tr.checks,
        assigns,
        value: Val {
            x: g,
            t: Ty::Real,
            d,
        },
    })
}

/// A number literal other than 0, possibly negated: a divisor the model's floats divide
/// by as BT.CPP's doubles do (no zero, so no sign of zero to lose).
pub(super) fn nonzero_literal(e: &Ex) -> bool {
    match &e.k {
        K::Int(n) => *n != 0,
        K::Number(t) => literal(t).is_ok_and(|(x, _)| x.parse::<f64>().is_ok_and(|v| v != 0.0)),
        K::Un("-", a) => nonzero_literal(a),
        _ => false,
    }
}

/// A real literal as BT.CPP 4 reads it (`scripting/any_types.hpp`, `Grammar::Real`:
/// digits, then `.digits` and an optional exponent, or an exponent; `std::stod`, which
/// refuses a value out of range) or a hexadecimal integer (`Grammar::Integer`).
pub(super) fn literal(t: &str) -> Result<(String, Ty), BadNumber> {
    if let Some(h) = t.strip_prefix("0x").or_else(|| t.strip_prefix("0X")) {
        return i64::from_str_radix(h, 16)
            .map(|v| (v.to_string(), Ty::Int))
            .map_err(|_| BadNumber::Unread(t.to_string()));
    }
    let b = t.as_bytes();
    let digits = |mut i: usize| {
        let s = i;
        while i < b.len() && b[i].is_ascii_digit() {
            i += 1;
        }
        (i, i > s)
    };
    let (mut i, _) = digits(0);
    let mut real = false;
    if i < b.len() && b[i] == b'.' {
        let (j, some) = digits(i + 1);
        if !some {
            return Err(BadNumber::Refused(t.to_string()));
        }
        (i, real) = (j, true);
    }
    if i < b.len() && (b[i] == b'e' || b[i] == b'E') {
        let j = i + 1 + usize::from(b.get(i + 1).is_some_and(|c| *c == b'+' || *c == b'-'));
        let (k, some) = digits(j);
        if !some {
            return Err(BadNumber::Refused(t.to_string()));
        }
        (i, real) = (k, true);
    }
    if i != b.len() || !real {
        return Err(BadNumber::Refused(t.to_string()));
    }
    let v: f64 = t.parse().map_err(|_| BadNumber::Unread(t.to_string()))?;
    let zero = t
        .split(['e', 'E'])
        .next()
        .is_some_and(|m| m.bytes().all(|c| c == b'0' || c == b'.'));
    if !v.is_finite() || (!v.is_normal() && !zero) {
        return Err(BadNumber::OutOfRange(t.to_string()));
    }
    Ok((format!("{v:?}"), Ty::Real))
}

/// Why [`literal`] refused a number (the number as written).
#[derive(Debug, Clone, PartialEq, Eq)]
pub(super) enum BadNumber {
    /// Not a number BT.CPP 4 reads.
    Unread(String),
    /// Outside BT.CPP 4's grammar: 4.8.2 refuses it when the tree loads.
    Refused(String),
    /// Outside a double's range: `std::stod` throws when the tree loads.
    OutOfRange(String),
}

impl std::fmt::Display for BadNumber {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            BadNumber::Unread(t) => write!(f, "the number `{t}` is not one BT.CPP 4 reads"),
            BadNumber::Refused(t) => write!(
                f,
                "the number `{t}` is not one BT.CPP 4 reads (4.8.2 refuses it at load)"
            ),
            BadNumber::OutOfRange(t) => write!(
                f,
                "the number `{t}` is out of a double's range (BT.CPP's `std::stod` throws at load)"
            ),
        }
    }
}
