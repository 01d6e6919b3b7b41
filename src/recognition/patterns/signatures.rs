//! Signatures, per frame: every pink blob that is not a beacon's band gets nine regions the
//! size of its box in a 3 × 3 grid around it, each with its two most common colours, its size
//! (mean column height) and its ray on the ground.

use serde::{Deserialize, Serialize};

use super::{PatternParams, Signature};
use crate::blobs::{Blob, BlobSet};
use crate::classify::ClassifiedImage;
use crate::frame::PixelBox;
use crate::geometry::{ImagePoint, RobotPose};
use crate::lut::ColourClass;
use crate::recognition::context::ViewContext;

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
    pub bounds: PixelBox,
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
        let [x0, y0, x1, y1] = self.bounds.to_array().map(i64::from);
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
    pub fn centre(&self) -> ImagePoint {
        let [x0, y0, x1, y1] = self.bounds.to_array().map(f64::from);
        ImagePoint::new((x0 + x1 + 1.0) / 2.0, (y0 + y1 + 1.0) / 2.0)
    }
}

/// The distance assumed for removing the rolling shutter's skew from a marker before its
/// distance is known, centimetres.
pub(super) const ASSUMED_DISTANCE_CM: f64 = 200.0;

/// Regions larger than this many pixels are sampled on a grid instead of read whole, so a close
/// marker costs no more than a middling one.
pub(super) const REGION_SAMPLES: i64 = 128;

/// Signatures of the pink markers in a classified frame, leaving out pink blobs inside any of
/// the boxes `except` (accepted beacons, whose bands are theirs).
#[must_use]
pub fn observe(
    img: &ClassifiedImage,
    blobs: &BlobSet,
    ctx: &ViewContext,
    params: &PatternParams,
    except: &[PixelBox],
) -> Vec<PatternObservation> {
    blobs
        .of_class(ColourClass::Pink)
        .filter(|b| b.pixels >= params.min_pixels)
        .filter(|b| !except.iter().any(|e| b.bounds().is_within(e)))
        .map(|b| observe_blob(img, b, ctx))
        .collect()
}

/// The two most common class codes in the inclusive box `[x0, y0, x1, y1]` (clipped to the
/// image) and whether the box lies wholly inside the image.
pub(super) fn region_colours(img: &ClassifiedImage, [x0, y0, x1, y1]: [i64; 4]) -> ([u8; 2], bool) {
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
pub(super) fn column_height(img: &ClassifiedImage, b: &Blob) -> f64 {
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

pub(super) fn observe_blob(
    img: &ClassifiedImage,
    b: &Blob,
    ctx: &ViewContext,
) -> PatternObservation {
    let mut obs = PatternObservation {
        signature: Signature([[0; 2]; 9]),
        size_px: column_height(img, b),
        bearing_rad: 0.0,
        elevation_rad: 0.0,
        bounds: b.bounds(),
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
    let below = ctx.unskew_at(
        ImagePoint::new(seen.x_px, seen.y_px + 1.0),
        ASSUMED_DISTANCE_CM,
        true,
    );
    if (centre.x_px - below.x_px).is_finite() {
        obs.shear_px_per_row = centre.x_px - below.x_px;
    }
    for k in 0..9 {
        let (colours, inside) = region_colours(img, obs.region_bounds(k));
        obs.signature.0[k] = colours;
        obs.regions_in_image += usize::from(inside);
    }
    (obs.bearing_rad, obs.elevation_rad) = ctx.camera_angles(centre);
    obs.ray = ctx.pose.map(|pose| {
        let o = pose.position();
        let d = pose.field_ray(centre).coords;
        GroundRay {
            origin_cm: [o.x(), o.y(), o.z()],
            direction: [d.x, d.y, d.z],
        }
    });
    obs
}
