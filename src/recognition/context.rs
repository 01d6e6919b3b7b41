//! What recognition knows about the camera for one frame: its intrinsics, its pose over the
//! ground (the robot's own estimate carried in the readings, or the joint readings through the
//! ERS-7 body model), the horizon, the rolling-shutter skew implied by the head's motion during
//! the camera's read-out time, and the infra-red distance.

use serde::{Deserialize, Serialize};

use crate::geometry::{
    Body, BodyPose, Camera, CameraPose, Ers7Dimensions, Field, HeadJoints, Horizon, ImagePoint,
    PinholeCamera, Point as GeoPoint, RobotPose, Transform, camera_pose_from_readings, rotation_y,
    rotation_z,
};
use crate::sensors::SensorReadings;

/// Distance, bearing and elevation of something seen, relative to the camera or the body.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Relative {
    /// Straight-line distance, centimetres.
    pub distance_cm: f64,
    /// Bearing, radians, positive to the left.
    pub bearing_rad: f64,
    /// Elevation, radians, positive up.
    pub elevation_rad: f64,
}

impl Relative {
    fn of_point(x: f64, y: f64, z: f64) -> Self {
        let ground = x.hypot(y);
        Self {
            distance_cm: ground.hypot(z),
            bearing_rad: y.atan2(x),
            elevation_rad: z.atan2(ground),
        }
    }
}

/// Read-out time of a whole image, first row to last, seconds, when the camera's parameters do
/// not say otherwise: the ERS-7's and the Nao's cameras deliver 30 frames per second and read
/// their rows out over about one frame time (B-Human's later Nao code uses 34 ms).
pub const DEFAULT_READOUT_S: f64 = 1.0 / 30.0;

/// Where a frame's camera pose came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PoseSource {
    /// The robot's own estimate of its camera's pose over the ground, carried in the readings
    /// (`camera_height_cm`, `camera_pitch_rad`, …; see [`camera_pose_from_readings`]).
    Readings,
    /// The head joints through the ERS-7 chain ([`Ers7Dimensions`]) on a typical stance.
    Ers7Joints,
}

/// How the camera turns while the rows are read out.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum MotionChain {
    /// The ERS-7 head chain: the joints at the reference row and the body they sit on.
    Ers7 {
        /// Joint angles at the reference row's read-out time, radians.
        joints: HeadJoints,
        /// The body in the robot's ground frame (taken as still during the frame).
        field_from_body: Transform<Field, Body>,
        /// The head chain.
        dims: Ers7Dimensions,
    },
    /// A camera pose given by the robot, with no head chain known: the pan turns the camera
    /// about the vertical through its centre and the tilt about its own y axis (the few
    /// centimetres between the joints and the lens move the image by well under a pixel over
    /// one read-out).
    Camera {
        /// The camera at the reference row's read-out time.
        field_from_camera: Transform<Field, Camera>,
    },
}

/// How the head moved while the frame was read out: the pose at the reference row and the
/// pan and tilt changes over one read-out (first row to last). The changes are the joints'
/// velocities times the camera's read-out time, the velocities measured between the previous
/// logged frame and this one — which may be several camera frames apart (the B-Human log kept
/// about every sixth). It gives the camera pose at any row's read-out time, so the rolling
/// shutter's skew can be removed through the body model rather than by a linear shear.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HeadMotion {
    /// Pan change over one read-out, radians (positive left).
    pub pan_per_readout_rad: f64,
    /// Tilt change over one read-out, radians (positive up).
    pub tilt_per_readout_rad: f64,
    /// What turns.
    pub chain: MotionChain,
}

impl HeadMotion {
    /// The camera pose `readouts` read-out times after the reference row's read-out time
    /// (negative: before; the first row is −0.5, the last +0.5), the joints moving at their
    /// measured rate; `with_tilt` false keeps the tilt at its reference value (pan only).
    #[must_use]
    pub fn pose_at(&self, camera: PinholeCamera, readouts: f64, with_tilt: bool) -> CameraPose {
        let pan = readouts * self.pan_per_readout_rad;
        let tilt = if with_tilt {
            readouts * self.tilt_per_readout_rad
        } else {
            0.0
        };
        let field_from_camera = match self.chain {
            MotionChain::Ers7 {
                mut joints,
                field_from_body,
                dims,
            } => {
                joints.pan_rad += pan;
                if with_tilt {
                    joints.tilt1_rad += tilt;
                }
                field_from_body * dims.body_from_camera(&joints)
            }
            MotionChain::Camera { field_from_camera } => {
                let iso = field_from_camera.isometry;
                // Tilt positive up is a negative rotation about the camera's y axis.
                Transform::from_isometry(nalgebra::Isometry3::from_parts(
                    iso.translation,
                    rotation_z(pan) * iso.rotation * rotation_y(-tilt),
                ))
            }
        };
        CameraPose {
            camera,
            field_from_camera,
        }
    }
}

/// The camera of one frame, as recognition needs it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ViewContext {
    /// Intrinsics: size and effective distance d (pixels).
    pub camera: PinholeCamera,
    /// The camera's pose in the robot's ground frame (robot at the origin facing +x), when the
    /// readings gave it or the joint readings were available.
    pub pose: Option<CameraPose>,
    /// Where the pose came from.
    pub pose_source: Option<PoseSource>,
    /// The camera in the body frame, when the pose is known. With a pose from the readings the
    /// "body" is the robot's ground frame (origin on the ground below the robot, as the pose).
    pub body_from_camera: Option<Transform<Body, Camera>>,
    /// The horizon line, when the pose is known.
    pub horizon: Option<Horizon>,
    /// Horizontal rolling-shutter shear, pixels per image row, by the formula
    /// Δx = d·tan θ_now − d·tan θ_before over the rows (θ the head pan): the shift of an object
    /// straight ahead of the body. Reported; [`Self::unskew`] uses each point's own angle.
    pub skew_x_per_line: f64,
    /// Vertical rolling-shutter stretch, pixels per image row (the same from the tilt).
    pub skew_y_per_line: f64,
    /// How far the head panned during one read-out (first row to last), radians, positive left.
    pub pan_per_readout_rad: f64,
    /// How far the head tilted during one read-out, radians, positive up.
    pub tilt_per_readout_rad: f64,
    /// Near infra-red distance, centimetres.
    pub ir_distance_cm: Option<f64>,
    /// The head's motion during read-out, when the joints now and at the previous frame were
    /// known (and the pose is known).
    pub motion: Option<HeadMotion>,
    /// Time between this frame and the previous one, seconds, when the readings gave it.
    pub frame_interval_s: Option<f64>,
    /// Read-out time of the whole image, first row to last, seconds (a camera parameter,
    /// [`DEFAULT_READOUT_S`] unless set).
    pub readout_s: f64,
}

/// The angle one read-out time before `now`, at the rate measured between `before` (one frame
/// interval earlier) and `now`; `scale` = read-out time / frame interval. With a scale of 1 (a
/// stream that kept every camera frame) that is `before` itself.
fn one_readout_before(now: f64, before: f64, scale: f64) -> f64 {
    if scale == 1.0 {
        before
    } else {
        now - (now - before) * scale
    }
}

impl ViewContext {
    /// A camera with no pose: bearings and distances still work, heights and the horizon do not.
    #[must_use]
    pub fn without_pose(camera: PinholeCamera) -> Self {
        Self {
            camera,
            pose: None,
            pose_source: None,
            body_from_camera: None,
            horizon: None,
            skew_x_per_line: 0.0,
            skew_y_per_line: 0.0,
            pan_per_readout_rad: 0.0,
            tilt_per_readout_rad: 0.0,
            ir_distance_cm: None,
            motion: None,
            frame_interval_s: None,
            readout_s: DEFAULT_READOUT_S,
        }
    }

    /// The context of a frame with these sensor readings, through the ERS-7 chain `dims` when
    /// the readings carry no camera pose, with the default read-out time
    /// ([`Self::from_sensors_with_readout`]).
    #[must_use]
    pub fn from_sensors(
        camera: PinholeCamera,
        readings: &SensorReadings,
        dims: &Ers7Dimensions,
    ) -> Self {
        Self::from_sensors_with_readout(camera, readings, dims, DEFAULT_READOUT_S)
    }

    /// The context of a frame with these sensor readings. The camera pose is the readings' own
    /// ([`camera_pose_from_readings`]) when they carry one, else the joints through the ERS-7
    /// chain `dims`; missing or non-finite readings leave the pose (and with it heights and the
    /// horizon) out. The shutter skew is the pan (tilt) velocity between the previous frame and
    /// this one times `readout_s`, the time the camera takes to read all rows; without a usable
    /// frame interval (missing, zero, negative) the change since the previous frame is taken as
    /// the change over one read-out, as the formula does.
    #[must_use]
    pub fn from_sensors_with_readout(
        camera: PinholeCamera,
        readings: &SensorReadings,
        dims: &Ers7Dimensions,
        readout_s: f64,
    ) -> Self {
        let (readings, _) = readings.sanitised();
        let mut ctx = Self::without_pose(camera);
        if readout_s.is_finite() && readout_s >= 0.0 {
            ctx.readout_s = readout_s;
        }
        ctx.ir_distance_cm = readings.ir_near_cm.or(readings.ir_far_cm);
        ctx.frame_interval_s = readings
            .frame_interval_s
            .filter(|s| s.is_finite() && *s > 0.0);
        let scale = ctx
            .frame_interval_s
            .map_or(1.0, |interval| ctx.readout_s / interval);
        // Each joint one read-out before now, when its previous reading is known.
        let earlier = |now: Option<f64>, before: Option<f64>| match (now, before) {
            (Some(a), Some(b)) if (a - b).is_finite() => Some((a, one_readout_before(a, b, scale))),
            _ => None,
        };
        let pan = earlier(readings.head_pan_rad, readings.previous_head_pan_rad);
        let tilt = earlier(readings.head_tilt_rad, readings.previous_head_tilt_rad);
        let posed = match camera_pose_from_readings(&readings) {
            Some(field_from_camera) => Some((
                PoseSource::Readings,
                field_from_camera,
                Transform::<Body, Camera>::from_isometry(field_from_camera.isometry),
                MotionChain::Camera { field_from_camera },
            )),
            None => HeadJoints::from_sensors(&readings).map(|joints| {
                let body_from_camera = dims.body_from_camera(&joints);
                let body = BodyPose::from_sensors(&readings, &BodyPose::ERS7_STANCE);
                let field_from_body = body.field_from_body(&RobotPose::default());
                (
                    PoseSource::Ers7Joints,
                    field_from_body * body_from_camera,
                    body_from_camera,
                    MotionChain::Ers7 {
                        joints,
                        field_from_body,
                        dims: *dims,
                    },
                )
            }),
        };
        if let Some((source, field_from_camera, body_from_camera, chain)) = posed {
            if pan.is_some() || tilt.is_some() {
                ctx.motion = Some(HeadMotion {
                    pan_per_readout_rad: pan.map_or(0.0, |(a, b)| a - b),
                    tilt_per_readout_rad: tilt.map_or(0.0, |(a, b)| a - b),
                    chain,
                });
            }
            let pose = CameraPose {
                camera,
                field_from_camera,
            };
            ctx.pose_source = Some(source);
            ctx.body_from_camera = Some(body_from_camera);
            ctx.horizon = pose.horizon();
            ctx.pose = Some(pose);
        }
        let d = camera.focal_px;
        let lines = camera.height_px.max(1) as f64;
        // The formula, Δx = d·tan(θ_current) − d·tan(θ_previous), with θ_previous the
        // angle one read-out earlier, spread over the lines of one image.
        if let Some((now, before)) = pan {
            let dx = d * now.tan() - d * before.tan();
            if dx.is_finite() {
                ctx.skew_x_per_line = dx / lines;
                ctx.pan_per_readout_rad = now - before;
            }
        }
        if let Some((now, before)) = tilt {
            let dy = d * now.tan() - d * before.tan();
            if dy.is_finite() {
                ctx.skew_y_per_line = dy / lines;
                ctx.tilt_per_readout_rad = now - before;
            }
        }
        ctx
    }

    /// The same context without a pose that came from the ERS-7 chain (for frames of other
    /// robots, whose head chain is not the ERS-7's); a pose from the readings is kept.
    #[must_use]
    pub fn without_joint_pose(mut self) -> Self {
        if self.pose_source == Some(PoseSource::Ers7Joints) {
            self.pose = None;
            self.pose_source = None;
            self.body_from_camera = None;
            self.horizon = None;
            self.motion = None;
        }
        self
    }

    /// The row whose read-out time the sensor readings describe (the middle of the read-out),
    /// pixels.
    #[must_use]
    pub fn reference_row(&self) -> f64 {
        self.camera.height_px as f64 / 2.0
    }

    /// Moves an image point to where it would have been seen at the reference row's read-out
    /// time, removing the rolling shutter's horizontal shear (and, with `vertical`, the tilt's
    /// stretch), without a camera pose. Rows above the reference were read earlier, rows below
    /// later. This is the Δx = d·tan θ_now − d·tan θ_before with θ the point's own angle
    /// from the optical axis: the head panned by δ between the reference and the point's row,
    /// so the point's angle then was its angle now plus δ. For an object straight ahead of the
    /// body that angle is minus the head pan, as the formula has it; elsewhere the head-pan
    /// version is wrong by the tangent's growth (13× for a point at the image centre with the
    /// head panned 1.3 rad).
    #[must_use]
    pub fn unskew(&self, p: ImagePoint, vertical: bool) -> ImagePoint {
        let (c, d) = (self.camera.centre, self.camera.focal_px);
        let readouts = p.y_px / self.camera.height_px.max(1) as f64 - 0.5;
        // x = cx − d·tan(angle left of the axis); y = cy − d·tan(angle above it).
        let turn = |pos: f64, centre: f64, delta: f64| {
            let moved = centre - d * (((centre - pos) / d).atan() + delta).tan();
            if moved.is_finite() { moved } else { pos }
        };
        let x = turn(p.x_px, c.x_px, self.pan_per_readout_rad * readouts);
        let y = if vertical {
            turn(p.y_px, c.y_px, self.tilt_per_readout_rad * readouts)
        } else {
            p.y_px
        };
        ImagePoint::new(x, y)
    }

    /// Moves an image point to where it would have been seen at the reference row's read-out
    /// time, through the body model when the head's motion is known: the point, taken to lie
    /// `distance_cm` from the camera, is placed in the ground frame with the camera pose of its
    /// row's read-out time and projected with the reference pose. This follows panning with a
    /// tilted head (which also moves things vertically) and the tangent's growth towards the
    /// image sides, which the linear shear of [`Self::unskew`] does not. `with_tilt` includes the
    /// tilt's motion. Without the motion (or when the point does not project back), falls back
    /// to [`Self::unskew`].
    #[must_use]
    pub fn unskew_at(&self, p: ImagePoint, distance_cm: f64, with_tilt: bool) -> ImagePoint {
        let (Some(motion), Some(pose)) = (self.motion, self.pose) else {
            return self.unskew(p, with_tilt);
        };
        let lines = self.camera.height_px.max(1) as f64;
        let readouts = p.y_px / lines - 0.5;
        if !(readouts.is_finite() && distance_cm.is_finite() && distance_cm > 0.0) {
            return self.unskew(p, with_tilt);
        }
        let then = motion.pose_at(self.camera, readouts, with_tilt);
        let field = then.field_from_camera * self.camera_point(p, distance_cm);
        match pose.image_from_field(&field) {
            Some(q) if q.is_finite() => q,
            _ => self.unskew(p, with_tilt),
        }
    }

    /// The horizon's angle on screen (radians, counter-clockwise positive), 0 without a pose.
    /// Scans "parallel to the ground" rotate by minus this angle.
    #[must_use]
    pub fn horizon_angle(&self) -> f64 {
        self.horizon.map_or(0.0, |h| h.angle_rad)
    }

    /// Camera-relative bearing and elevation of an image point, radians.
    #[must_use]
    pub fn camera_angles(&self, p: ImagePoint) -> (f64, f64) {
        (self.camera.bearing_rad(p), self.camera.elevation_rad(p))
    }

    /// The point `distance_cm` along the ray through `p`, camera frame.
    fn camera_point(&self, p: ImagePoint, distance_cm: f64) -> GeoPoint<Camera> {
        let ray = self.camera.unit_ray(p).coords * distance_cm;
        GeoPoint::new(ray.x, ray.y, ray.z)
    }

    /// Camera-relative distance, bearing and elevation of something at `distance_cm` along the ray
    /// through image point `p`.
    #[must_use]
    pub fn camera_relative(&self, p: ImagePoint, distance_cm: f64) -> Relative {
        let c = self.camera_point(p, distance_cm);
        Relative::of_point(c.x(), c.y(), c.z())
    }

    /// Body-relative distance, bearing and elevation (from the body centre), when the pose is known.
    #[must_use]
    pub fn body_relative(&self, p: ImagePoint, distance_cm: f64) -> Option<Relative> {
        let b = self.body_from_camera? * self.camera_point(p, distance_cm);
        Some(Relative::of_point(b.x(), b.y(), b.z()))
    }

    /// Height above the ground of the point `distance_cm` along the ray through `p`,
    /// centimetres, when the pose is known.
    #[must_use]
    pub fn height_above_ground(&self, p: ImagePoint, distance_cm: f64) -> Option<f64> {
        let pose = self.pose?;
        let g = pose.field_from_camera * self.camera_point(p, distance_cm);
        Some(g.z())
    }

    /// Straight-line distance (cm) from the camera to where the ray through `p` meets the plane at
    /// `z_cm`, when the pose is known and the ray goes there.
    #[must_use]
    pub fn distance_to_plane(&self, p: ImagePoint, z_cm: f64) -> Option<f64> {
        let pose = self.pose?;
        let hit = pose.point_on_plane(p, z_cm)?;
        Some(hit.distance_to(&pose.position()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    fn panning(interval_s: Option<f64>, pan_rad_per_s: f64) -> SensorReadings {
        let dt = interval_s.unwrap_or(DEFAULT_READOUT_S);
        SensorReadings {
            head_pan_rad: Some(0.2),
            previous_head_pan_rad: Some(0.2 - pan_rad_per_s * dt),
            head_tilt_rad: Some(-0.3),
            previous_head_tilt_rad: Some(-0.3 + 0.5 * dt),
            neck_tilt_rad: Some(0.0),
            frame_interval_s: interval_s,
            ..SensorReadings::default()
        }
    }

    #[test]
    fn unskew_turns_each_point_by_the_pan_at_its_own_angle() {
        // The head panned far left (1.3 rad) and 0.1 rad more over the read-out. Something at
        // body bearing 1.3 rad sits on the optical axis at the reference row's time; a row read
        // 0.4375 read-outs later saw it 0.04375 rad further right. Undoing that puts it back on
        // the axis (the camera turning about its own vertical, as `unskew` assumes).
        let camera = PinholeCamera::ers7();
        let readings = SensorReadings {
            head_pan_rad: Some(1.3),
            previous_head_pan_rad: Some(1.2),
            ..SensorReadings::default()
        };
        let ctx = ViewContext::from_sensors(camera, &readings, &Ers7Dimensions::ERS7);
        assert_relative_eq!(ctx.pan_per_readout_rad, 0.1, epsilon = 1e-12);
        let (cx, d) = (camera.centre.x_px, camera.focal_px);
        let row: f64 = 150.0;
        let seen = cx - d * (-0.1 * (row / 160.0 - 0.5)).tan();
        let moved = ctx.unskew(ImagePoint::new(seen, row), false);
        assert_relative_eq!(moved.x_px, cx, epsilon = 1e-9);
        assert_relative_eq!(moved.y_px, row);
        // The formula with the head's pan angle shifts that row ten times too far.
        let by_head_pan = ctx.skew_x_per_line * (row - ctx.reference_row());
        assert!(
            by_head_pan > 10.0 * (seen - cx),
            "{by_head_pan} vs {}",
            seen - cx
        );
        // Straight ahead of the body (the formula's own case) the two agree to first order.
        let level = ViewContext::from_sensors(
            camera,
            &SensorReadings {
                head_pan_rad: Some(0.01),
                previous_head_pan_rad: Some(-0.01),
                ..SensorReadings::default()
            },
            &Ers7Dimensions::ERS7,
        );
        let p = ImagePoint::new(cx, 10.0);
        let shift = p.x_px - level.unskew(p, false).x_px;
        assert_relative_eq!(
            shift,
            level.skew_x_per_line * (p.y_px - level.reference_row()),
            max_relative = 1e-3
        );
    }

    #[test]
    fn a_5_hz_log_skews_like_a_30_hz_one_at_the_same_pan_velocity() {
        let camera = PinholeCamera::ers7();
        let dims = Ers7Dimensions::ERS7;
        let fast = ViewContext::from_sensors(camera, &panning(Some(1.0 / 30.0), 3.0), &dims);
        let slow = ViewContext::from_sensors(camera, &panning(Some(0.2), 3.0), &dims);
        assert!(fast.skew_x_per_line.abs() > 0.1, "{}", fast.skew_x_per_line);
        assert_relative_eq!(
            slow.skew_x_per_line,
            fast.skew_x_per_line,
            max_relative = 1e-3
        );
        assert_relative_eq!(
            slow.skew_y_per_line,
            fast.skew_y_per_line,
            max_relative = 1e-3
        );
        let (a, b) = (fast.motion.expect("motion"), slow.motion.expect("motion"));
        assert_relative_eq!(a.pan_per_readout_rad, 0.1, epsilon = 1e-12);
        assert_relative_eq!(b.pan_per_readout_rad, 0.1, epsilon = 1e-12);
        assert_relative_eq!(
            b.tilt_per_readout_rad,
            a.tilt_per_readout_rad,
            epsilon = 1e-12
        );
        // The same point moved to the reference time lands in the same place.
        let p = ImagePoint::new(30.0, 10.0);
        let (u, v) = (fast.unskew_at(p, 80.0, true), slow.unskew_at(p, 80.0, true));
        assert!(u.distance_to(&v) < 0.01, "{u:?} vs {v:?}");
        // A longer read-out time skews proportionally more.
        let longer = ViewContext::from_sensors_with_readout(
            camera,
            &panning(Some(0.2), 3.0),
            &dims,
            2.0 / 30.0,
        );
        assert_relative_eq!(
            longer.skew_x_per_line,
            2.0 * fast.skew_x_per_line,
            max_relative = 2e-2
        );
    }

    #[test]
    fn without_a_usable_interval_the_change_since_the_previous_frame_is_one_read_out() {
        let camera = PinholeCamera::ers7();
        let dims = Ers7Dimensions::ERS7;
        let reference = ViewContext::from_sensors(camera, &panning(None, 3.0), &dims);
        let d = camera.focal_px;
        let expected = (d * 0.2_f64.tan() - d * 0.1_f64.tan()) / 160.0;
        assert_relative_eq!(reference.skew_x_per_line, expected, epsilon = 1e-12);
        for bad in [0.0, -0.1, f64::NAN, f64::INFINITY] {
            let mut r = panning(None, 3.0);
            r.frame_interval_s = Some(bad);
            let ctx = ViewContext::from_sensors(camera, &r, &dims);
            assert_eq!(ctx.frame_interval_s, None);
            assert_relative_eq!(ctx.skew_x_per_line, expected, epsilon = 1e-12);
        }
        // Nonsense read-out times fall back to the default and never panic.
        for bad in [f64::NAN, -1.0] {
            let ctx = ViewContext::from_sensors_with_readout(
                camera,
                &panning(Some(0.2), 3.0),
                &dims,
                bad,
            );
            assert_eq!(ctx.readout_s, DEFAULT_READOUT_S);
            assert!(ctx.skew_x_per_line.is_finite());
        }
    }

    #[test]
    fn a_camera_pose_in_the_readings_wins_for_any_frame_size() {
        let readings = SensorReadings {
            camera_x_cm: Some(5.6),
            camera_y_cm: Some(0.4),
            camera_height_cm: Some(48.5),
            camera_pitch_rad: Some(0.23),
            camera_roll_rad: Some(0.0),
            camera_yaw_rad: Some(0.0),
            head_pan_rad: Some(0.0),
            previous_head_pan_rad: Some(-0.1),
            head_tilt_rad: Some(-0.23),
            frame_interval_s: Some(0.2),
            ..SensorReadings::default()
        };
        let params = super::super::RecognitionParams::default();
        let ctx = params.context_for(320, 240, Some(&readings));
        assert_eq!(ctx.pose_source, Some(PoseSource::Readings));
        let pose = ctx.pose.expect("pose");
        assert_relative_eq!(pose.position().z(), 48.5, epsilon = 1e-12);
        // Looking 0.23 rad down: the horizon lies d·tan(0.23) above the image centre.
        let h = ctx.horizon.expect("horizon");
        let y = h.y_at(160.0).expect("not vertical");
        assert_relative_eq!(
            y,
            120.0 - ctx.camera.focal_px * 0.23_f64.tan(),
            epsilon = 1e-6
        );
        // Heights: a point on the ground below the centre has height 0.
        let centre = ImagePoint::new(160.0, 120.0);
        let along = ctx.distance_to_plane(centre, 0.0).expect("looks down");
        assert_relative_eq!(along, 48.5 / 0.23_f64.sin(), max_relative = 1e-9);
        assert!(ctx.height_above_ground(centre, along).expect("pose").abs() < 1e-6);
        assert!(ctx.body_relative(centre, along).is_some());
        // The head's motion turns that camera about the vertical: at the first row's time it
        // looked 0.5 · 0.1/0.2 · (1/30) rad further right (pan positive left).
        let motion = ctx.motion.expect("motion");
        let first = motion.pose_at(ctx.camera, -0.5, false);
        let axis = |p: &CameraPose| {
            let a = (p.field_from_camera * crate::geometry::Vector::<Camera>::new(1.0, 0.0, 0.0))
                .coords;
            a.y.atan2(a.x)
        };
        assert_relative_eq!(
            axis(&first) - axis(&pose),
            -0.5 * 0.5 / 30.0,
            epsilon = 1e-9
        );
        // The same readings without the pose: a 320×240 frame gets no pose from the ERS-7 chain,
        // a 208×160 one does.
        let joints_only = SensorReadings {
            camera_height_cm: None,
            ..readings
        };
        assert!(
            params
                .context_for(320, 240, Some(&joints_only))
                .pose
                .is_none()
        );
        let ers7 = params.context_for(208, 160, Some(&joints_only));
        assert_eq!(ers7.pose_source, Some(PoseSource::Ers7Joints));
    }

    #[test]
    fn a_calibrated_camera_in_the_readings_replaces_the_parameters_field_of_view() {
        let params = super::super::RecognitionParams::default();
        let default = params.context_for(320, 240, None).camera;
        let calibrated = SensorReadings {
            camera_focal_px: Some(250.0),
            camera_centre_x_px: Some(165.0),
            ..SensorReadings::default()
        };
        let ctx = params.context_for(320, 240, Some(&calibrated));
        assert_relative_eq!(ctx.camera.focal_px, 250.0);
        assert_relative_eq!(ctx.camera.centre.x_px, 165.0);
        assert_relative_eq!(ctx.camera.centre.y_px, 120.0);
        assert!((default.focal_px - 250.0).abs() > 50.0, "{default:?}");
        // Without a focal length the parameters' camera stays.
        let centre_only = SensorReadings {
            camera_focal_px: None,
            ..calibrated
        };
        let ctx = params.context_for(320, 240, Some(&centre_only));
        assert_eq!(ctx.camera, default);
    }
}
