//! Type-checks an expression against a machine's scope and compiles it, once, into typed closures.
//!
//! Variables and event parameters are resolved to slot indices here, so
//! evaluation does no name lookup and no allocation: a closure reads the
//! slot's [`Cell`] and returns a `bool`, `i64`, `f64` or [`StrId`], or writes an
//! array/struct into a caller-owned cell whose buffers are reused.

use super::ast::{BinOp, Expr, ExprKind, ObjField, UnOp};
use super::value::{Cell, StrId, Strings, Ty, TypeTable};

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
pub(crate) struct Env<'a> {
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
pub(crate) enum EvalErrorKind {
    /// Integer `%` by zero.
    DivByZero,
    /// Array index out of range (reads), or negative (writes).
    Index { index: i64, len: usize },
    /// An array would grow past its declared maximum length.
    TooLong { bound: u32 },
    /// A value did not have its static type (a compiler bug, reported not panicked).
    Internal,
}

/// An evaluation error at a byte offset of the expression text.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct EvalError {
    pub at: u32,
    pub kind: EvalErrorKind,
}

impl EvalError {
    pub(crate) fn message(&self) -> String {
        match self.kind {
            EvalErrorKind::DivByZero => "integer remainder by zero".into(),
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

pub(crate) type BoolFn = Box<dyn Fn(&mut Env<'_>) -> Res<bool> + Send + Sync>;
pub(crate) type IntFn = Box<dyn Fn(&mut Env<'_>) -> Res<i64> + Send + Sync>;
pub(crate) type FloatFn = Box<dyn Fn(&mut Env<'_>) -> Res<f64> + Send + Sync>;
pub(crate) type StrFn = Box<dyn Fn(&mut Env<'_>) -> Res<StrId> + Send + Sync>;
/// Writes a value (of any type) into a caller-owned cell, reusing its buffers.
pub(crate) type CellFn = Box<dyn Fn(&mut Env<'_>, &mut Cell) -> Res<()> + Send + Sync>;

/// Compiled code of one expression, by result type.
pub(crate) enum Code {
    Bool(BoolFn),
    Int(IntFn),
    Float(FloatFn),
    Str(StrFn),
    /// Arrays and structs.
    Comp(CellFn),
}

/// A compiled expression and its static type.
pub(crate) struct Typed {
    pub ty: Ty,
    pub code: Code,
}

impl Typed {
    /// A closure that writes the value into a cell, whatever its type.
    pub(crate) fn into_cell_fn(self) -> CellFn {
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
pub(crate) struct CompileError {
    pub at: u32,
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
pub(crate) fn unknown_param_type(field: &str, event: &str) -> String {
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
pub(crate) enum EventScope<'a> {
    /// No event (eventless transitions, `<onentry>`, `<datamodel>`).
    None,
    /// A triggering event: its name and parameters (`None` type: not inferred yet).
    Event {
        name: &'a str,
        params: &'a [(String, Option<Ty>)],
    },
}

/// Names an expression can refer to.
pub(crate) struct Scope<'a> {
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
pub(crate) const MAX_PATH: usize = 8;

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
pub(crate) fn compile(
    expr: &Expr,
    scope: &Scope<'_>,
    strings: &mut Strings,
    expect: Option<&Ty>,
) -> Result<Typed, CompileError> {
    let mut c = Compiler { scope, strings };
    c.expr(expr, expect)
}

/// Compiles `expr` and converts it to `target` (int to float, `[]` to any array).
pub(crate) fn compile_as(
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
pub(crate) fn unify(a: &Ty, b: &Ty) -> Option<Ty> {
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
        let n = fns.len();
        Ok(Typed {
            ty: Ty::Array(Box::new(elem_ty), bound),
            code: Code::Comp(Box::new(move |env, dest| {
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
            })),
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
        let n = fns.len();
        Ok(Typed {
            ty: Ty::Struct(s),
            code: Code::Comp(Box::new(move |env, dest| {
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
            })),
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

    fn member(
        &mut self,
        e: &Expr,
        obj: &Expr,
        field: &str,
        fat: u32,
    ) -> Result<Typed, CompileError> {
        if let ExprKind::Ident(n) = &obj.kind {
            if n == "_event" && self.scope.vars.iter().all(|(v, _)| v != "_event") {
                if let EventScope::None = self.scope.event {
                    return Err(cerr(
                        obj.start,
                        "`_event` is only available in a transition that has an `event`",
                    ));
                }
                return match field {
                    "name" => Ok(Typed {
                        ty: Ty::Str,
                        code: Code::Str(Box::new(|env| Ok(env.event))),
                    }),
                    "origin" => Ok(Typed {
                        ty: Ty::Str,
                        code: Code::Str(Box::new(|env| Ok(env.origin))),
                    }),
                    "data" => Err(cerr(
                        fat,
                        "`_event.data` cannot be used as a value; read a parameter with `_event.data.<name>`",
                    )),
                    "type" | "sendid" | "origintype" | "invokeid" => {
                        Err(cerr(fat, format!("`_event.{field}` is not supported")))
                    }
                    other => {
                        let hint = match self.scope.event {
                            EventScope::Event { params, .. }
                                if params.iter().any(|(p, _)| p == other) =>
                            {
                                format!(" (did you mean `_event.data.{other}`?)")
                            }
                            _ => format!("; {EVENT_FIELDS_HELP}"),
                        };
                        Err(cerr(fat, format!("`_event` has no field `{other}`{hint}")))
                    }
                };
            }
            if n == "Math" && self.scope.vars.iter().all(|(v, _)| v != "Math") {
                let v = match field {
                    "PI" => std::f64::consts::PI,
                    "E" => std::f64::consts::E,
                    "LN2" => std::f64::consts::LN_2,
                    "LN10" => std::f64::consts::LN_10,
                    "SQRT2" => std::f64::consts::SQRT_2,
                    _ => {
                        return Err(cerr(
                            fat,
                            format!(
                            "`Math.{field}` is not a supported constant (call functions with `()`)"
                        ),
                        ))
                    }
                };
                return Ok(Typed {
                    ty: Ty::Float,
                    code: Code::Float(Box::new(move |_| Ok(v))),
                });
            }
        }
        if let Some(p) = self.path(e)? {
            return Ok(self.path_code(p));
        }
        if let Some(p) = self.path(obj)? {
            if field != "length" {
                if let Some((fi, fty)) = self.projected_field(&p.ty, field) {
                    return Ok(project(p, fi, fty));
                }
            }
        }
        if field == "length" {
            if let Some(mut p) = self.path(obj)? {
                let whole = p.ty.clone();
                // AS2FM reads `s.length` of a struct as the length of its first field,
                // descending through struct fields (its translation flattens structs into
                // one array per leaf field and takes the first).
                while let Ty::Struct(s) = p.ty {
                    let first = self
                        .scope
                        .types
                        .structs
                        .get(s as usize)
                        .and_then(|d| d.fields.first());
                    match first {
                        Some((_, t)) if p.steps.len() < MAX_PATH => {
                            p.ty = t.clone();
                            p.steps.push(Step::Field(0));
                        }
                        _ => break,
                    }
                }
                if matches!(whole, Ty::Struct(_)) && !matches!(p.ty, Ty::Array(..)) {
                    return Err(cerr(
                        fat,
                        format!(
                            "a value of type {} has no `length` (only a struct whose first field is an array has one)",
                            self.tname(&whole)
                        ),
                    ));
                }
                let at = p.at;
                return match p.ty {
                    Ty::Array(..) => Ok(Typed {
                        ty: Ty::Int,
                        code: Code::Int(Box::new(move |env| match p.resolve(env)? {
                            Cell::List(v) => Ok(v.len() as i64),
                            _ => Err(internal(at)),
                        })),
                    }),
                    Ty::Str => Ok(Typed {
                        ty: Ty::Int,
                        code: Code::Int(Box::new(move |env| {
                            let id = match p.resolve(env)? {
                                Cell::Str(s) => *s,
                                _ => return Err(internal(at)),
                            };
                            Ok(env.strings.get(id).encode_utf16().count() as i64)
                        })),
                    }),
                    ref t => Err(cerr(
                        fat,
                        format!("a value of type {} has no `length`", self.tname(t)),
                    )),
                };
            }
            let t = self.expr(obj, None)?;
            return Err(cerr(
                fat,
                format!(
                    "`length` can only be read from a variable or event parameter (found {})",
                    self.tname(&t.ty)
                ),
            ));
        }
        // Not a path: report what the object is.
        let t = self.expr(obj, None)?;
        Err(cerr(
            fat,
            format!(
                "a value of type {} has no field `{field}`",
                self.tname(&t.ty)
            ),
        ))
    }

    /// For `a.f` with `a` an array of structs that have a field `f`: the field's index and
    /// the type of the projection (an array of the field's values).
    fn projected_field(&self, ty: &Ty, field: &str) -> Option<(u32, Ty)> {
        let Ty::Array(elem, bound) = ty else {
            return None;
        };
        let Ty::Struct(s) = **elem else {
            return None;
        };
        let def = self.scope.types.structs.get(s as usize)?;
        let fi = def.fields.iter().position(|(n, _)| n == field)?;
        Some((
            fi as u32,
            Ty::Array(Box::new(def.fields[fi].1.clone()), *bound),
        ))
    }

    fn call(&mut self, e: &Expr, callee: &Expr, args: &[Expr]) -> Result<Typed, CompileError> {
        let at = e.start;
        let fname = match &callee.kind {
            ExprKind::Member(obj, f, _) if matches!(&obj.kind, ExprKind::Ident(n) if n == "Math") => {
                f.as_str()
            }
            _ => return Err(cerr(callee.start, "only `Math` functions can be called")),
        };
        let arity = |n: usize| -> Result<(), CompileError> {
            if args.len() == n {
                Ok(())
            } else {
                Err(cerr(
                    at,
                    format!("`Math.{fname}` takes {n} argument(s), {} given", args.len()),
                ))
            }
        };
        let mut num_args = Vec::with_capacity(args.len());
        for a in args {
            let t = self.expr(a, None)?;
            if !t.ty.is_numeric() {
                return Err(cerr(
                    a.start,
                    format!("`Math.{fname}` needs numbers, found {}", self.tname(&t.ty)),
                ));
            }
            num_args.push(t);
        }
        let float1 = |f: fn(f64) -> f64, mut a: Vec<Typed>| -> Typed {
            let x = as_float(a.remove(0)).unwrap_or_else(|| Box::new(|_| Ok(0.0)));
            Typed {
                ty: Ty::Float,
                code: Code::Float(Box::new(move |e| Ok(f(x(e)?)))),
            }
        };
        match fname {
            "random" => {
                arity(0)?;
                Ok(Typed {
                    ty: Ty::Float,
                    code: Code::Float(Box::new(|env| Ok(unit_f64(env.rng)))),
                })
            }
            "floor" | "ceil" | "round" | "trunc" => {
                arity(1)?;
                let a = num_args.remove(0);
                if let Code::Int(f) = a.code {
                    return Ok(Typed {
                        ty: Ty::Int,
                        code: Code::Int(f),
                    });
                }
                let x = as_float(a).unwrap_or_else(|| Box::new(|_| Ok(0.0)));
                let g: fn(f64) -> f64 = match fname {
                    "floor" => f64::floor,
                    "ceil" => f64::ceil,
                    // ECMAScript rounds halves towards +infinity.
                    "round" => |v: f64| (v + 0.5).floor(),
                    _ => f64::trunc,
                };
                Ok(Typed {
                    ty: Ty::Int,
                    code: Code::Int(Box::new(move |e| Ok(g(x(e)?) as i64))),
                })
            }
            "abs" => {
                arity(1)?;
                let a = num_args.remove(0);
                match a.code {
                    Code::Int(f) => Ok(Typed {
                        ty: Ty::Int,
                        code: Code::Int(Box::new(move |e| Ok(f(e)?.wrapping_abs()))),
                    }),
                    _ => Ok(float1(f64::abs, vec![a])),
                }
            }
            "sign" => {
                arity(1)?;
                let a = num_args.remove(0);
                match a.code {
                    Code::Int(f) => Ok(Typed {
                        ty: Ty::Int,
                        code: Code::Int(Box::new(move |e| Ok(f(e)?.signum()))),
                    }),
                    _ => Ok(float1(
                        |v| {
                            if v == 0.0 || v.is_nan() {
                                v
                            } else {
                                v.signum()
                            }
                        },
                        vec![a],
                    )),
                }
            }
            "min" | "max" => {
                if num_args.is_empty() {
                    return Err(cerr(
                        at,
                        format!("`Math.{fname}` needs at least one argument"),
                    ));
                }
                let is_min = fname == "min";
                if num_args.iter().all(|t| t.ty == Ty::Int) {
                    let fs: Vec<IntFn> = num_args
                        .into_iter()
                        .filter_map(|t| match t.code {
                            Code::Int(f) => Some(f),
                            _ => None,
                        })
                        .collect();
                    Ok(Typed {
                        ty: Ty::Int,
                        code: Code::Int(Box::new(move |e| {
                            let mut acc = if is_min { i64::MAX } else { i64::MIN };
                            for f in &fs {
                                let v = f(e)?;
                                acc = if is_min { acc.min(v) } else { acc.max(v) };
                            }
                            Ok(acc)
                        })),
                    })
                } else {
                    let fs: Vec<FloatFn> = num_args.into_iter().filter_map(as_float).collect();
                    Ok(Typed {
                        ty: Ty::Float,
                        code: Code::Float(Box::new(move |e| {
                            let mut acc = if is_min {
                                f64::INFINITY
                            } else {
                                f64::NEG_INFINITY
                            };
                            for f in &fs {
                                let v = f(e)?;
                                if v.is_nan() {
                                    return Ok(f64::NAN);
                                }
                                acc = if is_min { acc.min(v) } else { acc.max(v) };
                            }
                            Ok(acc)
                        })),
                    })
                }
            }
            "sqrt" | "sin" | "cos" | "tan" | "asin" | "acos" | "atan" | "exp" | "log" | "log2"
            | "log10" | "cbrt" => {
                arity(1)?;
                let f: fn(f64) -> f64 = match fname {
                    "sqrt" => f64::sqrt,
                    "sin" => f64::sin,
                    "cos" => f64::cos,
                    "tan" => f64::tan,
                    "asin" => f64::asin,
                    "acos" => f64::acos,
                    "atan" => f64::atan,
                    "exp" => f64::exp,
                    "log" => f64::ln,
                    "log2" => f64::log2,
                    "log10" => f64::log10,
                    _ => f64::cbrt,
                };
                Ok(float1(f, num_args))
            }
            "atan2" | "pow" | "hypot" => {
                arity(2)?;
                let mut it = num_args.into_iter();
                let (Some(a), Some(b)) =
                    (it.next().and_then(as_float), it.next().and_then(as_float))
                else {
                    return Err(cerr(at, "internal error: bad arguments"));
                };
                let f: fn(f64, f64) -> f64 = match fname {
                    "atan2" => f64::atan2,
                    "pow" => f64::powf,
                    _ => f64::hypot,
                };
                Ok(Typed {
                    ty: Ty::Float,
                    code: Code::Float(Box::new(move |e| Ok(f(a(e)?, b(e)?)))),
                })
            }
            other => Err(cerr(
                callee.start,
                format!("`Math.{other}` is not supported"),
            )),
        }
    }

    fn unary(&mut self, at: u32, op: UnOp, x: &Expr) -> Result<Typed, CompileError> {
        let t = self.expr(x, None)?;
        match (op, t.code) {
            (UnOp::Not, Code::Bool(f)) => Ok(Typed {
                ty: Ty::Bool,
                code: Code::Bool(Box::new(move |e| Ok(!f(e)?))),
            }),
            (UnOp::Neg, Code::Int(f)) => Ok(Typed {
                ty: Ty::Int,
                code: Code::Int(Box::new(move |e| Ok(f(e)?.wrapping_neg()))),
            }),
            (UnOp::Neg, Code::Float(f)) => Ok(Typed {
                ty: Ty::Float,
                code: Code::Float(Box::new(move |e| Ok(-f(e)?))),
            }),
            (UnOp::Plus, code @ (Code::Int(_) | Code::Float(_))) => Ok(Typed { ty: t.ty, code }),
            (UnOp::Not, _) => Err(cerr(
                at,
                format!("`!` needs a bool, found {}", self.tname(&t.ty)),
            )),
            (_, _) => Err(cerr(
                at,
                format!(
                    "unary minus/plus needs a number, found {}",
                    self.tname(&t.ty)
                ),
            )),
        }
    }

    fn binary(&mut self, e: &Expr, op: BinOp, a: &Expr, b: &Expr) -> Result<Typed, CompileError> {
        let at = e.start;
        let ta = self.expr(a, None)?;
        let tb = self.expr(b, None)?;
        let type_err = |s: &Self, ta: &Ty, tb: &Ty| {
            cerr(
                at,
                format!(
                    "operator `{}` cannot be applied to {} and {}",
                    op.symbol(),
                    s.tname(ta),
                    s.tname(tb)
                ),
            )
        };
        match op {
            BinOp::And | BinOp::Or => match (ta.code, tb.code) {
                (Code::Bool(x), Code::Bool(y)) => Ok(Typed {
                    ty: Ty::Bool,
                    code: Code::Bool(if op == BinOp::And {
                        Box::new(move |e| Ok(x(e)? && y(e)?))
                    } else {
                        Box::new(move |e| Ok(x(e)? || y(e)?))
                    }),
                }),
                _ => Err(type_err(self, &ta.ty, &tb.ty)),
            },
            BinOp::Add | BinOp::Sub | BinOp::Mul | BinOp::Div | BinOp::Rem => {
                if !ta.ty.is_numeric() || !tb.ty.is_numeric() {
                    if op == BinOp::Add && (ta.ty == Ty::Str || tb.ty == Ty::Str) {
                        return Err(cerr(at, "string concatenation is not supported"));
                    }
                    return Err(type_err(self, &ta.ty, &tb.ty));
                }
                if ta.ty == Ty::Int && tb.ty == Ty::Int && op != BinOp::Div {
                    let (Code::Int(x), Code::Int(y)) = (ta.code, tb.code) else {
                        return Err(cerr(at, "internal error"));
                    };
                    let bat = self.abs(b.start);
                    let f: IntFn = match op {
                        BinOp::Add => Box::new(move |e| Ok(x(e)?.wrapping_add(y(e)?))),
                        BinOp::Sub => Box::new(move |e| Ok(x(e)?.wrapping_sub(y(e)?))),
                        BinOp::Mul => Box::new(move |e| Ok(x(e)?.wrapping_mul(y(e)?))),
                        _ => Box::new(move |e| {
                            let l = x(e)?;
                            let r = y(e)?;
                            if r == 0 {
                                Err(EvalError {
                                    at: bat,
                                    kind: EvalErrorKind::DivByZero,
                                })
                            } else {
                                Ok(l.wrapping_rem(r))
                            }
                        }),
                    };
                    return Ok(Typed {
                        ty: Ty::Int,
                        code: Code::Int(f),
                    });
                }
                let (Some(x), Some(y)) = (as_float(ta), as_float(tb)) else {
                    return Err(cerr(at, "internal error"));
                };
                let f: FloatFn = match op {
                    BinOp::Add => Box::new(move |e| Ok(x(e)? + y(e)?)),
                    BinOp::Sub => Box::new(move |e| Ok(x(e)? - y(e)?)),
                    BinOp::Mul => Box::new(move |e| Ok(x(e)? * y(e)?)),
                    BinOp::Div => Box::new(move |e| Ok(x(e)? / y(e)?)),
                    _ => Box::new(move |e| Ok(x(e)? % y(e)?)),
                };
                Ok(Typed {
                    ty: Ty::Float,
                    code: Code::Float(f),
                })
            }
            BinOp::Eq | BinOp::Ne | BinOp::Lt | BinOp::Le | BinOp::Gt | BinOp::Ge => {
                let ordered = !matches!(op, BinOp::Eq | BinOp::Ne);
                let (tya, tyb) = (ta.ty.clone(), tb.ty.clone());
                let code: BoolFn = match (ta.code, tb.code) {
                    (Code::Int(x), Code::Int(y)) => match op {
                        BinOp::Eq => Box::new(move |e| Ok(x(e)? == y(e)?)),
                        BinOp::Ne => Box::new(move |e| Ok(x(e)? != y(e)?)),
                        BinOp::Lt => Box::new(move |e| Ok(x(e)? < y(e)?)),
                        BinOp::Le => Box::new(move |e| Ok(x(e)? <= y(e)?)),
                        BinOp::Gt => Box::new(move |e| Ok(x(e)? > y(e)?)),
                        _ => Box::new(move |e| Ok(x(e)? >= y(e)?)),
                    },
                    (
                        ca @ (Code::Int(_) | Code::Float(_)),
                        cb @ (Code::Int(_) | Code::Float(_)),
                    ) => {
                        let (Some(x), Some(y)) = (
                            as_float(Typed {
                                ty: tya.clone(),
                                code: ca,
                            }),
                            as_float(Typed {
                                ty: tyb.clone(),
                                code: cb,
                            }),
                        ) else {
                            return Err(cerr(at, "internal error"));
                        };
                        match op {
                            BinOp::Eq => Box::new(move |e| Ok(x(e)? == y(e)?)),
                            BinOp::Ne => Box::new(move |e| Ok(x(e)? != y(e)?)),
                            BinOp::Lt => Box::new(move |e| Ok(x(e)? < y(e)?)),
                            BinOp::Le => Box::new(move |e| Ok(x(e)? <= y(e)?)),
                            BinOp::Gt => Box::new(move |e| Ok(x(e)? > y(e)?)),
                            _ => Box::new(move |e| Ok(x(e)? >= y(e)?)),
                        }
                    }
                    (Code::Bool(x), Code::Bool(y)) if !ordered => {
                        if op == BinOp::Eq {
                            Box::new(move |e| Ok(x(e)? == y(e)?))
                        } else {
                            Box::new(move |e| Ok(x(e)? != y(e)?))
                        }
                    }
                    (Code::Str(x), Code::Str(y)) if !ordered => {
                        if op == BinOp::Eq {
                            Box::new(move |e| Ok(x(e)? == y(e)?))
                        } else {
                            Box::new(move |e| Ok(x(e)? != y(e)?))
                        }
                    }
                    _ => return Err(type_err(self, &tya, &tyb)),
                };
                Ok(Typed {
                    ty: Ty::Bool,
                    code: Code::Bool(code),
                })
            }
        }
    }

    fn cond(
        &mut self,
        e: &Expr,
        c: &Expr,
        a: &Expr,
        b: &Expr,
        expect: Option<&Ty>,
    ) -> Result<Typed, CompileError> {
        let tc = self.expr(c, None)?;
        let Code::Bool(fc) = tc.code else {
            return Err(cerr(
                c.start,
                format!(
                    "condition has type {} but bool is expected",
                    self.tname(&tc.ty)
                ),
            ));
        };
        let ta = self.expr(a, expect)?;
        let tb = self.expr(b, expect)?;
        let Some(ty) = unify(&ta.ty, &tb.ty) else {
            return Err(cerr(
                e.start,
                format!(
                    "the branches of `?:` have different types ({} and {})",
                    self.tname(&ta.ty),
                    self.tname(&tb.ty)
                ),
            ));
        };
        let types = self.scope.types;
        let (Ok(ta), Ok(tb)) = (coerce(ta, &ty, types), coerce(tb, &ty, types)) else {
            return Err(cerr(e.start, "internal error: branch types"));
        };
        let code = match (ta.code, tb.code) {
            (Code::Bool(x), Code::Bool(y)) => {
                Code::Bool(Box::new(move |e| if fc(e)? { x(e) } else { y(e) }))
            }
            (Code::Int(x), Code::Int(y)) => {
                Code::Int(Box::new(move |e| if fc(e)? { x(e) } else { y(e) }))
            }
            (Code::Float(x), Code::Float(y)) => {
                Code::Float(Box::new(move |e| if fc(e)? { x(e) } else { y(e) }))
            }
            (Code::Str(x), Code::Str(y)) => {
                Code::Str(Box::new(move |e| if fc(e)? { x(e) } else { y(e) }))
            }
            (Code::Comp(x), Code::Comp(y)) => {
                Code::Comp(Box::new(move |e, d| if fc(e)? { x(e, d) } else { y(e, d) }))
            }
            _ => return Err(cerr(e.start, "internal error: branch code")),
        };
        Ok(Typed { ty, code })
    }
}

/// `a.f` for an array of structs `a`: the array of every element's field `f`, written into
/// the destination's buffers.
fn project(p: Path, fi: u32, ty: Ty) -> Typed {
    let at = p.at;
    Typed {
        ty,
        code: Code::Comp(Box::new(move |env, dest| {
            let Cell::List(items) = p.resolve(env)? else {
                return Err(internal(at));
            };
            if !matches!(dest, Cell::List(_)) {
                *dest = Cell::list(Vec::with_capacity(items.len()));
            }
            let Cell::List(out) = dest else {
                return Err(internal(at));
            };
            out.truncate(items.len());
            for (k, item) in items.iter().enumerate() {
                let Cell::List(fields) = item else {
                    return Err(internal(at));
                };
                let v = fields.get(fi as usize).ok_or(internal(at))?;
                match out.get_mut(k) {
                    Some(o) => o.clone_from(v),
                    None => out.push_copy(v),
                }
            }
            Ok(())
        })),
    }
}

/// An assignable location: a variable, then indices and fields.
pub(crate) struct Place {
    /// Variable slot.
    pub var: u32,
    steps: Vec<PlaceStep>,
    /// Type of the location.
    pub ty: Ty,
    /// Maximum length when the location is a bounded array.
    pub bound: Option<u32>,
    /// `a.length = n`: the element default used when the array grows.
    set_length: Option<Cell>,
    /// `a.f = v` for an array of structs `a`: the field index and the element default;
    /// `a` takes the length of `v` and element `k` gets `v[k]` as its field `f`.
    column: Option<(u32, Cell)>,
}

enum PlaceStep {
    /// Index into an array; the element default (for growth), the array's bound, text offset.
    Index(IntFn, Cell, Option<u32>, u32),
    Field(u32),
}

impl Place {
    /// True when the location is a whole variable.
    pub fn is_whole_var(&self) -> bool {
        self.steps.is_empty() && self.set_length.is_none() && self.column.is_none()
    }

    /// Stores `value`, reusing the destination's buffers.
    pub fn store(&self, vars: &mut [Cell], idx: &[i64; MAX_PATH], value: &Cell) -> Res<()> {
        let dst = self.target(vars, idx)?;
        if let Some((fi, default)) = &self.column {
            let (Cell::List(items), Cell::List(values)) = (dst, value) else {
                return Err(internal(0));
            };
            if let Some(b) = self.bound {
                if values.len() > b as usize {
                    return Err(EvalError {
                        at: 0,
                        kind: EvalErrorKind::TooLong { bound: b },
                    });
                }
            }
            items.resize(values.len(), default);
            for (item, v) in items.iter_mut().zip(values.iter()) {
                let Cell::List(fields) = item else {
                    return Err(internal(0));
                };
                fields
                    .get_mut(*fi as usize)
                    .ok_or(internal(0))?
                    .clone_from(v);
            }
            return Ok(());
        }
        let Some(default) = &self.set_length else {
            if let (Some(b), Cell::List(v)) = (self.bound, value) {
                if v.len() > b as usize {
                    return Err(EvalError {
                        at: 0,
                        kind: EvalErrorKind::TooLong { bound: b },
                    });
                }
            }
            dst.clone_from(value);
            return Ok(());
        };
        let (Cell::List(items), Cell::Int(n)) = (dst, value) else {
            return Err(internal(0));
        };
        let len = items.len();
        let Ok(n) = usize::try_from(*n) else {
            return Err(EvalError {
                at: 0,
                kind: EvalErrorKind::Index { index: *n, len },
            });
        };
        if let Some(b) = self.bound {
            if n > b as usize {
                return Err(EvalError {
                    at: 0,
                    kind: EvalErrorKind::TooLong { bound: b },
                });
            }
        }
        if n > len + 1_000_000 {
            return Err(EvalError {
                at: 0,
                kind: EvalErrorKind::Index {
                    index: n as i64,
                    len,
                },
            });
        }
        items.resize(n, default);
        Ok(())
    }

    /// Evaluates the indices (before the variables are borrowed mutably).
    pub fn eval_indices(&self, env: &mut Env<'_>, out: &mut [i64; MAX_PATH]) -> Res<()> {
        for (k, s) in self.steps.iter().enumerate() {
            if let (PlaceStep::Index(f, ..), Some(slot)) = (s, out.get_mut(k)) {
                *slot = f(env)?;
            }
        }
        Ok(())
    }

    /// The cell to write, growing arrays written at or past their end (ECMAScript style).
    pub fn target<'v>(&self, vars: &'v mut [Cell], idx: &[i64; MAX_PATH]) -> Res<&'v mut Cell> {
        let mut cell = vars.get_mut(self.var as usize).ok_or(internal(0))?;
        for (k, s) in self.steps.iter().enumerate() {
            let Cell::List(items) = cell else {
                return Err(internal(0));
            };
            match s {
                PlaceStep::Field(f) => {
                    cell = items.get_mut(*f as usize).ok_or(internal(0))?;
                }
                PlaceStep::Index(_, default, bound, at) => {
                    let i = idx.get(k).copied().unwrap_or(0);
                    let len = items.len();
                    let Ok(u) = usize::try_from(i) else {
                        return Err(EvalError {
                            at: *at,
                            kind: EvalErrorKind::Index { index: i, len },
                        });
                    };
                    if let Some(b) = bound {
                        if u >= *b as usize {
                            return Err(EvalError {
                                at: *at,
                                kind: EvalErrorKind::TooLong { bound: *b },
                            });
                        }
                    }
                    if u >= len {
                        if u > len + 1_000_000 {
                            return Err(EvalError {
                                at: *at,
                                kind: EvalErrorKind::Index { index: i, len },
                            });
                        }
                        items.resize(u + 1, default);
                    }
                    cell = items.get_mut(u).ok_or(internal(*at))?;
                }
            }
        }
        Ok(cell)
    }
}

/// Compiles the left-hand side of an `<assign>`.
pub(crate) fn compile_place(
    e: &Expr,
    scope: &Scope<'_>,
    strings: &mut Strings,
) -> Result<Place, CompileError> {
    match &e.kind {
        ExprKind::Ident(name) => match scope.vars.iter().position(|(n, _)| n == name) {
            Some(i) => {
                let ty = scope.vars[i].1.clone();
                let bound = match &ty {
                    Ty::Array(_, b) => *b,
                    _ => None,
                };
                Ok(Place {
                    var: i as u32,
                    steps: Vec::new(),
                    ty,
                    bound,
                    set_length: None,
                    column: None,
                })
            }
            None if name == "_event" => Err(cerr(e.start, "cannot assign to `_event`")),
            None => Err(unknown_variable(e.start, name)),
        },
        ExprKind::Index(arr, idx) => {
            let mut p = compile_place(arr, scope, strings)?;
            if p.set_length.is_some() {
                return Err(cerr(idx.start, "`length` cannot be indexed"));
            }
            if p.column.is_some() {
                return Err(cerr(
                    idx.start,
                    "a field of every element (`a.f`) cannot be indexed here; write `a[i].f`",
                ));
            }
            let Ty::Array(elem, bound) = p.ty.clone() else {
                return Err(cerr(
                    idx.start,
                    format!(
                        "a value of type {} cannot be indexed",
                        scope.types.name(&p.ty)
                    ),
                ));
            };
            let i = compile(idx, scope, strings, None)?;
            let Code::Int(f) = i.code else {
                return Err(cerr(
                    idx.start,
                    format!(
                        "array index has type {} but int is expected",
                        scope.types.name(&i.ty)
                    ),
                ));
            };
            if p.steps.len() >= MAX_PATH {
                return Err(cerr(idx.start, "access path too long"));
            }
            let default = scope.types.default_cell(&elem);
            p.steps
                .push(PlaceStep::Index(f, default, bound, (scope.abs)(idx.start)));
            p.bound = match &*elem {
                Ty::Array(_, b) => *b,
                _ => None,
            };
            p.ty = *elem;
            Ok(p)
        }
        ExprKind::Member(obj, field, fat) => {
            if matches!(&obj.kind, ExprKind::Ident(n) if n == "_event")
                || matches!(&obj.kind, ExprKind::Member(o, _, _) if matches!(&o.kind, ExprKind::Ident(n) if n == "_event"))
            {
                return Err(cerr(e.start, "cannot assign to `_event`"));
            }
            let mut p = compile_place(obj, scope, strings)?;
            if p.set_length.is_some() {
                return Err(cerr(*fat, format!("`length` has no field `{field}`")));
            }
            if p.column.is_some() {
                return Err(cerr(
                    *fat,
                    format!("a field of every element (`a.f`) has no field `{field}` here; write `a[i].f.{field}`"),
                ));
            }
            if let (Ty::Array(elem, _), "length") = (&p.ty, field.as_str()) {
                // `a.length = n` truncates or extends with default values.
                p.set_length = Some(scope.types.default_cell(elem));
                p.ty = Ty::Int;
                return Ok(p);
            }
            if let Ty::Array(elem, _) = &p.ty {
                if let Ty::Struct(s) = **elem {
                    let found = scope.types.structs.get(s as usize).and_then(|d| {
                        d.fields
                            .iter()
                            .enumerate()
                            .find(|(_, (n, _))| n == field)
                            .map(|(i, (_, t))| (i, t.clone()))
                    });
                    if let Some((fi, fty)) = found {
                        // `a.f = v` writes field `f` of every element (AS2FM's flattened
                        // structs make `a.f` the array of the elements' `f`).
                        p.column = Some((fi as u32, scope.types.default_cell(elem)));
                        p.ty = Ty::Array(Box::new(fty), p.bound);
                        return Ok(p);
                    }
                }
            }
            let Ty::Struct(s) = p.ty else {
                return Err(cerr(
                    *fat,
                    format!("type {} has no field `{field}`", scope.types.name(&p.ty)),
                ));
            };
            let def = scope.types.structs.get(s as usize);
            let Some((fi, (_, fty))) =
                def.and_then(|d| d.fields.iter().enumerate().find(|(_, (n, _))| n == field))
            else {
                return Err(cerr(
                    *fat,
                    format!("type {} has no field `{field}`", scope.types.name(&p.ty)),
                ));
            };
            if p.steps.len() >= MAX_PATH {
                return Err(cerr(*fat, "access path too long"));
            }
            p.steps.push(PlaceStep::Field(fi as u32));
            p.ty = fty.clone();
            p.bound = match &p.ty {
                Ty::Array(_, b) => *b,
                _ => None,
            };
            Ok(p)
        }
        _ => Err(cerr(
            e.start,
            "an assignment location must be a variable, `a[i]` or `s.field`",
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::super::parse::parse_expr;
    use super::super::value::StructDef;
    use super::*;

    struct Fixed(u64);
    impl Entropy for Fixed {
        fn next_u64(&mut self) -> u64 {
            self.0
        }
    }

    fn vars() -> Vec<(String, Ty)> {
        vec![
            ("i".into(), Ty::Int),
            ("f".into(), Ty::Float),
            ("b".into(), Ty::Bool),
            ("s".into(), Ty::Str),
            ("a".into(), Ty::Array(Box::new(Ty::Int), None)),
            (
                "m".into(),
                Ty::Array(Box::new(Ty::Array(Box::new(Ty::Float), None)), Some(3)),
            ),
        ]
    }

    fn cells(strings: &mut Strings) -> Vec<Cell> {
        vec![
            Cell::Int(7),
            Cell::Float(2.5),
            Cell::Bool(true),
            Cell::Str(strings.intern("hi")),
            Cell::list(vec![Cell::Int(1), Cell::Int(2), Cell::Int(3)]),
            Cell::list(vec![
                Cell::list(vec![]),
                Cell::list(vec![Cell::Float(0.5), Cell::Float(1.5)]),
            ]),
        ]
    }

    /// Compiles and evaluates `text` in a fixed scope; the result as a cell.
    fn eval(text: &str) -> Result<Cell, String> {
        let mut strings = Strings::default();
        let vs = vars();
        let types = TypeTable::default();
        let params = [("p".to_string(), Some(Ty::Int))];
        let scope = Scope {
            vars: &vs,
            event: EventScope::Event {
                name: "ev",
                params: &params,
            },
            types: &types,
            abs: &|k| k,
        };
        let e = parse_expr(text).map_err(|e| e.to_string())?;
        let t =
            compile(&e, &scope, &mut strings, None).map_err(|e| format!("{}@{}", e.msg, e.at))?;
        let f = t.into_cell_fn();
        let vals = cells(&mut strings);
        let ps = [Cell::Int(40)];
        let mut rng = Fixed(1 << 63);
        let mut env = Env {
            vars: &vals,
            params: &ps,
            event: StrId(0),
            origin: StrId(0),
            rng: &mut rng,
            strings: &strings,
        };
        let mut out = Cell::Int(0);
        f(&mut env, &mut out).map_err(|e| e.message())?;
        Ok(out)
    }

    #[test]
    fn arithmetic_and_typing() {
        assert_eq!(eval("i * 2 + 1"), Ok(Cell::Int(15)));
        assert_eq!(eval("i / 2"), Ok(Cell::Float(3.5)));
        assert_eq!(eval("i % 4"), Ok(Cell::Int(3)));
        assert_eq!(eval("i + f"), Ok(Cell::Float(9.5)));
        assert_eq!(eval("-i"), Ok(Cell::Int(-7)));
        assert_eq!(eval("Math.floor(f)"), Ok(Cell::Int(2)));
        assert_eq!(eval("Math.round(-2.5)"), Ok(Cell::Int(-2)));
        assert_eq!(eval("Math.max(i, 3)"), Ok(Cell::Int(7)));
        assert_eq!(eval("Math.min(i, f)"), Ok(Cell::Float(2.5)));
        assert_eq!(eval("Math.abs(-3)"), Ok(Cell::Int(3)));
        assert_eq!(eval("Math.random()"), Ok(Cell::Float(0.5)));
        assert_eq!(eval("9223372036854775807 + 1"), Ok(Cell::Int(i64::MIN)));
        assert!(eval("i % 0").unwrap_err().contains("by zero"));
    }

    #[test]
    fn logic_comparisons_ternary() {
        assert_eq!(eval("i > 3 && !b || false"), Ok(Cell::Bool(false)));
        assert_eq!(eval("i == 7.0"), Ok(Cell::Bool(true)));
        assert_eq!(eval("0.131"), Ok(Cell::Float(0.131)));
        assert_eq!(eval("f <= 2.6"), Ok(Cell::Bool(true)));
        assert_eq!(eval("0.0 <= f && f <= 3.0"), Ok(Cell::Bool(true)));
        assert_eq!(eval("0.0 <= f && f <= 0.7"), Ok(Cell::Bool(false)));
        assert_eq!(eval("s == 'hi'"), Ok(Cell::Bool(true)));
        assert_eq!(eval("s != 'ho'"), Ok(Cell::Bool(true)));
        assert_eq!(eval("b ? i : f"), Ok(Cell::Float(7.0)));
        assert_eq!(
            eval("i < 0 ? 'neg' : s").map(|c| matches!(c, Cell::Str(_))),
            Ok(true)
        );
        assert_eq!(eval("_event.data.p + 2"), Ok(Cell::Int(42)));
    }

    #[test]
    fn arrays() {
        assert_eq!(eval("a[1]"), Ok(Cell::Int(2)));
        assert_eq!(eval("a.length"), Ok(Cell::Int(3)));
        assert_eq!(eval("m[1][1] + m.length"), Ok(Cell::Float(3.5)));
        assert_eq!(eval("m[0].length"), Ok(Cell::Int(0)));
        assert_eq!(eval("s.length"), Ok(Cell::Int(2)));
        assert_eq!(
            eval("[i, 2]"),
            Ok(Cell::list(vec![Cell::Int(7), Cell::Int(2)]))
        );
        assert_eq!(
            eval("[1, 2.5]"),
            Ok(Cell::list(vec![Cell::Float(1.0), Cell::Float(2.5)]))
        );
        assert!(eval("a[3]").unwrap_err().contains("out of bounds"));
        assert!(eval("a[-1]").unwrap_err().contains("out of bounds"));
    }

    #[test]
    fn type_errors_with_offsets() {
        for (t, at, needle) in [
            ("i - s", 0, "cannot be applied"),
            ("i && b", 0, "cannot be applied"),
            ("!i", 0, "needs a bool"),
            ("x + 1", 0, "unknown variable `x`"),
            ("a[f]", 2, "int is expected"),
            ("i[0]", 2, "cannot be indexed"),
            ("_event.p == 1", 7, "did you mean `_event.data.p`"),
            ("_event.data.q", 12, "never sent with a parameter `q`"),
            ("Math.foo(1)", 0, "not supported"),
            ("Math.floor(1, 2)", 0, "takes 1 argument"),
            ("s + 'x'", 0, "concatenation"),
            ("b ? 1 : 'x'", 0, "different types"),
            ("[1, 'x']", 4, "different types"),
            ("f(1)", 0, "only `Math` functions"),
            ("i.x", 2, "has no field"),
            ("s < 'a'", 0, "cannot be applied"),
        ] {
            let err = eval(t).unwrap_err();
            assert!(err.contains(needle), "{t}: {err}");
            assert!(err.ends_with(&format!("@{at}")), "{t}: {err}");
        }
    }

    #[test]
    fn places_grow_arrays() {
        let mut strings = Strings::default();
        let vs = vars();
        let types = TypeTable::default();
        let scope = Scope {
            vars: &vs,
            event: EventScope::None,
            types: &types,
            abs: &|k| k,
        };
        let mut vals = cells(&mut strings);
        let mut idx = [0i64; MAX_PATH];
        let p = compile_place(&parse_expr("a[a.length]").unwrap(), &scope, &mut strings).unwrap();
        {
            let mut rng = Fixed(0);
            let mut env = Env {
                vars: &vals,
                params: &[],
                event: StrId(0),
                origin: StrId(0),
                rng: &mut rng,
                strings: &strings,
            };
            p.eval_indices(&mut env, &mut idx).unwrap();
        }
        *p.target(&mut vals, &idx).unwrap() = Cell::Int(9);
        assert_eq!(
            vals[4],
            Cell::list(vec![Cell::Int(1), Cell::Int(2), Cell::Int(3), Cell::Int(9)])
        );
        // m is bounded to 3 rows: row 3 is out of range, row 2 is created.
        let q = compile_place(
            &parse_expr("m[k]").unwrap_or_else(|_| unreachable!()),
            &scope,
            &mut strings,
        );
        assert!(q.is_err(), "unknown index variable");
        let q = compile_place(&parse_expr("m[i - 4]").unwrap(), &scope, &mut strings).unwrap();
        idx[0] = 3;
        assert!(q.target(&mut vals, &idx).is_err());
        idx[0] = 2;
        *q.target(&mut vals, &idx).unwrap() = Cell::list(vec![Cell::Float(4.0)]);
        assert!(matches!(&vals[5], Cell::List(rows) if rows.len() == 3));
        assert!(
            compile_place(&parse_expr("_event.data.p").unwrap(), &scope, &mut strings).is_err()
        );
        let len = compile_place(&parse_expr("a.length").unwrap(), &scope, &mut strings).unwrap();
        len.store(&mut vals, &idx, &Cell::Int(1)).unwrap();
        assert_eq!(vals[4], Cell::list(vec![Cell::Int(1)]));
        len.store(&mut vals, &idx, &Cell::Int(3)).unwrap();
        assert_eq!(
            vals[4],
            Cell::list(vec![Cell::Int(1), Cell::Int(0), Cell::Int(0)])
        );
        assert!(compile_place(&parse_expr("a.length.x").unwrap(), &scope, &mut strings).is_err());
        assert!(compile_place(&parse_expr("i + 1").unwrap(), &scope, &mut strings).is_err());
    }

    /// Point {frame: string, x: float, y: float}, Poly {points: Point[]}, and variables
    /// `pt: Point`, `poly: Poly`, `polys: Poly[]`, `i: int`.
    fn struct_scope() -> (Vec<(String, Ty)>, TypeTable) {
        let mut types = TypeTable::default();
        types.structs.push(StructDef {
            name: "Point".into(),
            fields: vec![
                ("frame".into(), Ty::Str),
                ("x".into(), Ty::Float),
                ("y".into(), Ty::Float),
            ],
        });
        types.structs.push(StructDef {
            name: "Poly".into(),
            fields: vec![("points".into(), Ty::Array(Box::new(Ty::Struct(0)), None))],
        });
        let vars = vec![
            ("pt".into(), Ty::Struct(0)),
            ("poly".into(), Ty::Struct(1)),
            ("polys".into(), Ty::Array(Box::new(Ty::Struct(1)), Some(4))),
            ("i".into(), Ty::Int),
        ];
        (vars, types)
    }

    fn point(strings: &mut Strings, frame: &str, x: f64, y: f64) -> Cell {
        Cell::list(vec![
            Cell::Str(strings.intern(frame)),
            Cell::Float(x),
            Cell::Float(y),
        ])
    }

    /// Compiles `text` as a value of `expect` in [`struct_scope`], evaluates it, and (when
    /// `place` is given) stores it there; returns the variables afterwards.
    fn eval_struct(
        text: &str,
        expect: Option<&str>,
        place: Option<&str>,
    ) -> Result<(Vec<Cell>, Cell, Strings), String> {
        let (vs, types) = struct_scope();
        let mut strings = Strings::default();
        let scope = Scope {
            vars: &vs,
            event: EventScope::None,
            types: &types,
            abs: &|k| k,
        };
        let place = match place {
            Some(p) => Some(
                compile_place(&parse_expr(p).unwrap(), &scope, &mut strings)
                    .map_err(|e| format!("{}@{}", e.msg, e.at))?,
            ),
            None => None,
        };
        let want = match (expect, &place) {
            (Some("Point"), _) => Some(Ty::Struct(0)),
            (Some("Poly"), _) => Some(Ty::Struct(1)),
            (Some("Poly[]"), _) => Some(Ty::Array(Box::new(Ty::Struct(1)), None)),
            (_, Some(p)) => Some(p.ty.clone()),
            _ => None,
        };
        let e = parse_expr(text).map_err(|e| e.to_string())?;
        let t = match &want {
            Some(w) => compile_as(&e, &scope, &mut strings, w, "the value"),
            None => compile(&e, &scope, &mut strings, None),
        }
        .map_err(|e| format!("{}@{}", e.msg, e.at))?;
        let f = t.into_cell_fn();
        let p0 = point(&mut strings, "a", 1.0, 2.0);
        let p1 = point(&mut strings, "b", 3.0, 4.0);
        let mut vals = vec![
            p0.clone(),
            Cell::list(vec![Cell::list(vec![p0.clone(), p1.clone()])]),
            Cell::list(vec![
                Cell::list(vec![Cell::list(vec![])]),
                Cell::list(vec![Cell::list(vec![p1])]),
            ]),
            Cell::Int(1),
        ];
        let mut out = Cell::Int(0);
        let mut idx = [0i64; MAX_PATH];
        {
            let mut rng = Fixed(0);
            let mut env = Env {
                vars: &vals,
                params: &[],
                event: StrId(0),
                origin: StrId(0),
                rng: &mut rng,
                strings: &strings,
            };
            f(&mut env, &mut out).map_err(|e| e.message())?;
            if let Some(p) = &place {
                p.eval_indices(&mut env, &mut idx)
                    .map_err(|e| e.message())?;
            }
        }
        if let Some(p) = &place {
            p.store(&mut vals, &idx, &out).map_err(|e| e.message())?;
        }
        Ok((vals, out, strings))
    }

    #[test]
    fn object_literals_take_the_declared_struct_type() {
        let (_, out, mut st) =
            eval_struct("{'frame': 'w', y: 2, x: -1}", Some("Point"), None).unwrap();
        assert_eq!(out, point(&mut st, "w", -1.0, 2.0));
        let (_, out, mut st) = eval_struct(
            "{points: [{frame: 'a', x: 0.5, y: 1}, {frame: 'b', x: 2, y: 3},]}",
            Some("Poly"),
            None,
        )
        .unwrap();
        assert_eq!(
            out,
            Cell::list(vec![Cell::list(vec![
                point(&mut st, "a", 0.5, 1.0),
                point(&mut st, "b", 2.0, 3.0)
            ])])
        );
        let (_, out, _) = eval_struct("[{points: []}, poly]", Some("Poly[]"), None).unwrap();
        assert!(matches!(out, Cell::List(ref v) if v.len() == 2));
        // Typed by the location it is assigned to, even deep inside a path.
        let (vals, _, mut st) =
            eval_struct("{frame: 'n', x: 9, y: 8}", None, Some("polys[1].points[0]")).unwrap();
        assert_eq!(
            vals[2],
            Cell::list(vec![
                Cell::list(vec![Cell::list(vec![])]),
                Cell::list(vec![Cell::list(vec![point(&mut st, "n", 9.0, 8.0)])]),
            ])
        );
        let (_, out, _) =
            eval_struct("i > 0 ? {frame: '', x: 1, y: 1} : pt", Some("Point"), None).unwrap();
        assert!(matches!(out, Cell::List(ref v) if v[1] == Cell::Float(1.0)));
    }

    #[test]
    fn bad_object_literals_are_errors_at_their_position() {
        for (text, expect, at, needle) in [
            ("{x: 1, y: 2}", "Point", 0, "no value for field `frame`"),
            ("{x: 1}", "Point", 0, "fields `frame`, `y`"),
            (
                "{frame: '', x: 1, y: 2, z: 3}",
                "Point",
                24,
                "type Point has no field `z` (its fields: frame, x, y)",
            ),
            (
                "{frame: 1, x: 1, y: 2}",
                "Point",
                8,
                "field `frame` of Point has type int but string is expected",
            ),
            (
                "{points: [{frame: 'a', x: 'no', y: 1}]}",
                "Poly",
                26,
                "field `x` of Point has type string",
            ),
            (
                "{points: pt}",
                "Poly",
                9,
                "has type Point but Point[] is expected",
            ),
            ("pt", "Poly", 0, "has type Point but Poly is expected"),
        ] {
            let err = eval_struct(text, Some(expect), None).unwrap_err();
            assert!(err.contains(needle), "{text}: {err}");
            assert!(err.ends_with(&format!("@{at}")), "{text}: {err}");
        }
        let err = eval_struct("{x: 1}", None, None).unwrap_err();
        assert!(
            err.contains("struct type of this object literal is not known"),
            "{err}"
        );
        let err = eval_struct("{x: 1}", None, Some("i")).unwrap_err();
        assert!(err.contains("not a value of type int"), "{err}");
        let err = eval_struct("1", None, Some("pt.z")).unwrap_err();
        assert!(err.contains("type Point has no field `z`"), "{err}");
    }

    #[test]
    fn struct_paths_projections_and_length() {
        let f = |t: &str| eval_struct(t, None, None).map(|r| r.1);
        assert_eq!(f("poly.points[1].x + pt.y"), Ok(Cell::Float(5.0)));
        assert_eq!(f("polys[1].points[0].frame == 'b'"), Ok(Cell::Bool(true)));
        assert_eq!(f("poly.points.length"), Ok(Cell::Int(2)));
        // AS2FM: the length of a struct is that of its first field.
        assert_eq!(f("poly.length"), Ok(Cell::Int(2)));
        assert_eq!(f("polys[0].length"), Ok(Cell::Int(0)));
        assert!(f("pt.length").unwrap_err().contains("no `length`"));
        // `a.f` over an array of structs: every element's field.
        assert_eq!(
            f("poly.points.y"),
            Ok(Cell::list(vec![Cell::Float(2.0), Cell::Float(4.0)]))
        );
        assert_eq!(f("polys.points"), {
            let (vals, _, _) = eval_struct("1", None, None).unwrap();
            let Cell::List(ps) = &vals[2] else { panic!() };
            Ok(Cell::list(
                ps.iter()
                    .map(|p| match p {
                        Cell::List(fs) => fs[0].clone(),
                        _ => panic!(),
                    })
                    .collect(),
            ))
        });
        assert!(f("poly.points[2].x").unwrap_err().contains("out of bounds"));
    }

    #[test]
    fn struct_places() {
        // A whole struct into an array element, growing the array.
        let (vals, _, mut st) = eval_struct("pt", None, Some("poly.points[2]")).unwrap();
        let Cell::List(fields) = &vals[1] else {
            panic!()
        };
        assert!(
            matches!(&fields[0], Cell::List(ps) if ps.len() == 3 && ps[2] == point(&mut st, "a", 1.0, 2.0))
        );
        // One field of every element: the array takes the value's length.
        let (vals, _, mut st) = eval_struct("[7, 8, 9]", None, Some("poly.points.x")).unwrap();
        assert_eq!(
            vals[1],
            Cell::list(vec![Cell::list(vec![
                point(&mut st, "a", 7.0, 2.0),
                point(&mut st, "b", 8.0, 4.0),
                point(&mut st, "", 9.0, 0.0),
            ])])
        );
        let (vals, _, _) = eval_struct("[]", None, Some("polys[1].points.frame")).unwrap();
        assert_eq!(
            vals[2],
            Cell::list(vec![
                Cell::list(vec![Cell::list(vec![])]),
                Cell::list(vec![Cell::list(vec![])]),
            ])
        );
        assert!(
            eval_struct("[[], [], [], [], []]", None, Some("polys.points"))
                .unwrap_err()
                .contains("at most 4")
        );
        assert!(eval_struct("1", None, Some("poly.points.x[0]"))
            .unwrap_err()
            .contains("write `a[i].f`"));
        assert!(eval_struct("1", None, Some("pt.x.y"))
            .unwrap_err()
            .contains("has no field `y`"));
    }
}
