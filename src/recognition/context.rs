//! What recognition knows about the camera for one frame: its intrinsics, its pose over the
//! ground (from the joint readings through the ERS-7 body model), the horizon, the rolling-shutter
//! skew implied by the head's motion, and the infra-red distance.

use serde::{Deserialize, Serialize};

use super::fit::Point;
use crate::geometry::{
    Body, BodyPose, Camera, CameraPose, Ers7Dimensions, Field, HeadJoints, Horizon, ImagePoint,
    PinholeCamera, Point as GeoPoint, RobotPose, Transform,
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

/// How the head moved while the frame was read out: the joints at the reference row and their
/// change over one frame interval (from the previous frame's readings), with the body they sit
/// on. It gives the camera pose at any row's read-out time, so the rolling shutter's skew can be
/// removed through the body model rather than by a linear shear.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HeadMotion {
    /// Joint angles at the reference row's read-out time, radians.
    pub joints: HeadJoints,
    /// Pan change over one frame interval (now − previous), radians.
    pub pan_per_frame_rad: f64,
    /// Lower-tilt change over one frame interval (now − previous), radians.
    pub tilt_per_frame_rad: f64,
    /// The body in the robot's ground frame (taken as still during the frame).
    pub field_from_body: Transform<Field, Body>,
    /// The head chain.
    pub dims: Ers7Dimensions,
}

impl HeadMotion {
    /// The camera pose `frames` frame intervals after the reference row's read-out time
    /// (negative: before), the joints moving at their last measured rate; `with_tilt` false
    /// keeps the tilt at its reference value (pan only).
    #[must_use]
    pub fn pose_at(&self, camera: PinholeCamera, frames: f64, with_tilt: bool) -> CameraPose {
        let mut joints = self.joints;
        joints.pan_rad += frames * self.pan_per_frame_rad;
        if with_tilt {
            joints.tilt1_rad += frames * self.tilt_per_frame_rad;
        }
        CameraPose {
            camera,
            field_from_camera: self.field_from_body * self.dims.body_from_camera(&joints),
        }
    }
}

/// The camera of one frame, as recognition needs it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ViewContext {
    /// Intrinsics: size and effective distance d (pixels).
    pub camera: PinholeCamera,
    /// The camera's pose in the robot's ground frame (robot at the origin facing +x), when the
    /// joint readings were available.
    pub pose: Option<CameraPose>,
    /// The camera in the body frame, when the joint readings were available.
    pub body_from_camera: Option<Transform<Body, Camera>>,
    /// The horizon line, when the pose is known.
    pub horizon: Option<Horizon>,
    /// Horizontal rolling-shutter shear, pixels per image row (from the pan velocity).
    pub skew_x_per_line: f64,
    /// Vertical rolling-shutter stretch, pixels per image row (from the tilt velocity).
    pub skew_y_per_line: f64,
    /// Near infra-red distance, centimetres.
    pub ir_distance_cm: Option<f64>,
    /// The head's motion during read-out, when the joints now and one frame earlier were known
    /// (and the pose is known).
    pub motion: Option<HeadMotion>,
    /// Time between frames, seconds, when the readings gave it; the read-out of all rows is
    /// taken to last one frame interval (as the skew removal assumes).
    pub frame_interval_s: Option<f64>,
}

impl ViewContext {
    /// A camera with no pose: bearings and distances still work, heights and the horizon do not.
    #[must_use]
    pub fn without_pose(camera: PinholeCamera) -> Self {
        Self {
            camera,
            pose: None,
            body_from_camera: None,
            horizon: None,
            skew_x_per_line: 0.0,
            skew_y_per_line: 0.0,
            ir_distance_cm: None,
            motion: None,
            frame_interval_s: None,
        }
    }

    /// The context of a frame with these sensor readings, through the ERS-7 chain `dims`.
    /// Missing or non-finite readings leave the pose (and with it heights and the horizon) out.
    #[must_use]
    pub fn from_sensors(
        camera: PinholeCamera,
        readings: &SensorReadings,
        dims: &Ers7Dimensions,
    ) -> Self {
        let (readings, _) = readings.sanitised();
        let mut ctx = Self::without_pose(camera);
        ctx.ir_distance_cm = readings.ir_near_cm.or(readings.ir_far_cm);
        ctx.frame_interval_s = readings
            .frame_interval_s
            .filter(|s| s.is_finite() && *s > 0.0);
        if let Some(joints) = HeadJoints::from_sensors(&readings) {
            let body_from_camera = dims.body_from_camera(&joints);
            let body = BodyPose::from_sensors(&readings, &BodyPose::ERS7_STANCE);
            let field_from_body = body.field_from_body(&RobotPose::default());
            let field_from_camera = field_from_body * body_from_camera;
            let change = |now: Option<f64>, before: Option<f64>| match (now, before) {
                (Some(a), Some(b)) if (a - b).is_finite() => Some(a - b),
                _ => None,
            };
            let pan = change(readings.head_pan_rad, readings.previous_head_pan_rad);
            let tilt = change(readings.head_tilt_rad, readings.previous_head_tilt_rad);
            if pan.is_some() || tilt.is_some() {
                ctx.motion = Some(HeadMotion {
                    joints,
                    pan_per_frame_rad: pan.unwrap_or(0.0),
                    tilt_per_frame_rad: tilt.unwrap_or(0.0),
                    field_from_body,
                    dims: *dims,
                });
            }
            let pose = CameraPose {
                camera,
                field_from_camera,
            };
            ctx.body_from_camera = Some(body_from_camera);
            ctx.horizon = pose.horizon();
            ctx.pose = Some(pose);
        }
        let d = camera.focal_px;
        let lines = camera.height_px.max(1) as f64;
        if let (Some(now), Some(before)) = (readings.head_pan_rad, readings.previous_head_pan_rad) {
            // The formula: Δx = d·tan(θ_current) − d·tan(θ_previous), spread over the
            // lines of one frame.
            let dx = d * now.tan() - d * before.tan();
            if dx.is_finite() {
                ctx.skew_x_per_line = dx / lines;
            }
        }
        if let (Some(now), Some(before)) = (readings.head_tilt_rad, readings.previous_head_tilt_rad)
        {
            let dy = d * now.tan() - d * before.tan();
            if dy.is_finite() {
                ctx.skew_y_per_line = dy / lines;
            }
        }
        ctx
    }

    /// The row whose read-out time the sensor readings describe (the middle of the read-out),
    /// pixels.
    #[must_use]
    pub fn reference_row(&self) -> f64 {
        self.camera.height_px as f64 / 2.0
    }

    /// Moves an image point to where it would have been seen at the reference row's read-out
    /// time, removing the rolling shutter's horizontal shear (and, with `vertical`, the tilt's
    /// stretch). Rows above the reference were read earlier, rows below later.
    #[must_use]
    pub fn unskew(&self, p: Point, vertical: bool) -> Point {
        let lines = p.1 - self.reference_row();
        let y = if vertical {
            p.1 - self.skew_y_per_line * lines
        } else {
            p.1
        };
        (p.0 - self.skew_x_per_line * lines, y)
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
    pub fn unskew_at(&self, p: Point, distance_cm: f64, with_tilt: bool) -> Point {
        let (Some(motion), Some(pose)) = (self.motion, self.pose) else {
            return self.unskew(p, with_tilt);
        };
        let lines = self.camera.height_px.max(1) as f64;
        let frames = p.1 / lines - 0.5;
        if !(frames.is_finite() && distance_cm.is_finite() && distance_cm > 0.0) {
            return self.unskew(p, with_tilt);
        }
        let then = motion.pose_at(self.camera, frames, with_tilt);
        let field = then.field_from_camera * self.camera_point(p, distance_cm);
        match pose.image_from_field(&field) {
            Some(q) if q.x_px.is_finite() && q.y_px.is_finite() => (q.x_px, q.y_px),
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
    pub fn camera_angles(&self, p: Point) -> (f64, f64) {
        let ip = ImagePoint::new(p.0, p.1);
        (self.camera.bearing_rad(ip), self.camera.elevation_rad(ip))
    }

    /// The point `distance_cm` along the ray through `p`, camera frame.
    fn camera_point(&self, p: Point, distance_cm: f64) -> GeoPoint<Camera> {
        let ray = self.camera.unit_ray(ImagePoint::new(p.0, p.1)).coords * distance_cm;
        GeoPoint::new(ray.x, ray.y, ray.z)
    }

    /// Camera-relative distance, bearing and elevation of something at `distance_cm` along the ray
    /// through image point `p`.
    #[must_use]
    pub fn camera_relative(&self, p: Point, distance_cm: f64) -> Relative {
        let c = self.camera_point(p, distance_cm);
        Relative::of_point(c.x(), c.y(), c.z())
    }

    /// Body-relative distance, bearing and elevation (from the body centre), when the pose is known.
    #[must_use]
    pub fn body_relative(&self, p: Point, distance_cm: f64) -> Option<Relative> {
        let b = self.body_from_camera? * self.camera_point(p, distance_cm);
        Some(Relative::of_point(b.x(), b.y(), b.z()))
    }

    /// Height above the ground of the point `distance_cm` along the ray through `p`,
    /// centimetres, when the pose is known.
    #[must_use]
    pub fn height_above_ground(&self, p: Point, distance_cm: f64) -> Option<f64> {
        let pose = self.pose?;
        let g = pose.field_from_camera * self.camera_point(p, distance_cm);
        Some(g.z())
    }

    /// Ground distance (cm) to where the ray through `p` meets the plane at `z_cm`, when the pose
    /// is known and the ray goes there.
    #[must_use]
    pub fn distance_to_plane(&self, p: Point, z_cm: f64) -> Option<f64> {
        let pose = self.pose?;
        let hit = pose.point_on_plane(ImagePoint::new(p.0, p.1), z_cm)?;
        Some(hit.distance_to(&pose.position()))
    }
}
