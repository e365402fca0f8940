//! Tests of sharded fixed-size studies: shard ranges, partial result files, and merging.

use hindsight::verify::smc::{
    merge, run_fixed_study, run_shard, FixedStudy, PartialResult, Progress, PropertySpec,
    RuleConfig, RuleKind, RunEnd, RunOutcome, Shard, ShardError, StudyConfig, Verdict,
};
use rand_core::Rng;
use rand_xoshiro::Xoshiro256PlusPlus;

fn uniform(rng: &mut Xoshiro256PlusPlus) -> f64 {
    (rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64
}

/// Property 0 holds with probability 0.3, property 1 with 0.9; 10% of runs violate the
/// assumption and 5% are cut short with property 1 unknown.
fn run(_: u64, rng: &mut Xoshiro256PlusPlus) -> RunOutcome {
    let assume = uniform(rng) >= 0.1;
    let cut = uniform(rng) < 0.05;
    let first = uniform(rng) < 0.3;
    let second = uniform(rng) < 0.9;
    RunOutcome {
        verdicts: vec![
            Verdict::from(first),
            if cut {
                Verdict::Unknown
            } else {
                Verdict::from(second)
            },
        ],
        assumptions: Verdict::from(assume),
        end: if cut {
            RunEnd::StepLimit
        } else {
            RunEnd::TimeHorizon
        },
        steps: 7,
        time: 50,
    }
}

fn study(seed: u64, runs: u64) -> FixedStudy {
    let rule = |kind| RuleConfig {
        kind,
        confidence: 0.95,
        precision: 0.05,
    };
    FixedStudy {
        seed,
        study_runs: runs,
        model: "model-sha256:abc".to_owned(),
        properties_fingerprint: "props-sha256:def".to_owned(),
        properties: vec![
            PropertySpec {
                id: "rare".to_owned(),
                rule: rule(RuleKind::ClopperPearson),
            },
            PropertySpec {
                id: "often".to_owned(),
                rule: rule(RuleKind::Sprt { threshold: 0.8 }),
            },
        ],
        paths: None,
    }
}

fn config(threads: usize) -> StudyConfig {
    StudyConfig {
        threads,
        keep_failing: 4,
        ..StudyConfig::default()
    }
}

fn quiet(_: &Progress<'_>) {}

fn shards(study: &FixedStudy, count: u64) -> Vec<PartialResult> {
    (0..count)
        .map(|index| {
            let shard = Shard::new(index, count).expect("valid shard");
            run_shard(
                &config(1 + index as usize % 3),
                study,
                shard,
                run,
                &mut quiet,
            )
        })
        .collect()
}

#[test]
fn shard_ranges_tile_the_study() {
    for runs in [0u64, 1, 7, 100, 1001] {
        for count in [1u64, 2, 3, 8, 13] {
            let mut next = 0;
            for index in 0..count {
                let range = Shard::new(index, count).expect("valid").range(runs);
                assert_eq!(range.start, next);
                assert!(range.end >= range.start);
                next = range.end;
            }
            assert_eq!(next, runs);
        }
    }
}

#[test]
fn shard_syntax() {
    assert_eq!("2/5".parse::<Shard>(), Ok(Shard { index: 2, count: 5 }));
    assert_eq!(" 0 / 1 ".parse::<Shard>(), Ok(Shard::WHOLE));
    for bad in ["5/5", "1/0", "x/2", "3", "-1/4", ""] {
        assert!(
            matches!(bad.parse::<Shard>(), Err(ShardError::Invalid(_))),
            "{bad}"
        );
    }
    assert_eq!(Shard::new(3, 4).expect("valid").to_string(), "3/4");
}

#[test]
fn sharded_study_equals_the_single_machine_study() {
    let study = study(77, 2000);
    let whole = run_fixed_study(&config(1), &study, run, &mut quiet).expect("merges");
    for count in [2, 5] {
        let mut parts = shards(&study, count);
        parts.reverse();
        let merged = merge(&parts, 4).expect("merges");
        assert_eq!(merged.properties, whole.properties, "{count} shards");
        assert_eq!(merged.runs, whole.runs);
        assert_eq!(merged.shards, count);
    }
    assert_eq!(whole.runs.runs, 2000);
    let rare = &whole.properties[0];
    let often = &whole.properties[1];
    assert_eq!(rare.counts.judged() + whole.runs.discarded, 2000);
    assert!(rare.interval.contains(0.3), "{:?}", rare.interval);
    assert!(often.counts.unknown > 0);
    assert!(often.interval.contains(0.9), "{:?}", often.interval);
    assert_eq!(
        often.estimate.decision,
        Some(hindsight::verify::smc::Decision::Accept)
    );
    assert_eq!(rare.failing_runs.len(), 4);
    assert!(rare.failing_runs.windows(2).all(|w| w[0] < w[1]));
}

#[test]
fn partial_results_round_trip_through_json() {
    let study = study(5, 300);
    let part = &shards(&study, 3)[1];
    let text = part.to_json();
    assert!(text.contains("\"format\": \"hindsight-partial-1\""));
    assert!(text.contains("model-sha256:abc"));
    assert_eq!(&PartialResult::from_json(&text).expect("parses"), part);
    assert!(matches!(
        PartialResult::from_json("{\"format\": 3}"),
        Err(ShardError::Json(_))
    ));
    let other = text.replace("hindsight-partial-1", "hindsight-partial-0");
    assert_eq!(
        PartialResult::from_json(&other),
        Err(ShardError::Format("hindsight-partial-0".to_owned()))
    );
}

#[test]
fn merge_rejects_incomplete_or_foreign_shards() {
    let study = study(5, 300);
    let parts = shards(&study, 3);
    assert_eq!(merge(&[], 0), Err(ShardError::Empty));
    // Every missing shard is named, not only the first.
    assert_eq!(
        merge(&parts[1..2], 0),
        Err(ShardError::Missing(vec![
            Shard { index: 0, count: 3 },
            Shard { index: 2, count: 3 }
        ]))
    );
    let err = merge(&parts[..2], 0).unwrap_err().to_string();
    assert!(err.starts_with("shard 2/3 is missing: run each"), "{err}");
    // A shard re-run by the batch system is identical: counted once.
    let twice = [
        parts[0].clone(),
        parts[1].clone(),
        parts[1].clone(),
        parts[2].clone(),
    ];
    assert_eq!(merge(&twice, 0), merge(&parts, 0));
    assert_eq!(
        hindsight::verify::smc::shard::duplicates(&twice),
        vec![(Shard { index: 1, count: 3 }, vec![1, 2])]
    );
    // Two different copies of one shard are an error.
    let mut differ = twice.clone();
    differ[2].runs.discarded += 1;
    assert_eq!(
        merge(&differ, 0),
        Err(ShardError::Duplicate(Shard { index: 1, count: 3 }))
    );

    let foreign = shards(&self::study(6, 300), 3);
    let mixed = [parts[0].clone(), foreign[1].clone(), parts[2].clone()];
    assert_eq!(
        merge(&mixed, 0),
        Err(ShardError::Mismatch {
            field: "seed",
            shard: Shard { index: 1, count: 3 }
        })
    );

    let mut other_model = parts.clone();
    other_model[2].study.model = "model-sha256:other".to_owned();
    assert!(matches!(
        merge(&other_model, 0),
        Err(ShardError::Mismatch { field: "model", .. })
    ));

    let mut other_size = parts.clone();
    other_size[0].study.study_runs = 301;
    assert!(matches!(
        merge(&other_size, 0),
        Err(ShardError::Mismatch {
            field: "study_runs",
            ..
        })
    ));

    let halves = shards(&study, 2);
    let mixed_counts = [parts[0].clone(), halves[1].clone()];
    assert!(matches!(
        merge(&mixed_counts, 0),
        Err(ShardError::Mismatch {
            field: "shard count",
            ..
        })
    ));

    let mut short = parts.clone();
    short[1].runs.runs -= 1;
    assert_eq!(
        merge(&short, 0),
        Err(ShardError::Range(Shard { index: 1, count: 3 }))
    );

    let mut renamed = parts;
    renamed[0].properties[1].id = "other".to_owned();
    assert!(matches!(
        merge(&renamed, 0),
        Err(ShardError::Mismatch {
            field: "properties",
            ..
        })
    ));
}
