//! Beacons: a pink band directly above or below a sky-blue or yellow band of about the same
//! width (the 2005 landmarks at the field's corners and sides). Their distance comes from the
//! height of both bands, or from the width when top or bottom is cut off.

use serde::{Deserialize, Serialize};

use super::confidence::{Confidence, TestName, TestWeight};
use super::context::{Relative, ViewContext};
use super::draw::{ObjectId, Primitive};
use crate::blobs::{Blob, BlobSet};
use crate::frame::{ImagePoint, PixelBox};
use crate::lut::ColourClass;

/// Settings of beacon recognition.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct BeaconParams {
    /// Height of one coloured band, centimetres.
    pub band_height_cm: f64,
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
}

impl Default for BeaconParams {
    fn default() -> Self {
        Self {
            band_height_cm: 10.0,
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
    /// Camera-relative distance, bearing, elevation of the centre.
    pub camera: Relative,
    /// Body-relative, when the joints are known.
    pub body: Option<Relative>,
    /// The confidence breakdown.
    pub confidence: Confidence,
    /// Accepted as a beacon.
    pub accepted: bool,
}

/// Finds beacons among the pink, sky-blue and yellow blobs.
#[must_use]
pub fn recognise_beacons(blobs: &BlobSet, ctx: &ViewContext, p: &BeaconParams) -> Vec<Beacon> {
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
    let mut out: Vec<Beacon> = Vec::new();
    let pinks: Vec<&Blob> = blobs
        .of_class(ColourClass::Pink)
        .filter(|b| b.pixels >= p.min_band_pixels)
        .collect();
    for pink in pinks {
        let mut best: Option<Beacon> = None;
        for other_colour in [ColourClass::SkyBlue, ColourClass::Yellow] {
            for other in blobs
                .of_class(other_colour)
                .filter(|b| b.pixels >= p.min_band_pixels)
            {
                let (px, py, pw, ph) = level(pink);
                let (ox, oy, ow, oh) = level(other);
                let pink_on_top = py < oy;
                let (top_h, top_y, bottom_h, bottom_y) = if pink_on_top {
                    (ph, py, oh, oy)
                } else {
                    (oh, oy, ph, py)
                };
                let gap = ((bottom_y - bottom_h / 2.0) - (top_y + top_h / 2.0)) / ph.max(oh);
                let mut confidence = Confidence::default();
                confidence.range_test(
                    TestName::WidthRatio,
                    pw / ow,
                    p.width_ratio,
                    p.width_ratio_weight,
                );
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
                let distance = if cut_off {
                    ctx.camera.focal_px * p.diameter_cm / bw
                } else {
                    ctx.camera.focal_px * 2.0 * p.band_height_cm / bh
                };
                let c = all.box_centre();
                let kind = if pink_on_top {
                    BeaconKind {
                        top: ColourClass::Pink,
                        bottom: other_colour,
                    }
                } else {
                    BeaconKind {
                        top: other_colour,
                        bottom: ColourClass::Pink,
                    }
                };
                let beacon = Beacon {
                    kind,
                    bounds: all.bounds(),
                    cut_off,
                    camera: ctx.camera_relative(c, distance),
                    body: ctx.body_relative(c, distance),
                    confidence,
                    accepted: false,
                };
                if best
                    .as_ref()
                    .is_none_or(|b| beacon.confidence.total > b.confidence.total)
                {
                    best = Some(beacon);
                }
            }
        }
        if let Some(mut b) = best {
            b.accepted =
                b.confidence.accepted() && !out.iter().any(|o| o.accepted && o.kind == b.kind);
            out.push(b);
        }
    }
    out
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::blobs::Connectivity;
    use crate::classify::ClassifiedImage;
    use crate::geometry::PinholeCamera;

    fn image(bands: &[(usize, usize, usize, usize, ColourClass)]) -> ClassifiedImage {
        let (w, h) = (208, 160);
        let mut codes = vec![ColourClass::White.code(); w * h];
        for &(x0, x1, y0, y1, c) in bands {
            for y in y0..y1 {
                for x in x0..x1 {
                    codes[y * w + x] = c.code();
                }
            }
        }
        ClassifiedImage::from_codes(w, h, codes).expect("size")
    }

    #[test]
    fn pink_over_yellow_is_found_with_distance_from_height() {
        let img = image(&[
            (100, 110, 40, 50, ColourClass::Pink),
            (100, 110, 50, 60, ColourClass::Yellow),
            (20, 30, 40, 50, ColourClass::SkyBlue),
        ]);
        let blobs = BlobSet::from_image(&img, Connectivity::Eight);
        let ctx = ViewContext::without_pose(PinholeCamera::ers7());
        let found = recognise_beacons(&blobs, &ctx, &BeaconParams::default());
        let b = found.iter().find(|b| b.accepted).expect("beacon");
        assert_eq!(
            b.kind,
            BeaconKind {
                top: ColourClass::Pink,
                bottom: ColourClass::Yellow
            }
        );
        assert!((b.camera.distance_cm - 191.9 * 20.0 / 20.0).abs() < 2.0);
        assert!(!beacon_primitives(&found).is_empty());
    }

    #[test]
    fn unrelated_pink_and_blue_are_not_a_beacon() {
        let img = image(&[
            (100, 110, 40, 50, ColourClass::Pink),
            (20, 30, 90, 100, ColourClass::SkyBlue),
        ]);
        let blobs = BlobSet::from_image(&img, Connectivity::Eight);
        let ctx = ViewContext::without_pose(PinholeCamera::ers7());
        let found = recognise_beacons(&blobs, &ctx, &BeaconParams::default());
        assert!(found.iter().all(|b| !b.accepted));
    }
}
