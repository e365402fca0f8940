//! Unit tests of the expression compiler: typing, evaluation, places, struct literals.

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
    let t = compile(&e, &scope, &mut strings, None).map_err(|e| format!("{}@{}", e.msg, e.at))?;
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
    assert!(eval("i % 0").unwrap_err().contains("by zero"));
    // Functions outside `Math` are named in the refusal; `In()` says why.
    assert!(eval("parseInt(s)")
        .unwrap_err()
        .starts_with("`parseInt()` is not supported"));
    assert!(eval("In('a')")
        .unwrap_err()
        .contains("one active state at a time"));
    // An integer result outside 64 bits is an error, not a wrapped value: neither
    // ECMAScript (doubles) nor arithmetic gives a negative sum of positive numbers.
    for text in [
        "9223372036854775807 + 1",
        "-9223372036854775807 - i",
        "4611686018427387904 * 2",
        "-(-9223372036854775807 - 1)",
        "Math.abs(-9223372036854775807 - 1)",
        "9223372036854775807 + i - i",
    ] {
        assert_eq!(
            eval(text),
            Err("integer overflow: the result is outside the 64-bit range".into()),
            "{text}"
        );
    }
    assert_eq!(eval("-9223372036854775807 - 1"), Ok(Cell::Int(i64::MIN)));
    assert_eq!(eval("(-9223372036854775807 - 1) % -1"), Ok(Cell::Int(0)));
    // A float without an integer value has no floor: a cast made NaN 0 and 1e300 the
    // largest integer.
    assert_eq!(
        eval("Math.floor(f / 0 - f / 0)"),
        Err("NaN has no 64-bit integer value".into())
    );
    assert_eq!(
        eval("Math.trunc(1e300)"),
        Err("1e300 has no 64-bit integer value".into())
    );
    assert_eq!(
        eval("Math.ceil(-f / 0)").unwrap_err(),
        "-inf has no 64-bit integer value"
    );
    assert_eq!(
        eval("Math.floor(-9223372036854775808.0)"),
        Ok(Cell::Int(i64::MIN))
    );
    assert_eq!(
        eval("Math.floor(9223372036854775808.0)").unwrap_err(),
        "9.223372036854776e18 has no 64-bit integer value"
    );
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
    assert!(compile_place(&parse_expr("_event.data.p").unwrap(), &scope, &mut strings).is_err());
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
    let (_, out, mut st) = eval_struct("{'frame': 'w', y: 2, x: -1}", Some("Point"), None).unwrap();
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

/// `compile_cell` of `text` into `target`, evaluated in the scope of [`eval`].
fn eval_cell(text: &str, target: &Ty) -> Result<Cell, String> {
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
    let f = compile_cell(&e, &scope, &mut strings, target, "x")
        .map_err(|e| format!("{}@{}", e.msg, e.at))?;
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
    let mut out = Cell::list(vec![Cell::Int(9)]);
    f(&mut env, &mut out).map_err(|e| e.message())?;
    Ok(out)
}

#[test]
fn fused_leaf_comparisons_agree_with_the_operators() {
    // i = 7, p (`_event.data.p`) = 40, b = true, s = "hi": every leaf shape, every operator.
    let t = Ok(Cell::Bool(true));
    let f = Ok(Cell::Bool(false));
    for (text, want) in [
        ("i == 7", &t),
        ("i != 7", &f),
        ("i < 8", &t),
        ("i <= 6", &f),
        ("i > -1", &t),
        ("i >= 8", &f),
        ("7 == i", &t),
        ("_event.data.p == 40", &t),
        ("_event.data.p < 40", &f),
        ("i == _event.data.p", &f),
        ("_event.data.p > i", &t),
        ("i == i", &t),
        ("i < i", &f),
        ("3 < 4", &t),
        ("b == true", &t),
        ("b != b", &f),
        ("s == 'hi'", &t),
        ("s != 'hi'", &f),
        ("'ho' == s", &f),
        ("(_event.data.p == 40) && (i == 0)", &f),
        ("(_event.data.p == 40) && (i == 7)", &t),
    ] {
        assert_eq!(&eval(text), want, "{text}");
    }
    // Strings and booleans stay unordered.
    assert!(eval("s < 'hi'").is_err());
    assert!(eval("b < true").is_err());
}

#[test]
fn cells_written_from_leaves_and_other_code() {
    assert_eq!(eval_cell("3", &Ty::Int), Ok(Cell::Int(3)));
    assert_eq!(eval_cell("-3", &Ty::Float), Ok(Cell::Float(-3.0)));
    assert_eq!(eval_cell("i", &Ty::Float), Ok(Cell::Float(7.0)));
    assert_eq!(eval_cell("_event.data.p", &Ty::Int), Ok(Cell::Int(40)));
    assert_eq!(eval_cell("b", &Ty::Bool), Ok(Cell::Bool(true)));
    assert_eq!(eval_cell("false", &Ty::Bool), Ok(Cell::Bool(false)));
    let mut strings = Strings::default();
    let _ = cells(&mut strings);
    let hi = strings.lookup("hi").unwrap_or_default();
    assert_eq!(eval_cell("s", &Ty::Str), Ok(Cell::Str(hi)));
    // Not leaves: the general code.
    assert_eq!(eval_cell("i + 1", &Ty::Int), Ok(Cell::Int(8)));
    assert_eq!(eval_cell("f", &Ty::Float), Ok(Cell::Float(2.5)));
    assert_eq!(
        eval_cell("a", &Ty::Array(Box::new(Ty::Int), None)),
        Ok(Cell::list(vec![Cell::Int(1), Cell::Int(2), Cell::Int(3)]))
    );
    assert!(eval_cell("f", &Ty::Int).is_err());
}

#[test]
fn fused_leaf_arithmetic_and_negation_agree_with_the_operators() {
    // i = 7, p (`_event.data.p`) = 40, b = true.
    for (text, want) in [
        ("i + 1", 8),
        ("1 + i", 8),
        ("i - 10", -3),
        ("i * _event.data.p", 280),
        ("_event.data.p % i", 5),
        ("i % -4", 3),
        ("-7 % i", 0),
        ("i + i", 14),
        ("(i + 1) * 2", 16),
        ("9223372036854775800 + i", i64::MAX),
    ] {
        assert_eq!(eval(text), Ok(Cell::Int(want)), "{text}");
    }
    // The fused forms overflow as the operators do.
    for text in [
        "9223372036854775807 + i",
        "i * 4611686018427387904",
        "-9223372036854775807 - i",
    ] {
        assert!(eval(text).unwrap_err().contains("overflow"), "{text}");
    }
    // A remainder by zero is reported at the divisor, as the unfused code reports it.
    let zero = "i % 0";
    let e = parse_expr(zero).unwrap();
    let vs = vars();
    let types = TypeTable::default();
    let scope = Scope {
        vars: &vs,
        event: EventScope::None,
        types: &types,
        abs: &|k| k + 100,
    };
    let mut strings = Strings::default();
    let Code::Int(f) = compile(&e, &scope, &mut strings, None).unwrap().code else {
        panic!("an int")
    };
    let vals = cells(&mut strings);
    let mut rng = Fixed(0);
    let mut env = Env {
        vars: &vals,
        params: &[],
        event: StrId(0),
        origin: StrId(0),
        rng: &mut rng,
        strings: &strings,
    };
    assert_eq!(
        f(&mut env),
        Err(EvalError {
            at: 104,
            kind: EvalErrorKind::DivByZero
        })
    );
    // A cell that does not hold its static type is an internal error at the leaf (a
    // fused read takes only the variant of the leaf's type, as the leaf's closure did).
    let wrong = [Cell::Bool(true)];
    let mut env = Env {
        vars: &wrong,
        params: &[],
        event: StrId(0),
        origin: StrId(0),
        rng: &mut rng,
        strings: &strings,
    };
    assert_eq!(
        f(&mut env),
        Err(EvalError {
            at: 100,
            kind: EvalErrorKind::Internal
        })
    );
    assert_eq!(eval("!b"), Ok(Cell::Bool(false)));
    assert_eq!(eval("!(b)"), Ok(Cell::Bool(false)));
    assert_eq!(eval("!!b"), Ok(Cell::Bool(true)));
    assert_eq!(eval("!(i == 7)"), Ok(Cell::Bool(false)));
    assert_eq!(eval("!false"), Ok(Cell::Bool(true)));
    assert_eq!(eval_cell("true", &Ty::Bool), Ok(Cell::Bool(true)));
    assert_eq!(eval_cell("7", &Ty::Float), Ok(Cell::Float(7.0)));
}
