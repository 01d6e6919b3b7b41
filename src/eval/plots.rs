//! PNG charts of an evaluation — measured against true distance, error histograms, detection
//! rates per distance band — and of a size → distance calibration: people would rather look
//! than read a table of percentiles.
//!
//! Drawn on [`Canvas`] in the overlays' 8×8 bitmap font ([`Canvas::text`]), so nothing depends
//! on system fonts or a plotting crate. Every chart is a fixed-size RGB image with a title, labelled axes and a
//! legend.

use std::io;
use std::path::{Path, PathBuf};

use super::FrameEval;
use crate::frame::ImagePoint;
use crate::overlay::{Canvas, FONT_CELL_PX, text_size_px};

/// Chart size, pixels.
const WIDTH: usize = 720;
/// Chart size, pixels.
const HEIGHT: usize = 480;
/// Plot area margins (left, right, top, bottom), pixels.
const MARGIN: (f64, f64, f64, f64) = (78.0, 24.0, 52.0, 56.0);
/// Text scale of ticks, axis labels and legends: one output pixel per font pixel (8 pixels a
/// character).
const TEXT_SCALE: usize = 1;
/// Text scale of a title: each font pixel a 2 × 2 block, when the title fits the chart's width.
const TITLE_SCALE: usize = 2;
/// Half the height of a line of text at [`TEXT_SCALE`], pixels: text centred on `y` starts here.
const TEXT_HALF_HEIGHT: f64 = (FONT_CELL_PX * TEXT_SCALE) as f64 / 2.0;

/// Colours of the series.
const BALL: [u8; 3] = [235, 120, 20];
const BALL_CUT: [u8; 3] = [150, 60, 160];
const YELLOW: [u8; 3] = [210, 170, 0];
const SKY_BLUE: [u8; 3] = [30, 140, 220];
const GREY: [u8; 3] = [150, 150, 150];
const LIGHT: [u8; 3] = [225, 225, 225];
const BLACK: [u8; 3] = [20, 20, 20];
const RED: [u8; 3] = [200, 30, 30];

/// Width of `text` drawn at [`TEXT_SCALE`], pixels.
fn text_width(text: &str) -> f64 {
    text_size_px(text, TEXT_SCALE).0 as f64
}

/// A chart being drawn: a canvas, the plot area and the data ranges it maps.
struct Chart {
    canvas: Canvas,
    x: (f64, f64),
    y: (f64, f64),
}

/// Round tick steps: 1, 2 or 5 times a power of ten, about `n` ticks over `span`.
fn tick_step(span: f64, n: f64) -> f64 {
    if !(span.is_finite() && span > 0.0) {
        return 1.0;
    }
    let raw = span / n;
    let mag = 10f64.powf(raw.log10().floor());
    let f = raw / mag;
    mag * if f < 1.5 {
        1.0
    } else if f < 3.5 {
        2.0
    } else if f < 7.5 {
        5.0
    } else {
        10.0
    }
}

/// Tick label without needless decimals.
fn tick_label(v: f64, step: f64) -> String {
    if step >= 1.0 {
        format!("{v:.0}")
    } else if step >= 0.1 {
        format!("{v:.1}")
    } else {
        format!("{v:.2}")
    }
}

/// Factor on the upper end of charts whose legend sits in a top corner, so that the largest
/// points are not hidden under it.
const LEGEND_HEADROOM: f64 = 1.25;

/// A range that holds every value (and `extra`), widened a little; `(0, 1)` when empty.
fn range_of(values: impl Iterator<Item = f64>, extra: &[f64]) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values
        .chain(extra.iter().copied())
        .filter(|v| v.is_finite())
    {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if !lo.is_finite() {
        return (0.0, 1.0);
    }
    if hi - lo < 1e-9 {
        return (lo - 1.0, hi + 1.0);
    }
    let pad = (hi - lo) * 0.05;
    (lo - pad, hi + pad)
}

impl Chart {
    /// A white chart with its title, axes, grid, ticks and axis labels.
    fn new(title: &str, x_label: &str, y_label: &str, x: (f64, f64), y: (f64, f64)) -> Self {
        let white = vec![255u8; WIDTH * HEIGHT * 3];
        let canvas = match Canvas::from_rgb(WIDTH, HEIGHT, &white, 1) {
            Some(c) => c,
            None => Canvas {
                width: WIDTH,
                height: HEIGHT,
                rgb: white,
                scale: 1,
            },
        };
        let mut c = Self { canvas, x, y };
        let (l, r, t, b) = c.area();
        let title_scale = if text_size_px(title, TITLE_SCALE).0 + 16 <= WIDTH {
            TITLE_SCALE
        } else {
            TEXT_SCALE
        };
        let title_width = text_size_px(title, title_scale).0 as f64;
        c.text_scaled(
            title,
            (WIDTH as f64 - title_width) / 2.0,
            10.0,
            title_scale,
            BLACK,
        );
        c.text(y_label, 8.0, t - 22.0, BLACK);
        c.text(
            x_label,
            (l + r - text_width(x_label)) / 2.0,
            HEIGHT as f64 - 22.0,
            BLACK,
        );
        let xs = tick_step(x.1 - x.0, 8.0);
        let mut v = (x.0 / xs).ceil() * xs;
        while v <= x.1 + 1e-9 {
            let (px, _) = c.to_px(v, y.0);
            c.canvas
                .line(ImagePoint::new(px, t), ImagePoint::new(px, b), LIGHT);
            c.canvas
                .line(ImagePoint::new(px, b), ImagePoint::new(px, b + 5.0), BLACK);
            let s = tick_label(v, xs);
            c.text(&s, px - text_width(&s) / 2.0, b + 9.0, BLACK);
            v += xs;
        }
        let ys = tick_step(y.1 - y.0, 6.0);
        let mut v = (y.0 / ys).ceil() * ys;
        while v <= y.1 + 1e-9 {
            let (_, py) = c.to_px(x.0, v);
            c.canvas
                .line(ImagePoint::new(l, py), ImagePoint::new(r, py), LIGHT);
            c.canvas
                .line(ImagePoint::new(l - 5.0, py), ImagePoint::new(l, py), BLACK);
            let s = tick_label(v, ys);
            c.text(&s, l - 8.0 - text_width(&s), py - TEXT_HALF_HEIGHT, BLACK);
            v += ys;
        }
        c.canvas
            .line(ImagePoint::new(l, t), ImagePoint::new(l, b), BLACK);
        c.canvas
            .line(ImagePoint::new(l, b), ImagePoint::new(r, b), BLACK);
        c
    }

    /// Plot area: left, right, top, bottom, pixels.
    fn area(&self) -> (f64, f64, f64, f64) {
        (
            MARGIN.0,
            WIDTH as f64 - MARGIN.1,
            MARGIN.2,
            HEIGHT as f64 - MARGIN.3,
        )
    }

    /// Data → pixel coordinates.
    fn to_px(&self, x: f64, y: f64) -> (f64, f64) {
        let (l, r, t, b) = self.area();
        (
            l + (x - self.x.0) / (self.x.1 - self.x.0) * (r - l),
            b - (y - self.y.0) / (self.y.1 - self.y.0) * (b - t),
        )
    }

    fn inside(&self, p: (f64, f64)) -> bool {
        let (l, r, t, b) = self.area();
        p.0 >= l - 0.5 && p.0 <= r + 0.5 && p.1 >= t - 0.5 && p.1 <= b + 0.5
    }

    fn fill(&mut self, x0: f64, y0: f64, x1: f64, y1: f64, c: [u8; 3]) {
        let (xa, xb) = (x0.min(x1).round() as i64, x0.max(x1).round() as i64);
        let (ya, yb) = (y0.min(y1).round() as i64, y0.max(y1).round() as i64);
        for y in ya.max(0)..yb.min(HEIGHT as i64) {
            for x in xa.max(0)..xb.min(WIDTH as i64) {
                let i = (y as usize * WIDTH + x as usize) * 3;
                self.canvas.rgb[i..i + 3].copy_from_slice(&c);
            }
        }
    }

    /// Writes `s` at [`TEXT_SCALE`], its top-left corner at (`x`, `y`) pixels.
    fn text(&mut self, s: &str, x: f64, y: f64, c: [u8; 3]) {
        self.text_scaled(s, x, y, TEXT_SCALE, c);
    }

    fn text_scaled(&mut self, s: &str, x: f64, y: f64, scale: usize, c: [u8; 3]) {
        let top_left = (x.round() as i64, y.round() as i64);
        self.canvas.text(top_left, s, scale, c);
    }

    /// A data point as a small filled square (points outside the ranges are left out).
    fn point(&mut self, x: f64, y: f64, c: [u8; 3]) {
        let p = self.to_px(x, y);
        if p.0.is_finite() && p.1.is_finite() && self.inside(p) {
            self.fill(p.0 - 2.0, p.1 - 2.0, p.0 + 3.0, p.1 + 3.0, c);
        }
    }

    /// A curve through data points, clipped to the plot area point by point.
    fn polyline(&mut self, pts: &[(f64, f64)], c: [u8; 3]) {
        for w in pts.windows(2) {
            let (a, b) = (self.to_px(w[0].0, w[0].1), self.to_px(w[1].0, w[1].1));
            if self.inside(a) && self.inside(b) {
                let (a, b) = (ImagePoint::new(a.0, a.1), ImagePoint::new(b.0, b.1));
                self.canvas.line(a, b, c);
                let down = ImagePoint::new(0.0, 1.0);
                self.canvas.line(a + down, b + down, c);
            }
        }
    }

    /// A bar from y = `base` to `y` between data x0 and x1.
    fn bar(&mut self, x0: f64, x1: f64, base: f64, y: f64, c: [u8; 3]) {
        let (a, b) = (self.to_px(x0, base), self.to_px(x1, y));
        self.fill(a.0, a.1, b.0, b.1, c);
    }

    /// Legend entries in the plot area's top-left corner.
    fn legend(&mut self, entries: &[(&str, [u8; 3])]) {
        self.legend_at(entries, false);
    }

    /// Legend entries on a white box in the plot area's top-left or top-right corner.
    fn legend_at(&mut self, entries: &[(&str, [u8; 3])], right: bool) {
        let widest = entries
            .iter()
            .map(|(s, _)| text_width(s))
            .fold(0.0, f64::max);
        let (l, r, t, _) = self.area();
        let l = if right { r - widest - 40.0 } else { l };
        let bottom = t + 8.0 + entries.len() as f64 * 20.0;
        self.fill(l + 4.0, t + 3.0, l + 32.0 + widest, bottom, [255, 255, 255]);
        for (i, (label, c)) in entries.iter().enumerate() {
            let y = t + 8.0 + i as f64 * 20.0;
            self.fill(l + 10.0, y + 2.0, l + 20.0, y + 12.0, *c);
            self.text(label, l + 26.0, y + 7.0 - TEXT_HALF_HEIGHT, BLACK);
        }
    }

    /// The chart as PNG bytes.
    fn png(&self) -> io::Result<Vec<u8>> {
        let img = image::RgbImage::from_raw(WIDTH as u32, HEIGHT as u32, self.canvas.rgb.clone())
            .ok_or_else(|| io::Error::other("chart buffer has the wrong size"))?;
        let mut out = io::Cursor::new(Vec::new());
        img.write_to(&mut out, image::ImageFormat::Png)
            .map_err(io::Error::other)?;
        Ok(out.into_inner())
    }

    /// Writes the chart atomically; the error names the file.
    fn save(&self, path: &Path) -> io::Result<()> {
        let bytes = self.png()?;
        crate::atomic_file::write_atomic(path, &bytes)
            .map_err(|e| io::Error::new(e.kind(), format!("{}: {e}", path.display())))
    }
}

/// A labelled, coloured set of (true, measured) points.
type Series<'a> = (&'a str, [u8; 3], Vec<(f64, f64)>);

/// Measured against true distance with the line of perfect agreement.
fn distance_chart(title: &str, series: &[Series<'_>]) -> Chart {
    let all = || series.iter().flat_map(|s| s.2.iter());
    let x = range_of(all().map(|p| p.0), &[0.0]);
    let y = range_of(all().map(|p| p.1), &[0.0]);
    // Headroom above the data keeps the legend (top corner) off the points.
    let hi = x.1.max(y.1) * LEGEND_HEADROOM;
    let mut c = Chart::new(
        title,
        "true distance (cm)",
        "measured distance (cm)",
        (0.0, hi),
        (0.0, hi),
    );
    c.polyline(&[(0.0, 0.0), (hi, hi)], GREY);
    for (_, colour, pts) in series {
        for p in pts {
            c.point(p.0, p.1, *colour);
        }
    }
    let entries: Vec<(String, [u8; 3])> = series
        .iter()
        .map(|s| (format!("{} (n={})", s.0, s.2.len()), s.1))
        .collect();
    let refs: Vec<(&str, [u8; 3])> = entries.iter().map(|(s, c)| (s.as_str(), *c)).collect();
    c.legend(&refs);
    c
}

/// A histogram of `values` in `bins` equal bins over their range.
fn histogram_chart(title: &str, x_label: &str, values: &[f64], colour: [u8; 3]) -> Chart {
    let v: Vec<f64> = values.iter().copied().filter(|x| x.is_finite()).collect();
    let (lo, hi) = range_of(v.iter().copied(), &[0.0]);
    let bins = 24usize;
    let w = (hi - lo) / bins as f64;
    let mut counts = vec![0usize; bins];
    for x in &v {
        let i = (((x - lo) / w).floor() as usize).min(bins - 1);
        counts[i] += 1;
    }
    let top = counts.iter().copied().max().unwrap_or(0).max(1) as f64 * 1.1;
    let title = format!("{title} (n={})", v.len());
    let mut c = Chart::new(&title, x_label, "count", (lo, hi), (0.0, top));
    for (i, n) in counts.iter().enumerate() {
        if *n > 0 {
            let x0 = lo + i as f64 * w;
            c.bar(x0 + w * 0.08, x0 + w * 0.92, 0.0, *n as f64, colour);
        }
    }
    let (_, zero_y0) = c.to_px(0.0, 0.0);
    let (_, zero_y1) = c.to_px(0.0, top);
    let (zx, _) = c.to_px(0.0, 0.0);
    if lo < 0.0 && hi > 0.0 {
        c.canvas.line(
            ImagePoint::new(zx, zero_y0),
            ImagePoint::new(zx, zero_y1),
            RED,
        );
    }
    c
}

/// Found / eligible per distance band: bars of the rate, with each band's count above it.
fn rate_chart(title: &str, samples: &[(f64, bool)], band_cm: f64, colour: [u8; 3]) -> Chart {
    rate_chart_over(title, "true distance", "cm", samples, band_cm, colour)
}

/// Found / eligible per band of `quantity` (in `unit`), as [`rate_chart`].
fn rate_chart_over(
    title: &str,
    quantity: &str,
    unit: &str,
    samples: &[(f64, bool)],
    band_cm: f64,
    colour: [u8; 3],
) -> Chart {
    let max = samples.iter().map(|s| s.0).fold(0.0, f64::max);
    let bands = ((max / band_cm).floor() as usize + 1).clamp(1, 40);
    let mut n = vec![0usize; bands];
    let mut found = vec![0usize; bands];
    for (d, ok) in samples {
        if !d.is_finite() || *d < 0.0 {
            continue;
        }
        let i = ((d / band_cm).floor() as usize).min(bands - 1);
        n[i] += 1;
        found[i] += usize::from(*ok);
    }
    let x_hi = bands as f64 * band_cm;
    let x_label = format!(
        "{quantity} ({unit}), {} {unit} bands",
        tick_label(band_cm, 1.0)
    );
    let mut c = Chart::new(title, &x_label, "found (%)", (0.0, x_hi), (0.0, 115.0));
    for i in 0..bands {
        if n[i] == 0 {
            continue;
        }
        let rate = 100.0 * found[i] as f64 / n[i] as f64;
        let x0 = i as f64 * band_cm;
        c.bar(x0 + band_cm * 0.1, x0 + band_cm * 0.9, 0.0, rate, colour);
        let label = format!("{}/{}", found[i], n[i]);
        let (px, py) = c.to_px(x0 + band_cm / 2.0, rate);
        c.text(&label, px - text_width(&label) / 2.0, py - 12.0, BLACK);
    }
    c
}

/// Writes an evaluation's charts into `dir` (created if missing) and returns their paths:
/// `ball_distance.png`, `goal_distance.png` (measured against true distance),
/// `ball_distance_error.png`, `goal_distance_error.png` (signed relative error histograms, %),
/// `ball_detection.png`, `goal_detection.png` (found rate per distance band),
/// `post_error.png` (post position errors, pixels).
///
/// # Errors
/// The folder or a file cannot be written (the message names it).
pub fn write_eval_plots(dir: &Path, frames: &[FrameEval]) -> io::Result<Vec<PathBuf>> {
    crate::atomic_file::output_folder(dir)
        .map_err(|e| io::Error::new(e.kind(), format!("{}: {e}", dir.display())))?;
    let charts = EvalSeries::from_frames(frames).charts();
    let mut written = Vec::new();
    for (name, chart) in &charts {
        let path = dir.join(name);
        chart.save(&path)?;
        written.push(path);
    }
    Ok(written)
}

/// The series the evaluation's charts draw, gathered from its frames.
#[derive(Default)]
struct EvalSeries {
    /// (true, measured) distance of each matched ball not cut by the image edge, cm.
    ball_uncut: Vec<(f64, f64)>,
    /// ... and of each cut one, cm.
    ball_cut: Vec<(f64, f64)>,
    /// (true distance cm, found) of each eligible ball.
    ball_rates: Vec<(f64, bool)>,
    /// (true, measured) distance of each uncut yellow goal, cm.
    goal_yellow: Vec<(f64, f64)>,
    /// ... and of each sky-blue one, cm.
    goal_blue: Vec<(f64, f64)>,
    /// (true distance cm, found) of each eligible goal.
    goal_rates: Vec<(f64, bool)>,
    /// Post position errors, pixels.
    posts: Vec<f64>,
}

impl EvalSeries {
    fn from_frames(frames: &[FrameEval]) -> Self {
        let mut s = Self::default();
        for f in frames {
            if let Some((t, m)) = f.ball_distances_cm {
                if f.ball_cut {
                    s.ball_cut.push((t, m));
                } else {
                    s.ball_uncut.push((t, m));
                }
            }
            if let Some(t) = f.ball_true_distance_cm.filter(|_| f.ball_eligible) {
                s.ball_rates.push((t, f.ball_correct));
            }
            for g in &f.goal_distances_cm {
                if g.sky_blue {
                    s.goal_blue.push((g.true_cm, g.measured_cm));
                } else {
                    s.goal_yellow.push((g.true_cm, g.measured_cm));
                }
            }
            s.goal_rates.extend(f.goal_detections.iter().copied());
            s.posts.extend(f.post_errors_px.iter().copied());
        }
        s
    }

    /// Each chart with its file name.
    fn charts(&self) -> [(&'static str, Chart); 7] {
        let signed = |pts: &[(f64, f64)]| -> Vec<f64> {
            pts.iter()
                .filter(|p| p.0 > 0.0)
                .map(|p| 100.0 * (p.1 - p.0) / p.0)
                .collect()
        };
        let ball_all: Vec<(f64, f64)> = self
            .ball_uncut
            .iter()
            .chain(&self.ball_cut)
            .copied()
            .collect();
        let goal_all: Vec<(f64, f64)> = self
            .goal_yellow
            .iter()
            .chain(&self.goal_blue)
            .copied()
            .collect();
        [
            (
                "ball_distance.png",
                distance_chart(
                    "ball: measured against true distance",
                    &[
                        ("whole ball", BALL, self.ball_uncut.clone()),
                        ("cut off by the image edge", BALL_CUT, self.ball_cut.clone()),
                    ],
                ),
            ),
            (
                "goal_distance.png",
                distance_chart(
                    "goals (uncut): measured against true distance",
                    &[
                        ("yellow goal", YELLOW, self.goal_yellow.clone()),
                        ("sky-blue goal", SKY_BLUE, self.goal_blue.clone()),
                    ],
                ),
            ),
            (
                "ball_distance_error.png",
                histogram_chart(
                    "ball distance error",
                    "(measured - true) / true (%)",
                    &signed(&ball_all),
                    BALL,
                ),
            ),
            (
                "goal_distance_error.png",
                histogram_chart(
                    "goal distance error",
                    "(measured - true) / true (%)",
                    &signed(&goal_all),
                    YELLOW,
                ),
            ),
            (
                "ball_detection.png",
                rate_chart(
                    "ball found, per distance band (eligible frames)",
                    &self.ball_rates,
                    50.0,
                    BALL,
                ),
            ),
            (
                "goal_detection.png",
                rate_chart(
                    "goals found, per distance band (eligible goals)",
                    &self.goal_rates,
                    100.0,
                    YELLOW,
                ),
            ),
            (
                "post_error.png",
                histogram_chart(
                    "post position error (worst of top and foot)",
                    "error (px)",
                    &self.posts,
                    SKY_BLUE,
                ),
            ),
        ]
    }
}

/// Writes the charts of a score against boxed labels (`eotn eval --labels` with a YOLO, COCO
/// or VOC set) into `dir`: `ball_detection.png` (eligible frames found, per 2 px band of the
/// largest ball box's larger side) and `ball_centre_error.png` (found balls' centre error over
/// the box's larger side).
///
/// # Errors
/// The folder or a file cannot be written (the message names it).
pub fn write_box_plots(
    dir: &Path,
    frames: &[super::ball_boxes::BoxFrameEval],
) -> io::Result<Vec<PathBuf>> {
    crate::atomic_file::output_folder(dir)
        .map_err(|e| io::Error::new(e.kind(), format!("{}: {e}", dir.display())))?;
    let rates: Vec<(f64, bool)> = frames
        .iter()
        .filter(|f| f.eligible)
        .filter_map(|f| f.ball_size_px.map(|s| (s, f.correct)))
        .collect();
    let errors: Vec<f64> = frames.iter().filter_map(|f| f.centre_error).collect();
    let charts = [
        (
            "ball_detection.png",
            rate_chart_over(
                "ball found, per ball size (eligible frames)",
                "largest ball box side",
                "px",
                &rates,
                2.0,
                BALL,
            ),
        ),
        (
            "ball_centre_error.png",
            histogram_chart(
                "ball centre error (found balls)",
                "distance from the box centre / box side",
                &errors,
                BALL,
            ),
        ),
    ];
    let mut written = Vec::new();
    for (name, chart) in &charts {
        let path = dir.join(name);
        chart.save(&path)?;
        written.push(path);
    }
    Ok(written)
}

/// Draws a size → distance calibration: the samples (height px, true distance cm), the fitted
/// relation distance = multiplier / height + offset and, for comparison, the relation in use
/// before; written atomically to `path`.
///
/// # Errors
/// The file cannot be written (the message names it).
pub fn write_calibration_plot(
    path: &Path,
    samples: &[(f64, f64)],
    fitted: (f64, f64),
    previous: (f64, f64),
) -> io::Result<()> {
    let pts: Vec<(f64, f64)> = samples
        .iter()
        .copied()
        .filter(|(h, d)| *h > 0.0 && h.is_finite() && d.is_finite())
        .collect();
    let x = range_of(pts.iter().map(|p| p.0), &[0.0]);
    let y = range_of(pts.iter().map(|p| p.1), &[0.0]);
    let title = format!(
        "goal distance = {:.0} / height + {:.1} cm",
        fitted.0, fitted.1
    );
    let mut c = Chart::new(
        &title,
        "goal height (px)",
        "true distance (cm)",
        (0.0, x.1 * LEGEND_HEADROOM),
        (0.0, y.1 * LEGEND_HEADROOM),
    );
    let x = (x.0, x.1 * LEGEND_HEADROOM);
    let y = (y.0, y.1 * LEGEND_HEADROOM);
    let curve = |(m, o): (f64, f64)| -> Vec<(f64, f64)> {
        let lo = (x.1 / 200.0).max(0.5);
        (0..=200)
            .map(|i| {
                let h = lo + (x.1 - lo) * f64::from(i) / 200.0;
                (h, m / h + o)
            })
            .filter(|p| p.1 >= 0.0 && p.1 <= y.1)
            .collect()
    };
    c.polyline(&curve(previous), GREY);
    c.polyline(&curve(fitted), RED);
    for p in &pts {
        c.point(p.0, p.1, SKY_BLUE);
    }
    let n = format!("samples (n={})", pts.len());
    c.legend_at(
        &[
            (n.as_str(), SKY_BLUE),
            ("fit", RED),
            ("parameters before", GREY),
        ],
        true,
    );
    c.save(path)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ticks_are_round_and_text_has_width() {
        assert_eq!(tick_step(100.0, 8.0), 10.0);
        assert_eq!(tick_step(7.0, 6.0), 1.0);
        assert_eq!(tick_step(0.0, 6.0), 1.0);
        assert_eq!(text_width("ab"), 16.0);
        assert_eq!(range_of(std::iter::empty(), &[]), (0.0, 1.0));
    }

    /// The columns and rows of the title band (above the plot area) that hold black text.
    fn title_extent(c: &Chart) -> Option<[usize; 4]> {
        let mut b: Option<[usize; 4]> = None;
        for y in 0..MARGIN.2 as usize - 22 {
            for x in 0..WIDTH {
                let i = (y * WIDTH + x) * 3;
                if c.canvas.rgb[i..i + 3] == BLACK {
                    b = Some(b.map_or([x, y, x, y], |[x0, y0, x1, y1]| {
                        [x0.min(x), y0.min(y), x1.max(x), y1.max(y)]
                    }));
                }
            }
        }
        b
    }

    #[test]
    fn a_title_is_written_centred_and_a_long_one_smaller_to_fit() {
        let short = Chart::new("ball distance error", "x", "y", (0.0, 1.0), (0.0, 1.0));
        let [x0, y0, x1, y1] = title_extent(&short).expect("title drawn");
        assert!(y1 - y0 >= 12, "twice the font's size: rows {y0}..{y1}");
        assert!(x0.abs_diff(WIDTH - 1 - x1) <= 16, "centred: {x0}..{x1}");
        let long = "post position error (worst of top and foot) (n=1234)";
        let long = Chart::new(long, "x", "y", (0.0, 1.0), (0.0, 1.0));
        let [x0, y0, x1, y1] = title_extent(&long).expect("title drawn");
        assert!(y1 - y0 < 8, "at the font's own size: rows {y0}..{y1}");
        assert!(x0 > 0 && x1 < WIDTH - 1, "inside the picture: {x0}..{x1}");
    }

    #[test]
    fn a_chart_draws_points_text_and_bars_inside_its_picture() {
        let mut c = Chart::new("t", "x", "y", (0.0, 10.0), (0.0, 10.0));
        c.point(5.0, 5.0, RED);
        c.point(f64::NAN, 5.0, RED);
        c.point(50.0, 5.0, RED);
        c.bar(1.0, 2.0, 0.0, 8.0, BALL);
        let (px, py) = c.to_px(5.0, 5.0);
        let i = (py.round() as usize * WIDTH + px.round() as usize) * 3;
        assert_eq!(&c.canvas.rgb[i..i + 3], &RED);
        let (bx, by) = c.to_px(1.5, 4.0);
        let j = (by.round() as usize * WIDTH + bx.round() as usize) * 3;
        assert_eq!(&c.canvas.rgb[j..j + 3], &BALL);
        let png = c.png().expect("png");
        assert_eq!(&png[1..4], b"PNG");
    }
}
