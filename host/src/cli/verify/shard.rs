//! `hindsight merge`: the parts `verify --shard I/N --runs R` wrote (a fixed-size study
//! run as shards, fingerprinted by `verify::fixed` so that `merge` refuses to mix
//! studies), checked and reported as one study (`verify::result::Study::merged`).

use std::path::PathBuf;

use super::super::CliError;
use super::print_report;
use crate::verify::result::Study;
use crate::verify::sched_fixed::{merge_stage, StagePart, PART_FORMAT};

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
        let report = plan.study()?;
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
    print_report(&Study::merged(&m), args.json)
}
