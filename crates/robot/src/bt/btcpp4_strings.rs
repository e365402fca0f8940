//! Strings in BehaviorTree.CPP 4's script language under [`super::BtSemantics::Btcpp`]:
//! every text a tree can hold, interned as an integer in byte order.
//!
//! The model's expressions have no string operations. Without joins every string a
//! script or a SetBlackboard can put in an entry is a text written in the tree: a
//! script's `'literal'` or a SetBlackboard's `value`; with joins (`..`, `+` of two
//! strings, `+=`) [`prepare`] adds the closed set of texts they make
//! (`btcpp4_script/join.rs`, `closure`). [`prepare`] collects them, sorts
//! them as `std::string` compares them (byte by byte, a prefix first: BT.CPP 4.10
//! `scripting/operators.hpp`, `ExprComparison::evaluate` compares two strings with the
//! `SimpleString` operators; 4.8.2 measured: `'B' < 'a'`, `'a' < 'aa'`, `'10' < '9'`)
//! and gives each its rank, so that `==`, `!=`, `<`, `<=`, `>`, `>=` over ranks are
//! BT.CPP's comparisons over the texts. A string entry holds its text's rank in the
//! blackboard machine's `bt_sid__<entry>` ([`sid`]).
//!
//! Which entries hold strings is decided once, before any node is lowered:
//! - an entry a SetBlackboard writes (BT.CPP 4 stores `value` as text) that a script
//!   reads, unless a plugin's port types it or a SetBlackboard copies to or from it
//!   (4.8.2's copies leave entries a script cannot read): every constant written to it
//!   is interned, and the SetBlackboard sends its text's rank beside the value other
//!   nodes read ([`Strings::set_entries`]);
//! - an entry a script assigns a string to (`t := 'a'`, `t := k`, `t := c ? 'a' : 'b'`),
//!   created by scripts, or a LoopString writes its items to (`btcpp4_loop.rs`,
//!   `script_strings`) ([`Strings::script_entries`]).
//!
//! The rules where a string meets a number (4.8.2 measured, `tests/tests/bt_real.rs`
//! `strings_in_scripts_agree_with_the_real_library`): a comparison, and the condition of
//! `c ? a : b`, read the string as a number ([`number`]), which throws "Any failed string
//! to number conversion" for a text that is not one; the arithmetic and logic operators,
//! `-` and `!` throw ("Operation not permitted", "Invalid operator for std::string"); a
//! condition whose value is a string throws ("no known safe conversion"); assigning a
//! number to an entry holding a string throws, and so do `-=`, `*=`, `/=` with a string
//! and `+=` of a number to a string.

use super::blackboard::Blackboard;
use super::script::{self, Ex, K};
use super::tree::{Btcpp4, Control, Kind, PortValue, Tree};
use std::collections::{BTreeMap, BTreeSet};

/// The blackboard machine's variable holding string entry `e`'s text, as its rank.
pub(crate) fn sid(e: &str) -> String {
    format!("bt_sid__{e}")
}

/// The strings of one tree.
#[derive(Clone, Debug, Default)]
pub(crate) struct Strings {
    /// Every text, in byte order: a text's rank is its index.
    pub texts: Vec<String>,
    /// Entries a SetBlackboard writes that scripts read as strings.
    pub set_entries: Vec<String>,
    /// Entries scripts create that hold strings.
    pub script_entries: Vec<String>,
    /// Those of them a plugin's `string` input port types (a script setting an
    /// action's text parameter, `msg := 'hello'`): the rank in [`sid`], the text in the
    /// entry for the plugins (`getInput<std::string>`), [`Strings::text_of`].
    pub port_entries: Vec<String>,
    /// The texts each string entry may hold (the closure over the scripts' joins).
    pub sets: std::collections::BTreeMap<String, std::collections::BTreeSet<String>>,
    /// Why the tree's texts cannot be closed (unbounded, or beyond the cap): every
    /// join is refused with it.
    pub overflow: Option<String>,
}

/// What BT.CPP 4.8.2 makes of a text read as a number.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum AsNumber {
    /// This whole number.
    Int(i64),
    /// It throws ("Any failed string to number conversion").
    Throws,
    /// Something the model does not know the rule of.
    Unknown,
}

/// A text read as a number (4.8.2 measured; the conversion reads a prefix, so `3abc` is
/// 3, `0x10` 16, `true` 1, `1e2` 100, `nan` a NaN): a whole decimal number with an
/// optional sign and spaces around it is that number (` 3`, `3 `, `+3`, `-0`, `007`),
/// up to 2^53 (beyond it 4.8.2 throws "Loss of precision"); the empty text, spaces, and
/// letters and spaces that begin with a letter other than `i`, `n`, `t`, `f` (the
/// beginnings of `inf`, `nan`, `true`, `false`) throw; the rest is
/// [`AsNumber::Unknown`].
pub(crate) fn as_number(t: &str) -> AsNumber {
    let s = t.trim_matches(' ');
    let digits = s.strip_prefix(['+', '-']).unwrap_or(s);
    if !digits.is_empty() && digits.bytes().all(|c| c.is_ascii_digit()) {
        return match s.parse::<i64>() {
            Ok(n) if n.unsigned_abs() <= 1 << 53 => AsNumber::Int(n),
            _ => AsNumber::Unknown,
        };
    }
    let words = s.bytes().all(|c| c.is_ascii_alphabetic() || c == b' ');
    let first = s.bytes().next().map(|c| c.to_ascii_lowercase());
    match first {
        None => AsNumber::Throws,
        Some(c) if words && !b"intf".contains(&c) => AsNumber::Throws,
        _ => AsNumber::Unknown,
    }
}

impl Strings {
    /// The rank of `text` (interned by [`prepare`]).
    pub(crate) fn id(&self, text: &str) -> i64 {
        self.texts
            .binary_search_by(|t| t.as_str().cmp(text))
            .map(|i| i as i64)
            .expect("every text of the tree was interned")
    }

    /// The text whose rank is model expression `x` as a model expression: a balanced
    /// `?:` over the ranks of every text of the tree (a rank stands for the same text
    /// wherever it is stored), so its depth grows with the logarithm of their number.
    pub(crate) fn text_of(&self, x: &str) -> String {
        fn pick(x: &str, ts: &[String], lo: usize) -> String {
            match ts {
                [] => "''".into(),
                [t] => super::plugin::literal_expr(t, "string"),
                _ => {
                    let (a, b) = ts.split_at(ts.len() / 2);
                    let mid = lo + a.len();
                    format!("({x} < {mid} ? {} : {})", pick(x, a, lo), pick(x, b, mid))
                }
            }
        }
        pick(x, &self.texts, 0)
    }

    /// Entry `g` holds strings.
    pub(crate) fn holds(&self, g: &str) -> bool {
        self.set_entries.iter().any(|e| e == g) || self.script_entries.iter().any(|e| e == g)
    }

    /// The string whose rank is `x` (a model expression) read as a number, when it is
    /// one of `texts`: the condition under which BT.CPP throws and the number; `Err`
    /// with a text whose number the model does not know.
    pub(crate) fn number(
        &self,
        x: &str,
        texts: &[&str],
    ) -> Result<(Option<String>, String), UnknownNumber> {
        let mut throws = Vec::new();
        let mut value = "0".to_string();
        for t in texts.iter().rev() {
            let id = self.id(t);
            match as_number(t) {
                AsNumber::Int(n) => value = format!("({x} == {id} ? {n} : {value})"),
                AsNumber::Throws => throws.push(format!("{x} == {id}")),
                AsNumber::Unknown => return Err(UnknownNumber(t.to_string())),
            }
        }
        if texts.len() == 1 {
            // A literal: a constant.
            if let AsNumber::Int(n) = as_number(texts[0]) {
                value = n.to_string();
            }
        }
        let throws = (!throws.is_empty()).then(|| throws.join(" || "));
        Ok((throws, value))
    }
}

/// A text read as a number by rules the model does not know (the text), for the
/// refusal: [`Strings::number`].
#[derive(Debug, Clone)]
pub(crate) struct UnknownNumber(pub String);

impl std::fmt::Display for UnknownNumber {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "the string `{}` read as a number: BT.CPP 4.8.2 reads a prefix of a text as a number by rules the model does not know (`3abc` is 3, `0x10` 16, `true` 1); modelled are whole decimal numbers with spaces around them, and texts of letters (which throw)",
            self.0
        )
    }
}

/// Every script of node `i` (its `code` / `if` port and its pre/post conditions).
fn scripts(tree: &Tree, i: usize) -> Vec<&str> {
    let n = &tree.nodes[i];
    let mut out: Vec<&str> = n.conds.iter().map(|c| c.code.as_str()).collect();
    if let Kind::Control(Control::Btcpp4(Btcpp4::Script(_))) = n.kind {
        for p in &n.ports {
            if let (PortValue::Literal(code), "code" | "if") = (&p.value, p.key.as_str()) {
                out.push(code);
            }
        }
    }
    out
}

fn literals<'e>(e: &'e Ex, out: &mut Vec<&'e str>) {
    match &e.k {
        K::Str(t) => out.push(t),
        K::Un(_, a) => literals(a, out),
        K::Bin(_, a, b) => {
            literals(a, out);
            literals(b, out);
        }
        K::Cmp(xs, _) => xs.iter().for_each(|x| literals(x, out)),
        K::Ite(c, a, b) => {
            literals(c, out);
            literals(a, out);
            literals(b, out);
        }
        _ => {}
    }
}

/// Whether `e` is a string by its form: a literal, an entry holding strings, or `?:`
/// with a string on either side (`global` maps a script name to its entry).
fn stringy(e: &Ex, global: &dyn Fn(&str) -> Option<String>, s: &Strings) -> bool {
    match &e.k {
        K::Str(_) => true,
        K::Name(n) => global(n).is_some_and(|g| s.holds(&g)),
        K::Ite(_, a, b) => stringy(a, global, s) || stringy(b, global, s),
        // A join gives a string (`btcpp4_script/join.rs`).
        K::Bin("..", ..) => true,
        K::Bin("+", a, b) => stringy(a, global, s) && stringy(b, global, s),
        _ => false,
    }
}

/// Before any node is lowered: the texts of the tree and the entries that hold strings
/// (see the module comment). Nothing is reported here; the script lowering refuses what
/// it cannot model, at the script.
pub(super) fn prepare(tree: &Tree, bb: &mut Blackboard) {
    let mut s = Strings::default();
    let mut texts: Vec<String> = Vec::new();
    // The scripts, parsed, with their nodes' names.
    let mut parsed = Vec::new();
    for i in 0..tree.nodes.len() {
        for code in scripts(tree, i) {
            if let Ok(stmts) = script::parse(code) {
                for st in &stmts {
                    let mut ls = Vec::new();
                    literals(&st.e, &mut ls);
                    texts.extend(ls.into_iter().map(str::to_string));
                }
                parsed.push((i, stmts));
            }
        }
    }
    let global = |i: usize, name: &str| -> Option<String> {
        tree.nodes[i]
            .script_names
            .iter()
            .find(|(n, _)| n == name)
            .and_then(|(_, v)| match v {
                PortValue::Blackboard(g) => Some(g.clone()),
                PortValue::Literal(_) => None,
            })
    };
    // SetBlackboard entries scripts read.
    let used: Vec<String> = tree
        .nodes
        .iter()
        .flat_map(|n| n.script_names.iter())
        .filter_map(|(_, v)| match v {
            PortValue::Blackboard(g) => Some(g.clone()),
            PortValue::Literal(_) => None,
        })
        .collect();
    for g in &used {
        if !bb.texts.contains(g) || s.set_entries.contains(g) {
            continue;
        }
        let ok = bb.entry(g).is_some_and(|e| !e.why.contains("of plugin"))
            && !bb.copies.contains(g)
            && !bb.conflicted.contains(g);
        if !ok {
            continue;
        }
        s.set_entries.push(g.clone());
        texts.extend(set_texts(tree, g));
    }
    // Entries a LoopString writes that scripts name (`btcpp4_loop.rs`).
    let looped = super::btcpp4_loop::script_strings(tree, bb);
    for (g, items) in &looped {
        texts.extend(items.iter().cloned());
        if !s.holds(g) {
            s.script_entries.push(g.clone());
        }
    }
    // Entries scripts assign strings to, until nothing changes (`t := k` after
    // `k := 'a'`).
    loop {
        let mut changed = false;
        for (i, stmts) in &parsed {
            let g = |n: &str| global(*i, n);
            for st in stmts {
                let Some((target, _, _)) = &st.assign else {
                    continue;
                };
                let Some(t) = g(target) else { continue };
                if !s.holds(&t) && stringy(&st.e, &g, &s) {
                    s.script_entries.push(t);
                    changed = true;
                }
            }
        }
        if !changed {
            break;
        }
    }
    // Those a plugin's `string` input port types and nothing else writes: the text goes
    // to the plugins too (a LoopString's item into such an entry stays refused).
    s.port_entries = (s.script_entries.iter())
        .filter(|g| port_string(bb, g) && !looped.iter().any(|(l, _)| l == *g))
        .cloned()
        .collect();
    // The closed set of texts (`btcpp4_script/join.rs`): what each string entry may
    // hold, and what every join may make.
    let mut sets: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for g in &s.set_entries {
        sets.insert(g.clone(), set_texts(tree, g).into_iter().collect());
    }
    // What a LoopString writes is among what its entry may hold, for the joins and for
    // reading it as a number.
    for (g, items) in looped {
        sets.entry(g).or_default().extend(items);
    }
    let globals: Vec<Global<'_>> = parsed
        .iter()
        .map(|(i, _)| {
            let (i, s) = (*i, &s);
            Box::new(move |n: &str| global(i, n).filter(|g| s.holds(g)))
                as Box<dyn Fn(&str) -> Option<String>>
        })
        .collect();
    let scripts: Vec<super::btcpp4_script::Script<'_>> = parsed
        .iter()
        .zip(&globals)
        .map(|((_, stmts), g)| (stmts.as_slice(), g.as_ref()))
        .collect();
    let mut overflow = None;
    match super::btcpp4_script::closure(&scripts, &s.script_entries, &mut sets) {
        Ok(made) => texts.extend(made),
        Err(super::btcpp4_script::Overflow(why)) => overflow = Some(why),
    }
    drop(scripts);
    drop(globals);
    texts.extend(sets.values().flatten().cloned());
    texts.sort();
    texts.dedup();
    if overflow.is_none() && texts.len() > super::btcpp4_script::CAP {
        overflow = Some(format!(
            "the tree's scripts may hold {} texts, more than {}, which is not modelled",
            texts.len(),
            super::btcpp4_script::CAP
        ));
    }
    s.texts = texts;
    s.sets = sets;
    s.overflow = overflow;
    bb.strings = s;
}

/// Whether entry `g` is one plugins' `string` ports type that only input ports name,
/// that no SetBlackboard writes or copies and whose type no two ports dispute: a script
/// may write texts there for the plugins to read ([`Strings::port_entries`]).
fn port_string(bb: &Blackboard, g: &str) -> bool {
    bb.entry(g)
        .is_some_and(|e| e.why.contains("of plugin") && e.ty.trim() == "string")
        && bb.declared.iter().any(|d| d == g)
        && !bb.port_outputs.iter().any(|d| d == g)
        && !bb.texts.iter().any(|d| d == g)
        && !bb.copies.iter().any(|d| d == g)
        && !bb.conflicted.iter().any(|d| d == g)
}

/// A script's names to the string entries they stand for.
type Global<'a> = Box<dyn Fn(&str) -> Option<String> + 'a>;

/// The texts the SetBlackboard nodes write to entry `g`.
fn set_texts(tree: &Tree, g: &str) -> Vec<String> {
    let mut out = Vec::new();
    for n in &tree.nodes {
        if n.kind != Kind::Control(Control::SetBlackboard) {
            continue;
        }
        let (Some(k), Some(v)) = (n.port("output_key"), n.port("value")) else {
            continue;
        };
        let key = match &k.value {
            PortValue::Literal(v) => v.trim().to_string(),
            PortValue::Blackboard(b) => b.clone(),
        };
        if key == g {
            if let PortValue::Literal(v) = &v.value {
                out.push(v.clone());
            }
        }
    }
    out
}
