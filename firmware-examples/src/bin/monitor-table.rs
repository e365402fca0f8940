//! Firmware B: a postcard monitor table and a replay trace, both embedded as bytes by build.rs, decoded and run at start-up: a new spec needs no new code.
#![no_std]
#![no_main]

use cortex_m_rt::entry;
use firmware::{end_of_setup, fail, finish, log_start, step_point, VerdictLog};
use monitor_core::{Monitor, Value};
use museum_spec::trace::Reader;

mod info {
    //! Sizes of the embedded table, computed by build.rs.
    include!(concat!(env!("OUT_DIR"), "/table_info.rs"));
}

static TABLE: &[u8] = include_bytes!(concat!(env!("OUT_DIR"), "/table.postcard"));
static TRACE: &[u8] = include_bytes!(concat!(env!("OUT_DIR"), "/trace.bin"));

/// Decodes the embedded table into a `static` store of exactly its size,
/// element by element (no temporary copy of the program on the stack), and
/// validates it.
#[inline(never)]
fn load() -> Monitor<'static> {
    let Some(store) = cortex_m::singleton!(: info::Store = info::Store::new()) else {
        fail("table loaded twice")
    };
    match store.load(TABLE) {
        Ok(m) => m,
        Err(e) => {
            defmt::error!("table rejected: {}", e);
            fail("table")
        }
    }
}

#[entry]
fn main() -> ! {
    let monitor = load();
    defmt::info!(
        "table bytes={=usize} decoded_bytes={=usize}",
        TABLE.len(),
        core::mem::size_of::<info::Store>()
    );
    let mut trace = match Reader::new(TRACE, monitor.program().vars.len()) {
        Ok(r) => r,
        Err(_) => fail("trace header"),
    };
    let mut state = [0u64; info::STATE_WORDS];
    if let Err(e) = monitor.reset(&mut state) {
        defmt::error!("state: {}", e);
        fail("state")
    }
    log_start("monitor-table", &monitor, trace.points());
    let setup_stack = end_of_setup();
    // Variables start at their declared values; each point then gives all of them.
    let mut values = [Value::Bool(false); info::VARS];
    monitor_core::valuation::init(monitor.program().vars, &mut values);
    let mut log = VerdictLog::<{ info::PROPS }>::new();
    let mut verdicts = [false; info::PROPS];
    loop {
        let time = match trace.next_point(&mut values) {
            Ok(Some(t)) => t,
            Ok(None) => break,
            Err(_) => fail("trace point"),
        };
        if let Err(e) = step_point(&monitor, &mut state, time, &values, &mut verdicts) {
            defmt::error!("step at time {=u64}: {}", time, e);
            fail("step")
        }
        log.record(time, &verdicts);
    }
    finish(log.points(), setup_stack)
}
