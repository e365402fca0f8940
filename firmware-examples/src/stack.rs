//! The stack high-water mark: how much of the stack cortex-m-rt painted at reset was ever written.

// The only unsafe code of the firmware: reading the linker's stack bounds and
// the painted words between them.
#![allow(unsafe_code)]

use cortex_m_rt::STACK_PAINT_VALUE;

extern "C" {
    /// Lowest address of the stack region (cortex-m-rt's link.x), 4-byte aligned.
    static mut _stack_end: u32;
    /// One past the highest stack address, where the stack pointer starts.
    static mut _stack_start: u32;
}

/// Bytes between the top of the stack and the deepest word that no longer
/// holds the paint, scanning up from the bottom of the stack region.
pub fn high_water() -> usize {
    let bottom = (&raw const _stack_end) as usize;
    let top = (&raw const _stack_start) as usize;
    let mut addr = bottom;
    while addr < top {
        // SAFETY: `addr` is 4-byte aligned (`_stack_end` is, and we step by 4)
        // and lies in [_stack_end, _stack_start), RAM that cortex-m-rt reserves
        // for the stack; a volatile read of it has no side effect.
        let word = unsafe { core::ptr::read_volatile(addr as *const u32) };
        if word != STACK_PAINT_VALUE {
            break;
        }
        addr += 4;
    }
    top - addr
}
