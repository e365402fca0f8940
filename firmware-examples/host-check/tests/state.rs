//! The per-property state breakdown of the compiled museum table adds up to what the monitor allocates and equals what the compiler reported.

use host_check::state_breakdown;
use host_check::verdicts::{on_big_stack, HOST_CAPACITY};
use monitor_core::table::Table;

#[test]
fn breakdown_adds_up_to_the_monitor_state_and_matches_the_compiler() {
    on_big_stack(|| {
        let table = Table::<HOST_CAPACITY>::from_bytes(museum_spec::TABLE).unwrap();
        let m = table.monitor().unwrap();
        let b = state_breakdown(&table.program()).unwrap();
        assert_eq!(b.total(), m.state_bytes());
        assert_eq!(m.state_bytes(), museum_spec::STATE_BYTES);
        let bytes: Vec<usize> = b.props.iter().map(|(_, n)| *n).collect();
        assert_eq!(bytes, museum_spec::PROPERTY_STATE_BYTES);
        let names: Vec<&str> = b.props.iter().map(|(n, _)| n.as_str()).collect();
        assert_eq!(names, museum_spec::museum::PROPERTY_NAMES);
        Ok(())
    })
    .unwrap();
}
