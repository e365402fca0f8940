//! Assignment locations: paths into variables that `<assign>` writes, and array projections.

use super::*;

/// `a.f` for an array of structs `a`: the array of every element's field `f`, written into
/// the destination's buffers.
pub(super) fn project(p: Path, fi: u32, ty: Ty) -> Typed {
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
pub struct Place {
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
pub fn compile_place(
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
