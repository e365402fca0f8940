//! The per-property state breakdown adds up to what the monitor allocates.

use host_check::state_breakdown;
use monitor_core::Monitor;

#[test]
fn breakdown_adds_up_to_the_monitor_state() {
    let b = state_breakdown(&museum_spec::PROGRAM).unwrap();
    let m = Monitor::try_new(museum_spec::PROGRAM).unwrap();
    assert_eq!(b.total(), m.state_bytes());
    // Shared: timestamp, one word of atom bits, one word of node bits (19 nodes).
    assert_eq!(b.shared, 3 * 8);
    // P[10:] and P[:10] one word each; P[1:20] a header and two runs; P[:10] one word.
    let bytes: Vec<usize> = b.props.iter().map(|(_, n)| *n).collect();
    assert_eq!(bytes, [16, 40, 8]);
}
