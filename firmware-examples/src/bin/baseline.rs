//! Size baseline for `monitor-static`: the same replay of the compiled-in `static` trace, with the same logging and exit, but no monitor.
#![no_std]
#![no_main]

use core::hint::black_box;

use cortex_m_rt::entry;
use firmware::{end_of_setup, finish};
use monitor_core::Value;
use museum_spec::TRACE;

#[entry]
fn main() -> ! {
    defmt::info!(
        "start {=str} props=0 points={=u32} state_bytes=0",
        "baseline",
        TRACE.len() as u32
    );
    let setup_stack = end_of_setup();
    // Read every value, as the monitored image does.
    let mut events = 0u32;
    let mut level_sum = 0i64;
    for point in black_box(&TRACE).iter() {
        for v in &point.values {
            match *v {
                Value::Bool(b) => events += b as u32,
                Value::Int(i) => level_sum = level_sum.wrapping_add(i),
                _ => {}
            }
        }
    }
    defmt::info!("replayed events={=u32} level_sum={=i64}", events, level_sum);
    finish(TRACE.len() as u32, setup_stack)
}
