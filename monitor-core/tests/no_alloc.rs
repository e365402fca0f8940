//! Proves, with a counting global allocator, that stepping a monitor never allocates.

mod common;

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

use common::{program, since_nodes, Rng};
use monitor_core::{Monitor, Value};

struct Counting;

thread_local! {
    // Per thread, so the test harness's own threads cannot disturb the count.
    static ALLOCATIONS: Cell<usize> = const { Cell::new(0) };
}

fn allocations() -> usize {
    ALLOCATIONS.with(|a| a.get())
}

// SAFETY-free wrapper: forwards to the system allocator and counts calls.
#[allow(unsafe_code)]
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.with(|a| a.set(a.get() + 1));
        // SAFETY: same contract as the caller's.
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: same contract as the caller's.
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

#[test]
fn a_million_steps_allocate_nothing() {
    // 5 shapes x 1,000,000 points.
    for (lo, hi) in [
        (0, None),
        (0, Some(100)),
        (10, None),
        (50, Some(100)),
        (1000, Some(1000)),
    ] {
        let nodes = since_nodes(lo, hi);
        let m = Monitor::try_new(program(&nodes)).unwrap();
        let mut state = vec![0u64; m.state_words()];
        let mut out = [false];
        let mut rng = Rng(99);
        let before = allocations();
        let mut t = 0;
        let mut trues = 0u64;
        for _ in 0..1_000_000 {
            t += rng.next() % 3;
            let vals = [
                Value::Bool(rng.next() % 1000 < 999),
                Value::Bool(rng.chance(10)),
            ];
            m.try_step(&mut state, t, &vals, &mut out).unwrap();
            trues += out[0] as u64;
        }
        assert_eq!(allocations(), before, "S[{lo}:{hi:?}] allocated");
        // The formula did real work: some points true, some false.
        assert!(
            trues > 0 && trues < 1_000_000,
            "S[{lo}:{hi:?}]: {trues} true"
        );
    }
}
