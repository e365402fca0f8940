//! Shrinks random trees on which AS2FM's reading and BT.CPP 4's (the real library's, as
//! `bt_real.rs` holds it) give other root statuses to minimal ones: the source of the
//! README's table of differences (`tests/bt/real/differences.toml`, where each one found
//! is kept and checked against the real library).
//!
//! `cargo test -p hindsight-tests --test bt_shrink -- --ignored --nocapture` prints the
//! smallest minimal tree of each set of node kinds among the first `HINDSIGHT_BT_SHRINK` (default 200) differing
//! seeds; the plain run checks the shrinker on one seed.

use hindsight_tests::bt::gen;
use hindsight_tests::bt::oracle::{run_with, Options, Reading, Scripts, TickMode};
use hindsight_tests::bt::tree::{self, El, Status};
use rand_core::SeedableRng;
use rand_xoshiro::Xoshiro256PlusPlus;
use std::collections::BTreeSet;

/// A case being shrunk.
#[derive(Clone, Debug)]
struct Case {
    doc: El,
    scripts: Scripts,
    ticks: usize,
    mode: TickMode,
}

impl Case {
    fn xml(&self) -> String {
        let mut s = String::new();
        self.doc.write(&mut s);
        s
    }

    fn size(&self) -> usize {
        fn n(e: &El) -> usize {
            1 + e.attrs.len() + e.children.iter().map(n).sum::<usize>()
        }
        n(&self.doc) + self.scripts.values().map(|s| s.len()).sum::<usize>() + self.ticks
    }

    /// Both readings' root statuses when both run every tick and they differ.
    fn differs(&self) -> Option<(Vec<Status>, Vec<Status>)> {
        let xml = self.xml();
        let t = tree::read(&xml).ok()?;
        // Every leaf needs a script; unused scripts are dropped by the shrinker.
        let bt = run_with(&t, &self.scripts, Options::xml4(self.mode), self.ticks).ok()?;
        let as2 = run_with(&t, &self.scripts, Options::of(Reading::As2fm), self.ticks).ok()?;
        if bt.end.is_some() || as2.end.is_some() || bt.statuses == as2.statuses {
            return None;
        }
        if hindsight_tests::bt::oracle::btcpp4_refuses(&t, &self.scripts).is_some() {
            return None;
        }
        Some((bt.statuses, as2.statuses))
    }
}

/// Every element path (indices from the root) in the document.
fn paths(e: &El, at: &mut Vec<usize>, out: &mut Vec<Vec<usize>>) {
    out.push(at.clone());
    for (i, c) in e.children.iter().enumerate() {
        at.push(i);
        paths(c, at, out);
        at.pop();
    }
}

fn get_mut<'a>(e: &'a mut El, path: &[usize]) -> &'a mut El {
    path.iter().fold(e, |e, &i| &mut e.children[i])
}

/// Smaller variants of `c`, most promising first.
fn candidates(c: &Case) -> Vec<Case> {
    let mut out = Vec::new();
    let mut ps = Vec::new();
    paths(&c.doc, &mut Vec::new(), &mut ps);
    for p in &ps {
        if p.len() < 2 {
            continue;
        }
        let node = get_mut(&mut c.doc.clone(), p).clone();
        // The node replaced by one of its children.
        for k in 0..node.children.len() {
            let mut d = c.clone();
            *get_mut(&mut d.doc, p) = node.children[k].clone();
            out.push(d);
        }
        // The node removed from its parent.
        let mut d = c.clone();
        let (last, parent) = p.split_last().expect("len >= 2");
        get_mut(&mut d.doc, parent).children.remove(*last);
        out.push(d);
        // A SubTree's remapping dropped, an unused tree dropped.
        for k in node
            .attrs
            .keys()
            .filter(|k| node.name == "SubTree" && *k != "ID")
        {
            let mut d = c.clone();
            get_mut(&mut d.doc, p).attrs.remove(k);
            out.push(d);
        }
        // A count made smaller.
        for k in ["num_cycles", "num_attempts"] {
            if let Some(v) = node.attrs.get(k).and_then(|v| v.parse::<i64>().ok()) {
                if v > 1 {
                    let mut d = c.clone();
                    get_mut(&mut d.doc, p)
                        .attrs
                        .insert(k.into(), (v - 1).to_string());
                    out.push(d);
                }
            }
        }
    }
    for (name, s) in &c.scripts {
        for i in 0..s.len() {
            if s.len() > 1 {
                let mut d = c.clone();
                d.scripts.get_mut(name).expect("script").remove(i);
                out.push(d);
            }
        }
    }
    if c.ticks > 1 {
        let mut d = c.clone();
        d.ticks -= 1;
        out.push(d);
    }
    out
}

/// Drops the scripts of leaf types no longer in the tree.
fn tidy(mut c: Case) -> Case {
    let xml = c.xml();
    c.scripts.retain(|k, _| xml.contains(&format!("<{k}/>")));
    c
}

fn shrink(mut c: Case) -> Case {
    loop {
        let size = c.size();
        let better = candidates(&c)
            .into_iter()
            .map(tidy)
            .find(|d| d.size() < size && d.differs().is_some());
        match better {
            Some(d) => c = d,
            None => return c,
        }
    }
}

fn case(seed: u64, mode: TickMode) -> Option<Case> {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    let g = gen::case(&mut rng, 4 + (seed % 12) as i64);
    if g.xml.contains("BTCPP_format=\"3\"") {
        return None;
    }
    let c = Case {
        doc: tree::parse_xml(&g.xml).ok()?,
        scripts: g.scripts,
        ticks: g.ticks,
        mode,
    };
    c.differs().map(|_| c)
}

fn show(c: &Case) -> String {
    let (bt, as2) = c.differs().expect("differs");
    let names = |v: &[Status]| v.iter().map(|s| s.name()).collect::<Vec<_>>();
    format!(
        "mode = {:?}, ticks = {}\ntree = '''{}'''\nscripts = {:?}\nBT.CPP {:?}\nAS2FM  {:?}\n",
        c.mode,
        c.ticks,
        c.xml(),
        c.scripts
            .iter()
            .map(|(k, v)| (k.clone(), names(v)))
            .collect::<Vec<_>>(),
        names(&bt),
        names(&as2)
    )
}

#[test]
fn a_difference_shrinks_to_a_few_nodes_and_stays_a_difference() {
    let (seed, c) = (0..2000)
        .find_map(|s| case(s, TickMode::ExactlyOnce).map(|c| (s, c)))
        .expect("some seed differs");
    let before = c.size();
    let m = shrink(c);
    assert!(
        m.differs().is_some(),
        "seed {seed}: the minimal tree must still differ"
    );
    assert!(
        m.size() < before && m.size() <= 30,
        "seed {seed}: {before} -> {}\n{}",
        m.size(),
        show(&m)
    );
}

#[test]
#[ignore = "a tool: prints the minimal differences for the README's table"]
fn print_minimal_differences() {
    let n: usize = std::env::var("HINDSIGHT_BT_SHRINK")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(200);
    let mut seen = std::collections::BTreeMap::new();
    let mut found = 0;
    for seed in 0.. {
        if found >= n {
            break;
        }
        for mode in [TickMode::ExactlyOnce, TickMode::Once] {
            let Some(c) = case(seed, mode) else { continue };
            found += 1;
            let m = shrink(c);
            // One per set of node kinds (leaf types aside), the smallest.
            let t = tree::read(&m.xml()).expect("tree");
            let kinds: BTreeSet<String> = t
                .nodes
                .iter()
                .filter(|n| !matches!(n.kind, hindsight_tests::bt::tree::Kind::Leaf(_)))
                .map(|n| n.tag.clone())
                .collect();
            let key = format!("{:?} {kinds:?}", m.mode);
            let smaller = seen
                .get(&key)
                .is_none_or(|(s, _): &(usize, String)| m.size() < *s);
            if smaller {
                seen.insert(key, (m.size(), format!("seed {seed}:\n{}", show(&m))));
            }
        }
    }
    for (k, (_, text)) in &seen {
        eprintln!("{k}\n{text}");
    }
    eprintln!(
        "{} kinds of minimal trees from {found} differing runs",
        seen.len()
    );
}
