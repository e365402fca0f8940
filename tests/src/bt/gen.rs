//! Seeded random behavior trees and leaf scripts for the differential test: every node
//! kind the oracle knows, mixed at random depth and width, SubTrees with remapping, and
//! blackboard writes and reads of two integer entries.

use super::oracle::Scripts;
use super::tree::Status;
use rand_core::Rng;

/// A generated case: the tree XML, the scripts of its leaf types, how many root ticks.
#[derive(Clone, Debug)]
pub struct Case {
    /// The tree document.
    pub xml: String,
    /// The leaf types' scripts.
    pub scripts: Scripts,
    /// Root ticks to run.
    pub ticks: usize,
}

struct G<'r, R: Rng> {
    rng: &'r mut R,
    scripts: Scripts,
    /// Nodes left to place.
    budget: i64,
    /// SubTree definitions written so far (a tree only uses earlier ones).
    subtrees: Vec<String>,
}

impl<R: Rng> G<'_, R> {
    fn below(&mut self, n: u64) -> u64 {
        self.rng.next_u64() % n
    }

    fn status(&mut self) -> Status {
        match self.below(10) {
            0..=3 => Status::Success,
            4..=6 => Status::Failure,
            _ => Status::Running,
        }
    }

    fn leaf(&mut self) -> String {
        let name = format!("L{}", self.scripts.len());
        let len = 1 + self.below(4) as usize;
        let script = (0..len).map(|_| self.status()).collect();
        self.scripts.insert(name.clone(), script);
        format!("<{name}/>")
    }

    fn children(&mut self, depth: u32, lo: u64, hi: u64) -> String {
        let n = lo + self.below(hi - lo + 1);
        (0..n).map(|_| self.node(depth + 1)).collect()
    }

    fn entry(&mut self) -> &'static str {
        if self.below(2) == 0 {
            "k0"
        } else {
            "k1"
        }
    }

    fn node(&mut self, depth: u32) -> String {
        self.budget -= 1;
        if depth >= 5 || self.budget <= 0 || self.below(10) < 3 {
            return match self.below(12) {
                0 => "<AlwaysSuccess/>".into(),
                1 => "<AlwaysFailure/>".into(),
                2 => format!(
                    "<SetBlackboard output_key=\"{}\" value=\"{}\"/>",
                    self.entry(),
                    self.below(3)
                ),
                3 if !self.subtrees.is_empty() => self.subtree_ref(),
                _ => self.leaf(),
            };
        }
        match self.below(18) {
            0 | 1 => format!("<Sequence>{}</Sequence>", self.children(depth, 1, 4)),
            2 | 3 => format!("<Fallback>{}</Fallback>", self.children(depth, 1, 4)),
            4 => format!(
                "<ReactiveSequence>{}</ReactiveSequence>",
                self.children(depth, 1, 3)
            ),
            5 => format!(
                "<ReactiveFallback>{}</ReactiveFallback>",
                self.children(depth, 1, 3)
            ),
            6 | 7 => {
                let tag = if self.below(2) == 0 {
                    "SequenceWithMemory"
                } else {
                    "SequenceStar"
                };
                format!("<{tag}>{}</{tag}>", self.children(depth, 1, 4))
            }
            8 => {
                let n = 1 + self.below(3) as i64;
                let th = |g: &mut Self| {
                    let t = 1 + g.below(n as u64) as i64;
                    if g.below(3) == 0 {
                        t - n - 1
                    } else {
                        t
                    }
                };
                let (s, f) = (th(self), th(self));
                let kids: String = (0..n).map(|_| self.node(depth + 1)).collect();
                format!("<Parallel success_count=\"{s}\" failure_count=\"{f}\">{kids}</Parallel>")
            }
            9 => format!("<IfThenElse>{}</IfThenElse>", self.children(depth, 2, 3)),
            10 => format!("<Inverter>{}</Inverter>", self.node(depth + 1)),
            11 => format!("<ForceSuccess>{}</ForceSuccess>", self.node(depth + 1)),
            12 => format!("<ForceFailure>{}</ForceFailure>", self.node(depth + 1)),
            13 => format!(
                "<Repeat num_cycles=\"{}\">{}</Repeat>",
                self.below(4),
                self.node(depth + 1)
            ),
            14 | 15 => format!(
                "<RetryUntilSuccessful num_attempts=\"{}\">{}</RetryUntilSuccessful>",
                self.below(4),
                self.node(depth + 1)
            ),
            16 => {
                let a = self.entry();
                let b = if self.below(2) == 0 {
                    format!("{{{}}}", self.entry())
                } else {
                    self.below(3).to_string()
                };
                let m = self.status().name();
                format!(
                    "<BlackboardCheckInt value_A=\"{{{a}}}\" value_B=\"{b}\" return_on_mismatch=\"{m}\">{}</BlackboardCheckInt>",
                    self.node(depth + 1)
                )
            }
            _ if !self.subtrees.is_empty() => self.subtree_ref(),
            _ => self.leaf(),
        }
    }

    fn subtree_ref(&mut self) -> String {
        let i = self.below(self.subtrees.len() as u64);
        let remap = match self.below(3) {
            0 => "_autoremap=\"true\"",
            1 => "k0=\"{k0}\" k1=\"{k1}\"",
            _ => "k0=\"{k1}\" k1=\"{k0}\"",
        };
        format!("<SubTree ID=\"S{i}\" {remap}/>")
    }
}

/// A random case of about `size` nodes.
pub fn case<R: Rng>(rng: &mut R, size: i64) -> Case {
    let mut g = G {
        rng,
        scripts: Scripts::new(),
        budget: 0,
        subtrees: Vec::new(),
    };
    let n_sub = g.below(3);
    let mut defs = String::new();
    for i in 0..n_sub {
        g.budget = size / 3;
        let body = g.node(1);
        defs += &format!("<BehaviorTree ID=\"S{i}\">{body}</BehaviorTree>");
        g.subtrees.push(format!("S{i}"));
    }
    g.budget = size;
    let body = g.node(0);
    // Both entries written first and read once, so each has a value and a type.
    let xml = format!(
        "<root BTCPP_format=\"4\" main_tree_to_execute=\"Main\"><BehaviorTree ID=\"Main\"><Sequence>\
<SetBlackboard output_key=\"k0\" value=\"0\"/><SetBlackboard output_key=\"k1\" value=\"1\"/>\
<ForceSuccess><BlackboardCheckInt value_A=\"{{k0}}\" value_B=\"{{k1}}\" return_on_mismatch=\"SUCCESS\"><AlwaysSuccess/></BlackboardCheckInt></ForceSuccess>\
{body}</Sequence></BehaviorTree>{defs}</root>"
    );
    let ticks = 4 + g.below(7) as usize;
    Case {
        xml,
        scripts: g.scripts,
        ticks,
    }
}
