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

/// How a leaf of one static type is read as a key: only the cell variant of that type is
/// accepted (any other is an internal error at the leaf, as the leaf's own closure
/// reports it), so a read is one tag test and one load instead of a match over the
/// variants (the shared `key` match was the largest single cost of the fused code in
/// the profile of issue 26 part 5).
trait Kind: 'static {
    fn key(c: Option<&Cell>) -> Option<i64>;
}

struct IntK;
struct BoolK;
struct StrK;

impl Kind for IntK {
    #[inline(always)]
    fn key(c: Option<&Cell>) -> Option<i64> {
        match c {
            Some(Cell::Int(v)) => Some(*v),
            _ => None,
        }
    }
}

impl Kind for BoolK {
    #[inline(always)]
    fn key(c: Option<&Cell>) -> Option<i64> {
        match c {
            Some(Cell::Bool(b)) => Some(*b as i64),
            _ => None,
        }
    }
}

impl Kind for StrK {
    #[inline(always)]
    fn key(c: Option<&Cell>) -> Option<i64> {
        match c {
            Some(Cell::Str(s)) => Some(s.0 as i64),
            _ => None,
        }
    }
}

/// The key of `leaf` in `env`, read as kind `K`.
#[inline(always)]
fn read_k<K: Kind>(env: &Env<'_>, leaf: Leaf) -> Res<i64> {
    let (c, at) = match leaf {
        Leaf::Const(v) => return Ok(v),
        Leaf::Var(i, at) => (env.vars.get(i as usize), at),
        Leaf::Param(i, at) => (env.params.get(i as usize), at),
    };
    K::key(c).ok_or(internal(at))
}

/// A relation between two keys.
trait Rel: 'static {
    fn rel(a: i64, b: i64) -> bool;
}

macro_rules! rels {
    ($($name:ident $op:tt),*) => {$(
        struct $name;
        impl Rel for $name {
            #[inline(always)]
            fn rel(a: i64, b: i64) -> bool {
                a $op b
            }
        }
    )*};
}
rels!(EqR ==, NeR !=, LtR <, LeR <=, GtR >, GeR >=);

/// `a R b` for leaves of kind `K`, one closure per operand shape.
fn fused<K: Kind, R: Rel>(a: Leaf, b: Leaf) -> BoolFn {
    match (a, b) {
        (Leaf::Var(i, at), Leaf::Const(k)) => {
            Box::new(
                move |env: &mut Env<'_>| match K::key(env.vars.get(i as usize)) {
                    Some(v) => Ok(R::rel(v, k)),
                    None => Err(internal(at)),
                },
            )
        }
        (Leaf::Param(i, at), Leaf::Const(k)) => {
            Box::new(
                move |env: &mut Env<'_>| match K::key(env.params.get(i as usize)) {
                    Some(v) => Ok(R::rel(v, k)),
                    None => Err(internal(at)),
                },
            )
        }
        (Leaf::Var(i, ai), Leaf::Var(j, aj)) => Box::new(move |env: &mut Env<'_>| {
            match (
                K::key(env.vars.get(i as usize)),
                K::key(env.vars.get(j as usize)),
            ) {
                (Some(v), Some(w)) => Ok(R::rel(v, w)),
                (None, _) => Err(internal(ai)),
                (_, None) => Err(internal(aj)),
            }
        }),
        (a, b) => Box::new(move |env: &mut Env<'_>| {
            Ok(R::rel(read_k::<K>(env, a)?, read_k::<K>(env, b)?))
        }),
    }
}

fn by_rel<K: Kind>(op: BinOp, a: Leaf, b: Leaf) -> Option<BoolFn> {
    Some(match op {
        BinOp::Eq => fused::<K, EqR>(a, b),
        BinOp::Ne => fused::<K, NeR>(a, b),
        BinOp::Lt => fused::<K, LtR>(a, b),
        BinOp::Le => fused::<K, LeR>(a, b),
        BinOp::Gt => fused::<K, GtR>(a, b),
        BinOp::Ge => fused::<K, GeR>(a, b),
        _ => return None,
    })
}

/// `a op b` for two leaves of the same static type `ty` (`op` ordered only for integers).
pub(super) fn compare(op: BinOp, ty: &Ty, a: Leaf, b: Leaf) -> Option<BoolFn> {
    match ty {
        Ty::Int => by_rel::<IntK>(op, a, b),
        Ty::Bool => by_rel::<BoolK>(op, a, b),
        Ty::Str => by_rel::<StrK>(op, a, b),
        _ => None,
    }
}

/// Integer arithmetic on two keys; `at` is where an overflow or a remainder by zero is
/// reported.
trait Arith: 'static {
    fn apply(a: i64, b: i64, at: u32) -> Res<i64>;
}

struct AddA;
struct SubA;
struct MulA;
struct RemA;

impl Arith for AddA {
    #[inline(always)]
    fn apply(a: i64, b: i64, at: u32) -> Res<i64> {
        a.checked_add(b).ok_or(EvalError {
            at,
            kind: EvalErrorKind::Overflow,
        })
    }
}

impl Arith for SubA {
    #[inline(always)]
    fn apply(a: i64, b: i64, at: u32) -> Res<i64> {
        a.checked_sub(b).ok_or(EvalError {
            at,
            kind: EvalErrorKind::Overflow,
        })
    }
}

impl Arith for MulA {
    #[inline(always)]
    fn apply(a: i64, b: i64, at: u32) -> Res<i64> {
        a.checked_mul(b).ok_or(EvalError {
            at,
            kind: EvalErrorKind::Overflow,
        })
    }
}

impl Arith for RemA {
    #[inline(always)]
    fn apply(a: i64, b: i64, at: u32) -> Res<i64> {
        if b == 0 {
            Err(EvalError {
                at,
                kind: EvalErrorKind::DivByZero,
            })
        } else {
            Ok(a.wrapping_rem(b))
        }
    }
}

fn arith_k<A: Arith>(a: Leaf, b: Leaf, at: u32) -> IntFn {
    match (a, b) {
        (Leaf::Var(i, ai), Leaf::Const(k)) => {
            Box::new(
                move |env: &mut Env<'_>| match IntK::key(env.vars.get(i as usize)) {
                    Some(v) => A::apply(v, k, at),
                    None => Err(internal(ai)),
                },
            )
        }
        (a, b) => Box::new(move |env: &mut Env<'_>| {
            let x = read_k::<IntK>(env, a)?;
            A::apply(x, read_k::<IntK>(env, b)?, at)
        }),
    }
}

/// `a op b` for two integer leaves and `op` one of `+ - * %` (`at`: where an overflow or
/// `%` by zero is reported): one closure for `i + 1`, where the tree of closures made three. Both leaves
/// are read, in order, before the operation, as the tree reads them.
pub(super) fn arith(op: BinOp, a: Leaf, b: Leaf, at: u32) -> Option<IntFn> {
    Some(match op {
        BinOp::Add => arith_k::<AddA>(a, b, at),
        BinOp::Sub => arith_k::<SubA>(a, b, at),
        BinOp::Mul => arith_k::<MulA>(a, b, at),
        BinOp::Rem => arith_k::<RemA>(a, b, at),
        _ => return None,
    })
}

/// Code that writes `leaf`'s value into a cell as `store` says: a literal is stored
/// directly (a scalar cell is overwritten whatever it held, as `clone_from` of a scalar
/// does), a variable or parameter is read as its static type.
pub(super) fn write(leaf: Leaf, store: Store) -> CellFn {
    fn of<K: Kind, M: Fn(i64) -> Cell + Copy + Send + Sync + 'static>(
        leaf: Leaf,
        make: M,
    ) -> CellFn {
        match leaf {
            Leaf::Const(v) => {
                let c = make(v);
                match c {
                    Cell::Int(v) => Box::new(move |_, d| {
                        *d = Cell::Int(v);
                        Ok(())
                    }),
                    Cell::Bool(b) => Box::new(move |_, d| {
                        *d = Cell::Bool(b);
                        Ok(())
                    }),
                    Cell::Str(s) => Box::new(move |_, d| {
                        *d = Cell::Str(s);
                        Ok(())
                    }),
                    Cell::Float(f) => Box::new(move |_, d| {
                        *d = Cell::Float(f);
                        Ok(())
                    }),
                    Cell::List(_) => Box::new(move |_, d| {
                        d.clone_from(&c);
                        Ok(())
                    }),
                }
            }
            leaf => Box::new(move |env, d| {
                *d = make(read_k::<K>(env, leaf)?);
                Ok(())
            }),
        }
    }
    match store {
        Store::Int => of::<IntK, _>(leaf, Cell::Int),
        Store::Bool => of::<BoolK, _>(leaf, |v| Cell::Bool(v != 0)),
        Store::Str => of::<StrK, _>(leaf, |v| Cell::Str(StrId(v as u32))),
        Store::Float => of::<IntK, _>(leaf, |v| Cell::Float(v as f64)),
    }
}
