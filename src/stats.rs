//! Small statistics shared by recognition, evaluation and the CLI: the median and the
//! inverse-size least squares (distance = multiplier / size + offset) that goal calibration and
//! the coloured patterns' size relation both fit.

/// The median of `samples` (the upper of the two middle values for an even count, as a sample
/// of the data); `None` for none.
#[must_use]
pub fn median(samples: &[f64]) -> Option<f64> {
    if samples.is_empty() {
        return None;
    }
    let mut sorted = samples.to_vec();
    sorted.sort_by(f64::total_cmp);
    Some(sorted[sorted.len() / 2])
}

/// Least squares of distance = multiplier / size + offset over `(size, distance)` pairs, in
/// 1 / size: `(multiplier, offset)`. Pairs with a non-positive or non-finite size or a
/// non-finite distance are left out; `None` with fewer than two usable pairs or sizes too
/// alike to separate multiplier and offset.
#[must_use]
pub fn fit_inverse_size(samples: &[(f64, f64)]) -> Option<(f64, f64)> {
    let pts: Vec<(f64, f64)> = samples
        .iter()
        .filter(|(s, d)| *s > 0.0 && s.is_finite() && d.is_finite())
        .map(|(s, d)| (1.0 / s, *d))
        .collect();
    if pts.len() < 2 {
        return None;
    }
    let n = pts.len() as f64;
    let (mx, my) = pts
        .iter()
        .fold((0.0, 0.0), |(a, b), p| (a + p.0 / n, b + p.1 / n));
    let (sxx, sxy) = pts.iter().fold((0.0, 0.0), |(a, b), p| {
        (a + (p.0 - mx).powi(2), b + (p.0 - mx) * (p.1 - my))
    });
    if sxx.is_nan() || sxx <= 1e-18 {
        return None;
    }
    let m = sxy / sxx;
    let o = my - m * mx;
    (m.is_finite() && o.is_finite()).then_some((m, o))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_median_is_the_upper_middle_value_and_none_of_nothing() {
        assert_eq!(median(&[3.0, 1.0, 2.0]), Some(2.0));
        assert_eq!(median(&[4.0, 1.0, 3.0, 2.0]), Some(3.0));
        assert_eq!(median(&[]), None);
    }

    #[test]
    fn inverse_size_fit_recovers_an_exact_relation_and_refuses_one_size() {
        let samples: Vec<(f64, f64)> = [5.0, 10.0, 20.0, 40.0]
            .iter()
            .map(|&s| (s, 1500.0 / s + 6.0))
            .collect();
        let (m, o) = fit_inverse_size(&samples).expect("fit");
        assert!(
            (m - 1500.0).abs() < 1e-6 && (o - 6.0).abs() < 1e-6,
            "{m} {o}"
        );
        assert_eq!(fit_inverse_size(&[(10.0, 100.0), (10.0, 120.0)]), None);
        assert_eq!(fit_inverse_size(&[(10.0, 100.0), (f64::NAN, 1.0)]), None);
    }
}
