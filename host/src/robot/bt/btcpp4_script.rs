//! BehaviorTree.CPP 4's script language lowered under [`super::BtSemantics::Btcpp`]:
//! the `Script`, `ScriptCondition` and `Precondition` nodes over integer and boolean
//! blackboard entries.
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
//! - `!e` is `e == 0`; `-`, `+`, `*` are integer arithmetic (BT.CPP computes in doubles:
//!   the same values up to 2^53); comparisons chain (`a < b < c` is `a < b && b < c`).
//! - `&&` / `||` take operands 0 or 1 only, else BT.CPP throws ("Logic operators are not
//!   allowed if one of the operands is not castable to bool"); `c ? a : b` takes any
//!   number, non-zero being true.
//! - A condition (`ScriptCondition`, Precondition's `if`) is `Any::cast<bool>` of the
//!   last statement's value: 0 or 1, anything else throws.
//! - Reading an entry that holds no value throws ("Variable not found"); so does `=`,
//!   `+=`, `-=`, `*=` on one (`:=` creates it).
//! - `+ -` and `*` group to the right (`10 - 4 - 2` is 8, `1 - 1 + 1` is -1).
//! - An entry SetBlackboard wrote holds a string (BT.CPP 4 stores SetBlackboard's value
//!   as text). Where every write is an integer constant, a script may read it: compared
//!   with a number it reads as that number (the text `3` equals 3), as the condition of
//!   `c ? a : b` it is true unless 0; an arithmetic or logic operator, `-`, `!` over it,
//!   or a condition whose value it is, throws ("Operation not permitted", "Invalid
//!   operator for std::string", "no known safe conversion"). Refused: comparing two such
//!   entries (a string comparison), copying one (`y := k`), writing one from a script.
//!
//! Where BT.CPP throws, the exception ends the tree's execution: the blackboard machine
//! goes to its `error` state (`bt_script_fault` set), the node never answers, and the
//! tree stops. Refused when the tree is read, each at the script's attribute with the
//! column in the script: strings and real numbers (not modelled yet), division (`/`,
//! `/=`: BT.CPP divides in floating point and may store a real number), the bit
//! operators, an entry SetBlackboard writes other than as above, an entry of a type
//! other than integer or boolean, an entry a SubTree maps to a constant.

use super::blackboard::{Blackboard, MACHINE};
use super::btcpp4_skip::SELF_RUNNING;
use super::control::{init_state, n_children, Ctx, FAILURE, RUNNING, SUCCESS};
use super::script::{self, Ex, Stmt, K};
use super::tree::{PortValue, ScriptNode, TreeNode};
use crate::model::source::{Diagnostic, SourceMap, Span};
use crate::model::types::Scalar;
use crate::model::xml::Element;

/// The blackboard machine's flag: a script threw.
pub(crate) const FAULT: &str = "bt_script_fault";

/// The blackboard machine's flag: entry `e` holds a value.
pub(crate) fn has(e: &str) -> String {
    format!("bt_has__{e}")
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
    /// An entry SetBlackboard wrote an integer constant to: BT.CPP 4 holds its text
    /// (the model variable holds the number the text reads as).
    Text,
}

/// Why an operator over an entry SetBlackboard wrote cannot be modelled.
const TWO_TEXTS: &str = "two entries SetBlackboard wrote: BT.CPP 4 holds their texts and compares or joins them as strings, which is not modelled";

/// A refusal: the byte offset in the script and why.
type Refuse = (usize, String);

/// Translates one script of one node to the blackboard machine's expressions.
struct Tr<'a> {
    /// The script's entry names: the entry in the tree's terms and its type.
    names: &'a [(String, String, Ty)],
    /// Conditions under which the statement being translated throws.
    checks: Vec<String>,
}

fn int(x: &str, t: Ty) -> String {
    match t {
        Ty::Int | Ty::Text => x.to_string(),
        Ty::Bool => format!("({x} ? 1 : 0)"),
    }
}

impl Tr<'_> {
    fn entry(&self, name: &str) -> (String, Ty) {
        let (_, g, t) = self
            .names
            .iter()
            .find(|(n, _, _)| n == name)
            .expect("every name was resolved");
        (g.clone(), *t)
    }

    /// `e` is an entry SetBlackboard wrote, read as it is (a string in BT.CPP 4).
    fn is_text(&self, e: &Ex) -> bool {
        matches!(&e.k, K::Name(n) if self.entry(n).1 == Ty::Text)
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
    fn number(&mut self, e: &Ex, guard: &str) -> Result<(String, Ty), Refuse> {
        let (x, t) = self.ex(e, guard)?;
        if t == Ty::Text {
            self.check(guard, "true".into());
            return Ok(("0".into(), Ty::Int));
        }
        Ok((x, t))
    }

    /// Operand of `&&` / `||`: a boolean, or an integer that must be 0 or 1.
    fn logic_operand(&mut self, e: &Ex, guard: &str) -> Result<String, Refuse> {
        let (x, t) = self.number(e, guard)?;
        Ok(match t {
            Ty::Bool => x,
            Ty::Int | Ty::Text => {
                self.check(guard, format!("{x} != 0 && {x} != 1"));
                format!("({x} == 1)")
            }
        })
    }

    fn ex(&mut self, e: &Ex, guard: &str) -> Result<(String, Ty), Refuse> {
        let refuse = |what: &str| Err((e.at, what.to_string()));
        Ok(match &e.k {
            K::Int(n) => (n.to_string(), Ty::Int),
            K::Bool(b) => (b.to_string(), Ty::Bool),
            K::Number(t) => {
                return Err((
                    e.at,
                    format!("the number `{t}`: only whole decimal numbers are modelled (real numbers in scripts are not modelled yet)"),
                ))
            }
            K::Str => return refuse("strings in scripts are not modelled yet"),
            K::Name(n) => {
                let (g, t) = self.entry(n);
                // "Variable not found".
                self.check(guard, format!("!{}", has(&g)));
                (g, t)
            }
            K::Un("-", a) => {
                let (x, t) = self.number(a, guard)?;
                (format!("(-{})", int(&x, t)), Ty::Int)
            }
            K::Un("!", a) => {
                let (x, t) = self.number(a, guard)?;
                match t {
                    Ty::Bool => (format!("(!{x})"), Ty::Bool),
                    Ty::Int | Ty::Text => (format!("({x} == 0)"), Ty::Bool),
                }
            }
            K::Un(..) => return refuse("the bit operators (`~`, `|`, `&`, `^`) are not modelled"),
            K::Bin(op @ ("+" | "-" | "*"), a, b) => {
                if self.is_text(a) && self.is_text(b) {
                    return Err((e.at, format!("`{op}` over {TWO_TEXTS}")));
                }
                let (x, tx) = self.number(a, guard)?;
                let (y, ty) = self.number(b, guard)?;
                (format!("({} {op} {})", int(&x, tx), int(&y, ty)), Ty::Int)
            }
            K::Bin("/", ..) => return refuse(
                "division: BT.CPP divides in floating point and may store a real number, which is not modelled yet",
            ),
            K::Bin(op @ ("&&" | "||"), a, b) => {
                let x = self.logic_operand(a, guard)?;
                let y = self.logic_operand(b, guard)?;
                (format!("({x} {op} {y})"), Ty::Bool)
            }
            K::Bin(..) => return refuse("the bit operators (`~`, `|`, `&`, `^`) are not modelled"),
            K::Cmp(xs, ops) => {
                // A string compared with a number is read as one (BT.CPP 4.8.2: the text
                // `3` equals 3): the model variable's number. Two strings compare as
                // strings.
                if let Some(w) = xs.windows(2).find(|w| self.is_text(&w[0]) && self.is_text(&w[1])) {
                    return Err((w[0].at, format!("comparing {TWO_TEXTS}")));
                }
                let mut vs = Vec::with_capacity(xs.len());
                for x in xs {
                    let (v, t) = self.ex(x, guard)?;
                    vs.push(int(&v, t));
                }
                let parts: Vec<String> = ops
                    .iter()
                    .enumerate()
                    .map(|(i, op)| format!("{} {op} {}", vs[i], vs[i + 1]))
                    .collect();
                (format!("({})", parts.join(" && ")), Ty::Bool)
            }
            K::Ite(c, a, b) => {
                // A string condition is read as a number (4.8.2: the text `0` is false).
                let (cx, ct) = self.ex(c, guard)?;
                let cond = match ct {
                    Ty::Bool => cx,
                    Ty::Int | Ty::Text => format!("({cx} != 0)"),
                };
                let join = |g: &str, c: &str| {
                    if g.is_empty() {
                        c.to_string()
                    } else {
                        format!("({g}) && {c}")
                    }
                };
                // Only the branch taken is evaluated: its checks only count then.
                if let Some(x) = [a, b].into_iter().find(|x| self.is_text(x)) {
                    return Err((x.at, "a SetBlackboard's text as the value of `?:`: BT.CPP 4 gives the string, and strings in scripts are not modelled yet".into()));
                }
                let (x, tx) = self.ex(a, &join(guard, &cond))?;
                let (y, ty) = self.ex(b, &join(guard, &format!("!{cond}")))?;
                if tx == Ty::Bool && ty == Ty::Bool {
                    (format!("({cond} ? {x} : {y})"), Ty::Bool)
                } else {
                    (
                        format!("({cond} ? {} : {})", int(&x, tx), int(&y, ty)),
                        Ty::Int,
                    )
                }
            }
        })
    }
}

/// One statement: what makes it throw, the assignments, its value.
struct Lowered {
    checks: Vec<String>,
    assigns: Vec<(String, String)>,
    value: (String, Ty),
}

fn statement(names: &[(String, String, Ty)], s: &Stmt) -> Result<Lowered, Refuse> {
    let mut tr = Tr {
        names,
        checks: Vec::new(),
    };
    let (x, t) = tr.ex(&s.e, "")?;
    let Some((target, op, at)) = &s.assign else {
        return Ok(Lowered {
            checks: tr.checks,
            assigns: Vec::new(),
            value: (x, t),
        });
    };
    let (g, et) = tr.entry(target);
    if et == Ty::Text {
        return Err((*at, format!("a script writing `{g}`, which a SetBlackboard writes: BT.CPP 4 holds a string there (4.8.2 refuses to assign it a number), which is not modelled")));
    }
    if t == Ty::Text {
        return Err((s.e.at, format!("assigning a SetBlackboard's text to `{g}`: BT.CPP 4 copies the string, and strings in scripts are not modelled yet")));
    }
    if *op != ":=" {
        // "The blackboard entry [..] doesn't exist".
        tr.checks.push(format!("!{}", has(&g)));
    }
    let new = match (*op, et, t) {
        ("/=", ..) => {
            return Err((
                *at,
                "`/=`: BT.CPP divides in floating point and may store a real number, which is not modelled yet".into(),
            ))
        }
        (":=" | "=", Ty::Int, _) => int(&x, t),
        (":=" | "=", Ty::Bool, Ty::Bool) => x,
        (":=" | "=", Ty::Bool, Ty::Int) => {
            return Err((*at, format!("assigning an integer to the boolean entry `{g}` (typed by a port) is not modelled: assign a boolean")))
        }
        (_, Ty::Bool, _) => {
            return Err((*at, format!("`{op}` on the boolean entry `{g}` (typed by a port) is not modelled")))
        }
        (_, Ty::Int, _) => format!("({g} {} {})", &op[..1], int(&x, t)),
        (_, Ty::Text, _) => unreachable!("refused above"),
    };
    Ok(Lowered {
        checks: tr.checks,
        assigns: vec![(g.clone(), new), (has(&g), "true".into())],
        value: (g, et),
    })
}

/// Resolves node `n`'s script names to entries with their types, registering the
/// entries only scripts write (`int64`); an error at `span` for a name that cannot be
/// modelled.
fn resolve(
    sm: &SourceMap,
    n: &TreeNode,
    span: Span,
    bb: &mut Blackboard,
    errs: &mut Vec<Diagnostic>,
) -> Option<Vec<(String, String, Ty)>> {
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
            // BT.CPP 4 holds SetBlackboard's text; a script reads a string there. Modelled
            // where every write is an integer constant (typed `int32`/`int64` by
            // `blackboard::type_entries`, the model variable holding the number the text
            // reads as; a BlackboardCheck may read it too), no plugin port types it
            // (a plugin's output would store a number), and no SetBlackboard copies to or
            // from it (4.8.2's copies leave entries a script cannot read,
            // `tests/bt/real/set_blackboard.toml`).
            let e = bb.entry(&g);
            let ints = e.is_some_and(|e| {
                !e.why.contains("of plugin")
                    && Scalar::from_name(e.ty.trim()).is_some_and(|s| s.int_range().is_some())
            });
            if !ints || bb.copies.contains(&g) || bb.conflicted.contains(&g) {
                errs.push(sm.diag(span, format!("the script uses the entry `{g}`, which a SetBlackboard writes: BT.CPP 4 stores SetBlackboard's value as text; scripts read it only where every write is an integer constant and no SetBlackboard copies to or from it (strings and reals in scripts are not modelled yet)")));
                continue;
            }
            if !bb.script_entries.contains(&g) {
                bb.script_entries.push(g.clone());
            }
            out.push((name.clone(), g, Ty::Text));
            continue;
        }
        let t = match bb.entry(&g) {
            None => {
                bb.entries.push(super::blackboard::Entry {
                    name: g.clone(),
                    ty: "int64".into(),
                    span,
                    why: "a script".into(),
                });
                Ty::Int
            }
            Some(e) => match Scalar::from_name(e.ty.trim()) {
                Some(Scalar::Bool) => Ty::Bool,
                Some(s) if s.int_range().is_some() => Ty::Int,
                _ => {
                    let at = sm.diag(e.span, "");
                    errs.push(sm.diag(span, format!("the script uses the entry `{g}`, which is {} at {}:{}:{} ({}): scripts over entries other than integers and booleans are not modelled yet", e.ty, at.file, at.line, at.col, e.why)));
                    continue;
                }
            },
        };
        if !bb.script_entries.contains(&g) {
            bb.script_entries.push(g.clone());
        }
        out.push((name.clone(), g, t));
    }
    (errs.len() == before).then_some(out)
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
        match statement(&names, s) {
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
    let (v, t) = lowered.last().expect("a statement").value.clone();
    let mut inner = if condition {
        let (value, check) = match t {
            Ty::Bool => (v, None),
            // `Any::cast<bool>`: 0 or 1, else it throws.
            Ty::Int => (format!("{v} == 1"), Some(format!("{v} != 0 && {v} != 1"))),
            // A string: 4.8.2 throws ("no known safe conversion between [std::string]
            // and [bool]").
            Ty::Text => ("false".into(), Some("true".into())),
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

/// Script (`condition` false) or ScriptCondition: a tick runs the script in the
/// blackboard machine; Script answers SUCCESS (BT.CPP 4.10 `actions/script_node.h`,
/// `ScriptNode::tick`), ScriptCondition SUCCESS if the value is true, else FAILURE
/// (`actions/script_condition.h`, `ScriptCondition::tick`). Neither is ever RUNNING, so
/// a halt answers at once.
fn script_node(ctx: &Ctx, condition: bool) -> Element {
    let b = &ctx.b;
    let mut m = b.scxml(&ctx.machine, "wait_for_tick");
    m.push(
        b.state("wait_for_tick")
            .with_child(b.tr(
                Some(&ctx.tick_ev()),
                None,
                Some("running_script"),
                vec![b.send(&run_event(ctx.id), MACHINE)],
            ))
            .with_child(b.tr(
                Some(&ctx.halt_ev()),
                None,
                Some("wait_for_tick"),
                vec![ctx.respond_halted()],
            )),
    );
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
