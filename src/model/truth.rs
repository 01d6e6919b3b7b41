//! Per-frame ground truth: what a perfect recognition would report for a frame, as types.
//!
//! Stored as JSON on a stream's `/ground_truth` channel (the simulator writes it, `sim::truth`
//! computes it; evaluation and the app read it). Image positions are projections with the
//! camera pose at the middle of the frame's readout, the instant the sensor readings describe
//! (so they are what a perfect skew correction would give); pixel counts, boxes and gaps count
//! what the frame shows, so they include occlusion, the image border and the rolling shutter's
//! skew. Distances in centimetres, angles in radians (`FORMATS.md` signs: bearing positive
//! left, elevation positive up), image coordinates in pixels.

use serde::{Deserialize, Serialize};

pub use crate::frame::CutOff;
use crate::frame::PixelBox;
use crate::geometry::{
    BodyPose, HeadJoints, Horizon, ImagePoint, MarkerIdentity, MarkerTeam, OverheadCamera,
    PoseRecord, RobotPose,
};
use crate::lut::ColourClass;
use crate::model::scene::{GoalColour, Team};
use crate::sensors::SensorReadings;

/// Ground truth of one frame: a robot's camera view or the overhead view.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "view", rename_all = "snake_case")]
pub enum GroundTruth {
    /// A frame from a robot's head camera.
    Robot(Box<RobotViewTruth>),
    /// A frame from the overhead camera.
    Overhead(Box<OverheadTruth>),
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
    #[serde(with = "box_fields", default)]
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
    #[serde(with = "box_fields", default)]
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
    #[serde(with = "box_fields", default)]
    pub image_box: Option<PixelBox>,
    /// The colour classes of its upper and lower band (`None` in streams made before they
    /// were recorded).
    #[serde(default)]
    pub colours: Option<[ColourClass; 2]>,
    /// Pixels that show its two coloured bands (the white base not counted).
    #[serde(default)]
    pub band_pixels: usize,
    /// Band pixels over the area of the two bands' whole projection (0..1): less than 1 when
    /// cut by the image border or hidden behind something.
    #[serde(default)]
    pub bands_visible_fraction: f64,
    /// Image borders that cut the bands' projection.
    #[serde(default)]
    pub bands_cut_off: CutOff,
    /// Box of the band pixels.
    #[serde(with = "box_fields", default)]
    pub bands_box: Option<PixelBox>,
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
    #[serde(with = "box_fields", default)]
    pub image_box: Option<PixelBox>,
    /// Every corner of the whole 3 × 3 panel projects inside the image.
    pub panel_in_image: bool,
    /// Angle between the panel's facing direction and the direction to the camera, radians
    /// (0: seen head-on).
    pub view_angle_rad: f64,
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
    #[serde(with = "box_fields", default)]
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

/// The ground truth's boxes in JSON: `{"min_x", "min_y", "max_x", "max_y"}` or `null`, the form
/// they had before [`PixelBox`] (which writes four numbers), so the shipped streams' truth reads
/// and compares unchanged.
mod box_fields {
    use serde::{Deserialize, Deserializer, Serialize, Serializer};

    use crate::frame::PixelBox;

    #[derive(Serialize, Deserialize)]
    struct Fields {
        min_x: u32,
        min_y: u32,
        max_x: u32,
        max_y: u32,
    }

    pub(super) fn serialize<S: Serializer>(b: &Option<PixelBox>, s: S) -> Result<S::Ok, S::Error> {
        b.map(|b| Fields {
            min_x: b.min_x,
            min_y: b.min_y,
            max_x: b.max_x,
            max_y: b.max_y,
        })
        .serialize(s)
    }

    pub(super) fn deserialize<'de, D: Deserializer<'de>>(
        d: D,
    ) -> Result<Option<PixelBox>, D::Error> {
        Ok(Option::<Fields>::deserialize(d)?
            .map(|f| PixelBox::new(f.min_x, f.min_y, f.max_x, f.max_y)))
    }
}
