//! Differential test of the behavior-tree lowering against the oracle: seeded random
//! trees over every supported node kind, random leaf scripts; root status at every tick
//! and every leaf tick and halt must agree (AS2FM's reading; both `Halts` rules).
//!
//! A run of 1,000 trees or more also checks that each feature of the generator
//! ([`FEATURES`]) appears in at least one tree in 200.
//!
//! `HINDSIGHT_BT_TREES` sets how many trees (default 10,000); `HINDSIGHT_BT_SEED` the
//! first seed.

mod bt_common;

use bt_common::{diff, lowered, reference, show};
use hindsight::verify::robot::bt::Halts;
use hindsight_tests::bt::oracle::LeafEvent;
use hindsight_tests::bt::oracle::Reading;
use hindsight_tests::bt::tree::{self, Kind};
use hindsight_tests::bt::{gen, model};
use rand_core::SeedableRng;
use rand_xoshiro::Xoshiro256PlusPlus;

fn env(name: &str, default: u64) -> u64 {
    std::env::var(name)
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

/// The log without the halts of leaves whose plugin has no `<bt_halt>`: under
/// `Halts::WhenNeeded` the lowering does not send them (such a halt changes nothing).
fn without_halts_to_haltless(xml: &str, log: &[LeafEvent]) -> Vec<LeafEvent> {
    let t = tree::read(xml).expect("the oracle read it");
    let silent: std::collections::BTreeSet<u32> = t
        .nodes
        .iter()
        .filter(|n| matches!(&n.kind, Kind::Leaf(ty) if !model::has_halt(ty)))
        .map(|n| n.id)
        .collect();
    log.iter()
        .copied()
        .filter(|e| !matches!(e, LeafEvent::Halt(id) if silent.contains(id)))
        .collect()
}

/// Features of the generator that must show up in a run, as text of the tree.
const FEATURES: &[&str] = &[
    "BTCPP_format=\"3\"",
    "<SequenceStar>",
    "<SubTreePlus",
    "__shared_blackboard=\"true\"",
    "__autoremap=\"true\"",
    " _autoremap=\"true\"",
    "d0=\"d0\"",
    "<BlackboardCheckDouble",
    "<BlackboardCheckString",
    "<BlackboardCheckBool",
    "value_B=\"1.50000005\"",
    "return_on_mismatch=\"3\"",
    "value=\"{",
    "num_cycles=\"-1\"",
    "num_attempts=\"-1\"",
    "RetryUntilSuccesful ",
    "<N",
];

#[test]
fn random_trees_lower_to_what_the_oracle_does() {
    let n = env("HINDSIGHT_BT_TREES", 10_000);
    let seed0 = env("HINDSIGHT_BT_SEED", 0);
    let threads = std::thread::available_parallelism()
        .map_or(1, |p| p.get())
        .min(4) as u64;
    let start = std::time::Instant::now();
    let seen: Vec<std::sync::atomic::AtomicUsize> =
        FEATURES.iter().map(|_| Default::default()).collect();
    let seen = &seen;
    let fails: Vec<String> = std::thread::scope(|s| {
        let hs: Vec<_> = (0..threads)
            .map(|t| {
                s.spawn(move || {
                    let mut fails = Vec::new();
                    let mut i = t;
                    while i < n && fails.len() < 3 {
                        let seed = seed0 + i;
                        let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
                        let c = gen::case(&mut rng, 4 + (seed % 12) as i64);
                        for (f, n) in FEATURES.iter().zip(seen) {
                            if c.xml.contains(f) {
                                n.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                            }
                        }
                        let halts = if seed % 2 == 0 {
                            Halts::As2fm
                        } else {
                            Halts::WhenNeeded
                        };
                        let mut want = reference(&c.xml, &c.scripts, c.ticks, Reading::As2fm);
                        if halts == Halts::WhenNeeded {
                            if let Ok(w) = &mut want {
                                w.1 = without_halts_to_haltless(&c.xml, &w.1);
                            }
                        }
                        let got = lowered(&c.xml, &c.scripts, c.ticks, halts);
                        let problem = match (&want, &got) {
                            (Ok(w), Ok(g)) => {
                                diff(w, g).map(|d| format!("oracle vs lowering: {d}"))
                            }
                            (Err(e), _) => Some(format!("oracle: {e}")),
                            (_, Err(e)) => Some(format!("lowering: {e}")),
                        };
                        if let Some(p) = problem {
                            fails.push(format!(
                                "seed {seed} ({halts:?}): {p}\n{}",
                                show(&c.xml, &c.scripts, c.ticks)
                            ));
                        }
                        i += threads;
                    }
                    fails
                })
            })
            .collect();
        hs.into_iter()
            .flat_map(|h| h.join().expect("worker"))
            .collect()
    });
    eprintln!(
        "{n} random trees in {:.1} s on {threads} threads",
        start.elapsed().as_secs_f64()
    );
    if n >= 1000 {
        for (f, k) in FEATURES.iter().zip(seen) {
            let k = k.load(std::sync::atomic::Ordering::Relaxed);
            eprintln!("  {k:>6} trees with `{f}`");
            assert!(k as u64 >= n / 200, "only {k} of {n} trees have `{f}`");
        }
    }
    assert!(
        fails.is_empty(),
        "{} disagreements:\n{}",
        fails.len(),
        fails.join("\n")
    );
}
