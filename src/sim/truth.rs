//! Per-frame ground truth: what a perfect recognition would report for a rendered frame.
//!
//! Stored as JSON on a stream's `/ground_truth` channel. Image positions are projections with
//! the camera pose at the middle of the frame's readout, the instant the sensor readings
//! describe (so they are what a perfect skew correction would give); pixel counts, boxes and
//! gaps come from the rendered object buffer, so they include occlusion, the image border and
//! the rolling shutter's skew. Distances in centimetres, angles in radians (`FORMATS.md` signs:
//! bearing positive left, elevation positive up), image coordinates in pixels.

use serde::{Deserialize, Serialize};

use super::render::object_id;
use super::scene::{GoalColour, Robot, Scene, Team};
use crate::geometry::{
    BodyPose, CameraPose, Field, HeadJoints, Horizon, ImagePoint, MarkerIdentity, MarkerTeam,
    OverheadCamera, Point, PoseRecord, RobotMarker, RobotPose,
};
use crate::sensors::SensorReadings;

/// Ground truth of one frame: a robot's camera view or the overhead view.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "view", rename_all = "snake_case")]
pub enum GroundTruth {
    /// A frame from a robot's head camera.
    Robot(Box<RobotViewTruth>),
    /// A frame from the overhead camera.
    Overhead(OverheadTruth),
}

/// An inclusive pixel box, `FORMATS.md` convention.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct PixelBox {
    /// Leftmost column.
    pub min_x: usize,
    /// Topmost row.
    pub min_y: usize,
    /// Rightmost column.
    pub max_x: usize,
    /// Bottom row.
    pub max_y: usize,
}

/// Which image borders cut an object's outline.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub struct CutOff {
    /// Cut by the left border.
    pub left: bool,
    /// Cut by the right border.
    pub right: bool,
    /// Cut by the top border.
    pub top: bool,
    /// Cut by the bottom border.
    pub bottom: bool,
}

/// Truth of a robot-camera frame.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RobotViewTruth {
    /// Time of the frame (middle of readout), seconds since the scenario start.
    pub time_s: f64,
    /// Identity of the robot whose camera this is.
    pub observer_id: u32,
    /// Where it stands.
    pub robot_pose: RobotPose,
    /// Its body height and tilt.
    pub body: BodyPose,
    /// Its head joints at the middle of readout.
    pub joints: HeadJoints,
    /// The camera pose in the field at the middle of readout.
    pub camera_pose: PoseRecord,
    /// The sensor readings sent with the frame (also on `/sensors`).
    pub sensors: SensorReadings,
    /// The horizon at the middle of readout, if the camera is not looking straight down.
    pub horizon: Option<Horizon>,
    /// The ball, if in the scene.
    pub ball: Option<BallTruth>,
    /// Both goals.
    pub goals: Vec<GoalTruth>,
    /// Every beacon.
    pub beacons: Vec<BeaconTruth>,
    /// Every other robot.
    pub robots: Vec<RobotTruth>,
    /// Every coloured-pattern marker of the scene (none outside the pattern tour).
    #[serde(default)]
    pub markers: Vec<MarkerTruth>,
}

/// Where something is relative to the observing robot.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Relative {
    /// Field position (x, y), centimetres.
    pub field_cm: [f64; 2],
    /// Straight-line distance from the camera to the object's reference point, centimetres.
    pub camera_distance_cm: f64,
    /// Distance on the ground from the body centre, centimetres.
    pub body_distance_cm: f64,
    /// Bearing on the ground from the body's heading, radians, positive left.
    pub body_bearing_rad: f64,
    /// Bearing from the camera's optical axis (as the image point gives it), radians.
    pub camera_bearing_rad: f64,
    /// Elevation above the camera's x–y plane, radians.
    pub camera_elevation_rad: f64,
    /// Projection of the reference point into the image, if in front of the camera (may lie
    /// outside the image).
    pub image: Option<ImagePoint>,
}

/// The ball in a robot's view.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct BallTruth {
    /// Position relative to the observer (reference point: the ball's centre).
    pub relative: Relative,
    /// Image radius, pixels (for a ball in front of the camera).
    pub image_radius_px: Option<f64>,
    /// Pixels that show the ball.
    pub visible_pixels: usize,
    /// Visible pixels over the area of the whole projected disc (0..1): less than 1 when cut
    /// by the image border or hidden behind something.
    pub visible_fraction: f64,
    /// Part of the projected disc inside the image (0..1), ignoring occlusion.
    pub in_image_fraction: f64,
    /// Image borders that cut the disc.
    pub cut_off: CutOff,
    /// Box of the visible ball pixels.
    pub image_box: Option<PixelBox>,
    /// The ball's velocity on the ground in the observer's frame (x ahead, y left),
    /// centimetres per second.
    #[serde(default)]
    pub ground_velocity_cm_s: Option<[f64; 2]>,
    /// How fast the ball's centre moves in the image through its own motion, with the camera
    /// held at its mid-readout pose, pixels per second (x right, y down): what a fit of the
    /// ball's rolling-shutter shear should find once the camera's own skew is removed.
    #[serde(default)]
    pub image_velocity_px_s: Option<[f64; 2]>,
}

/// Fills in a ball's velocity truth from its field velocity `v_cm_s` (cm/s): turned into the
/// observer's frame, and as the image motion of its centre through the mid-readout `pose`
/// (a finite difference over ±1 ms).
pub fn add_ball_velocity(
    ball: &mut BallTruth,
    v_cm_s: [f64; 2],
    robot: &RobotPose,
    pose: &CameraPose,
) {
    let (s, c) = robot.heading_rad.sin_cos();
    ball.ground_velocity_cm_s = Some([
        c * v_cm_s[0] + s * v_cm_s[1],
        -s * v_cm_s[0] + c * v_cm_s[1],
    ]);
    let centre = ball.relative.field_cm;
    let h = 1e-3;
    let at = |k: f64| {
        pose.image_from_field(&Point::<Field>::new(
            centre[0] + k * h * v_cm_s[0],
            centre[1] + k * h * v_cm_s[1],
            4.25,
        ))
    };
    ball.image_velocity_px_s = match (at(-1.0), at(1.0)) {
        (Some(a), Some(b)) => Some([(b.x_px - a.x_px) / (2.0 * h), (b.y_px - a.y_px) / (2.0 * h)]),
        _ => None,
    };
}

/// A goal post: the front end of a side wall.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PostTruth {
    /// Field position of the post's centre on the ground (x, y), centimetres.
    pub field_cm: [f64; 2],
    /// Image position of the post's foot.
    pub image_base: Option<ImagePoint>,
    /// Image position of the post's top.
    pub image_top: Option<ImagePoint>,
}

/// An open stretch of a goal: not hidden by anything in front, along the gap scan.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct GoalGap {
    /// Leftmost open column.
    pub from_x_px: usize,
    /// Rightmost open column.
    pub to_x_px: usize,
    /// Camera bearing of the gap's centre, radians.
    pub centre_bearing_rad: f64,
    /// Angular width of the gap, radians.
    pub width_rad: f64,
}

/// A goal in a robot's view.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct GoalTruth {
    /// Which goal.
    pub colour: GoalColour,
    /// Position relative to the observer (reference point: the goal mouth's centre on the
    /// ground).
    pub relative: Relative,
    /// Pixels that show the goal.
    pub visible_pixels: usize,
    /// Box of those pixels.
    pub image_box: Option<PixelBox>,
    /// Left and right post as seen from the field (left = +y side for the yellow goal seen
    /// from the centre).
    pub posts: [PostTruth; 2],
    /// The largest open stretch of the goal along the gap scan (see `open_gaps`), if any of
    /// the goal shows.
    pub largest_gap: Option<GoalGap>,
    /// The second largest open stretch, if any: two of about equal width are both "the
    /// largest" to within a pixel or two.
    #[serde(default)]
    pub second_gap: Option<GoalGap>,
}

/// A beacon in a robot's view.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BeaconTruth {
    /// Its name in the scene (top colour first).
    pub name: String,
    /// Relative position (reference point: the boundary between the two colour bands).
    pub relative: Relative,
    /// Pixels that show the beacon.
    pub visible_pixels: usize,
    /// Box of those pixels.
    pub image_box: Option<PixelBox>,
}

/// A coloured-pattern marker in a robot's view.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MarkerTruth {
    /// Its index in the scene's markers: the place's identity.
    pub id: usize,
    /// Its name in the scene.
    pub name: String,
    /// Relative position (reference point: the centre of the pink middle tile).
    pub relative: Relative,
    /// Height of the pink tile's centre above the ground, centimetres.
    pub centre_height_cm: f64,
    /// The class code of each of the nine tiles, row by row as seen from the front (the
    /// signature a perfect classification gives).
    pub tiles: [u8; 9],
    /// Pixels that show the pink middle tile.
    pub pink_pixels: usize,
    /// Those pixels over the area of the tile's projection (0..1): less than 1 when cut by the
    /// image border or hidden behind something.
    pub pink_visible_fraction: f64,
    /// Box of the visible pink pixels.
    pub image_box: Option<PixelBox>,
    /// Every corner of the whole 3 × 3 panel projects inside the image.
    pub panel_in_image: bool,
    /// Angle between the panel's facing direction and the direction to the camera, radians
    /// (0: seen head-on).
    pub view_angle_rad: f64,
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

/// Another robot in a robot's view.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct RobotTruth {
    /// Identity.
    pub id: u32,
    /// Team.
    pub team: Team,
    /// Heading, radians.
    pub heading_rad: f64,
    /// Relative position (reference point: the body centre).
    pub relative: Relative,
    /// Pixels that show the robot.
    pub visible_pixels: usize,
    /// Box of those pixels.
    pub image_box: Option<PixelBox>,
}

/// Truth of an overhead frame.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct OverheadTruth {
    /// Time of the frame, seconds since the scenario start.
    pub time_s: f64,
    /// The camera model that made the frame.
    pub camera: OverheadCamera,
    /// The ball, if in the scene.
    pub ball: Option<OverheadObject>,
    /// Every robot.
    pub robots: Vec<OverheadRobot>,
}

/// The ball seen from above.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct OverheadObject {
    /// Field position (x, y), centimetres.
    pub field_cm: [f64; 2],
    /// Image position of its centre.
    pub image: Option<ImagePoint>,
    /// Pixels that show it.
    pub visible_pixels: usize,
}

/// A robot seen from above.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct OverheadRobot {
    /// Identity.
    pub id: u32,
    /// Team.
    pub team: Team,
    /// Field position of the body centre (x, y), centimetres.
    pub field_cm: [f64; 2],
    /// Heading, radians counter-clockwise from +x.
    pub heading_rad: f64,
    /// Image position of the body centre.
    pub image: Option<ImagePoint>,
    /// Pixels that show it.
    pub visible_pixels: usize,
    /// Its overhead marker, if it wears one.
    #[serde(default)]
    pub marker: Option<OverheadMarkerTruth>,
}

/// A robot's overhead marker as the overhead camera sees it.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct OverheadMarkerTruth {
    /// Team dot colour.
    pub team: MarkerTeam,
    /// Identity, 0–15.
    pub identity: MarkerIdentity,
    /// Height of the plate's top, centimetres.
    pub plate_height_cm: f64,
    /// Image position of the plate's centre.
    pub image: Option<ImagePoint>,
    /// Share of the plate's full image area that shows, 0 to 1 (less when another robot's
    /// plate covers it or the image edge cuts it).
    pub visible_fraction: f64,
}

impl OverheadMarkerTruth {
    /// Whether the whole plate shows (at least 98% of it: the outline's pixels are shared).
    #[must_use]
    pub fn fully_visible(&self) -> bool {
        self.visible_fraction >= 0.98
    }
}

/// Pixel statistics of one object in an object buffer.
#[derive(Debug, Clone, Copy, Default)]
struct Coverage {
    pixels: usize,
    bbox: Option<PixelBox>,
}

fn coverage(objects: &[u16], width: usize, id: u16) -> Coverage {
    let mut c = Coverage::default();
    for (k, _) in objects.iter().enumerate().filter(|(_, o)| **o == id) {
        let (x, y) = (k % width, k / width);
        c.pixels += 1;
        c.bbox = Some(match c.bbox {
            None => PixelBox {
                min_x: x,
                min_y: y,
                max_x: x,
                max_y: y,
            },
            Some(b) => PixelBox {
                min_x: b.min_x.min(x),
                min_y: b.min_y.min(y),
                max_x: b.max_x.max(x),
                max_y: b.max_y.max(y),
            },
        });
    }
    c
}

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
/// the rendered object buffer.
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
) -> RobotViewTruth {
    let (w, h) = (pose.camera.width_px, pose.camera.height_px);
    let ball = scene.ball.map(|b| {
        let centre = Point::<Field>::new(b.x_cm, b.y_cm, b.radius_cm);
        let rel = relative(pose, &robot_pose, &centre);
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
    });
    let f = &scene.field;
    let goals = [GoalColour::Yellow, GoalColour::SkyBlue]
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
                relative: relative(pose, &robot_pose, &Point::new(x, 0.0, 0.0)),
                visible_pixels: cov.pixels,
                image_box: cov.bbox,
                posts: [post(s * post_y), post(-s * post_y)],
                largest_gap: gaps.first().copied(),
                second_gap: gaps.get(1).copied(),
            }
        })
        .collect();
    let beacons = scene
        .beacons
        .iter()
        .enumerate()
        .map(|(i, b)| {
            let id = object_id::BEACON + u16::try_from(i).unwrap_or(0).min(89);
            let cov = coverage(objects, w, id);
            let boundary = Point::new(b.x_cm, b.y_cm, b.base_height_cm + b.band_height_cm);
            BeaconTruth {
                name: b.name.clone(),
                relative: relative(pose, &robot_pose, &boundary),
                visible_pixels: cov.pixels,
                image_box: cov.bbox,
            }
        })
        .collect();
    let robots = scene
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
                relative: relative(pose, &robot_pose, &centre),
                visible_pixels: cov.pixels,
                image_box: cov.bbox,
            }
        })
        .collect();
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

/// Builds the truth of an overhead frame.
#[must_use]
pub fn overhead_truth(
    scene: &Scene,
    time_s: f64,
    camera: &OverheadCamera,
    objects: &[u16],
) -> OverheadTruth {
    let w = camera.width_px;
    OverheadTruth {
        time_s,
        camera: *camera,
        ball: scene.ball.map(|b| OverheadObject {
            field_cm: [b.x_cm, b.y_cm],
            image: camera.image_from_field(&Point::new(b.x_cm, b.y_cm, b.radius_cm)),
            visible_pixels: coverage(objects, w, object_id::BALL).pixels,
        }),
        robots: scene
            .robots
            .iter()
            .map(|r| OverheadRobot {
                id: r.id,
                team: r.team,
                field_cm: [r.pose.x_cm, r.pose.y_cm],
                heading_rad: r.pose.heading_rad,
                image: camera.image_from_field(&Point::new(
                    r.pose.x_cm,
                    r.pose.y_cm,
                    r.body.height_cm,
                )),
                visible_pixels: coverage(
                    objects,
                    w,
                    object_id::ROBOT + u16::try_from(r.id).unwrap_or(0).min(899),
                )
                .pixels,
                marker: r
                    .marker
                    .map(|m| overhead_marker_truth(&m, r, camera, objects)),
            })
            .collect(),
    }
}

fn overhead_marker_truth(
    m: &RobotMarker,
    r: &Robot,
    camera: &OverheadCamera,
    objects: &[u16],
) -> OverheadMarkerTruth {
    let n = u16::try_from(r.id).unwrap_or(0).min(899);
    let pixels = coverage(objects, camera.width_px, object_id::ROBOT_MARKER + n).pixels;
    // The plate's full image area: the projected outline as a 64-gon (shoelace formula).
    let radius = crate::geometry::marker::PLATE_DIAMETER_CM / 2.0;
    let outline: Option<Vec<ImagePoint>> = (0..64)
        .map(|k| {
            let a = f64::from(k) * std::f64::consts::TAU / 64.0;
            camera.image_from_field(&Point::new(
                r.pose.x_cm + radius * a.cos(),
                r.pose.y_cm + radius * a.sin(),
                m.plate_height_cm,
            ))
        })
        .collect();
    let area = outline.map_or(0.0, |o| {
        let twice: f64 = o
            .iter()
            .zip(o.iter().cycle().skip(1))
            .map(|(a, b)| a.x_px * b.y_px - b.x_px * a.y_px)
            .sum();
        twice.abs() / 2.0
    });
    OverheadMarkerTruth {
        team: m.team,
        identity: m.identity,
        plate_height_cm: m.plate_height_cm,
        image: camera.image_from_field(&Point::new(r.pose.x_cm, r.pose.y_cm, m.plate_height_cm)),
        visible_fraction: covered_fraction(pixels, area),
    }
}

/// The share of an object's full image area (pixels²) that its visible pixels cover, 0 to 1
/// (0 when the area is empty).
fn covered_fraction(pixels: usize, area: f64) -> f64 {
    if area > 0.0 {
        (pixels as f64 / area).min(1.0)
    } else {
        0.0
    }
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

    #[test]
    fn coverage_counts_pixels_and_boxes() {
        let mut objects = vec![0_u16; 10 * 4];
        objects[12] = 1;
        objects[27] = 1;
        let c = coverage(&objects, 10, 1);
        assert_eq!(c.pixels, 2);
        assert_eq!(
            c.bbox,
            Some(PixelBox {
                min_x: 2,
                min_y: 1,
                max_x: 7,
                max_y: 2
            })
        );
    }
}
