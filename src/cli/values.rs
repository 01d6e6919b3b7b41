//! Value parsers for the command line's numbers: every numeric option names the range it means,
//! so that `NaN`, `inf`, a negative count or an absurd size is refused by clap with the range in
//! the message, before any work (`tests/it/cli.rs` tries every numeric option the definition
//! lists).

use clap::builder::{RangedU64ValueParser, TypedValueParser};

/// Most frames a command makes or records in one run (about four days at 30 fps).
pub const MAX_FRAMES: u64 = 10_000_000;
/// Most pixels a frame has (4096 × 4096): the largest sensible pixel-count threshold.
pub const MAX_PIXELS: u64 = 4096 * 4096;
/// Longest duration an option may give, seconds (about 115 days).
pub const MAX_SECONDS: f64 = 1e7;

/// A finite number from `lo` to `hi` (both included).
#[must_use]
pub fn number_in(lo: f64, hi: f64) -> impl TypedValueParser<Value = f64> {
    move |text: &str| -> Result<f64, String> {
        match text.trim().parse::<f64>() {
            Ok(v) if v.is_finite() && (lo..=hi).contains(&v) => Ok(v),
            _ => Err(format!("must be a number from {lo} to {hi}, not '{text}'")),
        }
    }
}

/// A whole number from `lo` to `hi` (both included), as `T` (`usize`, `u32`, `u64`, `u8`).
#[must_use]
pub fn whole_in<T>(lo: u64, hi: u64) -> RangedU64ValueParser<T>
where
    T: TryFrom<u64> + Clone + Send + Sync + 'static,
    <T as TryFrom<u64>>::Error: std::error::Error + Send + Sync + 'static,
{
    RangedU64ValueParser::<T>::new().range(lo..=hi)
}

/// A seed: any whole number (every one makes a valid run).
#[must_use]
pub fn seed() -> RangedU64ValueParser<u64> {
    RangedU64ValueParser::<u64>::new()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_outside_their_range_or_not_finite_are_refused() {
        let cmd = clap::Command::new("t");
        let parse = |p: &dyn Fn(&str) -> bool, s: &str| p(s);
        let real = |s: &str| {
            number_in(0.0, 10.0)
                .parse_ref(&cmd, None, s.as_ref())
                .is_ok()
        };
        for ok in ["0", "2.5", "10"] {
            assert!(parse(&real, ok), "{ok}");
        }
        for bad in ["NaN", "inf", "-inf", "1e300", "-0.1", "10.01", "x"] {
            assert!(!parse(&real, bad), "{bad}");
        }
        let whole = |s: &str| {
            whole_in::<usize>(1, 100)
                .parse_ref(&cmd, None, s.as_ref())
                .is_ok()
        };
        assert!(whole("1") && whole("100"));
        for bad in ["0", "101", "-1", "18446744073709551615", "1.5"] {
            assert!(!whole(bad), "{bad}");
        }
    }
}
