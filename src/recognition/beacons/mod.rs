//! Beacons: a pink band directly above or below a sky-blue or yellow band of about the same
//! width (the 2005 landmarks at the field's corners and sides), or — with the upper band cut off
//! by the image top — a yellow or sky-blue band standing on its white base: only pink over
//! yellow and pink over sky blue have those lower bands, so the band names the beacon.
//!
//! The distance comes from the elevations of the band edges ([`distance`]), or from the width
//! when they are cut off.
//!
//! | file | role |
//! |---|---|
//! | `mod.rs` | parameters, candidates and their tests, drawing |
//! | `distance.rs` | the band edges to 1/64 px along the beacon's axis, and the distance from them |

pub mod distance;
#[cfg(test)]
mod tests;

use serde::{Deserialize, Serialize};

use super::confidence::{Confidence, TestName, TestWeight};
use super::context::{Relative, ViewContext};
use super::draw::{ObjectId, Primitive};
use crate::blobs::{Blob, BlobSet};
use crate::classify::ClassifiedImage;
use crate::frame::{ImagePoint, PixelBox};
use crate::lut::ColourClass;
pub use distance::DistanceSource;

/// Settings of beacon recognition.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct BeaconParams {
    /// Height of one coloured band, centimetres.
    pub band_height_cm: f64,
    /// Height of the white base below the bands, centimetres.
    pub base_height_cm: f64,
    /// Diameter of the beacon's cylinder, centimetres.
    pub diameter_cm: f64,
    /// Bands with fewer pixels are ignored.
    pub min_band_pixels: u32,
    /// Accepted width ratio of the two bands.
    pub width_ratio: [f64; 2],
    /// Weight of the width-ratio test.
    pub width_ratio_weight: TestWeight,
    /// Accepted horizontal offset of the bands' centres, in band widths.
    pub alignment: [f64; 2],
    /// Weight of the alignment test.
    pub alignment_weight: TestWeight,
    /// Accepted vertical gap between the bands, in band heights (negative: overlap).
    pub gap: [f64; 2],
    /// Weight of the gap test.
    pub gap_weight: TestWeight,
    /// Accepted height / width of the two bands together (true: 2 × 10 / 10 = 2).
    pub aspect: [f64; 2],
    /// Weight of the aspect test (skipped when cut off).
    pub aspect_weight: TestWeight,
    /// A band cut by the image top standing on its base: accepted share of white right below
    /// it, across the middle half of its width.
    pub white_base: [f64; 2],
    /// Weight of the white-base test.
    pub white_base_weight: TestWeight,
    /// ... and accepted share of white beside the base, a band's width out on each side (a
    /// field line below a goal runs on beyond it).
    pub base_flanks: [f64; 2],
    /// Weight of the base-flanks test.
    pub base_flanks_weight: TestWeight,
    /// Accepted height / width of such a band (at most one band shows: 10 / 10 cm).
    pub band_aspect: [f64; 2],
    /// Weight of the band-aspect test.
    pub band_aspect_weight: TestWeight,
    /// Move the band edges to the reference row's read-out time (the rolling shutter), as the
    /// ball's outline is.
    pub skew_correction: bool,
}

impl Default for BeaconParams {
    fn default() -> Self {
        Self {
            band_height_cm: 10.0,
            base_height_cm: 20.0,
            diameter_cm: 10.0,
            min_band_pixels: 6,
            width_ratio: [0.5, 2.0],
            width_ratio_weight: TestWeight::new(1.0, 2.0),
            alignment: [0.0, 0.5],
            alignment_weight: TestWeight::new(1.0, 2.0),
            gap: [-0.3, 0.4],
            gap_weight: TestWeight::new(1.0, 2.0),
            aspect: [1.0, 3.5],
            aspect_weight: TestWeight::new(0.5, 1.0),
            white_base: [0.7, 1.0],
            white_base_weight: TestWeight::new(1.0, 3.0),
            base_flanks: [0.0, 0.3],
            base_flanks_weight: TestWeight::new(1.0, 3.0),
            band_aspect: [0.0, 1.6],
            band_aspect_weight: TestWeight::new(0.5, 2.0),
            skew_correction: true,
        }
    }
}

/// Which beacon: the colour of the top band and of the bottom band.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct BeaconKind {
    /// Colour of the upper band.
    pub top: ColourClass,
    /// Colour of the lower band.
    pub bottom: ColourClass,
}

impl BeaconKind {
    /// A name such as `"pink over yellow"`.
    #[must_use]
    pub fn name(&self) -> String {
        format!("{} over {}", self.top.name(), self.bottom.name())
    }
}

/// A beacon candidate with its evidence.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Beacon {
    /// Which beacon.
    pub kind: BeaconKind,
    /// Both bands' box, inclusive pixels.
    pub bounds: PixelBox,
    /// Top or bottom touches the image edge.
    pub cut_off: bool,
    /// Camera-relative distance, bearing, elevation of the boundary between the bands.
    pub camera: Relative,
    /// Body-relative, when the joints are known.
    pub body: Option<Relative>,
    /// What the distance was measured from.
    #[serde(default)]
    pub distance_from: DistanceSource,
    /// The band edges found (top, boundary, bottom; as scanned, before the skew removal).
    #[serde(default, with = "crate::frame::xy_array")]
    pub edges: Vec<ImagePoint>,
    /// The confidence breakdown.
    pub confidence: Confidence,
    /// Accepted as a beacon.
    pub accepted: bool,
}

/// The blobs of a band colour large enough to count.
fn bands<'a>(blobs: &'a BlobSet, colour: ColourClass, p: &BeaconParams) -> Vec<&'a Blob> {
    blobs
        .of_class(colour)
        .filter(|b| b.pixels >= p.min_band_pixels)
        .collect()
}

/// Finds beacons among the pink, sky-blue and yellow blobs: pink paired with the best-matching
/// band of another colour above or below it, then goal-coloured bands on a white base with the
/// image top cutting off whatever was above them.
#[must_use]
pub fn recognise_beacons(
    img: &ClassifiedImage,
    blobs: &BlobSet,
    ctx: &ViewContext,
    p: &BeaconParams,
) -> Vec<Beacon> {
    let mut out: Vec<Beacon> = Vec::new();
    let mut paired: Vec<u32> = Vec::new();
    for pink in bands(blobs, ColourClass::Pink, p) {
        let mut best: Option<(PairCandidate, u32)> = None;
        for other_colour in [ColourClass::SkyBlue, ColourClass::Yellow] {
            for other in bands(blobs, other_colour, p) {
                let candidate = pair_candidate(ctx, p, pink, other);
                if best
                    .as_ref()
                    .is_none_or(|(b, _)| candidate.confidence.total > b.confidence.total)
                {
                    best = Some((candidate, other.number));
                }
            }
        }
        // Only the best pairing is measured: the distance plays no part in the confidence,
        // and scanning the band edges of every pink-and-other pair was half the recognition
        // time of a frame with a goal in view.
        if let Some((candidate, other)) = best {
            let mut b = candidate.measured(img, ctx, p);
            b.accepted =
                b.confidence.accepted() && !out.iter().any(|o| o.accepted && o.kind == b.kind);
            if b.accepted {
                paired.push(other);
            }
            out.push(b);
        }
    }
    for colour in [ColourClass::Yellow, ColourClass::SkyBlue] {
        for band in bands(blobs, colour, p) {
            if band.miny > 0 || paired.contains(&band.number) {
                continue;
            }
            let mut b = band_over_base(img, ctx, p, band);
            b.accepted =
                b.confidence.accepted() && !out.iter().any(|o| o.accepted && o.kind == b.kind);
            out.push(b);
        }
    }
    out
}

/// A pink band and a band of another colour above or below it, judged by the shape tests
/// alone, before its distance is measured.
struct PairCandidate<'a> {
    top: &'a Blob,
    bottom: &'a Blob,
    kind: BeaconKind,
    all: Blob,
    cut_off: bool,
    /// The pinhole distance of the two bands' box height, centimetres.
    guess_cm: f64,
    confidence: Confidence,
}

impl PairCandidate<'_> {
    /// The beacon, its distance measured from the band edges.
    fn measured(self, img: &ClassifiedImage, ctx: &ViewContext, p: &BeaconParams) -> Beacon {
        let measured = distance::measure(img, ctx, p, self.top, self.bottom, self.guess_cm);
        Beacon {
            kind: self.kind,
            bounds: self.all.bounds(),
            cut_off: self.cut_off,
            camera: ctx.camera_relative(measured.at, measured.distance_cm),
            body: ctx.body_relative(measured.at, measured.distance_cm),
            distance_from: measured.source,
            edges: measured.edges,
            confidence: self.confidence,
            accepted: false,
        }
    }
}

/// The candidate made of `pink` and a band of another colour above or below it.
fn pair_candidate<'a>(
    ctx: &ViewContext,
    p: &BeaconParams,
    pink: &'a Blob,
    other: &'a Blob,
) -> PairCandidate<'a> {
    let height = ctx.camera.height_px as u32;
    let centre = ctx.camera.centre;
    let angle = ctx.horizon_angle();
    let level = |b: &Blob| {
        let c = b.box_centre().rotated_about(centre, angle);
        (
            c.x_px,
            c.y_px,
            f64::from(b.maxx - b.minx + 1),
            f64::from(b.maxy - b.miny + 1),
        )
    };
    let (px, py, pw, ph) = level(pink);
    let (ox, oy, ow, oh) = level(other);
    let pink_on_top = py < oy;
    let (top, bottom) = if pink_on_top {
        (pink, other)
    } else {
        (other, pink)
    };
    let (top_h, top_y, bottom_h, bottom_y) = if pink_on_top {
        (ph, py, oh, oy)
    } else {
        (oh, oy, ph, py)
    };
    let gap = ((bottom_y - bottom_h / 2.0) - (top_y + top_h / 2.0)) / ph.max(oh);
    let mut confidence = Confidence::default();
    // A band the image border cuts at its outer end shows only part of its width (the image
    // edge crosses a curved band): its width says nothing.
    let narrower = if pw < ow { pink } else { other };
    let narrow_cut = (std::ptr::eq(narrower, top) && top.miny == 0)
        || (std::ptr::eq(narrower, bottom) && bottom.maxy + 1 >= height);
    if narrow_cut {
        confidence.skipped(TestName::WidthRatio, p.width_ratio);
    } else {
        confidence.range_test(
            TestName::WidthRatio,
            pw / ow,
            p.width_ratio,
            p.width_ratio_weight,
        );
    }
    confidence.range_test(
        TestName::Alignment,
        (px - ox).abs() / pw.max(ow),
        p.alignment,
        p.alignment_weight,
    );
    confidence.range_test(TestName::Gap, gap, p.gap, p.gap_weight);
    let all = pink.merged_with(other);
    let cut_off = all.miny == 0 || all.maxy + 1 >= height;
    let bw = f64::from(all.maxx - all.minx + 1);
    let bh = f64::from(all.maxy - all.miny + 1);
    if cut_off {
        confidence.skipped(TestName::Aspect, p.aspect);
    } else {
        confidence.range_test(TestName::Aspect, bh / bw, p.aspect, p.aspect_weight);
    }
    let kind = BeaconKind {
        top: ColourClass::from_code(top.colour).unwrap_or(ColourClass::Pink),
        bottom: ColourClass::from_code(bottom.colour).unwrap_or(ColourClass::Pink),
    };
    // A first guess for the skew removal and the axis direction: the pinhole distance of the
    // two bands' box height.
    PairCandidate {
        top,
        bottom,
        kind,
        all,
        cut_off,
        guess_cm: ctx.camera.focal_px * 2.0 * p.band_height_cm / bh,
        confidence,
    }
}

/// A yellow or sky-blue band touching the image top, standing on a white base as wide as it:
/// the lower band of pink over yellow (or sky blue), its pink band above the image.
fn band_over_base(
    img: &ClassifiedImage,
    ctx: &ViewContext,
    p: &BeaconParams,
    band: &Blob,
) -> Beacon {
    let colour = ColourClass::from_code(band.colour).unwrap_or(ColourClass::Yellow);
    let guess = ctx.camera.focal_px * p.diameter_cm / f64::from(band.width());
    let measured = distance::measure_band_over_base(img, ctx, p, band, guess);
    let mut confidence = Confidence::default();
    let base = distance::base_below(img, ctx, band, guess);
    confidence.range_test(
        TestName::WhiteBase,
        base.white_below,
        p.white_base,
        p.white_base_weight,
    );
    confidence.range_test(
        TestName::BaseFlanks,
        base.white_beside,
        p.base_flanks,
        p.base_flanks_weight,
    );
    confidence.range_test(
        TestName::Aspect,
        f64::from(band.height()) / f64::from(band.width()),
        p.band_aspect,
        p.band_aspect_weight,
    );
    Beacon {
        kind: BeaconKind {
            top: ColourClass::Pink,
            bottom: colour,
        },
        bounds: band.bounds(),
        cut_off: true,
        camera: ctx.camera_relative(measured.at, measured.distance_cm),
        body: ctx.body_relative(measured.at, measured.distance_cm),
        distance_from: measured.source,
        edges: measured.edges,
        confidence,
        accepted: false,
    }
}

/// Drawing primitives for beacon candidates.
#[must_use]
pub fn beacon_primitives(beacons: &[Beacon]) -> Vec<Primitive> {
    let mut out = Vec::new();
    for (i, b) in beacons.iter().enumerate() {
        let owner = ObjectId::Beacon(i);
        out.push(Primitive::Box {
            owner,
            colour: ColourClass::Pink.code(),
            bounds: b.bounds,
        });
        if !b.edges.is_empty() {
            out.push(Primitive::ScanPoints {
                owner,
                points: b.edges.clone(),
            });
        }
        if b.accepted {
            out.push(Primitive::Label {
                owner,
                at: ImagePoint::new(f64::from(b.bounds.min_x), f64::from(b.bounds.min_y) - 2.0),
                text: format!("{} {:.0} cm", b.kind.name(), b.camera.distance_cm),
            });
        }
    }
    out
}
