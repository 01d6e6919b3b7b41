//! The confidence tests of one ball candidate (colour, fill, shape, height, green below).

use super::circle::{CircleStage, FitRejection};
use super::outline::Outline;
use super::{BallParams, is_ball_colour};
use crate::blobs::Blob;
use crate::classify::ClassifiedImage;
use crate::frame::PixelBox;
use crate::geometry::ImagePoint;
use crate::lut::ColourClass;
use crate::recognition::confidence::{Confidence, TestName, TestWeight};
use crate::recognition::context::ViewContext;
use crate::recognition::scan::{ScanArea, scan_rotated_rect};

/// What the earlier stages measured of one candidate.
pub(super) struct Measured<'a> {
    /// The joined blobs.
    pub group: &'a Blob,
    /// Pixels of basic orange in them.
    pub orange_pixels: u32,
    /// The outline stage's result.
    pub outline: &'a Outline,
    /// The fit stage's result.
    pub circle: &'a CircleStage,
    /// Centre at the reference read-out time, pixels.
    pub center: ImagePoint,
    /// Centre where the image shows the ball, pixels.
    pub observed_center: ImagePoint,
    /// Radius, pixels.
    pub radius: f64,
    /// Camera distance, centimetres.
    pub distance: f64,
}

/// Every test of one candidate, in order, and the colour-below scan area.
pub(super) fn score(
    img: &ClassifiedImage,
    ctx: &ViewContext,
    m: &Measured<'_>,
    params: &BallParams,
) -> (Confidence, ScanArea) {
    let mut confidence = Confidence::default();
    colour_tests(&mut confidence, img, m, params);
    shape_tests(&mut confidence, m, params);
    let below = place_tests(&mut confidence, img, ctx, m, params);
    (confidence, below)
}

/// Orange share, circle fill, unclassified pixels around.
fn colour_tests(
    confidence: &mut Confidence,
    img: &ClassifiedImage,
    m: &Measured<'_>,
    params: &BallParams,
) {
    confidence.range_test(
        TestName::OrangeFraction,
        f64::from(m.orange_pixels) / f64::from(m.group.pixels.max(1)),
        params.orange_fraction,
        params.orange_fraction_weight,
    );
    match circle_fill(img, m.observed_center, m.radius) {
        Some(fill) => confidence.range_test(
            TestName::CircleFill,
            fill,
            params.circle_fill,
            params.circle_fill_weight,
        ),
        None => confidence.skipped(TestName::CircleFill, params.circle_fill),
    }
    if let Some(share) = unclassified_around(img, m.outline.bounds, params.unclassified_ring_gap_px)
    {
        confidence.range_test(
            TestName::UnclassifiedAround,
            share,
            params.unclassified_around,
            params.unclassified_around_weight,
        );
    }
}

/// Cut extent, the circle fit's residual and points, pixel ratio and roundness.
fn shape_tests(confidence: &mut Confidence, m: &Measured<'_>, params: &BallParams) {
    let (w, h, cut) = (m.outline.width, m.outline.height, m.outline.cut);
    let horizontal_cut = cut.left || cut.right;
    let vertical_cut = cut.top || cut.bottom;
    if horizontal_cut != vertical_cut {
        let slack = params.extent_slack_px;
        let ratio = if horizontal_cut {
            w / (h + slack)
        } else {
            h / (w + slack)
        };
        confidence.range_test(
            TestName::CutExtent,
            ratio,
            [0.0, params.max_cut_extent_ratio],
            params.cut_extent_weight,
        );
    }
    let fit = m.circle.fit.as_ref();
    if let (Some(f), Some(FitRejection::ResidualTooLarge { .. })) = (fit, m.circle.rejection) {
        confidence.range_test(
            TestName::CircleResidualPx,
            f.residual_sd,
            [0.0, params.max_fit_residual_ratio * f.radius + 0.75],
            TestWeight::new(0.0, params.bad_circle_penalty),
        );
    }
    if let Some(f) = fit
        && m.circle.used()
        && f.radius >= params.circle_fit_min_radius_px
    {
        confidence.bonus_test(
            TestName::CircleFitPoints,
            f.points as f64,
            [params.circle_fit_min_points as f64, f64::INFINITY],
            params.circle_fit_bonus,
        );
    }
    if fit.is_none() && m.outline.points.len() >= 5 {
        // Enough outline points, but on a line: a straight edge.
        confidence.range_test(
            TestName::CircleFit,
            0.0,
            [1.0, 1.0],
            TestWeight::new(0.0, params.bad_circle_penalty),
        );
    }
    if cut.any() {
        confidence.skipped(TestName::PixelRatio, params.pixel_ratio);
        confidence.skipped(TestName::Roundness, params.aspect);
    } else {
        confidence.range_test(
            TestName::PixelRatio,
            f64::from(m.group.pixels) / (w * h),
            params.pixel_ratio,
            params.pixel_ratio_weight,
        );
        confidence.range_test(
            TestName::Roundness,
            w / h,
            params.aspect,
            params.aspect_weight,
        );
    }
}

/// Height above the ground and green below; returns the colour-below scan area.
fn place_tests(
    confidence: &mut Confidence,
    img: &ClassifiedImage,
    ctx: &ViewContext,
    m: &Measured<'_>,
    params: &BallParams,
) -> ScanArea {
    let (center, radius) = (m.center, m.radius);
    // The pose's angular error turns into a height error that grows with distance.
    let slack = m.distance * params.height_pose_slack_rad.tan();
    let height_range = if slack.is_finite() && slack > 0.0 {
        [params.height_cm[0] - slack, params.height_cm[1] + slack]
    } else {
        params.height_cm
    };
    let height = ctx.height_above_ground(center, m.distance);
    match height {
        Some(z) => confidence.range_test(TestName::HeightCm, z, height_range, params.height_weight),
        None => confidence.skipped(TestName::HeightCm, height_range),
    }
    // Colour below: an area under the ball, parallel to the horizon, where the ball is in
    // the image (the centre before skew removal).
    let shift = m.outline.box_shift;
    let below_scan = scan_rotated_rect(
        img,
        center - shift,
        [
            -radius,
            radius,
            radius + 1.0,
            radius + 1.0 + (radius * 0.8).max(2.0),
        ],
        -ctx.horizon_angle(),
        (radius / 6.0).max(1.0),
    );
    match below_scan.ratio(|c| c == ColourClass::Green.code()) {
        Some(green) => confidence.bonus_test(
            TestName::GreenBelow,
            green,
            params.green_below,
            params.green_below_bonus,
        ),
        None => confidence.skipped(TestName::GreenBelow, params.green_below),
    }
    if height.is_none() {
        // No pose, so no height: an orange thing off the field (in the audience, on a table, a
        // chair on the floor) would pass every other test. A ball lies on the field, so field
        // colour (carpet, its shadow on the carpet, or a line) lies right at its foot; at the
        // foot of an off-field thing lie furniture or the floor, even where the carpet shows a
        // little lower in the image.
        match field_below(img, m.outline.bounds, params.field_below_reach_radii) {
            Some(field) => confidence.range_test(
                TestName::FieldBelow,
                field,
                params.field_below_without_pose,
                params.field_below_without_pose_weight,
            ),
            None => confidence.skipped(TestName::FieldBelow, params.field_below_without_pose),
        }
        if params.field_beneath_without_pose_weight.penalty > 0.0 {
            match field_beneath(img, m.outline.bounds, params.field_beneath_radii) {
                Some(field) => confidence.range_test(
                    TestName::FieldBeneath,
                    field,
                    params.field_beneath_without_pose,
                    params.field_beneath_without_pose_weight,
                ),
                None => {
                    confidence.skipped(TestName::FieldBeneath, params.field_beneath_without_pose);
                }
            }
        }
    }
    below_scan.area
}

/// Share of field colours (green or white) in the strip beneath the box: its columns, from two
/// pixels below it down `radii` × half its larger side (pixels inside the image only); `None`
/// when the strip lies wholly outside (a ball at the image's bottom edge).
fn field_beneath(img: &ClassifiedImage, b: PixelBox, radii: f64) -> Option<f64> {
    let (minx, maxx) = (i64::from(b.min_x), i64::from(b.max_x));
    let (miny, maxy) = (i64::from(b.min_y), i64::from(b.max_y));
    let radius = f64::from(u32::try_from((maxx - minx).max(maxy - miny) + 1).unwrap_or(0)) / 2.0;
    // Whole pixels; a NaN or negative length gives an empty strip.
    let length = (radius * radii).clamp(0.0, f64::from(u16::MAX)) as i64;
    let (mut n, mut field) = (0u32, 0u32);
    for y in maxy + 2..=maxy + 2 + length {
        for x in minx..=maxx {
            if let Some(c) = img.get_signed(x, y) {
                n += 1;
                field +=
                    u32::from(c == ColourClass::Green.code() || c == ColourClass::White.code());
            }
        }
    }
    (n > 0).then(|| f64::from(field) / f64::from(n))
}

/// The field-below share: the band at the box's foot ([`field_at_foot`]) and, when
/// `reach_radii` is positive, the same band moved down one pixel at a time up to that many
/// radii (half the box's larger side) further; the best share counts (`None` when no band lies
/// inside the image).
fn field_below(img: &ClassifiedImage, b: PixelBox, reach_radii: f64) -> Option<f64> {
    let side = (b.max_x - b.min_x).max(b.max_y - b.min_y) + 1;
    // Whole pixels; a NaN or negative reach reads the foot only.
    let reach = (f64::from(side) / 2.0 * reach_radii).clamp(0.0, 1024.0) as i64;
    (0..=reach)
        .filter_map(|down| field_at_foot(img, b, down))
        .max_by(f64::total_cmp)
}

/// Share of field colours in a band three rows high just below the box, a few pixels down
/// (past the rim pixels whose UYVY pair mixes the ball's chroma with the carpet's) and `down`
/// rows further, across the middle three fifths of its width (pixels inside the image only);
/// `None` when the band lies wholly outside (a ball cut by the bottom edge). White counts only
/// beside some green (at least a tenth of the band): a line crossing under a ball has carpet
/// beside it, while the white base of a beacon or a robot's shell standing off the field has
/// none.
fn field_at_foot(img: &ClassifiedImage, b: PixelBox, down: i64) -> Option<f64> {
    let (minx, maxx) = (i64::from(b.min_x), i64::from(b.max_x));
    let (miny, maxy) = (i64::from(b.min_y), i64::from(b.max_y));
    let inset = (maxx - minx + 1) / 5;
    let gap = ((maxy - miny + 1) / 16).clamp(1, 3) + down;
    let (mut n, mut green, mut white) = (0u32, 0u32, 0u32);
    for y in maxy + 1 + gap..=maxy + 3 + gap {
        for x in minx + inset..=maxx - inset {
            if let Some(c) = img.get_signed(x, y) {
                n += 1;
                green += u32::from(c == ColourClass::Green.code());
                white += u32::from(c == ColourClass::White.code());
            }
        }
    }
    let field = if green * 10 >= n {
        green + white
    } else {
        green
    };
    (n > 0).then(|| f64::from(field) / f64::from(n))
}

/// Share of unclassified pixels on the ring one pixel outside the box, or `gap` pixels further
/// out (pixels inside the image only); `None` when the ring lies wholly outside.
fn unclassified_around(img: &ClassifiedImage, b: PixelBox, gap: u32) -> Option<f64> {
    let d = 1 + i64::from(gap);
    let (minx, miny) = (i64::from(b.min_x) - d, i64::from(b.min_y) - d);
    let (maxx, maxy) = (i64::from(b.max_x) + d, i64::from(b.max_y) + d);
    let ring = (minx..=maxx)
        .flat_map(|x| [(x, miny), (x, maxy)])
        .chain((miny + 1..maxy).flat_map(|y| [(minx, y), (maxx, y)]));
    let (mut n, mut none) = (0u32, 0u32);
    for (x, y) in ring {
        if let Some(c) = img.get_signed(x, y) {
            n += 1;
            none += u32::from(c == ColourClass::Unclassified.code());
        }
    }
    (n > 0).then(|| f64::from(none) / f64::from(n))
}

/// Share of ball colours among the image pixels whose centres lie inside the circle (`center`,
/// `radius` px), sampled every pixel up to a 24-pixel diameter and on a 24 × 24 grid over
/// larger circles (a close ball or a robot's arm fills tens of thousands of pixels; the share
/// needs a few hundred); `None` when no sample of the image lies inside.
pub(super) fn circle_fill(img: &ClassifiedImage, center: ImagePoint, radius: f64) -> Option<f64> {
    if !(center.is_finite() && radius.is_finite() && radius > 0.0) {
        return None;
    }
    let step = (2.0 * radius / 24.0).max(1.0);
    let (w, h) = (img.width() as f64, img.height() as f64);
    let (mut n, mut ball) = (0u32, 0u32);
    let mut y = (center.y_px - radius).floor() + 0.5;
    while y <= center.y_px + radius {
        let mut x = (center.x_px - radius).floor() + 0.5;
        while x <= center.x_px + radius {
            if x >= 0.0
                && y >= 0.0
                && x < w
                && y < h
                && (x - center.x_px).powi(2) + (y - center.y_px).powi(2) <= radius * radius
                && let Some(c) = img.get_at(x, y)
            {
                n += 1;
                ball += u32::from(is_ball_colour(c));
            }
            x += step;
        }
        y += step;
    }
    (n > 0).then(|| f64::from(ball) / f64::from(n))
}
