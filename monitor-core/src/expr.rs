//! The atom stack machine: type-checked once on load, then evaluated with a fixed stack.

use crate::analysis::Arithmetic;
use crate::error::StepError;
use crate::program::{CmpOp, Instr, NumTy, Ty, Value, Var};

/// Deepest stack an atom may use; deeper expressions are rejected by the compiler.
pub const MAX_STACK: usize = 32;

// [`check`] keeps its stack of types in a `u64`, two bits a type.
const _: () = assert!(MAX_STACK * 2 <= 64);

/// Type-checks one atom's bytecode against the variable types: when it
/// never underflows, never exceeds [`MAX_STACK`], types every operand and leaves
/// exactly one boolean, what it computes ([`enabled`] says whether this build
/// does), else `None`.
pub(crate) fn check(code: &[Instr], vars: &[Var<'_>]) -> Option<Arithmetic> {
    // The stack of types, two bits a type with the top in the low bits
    // ([`MAX_STACK`] of them fill a `u64`): no array to clear (a `memset`
    // call in firmware) and no bounds to check.
    let mut stack = 0u64;
    let mut sp = 0usize;
    let mut needs = Arithmetic::default();
    if code.is_empty() {
        return None;
    }
    for ins in code {
        // How many operands it pops, all of type `arg`, and what it pushes.
        let num = |n| match n {
            NumTy::Int => Ty::Int,
            NumTy::Float => Ty::Float,
        };
        let (pops, arg, push) = match *ins {
            Instr::Push(v) => (0, Ty::Bool, v.ty()),
            Instr::Load(n) => match vars.get(n as usize) {
                Some(v) => (0, Ty::Bool, v.ty),
                None => return None,
            },
            Instr::Not => (1, Ty::Bool, Ty::Bool),
            Instr::And | Instr::Or => (2, Ty::Bool, Ty::Bool),
            Instr::Neg(n) => (1, num(n), num(n)),
            Instr::Add(n) | Instr::Sub(n) | Instr::Mul(n) | Instr::Div(n) | Instr::Rem(n) => {
                (2, num(n), num(n))
            }
            Instr::Cmp(op, ty) => {
                let ordered = matches!(op, CmpOp::Lt | CmpOp::Le | CmpOp::Gt | CmpOp::Ge);
                if ordered && matches!(ty, Ty::Bool | Ty::Str) {
                    return None;
                }
                (2, ty, Ty::Bool)
            }
            Instr::ToFloat => (1, Ty::Int, Ty::Float),
        };
        // A float pushed or popped; `analysis::arithmetic`'s rules.
        needs.float |= push == Ty::Float || (pops > 0 && arg == Ty::Float);
        needs.int_div |= matches!(ins, Instr::Div(NumTy::Int) | Instr::Rem(NumTy::Int));
        if sp < pops {
            return None;
        }
        for _ in 0..pops {
            if stack & 3 != arg as u64 {
                return None;
            }
            stack >>= 2;
        }
        sp -= pops;
        if sp >= MAX_STACK {
            return None;
        }
        stack = stack << 2 | push as u64;
        sp += 1;
    }
    (sp == 1 && stack == Ty::Bool as u64).then_some(needs)
}

/// Whether this build evaluates code that computes `needs` ([`check`]):
/// without feature `float` no instruction may touch a float (load, push,
/// compute or compare one), without feature `int-div` none may divide
/// integers. Checked on load, so that the step never meets what the build
/// left out.
pub(crate) fn enabled(needs: Arithmetic) -> bool {
    (cfg!(feature = "float") || !needs.float) && (cfg!(feature = "int-div") || !needs.int_div)
}

/// Evaluates a checked atom over `vals`. Errors on a value of the wrong type
/// (the caller's input) or on integer overflow / division by zero.
///
/// The shapes most atoms have (a boolean variable, its negation, a variable
/// compared with a constant or with another variable) are matched on the code
/// itself and computed without the stack machine; any surprise (a value of
/// another type) falls through to the general machine, so errors are the same.
#[inline]
pub(crate) fn eval(code: &[Instr], vals: &[Value], atom: u16) -> Result<bool, StepError> {
    // The common shapes without the stack; `compact` (firmware) keeps only the stack.
    match *code {
        _ if cfg!(feature = "compact") => {}
        [Instr::Load(n)] => {
            if let Some(Value::Bool(b)) = vals.get(n as usize) {
                return Ok(*b);
            }
        }
        [Instr::Load(n), Instr::Not] => {
            if let Some(Value::Bool(b)) = vals.get(n as usize) {
                return Ok(!*b);
            }
        }
        [Instr::Load(n), Instr::Push(c), Instr::Cmp(op, _)] => {
            if let Some(r) = vals.get(n as usize).and_then(|v| compare(op, *v, c)) {
                return Ok(r);
            }
        }
        [Instr::Push(c), Instr::Load(n), Instr::Cmp(op, _)] => {
            if let Some(r) = vals.get(n as usize).and_then(|v| compare(op, c, *v)) {
                return Ok(r);
            }
        }
        [Instr::Load(m), Instr::Load(n), Instr::Cmp(op, _)] => {
            if let (Some(a), Some(b)) = (vals.get(m as usize), vals.get(n as usize)) {
                if let Some(r) = compare(op, *a, *b) {
                    return Ok(r);
                }
            }
        }
        _ => {}
    }
    #[cfg(feature = "compact")]
    {
        eval_words(code, vals, atom)
    }
    // The stack never holds more values than the code has instructions: a short
    // atom gets a short stack to clear.
    #[cfg(not(feature = "compact"))]
    if code.len() <= 8 {
        eval_stack::<8>(code, vals, atom)
    } else {
        eval_stack::<MAX_STACK>(code, vals, atom)
    }
}

/// A value as one word of the `compact` machine: its payload without its
/// variant (a `bool` 0 or 1, an `i64` or `f64`'s bits, a string id).
#[cfg(feature = "compact")]
#[inline(always)]
fn word(v: Value) -> u64 {
    match v {
        Value::Bool(b) => b as u64,
        Value::Int(i) => i as u64,
        Value::Float(f) => f.to_bits(),
        Value::Str(s) => s as u64,
    }
}

/// The `compact` atom machine: a stack of words, not of [`Value`]s (8 bytes
/// a slot instead of 16, stored with one instruction, no variant to match).
/// [`check`] typed every instruction's operands on load and the step checks
/// every variable's value against its declared type before any atom, so the
/// instructions' own types ([`NumTy`], the `Ty` of `Cmp`) say what each word
/// holds: the results and errors of checked code over checked values are
/// [`eval_stack`]'s.
#[cfg(feature = "compact")]
fn eval_words(code: &[Instr], vals: &[Value], atom: u16) -> Result<bool, StepError> {
    let mut stack = [0u64; MAX_STACK];
    let mut sp = 0usize;
    let arith = StepError::Arithmetic { atom };
    for ins in code {
        // Checked programs never underflow or overflow; the guards only keep this panic-free.
        let pops = match *ins {
            Instr::Push(_) | Instr::Load(_) => 0,
            Instr::Not | Instr::Neg(_) | Instr::ToFloat => 1,
            _ => 2,
        };
        let Some(base) = sp.checked_sub(pops) else {
            return Err(arith);
        };
        let a = stack.get(base).copied().unwrap_or(0);
        let b = stack.get(sp.wrapping_sub(1)).copied().unwrap_or(0);
        // A pushed or loaded value, converted at one place.
        let operand = match ins {
            Instr::Push(v) => Some(v),
            Instr::Load(n) => match vals.get(*n as usize) {
                Some(v) => Some(v),
                None => return Err(StepError::VarType { var: *n }),
            },
            _ => None,
        };
        let v = match *ins {
            _ if operand.is_some() => operand.map_or(0, |v| word(*v)),
            Instr::Not => a ^ 1,
            Instr::And => a & b,
            Instr::Or => a | b,
            Instr::Neg(NumTy::Int) => (a as i64).checked_neg().ok_or(arith)? as u64,
            Instr::Add(NumTy::Int) => (a as i64).checked_add(b as i64).ok_or(arith)? as u64,
            Instr::Sub(NumTy::Int) => (a as i64).checked_sub(b as i64).ok_or(arith)? as u64,
            Instr::Mul(NumTy::Int) => (a as i64).checked_mul(b as i64).ok_or(arith)? as u64,
            #[cfg(feature = "int-div")]
            Instr::Div(NumTy::Int) => (a as i64).checked_div(b as i64).ok_or(arith)? as u64,
            #[cfg(feature = "int-div")]
            Instr::Rem(NumTy::Int) => (a as i64).checked_rem(b as i64).ok_or(arith)? as u64,
            // One comparison of orderings for every type: integers signed,
            // booleans and string ids as words (equal words are equal values).
            Instr::Cmp(op, ty) => {
                let ord = match ty {
                    Ty::Int => Some((a as i64).cmp(&(b as i64))),
                    #[cfg(feature = "float")]
                    Ty::Float => f64::from_bits(a).partial_cmp(&f64::from_bits(b)),
                    _ => Some(a.cmp(&b)),
                };
                cmp(op, ord) as u64
            }
            #[cfg(feature = "float")]
            Instr::Neg(NumTy::Float) => (-f64::from_bits(a)).to_bits(),
            #[cfg(feature = "float")]
            Instr::ToFloat => (a as i64 as f64).to_bits(),
            #[cfg(feature = "float")]
            Instr::Add(NumTy::Float)
            | Instr::Sub(NumTy::Float)
            | Instr::Mul(NumTy::Float)
            | Instr::Div(NumTy::Float)
            | Instr::Rem(NumTy::Float) => {
                let (x, y) = (f64::from_bits(a), f64::from_bits(b));
                match *ins {
                    Instr::Add(_) => x + y,
                    Instr::Sub(_) => x - y,
                    Instr::Mul(_) => x * y,
                    Instr::Div(_) => x / y,
                    _ => x % y,
                }
                .to_bits()
            }
            // What this build leaves out (`enabled` rejected it on load).
            #[allow(unreachable_patterns)]
            _ => return Err(arith),
        };
        let Some(slot) = stack.get_mut(base) else {
            return Err(arith);
        };
        *slot = v;
        sp = base + 1;
    }
    match (sp, stack.first()) {
        (1, Some(&b)) => Ok(b != 0),
        _ => Err(arith),
    }
}

/// The general stack machine, with room for `D` values.
#[cfg(any(test, not(feature = "compact")))]
fn eval_stack<const D: usize>(
    code: &[Instr],
    vals: &[Value],
    atom: u16,
) -> Result<bool, StepError> {
    let mut stack = [Value::Bool(false); D];
    let mut sp = 0usize;
    let arith = StepError::Arithmetic { atom };
    for ins in code {
        // Checked programs never underflow or overflow; the guards only keep this panic-free.
        let v = match *ins {
            Instr::Push(v) => v,
            Instr::Load(n) => match vals.get(n as usize) {
                Some(v) => *v,
                None => return Err(StepError::VarType { var: n }),
            },
            Instr::Not | Instr::Neg(_) | Instr::ToFloat => {
                let Some(&a) = sp.checked_sub(1).and_then(|i| stack.get(i)) else {
                    return Err(arith);
                };
                sp -= 1;
                match (*ins, a) {
                    (Instr::Not, Value::Bool(a)) => Value::Bool(!a),
                    (Instr::Neg(_), Value::Int(a)) => Value::Int(a.checked_neg().ok_or(arith)?),
                    #[cfg(feature = "float")]
                    (Instr::Neg(_), Value::Float(a)) => Value::Float(-a),
                    #[cfg(feature = "float")]
                    (Instr::ToFloat, Value::Int(a)) => Value::Float(a as f64),
                    _ => return Err(arith),
                }
            }
            _ => {
                let (Some(&a), Some(&b)) = (
                    sp.checked_sub(2).and_then(|i| stack.get(i)),
                    sp.checked_sub(1).and_then(|i| stack.get(i)),
                ) else {
                    return Err(arith);
                };
                sp -= 2;
                binary(*ins, a, b).ok_or(arith)?
            }
        };
        let Some(slot) = stack.get_mut(sp) else {
            return Err(arith);
        };
        *slot = v;
        sp += 1;
    }
    match (sp, stack.first()) {
        (1, Some(Value::Bool(b))) => Ok(*b),
        _ => Err(arith),
    }
}

#[cfg(any(test, not(feature = "compact")))]
fn binary(ins: Instr, a: Value, b: Value) -> Option<Value> {
    #[cfg(feature = "float")]
    use Value::Float;
    use Value::{Bool, Int};
    Some(match (ins, a, b) {
        (Instr::And, Bool(a), Bool(b)) => Bool(a && b),
        (Instr::Or, Bool(a), Bool(b)) => Bool(a || b),
        (Instr::Add(_), Int(a), Int(b)) => Int(a.checked_add(b)?),
        (Instr::Sub(_), Int(a), Int(b)) => Int(a.checked_sub(b)?),
        (Instr::Mul(_), Int(a), Int(b)) => Int(a.checked_mul(b)?),
        #[cfg(feature = "int-div")]
        (Instr::Div(_), Int(a), Int(b)) => Int(a.checked_div(b)?),
        #[cfg(feature = "int-div")]
        (Instr::Rem(_), Int(a), Int(b)) => Int(a.checked_rem(b)?),
        #[cfg(feature = "float")]
        (Instr::Add(_), Float(a), Float(b)) => Float(a + b),
        #[cfg(feature = "float")]
        (Instr::Sub(_), Float(a), Float(b)) => Float(a - b),
        #[cfg(feature = "float")]
        (Instr::Mul(_), Float(a), Float(b)) => Float(a * b),
        #[cfg(feature = "float")]
        (Instr::Div(_), Float(a), Float(b)) => Float(a / b),
        #[cfg(feature = "float")]
        (Instr::Rem(_), Float(a), Float(b)) => Float(a % b),
        (Instr::Cmp(op, _), a, b) => Bool(compare(op, a, b)?),
        _ => return None,
    })
}

/// `a op b` for two values of the same type; `None` for mixed types.
#[inline(always)]
fn compare(op: CmpOp, a: Value, b: Value) -> Option<bool> {
    #[cfg(feature = "float")]
    use Value::Float;
    use Value::{Bool, Int, Str};
    Some(match (a, b) {
        (Int(a), Int(b)) => int_cmp(op, a, b),
        #[cfg(feature = "float")]
        (Float(a), Float(b)) => cmp(op, a.partial_cmp(&b)),
        (Bool(a), Bool(b)) => cmp(op, Some(a.cmp(&b))),
        (Str(a), Str(b)) => cmp(op, Some(a.cmp(&b))),
        _ => return None,
    })
}

/// Integer comparison straight to a flag (the common atom `x op constant`).
#[inline(always)]
fn int_cmp(op: CmpOp, a: i64, b: i64) -> bool {
    match op {
        CmpOp::Eq => a == b,
        CmpOp::Ne => a != b,
        CmpOp::Lt => a < b,
        CmpOp::Le => a <= b,
        CmpOp::Gt => a > b,
        CmpOp::Ge => a >= b,
    }
}

fn cmp(op: CmpOp, ord: Option<core::cmp::Ordering>) -> bool {
    use core::cmp::Ordering::{Equal, Greater, Less};
    match (op, ord) {
        // NaN: every comparison false except `!=`.
        (CmpOp::Ne, None) => true,
        (_, None) => false,
        (CmpOp::Eq, Some(o)) => o == Equal,
        (CmpOp::Ne, Some(o)) => o != Equal,
        (CmpOp::Lt, Some(o)) => o == Less,
        (CmpOp::Le, Some(o)) => o != Greater,
        (CmpOp::Gt, Some(o)) => o == Greater,
        (CmpOp::Ge, Some(o)) => o != Less,
    }
}

#[cfg(all(test, feature = "compact"))]
mod tests {
    extern crate std;
    use std::{vec, vec::Vec};

    use super::{eval_stack, eval_words, MAX_STACK};
    use crate::program::{CmpOp, Instr, NumTy, Ty, Value};

    const CMPS: [CmpOp; 6] = [
        CmpOp::Eq,
        CmpOp::Ne,
        CmpOp::Lt,
        CmpOp::Le,
        CmpOp::Gt,
        CmpOp::Ge,
    ];

    /// The word machine gives the value machine's result (verdict or error)
    /// on checked code over every instruction, at the extremes of each type.
    #[test]
    fn the_word_machine_agrees_with_the_value_machine() {
        let mut codes: Vec<Vec<Instr>> = Vec::new();
        let ints = [0i64, 1, -1, 7, -3, i64::MAX, i64::MIN];
        let mut int_ops = vec![
            Instr::Add(NumTy::Int),
            Instr::Sub(NumTy::Int),
            Instr::Mul(NumTy::Int),
        ];
        if cfg!(feature = "int-div") {
            int_ops.extend([Instr::Div(NumTy::Int), Instr::Rem(NumTy::Int)]);
        }
        for &a in &ints {
            for &b in &ints {
                for &op in &int_ops {
                    for &c in &CMPS {
                        codes.push(vec![
                            Instr::Push(Value::Int(a)),
                            Instr::Load(0),
                            op,
                            Instr::Push(Value::Int(b)),
                            Instr::Cmp(c, Ty::Int),
                        ]);
                    }
                }
                for &c in &CMPS {
                    codes.push(vec![
                        Instr::Push(Value::Int(a)),
                        Instr::Neg(NumTy::Int),
                        Instr::Push(Value::Int(b)),
                        Instr::Cmp(c, Ty::Int),
                    ]);
                }
            }
        }
        for a in [false, true] {
            for b in [false, true] {
                for op in [Instr::And, Instr::Or] {
                    codes.push(vec![
                        Instr::Push(Value::Bool(a)),
                        Instr::Push(Value::Bool(b)),
                        op,
                        Instr::Not,
                    ]);
                }
                for c in [CmpOp::Eq, CmpOp::Ne] {
                    codes.push(vec![
                        Instr::Push(Value::Bool(a)),
                        Instr::Push(Value::Bool(b)),
                        Instr::Cmp(c, Ty::Bool),
                    ]);
                    codes.push(vec![
                        Instr::Push(Value::Str(a as u32)),
                        Instr::Push(Value::Str(b as u32 + 7)),
                        Instr::Cmp(c, Ty::Str),
                    ]);
                }
            }
        }
        if cfg!(feature = "float") {
            let floats = [0.0, -0.0, 1.5, -2.25, f64::NAN, f64::INFINITY, f64::MAX];
            let ops = [
                Instr::Add(NumTy::Float),
                Instr::Sub(NumTy::Float),
                Instr::Mul(NumTy::Float),
                Instr::Div(NumTy::Float),
                Instr::Rem(NumTy::Float),
            ];
            for &a in &floats {
                for &b in &floats {
                    for &op in &ops {
                        for &c in &CMPS {
                            codes.push(vec![
                                Instr::Push(Value::Float(a)),
                                Instr::Push(Value::Float(b)),
                                op,
                                Instr::Neg(NumTy::Float),
                                Instr::Load(0),
                                Instr::ToFloat,
                                Instr::Cmp(c, Ty::Float),
                            ]);
                        }
                    }
                }
            }
        }
        for x in [0i64, 5, -5, i64::MIN] {
            let vals = [Value::Int(x)];
            for code in &codes {
                assert_eq!(
                    eval_words(code, &vals, 3),
                    eval_stack::<MAX_STACK>(code, &vals, 3),
                    "{code:?} over {x}"
                );
            }
        }
    }
}

#[cfg(test)]
mod check_tests {
    use super::check;
    use crate::analysis::{instr_arithmetic, Arithmetic};
    use crate::program::{CmpOp, Instr, NumTy, Ty, Value, Var, VarKind};

    /// What [`check`] says a checked atom computes is what the analysis of
    /// its instructions says.
    #[test]
    fn check_finds_the_arithmetic_the_analysis_finds() {
        let var = |ty, init| Var {
            name: "v",
            ty,
            kind: VarKind::State,
            init,
        };
        let vars = [
            var(Ty::Int, Value::Int(0)),
            var(Ty::Float, Value::Float(0.0)),
        ];
        let (i, f) = (Instr::Push(Value::Int(2)), Instr::Push(Value::Float(2.0)));
        let cmp_i = Instr::Cmp(CmpOp::Lt, Ty::Int);
        let cmp_f = Instr::Cmp(CmpOp::Lt, Ty::Float);
        let codes: [&[Instr]; 12] = [
            &[Instr::Load(0), i, cmp_i],
            &[Instr::Load(1), f, cmp_f],
            &[Instr::Load(0), Instr::ToFloat, f, cmp_f],
            &[i, Instr::Neg(NumTy::Int), i, cmp_i],
            &[f, Instr::Neg(NumTy::Float), f, cmp_f],
            &[i, i, Instr::Div(NumTy::Int), i, cmp_i],
            &[i, i, Instr::Rem(NumTy::Int), i, cmp_i],
            &[f, f, Instr::Div(NumTy::Float), f, cmp_f],
            &[f, f, Instr::Add(NumTy::Float), f, cmp_f],
            &[i, i, Instr::Mul(NumTy::Int), i, cmp_i],
            &[Instr::Push(Value::Bool(true)), Instr::Not],
            &[
                Instr::Push(Value::Str(1)),
                Instr::Push(Value::Str(2)),
                Instr::Cmp(CmpOp::Eq, Ty::Str),
            ],
        ];
        for code in codes {
            let want = code.iter().map(|ins| instr_arithmetic(ins, &vars)).fold(
                Arithmetic::default(),
                |a, b| Arithmetic {
                    float: a.float || b.float,
                    int_div: a.int_div || b.int_div,
                },
            );
            assert_eq!(check(code, &vars), Some(want), "{code:?}");
        }
    }
}
