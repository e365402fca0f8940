//! What can panic below the monitor step in the linked firmware (`museum_spec::step` for the generated monitor, `firmware::step_point` for the table).

use host_check::callgraph::analyse;
use host_check::{read_image, STEPS};

#[test]
fn every_panic_below_the_step_comes_from_monitor_core() {
    for (name, step) in STEPS {
        let (path, _) = read_image(name).unwrap();
        let report = analyse(&path, step).unwrap();
        assert_eq!(report.reachable.first().map(String::as_str), Some(step));
        // The firmware glue, the trace reader and the generated code add no panic of their own.
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
    for (name, step) in STEPS {
        let (path, _) = read_image(name).unwrap();
        let report = analyse(&path, step).unwrap();
        assert!(
            report.panic_calls.is_empty(),
            "{name}: {:#?}\n{:#?}",
            report.panic_calls,
            report.locations
        );
    }
}
