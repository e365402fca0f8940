//! Durations and time units: the one place that reads `2.5s` and writes `2500ms` back.
//!
//! Every reader of a duration uses this module: formula bounds (the parser and the
//! checker), the main file's `<max_time>`, property files' `time_unit`, `--time-unit`
//! and sweep bounds on the command line, and the texts the sidecar and `verify` write.
//!
//! The accepted units are exactly [`TimeUnit::ALL`]: `ns`, `us`, `ms`, `s`, `min`.
//! That is the set of AS2FM's main-file reader (`scxml_helpers/roaml_model.py`,
//! `TIME_MULTIPLIERS`: `s`, `ms`, `us`, `ns`) plus `min`, which formulas have always
//! accepted. Spellings outside it (`µs`, `sec`, `h`) are errors everywhere, so a
//! duration that one reader accepts no other reader rejects.

/// A time unit suffix.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum TimeUnit {
    /// Nanoseconds, `ns`.
    Ns,
    /// Microseconds, `us`.
    Us,
    /// Milliseconds, `ms`.
    Ms,
    /// Seconds, `s`.
    S,
    /// Minutes, `min`.
    Min,
}

/// The accepted units in words, for error messages.
pub const UNITS_TEXT: &str = "ns, us, ms, s or min";

impl TimeUnit {
    /// Every unit, smallest first.
    pub const ALL: [TimeUnit; 5] = [
        TimeUnit::Ns,
        TimeUnit::Us,
        TimeUnit::Ms,
        TimeUnit::S,
        TimeUnit::Min,
    ];

    /// The unit a suffix names (`"ms"`), or `None` for anything else.
    pub fn from_suffix(s: &str) -> Option<TimeUnit> {
        TimeUnit::ALL.into_iter().find(|u| u.suffix() == s)
    }

    /// The suffix as written: `ns`, `us`, `ms`, `s`, `min`.
    pub fn suffix(self) -> &'static str {
        match self {
            TimeUnit::Ns => "ns",
            TimeUnit::Us => "us",
            TimeUnit::Ms => "ms",
            TimeUnit::S => "s",
            TimeUnit::Min => "min",
        }
    }

    /// Nanoseconds in one unit.
    pub fn nanos(self) -> u64 {
        match self {
            TimeUnit::Ns => 1,
            TimeUnit::Us => 1_000,
            TimeUnit::Ms => 1_000_000,
            TimeUnit::S => 1_000_000_000,
            TimeUnit::Min => 60_000_000_000,
        }
    }
}

/// The decimal `int.frac` (digits only; an empty `int` is 0) times `scale`, exactly, as
/// `(numerator, denominator)`: the value is `numerator / denominator`, the denominator
/// `10^k` for the fraction's `k` significant digits. `None` when it overflows `u128`.
/// [`decimal_times`] and the formula checker's bounds in ticks both compute with it.
pub(crate) fn scaled_decimal(int: &str, frac: &str, scale: u64) -> Option<(u128, u128)> {
    let frac = frac.trim_end_matches('0');
    let pow = 10u128.checked_pow(u32::try_from(frac.len()).ok()?)?;
    let int_v: u128 = if int.is_empty() { 0 } else { int.parse().ok()? };
    let frac_v: u128 = if frac.is_empty() {
        0
    } else {
        frac.parse().ok()?
    };
    let num = int_v
        .checked_mul(pow)?
        .checked_add(frac_v)?
        .checked_mul(u128::from(scale))?;
    Some((num, pow))
}

/// Why a duration (or a count of model steps) could not be read; each quotes the text
/// it is about and displays as one sentence. Returned by [`decimal_times`], [`parse`] and
/// [`parse_steps_or_duration`]; a caller puts its flag or file position in front.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum DurationError {
    /// Not a plain non-negative decimal number (`-1`, `1e3`, `.`, empty).
    NotDecimal(String),
    /// More precise than a nanosecond (`0.5ns`).
    FinerThanNanosecond(String),
    /// Does not fit in 64 bits (of nanoseconds or of steps).
    TooLarge(String),
    /// A number without a unit where a duration is required.
    NoUnit(String),
    /// A suffix that is not one of [`TimeUnit::ALL`].
    UnknownUnit(String),
    /// Neither a whole number of steps nor a number with a unit.
    NotStepsOrDuration(String),
    /// A fraction without a unit, where a plain number counts steps (`2.5`).
    FractionWithoutUnit(String),
}

impl std::fmt::Display for DurationError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            DurationError::NotDecimal(t) => write!(
                f,
                "`{t}` is not a non-negative decimal number (write `100` or `2.5`)"
            ),
            DurationError::FinerThanNanosecond(t) => write!(f, "`{t}` is finer than a nanosecond"),
            DurationError::TooLarge(t) => write!(f, "`{t}` is too large"),
            DurationError::NoUnit(t) => write!(f, "`{t}` has no time unit ({UNITS_TEXT})"),
            DurationError::UnknownUnit(u) => {
                write!(f, "unknown time unit `{u}` (use {UNITS_TEXT})")
            }
            DurationError::NotStepsOrDuration(t) => write!(
                f,
                "`{t}` is not a number of steps or a duration (write `62`, `6.2s` or `100ms`)"
            ),
            DurationError::FractionWithoutUnit(t) => {
                write!(f, "`{t}` has a fraction but no time unit ({UNITS_TEXT})")
            }
        }
    }
}

impl std::error::Error for DurationError {}

/// The decimal `text` (`100`, `2.5`, `.5`) times `scale` nanoseconds, exactly; an error
/// when it is negative, not a plain decimal, not a whole number of nanoseconds or too
/// large for `u64`.
pub fn decimal_times(text: &str, scale: u64) -> Result<u64, DurationError> {
    let (int, frac) = text.split_once('.').unwrap_or((text, ""));
    let digits = |s: &str| s.bytes().all(|b| b.is_ascii_digit());
    if (int.is_empty() && frac.is_empty()) || !digits(int) || !digits(frac) {
        return Err(DurationError::NotDecimal(text.to_owned()));
    }
    let finer = || DurationError::FinerThanNanosecond(text.to_owned());
    if frac.trim_end_matches('0').len() > 19 {
        return Err(finer());
    }
    let too_big = || DurationError::TooLarge(text.to_owned());
    let (num, pow) = scaled_decimal(int, frac, scale).ok_or_else(too_big)?;
    if num % pow != 0 {
        return Err(finer());
    }
    u64::try_from(num / pow).map_err(|_| too_big())
}

/// Splits `2.5ms` into the number `2.5` and the suffix `ms` (after trimming blanks).
pub fn split(text: &str) -> (&str, &str) {
    let t = text.trim();
    let at = t
        .find(|c: char| !(c.is_ascii_digit() || c == '.'))
        .unwrap_or(t.len());
    t.split_at(at)
}

/// Parses a duration with its unit (`100ms`, `2.5s`, `1min`) into nanoseconds, exactly.
pub fn parse(text: &str) -> Result<u64, DurationError> {
    let (number, suffix) = split(text);
    let Some(unit) = TimeUnit::from_suffix(suffix) else {
        return Err(if suffix.is_empty() {
            DurationError::NoUnit(text.trim().to_owned())
        } else {
            DurationError::UnknownUnit(suffix.to_owned())
        });
    };
    decimal_times(number, unit.nanos())
}

/// A duration in the largest unit that expresses it exactly: `1s`, `100ms`, `2500ns`,
/// `0ns`. [`parse`] reads it back to the same value.
pub fn format(ns: u64) -> String {
    for unit in TimeUnit::ALL.into_iter().rev() {
        let n = unit.nanos();
        if ns >= n && ns % n == 0 {
            return format!("{}{}", ns / n, unit.suffix());
        }
    }
    format!("{ns}ns")
}

/// A duration in seconds, as the command line and the reports write one: `0.1s`, `6.2s`,
/// `2s`, exact to the nanosecond.
pub fn seconds(ns: u64) -> String {
    let s = format!("{}.{:09}", ns / 1_000_000_000, ns % 1_000_000_000);
    format!("{}s", s.trim_end_matches('0').trim_end_matches('.'))
}

/// A length as the command line writes one (`--max-time`, sweep bounds): a plain
/// integer counts model steps, a number with a unit is a duration.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum StepsOrDuration {
    /// A plain integer: model time steps.
    Steps(u64),
    /// A duration with a unit, in nanoseconds.
    Nanos(u64),
}

/// Parses `62` (steps) or `6.2s`, `100ms`, `1.5min` (a duration, exactly).
pub fn parse_steps_or_duration(text: &str) -> Result<StepsOrDuration, DurationError> {
    let t = text.trim();
    let (num, unit) = split(t);
    let bad = || DurationError::NotStepsOrDuration(t.to_owned());
    if num.is_empty() || num.starts_with('.') || num.ends_with('.') {
        return Err(bad());
    }
    let (int, frac) = num.split_once('.').unwrap_or((num, ""));
    if frac.contains('.') {
        return Err(bad());
    }
    if unit.is_empty() {
        if frac.is_empty() {
            return int
                .parse()
                .map(StepsOrDuration::Steps)
                .map_err(|_| DurationError::TooLarge(t.to_owned()));
        }
        return Err(DurationError::FractionWithoutUnit(t.to_owned()));
    }
    parse(t).map(StepsOrDuration::Nanos)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn steps_or_durations() {
        use StepsOrDuration::{Nanos, Steps};
        assert_eq!(parse_steps_or_duration("62"), Ok(Steps(62)));
        assert_eq!(parse_steps_or_duration(" 6.2s"), Ok(Nanos(6_200_000_000)));
        assert_eq!(parse_steps_or_duration("1.5min"), Ok(Nanos(90_000_000_000)));
        let err = |t| parse_steps_or_duration(t).unwrap_err().to_string();
        assert!(
            err("2.5").contains("fraction but no time unit"),
            "{}",
            err("2.5")
        );
        assert!(err("s").contains("not a number of steps"));
        assert!(err("1.2.3s").contains("not a number of steps"));
        assert!(err("3parsecs").contains("unknown time unit `parsecs`"));
        assert!(err("99999999999999999999").contains("too large"));
        assert!(err("0.5ns").contains("finer than a nanosecond"));
        assert_eq!(seconds(6_200_000_000), "6.2s");
        assert_eq!(seconds(2_000_000_000), "2s");
        assert_eq!(seconds(100_000_000), "0.1s");
        assert_eq!(seconds(0), "0s");
    }

    #[test]
    fn exact_decimals() {
        let s = 1_000_000_000;
        assert_eq!(decimal_times("100", s), Ok(100 * s));
        assert_eq!(decimal_times("2.5", s), Ok(2_500_000_000));
        assert_eq!(decimal_times("0.000000001", s), Ok(1));
        assert_eq!(decimal_times(".5", 1_000), Ok(500));
        assert_eq!(decimal_times("1.50000", 1_000), Ok(1_500));
        assert!(decimal_times("1.5", 1).is_err());
        assert!(decimal_times("-1", s).is_err());
        assert!(decimal_times("1e3", s).is_err());
        assert!(decimal_times("", s).is_err());
        assert!(decimal_times(".", s).is_err());
        assert!(decimal_times("99999999999999999999999", s).is_err());
    }

    #[test]
    fn parse_and_format_agree() {
        assert_eq!(parse("100ms"), Ok(100_000_000));
        assert_eq!(parse(" 2.5s "), Ok(2_500_000_000));
        assert_eq!(parse("1.5min"), Ok(90_000_000_000));
        assert_eq!(parse("7ns"), Ok(7));
        for bad in ["5", "5µs", "5sec", "5h", "ms", "1.5ns", "-1s"] {
            assert!(parse(bad).is_err(), "{bad}");
        }
        // The error says which rule the text broke; callers match on it.
        assert_eq!(parse(" 5 "), Err(DurationError::NoUnit("5".into())));
        assert_eq!(parse("5h"), Err(DurationError::UnknownUnit("h".into())));
        assert_eq!(
            parse("1.5ns"),
            Err(DurationError::FinerThanNanosecond("1.5".into()))
        );
        assert_eq!(
            parse("5h").unwrap_err().to_string(),
            "unknown time unit `h` (use ns, us, ms, s or min)"
        );
        for ns in [
            0,
            1,
            999,
            1_000,
            2_500,
            100_000_000,
            1_000_000_000,
            90_000_000_000,
        ] {
            assert_eq!(parse(&format(ns)), Ok(ns), "{}", format(ns));
        }
        assert_eq!(format(0), "0ns");
        assert_eq!(format(1_000_000_000), "1s");
        assert_eq!(format(120_000_000_000), "2min");
        assert_eq!(format(1_500_000), "1500us");
    }
}
