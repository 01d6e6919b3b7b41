//! Object recognition on a classified frame and its blobs: the ball, goals with posts and the
//! open gap, beacons and the horizon. Every candidate carries a [`confidence::Confidence`]
//! breakdown, and every scan is kept as drawing data ([`draw::Primitive`]), so the app, `eotn
//! render` and the JSON show why an object was or was not recognised.
//!
//! | module | role |
//! |---|---|
//! | [`context`] | the frame's camera: intrinsics, pose (from the readings or the joints), horizon, shutter skew |
//! | [`confidence`] | named tests adding to or subtracting from a candidate's confidence |
//! | [`fit`] | circle and line fits, rotation about a centre |
//! | [`scan`] | horizon-parallel scan areas, the six edge-scan patterns, skew removal |
//! | [`ball`], [`goals`], [`beacons`] | the recognisers |
//! | [`patterns`] | the "almost SLAM" coloured-pattern recogniser (learn, then identify) |
//! | [`overhead_params`] | the overhead recogniser's settings (marker sizes, fills), a section of the parameters file |
//! | [`draw`] | drawing primitives as data |

pub mod ball;
pub mod beacons;
pub mod confidence;
pub mod context;
pub mod draw;
pub mod fit;
pub mod goals;
pub mod overhead_params;
pub mod params_file;
pub mod patterns;
pub mod scan;

use serde::{Deserialize, Serialize};

use crate::blobs::BlobSet;
use crate::classify::ClassifiedImage;
use crate::geometry::{Ers7Dimensions, Horizon, PinholeCamera};
use crate::sensors::SensorReadings;
pub use ball::{Ball, BallParams, BallResult};
pub use beacons::{Beacon, BeaconParams};
pub use context::{Relative, ViewContext};
pub use draw::{CircleRole, LineRole, ObjectId, Primitive};
pub use goals::{GoalCandidate, GoalParams, GoalResult};
pub use overhead_params::OverheadRecognitionParams;

/// Settings of every recogniser, and the camera to assume for frames that are not the ERS-7's.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct RecognitionParams {
    /// Ball recognition.
    pub ball: BallParams,
    /// Goal recognition.
    pub goals: GoalParams,
    /// Beacon recognition.
    pub beacons: BeaconParams,
    /// Coloured-pattern signatures.
    pub patterns: patterns::PatternParams,
    /// Horizontal field of view (degrees) for frames other than 208×160 (which are the ERS-7's
    /// 56.9°). 46.4° is the Nao's camera.
    pub other_camera_fov_deg: f64,
    /// Time the camera takes to read out all rows of one image, seconds: the rolling shutter's
    /// skew is the head's velocity times this (1/30 s for the ERS-7's and the Nao's cameras).
    pub camera_readout_s: f64,
    /// Lengths of the head chain used to place the camera from the joints.
    pub body: Ers7Dimensions,
    /// The overhead camera's recogniser: marker and ball sizes, fills, layout agreement.
    pub overhead: OverheadRecognitionParams,
}

impl Default for RecognitionParams {
    fn default() -> Self {
        Self {
            ball: BallParams::default(),
            goals: GoalParams::default(),
            beacons: BeaconParams::default(),
            patterns: patterns::PatternParams::default(),
            other_camera_fov_deg: 46.4,
            camera_readout_s: context::DEFAULT_READOUT_S,
            body: Ers7Dimensions::ERS7,
            overhead: OverheadRecognitionParams::default(),
        }
    }
}

impl RecognitionParams {
    /// The camera for a frame of this size: the ERS-7's for 208×160, else a pinhole with
    /// [`Self::other_camera_fov_deg`].
    #[must_use]
    pub fn camera_for(&self, width: usize, height: usize) -> PinholeCamera {
        if (width, height) == (208, 160) {
            PinholeCamera::ers7()
        } else {
            PinholeCamera::from_horizontal_fov(
                width,
                height,
                self.other_camera_fov_deg.to_radians(),
            )
        }
    }

    /// The view context of a frame of this size with these readings (none: no pose). A camera
    /// pose carried in the readings (the robot's own estimate) is used for any frame; otherwise
    /// the pose comes from the joints through the ERS-7 body model, for 208×160 frames only, so
    /// frames of other robots without a pose get camera-relative recognition without heights or
    /// horizon, but keep their infra-red and shutter-skew readings.
    #[must_use]
    pub fn context_for(
        &self,
        width: usize,
        height: usize,
        sensors: Option<&SensorReadings>,
    ) -> ViewContext {
        let camera = sensors
            .and_then(|s| calibrated_camera(width, height, s))
            .unwrap_or_else(|| self.camera_for(width, height));
        match sensors {
            Some(s) => {
                let ctx = ViewContext::from_sensors_with_readout(
                    camera,
                    s,
                    &self.body,
                    self.camera_readout_s,
                );
                if (width, height) == (208, 160) {
                    ctx
                } else {
                    ctx.without_joint_pose()
                }
            }
            None => ViewContext::without_pose(camera),
        }
    }
}

/// The camera as calibrated (`camera_focal_px` and the optical centre in the readings, from a
/// ROS `CameraInfo`), when the readings carry a positive focal length; the centre defaults to
/// the image's middle.
fn calibrated_camera(width: usize, height: usize, s: &SensorReadings) -> Option<PinholeCamera> {
    let focal_px = s.camera_focal_px.filter(|f| f.is_finite() && *f > 0.0)?;
    let (w, h) = (width as f64, height as f64);
    Some(PinholeCamera {
        width_px: width,
        height_px: height,
        focal_px,
        centre: crate::geometry::ImagePoint::new(
            s.camera_centre_x_px.unwrap_or(w / 2.0),
            s.camera_centre_y_px.unwrap_or(h / 2.0),
        ),
    })
}

/// Everything recognised in one frame.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct Recognition {
    /// The ball and every ball candidate.
    pub ball: BallResult,
    /// Goal candidates; accepted ones are goals.
    pub goals: GoalResult,
    /// Beacon candidates; accepted ones are beacons.
    pub beacons: Vec<Beacon>,
    /// Pink markers with the signature around each, identified when a pattern memory was
    /// given.
    pub patterns: Vec<patterns::PatternCandidate>,
    /// The horizon, when the camera pose was known.
    pub horizon: Option<Horizon>,
}

/// Runs every recogniser on a classified frame; `memory` (learnt coloured patterns), when
/// given, identifies the pink markers' signatures.
#[must_use]
pub fn recognise(
    img: &ClassifiedImage,
    blobs: &BlobSet,
    ctx: &ViewContext,
    params: &RecognitionParams,
    memory: Option<&patterns::PatternMemory>,
) -> Recognition {
    let beacons = beacons::recognise_beacons(img, blobs, ctx, &params.beacons);
    let beacon_boxes: Vec<crate::frame::PixelBox> = beacons
        .iter()
        .filter(|b| b.accepted)
        .map(|b| b.bounds)
        .collect();
    // A beacon's pink band is the beacon's, not a coloured-pattern marker.
    let observations = patterns::observe(img, blobs, ctx, &params.patterns, &beacon_boxes);
    Recognition {
        ball: ball::recognise_ball(img, blobs, ctx, &params.ball),
        goals: goals::recognise_goals(img, blobs, ctx, &params.goals, &beacon_boxes),
        beacons,
        patterns: observations
            .into_iter()
            .map(|o| patterns::PatternMemory::candidate(memory, o, ctx, &params.patterns))
            .collect(),
        horizon: ctx.horizon,
    }
}

impl Recognition {
    /// Every accepted object: what a viewer shows when it shows only what was found.
    #[must_use]
    pub fn accepted_owners(&self) -> Vec<ObjectId> {
        let balls = self.ball.candidates.iter().enumerate();
        let balls = balls
            .filter(|(_, c)| c.accepted)
            .map(|(i, _)| ObjectId::Ball(i));
        let goals = self.goals.candidates.iter().enumerate();
        let goals = goals
            .filter(|(_, c)| c.accepted)
            .map(|(i, c)| ObjectId::Goal(c.colour, i));
        let beacons = self.beacons.iter().enumerate().filter(|(_, b)| b.accepted);
        let patterns = self.patterns.iter().enumerate().filter(|(_, p)| p.accepted);
        balls
            .chain(goals)
            .chain(beacons.map(|(i, _)| ObjectId::Beacon(i)))
            .chain(patterns.map(|(i, _)| ObjectId::Pattern(i)))
            .collect()
    }

    /// Every drawing primitive: horizon, ball, goals, beacons, coloured patterns.
    #[must_use]
    pub fn primitives(&self, width: usize, height: usize) -> Vec<Primitive> {
        let mut out = Vec::new();
        if let Some((a, b)) = self
            .horizon
            .and_then(|h| h.clip_to_image(width as f64, height as f64))
        {
            out.push(Primitive::Line {
                owner: ObjectId::Horizon,
                role: LineRole::Horizon,
                from: a,
                to: b,
            });
        }
        out.extend(self.ball.primitives());
        out.extend(self.goals.primitives());
        out.extend(beacons::beacon_primitives(&self.beacons));
        out.extend(patterns::pattern_primitives(&self.patterns));
        out
    }
}
