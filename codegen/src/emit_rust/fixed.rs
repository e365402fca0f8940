//! The parts of every emitted module that do not depend on the spec: the step error and the window ring.
//!
//! Written as the text they emit (indented by [`super::out::Out::block`] to where they
//! go), so that they read as the Rust they are.

/// `StepError`, its `Display` and `Error` impls.
pub(super) const STEP_ERROR: &str = r#"
/// Why a point was not judged; the monitor is unchanged when this is returned.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StepError {
    /// The point's timestamp is earlier than the previous point's.
    TimeWentBackwards {
        /// Timestamp of the previous point.
        last: u64,
        /// The rejected timestamp.
        now: u64,
    },
    /// `u64::MAX` is reserved and cannot be a timestamp.
    TimeOutOfRange,
    /// Integer overflow or division by zero while computing an atom.
    Arithmetic {
        /// Index of the atom.
        atom: u16,
    },
}

impl core::fmt::Display for StepError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            StepError::TimeWentBackwards { last, now } => {
                write!(f, "timestamp {now} is before the previous point's {last}")
            }
            StepError::TimeOutOfRange => write!(f, "timestamp u64::MAX is reserved"),
            StepError::Arithmetic { atom } => {
                write!(f, "atom {atom}: integer overflow or division by zero")
            }
        }
    }
}

impl core::error::Error for StepError {}
"#;

/// `Run` and `Window<N, LO, HI>`: the ring of witness runs of a bounded `S[LO:HI]`.
pub(super) const WINDOW: &str = r#"
/// Witnesses of an `S[LO:HI]` at timestamps `first..=last`, gaps at most `HI - LO`.
#[derive(Clone, Copy, Debug)]
struct Run {
    first: u64,
    last: u64,
}

/// State of `f S[LO:HI] g` with `0 < LO <= HI`: a ring of at most `N` runs,
/// oldest at `head`; `N` is the most runs that can be live at once.
#[derive(Clone, Copy, Debug)]
struct Window<const N: usize, const LO: u64, const HI: u64> {
    head: u32,
    len: u32,
    runs: [Run; N],
}

impl<const N: usize, const LO: u64, const HI: u64> Window<N, LO, HI> {
    /// Checked when compiled: the bounds and capacity are valid.
    const VALID: () = assert!(N > 0 && N <= u32::MAX as usize && LO > 0 && LO <= HI);
    const EMPTY: Self = Window { head: 0, len: 0, runs: [Run { first: 0, last: 0 }; N] };

    #[inline(always)]
    fn clear(&mut self) {
        self.head = 0;
        self.len = 0;
    }

    /// One point at time `t` with `f` and `g`; true when a witness lies in `[t - HI, t - LO]`.
    #[inline(always)]
    fn step(&mut self, t: u64, f: bool, g: bool) -> bool {
        let () = Self::VALID;
        let mut head = self.head as usize % N;
        let mut len = if f { self.len as usize } else { 0 };
        // Expire runs whose last witness is older than t - HI.
        while len > 0 && self.runs[head % N].last.saturating_add(HI) < t {
            head = if head + 1 >= N { 0 } else { head + 1 };
            len -= 1;
        }
        if len == 0 {
            head = 0;
        }
        if g {
            let newest = head.wrapping_add(len).wrapping_add(N - 1) % N;
            if len > 0 && t.wrapping_sub(self.runs[newest].last) <= HI - LO {
                self.runs[newest].last = t;
            } else if len < N {
                self.runs[head.wrapping_add(len) % N] = Run { first: t, last: t };
                len += 1;
            }
            // len == N cannot happen: at most N runs are ever live at once.
        }
        self.head = head as u32;
        self.len = len as u32;
        len > 0 && self.runs[head % N].first.saturating_add(LO) <= t
    }
}
"#;
