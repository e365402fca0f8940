//! The one rule from a rate in hertz, as a model writes it, to a period in nanoseconds:
//! the BT tick rate of a main file (`<bt_tick_rate>`) and the ROS timers
//! (`<ros_time_rate rate_hz>`) both read their rate here.
//!
//! The period is exact whenever it is a whole number of nanoseconds: a plain decimal
//! `m / 10^k` is divided in integers (`1e9 * 10^k / m`), never through a float, so that
//! `0.00000015625` Hz is 6 400 000 000 000 000 ns and not one less.

/// A rate and its period.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RatePeriod {
    /// Ticks per second, as written.
    pub hz: f64,
    /// The period in nanoseconds: exact when `exact`, otherwise `1e9 / hz` rounded to the
    /// nearest nanosecond.
    pub period_ns: u64,
    /// Whether `period_ns` is exactly the period of `hz`.
    pub exact: bool,
}

/// Why a rate has no period.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RateError {
    /// Not a number, or not a finite number above zero.
    NotPositive,
    /// A period shorter than half a nanosecond.
    FasterThanNs,
    /// A period of 2^64 ns (about 584 years) or more: it does not fit the time unit.
    TooSlow,
}

/// The period of the rate written `text` (a number of hertz; `10`, `0.5`, `1e1`).
pub fn period(text: &str) -> Result<RatePeriod, RateError> {
    let hz: f64 = text.parse().map_err(|_| RateError::NotPositive)?;
    if !(hz.is_finite() && hz > 0.0) {
        return Err(RateError::NotPositive);
    }
    // Exact period when the rate is a plain decimal m / 10^k: 1e9 * 10^k / m.
    let (int, frac) = text.split_once('.').unwrap_or((text, ""));
    let frac = frac.trim_end_matches('0');
    let exact_ns = if int.bytes().all(|b| b.is_ascii_digit())
        && frac.bytes().all(|b| b.is_ascii_digit())
        && frac.len() <= 18
    {
        format!("{int}{frac}")
            .parse::<u128>()
            .ok()
            .filter(|m| *m > 0)
            .and_then(|m| {
                let n = 1_000_000_000u128 * 10u128.pow(frac.len() as u32);
                (n % m == 0).then(|| n / m)
            })
    } else {
        None
    };
    let period = 1e9 / hz;
    if period.round() < 1.0 {
        return Err(RateError::FasterThanNs);
    }
    // The period must fit the time unit (nanoseconds, 64 bits: about 584 years).
    if period >= u64::MAX as f64 {
        return Err(RateError::TooSlow);
    }
    // A rate written otherwise (`1e1`) is exact when its period is a whole number of
    // nanoseconds that gives the rate back.
    let exact_ns = exact_ns
        .and_then(|n| u64::try_from(n).ok())
        .or_else(|| (period.fract() == 0.0 && 1e9 / period == hz).then_some(period as u64));
    Ok(match exact_ns {
        Some(ns) => RatePeriod {
            hz,
            period_ns: ns,
            exact: true,
        },
        None => RatePeriod {
            hz,
            period_ns: period.round() as u64,
            exact: false,
        },
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ns(text: &str) -> (u64, bool) {
        let p = period(text).unwrap();
        (p.period_ns, p.exact)
    }

    #[test]
    fn periods() {
        assert_eq!(ns("10.0"), (100_000_000, true));
        assert_eq!(ns("0.5"), (2_000_000_000, true));
        assert_eq!(ns("1e1"), (100_000_000, true));
        assert_eq!(ns("3"), (333_333_333, false));
        assert_eq!(period("1e-12"), Err(RateError::TooSlow));
        assert_eq!(period("3e9"), Err(RateError::FasterThanNs));
        for bad in ["0", "-1", "fast", "inf", "NaN", ""] {
            assert_eq!(period(bad), Err(RateError::NotPositive), "{bad}");
        }
    }

    /// The ROS timers divided in floats and rounded (`(1e9 / hz).round()`), the BT tick
    /// rate in integers: for a slow rate the two disagreed by a nanosecond. Both use this.
    #[test]
    fn a_slow_decimal_rate_has_its_exact_period() {
        let float_rounded = (1e9f64 / 0.00000015625).round() as u64;
        assert_eq!(float_rounded, 6_399_999_999_999_999);
        assert_eq!(ns("0.00000015625"), (6_400_000_000_000_000, true));
    }
}
