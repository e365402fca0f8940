//! Firmware A: museum-spec's hand-lowered `static` program replays the compiled-in trace, logging every verdict change.
#![no_std]
#![no_main]

use cortex_m_rt::entry;
use firmware::{end_of_setup, fail, finish, log_start, step_point, VerdictLog};
use monitor_core::Monitor;
use museum_spec::{PROGRAM, PROPS, STATE_WORDS, TRACE};

#[entry]
fn main() -> ! {
    let monitor = match Monitor::try_new(PROGRAM) {
        Ok(m) => m,
        Err(e) => {
            defmt::error!("program rejected: {}", e);
            fail("program")
        }
    };
    let mut state = [0u64; STATE_WORDS];
    if let Err(e) = monitor.reset(&mut state) {
        defmt::error!("state: {}", e);
        fail("state")
    }
    log_start("monitor-static", &monitor, TRACE.len() as u32);
    let setup_stack = end_of_setup();
    let mut log = VerdictLog::<PROPS>::new();
    let mut verdicts = [false; PROPS];
    for point in TRACE.iter() {
        if let Err(e) = step_point(
            &monitor,
            &mut state,
            point.time,
            &point.values,
            &mut verdicts,
        ) {
            defmt::error!("step at time {=u64}: {}", point.time, e);
            fail("step")
        }
        log.record(point.time, &verdicts);
    }
    finish(log.points(), setup_stack)
}
