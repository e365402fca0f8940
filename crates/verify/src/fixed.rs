//! Fixed-size studies (`verify --runs R [--shard I/N]`): what identifies one, so that
//! `merge` refuses to mix the shards of different studies. The shards themselves run
//! through `crate::study::study_shard`, the same runner as every other study.
//!
//! ```
//! use hindsight_verify::fixed::fingerprint;
//!
//! // Stable across runs and machines, and the parts are kept apart.
//! assert_eq!(fingerprint(&[b"ab"]), fingerprint(&[b"ab"]));
//! assert_ne!(fingerprint(&[b"ab"]), fingerprint(&[b"a", b"b"]));
//! assert_eq!(fingerprint(&[]).len(), 16);
//! ```

use std::path::Path;

use crate::load::Loaded;
use crate::sim::{RunConfig, Scheduler};
use crate::smc::shard::{FixedStudy, PropertySpec, StudyPaths};
use crate::smc::stats::RuleConfig;

/// FNV-1a over bytes (each part ended by `0xff`), as 16 hex digits: a stable
/// fingerprint so `merge` can refuse mixed studies.
pub fn fingerprint(parts: &[&[u8]]) -> String {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for p in parts {
        for b in p.iter().chain(&[0xff]) {
            h ^= *b as u64;
            h = h.wrapping_mul(0x0100_0000_01b3);
        }
    }
    format!("{h:016x}")
}

/// What identifies the fixed-size study of `runs` runs of `loaded` (read from
/// `model_path`) with `seed`, `run_cfg` and `rule`: what `merge` compares across shards.
/// The property file is fingerprinted by its bytes (an unreadable one as empty).
pub(crate) fn fixed_study(
    loaded: &Loaded,
    model_path: &Path,
    seed: u64,
    run_cfg: &RunConfig,
    rule: &RuleConfig,
    runs: u64,
) -> FixedStudy {
    let model = &loaded.model;
    let props_text = std::fs::read(&loaded.props_path).unwrap_or_default();
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
        seed,
        study_runs: runs,
        model: format!("{} ({model_desc})", fingerprint(&[model_desc.as_bytes()])),
        properties_fingerprint: fingerprint(&[&props_text]),
        properties: loaded
            .set
            .guarantee_names()
            .iter()
            .map(|id| PropertySpec {
                id: id.clone(),
                rule: *rule,
            })
            .collect(),
        paths: Some(StudyPaths {
            model: model_path.display().to_string(),
            properties: loaded.props_path.display().to_string(),
            replay: serde_json::to_value(crate::replay::Replay::of(loaded, model_path, run_cfg))
                .ok(),
        }),
    }
}
