//! clap value parsers for durations, rates and counts that refuse what would panic or hang later:
//! `inf`, `NaN`, negative and absurdly large values, each with one line saying what is allowed.
//! (`Duration::from_secs_f64(inf)` panics; `--seconds 1e300` would wait forever.)

/// Longest duration a command waits or runs for, seconds: a week. Longer runs leave the
/// duration out and stop with Ctrl+C.
pub const MAX_SECONDS: f64 = 7.0 * 24.0 * 3600.0;

/// Most frames a command can be asked to wait for: about 38 days at 30 fps.
pub const MAX_FRAMES: u64 = 100_000_000;

/// A number of seconds: finite, above 0 and at most [`MAX_SECONDS`].
///
/// # Errors
/// One line naming what is allowed.
pub fn seconds(text: &str) -> Result<f64, String> {
    finite_in(text, "seconds", 0.0, MAX_SECONDS)
}

/// A short deadline in seconds: finite, above 0 and at most 600 (ten minutes).
///
/// # Errors
/// One line naming what is allowed.
pub fn deadline_seconds(text: &str) -> Result<f64, String> {
    finite_in(text, "seconds", 0.0, 600.0)
}

/// A frame rate in frames per second: finite, above 0 and at most 1000.
///
/// # Errors
/// One line naming what is allowed.
pub fn rate_hz(text: &str) -> Result<f64, String> {
    finite_in(text, "frames per second", 0.0, 1000.0)
}

/// A number in `(above, at_most]`; `what` names its unit in the message.
fn finite_in(text: &str, what: &str, above: f64, at_most: f64) -> Result<f64, String> {
    let value: f64 = text
        .trim()
        .parse()
        .map_err(|_| format!("'{text}' is not a number of {what}"))?;
    if !value.is_finite() {
        return Err(format!(
            "{what} must be a finite number (at most {at_most}), not '{text}'"
        ));
    }
    if value <= above || value > at_most {
        return Err(format!(
            "{what} must be above {above} and at most {at_most}, not {value}"
        ));
    }
    Ok(value)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn non_finite_negative_zero_and_absurd_seconds_are_refused_with_a_reason() {
        for bad in ["inf", "-inf", "NaN", "nan", "-1", "0", "1e300", "x", ""] {
            let err = seconds(bad).expect_err(bad);
            assert!(err.contains("seconds"), "{bad}: {err}");
        }
        assert!(seconds("inf").unwrap_err().contains("finite"));
        assert!(seconds("1e300").unwrap_err().contains("at most 604800"));
        assert_eq!(seconds("2.5"), Ok(2.5));
        assert_eq!(seconds(" 60 "), Ok(60.0));
        assert_eq!(seconds("604800"), Ok(MAX_SECONDS));
        assert!(deadline_seconds("601").is_err());
        assert_eq!(deadline_seconds("0.5"), Ok(0.5));
        assert!(rate_hz("0").is_err() && rate_hz("NaN").is_err() && rate_hz("1001").is_err());
        assert_eq!(rate_hz("30"), Ok(30.0));
    }
}
