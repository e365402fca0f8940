//! What can panic below the monitor step in the linked firmware (`firmware::step_point`).

use host_check::callgraph::analyse;
use host_check::read_image;

const STEP: &str = "firmware::step_point";

#[test]
fn every_panic_below_the_step_comes_from_monitor_core() {
    for name in ["monitor-static", "monitor-table"] {
        let (path, _) = read_image(name).unwrap();
        let report = analyse(&path, STEP).unwrap();
        assert_eq!(report.reachable.first().map(String::as_str), Some(STEP));
        // The firmware glue and the trace reader add no panic of their own.
        for l in &report.locations {
            assert!(
                l.file.contains("monitor-core/src/"),
                "{name}: panic at {}:{} below the step",
                l.file,
                l.line
            );
        }
        // Every call into core's panic machinery has a location to report.
        assert_eq!(report.panic_calls.is_empty(), report.locations.is_empty());
    }
}

#[test]
fn the_monitor_step_links_no_panic_path() {
    for name in ["monitor-static", "monitor-table"] {
        let (path, _) = read_image(name).unwrap();
        let report = analyse(&path, STEP).unwrap();
        assert!(
            report.panic_calls.is_empty(),
            "{name}: {:#?}\n{:#?}",
            report.panic_calls,
            report.locations
        );
    }
}
