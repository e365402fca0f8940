//! `Y p` and `Z p` step to `p`'s value at the previous point, false / true at the first point, in every build (`compact` steps them in one arm).

mod common;

use common::{Rng, ATOMS, INSTRS, VARS};
use monitor_core::{layout, Monitor, Node, Op, Program, Property, Value};

#[test]
fn yesterday_and_weak_yesterday_agree_with_the_definition() {
    for weak in [false, true] {
        let op = if weak {
            Op::WeakYesterday(0)
        } else {
            Op::Yesterday(0)
        };
        let nodes = [
            Node {
                op: Op::Atom(0),
                slot: 0,
            },
            Node {
                op,
                slot: layout::first_node_word(2, 2) as u32,
            },
        ];
        let props = [Property {
            name: "y",
            first: 0,
            root: 1,
        }];
        let p = Program {
            tick_ns: 1,
            vars: &VARS,
            strings: &[],
            instrs: &INSTRS,
            atoms: &ATOMS,
            nodes: &nodes,
            props: &props,
        };
        let m = Monitor::try_new(p).expect("valid program");
        let mut state = vec![0u64; m.state_words()];
        m.reset(&mut state).unwrap();
        let mut rng = Rng(0x5eed + weak as u64);
        let mut last = None;
        for t in 0..200u64 {
            let v = rng.chance(50);
            let mut out = [false];
            m.try_step(
                &mut state,
                t / 3,
                &[Value::Bool(v), Value::Bool(false)],
                &mut out,
            )
            .unwrap();
            assert_eq!(out[0], last.unwrap_or(weak), "weak {weak} point {t}");
            last = Some(v);
        }
    }
}
