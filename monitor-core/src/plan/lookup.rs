//! The lookup tables a folded plan steps by, built once: its transition table and its literal nodes' bits by atoms.

use super::{literal_bits, logic_step, with_value, AtomStep, Kind, Step, C};

/// The most index bits (atoms, memory bits and timed steps together) of a transition table.
pub(super) const TABLE_BITS: usize = 8;

/// `v`'s bits spread over the bits of `mask`, lowest first (the inverse of
/// [`gather`]'s memory part).
fn spread(v: u64, mask: u64) -> u64 {
    let (mut x, mut rest, mut j) = (0u64, mask, 0u32);
    while rest != 0 {
        x |= (v.wrapping_shr(j) & 1) << rest.trailing_zeros();
        rest &= rest - 1;
        j += 1;
    }
    x
}

/// Whether a truth table reads the node's own last value ([`C`]).
const fn reads_own(table: u16) -> bool {
    let mut x = 0u16;
    while x < 16 {
        if (table >> x) & 1 != (table >> (x ^ C)) & 1 {
            return true;
        }
        x += 1;
    }
    false
}

/// Whether `s` is a timed `Since` (a step with words of its own that a
/// transition table cannot index).
fn is_timed(s: &Step) -> bool {
    matches!(
        s.kind,
        Kind::SinceUpTo | Kind::SinceAtLeast | Kind::SinceWindow
    )
}

/// A node's bit and, for a step with a fused `Not`, that node's bit too.
fn written(s: &Step) -> u64 {
    let neg = if s.negate != 0 {
        1u64 << (s.neg & 63)
    } else {
        0
    };
    1u64 << (s.dest & 63) | neg
}

/// Moves the timed steps of a folded plan before its `Logic` steps (keeping the
/// order within each) when that computes the same values: every step is
/// `Logic` or timed, and a timed step reads only literal nodes and the nodes of
/// timed steps before it. The plan stays in dependency order (a `Logic` step
/// only moves after steps it may read). Returns the number of timed steps, or
/// `None` with `steps` unchanged.
pub(crate) fn timed_first(steps: &mut [Step]) -> Option<usize> {
    let stepped = steps.iter().fold(0u64, |m, s| m | written(s));
    let mut ready = !stepped;
    for s in steps.iter() {
        if is_timed(s) {
            let reads = 1u64 << (s.a & 63) | 1u64 << (s.b & 63);
            if reads & !ready != 0 {
                return None;
            }
            ready |= written(s);
        } else if s.kind != Kind::Logic {
            return None;
        }
    }
    let mut n = 0;
    for i in 0..steps.len() {
        if steps.get(i).is_some_and(is_timed) {
            steps.get_mut(n..=i)?.rotate_right(1);
            n += 1;
        }
    }
    Some(n)
}

/// Bit `at & 63` of a transition table's index, flipped when `at` has
/// [`FLIP`]: a timed step's child ([`super::Step::ia`], [`super::Step::ib`]). Bit 63 of an
/// index is always 0, so a constant is bit 63, flipped for `true`.
#[inline(always)]
pub(crate) fn index_bit(idx: u64, at: u8) -> bool {
    (idx.wrapping_shr(at as u32) ^ (at >> 7) as u64) & 1 == 1
}

/// The flag of [`index_bit`]'s position that flips the bit.
pub(crate) const FLIP: u8 = 0x80;

/// Where node `x`, a timed step's child, is in a transition table's index
/// ([`index_bit`]): a literal node (an atom, its negation or a constant; not
/// under `stepped`) at its atom's bit, or the node of one of the `first`
/// timed steps (or its fused `Not`) at that step's bit `at + j`; `None` for
/// another node.
fn index_of(x: u16, atoms: &[AtomStep], stepped: u64, first: &[Step], at: usize) -> Option<u8> {
    let bit = 1u64 << (x & 63);
    for (j, s) in first.iter().enumerate() {
        let pos = (at + j) as u8;
        if s.dest == x {
            return Some(pos);
        }
        if s.negate != 0 && s.neg == x {
            return Some(pos | FLIP);
        }
    }
    if stepped & bit != 0 {
        return None;
    }
    for (k, a) in atoms.iter().enumerate() {
        match (a.pos & bit != 0, a.neg & bit != 0) {
            // A `true` constant (in both masks of atom 0, see `build`).
            (true, true) => return Some(63 | FLIP),
            (true, false) => return Some(k as u8),
            (false, true) => return Some(k as u8 | FLIP),
            (false, false) => {}
        }
    }
    // A `false` constant: a literal node no atom sets.
    Some(63)
}

/// The transition table of a folded plan ([`super::Plan::TABLE`]) whose first
/// `timed` steps are timed ([`timed_first`]) and the rest `Logic`:
/// `table[i]` is the value word after a point that is not the first, where
/// index `i` holds the point's atoms (bit `k`: atom `k`), above them the last
/// values of the `Logic` nodes that read their own (the memory bits, in node
/// order) and above those the values of the timed steps at this point (in
/// plan order), for `i < 2^(atoms + memory bits + timed)`. The table's last
/// entry is the mask of the memory nodes ([`gather`]), the one before it a
/// multiplier that gathers them into the top bits of a word ([`multiplier`], 0
/// if none does). Each timed step is given where its children and its value
/// are in the index ([`super::Step::ia`], [`super::Step::ib`], [`super::Step::at`]): it reads and
/// writes the index, not the value word. Returns the number of memory bits,
/// or `None` (nothing to use, the steps unchanged) when the steps are not
/// so, none is `Logic`, or the index does not fit [`TABLE_BITS`] or `table`
/// (all but its last two entries).
pub(crate) fn build_table(
    steps: &mut [Step],
    timed: usize,
    atoms: &[AtomStep],
    table: &mut [u64],
) -> Option<u32> {
    let (first, logic) = (steps.get(..timed)?, steps.get(timed..)?);
    // A plan of timed steps alone gains nothing from a lookup.
    if logic.is_empty()
        || !first.iter().all(is_timed)
        || logic.iter().any(|s| s.kind != Kind::Logic)
    {
        return None;
    }
    let mut mem = 0u64;
    for s in logic {
        if reads_own(s.table) {
            mem |= 1 << (s.dest & 63);
        }
    }
    let m = mem.count_ones() as usize;
    let (n, at) = (atoms.len(), atoms.len() + m);
    let bits = at + timed;
    if bits > TABLE_BITS || (1usize << bits) + 2 > table.len() {
        return None;
    }
    // Each timed step's children: literal nodes or earlier timed steps (`timed_first`).
    let stepped = steps.iter().fold(0u64, |m, s| m | written(s));
    let mut reads = [(0u8, 0u8); TABLE_BITS];
    for (j, s) in first.iter().enumerate() {
        let before = first.get(..j)?;
        *reads.get_mut(j)? = (
            index_of(s.a, atoms, stepped, before, at)?,
            index_of(s.b, atoms, stepped, before, at)?,
        );
    }
    for idx in 0..1usize << bits {
        // The index's memory bits back to their nodes (the inverse of `gather`).
        let old = spread((idx >> n) as u64, mem);
        let mut nodes = literal_bits(atoms, idx as u64);
        for (j, s) in first.iter().enumerate() {
            nodes = with_value(s, nodes, (idx >> (at + j)) as u64 & 1);
        }
        let new = logic
            .iter()
            .fold(nodes, |new, s| logic_step(s, old, new, 0));
        *table.get_mut(idx)? = new;
    }
    let [.., magic, last] = table else {
        return None;
    };
    (*magic, *last) = (multiplier(mem), mem);
    for (j, (s, (ia, ib))) in steps.iter_mut().zip(reads).take(timed).enumerate() {
        (s.ia, s.ib, s.at) = (ia, ib, (at + j) as u8);
    }
    Some(m as u32)
}

/// A multiplier `k` such that `(x & mem) * k >> (64 - m)` is [`gather`]'s
/// memory part of `x` (the `m` bits of `x` under `mem`, lowest first) for
/// every `x`, or 0 when the direct construction (bit `j` of `mem` moved to bit
/// `64 - m + j`) does not give one (the moved bits would collide or carry).
/// Checked over every value of the bits, at most 2^8 of them.
fn multiplier(mem: u64) -> u64 {
    let m = mem.count_ones();
    if m == 0 || m as usize > TABLE_BITS {
        return 0;
    }
    let (mut k, mut rest, mut j) = (0u64, mem, 0u32);
    while rest != 0 {
        let at = rest.trailing_zeros();
        // Bit `at` to `64 - m + j`: only upwards (a left shift).
        let Some(by) = (64 - m + j).checked_sub(at) else {
            return 0;
        };
        k |= 1 << by;
        rest &= rest - 1;
        j += 1;
    }
    for v in 0..1u64 << m {
        // The value `v` spread over the bits of `mem`, and gathered back.
        if spread(v, mem).wrapping_mul(k) >> (64 - m) != v {
            return 0;
        }
    }
    k
}

/// A transition table's index ([`build_table`]): the atoms `atoms` (`n` of
/// them), then above them the bits of `old` under `mem`, lowest first.
#[inline(always)]
pub(crate) fn gather(atoms: u64, n: usize, old: u64, mem: u64) -> u64 {
    let (mut idx, mut rest, mut j) = (atoms, mem, n);
    while rest != 0 {
        idx |= (old >> rest.trailing_zeros() & 1) << (j & 63);
        rest &= rest - 1;
        j += 1;
    }
    idx
}

/// The literal nodes' bits of a folded plan for each value of its atoms
/// ([`super::Plan::LITS`]): `table[i]` for atoms `i`; `None` (nothing to use) when
/// the atoms are more than [`TABLE_BITS`] or than `table` indexes.
pub(crate) fn build_literals(atoms: &[AtomStep], table: &mut [u64]) -> Option<()> {
    if atoms.len() > TABLE_BITS || 1usize << atoms.len() > table.len() {
        return None;
    }
    for idx in 0..1usize << atoms.len() {
        *table.get_mut(idx)? = literal_bits(atoms, idx as u64);
    }
    Some(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::program::Op;

    #[test]
    fn timed_steps_move_first_only_over_literals_and_timed_steps() {
        let since = |a, b, dest| {
            Step::of(
                &Op::Since {
                    lhs: a,
                    rhs: b,
                    lo: 0,
                    hi: Some(3),
                },
                dest,
                0,
            )
        };
        let and = |a, b, dest| Step::of(&Op::And(a, b), dest, 0);
        let dests = |s: &[Step; 4]| s.map(|s| s.dest);
        // Nodes 0 and 1 are literals; the `S` reads them, the `And`s do not feed it.
        let none = Some(Step::NONE);
        let mut steps = [and(0, 1, 2), since(0, 1, 3), and(2, 3, 4), none].map(Option::unwrap);
        assert_eq!(timed_first(&mut steps[..3]), Some(1));
        assert_eq!(dests(&steps), [3, 2, 4, 0]);
        // A timed step over another's value, after it.
        let mut steps =
            [and(0, 1, 2), since(0, 1, 3), since(3, 1, 4), and(2, 4, 5)].map(Option::unwrap);
        assert_eq!(timed_first(&mut steps), Some(2));
        assert_eq!(dests(&steps), [3, 4, 2, 5]);
        // The `S` reads node 2, which a truth table computes: nothing moves.
        let mut steps = [and(0, 1, 2), since(0, 2, 3), none, none].map(Option::unwrap);
        assert_eq!(timed_first(&mut steps[..2]), None);
        assert_eq!(dests(&steps), [2, 3, 0, 0]);
        // Nor over a `Not` fused into a truth table's step.
        let mut steps = [and(0, 1, 2), since(0, 5, 3)].map(Option::unwrap);
        steps[0].negate = 1;
        steps[0].neg = 5;
        assert_eq!(timed_first(&mut steps), None);
    }

    #[test]
    fn a_multiplier_gathers_like_the_loop_or_is_zero() {
        // Bits 0, 1 and 3: bit 3's move lands a cross term in the window.
        assert_eq!(multiplier(0b1011), 0);
        assert_eq!(multiplier(0), 0);
        let masks = [
            1u64 << 63,
            0b11,
            1 << 4 | 1 << 8,
            0x8000_0100_0010_0001,
            0xff << 20,
        ];
        for mem in masks {
            let k = multiplier(mem);
            assert_ne!(k, 0, "{mem:#x}");
            let top = 64 - mem.count_ones();
            for old in [0, u64::MAX, 0x5555_5555_5555_5555, 0xdead_beef_0123_4567] {
                let want = gather(0b101, 3, old, mem);
                assert_eq!(
                    0b101 | (old & mem).wrapping_mul(k) >> top << 3,
                    want,
                    "{mem:#x}"
                );
            }
        }
    }
}
