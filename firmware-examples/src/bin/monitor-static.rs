//! Firmware A: the monitor that hindsight-codegen generated from museum-spec's `museum.hspec` at build time replays the compiled-in run, logging every verdict change.
#![no_std]
#![no_main]

use cortex_m_rt::entry;
use firmware::{end_of_setup, fail, finish, VerdictLog};
use museum_spec::{museum, step, PROPS, TRACE};

#[entry]
fn main() -> ! {
    let mut monitor = museum::Monitor::new();
    defmt::info!(
        "start {=str} props={=usize} points={=u32} state_bytes={=usize}",
        "monitor-static",
        museum::PROPERTIES,
        TRACE.len() as u32,
        museum::STATE_BYTES
    );
    for (i, name) in museum::PROPERTY_NAMES.iter().enumerate() {
        defmt::info!("property {=usize} {=str}", i, *name);
    }
    let setup_stack = end_of_setup();
    let mut log = VerdictLog::<PROPS>::new();
    for point in TRACE.iter() {
        match step(&mut monitor, point) {
            Ok(verdicts) => log.record(point.time, &verdicts),
            Err(_) => {
                defmt::error!("step at time {=u64}", point.time);
                fail("step")
            }
        }
    }
    finish(log.points(), setup_stack)
}
