//! The live page's attack at any size: starts `hindsight monitor --serve :0` (the binary
//! built beside this example), floods it until its page's history is full, then sends a
//! long request line, `/events` clients that never read and clients that trickle a
//! request, and prints the sidecar's peak resident memory, how much of the line it took,
//! and whether its verdict points kept coming. The same attack, at the issue's sizes, is
//! the test `host/tests/live_serve_hostile.rs`.
//!
//! ```text
//! cargo build --release -p hindsight --bin hindsight --example live_serve_attack
//! target/release/examples/live_serve_attack [--slow 500] [--stalled 100] [--line-mb 1024] [--seconds 30]
//! ```

#[path = "../tests/live_common/attack.rs"]
mod attack;

use attack::{status, Sidecar, Sizes};

fn main() {
    let mut sizes = Sizes {
        slow: 500,
        stalled: 100,
        line_bytes: 1 << 30,
        seconds: 30,
    };
    let args: Vec<String> = std::env::args().skip(1).collect();
    let usage = "options: --slow N --stalled N --line-mb N --seconds S";
    for pair in args.chunks(2) {
        let Some(n) = pair.get(1).and_then(|v| v.parse::<u64>().ok()) else {
            eprintln!("{}: expected a number; {usage}", pair[0]);
            std::process::exit(2);
        };
        match pair[0].as_str() {
            "--slow" => sizes.slow = n as usize,
            "--stalled" => sizes.stalled = n as usize,
            "--line-mb" => sizes.line_bytes = n << 20,
            "--seconds" => sizes.seconds = n,
            other => {
                eprintln!("unknown option {other}; {usage}");
                std::process::exit(2);
            }
        }
    }
    iceoryx2::prelude::set_log_level(iceoryx2::prelude::LogLevel::Error);
    let exe = std::env::current_exe().unwrap();
    let bin = exe.parent().unwrap().parent().unwrap().join("hindsight");
    let dir = std::env::temp_dir().join(format!("live_serve_attack_{}", std::process::id()));
    let mut sc = Sidecar::start(
        &bin,
        &dir,
        &format!("hindsight-attack/{}", std::process::id()),
    );
    sc.flood(300_000);
    let m = attack::attack(&mut sc, &sizes);
    let after = status(&sc.addr, "/");
    println!("attack: {sizes:?}");
    println!(
        "sidecar resident memory: {} MB before the attack, {} MB at its peak",
        m.before_kb / 1024,
        m.peak_kb / 1024
    );
    println!(
        "request line: {} MB of {} MB taken before the connection was closed",
        m.line_taken >> 20,
        sizes.line_bytes >> 20
    );
    println!("clients connected: {}", m.connected);
    println!(
        "verdict lines during the attack: {}, largest gap between points {} ms",
        m.lines,
        m.gap * 10
    );
    println!(
        "sidecar CPU: {:.2} s in {:.1} s; the page afterwards: {after}",
        m.cpu_s, m.wall_s
    );
    let _ = std::fs::remove_dir_all(&dir);
}
