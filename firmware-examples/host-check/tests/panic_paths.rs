//! What the monitor step reaches in the linked firmware (`museum_spec::step` for the generated monitor, `firmware::step_point` for the table): no panic, no soft-float or division routine.

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

#[test]
fn an_integer_specs_step_reaches_no_soft_float_or_division_routine() {
    // museum.hspec's atoms are integer and boolean, and the images build
    // monitor-core without `float` and `int-div`: neither the generated step nor
    // the interpreter's (a window's capacity included) may call such a routine.
    for (name, step) in STEPS {
        let (path, _) = read_image(name).unwrap();
        let report = analyse(&path, step).unwrap();
        let routines: Vec<&String> = report
            .reachable
            .iter()
            .filter(|f| host_check::callgraph::is_soft_float_or_division(f))
            .collect();
        assert!(routines.is_empty(), "{name}: {routines:?}");
    }
}
