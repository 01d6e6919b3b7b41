//! The "almost SLAM" coloured-pattern recogniser of the original: any pink marker together with
//! the colours around it forms a signature that identifies a place. Nine regions the size of the
//! pink blob in a 3×3 grid centred on it each give their two most common colours; a signature
//! matches a stored one when at least eight regions agree on the most common colour.
//!
//! A learning phase, given where the robot stands, creates objects or adds patterns to a known
//! object nearby, and learns a linear relation between the inverse of the marker's size and its
//! distance; an identification phase only identifies, and uses that relation for the distance.

use serde::{Deserialize, Serialize};

use crate::blobs::{Blob, BlobSet};
use crate::classify::ClassifiedImage;
use crate::geometry::RobotPose;
use crate::lut::ColourClass;

/// The two most common class codes of each of the nine regions, row by row (top-left first,
/// the pink blob's own region in the middle). 0 stands for "nothing".
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
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
}

/// One pink marker seen in a frame.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PatternObservation {
    /// The colours around it.
    pub signature: Signature,
    /// Size of the pink blob: the square root of its box area, pixels.
    pub size_px: f64,
    /// Camera bearing of the blob's centre, radians.
    pub bearing_rad: f64,
    /// The pink blob's box, inclusive pixels.
    pub bounds: [u32; 4],
}

/// Settings of the pattern recogniser.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct PatternParams {
    /// Pink blobs with fewer pixels are ignored.
    pub min_pixels: u32,
    /// Regions that must agree for a match (of nine).
    pub min_agreement: usize,
    /// A learnt observation joins a known object within this distance, centimetres.
    pub same_object_cm: f64,
}

impl Default for PatternParams {
    fn default() -> Self {
        Self {
            min_pixels: 9,
            min_agreement: 8,
            same_object_cm: 60.0,
        }
    }
}

/// Signatures of the pink markers in a classified frame.
#[must_use]
pub fn observe(
    img: &ClassifiedImage,
    blobs: &BlobSet,
    focal_px: f64,
    params: &PatternParams,
) -> Vec<PatternObservation> {
    blobs
        .of_class(ColourClass::Pink)
        .filter(|b| b.pixels >= params.min_pixels)
        .map(|b| observe_blob(img, b, focal_px))
        .collect()
}

fn observe_blob(img: &ClassifiedImage, b: &Blob, focal_px: f64) -> PatternObservation {
    let w = i64::from(b.maxx - b.minx + 1);
    let h = i64::from(b.maxy - b.miny + 1);
    let mut regions = [[0u8; 2]; 9];
    for (k, region) in regions.iter_mut().enumerate() {
        let (gx, gy) = (k as i64 % 3 - 1, k as i64 / 3 - 1);
        let (x0, y0) = (i64::from(b.minx) + gx * w, i64::from(b.miny) + gy * h);
        let mut counts = [0u32; 256];
        for y in y0..y0 + h {
            for x in x0..x0 + w {
                if let Some(c) = img.get_signed(x, y) {
                    counts[usize::from(c)] += 1;
                }
            }
        }
        counts[0] = 0;
        let mut order: Vec<u8> = (1u8..=255)
            .filter(|&c| counts[usize::from(c)] > 0)
            .collect();
        order.sort_by_key(|&c| (std::cmp::Reverse(counts[usize::from(c)]), c));
        *region = [
            order.first().copied().unwrap_or(0),
            order.get(1).copied().unwrap_or(0),
        ];
    }
    let cx = f64::from(b.minx + b.maxx + 1) / 2.0;
    PatternObservation {
        signature: Signature(regions),
        size_px: ((w * h) as f64).sqrt(),
        bearing_rad: ((img.width() as f64 / 2.0 - cx) / focal_px).atan(),
        bounds: [b.minx, b.miny, b.maxx, b.maxy],
    }
}

/// A place known by its patterns.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PatternObject {
    /// Identity, counting from 0.
    pub id: usize,
    /// Estimated field position (x, y), centimetres.
    pub field_cm: [f64; 2],
    /// Signatures seen of it.
    pub patterns: Vec<Signature>,
}

/// What the recogniser has learnt.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct PatternMemory {
    /// Known objects.
    pub objects: Vec<PatternObject>,
    /// (1 / size px, distance cm) samples from the learning phase.
    pub samples: Vec<[f64; 2]>,
}

/// An identification.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PatternMatch {
    /// Which object.
    pub id: usize,
    /// Regions that agreed.
    pub agreement: usize,
    /// Distance from the learnt size relation, centimetres (None before enough samples).
    pub distance_cm: Option<f64>,
}

impl PatternMemory {
    /// The learnt relation distance = a / size + b, as (a, b); `None` with fewer than two
    /// distinct sizes.
    #[must_use]
    pub fn size_relation(&self) -> Option<(f64, f64)> {
        let pts: Vec<(f64, f64)> = self.samples.iter().map(|s| (s[0], s[1])).collect();
        let fit = super::fit::fit_line(&pts)?;
        // fit_line may regress x on y; turn it into distance as a function of 1/size.
        if fit.steep {
            (fit.slope.abs() > 1e-12).then(|| (1.0 / fit.slope, -fit.intercept / fit.slope))
        } else {
            Some((fit.slope, fit.intercept))
        }
    }

    /// Identification phase: the best stored object with enough agreeing regions.
    #[must_use]
    pub fn identify(
        &self,
        obs: &PatternObservation,
        params: &PatternParams,
    ) -> Option<PatternMatch> {
        let (id, agreement) = self
            .objects
            .iter()
            .filter_map(|o| {
                let best = o
                    .patterns
                    .iter()
                    .map(|p| p.agreement(&obs.signature))
                    .max()?;
                (best >= params.min_agreement).then_some((o.id, best))
            })
            .max_by_key(|&(_, a)| a)?;
        let distance_cm = self
            .size_relation()
            .map(|(a, b)| a / obs.size_px.max(1e-6) + b);
        Some(PatternMatch {
            id,
            agreement,
            distance_cm,
        })
    }

    /// Learning phase: records the observation made from `robot` with the marker at
    /// `distance_cm` (known in learning); adds the pattern to a known object within
    /// [`PatternParams::same_object_cm`] of where it must be, or creates a new object. Returns
    /// the object's id.
    pub fn learn(
        &mut self,
        obs: &PatternObservation,
        robot: &RobotPose,
        distance_cm: f64,
        params: &PatternParams,
    ) -> usize {
        if distance_cm.is_finite() && distance_cm > 0.0 && obs.size_px > 0.0 {
            self.samples.push([1.0 / obs.size_px, distance_cm]);
        }
        let heading = robot.heading_rad + obs.bearing_rad;
        let at = [
            robot.x_cm + distance_cm * heading.cos(),
            robot.y_cm + distance_cm * heading.sin(),
        ];
        let near = self.objects.iter_mut().find(|o| {
            (o.field_cm[0] - at[0]).hypot(o.field_cm[1] - at[1]) <= params.same_object_cm
        });
        match near {
            Some(o) => {
                if !o
                    .patterns
                    .iter()
                    .any(|p| p.agreement(&obs.signature) >= params.min_agreement)
                {
                    o.patterns.push(obs.signature);
                }
                o.id
            }
            None => {
                let id = self.objects.len();
                self.objects.push(PatternObject {
                    id,
                    field_cm: at,
                    patterns: vec![obs.signature],
                });
                id
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::blobs::Connectivity;

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

    fn one(img: &ClassifiedImage) -> PatternObservation {
        let blobs = BlobSet::from_image(img, Connectivity::Four);
        let obs = observe(img, &blobs, 191.9, &PatternParams::default());
        assert_eq!(obs.len(), 1);
        obs[0]
    }

    #[test]
    fn learns_places_identifies_them_and_their_distance() {
        let p = PatternParams::default();
        let mut memory = PatternMemory::default();
        let robot = RobotPose::new(0.0, 0.0, 0.0);
        // The same place seen from two distances (tile 10 px at 200 cm, 20 px at 100 cm).
        let far = one(&tiles(PLACE, 10, 60, 40));
        let id = memory.learn(&far, &robot, 200.0, &p);
        let near = one(&tiles(PLACE, 20, 50, 30));
        let robot_closer = RobotPose::new(
            100.0,
            far.bearing_rad.tan() * 100.0 - near.bearing_rad.tan() * 100.0,
            0.0,
        );
        assert_eq!(memory.learn(&near, &robot_closer, 100.0, &p), id);
        assert_eq!(memory.objects.len(), 1);
        // Identification at 133 cm (tile 15 px).
        let mid = one(&tiles(PLACE, 15, 55, 35));
        let m = memory.identify(&mid, &p).expect("identified");
        assert_eq!(m.id, id);
        assert!(m.agreement >= 8);
        let d = m.distance_cm.expect("relation learnt");
        assert!((d - 133.3).abs() < 5.0, "{d}");
        // A different place does not match.
        let mut other = PLACE;
        other[1] = ColourClass::Red;
        other[3] = ColourClass::Red;
        assert!(
            memory
                .identify(&one(&tiles(other, 10, 60, 40)), &p)
                .is_none()
        );
    }
}
