//! A monitored publisher process that crashes (SIGKILL) and restarts: the sidecar reconnects and reports the gap.
//!
//! A `harness = false` target (`host/Cargo.toml`): the same binary is the test and,
//! with `HINDSIGHT_LIVE_CHILD_SERVICE` set, the publisher process the test starts
//! and kills, so the publisher is not registered as a test of its own.

mod live_common;

use std::io::BufRead;
use std::process::{Child, Command, Stdio};

use iceoryx2::prelude::*;
use live_common::*;

const CHILD_ENV: &str = "HINDSIGHT_LIVE_CHILD_SERVICE";
const SENT: &str = "HINDSIGHT-CHILD-SENT";

fn main() {
    match std::env::var(CHILD_ENV) {
        Ok(svc) => child_publisher_process(&svc),
        Err(_) => {
            a_crashed_publisher_is_picked_up_again_and_the_gap_is_reported();
            println!("test a_crashed_publisher_is_picked_up_again_and_the_gap_is_reported ... ok");
        }
    }
}

/// The publisher process that the restart test starts and kills: never returns.
fn child_publisher_process(svc: &str) -> ! {
    let node = node();
    let p = publisher(&node, svc);
    // Every process counts from 0: a new publisher's sequence is its own.
    for i in 0..5u64 {
        send(&p, &battery(70, i));
    }
    println!("{SENT}");
    loop {
        std::thread::sleep(std::time::Duration::from_secs(1));
    }
}

fn spawn_publisher(svc: &str) -> Child {
    let mut child = Command::new(std::env::current_exe().unwrap())
        .env(CHILD_ENV, svc)
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let out = std::io::BufReader::new(child.stdout.take().unwrap());
    for line in out.lines() {
        if line.unwrap().contains(SENT) {
            return child;
        }
    }
    let _ = child.kill();
    let _ = child.wait();
    panic!("the publisher process ended before sending");
}

fn a_crashed_publisher_is_picked_up_again_and_the_gap_is_reported() {
    let svc = unique("battery");
    let run = Running::start(&battery_topic(&svc), "restart");
    let mut first = spawn_publisher(&svc);
    run.wait_judged(5);
    first.kill().unwrap(); // SIGKILL: no clean-up by the publisher
    first.wait().unwrap();
    let mut second = spawn_publisher(&svc);
    run.wait_judged(10);
    second.kill().unwrap();
    second.wait().unwrap();
    let done = run.finish();
    let s = &done.report.sources[0];
    assert_eq!(
        (s.samples, s.restarts, s.lost, s.malformed),
        (10, 1, 0, 0),
        "{}",
        done.log
    );
    assert!(
        done.log.contains("new publisher after a gap of"),
        "{}",
        done.log
    );
    assert!(
        done.record.contains("\"kind\":\"restart\""),
        "{}",
        done.record
    );
    done.assert_replay_matches();
    // The killed processes' nodes are stale: remove their resources.
    Node::<ipc::Service>::try_cleanup_dead_nodes(Config::global_config());
}
