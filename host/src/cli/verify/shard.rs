//! `hindsight merge`: the parts `verify --shard I/N --runs R` wrote (a fixed-size study
//! run as shards, fingerprinted by `verify::fixed` so that `merge` refuses to mix
//! studies), checked and reported as one study (`verify::result::Study::merged`).

use std::path::PathBuf;

use super::super::CliError;
use super::print_report;
use crate::verify::pipeline::{merge_parts, Merged};

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

/// Runs `hindsight merge`: the library checks the parts cover one study exactly once and
/// merges them; this reports the study, or writes the next stage's plan.
pub fn merge(args: &MergeArgs) -> Result<(), CliError> {
    let mut parts = Vec::new();
    for p in &args.parts {
        parts.push((p.display().to_string(), super::super::read_file(p)?));
    }
    match merge_parts(&parts).map_err(|e| CliError::Input(e.to_string()))? {
        Merged::Study(study, twice) => {
            for (shard, files) in twice {
                eprintln!(
                    "merge: shard {shard} is given more than once, identical ({files}): \
                     counted once"
                );
            }
            print_report(&study, args.json)
        }
        Merged::Next(plan) => {
            let Some(next) = &args.next else {
                return Err(CliError::Input(format!(
                    "merge: these are the parts of stage {} of a scheduler study, which is \
                     not the last: give --next PLAN.json to write stage {}'s plan",
                    plan.stage - 1,
                    plan.stage
                )));
            };
            let json =
                serde_json::to_string(&plan).map_err(|e| CliError::Failed(format!("json: {e}")))?;
            std::fs::write(next, json)
                .map_err(|e| CliError::Failed(format!("{}: {e}", next.display())))?;
            eprintln!(
                "merge: stage {} merged; stage {} ({}) has {} run ranges: run every shard \
                 with --plan {}, then merge their parts",
                plan.stage - 1,
                plan.stage,
                plan.stage_kind(),
                plan.jobs.len(),
                next.display()
            );
            Ok(())
        }
    }
}
