//! Every corpus model (AS2FM plain SCXML, the museum guide, UC3) loads and compiles; the
//! museum's known `_event.thread_id` bug is reported precisely; corrected, the museum runs.

mod common;

use hindsight::verify::sim::{CompiledModel, EndReason, RunConfig, Simulator, TraceRecorder};
use rand_core::SeedableRng;
use rand_xoshiro::Xoshiro256PlusPlus;
use std::path::{Path, PathBuf};

fn corpus() -> PathBuf {
    common::corpus_root()
}

fn rng(seed: u64) -> Xoshiro256PlusPlus {
    Xoshiro256PlusPlus::seed_from_u64(seed)
}

fn has_scxml(dir: &Path) -> bool {
    std::fs::read_dir(dir)
        .unwrap()
        .any(|e| e.unwrap().path().extension().is_some_and(|x| x == "scxml"))
}

#[test]
fn as2fm_plain_models_compile_and_run() {
    if common::corpus_or_skip().is_none() {
        return;
    }
    let mut dirs: Vec<PathBuf> = std::fs::read_dir(corpus().join("as2fm/plain"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    dirs.sort();
    let mut spinning = std::collections::BTreeSet::new();
    for dir in &dirs {
        if !has_scxml(dir) {
            // A case AS2FM translated to JANI only: a clear error, not a panic.
            let err = hindsight::verify::model::load(dir).unwrap_err();
            assert!(err.to_string().contains("no .scxml file"), "{err}");
            continue;
        }
        let m = CompiledModel::load(dir).unwrap_or_else(|e| panic!("{}:\n{e}", dir.display()));
        let cfg = RunConfig {
            max_time: 200,
            max_steps: 200_000,
            max_steps_per_instant: 50_000,
            ..RunConfig::default()
        };
        let mut sim = Simulator::new(&m);
        for seed in 0..3 {
            let out = sim.run(&mut rng(seed), &cfg, &mut ());
            let name = dir.file_name().unwrap().to_string_lossy().into_owned();
            match &out.end {
                EndReason::Error(e) => panic!("{name}: {e}"),
                EndReason::Spin(s) => {
                    assert_eq!(
                        s.kind,
                        hindsight::verify::sim::SpinKind::NoTimeProgress,
                        "{name}: {s}"
                    );
                    spinning.insert(name);
                }
                _ => {}
            }
        }
    }
    // Test models written for reachability checking: a sender loops forever with eventless
    // transitions and no delay, so time never advances. They are reported, not hung on.
    let expected = [
        "array_model_basic_main",
        "array_of_strings_main",
        "conditional_transitions_main",
        "events_sync_ex_main",
        "multiple_senders_same_event_main",
        "on_entry_exit_test_main",
    ];
    assert_eq!(spinning.into_iter().collect::<Vec<_>>(), expected);
}

#[test]
fn museum_reports_the_event_thread_id_bug() {
    if common::corpus_or_skip().is_none() {
        return;
    }
    let err = CompiledModel::load(&corpus().join("museum-simpar2025/model_scxml")).unwrap_err();
    assert_eq!(err.0.len(), 1, "{err}");
    let d = &err.0[0];
    assert!(
        Path::new(&d.file).ends_with("model_scxml/NavigationComponent.scxml"),
        "{d}"
    );
    assert_eq!((d.line, d.col), (20, 30), "{d}");
    assert_eq!(
        d.message,
        "`_event` has no field `thread_id` (did you mean `_event.data.thread_id`?)"
    );
    let text = std::fs::read_to_string(&d.file).unwrap();
    let line = text.lines().nth(19).unwrap();
    assert!(line[29..].starts_with("thread_id == 0"), "{line}");
}

#[test]
fn museum_runs() {
    let m = common::museum_fixed();
    // 57 machines plus the `NONE` sink machine the generator wrote.
    assert_eq!(m.machine_count(), 58);
    assert!(m.warnings().is_empty(), "{:?}", m.warnings());
    let battery = m
        .event_id("topic_BatteryComponent__battery_level_msg")
        .unwrap();
    let data = m.param_index(battery, "ros_fields__data").unwrap();
    let mut sim = Simulator::new(&m);
    let cfg = RunConfig {
        max_time: 2000,
        ..RunConfig::default()
    };
    for seed in 0..3 {
        let mut rec = TraceRecorder::new();
        let out = sim.run(&mut rng(seed), &cfg, &mut rec);
        // The global timer stops after 1000 steps of 100 ms: the model then goes quiet.
        assert_eq!(out.end, EndReason::Quiescent);
        assert_eq!(out.time, 1000);
        assert!(out.steps > 40_000, "{out:?}");
        // The battery publishes at start and then every second (10 steps), losing 1% each time.
        let levels: Vec<(u64, i64)> = rec
            .rows
            .iter()
            .filter(|r| r.event == battery)
            .map(|r| match r.params[data] {
                hindsight::verify::expr::OwnedValue::Int(v) => (r.time, v),
                ref v => panic!("{v:?}"),
            })
            .collect();
        assert_eq!(levels.len(), 101);
        for (i, (t, v)) in levels.iter().enumerate() {
            assert_eq!((*t, *v), (10 * i as u64, 100 - i as i64));
        }
    }
}

#[test]
fn uc3_compiles_and_runs() {
    if common::corpus_or_skip().is_none() {
        return;
    }
    let m = CompiledModel::load(&corpus().join("uc3-plain/model.xml")).unwrap();
    assert_eq!(m.machine_count(), 278);
    assert!(m.properties_path().is_some());
    // Transitions on events no machine sends are reported, not silently kept.
    assert_eq!(m.warnings().len(), 3);
    let mut sim = Simulator::new(&m);
    let cfg = RunConfig {
        max_time: 100,
        ..RunConfig::default()
    };
    for seed in 0..2 {
        let out = sim.run(&mut rng(seed), &cfg, &mut ());
        assert_eq!(out.end, EndReason::MaxTime);
        assert!(out.steps > 10_000, "{out:?}");
    }
}
