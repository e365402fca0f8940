//! The size pass: checked formulas to monitor networks, atoms to bytecode, state laid out and limited.
//!
//! - Atoms are deduplicated over the whole spec (structurally, ignoring spans)
//!   and compiled to [`Instr`] stack code whose depth is checked against
//!   [`MAX_STACK`].
//! - Each property becomes a network of [`Node`]s in post order (children first),
//!   identical subformulas of one property sharing one node. `P[I] f` lowers to
//!   `true S[I] f`, `H[I] f` to `!(true S[I] !f)`.
//! - Slots follow [`monitor_core::layout`]: node-owned words start after the
//!   header, atom bits and value bits, in node order; stateless nodes have slot 0.
//! - The total state is checked against [`Limits::max_state_bytes`].

use std::collections::HashMap;

use monitor_core::layout;
use monitor_core::{Atom, Instr, Node, NodeId, NumTy, Op, Ty, MAX_IDS, MAX_STACK};

use crate::ast::{self, BinaryOp, CheckedSpec, ExprKind, FormulaKind, Interval, UnaryOp};
use crate::diag::{Sink, Span};

/// Resource limits the size pass enforces.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Limits {
    /// Largest total monitor state, in bytes ([`monitor_core::Monitor::state_bytes`]).
    /// Default: 64 MiB.
    pub max_state_bytes: u64,
}

impl Default for Limits {
    fn default() -> Self {
        Limits {
            max_state_bytes: 64 << 20,
        }
    }
}

/// One property's network.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) struct PropNet {
    pub name: String,
    pub first: NodeId,
    pub root: NodeId,
    /// Words owned by this property's nodes.
    pub words: u64,
}

/// The lowered, laid-out program, ready to be packaged.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Net {
    pub instrs: Vec<Instr>,
    pub atoms: Vec<Atom>,
    /// The expression of every atom (for printing).
    pub atom_exprs: Vec<ast::Expr>,
    pub nodes: Vec<Node>,
    /// Words owned by each node.
    pub node_words: Vec<u64>,
    pub props: Vec<PropNet>,
    /// Total state words ([`monitor_core::Monitor::state_words`]).
    pub state_words: u64,
}

struct Lower<'a> {
    sink: &'a mut Sink,
    atom_ids: HashMap<String, u16>,
    atom_exprs: Vec<ast::Expr>,
    instrs: Vec<Instr>,
    atoms: Vec<Atom>,
    ops: Vec<Op>,
    spans: Vec<Span>,
    memo: HashMap<String, NodeId>,
    full: bool,
}

/// Lowers and lays out `spec`; problems go to `sink` (the result is meaningful only without errors).
pub(crate) fn lower(spec: &CheckedSpec, limits: &Limits, sink: &mut Sink) -> Net {
    let mut lw = Lower {
        sink,
        atom_ids: HashMap::new(),
        atom_exprs: Vec::new(),
        instrs: Vec::new(),
        atoms: Vec::new(),
        ops: Vec::new(),
        spans: Vec::new(),
        memo: HashMap::new(),
        full: false,
    };
    let mut props = Vec::new();
    if spec.properties.len() > MAX_IDS {
        if let Some(p) = spec.properties.get(MAX_IDS) {
            lw.sink
                .error(p.span, format!("more than {MAX_IDS} properties"));
        }
    }
    for p in &spec.properties {
        lw.memo.clear();
        let first = lw.ops.len();
        let root = lw.formula(&p.formula);
        if lw.full {
            break;
        }
        props.push(PropNet {
            name: p.name.clone(),
            first: first as NodeId,
            root,
            words: 0,
        });
    }
    // Layout: node-owned words follow the header, atom bits and value bits.
    let mut next = layout::first_node_word(lw.atoms.len(), lw.ops.len()) as u64;
    let mut nodes = Vec::with_capacity(lw.ops.len());
    let mut node_words = Vec::with_capacity(lw.ops.len());
    let limit_words = limits.max_state_bytes / 8;
    for (i, op) in lw.ops.iter().enumerate() {
        let span = lw.spans[i];
        let words = match safe_node_words(op) {
            Some(w) if w <= limit_words => w,
            w => {
                let (lo, hi) = match op {
                    Op::Since { lo, hi, .. } => (*lo, *hi),
                    _ => (0, None),
                };
                let need = w.map_or("more than 2^32 witness runs".to_string(), |w| {
                    format!("{} bytes", w.saturating_mul(8))
                });
                lw.sink.error(
                    span,
                    format!(
                        "the bound [{lo}:{}] needs {need} of monitor state, over the limit of {} bytes; \
                         widen the bound's window or use a coarser time unit",
                        hi.map_or(String::new(), |h| h.to_string()),
                        limits.max_state_bytes
                    ),
                );
                0
            }
        };
        let slot = if words == 0 { 0 } else { next };
        next = next.saturating_add(words);
        nodes.push(Node {
            op: *op,
            slot: u32::try_from(slot).unwrap_or(u32::MAX),
        });
        node_words.push(words);
    }
    for p in &mut props {
        p.words = node_words[p.first as usize..=p.root as usize].iter().sum();
    }
    let state_bytes = next.saturating_mul(8);
    if !lw.sink.has_errors() && (state_bytes > limits.max_state_bytes || next > u32::MAX as u64) {
        let worst = (0..node_words.len())
            .max_by_key(|&i| node_words[i])
            .unwrap_or(0);
        let span = lw.spans.get(worst).copied().unwrap_or_default();
        lw.sink.error(
            span,
            format!(
                "the monitor state would be {state_bytes} bytes, over the limit of {} bytes (the largest part is here)",
                limits.max_state_bytes
            ),
        );
    }
    Net {
        instrs: lw.instrs,
        atoms: lw.atoms,
        atom_exprs: lw.atom_exprs,
        nodes,
        node_words,
        props,
        state_words: next,
    }
}

/// [`layout::node_words`], except for `S[b:b]` with `b == u64::MAX`, whose
/// capacity `b + 1` overflows inside `layout::window_capacity`: too large either way.
fn safe_node_words(op: &Op) -> Option<u64> {
    match op {
        Op::Since {
            lo,
            hi: Some(u64::MAX),
            ..
        } if *lo == u64::MAX => None,
        op => layout::node_words(op),
    }
}

/// A canonical text for an atom expression: equal texts mean equal expressions.
fn canon(e: &ast::Expr, out: &mut String) {
    use std::fmt::Write;
    match &e.kind {
        ExprKind::Const(v) => {
            let _ = match v {
                monitor_core::Value::Float(x) => write!(out, "F{:x}", x.to_bits()),
                v => write!(out, "{v:?}"),
            };
        }
        ExprKind::Var(i) => {
            let _ = write!(out, "V{i}");
        }
        ExprKind::Unary(op, a) => {
            let _ = write!(out, "({op:?} ");
            canon(a, out);
            out.push(')');
        }
        ExprKind::Binary(op, a, b) => {
            let _ = write!(out, "({op:?} ");
            canon(a, out);
            out.push(' ');
            canon(b, out);
            out.push(')');
        }
        ExprKind::ToFloat(a) => {
            out.push_str("(F ");
            canon(a, out);
            out.push(')');
        }
    }
}

fn num(ty: Ty) -> NumTy {
    if ty == Ty::Float {
        NumTy::Float
    } else {
        NumTy::Int
    }
}

/// Emits stack code for `e`; returns the stack depth it needs.
fn gen(e: &ast::Expr, out: &mut Vec<Instr>) -> usize {
    match &e.kind {
        ExprKind::Const(v) => {
            out.push(Instr::Push(*v));
            1
        }
        ExprKind::Var(i) => {
            out.push(Instr::Load(*i));
            1
        }
        ExprKind::Unary(op, a) => {
            let d = gen(a, out);
            out.push(match op {
                UnaryOp::Neg => Instr::Neg(num(e.ty)),
                UnaryOp::Not => Instr::Not,
            });
            d
        }
        ExprKind::ToFloat(a) => {
            let d = gen(a, out);
            out.push(Instr::ToFloat);
            d
        }
        ExprKind::Binary(op, a, b) => {
            let da = gen(a, out);
            let db = gen(b, out);
            let n = num(a.ty);
            out.push(match op {
                BinaryOp::Add => Instr::Add(n),
                BinaryOp::Sub => Instr::Sub(n),
                BinaryOp::Mul => Instr::Mul(n),
                BinaryOp::Div => Instr::Div(n),
                BinaryOp::Rem => Instr::Rem(n),
                BinaryOp::Cmp(c) => Instr::Cmp(*c, a.ty),
                BinaryOp::And => Instr::And,
                BinaryOp::Or => Instr::Or,
            });
            da.max(db + 1)
        }
    }
}

impl Lower<'_> {
    fn node(&mut self, op: Op, span: Span) -> NodeId {
        let key = format!("{op:?}");
        if let Some(&id) = self.memo.get(&key) {
            return id;
        }
        if self.ops.len() >= MAX_IDS {
            if !self.full {
                self.sink.error(
                    span,
                    format!("the specification needs more than {MAX_IDS} monitor nodes"),
                );
            }
            self.full = true;
            return 0;
        }
        let id = self.ops.len() as NodeId;
        self.ops.push(op);
        self.spans.push(span);
        self.memo.insert(key, id);
        id
    }

    fn atom(&mut self, e: &ast::Expr) -> u16 {
        let mut key = String::new();
        canon(e, &mut key);
        if let Some(&id) = self.atom_ids.get(&key) {
            return id;
        }
        let mut code = Vec::new();
        let depth = gen(e, &mut code);
        if depth > MAX_STACK {
            self.sink.error(
                e.span,
                format!(
                    "this atom needs a stack of {depth} values, over the limit of {MAX_STACK}; split it into smaller atoms"
                ),
            );
        }
        if self.atoms.len() >= MAX_IDS || self.instrs.len() + code.len() > MAX_IDS {
            self.sink.error(
                e.span,
                format!("the atoms need more than {MAX_IDS} instructions or atoms in total"),
            );
            self.full = true;
            return 0;
        }
        let id = self.atoms.len() as u16;
        self.atoms.push(Atom {
            start: self.instrs.len() as u16,
            len: code.len() as u16,
        });
        self.instrs.extend(code);
        self.atom_exprs.push(e.clone());
        self.atom_ids.insert(key, id);
        id
    }

    fn since(&mut self, iv: Interval, lhs: NodeId, rhs: NodeId, span: Span) -> NodeId {
        let op = Op::Since {
            lhs,
            rhs,
            lo: iv.lo,
            hi: iv.hi,
        };
        self.node(op, span)
    }

    fn formula(&mut self, f: &ast::Formula) -> NodeId {
        if self.full {
            return 0;
        }
        let s = f.span;
        match &f.kind {
            FormulaKind::Const(b) => self.node(Op::Const(*b), s),
            FormulaKind::Atom(e) => {
                let a = self.atom(e);
                self.node(Op::Atom(a), s)
            }
            FormulaKind::Not(a) => {
                let a = self.formula(a);
                self.node(Op::Not(a), s)
            }
            FormulaKind::And(a, b) => {
                let (a, b) = (self.formula(a), self.formula(b));
                self.node(Op::And(a, b), s)
            }
            FormulaKind::Or(a, b) => {
                let (a, b) = (self.formula(a), self.formula(b));
                self.node(Op::Or(a, b), s)
            }
            FormulaKind::Implies(a, b) => {
                let (a, b) = (self.formula(a), self.formula(b));
                self.node(Op::Implies(a, b), s)
            }
            FormulaKind::Iff(a, b) => {
                let (a, b) = (self.formula(a), self.formula(b));
                self.node(Op::Iff(a, b), s)
            }
            FormulaKind::Yesterday(a) => {
                let a = self.formula(a);
                self.node(Op::Yesterday(a), s)
            }
            FormulaKind::WeakYesterday(a) => {
                let a = self.formula(a);
                self.node(Op::WeakYesterday(a), s)
            }
            FormulaKind::Once(iv, a) => {
                let t = self.node(Op::Const(true), s);
                let a = self.formula(a);
                self.since(*iv, t, a, s)
            }
            FormulaKind::Historically(iv, a) => {
                let t = self.node(Op::Const(true), s);
                let a = self.formula(a);
                let na = self.node(Op::Not(a), s);
                let p = self.since(*iv, t, na, s);
                self.node(Op::Not(p), s)
            }
            FormulaKind::Since(iv, a, b) => {
                let (a, b) = (self.formula(a), self.formula(b));
                self.since(*iv, a, b, s)
            }
        }
    }
}
