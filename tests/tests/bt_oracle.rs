//! The oracle's two readings, node by node where AS2FM's models and BehaviorTree.CPP
//! disagree (and one where they agree), with the leaf ticks and halts each gives; and the
//! blackboard rules the random trees lean on (typed checks, status numbers, copies,
//! format-3 SubTree mapping).

use hindsight_tests::bt::oracle::{run, LeafEvent, Reading, Scripts};
use hindsight_tests::bt::tree::{read, Status};

use LeafEvent::{Halt as H, Tick as T};
use Status::{Failure as F, Running as R, Success as S};

fn go(
    body: &str,
    scripts: &[(&str, &[Status])],
    ticks: usize,
    reading: Reading,
) -> (Vec<Status>, Vec<LeafEvent>) {
    let xml =
        format!("<root BTCPP_format=\"4\"><BehaviorTree ID=\"M\">{body}</BehaviorTree></root>");
    let tree = read(&xml).expect("tree");
    let s: Scripts = scripts
        .iter()
        .map(|(k, v)| (k.to_string(), v.to_vec()))
        .collect();
    run(&tree, &s, reading, ticks).expect("run")
}

#[test]
fn repeat_over_a_memory_sequence_restarts_it_in_as2fm_and_resumes_it_in_btcpp() {
    // Ids: Repeat 1000, SequenceWithMemory 1001, A 1002, B 1003.
    let body =
        "<Repeat num_cycles=\"2\"><SequenceWithMemory><A/><B/></SequenceWithMemory></Repeat>";
    let sc: &[(&str, &[Status])] = &[("A", &[S]), ("B", &[F, S])];
    // Both fail twice (B's script comes round to FAILURE again); the leaves differ.
    let (st, log) = go(body, sc, 2, Reading::As2fm);
    assert_eq!(st, [F, F]);
    // AS2FM: the failed sequence is halted (back to A); the second tick starts at A.
    assert_eq!(log[..4], [T(1002), T(1003), H(1003), H(1002)]);
    assert_eq!(log[5], T(1002));
    let (st, log) = go(body, sc, 2, Reading::Btcpp);
    assert_eq!(st, [F, F]);
    // BT.CPP: nothing is halted (nothing RUNNING); the second tick resumes at B.
    assert_eq!(log[..3], [T(1002), T(1003), T(1003)]);
}

#[test]
fn retry_over_a_memory_sequence_resumes_it_in_both_readings() {
    let body = "<RetryUntilSuccessful num_attempts=\"3\"><SequenceWithMemory><A/><B/></SequenceWithMemory></RetryUntilSuccessful>";
    let sc: &[(&str, &[Status])] = &[("A", &[S]), ("B", &[F, S])];
    for r in [Reading::As2fm, Reading::Btcpp] {
        let (st, log) = go(body, sc, 1, r);
        assert_eq!(st, [S], "{r:?}");
        let ticks: Vec<_> = log.iter().filter(|e| matches!(e, T(_))).copied().collect();
        assert_eq!(ticks, [T(1002), T(1003), T(1003)], "{r:?}");
    }
}

#[test]
fn parallel_reticks_finished_children_only_in_as2fm() {
    let body = "<Parallel success_count=\"2\" failure_count=\"1\"><A/><B/></Parallel>";
    let sc: &[(&str, &[Status])] = &[("A", &[S, R]), ("B", &[R, S])];
    // AS2FM: A ticked again on tick 2 answers RUNNING; only B succeeds.
    assert_eq!(go(body, sc, 2, Reading::As2fm).0, [R, R]);
    // BT.CPP: A's success is remembered.
    assert_eq!(go(body, sc, 2, Reading::Btcpp).0, [R, S]);
}

#[test]
fn finished_children_are_halted_only_in_as2fm() {
    let body = "<Sequence><A/><B/></Sequence>";
    let sc: &[(&str, &[Status])] = &[("A", &[S]), ("B", &[S])];
    let (_, log) = go(body, sc, 1, Reading::As2fm);
    assert_eq!(log, [T(1001), T(1002), H(1001), H(1002)]);
    let (_, log) = go(body, sc, 1, Reading::Btcpp);
    assert_eq!(log, [T(1001), T(1002)]);
}

#[test]
fn a_halted_memory_sequence_forgets_its_place_only_in_as2fm() {
    // The ReactiveSequence's condition C fails on tick 2 and halts the running
    // SequenceWithMemory (at B); tick 3 ticks it again.
    let body = "<ReactiveSequence><C/><SequenceWithMemory><A/><B/></SequenceWithMemory></ReactiveSequence>";
    let sc: &[(&str, &[Status])] = &[("C", &[S, F, S]), ("A", &[S]), ("B", &[R])];
    let (st, log) = go(body, sc, 3, Reading::As2fm);
    assert_eq!(st, [R, F, R]);
    // AS2FM: halted, it starts again at A.
    assert!(
        log.ends_with(&[T(1001), T(1003), T(1004), H(1001)]),
        "{log:?}"
    );
    let (st, log) = go(body, sc, 3, Reading::Btcpp);
    assert_eq!(st, [R, F, R]);
    // BT.CPP: halted, it keeps its place at B.
    assert!(log.ends_with(&[H(1004), T(1001), T(1004)]), "{log:?}");
}

#[test]
fn subtree_remapping_reaches_the_callers_entries() {
    let xml = "<root BTCPP_format=\"4\" main_tree_to_execute=\"M\">\
<BehaviorTree ID=\"M\"><Sequence><SetBlackboard output_key=\"x\" value=\"2\"/><SubTree ID=\"S\" y=\"{x}\"/></Sequence></BehaviorTree>\
<BehaviorTree ID=\"S\"><BlackboardCheckInt value_A=\"{y}\" value_B=\"2\" return_on_mismatch=\"FAILURE\"><A/></BlackboardCheckInt></BehaviorTree></root>";
    let tree = read(xml).expect("tree");
    let s: Scripts = [("A".to_string(), vec![S])].into_iter().collect();
    assert_eq!(run(&tree, &s, Reading::As2fm, 1).expect("run").0, [S]);
    let xml2 = xml.replace("value=\"2\"", "value=\"3\"");
    let tree = read(&xml2).expect("tree");
    assert_eq!(run(&tree, &s, Reading::As2fm, 1).expect("run").0, [F]);
}

/// A whole document, AS2FM's reading: the root's statuses.
fn doc(xml: &str, scripts: &[(&str, &[Status])], ticks: usize) -> Vec<Status> {
    let tree = read(xml).expect("tree");
    let s: Scripts = scripts
        .iter()
        .map(|(k, v)| (k.to_string(), v.to_vec()))
        .collect();
    run(&tree, &s, Reading::As2fm, ticks).expect("run").0
}

#[test]
fn blackboard_checks_compare_by_type_with_the_float_epsilon() {
    // v3.8 `IsSame(double, double)`: within 2^-23; Int, String, Bool exactly.
    let check = |tag: &str, set: &str, b: &str| {
        let body = format!(
            "<Sequence><SetBlackboard output_key=\"e\" value=\"{set}\"/><BlackboardCheck{tag} value_A=\"{{e}}\" value_B=\"{b}\" return_on_mismatch=\"3\"><A/></BlackboardCheck{tag}></Sequence>"
        );
        go(&body, &[("A", &[S])], 1, Reading::As2fm).0[0]
    };
    assert_eq!(check("Double", "1.5", "1.50000005"), S);
    assert_eq!(check("Double", "1.5", "1.5000005"), R);
    assert_eq!(check("Int", "2", "2"), S);
    assert_eq!(check("Int", "2", "3"), R);
    assert_eq!(check("String", "a", "a"), S);
    assert_eq!(check("String", "a", "b"), R);
    assert_eq!(check("Bool", "true", "true"), S);
    assert_eq!(check("Bool", "true", "false"), R);
}

#[test]
fn return_on_mismatch_takes_as2fms_numbers() {
    let with = |m: &str| {
        let body = format!("<BlackboardCheckInt value_A=\"1\" value_B=\"2\" return_on_mismatch=\"{m}\"><A/></BlackboardCheckInt>");
        go(&body, &[("A", &[S])], 1, Reading::As2fm).0[0]
    };
    assert_eq!([with("1"), with("2"), with("3")], [S, F, R]);
    assert_eq!(
        [with("SUCCESS"), with("FAILURE"), with("RUNNING")],
        [S, F, R]
    );
}

#[test]
fn set_blackboard_copies_an_entry() {
    let body = "<Sequence><SetBlackboard output_key=\"a\" value=\"7\"/><SetBlackboard output_key=\"b\" value=\"{a}\"/><SetBlackboard output_key=\"a\" value=\"8\"/>\
<BlackboardCheckInt value_A=\"{b}\" value_B=\"7\" return_on_mismatch=\"FAILURE\"><A/></BlackboardCheckInt></Sequence>";
    assert_eq!(go(body, &[("A", &[S])], 1, Reading::As2fm).0, [S]);
}

#[test]
fn format_3_subtrees_map_by_name_share_or_keep_entries_private() {
    // The SubTree writes `y`; the caller then checks its `x`.
    let main = |attrs: &str, tag: &str| {
        format!(
            "<root BTCPP_format=\"3\" main_tree_to_execute=\"M\"><BehaviorTree ID=\"M\"><Sequence>\
<SetBlackboard output_key=\"x\" value=\"1\"/><SetBlackboard output_key=\"y\" value=\"1\"/><{tag} ID=\"S\" {attrs}/>\
<BlackboardCheckInt value_A=\"{{x}}\" value_B=\"5\" return_on_mismatch=\"FAILURE\"><A/></BlackboardCheckInt></Sequence></BehaviorTree>\
<BehaviorTree ID=\"S\"><SetBlackboard output_key=\"y\" value=\"5\"/></BehaviorTree></root>"
        )
    };
    let sc: &[(&str, &[Status])] = &[("A", &[S])];
    // `y="x"`: the SubTree's `y` is the caller's `x` (format 3 maps by name).
    assert_eq!(doc(&main("y=\"x\"", "SubTree"), sc, 1), [S]);
    // Not mapped: its `y` is its own; the caller's `x` stays 1.
    assert_eq!(doc(&main("", "SubTree"), sc, 1), [F]);
    // Shared: its `y` is the caller's `y`, not `x`.
    assert_eq!(
        doc(&main("__shared_blackboard=\"true\"", "SubTree"), sc, 1),
        [F]
    );
    // SubTreePlus maps `{x}`.
    assert_eq!(doc(&main("y=\"{x}\"", "SubTreePlus"), sc, 1), [S]);
    // Shared, then checked on `y`: the SubTree's write is the caller's.
    let shared = main("__shared_blackboard=\"true\"", "SubTree").replace("{x}", "{y}");
    assert_eq!(doc(&shared, sc, 1), [S]);
    let private = main("", "SubTree").replace("{x}", "{y}");
    assert_eq!(doc(&private, sc, 1), [F]);
}
