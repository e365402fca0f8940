//! Runs per second of the museum guide: the high-level robot model against its plain-SCXML translations.
//!
//! `cargo bench -p hindsight --bench museum [-- --runs N --reps R --only K]`
//!
//! Issue 5 asks for at least as many runs per second on the high-level model as on its
//! plain-SCXML translation. Two translations of the same high-level model with the same
//! semantics (AS2FM's current BT translation, AS2FM's event semantics) are measured:
//! - `converted`: the guide (`examples/museum-guide`) translated by `hindsight convert`
//!   and loaded back as plain SCXML;
//! - `uc3 ...`: the museum guide as AS2FM's own tests have it
//!   (the external corpus's `as2fm/test_data/uc3_museum_guide`, read natively) against
//!   AS2FM's own plain translation of that model (`as2fm/plain/uc3_museum_guide_main`),
//!   both judged by the case's JANI properties (left out without the corpus:
//!   `HINDSIGHT_CORPUS`, or `shared/corpus` next to the repository).
//!
//! For context, the paper's plain model (`examples/museum-scxml`, SCAN's queues, runs of
//! 1001 steps like the guide's `max_time` of 100.1 s) comes from an older AS2FM whose
//! BT nodes never halted their children: 30 % fewer steps per run than the current
//! translation, so it is not the same model step for step. The `halts when needed` line
//! is the guide lowered with `Halts::WhenNeeded` (not the default: it changes how races
//! at one instant come out, see `hindsight::verify::robot::bt::Halts`).
//!
//! Each configuration runs N seeded runs (stream k of seed 1, as `hindsight verify --seed
//! 1` does) judged by its properties, exactly as a study runs them; passes of all
//! configurations are interleaved and the median pass is reported, so that load on a
//! shared machine falls on every configuration alike. The `sim only` column runs the
//! simulator without properties. The figures to read are the ratios, measured in the
//! same run.

use std::path::{Path, PathBuf};
use std::time::Instant;

#[path = "../tests/common/corpus.rs"]
mod corpus;

use hindsight::verify::load::{load, LoadOptions, Loaded};
use hindsight::verify::observe::PropertySet;
use hindsight::verify::robot::bt::Halts;
use hindsight::verify::sim::{EventSemantics, RunConfig, Simulator};
use hindsight::verify::smc::runner::stream;
use hindsight::verify::study::Runner;

fn examples() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("host/ inside the workspace")
        .join("examples")
}

/// One benchmarked configuration: a loaded model and how its runs are configured.
struct Case {
    name: &'static str,
    loaded: Loaded,
    cfg: RunConfig,
}

impl Case {
    fn new(
        name: &'static str,
        dir: impl AsRef<Path>,
        events: Option<EventSemantics>,
        max_time: Option<u64>,
    ) -> Case {
        let dir = dir.as_ref();
        let args = LoadOptions {
            model: examples().join(dir),
            events,
            ..LoadOptions::default()
        };
        let loaded = match load(&args) {
            Ok(l) => l,
            Err(e) => panic!("{}: {e}", dir.display()),
        };
        Case::of(name, loaded, max_time)
    }

    fn of(name: &'static str, loaded: Loaded, max_time: Option<u64>) -> Case {
        let cfg = RunConfig {
            max_time: max_time.unwrap_or_else(|| loaded.default_max_time.unwrap_or(10_000)),
            events: loaded.events,
            ..RunConfig::default()
        };
        Case { name, loaded, cfg }
    }

    /// The guide's own plain-SCXML translation: `hindsight convert examples/museum-guide`
    /// written to a temporary folder and loaded back as plain SCXML, AS2FM's semantics.
    fn converted() -> Case {
        let out =
            std::env::temp_dir().join(format!("hindsight-bench-convert-{}", std::process::id()));
        hindsight::cli::convert::run(&hindsight::cli::convert::ConvertArgs {
            model: examples().join("museum-guide"),
            out: out.clone(),
            interfaces: Vec::new(),
            bt: Default::default(),
            bt_tick: None,
        })
        .unwrap_or_else(|e| panic!("convert: {e:?}"));
        let args = LoadOptions {
            model: out.clone(),
            time_unit_ns: Some(100_000_000),
            events: Some(EventSemantics::As2fm),
            ..LoadOptions::default()
        };
        let loaded = load(&args).unwrap_or_else(|e| panic!("converted guide: {e:?}"));
        let _ = std::fs::remove_dir_all(&out);
        let max_time = loaded.default_max_time.or(Some(1002));
        Case::of("guide converted (plain, as2fm)", loaded, max_time)
    }

    /// The corpus's museum guide as AS2FM's tests have it (`as2fm/test_data/uc3_museum_guide`,
    /// read natively) and AS2FM's own plain translation of that very model
    /// (`as2fm/plain/uc3_museum_guide_main`, AS2FM's semantics), both judged by the case's
    /// JANI property; `None` without the external corpus.
    fn corpus_pair() -> Option<[Case; 2]> {
        let root = corpus::find()?.join("as2fm");
        let high = Case::new(
            "uc3 high-level (corpus)",
            root.join("test_data/uc3_museum_guide/Main/main.xml"),
            None,
            None,
        );
        let plain_dir = root.join("plain/uc3_museum_guide_main");
        let model = hindsight::verify::sim::CompiledModel::load(&plain_dir)
            .unwrap_or_else(|e| panic!("uc3 plain: {e}"));
        let props_path = root.join("test_data/uc3_museum_guide/Properties/properties.jani");
        let file = hindsight::verify::props::jani::parse_file(&props_path, &model)
            .unwrap_or_else(|e| panic!("uc3 properties: {e}"));
        let set = PropertySet::new(&file, &model).unwrap_or_else(|e| panic!("uc3: {e}"));
        let loaded = Loaded {
            model,
            file,
            set,
            props_path,
            unit_ns: Some(100_000_000),
            default_max_time: Some(1001),
            events: EventSemantics::As2fm,
            bt_notes: Vec::new(),
            warnings: Default::default(),
            options: Default::default(),
            no_props: None,
        };
        Some([high, Case::of("uc3 AS2FM plain (corpus)", loaded, None)])
    }

    /// The guide lowered with `halts`, AS2FM's event semantics.
    fn guide_with(name: &'static str, halts: Halts) -> Case {
        let dir = examples().join("museum-guide");
        let robot = hindsight::verify::robot::load::load_with(&dir.join("main.xml"), halts)
            .unwrap_or_else(|e| panic!("museum-guide: {e}"));
        let props_path = dir.join("properties.xml");
        let file = hindsight::verify::props::parse_file(&props_path)
            .unwrap_or_else(|e| panic!("museum-guide properties: {e}"));
        let set = PropertySet::with_unit(&file, &robot.model, Some(robot.time_unit_ns))
            .unwrap_or_else(|e| panic!("museum-guide properties: {e}"));
        let loaded = Loaded {
            model: robot.model,
            file,
            set,
            props_path,
            unit_ns: Some(robot.time_unit_ns),
            default_max_time: Some(robot.max_time_steps),
            events: EventSemantics::As2fm,
            bt_notes: Vec::new(),
            warnings: Default::default(),
            options: Default::default(),
            no_props: None,
        };
        Case::of(name, loaded, None)
    }
}

/// Seconds for `runs` judged runs (streams 0.. of seed 1), and the steps they took.
fn judged_pass(runner: &Runner<'_>, runs: u64) -> (f64, u64) {
    let t0 = Instant::now();
    let mut steps = 0;
    for k in 0..runs {
        let out = runner.run(k, &mut stream(1, k));
        steps += out.steps;
    }
    (t0.elapsed().as_secs_f64(), steps)
}

/// Seconds for `runs` runs of the simulator alone (no observer).
fn sim_pass(sim: &mut Simulator<'_>, cfg: &RunConfig, runs: u64) -> (f64, u64) {
    let t0 = Instant::now();
    let mut steps = 0;
    for k in 0..runs {
        steps += sim.run(&mut stream(1, k), cfg, &mut ()).steps;
    }
    (t0.elapsed().as_secs_f64(), steps)
}

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn arg(args: &[String], name: &str, default: u64) -> u64 {
    args.iter()
        .position(|a| a == name)
        .and_then(|i| args.get(i + 1))
        .map_or(default, |v| {
            v.parse()
                .unwrap_or_else(|_| panic!("{name}: expected a number"))
        })
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let runs = arg(&args, "--runs", 20).max(1);
    let reps = arg(&args, "--reps", 5).max(1) as usize;
    let mut cases = vec![
        Case::new("guide (robot model, as2fm)", "museum-guide", None, None),
        Case::new(
            "guide (robot model, queues)",
            "museum-guide",
            Some(EventSemantics::Queues),
            None,
        ),
        Case::new(
            "plain (museum-scxml, queues)",
            "museum-scxml",
            None,
            Some(1001),
        ),
        Case::new(
            "plain (museum-scxml, as2fm)",
            "museum-scxml",
            Some(EventSemantics::As2fm),
            Some(1001),
        ),
        Case::guide_with("guide (halts needed, as2fm)", Halts::WhenNeeded),
        Case::converted(),
    ];
    let corpus = match Case::corpus_pair() {
        Some(pair) => {
            cases.extend(pair);
            true
        }
        None => false,
    };
    let runners: Vec<Runner<'_>> = cases
        .iter()
        .map(|c| Runner::new(&c.loaded.model, &c.loaded.set, &c.cfg))
        .collect();
    let mut sims: Vec<Simulator<'_>> = cases
        .iter()
        .map(|c| Simulator::new(&c.loaded.model))
        .collect();
    // `--only K`: time configuration K alone (for a profiler); the ratios then mean nothing.
    let only = args
        .iter()
        .any(|a| a == "--only")
        .then(|| arg(&args, "--only", 0) as usize);
    // Warm-up: fills the runners' pools and the simulators' buffers.
    for (i, c) in cases.iter().enumerate() {
        if only.is_some_and(|k| k != i) {
            continue;
        }
        judged_pass(&runners[i], 1);
        sim_pass(&mut sims[i], &c.cfg, 1);
    }
    let n = cases.len();
    let mut judged = vec![Vec::new(); n];
    let mut alone = vec![Vec::new(); n];
    let mut steps = vec![0u64; n];
    for _ in 0..reps {
        for i in (0..n).filter(|&i| only.is_none_or(|k| k == i)) {
            let (dt, s) = judged_pass(&runners[i], runs);
            judged[i].push(dt);
            steps[i] = s;
            let (dt, _) = sim_pass(&mut sims[i], &cases[i].cfg, runs);
            alone[i].push(dt);
        }
    }
    println!(
        "museum guide: {runs} runs of 100.1 s model time per pass, median of {reps} passes (seed 1)\n"
    );
    println!("| configuration                  |  runs/s | steps/run | sim only runs/s |");
    println!("|--------------------------------|---------|-----------|-----------------|");
    let mut rate = vec![0.0; n];
    let mut sim_rate = vec![0.0; n];
    for i in (0..n).filter(|&i| only.is_none_or(|k| k == i)) {
        rate[i] = runs as f64 / median(&mut judged[i]);
        sim_rate[i] = runs as f64 / median(&mut alone[i]);
        println!(
            "| {:<30} | {:>7.1} | {:>9} | {:>15.1} |",
            cases[i].name,
            rate[i],
            steps[i] / runs,
            sim_rate[i]
        );
    }
    println!();
    println!(
        "ratio guide (as2fm) / its own plain translation (convert): {:.2}x runs/s, simulator alone {:.2}x (goal: >= 1)",
        rate[0] / rate[5],
        sim_rate[0] / sim_rate[5]
    );
    if corpus {
        println!(
            "ratio uc3 high-level / AS2FM's own plain translation of it: {:.2}x runs/s, simulator alone {:.2}x (goal: >= 1)",
            rate[6] / rate[7],
            sim_rate[6] / sim_rate[7]
        );
    }
    println!(
        "context: guide (as2fm) / paper's older translation (museum-scxml, queues): {:.2}x runs/s, simulator alone {:.2}x",
        rate[0] / rate[2],
        sim_rate[0] / sim_rate[2]
    );
    println!(
        "context: guide (as2fm) / paper's older translation (museum-scxml, as2fm):  {:.2}x runs/s, simulator alone {:.2}x",
        rate[0] / rate[3],
        sim_rate[0] / sim_rate[3]
    );
    println!(
        "context: guide (halts when needed) / paper's older translation (queues): {:.2}x runs/s, simulator alone {:.2}x",
        rate[4] / rate[2],
        sim_rate[4] / sim_rate[2]
    );
}
