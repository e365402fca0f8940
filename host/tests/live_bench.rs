//! The benchmark mode runs end to end on a few samples (its numbers are reported, not asserted).

mod live_common;

#[test]
fn the_benchmark_measures_both_receivers_and_counts_the_flood() {
    iceoryx2::prelude::set_log_level(iceoryx2::prelude::LogLevel::Error);
    let prefix = live_common::unique("bench");
    let r = hindsight::live::bench::run(&prefix, 200, 10_000.0, 2_000).unwrap();
    assert_eq!(r.paced, 200);
    // Both receivers saw samples (a latency of exactly 0 ns is not measurable here).
    assert!(r.plain_ns.0 > 0 && r.sidecar_ns.0 > 0, "{r}");
    assert!(
        r.plain_ns.0 <= r.plain_ns.1 && r.sidecar_ns.0 <= r.sidecar_ns.1,
        "{r}"
    );
    // Every flood sample was either judged or counted lost, never both.
    assert!(
        r.flood_judged > 0 && r.flood_judged + r.flood_lost <= 2_000,
        "{r}"
    );
    let text = r.to_string();
    assert!(
        text.contains("plain subscriber latency") && text.contains("sidecar judged"),
        "{text}"
    );
}
