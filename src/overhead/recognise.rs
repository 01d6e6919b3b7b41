//! The overhead recogniser: ball and robot markers in a classified overhead image, in field
//! coordinates through a calibrated camera.
//!
//! - **Ball**: orange blobs whose size matches the ball's image size at that place (the
//!   calibration says how large an 8.5 cm sphere looks there), refined by a circle fit on the
//!   blob's outline (`recognition::fit`), placed on the plane at the ball centre's height.
//! - **Robots**: sky-blue or yellow blobs the size and shape of a team dot, placed on the plane
//!   of the marker plates; around each, the four identity dots are looked for where the layout
//!   puts them: a ring of samples 10 cm from the centre gives the heading (the dots' uneven
//!   spacing fixes it), then each dot's own pixels give its colour (its bit) and its centroid,
//!   and the four centroids refine the heading.
//!
//! Output per frame: [`OverheadDetections`], plus the rejected candidates with their reasons
//! for the overlays.

use std::cell::Cell;
use std::time::{Duration, Instant};

use serde::{Deserialize, Serialize};

use crate::blobs::{Blob, BlobSet};
use crate::classify::ClassifiedImage;
use crate::frame::PixelBox;
use crate::geometry::marker::ID_DOT_ANGLES_DEG;
use crate::geometry::{
    Field, ImagePoint, MarkerIdentity, MarkerTeam, OverheadCamera, OverheadProjector, Point,
};
use crate::lut::ColourClass;
use crate::recognition::OverheadRecognitionParams;
use crate::recognition::fit::fit_circle;

/// Settings of the overhead recogniser: the field's ball radius and plate height, and the
/// tunable rest (the `overhead` section of the recognition parameters, its keys at the top
/// level here as in a session's overhead parameters file).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct OverheadParams {
    /// Ball radius, centimetres.
    pub ball_radius_cm: f64,
    /// Height of the marker plates, centimetres.
    pub plate_height_cm: f64,
    /// Marker and ball sizes, fills, layout agreement.
    #[serde(flatten)]
    pub recogniser: OverheadRecognitionParams,
}

impl Default for OverheadParams {
    fn default() -> Self {
        Self {
            ball_radius_cm: 4.25,
            plate_height_cm: crate::geometry::marker::DEFAULT_PLATE_HEIGHT_CM,
            recogniser: OverheadRecognitionParams::default(),
        }
    }
}

/// The ball seen from above.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct OverheadBall {
    /// Field position of its centre projected down, centimetres `[x, y]`.
    pub field_cm: [f64; 2],
    /// Image position of its centre, pixels.
    pub image: ImagePoint,
    /// Image radius, pixels.
    pub radius_px: f64,
    /// Confidence, 0 to 1.
    pub confidence: f64,
}

/// A robot read from its marker.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct OverheadRobot {
    /// Team dot colour.
    pub team: MarkerTeam,
    /// Identity read from the four dots.
    pub identity: MarkerIdentity,
    /// Field position of the plate's centre projected down, centimetres `[x, y]`.
    pub field_cm: [f64; 2],
    /// Heading, radians counter-clockwise from +x, in (−π, π].
    pub heading_rad: f64,
    /// Image position of the plate's centre, pixels.
    pub image: ImagePoint,
    /// Image positions of the four identity dots (bit 0 first), pixels.
    pub dots: [ImagePoint; 4],
    /// Confidence, 0 to 1.
    pub confidence: f64,
}

/// Why a blob was not taken for a ball or a team dot.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "reason", rename_all = "snake_case")]
pub enum OverheadRejection {
    /// Its area is far from the expected image area there.
    Size {
        /// Blob pixels.
        pixels: u32,
        /// Expected pixels.
        expected: f64,
        /// The accepted range of pixels / expected (`OverheadParams::area_ratio`).
        #[serde(default)]
        accepted_ratio: [f64; 2],
    },
    /// Its box is too long for a disc: width / height outside 1:2 to 2:1.
    Shape {
        /// Box width / height.
        aspect: f64,
    },
    /// It fills too little of its box for a disc (a ring, a speckled or ragged blob).
    Fill {
        /// Blob pixels / box area.
        fill: f64,
        /// The least fill accepted (a disc fills π/4 of its box).
        min: f64,
    },
    /// The camera does not see its place on the field.
    OffField,
    /// No marker layout around a team dot.
    NoMarker {
        /// Share of the ring samples that agreed at the best heading.
        agreement: f64,
        /// The least share accepted (`OverheadParams::min_layout_agreement`).
        #[serde(default)]
        needed: f64,
    },
    /// Another candidate was better.
    Duplicate,
}

impl std::fmt::Display for OverheadRejection {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Size {
                pixels,
                expected,
                accepted_ratio: [lo, hi],
            } => write!(
                f,
                "size: {pixels} px where {expected:.0} px are expected ({:.2}×; {lo:.2}× to {hi:.2}× accepted)",
                f64::from(*pixels) / expected.max(1e-9)
            ),
            Self::Shape { aspect } => write!(
                f,
                "shape: its box is {aspect:.2} wide per unit of height (0.5 to 2 accepted)"
            ),
            Self::Fill { fill, min } => write!(
                f,
                "fill: it covers {:.0} % of its box, at least {:.0} % needed",
                fill * 100.0,
                min * 100.0
            ),
            Self::OffField => f.write_str("off the field: the calibration places it nowhere"),
            Self::NoMarker { agreement, needed } => write!(
                f,
                "no marker: {:.0} % of the ring samples around it agree with the marker layout, {:.0} % needed",
                agreement * 100.0,
                needed * 100.0
            ),
            Self::Duplicate => f.write_str("duplicate: another candidate was better"),
        }
    }
}

/// A rejected candidate, for overlays.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct RejectedCandidate {
    /// Blob box, inclusive pixels (`[minx, miny, maxx, maxy]` in JSON).
    pub bounds: PixelBox,
    /// Blob class code.
    pub colour: u8,
    /// Why.
    pub reason: OverheadRejection,
}

/// What one overhead frame shows.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct OverheadDetections {
    /// The ball, if found.
    pub ball: Option<OverheadBall>,
    /// Robots, in image order of their team dots.
    pub robots: Vec<OverheadRobot>,
    /// Candidates not taken.
    pub rejected: Vec<RejectedCandidate>,
}

/// Recognises ball and robots in a classified overhead image.
#[must_use]
pub fn recognise_overhead(
    image: &ClassifiedImage,
    blobs: &BlobSet,
    camera: &OverheadCamera,
    params: &OverheadParams,
) -> OverheadDetections {
    recognise_overhead_timed(image, blobs, camera, params).0
}

/// Where recognition's time went on one frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct RecognitionParts {
    /// Finding the ball.
    pub ball: Duration,
    /// Reading the robot markers (and keeping one of two candidates at one place).
    pub markers: Duration,
    /// Field points carried into the image (pose, then the lens's distortion) in both.
    pub to_image: u32,
    /// Image points carried onto the field (the lens's undistortion, then the pose) in both.
    pub to_field: u32,
}

/// [`recognise_overhead`], with where its time went.
#[must_use]
pub fn recognise_overhead_timed(
    image: &ClassifiedImage,
    blobs: &BlobSet,
    camera: &OverheadCamera,
    params: &OverheadParams,
) -> (OverheadDetections, RecognitionParts) {
    let t0 = Instant::now();
    let camera = &Lens::new(camera);
    let mut out = OverheadDetections::default();
    out.ball = find_ball(blobs, camera, params, &mut out.rejected);
    let t1 = Instant::now();
    out.robots = find_robots(image, blobs, camera, params, &mut out.rejected);
    let parts = RecognitionParts {
        ball: t1 - t0,
        markers: t1.elapsed(),
        to_image: camera.to_image.get(),
        to_field: camera.to_field.get(),
    };
    (out, parts)
}

/// The camera as recognition uses it: its pose built once, and counts of the points carried
/// through it each way.
struct Lens {
    projector: OverheadProjector,
    to_image: Cell<u32>,
    to_field: Cell<u32>,
}

impl Lens {
    fn new(camera: &OverheadCamera) -> Self {
        Self {
            projector: camera.projector(),
            to_image: Cell::new(0),
            to_field: Cell::new(0),
        }
    }

    fn image_from_field(&self, p: &Point<Field>) -> Option<ImagePoint> {
        self.to_image.set(self.to_image.get().saturating_add(1));
        self.projector.image_from_field(p)
    }

    fn field_from_image(&self, p: ImagePoint, z_cm: f64) -> Option<Point<Field>> {
        self.to_field.set(self.to_field.get().saturating_add(1));
        self.projector.field_from_image(p, z_cm)
    }
}

/// Every robot whose marker reads around a team dot; of two within a plate of each other the
/// more confident; in image order.
fn find_robots(
    image: &ClassifiedImage,
    blobs: &BlobSet,
    camera: &Lens,
    params: &OverheadParams,
    rejected_out: &mut Vec<RejectedCandidate>,
) -> Vec<OverheadRobot> {
    let mut robots = Vec::new();
    for blob in blobs.active() {
        let Some(team) = MarkerTeam::from_class(blob.class()) else {
            continue;
        };
        match read_marker(image, blob, team, camera, params) {
            Ok(r) => robots.push(r),
            Err(reason) => rejected_out.push(rejected(blob, reason)),
        }
    }
    // Two candidates within a plate of each other: keep the more confident.
    robots.sort_by(|a, b| b.confidence.total_cmp(&a.confidence));
    let mut kept: Vec<OverheadRobot> = Vec::new();
    for r in robots {
        let close = kept
            .iter()
            .any(|k| (k.field_cm[0] - r.field_cm[0]).hypot(k.field_cm[1] - r.field_cm[1]) < 20.0);
        if close {
            rejected_out.push(RejectedCandidate {
                bounds: box_around(r.image, 4.0),
                colour: r.team.class().code(),
                reason: OverheadRejection::Duplicate,
            });
        } else {
            kept.push(r);
        }
    }
    kept.sort_by(|a, b| {
        (a.image.y_px, a.image.x_px)
            .partial_cmp(&(b.image.y_px, b.image.x_px))
            .unwrap_or(std::cmp::Ordering::Equal)
    });
    kept
}

fn rejected(blob: &Blob, reason: OverheadRejection) -> RejectedCandidate {
    RejectedCandidate {
        bounds: blob.bounds(),
        colour: blob.colour,
        reason,
    }
}

fn box_around(p: ImagePoint, r: f64) -> PixelBox {
    let c = |v: f64| v.max(0.0) as u32;
    PixelBox::new(c(p.x_px - r), c(p.y_px - r), c(p.x_px + r), c(p.y_px + r))
}

/// Image radius (pixels) of a disc or sphere of `radius_cm` centred at field point `p`: the
/// mean image distance of four points `radius_cm` away across the viewing ray.
fn image_radius_px(camera: &Lens, p: &Point<Field>, radius_cm: f64) -> Option<f64> {
    let c = camera.image_from_field(p)?;
    let mut sum = 0.0;
    for (dx, dy) in [(1.0, 0.0), (0.0, 1.0), (-1.0, 0.0), (0.0, -1.0)] {
        let q = camera.image_from_field(&Point::new(
            p.x() + dx * radius_cm,
            p.y() + dy * radius_cm,
            p.z(),
        ))?;
        sum += q.distance_to(&c);
    }
    Some(sum / 4.0)
}

/// Checks a blob's size against a disc of `radius_cm` at height `z_cm`; gives its field point.
fn sized_like(
    blob: &Blob,
    camera: &Lens,
    z_cm: f64,
    radius_cm: f64,
    min_fill: f64,
    params: &OverheadParams,
) -> Result<(Point<Field>, f64, f64), OverheadRejection> {
    let (cx, cy) = blob.centroid();
    let ground = camera
        .field_from_image(ImagePoint::new(cx, cy), z_cm)
        .ok_or(OverheadRejection::OffField)?;
    let expected_r =
        image_radius_px(camera, &ground, radius_cm).ok_or(OverheadRejection::OffField)?;
    let expected = std::f64::consts::PI * expected_r * expected_r;
    let ratio = f64::from(blob.pixels) / expected.max(1e-9);
    let area_ratio = params.recogniser.area_ratio;
    if !(area_ratio[0]..=area_ratio[1]).contains(&ratio) {
        return Err(OverheadRejection::Size {
            pixels: blob.pixels,
            expected,
            accepted_ratio: area_ratio,
        });
    }
    let aspect = f64::from(blob.width()) / f64::from(blob.height());
    if !(0.5..=2.0).contains(&aspect) {
        return Err(OverheadRejection::Shape { aspect });
    }
    let fill = f64::from(blob.pixels) / blob.area() as f64;
    if fill < min_fill {
        return Err(OverheadRejection::Fill {
            fill,
            min: min_fill,
        });
    }
    Ok((ground, expected_r, ratio))
}

/// Outline points of a blob: the outermost run ends of each row (holes inside a speckled blob
/// are no outline).
fn outline_points(blobs: &BlobSet, blob: &Blob) -> Vec<ImagePoint> {
    let mut rows: Vec<(u16, u16, u16)> = Vec::new();
    for run in blobs.runs_of(blob.number) {
        match rows.iter_mut().find(|r| r.0 == run.y) {
            Some(r) => {
                r.1 = r.1.min(run.x0);
                r.2 = r.2.max(run.x1);
            }
            None => rows.push((run.y, run.x0, run.x1)),
        }
    }
    rows.iter()
        .flat_map(|&(y, x0, x1)| {
            let y = f64::from(y) + 0.5;
            [
                ImagePoint::new(f64::from(x0), y),
                ImagePoint::new(f64::from(x1), y),
            ]
        })
        .collect()
}

fn find_ball(
    blobs: &BlobSet,
    camera: &Lens,
    params: &OverheadParams,
    rejected_out: &mut Vec<RejectedCandidate>,
) -> Option<OverheadBall> {
    let r_cm = params.ball_radius_cm;
    let mut best: Option<OverheadBall> = None;
    for blob in blobs.of_class(ColourClass::Orange) {
        let (_, expected_r, ratio) = match sized_like(
            blob,
            camera,
            r_cm,
            r_cm,
            params.recogniser.ball_min_fill,
            params,
        ) {
            Ok(v) => v,
            Err(reason) => {
                if blob.pixels >= 3 {
                    rejected_out.push(rejected(blob, reason));
                }
                continue;
            }
        };
        let outline = outline_points(blobs, blob);
        let (cx, cy) = blob.centroid();
        let (centre, radius) = match fit_circle(&outline) {
            Some(fit)
                if (fit.radius - expected_r).abs() < 0.5 * expected_r
                    && (fit.center_x - cx).hypot(fit.center_y - cy) < expected_r =>
            {
                (fit.center(), fit.radius)
            }
            _ => (
                ImagePoint::new(cx, cy),
                (f64::from(blob.pixels) / std::f64::consts::PI).sqrt(),
            ),
        };
        let Some(ground) = camera.field_from_image(centre, r_cm) else {
            continue;
        };
        // A speckled ball shows half its area or less: a wide tolerance.
        let size_match = (-(ratio.ln() / 0.8).powi(2)).exp();
        let confidence = size_match.clamp(0.0, 1.0);
        if best.is_none_or(|b| confidence > b.confidence) {
            if let Some(old) = best {
                rejected_out.push(RejectedCandidate {
                    bounds: box_around(old.image, old.radius_px),
                    colour: ColourClass::Orange.code(),
                    reason: OverheadRejection::Duplicate,
                });
            }
            best = Some(OverheadBall {
                field_cm: [ground.x(), ground.y()],
                image: centre,
                radius_px: radius,
                confidence,
            });
        }
    }
    best
}

/// Ring samples per turn for the heading search.
const RING_SAMPLES: usize = 180;

/// Whether a class belongs to an identity dot.
fn is_dot(code: u8) -> bool {
    code == ColourClass::Pink.code() || code == ColourClass::Green.code()
}

fn read_marker(
    image: &ClassifiedImage,
    blob: &Blob,
    team: MarkerTeam,
    camera: &Lens,
    params: &OverheadParams,
) -> Result<OverheadRobot, OverheadRejection> {
    let z = params.plate_height_cm;
    let marker = &params.recogniser;
    let ring_r = marker.id_dot_ring_radius_cm;
    let (centre, _, ratio) = sized_like(
        blob,
        camera,
        z,
        marker.team_dot_diameter_cm / 2.0,
        marker.team_dot_min_fill,
        params,
    )?;
    // Ring of samples through the dots' centres: which angles show a dot.
    let ring: Vec<bool> = (0..RING_SAMPLES)
        .map(|k| {
            let a = k as f64 * std::f64::consts::TAU / RING_SAMPLES as f64;
            let p = Point::new(
                centre.x() + ring_r * a.cos(),
                centre.y() + ring_r * a.sin(),
                z,
            );
            camera
                .image_from_field(&p)
                .and_then(|q| image.get_at(q.x_px, q.y_px))
                .is_some_and(is_dot)
        })
        .collect();
    let (heading, agreement) = best_layout_heading(&ring, marker.id_dot_diameter_cm / 2.0 / ring_r);
    if agreement < marker.min_layout_agreement {
        return Err(OverheadRejection::NoMarker {
            agreement,
            needed: marker.min_layout_agreement,
        });
    }
    // Each dot's own pixels: colour (majority) and centroid.
    let dot_r = marker.id_dot_diameter_cm / 2.0;
    let mut bits = [false; 4];
    let mut dots = [ImagePoint::default(); 4];
    let mut heading_sum = (0.0, 0.0);
    for (k, angle_deg) in ID_DOT_ANGLES_DEG.iter().enumerate() {
        let a = heading + angle_deg.to_radians();
        let expected = Point::new(
            centre.x() + ring_r * a.cos(),
            centre.y() + ring_r * a.sin(),
            z,
        );
        let Some(q) = camera.image_from_field(&expected) else {
            return Err(OverheadRejection::OffField);
        };
        let r_px = image_radius_px(camera, &expected, 1.35 * dot_r).unwrap_or(4.0);
        let dot = dot_pixels(image, q, r_px);
        bits[k] = dot.pink > dot.green;
        dots[k] = dot.centroid.unwrap_or(q);
        if let Some(g) = dot.centroid.and_then(|c| camera.field_from_image(c, z)) {
            let measured = (g.y() - centre.y()).atan2(g.x() - centre.x());
            let h = measured - angle_deg.to_radians();
            let w = f64::from(dot.pink + dot.green);
            heading_sum.0 += w * h.cos();
            heading_sum.1 += w * h.sin();
        }
    }
    let refined = if heading_sum.0.hypot(heading_sum.1) > 0.0 {
        heading_sum.1.atan2(heading_sum.0)
    } else {
        heading
    };
    let size_match = (-((ratio.ln()) / 0.6).powi(2)).exp();
    let image_centre = camera
        .image_from_field(&centre)
        .unwrap_or(ImagePoint::new(blob.centroid().0, blob.centroid().1));
    Ok(OverheadRobot {
        team,
        identity: MarkerIdentity::from_bits(bits),
        field_cm: [centre.x(), centre.y()],
        heading_rad: refined,
        image: image_centre,
        dots,
        confidence: (agreement * size_match).clamp(0.0, 1.0),
    })
}

/// The heading (radians) whose four dot arcs best match the ring, and the share of ring
/// samples that agree with the layout there (dot inside an arc, none outside). The first best
/// turn wins a tie. `dot_over_ring` is an identity dot's radius over the ring's radius (their
/// sine gives each dot's half-width as an angle).
///
/// Every turn of the layout is tried against the ring as bits, a word at a time: at 180 samples
/// that is 180 × 3 word compares where sample by sample it was 180 × 180 (the slowest part of
/// reading a marker at 1920×1200, docs/speed.md).
fn best_layout_heading(ring: &[bool], dot_over_ring: f64) -> (f64, f64) {
    let n = ring.len();
    if n == 0 || n > RING_BITS {
        return (0.0, 0.0);
    }
    let template = layout_template(n, dot_over_ring);
    // The ring twice over, so a turn by `shift` is the n bits from bit `shift`.
    let mut doubled = [0u64; 2 * RING_WORDS + 1];
    for (k, &dot) in ring.iter().chain(ring).enumerate() {
        doubled[k / 64] |= u64::from(dot) << (k % 64);
    }
    let mut best = (0, 0);
    for shift in 0..n {
        let mut differ = 0;
        for (w, t) in template.iter().enumerate() {
            let (i, o) = ((shift + 64 * w) / 64, (shift + 64 * w) % 64);
            let mut word = doubled[i] >> o;
            if o > 0 {
                word |= doubled[i + 1] << (64 - o);
            }
            differ += ((word ^ t) & word_mask(n, w)).count_ones() as usize;
        }
        let agree = n - differ;
        if agree > best.1 {
            best = (shift, agree);
        }
    }
    let step = std::f64::consts::TAU / n as f64;
    let heading = best.0 as f64 * step;
    let heading =
        (heading + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI;
    (heading, best.1 as f64 / n as f64)
}

/// Most ring samples the bit form holds.
const RING_BITS: usize = 64 * RING_WORDS;
const RING_WORDS: usize = 3;

/// The bits of word `w` that hold samples of an `n`-sample ring.
fn word_mask(n: usize, w: usize) -> u64 {
    match n.saturating_sub(64 * w) {
        0 => 0,
        k if k >= 64 => u64::MAX,
        k => (1u64 << k) - 1,
    }
}

/// [`layout_bits`] of a ring, kept per thread for the last ring size and dot ratio asked (the
/// same for every marker of a camera's parameters).
fn layout_template(n: usize, dot_over_ring: f64) -> [u64; RING_WORDS] {
    type Kept = Option<(usize, u64, [u64; RING_WORDS])>;
    thread_local! {
        static LAST: std::cell::Cell<Kept> = const { std::cell::Cell::new(None) };
    }
    let key = (n, dot_over_ring.to_bits());
    LAST.with(|last| match last.get() {
        Some((kn, kb, t)) if (kn, kb) == key => t,
        _ => {
            let t = layout_bits(n, dot_over_ring);
            last.set(Some((key.0, key.1, t)));
            t
        }
    })
}

/// The marker layout at heading 0 on a ring of `n` (at most [`RING_BITS`]) samples: sample k
/// (at angle k·2π/n) is set when it falls on an identity dot of radius `dot_over_ring` (of the
/// ring's radius).
fn layout_bits(n: usize, dot_over_ring: f64) -> [u64; RING_WORDS] {
    let half_width = dot_over_ring.clamp(0.0, 1.0).asin();
    let step = std::f64::consts::TAU / n as f64;
    let mut bits = [0u64; RING_WORDS];
    for k in 0..n.min(RING_BITS) {
        let a = k as f64 * step;
        let on_dot = ID_DOT_ANGLES_DEG.iter().any(|d| {
            let diff = (a - d.to_radians() + std::f64::consts::PI)
                .rem_euclid(std::f64::consts::TAU)
                - std::f64::consts::PI;
            diff.abs() <= half_width
        });
        bits[k / 64] |= u64::from(on_dot) << (k % 64);
    }
    bits
}

#[derive(Debug, Default)]
struct DotPixels {
    pink: u32,
    green: u32,
    centroid: Option<ImagePoint>,
}

/// Pink and green pixels within `r_px` of `q`, and their centroid.
fn dot_pixels(image: &ClassifiedImage, q: ImagePoint, r_px: f64) -> DotPixels {
    let mut d = DotPixels::default();
    let (mut sx, mut sy) = (0.0, 0.0);
    let (x0, x1) = ((q.x_px - r_px).floor().max(0.0), (q.x_px + r_px).ceil());
    let (y0, y1) = ((q.y_px - r_px).floor().max(0.0), (q.y_px + r_px).ceil());
    let r2 = r_px * r_px;
    for y in y0 as usize..=(y1.max(0.0) as usize) {
        for x in x0 as usize..=(x1.max(0.0) as usize) {
            let (px, py) = (x as f64 + 0.5, y as f64 + 0.5);
            if (px - q.x_px).powi(2) + (py - q.y_px).powi(2) > r2 {
                continue;
            }
            match image.get(x, y) {
                Some(c) if c == ColourClass::Pink.code() => d.pink += 1,
                Some(c) if c == ColourClass::Green.code() => d.green += 1,
                _ => continue,
            }
            sx += px;
            sy += py;
        }
    }
    let n = d.pink + d.green;
    if n > 0 {
        d.centroid = Some(ImagePoint::new(sx / f64::from(n), sy / f64::from(n)));
    }
    d
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_layout_heading_is_found_from_a_ring_alone() {
        for heading_deg in [0.0f64, 37.0, -100.0, 170.0] {
            let h = heading_deg.to_radians();
            let half = (0.3f64).asin();
            let ring: Vec<bool> = (0..RING_SAMPLES)
                .map(|k| {
                    let a = k as f64 * std::f64::consts::TAU / RING_SAMPLES as f64;
                    ID_DOT_ANGLES_DEG.iter().any(|d| {
                        let diff = (a - h - d.to_radians() + std::f64::consts::PI)
                            .rem_euclid(std::f64::consts::TAU)
                            - std::f64::consts::PI;
                        diff.abs() <= half
                    })
                })
                .collect();
            let (found, agreement) = best_layout_heading(&ring, 0.3);
            let err = (found - h + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU)
                - std::f64::consts::PI;
            assert!(err.abs() < 0.04, "{heading_deg}: {found}");
            assert!(agreement > 0.97, "{agreement}");
        }
    }

    /// The sample-by-sample search the bit form replaced, as the reference it must equal.
    fn best_layout_heading_by_sample(ring: &[bool], dot_over_ring: f64) -> (f64, f64) {
        let n = ring.len();
        let half_width = dot_over_ring.asin();
        let step = std::f64::consts::TAU / n as f64;
        let template: Vec<bool> = (0..n)
            .map(|k| {
                let a = k as f64 * step;
                ID_DOT_ANGLES_DEG.iter().any(|d| {
                    let diff = (a - d.to_radians() + std::f64::consts::PI)
                        .rem_euclid(std::f64::consts::TAU)
                        - std::f64::consts::PI;
                    diff.abs() <= half_width
                })
            })
            .collect();
        let mut best = (0, 0);
        for shift in 0..n {
            let agree = (0..n)
                .filter(|&k| ring[(k + shift) % n] == template[k])
                .count();
            if agree > best.1 {
                best = (shift, agree);
            }
        }
        let heading = best.0 as f64 * step;
        let heading = (heading + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU)
            - std::f64::consts::PI;
        (heading, best.1 as f64 / n as f64)
    }

    #[test]
    fn the_bit_search_equals_the_sample_search_on_any_ring() {
        let mut state = 0x2545_f491_4f6c_dd1d_u64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        for n in [RING_SAMPLES, 64, 65, 128, 130, 191, 192, 7] {
            for density in [2, 4, 8, 64] {
                let ring: Vec<bool> = (0..n).map(|_| next() % density == 0).collect();
                for ratio in [0.3, 0.25] {
                    assert_eq!(
                        best_layout_heading(&ring, ratio),
                        best_layout_heading_by_sample(&ring, ratio),
                        "{n} samples, 1 in {density} set, dot/ring {ratio}"
                    );
                }
            }
        }
        assert_eq!(best_layout_heading(&[], 0.3), (0.0, 0.0));
    }

    #[test]
    fn an_all_black_ring_is_no_marker() {
        let (_, agreement) = best_layout_heading(&[false; RING_SAMPLES], 0.3);
        assert!(
            agreement < OverheadParams::default().recogniser.min_layout_agreement,
            "{agreement}"
        );
    }
}
