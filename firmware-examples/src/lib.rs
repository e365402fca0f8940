//! Shared run-time of the example firmware: defmt over semihosting, exit status, panic handler, stack high-water mark, verdict log.
//!
//! # Pipeline
//!
//! Each binary steps a monitor over every point of a replay trace:
//! `monitor-static` the straight-line monitor that codegen generated from
//! museum-spec's `museum.hspec` at build time (through `museum_spec::step`),
//! `monitor-table` a [`monitor_core::Program`] decoded from a postcard table
//! and validated with `Monitor::try_new` (through [`step_point`]). Each hands
//! the verdicts to [`VerdictLog`], which logs every change. At the end [`finish`] logs the point count and the stack high-water
//! marks and exits QEMU with status 0; any error goes to [`fail`] (status 1),
//! and so does a panic.
//!
//! # Log lines (the contract with `host-check`)
//!
//! - `start <name> props=<P> points=<N> state_bytes=<S>`
//! - `property <index> <name>` for each property
//! - `verdict prop=<p> point=<i> time=<t> value=<bool>`: property `p`'s
//!   verdict at point `i` (0-based) differs from its verdict at point `i-1`,
//!   or `i` is the first point
//! - `final point=<i> time=<t>` (table images): after point `i` every
//!   property's verdict is final ([`Finality`]): no later point can change
//!   one, so the image stops stepping and the `done` line follows with
//!   `points=<i+1>`
//! - `done points=<N> stack=<bytes> setup_stack=<bytes> replay_stack=<bytes>`:
//!   stack high-water marks of the whole run, of the set-up (decoding and
//!   validating the program) and of the replay (from [`end_of_setup`] on,
//!   frames live at that point included)
//! - `error ...` before a failing exit
#![no_std]

use core::panic::PanicInfo;

use cortex_m_rt as _;
use defmt_semihosting as _;
use monitor_core::analysis::{settle, settled};
use monitor_core::{Monitor, StepError, Value};

// Provides the single-core critical section that defmt-semihosting needs.
use cortex_m as _;

/// The stack high-water mark in bytes, from cortex-m-rt's `paint-stack`.
pub mod stack;

/// Exits QEMU through semihosting: status 0 when `success`, else 1.
pub fn exit(success: bool) -> ! {
    semihosting::process::exit(if success { 0 } else { 1 })
}

/// Logs `error <what>` and exits with status 1.
pub fn fail(what: &str) -> ! {
    defmt::error!("error {=str}", what);
    exit(false)
}

/// Ends the set-up phase: returns its stack high-water mark in bytes and
/// repaints the free stack so that [`finish`] measures the replay on its own.
pub fn end_of_setup() -> usize {
    let setup = stack::high_water();
    stack::repaint();
    setup
}

/// Logs the end of the replay (point count; stack high-water marks of the
/// whole run, of the set-up and of the replay) and exits with status 0.
pub fn finish(points: u32, setup_stack: usize) -> ! {
    let replay = stack::high_water();
    defmt::info!(
        "done points={=u32} stack={=u32} setup_stack={=u32} replay_stack={=u32}",
        points,
        setup_stack.max(replay) as u32,
        setup_stack as u32,
        replay as u32
    );
    exit(true)
}

/// Logs the program's shape before the replay starts.
pub fn log_start(name: &str, monitor: &Monitor<'_>, points: u32) {
    defmt::info!(
        "start {=str} props={=usize} points={=u32} state_bytes={=usize}",
        name,
        monitor.properties(),
        points,
        monitor.state_bytes()
    );
    for (i, p) in monitor.program().props.iter().enumerate() {
        defmt::info!("property {=usize} {=str}", i, p.name);
    }
}

/// One monitor step; never inlined so that the image has a symbol to start the panic-path analysis from.
///
/// An error is its [`StepError::code`], all the log shows: a one-byte result,
/// where returning the error itself copied its bytes through `memcpy` (not
/// otherwise linked on a Cortex-M0: 600 B of flash).
#[inline(never)]
pub fn step_point(
    monitor: &Monitor<'_>,
    state: &mut [u64],
    time: u64,
    vars: &[Value],
    verdicts: &mut [bool],
) -> Result<(), u8> {
    monitor
        .try_step(state, time, vars, verdicts)
        .map_err(|e: StepError| e.code())
}

/// Tells when every property's verdict is final, by the host's own finality
/// analysis ([`monitor_core::analysis::settle`]) over the node values after
/// each point: from then on no point can change a verdict, so stepping on is
/// wasted work. `N` is the program's node count (one slot per node).
pub struct Finality<const N: usize> {
    finals: Finals<N>,
}

/// The final values, aligned like the state words: the compiler clears them
/// with the state's routine (`__aeabi_memclr8`) instead of linking a second
/// one for 4-byte alignment (`__aeabi_memclr4`, 158-174 B of flash).
#[repr(align(8))]
struct Finals<const N: usize>([Option<bool>; N]);

impl<const N: usize> Default for Finality<N> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const N: usize> Finality<N> {
    /// Nothing known to be final yet.
    pub const fn new() -> Self {
        // `settle` writes every entry before `all_final` reads one, so the
        // start value does not matter: all zero bytes (`Some(false)`) lets the
        // compiler clear the array like the others instead of linking
        // `__aeabi_memset4` for `None` (160 B of flash).
        Finality {
            finals: Finals([Some(false); N]),
        }
    }

    /// After a step: whether every property's verdict is now final.
    pub fn all_final(&mut self, monitor: &Monitor<'_>, state: &[u64]) -> bool {
        let program = monitor.program();
        settle(
            program,
            |n| monitor.node_value(state, n).unwrap_or(false),
            &mut self.finals.0,
        );
        (0..monitor.properties()).all(|p| settled(program, &self.finals.0, p).is_some())
    }
}

/// The `main` of an image that decodes a postcard table embedded by build.rs
/// and replays the embedded trace through it, stopping once every verdict is
/// final. `$name` is the image's name in its log, `$table` the table file in
/// `OUT_DIR` and `$info` the `<name>_info.rs` that build.rs sized for it.
#[macro_export]
macro_rules! table_image {
    ($name:literal, $table:literal, $info:literal) => {
        mod info {
            //! Sizes of the embedded table, computed by build.rs.
            include!(concat!(env!("OUT_DIR"), "/", $info));
        }

        static TABLE: &[u8] = include_bytes!(concat!(env!("OUT_DIR"), "/", $table));
        static TRACE: &[u8] = include_bytes!(concat!(env!("OUT_DIR"), "/trace.bin"));

        /// Decodes the embedded table into a `static` store of exactly its
        /// size, element by element (no copy of the program on the stack),
        /// and validates it.
        #[inline(never)]
        fn load() -> monitor_core::Monitor<'static> {
            // The static starts uninitialised (no image of it in flash) and
            // the empty store is written into it, not built on the stack.
            let Some(slot) = ::cortex_m::singleton!(
                : ::core::mem::MaybeUninit<info::Store> = ::core::mem::MaybeUninit::uninit()
            ) else {
                $crate::fail("table loaded twice")
            };
            let store = slot.write(info::Store::new());
            match store.load(TABLE) {
                Ok(m) => m,
                Err(e) => {
                    // A small code, not `e`'s message (flash): build.rs validated
                    // the same bytes with the same code and says which element.
                    defmt::error!("table rejected: code {=u8}", e.code());
                    $crate::fail("table")
                }
            }
        }

        #[cortex_m_rt::entry]
        fn main() -> ! {
            let monitor = load();
            defmt::info!(
                "table bytes={=usize} decoded_bytes={=usize}",
                TABLE.len(),
                ::core::mem::size_of::<info::Store>()
            );
            let nvars = monitor.program().vars.len();
            let mut trace = match museum_spec::trace::Reader::new(TRACE, nvars) {
                Ok(r) => r,
                Err(_) => $crate::fail("trace header"),
            };
            let mut state = [0u64; info::STATE_WORDS];
            if let Err(e) = monitor.reset(&mut state) {
                defmt::error!("state: code {=u8}", e.code());
                $crate::fail("state")
            }
            $crate::log_start($name, &monitor, trace.points());
            let setup_stack = $crate::end_of_setup();
            // Variables start at their declared values; each point then gives all of them.
            let mut values = [monitor_core::Value::Bool(false); info::VARS];
            monitor_core::valuation::init(monitor.program().vars, &mut values);
            let mut log = $crate::VerdictLog::<{ info::PROPS }>::new();
            let mut finality = $crate::Finality::<{ info::NODES }>::new();
            let mut verdicts = [false; info::PROPS];
            loop {
                let time = match trace.next_point(&mut values) {
                    Ok(Some(t)) => t,
                    Ok(None) => break,
                    Err(_) => $crate::fail("trace point"),
                };
                if let Err(e) = $crate::step_point(&monitor, &mut state, time, &values, &mut verdicts)
                {
                    defmt::error!("step at time {=u64}: code {=u8}", time, e);
                    $crate::fail("step")
                }
                log.record(time, &verdicts);
                if finality.all_final(&monitor, &state) {
                    defmt::info!(
                        "final point={=u32} time={=u64}",
                        log.points().saturating_sub(1),
                        time
                    );
                    break;
                }
            }
            $crate::finish(log.points(), setup_stack)
        }
    };
}

/// Remembers the last verdict of each of `P` properties and logs every change.
pub struct VerdictLog<const P: usize> {
    last: [bool; P],
    points: u32,
}

impl<const P: usize> Default for VerdictLog<P> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const P: usize> VerdictLog<P> {
    /// A log before the first point.
    pub const fn new() -> Self {
        VerdictLog {
            last: [false; P],
            points: 0,
        }
    }

    /// Logs each verdict of the point at `time` that differs from the previous point's (all of them at the first point).
    pub fn record(&mut self, time: u64, verdicts: &[bool; P]) {
        let point = self.points;
        for (prop, (last, &now)) in self.last.iter_mut().zip(verdicts).enumerate() {
            if point == 0 || *last != now {
                defmt::info!(
                    "verdict prop={=usize} point={=u32} time={=u64} value={=bool}",
                    prop,
                    point,
                    time,
                    now
                );
            }
            *last = now;
        }
        self.points = point.saturating_add(1);
    }

    /// Number of points recorded.
    pub fn points(&self) -> u32 {
        self.points
    }
}

#[panic_handler]
fn panic(info: &PanicInfo<'_>) -> ! {
    match info.location() {
        Some(l) => defmt::error!("error panic at {=str}:{=u32}", l.file(), l.line()),
        None => defmt::error!("error panic"),
    }
    exit(false)
}
