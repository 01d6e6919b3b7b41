//! Drawing primitives as data: what recognition looked at and found, in image pixels, so the
//! app, `eotn render` and the JSON all draw the same thing. Each primitive names the object it
//! belongs to (`owner`, e.g. `"ball#0"`, `"goal:yellow#1"`) so a selected candidate can be
//! highlighted.

use serde::{Deserialize, Serialize};

use super::fit::Point;
use crate::lut::ColourClass;

/// The `owner` names of primitives, made in one place so that recognition, the app's selection
/// and its object inspector always agree on them. `i` is the candidate's index in its list.
pub mod owner {
    use super::ColourClass;

    /// A ball candidate: `ball#i`.
    #[must_use]
    pub fn ball(i: usize) -> String {
        format!("ball#{i}")
    }

    /// A goal candidate of a goal colour: `goal:yellow#i`.
    #[must_use]
    pub fn goal(colour: ColourClass, i: usize) -> String {
        format!("goal:{}#{i}", colour.name())
    }

    /// A beacon candidate: `beacon#i`.
    #[must_use]
    pub fn beacon(i: usize) -> String {
        format!("beacon#{i}")
    }

    /// A pink marker's coloured pattern: `pattern#i`.
    #[must_use]
    pub fn pattern(i: usize) -> String {
        format!("pattern#{i}")
    }

    /// Whether an owner name is a coloured pattern's.
    #[must_use]
    pub fn is_pattern(owner: &str) -> bool {
        owner.starts_with("pattern#")
    }
}

/// One thing to draw over the image.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Primitive {
    /// An inclusive pixel box, e.g. a blob or a candidate's extent.
    Box {
        /// Which object this belongs to.
        owner: String,
        /// Class code whose display colour to use.
        colour: u8,
        /// `[minx, miny, maxx, maxy]`, inclusive pixels.
        bounds: [u32; 4],
    },
    /// A scanned quadrilateral (colour-below areas, goal scans).
    ScanArea {
        /// Which object this belongs to.
        owner: String,
        /// Corners in order, pixels.
        corners: [Point; 4],
    },
    /// Points found by edge scans.
    ScanPoints {
        /// Which object this belongs to.
        owner: String,
        /// The points, pixels.
        points: Vec<Point>,
    },
    /// A fitted circle.
    Circle {
        /// Which object this belongs to.
        owner: String,
        /// Centre, pixels.
        center: Point,
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
        owner: String,
        /// What the line is.
        role: LineRole,
        /// Start, pixels.
        from: Point,
        /// End, pixels.
        to: Point,
    },
    /// One of the nine regions of a coloured pattern around a pink marker.
    PatternRegion {
        /// Which pattern this belongs to (`pattern#i`).
        owner: String,
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
        owner: String,
        /// Where, pixels.
        at: Point,
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
    pub fn owner(&self) -> &str {
        match self {
            Self::Box { owner, .. }
            | Self::ScanArea { owner, .. }
            | Self::ScanPoints { owner, .. }
            | Self::Circle { owner, .. }
            | Self::Line { owner, .. }
            | Self::PatternRegion { owner, .. }
            | Self::Label { owner, .. } => owner,
        }
    }
}
