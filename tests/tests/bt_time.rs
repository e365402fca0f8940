//! BT.CPP 4's timed nodes (Timeout, Delay, Sleep) and 4.10's TryCatch: runs derived by
//! hand from the BT.CPP 4.10 sources (`decorators/timeout_node.cpp`,
//! `decorators/delay_node.cpp`, `actions/sleep_node.cpp`, `controls/try_catch_node.cpp`,
//! `bt_factory.cpp` `Tree::tickRoot`), each checked on the oracle's BT.CPP 4 reading and
//! on the lowering (`--bt btcpp`, the root machine keeping the timers in model time), in
//! the tick mode each names.
//!
//! The executor ticks every 100 ms, root tick `k` at `k * 100` ms (the oracle's
//! `PERIOD_MS`, the lowering at 10 Hz). A timer started by a tick at `t` fires at
//! `t + d`, between ticks (one due at a tick fires first): Delay's and Sleep's flags,
//! Timeout's halt of its RUNNING child, and the wake-up signal, which under `tickOnce`
//! ticks the root again when the next executor tick answers RUNNING (docs/SEMANTICS.md
//! section 5, "Timers of the tree").

mod bt_common;

use bt_common::lower_and_run_clocked;
use hindsight::verify::robot::bt::{BtSemantics, BtTick};
use hindsight_tests::bt::oracle::{self, LeafEvent, Options, Scripts, TickMode};
use hindsight_tests::bt::tree::{self, Status};

use LeafEvent::{Halt as H, Tick as T};
use Status::{Failure as F, Running as R, Success as S};

fn v4(body: &str) -> String {
    format!(
        "<root BTCPP_format=\"4\" main_tree_to_execute=\"Main\"><BehaviorTree ID=\"Main\">{body}</BehaviorTree></root>"
    )
}

fn scripts(list: &[(&str, &[Status])]) -> Scripts {
    list.iter()
        .map(|(n, s)| (n.to_string(), s.to_vec()))
        .collect()
}

/// Checks that the oracle and the lowering both give `statuses` and `log` for `body`
/// under `mode`.
fn check(
    body: &str,
    sc: &[(&str, &[Status])],
    mode: TickMode,
    statuses: &[Status],
    log: &[LeafEvent],
) {
    let xml = v4(body);
    let sc = scripts(sc);
    let t = tree::read(&xml).expect("reads");
    let o = oracle::run_with(&t, &sc, Options::xml4(mode), statuses.len()).expect("oracle runs");
    assert_eq!(o.end, None, "{body}");
    assert_eq!(
        (o.statuses.as_slice(), o.log.as_slice()),
        (statuses, log),
        "oracle, {mode:?}: {body}"
    );
    let tick = match mode {
        TickMode::Once => BtTick::Once,
        TickMode::ExactlyOnce => BtTick::ExactlyOnce,
    };
    let ((st, lg), _) = lower_and_run_clocked(
        &xml,
        &sc,
        BtSemantics::Btcpp { tick },
        statuses.len(),
        100_000,
    )
    .expect("lowers and runs");
    assert_eq!(
        (st.as_slice(), lg.as_slice()),
        (statuses, log),
        "lowering, {mode:?}: {body}"
    );
}

#[test]
fn delay_ticks_its_child_from_the_first_tick_after_the_timer() {
    // t=0 starts the timer (due 150): RUNNING; t=100 RUNNING; it fires at 150; t=200
    // ticks A; t=300 starts again.
    let body = "<Delay delay_msec=\"150\"><A/></Delay>";
    for mode in [TickMode::Once, TickMode::ExactlyOnce] {
        check(body, &[("A", &[S])], mode, &[R, R, S, R], &[T(1001)]);
    }
    // Due at a tick (200): it fires before that tick.
    let body = "<Delay delay_msec=\"200\"><A/></Delay>";
    check(
        body,
        &[("A", &[S])],
        TickMode::ExactlyOnce,
        &[R, R, S],
        &[T(1001)],
    );
}

#[test]
fn the_delays_wake_up_ticks_again_under_tick_once() {
    // A answers RUNNING at t=200; under tickOnce the wake-up the timer emitted at 150 is
    // pending, so `Tree::tickRoot` ticks again at once and A answers SUCCESS.
    let body = "<Delay delay_msec=\"150\"><A/></Delay>";
    check(
        body,
        &[("A", &[R, S])],
        TickMode::Once,
        &[R, R, S],
        &[T(1001), T(1001)],
    );
    check(
        body,
        &[("A", &[R, S])],
        TickMode::ExactlyOnce,
        &[R, R, R, S],
        &[T(1001), T(1001)],
    );
}

#[test]
fn timeout_halts_its_running_child_when_the_timer_fires() {
    // A runs from t=0; the timer (due 150) halts it at 150; t=200 answers FAILURE
    // without ticking it; t=300 starts again. Under tickOnce the wake-up of 150 is still
    // pending at t=300 (t=200 finished, so `tickRoot` did not take it): the RUNNING
    // answer is ticked again at once.
    let body = "<Timeout msec=\"150\"><A/></Timeout>";
    check(
        body,
        &[("A", &[R])],
        TickMode::ExactlyOnce,
        &[R, R, F, R],
        &[T(1001), T(1001), H(1001), T(1001)],
    );
    check(
        body,
        &[("A", &[R])],
        TickMode::Once,
        &[R, R, F, R],
        &[T(1001), T(1001), H(1001), T(1001), T(1001)],
    );
    // A child that finishes in time cancels the timer: no halt, no FAILURE.
    check(
        body,
        &[("A", &[R, S])],
        TickMode::ExactlyOnce,
        &[R, S, R, S],
        &[T(1001), T(1001), T(1001), T(1001)],
    );
    // 0 ms: no timer at all (`if(msec_ > 0)`).
    check(
        "<Timeout msec=\"0\"><A/></Timeout>",
        &[("A", &[R])],
        TickMode::ExactlyOnce,
        &[R, R, R],
        &[T(1001), T(1001), T(1001)],
    );
}

#[test]
fn sleep_answers_success_after_its_time() {
    // Due 250: RUNNING at 0, 100, 200; SUCCESS at 300, then B.
    let body = "<Sequence><Sleep msec=\"250\"/><B/></Sequence>";
    check(
        body,
        &[("B", &[S])],
        TickMode::ExactlyOnce,
        &[R, R, R, S],
        &[T(1002)],
    );
    // 0 ms: SUCCESS at once (`onStart`).
    check(
        "<Sequence><Sleep msec=\"0\"/><B/></Sequence>",
        &[("B", &[S])],
        TickMode::Once,
        &[S],
        &[T(1002)],
    );
}

#[test]
fn a_halted_timer_is_cancelled() {
    // The ReactiveSequence halts the Timeout at t=100 (C fails): A is halted and the
    // timer (due 250) cancelled (`TimeoutNode::halt`, `cancelAll`). The Timeout started
    // again at t=200 is due at 450, so A is still ticked at 300 and 400; had the first
    // timer fired at 250 it would have halted A and answered FAILURE at 300.
    let body = "<ReactiveSequence><C/><Timeout msec=\"250\"><A/></Timeout></ReactiveSequence>";
    check(
        body,
        &[("C", &[S, F, S, S, S]), ("A", &[R])],
        TickMode::ExactlyOnce,
        &[R, F, R, R, R],
        &[
            T(1001),
            T(1003),
            T(1001),
            H(1003),
            T(1001),
            T(1003),
            T(1001),
            T(1003),
            T(1001),
            T(1003),
        ],
    );
}

#[test]
fn try_catch_runs_the_catch_after_a_failure() {
    // A succeeds, B fails: the children are reset and C (the catch) ticked in the same
    // tick; C's finished answer ends the catch with FAILURE.
    let body = "<TryCatch><A/><B/><C/></TryCatch>";
    let log = [
        T(1001),
        T(1002),
        T(1003),
        T(1003),
        T(1001),
        T(1002),
        T(1003),
    ];
    for mode in [TickMode::Once, TickMode::ExactlyOnce] {
        check(
            body,
            &[("A", &[S]), ("B", &[F]), ("C", &[R, S])],
            mode,
            &[R, F, R],
            &log,
        );
    }
    // The try block all SUCCESS: SUCCESS, the catch never ticked.
    check(
        body,
        &[("A", &[S]), ("B", &[S]), ("C", &[S])],
        TickMode::ExactlyOnce,
        &[S, S],
        &[T(1001), T(1002), T(1001), T(1002)],
    );
}

#[test]
fn try_catch_with_catch_on_halt_runs_the_catch_when_halted() {
    // K fails at the second tick: the ReactiveSequence halts the TryCatch, which halts A
    // and, with `catch_on_halt`, ticks C once.
    let body = "<ReactiveSequence><K/><TryCatch catch_on_halt=\"true\"><A/><C/></TryCatch></ReactiveSequence>";
    let sc: &[(&str, &[Status])] = &[("K", &[S, F]), ("A", &[R]), ("C", &[S])];
    check(
        body,
        sc,
        TickMode::ExactlyOnce,
        &[R, F],
        &[T(1001), T(1003), T(1001), H(1003), T(1004)],
    );
    // Without it, the catch is not run.
    let body = "<ReactiveSequence><K/><TryCatch><A/><C/></TryCatch></ReactiveSequence>";
    check(
        body,
        sc,
        TickMode::ExactlyOnce,
        &[R, F],
        &[T(1001), T(1003), T(1001), H(1003)],
    );
    // Halted while in the catch: the catch child is halted, not ticked again.
    let body = "<ReactiveSequence><K/><TryCatch catch_on_halt=\"true\"><A/><C/></TryCatch></ReactiveSequence>";
    check(
        body,
        &[("K", &[S, F]), ("A", &[F]), ("C", &[R])],
        TickMode::ExactlyOnce,
        &[R, F],
        &[T(1001), T(1003), T(1004), T(1001), H(1004)],
    );
}

// BT.CPP 4.10 `tests/gtest_decorator.cpp`, the timed tests, as tick facts. The gtests
// tick on wall-clock time (sleeps between ticks); here the executor ticks every 100 ms,
// so each duration is chosen to keep the gtest's order of ticks, timers and the
// action's end.

#[test]
fn gtest_decorator_deadline_triggered() {
    // `DeadlineTest.DeadlineTriggeredTest`: a Timeout of 100 ms over an action of 150 ms,
    // ticked at 0 and 170 ms: RUNNING, then FAILURE with the action halted (IDLE). The
    // deadline falls between the two ticks and before the action ends: 50 ms here, the
    // action answering RUNNING then (were it ticked) SUCCESS. The gtest builds the nodes
    // by hand (no wake-up signal, as `tickExactlyOnce` of a tree of these two nodes).
    check(
        "<Timeout msec=\"50\"><A/></Timeout>",
        &[("A", &[R, S])],
        TickMode::ExactlyOnce,
        &[R, F],
        &[T(1001), H(1001)],
    );
}

#[test]
fn gtest_decorator_deadline_not_triggered() {
    // `DeadlineTest.DeadlineNotTriggeredTest`: the action (30 ms) ends before the
    // second tick (50 ms), the deadline (100 ms) after it: RUNNING, then SUCCESS with
    // the action IDLE (not halted). Here the deadline is 150 ms, the second tick at 100.
    check(
        "<Timeout msec=\"150\"><A/></Timeout>",
        &[("A", &[R, S])],
        TickMode::ExactlyOnce,
        &[R, S],
        &[T(1001), T(1001)],
    );
}

#[test]
fn gtest_decorator_delay_with_xml() {
    // `Decorator.DelayWithXML`: a tree from XML, `tickOnce`: a Delay of 100 ms over
    // AlwaysSuccess answers RUNNING at 0 and 50 ms and SUCCESS at the first tick after
    // its timer. Here 150 ms: RUNNING at 0 and 100, SUCCESS at 200.
    check(
        "<Delay delay_msec=\"150\"><AlwaysSuccess/></Delay>",
        &[],
        TickMode::Once,
        &[R, R, S],
        &[],
    );
}

#[test]
fn gtest_decorator_issue57() {
    // `TimeoutAndRetry.Issue57`: a Timeout of 9 ms over RetryUntilSuccessful (1000
    // attempts) over an action that always fails, ticked for 2 s: the Timeout never
    // answers IDLE (BT.CPP issue 57: a Timeout whose timer halted its child). The gtest
    // builds the nodes by hand; as a tree from XML (what hindsight lowers), under
    // `tickExactlyOnce`, the Retry yields RUNNING after each failed attempt (its wake-up
    // signal), the timer halts it at 9 ms (resetting its count; the action is not
    // RUNNING, so it gets no halt), and the next tick answers FAILURE; then again. (100
    // attempts instead of 1000: the lowering counts to 127; one attempt a tick is made.)
    check(
        "<Timeout msec=\"9\"><RetryUntilSuccessful num_attempts=\"100\"><A/></RetryUntilSuccessful></Timeout>",
        &[("A", &[F])],
        TickMode::ExactlyOnce,
        &[R, F, R, F],
        &[T(1002), T(1002)],
    );
}
