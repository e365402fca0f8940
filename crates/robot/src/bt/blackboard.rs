//! The blackboard: one machine holding every `{entry}` the tree names, the types of its
//! entries, and the built-in nodes that use it (SetBlackboard, BlackboardCheckInt /
//! Double / String / Bool).
//!
//! As in AS2FM's translation (`bt_converter.py`, `generate_blackboard_scxml`), a write
//! is `bt_blackboard_set_<entry>` with a `value` parameter; a read is
//! `bt_blackboard_req`, answered by `bt_blackboard_get` carrying every entry as a
//! parameter of the same name, sent to every machine that reads.
//!
//! # Entry types
//! AS2FM types an entry by the ports that name it (`get_blackboard_variables_from_models`:
//! every port declaration whose value is `{entry}`, two types being an error), its
//! SetBlackboard model's ports being `int32`. Here the ports of plugins and of the
//! BlackboardCheck nodes type an entry first; an entry that only SetBlackboard writes
//! takes the type of the constants written (AS2FM's literal typing,
//! `ecmascript_interpretation_functions.py`, `__get_ast_literal_type`: `10` int, `1.5`
//! float, `true` bool; other text is a string, as BT.CPP keeps it); a copy
//! (`value="{other}"`) has its source's type. Two types for one entry are an error
//! naming both places.

use super::build::B;
use super::control::{status_code, Ctx, HaltEffect, FAILURE, RUNNING, SUCCESS};
use super::plugin;
use super::tree::{CheckType, Control, Kind, PortValue, Tree, TreeNode};
use crate::model::source::{Diagnostic, SourceMap, Span};
use crate::model::types::Scalar;
use crate::model::xml::Element;

/// The blackboard machine's name.
pub(crate) const MACHINE: &str = "bt_blackboard_fsm";
/// The read request event.
pub(crate) const REQ: &str = "bt_blackboard_req";
/// The read answer event.
pub(crate) const GET: &str = "bt_blackboard_get";

/// The write event of entry `name`.
pub(crate) fn set_event(name: &str) -> String {
    format!("bt_blackboard_set_{name}")
}

/// One blackboard entry.
#[derive(Clone, Debug)]
pub(crate) struct Entry {
    /// The entry's name (without braces).
    pub name: String,
    /// Its type (a port type such as `int32` or `string`).
    pub ty: String,
    /// Where the type was first given.
    pub span: Span,
    /// What gave it, for errors: "port `x` of plugin `P`", "SetBlackboard writing `1`".
    pub why: String,
}

/// The entries and readers collected while lowering the tree.
#[derive(Clone, Debug, Default)]
pub(crate) struct Blackboard {
    /// Entries in the order first seen.
    pub entries: Vec<Entry>,
    /// Machines that read (receive `bt_blackboard_get`), in the order first seen.
    pub readers: Vec<String>,
    /// Entries whose constants already conflict (reported once, not again per node).
    pub conflicted: Vec<String>,
    /// Entries a SetBlackboard writes (BT.CPP 4 stores its value as text).
    pub texts: Vec<String>,
    /// Entries a SetBlackboard copies to or from (`value="{entry}"`).
    pub copies: Vec<String>,
    /// Entries scripts read or write: the machine keeps whether each holds a value
    /// (`btcpp4_script.rs`).
    pub script_entries: Vec<String>,
    /// Entries a port of the tree names in `{}` (a Loop's `value`, a plugin's port):
    /// BT.CPP 4 creates them, without a value, when it loads the tree, so `=` on one
    /// does not throw (`btcpp4_script.rs`, `exists`).
    pub declared: Vec<String>,
    /// Entries a plugin's output port names: the plugin writes them (`setOutput`).
    pub port_outputs: Vec<String>,
    /// Those of `declared` an UnsetBlackboard erases: the machine keeps whether it did
    /// (`bt_gone__<entry>`).
    pub gone: Vec<String>,
    /// Entries only scripts create that hold a number that need not be whole: the
    /// machine keeps them as `float64` (`btcpp4_script/num.rs`, `float_entries`).
    pub floats: Vec<String>,
    /// The transitions that run the tree's scripts (`btcpp4_script.rs`) and store Loop
    /// items in float entries (`btcpp4_loop.rs`, `Store`): each may throw.
    pub scripts: Vec<Element>,
    /// Entries whose update counter the machine keeps (`bt_seq__<entry>`, one more at
    /// every write): the ones an entry-updated node looks at (`btcpp4_blackboard.rs`).
    pub watched: Vec<String>,
    /// The entry-updated nodes: id, entry, machine; each gets a transition that compares
    /// the entry's counter with the one it saw last (`btcpp4_blackboard.rs`).
    pub updated: Vec<(u32, String, String)>,
    /// The tree's texts and the entries holding strings in scripts
    /// (`btcpp4_strings.rs`).
    pub strings: super::btcpp4_strings::Strings,
}

impl Blackboard {
    /// The entry called `name`.
    pub(crate) fn entry(&self, name: &str) -> Option<&Entry> {
        self.entries.iter().find(|e| e.name == name)
    }

    /// Records that `machine` reads the blackboard.
    pub(crate) fn add_reader(&mut self, machine: &str) {
        if !self.readers.iter().any(|r| r == machine) {
            self.readers.push(machine.to_string());
        }
    }

    /// The blackboard machine, or `None` when the tree uses no entry.
    pub(crate) fn machine(&self, b: B) -> Option<Element> {
        if self.entries.is_empty() && self.scripts.is_empty() && self.updated.is_empty() {
            return None;
        }
        let mut m = b.scxml(MACHINE, "idle");
        let flags: Vec<String> = self
            .script_entries
            .iter()
            .flat_map(|e| [super::btcpp4_script::has(e), super::btcpp4_script::dbl(e)])
            .chain(self.gone.iter().map(|e| super::btcpp4_script::gone(e)))
            .collect();
        let mut vars: Vec<(&str, &str, String)> = self
            .entries
            .iter()
            .map(|e| (e.name.as_str(), e.ty.as_str(), default_value(&e.ty)))
            .collect();
        vars.extend(
            flags
                .iter()
                .map(|f| (f.as_str(), "bool", "false".to_string())),
        );
        // String entries: their texts' ranks (`btcpp4_strings.rs`).
        let sids: Vec<String> = (self.strings.set_entries.iter())
            .chain(&self.strings.script_entries)
            .map(|e| super::btcpp4_strings::sid(e))
            .collect();
        vars.extend(sids.iter().map(|v| (v.as_str(), "int64", "0".to_string())));
        if !self.scripts.is_empty() {
            vars.push((super::btcpp4_script::FAULT, "bool", "false".to_string()));
        }
        let counters = super::btcpp4_blackboard::counter_data(self);
        vars.extend(
            counters
                .iter()
                .map(|(v, t)| (v.as_str(), *t, "0".to_string())),
        );
        m.push(b.datamodel(&vars));
        let mut idle = b.state("idle");
        for e in &self.entries {
            let mut body = vec![b.assign(&e.name, "_event.data.value")];
            if self.strings.set_entries.contains(&e.name) {
                body.push(b.assign(&super::btcpp4_strings::sid(&e.name), "_event.data.sid"));
            }
            if self.script_entries.contains(&e.name) {
                body.push(b.assign(&super::btcpp4_script::has(&e.name), "true"));
            }
            body.extend(super::btcpp4_blackboard::count_write(self, b, &e.name));
            idle.push(b.tr(Some(&set_event(&e.name)), None, Some("idle"), body));
        }
        for t in super::btcpp4_blackboard::updated_transitions(self, b) {
            idle.push(t);
        }
        // A script that threw stops the tree (`btcpp4_script.rs`).
        if !self.scripts.is_empty() {
            idle.push(b.tr(
                None,
                Some(super::btcpp4_script::FAULT),
                Some("error"),
                vec![],
            ));
            for t in &self.scripts {
                idle.push(t.clone());
            }
        }
        if !self.readers.is_empty() {
            let params: Vec<(&str, &str)> = self
                .entries
                .iter()
                .map(|e| (e.name.as_str(), e.name.as_str()))
                .collect();
            let sends = self
                .readers
                .iter()
                .map(|r| b.send_params(GET, r, &params))
                .collect();
            idle.push(b.tr(Some(REQ), None, Some("idle"), sends));
        }
        m.push(idle);
        if !self.scripts.is_empty() {
            m.push(b.state("error"));
        }
        Some(m)
    }
}

/// The value an entry of type `ty` has before anything writes it.
pub(crate) fn default_value(ty: &str) -> String {
    let t = ty.trim();
    if t.ends_with(']') {
        return "[]".into();
    }
    match Scalar::from_name(t) {
        Some(Scalar::Bool) => "false",
        Some(Scalar::Str) => "''",
        Some(Scalar::F32 | Scalar::F64) => "0.0",
        _ => "0",
    }
    .into()
}

/// SetBlackboard: on every tick writes `value` (an expression) to `entry`, answers
/// SUCCESS.
pub(crate) fn set_blackboard(ctx: &Ctx, entry: &str, value: &str) -> Element {
    set_blackboard_params(ctx, entry, &[("value", value)])
}

/// SetBlackboard sending `params` with its write.
fn set_blackboard_params(ctx: &Ctx, entry: &str, params: &[(&str, &str)]) -> Element {
    let b = &ctx.b;
    let mut m = b.scxml(&ctx.machine, "idle");
    m.push(
        b.state("idle")
            .with_child(b.tr(
                Some(&ctx.tick_ev()),
                None,
                Some("idle"),
                vec![
                    b.send_params(&set_event(entry), MACHINE, params),
                    ctx.respond(SUCCESS),
                ],
            ))
            .with_child(b.tr(
                Some(&ctx.halt_ev()),
                None,
                Some("idle"),
                vec![ctx.respond_halted()],
            )),
    );
    m
}

/// The status a tree attribute such as `return_on_mismatch` names: `SUCCESS`,
/// `FAILURE`, `RUNNING`, or AS2FM's numbers for them (`bt_utils.py`, `BtResponse`: an
/// `Enum` of `auto()` values, 1 SUCCESS, 2 FAILURE, 3 RUNNING; its
/// `blackboard_check_int.ascxml` declares `return_on_mismatch` an `int8` port). BT.CPP's
/// own `NodeStatus` numbers differ (0 IDLE, 1 RUNNING, 2 SUCCESS, 3 FAILURE, 4 SKIPPED;
/// `test_node.cpp`, `createTestNodeEnums`), but its `convertFromString<NodeStatus>` takes
/// names only, so a number in a tree can only be AS2FM's.
pub(crate) fn parse_status(v: &str) -> Result<u8, BadStatus> {
    match v.trim() {
        "SUCCESS" | "1" => Ok(SUCCESS),
        "FAILURE" | "2" => Ok(FAILURE),
        "RUNNING" | "3" => Ok(RUNNING),
        s @ ("IDLE" | "SKIPPED" | "0" | "4") => Err(BadStatus::NotAnAnswer(s.to_string())),
        s => Err(BadStatus::Unknown(s.to_string())),
    }
}

/// Why [`parse_status`] refused a status (the text, trimmed).
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) enum BadStatus {
    /// A status of BT.CPP's that no node answers (`IDLE`, `SKIPPED`, 0, 4).
    NotAnAnswer(String),
    /// No status at all.
    Unknown(String),
}

impl std::fmt::Display for BadStatus {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            BadStatus::NotAnAnswer(s) => write!(
                f,
                "`{s}` is not a status a node can answer: write SUCCESS, FAILURE or RUNNING (or AS2FM's 1, 2, 3)"
            ),
            BadStatus::Unknown(s) => write!(
                f,
                "`{s}` is not a status: write SUCCESS, FAILURE or RUNNING (or AS2FM's numbers 1 SUCCESS, 2 FAILURE, 3 RUNNING)"
            ),
        }
    }
}

impl std::error::Error for BadStatus {}

/// The type AS2FM gives constant `v` (see the module comment), or `string`.
pub(crate) fn literal_type(v: &str) -> &'static str {
    let t = v.trim();
    let digits = t.strip_prefix(['-', '+']).unwrap_or(t);
    if !digits.is_empty() && digits.chars().all(|c| c.is_ascii_digit()) {
        return if t.parse::<i32>().is_ok() {
            Scalar::I32.name()
        } else {
            Scalar::I64.name()
        };
    }
    let numeric = digits
        .chars()
        .next()
        .is_some_and(|c| c.is_ascii_digit() || c == '.')
        && digits
            .chars()
            .all(|c| c.is_ascii_digit() || matches!(c, '.' | 'e' | 'E' | '-' | '+'));
    if numeric && t.parse::<f64>().is_ok_and(|f| f.is_finite()) {
        return Scalar::F64.name();
    }
    match t {
        "true" | "false" => Scalar::Bool.name(),
        _ => Scalar::Str.name(),
    }
}

/// Records entry `name` of type `ty` given at `span` by `why`; an error naming both
/// places if it already has another type.
pub(crate) fn register(
    sm: &SourceMap,
    bb: &mut Blackboard,
    name: &str,
    ty: &str,
    span: Span,
    why: &str,
    errs: &mut Vec<Diagnostic>,
) {
    match bb.entry(name) {
        Some(e) if plugin::normalize(&e.ty) != plugin::normalize(ty) => {
            let at = sm.diag(e.span, "");
            errs.push(sm.diag(
                span,
                format!(
                    "blackboard entry `{{{name}}}` is used as {ty} here but as {} at {}:{}:{} (here: {why}; there: {})",
                    e.ty,
                    at.file,
                    at.line,
                    at.col,
                    e.why
                ),
            ));
        }
        Some(_) => {}
        None => bb.entries.push(Entry {
            name: name.to_string(),
            ty: ty.to_string(),
            span,
            why: why.to_string(),
        }),
    }
}

/// `output_key` and `value` of a SetBlackboard node: the entry written and what.
fn set_ports(n: &TreeNode) -> Option<(String, &super::tree::Port)> {
    let key = n.port("output_key")?;
    let value = n.port("value")?;
    let entry = match &key.value {
        PortValue::Literal(v) => v.trim().to_string(),
        PortValue::Blackboard(b) => b.clone(),
    };
    Some((entry, value))
}

/// Types every entry (see the module comment): ports first, then SetBlackboard's
/// constants for the entries no port types, then copies, in both directions, until
/// nothing changes.
pub(crate) fn type_entries(
    sm: &SourceMap,
    tree: &Tree,
    plugins: &[plugin::Plugin],
    bb: &mut Blackboard,
    errs: &mut Vec<Diagnostic>,
) {
    for n in &tree.nodes {
        match n.kind {
            Kind::Plugin(i) => plugin::check_ports(sm, &plugins[i], n, bb, errs),
            Kind::Control(Control::BlackboardCheck(t)) => {
                for p in &n.ports {
                    if let (true, PortValue::Blackboard(b)) =
                        (p.key.starts_with("value_"), &p.value)
                    {
                        let why = format!("port `{}` of {}", p.key, t.node_name());
                        register(sm, bb, b, t.port_type(), p.span, &why, errs);
                    }
                }
            }
            // BT.CPP 4.10 `switch_node.h`, `SwitchNode::providedPorts`:
            // `InputPort<std::string>("variable")`.
            Kind::Control(Control::Btcpp4(super::tree::Btcpp4::Switch(k))) => {
                if let Some(PortValue::Blackboard(b)) = n.port("variable").map(|p| &p.value) {
                    let span = n.port("variable").map_or(n.span, |p| p.span);
                    let why =
                        format!("port `variable` of Switch{k}, which hindsight compares as text");
                    register(sm, bb, b, "string", span, &why, errs);
                }
            }
            Kind::Control(_) => {}
        }
    }
    let by_ports: Vec<String> = bb.entries.iter().map(|e| e.name.clone()).collect();
    for n in &tree.nodes {
        if let Some((entry, _)) = (n.kind == Kind::Control(Control::SetBlackboard))
            .then(|| set_ports(n))
            .flatten()
        {
            if let Some(PortValue::Blackboard(from)) = n.port("value").map(|p| &p.value) {
                for e in [&entry, from] {
                    if !bb.copies.contains(e) {
                        bb.copies.push(e.clone());
                    }
                }
            }
            if !bb.texts.contains(&entry) {
                bb.texts.push(entry);
            }
        }
    }
    let sets: Vec<(String, &super::tree::Port)> = tree
        .nodes
        .iter()
        .filter(|n| n.kind == Kind::Control(Control::SetBlackboard))
        .filter_map(set_ports)
        .collect();
    // The constants written to each entry no port types, in tree order.
    let mut consts: Vec<(&str, Vec<(&str, Span)>)> = Vec::new();
    for (entry, value) in &sets {
        if let PortValue::Literal(v) = &value.value {
            if !by_ports.contains(entry) {
                match consts.iter_mut().find(|(e, _)| e == entry) {
                    Some((_, vs)) => vs.push((v, value.span)),
                    None => consts.push((entry, vec![(v, value.span)])),
                }
            }
        }
    }
    for (entry, vs) in consts {
        let kinds: Vec<&str> = vs.iter().map(|(v, _)| literal_type(v)).collect();
        let scalar = |k: &str| Scalar::from_exact_name(k);
        let int = |k: &str| scalar(k).is_some_and(|s| s.int_range().is_some());
        let numeric = |k: &str| int(k) || scalar(k) == Some(Scalar::F64);
        // Integers and decimals together make a float; other mixtures are conflicts.
        let ty = if kinds.iter().all(|k| scalar(k) == Some(Scalar::I32)) {
            Scalar::I32.name()
        } else if kinds.iter().all(|k| int(k)) {
            Scalar::I64.name()
        } else if kinds.iter().all(|k| numeric(k)) {
            Scalar::F64.name()
        } else {
            kinds[0]
        };
        let (first, span) = vs[0];
        let why = format!("SetBlackboard writing `{}`", first.trim());
        register(sm, bb, entry, ty, span, &why, errs);
        if let Some(i) = kinds
            .iter()
            .position(|k| !(*k == ty || (numeric(k) && numeric(ty))))
        {
            let (v, at) = vs[i];
            let why = format!("SetBlackboard writing `{}`", v.trim());
            register(sm, bb, entry, kinds[i], at, &why, errs);
            bb.conflicted.push(entry.to_string());
        }
    }
    loop {
        let mut changed = false;
        for (entry, value) in &sets {
            let PortValue::Blackboard(src) = &value.value else {
                continue;
            };
            let (d, s) = (bb.entry(entry).cloned(), bb.entry(src).cloned());
            let why = format!("SetBlackboard copying `{{{src}}}` to `{{{entry}}}`");
            match (d, s) {
                (Some(d), None) => {
                    register(sm, bb, src, &d.ty, value.span, &why, errs);
                    changed = true;
                }
                (None, Some(s)) => {
                    register(sm, bb, entry, &s.ty, value.span, &why, errs);
                    changed = true;
                }
                _ => {}
            }
        }
        if !changed {
            break;
        }
    }
    for (entry, value) in &sets {
        let PortValue::Blackboard(src) = &value.value else {
            continue;
        };
        if let (Some(d), Some(s)) = (bb.entry(entry), bb.entry(src)) {
            if plugin::normalize(&d.ty) != plugin::normalize(&s.ty) {
                let (a, b) = (sm.diag(d.span, ""), sm.diag(s.span, ""));
                errs.push(sm.diag(
                    value.span,
                    format!(
                        "SetBlackboard copies `{{{src}}}` ({} at {}:{}:{}, {}) to `{{{entry}}}` ({} at {}:{}:{}, {})",
                        s.ty,
                        b.file,
                        b.line,
                        b.col,
                        s.why,
                        d.ty,
                        a.file,
                        a.line,
                        a.col,
                        d.why
                    ),
                ));
            }
        }
    }
}

/// The entry `n` (a SetBlackboard node) writes, with its type, or an error.
fn typed_entry(
    sm: &SourceMap,
    n: &TreeNode,
    bb: &Blackboard,
    errs: &mut Vec<Diagnostic>,
) -> Option<(String, Entry, super::tree::Port)> {
    let Some((entry, value)) = set_ports(n) else {
        errs.push(sm.diag(n.span, "SetBlackboard needs `output_key` and `value`"));
        return None;
    };
    let Some(e) = bb.entry(&entry).cloned() else {
        errs.push(sm.diag(
            value.span,
            format!("blackboard entry `{{{entry}}}` has no type: nothing writes it a constant and no port reads it"),
        ));
        return None;
    };
    Some((entry, e, value.clone()))
}

/// SetBlackboard: checks what it writes against the entry's type and builds its machine
/// (AS2FM's `set_blackboard.ascxml`: on a tick, write and answer SUCCESS).
pub(crate) fn lower_set(
    sm: &SourceMap,
    n: &TreeNode,
    ctx: &Ctx,
    bb: &mut Blackboard,
    errs: &mut Vec<Diagnostic>,
) -> Option<Element> {
    let (entry, e, value) = typed_entry(sm, n, bb, errs)?;
    match &value.value {
        PortValue::Literal(v) => match plugin::check_literal(v, &e.ty) {
            // An entry scripts read as a string: its text's rank too
            // (`btcpp4_strings.rs`).
            Ok(()) if bb.strings.set_entries.contains(&entry) => {
                let id = bb.strings.id(v).to_string();
                let value = plugin::literal_expr(v, &e.ty);
                Some(set_blackboard_params(
                    ctx,
                    &entry,
                    &[("value", &value), ("sid", &id)],
                ))
            }
            Ok(()) => Some(set_blackboard(ctx, &entry, &plugin::literal_expr(v, &e.ty))),
            Err(_) if bb.conflicted.contains(&entry) => None,
            Err(m) => {
                let at = sm.diag(e.span, "");
                errs.push(sm.diag(
                    value.span,
                    format!(
                        "SetBlackboard writes `{}` to `{{{entry}}}`, which is {} at {}:{}:{} ({}): {m}",
                        v.trim(),
                        e.ty,
                        at.file,
                        at.line,
                        at.col,
                        e.why
                    ),
                ));
                None
            }
        },
        // BT.CPP 4's copy is not AS2FM's (BT.CPP 4.10 `SetBlackboardNode::tick`, 4.8.2
        // measured, `tests/bt/real/set_blackboard.toml`): the `value` port creates the
        // source untyped when the tree loads, so a constant a SetBlackboard writes there
        // leaves it empty, a second one throws, and a copy of an entry with no value
        // answers FAILURE. Not modelled: refused rather than copied.
        PortValue::Blackboard(src) if ctx.btcpp => {
            errs.push(sm.diag(
                value.span,
                format!(
                    "SetBlackboard copying `{{{src}}}` under `--bt btcpp`: BT.CPP 4 creates `{src}` untyped when it loads the tree, so a constant a SetBlackboard writes there leaves it empty and a second one throws \"Can't convert string [..] to type [BT::Any]\", and a copy of an entry that holds no value answers FAILURE (4.8.2 measured); that is not modelled (a Script `{entry} := {src}` copies a value)"
                ),
            ));
            None
        }
        PortValue::Blackboard(src) => {
            bb.add_reader(&ctx.machine);
            Some(copy_blackboard(ctx, &entry, src))
        }
    }
}

/// SetBlackboard with `value="{src}"`: reads the blackboard, writes `src`'s value to
/// `entry`, answers SUCCESS (BT.CPP 4 `SetBlackboardNode::tick`, 3.8 `SetBlackboard::tick`).
fn copy_blackboard(ctx: &Ctx, entry: &str, src: &str) -> Element {
    let b = &ctx.b;
    let mut m = b.scxml(&ctx.machine, "idle");
    m.push(
        b.state("idle")
            .with_child(b.tr(
                Some(&ctx.tick_ev()),
                None,
                Some("read_blackboard"),
                vec![b.send(REQ, MACHINE)],
            ))
            .with_child(b.tr(
                Some(&ctx.halt_ev()),
                None,
                Some("idle"),
                vec![ctx.respond_halted()],
            )),
    );
    let from = format!("_event.data.{src}");
    m.push(b.state("read_blackboard").with_child(b.tr(
        Some(GET),
        None,
        Some("idle"),
        vec![
            b.send_params(&set_event(entry), MACHINE, &[("value", &from)]),
            ctx.respond(SUCCESS),
        ],
    )));
    m
}

/// One side of a BlackboardCheck comparison as an expression of type `t`.
fn check_side(
    sm: &SourceMap,
    t: CheckType,
    n: &TreeNode,
    key: &str,
    reads: &mut bool,
    errs: &mut Vec<Diagnostic>,
) -> Option<String> {
    let Some(p) = n.port(key) else {
        errs.push(sm.diag(n.span, format!("{} needs `{key}`", t.node_name())));
        return None;
    };
    match &p.value {
        PortValue::Literal(v) => match plugin::check_literal(v, t.port_type()) {
            Ok(()) => Some(plugin::literal_expr(v, t.port_type())),
            Err(m) => {
                errs.push(sm.diag(
                    p.span,
                    format!(
                        "`{key}` of {}: {m} (give a constant of that type or a blackboard entry)",
                        t.node_name()
                    ),
                ));
                None
            }
        },
        PortValue::Blackboard(b) => {
            *reads = true;
            Some(format!("_event.data.{b}"))
        }
    }
}

/// BlackboardCheckInt / Double / String / Bool: checks its ports and builds its machine.
pub(crate) fn lower_check(
    sm: &SourceMap,
    t: CheckType,
    n: &TreeNode,
    ctx: &Ctx,
    bb: &mut Blackboard,
    errs: &mut Vec<Diagnostic>,
) -> Option<Element> {
    let mut reads = false;
    let a = check_side(sm, t, n, "value_A", &mut reads, errs);
    let bv = check_side(sm, t, n, "value_B", &mut reads, errs);
    // BT.CPP's default is FAILURE (`BlackboardPreconditionNode::tick`,
    // `default_return_status`); AS2FM's model needs the port.
    let mismatch = match n.port("return_on_mismatch") {
        None => FAILURE,
        Some(p) => match &p.value {
            PortValue::Literal(v) => match parse_status(v) {
                // BT.CPP converts the port with `convertFromString<NodeStatus>`, which
                // knows the names only: AS2FM's numbers fail to convert and the default
                // FAILURE stays (3.8 `BlackboardPreconditionNode::tick`).
                Ok(_) if ctx.btcpp && status_code(v).is_none() => FAILURE,
                Ok(s) => s,
                Err(m) => {
                    errs.push(sm.diag(p.span, format!("`return_on_mismatch`: {m}")));
                    return None;
                }
            },
            PortValue::Blackboard(b) => {
                errs.push(sm.diag(
                    p.span,
                    format!("`return_on_mismatch` must be a constant status; a blackboard entry (`{{{b}}}`) is not supported here"),
                ));
                return None;
            }
        },
    };
    let (a, bv) = (a?, bv?);
    if reads {
        bb.add_reader(&ctx.machine);
    }
    let cond = match t {
        // BT.CPP 3.8 `blackboard_precondition.h`, `IsSame(const double&, const double&)`:
        // equal within the float epsilon, 2^-23.
        CheckType::Double => format!(
            "({a}) - ({bv}) <= {EPS} && ({bv}) - ({a}) <= {EPS}",
            EPS = "0.00000011920928955078125"
        ),
        _ => format!("({a}) == ({bv})"),
    };
    Some(check(ctx, &cond, reads, mismatch))
}

/// A BlackboardCheck node's machine: on a tick (after a blackboard read when `reads`)
/// `cond` ticks the child and answers as it does; otherwise the child is halted and the
/// node answers `mismatch`, as AS2FM's `blackboard_check_int.ascxml` does (its
/// `value_mismatch` state; BT.CPP halts the child only while it runs, which is what
/// [`super::Halts::WhenNeeded`] does).
fn check(ctx: &Ctx, cond: &str, reads: bool, mismatch: u8) -> Element {
    let b = &ctx.b;
    let mut m = b.scxml(&ctx.machine, "wait_for_tick");
    // BT.CPP: the child is not reset after it finished (3.8
    // `BlackboardPreconditionNode::tick` returns `child_node_->executeTick()`; a mismatch
    // halts it only while RUNNING), and a stateful leaf ticked in a finished status
    // answers it again without running (`btcpp.rs`, "Leaves"): its status kept in
    // `child_done` (0 while idle or running).
    let stale = ctx.btcpp && ctx.stateful.first() == Some(&true);
    let mut flags = ctx.running_data();
    if stale {
        flags.push(("child_done".into(), "int8", "0".into()));
    }
    if !flags.is_empty() {
        let data: Vec<(&str, &str, String)> = flags
            .iter()
            .map(|(v, t, e)| (v.as_str(), *t, e.clone()))
            .collect();
        m.push(b.datamodel(&data));
    }
    let on_mismatch = if ctx.effect(0) == HaltEffect::Never {
        b.tr(
            None,
            None,
            Some("wait_for_tick"),
            vec![ctx.respond(mismatch)],
        )
    } else if ctx.btcpp {
        b.tr(None, None, Some("check_mismatch"), vec![])
    } else {
        b.tr(None, None, Some("value_mismatch"), vec![])
    };
    let mut w = b.state("wait_for_tick");
    let exec = if reads {
        "read_blackboard"
    } else {
        "exec_tick"
    };
    let send_req = if reads {
        vec![b.send(REQ, MACHINE)]
    } else {
        vec![]
    };
    w.push(b.tr(Some(&ctx.tick_ev()), None, Some(exec), send_req));
    for t in ctx.halt_single("halting_child", Vec::new()) {
        w.push(t);
    }
    m.push(w);
    if reads {
        // The answer carries the entries; compare on it.
        let mut r = b.state("read_blackboard");
        if stale {
            r.push(b.tr(
                Some(GET),
                Some(&format!("({cond}) && child_done > 0")),
                Some("wait_for_tick"),
                vec![ctx.respond_expr("child_done")],
            ));
        }
        r.push(b.tr(Some(GET), Some(cond), Some("tick_child"), vec![]));
        let mut other = on_mismatch.clone();
        other.set_attr("event", GET);
        r.push(other);
        m.push(r);
    } else {
        let mut e = b.state("exec_tick");
        if stale {
            e.push(b.tr(
                None,
                Some(&format!("({cond}) && child_done > 0")),
                Some("wait_for_tick"),
                vec![ctx.respond_expr("child_done")],
            ));
        }
        m.push(
            e.with_child(b.tr(None, Some(cond), Some("tick_child"), vec![]))
                .with_child(on_mismatch),
        );
    }
    m.push(ctx.halting_child_state());
    let mut t = b.state_entry("tick_child", vec![ctx.tick_child(0)]);
    for s in [SUCCESS, FAILURE, RUNNING] {
        let mut body = vec![ctx.respond(s)];
        if stale && s != RUNNING {
            body.push(b.assign("child_done", &s.to_string()));
        }
        t.push(b.tr(
            Some(&ctx.child_resp(0)),
            Some(&format!("_event.data.status == {s}")),
            Some("wait_for_tick"),
            ctx.marked(0, s, body),
        ));
    }
    m.push(t);
    if ctx.btcpp {
        // BT.CPP halts the child only while it is RUNNING (3.8
        // `BlackboardPreconditionNode::tick` calls `haltChild`; 4.10
        // `decorator_node.cpp`, `DecoratorNode::resetChild`).
        let r = ctx
            .running_var(0)
            .expect("BT.CPP's rules keep every child's flag");
        m.push(
            b.state("check_mismatch")
                .with_child(b.tr(None, Some(&r), Some("value_mismatch"), vec![]))
                .with_child(b.tr(
                    None,
                    None,
                    Some("wait_for_tick"),
                    vec![ctx.respond(mismatch)],
                )),
        );
    }
    if ctx.effect(0) != HaltEffect::Never {
        m.push(
            b.state_entry("value_mismatch", ctx.halt_child_body(0))
                .with_child(b.tr(
                    Some(&ctx.child_halt_resp(0)),
                    None,
                    Some("wait_for_tick"),
                    vec![ctx.respond(mismatch)],
                )),
        );
    }
    m
}
