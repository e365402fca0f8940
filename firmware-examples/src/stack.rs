//! The stack high-water mark: how much of the stack cortex-m-rt painted at reset was ever written, and repainting to measure a phase on its own.

// The only unsafe code of the firmware: reading the linker's stack bounds and
// reading or repainting the words between them.
#![allow(unsafe_code)]

use cortex_m_rt::STACK_PAINT_VALUE;

extern "C" {
    /// Lowest address of the stack region (cortex-m-rt's link.x), 4-byte aligned.
    static mut _stack_end: u32;
    /// One past the highest stack address, where the stack pointer starts.
    static mut _stack_start: u32;
}

fn bounds() -> (usize, usize) {
    (
        (&raw const _stack_end) as usize,
        (&raw const _stack_start) as usize,
    )
}

/// Bytes between the top of the stack and the deepest word that no longer
/// holds the paint, scanning up from the bottom of the stack region.
pub fn high_water() -> usize {
    let (bottom, top) = bounds();
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

/// Paints the free stack again (everything below the current frame), so that
/// the next [`high_water`] measures only what runs after this call. The
/// frames above, the caller's among them, stay counted.
#[inline(never)]
pub fn repaint() {
    let (bottom, _) = bounds();
    // Leave a margin below the stack pointer for this function's own spills.
    let limit = (cortex_m::register::msp::read() as usize).saturating_sub(64);
    let mut addr = bottom;
    while addr < limit {
        // SAFETY: `addr` is 4-byte aligned and lies in [_stack_end, sp - 64):
        // stack memory below every live frame. No interrupt is enabled in
        // these images, so nothing else uses it while we paint.
        unsafe { core::ptr::write_volatile(addr as *mut u32, STACK_PAINT_VALUE) };
        addr += 4;
    }
}
