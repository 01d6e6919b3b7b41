//! Scans over the classified image: areas rotated by the horizon angle ("parallel to the
//! ground"), and the edge scans that collect points on a ball's outline for the circle fit.
//! All coordinates are image pixels (FORMATS.md: x right, y down, pixel centres at +0.5).

use serde::{Deserialize, Serialize};

use crate::classify::ClassifiedImage;
use crate::frame::PixelBox;
use crate::frame::xy_array;
use crate::geometry::ImagePoint;

pub use crate::frame::CutOff;

/// A scanned quadrilateral, kept for drawing (corners in image pixels, in order).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ScanArea {
    /// The four corners, clockwise on screen.
    #[serde(with = "xy_array")]
    pub corners: [ImagePoint; 4],
}

/// What a scan area found: how many in-image pixels were looked at, and how many of each class.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ScanCount {
    /// Where the scan looked.
    pub area: ScanArea,
    /// Sample points that fell inside the image.
    pub scanned: u32,
    /// Samples per class code (index = code, 0..16).
    pub per_class: [u32; 16],
}

impl ScanCount {
    /// Fraction of scanned samples whose class satisfies `wanted`; `None` when nothing inside the
    /// image was scanned (the area lay wholly outside it).
    #[must_use]
    pub fn ratio(&self, wanted: impl Fn(u8) -> bool) -> Option<f64> {
        if self.scanned == 0 {
            return None;
        }
        let hits: u32 = (0u8..16)
            .filter(|&c| wanted(c))
            .map(|c| self.per_class[usize::from(c)])
            .sum();
        Some(f64::from(hits) / f64::from(self.scanned))
    }
}

/// Samples a rectangle given in "horizon" coordinates about `centre`: x from `left` to `right`
/// and y from `top` to `bottom` (pixels, relative to `centre`, y down), rotated by `angle`
/// (the horizon's angle, radians) about `centre`, one sample per `step` pixels. Counts only
/// samples that land inside the image.
#[must_use]
pub fn scan_rotated_rect(
    img: &ClassifiedImage,
    centre: ImagePoint,
    [left, right, top, bottom]: [f64; 4],
    angle: f64,
    step: f64,
) -> ScanCount {
    let step = if step.is_finite() && step > 0.05 {
        step
    } else {
        1.0
    };
    let rotation = angle.sin_cos();
    let corner = |x: f64, y: f64| {
        ImagePoint::new(centre.x_px + x, centre.y_px + y).rotated_by(centre, rotation)
    };
    let area = ScanArea {
        corners: [
            corner(left, top),
            corner(right, top),
            corner(right, bottom),
            corner(left, bottom),
        ],
    };
    let mut count = ScanCount {
        area,
        scanned: 0,
        per_class: [0; 16],
    };
    if !(left.is_finite() && right.is_finite() && top.is_finite() && bottom.is_finite()) {
        return count;
    }
    let nx = (((right - left) / step).floor().max(0.0) as usize).min(4096);
    let ny = (((bottom - top) / step).floor().max(0.0) as usize).min(4096);
    for j in 0..=ny {
        for i in 0..=nx {
            let p = corner(left + i as f64 * step, top + j as f64 * step);
            if let Some(code) = img.get_at(p.x_px, p.y_px) {
                count.scanned += 1;
                count.per_class[usize::from(code & 15)] += 1;
            }
        }
    }
    count
}

/// The six ways of scanning a ball's outline, chosen by which sides are cut off.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum EdgeScanPattern {
    /// Each row from the left, stopping at the first ball pixel (right side cut off).
    LeftToRight,
    /// Each row from the right (left side cut off).
    RightToLeft,
    /// Each row from both sides towards the centre (both sides visible).
    SidesToCentre,
    /// Each column from the top (bottom cut off, both sides too).
    TopToBottom,
    /// Each column from the bottom (top cut off, both sides too).
    BottomToTop,
    /// Each column from top and bottom towards the centre.
    TopBottomToCentre,
}

impl EdgeScanPattern {
    /// The pattern that only scans from sides that are visible.
    #[must_use]
    pub fn for_cut_off(cut: CutOff) -> Self {
        match (cut.left, cut.right) {
            (true, true) => match (cut.top, cut.bottom) {
                (true, false) => Self::BottomToTop,
                (false, true) => Self::TopToBottom,
                _ => Self::TopBottomToCentre,
            },
            (true, false) => Self::RightToLeft,
            (false, true) => Self::LeftToRight,
            (false, false) => Self::SidesToCentre,
        }
    }
}

/// Collects outline points of the object in the box `bounds` (inclusive pixels) by scanning each row or column from `margin` pixels outside the box inward until
/// `run` consecutive pixels whose class satisfies `is_object` (a run of 2 steps over single
/// noisy pixels outside a ball; 1 stops at the first object pixel). Each point lies on the pixel
/// boundary where the run starts (e.g. `x` = left edge of its first pixel), at the row's or
/// column's centre. A scan that starts on an object pixel already (the object touches something
/// of its own colour) gives no point.
#[must_use]
pub fn edge_points(
    img: &ClassifiedImage,
    bounds: PixelBox,
    pattern: EdgeScanPattern,
    margin: u32,
    run: u32,
    is_object: impl Fn(u8) -> bool,
) -> Vec<ImagePoint> {
    edge_points_with_mixed(
        img,
        bounds,
        pattern,
        margin,
        run,
        is_object,
        |_| false,
        MixedEdge::Never,
    )
}

/// Where an edge scan counts an ambiguous pixel right outside the object's run as object.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum MixedEdge {
    /// Never: the outline is where the run starts.
    Never,
    /// On row scans, when the ambiguous pixel belongs to the neighbouring UYVY chroma pair
    /// (pixels 2k and 2k+1 share U and V): a ball pixel paired with a carpet pixel gets their
    /// mean chroma and is classified as neither, which without this takes about half a pixel
    /// off each side of a ball. Column scans (no chroma sharing) as [`Self::Always`].
    #[default]
    ChromaPairs,
    /// Always, on rows and columns.
    Always,
}

/// [`edge_points`], moving a point one pixel outwards when the pixel right outside the run
/// satisfies `is_mixed` (e.g. unclassified: neither the object's colour nor the background's)
/// and `mode` allows it there. The classified outline of a small ball loses its rim pixels to
/// mixed colours (UYVY chroma pairs, noise), which shrinks its radius by about half a pixel: 15%
/// of the distance of a ball 3 px in radius.
#[must_use]
#[expect(
    clippy::too_many_arguments,
    reason = "the scan's settings are independent; one call site"
)]
pub fn edge_points_with_mixed(
    img: &ClassifiedImage,
    bounds: PixelBox,
    pattern: EdgeScanPattern,
    margin: u32,
    run: u32,
    is_object: impl Fn(u8) -> bool,
    is_mixed: impl Fn(u8) -> bool,
    mode: MixedEdge,
) -> Vec<ImagePoint> {
    let (w, h) = (img.width() as i64, img.height() as i64);
    let (minx, miny, maxx, maxy) = (
        i64::from(bounds.min_x),
        i64::from(bounds.min_y),
        i64::from(bounds.max_x),
        i64::from(bounds.max_y),
    );
    let margin = i64::from(margin);
    let mut points = Vec::new();
    let scanner = EdgeScanner {
        img,
        run: i64::from(run.max(1)),
        is_object,
        is_mixed,
        mode,
    };
    let scan = |fixed: i64, start: i64, end: i64, dir: i64, horizontal: bool| {
        scanner.scan(fixed, start, end, dir, horizontal)
    };
    use EdgeScanPattern as P;
    let rows = matches!(pattern, P::LeftToRight | P::RightToLeft | P::SidesToCentre);
    if rows {
        for y in miny.max(0)..=maxy.min(h - 1) {
            let yc = y as f64 + 0.5;
            if matches!(pattern, P::LeftToRight | P::SidesToCentre)
                && let Some(x) = scan(y, minx - margin, maxx, 1, true)
            {
                points.push(ImagePoint::new(x, yc));
            }
            if matches!(pattern, P::RightToLeft | P::SidesToCentre)
                && let Some(x) = scan(y, maxx + margin, minx, -1, true)
            {
                points.push(ImagePoint::new(x, yc));
            }
        }
    } else {
        for x in minx.max(0)..=maxx.min(w - 1) {
            let xc = x as f64 + 0.5;
            if matches!(pattern, P::TopToBottom | P::TopBottomToCentre)
                && let Some(y) = scan(x, miny - margin, maxy, 1, false)
            {
                points.push(ImagePoint::new(xc, y));
            }
            if matches!(pattern, P::BottomToTop | P::TopBottomToCentre)
                && let Some(y) = scan(x, maxy + margin, miny, -1, false)
            {
                points.push(ImagePoint::new(xc, y));
            }
        }
    }
    // Points on the image border are where the object is cut, not its outline.
    points.retain(|p| p.x_px > 0.0 && p.x_px < w as f64 && p.y_px > 0.0 && p.y_px < h as f64);
    points
}

/// One scan line of [`edge_points_with_mixed`]: its image, settings and class tests.
struct EdgeScanner<'a, O, M> {
    img: &'a ClassifiedImage,
    /// Object pixels in a row that make an edge (at least 1).
    run: i64,
    is_object: O,
    is_mixed: M,
    mode: MixedEdge,
}

impl<O: Fn(u8) -> bool, M: Fn(u8) -> bool> EdgeScanner<'_, O, M> {
    /// The class code at `t` along the line (a row at y = `fixed` when `horizontal`, else a
    /// column at x = `fixed`).
    fn code(&self, fixed: i64, t: i64, horizontal: bool) -> Option<u8> {
        if horizontal {
            self.img.get_signed(t, fixed)
        } else {
            self.img.get_signed(fixed, t)
        }
    }

    /// Scans from `start` (clamped into the image) by `dir` up to `end` until `run` object
    /// pixels in a row; returns the boundary coordinate, one pixel farther out when the pixel
    /// before the run is mixed and `mode` allows it. `None` when the line starts inside the
    /// object or meets none.
    fn scan(&self, fixed: i64, start: i64, end: i64, dir: i64, horizontal: bool) -> Option<f64> {
        let (w, h) = (self.img.width() as i64, self.img.height() as i64);
        let start = if horizontal {
            start.clamp(0, w - 1)
        } else {
            start.clamp(0, h - 1)
        };
        let at = |t: i64| self.code(fixed, t, horizontal).is_some_and(&self.is_object);
        if (0..self.run).all(|k| at(start + k * dir)) {
            return None;
        }
        let mut t = start;
        while (dir > 0 && t <= end) || (dir < 0 && t >= end) {
            if (0..self.run).all(|k| at(t + k * dir)) {
                // The pixel before the run: another chroma pair when the run starts at a pair's
                // first pixel (scanning right) or ends at a pair's second (scanning left).
                let before = t - dir;
                let other_pair = before.div_euclid(2) != t.div_euclid(2);
                let allowed = match self.mode {
                    MixedEdge::Never => false,
                    MixedEdge::ChromaPairs => !horizontal || other_pair,
                    MixedEdge::Always => true,
                };
                let mixed = || {
                    self.code(fixed, before, horizontal)
                        .is_some_and(&self.is_mixed)
                };
                let out = if allowed && mixed() { 1.0 } else { 0.0 };
                return Some(if dir > 0 {
                    t as f64 - out
                } else {
                    t as f64 + 1.0 + out
                });
            }
            t += dir;
        }
        None
    }
}

/// Removes a rolling shutter's horizontal shear: row `y` was read `y − reference_row` lines after
/// the reference row, so its content moved by `skew_per_line` pixels per line; shift it back.
pub fn unskew_points(points: &mut [ImagePoint], skew_per_line: f64, reference_row: f64) {
    if !skew_per_line.is_finite() || !reference_row.is_finite() {
        return;
    }
    for p in points {
        p.x_px -= skew_per_line * (p.y_px - reference_row);
    }
}

/// Removes the vertical counterpart (tilt during read-out): each row moved `skew_per_line` pixels
/// vertically per line read.
pub fn unskew_points_vertical(points: &mut [ImagePoint], skew_per_line: f64, reference_row: f64) {
    if !skew_per_line.is_finite() || !reference_row.is_finite() {
        return;
    }
    for p in points {
        p.y_px -= skew_per_line * (p.y_px - reference_row);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::recognition::fit::fit_circle;

    fn disc(w: usize, h: usize, cx: f64, cy: f64, r: f64, code: u8) -> ClassifiedImage {
        let mut codes = vec![5u8; w * h];
        for y in 0..h {
            for x in 0..w {
                let (dx, dy) = (x as f64 + 0.5 - cx, y as f64 + 0.5 - cy);
                if dx * dx + dy * dy <= r * r {
                    codes[y * w + x] = code;
                }
            }
        }
        ClassifiedImage::from_codes(w, h, codes).expect("size")
    }

    #[test]
    fn edge_scans_fit_the_disc_in_every_pattern() {
        let img = disc(80, 60, 40.0, 30.0, 12.0, 1);
        let bbox = PixelBox::new(28, 18, 51, 41);
        for pattern in [
            EdgeScanPattern::LeftToRight,
            EdgeScanPattern::RightToLeft,
            EdgeScanPattern::SidesToCentre,
            EdgeScanPattern::TopToBottom,
            EdgeScanPattern::BottomToTop,
            EdgeScanPattern::TopBottomToCentre,
        ] {
            let pts = edge_points(&img, bbox, pattern, 3, 2, |c| c == 1);
            let fit = fit_circle(&pts).expect("fit");
            assert!((fit.center_x - 40.0).abs() < 0.8, "{pattern:?} {fit:?}");
            assert!((fit.center_y - 30.0).abs() < 0.8, "{pattern:?} {fit:?}");
            assert!((fit.radius - 12.0).abs() < 0.8, "{pattern:?} {fit:?}");
        }
    }

    #[test]
    fn cut_off_disc_keeps_its_true_circle() {
        // Centre left of the image: only the right part is visible; scanning from the right.
        let img = disc(80, 60, 4.0, 30.0, 15.0, 1);
        let cut = CutOff {
            left: true,
            ..CutOff::default()
        };
        let pattern = EdgeScanPattern::for_cut_off(cut);
        assert_eq!(pattern, EdgeScanPattern::RightToLeft);
        let pts = edge_points(&img, PixelBox::new(0, 15, 18, 44), pattern, 3, 2, |c| {
            c == 1
        });
        let fit = fit_circle(&pts).expect("fit");
        assert!((fit.radius - 15.0).abs() < 1.0, "{fit:?}");
        assert!((fit.center_x - 4.0).abs() < 1.0, "{fit:?}");
    }

    #[test]
    fn rotated_scan_counts_only_inside_pixels() {
        let img = disc(40, 40, 20.0, 20.0, 5.0, 1);
        let below = scan_rotated_rect(
            &img,
            ImagePoint::new(20.0, 20.0),
            [-5.0, 5.0, 8.0, 12.0],
            0.3,
            1.0,
        );
        assert!(below.scanned > 0);
        assert_eq!(below.ratio(|c| c == 5), Some(1.0));
        let outside = scan_rotated_rect(
            &img,
            ImagePoint::new(20.0, 20.0),
            [-5.0, 5.0, 100.0, 120.0],
            0.0,
            1.0,
        );
        assert_eq!(outside.scanned, 0);
        assert_eq!(outside.ratio(|c| c == 5), None);
    }

    #[test]
    fn unskewing_straightens_a_sheared_column() {
        let mut pts: Vec<ImagePoint> = (0..10)
            .map(|y| ImagePoint::new(10.0 + 0.5 * f64::from(y), f64::from(y)))
            .collect();
        unskew_points(&mut pts, 0.5, 0.0);
        assert!(pts.iter().all(|p| (p.x_px - 10.0).abs() < 1e-12));
    }
}
