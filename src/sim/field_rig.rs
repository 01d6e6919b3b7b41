//! A Small Size League style rig: N overhead cameras over one field, each over its own tile with
//! overlapping edges, each with its own pose, lens and resolution (up to 1920×1200), delivering
//! 75 frames a second without synchronisation.
//!
//! The world is the overhead game's ([`super::Scenario`]); each camera's frame `k` is rendered at
//! its own time `k / 75 s + offset` (the offset under half a frame period, so the reference
//! camera's frame and the others' nearest ones form one field frame), with the truth as that
//! camera sees it.

use nalgebra::{UnitQuaternion, Vector3};

use super::render::Renderer;
use super::{CameraEffects, Scenario, SimError, SimFrame, SimRng, World, truth};
use crate::geometry::{Camera, Field, OverheadCamera, PoseRecord, Transform};
use crate::model::GroundTruth;

/// Frames a second of each rig camera (ssl-vision's cameras: 75).
pub const RIG_FPS: f64 = 75.0;

/// Largest frame of a rig camera, pixels.
pub const MAX_RIG_SIZE: (usize, usize) = (1920, 1200);

/// Most cameras in a rig.
pub const MAX_RIG_CAMERAS: usize = 16;

/// How far each camera's view reaches past its tile on every side, centimetres: a marker plate
/// (30 cm) in the overlap is seen whole by both neighbours.
pub const OVERLAP_CM: f64 = 35.0;

/// Height of the marker plates the tiles are planned for, centimetres.
const PLAN_HEIGHT_CM: f64 = 25.0;

/// One camera of the rig.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RigCamera {
    /// The true camera.
    pub camera: OverheadCamera,
    /// When its frames are taken after the reference camera's, nanoseconds (< half a period).
    pub offset_ns: u64,
    /// The field tile it is centred over, `[min_x, min_y, max_x, max_y]` centimetres.
    pub tile_cm: [f64; 4],
}

/// N cameras over the overhead game's field.
#[derive(Debug, Clone)]
pub struct FieldRig {
    scenario: Scenario,
    cameras: Vec<RigCamera>,
    effects: CameraEffects,
}

/// Columns and rows of the tiles for `n` cameras: one row up to three cameras, two beyond.
#[must_use]
pub fn grid(n: usize) -> (usize, usize) {
    let rows = if n >= 4 { 2 } else { 1 };
    (n.div_ceil(rows), rows)
}

impl FieldRig {
    /// A rig of `count` cameras (1–[`MAX_RIG_CAMERAS`]) of `width`×`height` pixels over the
    /// overhead game of `seed`; poses, lenses and clock offsets vary with the seed.
    ///
    /// # Panics
    /// Never: sizes and counts are clamped to their ranges.
    #[must_use]
    pub fn new(seed: u64, count: usize, width: usize, height: usize) -> Self {
        let count = count.clamp(1, MAX_RIG_CAMERAS);
        let (width, height) = (
            width.clamp(64, MAX_RIG_SIZE.0),
            height.clamp(48, MAX_RIG_SIZE.1),
        );
        let scenario = Scenario::new(super::ScenarioKind::OverheadGame, seed);
        let spec = crate::model::scene::FieldSpec::default();
        // The tiles cover the field and a little of its border.
        let half = [spec.length_cm / 2.0 + 10.0, spec.width_cm / 2.0 + 10.0];
        let (cols, rows) = grid(count);
        let (tw, th) = (2.0 * half[0] / cols as f64, 2.0 * half[1] / rows as f64);
        let cameras = (0..count)
            .map(|k| {
                let (c, r) = (k % cols, k / cols);
                let tile = [
                    -half[0] + c as f64 * tw,
                    -half[1] + r as f64 * th,
                    -half[0] + (c + 1) as f64 * tw,
                    -half[1] + (r + 1) as f64 * th,
                ];
                rig_camera(seed, k, tile, width, height)
            })
            .collect();
        Self {
            scenario,
            cameras,
            effects: CameraEffects::OVERHEAD,
        }
    }

    /// The same rig with other camera effects ([`CameraEffects::NONE`]: ideal frames).
    #[must_use]
    pub fn with_effects(mut self, effects: CameraEffects) -> Self {
        self.effects = effects;
        self
    }

    /// The cameras, the reference first.
    #[must_use]
    pub fn cameras(&self) -> &[RigCamera] {
        &self.cameras
    }

    /// The scenario filmed.
    #[must_use]
    pub fn scenario(&self) -> &Scenario {
        &self.scenario
    }

    /// The renderer of camera `k` (its rays: build once per camera, it is large).
    #[must_use]
    pub fn renderer(&self, k: usize) -> Option<Renderer> {
        self.cameras.get(k).map(|c| Renderer::overhead(&c.camera))
    }

    /// Camera `k`'s frame `index`, rendered by `renderer` (from [`Self::renderer`]).
    ///
    /// # Errors
    /// [`SimError`] when the frame cannot be assembled; `k` out of range is
    /// [`SimError::MissingObserver`] naming the camera.
    pub fn frame(&self, renderer: &Renderer, k: usize, index: u64) -> Result<SimFrame, SimError> {
        let name = self.scenario.kind.name();
        let Some(cam) = self.cameras.get(k) else {
            return Err(SimError::MissingObserver {
                scenario: name,
                id: u32::try_from(k).unwrap_or(u32::MAX),
                time_s: 0.0,
            });
        };
        let period_ns = (1e9 / RIG_FPS).round() as u64;
        let time_ns = index * period_ns + cam.offset_ns;
        let t = time_ns as f64 * 1e-9;
        let scene = self.scenario.scene_at(t);
        let world = World::compile(&scene);
        let mut rng = SimRng::derived(self.scenario.seed ^ (0x5EED_CA00 + k as u64), index);
        let pose = cam.camera.field_from_camera().isometry;
        let out = renderer
            .render(&world, &|_| pose, &self.effects, u16::MAX, &mut rng)
            .map_err(|source| SimError::Frame {
                scenario: name,
                source,
            })?;
        let truth = truth::overhead_truth(&scene, t, &cam.camera, &out.objects);
        Ok(SimFrame {
            time_ns,
            frame: out.frame,
            labels: out.labels,
            sensors: None,
            ground_truth: GroundTruth::Overhead(Box::new(truth)),
            extra: Vec::new(),
        })
    }
}

/// Camera `k` over `tile`: 360–420 cm up, its long image side along the tile's long side, the
/// focal length chosen so that the tile grown by [`OVERLAP_CM`] fills the image at plate height,
/// with a lens (k1, k2), principal point, tilt and clock offset of its own.
fn rig_camera(seed: u64, k: usize, tile: [f64; 4], width: usize, height: usize) -> RigCamera {
    let mut rng = SimRng::derived(seed, 0x0516_CA00 + k as u64);
    let height_cm = rng.range(360.0, 420.0);
    let (k1, k2) = (rng.range(-0.2, -0.12), rng.range(0.01, 0.04));
    let (tw, th) = (tile[2] - tile[0], tile[3] - tile[1]);
    // Long image side along the tile's long side.
    let turned = (tw >= th) != (width >= height);
    let (along_x, along_y) = if turned { (th, tw) } else { (tw, th) };
    let depth = height_cm - PLAN_HEIGHT_CM;
    let fx = width as f64 / 2.0 / ((along_x / 2.0 + OVERLAP_CM) / depth);
    let fy = height as f64 / 2.0 / ((along_y / 2.0 + OVERLAP_CM) / depth);
    let focal = fx.min(fy) * rng.range(0.97, 1.0);
    let mut camera = OverheadCamera::looking_down(width, height, height_cm, focal, k1, k2);
    let s = width as f64 / 640.0;
    camera.centre.x_px += s * rng.range(-6.0, 6.0);
    camera.centre.y_px += s * rng.range(-5.0, 5.0);
    let centre = [
        (tile[0] + tile[2]) / 2.0 + rng.range(-5.0, 5.0),
        (tile[1] + tile[3]) / 2.0 + rng.range(-5.0, 5.0),
    ];
    let yaw = if turned {
        std::f64::consts::FRAC_PI_2
    } else {
        0.0
    } + rng.range(-0.03, 0.03);
    let tilt =
        UnitQuaternion::from_euler_angles(rng.range(-0.02, 0.02), rng.range(-0.02, 0.02), yaw);
    let t: Transform<Field, Camera> = camera.field_from_camera();
    let placed: Transform<Field, Camera> = Transform::new(
        Vector3::new(centre[0], centre[1], height_cm),
        tilt * t.rotation(),
    );
    camera.pose = PoseRecord::from_transform(&placed);
    let half_period_ns = 0.5e9 / RIG_FPS;
    let offset_ns = if k == 0 {
        0
    } else {
        (rng.range(0.0, 0.8) * half_period_ns) as u64
    };
    RigCamera {
        camera,
        offset_ns,
        tile_cm: tile,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Point;

    fn sees(c: &OverheadCamera, x: f64, y: f64, z: f64) -> bool {
        c.image_from_field(&Point::new(x, y, z)).is_some_and(|p| {
            p.x_px >= 0.0
                && p.y_px >= 0.0
                && p.x_px < c.width_px as f64
                && p.y_px < c.height_px as f64
        })
    }

    #[test]
    fn every_point_of_the_field_is_seen_by_a_camera_and_overlaps_by_two() {
        for n in [1, 2, 4, 8] {
            let rig = FieldRig::new(3, n, 1920, 1200);
            assert_eq!(rig.cameras().len(), n);
            let mut twice = 0;
            for i in -26..=26 {
                for j in -17..=17 {
                    let (x, y) = (f64::from(i) * 10.0, f64::from(j) * 10.0);
                    let seen = rig
                        .cameras()
                        .iter()
                        .filter(|c| sees(&c.camera, x, y, 22.5))
                        .count();
                    assert!(seen >= 1, "{n} cameras: ({x}, {y}) unseen");
                    twice += usize::from(seen >= 2);
                }
            }
            assert_eq!(twice > 0, n > 1, "{n} cameras: overlap {twice}");
        }
    }

    #[test]
    fn cameras_differ_in_pose_lens_and_clock_within_half_a_period() {
        let rig = FieldRig::new(5, 8, 1920, 1200);
        let c = rig.cameras();
        assert_eq!(c[0].offset_ns, 0);
        for pair in c.windows(2) {
            assert_ne!(pair[0].camera.k1, pair[1].camera.k1);
            assert_ne!(
                pair[0].camera.pose.position_cm,
                pair[1].camera.pose.position_cm
            );
        }
        let half = (0.5e9 / RIG_FPS) as u64;
        assert!(c.iter().all(|r| r.offset_ns < half));
        assert!(c.iter().any(|r| r.offset_ns > 0));
    }

    #[test]
    fn a_small_rig_frame_has_the_robots_in_its_truth() {
        let rig = FieldRig::new(7, 2, 320, 200).with_effects(CameraEffects::NONE);
        let renderer = rig.renderer(1).expect("camera 1");
        let f = rig.frame(&renderer, 1, 3).expect("frame");
        assert_eq!((f.frame.width(), f.frame.height()), (320, 200));
        assert_eq!(f.time_ns, 3 * 13_333_333 + rig.cameras()[1].offset_ns);
        let GroundTruth::Overhead(t) = &f.ground_truth else {
            panic!("overhead truth expected");
        };
        assert_eq!(t.camera, rig.cameras()[1].camera);
        assert!(rig.frame(&renderer, 9, 0).is_err());
    }
}
