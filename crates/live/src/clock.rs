//! Model time on the wall clock: one clock for the sidecar (`monitor`) and the paced simulator (`run`).

use std::time::{Duration, Instant};

/// A monotonic clock quantised to the spec's time unit: ticks of model time since the
/// sidecar started.
///
/// The monitored system may run `speed` times faster than real time (`hindsight run
/// --speed S`); the clock then counts model time, `ticks = elapsed * speed / tick`, so
/// the spec's bounds keep meaning model time. The speed is kept exactly to a millionth
/// (an integer ratio), so the arithmetic is exact and never decreases.
#[derive(Clone, Copy, Debug)]
pub struct Clock {
    start: Instant,
    tick_ns: u64,
    /// Millionths of the speed: model nanoseconds per 10^6 wall-clock nanoseconds.
    speed_micros: u64,
}

/// The slowest and fastest speeds a [`Clock`] takes.
pub const SPEED_RANGE: (f64, f64) = (1e-6, 1e9);

/// A speed outside [`SPEED_RANGE`] (or not a number); the caller names its flag or
/// file position in front.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpeedError(pub f64);

impl std::fmt::Display for SpeedError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "speed {}: must be a number from {} to {} (1: real time)",
            self.0, SPEED_RANGE.0, SPEED_RANGE.1
        )
    }
}

impl std::error::Error for SpeedError {}

/// Checks a speed for [`Clock::with_speed`]: finite, within [`SPEED_RANGE`].
pub fn check_speed(speed: f64) -> Result<f64, SpeedError> {
    if speed.is_finite() && speed >= SPEED_RANGE.0 && speed <= SPEED_RANGE.1 {
        Ok(speed)
    } else {
        Err(SpeedError(speed))
    }
}

impl Clock {
    /// A real-time clock starting now with ticks of `tick_ns` nanoseconds.
    pub fn new(tick_ns: u64) -> Self {
        Self::with_speed(tick_ns, 1.0)
    }

    /// A clock starting now that counts ticks of `tick_ns` nanoseconds of model time in a
    /// system running `speed` times faster than real time (rounded to a millionth and
    /// clamped to [`SPEED_RANGE`]; see [`check_speed`]).
    pub fn with_speed(tick_ns: u64, speed: f64) -> Self {
        let speed = if speed.is_nan() {
            1.0
        } else {
            speed.clamp(SPEED_RANGE.0, SPEED_RANGE.1)
        };
        Clock {
            start: Instant::now(),
            tick_ns: tick_ns.max(1),
            speed_micros: (speed * 1e6).round() as u64,
        }
    }

    /// Restarts the clock so that now is tick 0 and later instants are rounded to the
    /// nearest tick instead of truncated: it starts half a tick of wall-clock time ago.
    /// A system that steps on whole ticks from now on is stamped on whole ticks despite
    /// up to half a tick of scheduling jitter either way.
    pub(crate) fn anchor_now(&mut self) {
        let half_tick_wall_ns =
            (self.tick_ns as u128 * 1_000_000 / (2 * self.speed_micros.max(1) as u128)) as u64;
        let now = Instant::now();
        self.start = now
            .checked_sub(Duration::from_nanos(half_tick_wall_ns))
            .unwrap_or(now);
    }

    /// Whole ticks elapsed since the start (never decreases).
    pub fn now(&self) -> u64 {
        self.ticks(self.start.elapsed())
    }

    /// The wall-clock instant at which model tick `tick` happens (the inverse of
    /// [`Clock::now`]: `now()` reads at least `tick` from then on), saturating far out.
    pub fn due(&self, tick: u64) -> Instant {
        let wall_ns = (tick as u128 * self.tick_ns as u128 * 1_000_000)
            .div_ceil(self.speed_micros.max(1) as u128);
        let wall = Duration::from_nanos(u64::try_from(wall_ns).unwrap_or(u64::MAX));
        self.start
            .checked_add(wall)
            .unwrap_or(self.start + Duration::from_secs(1 << 40))
    }

    /// The tick the clock read `age` of wall-clock time ago, or `None` when that was
    /// before the clock started (see [`Clock::now`]).
    pub(crate) fn ticks_ago(&self, age: Duration) -> Option<u64> {
        self.start.elapsed().checked_sub(age).map(|e| self.ticks(e))
    }

    /// Whole ticks of model time in `elapsed` wall-clock time:
    /// `floor(elapsed * speed / tick)`, saturating.
    pub fn ticks(&self, elapsed: Duration) -> u64 {
        let model_ns = elapsed.as_nanos().saturating_mul(self.speed_micros as u128);
        let t = model_ns / (self.tick_ns as u128 * 1_000_000);
        u64::try_from(t).unwrap_or(u64::MAX)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn due_is_the_first_instant_a_tick_is_read() {
        for (tick_ns, speed) in [
            (100_000_000, 1.0),
            (10_000_000, 5.0),
            (1_000, 0.25),
            (7, 3.3),
        ] {
            let c = Clock::with_speed(tick_ns, speed);
            for tick in [0, 1, 2, 9, 1000, 123_457] {
                let wall = c.due(tick) - c.start;
                assert!(c.ticks(wall) >= tick, "{tick_ns} {speed} {tick}");
                if tick > 0 && wall > Duration::ZERO {
                    let before = wall - Duration::from_nanos(1);
                    assert!(c.ticks(before) < tick, "{tick_ns} {speed} {tick}");
                }
            }
        }
    }

    #[test]
    fn clock_counts_model_time_at_any_speed() {
        let ms = Duration::from_millis;
        // Real time, 100 ms ticks: whole ticks, rounded down.
        let c = Clock::new(100_000_000);
        assert_eq!(c.ticks(ms(0)), 0);
        assert_eq!(c.ticks(ms(99)), 0);
        assert_eq!(c.ticks(ms(100)), 1);
        assert_eq!(c.ticks(ms(2_550)), 25);
        // Ten times faster: 10 ms of wall-clock time is one 100 ms tick of model time.
        let c = Clock::with_speed(100_000_000, 10.0);
        assert_eq!(c.ticks(ms(9)), 0);
        assert_eq!(c.ticks(ms(10)), 1);
        assert_eq!(c.ticks(ms(1_000)), 100);
        // Slower than real time, exactly at the boundaries (no floating rounding).
        let c = Clock::with_speed(100_000_000, 0.1);
        assert_eq!(c.ticks(Duration::from_nanos(999_999_999)), 0);
        assert_eq!(c.ticks(ms(1_000)), 1);
        let c = Clock::with_speed(1_000_000, 2.5);
        assert_eq!(c.ticks(Duration::from_nanos(399_999)), 0);
        assert_eq!(c.ticks(Duration::from_nanos(400_000)), 1);
        assert_eq!(c.ticks(ms(4)), 10);
        // Saturates instead of wrapping.
        let c = Clock::with_speed(1, SPEED_RANGE.1);
        assert_eq!(c.ticks(Duration::MAX), u64::MAX);
    }

    #[test]
    fn clock_ticks_never_decrease() {
        let c = Clock::with_speed(100_000_000, 3.7);
        let mut last = 0;
        for ns in (0..5_000_000_000u64).step_by(7_777_777) {
            let t = c.ticks(Duration::from_nanos(ns));
            assert!(t >= last);
            last = t;
        }
        assert_eq!(last, 184); // floor(4.9933 s * 3.7 / 0.1 s), the last time taken
    }

    #[test]
    fn speeds_are_checked() {
        assert_eq!(check_speed(1.0), Ok(1.0));
        assert_eq!(check_speed(10.0), Ok(10.0));
        for bad in [0.0, -1.0, f64::NAN, f64::INFINITY, 1e-7, 1e10] {
            assert!(check_speed(bad).is_err(), "{bad}");
        }
    }
}
