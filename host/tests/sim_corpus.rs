//! Loads every corpus model (museum, AS2FM plain, UC3) and simulates the museum guide.

use std::path::{Path, PathBuf};

fn corpus() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/corpus")
}

#[test]
fn as2fm_plain_models_read() {
    let dir = corpus().join("as2fm/plain");
    let mut n = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        let has_scxml = std::fs::read_dir(&path)
            .unwrap()
            .any(|e| e.unwrap().path().extension().is_some_and(|x| x == "scxml"));
        if !has_scxml {
            // A case AS2FM translated to JANI only: a clear error, not a panic.
            let err = hindsight::model::load(&path).unwrap_err();
            assert!(err.to_string().contains("no .scxml file"), "{err}");
            continue;
        }
        match hindsight::model::load(&path) {
            Ok(m) => assert!(!m.machines.is_empty()),
            Err(e) => panic!("{}: {e}", path.display()),
        }
        n += 1;
    }
    assert!(n > 30);
}

#[test]
fn uc3_reads_through_model_xml() {
    let m = hindsight::model::load(&corpus().join("uc3-plain/model.xml")).unwrap();
    assert_eq!(m.machines.len(), 278);
    assert!(m.properties.is_some());
}

#[test]
fn museum_reads() {
    let m = hindsight::model::load(&corpus().join("museum-simpar2025/model_scxml")).unwrap();
    // 57 machines plus the `NONE` sink machine the generator wrote.
    assert_eq!(m.machines.len(), 58);
}

#[test]
fn explore_compile_all() {
    let mut dirs: Vec<PathBuf> = std::fs::read_dir(corpus().join("as2fm/plain"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    dirs.sort();
    dirs.push(corpus().join("uc3-plain/model.xml"));
    dirs.push(corpus().join("museum-simpar2025/model_scxml"));
    dirs.push(corpus().join("museum-simpar2025/plain_regenerated"));
    for d in dirs {
        let Ok(src) = hindsight::model::load(&d) else {
            continue;
        };
        match hindsight::sim::CompiledModel::compile(src) {
            Ok(m) => eprintln!("OK {} warnings={}", d.display(), m.warnings().len()),
            Err(e) => eprintln!("ERR {}\n{e}", d.display()),
        }
    }
}

fn museum_fixed() -> hindsight::sim::CompiledModel {
    let dir = corpus().join("museum-simpar2025/model_scxml");
    let mut files: Vec<(String, String)> = Vec::new();
    let mut paths: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "scxml"))
        .collect();
    paths.sort();
    for p in paths {
        let mut text = std::fs::read_to_string(&p).unwrap();
        if p.ends_with("NavigationComponent.scxml") {
            text = text.replace("_event.thread_id", "_event.data.thread_id");
        }
        files.push((p.display().to_string(), text));
    }
    let src = hindsight::model::ModelSource::from_texts(
        files.iter().map(|(a, b)| (a.as_str(), b.as_str())),
    )
    .unwrap();
    hindsight::sim::CompiledModel::compile(src).unwrap()
}

#[test]
fn explore_run_museum() {
    use rand_core::SeedableRng;
    let m = museum_fixed();
    for w in m.warnings() {
        eprintln!("W {w}");
    }
    let mut sim = hindsight::sim::Simulator::new(&m);
    let cfg = hindsight::sim::RunConfig {
        max_time: 1000,
        ..Default::default()
    };
    let t0 = std::time::Instant::now();
    let mut total = 0;
    for seed in 0..20u64 {
        let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(seed);
        let out = sim.run(&mut rng, &cfg, &mut ());
        total += out.steps;
        if seed < 3 {
            eprintln!("{out:?}");
        }
    }
    let dt = t0.elapsed().as_secs_f64();
    eprintln!(
        "steps {total} in {dt:.3}s = {:.0} steps/s",
        total as f64 / dt
    );
}

#[test]
fn explore_trace_museum() {
    use rand_core::SeedableRng;
    let m = museum_fixed();
    let mut sim = hindsight::sim::Simulator::new(&m);
    let cfg = hindsight::sim::RunConfig {
        max_time: 25,
        ..Default::default()
    };
    let mut rec = hindsight::sim::TraceRecorder::new();
    let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(1);
    let out = sim.run(&mut rng, &cfg, &mut rec);
    eprintln!("{out:?}");
    let mut buf = Vec::new();
    rec.write_csv(&m, &mut buf).unwrap();
    let s = String::from_utf8(buf).unwrap();
    for l in s.lines().take(120) {
        eprintln!("{l}");
    }
    for l in s
        .lines()
        .filter(|l| l.contains("battery_level") || l.contains("StartAlarm"))
        .take(40)
    {
        eprintln!("{l}");
    }
}

#[test]
fn explore_run_uc3() {
    use rand_core::SeedableRng;
    let m = hindsight::sim::CompiledModel::load(&corpus().join("uc3-plain/model.xml")).unwrap();
    eprintln!("warnings {}", m.warnings().len());
    for w in m.warnings().iter().take(5) {
        eprintln!("W {w}");
    }
    let mut sim = hindsight::sim::Simulator::new(&m);
    let cfg = hindsight::sim::RunConfig {
        max_time: 1000,
        ..Default::default()
    };
    let t0 = std::time::Instant::now();
    let mut total = 0;
    for seed in 0..5u64 {
        let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(seed);
        let out = sim.run(&mut rng, &cfg, &mut ());
        total += out.steps;
        eprintln!("{out:?}");
    }
    let dt = t0.elapsed().as_secs_f64();
    eprintln!(
        "steps {total} in {dt:.3}s = {:.0} steps/s",
        total as f64 / dt
    );
}

#[test]
fn explore_trace_uc3() {
    use rand_core::SeedableRng;
    let m = hindsight::sim::CompiledModel::load(&corpus().join("uc3-plain/model.xml")).unwrap();
    let mut sim = hindsight::sim::Simulator::new(&m);
    let cfg = hindsight::sim::RunConfig {
        max_time: 1000,
        ..Default::default()
    };
    let mut rec = hindsight::sim::TraceRecorder::new();
    let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(1);
    let out = sim.run(&mut rng, &cfg, &mut rec);
    eprintln!("{out:?}");
    let mut buf = Vec::new();
    rec.write_csv(&m, &mut buf).unwrap();
    let s = String::from_utf8(buf).unwrap();
    let mut per: std::collections::BTreeMap<u64, usize> = Default::default();
    for r in &rec.rows {
        *per.entry(r.time / 50).or_default() += 1;
    }
    eprintln!("{per:?}");
    let lines: Vec<&str> = s.lines().collect();
    let start = 0;
    for l in lines[start..]
        .iter()
        .filter(|l| l.contains("NavigationComponent") && !l.contains("CheckNear"))
        .take(40)
    {
        eprintln!("{}", &l[..l.len().min(200)]);
    }
    for mid in m.machine_ids() {
        let st = sim.state_of(mid);
        eprintln!("{} : {}", m.machine_name(mid), m.state_name(mid, st));
    }
}

#[test]
fn explore_nav() {
    use rand_core::SeedableRng;
    let m = hindsight::sim::CompiledModel::load(&corpus().join("uc3-plain/model.xml")).unwrap();
    let nav = m.machine_id("NavigationComponent").unwrap();
    eprintln!("{}", m.dump_machine(nav));
    let mut sim = hindsight::sim::Simulator::new(&m);
    for t in 1..4 {
        let cfg = hindsight::sim::RunConfig {
            max_time: t,
            ..Default::default()
        };
        let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(1);
        let out = sim.run(&mut rng, &cfg, &mut ());
        eprintln!(
            "{out:?} state={} rand={:?} status={:?}",
            m.state_name(nav, sim.state_of(nav)),
            sim.var(nav, "__RAND__"),
            sim.var(nav, "status")
        );
    }
}

#[test]
fn explore_r() {
    use rand_core::SeedableRng;
    let text = std::fs::read_to_string("/tmp/r.scxml").unwrap();
    let m = hindsight::sim::CompiledModel::compile(
        hindsight::model::ModelSource::from_texts([("r.scxml", text.as_str())]).unwrap(),
    )
    .unwrap();
    let mut sim = hindsight::sim::Simulator::new(&m);
    let mut rec = hindsight::sim::TraceRecorder::new();
    let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(1);
    struct L;
    impl hindsight::sim::Observer for L {
        fn on_log(
            &mut self,
            _t: u64,
            _m: hindsight::sim::MachineId,
            l: &str,
            v: Option<hindsight::expr::Value<'_>>,
        ) {
            eprintln!("LOG {l} {v:?}");
        }
    }
    let out = sim.run(&mut rng, &Default::default(), &mut (&mut rec, L));
    eprintln!(
        "{out:?} {:?} {:?}",
        rec.rows,
        sim.var(hindsight::sim::MachineId(0), "r")
    );
    eprintln!("{}", m.dump_machine(hindsight::sim::MachineId(0)));
}
