//! The overhead robot marker of `FORMATS.md`: a black plate worn flat on top of every robot with
//! a team dot at its centre and four identity dots around it, so that an overhead camera tells
//! the robots apart and reads their headings.
//!
//! The layout (all sizes in centimetres, angles in radians counter-clockwise from the robot's
//! heading): plate 30 across; team dot 8 across, sky blue or yellow; identity dots 6 across,
//! pink = 1, green = 0, their centres 10 from the plate's centre at +35° (bit 0, front left),
//! −35° (bit 1, front right), −125° (bit 2, back right) and +125° (bit 3, back left). The front
//! pair is 70° apart, the back pair 110°, front and back 90° on each side, so the heading
//! follows from the dots' positions alone. The renderer paints it, the recogniser reads it and
//! the printable drawing (`overhead::drawing`) is made from the same numbers.

use serde::{Deserialize, Serialize};

use crate::lut::ColourClass;

/// Plate diameter, centimetres.
pub const PLATE_DIAMETER_CM: f64 = 30.0;
/// Team dot diameter, centimetres.
pub const TEAM_DOT_DIAMETER_CM: f64 = 8.0;
/// Identity dot diameter, centimetres.
pub const ID_DOT_DIAMETER_CM: f64 = 6.0;
/// Distance of the identity dots' centres from the plate's centre, centimetres.
pub const ID_DOT_RADIUS_CM: f64 = 10.0;
/// The plate's height above the ground unless a field description says otherwise, centimetres.
pub const DEFAULT_PLATE_HEIGHT_CM: f64 = 22.5;

/// Angle of each identity dot from the heading, bit 0 to bit 3, degrees.
pub const ID_DOT_ANGLES_DEG: [f64; 4] = [35.0, -35.0, -125.0, 125.0];

/// The team colour of a marker's centre dot.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum MarkerTeam {
    /// Sky-blue centre dot (class 2).
    Blue,
    /// Yellow centre dot (class 3).
    Yellow,
}

impl MarkerTeam {
    /// The colour class of the team dot.
    #[must_use]
    pub const fn class(self) -> ColourClass {
        match self {
            Self::Blue => ColourClass::SkyBlue,
            Self::Yellow => ColourClass::Yellow,
        }
    }

    /// The team whose dot has this class, if any.
    #[must_use]
    pub fn from_class(class: ColourClass) -> Option<Self> {
        match class {
            ColourClass::SkyBlue => Some(Self::Blue),
            ColourClass::Yellow => Some(Self::Yellow),
            _ => None,
        }
    }

    /// `"blue"` or `"yellow"`, as in `eotn overhead detect --json`.
    #[must_use]
    pub const fn name(self) -> &'static str {
        match self {
            Self::Blue => "blue",
            Self::Yellow => "yellow",
        }
    }

    /// The team with this name (`blue`, `yellow`).
    #[must_use]
    pub fn from_name(name: &str) -> Option<Self> {
        match name {
            "blue" => Some(Self::Blue),
            "yellow" => Some(Self::Yellow),
            _ => None,
        }
    }
}

/// A marker identity, 0–15: bit k is the colour of identity dot k (pink = 1, green = 0).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(try_from = "u8", into = "u8")]
pub struct MarkerIdentity(u8);

impl MarkerIdentity {
    /// Identity 0 (four green dots).
    pub const MIN: Self = Self(0);

    /// The identity `value`, or `None` above 15.
    #[must_use]
    pub const fn new(value: u8) -> Option<Self> {
        if value < 16 { Some(Self(value)) } else { None }
    }

    /// The identity read from four dots (bit 0 first; `true` = pink).
    #[must_use]
    pub fn from_bits(bits: [bool; 4]) -> Self {
        Self(
            bits.iter()
                .enumerate()
                .map(|(k, &b)| u8::from(b) << k)
                .sum(),
        )
    }

    /// The value, 0–15.
    #[must_use]
    pub const fn value(self) -> u8 {
        self.0
    }

    /// Dot k is pink (`true`) or green.
    #[must_use]
    pub fn bits(self) -> [bool; 4] {
        [0, 1, 2, 3].map(|k| self.0 >> k & 1 == 1)
    }
}

impl TryFrom<u8> for MarkerIdentity {
    type Error = String;
    fn try_from(value: u8) -> Result<Self, Self::Error> {
        Self::new(value).ok_or_else(|| format!("marker identity {value} is not in 0..=15"))
    }
}

impl From<MarkerIdentity> for u8 {
    fn from(id: MarkerIdentity) -> Self {
        id.0
    }
}

impl std::fmt::Display for MarkerIdentity {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}", self.0)
    }
}

/// One robot's marker: its team and identity, and the plate's height above the ground.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct RobotMarker {
    /// Colour of the team dot.
    pub team: MarkerTeam,
    /// Identity, 0–15.
    pub identity: MarkerIdentity,
    /// Height of the plate's top above the ground, centimetres.
    pub plate_height_cm: f64,
}

impl RobotMarker {
    /// A marker at the default plate height (22.5 cm).
    #[must_use]
    pub const fn new(team: MarkerTeam, identity: MarkerIdentity) -> Self {
        Self {
            team,
            identity,
            plate_height_cm: DEFAULT_PLATE_HEIGHT_CM,
        }
    }

    /// What the plate shows at `(forward, left)` centimetres from its centre (robot axes): the
    /// team dot's class, an identity dot's class, black on the rest of the plate, `None` off it.
    #[must_use]
    pub fn class_at(&self, forward_cm: f64, left_cm: f64) -> Option<ColourClass> {
        let r2 = forward_cm * forward_cm + left_cm * left_cm;
        let plate_r = PLATE_DIAMETER_CM / 2.0;
        if r2 > plate_r * plate_r {
            return None;
        }
        let team_r = TEAM_DOT_DIAMETER_CM / 2.0;
        if r2 <= team_r * team_r {
            return Some(self.team.class());
        }
        let dot_r2 = (ID_DOT_DIAMETER_CM / 2.0).powi(2);
        for (k, [dx, dy]) in id_dot_offsets_cm().into_iter().enumerate() {
            let (ex, ey) = (forward_cm - dx, left_cm - dy);
            if ex * ex + ey * ey <= dot_r2 {
                return Some(if self.identity.bits()[k] {
                    ColourClass::Pink
                } else {
                    ColourClass::Green
                });
            }
        }
        Some(ColourClass::Black)
    }
}

/// The identity dots' centres, bit 0 to bit 3, `[forward, left]` centimetres from the plate's
/// centre in robot axes.
#[must_use]
pub fn id_dot_offsets_cm() -> [[f64; 2]; 4] {
    ID_DOT_ANGLES_DEG.map(|a| {
        let (s, c) = a.to_radians().sin_cos();
        [ID_DOT_RADIUS_CM * c, ID_DOT_RADIUS_CM * s]
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn identity_round_trips_through_its_bits() {
        for v in 0..16 {
            let id = MarkerIdentity::new(v).expect("in range");
            assert_eq!(MarkerIdentity::from_bits(id.bits()), id);
        }
        assert!(MarkerIdentity::new(16).is_none());
        assert!(serde_json::from_str::<MarkerIdentity>("16").is_err());
        assert_eq!(
            serde_json::from_str::<MarkerIdentity>("9").ok(),
            MarkerIdentity::new(9)
        );
    }

    #[test]
    fn plate_shows_team_dot_bits_and_black() {
        let m = RobotMarker::new(
            MarkerTeam::Yellow,
            MarkerIdentity::new(0b0101).expect("in range"),
        );
        assert_eq!(m.class_at(0.0, 0.0), Some(ColourClass::Yellow));
        let [front_left, front_right, back_right, back_left] = id_dot_offsets_cm();
        assert_eq!(
            m.class_at(front_left[0], front_left[1]),
            Some(ColourClass::Pink)
        );
        assert_eq!(
            m.class_at(front_right[0], front_right[1]),
            Some(ColourClass::Green)
        );
        assert_eq!(
            m.class_at(back_right[0], back_right[1]),
            Some(ColourClass::Pink)
        );
        assert_eq!(
            m.class_at(back_left[0], back_left[1]),
            Some(ColourClass::Green)
        );
        // Front left is ahead and to the left.
        assert!(front_left[0] > 0.0 && front_left[1] > 0.0);
        assert_eq!(m.class_at(-13.0, 0.0), Some(ColourClass::Black));
        assert_eq!(m.class_at(15.5, 0.0), None);
    }
}
