//! `hindsight verify --bt both`: one study under AS2FM's node models and one under
//! BehaviorTree.CPP 4, side by side, and which properties are semantics-sensitive.

use super::{
    interrupt_flag, interrupted_error, interrupted_line, max_time_error, study_until, VerifyArgs,
};
use crate::cli::CliError;
use crate::verify::options::VerifyOptions;
use crate::verify::result::{PropertyRow, Study};

/// `verify --bt both`: the study under AS2FM's node models and under BehaviorTree.CPP 4,
/// each with the same seed and settings, and per property both probabilities and
/// whether they differ beyond the precision (the two intervals are disjoint:
/// "semantics-sensitive").
pub(super) fn run_both(args: &VerifyArgs, opts: &VerifyOptions) -> Result<(), CliError> {
    let refuse = |what: &str| {
        Err(CliError::Input(format!(
            "--bt both: not with {what} (run each semantics with --bt as2fm / --bt btcpp)"
        )))
    };
    if args.shard.is_some() || args.runs.is_some() {
        return refuse("--runs / --shard");
    }
    if args.report.is_some() || args.save_failing > 0 {
        return refuse("--report / --save-failing");
    }
    let mut studies = Vec::new();
    let stop = interrupt_flag();
    for bt in args.input.semantics()? {
        let loaded = crate::cli::load_model(&args.input.options_with(bt)?)?;
        let run_cfg = opts.run_config(&loaded).map_err(max_time_error)?;
        // `--report` and `--save-failing` are refused above: no failing run is kept.
        let study_cfg = opts.study_config();
        if !args.json {
            eprintln!("--bt {}:", bt.label());
        }
        // Once interrupted, the next semantics' study starts no run (0 runs, no estimate).
        let mut bar = super::progress_bar(!args.json);
        let result = study_until(
            &loaded.model,
            &loaded.set,
            &run_cfg,
            &study_cfg,
            &opts.rule,
            &mut |p| bar.update(p),
            stop,
        )
        .map_err(|e| CliError::Input(e.to_string()))?;
        let mut r = Study::of_result(
            &args.input.model,
            &loaded.props_path,
            &loaded.set,
            &opts.rule,
            opts.seed,
            opts.scheduler,
            &result,
        );
        r.settings.push(("bt".into(), bt.label().into()));
        r.set_time_unit(loaded.unit_ns, run_cfg.max_time);
        // `--schedulers`: the bounds under each semantics, on the same seed.
        if !result.interrupted
            && !super::schedulers::add_bounds(
                opts, !args.json, &loaded, &run_cfg, &study_cfg, &mut r, stop,
            )?
        {
            eprintln!("interrupted: the bounds over schedulers are left out");
            r.interrupted = true;
        }
        studies.push((bt, r));
    }
    let [(_, a), (bt, b)] = studies.as_slice() else {
        unreachable!("--bt both names two semantics")
    };
    let rows: Vec<Sensitivity> = a
        .properties
        .iter()
        .zip(&b.properties)
        .map(|(x, y)| Sensitivity::of(x, y))
        .collect();
    let interrupted = a.interrupted || b.interrupted;
    let done = a.runs + b.runs;
    if args.json {
        let mut doc = serde_json::json!({
            "bt": "both",
            "as2fm": a,
            "btcpp": b,
            "btcpp_semantics": bt.label(),
            "properties": rows.iter().map(|r| serde_json::json!({
                "property": r.property,
                "as2fm": r.as2fm,
                "btcpp": r.btcpp,
                "difference": r.difference,
                "semantics_sensitive": r.sensitive,
            })).collect::<Vec<_>>(),
        });
        if interrupted {
            doc["interrupted"] = true.into();
        }
        let text = serde_json::to_string_pretty(&doc)
            .map_err(|e| CliError::Failed(format!("json: {e}")))?;
        println!("{text}");
        return if interrupted {
            Err(interrupted_error(done))
        } else {
            Ok(())
        };
    }
    if interrupted {
        println!("{}", interrupted_line(done));
    }
    let w = rows
        .iter()
        .map(|r| r.property.len())
        .max()
        .unwrap_or(8)
        .max(8);
    let p = |x: Option<f64>| x.map_or("-".to_string(), |x| format!("{x:.4}"));
    println!(
        "{:<w$}  {:>8}  {:>8}  {:>10}  semantics-sensitive",
        "property", "as2fm", "btcpp", "difference"
    );
    for r in &rows {
        println!(
            "{:<w$}  {:>8}  {:>8}  {:>10}  {}",
            r.property,
            p(r.as2fm),
            p(r.btcpp),
            r.difference.map_or("-".into(), |d| format!("{d:+.4}")),
            if r.sensitive { "yes" } else { "no" }
        );
    }
    println!(
        "as2fm: {} runs; {}: {} runs; seed {}, confidence {}, precision {}; \
         semantics-sensitive: the two intervals (±precision) are disjoint",
        a.runs,
        bt.label(),
        b.runs,
        opts.seed,
        opts.rule.confidence,
        opts.rule.precision
    );
    for (bt, s) in &studies {
        if s.properties.iter().any(|p| p.schedulers.is_some()) {
            println!();
            println!("--bt {}:", bt.label());
            super::schedulers::print_bounds(s);
        }
    }
    if interrupted {
        return Err(interrupted_error(done));
    }
    Ok(())
}

/// One property under both semantics.
struct Sensitivity {
    property: String,
    as2fm: Option<f64>,
    btcpp: Option<f64>,
    /// BT.CPP's estimate minus AS2FM's.
    difference: Option<f64>,
    /// The two intervals are disjoint: the difference is beyond the precision.
    sensitive: bool,
}

impl Sensitivity {
    fn of(a: &PropertyRow, b: &PropertyRow) -> Self {
        let difference = a.probability.zip(b.probability).map(|(x, y)| y - x);
        let sensitive = difference.is_some() && (a.upper < b.lower || b.upper < a.lower);
        Sensitivity {
            property: a.property.clone(),
            as2fm: a.probability,
            btcpp: b.probability,
            difference,
            sensitive,
        }
    }
}
