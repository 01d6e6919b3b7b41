//! The "almost SLAM" coloured-pattern recogniser of the original: any pink marker together with
//! the colours around it forms a signature that identifies a place. Nine regions the size of the
//! pink blob in a 3 × 3 grid centred on it each give their two most common colours; a signature
//! matches a stored one when at least eight regions agree on the most common colour.
//!
//! **Learning** ([`PatternMemory::learn`]) needs only where the robot stood for each frame (its
//! localisation, or positions typed in), never the markers' distances: views of one marker are
//! grouped by signature, the marker's field position is the least-squares intersection of the
//! bearing rays seen from two or more robot positions (bearing-only triangulation, weighted so
//! that angles count alike near and far, outliers dropped), its height the median of what each
//! ray's elevation gives there. Every view of a triangulated marker then gives one (size,
//! distance) sample, and the linear relation distance = multiplier / size + offset is fitted to
//! them. A group seen from too narrow a baseline is placed along its rays by that relation. A
//! group placed within [`LearnParams::same_object_cm`] of a known object adds its signature to
//! that object as another pattern (unless it comes within one region of another object's
//! pattern); otherwise it becomes a new object. A recognised beacon's pink band is the beacon's
//! and gets no signature.
//!
//! **Identification** ([`PatternMemory::identify`]) only identifies: the best object with enough
//! agreeing regions, refused when another object agrees as well (the signature cannot tell
//! them apart), with the distance from the learnt relation.
//!
//! The memory is saved as a "places" JSON file ([`PatternMemory::save`], atomically) and read
//! back with every field checked ([`PatternMemory::load`]).
//!
//! One file per stage: `signatures` (per frame: the nine regions around each pink blob),
//! `identification` (per frame: a signature against the memory), `places` (the places file's
//! reading, checking and atomic writing: file I/O stays out of the per-frame stages) and
//! `learning` (multi-frame and offline, like `lut::learn`).

mod identification;
mod learning;
mod places;
mod signatures;
#[cfg(test)]
mod tests;

use serde::{Deserialize, Serialize};

use super::confidence::{Confidence, TestWeight};
use super::context::Relative;
use super::draw::{ObjectId, Primitive};
use crate::geometry::ImagePoint;

pub use learning::{LearnParams, LearnReport, LearnView, Triangulation, triangulate};
use learning::{median, theil_sen};
pub use places::{PlacesError, PlacesProblem};
pub use signatures::{FieldRay, GroundRay, PatternObservation, observe};

/// The two most common class codes of each of the nine regions, row by row (top-left first,
/// the pink blob's own region in the middle). 0 stands for "nothing" (no classified pixel, or
/// the region lies outside the image).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct Signature(pub [[u8; 2]; 9]);

impl Signature {
    /// How many regions agree on their most common colour.
    #[must_use]
    pub fn agreement(&self, other: &Self) -> usize {
        self.0
            .iter()
            .zip(other.0.iter())
            .filter(|(a, b)| a[0] == b[0])
            .count()
    }

    /// How many regions share both their colours (in either order): a finer score that breaks
    /// ties between equal [`Self::agreement`]s.
    #[must_use]
    pub fn both_colours_agreement(&self, other: &Self) -> usize {
        self.0
            .iter()
            .zip(other.0.iter())
            .filter(|(a, b)| (a[0] == b[0] && a[1] == b[1]) || (a[0] == b[1] && a[1] == b[0]))
            .count()
    }

    /// Regions whose most common colour is a class (not "nothing").
    #[must_use]
    pub fn coloured_regions(&self) -> usize {
        self.0.iter().filter(|r| r[0] != 0).count()
    }

    /// The signature as text, one region after another: `Y/W W/- …` with class letters (see
    /// [`class_letter`]).
    #[must_use]
    pub fn short_text(&self) -> String {
        self.0
            .iter()
            .map(|r| format!("{}/{}", class_letter(r[0]), class_letter(r[1])))
            .collect::<Vec<_>>()
            .join(" ")
    }
}

/// A one-letter name of a class code for compact signatures: O orange, B sky blue, Y yellow,
/// P pink, G green, W white, R red, D dark blue, K black, soft colours lower case, `-` nothing.
#[must_use]
pub fn class_letter(code: u8) -> char {
    match code {
        0 => '-',
        1 => 'O',
        2 => 'B',
        3 => 'Y',
        4 => 'P',
        5 => 'G',
        6 => 'W',
        7 => 'R',
        8 => 'D',
        9 => 'K',
        10 => 'y',
        11 => 'r',
        12 => 'p',
        13 => 'b',
        14 => 'g',
        _ => '?',
    }
}

/// Settings of the pattern recogniser (recognition, not learning).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct PatternParams {
    /// Pink blobs with fewer pixels are ignored.
    pub min_pixels: u32,
    /// Regions that must agree for a match (of nine).
    pub min_agreement: usize,
    /// Observations with fewer regions of a colour (not "nothing") are not places: a pink
    /// thing against an empty background (a beacon's band against the wall) would match any
    /// other.
    pub min_coloured_regions: usize,
    /// Weight of the agreement test.
    pub agreement_weight: TestWeight,
    /// Weight of the margin test (best object's agreement minus the next object's).
    pub margin_weight: TestWeight,
    /// Weight of the colour test ([`Self::min_coloured_regions`]).
    pub coloured_weight: TestWeight,
}

impl Default for PatternParams {
    fn default() -> Self {
        Self {
            min_pixels: 9,
            min_agreement: 8,
            min_coloured_regions: 6,
            agreement_weight: TestWeight::new(2.0, 2.0),
            margin_weight: TestWeight::new(1.0, 3.0),
            coloured_weight: TestWeight::new(0.5, 3.0),
        }
    }
}

/// A place known by its patterns.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PatternObject {
    /// Identity, unique in the memory.
    pub id: usize,
    /// Estimated field position (x, y), centimetres.
    pub field_cm: [f64; 2],
    /// Estimated height of the pink centre above the ground, centimetres (from the rays'
    /// elevations; `None` when placed by size only).
    #[serde(default)]
    pub height_cm: Option<f64>,
    /// Signatures seen of it (the consensus of each group of views that was placed here).
    pub patterns: Vec<Signature>,
    /// Views it was learnt from.
    #[serde(default)]
    pub views: usize,
    /// How its position was found.
    #[serde(default)]
    pub placed_by: Placement,
    /// Root mean square distance of its rays from the position, centimetres (triangulated
    /// objects; 0 otherwise).
    #[serde(default)]
    pub residual_cm: f64,
}

/// How a learnt object's position was found.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Placement {
    /// Least-squares intersection of bearing rays from several robot positions.
    #[default]
    Triangulation,
    /// Along its rays at the distance the learnt size relation gives (too narrow a baseline).
    SizeRelation,
}

/// The learnt linear relation between a marker's size in the image and its distance:
/// distance = `multiplier_cm_px` / size + `offset_cm` (a pinhole camera gives the multiplier as
/// focal length × tile height and an offset of 0).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SizeRelation {
    /// Centimetre-pixels.
    pub multiplier_cm_px: f64,
    /// Centimetres.
    pub offset_cm: f64,
    /// Root mean square residual of the samples it was fitted to, centimetres.
    pub residual_cm: f64,
    /// Samples it was fitted to.
    pub samples: usize,
}

impl SizeRelation {
    /// The distance (cm) of a marker `size_px` tall, `None` for a non-positive size.
    #[must_use]
    pub fn distance_cm(&self, size_px: f64) -> Option<f64> {
        (size_px > 0.0 && size_px.is_finite())
            .then(|| self.multiplier_cm_px / size_px + self.offset_cm)
            .filter(|d| d.is_finite() && *d > 0.0)
    }

    /// The relation over `(size px, distance cm)` samples: a robust line through them first
    /// (Theil–Sen in 1 / size: the median of pairwise slopes, so that a few views of the
    /// wrong marker cannot bend it), then least squares over the samples within three robust
    /// standard deviations of it. `None` with fewer than two distinct sizes or a relation that
    /// is not "smaller is farther".
    #[must_use]
    pub fn fit(samples: &[[f64; 2]]) -> Option<Self> {
        let good: Vec<[f64; 2]> = samples
            .iter()
            .copied()
            .filter(|s| s[0] > 0.0 && s[0].is_finite() && s[1].is_finite() && s[1] > 0.0)
            .collect();
        let (m, o) = theil_sen(&good)?;
        let residuals: Vec<f64> = good.iter().map(|s| (m / s[0] + o - s[1]).abs()).collect();
        let sigma = 1.4826 * median(&residuals);
        let limit = (3.0 * sigma).max(1.0);
        let kept: Vec<[f64; 2]> = good
            .iter()
            .zip(&residuals)
            .filter(|(_, r)| **r <= limit)
            .map(|(s, _)| *s)
            .collect();
        let fit = Self::least_squares(&kept)?;
        (fit.multiplier_cm_px > 0.0).then_some(fit)
    }

    fn least_squares(samples: &[[f64; 2]]) -> Option<Self> {
        let pairs: Vec<(f64, f64)> = samples.iter().map(|s| (s[0], s[1])).collect();
        let (m, o) = crate::stats::fit_inverse_size(&pairs)?;
        let ss: f64 = samples.iter().map(|s| (m / s[0] + o - s[1]).powi(2)).sum();
        Some(Self {
            multiplier_cm_px: m,
            offset_cm: o,
            residual_cm: (ss / samples.len() as f64).sqrt(),
            samples: samples.len(),
        })
    }
}

/// What the recogniser has learnt: the places file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PatternMemory {
    /// Always `"eotn.places"`.
    #[serde(default = "places::places_format")]
    pub format: String,
    /// The places format's version (1).
    #[serde(default = "places::places_version")]
    pub version: u32,
    /// Known objects.
    pub objects: Vec<PatternObject>,
    /// The size → distance relation, once learnt.
    #[serde(default)]
    pub relation: Option<SizeRelation>,
    /// `(size px, distance cm)` samples the relation was fitted to (kept, so that learning more
    /// refits over all of them).
    #[serde(default)]
    pub samples: Vec<[f64; 2]>,
}

impl Default for PatternMemory {
    fn default() -> Self {
        Self {
            format: places::places_format(),
            version: places::PLACES_VERSION,
            objects: Vec::new(),
            relation: None,
            samples: Vec::new(),
        }
    }
}

impl PatternMemory {
    /// The object with this id.
    #[must_use]
    pub fn object(&self, id: usize) -> Option<&PatternObject> {
        self.objects.iter().find(|o| o.id == id)
    }
}

/// An identification.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PatternMatch {
    /// Which object.
    pub id: usize,
    /// Regions that agreed on the most common colour (of nine).
    pub agreement: usize,
    /// Regions that shared both colours (the tie-breaker).
    pub both_colours: usize,
    /// Camera distance from the learnt size relation, centimetres (`None` before one was
    /// learnt).
    pub distance_cm: Option<f64>,
}

/// The closest known object to an observation, matched or not.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Closest {
    /// Which object.
    pub id: usize,
    /// Regions that agreed on the most common colour.
    pub agreement: usize,
    /// Regions that shared both colours.
    pub both_colours: usize,
}

/// A pink marker of a frame with its identification and evidence.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PatternCandidate {
    /// What was seen.
    pub observation: PatternObservation,
    /// The object it was identified as (accepted candidates only).
    pub identification: Option<PatternMatch>,
    /// The best-agreeing known object, whether or not it matched.
    pub closest: Option<Closest>,
    /// The next best object other than the closest one.
    pub runner_up: Option<Closest>,
    /// Camera-relative placement (distance from the size relation), when identified with a
    /// relation.
    pub camera: Option<Relative>,
    /// Body-relative placement, when also the joints were known.
    pub body: Option<Relative>,
    /// Some of the nine regions reach outside the image.
    pub cut_off: bool,
    /// Two objects agree equally well: the signature cannot tell them apart.
    pub ambiguous: bool,
    /// The confidence breakdown (empty without a memory).
    pub confidence: Confidence,
    /// Identified.
    pub accepted: bool,
}

/// Drawing primitives of the pattern candidates: the nine regions of each pink marker in their
/// most common colour (dashed where they disagree with the identified place), and a label with
/// the place and its distance.
#[must_use]
pub fn pattern_primitives(candidates: &[PatternCandidate]) -> Vec<Primitive> {
    let mut out = Vec::new();
    for (i, c) in candidates.iter().enumerate() {
        let owner = ObjectId::Pattern(i);
        let obs = &c.observation;
        for k in 0..9 {
            out.push(Primitive::PatternRegion {
                owner,
                bounds: obs.region_bounds(k),
                colour: obs.signature.0[k][0],
                centre: k == 4,
            });
        }
        let [x0, y0, ..] = obs.region_bounds(0);
        let text = match (&c.identification, &c.closest) {
            (Some(m), _) => match m.distance_cm {
                Some(d) => format!("place {} ({}/9) {d:.0} cm", m.id, m.agreement),
                None => format!("place {} ({}/9)", m.id, m.agreement),
            },
            (None, Some(b)) if c.ambiguous => {
                format!(
                    "pink: place {} or {}, tie {}/9",
                    b.id,
                    c.runner_up.map_or(0, |r| r.id),
                    b.agreement
                )
            }
            (None, Some(b)) => format!("pink: unknown (best place {} {}/9)", b.id, b.agreement),
            (None, None) if !c.confidence.tests.is_empty() => {
                "pink: unknown (no places)".to_owned()
            }
            (None, None) => format!("pink {}", obs.signature.short_text()),
        };
        out.push(Primitive::Label {
            owner,
            at: ImagePoint::new(x0.max(0) as f64, (y0 as f64 - 2.0).max(8.0)),
            text,
        });
    }
    out
}
