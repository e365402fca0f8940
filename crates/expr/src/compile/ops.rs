//! Type rules and code of members, calls, operators and conditionals: the rest of `Compiler::expr`.

use super::place::project;
use super::*;

impl Compiler<'_, '_> {
    pub(super) fn member(
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
    pub(super) fn projected_field(&self, ty: &Ty, field: &str) -> Option<(u32, Ty)> {
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

    pub(super) fn call(
        &mut self,
        e: &Expr,
        callee: &Expr,
        args: &[Expr],
    ) -> Result<Typed, CompileError> {
        let at = e.start;
        let fname = match &callee.kind {
            ExprKind::Member(obj, f, _) if matches!(&obj.kind, ExprKind::Ident(n) if n == "Math") => {
                f.as_str()
            }
            ExprKind::Ident(n) if n == "In" => {
                return Err(cerr(
                    callee.start,
                    "`In()` is not supported: a machine here has one active state at a \
                     time (no nesting, no <parallel>); keep the state in a variable",
                ))
            }
            ExprKind::Ident(n) => {
                return Err(cerr(
                    callee.start,
                    format!("`{n}()` is not supported: only `Math` functions can be called"),
                ))
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
                let at = self.abs(at);
                Ok(Typed {
                    ty: Ty::Int,
                    code: Code::Int(Box::new(move |e| whole(g(x(e)?), at))),
                })
            }
            "abs" | "sign" => {
                arity(1)?;
                let a = num_args.remove(0);
                let abs = fname == "abs";
                match a.code {
                    Code::Int(f) => {
                        let int: fn(i64) -> Option<i64> = if abs {
                            i64::checked_abs
                        } else {
                            |v| Some(v.signum())
                        };
                        let at = self.abs(at);
                        Ok(Typed {
                            ty: Ty::Int,
                            code: Code::Int(Box::new(move |e| int(f(e)?).ok_or(overflow(at)))),
                        })
                    }
                    _ => {
                        let float: fn(f64) -> f64 = if abs {
                            f64::abs
                        } else {
                            // ECMAScript's sign keeps zeros and NaN as they are.
                            |v| {
                                if v == 0.0 || v.is_nan() {
                                    v
                                } else {
                                    v.signum()
                                }
                            }
                        };
                        Ok(float1(float, vec![a]))
                    }
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

    pub(super) fn unary(&mut self, at: u32, op: UnOp, x: &Expr) -> Result<Typed, CompileError> {
        let t = self.expr(x, None)?;
        // `!b` of a boolean leaf is `b == false`: one closure (see `leaf.rs`).
        if op == UnOp::Not && t.ty == Ty::Bool {
            if let Some(code) = self
                .leaf(x, &Ty::Bool)
                .and_then(|l| leaf::compare(BinOp::Eq, &Ty::Bool, l, leaf::Leaf::Const(0)))
            {
                return Ok(Typed {
                    ty: Ty::Bool,
                    code: Code::Bool(code),
                });
            }
        }
        match (op, t.code) {
            (UnOp::Not, Code::Bool(f)) => Ok(Typed {
                ty: Ty::Bool,
                code: Code::Bool(Box::new(move |e| Ok(!f(e)?))),
            }),
            (UnOp::Neg, Code::Int(f)) => {
                let at = self.abs(at);
                Ok(Typed {
                    ty: Ty::Int,
                    code: Code::Int(Box::new(move |e| f(e)?.checked_neg().ok_or(overflow(at)))),
                })
            }
            (UnOp::Neg, Code::Float(f)) => Ok(Typed {
                ty: Ty::Float,
                code: Code::Float(Box::new(move |e| Ok(-f(e)?))),
            }),
            (UnOp::Plus, code @ (Code::Int(_) | Code::Float(_))) => Ok(Typed { ty: t.ty, code }),
            // Two's complement of the 64-bit integer (ECMAScript's `~` on a value within
            // 32 bits gives the same).
            (UnOp::BitNot, Code::Int(f)) => Ok(Typed {
                ty: Ty::Int,
                code: Code::Int(Box::new(move |e| Ok(!f(e)?))),
            }),
            (UnOp::BitNot, _) => Err(cerr(
                at,
                format!(
                    "`~` needs an integer, found {} (use Math.trunc for a float)",
                    self.tname(&t.ty)
                ),
            )),
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

    pub(super) fn binary(
        &mut self,
        e: &Expr,
        op: BinOp,
        a: &Expr,
        b: &Expr,
    ) -> Result<Typed, CompileError> {
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
            // Bitwise operators take integers only (a float is never silently narrowed:
            // use Math.trunc) and work on the 64-bit two's complement, which for values
            // within 32 bits is ECMAScript's `ToInt32` result.
            BinOp::BitAnd | BinOp::BitOr | BinOp::BitXor => match (ta.code, tb.code) {
                (Code::Int(x), Code::Int(y)) => {
                    let f: IntFn = match op {
                        BinOp::BitAnd => Box::new(move |e| Ok(x(e)? & y(e)?)),
                        BinOp::BitOr => Box::new(move |e| Ok(x(e)? | y(e)?)),
                        _ => Box::new(move |e| Ok(x(e)? ^ y(e)?)),
                    };
                    Ok(Typed {
                        ty: Ty::Int,
                        code: Code::Int(f),
                    })
                }
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
                    // A remainder by zero is said at the divisor, an overflow at the
                    // expression.
                    let bat = if op == BinOp::Rem {
                        self.abs(b.start)
                    } else {
                        self.abs(at)
                    };
                    // Two leaves: one closure reads both (see `leaf.rs`).
                    if let (Some(la), Some(lb)) = (self.leaf(a, &Ty::Int), self.leaf(b, &Ty::Int)) {
                        if let Some(f) = leaf::arith(op, la, lb, bat) {
                            return Ok(Typed {
                                ty: Ty::Int,
                                code: Code::Int(f),
                            });
                        }
                    }
                    let f: IntFn = match op {
                        BinOp::Add => {
                            Box::new(move |e| x(e)?.checked_add(y(e)?).ok_or(overflow(bat)))
                        }
                        BinOp::Sub => {
                            Box::new(move |e| x(e)?.checked_sub(y(e)?).ok_or(overflow(bat)))
                        }
                        BinOp::Mul => {
                            Box::new(move |e| x(e)?.checked_mul(y(e)?).ok_or(overflow(bat)))
                        }
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
                // Two leaves (a literal, a whole variable or parameter) of one type: one
                // closure reads both (see `leaf.rs`).
                if ta.ty == tb.ty && (ta.ty == Ty::Int || !ordered) {
                    if let (Some(la), Some(lb)) = (self.leaf(a, &ta.ty), self.leaf(b, &tb.ty)) {
                        if let Some(code) = leaf::compare(op, &ta.ty, la, lb) {
                            return Ok(Typed {
                                ty: Ty::Bool,
                                code: Code::Bool(code),
                            });
                        }
                    }
                }
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

    pub(super) fn cond(
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

/// The error of an integer result outside the 64-bit range, at `at`.
#[inline]
fn overflow(at: u32) -> EvalError {
    EvalError {
        at,
        kind: EvalErrorKind::Overflow,
    }
}

/// A whole float (`Math.floor` and its kin) as an integer: NaN, the infinities and values
/// outside the 64-bit range have none (a cast would make them 0 or the nearest end).
#[inline]
fn whole(v: f64, at: u32) -> Res<i64> {
    // -2^63 is exact as a float and fits; 2^63 is the first value that does not.
    const LIMIT: f64 = 9_223_372_036_854_775_808.0;
    if (-LIMIT..LIMIT).contains(&v) {
        Ok(v as i64)
    } else {
        Err(EvalError {
            at,
            kind: EvalErrorKind::NoInteger(v.to_bits()),
        })
    }
}
