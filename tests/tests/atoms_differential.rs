//! Randomised atom expressions: codegen reads them as written, and interpreter and table compute them as the semantics say.
//!
//! Random typed expressions over int, float, string and boolean variables
//! (every operator, int/float mixes, extreme literals) are printed fully
//! parenthesised and compiled as the single atom of `property p = {expr};`.
//! For each:
//! - codegen's checked AST must have exactly the generated tree's shape (the
//!   checker may only insert int-to-float conversions), so parsing, precedence
//!   and literal reading are checked;
//! - on random valuations (NaN, infinities, `-0.0`, `i64::MIN`/`MAX`, strings
//!   that are and are not constants) the interpreter and the postcard table
//!   must give the verdict that the tests' tree-walking evaluator gives on the
//!   checked AST (`hindsight_tests::checked`), and an arithmetic error exactly
//!   where it finds overflow or division by zero;
//! - an atom with an integer `/` or `%` by the literal 0 must be refused by the
//!   checker (it would fail at every point), and only such an atom.
//!
//! `HINDSIGHT_ATOMS` sets the number of expressions (default 3000),
//! `HINDSIGHT_ATOMS_SEED` the seed.

use codegen::ast::{BinaryOp, Expr, ExprKind, UnaryOp};
use hindsight_tests::checked::{self, AtomError};
use hindsight_tests::engines;
use hindsight_tests::gen::{self, Gen};
use hindsight_tests::trace::{self, Val};
use monitor_core::{StepError, Value};

const DECLS: &str = "state i: int = 0; state j: i32 = 0; state x: float = 0.0; \
                     state y: f32 = 0.0; state s: string = \"a\"; state t: string = \"b\"; \
                     state b: bool = false; event e;";

/// The generated tree, kept to compare with codegen's reading.
#[derive(Clone, Debug)]
enum E {
    /// A literal: its text and its value.
    Lit(String, Value),
    /// A string literal (its text).
    Str(String),
    /// Variable `k` of [`DECLS`].
    Var(u16),
    /// `!a` or `-a`.
    Un(UnaryOp, Box<E>),
    /// `a op b`.
    Bin(BinaryOp, Box<E>, Box<E>),
}

#[derive(Clone, Copy, PartialEq, Eq, Debug)]
enum T {
    Bool,
    Int,
    Float,
    Str,
}

fn pick<T: Clone>(rng: &mut Gen, items: &[T]) -> T {
    items[gen::range(rng, 0, items.len() as u64 - 1) as usize].clone()
}

const INT_LITS: &[i64] = &[0, 1, 2, 3, 7, 100, 3_037_000_500, i64::MAX];
const FLOAT_LITS: &[&str] = &["0.0", "0.5", "2.5", "3.0", "1e3", "1e-3", "1.5e2", "0.1"];

/// A random expression of type `ty` (numbers: `Int` or `Float` as drawn) and its type.
fn expr(rng: &mut Gen, ty: T, depth: u32) -> (E, T) {
    let leaf = depth == 0 || gen::chance(rng, 0.3);
    match ty {
        T::Bool if leaf => match gen::range(rng, 0, 3) {
            0 => (E::Var(6), T::Bool),
            1 => (E::Var(7), T::Bool),
            2 => (E::Lit("true".into(), Value::Bool(true)), T::Bool),
            _ => (E::Lit("false".into(), Value::Bool(false)), T::Bool),
        },
        T::Bool => {
            let e = match gen::range(rng, 0, 6) {
                0 => E::Un(UnaryOp::Not, Box::new(expr(rng, T::Bool, depth - 1).0)),
                1 | 2 => {
                    let op = pick(rng, &[BinaryOp::And, BinaryOp::Or]);
                    let a = expr(rng, T::Bool, depth - 1).0;
                    E::Bin(op, Box::new(a), Box::new(expr(rng, T::Bool, depth - 1).0))
                }
                3 | 4 => {
                    use monitor_core::CmpOp::*;
                    let op = pick(rng, &[Eq, Ne, Lt, Le, Gt, Ge]);
                    let a = expr(rng, T::Int, depth - 1).0;
                    let b = expr(rng, T::Int, depth - 1).0;
                    E::Bin(BinaryOp::Cmp(op), Box::new(a), Box::new(b))
                }
                5 => {
                    use monitor_core::CmpOp::*;
                    let op = pick(rng, &[Eq, Ne]);
                    let a = expr(rng, T::Str, 0).0;
                    let b = expr(rng, T::Str, 0).0;
                    E::Bin(BinaryOp::Cmp(op), Box::new(a), Box::new(b))
                }
                _ => {
                    use monitor_core::CmpOp::*;
                    let op = pick(rng, &[Eq, Ne]);
                    let a = expr(rng, T::Bool, depth - 1).0;
                    let b = expr(rng, T::Bool, depth - 1).0;
                    E::Bin(BinaryOp::Cmp(op), Box::new(a), Box::new(b))
                }
            };
            (e, T::Bool)
        }
        T::Str => match gen::range(rng, 0, 3) {
            0 => (E::Var(4), T::Str),
            1 => (E::Var(5), T::Str),
            _ => (E::Str(pick(rng, &["a", "b", "c"]).to_string()), T::Str),
        },
        // Numbers: either type may come out; mixes are the checker's business.
        T::Int | T::Float if leaf => match gen::range(rng, 0, 5) {
            0 => (E::Var(0), T::Int),
            1 => (E::Var(1), T::Int),
            2 => (E::Var(2), T::Float),
            3 => (E::Var(3), T::Float),
            4 => {
                let n = pick(rng, INT_LITS);
                (E::Lit(n.to_string(), Value::Int(n)), T::Int)
            }
            _ => {
                let s = pick(rng, FLOAT_LITS);
                let v = s.parse::<f64>().expect("a float literal");
                (E::Lit(s.to_string(), Value::Float(v)), T::Float)
            }
        },
        T::Int | T::Float => {
            if gen::chance(rng, 0.15) {
                let (a, t) = expr(rng, T::Int, depth - 1);
                return (E::Un(UnaryOp::Neg, Box::new(a)), t);
            }
            let op = pick(
                rng,
                &[
                    BinaryOp::Add,
                    BinaryOp::Sub,
                    BinaryOp::Mul,
                    BinaryOp::Div,
                    BinaryOp::Rem,
                ],
            );
            let (a, ta) = expr(rng, T::Int, depth - 1);
            let (b, tb) = expr(rng, T::Int, depth - 1);
            let t = if ta == T::Float || tb == T::Float {
                T::Float
            } else {
                T::Int
            };
            (E::Bin(op, Box::new(a), Box::new(b)), t)
        }
    }
}

const NAMES: [&str; 8] = ["i", "j", "x", "y", "s", "t", "b", "e"];

/// Fully parenthesised text.
fn print(e: &E) -> String {
    match e {
        E::Lit(text, _) => text.clone(),
        E::Str(s) => format!("\"{s}\""),
        E::Var(k) => NAMES[*k as usize].to_string(),
        E::Un(UnaryOp::Not, a) => format!("(!{})", print(a)),
        E::Un(UnaryOp::Neg, a) => format!("(-{})", print(a)),
        E::Bin(op, a, b) => format!("({} {} {})", print(a), op.symbol(), print(b)),
    }
}

/// Whether codegen's checked expression is `mine`, up to inserted int-to-float conversions.
fn same_tree(mine: &E, theirs: &Expr, strings: &[String]) -> bool {
    if let ExprKind::ToFloat(inner) = &theirs.kind {
        return same_tree(mine, inner, strings);
    }
    match (mine, &theirs.kind) {
        (E::Lit(_, Value::Float(a)), ExprKind::Const(Value::Float(b))) => {
            a.to_bits() == b.to_bits()
        }
        (E::Lit(_, a), ExprKind::Const(b)) => a == b,
        (E::Str(s), ExprKind::Const(Value::Str(id))) => strings.get(*id as usize) == Some(s),
        (E::Var(a), ExprKind::Var(b)) => a == b,
        (E::Un(a, x), ExprKind::Unary(b, y)) => a == b && same_tree(x, y, strings),
        (E::Bin(a, x1, x2), ExprKind::Binary(b, y1, y2)) => {
            a == b && same_tree(x1, y1, strings) && same_tree(x2, y2, strings)
        }
        _ => false,
    }
}

const INTS: &[i64] = &[
    0,
    1,
    -1,
    2,
    3,
    -7,
    100,
    3_037_000_500,
    i64::MAX,
    i64::MIN,
    i64::MIN + 1,
];
const I32S: &[i64] = &[0, 1, -1, 2, 5, -3, i32::MAX as i64, i32::MIN as i64];
const FLOATS: &[f64] = &[
    0.0,
    -0.0,
    0.5,
    -2.5,
    3.0,
    0.1,
    1e300,
    f64::NAN,
    f64::INFINITY,
    f64::NEG_INFINITY,
];

/// One random valuation of [`DECLS`], in declaration order.
fn valuation(rng: &mut Gen) -> Vec<Val> {
    let small = |rng: &mut Gen| gen::range(rng, 0, 20) as i128 - 10;
    let int = |rng: &mut Gen, set: &[i64]| {
        if gen::chance(rng, 0.5) {
            Val::Int(small(rng))
        } else {
            Val::Int(pick(rng, set) as i128)
        }
    };
    let float = |rng: &mut Gen| {
        if gen::chance(rng, 0.5) {
            Val::Float(small(rng) as f64 / 2.0)
        } else {
            Val::Float(pick(rng, FLOATS))
        }
    };
    let string = |rng: &mut Gen| Val::Str(pick(rng, &["a", "b", "c", "zz", ""]).to_string());
    vec![
        int(rng, INTS),
        int(rng, I32S),
        float(rng),
        float(rng),
        string(rng),
        string(rng),
        Val::Bool(gen::chance(rng, 0.5)),
        Val::Bool(gen::chance(rng, 0.5)),
    ]
}

fn env_count(name: &str, default: u64) -> u64 {
    std::env::var(name).map_or(default, |v| {
        v.trim()
            .parse()
            .unwrap_or_else(|_| panic!("{name}={v:?} is not a number"))
    })
}

/// The type of a numeric expression, as the checker gives it: a mix is a float.
fn num_ty(e: &E) -> T {
    match e {
        E::Lit(_, Value::Float(_)) | E::Var(2 | 3) => T::Float,
        E::Un(_, a) => num_ty(a),
        E::Bin(_, a, b) if num_ty(a) == T::Float || num_ty(b) == T::Float => T::Float,
        _ => T::Int,
    }
}

/// Whether `e` holds an integer `/` or `%` whose divisor is the literal 0: both
/// operands of every operator are always evaluated, so such an atom fails at every
/// point and the checker refuses it.
fn divides_by_literal_zero(e: &E) -> bool {
    match e {
        E::Lit(..) | E::Str(_) | E::Var(_) => false,
        E::Un(_, a) => divides_by_literal_zero(a),
        E::Bin(op, a, b) => {
            (matches!(op, BinaryOp::Div | BinaryOp::Rem)
                && matches!(**b, E::Lit(_, Value::Int(0)))
                && num_ty(a) == T::Int)
                || divides_by_literal_zero(a)
                || divides_by_literal_zero(b)
        }
    }
}

/// Checks one expression on `points` valuations; `Err` is a report. `Ok(false)`:
/// refused by the checker, as it must be ([`divides_by_literal_zero`]).
fn check_one(e: &E, rng: &mut Gen, points: usize, tally: &mut [usize; 3]) -> Result<bool, String> {
    let text = print(e);
    let src = format!("{DECLS}\nproperty p = {{{text}}};\n");
    let result = codegen::compile_spec(&src, "atom.hspec");
    if divides_by_literal_zero(e) {
        return match result {
            Err(d)
                if d.to_string()
                    .contains("by 0: the atom would fail at every point") =>
            {
                Ok(false)
            }
            Err(d) => Err(format!(
                "codegen rejected {{{text}}} for another reason:\n{d}"
            )),
            Ok(_) => Err(format!(
                "codegen accepted {{{text}}}, an integer division by a literal 0"
            )),
        };
    }
    let compiled = result.map_err(|d| format!("codegen rejected {{{text}}}:\n{d}"))?;
    let spec = compiled.checked();
    let (_, atoms) = checked::to_oracle(&spec.properties[0].formula);
    let [atom] = atoms.as_slice() else {
        return Err(format!("{{{text}}} has {} atoms", atoms.len()));
    };
    if !same_tree(e, atom, &spec.strings) {
        return Err(format!(
            "codegen read {{{text}}} as {{{}}}",
            codegen::print::expr(atom, spec)
        ));
    }
    let decls = trace::parse_decls(DECLS).map_err(|e| e.to_string())?;
    let by_decl: Vec<Vec<Val>> = (0..points).map(|_| valuation(rng)).collect();
    let values = engines::values(&compiled, &decls, &by_decl)?;
    let order = engines::var_order(&compiled, &decls)?;
    // Every point at time 0: each is judged on its own (an error changes nothing).
    let times = vec![0; points];
    let interpreter = engines::run_interpreter(compiled.program(), &times, &values)
        .map_err(|e| format!("{e:?}"))?;
    let table = engines::run_table(&compiled.to_table_bytes(), &times, &values)
        .map_err(|e| format!("{e:?}"))?;
    for (k, vals) in by_decl.iter().enumerate() {
        let ordered: Vec<Val> = order.iter().map(|&d| vals[d].clone()).collect();
        let want = match checked::eval_atom(atom, spec, &ordered) {
            Ok(b) => {
                tally[b as usize] += 1;
                Ok(vec![b])
            }
            Err(AtomError::Arithmetic(_)) => {
                tally[2] += 1;
                Err(StepError::Arithmetic { atom: 0 })
            }
            Err(e) => return Err(format!("{{{text}}}: {e}")),
        };
        for (engine, got) in [("interpreter", &interpreter[k]), ("table", &table[k])] {
            if *got != want {
                let named: Vec<String> = NAMES
                    .iter()
                    .zip(vals)
                    .map(|(n, v)| format!("{n}={v:?}"))
                    .collect();
                return Err(format!(
                    "{{{text}}} with {}: {engine} says {got:?}, the evaluator {want:?}",
                    named.join(" ")
                ));
            }
        }
    }
    Ok(true)
}

#[test]
fn random_atoms_are_read_and_computed_as_written() {
    let count = env_count("HINDSIGHT_ATOMS", 3000);
    let seed = env_count("HINDSIGHT_ATOMS_SEED", 77);
    let mut rng = gen::rng(seed);
    let mut failures = Vec::new();
    // Verdicts false, true, and arithmetic errors seen.
    let mut tally = [0usize; 3];
    let mut refused = 0;
    for _ in 0..count {
        let depth = gen::range(&mut rng, 1, 4) as u32;
        let (e, _) = expr(&mut rng, T::Bool, depth);
        match check_one(&e, &mut rng, 20, &mut tally) {
            Ok(judged) => refused += !judged as usize,
            Err(report) => failures.push(report),
        }
    }
    assert!(
        failures.is_empty(),
        "{} of {count} expressions disagree (seed {seed}); first ones:\n{}",
        failures.len(),
        failures
            .iter()
            .take(8)
            .cloned()
            .collect::<Vec<_>>()
            .join("\n")
    );
    assert!(
        tally.iter().all(|&n| n * 500 > tally.iter().sum::<usize>()),
        "false/true/error verdicts too uneven: {tally:?}"
    );
    // Few atoms divide by a literal 0 (4 of the default 3000): each was checked above.
    assert!(refused * 4 < count as usize, "{refused} of {count} refused");
}
