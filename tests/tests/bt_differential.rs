//! Differential test of the behavior-tree lowering against the oracle: seeded random
//! trees over every supported node kind, random leaf scripts; root status at every tick
//! and every leaf tick and halt must agree (AS2FM's reading; both `Halts` rules).
//!
//! `HINDSIGHT_BT_TREES` sets how many trees (default 10,000); `HINDSIGHT_BT_SEED` the
//! first seed.

mod bt_common;

use bt_common::{diff, lowered, reference, show};
use hindsight::robot::bt::Halts;
use hindsight_tests::bt::gen;
use hindsight_tests::bt::oracle::Reading;
use rand_core::SeedableRng;
use rand_xoshiro::Xoshiro256PlusPlus;

fn env(name: &str, default: u64) -> u64 {
    std::env::var(name)
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

#[test]
fn random_trees_lower_to_what_the_oracle_does() {
    let n = env("HINDSIGHT_BT_TREES", 10_000);
    let seed0 = env("HINDSIGHT_BT_SEED", 0);
    let threads = std::thread::available_parallelism()
        .map_or(1, |p| p.get())
        .min(4) as u64;
    let start = std::time::Instant::now();
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
                        let halts = if seed % 2 == 0 {
                            Halts::As2fm
                        } else {
                            Halts::WhenNeeded
                        };
                        let want = reference(&c.xml, &c.scripts, c.ticks, Reading::As2fm);
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
    assert!(
        fails.is_empty(),
        "{} disagreements:\n{}",
        fails.len(),
        fails.join("\n")
    );
}
