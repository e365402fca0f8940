//! The SCXML expression language: an ECMAScript subset, parsed with nom and compiled once to closures.
//!
//! `hindsight-expr` is the first crate of hindsight's off-line pipeline: it depends on no
//! other crate of the project (only `nom` and `rand_core`), and the simulator (`hindsight`'s
//! `sim`) compiles every `cond`, `expr` and `location` of a model with it.
//!
//! # Public API
//!
//! - [`parse_expr`] (text to [`ast::Expr`], or a [`ParseError`] at a byte offset;
//!   nesting is limited to [`MAX_NESTING`]).
//! - [`compile::compile`] / [`compile::compile_as`] (an expression, a [`compile::Scope`]
//!   of typed variables and the current event, to [`compile::Typed`] code) and
//!   [`compile::compile_place`] (an assignment location); evaluation errors are
//!   [`compile::EvalError`] values, never panics.
//! - The values: [`Ty`] (static types), [`TypeTable`] (structs and enumeration labels),
//!   [`Strings`] / [`StrId`] (interned strings), [`value::Cell`] (run-time storage),
//!   [`Value`] / [`ListRef`] (borrowed views of it) and [`OwnedValue`].
//!
//! ```
//! use hindsight_expr::compile::{compile, Code, Env, EventScope, Scope};
//! use hindsight_expr::value::Cell;
//! use hindsight_expr::{parse_expr, Strings, Ty, TypeTable};
//! use rand_core::SeedableRng;
//! use rand_xoshiro::Xoshiro256PlusPlus;
//!
//! // A datamodel of one integer variable, `x`, in slot 0.
//! let vars = [("x".to_string(), Ty::Int)];
//! let types = TypeTable::default();
//! let scope = Scope { vars: &vars, event: EventScope::None, types: &types, abs: &|at| at };
//! let mut strings = Strings::default();
//!
//! let ast = parse_expr("x * 2 + 1").unwrap();
//! let typed = compile(&ast, &scope, &mut strings, None).unwrap();
//! assert_eq!(typed.ty, Ty::Int);
//!
//! // Evaluating reads the slots; no name lookup, no allocation.
//! let mut rng = Xoshiro256PlusPlus::seed_from_u64(7); // for `Math.random()`
//! let event = strings.intern("");
//! let slots = [Cell::Int(20)];
//! let mut env = Env {
//!     vars: &slots, params: &[], event, origin: event, rng: &mut rng, strings: &strings,
//! };
//! let Code::Int(f) = typed.code else { unreachable!() };
//! assert_eq!(f(&mut env), Ok(41));
//!
//! // Errors carry the byte offset of the offending text.
//! let err = parse_expr("x = 1").unwrap_err();
//! assert_eq!(err.offset, 2);
//! ```
//!
//! # Pipeline
//!
//! 1. [`parse_expr`] turns text into an [`ast::Expr`] (every node keeps its
//!    byte range, so errors point at the exact column of the attribute).
//! 2. The simulator's compiler type-checks each expression against its
//!    machine's datamodel and the triggering event's parameters, and compiles
//!    it into a tree of typed closures over variable slots: no name lookup,
//!    no allocation when evaluated.
//!
//! # The language
//!
//! Literals: integers (`42`, `0x2A`), floats (`1.5`, `.5`, `1e3`), `true`,
//! `false`, strings (`'a'`, `"a"`), arrays (`[1, 2]`, `[[], [1]]`, a trailing comma
//! allowed), object literals (`{x: 1.0, 'frame': 'map'}`) of declared struct types. Names:
//! datamodel variables, enumeration labels (`types.xml`), `_event.name`,
//! `_event.origin`, `_event.data.<param>`. Postfix: `a[i]`, `s.field`,
//! `a.length`. Operators: `+ - * / %`, `== != === !== < <= > >=`,
//! `&& || !`, the bitwise `& | ^ ~` (ECMAScript's precedence: `|` loosest, then `^`,
//! then `&`, all looser than `==`), unary `-`/`+`, `c ? a : b`. Calls: `Math.random()`,
//! `Math.floor/ceil/round/trunc` (to int), `Math.abs/sign/min/max` (int when
//! all arguments are), `Math.sqrt/sin/cos/tan/asin/acos/atan/exp/log/log2/
//! log10/cbrt/atan2/pow/hypot`, constants `Math.PI`, `Math.E`.
//!
//! Typing (static, checked at load time): every integer width is `i64`
//! (arithmetic wraps), `float32`/`float64` are `f64`; int mixes with float by
//! widening; `/` always gives a float (as in ECMAScript); `%` of two ints is an
//! int (by zero: a run-time error). A float is never silently narrowed to an
//! int (use `Math.floor`). The bitwise operators take integers only and compute on
//! the 64-bit two's complement (for values within 32 bits, ECMAScript's `ToInt32`
//! result; a float operand is a type error where ECMAScript would truncate it). Strings compare with `==`/`!=` only; there is no
//! string concatenation, so every string is a model literal (interned).
//! Writing `a[i]` with `i == a.length` appends; past the end fills with
//! default values; reading past the end is a run-time error.
//!
//! Structs (declared in `types.xml` or a robot model's data declarations) are
//! values: `s.f`, `a[i].f.g[j]` read and write fields, a whole struct is
//! copied by assignment and sent as one event parameter. An object literal
//! takes the struct type expected where it is used (a typed `<data>`, the
//! location it is assigned to, a typed parameter, an array element) and must
//! give every field exactly once; an unknown, missing or ill-typed field is a
//! compile error at its position. Two AS2FM conventions, which come from its
//! translation flattening a struct into one array per leaf field, are kept so
//! that models written for it mean the same here: for an array of structs
//! `a`, `a.f` is the array of the elements' `f` (writing it sets `f` of every
//! element, giving `a` the length of the value, new elements default), and
//! `s.length` of a struct whose first field is (through nested first fields)
//! an array is that array's length.

// `pub` only where another crate can reach it: internals are `pub(crate)` (issue 27).
#![warn(unreachable_pub)]

pub mod ast;
pub mod compile;
mod parse;
pub mod value;

pub use compile::Entropy;
pub use parse::{is_reserved, parse_expr, ParseError, MAX_NESTING};
pub use value::{ListRef, OwnedValue, StrId, Strings, StructDef, Ty, TypeTable, Value};
