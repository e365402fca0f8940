//! `hindsight verify --bt both`: one study under AS2FM's node models and one under
//! BehaviorTree.CPP 4, side by side, and which properties are semantics-sensitive.

use super::{interrupt_flag, interrupted_error, interrupted_line, VerifyArgs};
use crate::cli::CliError;
use crate::verify::options::VerifyOptions;
use crate::verify::pipeline::{verify_both, Event};

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
    if args.shard.is_some() || args.plan.is_some() {
        // A shard's part, or a stage's plan, is one study's: `merge` would not know which
        // semantics it was.
        return refuse("--shard / --plan");
    }
    if args.report.is_some() || args.save_failing > 0 {
        return refuse("--report / --save-failing");
    }
    let semantics = args.input.semantics()?;
    let loads = semantics
        .iter()
        .map(|&bt| crate::cli::load_model(&args.input.options_with(bt)?))
        .collect::<Result<Vec<_>, CliError>>()?;
    let ([a, b], [bt_a, bt_b]) = (
        [&loads[0], &loads[1]],
        [semantics[0].label(), semantics[1].label()],
    );
    let show = !args.json;
    let mut bar = super::progress_bar(show);
    let both = verify_both(
        [(bt_a, a), (bt_b, b)],
        &args.input.model,
        opts,
        args.runs,
        &mut |label| {
            if show {
                eprintln!("--bt {label}:");
            }
        },
        &mut |e| match e {
            Event::Runs(p) => bar.update(p),
            Event::Bounds(s) if show => super::schedulers::say_stage(s),
            _ => {}
        },
        interrupt_flag(),
    )
    .map_err(super::verify_error)?;
    for line in &both.left_out {
        eprintln!("interrupted: {line}");
    }
    for ((label, study), loaded) in both.studies.iter().zip(&loads) {
        if let Some(line) = study.unjudged_line() {
            eprintln!("--bt {label}: {line}");
        }
        let note = opts.run_config(loaded).ok().and_then(|cfg| {
            loaded.deadlock_note(cfg.max_time, study.quiescent, study.runs, opts.seed)
        });
        if let Some(note) = note {
            eprintln!("--bt {label}: {note}");
        }
    }
    let rows = &both.rows;
    let [(_, a), (bt, b)] = both.studies.as_slice() else {
        unreachable!("--bt both names two semantics")
    };
    let (interrupted, done) = (both.interrupted(), both.runs());
    if args.json {
        let mut doc = serde_json::json!({
            "bt": "both",
            "as2fm": a,
            "btcpp": b,
            "btcpp_semantics": bt,
            "properties": rows,
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
    for r in rows {
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
        a.runs, bt, b.runs, opts.seed, opts.rule.confidence, opts.rule.precision
    );
    for (bt, s) in &both.studies {
        if s.properties.iter().any(|p| p.schedulers.is_some()) {
            println!();
            println!("--bt {bt}:");
            super::schedulers::print_bounds(s);
        }
    }
    if interrupted {
        return Err(interrupted_error(done));
    }
    Ok(())
}
