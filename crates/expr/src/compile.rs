//! Type-checks an expression against a machine's scope and compiles it, once, into typed closures.
//!
//! Variables and event parameters are resolved to slot indices here, so
//! evaluation does no name lookup and no allocation: a closure reads the
//! slot's [`Cell`] and returns a `bool`, `i64`, `f64` or [`StrId`], or writes an
//! array/struct into a caller-owned cell whose buffers are reused.

use super::ast::{BinOp, Expr, ExprKind, ObjField, UnOp};
use super::value::{Cell, StrId, Strings, Ty, TypeTable};

mod leaf;
mod ops;
mod place;
#[cfg(test)]
mod tests;

pub use place::{compile_place, Place};

/// Source of randomness for `Math.random()`: any [`rand_core::Rng`].
pub trait Entropy {
    /// 64 uniformly random bits.
    fn next_u64(&mut self) -> u64;
}

impl<R: rand_core::Rng + ?Sized> Entropy for R {
    fn next_u64(&mut self) -> u64 {
        rand_core::Rng::next_u64(self)
    }
}

/// A uniform float in `[0, 1)` with 53 random bits.
pub(crate) fn unit_f64(rng: &mut dyn Entropy) -> f64 {
    (rng.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}

/// What an expression can read while it is evaluated.
pub struct Env<'a> {
    /// The machine's datamodel, by slot.
    pub vars: &'a [Cell],
    /// The current event's parameters, by index (empty when there is none).
    pub params: &'a [Cell],
    /// `_event.name`.
    pub event: StrId,
    /// `_event.origin` (the sending machine's name).
    pub origin: StrId,
    /// For `Math.random()`.
    pub rng: &'a mut dyn Entropy,
    /// For the `length` of strings.
    pub strings: &'a Strings,
}

/// Why an evaluation failed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EvalErrorKind {
    /// Integer `%` by zero.
    DivByZero,
    /// An integer result outside the 64-bit range (`+ - *`, negation, `Math.abs`).
    Overflow,
    /// A `<send>`'s `delayexpr` gave a negative delay (the bits of its value as a float).
    NegativeDelay(u64),
    /// A `<send>`'s `delayexpr` gave a duration (nanoseconds) that is not a whole number
    /// of model time units (nanoseconds).
    DelaySteps {
        /// The delay.
        ns: u64,
        /// The model's time unit.
        unit: u64,
    },
    /// A float with no 64-bit integer value (`Math.floor` and its kin of NaN, an
    /// infinity or a value out of range): the bits of the float.
    NoInteger(u64),
    /// Array index out of range (reads), or negative (writes).
    Index {
        /// The index used.
        index: i64,
        /// The array's length.
        len: usize,
    },
    /// An array would grow past its declared maximum length.
    TooLong {
        /// The declared maximum length.
        bound: u32,
    },
    /// A value did not have its static type (a compiler bug, reported not panicked).
    Internal,
}

/// An evaluation error at a byte offset of the expression text.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct EvalError {
    /// Byte offset (as mapped by [`Scope::abs`]).
    pub at: u32,
    /// What went wrong.
    pub kind: EvalErrorKind,
}

impl EvalError {
    /// The error as a sentence, without its position.
    pub fn message(&self) -> String {
        match self.kind {
            EvalErrorKind::DivByZero => "integer remainder by zero".into(),
            EvalErrorKind::Overflow => {
                "integer overflow: the result is outside the 64-bit range".into()
            }
            EvalErrorKind::NegativeDelay(bits) => {
                format!("the delay is negative ({})", f64::from_bits(bits))
            }
            EvalErrorKind::DelaySteps { ns, unit } => {
                format!("a delay of {ns} ns is not a whole number of model time units of {unit} ns")
            }
            EvalErrorKind::NoInteger(bits) => {
                let v = f64::from_bits(bits);
                if v.is_finite() {
                    format!("{v:e} has no 64-bit integer value")
                } else {
                    format!("{v} has no 64-bit integer value")
                }
            }
            EvalErrorKind::Index { index, len } => {
                format!("array index {index} out of bounds (length {len})")
            }
            EvalErrorKind::TooLong { bound } => {
                format!("array would exceed its declared length {bound}")
            }
            EvalErrorKind::Internal => "internal error: value of unexpected type".into(),
        }
    }
}

type Res<T> = Result<T, EvalError>;

fn internal(at: u32) -> EvalError {
    EvalError {
        at,
        kind: EvalErrorKind::Internal,
    }
}

/// Compiled code of a boolean expression.
pub type BoolFn = Box<dyn Fn(&mut Env<'_>) -> Res<bool> + Send + Sync>;
/// Compiled code of an integer expression.
pub type IntFn = Box<dyn Fn(&mut Env<'_>) -> Res<i64> + Send + Sync>;
/// Compiled code of a float expression.
pub type FloatFn = Box<dyn Fn(&mut Env<'_>) -> Res<f64> + Send + Sync>;
/// Compiled code of a string expression (an interned id).
pub type StrFn = Box<dyn Fn(&mut Env<'_>) -> Res<StrId> + Send + Sync>;
/// Writes a value (of any type) into a caller-owned cell, reusing its buffers.
pub type CellFn = Box<dyn Fn(&mut Env<'_>, &mut Cell) -> Res<()> + Send + Sync>;

/// Compiled code of one expression, by result type.
pub enum Code {
    /// A boolean.
    Bool(BoolFn),
    /// An integer (every width is `i64`).
    Int(IntFn),
    /// A float (`float32` and `float64` are `f64`).
    Float(FloatFn),
    /// A string.
    Str(StrFn),
    /// Arrays and structs.
    Comp(CellFn),
}

/// A compiled expression and its static type.
pub struct Typed {
    /// The static type.
    pub ty: Ty,
    /// The code, by result type.
    pub code: Code,
}

impl Typed {
    /// A closure that writes the value into a cell, whatever its type.
    pub fn into_cell_fn(self) -> CellFn {
        match self.code {
            Code::Bool(f) => Box::new(move |e, d| {
                *d = Cell::Bool(f(e)?);
                Ok(())
            }),
            Code::Int(f) => Box::new(move |e, d| {
                *d = Cell::Int(f(e)?);
                Ok(())
            }),
            Code::Float(f) => Box::new(move |e, d| {
                *d = Cell::Float(f(e)?);
                Ok(())
            }),
            Code::Str(f) => Box::new(move |e, d| {
                *d = Cell::Str(f(e)?);
                Ok(())
            }),
            Code::Comp(f) => f,
        }
    }
}

/// A compile error at a byte offset of the expression text.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct CompileError {
    /// Byte offset in the expression text.
    pub at: u32,
    /// The message, without its position.
    pub msg: String,
    /// The error is only that an event parameter's type is not known yet
    /// (type inference of parameters retries these).
    pub deferred: bool,
    /// The error is only that this variable is not declared (the model compiler stays
    /// quiet about it when its declaration was already reported as wrong).
    pub unknown_variable: Option<String>,
}

/// The message of a read of a parameter whose type is not known: the model compiler
/// matches it to the parameter's own report.
pub fn unknown_param_type(field: &str, event: &str) -> String {
    format!("type of parameter `{field}` of event `{event}` is not known")
}

/// An undeclared variable `name` at `at`.
fn unknown_variable(at: u32, name: &str) -> CompileError {
    CompileError {
        unknown_variable: Some(name.to_string()),
        ..cerr(at, format!("unknown variable `{name}`"))
    }
}

fn cerr(at: u32, msg: impl Into<String>) -> CompileError {
    CompileError {
        at,
        msg: msg.into(),
        deferred: false,
        unknown_variable: None,
    }
}

/// The event whose `_event` an expression may read.
#[derive(Clone, Copy)]
pub enum EventScope<'a> {
    /// No event (eventless transitions, `<onentry>`, `<datamodel>`).
    None,
    /// A triggering event: its name and parameters (`None` type: not inferred yet).
    Event {
        /// The event's name.
        name: &'a str,
        /// Its parameters, by index.
        params: &'a [(String, Option<Ty>)],
    },
}

/// Names an expression can refer to.
pub struct Scope<'a> {
    /// The machine's datamodel: slot `i` is `vars[i]`.
    pub vars: &'a [(String, Ty)],
    /// The current event.
    pub event: EventScope<'a>,
    /// Structs and enumeration labels.
    pub types: &'a TypeTable,
    /// Maps an offset in the expression text to the offset reported by run-time errors
    /// (the simulator passes the file offset of the attribute character).
    pub abs: &'a dyn Fn(u32) -> u32,
}

/// Maximum number of `[i]`/`.f` steps in one access path.
pub const MAX_PATH: usize = 8;

enum Root {
    Var(u32),
    Param(u32),
}

enum Step {
    Index(IntFn, u32),
    Field(u32),
}

/// A resolved access path: a variable or event parameter, then indices and fields.
struct Path {
    root: Root,
    steps: Vec<Step>,
    ty: Ty,
    at: u32,
}

impl Path {
    fn resolve<'e>(&self, env: &'e mut Env<'_>) -> Res<&'e Cell> {
        let mut idx = [0i64; MAX_PATH];
        for (k, s) in self.steps.iter().enumerate() {
            if let (Step::Index(f, _), Some(slot)) = (s, idx.get_mut(k)) {
                *slot = f(env)?;
            }
        }
        let env: &'e Env<'_> = env;
        let mut cell = match self.root {
            Root::Var(i) => env.vars.get(i as usize),
            Root::Param(i) => env.params.get(i as usize),
        }
        .ok_or(internal(self.at))?;
        for (k, s) in self.steps.iter().enumerate() {
            let Cell::List(items) = cell else {
                return Err(internal(self.at));
            };
            let (i, at) = match s {
                Step::Index(_, at) => (idx.get(k).copied().unwrap_or(0), *at),
                Step::Field(f) => (*f as i64, self.at),
            };
            cell = usize::try_from(i)
                .ok()
                .and_then(|u| items.get(u))
                .ok_or(EvalError {
                    at,
                    kind: EvalErrorKind::Index {
                        index: i,
                        len: items.len(),
                    },
                })?;
        }
        Ok(cell)
    }
}

/// Compiles `expr`; `expect` types array literals (and lets `[]` take the declared type).
pub fn compile(
    expr: &Expr,
    scope: &Scope<'_>,
    strings: &mut Strings,
    expect: Option<&Ty>,
) -> Result<Typed, CompileError> {
    let mut c = Compiler { scope, strings };
    c.expr(expr, expect)
}

/// Compiles `expr` and converts it to `target` (int to float, `[]` to any array).
pub fn compile_as(
    expr: &Expr,
    scope: &Scope<'_>,
    strings: &mut Strings,
    target: &Ty,
    what: &str,
) -> Result<Typed, CompileError> {
    let t = compile(expr, scope, strings, Some(target))?;
    coerce(t, target, scope.types).map_err(|found| {
        cerr(
            expr.start,
            format!(
                "{what} has type {} but {} is expected",
                scope.types.name(&found),
                scope.types.name(target)
            ),
        )
    })
}

/// Converts to `target` when allowed; `Err(found type)` otherwise.
pub(crate) fn coerce(t: Typed, target: &Ty, types: &TypeTable) -> Result<Typed, Ty> {
    if assignable(&t.ty, target) {
        return Ok(match (t.code, target) {
            (Code::Int(f), Ty::Float) => Typed {
                ty: Ty::Float,
                code: Code::Float(Box::new(move |e| Ok(f(e)? as f64))),
            },
            (code, _) => Typed {
                ty: target.clone(),
                code,
            },
        });
    }
    let _ = types;
    Err(t.ty)
}

/// [`compile_as`], then the code that writes the value into a cell
/// ([`Typed::into_cell_fn`]); a literal, a whole variable or a whole event parameter
/// (int, bool or string) is written by one closure instead of two.
pub fn compile_cell(
    expr: &Expr,
    scope: &Scope<'_>,
    strings: &mut Strings,
    target: &Ty,
    what: &str,
) -> Result<CellFn, CompileError> {
    let t = compile_as(expr, scope, strings, target, what)?;
    let mut c = Compiler { scope, strings };
    let store = match target {
        Ty::Int => Some((leaf::Store::Int, Ty::Int)),
        Ty::Bool => Some((leaf::Store::Bool, Ty::Bool)),
        Ty::Str => Some((leaf::Store::Str, Ty::Str)),
        Ty::Float => Some((leaf::Store::Float, Ty::Int)),
        _ => None,
    };
    if let Some((store, ty)) = store {
        // The static type before conversion: a float target takes an int leaf only.
        let source = compile(expr, scope, c.strings, Some(target)).map(|s| s.ty);
        if source.as_ref() == Ok(&ty) {
            if let Some(l) = c.leaf(expr, &ty) {
                return Ok(leaf::write(l, store));
            }
        }
    }
    Ok(t.into_cell_fn())
}

/// True when a value of type `from` may be stored where `to` is expected.
pub(crate) fn assignable(from: &Ty, to: &Ty) -> bool {
    match (from, to) {
        (a, b) if a == b => true,
        (Ty::Int, Ty::Float) => true,
        (Ty::Unknown, _) => true,
        (Ty::Array(a, _), Ty::Array(b, _)) => array_elem_assignable(a, b),
        _ => false,
    }
}

fn array_elem_assignable(a: &Ty, b: &Ty) -> bool {
    match (a, b) {
        (x, y) if x == y => true,
        (Ty::Unknown, _) => true,
        (Ty::Array(x, _), Ty::Array(y, _)) => array_elem_assignable(x, y),
        _ => false,
    }
}

/// The common type of two branches or array items.
pub fn unify(a: &Ty, b: &Ty) -> Option<Ty> {
    match (a, b) {
        (x, y) if x == y => Some(x.clone()),
        (Ty::Int, Ty::Float) | (Ty::Float, Ty::Int) => Some(Ty::Float),
        (Ty::Unknown, y) => Some(y.clone()),
        (x, Ty::Unknown) => Some(x.clone()),
        (Ty::Array(x, bx), Ty::Array(y, by)) => {
            let e = unify(x, y)?;
            Some(Ty::Array(Box::new(e), if bx == by { *bx } else { None }))
        }
        _ => None,
    }
}

/// The code of an array or object literal: a list of what `fns` write, in order, built
/// in place (a destination that is already a list keeps its allocation).
fn list_of(fns: Vec<CellFn>) -> Code {
    let n = fns.len();
    Code::Comp(Box::new(move |env, dest| {
        if !matches!(dest, Cell::List(_)) {
            *dest = Cell::list(Vec::with_capacity(n));
        }
        if let Cell::List(v) = dest {
            v.set_len(n);
            for (f, slot) in fns.iter().zip(v.iter_mut()) {
                f(env, slot)?;
            }
        }
        Ok(())
    }))
}

fn as_float(t: Typed) -> Option<FloatFn> {
    match t.code {
        Code::Float(f) => Some(f),
        Code::Int(f) => Some(Box::new(move |e| Ok(f(e)? as f64))),
        _ => None,
    }
}

struct Compiler<'s, 'a> {
    scope: &'s Scope<'a>,
    strings: &'s mut Strings,
}

const EVENT_FIELDS_HELP: &str =
    "`_event` has the fields `name`, `origin` and `data` (parameters are read as `_event.data.<name>`)";

impl Compiler<'_, '_> {
    fn tname(&self, t: &Ty) -> String {
        self.scope.types.name(t)
    }

    fn abs(&self, at: u32) -> u32 {
        (self.scope.abs)(at)
    }

    fn expr(&mut self, e: &Expr, expect: Option<&Ty>) -> Result<Typed, CompileError> {
        let at = e.start;
        match &e.kind {
            ExprKind::Int(v) => {
                let v = *v;
                Ok(Typed {
                    ty: Ty::Int,
                    code: Code::Int(Box::new(move |_| Ok(v))),
                })
            }
            ExprKind::Float(v) => {
                let v = *v;
                Ok(Typed {
                    ty: Ty::Float,
                    code: Code::Float(Box::new(move |_| Ok(v))),
                })
            }
            ExprKind::Bool(b) => {
                let b = *b;
                Ok(Typed {
                    ty: Ty::Bool,
                    code: Code::Bool(Box::new(move |_| Ok(b))),
                })
            }
            ExprKind::Str(s) => {
                let id = self.strings.intern(s);
                Ok(Typed {
                    ty: Ty::Str,
                    code: Code::Str(Box::new(move |_| Ok(id))),
                })
            }
            ExprKind::Array(items) => self.array(e, items, expect),
            ExprKind::Object(fields) => self.object(e, fields, expect),
            ExprKind::Ident(name) => {
                if let Some(p) = self.path(e)? {
                    return Ok(self.path_code(p));
                }
                if let Some(&v) = self.scope.types.labels.get(name) {
                    return Ok(Typed {
                        ty: Ty::Int,
                        code: Code::Int(Box::new(move |_| Ok(v))),
                    });
                }
                match name.as_str() {
                    "_event" => Err(cerr(
                        at,
                        format!("`_event` cannot be used as a value; {EVENT_FIELDS_HELP}"),
                    )),
                    "Math" => Err(cerr(at, "`Math` cannot be used as a value")),
                    _ => Err(unknown_variable(at, name)),
                }
            }
            ExprKind::Member(obj, field, fat) => self.member(e, obj, field, *fat),
            ExprKind::Index(..) => match self.path(e)? {
                Some(p) => Ok(self.path_code(p)),
                None => Err(cerr(
                    at,
                    "only variables and event parameters can be indexed",
                )),
            },
            ExprKind::Call(callee, args) => self.call(e, callee, args),
            ExprKind::Unary(op, x) => self.unary(at, *op, x),
            ExprKind::Binary(op, a, b) => self.binary(e, *op, a, b),
            ExprKind::Cond(c, a, b) => self.cond(e, c, a, b, expect),
        }
    }

    fn array(
        &mut self,
        e: &Expr,
        items: &[Expr],
        expect: Option<&Ty>,
    ) -> Result<Typed, CompileError> {
        let (elem, bound) = match expect {
            Some(Ty::Array(t, b)) => (Some((**t).clone()), *b),
            _ => (None, None),
        };
        if let Some(b) = bound {
            if items.len() > b as usize {
                return Err(cerr(
                    e.start,
                    format!(
                        "array literal has {} elements but the type allows at most {b}",
                        items.len()
                    ),
                ));
            }
        }
        let mut compiled = Vec::with_capacity(items.len());
        for it in items {
            compiled.push(self.expr(it, elem.as_ref())?);
        }
        let elem_ty = match elem {
            Some(t) => t,
            None => {
                let mut t = Ty::Unknown;
                for (c, it) in compiled.iter().zip(items) {
                    t = unify(&t, &c.ty).ok_or_else(|| {
                        cerr(
                            it.start,
                            format!(
                                "array items have different types ({} and {})",
                                self.tname(&t),
                                self.tname(&c.ty)
                            ),
                        )
                    })?;
                }
                t
            }
        };
        let mut fns = Vec::with_capacity(compiled.len());
        for (c, it) in compiled.into_iter().zip(items) {
            let c = coerce(c, &elem_ty, self.scope.types).map_err(|found| {
                cerr(
                    it.start,
                    format!(
                        "array item has type {} but {} is expected",
                        self.tname(&found),
                        self.tname(&elem_ty)
                    ),
                )
            })?;
            fns.push(c.into_cell_fn());
        }
        Ok(Typed {
            ty: Ty::Array(Box::new(elem_ty), bound),
            code: list_of(fns),
        })
    }

    /// An object literal, typed by the struct `expect`ed where it is used: every field of
    /// the struct exactly once, each converted to the field's type.
    fn object(
        &mut self,
        e: &Expr,
        fields: &[ObjField],
        expect: Option<&Ty>,
    ) -> Result<Typed, CompileError> {
        let s = match expect {
            Some(Ty::Struct(s)) => *s,
            Some(t) => {
                return Err(cerr(
                    e.start,
                    format!(
                        "an object literal is not a value of type {}",
                        self.tname(t)
                    ),
                ))
            }
            None => {
                return Err(cerr(
                    e.start,
                    "the struct type of this object literal is not known: use it where a declared struct type is expected (a typed `<data>`, an assignment to a struct location, a typed parameter or array)",
                ))
            }
        };
        let Some(def) = self.scope.types.structs.get(s as usize) else {
            return Err(cerr(e.start, "internal error: unknown struct type"));
        };
        let sname = def.name.clone();
        let decl: Vec<(String, Ty)> = def.fields.clone();
        let mut fns: Vec<Option<CellFn>> = (0..decl.len()).map(|_| None).collect();
        for f in fields {
            let Some(fi) = decl.iter().position(|(n, _)| *n == f.name) else {
                let names: Vec<&str> = decl.iter().map(|(n, _)| n.as_str()).collect();
                return Err(cerr(
                    f.at,
                    format!(
                        "type {sname} has no field `{}` (its fields: {})",
                        f.name,
                        if names.is_empty() {
                            "none".to_string()
                        } else {
                            names.join(", ")
                        }
                    ),
                ));
            };
            let fty = &decl[fi].1;
            let t = self.expr(&f.value, Some(fty))?;
            let t = coerce(t, fty, self.scope.types).map_err(|found| {
                cerr(
                    f.value.start,
                    format!(
                        "field `{}` of {sname} has type {} but {} is expected",
                        f.name,
                        self.tname(&found),
                        self.tname(fty)
                    ),
                )
            })?;
            if let Some(slot) = fns.get_mut(fi) {
                *slot = Some(t.into_cell_fn());
            }
        }
        let missing: Vec<&str> = decl
            .iter()
            .zip(&fns)
            .filter(|(_, f)| f.is_none())
            .map(|((n, _), _)| n.as_str())
            .collect();
        if !missing.is_empty() {
            return Err(cerr(
                e.start,
                format!(
                    "the object literal of type {sname} has no value for field{} `{}`",
                    if missing.len() > 1 { "s" } else { "" },
                    missing.join("`, `")
                ),
            ));
        }
        let fns: Vec<CellFn> = fns.into_iter().flatten().collect();
        Ok(Typed {
            ty: Ty::Struct(s),
            code: list_of(fns),
        })
    }

    /// Resolves a variable / event parameter access path, or `None` if `e` is not one.
    fn path(&mut self, e: &Expr) -> Result<Option<Path>, CompileError> {
        match &e.kind {
            ExprKind::Ident(name) => match self.scope.vars.iter().position(|(n, _)| n == name) {
                Some(i) => Ok(Some(Path {
                    root: Root::Var(i as u32),
                    steps: Vec::new(),
                    ty: self.scope.vars[i].1.clone(),
                    at: self.abs(e.start),
                })),
                None => Ok(None),
            },
            ExprKind::Member(obj, field, fat) => {
                // `_event.data.<param>`
                if let ExprKind::Member(inner, data, _) = &obj.kind {
                    if matches!(&inner.kind, ExprKind::Ident(n) if n == "_event") && data == "data"
                    {
                        return self.event_param(field, *fat).map(Some);
                    }
                }
                let Some(mut p) = self.path(obj)? else {
                    return Ok(None);
                };
                match &p.ty {
                    Ty::Struct(s) => {
                        let def = self.scope.types.structs.get(*s as usize);
                        let Some((fi, (_, fty))) = def.and_then(|d| {
                            d.fields.iter().enumerate().find(|(_, (n, _))| n == field)
                        }) else {
                            if field == "length" {
                                return Ok(None);
                            }
                            return Err(cerr(
                                *fat,
                                format!("type {} has no field `{field}`", self.tname(&p.ty)),
                            ));
                        };
                        if p.steps.len() >= MAX_PATH {
                            return Err(cerr(*fat, "access path too long"));
                        }
                        p.ty = fty.clone();
                        p.steps.push(Step::Field(fi as u32));
                        Ok(Some(p))
                    }
                    _ => Ok(None),
                }
            }
            ExprKind::Index(arr, idx) => {
                let Some(mut p) = self.path(arr)? else {
                    return Ok(None);
                };
                let Ty::Array(elem, _) = &p.ty else {
                    return Err(cerr(
                        idx.start,
                        format!("a value of type {} cannot be indexed", self.tname(&p.ty)),
                    ));
                };
                let elem = (**elem).clone();
                let i = self.expr(idx, None)?;
                let Code::Int(f) = i.code else {
                    return Err(cerr(
                        idx.start,
                        format!(
                            "array index has type {} but int is expected",
                            self.tname(&i.ty)
                        ),
                    ));
                };
                if p.steps.len() >= MAX_PATH {
                    return Err(cerr(idx.start, "access path too long"));
                }
                p.steps.push(Step::Index(f, self.abs(idx.start)));
                p.ty = elem;
                Ok(Some(p))
            }
            _ => Ok(None),
        }
    }

    fn event_param(&mut self, field: &str, at: u32) -> Result<Path, CompileError> {
        match self.scope.event {
            EventScope::None => Err(cerr(
                at,
                "`_event.data` is only available in a transition that has an `event`",
            )),
            EventScope::Event { name, params } => {
                match params.iter().position(|(n, _)| n == field) {
                    Some(i) => match &params[i].1 {
                        Some(t) => Ok(Path {
                            root: Root::Param(i as u32),
                            steps: Vec::new(),
                            ty: t.clone(),
                            at: self.abs(at),
                        }),
                        None => Err(CompileError {
                            deferred: true,
                            ..cerr(at, unknown_param_type(field, name))
                        }),
                    },
                    None => {
                        let known: Vec<&str> = params.iter().map(|(n, _)| n.as_str()).collect();
                        Err(cerr(
                            at,
                            if known.is_empty() {
                                format!("event `{name}` is never sent with a parameter `{field}` (it has no parameters)")
                            } else {
                                format!(
                                    "event `{name}` is never sent with a parameter `{field}` (its parameters: {})",
                                    known.join(", ")
                                )
                            },
                        ))
                    }
                }
            }
        }
    }

    fn path_code(&mut self, p: Path) -> Typed {
        let at = p.at;
        let ty = p.ty.clone();
        // Fast paths: a whole variable or parameter, one closure per root so that a read
        // does not test which one it is.
        if p.steps.is_empty() {
            macro_rules! whole {
                ($slots:ident, $i:expr) => {{
                    let i = $i as usize;
                    match ty {
                        Ty::Bool => Code::Bool(Box::new(move |env| match env.$slots.get(i) {
                            Some(Cell::Bool(b)) => Ok(*b),
                            _ => Err(internal(at)),
                        })),
                        Ty::Int => Code::Int(Box::new(move |env| match env.$slots.get(i) {
                            Some(Cell::Int(v)) => Ok(*v),
                            _ => Err(internal(at)),
                        })),
                        Ty::Float => Code::Float(Box::new(move |env| match env.$slots.get(i) {
                            Some(Cell::Float(v)) => Ok(*v),
                            Some(Cell::Int(v)) => Ok(*v as f64),
                            _ => Err(internal(at)),
                        })),
                        Ty::Str => Code::Str(Box::new(move |env| match env.$slots.get(i) {
                            Some(Cell::Str(s)) => Ok(*s),
                            _ => Err(internal(at)),
                        })),
                        _ => Code::Comp(Box::new(move |env, dest| match env.$slots.get(i) {
                            Some(c) => {
                                dest.clone_from(c);
                                Ok(())
                            }
                            None => Err(internal(at)),
                        })),
                    }
                }};
            }
            let code = match p.root {
                Root::Var(i) => whole!(vars, i),
                Root::Param(i) => whole!(params, i),
            };
            return Typed { ty, code };
        }
        let code = match ty {
            Ty::Bool => Code::Bool(Box::new(move |env| match p.resolve(env)? {
                Cell::Bool(b) => Ok(*b),
                _ => Err(internal(at)),
            })),
            Ty::Int => Code::Int(Box::new(move |env| match p.resolve(env)? {
                Cell::Int(v) => Ok(*v),
                _ => Err(internal(at)),
            })),
            Ty::Float => Code::Float(Box::new(move |env| match p.resolve(env)? {
                Cell::Float(v) => Ok(*v),
                Cell::Int(v) => Ok(*v as f64),
                _ => Err(internal(at)),
            })),
            Ty::Str => Code::Str(Box::new(move |env| match p.resolve(env)? {
                Cell::Str(s) => Ok(*s),
                _ => Err(internal(at)),
            })),
            _ => Code::Comp(Box::new(move |env, dest| {
                let c = p.resolve(env)?;
                dest.clone_from(c);
                Ok(())
            })),
        };
        Typed { ty, code }
    }
}
