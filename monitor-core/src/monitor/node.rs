//! One node of a monitor's network at one point: the step of a program's [`Node`], of its plan's [`Step`], and the window ring of a bounded `S`.

use crate::layout;
use crate::plan::{self, Kind, Step};
use crate::program::{Node, Op};

/// One node at one point: a program's [`Node`] or its plan ([`Step`]).
pub(super) trait NodeStep {
    /// The node's value at this point, given its children's values at this point
    /// (`bit`), the atoms (`atom`) and its own value at the last point
    /// (`own_prev`); `words` holds the nodes' own words, from word `off` of the state.
    #[allow(clippy::too_many_arguments)]
    fn value(
        &self,
        off: usize,
        words: &mut [u64],
        t: u64,
        first_point: bool,
        atom: impl Fn(u16) -> bool,
        bit: impl Fn(u16) -> bool,
        own_prev: bool,
    ) -> bool;
}

impl NodeStep for Node {
    #[inline(always)]
    fn value(
        &self,
        off: usize,
        words: &mut [u64],
        t: u64,
        first_point: bool,
        atom: impl Fn(u16) -> bool,
        bit: impl Fn(u16) -> bool,
        own_prev: bool,
    ) -> bool {
        let slot = (self.slot as usize).wrapping_sub(off);
        node_step(&self.op, slot, words, t, first_point, atom, bit, own_prev)
    }
}

impl NodeStep for Step {
    /// A plan's slot already counts from `off`.
    #[inline(always)]
    fn value(
        &self,
        _off: usize,
        words: &mut [u64],
        t: u64,
        first_point: bool,
        atom: impl Fn(u16) -> bool,
        bit: impl Fn(u16) -> bool,
        own_prev: bool,
    ) -> bool {
        exec(self, words, t, first_point, atom, bit, own_prev)
    }
}

/// One planned node at one point (not folded: one step per node), as
/// [`node_step`] computes it from the node's [`Op`].
#[inline(always)]
fn exec(
    s: &Step,
    words: &mut [u64],
    t: u64,
    first_point: bool,
    atom: impl Fn(u16) -> bool,
    bit: impl Fn(u16) -> bool,
    own_prev: bool,
) -> bool {
    if s.kind == Kind::Atom {
        return atom(s.a);
    }
    // Only the children the operator reads (`Step::reads`): in a program of more
    // than 64 nodes a child's bit may have to be loaded from a stored word.
    let f = s.reads & plan::A as u8 != 0 && bit(s.a);
    let g = s.reads & plan::B as u8 != 0 && bit(s.b);
    let d = if first_point { plan::D } else { 0 };
    if s.kind == Kind::Logic {
        let x = f as u16 | (g as u16) << 1 | (own_prev as u16) << 2 | d;
        return (s.table >> x) & 1 == 1;
    }
    special::<false>(s, words, t, f, g, d)
}

/// A step that is not `Logic` (the cold part of a step, one branch away), its
/// children's values `f` and `g`; `d` is [`plan::D`] at the first point, else 0;
/// `words` the nodes' own words, whose `s.slot` .. are this node's.
#[inline(always)]
pub(super) fn special<const ONE: bool>(
    s: &Step,
    words: &mut [u64],
    t: u64,
    f: bool,
    g: bool,
    d: u16,
) -> bool {
    let slot = s.slot as usize;
    match s.kind {
        // Not reached: `Logic` is computed before.
        Kind::Logic => false,
        // Not reached: atoms are read before (`exec`) or folded.
        Kind::Atom => false,
        Kind::Latch => {
            // The table reads the word (the child's last value) in place of own_prev.
            let c = if rd(words, slot) != 0 { plan::C } else { 0 };
            wr(words, slot, f as u64);
            (s.table >> (c | d)) & 1 == 1
        }
        Kind::SinceAtLeast => {
            let mut w = rd(words, slot);
            if !f {
                w = 0;
            }
            if g && w == 0 {
                w = t + 1;
            }
            wr(words, slot, w);
            w != 0 && t.wrapping_sub(w - 1) >= s.lo
        }
        Kind::SinceUpTo => {
            let mut w = rd(words, slot);
            if !f {
                w = 0;
            }
            if g {
                w = t + 1;
            }
            wr(words, slot, w);
            w != 0 && t.wrapping_sub(w - 1) <= s.hi
        }
        // `ONE` (a plan of one step): the quiet point inline, the rest out of
        // line; in a step loop the whole window step inline (fewer registers
        // spilled around the loop).
        Kind::SinceWindow if ONE => {
            if !g {
                if let Some(v) = window_quiet(words, slot, s.lo, s.hi, t, f) {
                    return v;
                }
            }
            window_planned(s, words, t, f, g)
        }
        Kind::SinceWindow => match words.get_mut(slot..) {
            Some(w) => window_step(w, s.lo, s.hi, t, f, g, || s.cap as usize),
            None => false,
        },
    }
}

/// A planned window's step at a point with a witness or an expiry (out of
/// line: the step that calls it stays small enough to inline).
#[inline(never)]
fn window_planned(s: &Step, words: &mut [u64], t: u64, f: bool, g: bool) -> bool {
    match words.get_mut(s.slot as usize..) {
        Some(w) => window_step(w, s.lo, s.hi, t, f, g, || s.cap as usize),
        None => false,
    }
}

/// [`window_step`] at a point without a witness, when nothing expires (most
/// points): the ring's header at `words[slot]` is cleared if `f` fails, else
/// the oldest run alone gives the verdict. `None` when that run has expired
/// (the general step then drops it). A planned step only (never `compact`).
#[inline(always)]
fn window_quiet(words: &mut [u64], slot: usize, lo: u64, hi: u64, t: u64, f: bool) -> Option<bool> {
    let header = words.get_mut(slot)?;
    if !f {
        *header = 0;
        return Some(false);
    }
    let h = *header;
    if h >> 32 == 0 {
        return Some(false);
    }
    // Run `head` is `first`, `last` at `slot + 1 + 2 head` (`head < cap < 2^32`).
    let run = slot + 1 + 2 * (h & 0xffff_ffff) as usize;
    let &[first, last] = words.get(run..)?.first_chunk::<2>()?;
    // Expired when `last + hi < t` (no overflow: `last < t - hi`).
    if t.checked_sub(hi).is_some_and(|x| last < x) {
        return None;
    }
    // Started when `first + lo <= t` (no overflow: `first <= t - lo`).
    Some(t.checked_sub(lo).is_some_and(|x| first <= x))
}

/// One node at one point: its value, given its children's values at this point
/// (`bit`), the atoms (`atom`) and its own value at the last point (`own_prev`).
/// `slot` indexes the node's own words in `words`.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn node_step(
    op: &Op,
    slot: usize,
    words: &mut [u64],
    t: u64,
    first_point: bool,
    atom: impl Fn(u16) -> bool,
    bit: impl Fn(u16) -> bool,
    own_prev: bool,
) -> bool {
    match *op {
        Op::Const(c) => c,
        Op::Atom(a) => atom(a),
        Op::Not(a) => !bit(a),
        Op::And(a, b) => bit(a) && bit(b),
        Op::Or(a, b) => bit(a) || bit(b),
        Op::Implies(a, b) => !bit(a) || bit(b),
        Op::Iff(a, b) => bit(a) == bit(b),
        // `compact`: `Y` and `Z` in one arm (firmware size); they differ at
        // the first point only.
        #[cfg(feature = "compact")]
        Op::Yesterday(a) | Op::WeakYesterday(a) => {
            let out = if first_point {
                matches!(op, Op::WeakYesterday(_))
            } else {
                rd(words, slot) != 0
            };
            wr(words, slot, bit(a) as u64);
            out
        }
        #[cfg(not(feature = "compact"))]
        Op::Yesterday(a) => {
            let out = !first_point && rd(words, slot) != 0;
            wr(words, slot, bit(a) as u64);
            out
        }
        #[cfg(not(feature = "compact"))]
        Op::WeakYesterday(a) => {
            let out = first_point || rd(words, slot) != 0;
            wr(words, slot, bit(a) as u64);
            out
        }
        Op::Since { lhs, rhs, lo, hi } => {
            let f = bit(lhs);
            let g = bit(rhs);
            // The kinds of `layout::since_kind`, told apart by the bounds directly
            // (a window's capacity is only computed when it is needed).
            match hi {
                None if lo == 0 => g || (f && !first_point && own_prev),
                // `compact`: `S[a:]` and `S[0:b]`, one word each, in one arm
                // (firmware size): the oldest witness is kept, the newest
                // replaces it when there is an upper bound.
                #[cfg(feature = "compact")]
                _ if hi.is_none() || lo == 0 => {
                    let mut w = rd(words, slot);
                    if !f {
                        w = 0;
                    }
                    if g && (hi.is_some() || w == 0) {
                        w = t + 1;
                    }
                    wr(words, slot, w);
                    let age = t.wrapping_sub(w.wrapping_sub(1));
                    w != 0 && hi.map_or(age >= lo, |b| age <= b)
                }
                None => {
                    let mut w = rd(words, slot);
                    if !f {
                        w = 0;
                    }
                    if g && w == 0 {
                        w = t + 1;
                    }
                    wr(words, slot, w);
                    w != 0 && t.wrapping_sub(w - 1) >= lo
                }
                Some(b) if lo == 0 => {
                    let mut w = rd(words, slot);
                    if !f {
                        w = 0;
                    }
                    if g {
                        w = t + 1;
                    }
                    wr(words, slot, w);
                    w != 0 && t.wrapping_sub(w - 1) <= b
                }
                Some(hi) => match words.get_mut(slot..) {
                    // The capacity is only computed when needed.
                    Some(w) => window_step(w, lo, hi, t, f, g, || window_capacity(lo, hi)),
                    None => false,
                },
            }
        }
    }
}

/// [`layout::window_capacity`] of a validated window (`0 < lo <= hi`, the
/// capacity fits a `u32`), as the unplanned step needs it at a point: a point
/// interval's is `hi + 1`; any other's a division whose quotient validation
/// bounds below `2^32` ([`layout::div`]: no division routine on a 32-bit core).
#[inline(never)]
fn window_capacity(lo: u64, hi: u64) -> usize {
    if lo == hi {
        return hi.saturating_add(1) as usize;
    }
    (layout::div(hi, hi - (lo - 1), 32) as usize).saturating_add(1)
}

/// State word `i` (0 past the end: never, the slots were validated). Under
/// `compact` one shared copy of it and of [`wr`], not one bounds check per
/// use (firmware: about 110 B of flash less).
#[cfg_attr(not(feature = "compact"), inline(always))]
#[cfg_attr(feature = "compact", inline(never))]
pub(super) fn rd(w: &[u64], i: usize) -> u64 {
    w.get(i).copied().unwrap_or(0)
}

#[cfg_attr(not(feature = "compact"), inline(always))]
#[cfg_attr(feature = "compact", inline(never))]
pub(super) fn wr(w: &mut [u64], i: usize, v: u64) {
    if let Some(x) = w.get_mut(i) {
        *x = v;
    }
}

/// One point of `f S[lo:hi] g` with `0 < lo <= hi`, over a ring of witness runs.
///
/// `w[0]` packs `head | len << 32`; run `k` is `w[1 + 2k] = first`, `w[2 + 2k] = last`.
/// Amortised constant work: each run is pushed and expired once, and only the
/// oldest run decides the verdict (it has the smallest `first`, and every live
/// run still has `last + hi >= t`). The ring's capacity (`capacity`, at least 1)
/// is only asked for when a run expires or a witness arrives.
#[inline(always)]
fn window_step(
    w: &mut [u64],
    lo: u64,
    hi: u64,
    t: u64,
    f: bool,
    g: bool,
    capacity: impl Fn() -> usize,
) -> bool {
    // The header apart from the runs: run `k` is `runs[2k] = first`, `runs[2k + 1] = last`.
    let Some((header, runs)) = w.split_first_mut() else {
        return false;
    };
    // A run has expired when `last + hi < t` (no overflow: `last < t - hi`).
    let horizon = t.checked_sub(hi);
    let expired = |last: u64| horizon.is_some_and(|h| last < h);
    // The oldest run decides: `first + lo <= t` (no overflow: `first <= t - lo`).
    let started = |first: u64| t.checked_sub(lo).is_some_and(|h| first <= h);
    let mut head = (*header & 0xffff_ffff) as usize;
    let mut len = (*header >> 32) as usize;
    if !cfg!(feature = "compact") && !g {
        // Most points: no witness, and either `f` fails (every run ends) or
        // the oldest run has not expired (nothing changes; a stored empty
        // ring has `head` 0). Not in the smallest code (firmware).
        if !f {
            *header = 0;
            return false;
        }
        if len == 0 {
            return false;
        }
        let last = rd(runs, 1 + 2 * head);
        if !expired(last) {
            return started(rd(runs, 2 * head));
        }
    }
    if !f {
        len = 0;
    }
    // `compact`: the capacity once, whenever a run is live or a witness
    // arrives, and one expiry loop (firmware size).
    #[cfg(feature = "compact")]
    let cap = if len > 0 || g { capacity() } else { 1 };
    #[cfg(feature = "compact")]
    while len > 0 && expired(rd(runs, 1 + 2 * head)) {
        head = if head + 1 >= cap { 0 } else { head + 1 };
        len -= 1;
    }
    #[cfg(not(feature = "compact"))]
    if len > 0 && expired(rd(runs, 1 + 2 * head)) {
        let cap = capacity();
        while len > 0 && expired(rd(runs, 1 + 2 * head)) {
            head = if head + 1 >= cap { 0 } else { head + 1 };
            len -= 1;
        }
    }
    if len == 0 {
        head = 0;
    }
    if g {
        #[cfg(not(feature = "compact"))]
        let cap = capacity();
        // Index of the newest run and of the slot after it, without `%` (cap >= 1).
        let mut tail = head + len;
        if tail >= cap {
            tail -= cap;
        }
        let newest = if tail == 0 { cap - 1 } else { tail - 1 };
        if len > 0 && t.wrapping_sub(rd(runs, 1 + 2 * newest)) <= hi - lo {
            wr(runs, 1 + 2 * newest, t);
        } else if len < cap {
            wr(runs, 2 * tail, t);
            wr(runs, 1 + 2 * tail, t);
            len += 1;
        }
        // len == cap cannot happen: at most floor(hi / (hi - lo + 1)) + 1 runs are live.
    }
    *header = head as u64 | (len as u64) << 32;
    len > 0 && started(rd(runs, 2 * head))
}
