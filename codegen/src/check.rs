//! The checker: resolves names, types atoms, converts bounds to ticks; syntax in, [`CheckedSpec`] out.

use std::collections::HashMap;

use monitor_core::{CmpOp, Ty, Value, VarKind, MAX_IDS};

use crate::ast::{
    self, BinaryOp, CheckedSpec, ExprKind, FormulaKind, Interval, PropertyDef, UnaryOp, VarDecl,
};
use crate::diag::{Sink, SourceMap, Span};
use crate::syntax::{self, Bound, InfixOp, PrefixOp, SpecSyntax, TimeLit, TimeUnit};

/// Nanoseconds in the default time unit (one second).
pub(crate) const DEFAULT_TICK_NS: u64 = 1_000_000_000;

const RESERVED: &[&str] = &["true", "false", "and", "or", "not"];

/// The name of a type in messages.
pub(crate) fn ty_name(ty: Ty) -> &'static str {
    match ty {
        Ty::Bool => "bool",
        Ty::Int => "int",
        Ty::Float => "float",
        Ty::Str => "string",
    }
}

fn lit_text(t: &TimeLit) -> String {
    let unit = t.unit.map_or("", TimeUnit::suffix);
    if t.frac.is_empty() {
        format!("{}{unit}", t.int)
    } else {
        format!("{}.{}{unit}", t.int, t.frac)
    }
}

/// `value * unit_ns`, exactly, as `(numerator, scale)`: the duration is `numerator / scale` ns.
fn scaled_ns(t: &TimeLit, unit_ns: u64) -> Option<(u128, u128)> {
    crate::duration::scaled_decimal(&t.int, &t.frac, unit_ns)
}

/// Why a bound end is not a tick count, or a `unit` statement's literal not a time
/// unit; each quotes the literal as written and displays as the checker's message.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) enum TimeLitError {
    /// A bound without a unit that has a fraction (`2.5`).
    FractionalTicks(String),
    /// A bound past `u64::MAX` ticks.
    TooManyTicks(String),
    /// A bound with a unit that is not a whole number of ticks of `tick_ns`.
    NotWholeTicks(String, u64),
    /// A `unit` statement without a suffix.
    UnitWithoutSuffix(String),
    /// A `unit` statement past `u64::MAX` nanoseconds.
    UnitTooLarge(String),
    /// A `unit` statement finer than a nanosecond.
    UnitFinerThanNanosecond(String),
    /// A `unit` statement of zero.
    ZeroUnit,
}

impl std::fmt::Display for TimeLitError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            TimeLitError::FractionalTicks(text) => write!(
                f,
                "`{text}` is not a whole number of ticks; write an integer or give a unit (like `{text}s`)"
            ),
            TimeLitError::TooManyTicks(text) => {
                write!(f, "`{text}` is too large for a 64-bit tick count")
            }
            TimeLitError::NotWholeTicks(text, tick_ns) => write!(
                f,
                "`{text}` is not a whole number of ticks (the time unit is {})",
                crate::duration::format(*tick_ns)
            ),
            TimeLitError::UnitWithoutSuffix(text) => write!(
                f,
                "the time unit needs a unit suffix, like `{text}ms` or `{text}s`"
            ),
            TimeLitError::UnitTooLarge(text) => write!(f, "time unit `{text}` is too large"),
            TimeLitError::UnitFinerThanNanosecond(text) => write!(
                f,
                "time unit `{text}` is not a whole number of nanoseconds"
            ),
            TimeLitError::ZeroUnit => f.write_str("the time unit must be longer than zero"),
        }
    }
}

/// Converts a bound end to ticks of `tick_ns` exactly.
pub(crate) fn lit_ticks(t: &TimeLit, tick_ns: u64) -> Result<u64, TimeLitError> {
    let text = lit_text(t);
    let Some(unit) = t.unit else {
        if !t.frac.is_empty() {
            return Err(TimeLitError::FractionalTicks(text));
        }
        return t
            .int
            .parse::<u64>()
            .map_err(|_| TimeLitError::TooManyTicks(text));
    };
    let too_large = || TimeLitError::TooManyTicks(text.clone());
    let (ns_scaled, scale) = scaled_ns(t, unit.nanos()).ok_or_else(too_large)?;
    let denom = scale.checked_mul(tick_ns as u128).ok_or_else(too_large)?;
    if denom == 0 || ns_scaled % denom != 0 {
        return Err(TimeLitError::NotWholeTicks(text, tick_ns));
    }
    u64::try_from(ns_scaled / denom).map_err(|_| too_large())
}

/// The length in ns of a `unit` statement's literal.
fn unit_ns(t: &TimeLit) -> Result<u64, TimeLitError> {
    let text = lit_text(t);
    let Some(unit) = t.unit else {
        return Err(TimeLitError::UnitWithoutSuffix(text));
    };
    let (ns_scaled, scale) =
        scaled_ns(t, unit.nanos()).ok_or_else(|| TimeLitError::UnitTooLarge(text.clone()))?;
    if ns_scaled % scale != 0 {
        return Err(TimeLitError::UnitFinerThanNanosecond(text));
    }
    match u64::try_from(ns_scaled / scale) {
        Ok(0) => Err(TimeLitError::ZeroUnit),
        Ok(ns) => Ok(ns),
        Err(_) => Err(TimeLitError::UnitTooLarge(text)),
    }
}

/// Resolves a declared type name to its run-time type and, for integers, its range.
fn resolve_type(name: &str) -> Option<(Ty, Option<(i128, i128)>)> {
    use crate::scalar::{Scalar, ScalarKind};
    match name {
        "int" => Some((Ty::Int, Some((i64::MIN.into(), i64::MAX.into())))),
        "float" => Some((Ty::Float, None)),
        _ => {
            let scalar = Scalar::from_spec_name(name)?;
            let ty = match scalar.kind() {
                ScalarKind::Bool => Ty::Bool,
                ScalarKind::Float => Ty::Float,
                ScalarKind::Str => Ty::Str,
                ScalarKind::Int => Ty::Int,
            };
            // Stored as i64: the upper half of u64 is out of reach.
            let range = scalar
                .int_range()
                .map(|(lo, hi)| (lo, hi.min(i64::MAX.into())));
            Some((ty, range))
        }
    }
}

struct Checker<'a> {
    sink: &'a mut Sink,
    sources: &'a SourceMap,
    tick_ns: u64,
    untimed: bool,
    vars: Vec<VarDecl>,
    var_ids: HashMap<String, u16>,
    strings: Vec<String>,
    string_ids: HashMap<String, u32>,
}

/// Checks a parsed spec; errors and warnings go to `sink`. The result is only
/// meaningful when `sink` has no errors.
pub(crate) fn check(syn: &SpecSyntax, sources: &SourceMap, sink: &mut Sink) -> CheckedSpec {
    let mut ck = Checker {
        sink,
        sources,
        tick_ns: DEFAULT_TICK_NS,
        untimed: syn.untimed,
        vars: Vec::new(),
        var_ids: HashMap::new(),
        strings: Vec::new(),
        string_ids: HashMap::new(),
    };
    for (k, u) in syn.units.iter().enumerate() {
        if k > 0 {
            ck.sink.error(u.span, "the time unit is already set");
            continue;
        }
        match unit_ns(u) {
            Ok(ns) => ck.tick_ns = ns,
            Err(m) => ck.sink.error(u.span, m.to_string()),
        }
    }
    for d in &syn.decls {
        ck.decl(d);
    }
    let mut props = Vec::new();
    let mut prop_ids: HashMap<&str, Span> = HashMap::new();
    for p in &syn.props {
        if let Some(first) = prop_ids.get(p.name.name.as_str()) {
            let at = ck.at(*first);
            ck.sink.error(
                p.name.span,
                format!("property `{}` is defined twice (first {at})", p.name.name),
            );
        } else {
            prop_ids.insert(&p.name.name, p.name.span);
        }
        if let Some(f) = ck.formula(&p.formula) {
            props.push(PropertyDef {
                name: p.name.name.clone(),
                formula: f,
                span: p.span,
            });
        }
    }
    CheckedSpec {
        tick_ns: ck.tick_ns,
        vars: ck.vars,
        strings: ck.strings,
        properties: props,
    }
}

impl Checker<'_> {
    /// `at FILE:LINE:COL` for messages that point at a second place.
    fn at(&self, span: Span) -> String {
        let l = self.sources.locate(span);
        format!("at {}:{}:{}", l.file, l.line, l.col)
    }

    fn intern(&mut self, s: &str) -> u32 {
        if let Some(&i) = self.string_ids.get(s) {
            return i;
        }
        let i = self.strings.len() as u32;
        self.strings.push(s.to_string());
        self.string_ids.insert(s.to_string(), i);
        i
    }

    fn decl(&mut self, d: &syntax::Decl) {
        let name = &d.name.name;
        if RESERVED.contains(&name.as_str()) {
            self.sink.error(
                d.name.span,
                format!("`{name}` is a reserved word and cannot name a variable"),
            );
            return;
        }
        if let Some(&first) = self.var_ids.get(name) {
            let at = self.at(self.vars[first as usize].span);
            self.sink.error(
                d.name.span,
                format!("variable `{name}` is declared twice (first {at})"),
            );
            return;
        }
        if self.vars.len() >= MAX_IDS {
            self.sink
                .error(d.name.span, format!("more than {MAX_IDS} variables"));
            return;
        }
        let (ty, type_name, init) = match d.kind {
            VarKind::Event => (Ty::Bool, "bool".to_string(), Some(Value::Bool(false))),
            VarKind::State => {
                let Some(tn) = &d.ty else { return };
                let Some((ty, range)) = resolve_type(&tn.name) else {
                    self.sink.error(
                        tn.span,
                        format!(
                            "unknown type `{}` (use bool, int, i8..i64, u8..u64, float, f32, f64 or string)",
                            tn.name
                        ),
                    );
                    return;
                };
                let init = match &d.init {
                    None => Some(match ty {
                        Ty::Bool => Value::Bool(false),
                        Ty::Int => Value::Int(0),
                        Ty::Float => Value::Float(0.0),
                        Ty::Str => Value::Str(self.intern("")),
                    }),
                    Some(e) => self.init_value(e, ty, &tn.name, range),
                };
                (ty, tn.name.clone(), init)
            }
        };
        // Declare even with a bad initial value, so that uses do not cascade into "unknown variable".
        let id = self.vars.len() as u16;
        self.var_ids.insert(name.clone(), id);
        self.vars.push(VarDecl {
            name: name.clone(),
            ty,
            kind: d.kind,
            init: init.unwrap_or(Value::Bool(false)),
            type_name,
            span: d.span,
        });
    }

    fn init_value(
        &mut self,
        e: &syntax::Expr,
        ty: Ty,
        type_name: &str,
        range: Option<(i128, i128)>,
    ) -> Option<Value> {
        use syntax::ExprKind as K;
        let (neg, inner) = match &e.kind {
            K::Unary(UnaryOp::Neg, a) => (true, &a.kind),
            k => (false, k),
        };
        let v = match (ty, inner) {
            (Ty::Bool, K::Bool(b)) if !neg => Value::Bool(*b),
            (Ty::Str, K::Str(s)) if !neg => Value::Str(self.intern(s)),
            (Ty::Float, K::Float(x)) => Value::Float(if neg { -*x } else { *x }),
            (Ty::Float, K::Int(n)) => Value::Float(if neg { -(*n as f64) } else { *n as f64 }),
            (Ty::Int, K::Int(n)) => {
                let v = if neg { -(*n as i128) } else { *n as i128 };
                let (lo, hi) = range.unwrap_or((i64::MIN as i128, i64::MAX as i128));
                if v < lo || v > hi {
                    self.sink.error(
                        e.span,
                        format!("initial value {v} does not fit in {type_name} ({lo}..={hi})"),
                    );
                    return None;
                }
                Value::Int(v as i64)
            }
            _ => {
                self.sink.error(
                    e.span,
                    format!(
                        "the initial value must be a {} literal (the variable is {type_name})",
                        ty_name(ty)
                    ),
                );
                return None;
            }
        };
        Some(v)
    }

    fn interval(&mut self, b: &Option<Bound>) -> Option<Interval> {
        let Some(b) = b else {
            return Some(Interval::ALWAYS);
        };
        let mut end = |t: &Option<TimeLit>| -> Option<Option<u64>> {
            match t {
                None => Some(None),
                Some(t) if self.untimed && t.unit.is_some() => {
                    self.sink.error(
                        t.span,
                        format!(
                            "`{}` has a unit, but the model's time steps have no known \
                             duration: write the bound in steps or give the model a time unit",
                            lit_text(t)
                        ),
                    );
                    None
                }
                Some(t) => match lit_ticks(t, self.tick_ns) {
                    Ok(v) => Some(Some(v)),
                    Err(m) => {
                        self.sink.error(t.span, m.to_string());
                        None
                    }
                },
            }
        };
        let lo = end(&b.lo);
        let hi = end(&b.hi);
        let (lo, hi) = (lo?.unwrap_or(0), hi?);
        if let Some(h) = hi {
            if lo > h {
                self.sink.error(
                    b.span,
                    format!("empty interval: the lower bound ({lo} ticks) is above the upper bound ({h} ticks)"),
                );
                return None;
            }
        }
        Some(Interval { lo, hi })
    }

    fn formula(&mut self, f: &syntax::Formula) -> Option<ast::Formula> {
        use syntax::FormulaKind as S;
        let kind = match &f.kind {
            S::Const(b) => FormulaKind::Const(*b),
            S::Atom(e) => {
                let e = self.expr(e)?;
                if e.ty != Ty::Bool {
                    self.sink.error(
                        e.span,
                        format!(
                            "an atom must be a boolean expression, but this is {}",
                            ty_name(e.ty)
                        ),
                    );
                    return None;
                }
                FormulaKind::Atom(e)
            }
            S::Prefix(op, a) => {
                let iv = match op {
                    PrefixOp::Once(b) | PrefixOp::Historically(b) => self.interval(b),
                    _ => Some(Interval::ALWAYS),
                };
                let a = Box::new(self.formula(a)?);
                let iv = iv?;
                match op {
                    PrefixOp::Not => FormulaKind::Not(a),
                    PrefixOp::Yesterday => FormulaKind::Yesterday(a),
                    PrefixOp::WeakYesterday => FormulaKind::WeakYesterday(a),
                    PrefixOp::Once(_) => FormulaKind::Once(iv, a),
                    PrefixOp::Historically(_) => FormulaKind::Historically(iv, a),
                }
            }
            S::Infix(op, a, b) => {
                let a = self.formula(a);
                let iv = match op {
                    InfixOp::Since(bd) => self.interval(bd),
                    _ => Some(Interval::ALWAYS),
                };
                let b = self.formula(b);
                let (a, b, iv) = (Box::new(a?), Box::new(b?), iv?);
                match op {
                    InfixOp::And => FormulaKind::And(a, b),
                    InfixOp::Or => FormulaKind::Or(a, b),
                    InfixOp::Implies => FormulaKind::Implies(a, b),
                    InfixOp::Iff => FormulaKind::Iff(a, b),
                    InfixOp::Since(_) => FormulaKind::Since(iv, a, b),
                }
            }
        };
        Some(ast::Formula { kind, span: f.span })
    }

    fn to_float(e: ast::Expr) -> ast::Expr {
        if e.ty == Ty::Int {
            let span = e.span;
            ast::Expr {
                kind: ExprKind::ToFloat(Box::new(e)),
                ty: Ty::Float,
                span,
            }
        } else {
            e
        }
    }

    fn expr(&mut self, e: &syntax::Expr) -> Option<ast::Expr> {
        use syntax::ExprKind as K;
        let span = e.span;
        let mk = |kind, ty| Some(ast::Expr { kind, ty, span });
        match &e.kind {
            K::Bool(b) => mk(ExprKind::Const(Value::Bool(*b)), Ty::Bool),
            K::Int(n) => match i64::try_from(*n) {
                Ok(v) => mk(ExprKind::Const(Value::Int(v)), Ty::Int),
                Err(_) => {
                    self.sink.error(
                        span,
                        format!(
                            "integer literal {n} is larger than the largest int ({})",
                            i64::MAX
                        ),
                    );
                    None
                }
            },
            K::Float(x) => mk(ExprKind::Const(Value::Float(*x)), Ty::Float),
            K::Str(s) => {
                let id = self.intern(s);
                mk(ExprKind::Const(Value::Str(id)), Ty::Str)
            }
            K::Var(name) => match self.var_ids.get(name) {
                Some(&id) => {
                    let ty = self.vars[id as usize].ty;
                    mk(ExprKind::Var(id), ty)
                }
                None => {
                    self.sink.error(span, format!("unknown variable `{name}`"));
                    None
                }
            },
            K::Unary(UnaryOp::Neg, a) if a.kind == K::Int(1u64 << 63) => {
                mk(ExprKind::Const(Value::Int(i64::MIN)), Ty::Int)
            }
            K::Unary(op, a) => {
                let a = self.expr(a)?;
                let ok = match op {
                    UnaryOp::Neg => matches!(a.ty, Ty::Int | Ty::Float),
                    UnaryOp::Not => a.ty == Ty::Bool,
                };
                if !ok {
                    let (sym, want) = match op {
                        UnaryOp::Neg => ("-", "a number"),
                        UnaryOp::Not => ("!", "a bool"),
                    };
                    self.sink.error(
                        span,
                        format!("`{sym}` needs {want}, but its operand is {}", ty_name(a.ty)),
                    );
                    return None;
                }
                let ty = a.ty;
                mk(ExprKind::Unary(*op, Box::new(a)), ty)
            }
            K::Binary(op, a, b) => {
                let a = self.expr(a);
                let b = self.expr(b);
                let (a, b) = (a?, b?);
                let numeric = |t: Ty| matches!(t, Ty::Int | Ty::Float);
                let (ta, tb, op_sym) = (a.ty, b.ty, op.symbol());
                let bad = move |this: &mut Self, what: &str| {
                    this.sink.error(
                        span,
                        format!(
                            "`{op_sym}` {what}, but its operands are {} and {}",
                            ty_name(ta),
                            ty_name(tb)
                        ),
                    );
                    None
                };
                match op {
                    BinaryOp::And | BinaryOp::Or => {
                        if a.ty != Ty::Bool || b.ty != Ty::Bool {
                            return bad(self, "needs two bools");
                        }
                        mk(ExprKind::Binary(*op, Box::new(a), Box::new(b)), Ty::Bool)
                    }
                    BinaryOp::Cmp(c) => {
                        let (a, b) = if numeric(a.ty) && numeric(b.ty) && a.ty != b.ty {
                            (Self::to_float(a), Self::to_float(b))
                        } else {
                            (a, b)
                        };
                        let ordered = matches!(c, CmpOp::Lt | CmpOp::Le | CmpOp::Gt | CmpOp::Ge);
                        if a.ty != b.ty {
                            return bad(self, "compares values of one type");
                        }
                        if ordered && !numeric(a.ty) {
                            return bad(self, "orders numbers only (bools and strings compare with `==` and `!=`)");
                        }
                        mk(ExprKind::Binary(*op, Box::new(a), Box::new(b)), Ty::Bool)
                    }
                    _ => {
                        if !numeric(a.ty) || !numeric(b.ty) {
                            return bad(self, "needs two numbers");
                        }
                        let (a, b) = if a.ty != b.ty {
                            (Self::to_float(a), Self::to_float(b))
                        } else {
                            (a, b)
                        };
                        let ty = a.ty;
                        // Both operands are always evaluated (the atom machine has no
                        // jumps): an integer `/` or `%` by a literal 0 fails at every
                        // point, so it is refused here rather than at the first step.
                        if matches!(op, BinaryOp::Div | BinaryOp::Rem)
                            && ty == Ty::Int
                            && b.kind == ExprKind::Const(Value::Int(0))
                        {
                            self.sink.error(
                                b.span,
                                format!(
                                    "integer `{op_sym}` by 0: the atom would fail at every point"
                                ),
                            );
                            return None;
                        }
                        mk(ExprKind::Binary(*op, Box::new(a), Box::new(b)), ty)
                    }
                }
            }
        }
    }
}
