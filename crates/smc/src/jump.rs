//! Stream `k` of a seed in a few thousand operations whatever `k`: the jump as a matrix.
//!
//! Run `k` of a study draws from xoshiro256++ seeded from the study seed and then jumped
//! `k` times ([`rand_xoshiro::Xoshiro256PlusPlus::jump`], 2^128 draws each). A jump is
//! about 3,000 instructions, so stream `k` by `k` jumps made `trace --run 100000000000`
//! run for hours, and the first run of a shard late in a large study (`--shard 99/100`
//! of 10^9 runs) waited minutes for its stream.
//!
//! The generator's state moves linearly over GF(2) (xor, shift, rotate: the `++` output
//! is not part of the state), and a jump combines states along the sequence by xor, so a
//! jump is a linear map `J` of the 256 state bits. Its matrix is read off the generator
//! itself: column `j` is the state a jump makes of the state that is bit `j` alone.
//! Squaring gives `J^(2^i)` for `i < 64`, and `J^k` applied to a state is the product of
//! those whose bit is set in `k`: at most 64 matrix-vector products of 256 x 256 bits.
//! The matrices (512 KB) are built once per process (about 16 million word operations),
//! only when some stream needs more than [`FEW_JUMPS`] jumps.

use rand_core::SeedableRng;
use rand_xoshiro::Xoshiro256PlusPlus;
use std::sync::OnceLock;

/// The generator's 256 state bits, as its four words.
type State = [u64; 4];

/// A linear map of states: entry `j` is the image of the state that is bit `j` alone
/// (bit `j % 64` of word `j / 64`).
struct Map(Box<[State; 256]>);

/// Below this many jumps a stream is made by jumping (cheaper than building the maps).
pub(crate) const FEW_JUMPS: u64 = 4096;

/// The generator's state. The crate keeps it private; its serde form (the `serde`
/// feature) is the struct with its one field `s`, the four words.
fn state_of(rng: &Xoshiro256PlusPlus) -> State {
    let v = serde_json::to_value(rng).expect("a generator serialises");
    let words = v
        .get("s")
        .and_then(|s| s.as_array())
        .expect("xoshiro's state `s`");
    let mut s = [0u64; 4];
    for (w, x) in s.iter_mut().zip(words) {
        *w = x.as_u64().expect("a state word");
    }
    s
}

/// The generator in state `s` (`from_seed` reads the words little-endian; `s` is never
/// all zero, which it would replace).
fn with_state(s: State) -> Xoshiro256PlusPlus {
    let mut seed = [0u8; 32];
    for (chunk, w) in seed.chunks_exact_mut(8).zip(s) {
        chunk.copy_from_slice(&w.to_le_bytes());
    }
    Xoshiro256PlusPlus::from_seed(seed)
}

impl Map {
    /// The map applied to `s`: the xor of the images of its set bits.
    fn apply(&self, s: State) -> State {
        let mut out = [0u64; 4];
        for (w, &word) in s.iter().enumerate() {
            let mut bits = word;
            while bits != 0 {
                let b = bits.trailing_zeros() as usize;
                bits &= bits - 1;
                let image = &self.0[w * 64 + b];
                for (o, i) in out.iter_mut().zip(image) {
                    *o ^= i;
                }
            }
        }
        out
    }

    /// This map after itself.
    fn squared(&self) -> Map {
        let mut images = Box::new([[0u64; 4]; 256]);
        for (image, &column) in images.iter_mut().zip(self.0.iter()) {
            *image = self.apply(column);
        }
        Map(images)
    }

    /// One jump, read off the generator.
    fn jump() -> Map {
        let mut images = Box::new([[0u64; 4]; 256]);
        for (j, image) in images.iter_mut().enumerate() {
            let mut basis = [0u64; 4];
            basis[j / 64] = 1 << (j % 64);
            let mut rng = with_state(basis);
            rng.jump();
            *image = state_of(&rng);
        }
        Map(images)
    }
}

/// `J^(2^i)` for `i` in `0..64`, built on first use.
fn powers() -> &'static [Map] {
    static POWERS: OnceLock<Vec<Map>> = OnceLock::new();
    POWERS.get_or_init(|| {
        let mut all = vec![Map::jump()];
        for i in 1..64 {
            let next = all[i - 1].squared();
            all.push(next);
        }
        all
    })
}

/// `rng` jumped `k` times, by the powers of the jump: the same generator `k` calls to
/// `jump` make (checked against them in the tests).
pub(crate) fn jumped(rng: &Xoshiro256PlusPlus, k: u64) -> Xoshiro256PlusPlus {
    let powers = powers();
    let mut s = state_of(rng);
    for (i, map) in powers.iter().enumerate() {
        if k >> i & 1 == 1 {
            s = map.apply(s);
        }
    }
    with_state(s)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand_core::Rng;

    fn by_jumps(seed: u64, k: u64) -> Xoshiro256PlusPlus {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
        for _ in 0..k {
            rng.jump();
        }
        rng
    }

    #[test]
    fn the_state_round_trips() {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(7);
        let mut copy = with_state(state_of(&rng));
        for _ in 0..10 {
            assert_eq!(rng.next_u64(), copy.next_u64());
        }
    }

    #[test]
    fn powers_of_the_jump_are_the_jumps() {
        // Every k below 300 and some far apart, against k calls to `jump`: the same
        // generator, draw for draw.
        let ks = (0..300).chain([511, 512, 513, 1000, 4095, 4096, 4097, 9999]);
        for k in ks {
            for seed in [0, 1, u64::MAX] {
                let mut fast = jumped(&Xoshiro256PlusPlus::seed_from_u64(seed), k);
                let mut slow = by_jumps(seed, k);
                for _ in 0..4 {
                    assert_eq!(fast.next_u64(), slow.next_u64(), "seed {seed}, k {k}");
                }
            }
        }
        // Powers compose: 2^40 jumps then 3 more, against 2^40 + 3 at once.
        let base = Xoshiro256PlusPlus::seed_from_u64(5);
        let mut a = jumped(&jumped(&base, 1 << 40), 3);
        let mut b = jumped(&base, (1 << 40) + 3);
        assert_eq!(a.next_u64(), b.next_u64());
    }
}
