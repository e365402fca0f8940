//! `verify --shard I/N --runs R` and `hindsight merge`: a fixed-size study run as shards,
//! fingerprinted so that `merge` refuses to mix studies, and the merged study's report.

use std::path::{Path, PathBuf};

use super::super::CliError;
use super::{print_report, VerifyArgs};
use crate::cli::progress::TerminalProgress;
use crate::sim::{CompiledModel, RunConfig, Scheduler};
use crate::smc::stats::RuleConfig;
use crate::smc::StudyConfig;
use crate::verify::observe::PropertySet;
use crate::verify::result::{PropertyRow, Study};
use crate::verify::sched_fixed::{merge_stage, StagePart, PART_FORMAT};
use crate::verify::study::Runner;

/// `merge` of the parts of one stage of a scheduler study: the next stage's plan to
/// `--next`, or the report after the last stage.
fn merge_stage_cli(args: &MergeArgs, texts: &[String], staged: &[bool]) -> Result<(), CliError> {
    let mut parts = Vec::new();
    for ((p, text), &is) in args.parts.iter().zip(texts).zip(staged) {
        if !is {
            return Err(CliError::Input(format!(
                "merge: {}: not a part of a scheduler study's stage, while {} is: merge the \
                 parts of one study",
                p.display(),
                args.parts[staged.iter().position(|&s| s).unwrap_or(0)].display()
            )));
        }
        parts.push(
            serde_json::from_str::<StagePart>(text)
                .map_err(|e| CliError::Input(format!("{}: {e}", p.display())))?,
        );
    }
    let plan = merge_stage(&parts).map_err(|e| CliError::Input(format!("merge: {e}")))?;
    if plan.done() {
        let report = super::schedulers::fixed_report(&plan)?;
        return print_report(&report, args.json);
    }
    let Some(next) = &args.next else {
        return Err(CliError::Input(format!(
            "merge: these are the parts of stage {} of a scheduler study, which is not the \
             last: give --next PLAN.json to write stage {}'s plan",
            plan.stage - 1,
            plan.stage
        )));
    };
    let json = serde_json::to_string(&plan).map_err(|e| CliError::Failed(format!("json: {e}")))?;
    std::fs::write(next, json).map_err(|e| CliError::Failed(format!("{}: {e}", next.display())))?;
    eprintln!(
        "merge: stage {} merged; stage {} has {} run ranges: run every shard with --plan {}, \
         then merge their parts",
        plan.stage - 1,
        plan.stage,
        plan.jobs.len(),
        next.display()
    );
    Ok(())
}

/// FNV-1a over bytes: a stable fingerprint so `merge` can refuse mixed studies.
fn fingerprint(parts: &[&[u8]]) -> String {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for p in parts {
        for b in p.iter().chain(&[0xff]) {
            h ^= *b as u64;
            h = h.wrapping_mul(0x0100_0000_01b3);
        }
    }
    format!("{h:016x}")
}

/// What identifies the fixed-size study of `runs` runs that `args` describe: what `merge`
/// compares across shards.
pub(super) fn fixed_study(
    args: &VerifyArgs,
    model: &CompiledModel,
    set: &PropertySet,
    props_path: &Path,
    run_cfg: &RunConfig,
    rule: &RuleConfig,
    runs: u64,
) -> crate::smc::shard::FixedStudy {
    use crate::smc::shard::{FixedStudy, PropertySpec};
    let props_text = std::fs::read(props_path).unwrap_or_default();
    let mut model_desc = format!(
        "{} machines, {} events, max_time {}, max_steps {}",
        model.machine_count(),
        model.event_count(),
        run_cfg.max_time,
        run_cfg.max_steps
    );
    // Shards under different schedulers are different studies: `merge` refuses to mix
    // them (the uniform scheduler's description is unchanged).
    if run_cfg.scheduler != Scheduler::Uniform {
        model_desc.push_str(&format!(", scheduler {}", run_cfg.scheduler));
    }
    FixedStudy {
        seed: args.seed,
        study_runs: runs,
        model: format!("{} ({model_desc})", fingerprint(&[model_desc.as_bytes()])),
        properties_fingerprint: fingerprint(&[&props_text]),
        properties: set
            .guarantee_names()
            .iter()
            .map(|id| PropertySpec {
                id: id.clone(),
                rule: *rule,
            })
            .collect(),
        paths: Some(crate::smc::shard::StudyPaths {
            model: args.input.model.display().to_string(),
            properties: props_path.display().to_string(),
        }),
    }
}

#[allow(clippy::too_many_arguments)]
pub(super) fn run_shard_cli(
    args: &VerifyArgs,
    model: &CompiledModel,
    set: &PropertySet,
    props_path: &Path,
    run_cfg: &RunConfig,
    study_cfg: &StudyConfig,
    rule: &RuleConfig,
    shard: crate::smc::shard::Shard,
    runs: u64,
) -> Result<crate::smc::shard::PartialResult, CliError> {
    use crate::smc::shard::run_shard;
    let fixed = fixed_study(args, model, set, props_path, run_cfg, rule, runs);
    let runner = Runner::new(model, set, run_cfg);
    let mut bar = TerminalProgress::stderr();
    let part = run_shard(
        study_cfg,
        &fixed,
        shard,
        |k, rng| runner.run(k, rng),
        &mut |p| bar.update(p),
    );
    runner
        .finish()
        .map_err(|e| CliError::Input(e.to_string()))?;
    Ok(part)
}

/// Arguments of `hindsight merge`.
#[derive(Debug, clap::Args)]
pub struct MergeArgs {
    /// Partial results written by `verify --shard I/N --runs R`, one per shard.
    #[arg(required = true)]
    pub parts: Vec<PathBuf>,
    /// Print JSON instead of the table.
    #[arg(long)]
    pub json: bool,
    /// For the parts of a stage of a scheduler study (`verify --schedulers N --runs R
    /// --shard I/K`) that is not the last: where to write the next stage's plan (give it
    /// to every shard of that stage with --plan).
    #[arg(long, value_name = "PLAN")]
    pub next: Option<PathBuf>,
}

/// Runs `hindsight merge`: checks the parts cover one study exactly once, then reports it.
pub fn merge(args: &MergeArgs) -> Result<(), CliError> {
    use crate::smc::shard::{duplicates, merge, PartialResult, Shard, ShardError};
    let mut texts = Vec::new();
    for p in &args.parts {
        texts.push(super::super::read_file(p)?);
    }
    let format = |t: &str| -> Option<String> {
        let v: serde_json::Value = serde_json::from_str(t).ok()?;
        Some(v.get("format")?.as_str()?.to_string())
    };
    let staged: Vec<bool> = texts
        .iter()
        .map(|t| format(t).as_deref() == Some(PART_FORMAT))
        .collect();
    if staged.iter().any(|&s| s) {
        return merge_stage_cli(args, &texts, &staged);
    }
    let mut parts = Vec::new();
    for (p, text) in args.parts.iter().zip(texts) {
        parts.push(
            PartialResult::from_json(&text)
                .map_err(|e| CliError::Input(format!("{}: {e}", p.display())))?,
        );
    }
    // Name the files of a shard in every message about it.
    let files_of = |shard: Shard| -> String {
        let names: Vec<String> = args
            .parts
            .iter()
            .zip(&parts)
            .filter(|(_, p)| p.shard.index == shard.index)
            .map(|(f, _)| f.display().to_string())
            .collect();
        names.join(", ")
    };
    let m = merge(&parts, 0).map_err(|e| {
        let shard = match &e {
            ShardError::Mismatch { shard, .. }
            | ShardError::Duplicate(shard)
            | ShardError::Range(shard)
            | ShardError::Counts { shard, .. } => Some(*shard),
            _ => None,
        };
        match shard {
            Some(s) => CliError::Input(format!("merge: {e} ({})", files_of(s))),
            None => CliError::Input(format!("merge: {e}")),
        }
    })?;
    for (shard, _) in duplicates(&parts) {
        eprintln!(
            "merge: shard {shard} is given more than once, identical ({}): counted once",
            files_of(shard)
        );
    }
    print_report(&merged_report(&m), args.json)
}

/// The report of a merged fixed-size study (`merge`, and `verify --runs R` alone).
pub(super) fn merged_report(m: &crate::smc::shard::MergedResult) -> Study {
    let (model, properties_file) = match &m.study.paths {
        Some(p) => (p.model.clone(), p.properties.clone()),
        None => (
            m.study.model.clone(),
            m.study.properties_fingerprint.clone(),
        ),
    };
    Study {
        model,
        properties_file,
        seed: m.study.seed,
        confidence: m.properties.first().map_or(0.0, |p| p.rule.confidence),
        precision: m.properties.first().map_or(0.0, |p| p.rule.precision),
        runs: m.runs.runs,
        discarded: m.runs.discarded,
        time_horizon: m.runs.time_horizon,
        step_limit: m.runs.step_limit,
        decided: m.runs.decided,
        quiescent: m.runs.quiescent,
        interrupted: false,
        scheduler: None,
        seconds: 0.0,
        step_seconds: None,
        max_time_seconds: None,
        settings: Vec::new(),
        properties: m
            .properties
            .iter()
            .map(|p| PropertyRow::new(&p.id, &p.estimate, &p.interval, &p.counts))
            .collect(),
    }
}
