//! Drawing primitives as data: what recognition looked at and found, in image pixels, so the
//! app, `eotn render` and the JSON all draw the same thing. Each primitive names the object it
//! belongs to (`owner`, an [`ObjectId`]) so a selected candidate can be
//! highlighted.

use serde::{Deserialize, Serialize};

use crate::frame::{PixelBox, xy_array};
use crate::geometry::ImagePoint;
use crate::lut::ColourClass;

/// The object a primitive belongs to: what the app selects, the inspector lists and the
/// objects view filters by, made in one place so that they always agree. Indices are the
/// candidate's place in its list. [`Display`](std::fmt::Display) gives the readable name the
/// app shows (`ball#0`, `goal:yellow#1`, `beacon#0`, `pattern#2`, `horizon`, `blob#7`); a
/// serialised primitive carries that same text.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum ObjectId {
    /// A ball candidate.
    Ball(usize),
    /// A goal candidate of a goal colour (yellow or sky blue).
    Goal(ColourClass, usize),
    /// A beacon candidate.
    Beacon(usize),
    /// A pink marker's coloured pattern.
    Pattern(usize),
    /// The horizon line (belongs to no object; never dimmed by a selection).
    Horizon,
    /// A blob of `eotn render`'s blob overlay, by its blob number.
    Blob(u32),
}

impl ObjectId {
    /// Whether this is a pink marker's coloured pattern.
    #[must_use]
    pub const fn is_pattern(self) -> bool {
        matches!(self, Self::Pattern(_))
    }
}

impl std::fmt::Display for ObjectId {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Ball(i) => write!(f, "ball#{i}"),
            Self::Goal(colour, i) => write!(f, "goal:{}#{i}", colour.name()),
            Self::Beacon(i) => write!(f, "beacon#{i}"),
            Self::Pattern(i) => write!(f, "pattern#{i}"),
            Self::Horizon => f.write_str("horizon"),
            Self::Blob(n) => write!(f, "blob#{n}"),
        }
    }
}

impl Serialize for ObjectId {
    /// As its readable name, the form owners had when they were strings.
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.collect_str(self)
    }
}

/// One thing to draw over the image. Serialised (as JSON) for reading; nothing reads it back.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Primitive {
    /// An inclusive pixel box, e.g. a blob or a candidate's extent.
    Box {
        /// Which object this belongs to.
        owner: ObjectId,
        /// Class code whose display colour to use.
        colour: u8,
        /// The box, inclusive pixels (written as `[minx, miny, maxx, maxy]`).
        bounds: PixelBox,
    },
    /// A scanned quadrilateral (colour-below areas, goal scans).
    ScanArea {
        /// Which object this belongs to.
        owner: ObjectId,
        /// Corners in order, pixels.
        #[serde(with = "xy_array")]
        corners: [ImagePoint; 4],
    },
    /// Points found by edge scans.
    ScanPoints {
        /// Which object this belongs to.
        owner: ObjectId,
        /// The points, pixels.
        #[serde(with = "xy_array")]
        points: Vec<ImagePoint>,
    },
    /// A fitted circle.
    Circle {
        /// Which object this belongs to.
        owner: ObjectId,
        /// Centre, pixels.
        #[serde(with = "xy_array")]
        center: ImagePoint,
        /// Radius, pixels.
        radius: f64,
        /// Where the circle is: on the ball as the image shows it (drawn solid), or moved to
        /// the reference read-out time by the skew correction (drawn thin and dashed).
        #[serde(default)]
        role: CircleRole,
    },
    /// A straight segment: a goal post, a gap, a horizon.
    Line {
        /// Which object this belongs to.
        owner: ObjectId,
        /// What the line is.
        role: LineRole,
        /// Start, pixels.
        #[serde(with = "xy_array")]
        from: ImagePoint,
        /// End, pixels.
        #[serde(with = "xy_array")]
        to: ImagePoint,
    },
    /// One of the nine regions of a coloured pattern around a pink marker.
    PatternRegion {
        /// Which pattern this belongs to ([`ObjectId::Pattern`]).
        owner: ObjectId,
        /// Inclusive pixel box `[minx, miny, maxx, maxy]`; may reach outside the image.
        bounds: [i64; 4],
        /// The region's most common class code (0: nothing), whose display colour to use.
        colour: u8,
        /// The pink blob's own region (drawn thicker).
        centre: bool,
    },
    /// A text label at a point (object name, distance, bearing).
    Label {
        /// Which object this belongs to.
        owner: ObjectId,
        /// Where, pixels.
        #[serde(with = "xy_array")]
        at: ImagePoint,
        /// The text.
        text: String,
    },
}

/// What a [`Primitive::Circle`] shows.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum CircleRole {
    /// The outline as observed in the image (each row at its own read-out time): the circle
    /// sits on the ball's pixels. Drawn solid.
    #[default]
    Observed,
    /// The same ball moved to the reference row's read-out time by the rolling-shutter skew
    /// correction: where the sensor readings place it, up to several pixels off the ball's
    /// pixels on a fast pan. Drawn thin and dashed.
    SkewCorrected,
}

/// What a [`Primitive::Line`] shows.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum LineRole {
    /// The horizon.
    Horizon,
    /// A fitted goal post.
    Post,
    /// The largest open gap of a goal.
    Gap,
    /// A scan line.
    Scan,
}

impl Primitive {
    /// The object this primitive belongs to.
    #[must_use]
    pub const fn owner(&self) -> ObjectId {
        match self {
            Self::Box { owner, .. }
            | Self::ScanArea { owner, .. }
            | Self::ScanPoints { owner, .. }
            | Self::Circle { owner, .. }
            | Self::Line { owner, .. }
            | Self::PatternRegion { owner, .. }
            | Self::Label { owner, .. } => *owner,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_object_id_displays_as_the_name_the_app_shows() {
        assert_eq!(ObjectId::Ball(0).to_string(), "ball#0");
        assert_eq!(
            ObjectId::Goal(ColourClass::Yellow, 1).to_string(),
            "goal:yellow#1"
        );
        assert_eq!(
            ObjectId::Goal(ColourClass::SkyBlue, 0).to_string(),
            "goal:sky blue#0"
        );
        assert_eq!(ObjectId::Beacon(3).to_string(), "beacon#3");
        assert_eq!(ObjectId::Pattern(12).to_string(), "pattern#12");
        assert_eq!(ObjectId::Horizon.to_string(), "horizon");
        assert_eq!(ObjectId::Blob(7).to_string(), "blob#7");
    }

    #[test]
    fn only_a_pattern_is_a_pattern() {
        assert!(ObjectId::Pattern(0).is_pattern());
        for other in [
            ObjectId::Ball(0),
            ObjectId::Goal(ColourClass::Yellow, 0),
            ObjectId::Beacon(0),
            ObjectId::Horizon,
            ObjectId::Blob(0),
        ] {
            assert!(!other.is_pattern(), "{other}");
        }
    }

    #[test]
    fn candidates_of_different_kinds_or_indices_are_different_objects() {
        let ids = [
            ObjectId::Ball(0),
            ObjectId::Ball(1),
            ObjectId::Goal(ColourClass::Yellow, 0),
            ObjectId::Goal(ColourClass::SkyBlue, 0),
            ObjectId::Beacon(0),
            ObjectId::Pattern(0),
            ObjectId::Horizon,
            ObjectId::Blob(0),
        ];
        let distinct: std::collections::HashSet<ObjectId> = ids.into_iter().collect();
        assert_eq!(distinct.len(), ids.len());
        let names: std::collections::HashSet<String> =
            ids.iter().map(ToString::to_string).collect();
        assert_eq!(names.len(), ids.len(), "each has its own name");
    }

    #[test]
    fn a_primitive_serialises_its_owner_and_box_as_before_they_had_types() {
        let p = Primitive::Box {
            owner: ObjectId::Goal(ColourClass::Yellow, 1),
            colour: 3,
            bounds: PixelBox::new(1, 2, 30, 40),
        };
        assert_eq!(
            serde_json::to_string(&p).expect("serialises"),
            r#"{"kind":"box","owner":"goal:yellow#1","colour":3,"bounds":[1,2,30,40]}"#
        );
        assert_eq!(p.owner(), ObjectId::Goal(ColourClass::Yellow, 1));
    }
}
