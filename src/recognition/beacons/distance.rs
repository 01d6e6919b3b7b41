//! A beacon's distance from its band edges (derivation: `docs/recognition.md`, "Beacon
//! distance").
//!
//! The edges — the top of the upper band, the boundary between the bands, the bottom of the
//! lower band — are found on scan lines along the beacon's axis in the image (the image
//! direction of the world's vertical there), each to 1/64 px by bisection, and moved to the
//! reference row's read-out time as the ball's outline is (the rolling shutter). In the middle of
//! the beacon's width every edge is a point of the cylinder's near side, at a known height z and
//! the same horizontal distance D from the camera; its ray rises at an elevation e with
//! tan e = (z − z_camera) / D. So tan e is linear in z with slope 1 / D: two or three edges give
//! D by least squares whatever the camera's height and tilt — the view from below or above the
//! bands is in the elevations, not in a pixel height. The beacon's axis lies one radius beyond
//! the near side; the distance reported is the camera's to the boundary on the axis.
//!
//! With one edge and a camera pose the camera's height gives D; with none, or without a pose
//! and fewer than two edges, the angle the band's width subtends does.

use serde::{Deserialize, Serialize};

use super::BeaconParams;
use crate::blobs::Blob;
use crate::classify::ClassifiedImage;
use crate::frame::ImagePoint;
use crate::geometry::Point;
use crate::lut::ColourClass;
use crate::recognition::context::ViewContext;

/// What a beacon's distance was measured from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum DistanceSource {
    /// Two or three band edges' elevations.
    #[default]
    BandEdges,
    /// One band edge's elevation and the camera's height.
    EdgeAndCameraHeight,
    /// The angle the band's width subtends (edges cut off or not found).
    Width,
}

/// A beacon's measured distance.
#[derive(Debug, Clone, PartialEq)]
pub struct Measured {
    /// Camera distance to the boundary between the bands on the axis, centimetres.
    pub distance_cm: f64,
    /// The image point the distance is along (the boundary's, at the reference row's time).
    pub at: ImagePoint,
    /// How it was measured.
    pub source: DistanceSource,
    /// The edges found, as scanned (top to bottom).
    pub edges: Vec<ImagePoint>,
}

/// The three edges, top to bottom, where found and not cut by the image border: each the mean
/// over the scan lines, on the centre line.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct BandEdges {
    /// Top of the upper band.
    pub top: Option<ImagePoint>,
    /// The boundary between the bands.
    pub middle: Option<ImagePoint>,
    /// Bottom of the lower band.
    pub bottom: Option<ImagePoint>,
}

/// The sampling step along a scan line, pixels.
const STEP_PX: f64 = 0.25;

/// The classes under parallel scan lines along the beacon's axis, on a common grid: line `i`
/// runs through `centre + offsets[i] · across`, sample `k` lies at t = `t0` + k · [`STEP_PX`]
/// along `down` from there.
struct Samples {
    centre: ImagePoint,
    down: (f64, f64),
    t0: f64,
    /// Scan lines.
    lines: usize,
    /// Samples per line.
    len: usize,
    /// Sample-major: `classes[k · lines + i]` is line `i`'s class at sample `k` (`None` outside
    /// the image), so a sample's classes across the lines lie together.
    classes: Vec<Option<u8>>,
}

/// Fixed-point scale of the scan-line stepping: 32 fractional bits, so thousands of quarter-pixel
/// steps drift by under a millionth of a pixel.
const FIXED_ONE: f64 = 4_294_967_296.0;

impl Samples {
    /// Reads every line's pixels. Each line's position is stepped in fixed point rather than
    /// computed and floored per sample: this read was a third of the recognition step.
    fn take(
        img: &ClassifiedImage,
        centre: ImagePoint,
        down: (f64, f64),
        offsets: &[f64],
        [t0, t1]: [f64; 2],
    ) -> Self {
        let across = (down.1, -down.0);
        let len = ((t1 - t0) / STEP_PX).floor().max(0.0) as usize + 1;
        let lines = offsets.len();
        let mut classes = vec![None; len * lines];
        let (w, h) = (img.width() as i64, img.height() as i64);
        let codes = img.codes();
        // Beyond this the fixed-point position could overflow; such a line is all outside.
        let limit = 1e6;
        let step = (down.0 * STEP_PX * FIXED_ONE, down.1 * STEP_PX * FIXED_ONE);
        for (i, s) in offsets.iter().enumerate() {
            let x0 = centre.x_px + s * across.0 + t0 * down.0;
            let y0 = centre.y_px + s * across.1 + t0 * down.1;
            if !(x0.abs() < limit && y0.abs() < limit && step.0.is_finite() && step.1.is_finite()) {
                continue;
            }
            let (mut x, mut y) = (
                (x0 * FIXED_ONE).floor() as i64,
                (y0 * FIXED_ONE).floor() as i64,
            );
            let (dx, dy) = (step.0.round() as i64, step.1.round() as i64);
            for k in 0..len {
                let (px, py) = (x >> 32, y >> 32);
                if (0..w).contains(&px) && (0..h).contains(&py) {
                    classes[k * lines + i] = codes.get((py * w + px) as usize).copied();
                }
                x += dx;
                y += dy;
            }
        }
        Self {
            centre,
            down,
            t0,
            lines,
            len,
            classes,
        }
    }

    /// The classes of all lines at sample `k` (empty past the grid).
    fn at(&self, k: usize) -> &[Option<u8>] {
        if k < self.len {
            &self.classes[k * self.lines..(k + 1) * self.lines]
        } else {
            &[]
        }
    }

    fn t(&self, k: usize) -> f64 {
        self.t0 + k as f64 * STEP_PX
    }

    /// The sample nearest to `t`, clamped to the grid.
    fn index(&self, t: f64) -> usize {
        let last = if self.lines == 0 {
            0
        } else {
            self.len.saturating_sub(1)
        };
        (((t - self.t0) / STEP_PX).round().max(0.0) as usize).min(last)
    }

    /// The point at `t` on the centre line.
    fn point(&self, t: f64) -> ImagePoint {
        ImagePoint::new(
            self.centre.x_px + t * self.down.0,
            self.centre.y_px + t * self.down.1,
        )
    }

    /// Of the lines whose sample `k` is inside the image, the share of classes `code`; `None`
    /// when none is inside.
    fn share(&self, k: usize, code: u8) -> Option<f64> {
        let (mut seen, mut hits) = (0u32, 0u32);
        for c in self.at(k).iter().flatten() {
            seen += 1;
            hits += u32::from(*c == code);
        }
        (seen > 0).then(|| f64::from(hits) / f64::from(seen))
    }

    /// Whether half the lines or more are outside the image at sample `k`.
    fn outside(&self, k: usize) -> bool {
        let out = self.at(k).iter().filter(|c| c.is_none()).count();
        out * 2 >= self.lines
    }

    /// The edge between samples `from..=to` (increasing t): the least-squares step in the
    /// profile `value(k)` — one level before the step, another after it — which holes or specks
    /// of misclassified pixels in the band move far less than a search for the first pixel of
    /// another colour would. `falls`: the profile is high before the step (the band, when
    /// scanning out of it) rather than after. `None` when the two levels differ by less than
    /// `min_contrast`, the wrong way round, or when the image border lies within 2 px of the
    /// step on the side away from the band (`outer_before`: that side comes first) — the edge
    /// is cut off there.
    fn edge(
        &self,
        [from, to]: [usize; 2],
        value: impl Fn(usize) -> Option<f64>,
        falls: bool,
        min_contrast: f64,
        outer_before: Option<bool>,
    ) -> Option<f64> {
        let points: Vec<(usize, f64)> = (from..=to).filter_map(|k| Some((k, value(k)?))).collect();
        let (split, before, after) = step_fit(&points.iter().map(|p| p.1).collect::<Vec<_>>())?;
        let contrast = if falls {
            before - after
        } else {
            after - before
        };
        if contrast < min_contrast {
            return None;
        }
        let (k0, k1) = (points[split - 1].0, points[split].0);
        let t = (self.t(k0) + self.t(k1)) / 2.0;
        let margin = (2.0 / STEP_PX) as usize;
        let cut = match outer_before {
            Some(true) => (k0.saturating_sub(margin)..=k0).any(|k| self.outside(k)),
            Some(false) => (k1..=k1 + margin).any(|k| self.outside(k)),
            None => false,
        };
        (!cut).then_some(t)
    }
}

/// The least-squares step of `values`: the split `k` (1..len, the step between `k − 1` and `k`)
/// minimising the squared deviations of each side from its mean, and the two means. Among
/// equally good splits, the middle one.
fn step_fit(values: &[f64]) -> Option<(usize, f64, f64)> {
    let n = values.len();
    if n < 2 {
        return None;
    }
    let (total, total_sq) = values
        .iter()
        .fold((0.0, 0.0), |(a, b), v| (a + v, b + v * v));
    let (mut sum, mut sq) = (0.0, 0.0);
    let mut best: Option<(f64, usize, usize)> = None;
    for k in 1..n {
        sum += values[k - 1];
        sq += values[k - 1] * values[k - 1];
        let (l, r) = (k as f64, (n - k) as f64);
        let sse = (sq - sum * sum / l) + ((total_sq - sq) - (total - sum).powi(2) / r);
        match best {
            Some((b, _, last)) if (sse - b).abs() <= 1e-9 && last + 1 == k => {
                best = best.map(|(b, first, _)| (b, first, k));
            }
            Some((b, _, _)) if sse >= b => {}
            _ => best = Some((sse, k, k)),
        }
    }
    let (_, first, last) = best?;
    let k = (first + last) / 2;
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    Some((k, mean(&values[..k]), mean(&values[k..])))
}

/// The image direction of the world's "down" at `p`, for something about `distance_cm` away:
/// through the camera pose when known (vertical lines converge towards a vanishing point), else
/// perpendicular to the horizon (the image's own vertical without a pose).
fn down_at(ctx: &ViewContext, p: ImagePoint, distance_cm: f64) -> (f64, f64) {
    let level = {
        let a = ctx.horizon_angle();
        (-a.sin(), a.cos())
    };
    let Some(pose) = ctx.pose else {
        return level;
    };
    let o = pose.position().coords;
    let ray = pose.field_ray(p).coords * distance_cm;
    let at =
        |dz: f64| pose.image_from_field(&Point::new(o.x + ray.x, o.y + ray.y, o.z + ray.z + dz));
    match (at(5.0), at(-5.0)) {
        (Some(a), Some(b)) => {
            let (dx, dy) = (b.x_px - a.x_px, b.y_px - a.y_px);
            let n = dx.hypot(dy);
            if n > 1e-9 && (dx / n).is_finite() {
                (dx / n, dy / n)
            } else {
                level
            }
        }
        _ => level,
    }
}

/// The lateral offsets of the scan lines: every pixel across the middle half of `width`.
fn offsets(width: f64) -> Vec<f64> {
    let half = (width / 4.0).floor() as i32;
    (-half..=half).map(f64::from).collect()
}

/// Finds the three edges of a beacon whose upper band is `top` and lower band `bottom` (blobs of
/// their colours), on scan lines along the axis across the middle half of the narrower band.
#[must_use]
pub fn band_edges(
    img: &ClassifiedImage,
    ctx: &ViewContext,
    top: &Blob,
    bottom: &Blob,
    guess_cm: f64,
) -> BandEdges {
    let (tx, ty) = top.centroid();
    let (bx, by) = bottom.centroid();
    let (ct, cb) = (ImagePoint::new(tx, ty), ImagePoint::new(bx, by));
    let centre = ct.midpoint(cb);
    let down = down_at(ctx, centre, guess_cm);
    // The bands' centroids along the line through the middle between them.
    let t_bottom = ((cb.x_px - ct.x_px) * down.0 + (cb.y_px - ct.y_px) * down.1) / 2.0;
    let t_top = -t_bottom;
    let width = f64::from(top.width().min(bottom.width()));
    let reach = f64::from(top.height().max(bottom.height())) * 1.5 + 4.0;
    let s = Samples::take(
        img,
        centre,
        down,
        &offsets(width),
        [t_top - reach, t_bottom + reach],
    );
    let (kt, kb, last) = (s.index(t_top), s.index(t_bottom), s.index(t_bottom + reach));
    let (tc, bc) = (top.colour, bottom.colour);
    let upper = s.edge([0, kt], |k| s.share(k, tc), false, 0.3, Some(true));
    let middle = s.edge(
        [kt, kb],
        |k| Some(s.share(k, tc)? - s.share(k, bc)?),
        true,
        0.6,
        None,
    );
    let lower = s.edge([kb, last], |k| s.share(k, bc), true, 0.3, Some(false));
    BandEdges {
        top: upper.map(|t| s.point(t)),
        middle: middle.map(|t| s.point(t)),
        bottom: lower.map(|t| s.point(t)),
    }
}

/// Tangent of the elevation of the ray through `p` above the horizontal: through the camera pose
/// when known, else with the camera taken as level.
fn tan_elevation(ctx: &ViewContext, p: ImagePoint) -> f64 {
    let v = match ctx.pose {
        Some(pose) => pose.field_ray(p).coords,
        None => ctx.camera.unit_ray(p).coords,
    };
    v.z / v.x.hypot(v.y)
}

/// The distance from the edges: least squares of tan(elevation) on the edges' heights (slope
/// 1 / D), or one edge with the camera's height; `None` when neither gives a finite positive D.
/// Returns the horizontal distance to the near side and the camera's height.
fn near_side_distance(
    ctx: &ViewContext,
    heights_cm: [f64; 3],
    edges: [Option<ImagePoint>; 3],
) -> Option<(f64, f64, DistanceSource)> {
    let camera_z = ctx.pose.map(|p| p.position().z());
    // Seen from above its top, a beacon's top outline is the far rim of its cap, not the near
    // side: that edge is left out.
    let mut tans: [Option<f64>; 3] = [0, 1, 2].map(|i| {
        let above_top = i == 0 && camera_z.is_some_and(|c| c >= heights_cm[0]);
        edges[i]
            .filter(|_| !above_top)
            .map(|p| tan_elevation(ctx, p))
            .filter(|t| t.is_finite())
    });
    // Both bands are as tall, so the two steps in tan(elevation) are equal. When they differ by
    // more than pixel steps explain (1.5 px), an outer edge has been eaten by pixels the table
    // left unclassified (a dim band in a dark corner): the outer edge of the shorter band is
    // left out. The boundary between the two colours is the one to trust.
    if let [Some(a), Some(b), Some(c)] = tans {
        let (upper, lower) = (a - b, b - c);
        if (upper - lower).abs() * ctx.camera.focal_px > 1.5 {
            tans[if upper < lower { 0 } else { 2 }] = None;
        }
    }
    let samples: Vec<(f64, f64)> = heights_cm
        .iter()
        .zip(tans)
        .filter_map(|(z, t)| Some((*z, t?)))
        .collect();
    let good = |d: f64| d.is_finite() && d > 1.0;
    if samples.len() >= 2 {
        let n = samples.len() as f64;
        let (mz, mt) = samples
            .iter()
            .fold((0.0, 0.0), |(a, b), (z, t)| (a + z / n, b + t / n));
        let (szz, szt) = samples.iter().fold((0.0, 0.0), |(a, b), (z, t)| {
            (a + (z - mz) * (z - mz), b + (z - mz) * (t - mt))
        });
        let d = szz / szt;
        if good(d) {
            return Some((
                d,
                camera_z.unwrap_or(mz - mt * d),
                DistanceSource::BandEdges,
            ));
        }
    }
    let zc = camera_z?;
    samples
        .iter()
        .filter(|(z, _)| (z - zc).abs() >= 3.0)
        .map(|(z, t)| (z - zc) / t)
        .find(|d| good(*d))
        .map(|d| (d, zc, DistanceSource::EdgeAndCameraHeight))
}

/// A beacon's distance from its edges, else from the width of its bands (`top` and `bottom`
/// their blobs; `guess_cm` a first estimate for the skew removal and the axis direction).
#[must_use]
pub fn measure(
    img: &ClassifiedImage,
    ctx: &ViewContext,
    p: &BeaconParams,
    top: &Blob,
    bottom: &Blob,
    guess_cm: f64,
) -> Measured {
    let edges = band_edges(img, ctx, top, bottom, guess_cm);
    let base = p.base_height_cm;
    let heights = [base + 2.0 * p.band_height_cm, base + p.band_height_cm, base];
    let raw = [edges.top, edges.middle, edges.bottom];
    let unskew = |d: f64| {
        raw.map(|e| {
            e.map(|q| {
                if p.skew_correction {
                    ctx.unskew_at(q, d, true)
                } else {
                    q
                }
            })
        })
    };
    // Twice: the skew removal places each edge at a distance, which the first pass estimates.
    let mut guess = guess_cm;
    let mut result = None;
    for _ in 0..2 {
        let moved = unskew(guess);
        let Some((near, camera_z, source)) = near_side_distance(ctx, heights, moved) else {
            break;
        };
        let horizontal = near + p.diameter_cm / 2.0;
        let distance = horizontal.hypot(heights[1] - camera_z);
        let at = moved[1].unwrap_or_else(|| {
            let (tx, ty) = top.centroid();
            let (bx, by) = bottom.centroid();
            ImagePoint::new(tx, ty).midpoint(ImagePoint::new(bx, by))
        });
        guess = distance;
        result = Some(Measured {
            distance_cm: distance,
            at,
            source,
            edges: raw.iter().flatten().copied().collect(),
        });
    }
    result.unwrap_or_else(|| by_width(ctx, p, top, bottom))
}

/// The distance from the angle between the rays through the left and right sides of the wider
/// band at its middle row: a cylinder of radius r at distance D subtends 2·asin(r / D).
fn by_width(ctx: &ViewContext, p: &BeaconParams, top: &Blob, bottom: &Blob) -> Measured {
    let wide = if top.width() >= bottom.width() {
        top
    } else {
        bottom
    };
    let (_, cy) = wide.centroid();
    let left = ImagePoint::new(f64::from(wide.minx), cy);
    let right = ImagePoint::new(f64::from(wide.maxx) + 1.0, cy);
    let (a, b) = (
        ctx.camera.unit_ray(left).coords,
        ctx.camera.unit_ray(right).coords,
    );
    let angle = a.angle(&b);
    let half = (angle / 2.0).sin();
    let distance = if half > 1e-9 {
        p.diameter_cm / 2.0 / half
    } else {
        f64::INFINITY
    };
    let (tx, ty) = top.centroid();
    let (bx, by) = bottom.centroid();
    Measured {
        distance_cm: distance,
        at: ImagePoint::new(tx, ty).midpoint(ImagePoint::new(bx, by)),
        source: DistanceSource::Width,
        edges: Vec::new(),
    }
}

/// A band standing on its base with the band above it cut off (the top of the image): the
/// distance from its bottom edge and the camera's height when they differ enough, else from its
/// width.
#[must_use]
pub fn measure_band_over_base(
    img: &ClassifiedImage,
    ctx: &ViewContext,
    p: &BeaconParams,
    band: &Blob,
    guess_cm: f64,
) -> Measured {
    let (x, y) = band.centroid();
    let centre = ImagePoint::new(x, y);
    let down = down_at(ctx, centre, guess_cm);
    let reach = f64::from(band.height()) * 1.5 + 4.0;
    let s = Samples::take(
        img,
        centre,
        down,
        &offsets(f64::from(band.width())),
        [0.0, reach],
    );
    let last = s.index(reach);
    let bottom = s
        .edge(
            [0, last],
            |k| s.share(k, band.colour),
            true,
            0.3,
            Some(false),
        )
        .map(|t| s.point(t));
    let moved = bottom.map(|q| {
        if p.skew_correction {
            ctx.unskew_at(q, guess_cm, true)
        } else {
            q
        }
    });
    let base = p.base_height_cm;
    let heights = [base + 2.0 * p.band_height_cm, base + p.band_height_cm, base];
    if let Some((near, camera_z, source)) = near_side_distance(ctx, heights, [None, None, moved]) {
        let horizontal = near + p.diameter_cm / 2.0;
        return Measured {
            distance_cm: horizontal.hypot(heights[1] - camera_z),
            at: centre,
            source,
            edges: bottom.into_iter().collect(),
        };
    }
    let mut m = by_width(ctx, p, band, band);
    m.edges = bottom.into_iter().collect();
    m
}

/// What lies below a band: the share of white right below it across the middle half of its
/// width, and beside that, a band's width out on either side.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BaseBelow {
    /// White share below the band (0..1; 0 when nothing below is in the image).
    pub white_below: f64,
    /// White share beside the base (0..1).
    pub white_beside: f64,
}

/// Samples the base below `band`: from its bottom row down by its width (at least 3 px) along
/// the axis direction, across the middle half of its width, and the same strips a width to its
/// left and right.
#[must_use]
pub fn base_below(
    img: &ClassifiedImage,
    ctx: &ViewContext,
    band: &Blob,
    guess_cm: f64,
) -> BaseBelow {
    let white = ColourClass::White.code();
    let (x, _) = band.centroid();
    let start = ImagePoint::new(x, f64::from(band.maxy) + 1.5);
    let down = down_at(ctx, start, guess_cm);
    let across = (down.1, -down.0);
    let width = f64::from(band.width());
    let depth = width.max(3.0);
    let share = |offset: f64| {
        let (mut seen, mut hits) = (0u32, 0u32);
        let mut t = 0.0;
        while t <= depth {
            let mut s = offset - width / 4.0;
            while s <= offset + width / 4.0 {
                let q = ImagePoint::new(
                    start.x_px + t * down.0 + s * across.0,
                    start.y_px + t * down.1 + s * across.1,
                );
                if let Some(c) = img.get_at(q.x_px, q.y_px) {
                    seen += 1;
                    hits += u32::from(c == white);
                }
                s += 1.0;
            }
            t += 1.0;
        }
        (seen > 0).then(|| f64::from(hits) / f64::from(seen))
    };
    let beside = [share(-width), share(width)];
    BaseBelow {
        white_below: share(0.0).unwrap_or(0.0),
        white_beside: beside.iter().flatten().copied().fold(0.0, f64::max),
    }
}
