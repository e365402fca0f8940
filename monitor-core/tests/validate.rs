//! `Monitor::try_new` and `Table::from_bytes` reject every malformed program instead of misbehaving.

mod common;

use common::{program, since_nodes, Rng, ATOMS, INSTRS, PROPS, VARS};
use monitor_core::table::{Table, TABLE_VERSION};
use monitor_core::{Atom, Instr, Monitor, Node, Op, Program, Property, TableError};

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
