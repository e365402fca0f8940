//! Proves the panic path fails the run: indexes out of bounds on purpose, so the panic handler must log `error panic at ..` and exit QEMU with status 1.
#![no_std]
#![no_main]

use core::hint::black_box;

use cortex_m_rt::entry;

// Links the panic handler, the logger and the exit.
use firmware as _;

#[entry]
fn main() -> ! {
    defmt::info!("start {=str} props=0 points=0 state_bytes=0", "panic-check");
    let words = [1u32, 2, 3, 4];
    let index = black_box(7usize);
    defmt::info!("unreachable {=u32}", words[index]);
    firmware::exit(true)
}
