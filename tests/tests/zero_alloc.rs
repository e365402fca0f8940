//! Proves with a counting global allocator that judging the museum requirements allocates nothing per point.
//!
//! `examples/specs/museum.hspec` is compiled with codegen; its state, valuation
//! and verdict buffers are allocated up front, then a million points go through
//! the interpreter (on `Compiled::program()` and on the postcard table loaded
//! with `Table::from_bytes`) while the allocator counts every allocation made
//! by this thread. The count must not move.

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

use hindsight_tests::engines;
use monitor_core::{valuation, Monitor, Value};

/// Forwards to the system allocator and counts allocations per thread, so
/// other test threads cannot disturb the count.
struct Counting;

thread_local! {
    static ALLOCATIONS: Cell<u64> = const { Cell::new(0) };
}

fn count() {
    // `try_with`: during thread teardown the slot may be gone; such allocations are not ours.
    let _ = ALLOCATIONS.try_with(|n| n.set(n.get() + 1));
}

fn allocations() -> u64 {
    ALLOCATIONS.with(Cell::get)
}

#[allow(unsafe_code)]
// SAFETY: every method forwards to `System` with the caller's arguments unchanged.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        count();
        // SAFETY: same contract as the caller's.
        unsafe { System.alloc(layout) }
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        count();
        // SAFETY: same contract as the caller's.
        unsafe { System.alloc_zeroed(layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        count();
        // SAFETY: same contract as the caller's.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: same contract as the caller's.
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

const STEPS: u64 = 1_000_000;

/// A small deterministic generator (xorshift64*); it allocates nothing.
struct Rng(u64);

impl Rng {
    fn below(&mut self, n: u64) -> u64 {
        let mut x = self.0;
        x ^= x >> 12;
        x ^= x << 25;
        x ^= x >> 27;
        self.0 = x;
        x.wrapping_mul(0x2545_F491_4F6C_DD1D) % n
    }
}

/// Indices of the museum's variables in the compiled program.
struct Museum {
    battery_level: usize,
    battery_published: usize,
    alarm: usize,
    poi1_selected: usize,
    poi1_done: usize,
    visitors_published: usize,
}

/// Runs a million points through `monitor`; returns the allocations made
/// meanwhile and, per property, whether it was seen true and seen false.
fn million_steps(monitor: &Monitor<'_>, v: &Museum) -> (u64, Vec<(bool, bool)>) {
    let vars = monitor.program().vars;
    let mut state = vec![0u64; monitor.state_words()];
    let mut vals = vec![Value::Bool(false); vars.len()];
    let mut verdicts = vec![false; monitor.properties()];
    let mut seen = vec![(false, false); monitor.properties()];
    valuation::init(vars, &mut vals);
    let mut rng = Rng(0x9E37_79B9_7F4A_7C15);
    let mut battery: i64 = 100;
    let mut t = 0u64;

    let before = allocations();
    for step in 0..STEPS {
        valuation::begin_point(vars, &mut vals);
        // The battery drains and recharges; events come at irregular times.
        battery = match rng.below(100) {
            0..=5 => 100,
            6..=60 => (battery - 1).max(0),
            _ => battery,
        };
        vals[v.battery_level] = Value::Int(battery);
        vals[v.battery_published] = Value::Bool(rng.below(8) == 0);
        vals[v.alarm] = Value::Bool(rng.below(40) == 0);
        vals[v.visitors_published] = Value::Bool(rng.below(6) == 0);
        if rng.below(20) == 0 {
            vals[v.poi1_selected] = Value::Bool(rng.below(2) == 0);
        }
        if rng.below(15) == 0 {
            vals[v.poi1_done] = Value::Bool(rng.below(2) == 0);
        }
        // 100 ms ticks, with micro-steps (same timestamp) and pauses.
        t += [0, 1, 1, 1, 2, 7][rng.below(6) as usize];
        if step % 1000 == 999 {
            // Now and then start a fresh run, so that H-rooted properties recover.
            monitor.reset(&mut state).expect("state has the right size");
        }
        monitor
            .try_step(&mut state, t, &vals, &mut verdicts)
            .expect("timestamps never go backwards");
        for (s, &b) in seen.iter_mut().zip(&verdicts) {
            s.0 |= b;
            s.1 |= !b;
        }
    }
    (allocations() - before, seen)
}

#[test]
fn a_million_museum_points_allocate_nothing() {
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/specs/museum.hspec");
    let src = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let compiled = codegen::compile_spec(&src, "museum.hspec").unwrap_or_else(|d| panic!("{d}"));
    let index = |name: &str| {
        compiled
            .var_index(name)
            .unwrap_or_else(|| panic!("museum.hspec declares no `{name}`"))
    };
    let museum = Museum {
        battery_level: index("battery_level"),
        battery_published: index("battery_published"),
        alarm: index("alarm"),
        poi1_selected: index("poi1_selected"),
        poi1_done: index("poi1_done"),
        visitors_published: index("visitors_published"),
    };
    let names: Vec<&str> = compiled.property_names().collect();
    assert_eq!(names.len(), 5, "the museum has five requirements");

    let interpreter = Monitor::try_new(compiled.program()).expect("codegen output is valid");
    let bytes = compiled.to_table_bytes();
    let table = engines::load_table(&bytes).expect("the table loads");
    let from_table = table.monitor().expect("the table is valid");

    for (form, monitor) in [("interpreter", &interpreter), ("table", &from_table)] {
        let (allocated, seen) = million_steps(monitor, &museum);
        assert_eq!(
            allocated, 0,
            "{form}: {allocated} allocations in {STEPS} steps"
        );
        for (name, (was_true, was_false)) in names.iter().zip(seen) {
            assert!(
                was_true && was_false,
                "{form}: `{name}` never changed its verdict"
            );
        }
    }
}

/// The counter sees allocations at all (otherwise the test above proves nothing).
#[test]
fn the_counter_counts() {
    let before = allocations();
    let v = std::hint::black_box(vec![1u8; 64]);
    assert!(allocations() > before);
    drop(v);
}
