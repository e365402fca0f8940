//! Joining strings in BehaviorTree.CPP 4's script language under `--bt btcpp`: `a .. b`,
//! `a + b` over two strings and `s += t` on an entry holding a string.
//!
//! The model holds a string as its rank among the tree's texts in byte order
//! (`btcpp4_strings.rs`). A join makes texts the tree does not spell out, so before any
//! node is lowered [`closure`] computes the closed set of texts each string entry can
//! hold and each join can make: a fixed point over the scripts' assignments (within one
//! script, an entry assigned by an earlier statement holds just what that statement
//! stored), capped at [`CAP`] texts and a number of rounds. A tree whose texts are unbounded (`s := s .. 'a'`
//! ticked again and again) or beyond the cap is refused at each script that joins, with
//! the entry that grew. A join then lowers as a table over the ranks of its operands
//! ([`Tr::join`]): nested `?:` that give the rank of each pair's text.
//!
//! The rules, from BT.CPP 4.10 `include/behaviortree_cpp/scripting/operators.hpp`
//! (`ExprBinaryArithmetic::evaluate`, `concat` and `plus`; `ExprAssignment::evaluate`,
//! `assign_plus`; the grammar's `string_concat`), each measured in the real library
//! 4.8.2 through `behaviortreepy` (the oracle's `joins_as_the_real_library_answers`
//! keeps the answers), which decides where the two differ:
//! - `a .. b` joins two strings, or a string and a number, converting the number with
//!   `Any::cast<std::string>`: an `int64_t` (a literal integer, `true`, `false`, a hex
//!   literal) as its decimal digits (`'a' .. 3` is `a3`, `'a' .. true` `a1`,
//!   `'a' .. 0x10` `a16`), a `double` as `printf`'s `%f` (`'a' .. 1.5` is `a1.500000`,
//!   `'a' .. (1/0)` `ainf`, `'a' .. (0/0)` `a-nan`). Only number literals (possibly
//!   negated, in parentheses) are joined here: the text of a computed number is not
//!   modelled.
//! - Two numbers: 4.10's source throws "Operation not permitted"; 4.8.2 gives an empty
//!   value instead, which throws only where it is used (`3 .. 4` alone as a Script is
//!   SUCCESS, `s := 3 .. 4` throws "not initialized"): refused.
//! - `+` of two strings joins them too (4.8.2: `'a' + 'b'` is `ab`; an entry a
//!   SetBlackboard wrote is a string: `k + k` is `77` after `value="7"`); `+` of a string
//!   and a number throws "Operation not permitted" (`btcpp4_script.rs`).
//! - `s += t` with both strings joins (`s := 'a'; s += 'b'` holds `ab`).
//! - `..` is its own operator group, tighter than the comparisons, grouping to the left
//!   (`script.rs`).

use super::super::btcpp4_strings::Strings;
use super::super::script::{Ex, K};
use super::{literal, val, Lowered, Refuse, Tr, Ty, Val};
use std::collections::{BTreeMap, BTreeSet};

/// Most texts a tree may hold, and most texts one entry's set may grow to, before the
/// tree is refused.
pub(crate) const CAP: usize = 2_000;

/// Most cells of one join's table (pairs of texts its operands may hold).
const TABLE: usize = 1_024;

/// Why a join of two numbers is refused.
const TWO_NUMBERS: &str = "`..` over two numbers: BT.CPP 4.8.2 gives no value (it throws only where the value is used, \"not initialized\"), which is not modelled";

/// Why a join of a number other than a literal is refused.
const COMPUTED: &str = "joining a string and a number that is not a literal: BT.CPP writes the number's text (`3` for an integer, `3.000000` for a double), which the model does not compute; join a number literal or a string";

/// The text BT.CPP 4.8.2 joins for the number literal `e` (`Any::cast<std::string>`:
/// an `int64_t` as its digits, a `double` as `%f`), `None` for anything else or a
/// NaN (whose sign the text shows).
pub(crate) fn literal_text(e: &Ex) -> Option<String> {
    match &e.k {
        K::Int(n) => Some(n.to_string()),
        K::Bool(b) => Some(if *b { "1" } else { "0" }.to_string()),
        K::Number(t) => match literal(t).ok()? {
            (x, Ty::Int) => Some(x),
            (x, _) => fixed(x.parse().ok()?),
        },
        // `-` gives a `double` (`ExprUnaryArithmetic::evaluate`).
        K::Un("-", a) => fixed(-number(a)?),
        _ => None,
    }
}

/// The value of a number literal, possibly negated.
fn number(e: &Ex) -> Option<f64> {
    match &e.k {
        K::Int(n) if n.unsigned_abs() <= 1 << 53 => Some(*n as f64),
        K::Bool(b) => Some(f64::from(u8::from(*b))),
        K::Number(t) => literal(t).ok()?.0.parse().ok(),
        K::Un("-", a) => number(a).map(|v| -v),
        _ => None,
    }
}

/// `printf("%f")` of a double (`std::to_string`): six decimals, the exact binary value
/// rounded (Rust's formatting rounds the same exact value), `inf` and `-inf`; `None`
/// for NaN.
fn fixed(v: f64) -> Option<String> {
    if v.is_nan() {
        return None;
    }
    if v.is_infinite() {
        return Some(if v > 0.0 { "inf" } else { "-inf" }.to_string());
    }
    Some(format!("{v:.6}"))
}

/// Too many texts: why, for the refusal.
#[derive(Debug, Clone)]
pub(crate) struct Overflow(pub String);

fn product(
    a: &BTreeSet<String>,
    b: &BTreeSet<String>,
    made: &mut BTreeSet<String>,
) -> Result<BTreeSet<String>, Overflow> {
    if a.len() * b.len() > CAP {
        return Err(Overflow(format!(
            "a join whose operands may hold {} and {} texts: more than {CAP} texts, which is not modelled",
            a.len(),
            b.len()
        )));
    }
    let out: BTreeSet<String> = a
        .iter()
        .flat_map(|x| b.iter().map(move |y| format!("{x}{y}")))
        .collect();
    made.extend(out.iter().cloned());
    if made.len() > CAP {
        return Err(Overflow(format!(
            "the scripts' joins make more than {CAP} texts, which is not modelled"
        )));
    }
    Ok(out)
}

/// The texts `e` may be when it is a string (`entry` gives the texts of a string entry
/// by its name in the script, `None` for another entry); every text a join in `e` may
/// make goes into `made`. `None`: not a string (a number, or something the lowering
/// refuses).
pub(crate) fn texts(
    e: &Ex,
    entry: &dyn Fn(&str) -> Option<BTreeSet<String>>,
    made: &mut BTreeSet<String>,
) -> Result<Option<BTreeSet<String>>, Overflow> {
    let one = |t: String| Some(BTreeSet::from([t]));
    Ok(match &e.k {
        K::Str(t) => one(t.clone()),
        K::Name(n) => entry(n),
        K::Ite(c, a, b) => {
            texts(c, entry, made)?;
            match (texts(a, entry, made)?, texts(b, entry, made)?) {
                (Some(mut x), Some(y)) => {
                    x.extend(y);
                    Some(x)
                }
                (x, y) => x.or(y),
            }
        }
        K::Bin(op @ (".." | "+"), a, b) => {
            let (x, y) = (texts(a, entry, made)?, texts(b, entry, made)?);
            let side = |s: Option<BTreeSet<String>>, e: &Ex| {
                s.or_else(|| {
                    (*op == "..")
                        .then(|| literal_text(e).and_then(one))
                        .flatten()
                })
            };
            match (x.is_some() || y.is_some(), side(x, a), side(y, b)) {
                (true, Some(x), Some(y)) => Some(product(&x, &y, made)?),
                _ => None,
            }
        }
        K::Bin(_, a, b) => {
            texts(a, entry, made)?;
            texts(b, entry, made)?;
            None
        }
        K::Un(_, a) => {
            texts(a, entry, made)?;
            None
        }
        K::Cmp(xs, _) => {
            for x in xs {
                texts(x, entry, made)?;
            }
            None
        }
        K::Int(_) | K::Bool(_) | K::Number(_) => None,
    })
}

/// One script: its statements and the entry each script name stands for (`None`: not
/// an entry holding strings).
pub(crate) type Script<'a> = (
    &'a [super::super::script::Stmt],
    &'a dyn Fn(&str) -> Option<String>,
);

/// The closed set of texts: `sets` starts with the texts each entry a SetBlackboard
/// writes holds, and ends with those of every string entry (`script_entries` are the
/// ones scripts write); the texts every join may make. `Err` when the texts grow beyond
/// [`CAP`] or without bound, naming the entry.
pub(crate) fn closure(
    scripts: &[Script<'_>],
    script_entries: &[String],
    sets: &mut BTreeMap<String, BTreeSet<String>>,
) -> Result<BTreeSet<String>, Overflow> {
    for g in script_entries {
        sets.entry(g.clone()).or_default();
    }
    let mut last = String::new();
    let mut made = BTreeSet::new();
    // Each round of a closure that settles adds texts; one that keeps adding them after
    // [`ROUNDS`] rounds beyond one per script is taken as unbounded.
    for _ in 0..ROUNDS + scripts.len() {
        let mut grew: Option<String> = None;
        for (stmts, global) in scripts {
            // What an entry holds after this script assigned it.
            let mut local: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
            for st in *stmts {
                let v = {
                    let entry = |n: &str| {
                        let g = global(n)?;
                        local.get(&g).or_else(|| sets.get(&g)).cloned()
                    };
                    texts(&st.e, &entry, &mut made)?
                };
                let Some((target, op, _)) = &st.assign else {
                    continue;
                };
                let Some(g) = global(target).filter(|g| script_entries.contains(g)) else {
                    continue;
                };
                let new = match (*op, v) {
                    (":=" | "=", Some(v)) => v,
                    ("+=", Some(v)) => {
                        let old = local.get(&g).or_else(|| sets.get(&g)).cloned();
                        product(&old.unwrap_or_default(), &v, &mut made)?
                    }
                    _ => continue,
                };
                let set = sets.entry(g.clone()).or_default();
                let before = set.len();
                set.extend(new.iter().cloned());
                if set.len() > CAP {
                    return Err(unbounded(&g));
                }
                if set.len() > before {
                    grew = Some(g.clone());
                }
                local.insert(g, new);
            }
        }
        match grew {
            None => return Ok(made),
            Some(g) => last = g,
        }
    }
    Err(unbounded(&last))
}

/// Rounds of [`closure`] beyond one per script.
const ROUNDS: usize = 32;

/// Why entry `g`'s texts cannot be closed.
fn unbounded(g: &str) -> Overflow {
    Overflow(format!("the texts `{g}` can hold do not settle within {CAP} texts (a join whose result feeds itself, as `{g} := {g} .. 'a'` run again and again, makes new texts without bound), which is not modelled"))
}

/// One operand of a join: a constant text (a number literal's), or a rank expression
/// and the texts it may hold.
enum Side {
    Const(String),
    Var(String, Vec<String>),
}

impl Side {
    fn cases(&self) -> Vec<&str> {
        match self {
            Side::Const(t) => vec![t.as_str()],
            Side::Var(_, ts) => ts.iter().map(String::as_str).collect(),
        }
    }
}

/// The rank of `l`'s text followed by `r`'s, as a model expression over their ranks:
/// a `?:` per text the left may hold, over one per text the right may hold; pairs whose
/// text is not among the tree's texts cannot happen (the closure holds every text a
/// join can make) and are left out.
fn table(s: &Strings, l: &Side, r: &Side) -> Result<String, Overflow> {
    let rank = |t: &str| s.texts.binary_search_by(|x| x.as_str().cmp(t)).ok();
    let chain = |x: &str, items: Vec<(i64, String)>| -> Option<String> {
        let (last, rest) = items.split_last()?;
        let mut out = last.1.clone();
        for (k, v) in rest.iter().rev() {
            out = format!("({x} == {k} ? {v} : {out})");
        }
        Some(out)
    };
    let n = l.cases().len() * r.cases().len();
    if n > TABLE {
        return Err(Overflow(format!("a join whose operands may hold {n} pairs of texts: more than {TABLE}, which is not modelled")));
    }
    let mut outer = Vec::new();
    for a in l.cases() {
        let mut inner = Vec::new();
        for b in r.cases() {
            // An operand's text without a rank is one it cannot hold (the closure is
            // finer within a script than the sets an operand is read with).
            let key = match r {
                Side::Var(..) => rank(b),
                Side::Const(_) => Some(0),
            };
            if let (Some(k), Some(key)) = (rank(&format!("{a}{b}")), key) {
                inner.push((key as i64, k.to_string()));
            }
        }
        let v = match r {
            Side::Var(y, _) => chain(y, inner),
            Side::Const(_) => inner.pop().map(|(_, v)| v),
        };
        let key = match l {
            Side::Var(..) => rank(a),
            Side::Const(_) => Some(0),
        };
        if let (Some(v), Some(key)) = (v, key) {
            outer.push((key as i64, v));
        }
    }
    Ok(match l {
        Side::Var(x, _) => chain(x, outer),
        Side::Const(_) => outer.pop().map(|(_, v)| v),
    }
    .unwrap_or_else(|| "0".into()))
}

impl Tr<'_> {
    /// The texts the string `e` may hold (the closure's sets of the entries).
    fn texts_of(&self, e: &Ex) -> Option<Vec<String>> {
        let entry = |n: &str| {
            let (g, t, _) = self.entry(n);
            (t == Ty::Text).then(|| {
                self.strs
                    .sets
                    .get(&g)
                    .map(|s| s.iter().cloned().collect())
                    .unwrap_or_default()
            })
        };
        let mut made = BTreeSet::new();
        texts(e, &entry, &mut made)
            .ok()
            .flatten()
            .map(|s| s.into_iter().collect())
    }

    /// The texts a string expression may hold, for reading it as a number: `None`
    /// where the closure does not know them.
    pub(super) fn possible_texts(&self, e: &Ex) -> Option<Vec<String>> {
        self.texts_of(e)
    }

    fn side(&mut self, e: &Ex, guard: &str) -> Result<Side, Refuse> {
        if !self.is_text(e) {
            return literal_text(e)
                .map(Side::Const)
                .ok_or((e.at, COMPUTED.to_string()));
        }
        let v = self.ex(e, guard)?;
        let ts = self
            .texts_of(e)
            .ok_or((e.at, "a string whose texts are not known".to_string()))?;
        Ok(Side::Var(v.x, ts))
    }

    /// `a .. b`, or `a + b` over two strings (`e`): the rank of the joined text.
    pub(super) fn join(&mut self, e: &Ex, a: &Ex, b: &Ex, guard: &str) -> Result<Val, Refuse> {
        if let Some(why) = &self.strs.overflow {
            return Err((e.at, why.clone()));
        }
        if !self.is_text(a) && !self.is_text(b) {
            return Err((e.at, TWO_NUMBERS.to_string()));
        }
        let l = self.side(a, guard)?;
        let r = self.side(b, guard)?;
        let x = table(self.strs, &l, &r).map_err(|Overflow(w)| (e.at, w))?;
        Ok(val(x, Ty::Text, "false"))
    }

    /// `g += e` with `g` an entry holding strings (created by a script) and `e`'s value
    /// `v` a string: `g`'s text joined with `v`'s (4.10 `ExprAssignment::evaluate`,
    /// `assign_plus`; 4.8.2: `s := 'a'; s += 'b'` holds `ab`); it throws where `g` holds
    /// no value ("doesn't exist").
    pub(super) fn plus_assign(
        mut self,
        g: &str,
        v: Val,
        e: &Ex,
        at: usize,
    ) -> Result<Lowered, Refuse> {
        if let Some(why) = &self.strs.overflow {
            return Err((at, why.clone()));
        }
        let old = self.strs.sets.get(g).map(|s| s.iter().cloned().collect());
        let ts = self.texts_of(e);
        let (Some(old), Some(ts)) = (old, ts) else {
            return Err((at, "a string whose texts are not known".to_string()));
        };
        let x = table(
            self.strs,
            &Side::Var(g.to_string(), old),
            &Side::Var(v.x, ts),
        )
        .map_err(|Overflow(w)| (at, w))?;
        self.checks.push(format!("!{}", super::has(g)));
        Ok(Lowered {
            checks: self.checks,
            assigns: vec![(g.to_string(), x), (super::has(g), "true".into())],
            value: val(g.to_string(), Ty::Text, "false"),
        })
    }
}
