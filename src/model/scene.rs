//! The world described: the field, its landmarks, the ball, robots, clutter and the light (what
//! the simulator renders, what the overhead recogniser measures the field by).
//!
//! A [`Scene`] is plain serde data (JSON in streams and files), in field coordinates
//! (`FORMATS.md`: centimetres, origin at the centre spot, x towards the yellow goal, y left, z
//! up; headings in radians counter-clockwise from +x). [`Scene::four_legged_2005`] builds the
//! 2005 RoboCup Four-Legged League field as we read its rules:
//!
//! - carpet 600 × 400 cm; white lines 2.5 cm wide bounding a 540 × 360 cm playing area; centre
//!   line and a centre circle of 18 cm radius; penalty areas 130 cm wide and 65 cm deep;
//! - goals 80 cm wide (inside), 30 cm high and 30 cm deep, behind the goal lines, yellow at
//!   +x and sky blue at −x, with coloured back and side walls;
//! - four beacons, cylinders 10 cm across and 40 cm high standing 15 cm outside the side lines
//!   at x = ±135 cm: a white lower half and two 10 cm coloured bands above it. On the yellow
//!   half, the left beacon (+y) has pink over yellow and the right one yellow over pink; on the
//!   sky-blue half the left one has sky blue over pink and the right one pink over sky blue;
//! - the ball: 8.5 cm across, orange.
//!
//! Every figure is a field of [`FieldSpec`] or [`Beacon`], so a different year's field is a
//! different JSON file, not a code change. Around the carpet the renderer puts a grey floor and
//! the walls of a room ([`RoomSpec`]) where clutter stands: people, furniture, orange and yellow
//! things that classify as ball and goal colours but lie off the field.

use serde::{Deserialize, Serialize};

use crate::geometry::{BodyPose, HeadJoints, RobotMarker, RobotPose};
use crate::lut::ColourClass;

/// A surface's paint: its colour under full light and the colour class it should classify as.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Material {
    /// Field carpet (green).
    Carpet,
    /// Field lines (white).
    Line,
    /// The ball (orange).
    BallOrange,
    /// Yellow goal and beacon bands.
    Yellow,
    /// Sky-blue goal and beacon bands.
    SkyBlue,
    /// Pink beacon bands.
    Pink,
    /// White beacon base, robot shells.
    White,
    /// Robot joints, faces and paws (black).
    RobotBlack,
    /// Red team uniform.
    UniformRed,
    /// Dark-blue team uniform.
    UniformDarkBlue,
    /// The room's floor around the carpet (grey-brown; no class).
    Floor,
    /// The room's walls (off-white; no class).
    Wall,
    /// The room's ceiling (dark grey; no class).
    Ceiling,
    /// Off-field orange things (a chair, a bag): classify orange, are not balls.
    ClutterOrange,
    /// Off-field yellow things (a jacket, a box): classify yellow, are not goals.
    ClutterYellow,
    /// People's skin (no class).
    Skin,
    /// Dark clothing (no class).
    Cloth,
    /// Furniture wood (no class).
    Wood,
}

impl Material {
    /// The colour under full light, sRGB 0..=255.
    #[must_use]
    pub const fn rgb(self) -> [u8; 3] {
        match self {
            Self::Carpet => [50, 140, 62],
            Self::Line => [236, 236, 232],
            Self::BallOrange => [255, 112, 24],
            Self::Yellow => [238, 208, 32],
            Self::SkyBlue => [62, 160, 226],
            Self::Pink => [240, 92, 170],
            Self::White => [222, 222, 226],
            Self::RobotBlack => [34, 34, 40],
            Self::UniformRed => [196, 24, 36],
            Self::UniformDarkBlue => [26, 36, 128],
            Self::Floor => [112, 100, 88],
            Self::Wall => [186, 176, 156],
            Self::Ceiling => [78, 78, 84],
            Self::ClutterOrange => [248, 118, 30],
            Self::ClutterYellow => [232, 200, 44],
            Self::Skin => [204, 150, 118],
            Self::Cloth => [70, 74, 92],
            Self::Wood => [140, 96, 56],
        }
    }

    /// The colour class a good lookup table gives this surface (ground-truth labels).
    #[must_use]
    pub const fn class(self) -> ColourClass {
        match self {
            Self::Carpet => ColourClass::Green,
            Self::Line | Self::White => ColourClass::White,
            Self::BallOrange | Self::ClutterOrange => ColourClass::Orange,
            Self::Yellow | Self::ClutterYellow => ColourClass::Yellow,
            Self::SkyBlue => ColourClass::SkyBlue,
            Self::Pink => ColourClass::Pink,
            Self::RobotBlack => ColourClass::Black,
            Self::UniformRed => ColourClass::Red,
            Self::UniformDarkBlue => ColourClass::DarkBlue,
            Self::Floor | Self::Wall | Self::Ceiling | Self::Skin | Self::Cloth | Self::Wood => {
                ColourClass::Unclassified
            }
        }
    }
}

/// The field's dimensions, centimetres.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct FieldSpec {
    /// Length of the playing area between the goal lines' outer edges, centimetres.
    pub length_cm: f64,
    /// Width of the playing area between the side lines' outer edges, centimetres.
    pub width_cm: f64,
    /// Carpet beyond the lines on every side, centimetres.
    pub carpet_margin_cm: f64,
    /// Line width, centimetres.
    pub line_width_cm: f64,
    /// Centre circle radius (to the line's centre), centimetres.
    pub centre_circle_radius_cm: f64,
    /// Penalty area width along the goal line, centimetres.
    pub penalty_area_width_cm: f64,
    /// Penalty area depth into the field, centimetres.
    pub penalty_area_depth_cm: f64,
    /// Goal mouth width between the posts' inner faces, centimetres.
    pub goal_width_cm: f64,
    /// Goal height, centimetres.
    pub goal_height_cm: f64,
    /// Goal depth behind the goal line, centimetres.
    pub goal_depth_cm: f64,
    /// Thickness of the goal's walls, centimetres.
    pub goal_wall_cm: f64,
}

impl Default for FieldSpec {
    fn default() -> Self {
        Self {
            length_cm: 540.0,
            width_cm: 360.0,
            carpet_margin_cm: 30.0,
            line_width_cm: 2.5,
            centre_circle_radius_cm: 18.0,
            penalty_area_width_cm: 130.0,
            penalty_area_depth_cm: 65.0,
            goal_width_cm: 80.0,
            goal_height_cm: 30.0,
            goal_depth_cm: 30.0,
            goal_wall_cm: 2.0,
        }
    }
}

impl FieldSpec {
    /// Half the carpet's length (x), centimetres.
    #[must_use]
    pub fn carpet_half_length_cm(&self) -> f64 {
        self.length_cm / 2.0 + self.carpet_margin_cm
    }

    /// Half the carpet's width (y), centimetres.
    #[must_use]
    pub fn carpet_half_width_cm(&self) -> f64 {
        self.width_cm / 2.0 + self.carpet_margin_cm
    }

    /// x of the goal line's centre at the yellow goal (the −x goal mirrors it), centimetres.
    #[must_use]
    pub fn goal_line_x_cm(&self) -> f64 {
        (self.length_cm - self.line_width_cm) / 2.0
    }
}

/// The room around the field, centimetres from the centre spot.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct RoomSpec {
    /// Distance of the end walls (x), centimetres.
    pub half_length_cm: f64,
    /// Distance of the side walls (y), centimetres.
    pub half_width_cm: f64,
    /// Ceiling height, centimetres.
    pub height_cm: f64,
}

impl Default for RoomSpec {
    fn default() -> Self {
        Self {
            half_length_cm: 480.0,
            half_width_cm: 380.0,
            height_cm: 300.0,
        }
    }
}

/// Which goal colour.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum GoalColour {
    /// The yellow goal at +x.
    Yellow,
    /// The sky-blue goal at −x.
    SkyBlue,
}

/// A landmark beacon: a vertical cylinder with a white base and two coloured bands.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Beacon {
    /// A short name for ground truth, e.g. `"pink_yellow"` (top colour first).
    pub name: String,
    /// Field x of the axis, centimetres.
    pub x_cm: f64,
    /// Field y of the axis, centimetres.
    pub y_cm: f64,
    /// Radius, centimetres.
    pub radius_cm: f64,
    /// Height of the white base, centimetres.
    pub base_height_cm: f64,
    /// Height of each coloured band, centimetres.
    pub band_height_cm: f64,
    /// Upper band.
    pub top: Material,
    /// Lower band.
    pub bottom: Material,
}

impl Beacon {
    /// Total height, centimetres.
    #[must_use]
    pub fn height_cm(&self) -> f64 {
        self.base_height_cm + 2.0 * self.band_height_cm
    }
}

/// A coloured-pattern marker: a flat square panel of 3 × 3 tiles, the middle one pink, on a thin
/// dark post. The eight tiles around the pink one are the place's signature, which the
/// "almost SLAM" recogniser learns and identifies (`recognition::patterns`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Marker {
    /// A short name for ground truth, e.g. `"north_west"`.
    pub name: String,
    /// Field x of the panel's centre (the pink tile's centre), centimetres.
    pub x_cm: f64,
    /// Field y of the panel's centre, centimetres.
    pub y_cm: f64,
    /// Height of the panel's centre above the ground, centimetres.
    pub centre_height_cm: f64,
    /// The direction the painted front faces, radians counter-clockwise from +x.
    pub facing_rad: f64,
    /// Side of one tile, centimetres (the panel is three tiles across).
    pub tile_cm: f64,
    /// The tiles row by row as seen from the front, top-left first; `tiles[4]` is the middle.
    pub tiles: [Material; 9],
}

impl Marker {
    /// The unit vector (field x, y) along the panel to the right of someone facing its front.
    #[must_use]
    pub fn right(&self) -> [f64; 2] {
        let (s, c) = self.facing_rad.sin_cos();
        [-s, c]
    }

    /// Field point (cm) of the panel's face at `(across, up)` tiles from its centre (across
    /// positive to the right seen from the front, up positive upwards).
    #[must_use]
    pub fn face_point(&self, across: f64, up: f64) -> [f64; 3] {
        let r = self.right();
        [
            self.x_cm + r[0] * across * self.tile_cm,
            self.y_cm + r[1] * across * self.tile_cm,
            self.centre_height_cm + up * self.tile_cm,
        ]
    }
}

/// The ball.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Ball {
    /// Field x of the centre, centimetres.
    pub x_cm: f64,
    /// Field y of the centre, centimetres.
    pub y_cm: f64,
    /// Radius, centimetres (4.25 for the 8.5 cm ball).
    pub radius_cm: f64,
}

impl Ball {
    /// The 2005 ball (8.5 cm across) at a field position (cm).
    #[must_use]
    pub const fn at(x_cm: f64, y_cm: f64) -> Self {
        Self {
            x_cm,
            y_cm,
            radius_cm: 4.25,
        }
    }
}

/// A robot's team.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Team {
    /// Red uniform.
    Red,
    /// Dark-blue uniform.
    Blue,
}

impl Team {
    /// The uniform's material.
    #[must_use]
    pub const fn uniform(self) -> Material {
        match self {
            Self::Red => Material::UniformRed,
            Self::Blue => Material::UniformDarkBlue,
        }
    }
}

/// An ERS-7 on the field: white shell, black legs and face, a uniform band round the body.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Robot {
    /// Identity, unique in the scene (1..=8 in the scenarios).
    pub id: u32,
    /// Team and uniform colour.
    pub team: Team,
    /// Where it stands.
    pub pose: RobotPose,
    /// Body height and tilt.
    pub body: BodyPose,
    /// Head joints.
    pub joints: HeadJoints,
    /// The overhead marker on its back, if it wears one (the overhead scenes put one on every
    /// robot).
    #[serde(default)]
    pub marker: Option<RobotMarker>,
}

/// Shapes for clutter.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", tag = "kind")]
pub enum Shape {
    /// A box standing on its base, turned by yaw; sizes in centimetres.
    Box {
        /// Size along its own x, centimetres.
        length_cm: f64,
        /// Size along its own y, centimetres.
        width_cm: f64,
        /// Height, centimetres.
        height_cm: f64,
    },
    /// A vertical cylinder standing on its base, centimetres.
    Cylinder {
        /// Radius, centimetres.
        radius_cm: f64,
        /// Height, centimetres.
        height_cm: f64,
    },
    /// A sphere resting with its lowest point at the item's z, centimetres.
    Sphere {
        /// Radius, centimetres.
        radius_cm: f64,
    },
}

/// Something off the field (or anywhere): a coloured box, cylinder or sphere.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Clutter {
    /// What it is, for ground truth ("person", "orange chair", …).
    pub name: String,
    /// Shape and size.
    pub shape: Shape,
    /// Field position of the base's centre, centimetres `[x, y, z]`.
    pub position_cm: [f64; 3],
    /// Turn about the vertical, radians.
    pub yaw_rad: f64,
    /// Paint.
    pub material: Material,
}

/// The light: an ambient part and one distant lamp.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Lighting {
    /// Ambient light, fraction of full (0..1).
    pub ambient: f64,
    /// Direct light from the lamp, fraction of full (0..1).
    pub direct: f64,
    /// Direction towards the lamp, field axes (normalised by the renderer).
    pub towards_lamp: [f64; 3],
    /// Overall exposure multiplier.
    pub exposure: f64,
    /// Colour cast of the light, multipliers for R, G, B.
    pub tint: [f64; 3],
    /// Whether objects cast shadows on the ground.
    pub shadows: bool,
}

impl Default for Lighting {
    fn default() -> Self {
        Self {
            ambient: 0.45,
            direct: 0.6,
            towards_lamp: [0.25, 0.15, 1.0],
            exposure: 1.0,
            tint: [1.0, 1.0, 1.0],
            shadows: true,
        }
    }
}

/// Everything in the world at one instant.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Scene {
    /// Field dimensions.
    #[serde(default)]
    pub field: FieldSpec,
    /// The room around it.
    #[serde(default)]
    pub room: RoomSpec,
    /// Landmark beacons.
    pub beacons: Vec<Beacon>,
    /// The ball, if on the field.
    pub ball: Option<Ball>,
    /// Robots (the observing robot included; the renderer leaves it out of its own view).
    pub robots: Vec<Robot>,
    /// Things that are not field objects.
    pub clutter: Vec<Clutter>,
    /// Coloured-pattern markers (none on the standard field; the pattern tour adds them).
    #[serde(default)]
    pub markers: Vec<Marker>,
    /// The light.
    #[serde(default)]
    pub lighting: Lighting,
}

impl Scene {
    /// The 2005 Four-Legged League field with its four beacons, the ball at the centre spot, no
    /// robots, and a little off-field clutter (two people and a table).
    #[must_use]
    pub fn four_legged_2005() -> Self {
        let field = FieldSpec::default();
        let bx = 135.0;
        let by = field.width_cm / 2.0 + 15.0;
        let beacon = |name: &str, x: f64, y: f64, top: Material, bottom: Material| Beacon {
            name: name.to_owned(),
            x_cm: x,
            y_cm: y,
            radius_cm: 5.0,
            base_height_cm: 20.0,
            band_height_cm: 10.0,
            top,
            bottom,
        };
        let mut scene = Self {
            field,
            room: RoomSpec::default(),
            beacons: vec![
                beacon("pink_yellow", bx, by, Material::Pink, Material::Yellow),
                beacon("yellow_pink", bx, -by, Material::Yellow, Material::Pink),
                beacon("sky_blue_pink", -bx, by, Material::SkyBlue, Material::Pink),
                beacon("pink_sky_blue", -bx, -by, Material::Pink, Material::SkyBlue),
            ],
            ball: Some(Ball::at(0.0, 0.0)),
            robots: Vec::new(),
            clutter: vec![Clutter {
                name: "table".to_owned(),
                shape: Shape::Box {
                    length_cm: 120.0,
                    width_cm: 60.0,
                    height_cm: 75.0,
                },
                position_cm: [100.0, 330.0, 0.0],
                yaw_rad: 0.0,
                material: Material::Wood,
            }],
            markers: Vec::new(),
            lighting: Lighting::default(),
        };
        scene.clutter.extend(person(-200.0, 330.0));
        scene.clutter.extend(person(360.0, -300.0));
        scene
    }

    /// The robot with this identity, if present.
    #[must_use]
    pub fn robot(&self, id: u32) -> Option<&Robot> {
        self.robots.iter().find(|r| r.id == id)
    }
}

/// A standing person at a field position (cm): a dark cylinder for the body and a
/// skin-coloured sphere for the head.
#[must_use]
pub fn person(x_cm: f64, y_cm: f64) -> [Clutter; 2] {
    [
        Clutter {
            name: "person".to_owned(),
            shape: Shape::Cylinder {
                radius_cm: 20.0,
                height_cm: 150.0,
            },
            position_cm: [x_cm, y_cm, 0.0],
            yaw_rad: 0.0,
            material: Material::Cloth,
        },
        Clutter {
            name: "person's head".to_owned(),
            shape: Shape::Sphere { radius_cm: 11.0 },
            position_cm: [x_cm, y_cm, 151.0],
            yaw_rad: 0.0,
            material: Material::Skin,
        },
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scene_json_round_trip() {
        let mut scene = Scene::four_legged_2005();
        scene.robots.push(Robot {
            id: 3,
            team: Team::Blue,
            pose: RobotPose::new(10.0, 20.0, 0.5),
            body: BodyPose::ERS7_STANCE,
            joints: HeadJoints::default(),
            marker: Some(RobotMarker::new(
                crate::geometry::MarkerTeam::Blue,
                crate::geometry::MarkerIdentity::new(11).expect("in range"),
            )),
        });
        let json = serde_json::to_string_pretty(&scene).expect("serialise");
        assert!(json.contains("\"pink_yellow\""));
        assert!(json.contains("\"carpet_margin_cm\""));
        let back: Scene = serde_json::from_str(&json).expect("parse");
        assert_eq!(back, scene);
    }

    #[test]
    fn field_figures_match_the_2005_rules() {
        let scene = Scene::four_legged_2005();
        assert_eq!(scene.field.goal_width_cm, 80.0);
        assert_eq!(scene.field.goal_height_cm, 30.0);
        assert_eq!(scene.beacons.len(), 4);
        assert_eq!(scene.ball.map(|b| b.radius_cm * 2.0), Some(8.5));
        // Every beacon has pink and one goal colour, and each goal colour appears on both
        // sides with pink on top once.
        for b in &scene.beacons {
            assert!(b.top == Material::Pink || b.bottom == Material::Pink);
            assert_eq!(b.height_cm(), 40.0);
        }
        assert_eq!(
            scene
                .beacons
                .iter()
                .filter(|b| b.top == Material::Pink)
                .count(),
            2
        );
    }

    #[test]
    fn materials_label_off_field_colours_like_field_colours() {
        assert_eq!(Material::ClutterOrange.class(), ColourClass::Orange);
        assert_eq!(Material::ClutterYellow.class(), ColourClass::Yellow);
        assert_eq!(Material::Floor.class(), ColourClass::Unclassified);
    }
}
