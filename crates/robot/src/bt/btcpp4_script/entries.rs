//! Which entries a script's names are, with the type each holds (`resolve`: an integer,
//! a boolean, a double scripts create or a plugin's port types, a string a SetBlackboard
//! or a script writes, else refused at the script), and an assignment where a string meets an entry
//! (`assign_text`).

use super::super::blackboard::{Blackboard, Entry};
use super::super::tree::{PortValue, TreeNode};
use super::num::entry_type;
use super::{has, val, Lowered, Name, Refuse, Ty, Val};
use crate::model::source::{Diagnostic, SourceMap, Span};
use crate::model::types::Scalar;

/// Resolves node `n`'s script names to entries with their types, registering the
/// entries only scripts write (`int64`); an error at `span` for a name that cannot be
/// modelled.
pub(super) fn resolve(
    sm: &SourceMap,
    n: &TreeNode,
    span: Span,
    bb: &mut Blackboard,
    errs: &mut Vec<Diagnostic>,
) -> Option<Vec<Name>> {
    let mut out = Vec::new();
    let before = errs.len();
    for (name, v) in &n.script_names {
        let g = match v {
            PortValue::Blackboard(g) => g.clone(),
            PortValue::Literal(c) => {
                errs.push(sm.diag(span, format!("the script's entry `{name}` is the constant `{c}` its SubTree sets: a script over a SubTree's constant port is not modelled (map it to an entry, `{{...}}`)")));
                continue;
            }
        };
        if bb.texts.contains(&g) {
            // BT.CPP 4 holds SetBlackboard's text; a script reads a string there, its
            // rank kept beside the value other nodes read (`btcpp4_strings.rs`), where
            // no plugin port types the entry (a plugin's output would store a number)
            // and no SetBlackboard copies to or from it (4.8.2's copies leave entries a
            // script cannot read, `tests/bt/real/set_blackboard.toml`).
            if !bb.strings.set_entries.contains(&g) {
                errs.push(sm.diag(span, format!("the script uses the entry `{g}`, which a SetBlackboard writes: BT.CPP 4 stores SetBlackboard's value as text; scripts read it only where no plugin's port types it and no SetBlackboard copies to or from it")));
                continue;
            }
            if !bb.script_entries.contains(&g) {
                bb.script_entries.push(g.clone());
            }
            out.push((name.clone(), g, Ty::Text, false));
            continue;
        }
        // An entry no port types: BT.CPP's script creates it (`PortInfo()`, any type).
        let dynamic = bb.entry(&g).is_none_or(|e| e.why == "a script");
        if bb.strings.script_entries.contains(&g) {
            // A script assigns it strings: it holds its text's rank
            // (`btcpp4_strings.rs`).
            match bb.entry(&g) {
                None => bb.entries.push(Entry {
                    name: g.clone(),
                    ty: "int64".into(),
                    span,
                    why: "a script".into(),
                }),
                Some(e) if e.why == "a script" => {}
                // A plugin's `string` input port types it: its rank in `bt_sid__`, the
                // text in the entry for the plugins (`btcpp4_strings.rs`).
                Some(_) if bb.strings.port_entries.contains(&g) => {
                    if !bb.script_entries.contains(&g) {
                        bb.script_entries.push(g.clone());
                    }
                    out.push((name.clone(), g, Ty::Text, false));
                    continue;
                }
                Some(e) => {
                    let at = sm.diag(e.span, "");
                    errs.push(sm.diag(span, format!("a script assigns a string to the entry `{g}`, which is {} at {}:{}:{} ({}): a string in an entry a port types is modelled only where `string` input ports alone name it and nothing but scripts writes it", e.ty, at.file, at.line, at.col, e.why)));
                    continue;
                }
            }
            if !bb.script_entries.contains(&g) {
                bb.script_entries.push(g.clone());
            }
            out.push((name.clone(), g, Ty::Text, true));
            continue;
        }
        // A `double` plugins' ports type and only input ports name: scripts write it as
        // an entry they create (the port created it empty at load; the first value goes
        // in as it is, `bt_dbl__` keeping its type), and the plugins read the number
        // (`getInput<double>` converts an integer).
        let input_double = bb.entry(&g).is_some_and(|e| {
            e.why != "a script"
                && Scalar::from_name(e.ty.trim()) == Some(Scalar::F64)
                && bb.declared.contains(&g)
                && !bb.port_outputs.contains(&g)
                && !bb.texts.contains(&g)
        });
        let dynamic = dynamic || input_double;
        let t = match bb.entry(&g) {
            None => {
                let ty = entry_type(bb, &g);
                bb.entries.push(Entry {
                    name: g.clone(),
                    ty: ty.into(),
                    span,
                    why: "a script".into(),
                });
                if ty == "float64" {
                    Ty::Real
                } else {
                    Ty::Int
                }
            }
            Some(e) => match Scalar::from_name(e.ty.trim()) {
                Some(Scalar::Bool) => Ty::Bool,
                // A `double` a plugin's output port types: the plugin stores doubles
                // there (`setOutput<double>`), which scripts read; a script writing it
                // is refused (`statement`).
                Some(Scalar::F64) => Ty::Real,
                Some(s) if s.int_range().is_some() => Ty::Int,
                _ => {
                    let at = sm.diag(e.span, "");
                    errs.push(sm.diag(span, format!("the script uses the entry `{g}`, which is {} at {}:{}:{} ({}): scripts over entries other than integers, booleans and doubles (`float64`) are not modelled yet", e.ty, at.file, at.line, at.col, e.why)));
                    continue;
                }
            },
        };
        if !bb.script_entries.contains(&g) {
            bb.script_entries.push(g.clone());
        }
        out.push((name.clone(), g, t, dynamic));
    }
    (errs.len() == before).then_some(out)
}

/// An assignment where a string meets an entry (BT.CPP 4.10 `ExprAssignment::evaluate`
/// and 4.8.2, measured): `entry_text`, the entry holds strings (a script creates it);
/// else it holds numbers and `v` is a string. `=`, `:=` of a string to a string entry
/// store its rank; `+=` of two strings joins them (`join.rs`, handled before); `-=`, `*=`, `/=` with
/// a string, and `+=` of a number to a string entry, throw ("Operator not supported for
/// strings", "can't be used with a non-numeric type"), as does `+=` of a string to a
/// number ("Any::copyInto fails"). A number stored in a string entry, or a string in a
/// number entry (4.8.2 converts it), is refused: the entry's type would change.
pub(super) fn assign_text(
    mut checks: Vec<String>,
    g: &str,
    exists: &str,
    entry_text: bool,
    v: Val,
    op: &str,
    at: usize,
) -> Result<Lowered, Refuse> {
    let text = v.t == Ty::Text;
    let throws = |mut checks: Vec<String>, v: Val| {
        checks.push("true".into());
        Ok(Lowered {
            checks,
            assigns: Vec::new(),
            value: v,
        })
    };
    match (entry_text, text, op) {
        (true, true, ":=" | "=") => {
            if op == "=" {
                // "The blackboard entry [..] doesn't exist" (`super::exists`).
                checks.push(format!("!{exists}"));
            }
            Ok(Lowered {
                checks,
                assigns: vec![(g.to_string(), v.x), (has(g), "true".into())],
                value: val(g.to_string(), Ty::Text, "false"),
            })
        }
        (_, _, ":=" | "=") if entry_text => Err((at, format!("assigning a number to `{g}`, which holds strings (a script or a LoopString writes them): BT.CPP 4 throws where it holds a string and stores the number where it holds none, and an entry whose type changes is not modelled"))),
        (_, _, ":=" | "=") => Err((at, format!("assigning a string to `{g}`, which holds numbers: BT.CPP 4.8.2 converts the text to the entry's type, which is not modelled"))),
        _ => throws(checks, v),
    }
}
