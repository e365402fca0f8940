//! The two halting rules of the tree's control nodes (`Halts::As2fm`, every child halted
//! with a round trip, and `Halts::WhenNeeded`, only children a halt can change) give the
//! same ROS messages, in the same order, at the same times, under fixed schedules: on
//! the museum guide and on corpus models with behavior trees. (Under the random
//! scheduler they differ in how races between machines at one instant come out, since
//! the trees take different numbers of steps; `Halts` says how.)

mod common;

use std::convert::Infallible;
use std::path::{Path, PathBuf};

use hindsight::verify::robot::bt::Halts;
use hindsight::verify::robot::load::{load_with, RobotModel};
use hindsight::verify::sim::{EventSemantics, Flow, Observer, RunConfig, SentMessage, Simulator};

/// A "random" stream that always gives the same word: the simulator then always picks
/// the same position among the machines that can move, and every random value is the
/// same, so a run is a fixed schedule that does not depend on how many choices came
/// before. (None of these words makes the simulator's unbiased draw retry: `w * n`
/// modulo 2^64 is never below `n` for the sizes here.)
struct Fixed(u64);

impl rand_core::TryRng for Fixed {
    type Error = Infallible;
    fn try_next_u32(&mut self) -> Result<u32, Infallible> {
        Ok((self.0 >> 32) as u32)
    }
    fn try_next_u64(&mut self) -> Result<u64, Infallible> {
        Ok(self.0)
    }
    fn try_fill_bytes(&mut self, dst: &mut [u8]) -> Result<(), Infallible> {
        for (i, b) in dst.iter_mut().enumerate() {
            *b = self.0.to_le_bytes()[i % 8];
        }
        Ok(())
    }
}

/// Every message that is not between tree nodes (`bt_<id>_...`): time, event, origin,
/// target and parameters.
#[derive(Default)]
struct Ros(Vec<String>);

impl Observer for Ros {
    fn on_send(&mut self, time: u64, msg: &SentMessage<'_>) -> Flow {
        let ev = msg.event_name();
        let tree_internal = ev
            .strip_prefix("bt_")
            .is_some_and(|r| r.starts_with(|c: char| c.is_ascii_digit()));
        if !tree_internal {
            let params: Vec<String> = msg.params().map(|v| format!("{v:?}")).collect();
            self.0.push(format!(
                "{time} {ev} {}->{} {}",
                msg.origin_name(),
                msg.target_name(),
                params.join(",")
            ));
        }
        Flow::Continue
    }
}

fn run(m: &RobotModel, word: u64) -> (Vec<String>, u64) {
    let cfg = RunConfig {
        max_time: m.max_time_steps,
        events: EventSemantics::As2fm,
        max_steps: 2_000_000,
        ..RunConfig::default()
    };
    let mut obs = Ros::default();
    let out = Simulator::new(&m.model).run(&mut Fixed(word), &cfg, &mut obs);
    (obs.0, out.steps)
}

/// The schedules: the last, a third and two thirds of the way along the machines that
/// can move.
const WORDS: [u64; 3] = [u64::MAX, 0x5555_5555_5555_5555, 0xAAAA_AAAA_AAAA_AAAA];

fn same_ros_messages(main: &Path) -> (usize, u64, u64) {
    let load = |h| load_with(main, h).unwrap_or_else(|e| panic!("{}: {e}", main.display()));
    let (exact, fast) = (load(Halts::As2fm), load(Halts::WhenNeeded));
    let (mut n, mut steps_exact, mut steps_fast) = (0, 0, 0);
    for w in WORDS {
        let ((a, sa), (b, sb)) = (run(&exact, w), run(&fast, w));
        if a != b {
            let i = a
                .iter()
                .zip(&b)
                .position(|(x, y)| x != y)
                .unwrap_or(a.len().min(b.len()));
            panic!(
                "{} schedule {w:#x}: first difference at ROS message {i} of {}/{}:\n  as2fm:       {:?}\n  when needed: {:?}",
                main.display(),
                a.len(),
                b.len(),
                a.get(i),
                b.get(i)
            );
        }
        n += a.len();
        steps_exact += sa;
        steps_fast += sb;
    }
    eprintln!(
        "{}: {n} ROS messages alike; {steps_exact} steps (as2fm), {steps_fast} (when needed)",
        main.display()
    );
    (n, steps_exact, steps_fast)
}

fn examples() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples")
}

#[test]
fn the_museum_guide_sends_the_same_ros_messages_with_either_halting_rule() {
    let (n, exact, fast) = same_ros_messages(&examples().join("museum-guide/main.xml"));
    assert!(n > 3 * 4_000, "{n} ROS messages");
    // The point of the rule: far fewer steps.
    assert!(fast * 10 < exact * 8, "{fast} steps against {exact}");
}

#[test]
fn corpus_trees_send_the_same_ros_messages_with_either_halting_rule() {
    if common::corpus_or_skip().is_none() {
        return;
    }
    let as2fm = common::corpus("as2fm");
    for main in [
        "test_data/uc1_docking/main.xml",
        "test_data/uc2_assembly/Main/main.xml",
        "test_data/blackboard_test/main.xml",
        "examples/tutorial_fetch_and_carry/main.xml",
    ] {
        let (n, exact, fast) = same_ros_messages(&as2fm.join(main));
        assert!(n > 0, "{main}: no ROS messages");
        assert!(fast <= exact, "{main}: {fast} steps against {exact}");
    }
}
