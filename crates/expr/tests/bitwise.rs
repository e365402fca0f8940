//! The bitwise operators `& | ^ ~` of the expression language: precedence, typing and
//! values, through the public API (parse, compile, evaluate).

use hindsight_expr::compile::{compile, Code, Env, EventScope, Scope};
use hindsight_expr::value::Cell;
use hindsight_expr::{parse_expr, Strings, Ty, TypeTable};
use rand_core::SeedableRng;
use rand_xoshiro::Xoshiro256PlusPlus;

/// `text` over `i` = 6 (int), `j` = -3 (int), `f` = 2.5 (float), `b` = true: the integer
/// value, or the error (with its byte offset).
fn int(text: &str) -> Result<i64, String> {
    let vars = [
        ("i".to_string(), Ty::Int),
        ("j".to_string(), Ty::Int),
        ("f".to_string(), Ty::Float),
        ("b".to_string(), Ty::Bool),
    ];
    let types = TypeTable::default();
    let scope = Scope {
        vars: &vars,
        event: EventScope::None,
        types: &types,
        abs: &|at| at,
    };
    let mut strings = Strings::default();
    let ast = parse_expr(text).map_err(|e| format!("{}@{}", e.message, e.offset))?;
    let typed =
        compile(&ast, &scope, &mut strings, None).map_err(|e| format!("{}@{}", e.msg, e.at))?;
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(1);
    let event = strings.intern("");
    let slots = [
        Cell::Int(6),
        Cell::Int(-3),
        Cell::Float(2.5),
        Cell::Bool(true),
    ];
    let mut env = Env {
        vars: &slots,
        params: &[],
        event,
        origin: event,
        rng: &mut rng,
        strings: &strings,
    };
    match typed.code {
        Code::Int(f) => f(&mut env).map_err(|e| e.message()),
        Code::Bool(f) => f(&mut env).map(i64::from).map_err(|e| e.message()),
        _ => Err(format!("not an integer: {:?}", typed.ty)),
    }
}

#[test]
fn values_are_two_s_complement() {
    assert_eq!(int("i & 3"), Ok(2));
    assert_eq!(int("i | 3"), Ok(7));
    assert_eq!(int("i ^ 3"), Ok(5));
    assert_eq!(int("~i"), Ok(-7));
    assert_eq!(int("~~i"), Ok(6));
    assert_eq!(int("j & 7"), Ok(5));
    assert_eq!(int("j | 0"), Ok(-3));
    assert_eq!(int("~0"), Ok(-1));
    // 64 bits wide: beyond ECMAScript's 32 (where the two agree).
    assert_eq!(int("0x100000000 | 1"), Ok(0x1_0000_0001));
    assert_eq!(int("~9223372036854775807"), Ok(i64::MIN));
    assert_eq!(int("Math.trunc(f) & 3"), Ok(2));
}

#[test]
fn precedence_as_in_ecmascript() {
    // `&` binds tighter than `^`, `^` than `|`; all looser than `==` and than `+`.
    assert_eq!(int("1 | 2 & 4"), Ok(1));
    assert_eq!(int("1 | 1 ^ 1"), Ok(1));
    assert_eq!(int("6 & 3 | 8"), Ok(10));
    assert_eq!(int("1 + 2 & 3"), Ok(3));
    assert_eq!(int("1 & 2 + 3"), Ok(1));
    assert_eq!(int("(i & 1) == 0 && (i | 1) == 7 ? 1 : 0"), Ok(1));
    assert_eq!(
        int("i & 2 == 2"),
        Err("operator `&` cannot be applied to int and bool@0".into())
    );
    assert_eq!(
        int("i|j||b"),
        Err("operator `||` cannot be applied to int and bool@0".into())
    );
}

#[test]
fn bitwise_operators_take_integers_only() {
    for (t, at, needle) in [
        ("f & 1", 0, "cannot be applied to float and int"),
        ("b | 1", 0, "cannot be applied to bool and int"),
        ("1 ^ 2.0", 0, "cannot be applied to int and float"),
        ("~f", 0, "`~` needs an integer, found float"),
        ("~b", 0, "`~` needs an integer, found bool"),
        ("i &", 3, "unexpected end"),
    ] {
        let err = int(t).unwrap_err();
        assert!(err.contains(needle), "{t}: {err}");
        assert!(err.ends_with(&format!("@{at}")), "{t}: {err}");
    }
}
