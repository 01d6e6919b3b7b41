//! Least-squares fits on image points (pixels, FORMATS.md image coordinates): circles for the
//! ball, straight lines for goal posts, and the rotation about a centre that turns "parallel to
//! the horizon" into "parallel to the image rows".

use serde::{Deserialize, Serialize};

/// A point in image coordinates, pixels (x right, y down; pixel centres at +0.5).
pub type Point = (f64, f64);

/// Rotates `p` about `centre` by `angle` radians (counter-clockwise on screen for positive
/// angles, i.e. with y down the rotation appears clockwise).
#[must_use]
pub fn rotate_about(p: Point, centre: Point, angle: f64) -> Point {
    let (s, c) = angle.sin_cos();
    let (dx, dy) = (p.0 - centre.0, p.1 - centre.1);
    (centre.0 + c * dx - s * dy, centre.1 + s * dx + c * dy)
}

/// A fitted circle, pixels.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct CircleFit {
    /// Centre x, pixels.
    pub center_x: f64,
    /// Centre y, pixels.
    pub center_y: f64,
    /// Radius, pixels.
    pub radius: f64,
    /// Standard deviation of the points' distances from the circle, pixels.
    pub residual_sd: f64,
    /// Number of points used.
    pub points: usize,
}

/// Fits a circle to at least three points: an algebraic (Kåsa) fit for the start, refined by a
/// few Gauss–Newton steps on the geometric distances, which removes the algebraic fit's bias
/// towards small circles on short arcs (a ball cut off by the image edge). `None` for fewer than
/// three points, collinear points or non-finite input.
#[must_use]
pub fn fit_circle(points: &[Point]) -> Option<CircleFit> {
    if points.len() < 3 || points.iter().any(|p| !p.0.is_finite() || !p.1.is_finite()) {
        return None;
    }
    let n = points.len() as f64;
    let (mx, my) = points
        .iter()
        .fold((0.0, 0.0), |(a, b), p| (a + p.0 / n, b + p.1 / n));
    // Kåsa in centred coordinates: minimise Σ (u² + v² − 2au − 2bv − c)².
    let (mut suu, mut suv, mut svv, mut suz, mut svz) = (0.0, 0.0, 0.0, 0.0, 0.0);
    for p in points {
        let (u, v) = (p.0 - mx, p.1 - my);
        let z = u * u + v * v;
        suu += u * u;
        suv += u * v;
        svv += v * v;
        suz += u * z;
        svz += v * z;
    }
    let det = suu * svv - suv * suv;
    let scale = (suu + svv).max(f64::MIN_POSITIVE);
    if det.abs() <= 1e-12 * scale * scale {
        return None;
    }
    let a = (suz * svv - svz * suv) / (2.0 * det);
    let b = (svz * suu - suz * suv) / (2.0 * det);
    let mut cx = a + mx;
    let mut cy = b + my;
    let mut r = points
        .iter()
        .map(|p| ((p.0 - cx).powi(2) + (p.1 - cy).powi(2)).sqrt())
        .sum::<f64>()
        / n;
    // Gauss–Newton on residuals d_i − r.
    for _ in 0..20 {
        let mut jtj = [[0.0f64; 3]; 3];
        let mut jtr = [0.0f64; 3];
        for p in points {
            let (dx, dy) = (p.0 - cx, p.1 - cy);
            let d = (dx * dx + dy * dy).sqrt();
            if d < 1e-12 {
                continue;
            }
            let j = [-dx / d, -dy / d, -1.0];
            let res = d - r;
            for row in 0..3 {
                jtr[row] += j[row] * res;
                for col in 0..3 {
                    jtj[row][col] += j[row] * j[col];
                }
            }
        }
        let Some(step) = solve3(jtj, jtr) else { break };
        cx -= step[0];
        cy -= step[1];
        r -= step[2];
        if step.iter().all(|s| s.abs() < 1e-9) {
            break;
        }
    }
    if !(cx.is_finite() && cy.is_finite() && r.is_finite() && r > 0.0) {
        return None;
    }
    let var = points
        .iter()
        .map(|p| (((p.0 - cx).powi(2) + (p.1 - cy).powi(2)).sqrt() - r).powi(2))
        .sum::<f64>()
        / n;
    Some(CircleFit {
        center_x: cx,
        center_y: cy,
        radius: r,
        residual_sd: var.sqrt(),
        points: points.len(),
    })
}

/// [`fit_circle`], then once more without the points farther from the circle than
/// `max(k_sd · residual SD, min_px)` pixels, when those are at most `max_share` of the points
/// (a classified outline has single noisy pixels; a shape that is not a circle has many points
/// off it and keeps its large residual). Returns the first fit when nothing is dropped or the
/// refit fails.
#[must_use]
pub fn fit_circle_trimmed(
    points: &[Point],
    k_sd: f64,
    min_px: f64,
    max_share: f64,
) -> Option<CircleFit> {
    let first = fit_circle(points)?;
    let limit = (k_sd * first.residual_sd).max(min_px);
    let keep: Vec<Point> = points
        .iter()
        .copied()
        .filter(|p| {
            (((p.0 - first.center_x).powi(2) + (p.1 - first.center_y).powi(2)).sqrt()
                - first.radius)
                .abs()
                <= limit
        })
        .collect();
    let dropped = points.len() - keep.len();
    if dropped == 0 || dropped as f64 > max_share * points.len() as f64 || keep.len() < 5 {
        return Some(first);
    }
    fit_circle(&keep).or(Some(first))
}

/// Solves a 3×3 system by Cramer's rule; `None` when singular.
fn solve3(m: [[f64; 3]; 3], b: [f64; 3]) -> Option<[f64; 3]> {
    let det3 = |m: &[[f64; 3]; 3]| {
        m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
            - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
    };
    let d = det3(&m);
    if !d.is_finite() || d.abs() < 1e-12 {
        return None;
    }
    let mut out = [0.0; 3];
    for (col, slot) in out.iter_mut().enumerate() {
        let mut mc = m;
        for row in 0..3 {
            mc[row][col] = b[row];
        }
        *slot = det3(&mc) / d;
    }
    Some(out)
}

/// A fitted straight line, pixels. Stored as `x = slope·y + intercept` when `steep` (near
/// vertical, the usual case for goal posts) and `y = slope·x + intercept` otherwise, so the slope
/// never becomes infinite.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct LineFit {
    /// True when x was regressed on y.
    pub steep: bool,
    /// Slope of the regression (dimensionless).
    pub slope: f64,
    /// Intercept of the regression, pixels.
    pub intercept: f64,
    /// Coefficient of determination r² (0..1; 1 for a perfect fit, also for a zero-variance
    /// dependent variable).
    pub r_squared: f64,
    /// Residual variance s² = Σ residual² / (n − 2), pixels².
    pub residual_variance: f64,
    /// Number of points used.
    pub points: usize,
}

impl LineFit {
    /// The point of the line at image row `y` (for a steep line) or column `x` (otherwise).
    #[must_use]
    pub fn at(&self, t: f64) -> Point {
        let s = self.slope * t + self.intercept;
        if self.steep { (s, t) } else { (t, s) }
    }
}

/// Least-squares line through at least two distinct points from sums of squares. x and y are
/// swapped when the points spread more vertically than horizontally, so vertical posts fit as
/// well as horizontal bars. `None` for fewer than two points, all points equal, non-finite
/// input or sums that overflow; never divides by zero.
#[must_use]
pub fn fit_line(points: &[Point]) -> Option<LineFit> {
    if points.len() < 2 || points.iter().any(|p| !p.0.is_finite() || !p.1.is_finite()) {
        return None;
    }
    let n = points.len() as f64;
    let (mx, my) = points
        .iter()
        .fold((0.0, 0.0), |(a, b), p| (a + p.0 / n, b + p.1 / n));
    let (mut sxx, mut syy, mut sxy) = (0.0, 0.0, 0.0);
    for p in points {
        let (dx, dy) = (p.0 - mx, p.1 - my);
        sxx += dx * dx;
        syy += dy * dy;
        sxy += dx * dy;
    }
    let steep = syy > sxx;
    // Regress "dependent" on "independent".
    let (sii, sdd, mi, md) = if steep {
        (syy, sxx, my, mx)
    } else {
        (sxx, syy, mx, my)
    };
    if sii <= 0.0 {
        return None;
    }
    let slope = sxy / sii;
    let intercept = md - slope * mi;
    if !(slope.is_finite() && intercept.is_finite()) {
        // Sums overflowed (coordinates near f64::MAX): no usable line.
        return None;
    }
    let ss_res = (sdd - slope * sxy).max(0.0);
    let r_squared = if sdd > 0.0 {
        (1.0 - ss_res / sdd).clamp(0.0, 1.0)
    } else {
        1.0
    };
    let residual_variance = if points.len() > 2 {
        ss_res / (n - 2.0)
    } else {
        0.0
    };
    Some(LineFit {
        steep,
        slope,
        intercept,
        r_squared,
        residual_variance,
        points: points.len(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn arc(cx: f64, cy: f64, r: f64, from: f64, to: f64, n: usize) -> Vec<Point> {
        (0..n)
            .map(|i| {
                let t = from + (to - from) * i as f64 / (n - 1) as f64;
                (cx + r * t.cos(), cy + r * t.sin())
            })
            .collect()
    }

    #[test]
    fn circle_from_full_and_partial_arcs() {
        let full = fit_circle(&arc(50.0, 40.0, 12.0, 0.0, 6.0, 30)).expect("fit");
        assert!((full.center_x - 50.0).abs() < 1e-6 && (full.center_y - 40.0).abs() < 1e-6);
        assert!((full.radius - 12.0).abs() < 1e-6 && full.residual_sd < 1e-6);
        // A quarter arc with alternating ±0.3 px noise: the geometric refinement keeps the radius.
        let mut pts = arc(10.0, 100.0, 30.0, -1.5, 0.0, 20);
        for (i, p) in pts.iter_mut().enumerate() {
            p.0 += if i % 2 == 0 { 0.3 } else { -0.3 };
        }
        let part = fit_circle(&pts).expect("fit");
        assert!((part.radius - 30.0).abs() < 1.0, "radius {}", part.radius);
        assert!(part.residual_sd > 0.0);
    }

    #[test]
    fn trimming_drops_a_stray_point_but_not_a_shape() {
        let mut pts = arc(20.0, 20.0, 8.0, 0.0, 6.0, 24);
        pts[5].0 += 4.0;
        let plain = fit_circle(&pts).expect("fit");
        let trimmed = fit_circle_trimmed(&pts, 2.5, 1.0, 0.2).expect("fit");
        assert!((trimmed.radius - 8.0).abs() < 1e-6 && trimmed.points == 23);
        assert!((plain.radius - 8.0).abs() > (trimmed.radius - 8.0).abs());
        // A square's outline is not a circle: too many points would go, so nothing does.
        let square: Vec<Point> = (0..40)
            .map(|i| {
                let t = f64::from(i % 10);
                match i / 10 {
                    0 => (t, 0.0),
                    1 => (10.0, t),
                    2 => (10.0 - t, 10.0),
                    _ => (0.0, 10.0 - t),
                }
            })
            .collect();
        let s = fit_circle_trimmed(&square, 1.0, 0.1, 0.15).expect("fit");
        assert_eq!(s.points, 40);
    }

    #[test]
    fn degenerate_circles_are_refused() {
        assert!(fit_circle(&[(0.0, 0.0), (1.0, 1.0)]).is_none());
        assert!(fit_circle(&[(0.0, 0.0), (1.0, 1.0), (2.0, 2.0), (3.0, 3.0)]).is_none());
        assert!(fit_circle(&[(0.0, 0.0), (1.0, f64::NAN), (2.0, 5.0)]).is_none());
        assert!(fit_circle(&[(4.0, 4.0); 5]).is_none());
    }

    #[test]
    fn lines_fit_both_ways_without_dividing_by_zero() {
        let vertical: Vec<Point> = (0..10).map(|i| (20.0, f64::from(i))).collect();
        let v = fit_line(&vertical).expect("vertical");
        assert!(v.steep && v.slope.abs() < 1e-12 && (v.intercept - 20.0).abs() < 1e-12);
        assert_eq!(v.r_squared, 1.0);
        let tilted: Vec<Point> = (0..10)
            .map(|i| (f64::from(i), 2.0 * f64::from(i) + 1.0))
            .collect();
        let t = fit_line(&tilted).expect("tilted");
        assert!(t.steep, "dy spreads more than dx");
        let (x, y) = t.at(5.0);
        assert!((x - 2.0).abs() < 1e-9 && (y - 5.0).abs() < 1e-9);
        let noisy = [(0.0, 0.0), (1.0, 1.0), (2.0, 0.0), (3.0, 1.0)];
        let n = fit_line(&noisy).expect("noisy");
        assert!(!n.steep && n.r_squared < 0.5 && n.residual_variance > 0.0);
        assert!(fit_line(&[(1.0, 1.0), (1.0, 1.0)]).is_none());
        assert!(fit_line(&[(1.0, 1.0)]).is_none());
        assert!(fit_line(&[(1e300, 1e300), (-1e300, -1e300), (1e300, 1e300)]).is_none());
        assert!(fit_line(&[(0.0, 0.0), (f64::INFINITY, 1.0)]).is_none());
    }

    #[test]
    fn rotation_about_a_centre() {
        let p = rotate_about((11.0, 5.0), (10.0, 5.0), std::f64::consts::FRAC_PI_2);
        assert!((p.0 - 10.0).abs() < 1e-12 && (p.1 - 6.0).abs() < 1e-12);
        let back = rotate_about(p, (10.0, 5.0), -std::f64::consts::FRAC_PI_2);
        assert!((back.0 - 11.0).abs() < 1e-12 && (back.1 - 5.0).abs() < 1e-12);
    }
}
