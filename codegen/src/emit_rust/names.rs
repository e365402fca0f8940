//! Names in the emitted module: Rust identifiers for variables, properties and string
//! constants, unique and never a keyword.

use std::collections::{BTreeMap, BTreeSet};

use monitor_core::{Instr, Program, Ty, Value};

use super::atoms::Kind;

/// Whether `s` is a Rust keyword (strict, reserved or weak enough to break `pub mod s`):
/// such a name cannot be an identifier of generated code.
pub fn is_rust_keyword(s: &str) -> bool {
    KEYWORDS.contains(&s)
}

pub(super) const KEYWORDS: &[&str] = &[
    "abstract", "as", "async", "await", "become", "box", "break", "const", "continue", "crate",
    "do", "dyn", "else", "enum", "extern", "false", "final", "fn", "for", "gen", "if", "impl",
    "in", "let", "loop", "macro", "match", "mod", "move", "mut", "override", "priv", "pub", "ref",
    "return", "self", "static", "struct", "super", "trait", "true", "try", "type", "typeof",
    "unsafe", "unsized", "use", "virtual", "where", "while", "yield",
];

/// Names that the generated module declares itself.
pub(super) const RESERVED_CONSTS: &[&str] = &[
    "TICK_NS",
    "ATOMS",
    "PROPERTIES",
    "PROPERTY_NAMES",
    "STATE_BYTES",
    "STRINGS",
];

pub(super) fn is_module_name(s: &str) -> bool {
    let mut chars = s.chars();
    let Some(first) = chars.next() else {
        return false;
    };
    (first.is_ascii_lowercase() || first == '_')
        && s != "_"
        && chars.all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '_')
        && !s.contains("__")
        && !KEYWORDS.contains(&s)
}

/// `s` as words of ASCII letters and digits joined by single `_`, camelCase split.
pub(super) fn ident_words(s: &str, upper: bool) -> String {
    let mut out = String::new();
    let mut gap = false;
    let mut prev_lower = false;
    for c in s.chars() {
        if c.is_ascii_alphanumeric() {
            if (gap || (c.is_ascii_uppercase() && prev_lower)) && !out.is_empty() {
                out.push('_');
            }
            gap = false;
            prev_lower = c.is_ascii_lowercase() || c.is_ascii_digit();
            out.push(if upper {
                c.to_ascii_uppercase()
            } else {
                c.to_ascii_lowercase()
            });
        } else {
            gap = true;
            prev_lower = false;
        }
    }
    out
}

/// A name not yet in `used` (appending `_2`, `_3`, ... when needed), recorded as used.
pub(super) fn unique(used: &mut BTreeSet<String>, base: String) -> String {
    let mut name = base.clone();
    let mut n = 2u64;
    while used.contains(&name) {
        name = format!("{base}_{n}");
        n += 1;
    }
    used.insert(name.clone());
    name
}

pub(super) fn field_names(p: &Program<'_>) -> Vec<String> {
    let mut used = BTreeSet::new();
    p.vars
        .iter()
        .enumerate()
        .map(|(i, v)| {
            let mut w = ident_words(v.name, false);
            if w.is_empty() {
                w = format!("v{i}");
            } else if w.starts_with(|c: char| c.is_ascii_digit()) {
                w = format!("v_{w}");
            } else if KEYWORDS.contains(&w.as_str()) {
                w.push('_');
            }
            unique(&mut used, w)
        })
        .collect()
}

/// Every identifier the generated code uses for the program's own names.
pub(super) struct Names {
    /// `Input` field of each variable.
    pub(super) fields: Vec<String>,
    /// `STR_*` constant of each string.
    pub(super) strs: Vec<String>,
    /// `<VAR>_<STRING>` alias for each string a variable is compared with or starts at.
    pub(super) aliases: BTreeMap<(u16, u32), String>,
    /// `PROP_*` constant of each property.
    pub(super) props: Vec<String>,
}

impl Names {
    pub(super) fn new(p: &Program<'_>) -> Self {
        let fields = field_names(p);
        let mut used: BTreeSet<String> = RESERVED_CONSTS.iter().map(|s| s.to_string()).collect();
        let strs: Vec<String> = p
            .strings
            .iter()
            .enumerate()
            .map(|(k, s)| {
                let w = ident_words(s, true);
                let w = if w.is_empty() { k.to_string() } else { w };
                unique(&mut used, format!("STR_{w}"))
            })
            .collect();
        let props = p
            .props
            .iter()
            .enumerate()
            .map(|(k, pr)| {
                let w = ident_words(pr.name, true);
                let w = if w.is_empty() { k.to_string() } else { w };
                unique(&mut used, format!("PROP_{w}"))
            })
            .collect();
        let mut pairs = BTreeSet::new();
        for (v, var) in p.vars.iter().enumerate() {
            if let Value::Str(k) = var.init {
                pairs.insert((v as u16, k));
            }
        }
        for a in p.atoms {
            let end = a.start as usize + a.len as usize;
            if let Some(code) = p.instrs.get(a.start as usize..end) {
                str_pairs(code, p, &mut pairs);
            }
        }
        let mut aliases = BTreeMap::new();
        for (v, k) in pairs {
            let (Some(var), Some(s)) = (p.vars.get(v as usize), p.strings.get(k as usize)) else {
                continue;
            };
            let mut vw = ident_words(var.name, true);
            if vw.is_empty() || vw.starts_with(|c: char| c.is_ascii_digit()) {
                vw = format!("V{v}_{vw}");
            }
            let sw = ident_words(s, true);
            let sw = if sw.is_empty() {
                format!("STR_{k}")
            } else {
                sw
            };
            let name = unique(&mut used, format!("{}_{sw}", vw.trim_end_matches('_')));
            aliases.insert((v, k), name);
        }
        Names {
            fields,
            strs,
            aliases,
            props,
        }
    }
}

/// Records each `(variable, string)` pair compared directly in `code`.
pub(super) fn str_pairs(code: &[Instr], p: &Program<'_>, pairs: &mut BTreeSet<(u16, u32)>) {
    let mut stack: Vec<Kind> = Vec::new();
    for ins in code {
        let pops = match ins {
            Instr::Push(_) | Instr::Load(_) => 0,
            Instr::Not | Instr::Neg(_) | Instr::ToFloat => 1,
            _ => 2,
        };
        let mut args = [Kind::Other, Kind::Other];
        for k in (0..pops).rev() {
            args[k] = stack.pop().unwrap_or(Kind::Other);
        }
        let pushed = match *ins {
            Instr::Push(Value::Str(k)) => Kind::StrConst(k),
            Instr::Load(v) if p.vars.get(v as usize).is_some_and(|d| d.ty == Ty::Str) => {
                Kind::StrVar(v)
            }
            Instr::Cmp(_, Ty::Str) => {
                match args {
                    [Kind::StrVar(v), Kind::StrConst(k)] | [Kind::StrConst(k), Kind::StrVar(v)] => {
                        pairs.insert((v, k));
                    }
                    _ => {}
                }
                Kind::Other
            }
            _ => Kind::Other,
        };
        stack.push(pushed);
    }
}
