//! Leaf operands (a literal, a whole variable, a whole event parameter) fused into the code
//! that uses them: one closure call for `x == 3`, `_event.data.status == 1` or a `<param>`
//! that sends a constant, where the tree of closures made three (or two).
//!
//! Profiled on the SCXML museum (callgrind, `verify --runs 20`): most guards of an AS2FM
//! model compare one variable or parameter with a literal, and most sent parameters are
//! literals, so the calls of the leaves' own closures and their `Result`s were most of
//! the expressions' instructions. The fused code reads the same cells in the same order
//! and reports the same internal error a leaf's own closure would, so results are
//! identical.

use super::*;

/// A leaf operand of a scalar type other than float, read as an `i64` key: an integer,
/// a boolean (0 or 1) or an interned string's id. Two keys of the same static type are
/// equal exactly when the values are, and integer keys order as the integers do.
#[derive(Clone, Copy, Debug)]
pub(super) enum Leaf {
    /// A literal or an enumeration label.
    Const(i64),
    /// A whole datamodel variable (slot, offset for errors).
    Var(u32, u32),
    /// A whole parameter of the current event (index, offset for errors).
    Param(u32, u32),
}

/// The key of a scalar cell that is not a float.
#[inline(always)]
fn key(c: Option<&Cell>) -> Option<i64> {
    match c {
        Some(Cell::Int(v)) => Some(*v),
        Some(Cell::Bool(b)) => Some(*b as i64),
        Some(Cell::Str(s)) => Some(s.0 as i64),
        _ => None,
    }
}

/// The key of `leaf` in `env` (an ill-typed cell is an internal error at the leaf).
#[inline(always)]
fn read(env: &Env<'_>, leaf: Leaf) -> Res<i64> {
    let (c, at) = match leaf {
        Leaf::Const(v) => return Ok(v),
        Leaf::Var(i, at) => (env.vars.get(i as usize), at),
        Leaf::Param(i, at) => (env.params.get(i as usize), at),
    };
    key(c).ok_or(internal(at))
}

/// What a key becomes when it is stored: the static type of the leaf, or a float for an
/// integer converted to one.
#[derive(Clone, Copy)]
pub(super) enum Store {
    Int,
    Bool,
    Str,
    Float,
}

impl Compiler<'_, '_> {
    /// `e` as a leaf, if it is one whose static type is `ty` (int, bool or string).
    pub(super) fn leaf(&mut self, e: &Expr, ty: &Ty) -> Option<Leaf> {
        if !matches!(ty, Ty::Int | Ty::Bool | Ty::Str) {
            return None;
        }
        match &e.kind {
            ExprKind::Int(v) => Some(Leaf::Const(*v)),
            ExprKind::Bool(b) => Some(Leaf::Const(*b as i64)),
            ExprKind::Str(s) => Some(Leaf::Const(self.strings.intern(s).0 as i64)),
            ExprKind::Unary(UnOp::Neg, x) => match &x.kind {
                ExprKind::Int(v) => Some(Leaf::Const(v.wrapping_neg())),
                _ => None,
            },
            ExprKind::Ident(_) | ExprKind::Member(..) => {
                // Only access paths without an index: resolving them compiles nothing.
                if let ExprKind::Member(obj, _, _) = &e.kind {
                    if !member_chain(obj) {
                        return None;
                    }
                }
                match self.path(e) {
                    Ok(Some(p)) if p.steps.is_empty() && p.ty == *ty => Some(match p.root {
                        Root::Var(i) => Leaf::Var(i, p.at),
                        Root::Param(i) => Leaf::Param(i, p.at),
                    }),
                    Ok(Some(_)) | Err(_) => None,
                    Ok(None) => match &e.kind {
                        ExprKind::Ident(name) if *ty == Ty::Int => {
                            self.scope.types.labels.get(name).map(|&v| Leaf::Const(v))
                        }
                        _ => None,
                    },
                }
            }
            _ => None,
        }
    }
}

/// Whether `e` is a name followed by field accesses only (no index, no call).
fn member_chain(e: &Expr) -> bool {
    match &e.kind {
        ExprKind::Ident(_) => true,
        ExprKind::Member(obj, _, _) => member_chain(obj),
        _ => false,
    }
}

/// `a op b` for two leaves of the same static type (`op` ordered only for integers).
pub(super) fn compare(op: BinOp, a: Leaf, b: Leaf) -> Option<BoolFn> {
    macro_rules! fused {
        ($cmp:tt) => {
            Some(match (a, b) {
                (Leaf::Var(i, at), Leaf::Const(k)) => Box::new(move |env: &mut Env<'_>| {
                    match key(env.vars.get(i as usize)) {
                        Some(v) => Ok(v $cmp k),
                        None => Err(internal(at)),
                    }
                }),
                (Leaf::Param(i, at), Leaf::Const(k)) => Box::new(move |env: &mut Env<'_>| {
                    match key(env.params.get(i as usize)) {
                        Some(v) => Ok(v $cmp k),
                        None => Err(internal(at)),
                    }
                }),
                (Leaf::Var(i, ai), Leaf::Var(j, aj)) => Box::new(move |env: &mut Env<'_>| {
                    match (key(env.vars.get(i as usize)), key(env.vars.get(j as usize))) {
                        (Some(v), Some(w)) => Ok(v $cmp w),
                        (None, _) => Err(internal(ai)),
                        (_, None) => Err(internal(aj)),
                    }
                }),
                (a, b) => Box::new(move |env: &mut Env<'_>| Ok(read(env, a)? $cmp read(env, b)?)),
            })
        };
    }
    match op {
        BinOp::Eq => fused!(==),
        BinOp::Ne => fused!(!=),
        BinOp::Lt => fused!(<),
        BinOp::Le => fused!(<=),
        BinOp::Gt => fused!(>),
        BinOp::Ge => fused!(>=),
        _ => None,
    }
}

/// Code that writes `leaf`'s value into a cell as `store` says.
pub(super) fn write(leaf: Leaf, store: Store) -> CellFn {
    let make = move |v: i64| match store {
        Store::Int => Cell::Int(v),
        Store::Bool => Cell::Bool(v != 0),
        Store::Str => Cell::Str(StrId(v as u32)),
        Store::Float => Cell::Float(v as f64),
    };
    match leaf {
        Leaf::Const(v) => {
            let c = make(v);
            Box::new(move |_, d| {
                d.clone_from(&c);
                Ok(())
            })
        }
        leaf => Box::new(move |env, d| {
            *d = make(read(env, leaf)?);
            Ok(())
        }),
    }
}
