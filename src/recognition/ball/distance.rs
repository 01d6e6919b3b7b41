//! The distance stage: from the angle the outline subtends (or the circle), fused with the
//! ground plane through the camera pose; and where the ball shows in the image.

use super::BallParams;
use super::circle::CircleStage;
use super::outline::Outline;
use crate::geometry::{ImagePoint, PinholeCamera};
use crate::recognition::context::ViewContext;
use crate::recognition::fit::{ShearedCircleFit, fit_circle_trimmed};

/// Camera distance to the ball's centre, centimetres: from the outline's angle when the circle
/// fit is used, else from the circle; fused with the ground plane when that is on.
pub(super) fn ball_distance(
    ctx: &ViewContext,
    outline: &Outline,
    circle: &CircleStage,
    center: ImagePoint,
    radius: f64,
    params: &BallParams,
) -> f64 {
    let used = circle.used();
    // With the fit's own points, the angle the ball subtends; else from the circle.
    let alpha = used
        .then(|| angular_radius(&ctx.camera, &outline.points, center, params))
        .flatten();
    let size_distance = match alpha {
        Some(a) => params.diameter_cm / 2.0 / a.sin(),
        None => distance_from_circle(&ctx.camera, center, radius, params.diameter_cm),
    };
    if params.ground_plane_fusion {
        let sigma = if used && !outline.cut.any() {
            params.radius_sigma_px
        } else {
            params.radius_sigma_cut_px
        };
        fuse_with_ground_plane(ctx, center, radius, sigma, size_distance, params)
    } else {
        size_distance
    }
}

/// Where the ball is in the image (pixels): the point the skew removal moves onto `center` (a
/// fixed-point iteration; the removal is nearly a shift over a ball's size), and for a ball
/// that moved on its own while read out, where it was when its centre row was read.
pub(super) fn observed_center(
    ctx: &ViewContext,
    outline: &Outline,
    moving: Option<&ShearedCircleFit>,
    center: ImagePoint,
    params: &BallParams,
) -> ImagePoint {
    let observed = if params.skew_correction {
        let shift = outline.box_shift;
        let mut p = center - shift;
        for _ in 0..3 {
            let q = outline.unskew(ctx, params, p);
            p = center - (q - p);
        }
        if p.is_finite() { p } else { center }
    } else {
        center
    };
    match moving {
        Some(e) => {
            let lines = observed.y_px - ctx.reference_row();
            ImagePoint::new(
                observed.x_px + e.shear_x * lines,
                observed.y_px + e.shear_y * lines,
            )
        }
        None => observed,
    }
}

/// Inverse-variance combination of the size-based distance with the ground-plane one. The
/// plane distance D = h / sin φ (h: camera height above ball centres, φ: depression of the ray)
/// has an error of about D² / h · σ_φ; the size distance one of D · σ_r / r. When the two
/// disagree by more than a factor of two (a ball in the air or held), the size distance stands.
fn fuse_with_ground_plane(
    ctx: &ViewContext,
    center: ImagePoint,
    radius: f64,
    radius_sigma_px: f64,
    size_distance: f64,
    params: &BallParams,
) -> f64 {
    let Some(pose) = ctx.pose else {
        return size_distance;
    };
    let Some(hit) = pose.point_on_plane(center, params.diameter_cm / 2.0) else {
        return size_distance;
    };
    let plane = hit.distance_to(&pose.position());
    if !(plane.is_finite() && plane > 0.5 * size_distance && plane < 2.0 * size_distance) {
        return size_distance;
    }
    let h = (pose.position().z() - params.diameter_cm / 2.0)
        .abs()
        .max(1.0);
    let sigma_phi = params.pose_sigma_rad + params.radius_sigma_px / ctx.camera.focal_px;
    let var_plane = (plane * plane / h * sigma_phi).powi(2);
    let var_size = (size_distance * radius_sigma_px / radius.max(0.5)).powi(2);
    (plane / var_plane + size_distance / var_size) / (1.0 / var_plane + 1.0 / var_size)
}

/// Distance (cm) to the centre of a ball of `diameter_cm` whose outline in the image is the
/// circle (`center`, `radius` px), from the angle the ball subtends. A sphere off the optical
/// axis projects to an ellipse stretched away from the axis (by 1/cos θ across and 1/cos² θ
/// along the radial direction, θ the angle off the axis): at the side of the ERS-7's image a
/// ball looks 15–25% wider than at the centre, and the original's d × 8.5 / diameter reads
/// that much too close. The half-angle between the rays through opposite ends of a diameter is
/// the ball's angular radius α for the ellipse's axes; the mean over the radial and the
/// tangential diameter of the fitted circle undoes the stretch, and distance = R / sin α.
/// Falls back to d × diameter / (2 × radius) when the rays are degenerate.
#[must_use]
pub fn distance_from_circle(
    camera: &PinholeCamera,
    center: ImagePoint,
    radius: f64,
    diameter_cm: f64,
) -> f64 {
    let radius = radius.max(0.25);
    let fallback = camera.focal_px * diameter_cm / (2.0 * radius);
    let (dx, dy) = (
        center.x_px - camera.centre.x_px,
        center.y_px - camera.centre.y_px,
    );
    let off = dx.hypot(dy);
    let u = if off > 1e-6 {
        (dx / off, dy / off)
    } else {
        (1.0, 0.0)
    };
    let half_angle = |dir: (f64, f64)| {
        let a = camera.unit_ray(ImagePoint::new(
            center.x_px + radius * dir.0,
            center.y_px + radius * dir.1,
        ));
        let b = camera.unit_ray(ImagePoint::new(
            center.x_px - radius * dir.0,
            center.y_px - radius * dir.1,
        ));
        a.coords.dot(&b.coords).clamp(-1.0, 1.0).acos() / 2.0
    };
    let alpha = (half_angle(u) + half_angle((-u.1, u.0))) / 2.0;
    let d = diameter_cm / 2.0 / alpha.sin();
    if d.is_finite() && d > 0.0 {
        d
    } else {
        fallback
    }
}

/// The ball's angular radius (radians) from its outline points: the points are turned into
/// the view of a camera looking straight at `center` (gnomonic coordinates about the ray
/// through it, scaled by d so that they stay in pixels), where a sphere's outline is an exact
/// circle wherever it is in the image, and a circle is fitted there. Unlike
/// [`distance_from_circle`] this also holds for a short arc (a ball cut by the image edge sees
/// only the side facing the image centre, whose curvature is not the fitted circle's mean).
/// `None` when the points do not fit a circle.
fn angular_radius(
    camera: &PinholeCamera,
    points: &[ImagePoint],
    center: ImagePoint,
    params: &BallParams,
) -> Option<f64> {
    let ray = |p: ImagePoint| camera.unit_ray(p).coords;
    let e1 = ray(center);
    let side = ray(ImagePoint::new(center.x_px + 1.0, center.y_px));
    let e2 = (side - e1 * side.dot(&e1)).try_normalize(1e-12)?;
    let e3 = e1.cross(&e2);
    let f = camera.focal_px;
    // The outline in that virtual camera's image, pixels.
    let turned: Vec<ImagePoint> = points
        .iter()
        .filter_map(|&p| {
            let r = ray(p);
            let along = r.dot(&e1);
            (along > 1e-6).then(|| ImagePoint::new(f * r.dot(&e2) / along, f * r.dot(&e3) / along))
        })
        .collect();
    if turned.len() < 5 {
        return None;
    }
    let fit = fit_circle_trimmed(
        &turned,
        params.fit_trim_sd,
        params.fit_trim_min_px,
        params.fit_trim_max_share,
    )?;
    let alpha = (fit.radius / f).atan();
    (alpha.is_finite() && alpha > 0.0).then_some(alpha)
}

/// The ground velocity (robot frame, cm/s) of a ball at image point `center` moving at
/// `v_px_s` pixels per second: where the ray through the centre meets the plane of ball
/// centres now and 10 ms later.
pub(super) fn ground_velocity(
    ctx: &ViewContext,
    center: ImagePoint,
    v_px_s: (f64, f64),
    params: &BallParams,
) -> Option<[f64; 2]> {
    let pose = ctx.pose?;
    let dt = 0.01;
    let z = params.diameter_cm / 2.0;
    let a = pose.point_on_plane(center, z)?;
    let b = pose.point_on_plane(
        ImagePoint::new(center.x_px + v_px_s.0 * dt, center.y_px + v_px_s.1 * dt),
        z,
    )?;
    let v = [(b.x() - a.x()) / dt, (b.y() - a.y()) / dt];
    v.iter().all(|c| c.is_finite()).then_some(v)
}
