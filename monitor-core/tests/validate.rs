//! `Monitor::try_new` and `Table::from_bytes` reject every malformed program instead of misbehaving.

mod common;

use common::{program, since_nodes, Rng, ATOMS, INSTRS, PROPS, VARS};
use monitor_core::table::{read_program, Sink, Store, Table, TABLE_VERSION};
use monitor_core::{
    Atom, CmpOp, Instr, Monitor, Node, NumTy, Op, Program, Property, TableError, Ty, Value, Var,
    VarKind,
};

#[test]
fn bad_nodes_are_rejected() {
    let mut nodes = since_nodes(2, Some(4));
    nodes[2].slot += 1;
    assert_eq!(
        Monitor::try_new(program(&nodes)).unwrap_err(),
        TableError::Layout { node: 2 }
    );
    let mut nodes = since_nodes(0, None);
    nodes[2].op = Op::Since {
        lhs: 2,
        rhs: 1,
        lo: 0,
        hi: None,
    };
    assert_eq!(
        Monitor::try_new(program(&nodes)).unwrap_err(),
        TableError::Node { node: 2 }
    );
    let mut nodes = since_nodes(0, Some(3));
    nodes[2].op = Op::Since {
        lhs: 0,
        rhs: 1,
        lo: 5,
        hi: Some(3),
    };
    assert!(Monitor::try_new(program(&nodes)).is_err());
    let mut nodes = since_nodes(0, None);
    nodes[0].op = Op::Atom(7);
    assert_eq!(
        Monitor::try_new(program(&nodes)).unwrap_err(),
        TableError::Node { node: 0 }
    );
}

#[test]
fn bad_atoms_and_properties_are_rejected() {
    let nodes = since_nodes(0, None);
    let ill_typed = [
        Instr::Load(0),
        Instr::Load(1),
        Instr::Add(monitor_core::NumTy::Int),
    ];
    let atoms = [Atom { start: 0, len: 3 }, Atom { start: 1, len: 1 }];
    let p = Program {
        instrs: &ill_typed,
        atoms: &atoms,
        ..program(&nodes)
    };
    assert_eq!(
        Monitor::try_new(p).unwrap_err(),
        TableError::Atom { atom: 0 }
    );
    let out_of_range = [Atom { start: 1, len: 5 }, ATOMS[1]];
    let p = Program {
        atoms: &out_of_range,
        ..program(&nodes)
    };
    assert_eq!(
        Monitor::try_new(p).unwrap_err(),
        TableError::Atom { atom: 0 }
    );
    let props = [Property {
        name: "s",
        first: 0,
        root: 1,
    }];
    let p = Program {
        props: &props,
        ..program(&nodes)
    };
    assert!(matches!(
        Monitor::try_new(p),
        Err(TableError::Node { .. } | TableError::Property { .. })
    ));
    let _ = (&INSTRS, &VARS, &PROPS);
}

fn table_bytes(nodes: &[Node]) -> Vec<u8> {
    postcard::to_allocvec(&(TABLE_VERSION, program(nodes))).unwrap()
}

#[test]
fn tables_round_trip_and_corruption_is_an_error() {
    let nodes = since_nodes(2, Some(4));
    let bytes = table_bytes(&nodes);
    let table = Table::<8>::from_bytes(&bytes).unwrap();
    assert_eq!(table.program(), program(&nodes));
    // Too small a capacity, truncation, trailing bytes, another version.
    assert!(Table::<2>::from_bytes(&bytes).is_err());
    for cut in 0..bytes.len() {
        assert!(
            Table::<8>::from_bytes(&bytes[..cut]).is_err(),
            "cut at {cut}"
        );
    }
    let mut long = bytes.clone();
    long.push(0);
    assert_eq!(
        Table::<8>::from_bytes(&long).unwrap_err(),
        TableError::Decode
    );
    let mut other = bytes.clone();
    other[0] = 9;
    assert_eq!(
        Table::<8>::from_bytes(&other).unwrap_err(),
        TableError::Version { found: 9 }
    );
    // Random corruption: never a panic, and anything accepted is a valid program.
    let mut rng = Rng(12345);
    for _ in 0..20_000 {
        let mut b = bytes.clone();
        for _ in 0..1 + rng.next() % 4 {
            let k = (rng.next() as usize) % b.len();
            b[k] = rng.next() as u8;
        }
        let table = Table::<8>::from_bytes(&b);
        if let Ok(t) = &table {
            let m = t.monitor().unwrap();
            let mut state = vec![0u64; m.state_words()];
            let mut out = vec![false; m.properties()];
            let vals: Vec<_> = t.program().vars.iter().map(|v| v.init).collect();
            let _ = m.try_step(&mut state, 1, &vals, &mut out);
        }
    }
}

/// `Store` decodes into arrays of exactly the table's size: the same program
/// as `Table`, and one element too many of any kind is a decode error.
#[test]
fn a_store_of_the_exact_size_loads_the_table_in_place() {
    let nodes = since_nodes(2, Some(4));
    let bytes = table_bytes(&nodes);
    let mut store = Store::<2, 0, 2, 2, 3, 1>::new();
    let m = store.load(&bytes).unwrap();
    assert_eq!(*m.program(), program(&nodes));
    assert_eq!(store.program(), program(&nodes));
    // One slot short in each array in turn.
    assert_eq!(
        Store::<1, 0, 2, 2, 3, 1>::new().load(&bytes).unwrap_err(),
        TableError::Decode
    );
    assert_eq!(
        Store::<2, 0, 1, 2, 3, 1>::new().load(&bytes).unwrap_err(),
        TableError::Decode
    );
    assert_eq!(
        Store::<2, 0, 2, 1, 3, 1>::new().load(&bytes).unwrap_err(),
        TableError::Decode
    );
    assert_eq!(
        Store::<2, 0, 2, 2, 2, 1>::new().load(&bytes).unwrap_err(),
        TableError::Decode
    );
    assert_eq!(
        Store::<2, 0, 2, 2, 3, 0>::new().load(&bytes).unwrap_err(),
        TableError::Decode
    );
    let mut bad = nodes;
    bad[2].slot += 1;
    let bad = table_bytes(&bad);
    // Every truncation is an error, and a store can be loaded again after one.
    let mut store = Store::<2, 0, 2, 2, 3, 1>::new();
    for cut in 0..bytes.len() {
        assert!(store.load(&bytes[..cut]).is_err(), "cut at {cut}");
    }
    assert!(store.load(&bytes).is_ok());
    // A store validates like `Monitor::try_new`.
    assert_eq!(
        store.load(&bad).unwrap_err(),
        TableError::Layout { node: 2 }
    );
}

/// An atom that needs floating point or integer division: accepted when
/// monitor-core is built with `float` / `int-div` (the default), rejected on
/// load with `TableError::Feature` when built without (scripts/test runs this
/// file both ways).
#[test]
fn atoms_beyond_the_build_s_features_are_rejected_on_load() {
    let nodes = since_nodes(0, None);
    let float_cmp = [
        Instr::Push(Value::Float(1.5)),
        Instr::Push(Value::Float(2.5)),
        Instr::Cmp(CmpOp::Lt, Ty::Float),
        Instr::Load(1),
    ];
    let int_to_float = [
        Instr::Push(Value::Int(3)),
        Instr::ToFloat,
        Instr::Push(Value::Float(2.5)),
        Instr::Cmp(CmpOp::Gt, Ty::Float),
        Instr::Load(1),
    ];
    let int_div = [
        Instr::Push(Value::Int(7)),
        Instr::Push(Value::Int(2)),
        Instr::Div(NumTy::Int),
        Instr::Push(Value::Int(3)),
        Instr::Cmp(CmpOp::Eq, Ty::Int),
        Instr::Load(1),
    ];
    let int_only = [
        Instr::Push(Value::Int(7)),
        Instr::Push(Value::Int(2)),
        Instr::Mul(NumTy::Int),
        Instr::Push(Value::Int(14)),
        Instr::Cmp(CmpOp::Eq, Ty::Int),
        Instr::Load(1),
    ];
    let cases: [(&[Instr], bool); 4] = [
        (&float_cmp, cfg!(feature = "float")),
        (&int_to_float, cfg!(feature = "float")),
        (&int_div, cfg!(feature = "int-div")),
        (&int_only, true),
    ];
    for (code, accepted) in cases {
        let n = code.len() as u16;
        let atoms = [
            Atom {
                start: 0,
                len: n - 1,
            },
            Atom {
                start: n - 1,
                len: 1,
            },
        ];
        let p = Program {
            instrs: code,
            atoms: &atoms,
            ..program(&nodes)
        };
        match Monitor::try_new(p) {
            Ok(m) => {
                assert!(accepted, "{code:?} accepted");
                // The atom is true: 1.5 < 2.5, 3.0 > 2.5, 7 / 2 == 3, 7 * 2 == 14.
                let mut state = vec![0u64; m.state_words()];
                let mut out = [false];
                m.try_step(&mut state, 0, &[Value::Bool(false); 2], &mut out)
                    .unwrap();
                assert_eq!(m.node_value(&state, 0), Some(true), "{code:?}");
            }
            Err(e) => {
                assert!(!accepted, "{code:?} rejected: {e}");
                assert_eq!(e, TableError::Feature { atom: 0 });
            }
        }
    }
}

/// Collects everything `read_program` hands out.
#[derive(Default)]
struct Collect<'a> {
    tick_ns: u64,
    vars: Vec<Var<'a>>,
    strings: Vec<&'a str>,
    instrs: Vec<Instr>,
    atoms: Vec<Atom>,
    nodes: Vec<Node>,
    props: Vec<Property<'a>>,
}

impl<'a> Sink<'a> for Collect<'a> {
    fn tick_ns(&mut self, tick_ns: u64) {
        self.tick_ns = tick_ns;
    }
    fn var(&mut self, _: usize, v: Var<'a>) -> bool {
        self.vars.push(v);
        true
    }
    fn string(&mut self, _: usize, s: &'a str) -> bool {
        self.strings.push(s);
        true
    }
    fn instr(&mut self, _: usize, ins: Instr) -> bool {
        self.instrs.push(ins);
        true
    }
    fn atom(&mut self, _: usize, a: Atom) -> bool {
        self.atoms.push(a);
        true
    }
    fn node(&mut self, _: usize, n: Node) -> bool {
        self.nodes.push(n);
        true
    }
    fn prop(&mut self, _: usize, p: Property<'a>) -> bool {
        self.props.push(p);
        true
    }
}

/// The table reader reads back what postcard writes for every variant of
/// every program type and for the extremes of every integer (it is not
/// validated here: `read_program` only decodes).
#[test]
fn the_table_reader_reads_what_postcard_writes() {
    let ints = [0, 1, -1, 63, -64, 64, i64::MAX, i64::MIN, 300, -301];
    let big = [
        0,
        1,
        127,
        128,
        16_383,
        16_384,
        u64::from(u32::MAX),
        u64::MAX,
    ];
    let mut instrs = vec![
        Instr::Push(Value::Bool(true)),
        Instr::Push(Value::Bool(false)),
        Instr::Push(Value::Float(-2.5)),
        Instr::Push(Value::Float(f64::INFINITY)),
        Instr::Push(Value::Str(0)),
        Instr::Push(Value::Str(u32::MAX)),
        Instr::Load(0),
        Instr::Load(u16::MAX),
        Instr::Not,
        Instr::And,
        Instr::Or,
        Instr::ToFloat,
    ];
    instrs.extend(ints.map(|i| Instr::Push(Value::Int(i))));
    for t in [NumTy::Int, NumTy::Float] {
        instrs.extend([
            Instr::Neg(t),
            Instr::Add(t),
            Instr::Sub(t),
            Instr::Mul(t),
            Instr::Div(t),
            Instr::Rem(t),
        ]);
    }
    for op in [
        CmpOp::Eq,
        CmpOp::Ne,
        CmpOp::Lt,
        CmpOp::Le,
        CmpOp::Gt,
        CmpOp::Ge,
    ] {
        for ty in [Ty::Bool, Ty::Int, Ty::Float, Ty::Str] {
            instrs.push(Instr::Cmp(op, ty));
        }
    }
    let mut ops = vec![
        Op::Const(true),
        Op::Const(false),
        Op::Atom(7),
        Op::Not(1),
        Op::And(1, 2),
        Op::Or(3, u16::MAX),
        Op::Implies(128, 129),
        Op::Iff(0, 0),
        Op::Yesterday(5),
        Op::WeakYesterday(6),
    ];
    for lo in big {
        for hi in [None, Some(lo), Some(u64::MAX)] {
            ops.push(Op::Since {
                lhs: 1,
                rhs: 2,
                lo,
                hi,
            });
        }
    }
    let nodes: Vec<Node> = ops
        .iter()
        .zip([0, 1, 127, 128, u32::MAX].iter().cycle())
        .map(|(&op, &slot)| Node { op, slot })
        .collect();
    let vars = [
        Var {
            name: "",
            ty: Ty::Bool,
            kind: VarKind::Event,
            init: Value::Bool(false),
        },
        Var {
            name: "höhe",
            ty: Ty::Float,
            kind: VarKind::State,
            init: Value::Float(1e-300),
        },
        Var {
            name: "n",
            ty: Ty::Int,
            kind: VarKind::State,
            init: Value::Int(i64::MIN),
        },
        Var {
            name: "s",
            ty: Ty::Str,
            kind: VarKind::State,
            init: Value::Str(3),
        },
    ];
    let strings = ["a", "", "ünïcode ✓"];
    let atoms = [
        Atom { start: 0, len: 1 },
        Atom {
            start: u16::MAX,
            len: 200,
        },
    ];
    let props = [
        Property {
            name: "p",
            first: 0,
            root: u16::MAX,
        },
        Property {
            name: "q",
            first: 300,
            root: 2,
        },
    ];
    let program = Program {
        tick_ns: u64::MAX,
        vars: &vars,
        strings: &strings,
        instrs: &instrs,
        atoms: &atoms,
        nodes: &nodes,
        props: &props,
    };
    let bytes = postcard::to_allocvec(&(TABLE_VERSION, program)).unwrap();
    let mut got = Collect::default();
    let counts = read_program(&bytes, &mut got).unwrap();
    let back = Program {
        tick_ns: got.tick_ns,
        vars: &got.vars,
        strings: &got.strings,
        instrs: &got.instrs,
        atoms: &got.atoms,
        nodes: &got.nodes,
        props: &got.props,
    };
    assert_eq!(back, program);
    assert_eq!(counts.instrs, instrs.len());
    // Every truncation fails, and so does a varint past its type's width.
    for cut in 0..bytes.len() {
        assert!(read_program(&bytes[..cut], &mut Collect::default()).is_err());
    }
    let mut wide = postcard::to_allocvec(&TABLE_VERSION).unwrap();
    wide.extend([0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0x02]);
    assert_eq!(
        read_program(&wide, &mut Collect::default()).unwrap_err(),
        TableError::Decode
    );
}
