//! Where each piece of monitor state lives in the caller's `[u64]` buffer, fixed by the bounds alone.
//!
//! Layout of a state buffer, in 64-bit words:
//!
//! | words | content |
//! |---|---|
//! | `0` | `1 +` timestamp of the last point, `0` before the first point |
//! | `1 .. 1+A` | atom bits of the current point (scratch), `A = ceil(atoms / 64)` |
//! | `.. +V` | value bit of every node at the last point, `V = ceil(nodes / 64)` |
//! | then | each node's own words, in node order ([`node_words`]) |
//!
//! Per-node words (section 3 of the design):
//! - boolean ops, constants, atoms, unbounded `S`: none (unbounded `S` reads its own value bit);
//! - `Y`, `Z`: one word, the child's previous value;
//! - `S[0:b]`: one word, `1 +` timestamp of the newest live witness (0: none);
//! - `S[a:]`, `a > 0`: one word, `1 +` timestamp of the oldest live witness;
//! - `S[a:b]`, `0 < a <= b`: one header word (`head | len << 32`) and
//!   [`window_capacity`] runs of two words `[first, last]`.

use crate::program::Op;

/// Number of words before the atom bits.
pub const HEADER_WORDS: usize = 1;

/// How the state of a `Since` node is kept, chosen from its bounds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SinceKind {
    /// `S` with no bound: the node's own previous value.
    Unbounded,
    /// `S[0:b]`: newest witness.
    UpTo(u64),
    /// `S[a:]`, `a > 0`: oldest witness.
    AtLeast(u64),
    /// `S[a:b]`, `0 < a <= b`: merged witness runs, at most `cap` of them.
    Window {
        /// Lower bound.
        lo: u64,
        /// Upper bound.
        hi: u64,
        /// Run capacity: `floor(hi / (hi - lo + 1)) + 1`.
        cap: u32,
    },
}

/// The number of runs an `S[lo:hi]` window can ever hold live at once, or
/// `None` when it does not fit in a `u32`. Requires `0 < lo <= hi`.
pub const fn window_capacity(lo: u64, hi: u64) -> Option<u32> {
    if lo == 0 || lo > hi {
        return None;
    }
    let width = hi - lo;
    let cap = if width == u64::MAX {
        1
    } else {
        match div(hi, width + 1, 64).checked_add(1) {
            Some(c) => c,
            None => return None,
        }
    };
    if cap > u32::MAX as u64 {
        None
    } else {
        Some(cap as u32)
    }
}

/// `n / d` for `d >= 1` whose quotient is below `2^bits` (`bits <= 64`).
///
/// On a 64-bit core a division instruction; on a 32-bit one a 64-bit division is
/// a library routine (`__aeabi_uldivmod`: several hundred bytes of flash and many
/// cycles), so there it is a restoring division of `bits` steps instead, and
/// firmware links no division routine. From bit `bits - 1` down, `r >> k >= d`
/// means `d << k <= r`: neither the shift nor the subtraction overflows.
#[inline]
pub(crate) const fn div(n: u64, d: u64, bits: u32) -> u64 {
    if cfg!(target_pointer_width = "64") {
        return n / d;
    }
    steps_div(n, d, bits)
}

/// [`div`]'s restoring division, on every target (so that its tests run on the host).
pub(crate) const fn steps_div(n: u64, d: u64, bits: u32) -> u64 {
    let (mut r, mut q) = (n, 0u64);
    let mut k = bits;
    while k > 0 {
        k -= 1;
        if r >> k >= d {
            r -= d << k;
            q |= 1 << k;
        }
    }
    q
}

/// Classifies a `Since` by its bounds; `None` when `lo > hi` or the capacity overflows.
pub const fn since_kind(lo: u64, hi: Option<u64>) -> Option<SinceKind> {
    match hi {
        None if lo == 0 => Some(SinceKind::Unbounded),
        None => Some(SinceKind::AtLeast(lo)),
        Some(hi) if lo > hi => None,
        Some(hi) if lo == 0 => Some(SinceKind::UpTo(hi)),
        Some(hi) => match window_capacity(lo, hi) {
            Some(cap) => Some(SinceKind::Window { lo, hi, cap }),
            None => None,
        },
    }
}

/// The number of state words a node owns, or `None` for bounds that cannot be laid out.
pub const fn node_words(op: &Op) -> Option<u64> {
    match op {
        Op::Yesterday(_) | Op::WeakYesterday(_) => Some(1),
        Op::Since { lo, hi, .. } => match since_kind(*lo, *hi) {
            None => None,
            Some(SinceKind::Unbounded) => Some(0),
            Some(SinceKind::UpTo(_)) | Some(SinceKind::AtLeast(_)) => Some(1),
            Some(SinceKind::Window { cap, .. }) => Some(1 + 2 * cap as u64),
        },
        _ => Some(0),
    }
}

/// Words holding `bits` bits.
pub const fn bit_words(bits: usize) -> usize {
    bits.div_ceil(64)
}

/// Index of the first node-owned word for a program with `atoms` atoms and `nodes` nodes.
pub const fn first_node_word(atoms: usize, nodes: usize) -> usize {
    HEADER_WORDS + bit_words(atoms) + bit_words(nodes)
}

#[cfg(test)]
mod tests {
    use super::steps_div;

    #[test]
    fn restoring_division_equals_division() {
        let cases = [
            (0, 1, 64),
            (10, 3, 64),
            (100, 51, 64),
            (u64::MAX, 1, 64),
            (u64::MAX, 2, 64),
            (u64::MAX, u64::MAX, 64),
            (u64::MAX - 1, 3, 64),
            ((1 << 34) - 5, 1 << 33, 64),
            (1_000_003, 999_997, 32),
            (1 << 40, 1 << 9, 32),
            (u32::MAX as u64 * 7, 7, 32),
        ];
        for (n, d, bits) in cases {
            assert_eq!(steps_div(n, d, bits), n / d, "{n} / {d}");
        }
    }
}
