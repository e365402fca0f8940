// Hand-built programs for the Rust emitter's tests, shared by `include!`:
// codegen/tests/golden.rs (snapshots), tests/build.rs (emits them into OUT_DIR)
// and tests/tests/emitted_agree.rs (runs them against the interpreter).
// Include it inside a module: `mod programs { include!(".../programs.rs"); }`.
//
// Together they cover every `Op`, every `Instr`, every `Since` kind (unbounded,
// [0:b], [a:], [a:b] with small and large capacity), Y, Z, ints, floats and strings.

use monitor_core::layout;
use monitor_core::{
    Atom, CmpOp, Instr as I, Node, NumTy, Op, Program, Property, Ty, Value, Var, VarKind,
};

/// One property: its name and its nodes, children numbered from the property's first node.
pub type Prop = (&'static str, Vec<Op>);

fn leak<T>(v: Vec<T>) -> &'static [T] {
    Box::leak(v.into_boxed_slice())
}

pub fn event(name: &'static str) -> Var<'static> {
    Var {
        name,
        ty: Ty::Bool,
        kind: VarKind::Event,
        init: Value::Bool(false),
    }
}

pub fn state(name: &'static str, init: Value) -> Var<'static> {
    Var {
        name,
        ty: init.ty(),
        kind: VarKind::State,
        init,
    }
}

pub fn since(lhs: u16, rhs: u16, lo: u64, hi: Option<u64>) -> Op {
    Op::Since { lhs, rhs, lo, hi }
}

/// Lays a program out: concatenates atom code, offsets children, assigns state slots.
pub fn build(
    vars: Vec<Var<'static>>,
    strings: Vec<&'static str>,
    atoms: Vec<Vec<I>>,
    props: Vec<Prop>,
) -> Program<'static> {
    let mut instrs = Vec::new();
    let mut atom_ranges = Vec::new();
    for code in atoms {
        atom_ranges.push(Atom {
            start: instrs.len() as u16,
            len: code.len() as u16,
        });
        instrs.extend(code);
    }
    let node_count: usize = props.iter().map(|(_, ops)| ops.len()).sum();
    let mut next = layout::first_node_word(atom_ranges.len(), node_count) as u32;
    let mut nodes = Vec::new();
    let mut properties = Vec::new();
    for (name, ops) in props {
        let first = nodes.len() as u16;
        for op in ops {
            let op = match op {
                Op::Not(a) => Op::Not(a + first),
                Op::And(a, b) => Op::And(a + first, b + first),
                Op::Or(a, b) => Op::Or(a + first, b + first),
                Op::Implies(a, b) => Op::Implies(a + first, b + first),
                Op::Iff(a, b) => Op::Iff(a + first, b + first),
                Op::Yesterday(a) => Op::Yesterday(a + first),
                Op::WeakYesterday(a) => Op::WeakYesterday(a + first),
                Op::Since { lhs, rhs, lo, hi } => since(lhs + first, rhs + first, lo, hi),
                op => op,
            };
            let words = layout::node_words(&op).expect("test bounds are valid") as u32;
            let slot = if words == 0 { 0 } else { next };
            next += words;
            nodes.push(Node { op, slot });
        }
        properties.push(Property {
            name,
            first,
            root: nodes.len() as u16 - 1,
        });
    }
    Program {
        tick_ns: 1_000_000,
        vars: leak(vars),
        strings: leak(strings),
        instrs: leak(instrs),
        atoms: leak(atom_ranges),
        nodes: leak(nodes),
        props: leak(properties),
    }
}

/// No variables, atoms or strings: constants, `Y`/`Z` of constants, zero-length arrays.
pub fn minimal() -> Program<'static> {
    use Op::*;
    build(
        vec![],
        vec![],
        vec![],
        vec![
            ("always", vec![Const(true)]),
            ("after_first", vec![Const(true), Yesterday(0)]),
            ("first_only", vec![Const(false), WeakYesterday(0)]),
        ],
    )
}

/// Boolean variables: every boolean `Op` and `Instr`, `Y`, `Z`, unbounded `S`, `P`, `H`.
pub fn logic() -> Program<'static> {
    use Op::*;
    build(
        vec![
            event("go"),
            state("armed", Value::Bool(true)),
            event("stop"),
        ],
        vec![],
        vec![
            vec![I::Load(0)],
            vec![I::Load(1)],
            vec![I::Load(2)],
            // !(go && armed) || stop
            vec![I::Load(0), I::Load(1), I::And, I::Not, I::Load(2), I::Or],
            // armed == true
            vec![
                I::Load(1),
                I::Push(Value::Bool(true)),
                I::Cmp(CmpOp::Eq, Ty::Bool),
            ],
            // go != !stop
            vec![I::Load(0), I::Load(2), I::Not, I::Cmp(CmpOp::Ne, Ty::Bool)],
            // false (a constant atom, reading no variable)
            vec![I::Push(Value::Bool(false))],
        ],
        vec![
            (
                "consts",
                vec![Const(true), Const(false), Or(0, 1), And(0, 1), Iff(2, 3)],
            ),
            (
                "gates",
                vec![
                    Atom(0),
                    Atom(1),
                    Not(0),
                    And(0, 1),
                    Or(2, 3),
                    Implies(3, 4),
                    Iff(5, 0),
                    Atom(3),
                    Atom(4),
                    Atom(5),
                    Atom(6),
                    And(7, 8),
                    Or(9, 10),
                    Iff(11, 12),
                    Iff(6, 13),
                ],
            ),
            (
                "yesterdays",
                vec![
                    Atom(0),
                    Yesterday(0),
                    WeakYesterday(0),
                    Yesterday(1),
                    WeakYesterday(2),
                    Or(3, 4),
                    Iff(1, 5),
                ],
            ),
            (
                "since",
                vec![
                    Atom(1),
                    Atom(0),
                    since(0, 1, 0, None),
                    Atom(2),
                    Not(3),
                    since(4, 2, 0, None),
                ],
            ),
            // P go && H !stop, as `true S go` and `!(true S stop)`.
            (
                "once_hist",
                vec![
                    Const(true),
                    Atom(0),
                    since(0, 1, 0, None),
                    Atom(2),
                    since(0, 3, 0, None),
                    Not(4),
                    And(2, 5),
                ],
            ),
        ],
    )
}

/// Integer state: checked `+ - * / %`, negation, `i64::MIN`, every comparison,
/// and `&&`/`||` whose other side overflows (no short-circuit).
pub fn ints() -> Program<'static> {
    use Op::*;
    let int = |v| I::Push(Value::Int(v));
    build(
        vec![
            state("battery", Value::Int(100)),
            state("delta", Value::Int(-3)),
            event("tick"),
        ],
        vec![],
        vec![
            // battery <= 30
            vec![I::Load(0), int(30), I::Cmp(CmpOp::Le, Ty::Int)],
            // battery + delta > 0
            vec![
                I::Load(0),
                I::Load(1),
                I::Add(NumTy::Int),
                int(0),
                I::Cmp(CmpOp::Gt, Ty::Int),
            ],
            // battery - delta * 2 >= -10
            vec![
                I::Load(0),
                I::Load(1),
                int(2),
                I::Mul(NumTy::Int),
                I::Sub(NumTy::Int),
                int(-10),
                I::Cmp(CmpOp::Ge, Ty::Int),
            ],
            // battery / delta == 7
            vec![
                I::Load(0),
                I::Load(1),
                I::Div(NumTy::Int),
                int(7),
                I::Cmp(CmpOp::Eq, Ty::Int),
            ],
            // battery % delta != 1
            vec![
                I::Load(0),
                I::Load(1),
                I::Rem(NumTy::Int),
                int(1),
                I::Cmp(CmpOp::Ne, Ty::Int),
            ],
            // -battery < i64::MIN + 1
            vec![
                I::Load(0),
                I::Neg(NumTy::Int),
                int(i64::MIN),
                int(1),
                I::Add(NumTy::Int),
                I::Cmp(CmpOp::Lt, Ty::Int),
            ],
            // tick && battery * battery > delta
            vec![
                I::Load(2),
                I::Load(0),
                I::Load(0),
                I::Mul(NumTy::Int),
                I::Load(1),
                I::Cmp(CmpOp::Gt, Ty::Int),
                I::And,
            ],
            // !tick || -(-7 - delta) == battery
            vec![
                I::Load(2),
                I::Not,
                int(-7),
                I::Load(1),
                I::Sub(NumTy::Int),
                I::Neg(NumTy::Int),
                I::Load(0),
                I::Cmp(CmpOp::Eq, Ty::Int),
                I::Or,
            ],
        ],
        vec![
            (
                "low_recently",
                vec![Const(true), Atom(0), since(0, 1, 0, Some(10))],
            ),
            (
                "all_atoms",
                vec![
                    Atom(0),
                    Atom(1),
                    Atom(2),
                    Atom(3),
                    Atom(4),
                    Atom(5),
                    Atom(6),
                    Atom(7),
                    Iff(0, 1),
                    Iff(8, 2),
                    Iff(9, 3),
                    Iff(10, 4),
                    Iff(11, 5),
                    Iff(12, 6),
                    Iff(13, 7),
                ],
            ),
            (
                "tick_since_positive",
                vec![Atom(1), Atom(6), since(0, 1, 2, None)],
            ),
        ],
    )
}

/// Float state: IEEE arithmetic, NaN and signed zero, infinities, int-to-float.
pub fn floats() -> Program<'static> {
    use Op::*;
    let float = |v| I::Push(Value::Float(v));
    build(
        vec![
            state("speed", Value::Float(0.0)),
            state("limit", Value::Float(f64::NAN)),
            state("count", Value::Int(0)),
        ],
        vec![],
        vec![
            // speed < limit
            vec![I::Load(0), I::Load(1), I::Cmp(CmpOp::Lt, Ty::Float)],
            // speed <= -0.0
            vec![I::Load(0), float(-0.0), I::Cmp(CmpOp::Le, Ty::Float)],
            // speed * 2.5 + 1e300 > inf
            vec![
                I::Load(0),
                float(2.5),
                I::Mul(NumTy::Float),
                float(1e300),
                I::Add(NumTy::Float),
                float(f64::INFINITY),
                I::Cmp(CmpOp::Gt, Ty::Float),
            ],
            // -speed >= limit / 3.0
            vec![
                I::Load(0),
                I::Neg(NumTy::Float),
                I::Load(1),
                float(3.0),
                I::Div(NumTy::Float),
                I::Cmp(CmpOp::Ge, Ty::Float),
            ],
            // speed % -1.5 == speed
            vec![
                I::Load(0),
                float(-1.5),
                I::Rem(NumTy::Float),
                I::Load(0),
                I::Cmp(CmpOp::Eq, Ty::Float),
            ],
            // float(count) - speed != NaN
            vec![
                I::Load(2),
                I::ToFloat,
                I::Load(0),
                I::Sub(NumTy::Float),
                float(f64::NAN),
                I::Cmp(CmpOp::Ne, Ty::Float),
            ],
            // 1 / float(count) == -inf
            vec![
                float(1.0),
                I::Load(2),
                I::ToFloat,
                I::Div(NumTy::Float),
                float(f64::NEG_INFINITY),
                I::Cmp(CmpOp::Eq, Ty::Float),
            ],
            // -(-0.5) > float(count * 2) / -speed
            vec![
                float(-0.5),
                I::Neg(NumTy::Float),
                I::Load(2),
                I::Push(Value::Int(2)),
                I::Mul(NumTy::Int),
                I::ToFloat,
                I::Load(0),
                I::Neg(NumTy::Float),
                I::Div(NumTy::Float),
                I::Cmp(CmpOp::Gt, Ty::Float),
            ],
            // speed - float(count) < 2.0 (a cast before `<` must not read as generics)
            vec![
                I::Load(0),
                I::Load(2),
                I::ToFloat,
                I::Sub(NumTy::Float),
                float(2.0),
                I::Cmp(CmpOp::Lt, Ty::Float),
            ],
        ],
        vec![
            ("below_limit", vec![Atom(0)]),
            ("cast_before_less", vec![Atom(8)]),
            (
                "mixed",
                vec![
                    Atom(1),
                    Atom(2),
                    Atom(3),
                    Atom(4),
                    Atom(5),
                    Atom(6),
                    Atom(7),
                    Or(0, 1),
                    Iff(7, 2),
                    Iff(8, 3),
                    Iff(9, 4),
                    Iff(10, 5),
                    Iff(11, 6),
                    WeakYesterday(12),
                ],
            ),
            (
                "fast_then_slow",
                vec![Atom(3), Atom(1), since(0, 1, 0, Some(3))],
            ),
        ],
    )
}

/// String state compared with constants and with each other; names that need care.
pub fn strings() -> Program<'static> {
    use Op::*;
    let s = |k| I::Push(Value::Str(k));
    build(
        vec![
            state("mode", Value::Str(0)),
            state("nextMode", Value::Str(1)),
            event("door.open"),
            state("type", Value::Bool(false)),
        ],
        vec!["idle", "moving", "docked", "a b-c", ""],
        vec![
            // mode == "idle"
            vec![I::Load(0), s(0), I::Cmp(CmpOp::Eq, Ty::Str)],
            // mode != "docked"
            vec![I::Load(0), s(2), I::Cmp(CmpOp::Ne, Ty::Str)],
            // mode == nextMode
            vec![I::Load(0), I::Load(1), I::Cmp(CmpOp::Eq, Ty::Str)],
            // "a b-c" == nextMode
            vec![s(3), I::Load(1), I::Cmp(CmpOp::Eq, Ty::Str)],
            // mode == string #7 (not a declared constant)
            vec![I::Load(0), s(7), I::Cmp(CmpOp::Eq, Ty::Str)],
            // (door.open == true) != (type == false)
            vec![
                I::Load(2),
                I::Push(Value::Bool(true)),
                I::Cmp(CmpOp::Eq, Ty::Bool),
                I::Load(3),
                I::Push(Value::Bool(false)),
                I::Cmp(CmpOp::Eq, Ty::Bool),
                I::Cmp(CmpOp::Ne, Ty::Bool),
            ],
            // !(nextMode == "")
            vec![I::Load(1), s(4), I::Cmp(CmpOp::Eq, Ty::Str), I::Not],
        ],
        vec![
            (
                "idle_since_door",
                vec![Atom(0), Atom(5), since(0, 1, 0, None)],
            ),
            (
                "modes",
                vec![
                    Atom(1),
                    Atom(2),
                    Atom(3),
                    Atom(4),
                    Atom(6),
                    Implies(0, 1),
                    Or(5, 2),
                    Iff(6, 3),
                    And(7, 4),
                    Yesterday(8),
                ],
            ),
        ],
    )
}

/// Every bounded `Since`: [0:b], [a:], [a:b] (small, capacity 1001, unbounded-width), nested.
pub fn windows() -> Program<'static> {
    use Op::*;
    build(
        vec![
            event("req"),
            event("ack"),
            state("ok", Value::Bool(true)),
            state("level", Value::Int(0)),
        ],
        vec![],
        vec![
            vec![I::Load(0)],
            vec![I::Load(1)],
            vec![I::Load(2)],
            vec![
                I::Load(3),
                I::Push(Value::Int(3)),
                I::Cmp(CmpOp::Gt, Ty::Int),
            ],
        ],
        vec![
            ("upto", vec![Atom(2), Atom(0), since(0, 1, 0, Some(5))]),
            ("atleast", vec![Atom(2), Atom(0), since(0, 1, 3, None)]),
            ("window", vec![Atom(2), Atom(0), since(0, 1, 2, Some(6))]),
            ("exact", vec![Atom(2), Atom(1), since(0, 1, 1, Some(1))]),
            (
                "big",
                vec![Const(true), Atom(0), since(0, 1, 1000, Some(1000))],
            ),
            ("now", vec![Const(true), Atom(1), since(0, 1, 0, Some(0))]),
            (
                "forever",
                vec![Const(true), Atom(0), since(0, 1, 0, Some(u64::MAX))],
            ),
            (
                "far",
                vec![Atom(2), Atom(1), since(0, 1, 5, Some(u64::MAX))],
            ),
            // H[2:4] ok = !(true S[2:4] !ok)
            (
                "hist",
                vec![
                    Const(true),
                    Atom(2),
                    Not(1),
                    since(0, 2, 2, Some(4)),
                    Not(3),
                ],
            ),
            // (Y (req S[0:3] Z ack)) S[1:10] {level > 3}
            (
                "nested",
                vec![
                    Atom(0),
                    Atom(1),
                    WeakYesterday(1),
                    since(0, 2, 0, Some(3)),
                    Yesterday(3),
                    Atom(3),
                    since(4, 5, 1, Some(10)),
                ],
            ),
        ],
    )
}

/// A deterministic xorshift generator for [`random`] programs.
struct Gen(u64);

impl Gen {
    fn below(&mut self, n: u64) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0 % n
    }
}

const BOOL_VARS: [u16; 2] = [0, 1];
const INT_VARS: [u16; 2] = [2, 3];
const FLOAT_VARS: [u16; 2] = [4, 5];
const STR_VAR: u16 = 6;

/// Appends the code of a random expression of type `ty`, at most `depth` deep.
fn random_expr(g: &mut Gen, ty: Ty, depth: u32, out: &mut Vec<I>) {
    let leaf = depth == 0 || g.below(4) == 0;
    let pick = |g: &mut Gen, vars: [u16; 2]| vars[g.below(2) as usize];
    let num = |g: &mut Gen| {
        if g.below(2) == 0 {
            NumTy::Int
        } else {
            NumTy::Float
        }
    };
    match ty {
        Ty::Bool if leaf => match g.below(3) {
            0 | 1 => out.push(I::Load(pick(g, BOOL_VARS))),
            _ => out.push(I::Push(Value::Bool(g.below(2) == 0))),
        },
        Ty::Bool => match g.below(5) {
            0 => {
                random_expr(g, Ty::Bool, depth - 1, out);
                out.push(I::Not);
            }
            1 => {
                random_expr(g, Ty::Bool, depth - 1, out);
                random_expr(g, Ty::Bool, depth - 1, out);
                out.push(if g.below(2) == 0 { I::And } else { I::Or });
            }
            2 | 3 => {
                let ty = if num(g) == NumTy::Int {
                    Ty::Int
                } else {
                    Ty::Float
                };
                random_expr(g, ty, depth - 1, out);
                random_expr(g, ty, depth - 1, out);
                let ops = [
                    CmpOp::Eq,
                    CmpOp::Ne,
                    CmpOp::Lt,
                    CmpOp::Le,
                    CmpOp::Gt,
                    CmpOp::Ge,
                ];
                out.push(I::Cmp(ops[g.below(6) as usize], ty));
            }
            _ => {
                let ty = if g.below(2) == 0 { Ty::Bool } else { Ty::Str };
                random_expr(g, ty, depth - 1, out);
                random_expr(g, ty, depth - 1, out);
                let op = if g.below(2) == 0 {
                    CmpOp::Eq
                } else {
                    CmpOp::Ne
                };
                out.push(I::Cmp(op, ty));
            }
        },
        Ty::Str => match g.below(2) {
            0 => out.push(I::Load(STR_VAR)),
            _ => out.push(I::Push(Value::Str(g.below(4) as u32))),
        },
        Ty::Int | Ty::Float if leaf => {
            let int = ty == Ty::Int;
            match (g.below(3), int) {
                (0 | 1, true) => out.push(I::Load(pick(g, INT_VARS))),
                (0 | 1, false) => out.push(I::Load(pick(g, FLOAT_VARS))),
                (_, true) => {
                    // Extremes are rare: any overflow in any atom rejects the whole point.
                    let ints = [0, 1, -1, 2, -7, 1000, 3, 5, -2, 10, 100, i64::MAX, i64::MIN];
                    out.push(I::Push(Value::Int(ints[g.below(13) as usize])));
                }
                (_, false) => {
                    let floats = [0.0, -0.0, 1.5, -2.25, 1e300, f64::NAN, f64::INFINITY];
                    out.push(I::Push(Value::Float(floats[g.below(7) as usize])));
                }
            }
        }
        Ty::Int | Ty::Float => {
            let n = if ty == Ty::Int {
                NumTy::Int
            } else {
                NumTy::Float
            };
            match g.below(4) {
                0 => {
                    random_expr(g, ty, depth - 1, out);
                    out.push(I::Neg(n));
                }
                1 if ty == Ty::Float => {
                    random_expr(g, Ty::Int, depth - 1, out);
                    out.push(I::ToFloat);
                }
                _ => {
                    let op = [I::Add(n), I::Sub(n), I::Mul(n), I::Div(n), I::Rem(n)]
                        [g.below(5) as usize];
                    random_expr(g, ty, depth - 1, out);
                    if n == NumTy::Int && matches!(op, I::Div(_) | I::Rem(_)) {
                        // A variable or a non-zero constant: `x / 0` would fail at every point.
                        match g.below(2) {
                            0 => out.push(I::Load(pick(g, INT_VARS))),
                            _ => out.push(I::Push(Value::Int([3, -2, 7][g.below(3) as usize]))),
                        }
                    } else {
                        random_expr(g, ty, depth - 1, out);
                    }
                    out.push(op);
                }
            }
        }
    }
}

/// Random well-typed atoms over every variable type, combined by one property
/// per atom (`Y`-delayed and `S[1:4]`-windowed in turn): exercises how every
/// operator nests, which the hand-built programs cannot cover.
pub fn random(seed: u64) -> Program<'static> {
    use Op::*;
    let mut g = Gen(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1);
    let atoms: Vec<Vec<I>> = (0..6)
        .map(|_| {
            let mut code = Vec::new();
            random_expr(&mut g, Ty::Bool, 4, &mut code);
            code
        })
        .collect();
    let props = (0..atoms.len() as u16)
        .map(|a| {
            let ops = match a % 3 {
                0 => vec![Atom(a)],
                1 => vec![Atom(a), Yesterday(0), Iff(0, 1)],
                _ => vec![Const(true), Atom(a), since(0, 1, 1, Some(4))],
            };
            ("p", ops)
        })
        .collect();
    build(
        vec![
            event("b0"),
            state("b1", Value::Bool(true)),
            state("i0", Value::Int(0)),
            state("i1", Value::Int(-3)),
            state("x0", Value::Float(0.5)),
            state("x1", Value::Float(-0.0)),
            state("s", Value::Str(1)),
        ],
        vec!["idle", "busy", "x"],
        atoms,
        props,
    )
}

/// Random programs for the compile-and-run test (not snapshotted).
pub fn random_all() -> Vec<(&'static str, Program<'static>)> {
    vec![
        ("random_1", random(1)),
        ("random_2", random(2)),
        ("random_3", random(3)),
        ("random_4", random(4)),
        ("random_5", random(5)),
        ("random_6", random(6)),
    ]
}

/// Every program, with the module name it is emitted under.
pub fn all() -> Vec<(&'static str, Program<'static>)> {
    vec![
        ("minimal", minimal()),
        ("logic", logic()),
        ("ints", ints()),
        ("floats", floats()),
        ("strings", strings()),
        ("windows", windows()),
    ]
}
