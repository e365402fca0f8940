//! A battery component written by hand: what a real process looks like when it replaces the museum model's `BatteryComponent` in `hindsight run --external BatteryComponent`.
//!
//! It speaks only iceoryx2 and the payload layout `hindsight run --layout` prints for
//! the topic `/BatteryComponent/battery_level` (std_msgs/Int32): 16 bytes, `data` as
//! i64 little-endian at 0, then a u64 `seq` at 8. Like the model, it publishes the
//! level at start and then, every period, one percent less (down to 0).
//!
//! ```text
//! hindsight run examples/museum-guide --external BatteryComponent --speed 5 &
//! cargo run -p hindsight --example battery_component -- --period 1.2s --speed 5
//! ```

use std::time::{Duration, Instant};

use clap::Parser;
use iceoryx2::prelude::*;

/// Publishes a battery level on `PREFIX/BatteryComponent/battery_level`.
#[derive(Debug, Parser)]
#[command(name = "battery_component")]
struct Args {
    /// The service prefix `hindsight run --prefix` uses.
    #[arg(long, default_value = "hindsight")]
    prefix: String,
    /// Model time between publications (`1s` as the model, `1.2s` late, `800ms`).
    #[arg(long, default_value = "1s", value_parser = parse_seconds)]
    period: f64,
    /// The run's `--speed`: model time per wall-clock time.
    #[arg(long, default_value_t = 1.0)]
    speed: f64,
    /// The first level published.
    #[arg(long, default_value_t = 100)]
    start: i64,
    /// Stop after this many publications (default: until SIGINT/SIGTERM).
    #[arg(long)]
    count: Option<u64>,
}

/// `1.2s`, `800ms` or a plain number of seconds.
fn parse_seconds(text: &str) -> Result<f64, String> {
    let t = text.trim();
    let (num, scale) = if let Some(n) = t.strip_suffix("ms") {
        (n, 1e-3)
    } else if let Some(n) = t.strip_suffix('s') {
        (n, 1.0)
    } else {
        (t, 1.0)
    };
    match num.trim().parse::<f64>() {
        Ok(v) if v.is_finite() && v > 0.0 => Ok(v * scale),
        _ => Err(format!(
            "`{text}`: expected a positive duration (1.2s, 800ms)"
        )),
    }
}

fn main() {
    let args = Args::parse();
    if !(args.speed.is_finite() && args.speed > 0.0) {
        eprintln!("error: --speed must be a positive number");
        std::process::exit(2);
    }
    if let Err(e) = run(&args) {
        eprintln!("error: {e}");
        std::process::exit(1);
    }
}

fn run(args: &Args) -> Result<(), String> {
    set_log_level_from_env_or(LogLevel::Error);
    let node = NodeBuilder::new()
        .signal_handling_mode(SignalHandlingMode::HandleTerminationRequests)
        .create::<ipc::Service>()
        .map_err(|e| format!("node: {e:?}"))?;
    let name = format!(
        "{}/BatteryComponent/battery_level",
        args.prefix.trim_end_matches('/')
    );
    let service_name = ServiceName::new(&name).map_err(|e| format!("{name}: {e:?}"))?;
    let service = node
        .service_builder(&service_name)
        .publish_subscribe::<[u8]>()
        .open_or_create()
        .map_err(|e| format!("{name}: {e:?}"))?;
    let publisher = service
        .publisher_builder()
        .initial_max_slice_len(16)
        .create()
        .map_err(|e| format!("{name}: {e:?}"))?;

    let period = Duration::from_secs_f64(args.period / args.speed);
    let start = Instant::now();
    let mut level = args.start;
    let mut seq: u64 = 0;
    loop {
        let mut payload = [0u8; 16];
        payload[0..8].copy_from_slice(&level.to_le_bytes());
        payload[8..16].copy_from_slice(&seq.to_le_bytes());
        let sample = publisher
            .loan_slice_uninit(16)
            .map_err(|e| format!("{name}: {e:?}"))?;
        sample
            .write_from_slice(&payload)
            .send()
            .map_err(|e| format!("{name}: {e:?}"))?;
        seq += 1;
        if args.count.is_some_and(|n| seq >= n) {
            break;
        }
        level = (level - 1).max(0);
        // Sleep until the next period of the schedule (no drift), waking on a signal.
        let due = start + period * u32::try_from(seq).unwrap_or(u32::MAX);
        let now = Instant::now();
        if due > now && node.wait(due - now).is_err() {
            break;
        }
    }
    eprintln!("battery_component: {seq} levels published on {name}");
    Ok(())
}
