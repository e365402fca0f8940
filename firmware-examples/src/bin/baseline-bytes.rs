//! Size baseline for `monitor-table`: the same replay of the trace embedded as bytes, read with the same reader, but no table and no monitor.
#![no_std]
#![no_main]

use cortex_m_rt::entry;
use firmware::{end_of_setup, fail, finish};
use monitor_core::Value;
use museum_spec::trace::Reader;

static TRACE: &[u8] = include_bytes!(concat!(env!("OUT_DIR"), "/trace.bin"));

mod info {
    //! Sizes of the embedded table, computed by build.rs (only `VARS` is needed here).
    #![allow(dead_code)]
    include!(concat!(env!("OUT_DIR"), "/table_info.rs"));
}

#[entry]
fn main() -> ! {
    let mut trace = match Reader::new(TRACE, info::VARS) {
        Ok(r) => r,
        Err(_) => fail("trace header"),
    };
    defmt::info!(
        "start {=str} props=0 points={=u32} state_bytes=0",
        "baseline-bytes",
        trace.points()
    );
    let setup_stack = end_of_setup();
    let mut values = [Value::Bool(false); info::VARS];
    let mut events = 0u32;
    let mut level_sum = 0i64;
    let mut points = 0u32;
    loop {
        match trace.next_point(&mut values) {
            Ok(Some(_)) => {}
            Ok(None) => break,
            Err(_) => fail("trace point"),
        }
        points += 1;
        for v in &values {
            match *v {
                Value::Bool(b) => events += b as u32,
                Value::Int(i) => level_sum = level_sum.wrapping_add(i),
                _ => {}
            }
        }
    }
    defmt::info!("replayed events={=u32} level_sum={=i64}", events, level_sum);
    finish(points, setup_stack)
}
