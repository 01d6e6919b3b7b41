//! Least-squares fits on [`ImagePoint`]s (pixels, FORMATS.md image coordinates): circles for
//! the ball, the moving circle of a rolling shutter, and straight lines for goal posts.

use nalgebra::{Matrix3, SMatrix, SVector, Vector3};
use serde::{Deserialize, Serialize};

use crate::geometry::ImagePoint;

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

impl CircleFit {
    /// The centre, pixels.
    #[must_use]
    pub fn center(&self) -> ImagePoint {
        ImagePoint::new(self.center_x, self.center_y)
    }
}

/// Fits a circle to at least three points: an algebraic (Kåsa) fit for the start, refined by a
/// few Gauss–Newton steps on the geometric distances, which removes the algebraic fit's bias
/// towards small circles on short arcs (a ball cut off by the image edge). `None` for fewer than
/// three points, collinear points or non-finite input.
#[must_use]
pub fn fit_circle(points: &[ImagePoint]) -> Option<CircleFit> {
    if points.len() < 3
        || points
            .iter()
            .any(|p| !p.x_px.is_finite() || !p.y_px.is_finite())
    {
        return None;
    }
    let n = points.len() as f64;
    let (mx, my) = points
        .iter()
        .fold((0.0, 0.0), |(a, b), p| (a + p.x_px / n, b + p.y_px / n));
    // Kåsa in centred coordinates: minimise Σ (u² + v² − 2au − 2bv − c)².
    let (mut suu, mut suv, mut svv, mut suz, mut svz) = (0.0, 0.0, 0.0, 0.0, 0.0);
    for p in points {
        let (u, v) = (p.x_px - mx, p.y_px - my);
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
        .map(|p| ((p.x_px - cx).powi(2) + (p.y_px - cy).powi(2)).sqrt())
        .sum::<f64>()
        / n;
    // Gauss–Newton on residuals d_i − r.
    for _ in 0..20 {
        let mut jtj = Matrix3::<f64>::zeros();
        let mut jtr = Vector3::<f64>::zeros();
        for p in points {
            let (dx, dy) = (p.x_px - cx, p.y_px - cy);
            let d = (dx * dx + dy * dy).sqrt();
            if d < 1e-12 {
                continue;
            }
            let j = Vector3::new(-dx / d, -dy / d, -1.0);
            jtr += j * (d - r);
            jtj += j * j.transpose();
        }
        let Some(step) = solve3(&jtj, &jtr) else {
            break;
        };
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
        .map(|p| (((p.x_px - cx).powi(2) + (p.y_px - cy).powi(2)).sqrt() - r).powi(2))
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
    points: &[ImagePoint],
    k_sd: f64,
    min_px: f64,
    max_share: f64,
) -> Option<CircleFit> {
    let first = fit_circle(points)?;
    let limit = (k_sd * first.residual_sd).max(min_px);
    let keep: Vec<ImagePoint> = points
        .iter()
        .copied()
        .filter(|p| {
            (((p.x_px - first.center_x).powi(2) + (p.y_px - first.center_y).powi(2)).sqrt()
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

/// A circle seen by a rolling shutter while it moved: the constrained ellipse of a ball that
/// moves in the image during read-out (after the camera's own skew is removed). Row `y` is read
/// `y − reference_row` lines after the reference row, by which time the ball's centre has moved
/// by `(shear_x, shear_y) · (y − reference_row)` pixels; undoing that puts every outline point
/// on one circle. So the model is a circle plus one shear parameter per axis.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ShearedCircleFit {
    /// The circle at the reference row's read-out time (centre, radius, residual SD), pixels.
    pub circle: CircleFit,
    /// Horizontal motion of the centre per image row read, pixels per line.
    pub shear_x: f64,
    /// Vertical motion of the centre per image row read, pixels per line.
    pub shear_y: f64,
    /// Standard error of `shear_x` from the fit's covariance, pixels per line.
    pub shear_x_sd: f64,
    /// Standard error of `shear_y`, pixels per line.
    pub shear_y_sd: f64,
}

impl ShearedCircleFit {
    /// The centre's image velocity, pixels per second, when one line takes `line_time_s`
    /// seconds to read.
    #[must_use]
    pub fn velocity_px_s(&self, line_time_s: f64) -> (f64, f64) {
        (self.shear_x / line_time_s, self.shear_y / line_time_s)
    }
}

/// Fits a circle that moved while its rows were read out: `points[i]` was read at image row
/// `rows[i]` (usually its own y before any skew removal moved it), and the centre moves
/// `(shear_x, shear_y)` pixels per line. Starts from the plain circle fit and refines all five
/// parameters (centre, radius, two shears) by damped Gauss–Newton on the geometric distances
/// of the points moved back to the reference row's time.
///
/// With `vertical_shear` false the vertical shear is held at zero (four parameters): a vertical
/// motion only stretches the outline vertically, by a few tenths of a pixel for a ball, which
/// the classified outline's own unevenness (shading at top and bottom) can swamp.
///
/// `None` for fewer than 6 points (five parameters and at least one degree of freedom), a
/// length mismatch, non-finite input, collinear points, or a fit that does not converge to a
/// finite positive radius. A short arc leaves the shear poorly determined: callers should look
/// at `shear_x_sd` / `shear_y_sd`.
#[must_use]
pub fn fit_sheared_circle(
    points: &[ImagePoint],
    rows: &[f64],
    reference_row: f64,
    vertical_shear: bool,
) -> Option<ShearedCircleFit> {
    if points.len() < 6
        || rows.len() != points.len()
        || !reference_row.is_finite()
        || rows.iter().any(|r| !r.is_finite())
    {
        return None;
    }
    let start = fit_circle(points)?;
    let problem = ShearedCircle {
        points,
        lines_after_reference: rows.iter().map(|r| r - reference_row).collect(),
        vertical_shear,
    };
    let (q, cost) = problem.refine([start.center_x, start.center_y, start.radius, 0.0, 0.0]);
    if !(q.iter().all(|v| v.is_finite()) && q[2] > 0.0) {
        return None;
    }
    Some(problem.result(&q, cost))
}

/// The sheared-circle least-squares problem of [`fit_sheared_circle`]. Its parameters `q` are
/// the centre x and y, the radius (pixels) and the horizontal and vertical shear (pixels per
/// line).
struct ShearedCircle<'a> {
    points: &'a [ImagePoint],
    /// Per point, lines read after the reference row (negative: before).
    lines_after_reference: Vec<f64>,
    /// Fit the vertical shear too (else it is held at zero).
    vertical_shear: bool,
}

impl ShearedCircle<'_> {
    /// A point moved back to the reference row's time, relative to the centre.
    fn unsheared(q: &[f64; 5], p: ImagePoint, s: f64) -> (f64, f64) {
        (p.x_px - q[3] * s - q[0], p.y_px - q[4] * s - q[1])
    }

    /// Sum of squared geometric distances to the circle, pixels².
    fn cost(&self, q: &[f64; 5]) -> f64 {
        self.points
            .iter()
            .zip(&self.lines_after_reference)
            .map(|(p, s)| {
                let (ux, uy) = Self::unsheared(q, *p, *s);
                ((ux * ux + uy * uy).sqrt() - q[2]).powi(2)
            })
            .sum()
    }

    /// The normal equations JᵀJ and Jᵀr at `q`; without the vertical shear its equation
    /// becomes "step = 0".
    fn normal(&self, q: &[f64; 5]) -> (Matrix5, Vector5) {
        let mut jtj = Matrix5::zeros();
        let mut jtr = Vector5::zeros();
        for (p, s) in self.points.iter().zip(&self.lines_after_reference) {
            let (ux, uy) = Self::unsheared(q, *p, *s);
            let d = (ux * ux + uy * uy).sqrt();
            if d < 1e-12 {
                continue;
            }
            let (nx, ny) = (ux / d, uy / d);
            let j = Vector5::from([-nx, -ny, -1.0, -nx * s, -ny * s]);
            jtr += j * (d - q[2]);
            jtj += j * j.transpose();
        }
        if !self.vertical_shear {
            let keep = jtj[(2, 2)].max(1.0);
            jtj.row_mut(4).fill(0.0);
            jtj.column_mut(4).fill(0.0);
            jtj[(4, 4)] = keep;
            jtr[4] = 0.0;
        }
        (jtj, jtr)
    }

    /// Damped Gauss–Newton (Levenberg–Marquardt) from `q`: the parameters and their cost.
    fn refine(&self, mut q: [f64; 5]) -> ([f64; 5], f64) {
        let mut current = self.cost(&q);
        let mut lambda = 1e-3;
        for _ in 0..60 {
            let (jtj, jtr) = self.normal(&q);
            let mut damped = jtj;
            for k in 0..5 {
                damped[(k, k)] += lambda * jtj[(k, k)].max(1e-9);
            }
            let Some(step) = solve5(damped, &jtr) else {
                break;
            };
            let mut next = q;
            for (v, d) in next.iter_mut().zip(step.iter()) {
                *v -= *d;
            }
            let c = self.cost(&next);
            if c.is_finite() && c <= current {
                let small = step.iter().all(|d| d.abs() < 1e-10);
                q = next;
                current = c;
                lambda = (lambda * 0.3).max(1e-9);
                if small {
                    break;
                }
            } else {
                lambda *= 10.0;
                if lambda > 1e8 {
                    break;
                }
            }
        }
        (q, current)
    }

    /// The fit at the converged `q` (of cost `cost`), with the shears' standard errors.
    fn result(&self, q: &[f64; 5], cost: f64) -> ShearedCircleFit {
        let n = self.points.len() as f64;
        let (jtj, _) = self.normal(q);
        let dof = (n - 5.0).max(1.0);
        let sigma2 = cost / dof;
        // Standard errors from the diagonal of (JᵀJ)⁻¹ σ²; a singular matrix (shear
        // undetermined) gives infinite errors.
        let inv_diag =
            |k: usize| solve5(jtj, &Vector5::ith(k, 1.0)).map_or(f64::INFINITY, |x| x[k].abs());
        let var = self.cost(q) / n;
        ShearedCircleFit {
            circle: CircleFit {
                center_x: q[0],
                center_y: q[1],
                radius: q[2],
                residual_sd: var.sqrt(),
                points: self.points.len(),
            },
            shear_x: q[3],
            shear_y: q[4],
            shear_x_sd: (sigma2 * inv_diag(3)).sqrt(),
            shear_y_sd: if self.vertical_shear {
                (sigma2 * inv_diag(4)).sqrt()
            } else {
                0.0
            },
        }
    }
}

type Matrix5 = SMatrix<f64, 5, 5>;
type Vector5 = SVector<f64, 5>;

/// Solves a 5×5 system by LU decomposition with partial pivoting; `None` when a pivot is
/// negligible against the matrix's largest entry (singular: a shear the points do not
/// determine) or the input or result is not finite.
fn solve5(m: Matrix5, b: &Vector5) -> Option<Vector5> {
    let scale = m.amax();
    if !(scale.is_finite() && scale > 0.0) {
        return None;
    }
    let lu = m.lu();
    if lu.u().diagonal().amin() <= 1e-13 * scale {
        return None;
    }
    lu.solve(b).filter(|x| x.iter().all(|v| v.is_finite()))
}

/// Solves a 3×3 system; `None` when its determinant is negligible (collinear points).
fn solve3(m: &Matrix3<f64>, b: &Vector3<f64>) -> Option<Vector3<f64>> {
    let d = m.determinant();
    if !d.is_finite() || d.abs() < 1e-12 {
        return None;
    }
    m.lu().solve(b)
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
    pub fn at(&self, t: f64) -> ImagePoint {
        let s = self.slope * t + self.intercept;
        if self.steep {
            ImagePoint::new(s, t)
        } else {
            ImagePoint::new(t, s)
        }
    }
}

/// Least-squares line through at least two distinct points from sums of squares. x and y are
/// swapped when the points spread more vertically than horizontally, so vertical posts fit as
/// well as horizontal bars. `None` for fewer than two points, all points equal, non-finite
/// input or sums that overflow; never divides by zero.
#[must_use]
pub fn fit_line(points: &[ImagePoint]) -> Option<LineFit> {
    if points.len() < 2
        || points
            .iter()
            .any(|p| !p.x_px.is_finite() || !p.y_px.is_finite())
    {
        return None;
    }
    let n = points.len() as f64;
    let (mx, my) = points
        .iter()
        .fold((0.0, 0.0), |(a, b), p| (a + p.x_px / n, b + p.y_px / n));
    let (mut sxx, mut syy, mut sxy) = (0.0, 0.0, 0.0);
    for p in points {
        let (dx, dy) = (p.x_px - mx, p.y_px - my);
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
    // Coincident points still spread by rounding (the mean of three equal coordinates is not
    // always that coordinate): below a spread of 1e-9 of their size they are one point.
    let size = 1.0 + mx.abs().max(my.abs());
    if sii <= n * (1e-9 * size).powi(2) {
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

    fn pt(x: f64, y: f64) -> ImagePoint {
        ImagePoint::new(x, y)
    }

    fn arc(cx: f64, cy: f64, r: f64, from: f64, to: f64, n: usize) -> Vec<ImagePoint> {
        (0..n)
            .map(|i| {
                let t = from + (to - from) * i as f64 / (n - 1) as f64;
                pt(cx + r * t.cos(), cy + r * t.sin())
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
            p.x_px += if i % 2 == 0 { 0.3 } else { -0.3 };
        }
        let part = fit_circle(&pts).expect("fit");
        assert!((part.radius - 30.0).abs() < 1.0, "radius {}", part.radius);
        assert!(part.residual_sd > 0.0);
    }

    #[test]
    fn trimming_drops_a_stray_point_but_not_a_shape() {
        let mut pts = arc(20.0, 20.0, 8.0, 0.0, 6.0, 24);
        pts[5].x_px += 4.0;
        let plain = fit_circle(&pts).expect("fit");
        let trimmed = fit_circle_trimmed(&pts, 2.5, 1.0, 0.2).expect("fit");
        assert!((trimmed.radius - 8.0).abs() < 1e-6 && trimmed.points == 23);
        assert!((plain.radius - 8.0).abs() > (trimmed.radius - 8.0).abs());
        // A square's outline is not a circle: too many points would go, so nothing does.
        let square: Vec<ImagePoint> = (0..40)
            .map(|i| {
                let t = f64::from(i % 10);
                match i / 10 {
                    0 => pt(t, 0.0),
                    1 => pt(10.0, t),
                    2 => pt(10.0 - t, 10.0),
                    _ => pt(0.0, 10.0 - t),
                }
            })
            .collect();
        let s = fit_circle_trimmed(&square, 1.0, 0.1, 0.15).expect("fit");
        assert_eq!(s.points, 40);
    }

    #[test]
    fn degenerate_circles_are_refused() {
        assert!(fit_circle(&[pt(0.0, 0.0), pt(1.0, 1.0)]).is_none());
        assert!(fit_circle(&[pt(0.0, 0.0), pt(1.0, 1.0), pt(2.0, 2.0), pt(3.0, 3.0)]).is_none());
        assert!(fit_circle(&[pt(0.0, 0.0), pt(1.0, f64::NAN), pt(2.0, 5.0)]).is_none());
        assert!(fit_circle(&[pt(4.0, 4.0); 5]).is_none());
    }

    #[test]
    fn lines_fit_both_ways_without_dividing_by_zero() {
        let vertical: Vec<ImagePoint> = (0..10).map(|i| pt(20.0, f64::from(i))).collect();
        let v = fit_line(&vertical).expect("vertical");
        assert!(v.steep && v.slope.abs() < 1e-12 && (v.intercept - 20.0).abs() < 1e-12);
        assert_eq!(v.r_squared, 1.0);
        let tilted: Vec<ImagePoint> = (0..10)
            .map(|i| pt(f64::from(i), 2.0 * f64::from(i) + 1.0))
            .collect();
        let t = fit_line(&tilted).expect("tilted");
        assert!(t.steep, "dy spreads more than dx");
        let at = t.at(5.0);
        assert!((at.x_px - 2.0).abs() < 1e-9 && (at.y_px - 5.0).abs() < 1e-9);
        let noisy = [pt(0.0, 0.0), pt(1.0, 1.0), pt(2.0, 0.0), pt(3.0, 1.0)];
        let n = fit_line(&noisy).expect("noisy");
        assert!(!n.steep && n.r_squared < 0.5 && n.residual_variance > 0.0);
        assert!(fit_line(&[pt(1.0, 1.0), pt(1.0, 1.0)]).is_none());
        assert!(fit_line(&[pt(1.0, 1.0)]).is_none());
        assert!(fit_line(&[pt(1e300, 1e300), pt(-1e300, -1e300), pt(1e300, 1e300)]).is_none());
        assert!(fit_line(&[pt(0.0, 0.0), pt(f64::INFINITY, 1.0)]).is_none());
    }

    /// Outline points of a circle moving `(ax, ay)` px per line, read row by row like a rolling
    /// shutter: each row's left and right crossing, found at the row's own read-out time.
    fn moving_outline(
        cx: f64,
        cy: f64,
        r: f64,
        ax: f64,
        ay: f64,
        reference: f64,
    ) -> Vec<(ImagePoint, f64)> {
        let mut out = Vec::new();
        for row in 0..400 {
            let y = f64::from(row) * 0.5;
            let s = y - reference;
            let (x0, y0) = (cx + ax * s, cy + ay * s);
            let dy = y - y0;
            if dy.abs() < r {
                let half = (r * r - dy * dy).sqrt();
                out.push((pt(x0 - half, y), y));
                out.push((pt(x0 + half, y), y));
            }
        }
        out
    }

    #[test]
    fn sheared_circle_recovers_shear_and_velocity_exactly() {
        let (ax, ay) = (0.15, 0.03);
        let data = moving_outline(90.0, 70.0, 20.0, ax, ay, 80.0);
        let (pts, rows): (Vec<ImagePoint>, Vec<f64>) = data.into_iter().unzip();
        let f = fit_sheared_circle(&pts, &rows, 80.0, true).expect("fit");
        assert!((f.shear_x - ax).abs() < 1e-6, "{f:?}");
        assert!((f.shear_y - ay).abs() < 1e-6, "{f:?}");
        assert!((f.circle.center_x - 90.0).abs() < 1e-5 && (f.circle.center_y - 70.0).abs() < 1e-5);
        assert!((f.circle.radius - 20.0).abs() < 1e-5 && f.circle.residual_sd < 1e-6);
        // 160 lines in 1/30 s: 0.15 px per line is 720 px/s.
        let (vx, vy) = f.velocity_px_s(1.0 / 30.0 / 160.0);
        assert!((vx - 720.0).abs() < 1e-3 && (vy - 144.0).abs() < 1e-3);
        // The plain circle fit of the same points is off in radius and centre.
        let plain = fit_circle(&pts).expect("plain");
        assert!((plain.center_x - 90.0).abs() > 0.1 || (plain.radius - 20.0).abs() > 0.1);
        // A still circle gives zero shear.
        let still = moving_outline(50.0, 50.0, 10.0, 0.0, 0.0, 80.0);
        let (pts, rows): (Vec<ImagePoint>, Vec<f64>) = still.into_iter().unzip();
        let f = fit_sheared_circle(&pts, &rows, 80.0, true).expect("still");
        assert!(f.shear_x.abs() < 1e-9 && f.shear_y.abs() < 1e-9 && f.shear_x_sd < 1e-3);
        // Horizontal motion only, fitted with the vertical shear held at zero.
        let across = moving_outline(60.0, 90.0, 15.0, -0.2, 0.0, 80.0);
        let (pts, rows): (Vec<ImagePoint>, Vec<f64>) = across.into_iter().unzip();
        let f = fit_sheared_circle(&pts, &rows, 80.0, false).expect("across");
        assert!((f.shear_x + 0.2).abs() < 1e-6 && f.shear_y == 0.0 && f.shear_y_sd == 0.0);
        assert!((f.circle.radius - 15.0).abs() < 1e-5);
    }

    #[test]
    fn sheared_circle_refuses_degenerate_input() {
        let line: Vec<ImagePoint> = (0..10).map(|i| pt(f64::from(i), f64::from(i))).collect();
        let rows: Vec<f64> = line.iter().map(|p| p.y_px).collect();
        assert!(fit_sheared_circle(&line, &rows, 80.0, true).is_none());
        let five = arc(10.0, 10.0, 5.0, 0.0, 5.0, 5);
        let rows5: Vec<f64> = five.iter().map(|p| p.y_px).collect();
        assert!(fit_sheared_circle(&five, &rows5, 80.0, true).is_none());
        let mut pts = arc(10.0, 10.0, 5.0, 0.0, 6.0, 12);
        let rows12: Vec<f64> = pts.iter().map(|p| p.y_px).collect();
        assert!(fit_sheared_circle(&pts, &rows12[..11], 80.0, true).is_none());
        assert!(fit_sheared_circle(&pts, &rows12, f64::NAN, false).is_none());
        pts[3].y_px = f64::NAN;
        assert!(fit_sheared_circle(&pts, &rows12, 80.0, true).is_none());
        let mut rows_nan = rows12.clone();
        rows_nan[0] = f64::INFINITY;
        assert!(
            fit_sheared_circle(&arc(10.0, 10.0, 5.0, 0.0, 6.0, 12), &rows_nan, 80.0, true)
                .is_none()
        );
        assert!(fit_sheared_circle(&[pt(4.0, 4.0); 8], &[4.0; 8], 80.0, false).is_none());
        // Points all on one row: the shear is undetermined; no panic, and either no fit or an
        // infinite / huge shear error.
        let one_row: Vec<ImagePoint> = (0..8)
            .map(|i| pt(f64::from(i), 5.0 + f64::from(i % 2)))
            .collect();
        if let Some(f) = fit_sheared_circle(&one_row, &[5.0; 8], 80.0, true) {
            assert!(f.shear_x_sd.is_nan() || f.shear_x_sd > 1.0 || f.shear_y_sd > 1.0);
        }
    }
}
