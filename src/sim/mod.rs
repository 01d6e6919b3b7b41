//! Synthetic test data: a renderer of the 2005 Four-Legged League field with ground truth.
//!
//! There is no public archive of 2005 AIBO camera frames, so the project makes its own frames
//! whose answers are known, from the same camera models recognition uses ([`crate::geometry`]).
//! [`crate::model`] describes the world, [`render`] ray-casts it into UYVY frames with the camera's
//! faults (noise, vignetting, shared chroma, rolling shutter), [`truth`] says what a perfect
//! recognition would find, and [`scenario`] moves the world over time. [`Simulator::frame`]
//! puts them together: frame `k` of a scenario and seed is always the same, whatever order
//! frames are made in.

mod effects;
pub mod field_rig;
pub mod render;
pub mod rng;
pub mod scenario;
pub mod truth;
pub mod world_models;

use thiserror::Error;

pub use crate::model::{GroundTruth, Scene};
pub use effects::CameraEffects;
pub use render::{Rendered, Renderer, World};
pub use rng::SimRng;
pub use scenario::{Scenario, ScenarioKind, View};
pub use world_models::{KnownError, WorldModelErrors};

use crate::frame::{Frame, FrameError};
use crate::geometry::{
    BodyPose, Camera, CameraPose, Ers7Dimensions, Field, HeadJoints, OverheadCamera, PinholeCamera,
    Transform, Vector,
};
use crate::sensors::SensorReadings;

/// Time between frames, seconds: both cameras deliver 30 frames a second.
pub const FRAME_INTERVAL_S: f64 = 1.0 / 30.0;

/// Why a frame could not be simulated.
#[derive(Debug, Error)]
pub enum SimError {
    /// The scenario's observing robot is missing from its scene (a scenario bug).
    #[error("scenario {scenario}: observing robot {id} is not in the scene at {time_s:.3} s")]
    MissingObserver {
        /// Scenario name.
        scenario: &'static str,
        /// Robot id.
        id: u32,
        /// Time, seconds.
        time_s: f64,
    },
    /// The frame could not be assembled.
    #[error("scenario {scenario}: {source}")]
    Frame {
        /// Scenario name.
        scenario: &'static str,
        /// What went wrong.
        source: FrameError,
    },
}

/// One simulated frame with everything that travels with it in a stream.
#[derive(Debug, Clone)]
pub struct SimFrame {
    /// Capture time (middle of readout), nanoseconds since the scenario start.
    pub time_ns: u64,
    /// The camera frame.
    pub frame: Frame,
    /// The true colour class of each pixel (row-major class codes), for building and scoring
    /// lookup tables.
    pub labels: Vec<u8>,
    /// The robot's sensor readings (robot views only).
    pub sensors: Option<SensorReadings>,
    /// What a perfect recognition would report.
    pub ground_truth: GroundTruth,
    /// Other JSON channels: each robot's world model in the overhead game.
    pub extra: Vec<(String, serde_json::Value)>,
}

/// Renders the frames of one scenario.
#[derive(Debug, Clone)]
pub struct Simulator {
    scenario: Scenario,
    renderer: Renderer,
    head_camera: PinholeCamera,
    overhead_camera: OverheadCamera,
    effects: CameraEffects,
    world_model_errors: WorldModelErrors,
    /// The named ground places the overhead game's robots measure (field cm).
    world_model_landmarks: Vec<(String, [f64; 2])>,
}

impl Simulator {
    /// A simulator for a scenario, with the camera's usual effects.
    #[must_use]
    pub fn new(scenario: Scenario) -> Self {
        let head_camera = PinholeCamera::ers7();
        let overhead_camera = scenario.overhead_camera();
        let (renderer, effects) = match scenario.view() {
            View::Robot { .. } => (Renderer::pinhole(&head_camera), CameraEffects::ERS7),
            View::Overhead => (
                Renderer::overhead(&overhead_camera),
                CameraEffects::OVERHEAD,
            ),
        };
        Self {
            scenario,
            renderer,
            head_camera,
            overhead_camera,
            effects,
            world_model_errors: WorldModelErrors::default(),
            world_model_landmarks: Vec::new(),
        }
    }

    /// The same, with the overhead game's robots measuring these named ground places (the
    /// field file's landmarks, field cm) where their cameras would see them.
    #[must_use]
    pub fn with_world_model_landmarks(mut self, landmarks: Vec<(String, [f64; 2])>) -> Self {
        self.world_model_landmarks = landmarks;
        self
    }

    /// The same, with the robots' world models erring as `errors` says (the overhead game).
    #[must_use]
    pub fn with_world_model_errors(mut self, errors: WorldModelErrors) -> Self {
        self.world_model_errors = errors;
        self
    }

    /// The same, with other camera effects (e.g. [`CameraEffects::NONE`] for ideal frames).
    #[must_use]
    pub fn with_effects(mut self, effects: CameraEffects) -> Self {
        self.effects = effects;
        self
    }

    /// The scenario.
    #[must_use]
    pub fn scenario(&self) -> &Scenario {
        &self.scenario
    }

    /// Renders frame `index` (time `index / 30` s).
    ///
    /// # Errors
    /// [`SimError`] if the scenario is inconsistent; never for valid scenarios.
    pub fn frame(&self, index: u64) -> Result<SimFrame, SimError> {
        let t = index as f64 * FRAME_INTERVAL_S;
        #[expect(
            clippy::cast_possible_truncation,
            clippy::cast_sign_loss,
            reason = "t ≥ 0, small"
        )]
        let time_ns = (t * 1e9).round() as u64;
        let scene = self.scenario.scene_at(t);
        let world = World::compile(&scene);
        let mut rng = SimRng::derived(self.scenario.seed, index);
        let at = FrameAt {
            index,
            t,
            time_ns,
            scene: &scene,
            world: &world,
        };
        match self.scenario.view() {
            View::Overhead => self.overhead_frame(&at, &mut rng),
            View::Robot { observer_id } => self.robot_frame(&at, observer_id, &mut rng),
        }
    }

    fn frame_error(&self) -> impl Fn(FrameError) -> SimError {
        let name = self.scenario.kind.name();
        move |source| SimError::Frame {
            scenario: name,
            source,
        }
    }

    /// The overhead camera's frame, with the robots' world models.
    fn overhead_frame(&self, at: &FrameAt<'_>, rng: &mut SimRng) -> Result<SimFrame, SimError> {
        let (t, scene) = (at.t, at.scene);
        let pose = self.overhead_camera.field_from_camera().isometry;
        let out = self
            .renderer
            .render(at.world, &|_| pose, &self.effects, u16::MAX, rng)
            .map_err(self.frame_error())?;
        let truth = truth::overhead_truth(scene, t, &self.overhead_camera, &out.objects);
        Ok(SimFrame {
            time_ns: at.time_ns,
            frame: out.frame,
            labels: out.labels,
            sensors: None,
            ground_truth: GroundTruth::Overhead(Box::new(truth)),
            extra: world_models::world_models(
                scene,
                world_models::WorldModelAt {
                    t_s: t,
                    time_ns: at.time_ns,
                    frame: at.index,
                },
                self.scenario.seed,
                &self.world_model_errors,
                &self.world_model_landmarks,
            ),
        })
    }

    /// A robot's head-camera frame: each row exposed at its own time (rolling shutter), with the
    /// robot's sensor readings.
    fn robot_frame(
        &self,
        at: &FrameAt<'_>,
        observer_id: u32,
        rng: &mut SimRng,
    ) -> Result<SimFrame, SimError> {
        let (t, scene, world) = (at.t, at.scene, at.world);
        let name = self.scenario.kind.name();
        let missing = |time_s| SimError::MissingObserver {
            scenario: name,
            id: observer_id,
            time_s,
        };
        let (robot, body, joints) = self.scenario.observer_at(t).ok_or_else(|| missing(t))?;
        let dims = Ers7Dimensions::ERS7;
        let mid: Transform<_, _> = body.field_from_body(&robot) * dims.body_from_camera(&joints);
        let height = self.head_camera.height_px;
        let readout = self.effects.readout_s;
        let row_pose = |row: usize| {
            let tr = t + ((row as f64 + 0.5) / height as f64 - 0.5) * readout;
            match self.scenario.observer_at(tr) {
                Some((r, b, j)) if readout > 0.0 => {
                    (b.field_from_body(&r) * dims.body_from_camera(&j)).isometry
                }
                _ => mid.isometry,
            }
        };
        let skip = render::object_id::ROBOT + u16::try_from(observer_id).unwrap_or(0).min(899);
        let moves = self.scenario.ball_moves_during_readout() && readout > 0.0;
        let ball_at_row = |row: usize| {
            if !moves {
                return None;
            }
            let tr = t + ((row as f64 + 0.5) / height as f64 - 0.5) * readout;
            self.scenario
                .scene_at(tr)
                .ball
                .map(|b| nalgebra::Vector3::new(b.x_cm, b.y_cm, b.radius_cm))
        };
        let out = self
            .renderer
            .render_moving_ball(world, &row_pose, &ball_at_row, &self.effects, skip, rng)
            .map_err(self.frame_error())?;
        let pose = CameraPose {
            camera: self.head_camera,
            field_from_camera: mid,
        };
        let sensors = self.robot_sensors(t, &body, &joints, &mid, world, skip);
        let mut truth = truth::robot_view_truth(
            scene,
            t,
            observer_id,
            robot,
            body,
            joints,
            &pose,
            sensors,
            &out.objects,
            &out.labels,
        );
        if let (Some(b), Some(v)) = (truth.ball.as_mut(), self.scenario.ball_velocity_cm_s(t)) {
            truth::add_ball_velocity(b, v, &robot, &pose);
        }
        Ok(SimFrame {
            time_ns: at.time_ns,
            frame: out.frame,
            labels: out.labels,
            sensors: Some(sensors),
            ground_truth: GroundTruth::Robot(Box::new(truth)),
            extra: Vec::new(),
        })
    }

    /// What the observing robot's sensors read at `t` (seconds): joints and body, the head's
    /// previous angles and pan duty, and the far infra-red distance along the optical axis of
    /// the camera pose `mid` (the middle of the readout), leaving out the robot itself (`skip`).
    fn robot_sensors(
        &self,
        t: f64,
        body: &BodyPose,
        joints: &HeadJoints,
        mid: &Transform<Field, Camera>,
        world: &World,
        skip: u16,
    ) -> SensorReadings {
        let mut sensors = SensorReadings::default();
        joints.write_to(&mut sensors);
        body.write_to(&mut sensors);
        let before = self.scenario.observer_at(t - FRAME_INTERVAL_S).map(|o| o.2);
        sensors.previous_head_pan_rad = before.map(|j| j.pan_rad);
        sensors.previous_head_tilt_rad = before.map(|j| j.tilt1_rad);
        sensors.frame_interval_s = Some(FRAME_INTERVAL_S);
        if let Some(v) = sensors.pan_velocity_rad_per_s() {
            // Duty grows with speed; the ERS-7's pan saturates around 8 rad/s.
            sensors.pan_pwm = Some((v / 8.0).clamp(-1.0, 1.0));
        }
        // The head's far infra-red sensor looks along the optical axis (10–150 cm).
        let axis = *mid * Vector::<crate::geometry::Camera>::new(1.0, 0.0, 0.0);
        let d = world.distance_along(&mid.origin(), &axis, skip);
        sensors.ir_far_cm = (10.0..=150.0).contains(&d).then_some(d);
        sensors
    }
}

/// The instant of one frame and the world then, shared by the frame's parts.
struct FrameAt<'a> {
    /// Frame index.
    index: u64,
    /// Time, seconds since the scenario start.
    t: f64,
    /// The same, nanoseconds.
    time_ns: u64,
    scene: &'a Scene,
    world: &'a World,
}
