//! Printing each IR level: checked formulas and atoms as text, compiled networks one node per line.

use std::fmt::Write;

use monitor_core::layout::{self, SinceKind};
use monitor_core::{CmpOp, Instr, NumTy, Op, Ty, Value, VarKind};

use crate::ast::{CheckedSpec, Expr, ExprKind, Formula, FormulaKind, Interval, UnaryOp};
use crate::check::ty_name;
use crate::compile::Compiled;
use crate::duration::format as fmt_ns;

fn value(v: &Value, strings: &[String]) -> String {
    match v {
        Value::Bool(b) => b.to_string(),
        Value::Int(i) => i.to_string(),
        Value::Float(x) => format!("{x:?}"),
        Value::Str(i) => match strings.get(*i as usize) {
            Some(s) => format!("{s:?}"),
            None => format!("<string {i}>"),
        },
    }
}

/// An atom expression in surface syntax; nested binary operations are parenthesised.
pub fn expr(e: &Expr, spec: &CheckedSpec) -> String {
    let sub = |a: &Expr| {
        let s = expr(a, spec);
        if matches!(a.kind, ExprKind::Binary(..)) {
            format!("({s})")
        } else {
            s
        }
    };
    match &e.kind {
        ExprKind::Const(v) => value(v, &spec.strings),
        ExprKind::Var(i) => spec
            .vars
            .get(*i as usize)
            .map_or_else(|| format!("<var {i}>"), |v| v.name.clone()),
        ExprKind::Unary(UnaryOp::Neg, a) => format!("-{}", sub(a)),
        ExprKind::Unary(UnaryOp::Not, a) => format!("!{}", sub(a)),
        ExprKind::Binary(op, a, b) => format!("{} {} {}", sub(a), op.symbol(), sub(b)),
        // Conversions are implicit in the surface syntax.
        ExprKind::ToFloat(a) => expr(a, spec),
    }
}

fn interval(iv: &Interval) -> String {
    match iv.hi {
        _ if iv.is_unbounded() => String::new(),
        Some(h) => format!("[{}:{h}]", iv.lo),
        None => format!("[{}:]", iv.lo),
    }
}

/// Node `node` of a compiled program as a formula in surface syntax (bounds in ticks,
/// `P`/`H` as lowered to `S`; every binary operation parenthesised): what a report
/// shows for a subformula.
pub fn node_formula(compiled: &crate::Compiled, node: u16) -> String {
    use monitor_core::Op;
    let program = compiled.program();
    let Some(n) = program.nodes.get(node as usize) else {
        return format!("node {node}");
    };
    let sub = |c: u16| node_formula(compiled, c);
    let bin = |a: u16, op: &str, b: u16| format!("({} {op} {})", sub(a), sub(b));
    match n.op {
        Op::Const(b) => b.to_string(),
        Op::Atom(k) => match compiled.atom_exprs().get(k as usize) {
            Some(e) => format!("{{{}}}", expr(e, compiled.checked())),
            None => format!("atom {k}"),
        },
        Op::Not(a) => format!("!{}", sub(a)),
        Op::And(a, b) => bin(a, "&&", b),
        Op::Or(a, b) => bin(a, "||", b),
        Op::Implies(a, b) => bin(a, "->", b),
        Op::Iff(a, b) => bin(a, "<->", b),
        Op::Yesterday(a) => format!("Y {}", sub(a)),
        Op::WeakYesterday(a) => format!("Z {}", sub(a)),
        Op::Since { lhs, rhs, lo, hi } => {
            let iv = match (lo, hi) {
                (0, None) => String::new(),
                (lo, None) => format!("[{lo}:]"),
                (lo, Some(hi)) => format!("[{lo}:{hi}]"),
            };
            bin(lhs, &format!("S{iv}"), rhs)
        }
    }
}

/// A checked formula in surface syntax (bounds in ticks); every binary operation is parenthesised.
pub fn formula(f: &Formula, spec: &CheckedSpec) -> String {
    let bin = |a: &Formula, op: &str, b: &Formula| {
        format!("({} {op} {})", formula(a, spec), formula(b, spec))
    };
    match &f.kind {
        FormulaKind::Const(b) => b.to_string(),
        FormulaKind::Atom(e) => format!("{{{}}}", expr(e, spec)),
        FormulaKind::Not(a) => format!("!{}", formula(a, spec)),
        FormulaKind::And(a, b) => bin(a, "&&", b),
        FormulaKind::Or(a, b) => bin(a, "||", b),
        FormulaKind::Implies(a, b) => bin(a, "->", b),
        FormulaKind::Iff(a, b) => bin(a, "<->", b),
        FormulaKind::Yesterday(a) => format!("Y {}", formula(a, spec)),
        FormulaKind::WeakYesterday(a) => format!("Z {}", formula(a, spec)),
        FormulaKind::Once(iv, a) => format!("P{} {}", interval(iv), formula(a, spec)),
        FormulaKind::Historically(iv, a) => format!("H{} {}", interval(iv), formula(a, spec)),
        FormulaKind::Since(iv, a, b) => bin(a, &format!("S{}", interval(iv)), b),
    }
}

fn num(n: NumTy) -> &'static str {
    match n {
        NumTy::Int => "int",
        NumTy::Float => "float",
    }
}

fn instr(i: &Instr, c: &Compiled) -> String {
    match i {
        Instr::Push(v) => format!("push {}", value(v, c.strings())),
        Instr::Load(n) => match c.vars().get(*n as usize) {
            Some(v) => format!("load {}", v.name),
            None => format!("load <var {n}>"),
        },
        Instr::Not => "not".into(),
        Instr::And => "and".into(),
        Instr::Or => "or".into(),
        Instr::Neg(n) => format!("neg {}", num(*n)),
        Instr::Add(n) => format!("add {}", num(*n)),
        Instr::Sub(n) => format!("sub {}", num(*n)),
        Instr::Mul(n) => format!("mul {}", num(*n)),
        Instr::Div(n) => format!("div {}", num(*n)),
        Instr::Rem(n) => format!("rem {}", num(*n)),
        Instr::Cmp(op, ty) => {
            let op = match op {
                CmpOp::Eq => "eq",
                CmpOp::Ne => "ne",
                CmpOp::Lt => "lt",
                CmpOp::Le => "le",
                CmpOp::Gt => "gt",
                CmpOp::Ge => "ge",
            };
            format!("cmp {op} {}", ty_name(*ty))
        }
        Instr::ToFloat => "tofloat".into(),
    }
}

fn op(o: &Op) -> String {
    match o {
        Op::Const(b) => format!("const {b}"),
        Op::Atom(a) => format!("atom a{a}"),
        Op::Not(a) => format!("not n{a}"),
        Op::And(a, b) => format!("and n{a} n{b}"),
        Op::Or(a, b) => format!("or n{a} n{b}"),
        Op::Implies(a, b) => format!("implies n{a} n{b}"),
        Op::Iff(a, b) => format!("iff n{a} n{b}"),
        Op::Yesterday(a) => format!("yesterday n{a}"),
        Op::WeakYesterday(a) => format!("weak-yesterday n{a}"),
        Op::Since { lhs, rhs, lo, hi } => {
            let hi_s = hi.map_or(String::new(), |h| h.to_string());
            let kind = match layout::since_kind(*lo, *hi) {
                Some(SinceKind::Unbounded) => "unbounded".to_string(),
                Some(SinceKind::UpTo(_)) => "newest witness".to_string(),
                Some(SinceKind::AtLeast(_)) => "oldest witness".to_string(),
                Some(SinceKind::Window { cap, .. }) => format!("window of {cap} runs"),
                None => "invalid".to_string(),
            };
            format!("since[{lo}:{hi_s}] n{lhs} n{rhs} ({kind})")
        }
    }
}

impl Compiled {
    /// The compiled program as text: variables, strings, atoms with their
    /// bytecode, then each property's network, one node per line with its
    /// operation, bounds, state slot and words.
    pub fn ir(&self) -> String {
        let spec = self.checked();
        let p = self.program();
        let mut s = String::new();
        let _ = writeln!(
            s,
            "unit {} ({} ns), state {} bytes",
            fmt_ns(self.tick_ns()),
            self.tick_ns(),
            self.state_bytes()
        );
        for (i, v) in self.vars().iter().enumerate() {
            let kind = match v.kind {
                VarKind::Event => "event",
                VarKind::State => "state",
            };
            let _ = write!(s, "v{i} {kind} {}: {}", v.name, v.type_name);
            if v.kind == VarKind::State {
                let _ = write!(s, " = {}", value(&v.init, self.strings()));
            }
            if v.ty != Ty::Bool && ty_name(v.ty) != v.type_name {
                let _ = write!(s, " (runs as {})", ty_name(v.ty));
            }
            s.push('\n');
        }
        for (i, st) in self.strings().iter().enumerate() {
            let _ = writeln!(s, "s{i} {st:?}");
        }
        for (i, (a, e)) in p.atoms.iter().zip(self.atom_exprs()).enumerate() {
            let code: Vec<String> = p
                .instrs
                .iter()
                .skip(a.start as usize)
                .take(a.len as usize)
                .map(|ins| instr(ins, self))
                .collect();
            let _ = writeln!(s, "a{i} {{{}}}: {}", expr(e, spec), code.join("; "));
        }
        for pr in self.properties() {
            let _ = writeln!(
                s,
                "property {}: n{}..=n{}, {} bytes",
                pr.name, pr.first, pr.root, pr.state_bytes
            );
            for n in pr.first..=pr.root {
                let node = &p.nodes[n as usize];
                let words = self.node_words()[n as usize];
                let _ = write!(s, "  n{n} {}", op(&node.op));
                if words > 0 {
                    let _ = write!(
                        s,
                        ", slot {}, {} word{}",
                        node.slot,
                        words,
                        if words == 1 { "" } else { "s" }
                    );
                }
                s.push('\n');
            }
        }
        s
    }
}
