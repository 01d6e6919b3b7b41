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

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};
use thiserror::Error;

use super::confidence::{Confidence, TestWeight};
use super::context::{Relative, ViewContext};
use super::draw::{Primitive, owner};
use crate::blobs::{Blob, BlobSet};
use crate::classify::ClassifiedImage;
use crate::geometry::{ImagePoint, RobotPose};
use crate::lut::ColourClass;

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

/// A ray in the robot's ground frame (origin on the ground below the body centre, x ahead, y
/// left, z up; centimetres): where the camera was and where it looked.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct GroundRay {
    /// The camera's centre, centimetres.
    pub origin_cm: [f64; 3],
    /// Unit direction.
    pub direction: [f64; 3],
}

impl GroundRay {
    /// The same ray in field coordinates for a robot standing at `robot`.
    #[must_use]
    pub fn in_field(&self, robot: &RobotPose) -> FieldRay {
        let (s, c) = robot.heading_rad.sin_cos();
        let turn = |v: [f64; 3]| [c * v[0] - s * v[1], s * v[0] + c * v[1], v[2]];
        let o = turn(self.origin_cm);
        let d = turn(self.direction);
        let ground = d[0].hypot(d[1]);
        FieldRay {
            origin_cm: [robot.x_cm + o[0], robot.y_cm + o[1], o[2]],
            heading_rad: d[1].atan2(d[0]),
            slope: if ground > 1e-12 { d[2] / ground } else { 0.0 },
        }
    }
}

/// A viewing ray in field coordinates, as triangulation uses it.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct FieldRay {
    /// The camera's centre, field centimetres.
    pub origin_cm: [f64; 3],
    /// Direction of the ray on the ground, radians counter-clockwise from field +x.
    pub heading_rad: f64,
    /// Rise per unit of ground distance (tangent of the elevation).
    pub slope: f64,
}

/// One pink marker seen in a frame.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PatternObservation {
    /// The colours around it.
    pub signature: Signature,
    /// Size of the pink blob: the mean height of its columns (first to last pink row of each
    /// column at least 60% as tall as the tallest), pixels. Unlike the width it does not shrink
    /// when the marker is seen from the side; unlike the box height or the pixel count it
    /// ignores a pan's rolling-shutter shear and holes in the classification.
    pub size_px: f64,
    /// Camera bearing of the blob's centre (shutter skew removed), radians, positive left.
    pub bearing_rad: f64,
    /// Camera elevation of the blob's centre, radians, positive up.
    pub elevation_rad: f64,
    /// The pink blob's box, inclusive pixels `[minx, miny, maxx, maxy]`.
    pub bounds: [u32; 4],
    /// The pink blob's pixels.
    pub pixels: u32,
    /// Of the nine regions, how many lie wholly inside the image.
    pub regions_in_image: usize,
    /// The ray to the blob's centre in the robot's ground frame, when the camera pose was
    /// known (joint readings); learning needs it.
    pub ray: Option<GroundRay>,
    /// The rolling shutter's horizontal shear while the frame was read (pixels per row, from
    /// the pan): the regions above and below are shifted by it, as the image shows them.
    #[serde(default)]
    pub shear_px_per_row: f64,
}

impl PatternObservation {
    /// Region `k`'s box (0..9, row by row), inclusive pixels `[minx, miny, maxx, maxy]`; it
    /// may reach outside the image. Regions are the pink blob's size side by side, the rows
    /// above and below moved along the shear. (Taking the shear out of their width as well
    /// measured worse: the pink blob's rim is often lost, so its box is narrower already.)
    #[must_use]
    pub fn region_bounds(&self, k: usize) -> [i64; 4] {
        let [x0, y0, x1, y1] = self.bounds.map(i64::from);
        let (w, h) = (x1 - x0 + 1, y1 - y0 + 1);
        let shear = if self.shear_px_per_row.is_finite() {
            self.shear_px_per_row
        } else {
            0.0
        };
        let (gx, gy) = ((k % 3) as i64 - 1, (k / 3) as i64 - 1);
        let dx = gx * w + (shear * (gy * h) as f64).round() as i64;
        [x0 + dx, y0 + gy * h, x1 + dx, y1 + gy * h]
    }

    /// The blob's box centre, image pixels.
    #[must_use]
    pub fn centre(&self) -> (f64, f64) {
        let [x0, y0, x1, y1] = self.bounds.map(f64::from);
        ((x0 + x1 + 1.0) / 2.0, (y0 + y1 + 1.0) / 2.0)
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

/// The distance assumed for removing the rolling shutter's skew from a marker before its
/// distance is known, centimetres.
const ASSUMED_DISTANCE_CM: f64 = 200.0;

/// Regions larger than this many pixels are sampled on a grid instead of read whole, so a close
/// marker costs no more than a middling one.
const REGION_SAMPLES: i64 = 128;

/// Signatures of the pink markers in a classified frame, leaving out pink blobs inside any of
/// the boxes `except` (inclusive `[minx, miny, maxx, maxy]`: accepted beacons, whose bands are
/// theirs).
#[must_use]
pub fn observe(
    img: &ClassifiedImage,
    blobs: &BlobSet,
    ctx: &ViewContext,
    params: &PatternParams,
    except: &[[u32; 4]],
) -> Vec<PatternObservation> {
    blobs
        .of_class(ColourClass::Pink)
        .filter(|b| b.pixels >= params.min_pixels)
        .filter(|b| {
            let own = [b.minx, b.miny, b.maxx, b.maxy];
            !except.iter().any(|e| inside(own, *e))
        })
        .map(|b| observe_blob(img, b, ctx))
        .collect()
}

/// Whether the inclusive box `a` lies within the inclusive box `b` (both `[minx, miny, maxx,
/// maxy]`).
#[must_use]
pub fn inside(a: [u32; 4], b: [u32; 4]) -> bool {
    a[0] >= b[0] && a[1] >= b[1] && a[2] <= b[2] && a[3] <= b[3]
}

/// The two most common class codes in the inclusive box `[x0, y0, x1, y1]` (clipped to the
/// image) and whether the box lies wholly inside the image.
fn region_colours(img: &ClassifiedImage, [x0, y0, x1, y1]: [i64; 4]) -> ([u8; 2], bool) {
    let (w, h) = (img.width() as i64, img.height() as i64);
    let inside = x0 >= 0 && y0 >= 0 && x1 < w && y1 < h;
    let (cx0, cy0, cx1, cy1) = (x0.max(0), y0.max(0), x1.min(w - 1), y1.min(h - 1));
    let mut counts = [0u32; 16];
    if cx0 <= cx1 && cy0 <= cy1 {
        let area = (x1 - x0 + 1) * (y1 - y0 + 1);
        let mut step = 1;
        while area / (step * step) > REGION_SAMPLES {
            step += 1;
        }
        // Clipped to the image above, so the conversions hold.
        let (from, to) = (cx0 as usize, cx1 as usize);
        let stride = step as usize;
        for y in (cy0 as usize..=cy1 as usize).step_by(stride) {
            if let Some(run) = img.row(y).get(from..=to) {
                for &c in run.iter().step_by(stride) {
                    if let Some(n) = counts.get_mut(usize::from(c)) {
                        *n += 1;
                    }
                }
            }
        }
    }
    counts[0] = 0;
    let (mut first, mut second) = (0u8, 0u8);
    for code in 1..16u8 {
        let n = counts[usize::from(code)];
        if n == 0 {
            continue;
        }
        if n > counts[usize::from(first)] || first == 0 {
            second = first;
            first = code;
        } else if n > counts[usize::from(second)] || second == 0 {
            second = code;
        }
    }
    ([first, second], inside)
}

/// The mean height of the blob's columns (see [`PatternObservation::size_px`]), pixels.
fn column_height(img: &ClassifiedImage, b: &Blob) -> f64 {
    let (x0, x1) = (b.minx as usize, b.maxx as usize);
    let mut extents = vec![(u32::MAX, 0u32); x1 - x0 + 1];
    for y in b.miny..=b.maxy {
        let row = img.row(y as usize);
        for (e, &c) in extents.iter_mut().zip(row.get(x0..=x1).unwrap_or(&[])) {
            if c == b.colour {
                *e = (e.0.min(y), e.1.max(y));
            }
        }
    }
    let heights: Vec<u32> = extents
        .iter()
        .filter(|e| e.0 <= e.1)
        .map(|e| e.1 - e.0 + 1)
        .collect();
    let tallest = heights.iter().copied().max().unwrap_or(0);
    let (sum, n) = heights
        .iter()
        .filter(|&&h| 5 * h >= 3 * tallest)
        .fold((0u32, 0u32), |(s, n), &h| (s + h, n + 1));
    if n == 0 {
        f64::from(b.height())
    } else {
        f64::from(sum) / f64::from(n)
    }
}

fn observe_blob(img: &ClassifiedImage, b: &Blob, ctx: &ViewContext) -> PatternObservation {
    let mut obs = PatternObservation {
        signature: Signature([[0; 2]; 9]),
        size_px: column_height(img, b),
        bearing_rad: 0.0,
        elevation_rad: 0.0,
        bounds: [b.minx, b.miny, b.maxx, b.maxy],
        pixels: b.pixels,
        regions_in_image: 0,
        ray: None,
        shear_px_per_row: 0.0,
    };
    // The rolling shutter through the body model (the linear shear of the pan formula grows
    // with tan² of the pan angle and is far too large towards the sides); the distance only
    // matters for the camera's own motion, so a typical one does.
    let seen = obs.centre();
    let centre = ctx.unskew_at(seen, ASSUMED_DISTANCE_CM, true);
    let below = ctx.unskew_at((seen.0, seen.1 + 1.0), ASSUMED_DISTANCE_CM, true);
    if (centre.0 - below.0).is_finite() {
        obs.shear_px_per_row = centre.0 - below.0;
    }
    for k in 0..9 {
        let (colours, inside) = region_colours(img, obs.region_bounds(k));
        obs.signature.0[k] = colours;
        obs.regions_in_image += usize::from(inside);
    }
    (obs.bearing_rad, obs.elevation_rad) = ctx.camera_angles(centre);
    obs.ray = ctx.pose.map(|pose| {
        let p = ImagePoint::new(centre.0, centre.1);
        let o = pose.position();
        let d = pose.field_ray(p).coords;
        GroundRay {
            origin_cm: [o.x(), o.y(), o.z()],
            direction: [d.x, d.y, d.z],
        }
    });
    obs
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
        let sigma = 1.4826 * median(residuals.clone());
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
        if samples.len() < 2 {
            return None;
        }
        let n = samples.len() as f64;
        let (mx, my) = samples
            .iter()
            .fold((0.0, 0.0), |(a, b), s| (a + 1.0 / s[0] / n, b + s[1] / n));
        let (sxx, sxy) = samples.iter().fold((0.0, 0.0), |(a, b), s| {
            let dx = 1.0 / s[0] - mx;
            (a + dx * dx, b + dx * (s[1] - my))
        });
        if sxx.is_nan() || sxx <= 1e-18 {
            return None;
        }
        let m = sxy / sxx;
        let o = my - m * mx;
        let ss: f64 = samples.iter().map(|s| (m / s[0] + o - s[1]).powi(2)).sum();
        Some(Self {
            multiplier_cm_px: m,
            offset_cm: o,
            residual_cm: (ss / n).sqrt(),
            samples: samples.len(),
        })
        .filter(|r| r.multiplier_cm_px.is_finite() && r.offset_cm.is_finite())
    }
}

/// The `format` of a places file.
pub const PLACES_FORMAT: &str = "eotn.places";
/// The places-file version this build writes and reads.
pub const PLACES_VERSION: u32 = 1;

fn places_format() -> String {
    PLACES_FORMAT.to_owned()
}

const fn places_version() -> u32 {
    PLACES_VERSION
}

/// What the recogniser has learnt: the places file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PatternMemory {
    /// Always [`PLACES_FORMAT`].
    #[serde(default = "places_format")]
    pub format: String,
    /// [`PLACES_VERSION`].
    #[serde(default = "places_version")]
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
            format: places_format(),
            version: PLACES_VERSION,
            objects: Vec::new(),
            relation: None,
            samples: Vec::new(),
        }
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

/// Why a places file could not be read or written; every message names the file.
#[derive(Debug, Error)]
pub enum PlacesError {
    /// Reading or writing failed.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// What the system said.
        source: std::io::Error,
    },
    /// Not JSON of the places shape.
    #[error("{path}: not a places file ({source})")]
    Parse {
        /// The file.
        path: PathBuf,
        /// Where and why parsing stopped.
        source: serde_json::Error,
    },
    /// JSON of the right shape with values that make no sense.
    #[error("{path}: {problem}")]
    Invalid {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        problem: String,
    },
}

impl PatternMemory {
    /// Reads a places file written by [`Self::save`] (`eotn patterns learn`), checking every
    /// field: format and version, unique ids, finite positions, class codes, a relation whose
    /// distances shrink with size.
    ///
    /// # Errors
    /// [`PlacesError`] naming the file and the problem.
    pub fn load(path: &Path) -> Result<Self, PlacesError> {
        let text = std::fs::read_to_string(path).map_err(|source| PlacesError::Io {
            path: path.to_owned(),
            source,
        })?;
        Self::from_json(&text).map_err(|e| match e {
            PlacesError::Parse { source, .. } => PlacesError::Parse {
                path: path.to_owned(),
                source,
            },
            PlacesError::Invalid { problem, .. } => PlacesError::Invalid {
                path: path.to_owned(),
                problem,
            },
            other @ PlacesError::Io { .. } => other,
        })
    }

    /// Parses and checks places JSON (see [`Self::load`]); errors name no file.
    ///
    /// # Errors
    /// [`PlacesError::Parse`] or [`PlacesError::Invalid`] with an empty path.
    pub fn from_json(text: &str) -> Result<Self, PlacesError> {
        let memory: Self = serde_json::from_str(text).map_err(|source| PlacesError::Parse {
            path: PathBuf::new(),
            source,
        })?;
        memory.check().map_err(|problem| PlacesError::Invalid {
            path: PathBuf::new(),
            problem,
        })?;
        Ok(memory)
    }

    fn check(&self) -> Result<(), String> {
        if self.format != PLACES_FORMAT {
            return Err(format!(
                "format is {:?}, not {PLACES_FORMAT:?}",
                self.format
            ));
        }
        if self.version != PLACES_VERSION {
            return Err(format!(
                "places version {} (this eotn reads version {PLACES_VERSION})",
                self.version
            ));
        }
        let mut ids: Vec<usize> = self.objects.iter().map(|o| o.id).collect();
        ids.sort_unstable();
        if let Some(w) = ids.windows(2).find(|w| w[0] == w[1]) {
            return Err(format!("object id {} appears twice", w[0]));
        }
        for o in &self.objects {
            if !o.field_cm.iter().all(|v| v.is_finite()) {
                return Err(format!("object {}: position is not a number", o.id));
            }
            if o.height_cm.is_some_and(|h| !h.is_finite()) {
                return Err(format!("object {}: height is not a number", o.id));
            }
            if o.patterns.is_empty() {
                return Err(format!("object {}: no patterns", o.id));
            }
            for p in &o.patterns {
                if let Some(c) =
                    p.0.iter()
                        .flatten()
                        .find(|&&c| ColourClass::from_code(c).is_none())
                {
                    return Err(format!("object {}: {c} is not a class code", o.id));
                }
            }
        }
        if let Some(r) = &self.relation
            && !(r.multiplier_cm_px.is_finite()
                && r.multiplier_cm_px > 0.0
                && r.offset_cm.is_finite())
        {
            return Err(format!(
                "size relation distance = {} / size + {} is not a relation (the multiplier \
                 must be a positive number)",
                r.multiplier_cm_px, r.offset_cm
            ));
        }
        Ok(())
    }

    /// Writes the places file atomically (temporary file, fsync, rename), pretty-printed.
    ///
    /// # Errors
    /// [`PlacesError::Io`] naming the file.
    pub fn save(&self, path: &Path) -> Result<(), PlacesError> {
        let io = |source| PlacesError::Io {
            path: path.to_owned(),
            source,
        };
        let json = serde_json::to_vec_pretty(self).map_err(|e| io(std::io::Error::other(e)))?;
        crate::atomic_file::write_atomic(path, &json).map_err(io)
    }

    /// The object with this id.
    #[must_use]
    pub fn object(&self, id: usize) -> Option<&PatternObject> {
        self.objects.iter().find(|o| o.id == id)
    }

    /// The best-agreeing object and the best other one: by agreement, then by regions sharing
    /// both colours.
    fn ranked(&self, sig: &Signature) -> (Option<Closest>, Option<Closest>) {
        let mut scores: Vec<Closest> = self
            .objects
            .iter()
            .filter_map(|o| {
                o.patterns
                    .iter()
                    .map(|p| Closest {
                        id: o.id,
                        agreement: p.agreement(sig),
                        both_colours: p.both_colours_agreement(sig),
                    })
                    .max_by_key(|c| (c.agreement, c.both_colours))
            })
            .collect();
        scores.sort_by_key(|c| std::cmp::Reverse((c.agreement, c.both_colours)));
        (scores.first().copied(), scores.get(1).copied())
    }

    /// Identification phase: the best stored object with at least
    /// [`PatternParams::min_agreement`] agreeing regions, unless another object agrees as well
    /// (same agreement and same both-colour score) or the observation shows too few coloured
    /// regions to be a place.
    #[must_use]
    pub fn identify(
        &self,
        obs: &PatternObservation,
        params: &PatternParams,
    ) -> Option<PatternMatch> {
        let (best, next) = self.ranked(&obs.signature);
        self.identify_ranked(obs, best, next, params)
    }

    fn identify_ranked(
        &self,
        obs: &PatternObservation,
        best: Option<Closest>,
        next: Option<Closest>,
        params: &PatternParams,
    ) -> Option<PatternMatch> {
        let best = best?;
        let tied = next
            .is_some_and(|n| (n.agreement, n.both_colours) == (best.agreement, best.both_colours));
        (best.agreement >= params.min_agreement
            && !tied
            && obs.signature.coloured_regions() >= params.min_coloured_regions)
            .then(|| PatternMatch {
                id: best.id,
                agreement: best.agreement,
                both_colours: best.both_colours,
                distance_cm: self.relation.and_then(|r| r.distance_cm(obs.size_px)),
            })
    }

    /// An observation as a candidate: identified against this memory (or not, with `None`),
    /// with its confidence breakdown and placement.
    #[must_use]
    pub fn candidate(
        memory: Option<&Self>,
        obs: PatternObservation,
        ctx: &ViewContext,
        params: &PatternParams,
    ) -> PatternCandidate {
        let cut_off = obs.regions_in_image < 9;
        let mut c = PatternCandidate {
            observation: obs,
            identification: None,
            closest: None,
            runner_up: None,
            camera: None,
            body: None,
            cut_off,
            ambiguous: false,
            confidence: Confidence::default(),
            accepted: false,
        };
        let Some(memory) = memory else {
            return c;
        };
        let (best, next) = memory.ranked(&obs.signature);
        c.closest = best;
        c.runner_up = next;
        let conf = &mut c.confidence;
        let coloured = obs.signature.coloured_regions();
        conf.range_test(
            "coloured_regions",
            coloured as f64,
            [params.min_coloured_regions as f64, 9.0],
            params.coloured_weight,
        );
        let agreement = best.map_or(0, |b| b.agreement);
        conf.range_test(
            "agreement",
            agreement as f64,
            [params.min_agreement as f64, 9.0],
            params.agreement_weight,
        );
        match (best, next) {
            (Some(b), Some(n)) => {
                // Regions apart, with the both-colour score as the fraction that breaks ties.
                let margin = (b.agreement - n.agreement) as f64
                    + 0.1 * (b.both_colours as f64 - n.both_colours as f64);
                c.ambiguous = margin <= 0.0;
                conf.range_test("margin", margin, [0.1, 9.0], params.margin_weight);
            }
            _ => conf.skipped("margin", [0.1, 9.0]),
        }
        c.identification = memory.identify_ranked(&obs, best, next, params);
        c.accepted = c.identification.is_some() && c.confidence.accepted();
        if !c.accepted {
            c.identification = None;
        }
        if let Some(d) = c.identification.and_then(|m| m.distance_cm) {
            let centre = ctx.unskew_at(obs.centre(), d, true);
            c.camera = Some(ctx.camera_relative(centre, d));
            c.body = ctx.body_relative(centre, d);
        }
        c
    }
}

/// Drawing primitives of the pattern candidates: the nine regions of each pink marker in their
/// most common colour (dashed where they disagree with the identified place), and a label with
/// the place and its distance.
#[must_use]
pub fn pattern_primitives(candidates: &[PatternCandidate]) -> Vec<Primitive> {
    let mut out = Vec::new();
    for (i, c) in candidates.iter().enumerate() {
        let owner = owner::pattern(i);
        let obs = &c.observation;
        for k in 0..9 {
            out.push(Primitive::PatternRegion {
                owner: owner.clone(),
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
            at: (x0.max(0) as f64, (y0 as f64 - 2.0).max(8.0)),
            text,
        });
    }
    out
}

/// Settings of the learning phase.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct LearnParams {
    /// A group of views placed within this distance of a known object adds its signature to
    /// that object instead of making a new one, centimetres.
    pub same_object_cm: f64,
    /// Views a group needs to be learnt.
    pub min_views: usize,
    /// Smallest spread of the bearing rays for triangulation, degrees: below it the baseline
    /// is too short and the position comes from the size relation.
    pub min_spread_deg: f64,
    /// A ray passing farther than this from the triangulated position is dropped as an
    /// outlier (and may form another object), centimetres.
    pub outlier_cm: f64,
}

impl Default for LearnParams {
    fn default() -> Self {
        Self {
            same_object_cm: 30.0,
            min_views: 4,
            min_spread_deg: 4.0,
            outlier_cm: 20.0,
        }
    }
}

/// One observation with the robot's pose when it was made: the input of learning.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LearnView {
    /// Where the view came from (frame number across the inputs), for the report.
    pub frame: usize,
    /// The robot's field pose.
    pub robot: RobotPose,
    /// What was seen.
    pub observation: PatternObservation,
}

/// A least-squares intersection of rays on the ground.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Triangulation {
    /// The point, field centimetres.
    pub field_cm: [f64; 2],
    /// Root mean square distance of the rays from it, centimetres.
    pub residual_cm: f64,
    /// Spread of the ray directions, degrees (the angle two rays would need to give the same
    /// conditioning).
    pub spread_deg: f64,
}

/// The point closest to every ray on the ground in the weighted least-squares sense (`weights`
/// per ray; perpendicular distances), or `None` when the rays are (nearly) parallel or the point
/// lies behind one of them.
#[must_use]
pub fn triangulate(rays: &[FieldRay], weights: &[f64]) -> Option<Triangulation> {
    let t = least_squares_point(rays, weights)?;
    rays.iter()
        .all(|r| along_and_across(r, t.field_cm).0 > 0.0)
        .then_some(t)
}

/// [`triangulate`] without the check that the point lies ahead of every ray (robust
/// triangulation drops the rays it lies behind).
fn least_squares_point(rays: &[FieldRay], weights: &[f64]) -> Option<Triangulation> {
    if rays.len() < 2 || weights.len() != rays.len() {
        return None;
    }
    let (mut a, mut b, mut total) = ([[0.0f64; 2]; 2], [0.0f64; 2], 0.0);
    for (r, &w) in rays.iter().zip(weights) {
        let n = [-r.heading_rad.sin(), r.heading_rad.cos()];
        let no = n[0] * r.origin_cm[0] + n[1] * r.origin_cm[1];
        for i in 0..2 {
            for j in 0..2 {
                a[i][j] += w * n[i] * n[j];
            }
            b[i] += w * n[i] * no;
        }
        total += w;
    }
    let det = a[0][0] * a[1][1] - a[0][1] * a[1][0];
    let trace = a[0][0] + a[1][1];
    if !(total > 0.0 && det.is_finite()) {
        return None;
    }
    // Smaller eigenvalue over the total weight = sin²(spread / 2) for two rays.
    let lambda_min = trace / 2.0 - ((trace / 2.0).powi(2) - det).max(0.0).sqrt();
    let spread_deg = 2.0
        * (lambda_min / total)
            .clamp(0.0, 1.0)
            .sqrt()
            .asin()
            .to_degrees();
    if det.abs() < 1e-12 * total * total {
        return None;
    }
    let p = [
        (a[1][1] * b[0] - a[0][1] * b[1]) / det,
        (a[0][0] * b[1] - a[1][0] * b[0]) / det,
    ];
    let ss: f64 = rays.iter().map(|r| along_and_across(r, p).1.powi(2)).sum();
    Some(Triangulation {
        field_cm: p,
        residual_cm: (ss / rays.len() as f64).sqrt(),
        spread_deg,
    })
    .filter(|t| t.field_cm.iter().all(|v| v.is_finite()))
}

/// Distance on the ground from a ray's origin to a point, and the point's perpendicular
/// distance from the ray (centimetres); the first is negative behind the ray.
fn along_and_across(r: &FieldRay, p: [f64; 2]) -> (f64, f64) {
    let (dx, dy) = (p[0] - r.origin_cm[0], p[1] - r.origin_cm[1]);
    let (s, c) = r.heading_rad.sin_cos();
    (c * dx + s * dy, (-s * dx + c * dy).abs())
}

/// What one learning run did.
#[derive(Debug, Clone, PartialEq, Default, Serialize)]
pub struct LearnReport {
    /// Views given.
    pub views: usize,
    /// Views without a camera pose (no joint readings): they have no ray.
    pub views_without_ray: usize,
    /// Views with too little colour around the pink to be a place.
    pub views_without_colour: usize,
    /// Objects made new.
    pub objects_created: Vec<usize>,
    /// Objects that got another pattern.
    pub patterns_added: Vec<usize>,
    /// Objects whose further pattern was refused as too close to another object's (within one
    /// region of a match).
    pub patterns_refused: Vec<usize>,
    /// Views added to an object whose pattern they already matched.
    pub views_merged: usize,
    /// Groups that could not be learnt, with the reason.
    pub groups_dropped: Vec<String>,
    /// Pairs of objects whose patterns match each other: identification cannot tell them
    /// apart.
    pub indistinct: Vec<(usize, usize)>,
}

/// A group's result before it is merged into the memory.
#[derive(Debug, Clone, Copy)]
struct Learnt {
    /// The group's consensus signature.
    signature: Signature,
    /// Where it was placed, field centimetres.
    at: [f64; 2],
    /// Its height, centimetres (triangulated groups).
    height: Option<f64>,
    /// Views in the group.
    views: usize,
    /// How it was placed.
    placed_by: Placement,
    /// Triangulation residual, centimetres.
    residual_cm: f64,
}

/// A group of views taken to show one marker.
#[derive(Debug, Clone)]
struct Group {
    views: Vec<(FieldRay, PatternObservation)>,
}

impl Group {
    /// The region-by-region consensus: each region's most common first colour and, among views
    /// with it, the most common second colour.
    fn consensus(&self) -> Signature {
        let mut out = [[0u8; 2]; 9];
        for (k, slot) in out.iter_mut().enumerate() {
            let mut first = [0usize; 16];
            for (_, o) in &self.views {
                if let Some(n) = first.get_mut(usize::from(o.signature.0[k][0])) {
                    *n += 1;
                }
            }
            let top = (0..16u8)
                .max_by_key(|&c| (first[usize::from(c)], std::cmp::Reverse(c)))
                .unwrap_or(0);
            let mut second = [0usize; 16];
            for (_, o) in self
                .views
                .iter()
                .filter(|(_, o)| o.signature.0[k][0] == top)
            {
                if let Some(n) = second.get_mut(usize::from(o.signature.0[k][1])) {
                    *n += 1;
                }
            }
            let next = (0..16u8)
                .max_by_key(|&c| (second[usize::from(c)], std::cmp::Reverse(c)))
                .unwrap_or(0);
            *slot = [top, next];
        }
        Signature(out)
    }

    /// Robust triangulation: weighted so that every ray's angle counts alike (weights 1 /
    /// distance²), the worst ray dropped while it passes farther than `outlier_cm`. Returns the
    /// result and the dropped views.
    fn triangulate(
        &mut self,
        p: &LearnParams,
    ) -> (Option<Triangulation>, Vec<(FieldRay, PatternObservation)>) {
        let mut dropped = Vec::new();
        loop {
            let rays: Vec<FieldRay> = self.views.iter().map(|v| v.0).collect();
            let mut weights = vec![1.0; rays.len()];
            let mut t = least_squares_point(&rays, &weights);
            for _ in 0..3 {
                let Some(tt) = t else { break };
                for (w, r) in weights.iter_mut().zip(&rays) {
                    let (along, _) = along_and_across(r, tt.field_cm);
                    *w = 1.0 / along.max(20.0).powi(2);
                }
                t = least_squares_point(&rays, &weights).or(t);
            }
            let Some(tt) = t else {
                return (None, dropped);
            };
            // The worst ray: one the point lies behind, else the one passing farthest off.
            let worst = rays
                .iter()
                .enumerate()
                .map(|(i, r)| {
                    let (along, across) = along_and_across(r, tt.field_cm);
                    (i, if along <= 0.0 { f64::INFINITY } else { across })
                })
                .max_by(|a, b| a.1.total_cmp(&b.1));
            match worst {
                Some((i, off)) if off > p.outlier_cm && self.views.len() > 2 => {
                    dropped.push(self.views.swap_remove(i));
                }
                Some((_, off)) if off.is_infinite() => return (None, dropped),
                _ => return (Some(tt), dropped),
            }
        }
    }
}

/// Theil–Sen line d = m · (1 / s) + o through `(s, d)` samples: m the median of the pairwise
/// slopes (at most about 250 000 pairs, evenly picked), o the median of d − m / s.
fn theil_sen(samples: &[[f64; 2]]) -> Option<(f64, f64)> {
    let n = samples.len();
    if n < 2 {
        return None;
    }
    let stride = (n * n / 2 / 250_000).max(1);
    let mut slopes = Vec::new();
    let mut k = 0usize;
    for i in 0..n {
        for j in i + 1..n {
            k += 1;
            if !k.is_multiple_of(stride) {
                continue;
            }
            let dx = 1.0 / samples[j][0] - 1.0 / samples[i][0];
            if dx.abs() > 1e-12 {
                slopes.push((samples[j][1] - samples[i][1]) / dx);
            }
        }
    }
    if slopes.is_empty() {
        return None;
    }
    let m = median(slopes);
    let o = median(samples.iter().map(|s| s[1] - m / s[0]).collect());
    (m.is_finite() && o.is_finite()).then_some((m, o))
}

/// Median of a list (0 for none).
fn median(mut v: Vec<f64>) -> f64 {
    if v.is_empty() {
        return 0.0;
    }
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

impl PatternMemory {
    /// Learning phase: adds what `views` show to the memory (see the module documentation) and
    /// refits the size relation over every sample learnt so far.
    pub fn learn(
        &mut self,
        views: &[LearnView],
        recognition: &PatternParams,
        p: &LearnParams,
    ) -> LearnReport {
        let mut report = LearnReport {
            views: views.len(),
            ..LearnReport::default()
        };
        // Group by signature.
        let mut groups: Vec<Group> = Vec::new();
        for v in views {
            let Some(ray) = v.observation.ray else {
                report.views_without_ray += 1;
                continue;
            };
            if v.observation.signature.coloured_regions() < recognition.min_coloured_regions {
                report.views_without_colour += 1;
                continue;
            }
            let item = (ray.in_field(&v.robot), v.observation);
            let sig = v.observation.signature;
            let best = groups
                .iter_mut()
                .map(|g| {
                    let a = g.views[0].1.signature.agreement(&sig);
                    (a, g)
                })
                .filter(|(a, _)| *a >= recognition.min_agreement)
                .max_by_key(|(a, _)| *a);
            match best {
                Some((_, g)) => g.views.push(item),
                None => groups.push(Group { views: vec![item] }),
            }
        }
        // Triangulate; rays that do not fit form groups of their own (the same signature at
        // another place, or a view grouped with the wrong near-twin).
        let mut placed: Vec<(Group, Triangulation)> = Vec::new();
        let mut narrow: Vec<Group> = Vec::new();
        let mut queue = groups;
        let mut rounds = 0;
        while let Some(mut g) = queue.pop() {
            rounds += 1;
            if g.views.len() < p.min_views || rounds > 10_000 {
                report.groups_dropped.push(format!(
                    "{} view(s) of {}: fewer than {}",
                    g.views.len(),
                    g.consensus().short_text(),
                    p.min_views
                ));
                continue;
            }
            let (t, dropped) = g.triangulate(p);
            if dropped.len() >= p.min_views.max(1) {
                queue.push(Group { views: dropped });
            } else if !dropped.is_empty() {
                report.groups_dropped.push(format!(
                    "{} outlier view(s) of {}",
                    dropped.len(),
                    g.consensus().short_text()
                ));
            }
            match t {
                Some(t) if t.spread_deg >= p.min_spread_deg && g.views.len() >= p.min_views => {
                    placed.push((g, t));
                }
                _ => narrow.push(g),
            }
        }
        // Size samples from every view of a triangulated marker.
        let mut heights = Vec::new();
        for (g, t) in &placed {
            let mut zs = Vec::new();
            for (r, _) in &g.views {
                let (along, _) = along_and_across(r, t.field_cm);
                zs.push(r.origin_cm[2] + along * r.slope);
            }
            let z = median(zs);
            heights.push(z);
            for (r, o) in &g.views {
                let (along, _) = along_and_across(r, t.field_cm);
                let d = along.hypot(z - r.origin_cm[2]);
                self.samples.push([o.size_px, d]);
            }
        }
        self.relation = SizeRelation::fit(&self.samples).or(self.relation);
        // Objects from triangulated groups, then from narrow ones placed by size.
        let mut learnt: Vec<Learnt> = placed
            .iter()
            .zip(&heights)
            .map(|((g, t), &z)| Learnt {
                signature: g.consensus(),
                at: t.field_cm,
                height: Some(z),
                views: g.views.len(),
                placed_by: Placement::Triangulation,
                residual_cm: t.residual_cm,
            })
            .collect();
        for g in narrow {
            let Some(rel) = self.relation else {
                report.groups_dropped.push(format!(
                    "{} view(s) of {}: baseline too short to triangulate and no size relation",
                    g.views.len(),
                    g.consensus().short_text()
                ));
                continue;
            };
            let (mut xs, mut ys) = (Vec::new(), Vec::new());
            for (r, o) in &g.views {
                if let Some(d) = rel.distance_cm(o.size_px) {
                    let ground = d / r.slope.hypot(1.0);
                    xs.push(r.origin_cm[0] + ground * r.heading_rad.cos());
                    ys.push(r.origin_cm[1] + ground * r.heading_rad.sin());
                }
            }
            if xs.is_empty() {
                continue;
            }
            learnt.push(Learnt {
                signature: g.consensus(),
                at: [median(xs), median(ys)],
                height: None,
                views: g.views.len(),
                placed_by: Placement::SizeRelation,
                residual_cm: 0.0,
            });
        }
        // Merge into the memory, the best-seen groups first: they place the objects, groups
        // merged into them later only add their patterns (a handful of views of a cut or
        // misread marker would only pull a well-triangulated position off).
        learnt.sort_by_key(|l| {
            (
                l.placed_by != Placement::Triangulation,
                std::cmp::Reverse(l.views),
            )
        });
        for l in learnt {
            let Learnt {
                signature: sig,
                at,
                height,
                views: n,
                placed_by: how,
                residual_cm: residual,
            } = l;
            let near = self
                .objects
                .iter_mut()
                .filter(|o| {
                    (o.field_cm[0] - at[0]).hypot(o.field_cm[1] - at[1]) <= p.same_object_cm
                })
                .min_by(|a, b| {
                    let d =
                        |o: &PatternObject| (o.field_cm[0] - at[0]).hypot(o.field_cm[1] - at[1]);
                    d(a).total_cmp(&d(b))
                });
            match near {
                Some(o) => {
                    if o.patterns
                        .iter()
                        .any(|q| q.agreement(&sig) >= recognition.min_agreement)
                    {
                        report.views_merged += n;
                    } else {
                        o.patterns.push(sig);
                        report.patterns_added.push(o.id);
                    }
                    // A size-placed object (from an earlier run) takes a triangulated position.
                    if how == Placement::Triangulation && o.placed_by == Placement::SizeRelation {
                        o.field_cm = at;
                        o.height_cm = height;
                        o.placed_by = how;
                        o.residual_cm = residual;
                    }
                    o.views += n;
                }
                None => {
                    let id = self.objects.iter().map(|o| o.id + 1).max().unwrap_or(0);
                    self.objects.push(PatternObject {
                        id,
                        field_cm: at,
                        height_cm: height,
                        patterns: vec![sig],
                        views: n,
                        placed_by: how,
                        residual_cm: residual,
                    });
                    report.objects_created.push(id);
                }
            }
        }
        // A further pattern of an object that comes within one region of another object's
        // pattern is refused: it would let a single misread region of the other object's marker
        // be identified as this one (a cut or misread view of one of two near-twin markers
        // otherwise becomes the other twin's pattern). Each object keeps its first pattern.
        let near_miss = recognition.min_agreement.saturating_sub(1);
        let snapshot: Vec<(usize, Vec<Signature>)> = self
            .objects
            .iter()
            .map(|o| (o.id, o.patterns.clone()))
            .collect();
        for o in &mut self.objects {
            let id = o.id;
            let mut k = 0;
            o.patterns.retain(|sig| {
                k += 1;
                let close = snapshot.iter().any(|(other, pats)| {
                    *other != id && pats.iter().any(|q| q.agreement(sig) >= near_miss)
                });
                let keep = k == 1 || !close;
                if !keep {
                    report.patterns_refused.push(id);
                }
                keep
            });
        }
        for (i, a) in self.objects.iter().enumerate() {
            for b in &self.objects[i + 1..] {
                let matches = a.patterns.iter().any(|x| {
                    b.patterns
                        .iter()
                        .any(|y| x.agreement(y) >= recognition.min_agreement)
                });
                if matches {
                    report.indistinct.push((a.id, b.id));
                }
            }
        }
        report
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::blobs::Connectivity;
    use crate::geometry::PinholeCamera;

    /// A 3×3 arrangement of coloured tiles of `tile` pixels with pink in the middle.
    fn tiles(colours: [ColourClass; 9], tile: usize, x0: usize, y0: usize) -> ClassifiedImage {
        let (w, h) = (208, 160);
        let mut codes = vec![ColourClass::Green.code(); w * h];
        for (k, c) in colours.iter().enumerate() {
            let (gx, gy) = (k % 3, k / 3);
            for y in 0..tile {
                for x in 0..tile {
                    let (px, py) = (x0 + gx * tile + x, y0 + gy * tile + y);
                    if px < w && py < h {
                        codes[py * w + px] = c.code();
                    }
                }
            }
        }
        ClassifiedImage::from_codes(w, h, codes).expect("size")
    }

    const PLACE: [ColourClass; 9] = [
        ColourClass::White,
        ColourClass::Yellow,
        ColourClass::White,
        ColourClass::SkyBlue,
        ColourClass::Pink,
        ColourClass::Yellow,
        ColourClass::White,
        ColourClass::Black,
        ColourClass::White,
    ];

    fn ctx() -> ViewContext {
        ViewContext::without_pose(PinholeCamera::ers7())
    }

    fn one(img: &ClassifiedImage) -> PatternObservation {
        let blobs = BlobSet::from_image(img, Connectivity::Four);
        let obs = observe(img, &blobs, &ctx(), &PatternParams::default(), &[]);
        assert_eq!(obs.len(), 1);
        obs[0]
    }

    /// A ray from `from` (field cm, 20 cm up) through the point `to` (field cm).
    fn ray(from: [f64; 2], to: [f64; 2]) -> FieldRay {
        FieldRay {
            origin_cm: [from[0], from[1], 20.0],
            heading_rad: (to[1] - from[1]).atan2(to[0] - from[0]),
            slope: 0.0,
        }
    }

    #[test]
    fn signatures_read_the_nine_regions() {
        let obs = one(&tiles(PLACE, 10, 60, 40));
        let firsts: Vec<u8> = obs.signature.0.iter().map(|r| r[0]).collect();
        let want: Vec<u8> = PLACE.iter().map(|c| c.code()).collect();
        assert_eq!(firsts, want);
        assert_eq!(obs.regions_in_image, 9);
        assert!((obs.size_px - 10.0).abs() < 1e-9);
        assert_eq!(obs.region_bounds(0), [60, 40, 69, 49]);
        assert_eq!(obs.region_bounds(8), [80, 60, 89, 69]);
        assert!(obs.ray.is_none(), "no camera pose without joints");
        // A pink square at the left edge: the left column of regions is outside, "nothing".
        let mut codes = vec![ColourClass::Green.code(); 208 * 160];
        for y in 50..60 {
            for x in 0..10 {
                codes[y * 208 + x] = ColourClass::Pink.code();
            }
        }
        let cut = one(&ClassifiedImage::from_codes(208, 160, codes).expect("size"));
        assert_eq!(cut.regions_in_image, 6);
        assert_eq!(cut.signature.0[3], [0, 0], "outside the image: nothing");
        assert_eq!(cut.signature.0[5], [ColourClass::Green.code(), 0]);
    }

    #[test]
    fn regions_follow_the_rolling_shutter_shear() {
        // The tiles of a pan at 0.5 px per row: each row half a pixel further right.
        let (w, h, t, shear) = (208usize, 160usize, 10.0, 0.5);
        let mut codes = vec![ColourClass::Green.code(); w * h];
        for y in 30..60 {
            for x in 0..w {
                let u = x as f64 - 60.0 - shear * (y as f64 - 45.0);
                let col = (u / t).floor();
                if (0.0..3.0).contains(&col) {
                    let k = ((y - 30) / 10) * 3 + col as usize;
                    codes[y * w + x] = PLACE[k].code();
                }
            }
        }
        let img = ClassifiedImage::from_codes(w, h, codes).expect("size");
        let blobs = BlobSet::from_image(&img, Connectivity::Four);
        let mut panning = ctx();
        // The pan during one read-out that shifts rows near the image centre by `shear` px each.
        panning.pan_per_readout_rad = shear * h as f64 / panning.camera.focal_px;
        let obs = observe(&img, &blobs, &panning, &PatternParams::default(), &[]);
        assert_eq!(obs.len(), 1);
        let firsts: Vec<u8> = obs[0].signature.0.iter().map(|r| r[0]).collect();
        let want: Vec<u8> = PLACE.iter().map(|c| c.code()).collect();
        assert_eq!(firsts, want);
        // Without the shear the box is too wide and the rows above and below miss.
        let plain = observe(&img, &blobs, &ctx(), &PatternParams::default(), &[]);
        assert_eq!(plain[0].shear_px_per_row, 0.0);
        assert!(obs[0].region_bounds(1)[0] <= plain[0].region_bounds(1)[0] - 5);
        assert!(obs[0].region_bounds(7)[0] >= plain[0].region_bounds(7)[0] + 5);
        assert_ne!(plain[0].signature, obs[0].signature);
    }

    #[test]
    fn triangulation_finds_where_rays_cross() {
        let target = [100.0, 220.0];
        let rays: Vec<FieldRay> = [[0.0, 0.0], [60.0, 10.0], [-50.0, 30.0]]
            .iter()
            .map(|&o| ray(o, target))
            .collect();
        let t = triangulate(&rays, &[1.0; 3]).expect("crossing rays");
        assert!((t.field_cm[0] - 100.0).abs() < 1e-6 && (t.field_cm[1] - 220.0).abs() < 1e-6);
        assert!(t.residual_cm < 1e-6);
        assert!(t.spread_deg > 10.0, "{}", t.spread_deg);
        // Parallel rays do not cross; a point behind a ray is refused.
        let parallel = [ray([0.0, 0.0], [1.0, 0.0]), ray([0.0, 5.0], [1.0, 5.0])];
        assert!(triangulate(&parallel, &[1.0; 2]).is_none());
        let away = [
            ray([0.0, 0.0], [100.0, 220.0]),
            ray([200.0, 440.0], [300.0, 660.0]),
        ];
        assert!(triangulate(&away, &[1.0; 2]).is_none());
        assert!(triangulate(&rays[..1], &[1.0]).is_none());
        // Two rays 5° apart: the spread says so.
        let a = ray([0.0, 0.0], [0.0, 200.0]);
        let b = FieldRay {
            heading_rad: a.heading_rad + 5f64.to_radians(),
            origin_cm: [17.5, 0.0, 20.0],
            ..a
        };
        let t = triangulate(&[a, b], &[1.0; 2]).expect("crossing");
        assert!((t.spread_deg - 5.0).abs() < 0.01, "{}", t.spread_deg);
    }

    #[test]
    fn robust_triangulation_drops_a_wrong_ray() {
        let target = [90.0, 225.0];
        let mut views: Vec<(FieldRay, PatternObservation)> = Vec::new();
        let obs = one(&tiles(PLACE, 10, 60, 40));
        for k in 0..8 {
            let from = [-100.0 + 25.0 * f64::from(k), 20.0 * f64::from(k % 3)];
            views.push((ray(from, target), obs));
        }
        // One view of the near-twin 180 cm away.
        views.push((ray([0.0, 0.0], [-90.0, 225.0]), obs));
        let mut g = Group { views };
        let (t, dropped) = g.triangulate(&LearnParams::default());
        let t = t.expect("placed");
        assert_eq!(dropped.len(), 1);
        assert!((t.field_cm[0] - 90.0).abs() < 0.5 && (t.field_cm[1] - 225.0).abs() < 0.5);
    }

    #[test]
    fn size_relation_fit_recovers_the_pinhole_relation() {
        let samples: Vec<[f64; 2]> = [5.0, 7.0, 9.0, 12.0, 15.0]
            .iter()
            .map(|s| [*s, 1535.0 / s + 3.0])
            .chain([[10.0, 900.0]])
            .collect();
        let r = SizeRelation::fit(&samples).expect("fit");
        assert!((r.multiplier_cm_px - 1535.0).abs() < 1e-6, "{r:?}");
        assert!((r.offset_cm - 3.0).abs() < 1e-6);
        assert_eq!(r.samples, 5, "the far-off sample was dropped");
        assert!((r.distance_cm(10.0).expect("distance") - 156.5).abs() < 1e-6);
        assert!(r.distance_cm(0.0).is_none());
        assert!(SizeRelation::fit(&[[10.0, 100.0]]).is_none());
        assert!(
            SizeRelation::fit(&[[10.0, 100.0], [20.0, 300.0]]).is_none(),
            "bigger is nearer"
        );
    }

    #[test]
    fn learns_places_from_robot_positions_and_identifies_them() {
        // Synthetic views of one place from six robot positions: rays aimed at it from the
        // tiles' observation, sizes as a pinhole camera gives them.
        let place: [f64; 2] = [120.0, 225.0];
        let img = tiles(PLACE, 10, 60, 40);
        let base = one(&img);
        let mut views = Vec::new();
        for (k, from) in [
            [-60.0_f64, 0.0],
            [-30.0, 20.0],
            [0.0, 30.0],
            [30.0, 20.0],
            [60.0, 0.0],
            [90.0, -20.0],
        ]
        .iter()
        .enumerate()
        {
            let d = (place[0] - from[0]).hypot(place[1] - from[1]);
            let heading = (place[1] - from[1]).atan2(place[0] - from[0]);
            let obs = PatternObservation {
                size_px: 1535.0 / d,
                ray: Some(GroundRay {
                    origin_cm: [0.0, 0.0, 25.0],
                    direction: [1.0, 0.0, 0.0],
                }),
                ..base
            };
            views.push(LearnView {
                frame: k,
                robot: RobotPose::new(from[0], from[1], heading),
                observation: obs,
            });
        }
        let params = PatternParams::default();
        let mut memory = PatternMemory::default();
        let report = memory.learn(&views, &params, &LearnParams::default());
        assert_eq!(report.objects_created, vec![0], "{report:?}");
        let o = &memory.objects[0];
        assert!((o.field_cm[0] - 120.0).abs() < 0.5 && (o.field_cm[1] - 225.0).abs() < 0.5);
        assert_eq!(o.placed_by, Placement::Triangulation);
        assert!((o.height_cm.expect("height") - 25.0).abs() < 1e-6);
        let rel = memory.relation.expect("relation");
        assert!((rel.multiplier_cm_px - 1535.0).abs() < 1.0, "{rel:?}");
        // Identification: the same place at 15 px is 102 cm away; another place is unknown.
        let near = PatternObservation {
            size_px: 15.0,
            ..base
        };
        let m = memory.identify(&near, &params).expect("identified");
        assert_eq!((m.id, m.agreement), (0, 9));
        assert!((m.distance_cm.expect("distance") - 102.3).abs() < 1.0);
        let mut other = PLACE;
        other[1] = ColourClass::Red;
        other[3] = ColourClass::Red;
        assert!(
            memory
                .identify(&one(&tiles(other, 10, 60, 40)), &params)
                .is_none()
        );
        // Learning the same views again adds nothing new; a different signature at the same
        // place becomes that object's second pattern.
        let again = memory.learn(&views, &params, &LearnParams::default());
        assert!(again.objects_created.is_empty() && again.views_merged == 6);
        let other_obs = one(&tiles(other, 10, 60, 40));
        let side: Vec<LearnView> = views
            .iter()
            .map(|v| LearnView {
                observation: PatternObservation {
                    signature: other_obs.signature,
                    ..v.observation
                },
                ..*v
            })
            .collect();
        let r = memory.learn(&side, &params, &LearnParams::default());
        assert_eq!(r.patterns_added, vec![0]);
        assert_eq!(memory.objects[0].patterns.len(), 2);
        assert!(
            memory
                .identify(&one(&tiles(other, 10, 60, 40)), &params)
                .is_some()
        );
    }

    #[test]
    fn equal_agreement_with_two_places_is_ambiguous() {
        let params = PatternParams::default();
        let a = one(&tiles(PLACE, 10, 60, 40));
        let mut twin = PLACE;
        twin[0] = ColourClass::Red;
        twin[8] = ColourClass::Red;
        let b = one(&tiles(twin, 10, 60, 40));
        let object = |id, sig| PatternObject {
            id,
            field_cm: [0.0, 0.0],
            height_cm: None,
            patterns: vec![sig],
            views: 1,
            placed_by: Placement::Triangulation,
            residual_cm: 0.0,
        };
        let memory = PatternMemory {
            objects: vec![object(0, a.signature), object(1, b.signature)],
            ..PatternMemory::default()
        };
        assert_eq!(memory.identify(&a, &params).map(|m| m.id), Some(0));
        assert_eq!(memory.identify(&b, &params).map(|m| m.id), Some(1));
        // Half way between: tile 0 as the first, tile 8 as the second.
        let mut half = PLACE;
        half[0] = ColourClass::Red;
        let h = one(&tiles(half, 10, 60, 40));
        assert!(memory.identify(&h, &params).is_none());
        let c = PatternMemory::candidate(Some(&memory), h, &ctx(), &params);
        assert!(c.ambiguous && !c.accepted);
        let prims = pattern_primitives(std::slice::from_ref(&c));
        assert_eq!(
            prims
                .iter()
                .filter(|p| matches!(p, Primitive::PatternRegion { .. }))
                .count(),
            9
        );
        assert!(prims.iter().any(
            |p| matches!(p, Primitive::Label { text, .. } if text.contains("place 0 or 1, tie"))
        ));
    }

    #[test]
    fn bad_places_files_are_refused_with_the_reason() {
        let good = PatternMemory {
            objects: vec![PatternObject {
                id: 3,
                field_cm: [1.0, 2.0],
                height_cm: Some(25.0),
                patterns: vec![Signature([[6, 0]; 9])],
                views: 4,
                placed_by: Placement::Triangulation,
                residual_cm: 1.0,
            }],
            relation: Some(SizeRelation {
                multiplier_cm_px: 1500.0,
                offset_cm: 2.0,
                residual_cm: 3.0,
                samples: 4,
            }),
            ..PatternMemory::default()
        };
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join("places.json");
        good.save(&path).expect("saved");
        assert_eq!(PatternMemory::load(&path).expect("loads"), good);
        let text = std::fs::read_to_string(&path).expect("read");
        let bad = |t: &str| {
            let e = PatternMemory::from_json(t).expect_err("refused");
            e.to_string()
        };
        assert!(bad("{").contains("not a places file"));
        assert!(bad("[1, 2]").contains("not a places file"));
        assert!(bad(&text.replace("eotn.places", "something")).contains("format"));
        assert!(bad(&text.replace("\"version\": 1", "\"version\": 9")).contains("version 9"));
        assert!(bad(&text.replace("1500.0", "-1500.0")).contains("multiplier"));
        assert!(bad(&text.replacen("6,", "77,", 1)).contains("77 is not a class code"));
        let twice = text.replace(
            "\"objects\": [",
            "\"objects\": [{\"id\": 3, \"field_cm\": [0, 0], \"patterns\": [[[6,0],[6,0],[6,0],[6,0],[4,0],[6,0],[6,0],[6,0],[6,0]]]},",
        );
        assert!(
            bad(&twice).contains("id 3 appears twice"),
            "{}",
            bad(&twice)
        );
        let e = PatternMemory::load(&dir.path().join("missing.json")).expect_err("missing");
        assert!(e.to_string().contains("missing.json"), "{e}");
        std::fs::write(&path, "not json").expect("write");
        let e = PatternMemory::load(&path).expect_err("garbled");
        assert!(
            e.to_string().contains("places.json") && e.to_string().contains("not a places file")
        );
    }
}
