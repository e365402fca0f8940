//! The SCXML expression language: an ECMAScript subset, parsed with nom and compiled once to closures.
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
//! `&& || !`, unary `-`/`+`, `c ? a : b`. Calls: `Math.random()`,
//! `Math.floor/ceil/round/trunc` (to int), `Math.abs/sign/min/max` (int when
//! all arguments are), `Math.sqrt/sin/cos/tan/asin/acos/atan/exp/log/log2/
//! log10/cbrt/atan2/pow/hypot`, constants `Math.PI`, `Math.E`.
//!
//! Typing (static, checked at load time): every integer width is `i64`
//! (arithmetic wraps), `float32`/`float64` are `f64`; int mixes with float by
//! widening; `/` always gives a float (as in ECMAScript); `%` of two ints is an
//! int (by zero: a run-time error). A float is never silently narrowed to an
//! int (use `Math.floor`). Strings compare with `==`/`!=` only; there is no
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

pub mod ast;
pub(crate) mod compile;
mod parse;
pub mod value;

pub use compile::Entropy;
pub use parse::{parse_expr, ParseError, MAX_NESTING};
pub use value::{ListRef, OwnedValue, StrId, Strings, StructDef, Ty, TypeTable, Value};
