//! The renderer: one ray per pixel against a handful of simple shapes, shaded, then turned into
//! a UYVY frame the way a camera would deliver it.
//!
//! [`World::compile`] turns a [`Scene`](super::Scene) into primitives (spheres, vertical cylinders, boxes
//! turned about the vertical or tilted with a robot's body) grouped into objects with bounding
//! spheres; the ground plane (carpet, lines, floor) and the room's walls and ceiling are
//! analytic. A [`Renderer`] holds the camera-frame ray of every pixel (computed once per camera,
//! undistorted for the overhead lens) and renders a frame from a camera pose *per row*, which is
//! how the rolling shutter comes in: row r is exposed at its own time, while the head moves.
//!
//! Per pixel: nearest hit → material colour × (ambient + direct·cos, unless in shadow) ×
//! exposure × tint → BT.601 studio-range YUV → vignetting (darker, bluer corners) → sensor
//! noise → the two pixels of a pair share the mean of their chroma (UYVY). Besides the frame it
//! returns each pixel's true colour class (for training and scoring tables) and the object it
//! shows (for ground truth: visible fractions, image boxes).
//!
//! | file | role |
//! |---|---|
//! | `mod.rs` | [`Renderer`]: the pixel rays, a frame row by row, YUV, vignetting, noise, UYVY |
//! | `world.rs` | [`World`]: the scene compiled; what a ray sees, lit or in shadow |
//! | `shapes.rs` | the scene's things as primitives with paint; ray–primitive intersection |

mod shapes;
mod world;

pub use world::World;

use nalgebra::{Isometry3, Vector3};

use super::effects::CameraEffects;
use super::rng::SimRng;
use crate::frame::{Frame, FrameError};
use crate::geometry::{OverheadCamera, PinholeCamera};
use crate::model::scene::Material;

/// Object identities in [`Rendered::objects`]: what each pixel shows.
pub mod object_id {
    /// Ground, lines, floor, walls, ceiling.
    pub const BACKGROUND: u16 = 0;
    /// The ball.
    pub const BALL: u16 = 1;
    /// The yellow goal.
    pub const YELLOW_GOAL: u16 = 2;
    /// The sky-blue goal.
    pub const SKY_BLUE_GOAL: u16 = 3;
    /// Beacon `i` of the scene is `BEACON + i`.
    pub const BEACON: u16 = 10;
    /// The robot with id `n` is `ROBOT + n`.
    pub const ROBOT: u16 = 100;
    /// Clutter item `i` of the scene is `CLUTTER + i`.
    pub const CLUTTER: u16 = 1000;
    /// The overhead marker plate of the robot with id `n` is `ROBOT_MARKER + n`.
    pub const ROBOT_MARKER: u16 = 61_000;
    /// The eight outer tiles and the post of coloured-pattern marker `i` are `MARKER + i`.
    pub const MARKER: u16 = 62_000;
    /// The pink middle tile of marker `i` is `MARKER_PINK + i`.
    pub const MARKER_PINK: u16 = 63_000;
}

/// A rendered image with its per-pixel ground truth.
#[derive(Debug, Clone)]
pub struct Rendered {
    /// The camera frame, UYVY.
    pub frame: Frame,
    /// The true colour class code of each pixel, row-major (`FORMATS.md` codes).
    pub labels: Vec<u8>,
    /// The object each pixel shows, row-major ([`object_id`]).
    pub objects: Vec<u16>,
}

/// A camera's pixel rays, computed once, and the frame-making machinery.
#[derive(Debug, Clone)]
pub struct Renderer {
    width: usize,
    height: usize,
    /// Unit ray per pixel in the camera frame; `None` where the lens model has no ray.
    rays: Vec<Option<Vector3<f64>>>,
}

impl Renderer {
    /// For a pinhole camera such as the ERS-7's.
    #[must_use]
    pub fn pinhole(camera: &PinholeCamera) -> Self {
        let mut rays = Vec::with_capacity(camera.width_px * camera.height_px);
        for j in 0..camera.height_px {
            for i in 0..camera.width_px {
                let r = camera.unit_ray(crate::geometry::ImagePoint::pixel_centre(i, j));
                rays.push(Some(r.coords));
            }
        }
        Self {
            width: camera.width_px,
            height: camera.height_px,
            rays,
        }
    }

    /// For a distorted overhead camera.
    #[must_use]
    pub fn overhead(camera: &OverheadCamera) -> Self {
        let mut rays = Vec::with_capacity(camera.width_px * camera.height_px);
        for j in 0..camera.height_px {
            for i in 0..camera.width_px {
                let r = camera.camera_ray(crate::geometry::ImagePoint::pixel_centre(i, j));
                rays.push(r.map(|v| v.coords));
            }
        }
        Self {
            width: camera.width_px,
            height: camera.height_px,
            rays,
        }
    }

    /// Image width × height, pixels.
    #[must_use]
    pub fn size(&self) -> (usize, usize) {
        (self.width, self.height)
    }

    /// Renders a frame. `field_from_camera_at_row(r)` gives the camera pose while row `r` is
    /// exposed (the same pose for every row without a rolling shutter); `skip` leaves one object
    /// out (the observing robot's own body); `rng` draws the sensor noise.
    ///
    /// # Errors
    /// [`FrameError`] only for an odd width (UYVY needs pixel pairs).
    pub fn render(
        &self,
        world: &World,
        field_from_camera_at_row: &dyn Fn(usize) -> Isometry3<f64>,
        effects: &CameraEffects,
        skip: u16,
        rng: &mut SimRng,
    ) -> Result<Rendered, FrameError> {
        self.render_moving_ball(
            world,
            field_from_camera_at_row,
            &|_| None,
            effects,
            skip,
            rng,
        )
    }

    /// [`Self::render`] with the ball's own motion during read-out: `ball_centre_at_row(r)`
    /// gives the ball's centre (field cm) while row `r` is exposed, `None` to leave it where
    /// `world` has it. A ball rolling across the view comes out sheared, as a real rolling
    /// shutter shows it.
    ///
    /// # Errors
    /// [`FrameError`] only for an odd width (UYVY needs pixel pairs).
    pub fn render_moving_ball(
        &self,
        world: &World,
        field_from_camera_at_row: &dyn Fn(usize) -> Isometry3<f64>,
        ball_centre_at_row: &dyn Fn(usize) -> Option<Vector3<f64>>,
        effects: &CameraEffects,
        skip: u16,
        rng: &mut SimRng,
    ) -> Result<Rendered, FrameError> {
        let mut moving: Option<World> = None;
        let (w, h) = (self.width, self.height);
        if !w.is_multiple_of(2) {
            return Err(FrameError::OddWidth { width: w });
        }
        let mut data = Vec::with_capacity(w * h * 2);
        let mut labels = Vec::with_capacity(w * h);
        let mut objects = Vec::with_capacity(w * h);
        let (cx, cy) = (w as f64 / 2.0, h as f64 / 2.0);
        let corner2 = cx * cx + cy * cy;
        let mut row_yuv = vec![[0.0_f64; 3]; w];
        for j in 0..h {
            if let Some(c) = ball_centre_at_row(j) {
                moving.get_or_insert_with(|| world.clone()).move_ball(c);
            }
            let world = moving.as_ref().unwrap_or(world);
            let pose = field_from_camera_at_row(j);
            let rot = pose.rotation.to_rotation_matrix().into_inner();
            let origin = pose.translation.vector;
            for (i, out) in row_yuv.iter_mut().enumerate() {
                let (colour, material, object) = match self.rays.get(j * w + i).copied().flatten() {
                    Some(ray) => world.trace(&origin, &(rot * ray), skip),
                    None => (Vector3::zeros(), Material::Ceiling, object_id::BACKGROUND),
                };
                labels.push(material.class().code());
                objects.push(object);
                let [r, g, b] = [colour.x, colour.y, colour.z];
                let mut y = 16.0 + (65.481 * r + 128.553 * g + 24.966 * b) / 255.0;
                let mut u = 128.0 + (-37.797 * r - 74.203 * g + 112.0 * b) / 255.0;
                let v = 128.0 + (112.0 * r - 93.786 * g - 18.214 * b) / 255.0;
                let (dx, dy) = (i as f64 + 0.5 - cx, j as f64 + 0.5 - cy);
                let rr = (dx * dx + dy * dy) / corner2;
                y = 16.0 + (y - 16.0) * (1.0 - effects.vignetting * rr);
                u += effects.corner_blue_u * rr;
                *out = [y, u, v];
            }
            for pair in row_yuv.chunks_exact(2) {
                let (a, b) = (pair[0], pair[1]);
                let nu = effects.noise_uv * f64::from(rng.fast_normal());
                let nv = effects.noise_uv * f64::from(rng.fast_normal());
                let y0 = a[0] + effects.noise_y * f64::from(rng.fast_normal());
                let y1 = b[0] + effects.noise_y * f64::from(rng.fast_normal());
                data.push(crate::frame::round_u8((a[1] + b[1]) / 2.0 + nu));
                data.push(crate::frame::round_u8(y0));
                data.push(crate::frame::round_u8((a[2] + b[2]) / 2.0 + nv));
                data.push(crate::frame::round_u8(y1));
            }
        }
        Ok(Rendered {
            frame: Frame::from_uyvy(w, h, data)?,
            labels,
            objects,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{BodyPose, Ers7Dimensions, HeadJoints, RobotPose, Transform};
    use crate::lut::ColourClass;
    use crate::model::scene::Ball;
    use crate::model::scene::Scene;

    fn robot_camera_pose(robot: RobotPose, joints: HeadJoints) -> Isometry3<f64> {
        let t: Transform<crate::geometry::Field, crate::geometry::Camera> = BodyPose::ERS7_STANCE
            .field_from_body(&robot)
            * Ers7Dimensions::ERS7.body_from_camera(&joints);
        t.isometry
    }

    #[test]
    fn ball_ahead_appears_orange_at_the_image_centre() {
        let mut scene = Scene::four_legged_2005();
        scene.ball = Some(Ball::at(60.0, 0.0));
        let world = World::compile(&scene);
        let camera = PinholeCamera::ers7();
        let renderer = Renderer::pinhole(&camera);
        // Aim the camera at the ball: camera ~20 cm up, ball centre 4.25 cm up, ~45 cm ahead.
        let joints = HeadJoints {
            tilt1_rad: -0.25,
            pan_rad: 0.0,
            tilt2_rad: -0.1,
        };
        let pose = robot_camera_pose(RobotPose::default(), joints);
        let out = renderer
            .render(
                &world,
                &|_| pose,
                &CameraEffects::NONE,
                0,
                &mut SimRng::new(1),
            )
            .expect("render");
        let orange = out
            .labels
            .iter()
            .filter(|&&c| c == ColourClass::Orange.code())
            .count();
        assert!(orange > 100, "{orange} orange pixels");
        let ball_px = out
            .objects
            .iter()
            .filter(|&&o| o == object_id::BALL)
            .count();
        assert_eq!(ball_px, orange);
        // The carpet fills most of the rest.
        let green = out
            .labels
            .iter()
            .filter(|&&c| c == ColourClass::Green.code())
            .count();
        assert!(green > 208 * 160 / 3, "{green}");
        // Orange pixels look orange: V high, U low.
        let ball: Vec<usize> = out
            .objects
            .iter()
            .enumerate()
            .filter(|(_, o)| **o == object_id::BALL)
            .map(|(k, _)| k)
            .collect();
        let p = ball[ball.len() / 2];
        let yuv = out.frame.pixel(p % 208, p / 208).expect("in image");
        assert!(yuv.v > 150 && yuv.u < 110 && yuv.v > yuv.u + 40, "{yuv:?}");
    }

    #[test]
    fn a_ball_moving_during_readout_comes_out_sheared() {
        let mut scene = Scene::four_legged_2005();
        scene.ball = Some(Ball::at(60.0, 0.0));
        let world = World::compile(&scene);
        let renderer = Renderer::pinhole(&PinholeCamera::ers7());
        let joints = HeadJoints {
            tilt1_rad: -0.25,
            pan_rad: 0.0,
            tilt2_rad: -0.1,
        };
        let pose = robot_camera_pose(RobotPose::default(), joints);
        let render = |ball_at: &dyn Fn(usize) -> Option<Vector3<f64>>| {
            renderer
                .render_moving_ball(
                    &world,
                    &|_| pose,
                    ball_at,
                    &CameraEffects::NONE,
                    0,
                    &mut SimRng::new(1),
                )
                .expect("render")
        };
        // Leftmost ball column of each row that shows the ball.
        let left_edges = |objects: &[u16]| -> Vec<(usize, usize)> {
            (0..160)
                .filter_map(|y| {
                    (0..208)
                        .find(|&x| objects[y * 208 + x] == object_id::BALL)
                        .map(|x| (y, x))
                })
                .collect()
        };
        let still = render(&|_| None);
        assert_eq!(
            still.objects,
            render(&|_| Some(Vector3::new(60.0, 0.0, 4.25))).objects
        );
        // The ball rolls to the right (−y) by 0.1 cm per row read.
        let moving = render(&|row| Some(Vector3::new(60.0, -0.1 * (row as f64 - 80.0), 4.25)));
        let (a, b) = (left_edges(&still.objects), left_edges(&moving.objects));
        let (top_a, bottom_a) = (a[0].1, a[a.len() - 1].1);
        let (top_b, bottom_b) = (b[0].1, b[b.len() - 1].1);
        // Rows read later see it further right: the left edge leans.
        let lean_still = bottom_a as i64 - top_a as i64;
        let lean_moving = bottom_b as i64 - top_b as i64;
        assert!(
            lean_moving >= lean_still + 4,
            "{lean_still} vs {lean_moving}"
        );
    }

    #[test]
    fn rendering_is_deterministic_for_a_seed() {
        let world = World::compile(&Scene::four_legged_2005());
        let renderer = Renderer::pinhole(&PinholeCamera::ers7());
        let pose = robot_camera_pose(RobotPose::new(-100.0, 0.0, 0.0), HeadJoints::default());
        let render = |seed| {
            renderer
                .render(
                    &world,
                    &|_| pose,
                    &CameraEffects::ERS7,
                    0,
                    &mut SimRng::new(seed),
                )
                .expect("render")
        };
        let (a, b, c) = (render(5), render(5), render(6));
        assert_eq!(a.frame, b.frame);
        assert_ne!(a.frame, c.frame);
        assert_eq!(a.labels, c.labels);
    }

    #[test]
    fn ground_paint_follows_the_field_lines() {
        let world = World::compile(&Scene::four_legged_2005());
        assert_eq!(world.ground_material(0.0, 100.0), Material::Line);
        assert_eq!(world.ground_material(50.0, 100.0), Material::Carpet);
        assert_eq!(world.ground_material(18.0, 0.0), Material::Line);
        assert_eq!(world.ground_material(269.0, 10.0), Material::Line);
        assert_eq!(world.ground_material(100.0, 179.0), Material::Line);
        assert_eq!(world.ground_material(100.0, 190.0), Material::Carpet);
        assert_eq!(world.ground_material(320.0, 0.0), Material::Floor);
    }

    #[test]
    fn overhead_sees_the_whole_carpet() {
        let camera = OverheadCamera::above_field_2005();
        let renderer = Renderer::overhead(&camera);
        let world = World::compile(&Scene::four_legged_2005());
        let pose = camera.field_from_camera().isometry;
        let out = renderer
            .render(
                &world,
                &|_| pose,
                &CameraEffects::NONE,
                0,
                &mut SimRng::new(1),
            )
            .expect("render");
        assert_eq!(out.frame.width(), 640);
        let green = out
            .labels
            .iter()
            .filter(|&&c| c == ColourClass::Green.code())
            .count();
        assert!(green > 640 * 480 / 2, "{green}");
        // The ball at the centre spot is at the image centre.
        assert_eq!(out.objects[240 * 640 + 320], object_id::BALL);
        // Both goals appear.
        assert!(out.objects.contains(&object_id::YELLOW_GOAL));
        assert!(out.objects.contains(&object_id::SKY_BLUE_GOAL));
    }
}
