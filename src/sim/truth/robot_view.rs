//! The truth of a robot-camera frame: the ball (with the image borders that cut it), both goals
//! with their posts and open stretches along the gap scan, beacons, the other robots and the
//! coloured-pattern markers, each relative to the observing robot.

use super::super::render::object_id;
use super::{coverage, coverage_where, covered_fraction};
use crate::frame::PixelBox;
use crate::geometry::{
    BodyPose, CameraPose, Field, HeadJoints, ImagePoint, Point, PoseRecord, RobotPose,
};
use crate::lut::ColourClass;
use crate::model::scene::{Beacon, GoalColour, Scene};
use crate::model::truth::{
    BallTruth, BeaconTruth, CutOff, GoalGap, GoalTruth, MarkerTruth, PostTruth, Relative,
    RobotTruth, RobotViewTruth,
};
use crate::sensors::SensorReadings;

fn relative(pose: &CameraPose, robot: &RobotPose, p: &Point<Field>) -> Relative {
    let camera_local = pose.field_from_camera.inverse() * *p;
    let (dx, dy) = (p.x() - robot.x_cm, p.y() - robot.y_cm);
    let (s, c) = robot.heading_rad.sin_cos();
    let (fx, fy) = (c * dx + s * dy, -s * dx + c * dy);
    let v = camera_local.coords;
    Relative {
        field_cm: [p.x(), p.y()],
        camera_distance_cm: v.coords.norm(),
        body_distance_cm: dx.hypot(dy),
        body_bearing_rad: fy.atan2(fx),
        camera_bearing_rad: v.y.atan2(v.x),
        camera_elevation_rad: v.z.atan2(v.x.hypot(v.y)),
        image: pose.camera.project(&camera_local),
    }
}

/// Builds the truth of a robot-camera frame from the scene, the camera pose at mid-readout and
/// the rendered object buffer and true colour classes (one per pixel, row-major).
#[must_use]
#[expect(
    clippy::too_many_arguments,
    reason = "one call site; every input is distinct"
)]
pub fn robot_view_truth(
    scene: &Scene,
    time_s: f64,
    observer_id: u32,
    robot_pose: RobotPose,
    body: BodyPose,
    joints: HeadJoints,
    pose: &CameraPose,
    sensors: SensorReadings,
    objects: &[u16],
    labels: &[u8],
) -> RobotViewTruth {
    let ball = ball_truth(scene, &robot_pose, pose, objects);
    let goals = goal_truths(scene, &robot_pose, pose, objects);
    let beacons = beacon_truths(scene, &robot_pose, pose, objects, labels);
    let robots = other_robot_truths(scene, observer_id, &robot_pose, pose, objects);
    RobotViewTruth {
        time_s,
        observer_id,
        robot_pose,
        body,
        joints,
        camera_pose: PoseRecord::from_transform(&pose.field_from_camera),
        sensors,
        horizon: pose.horizon(),
        ball,
        goals,
        beacons,
        robots,
        markers: marker_truths(scene, pose, &robot_pose, objects),
    }
}

/// The ball's truth, if the scene has one.
fn ball_truth(
    scene: &Scene,
    robot_pose: &RobotPose,
    pose: &CameraPose,
    objects: &[u16],
) -> Option<BallTruth> {
    let (w, h) = (pose.camera.width_px, pose.camera.height_px);
    scene.ball.map(|b| {
        let centre = Point::<Field>::new(b.x_cm, b.y_cm, b.radius_cm);
        let rel = relative(pose, robot_pose, &centre);
        let cov = coverage(objects, w, object_id::BALL);
        let radius = rel.image.and_then(|_| {
            pose.camera
                .sphere_radius_px(b.radius_cm, rel.camera_distance_cm)
        });
        let (in_image, cut_off, area) = match (rel.image, radius) {
            (Some(c), Some(r)) => disc_in_image(c, r, w, h),
            _ => (0.0, CutOff::default(), 0.0),
        };
        let visible_fraction = covered_fraction(cov.pixels, area);
        BallTruth {
            relative: rel,
            image_radius_px: radius,
            visible_pixels: cov.pixels,
            visible_fraction,
            in_image_fraction: in_image,
            cut_off,
            image_box: cov.bbox,
            ground_velocity_cm_s: None,
            image_velocity_px_s: None,
        }
    })
}

/// Both goals' truth: posts, visible pixels, open stretches.
fn goal_truths(
    scene: &Scene,
    robot_pose: &RobotPose,
    pose: &CameraPose,
    objects: &[u16],
) -> Vec<GoalTruth> {
    let w = pose.camera.width_px;
    let f = &scene.field;
    [GoalColour::Yellow, GoalColour::SkyBlue]
        .into_iter()
        .map(|colour| {
            let (s, id) = match colour {
                GoalColour::Yellow => (1.0, object_id::YELLOW_GOAL),
                GoalColour::SkyBlue => (-1.0, object_id::SKY_BLUE_GOAL),
            };
            let x = s * f.length_cm / 2.0;
            let post_y = f.goal_width_cm / 2.0 + f.goal_wall_cm / 2.0;
            let post = |y: f64| PostTruth {
                field_cm: [x, y],
                image_base: pose.image_from_field(&Point::new(x, y, 0.0)),
                image_top: pose.image_from_field(&Point::new(x, y, f.goal_height_cm)),
            };
            let cov = coverage(objects, w, id);
            let gaps = cov.bbox.map_or_else(Vec::new, |b| {
                open_gaps(objects, w, id, &b, pose, &Point::new(x, 0.0, 0.0))
            });
            GoalTruth {
                colour,
                relative: relative(pose, robot_pose, &Point::new(x, 0.0, 0.0)),
                visible_pixels: cov.pixels,
                image_box: cov.bbox,
                posts: [post(s * post_y), post(-s * post_y)],
                largest_gap: gaps.first().copied(),
                second_gap: gaps.get(1).copied(),
            }
        })
        .collect()
}

/// Every beacon's truth: the whole beacon's pixels, and its two coloured bands' pixels (the
/// object's pixels whose true class is not the white base's) against the bands' projection.
fn beacon_truths(
    scene: &Scene,
    robot_pose: &RobotPose,
    pose: &CameraPose,
    objects: &[u16],
    labels: &[u8],
) -> Vec<BeaconTruth> {
    let w = pose.camera.width_px;
    let white = ColourClass::White.code();
    scene
        .beacons
        .iter()
        .enumerate()
        .map(|(i, b)| {
            let id = object_id::BEACON + u16::try_from(i).unwrap_or(0).min(89);
            let cov = coverage(objects, w, id);
            let bands = coverage_where(objects, w, |k| {
                objects[k] == id && labels.get(k).is_some_and(|c| *c != white)
            });
            let boundary = Point::new(b.x_cm, b.y_cm, b.base_height_cm + b.band_height_cm);
            let (area, bands_cut_off) = beacon_bands_projection(b, pose);
            BeaconTruth {
                name: b.name.clone(),
                relative: relative(pose, robot_pose, &boundary),
                visible_pixels: cov.pixels,
                image_box: cov.bbox,
                colours: Some([b.top.class(), b.bottom.class()]),
                band_pixels: bands.pixels,
                bands_visible_fraction: covered_fraction(bands.pixels, area),
                bands_cut_off,
                bands_box: bands.bbox,
            }
        })
        .collect()
}

/// The image area (pixels²) of a beacon's two coloured bands as the camera at `pose` sees them
/// whole — the convex hull of the projected circles bounding the bands, a cylinder's outline —
/// and the image borders that hull crosses. Area 0 and every side cut when part of the bands
/// is behind the camera.
fn beacon_bands_projection(b: &Beacon, pose: &CameraPose) -> (f64, CutOff) {
    let (bottom, top) = (b.base_height_cm, b.base_height_cm + 2.0 * b.band_height_cm);
    let outline: Option<Vec<ImagePoint>> = [bottom, top]
        .into_iter()
        .flat_map(|z| {
            (0..48).map(move |k| {
                let a = f64::from(k) * std::f64::consts::TAU / 48.0;
                Point::new(
                    b.x_cm + b.radius_cm * a.cos(),
                    b.y_cm + b.radius_cm * a.sin(),
                    z,
                )
            })
        })
        .map(|p| pose.image_from_field(&p))
        .collect();
    let all = CutOff {
        left: true,
        right: true,
        top: true,
        bottom: true,
    };
    let Some(points) = outline else {
        return (0.0, all);
    };
    let (w, h) = (pose.camera.width_px as f64, pose.camera.height_px as f64);
    let cut = CutOff {
        left: points.iter().any(|p| p.x_px < 0.0),
        right: points.iter().any(|p| p.x_px > w),
        top: points.iter().any(|p| p.y_px < 0.0),
        bottom: points.iter().any(|p| p.y_px > h),
    };
    (convex_hull_area(points), cut)
}

/// The area of the convex hull of `points` (Andrew's monotone chain, then the shoelace
/// formula), pixels².
fn convex_hull_area(mut points: Vec<ImagePoint>) -> f64 {
    points.sort_by(|a, b| a.x_px.total_cmp(&b.x_px).then(a.y_px.total_cmp(&b.y_px)));
    let cross = |o: &ImagePoint, a: &ImagePoint, b: &ImagePoint| {
        (a.x_px - o.x_px) * (b.y_px - o.y_px) - (a.y_px - o.y_px) * (b.x_px - o.x_px)
    };
    let mut hull: Vec<ImagePoint> = Vec::with_capacity(points.len() + 1);
    for pass in 0..2 {
        let start = hull.len();
        let ordered: Box<dyn Iterator<Item = &ImagePoint>> = if pass == 0 {
            Box::new(points.iter())
        } else {
            Box::new(points.iter().rev())
        };
        for p in ordered {
            while hull.len() >= start + 2
                && cross(&hull[hull.len() - 2], &hull[hull.len() - 1], p) <= 0.0
            {
                hull.pop();
            }
            hull.push(*p);
        }
        hull.pop();
    }
    let twice: f64 = hull
        .iter()
        .zip(hull.iter().cycle().skip(1))
        .map(|(a, b)| a.x_px * b.y_px - b.x_px * a.y_px)
        .sum();
    twice.abs() / 2.0
}

/// The truth of every robot but the observer.
fn other_robot_truths(
    scene: &Scene,
    observer_id: u32,
    robot_pose: &RobotPose,
    pose: &CameraPose,
    objects: &[u16],
) -> Vec<RobotTruth> {
    let w = pose.camera.width_px;
    scene
        .robots
        .iter()
        .filter(|r| r.id != observer_id)
        .map(|r| {
            let id = object_id::ROBOT + u16::try_from(r.id).unwrap_or(0).min(899);
            let cov = coverage(objects, w, id);
            let centre = Point::new(r.pose.x_cm, r.pose.y_cm, r.body.height_cm);
            RobotTruth {
                id: r.id,
                team: r.team,
                heading_rad: r.pose.heading_rad,
                relative: relative(pose, robot_pose, &centre),
                visible_pixels: cov.pixels,
                image_box: cov.bbox,
            }
        })
        .collect()
}

/// Fraction of a disc inside the image (sampled on a 41×41 grid), the borders it crosses, and
/// its area in pixels.
fn disc_in_image(c: ImagePoint, r: f64, w: usize, h: usize) -> (f64, CutOff, f64) {
    let (wf, hf) = (w as f64, h as f64);
    let mut inside = 0_u32;
    let mut total = 0_u32;
    for a in -20..=20 {
        for b in -20..=20 {
            let (dx, dy) = (f64::from(a) / 20.0, f64::from(b) / 20.0);
            if dx * dx + dy * dy > 1.0 {
                continue;
            }
            total += 1;
            let (x, y) = (c.x_px + dx * r, c.y_px + dy * r);
            if x >= 0.0 && y >= 0.0 && x < wf && y < hf {
                inside += 1;
            }
        }
    }
    let overlaps = inside > 0;
    let cut_off = CutOff {
        left: overlaps && c.x_px - r < 0.0,
        right: overlaps && c.x_px + r > wf,
        top: overlaps && c.y_px - r < 0.0,
        bottom: overlaps && c.y_px + r > hf,
    };
    (
        f64::from(inside) / f64::from(total.max(1)),
        cut_off,
        std::f64::consts::PI * r * r,
    )
}

/// Height above the ground of the gap scan, centimetres: about an ERS-7's shoulder, where the
/// requirement puts it (and the recognition's default `gap_scan_height_cm`).
pub const GAP_SCAN_HEIGHT_CM: f64 = 15.0;

/// The open stretches of a goal, widest first: runs of goal pixels, not hidden by anything in
/// front, along the image line parallel to the horizon through the point 15 cm above the
/// mouth's centre ([`GAP_SCAN_HEIGHT_CM`]), sampled every pixel across the goal's box. Where
/// that line leaves the image (a goal cut off at the top under a tilted horizon), each sample
/// moves down, perpendicular to the horizon, to the first row inside it within the box: what
/// the camera shows of that stretch. Ends are the pixel columns of the first and last sample.
fn open_gaps(
    objects: &[u16],
    w: usize,
    goal: u16,
    b: &PixelBox,
    pose: &CameraPose,
    mouth: &Point<Field>,
) -> Vec<GoalGap> {
    let h = objects.len() / w.max(1);
    let Some(at) = pose.image_from_field(&Point::new(
        mouth.x(),
        mouth.y(),
        mouth.z() + GAP_SCAN_HEIGHT_CM,
    )) else {
        return Vec::new();
    };
    let c = pose.camera.centre;
    let angle = pose.horizon().map_or(0.0, |h| h.angle_rad);
    let (sin, cos) = angle.sin_cos();
    // Image → level frame (the horizon horizontal) and back, about the optical centre.
    let level = |x: f64, y: f64| {
        let (dx, dy) = (x - c.x_px, y - c.y_px);
        (c.x_px + cos * dx - sin * dy, c.y_px + sin * dx + cos * dy)
    };
    let image = |x: f64, y: f64| {
        let (dx, dy) = (x - c.x_px, y - c.y_px);
        (c.x_px + cos * dx + sin * dy, c.y_px - sin * dx + cos * dy)
    };
    let corners = [
        level(b.min_x as f64, b.min_y as f64),
        level((b.max_x + 1) as f64, b.min_y as f64),
        level(b.min_x as f64, (b.max_y + 1) as f64),
        level((b.max_x + 1) as f64, (b.max_y + 1) as f64),
    ];
    let x0 = corners
        .iter()
        .map(|p| p.0)
        .fold(f64::INFINITY, f64::min)
        .floor();
    let x1 = corners
        .iter()
        .map(|p| p.0)
        .fold(f64::NEG_INFINITY, f64::max)
        .ceil();
    let bottom = corners
        .iter()
        .map(|p| p.1)
        .fold(f64::NEG_INFINITY, f64::max);
    let row = level(at.x_px, at.y_px).1;
    let (wf, hf) = (w as f64, h as f64);
    let inside = |q: (f64, f64)| q.0 >= 0.0 && q.1 >= 0.0 && q.0 < wf && q.1 < hf;
    // Per sample: the image point and whether it shows the goal.
    let mut samples = Vec::new();
    let mut x = x0;
    while x <= x1 {
        let mut y = row;
        let mut q = image(x + 0.5, y);
        while !inside(q) && y + 1.0 < bottom {
            y += 1.0;
            q = image(x + 0.5, y);
        }
        #[expect(
            clippy::cast_possible_truncation,
            clippy::cast_sign_loss,
            reason = "inside the image"
        )]
        let shows = inside(q) && objects.get(q.1 as usize * w + q.0 as usize) == Some(&goal);
        samples.push((q, shows));
        x += 1.0;
    }
    let mut gaps: Vec<GoalGap> = samples
        .chunk_by(|a, b| a.1 == b.1)
        .filter(|run| run.first().is_some_and(|s| s.1))
        .filter_map(|run| {
            let (first, last) = (run.first()?.0, run.last()?.0);
            #[expect(
                clippy::cast_possible_truncation,
                clippy::cast_sign_loss,
                reason = "inside the image"
            )]
            let (s, e) = (first.0 as usize, (last.0 as usize).max(first.0 as usize));
            let (left, right) = (
                pose.camera.bearing_rad(ImagePoint::new(s as f64, first.1)),
                pose.camera
                    .bearing_rad(ImagePoint::new((e + 1) as f64, last.1)),
            );
            Some(GoalGap {
                from_x_px: s,
                to_x_px: e,
                centre_bearing_rad: (left + right) / 2.0,
                width_rad: left - right,
            })
        })
        .collect();
    gaps.sort_by_key(|g| std::cmp::Reverse(g.to_x_px - g.from_x_px));
    gaps
}

/// The truth of every marker of `scene` seen through `pose`.
fn marker_truths(
    scene: &Scene,
    pose: &CameraPose,
    robot_pose: &RobotPose,
    objects: &[u16],
) -> Vec<MarkerTruth> {
    let w = pose.camera.width_px;
    let camera = pose.position();
    scene
        .markers
        .iter()
        .enumerate()
        .map(|(i, m)| {
            let id = object_id::MARKER_PINK + u16::try_from(i).unwrap_or(0).min(999);
            let cov = coverage(objects, w, id);
            let project = |across: f64, up: f64| {
                let [x, y, z] = m.face_point(across, up);
                pose.image_from_field(&Point::new(x, y, z))
            };
            let quad: Option<Vec<ImagePoint>> =
                [(-0.5, 0.5), (0.5, 0.5), (0.5, -0.5), (-0.5, -0.5)]
                    .iter()
                    .map(|&(a, u)| project(a, u))
                    .collect();
            let area = quad.map_or(0.0, |q| {
                let twice: f64 = (0..4)
                    .map(|k| {
                        let (a, b) = (q[k], q[(k + 1) % 4]);
                        a.x_px * b.y_px - b.x_px * a.y_px
                    })
                    .sum();
                twice.abs() / 2.0
            });
            let panel_in_image = [(-1.5, 1.5), (1.5, 1.5), (1.5, -1.5), (-1.5, -1.5)]
                .iter()
                .all(|&(a, u)| project(a, u).is_some_and(|p| pose.camera.contains(p)));
            let to_camera = (camera.x() - m.x_cm, camera.y() - m.y_cm);
            let turn = to_camera.1.atan2(to_camera.0) - m.facing_rad;
            let view_angle_rad = turn.sin().atan2(turn.cos()).abs();
            let pink_visible_fraction = covered_fraction(cov.pixels, area);
            MarkerTruth {
                id: i,
                name: m.name.clone(),
                relative: relative(
                    pose,
                    robot_pose,
                    &Point::new(m.x_cm, m.y_cm, m.centre_height_cm),
                ),
                centre_height_cm: m.centre_height_cm,
                tiles: m.tiles.map(|t| t.class().code()),
                pink_pixels: cov.pixels,
                pink_visible_fraction,
                image_box: cov.bbox,
                panel_in_image,
                view_angle_rad,
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn disc_fully_inside_and_half_cut() {
        let (f, cut, area) = disc_in_image(ImagePoint::new(100.0, 80.0), 10.0, 208, 160);
        assert!((f - 1.0).abs() < 1e-12);
        assert_eq!(cut, CutOff::default());
        assert!((area - std::f64::consts::PI * 100.0).abs() < 1e-9);
        let (f, cut, _) = disc_in_image(ImagePoint::new(0.0, 80.0), 10.0, 208, 160);
        assert!((f - 0.5).abs() < 0.05, "{f}");
        assert!(cut.left && !cut.right && !cut.top && !cut.bottom);
        let (f, cut, _) = disc_in_image(ImagePoint::new(-50.0, 80.0), 10.0, 208, 160);
        assert_eq!(f, 0.0);
        assert_eq!(cut, CutOff::default());
    }

    #[test]
    fn open_gaps_run_along_the_shoulder_row_and_stop_at_what_is_in_front() {
        use crate::geometry::{PinholeCamera, Transform};
        use nalgebra::{UnitQuaternion, Vector3};
        // A level camera 20 cm up looking along +x: 15 cm above a mouth 200 cm ahead is
        // 191.9 · 5 / 200 = 4.8 px below the centre, row 84.
        let pose = CameraPose {
            camera: PinholeCamera::ers7(),
            field_from_camera: Transform::new(
                Vector3::new(0.0, 0.0, 20.0),
                UnitQuaternion::identity(),
            ),
        };
        let (w, h, goal, robot) = (208, 160, 2_u16, object_id::ROBOT);
        let mut objects = vec![0_u16; w * h];
        for y in 70..96 {
            for x in 60..150 {
                objects[y * w + x] = goal;
            }
        }
        // A robot hides columns 90..=100 below row 80, and a ball-sized thing 120..=121 only
        // below the scan row.
        for y in 80..96 {
            for x in 90..=100 {
                objects[y * w + x] = robot;
            }
        }
        for y in 88..96 {
            for x in 120..=121 {
                objects[y * w + x] = object_id::BALL;
            }
        }
        let b = coverage(&objects, w, goal).bbox.expect("goal");
        let gaps = open_gaps(&objects, w, goal, &b, &pose, &Point::new(200.0, 0.0, 0.0));
        let spans: Vec<(usize, usize)> = gaps.iter().map(|g| (g.from_x_px, g.to_x_px)).collect();
        assert_eq!(spans, vec![(101, 149), (60, 89)]);
        assert!(gaps[0].width_rad > gaps[1].width_rad && gaps[1].width_rad > 0.0);
        // The centre bearing of the right stretch is right of the image centre (negative).
        assert!(gaps[0].centre_bearing_rad < 0.0);
    }
}
