//! The geometry message from eotn's own descriptions: the field (size, lines, arcs) from a
//! field description, and each overhead camera's calibration in ssl-vision's camera model.
//!
//! **The field.** eotn's field descriptions list painted lines and arcs (unnamed) and
//! landmarks, not the league's sizes, so the sizes are derived: length and width from the
//! lines' extent (their centres), the goal width from the goal posts' feet (landmarks named
//! `… post foot`), the centre circle's radius from a full circle about the centre, the line
//! width and ball radius as given. The goal depth and the boundary width are not in a
//! description and are sent as 0. Lines are named by where they lie (touch lines, goal
//! lines, halfway line, centre line); the others `Line N`.
//!
//! **The camera.** ssl-vision's model is a pinhole with one radial coefficient κ: a camera-frame
//! point (z along the optical axis, x right, y down) has undistorted normalised coordinates
//! `p_u = (x/z, y/z)`, distorted ones `p_d` with `|p_u| = |p_d|·(1 + κ|p_d|²)`, and the pixel
//! `principal_point + f·p_d`. eotn's lens (k1/k2 or a checkerboard model, and perhaps a
//! vertical focal length of its own) is not of that form, so κ is fitted: over a grid of pixels
//! every [`GRID_STEP_PX`] across the image, each pixel's ray is found through eotn's lens, and κ
//! minimises the squared pixel distance between each pixel and that ray re-projected through
//! ssl-vision's model (focal length = eotn's horizontal one, principal point = eotn's). The
//! minimisation starts from the closed-form least squares in the radius,
//! `κ₀ = Σ r_d³(r_u − r_d) / Σ r_d⁶`, and is finished by a golden-section search on the pixel
//! error. What is left is the fit's residual ([`KappaFit`]: RMS and largest, pixels). A lens
//! that pincushions (κ < 0 would be needed) is sent as κ = 0, as ssl-vision takes κ ≤ 0 as none.

use nalgebra::{Matrix3, Rotation3, UnitQuaternion, Vector3};

use super::messages::{
    FieldShapeType, SslFieldCircularArc, SslFieldLineSegment, SslGeometryCameraCalibration,
    SslGeometryData, SslGeometryFieldSize, Vector2f,
};
use crate::geometry::OverheadCamera;
use crate::overhead::FieldDescription;

/// Spacing of the pixel grid κ is fitted over, pixels.
pub const GRID_STEP_PX: usize = 16;

/// How well one coefficient κ stands for eotn's lens.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KappaFit {
    /// The coefficient sent.
    pub kappa: f64,
    /// RMS pixel distance between eotn's projection and ssl-vision's of the same rays.
    pub rms_px: f64,
    /// The largest such distance, pixels.
    pub max_px: f64,
    /// Grid pixels compared.
    pub samples: usize,
    /// Grid pixels left out: eotn's lens gives no ray there (it folds over).
    pub skipped: usize,
}

/// One camera's calibration message and how well its κ fits.
#[derive(Debug, Clone, PartialEq)]
pub struct CameraCalibration {
    /// The message.
    pub message: SslGeometryCameraCalibration,
    /// The κ fit.
    pub fit: KappaFit,
}

/// The geometry message for a field and its cameras, with each camera's κ fit.
#[must_use]
pub fn geometry_data(
    field: &FieldDescription,
    cameras: &[super::CameraEntry],
) -> (SslGeometryData, Vec<CameraCalibration>) {
    let calibrations: Vec<CameraCalibration> = cameras
        .iter()
        .map(|c| camera_calibration(c.camera_id, &c.camera))
        .collect();
    let data = SslGeometryData {
        field: field_size(field),
        calib: calibrations.iter().map(|c| c.message.clone()).collect(),
    };
    (data, calibrations)
}

fn mm(cm: f64) -> f32 {
    (cm * 10.0) as f32
}

fn mm_i32(cm: f64) -> i32 {
    (cm * 10.0)
        .round()
        .clamp(f64::from(i32::MIN), f64::from(i32::MAX)) as i32
}

/// The field's size and markings (see the module documentation for what is derived).
#[must_use]
pub fn field_size(field: &FieldDescription) -> SslGeometryFieldSize {
    let half_length = field
        .lines
        .iter()
        .flat_map(|l| [l.from_cm[0].abs(), l.to_cm[0].abs()])
        .fold(0.0, f64::max);
    let half_width = field
        .lines
        .iter()
        .flat_map(|l| [l.from_cm[1].abs(), l.to_cm[1].abs()])
        .fold(0.0, f64::max);
    let goal_half_width = field
        .landmarks
        .iter()
        .filter(|l| l.name.contains("post foot"))
        .map(|l| l.field_cm[1].abs())
        .fold(0.0, f64::max);
    let thickness = mm(field.line_width_cm);
    let field_lines = field
        .lines
        .iter()
        .enumerate()
        .map(|(i, l)| {
            let shape = line_shape(l.from_cm, l.to_cm, half_length, half_width);
            SslFieldLineSegment {
                name: shape.map_or_else(|| format!("Line{i}"), |s| s.name().to_owned()),
                p1: Vector2f {
                    x: mm(l.from_cm[0]),
                    y: mm(l.from_cm[1]),
                },
                p2: Vector2f {
                    x: mm(l.to_cm[0]),
                    y: mm(l.to_cm[1]),
                },
                thickness,
                r#type: shape.map(|s| s as i32),
            }
        })
        .collect();
    let centre_circle = field.arcs.iter().find(|a| {
        a.centre_cm[0].abs() < 1e-6
            && a.centre_cm[1].abs() < 1e-6
            && a.to_rad - a.from_rad >= std::f64::consts::TAU - 1e-6
    });
    let field_arcs = field
        .arcs
        .iter()
        .enumerate()
        .map(|(i, a)| {
            let centre = centre_circle.is_some_and(|c| std::ptr::eq(c, a));
            SslFieldCircularArc {
                name: if centre {
                    "CenterCircle".to_owned()
                } else {
                    format!("Arc{i}")
                },
                center: Vector2f {
                    x: mm(a.centre_cm[0]),
                    y: mm(a.centre_cm[1]),
                },
                radius: mm(a.radius_cm),
                a1: a.from_rad as f32,
                a2: a.to_rad as f32,
                thickness,
                r#type: centre.then_some(FieldShapeType::CenterCircle as i32),
            }
        })
        .collect();
    SslGeometryFieldSize {
        field_length: mm_i32(2.0 * half_length),
        field_width: mm_i32(2.0 * half_width),
        goal_width: mm_i32(2.0 * goal_half_width),
        goal_depth: 0,
        boundary_width: 0,
        field_lines,
        field_arcs,
        penalty_area_depth: None,
        penalty_area_width: None,
        center_circle_radius: centre_circle.map(|c| mm_i32(c.radius_cm)),
        line_thickness: Some(mm_i32(field.line_width_cm)),
        goal_center_to_penalty_mark: None,
        goal_height: None,
        ball_radius: Some(mm(field.ball_radius_cm)),
        max_robot_radius: None,
    }
}

/// The field a geometry message describes, as a field description for the field view: its
/// lines and arcs in centimetres, line width and ball radius, the four corners as landmarks.
#[must_use]
pub fn field_description(f: &SslGeometryFieldSize) -> FieldDescription {
    use crate::overhead::field::{Arc, Landmark, LineSegment};
    let cm = |v: f32| f64::from(v) / 10.0;
    let finite = |v: &[f32]| v.iter().all(|x| x.is_finite());
    let lines = f
        .field_lines
        .iter()
        .filter(|l| finite(&[l.p1.x, l.p1.y, l.p2.x, l.p2.y]))
        .map(|l| LineSegment {
            from_cm: [cm(l.p1.x), cm(l.p1.y)],
            to_cm: [cm(l.p2.x), cm(l.p2.y)],
        })
        .collect();
    let arcs = f
        .field_arcs
        .iter()
        .filter(|a| finite(&[a.center.x, a.center.y, a.radius, a.a1, a.a2]))
        .map(|a| {
            // The arc runs counter-clockwise from a1 to a2; an a2 at or before a1 means it
            // wraps. Taken modulo a turn, not by adding turns one at a time: a packet's angle
            // of 1e30 rad would never move (a fuzzed packet hung the decoder that way).
            let tau = std::f64::consts::TAU;
            let from = f64::from(a.a1);
            let from = if from.abs() > 16.0 * tau {
                from.rem_euclid(tau)
            } else {
                from
            };
            let span = (f64::from(a.a2) - f64::from(a.a1)).rem_euclid(tau);
            let span = if span <= 0.0 || span >= tau {
                tau
            } else {
                span
            };
            Arc {
                centre_cm: [cm(a.center.x), cm(a.center.y)],
                radius_cm: cm(a.radius),
                from_rad: from,
                to_rad: from + span,
            }
        })
        .collect();
    let (hl, hw) = (
        f64::from(f.field_length) / 20.0,
        f64::from(f.field_width) / 20.0,
    );
    let landmarks = [(1.0, 1.0), (1.0, -1.0), (-1.0, -1.0), (-1.0, 1.0)]
        .iter()
        .map(|&(sx, sy)| Landmark {
            name: format!(
                "{} {} corner",
                if sx > 0.0 { "+x" } else { "-x" },
                if sy > 0.0 { "left" } else { "right" }
            ),
            field_cm: [sx * hl, sy * hw],
            height_cm: 0.0,
        })
        .collect();
    let defaults = FieldDescription::four_legged_2005();
    FieldDescription {
        name: "the field of ssl-vision's geometry".to_owned(),
        landmarks,
        lines,
        arcs,
        line_width_cm: f
            .line_thickness
            .map_or(defaults.line_width_cm, |t| f64::from(t) / 10.0),
        ball_radius_cm: f
            .ball_radius
            .filter(|r| r.is_finite() && *r > 0.0)
            .map_or(defaults.ball_radius_cm, cm),
        plate_height_cm: defaults.plate_height_cm,
        camera_height_guess_cm: defaults.camera_height_guess_cm,
    }
}

/// What a line is, by where it lies: along a border, across the middle, along the x axis.
fn line_shape(
    a: [f64; 2],
    b: [f64; 2],
    half_length: f64,
    half_width: f64,
) -> Option<FieldShapeType> {
    let near = |v: f64, w: f64| (v - w).abs() < 0.5;
    let spans = |u: f64, v: f64, half: f64| near(u.min(v), -half) && near(u.max(v), half);
    if near(a[1], b[1]) && spans(a[0], b[0], half_length) {
        return match a[1] {
            y if near(y, half_width) => Some(FieldShapeType::TopTouchLine),
            y if near(y, -half_width) => Some(FieldShapeType::BottomTouchLine),
            y if near(y, 0.0) => Some(FieldShapeType::CenterLine),
            _ => None,
        };
    }
    if near(a[0], b[0]) && spans(a[1], b[1], half_width) {
        return match a[0] {
            x if near(x, -half_length) => Some(FieldShapeType::LeftGoalLine),
            x if near(x, half_length) => Some(FieldShapeType::RightGoalLine),
            x if near(x, 0.0) => Some(FieldShapeType::HalfwayLine),
            _ => None,
        };
    }
    None
}

/// eotn's camera axes (x forward, y left, z up) → ssl-vision's (x right, y down, z forward).
fn ssl_from_eotn_axes() -> Matrix3<f64> {
    Matrix3::new(0.0, -1.0, 0.0, 0.0, 0.0, -1.0, 1.0, 0.0, 0.0)
}

/// One camera's calibration message: focal length and principal point as eotn's (horizontal
/// focal length), κ fitted to eotn's lens, and the pose as ssl-vision's
/// `p_camera = q·p_field + t` in millimetres.
#[must_use]
pub fn camera_calibration(camera_id: u32, camera: &OverheadCamera) -> CameraCalibration {
    let fit = fit_kappa(camera);
    let field_from_camera = camera.field_from_camera();
    let camera_from_field = field_from_camera.rotation().inverse().to_rotation_matrix();
    let rotation = ssl_from_eotn_axes() * camera_from_field.matrix();
    let origin_mm = field_from_camera.origin().coords.coords * 10.0;
    let translation = -(rotation * origin_mm);
    let q = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(rotation));
    let message = SslGeometryCameraCalibration {
        camera_id,
        focal_length: camera.focal_px as f32,
        principal_point_x: camera.centre.x_px as f32,
        principal_point_y: camera.centre.y_px as f32,
        distortion: fit.kappa as f32,
        q0: q.i as f32,
        q1: q.j as f32,
        q2: q.k as f32,
        q3: q.w as f32,
        tx: translation.x as f32,
        ty: translation.y as f32,
        tz: translation.z as f32,
        derived_camera_world_tx: Some(origin_mm.x as f32),
        derived_camera_world_ty: Some(origin_mm.y as f32),
        derived_camera_world_tz: Some(origin_mm.z as f32),
        pixel_image_width: u32::try_from(camera.width_px).ok(),
        pixel_image_height: u32::try_from(camera.height_px).ok(),
    };
    CameraCalibration { message, fit }
}

/// ssl-vision's distortion: the distorted radius of undistorted radius `r_u` (the root of
/// `κ·r³ + r − r_u = 0`, by Newton's method from `r_u`, which decreases monotonically to it).
#[must_use]
pub fn distorted_radius(r_u: f64, kappa: f64) -> f64 {
    if kappa <= 0.0 || r_u <= 0.0 {
        return r_u;
    }
    let mut r = r_u;
    for _ in 0..60 {
        let step = (kappa * r * r * r + r - r_u) / (3.0 * kappa * r * r + 1.0);
        r -= step;
        if step.abs() < 1e-14 {
            break;
        }
    }
    r
}

/// Where ssl-vision's model puts a field point (millimetres) in the image, or `None` behind
/// the camera: the reference model κ is fitted for and tests check the pose against.
#[must_use]
pub fn ssl_image_from_field(c: &SslGeometryCameraCalibration, p_mm: [f64; 3]) -> Option<[f64; 2]> {
    let q = UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(
        f64::from(c.q3),
        f64::from(c.q0),
        f64::from(c.q1),
        f64::from(c.q2),
    ));
    let t = Vector3::new(f64::from(c.tx), f64::from(c.ty), f64::from(c.tz));
    let pc = q * Vector3::new(p_mm[0], p_mm[1], p_mm[2]) + t;
    (pc.z > 1e-9).then(|| {
        project(
            pc.x / pc.z,
            pc.y / pc.z,
            f64::from(c.focal_length),
            [
                f64::from(c.principal_point_x),
                f64::from(c.principal_point_y),
            ],
            f64::from(c.distortion),
        )
    })
}

/// ssl-vision's projection of undistorted normalised coordinates.
fn project(u: f64, v: f64, focal: f64, centre: [f64; 2], kappa: f64) -> [f64; 2] {
    let r_u = u.hypot(v);
    let scale = if r_u > 1e-15 {
        distorted_radius(r_u, kappa) / r_u
    } else {
        1.0
    };
    [centre[0] + focal * u * scale, centre[1] + focal * v * scale]
}

/// A grid pixel and its ray through eotn's lens (undistorted normalised coordinates).
struct GridRay {
    pixel: [f64; 2],
    ray: [f64; 2],
}

fn grid_rays(camera: &OverheadCamera) -> (Vec<GridRay>, usize) {
    let (mut rays, mut skipped) = (Vec::new(), 0);
    let half = GRID_STEP_PX as f64 / 2.0;
    for y in (0..camera.height_px).step_by(GRID_STEP_PX) {
        for x in (0..camera.width_px).step_by(GRID_STEP_PX) {
            let pixel = [x as f64 + half, y as f64 + half];
            let d = (
                (pixel[0] - camera.centre.x_px) / camera.focal_px,
                (pixel[1] - camera.centre.y_px) / camera.focal_y(),
            );
            match camera.undistort(d.0, d.1) {
                Some((u, v)) if u.is_finite() && v.is_finite() => {
                    rays.push(GridRay { pixel, ray: [u, v] })
                }
                _ => skipped += 1,
            }
        }
    }
    (rays, skipped)
}

/// Squared pixel errors' sum and the largest error for `kappa`.
fn pixel_errors(rays: &[GridRay], camera: &OverheadCamera, kappa: f64) -> (f64, f64) {
    let centre = [camera.centre.x_px, camera.centre.y_px];
    rays.iter().fold((0.0, 0.0_f64), |(sum, max), g| {
        let p = project(g.ray[0], g.ray[1], camera.focal_px, centre, kappa);
        let e = (p[0] - g.pixel[0]).hypot(p[1] - g.pixel[1]);
        (sum + e * e, max.max(e))
    })
}

/// Fits κ to eotn's lens over the image (see the module documentation).
#[must_use]
pub fn fit_kappa(camera: &OverheadCamera) -> KappaFit {
    let (rays, skipped) = grid_rays(camera);
    let centre = [camera.centre.x_px, camera.centre.y_px];
    let (mut num, mut den) = (0.0, 0.0);
    for g in &rays {
        let r_d = (g.pixel[0] - centre[0]).hypot(g.pixel[1] - centre[1]) / camera.focal_px;
        let r_u = g.ray[0].hypot(g.ray[1]);
        num += r_d.powi(3) * (r_u - r_d);
        den += r_d.powi(6);
    }
    let closed_form = if den > 0.0 { (num / den).max(0.0) } else { 0.0 };
    let cost = |k: f64| pixel_errors(&rays, camera, k).0;
    // Golden-section search on [0, 2κ₀ + margin]: the error is one valley in κ.
    let (mut lo, mut hi) = (0.0, 2.0 * closed_form + 0.05);
    let ratio = (5.0_f64.sqrt() - 1.0) / 2.0;
    let mut a = hi - ratio * (hi - lo);
    let mut b = lo + ratio * (hi - lo);
    let (mut fa, mut fb) = (cost(a), cost(b));
    for _ in 0..80 {
        if fa < fb {
            hi = b;
            (b, fb) = (a, fa);
            a = hi - ratio * (hi - lo);
            fa = cost(a);
        } else {
            lo = a;
            (a, fa) = (b, fb);
            b = lo + ratio * (hi - lo);
            fb = cost(b);
        }
    }
    let mut kappa = (lo + hi) / 2.0;
    for candidate in [0.0, closed_form] {
        if cost(candidate) < cost(kappa) {
            kappa = candidate;
        }
    }
    let (sum, max_px) = pixel_errors(&rays, camera, kappa);
    let samples = rays.len();
    KappaFit {
        kappa,
        rms_px: if samples == 0 {
            0.0
        } else {
            (sum / samples as f64).sqrt()
        },
        max_px,
        samples,
        skipped,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{Field, Point};

    #[test]
    fn a_pinhole_fits_kappa_zero_and_the_pose_projects_as_eotn_does() {
        let mut camera = OverheadCamera::looking_down(640, 480, 350.0, 420.0, 0.0, 0.0);
        camera.pose.yaw_rad = 0.3;
        camera.pose.position_cm[0] = 40.0;
        let c = camera_calibration(2, &camera);
        assert!(c.fit.kappa.abs() < 1e-6, "{:?}", c.fit);
        assert!(c.fit.max_px < 1e-6);
        for p in [[0.0, 0.0, 0.0], [150.0, -90.0, 0.0], [-200.0, 120.0, 22.5]] {
            let eotn = camera
                .image_from_field(&Point::<Field>::new(p[0], p[1], p[2]))
                .expect("in front");
            let ssl = ssl_image_from_field(&c.message, p.map(|v| v * 10.0)).expect("in front");
            assert!(
                (ssl[0] - eotn.x_px).abs() < 0.01 && (ssl[1] - eotn.y_px).abs() < 0.01,
                "{p:?}: ssl {ssl:?} eotn {eotn:?}"
            );
        }
    }

    #[test]
    fn barrel_distortion_fits_a_positive_kappa_within_a_few_pixels() {
        let camera = OverheadCamera::above_field_2005();
        let c = camera_calibration(0, &camera);
        assert!(c.fit.kappa > 0.0, "{:?}", c.fit);
        assert!(c.fit.samples > 1000 && c.fit.rms_px < c.fit.max_px);
        // Projected through ssl-vision's model, field points land where eotn puts them, within
        // the fit's largest residual.
        for p in [[0.0, 0.0], [200.0, 100.0], [-250.0, -150.0]] {
            let eotn = camera
                .image_from_field(&Point::<Field>::new(p[0], p[1], 0.0))
                .expect("in front");
            let ssl = ssl_image_from_field(&c.message, [p[0] * 10.0, p[1] * 10.0, 0.0])
                .expect("in front");
            let e = (ssl[0] - eotn.x_px).hypot(ssl[1] - eotn.y_px);
            assert!(e <= c.fit.max_px + 0.01, "{p:?}: {e} px, fit {:?}", c.fit);
        }
        // The fitted κ beats the closed-form start and no distortion at all.
        let (rays, _) = grid_rays(&camera);
        let best = pixel_errors(&rays, &camera, c.fit.kappa).0;
        assert!(best <= pixel_errors(&rays, &camera, 0.0).0);
    }

    #[test]
    fn the_field_size_comes_from_the_lines_and_posts() {
        let field = FieldDescription::resolve("ssl-div-b").expect("shipped");
        let f = field_size(&field);
        assert_eq!(
            (f.field_length, f.field_width, f.goal_width),
            (9000, 6000, 1000)
        );
        assert_eq!(f.center_circle_radius, Some(500));
        let names: Vec<&str> = f.field_lines.iter().map(|l| l.name.as_str()).collect();
        for n in [
            "TopTouchLine",
            "BottomTouchLine",
            "LeftGoalLine",
            "RightGoalLine",
        ] {
            assert!(names.contains(&n), "{names:?}");
        }
        assert_eq!(distorted_radius(0.5, 0.0), 0.5);
        let r = distorted_radius(0.9, 0.3);
        assert!((r * (1.0 + 0.3 * r * r) - 0.9).abs() < 1e-12);
    }

    /// Arc angles from the wire: a wrap, a full circle and absurd angles all give one
    /// counter-clockwise span of at most a turn, without looping (a fuzzed packet with an
    /// angle of 1e30 rad once hung `field_description`).
    #[test]
    fn arc_angles_from_the_wire_give_one_span_of_at_most_a_turn() {
        let field = FieldDescription::resolve("ssl-div-b").expect("shipped");
        let mut f = field_size(&field);
        let template = f.field_arcs[0].clone();
        let arc = |a1: f32, a2: f32| SslFieldCircularArc {
            a1,
            a2,
            ..template.clone()
        };
        f.field_arcs = vec![
            arc(3.0, 1.0),
            arc(0.5, 0.5),
            arc(1e30, -1e30),
            arc(-3e38, 3e38),
            arc(0.25, 1.25),
        ];
        let d = field_description(&f);
        let spans: Vec<f64> = d.arcs.iter().map(|a| a.to_rad - a.from_rad).collect();
        let tau = std::f64::consts::TAU;
        assert!((spans[0] - (tau - 2.0)).abs() < 1e-6, "{spans:?}");
        assert!((spans[1] - tau).abs() < 1e-9, "{spans:?}");
        assert!((spans[4] - 1.0).abs() < 1e-6, "{spans:?}");
        assert_eq!(d.arcs[4].from_rad, 0.25);
        for a in &d.arcs {
            let span = a.to_rad - a.from_rad;
            assert!(span > 0.0 && span <= tau + 1e-9, "{a:?}");
            assert!(a.from_rad.abs() <= 16.0 * tau, "{a:?}");
        }
    }
}
