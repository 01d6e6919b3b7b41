//! Draws recognition's primitives onto an RGB image, for `eotn render` and PNG export. The app
//! draws the same primitives with egui's painter instead (crisp at any zoom); this is the
//! headless counterpart, so a PNG shows what the app shows.
//!
//! Images are packed RGB, 3 bytes per pixel, row-major; coordinates are image pixels
//! (FORMATS.md). An optional integer `scale` enlarges the picture first so thin lines stay
//! readable on 208×160 frames.

use crate::lut::classes::code_display_rgb;
use crate::recognition::{CircleRole, LineRole, Primitive};

/// Outlines the inclusive pixel box `[minx, miny, maxx, maxy]` on a packed RGB image of
/// `width` × `height` at its own resolution (one-pixel lines), clamped to the image: blob boxes in
/// exports and the app's blob view.
pub fn outline_box(rgb: &mut [u8], width: usize, height: usize, bounds: [u32; 4], colour: [u8; 3]) {
    if width == 0 || height == 0 || rgb.len() < width * height * 3 {
        return;
    }
    let clamp = |v: u32, max: usize| (v as usize).min(max - 1);
    let (x0, y0) = (clamp(bounds[0], width), clamp(bounds[1], height));
    let (x1, y1) = (clamp(bounds[2], width), clamp(bounds[3], height));
    let mut put = |x: usize, y: usize| {
        let i = (y * width + x) * 3;
        rgb[i..i + 3].copy_from_slice(&colour);
    };
    for x in x0..=x1 {
        put(x, y0);
        put(x, y1);
    }
    for y in y0..=y1 {
        put(x0, y);
        put(x1, y);
    }
}

/// An RGB picture being drawn on.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Canvas {
    /// Width, pixels.
    pub width: usize,
    /// Height, pixels.
    pub height: usize,
    /// Packed RGB.
    pub rgb: Vec<u8>,
    /// Image pixels per source pixel.
    pub scale: usize,
}

impl Canvas {
    /// A canvas from a packed RGB image of `width` × `height`, enlarged `scale` times (nearest).
    /// `None` when `rgb` has the wrong length or `scale` is 0.
    #[must_use]
    pub fn from_rgb(width: usize, height: usize, rgb: &[u8], scale: usize) -> Option<Self> {
        if scale == 0 || rgb.len() != width * height * 3 {
            return None;
        }
        let (w, h) = (width * scale, height * scale);
        let mut out = vec![0u8; w * h * 3];
        for y in 0..h {
            for x in 0..w {
                let s = ((y / scale) * width + x / scale) * 3;
                let d = (y * w + x) * 3;
                out[d..d + 3].copy_from_slice(&rgb[s..s + 3]);
            }
        }
        Some(Self {
            width: w,
            height: h,
            rgb: out,
            scale,
        })
    }

    fn put(&mut self, x: i64, y: i64, c: [u8; 3]) {
        if x >= 0 && y >= 0 && (x as usize) < self.width && (y as usize) < self.height {
            let i = (y as usize * self.width + x as usize) * 3;
            self.rgb[i..i + 3].copy_from_slice(&c);
        }
    }

    /// A line between two points in source-image pixels.
    pub fn line(&mut self, a: (f64, f64), b: (f64, f64), c: [u8; 3]) {
        let s = self.scale as f64;
        let (x0, y0, x1, y1) = (a.0 * s, a.1 * s, b.0 * s, b.1 * s);
        if ![x0, y0, x1, y1].iter().all(|v| v.is_finite()) {
            return;
        }
        let steps = (x1 - x0).abs().max((y1 - y0).abs()).ceil().min(100_000.0) as usize;
        for i in 0..=steps {
            let t = if steps == 0 {
                0.0
            } else {
                i as f64 / steps as f64
            };
            self.put(
                (x0 + (x1 - x0) * t).floor() as i64,
                (y0 + (y1 - y0) * t).floor() as i64,
                c,
            );
        }
    }

    /// A circle in source-image pixels.
    pub fn circle(&mut self, centre: (f64, f64), r: f64, c: [u8; 3]) {
        self.circle_dashed(centre, r, c, None);
    }

    /// A circle in source-image pixels; with `dash` = Some(n), drawn as dashes n output pixels
    /// long with equal gaps.
    pub fn circle_dashed(&mut self, centre: (f64, f64), r: f64, c: [u8; 3], dash: Option<usize>) {
        if !(r.is_finite() && r > 0.0) {
            return;
        }
        // One segment per output pixel of circumference.
        let n = ((r * self.scale as f64 * 6.3).ceil() as usize).clamp(8, 20_000);
        let mut prev = (centre.0 + r, centre.1);
        for i in 1..=n {
            let t = i as f64 / n as f64 * std::f64::consts::TAU;
            let p = (centre.0 + r * t.cos(), centre.1 + r * t.sin());
            if dash.is_none_or(|d| (i - 1) / d.max(1) % 2 == 0) {
                self.line(prev, p, c);
            }
            prev = p;
        }
    }

    /// An inclusive pixel box's outline.
    pub fn rect(&mut self, [minx, miny, maxx, maxy]: [u32; 4], c: [u8; 3]) {
        let (x0, y0) = (f64::from(minx), f64::from(miny));
        let (x1, y1) = (f64::from(maxx) + 1.0, f64::from(maxy) + 1.0);
        let e = 0.5 / self.scale as f64;
        self.line((x0, y0), (x1 - e, y0), c);
        self.line((x1 - e, y0), (x1 - e, y1 - e), c);
        self.line((x1 - e, y1 - e), (x0, y1 - e), c);
        self.line((x0, y1 - e), (x0, y0), c);
    }

    /// Draws every primitive (labels are left to the app, which has fonts).
    pub fn draw(&mut self, primitives: &[Primitive]) {
        for p in primitives {
            match p {
                Primitive::Box { bounds, .. } => self.rect(*bounds, primitive_rgb(p)),
                Primitive::ScanArea { corners, .. } => {
                    for i in 0..4 {
                        self.line(corners[i], corners[(i + 1) % 4], primitive_rgb(p));
                    }
                }
                Primitive::ScanPoints { points, .. } => {
                    for q in points {
                        let s = self.scale as f64;
                        self.put(
                            (q.0 * s).floor() as i64,
                            (q.1 * s).floor() as i64,
                            primitive_rgb(p),
                        );
                    }
                }
                Primitive::Circle {
                    center,
                    radius,
                    role,
                    ..
                } => {
                    let dash = match role {
                        CircleRole::Observed => None,
                        CircleRole::SkewCorrected => Some(3),
                    };
                    self.circle_dashed(*center, *radius, primitive_rgb(p), dash);
                }
                Primitive::Line { from, to, .. } => self.line(*from, *to, primitive_rgb(p)),
                Primitive::PatternRegion { bounds, centre, .. } => {
                    let c = primitive_rgb(p);
                    let [x0, y0, x1, y1] = bounds.map(|v| v as f64);
                    let e = 0.5 / self.scale as f64;
                    let inset = if *centre {
                        1.0 / self.scale as f64
                    } else {
                        0.0
                    };
                    for d in [0.0, inset] {
                        let (a, b) = ((x0 + d, y0 + d), (x1 + 1.0 - e - d, y1 + 1.0 - e - d));
                        self.line(a, (b.0, a.1), c);
                        self.line((b.0, a.1), b, c);
                        self.line(b, (a.0, b.1), c);
                        self.line((a.0, b.1), a, c);
                    }
                }
                Primitive::Label { .. } => {}
            }
        }
    }
}

/// The one palette of the overlays: the colour a primitive is drawn in by `eotn render`, the app
/// and the `foxglove.ImageAnnotations` of `eotn detect --annotate`.
#[must_use]
pub fn primitive_rgb(p: &Primitive) -> [u8; 3] {
    match p {
        Primitive::Box { colour, .. } => box_rgb(*colour),
        Primitive::ScanArea { .. } => [255, 0, 255],
        Primitive::ScanPoints { .. } => [0, 255, 255],
        Primitive::Circle { .. } => [255, 255, 0],
        Primitive::Line { role, .. } => match role {
            LineRole::Horizon => [255, 64, 64],
            LineRole::Post => [0, 255, 0],
            LineRole::Gap => [255, 255, 255],
            LineRole::Scan => [128, 128, 255],
        },
        Primitive::PatternRegion { colour, .. } => pattern_region_rgb(*colour),
        Primitive::Label { .. } => [255, 255, 255],
    }
}

/// The colour blob boxes of class `code` are outlined in: the class colour, white for black
/// (which would vanish on a dark image).
#[must_use]
pub fn box_rgb(code: u8) -> [u8; 3] {
    match code {
        9 => [255, 255, 255],
        c => code_display_rgb(c),
    }
}

/// The colour a pattern region is outlined in: its class's display colour, grey for "nothing"
/// and white for black (which would vanish on a dark image).
#[must_use]
pub fn pattern_region_rgb(code: u8) -> [u8; 3] {
    match code {
        0 => [128, 128, 128],
        9 => [255, 255, 255],
        c => code_display_rgb(c),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn draws_boxes_lines_and_circles_inside_the_canvas_only() {
        let mut c = Canvas::from_rgb(10, 10, &[0u8; 300], 2).expect("canvas");
        assert_eq!((c.width, c.height), (20, 20));
        c.draw(&[
            Primitive::Box {
                owner: "b".into(),
                colour: 1,
                bounds: [1, 1, 3, 3],
            },
            Primitive::Line {
                owner: "h".into(),
                role: LineRole::Horizon,
                from: (-5.0, 1.0),
                to: (50.0, 1.0),
            },
            Primitive::Circle {
                owner: "c".into(),
                center: (5.0, 5.0),
                radius: 3.0,
                role: CircleRole::Observed,
            },
        ]);
        let at = |x: usize, y: usize| &c.rgb[(y * 20 + x) * 3..(y * 20 + x) * 3 + 3];
        assert_eq!(at(2, 4), &code_display_rgb(1));
        assert_eq!(at(19, 2), &[255, 64, 64]);
        assert_eq!(
            at(16, 9),
            &[255, 255, 0],
            "circle's right edge at x = 8 source px"
        );
        assert!(Canvas::from_rgb(10, 10, &[0u8; 299], 1).is_none());
    }

    #[test]
    fn a_skew_corrected_circle_is_dashed() {
        let yellow = |c: &Canvas| c.rgb.chunks(3).filter(|p| p == &[255, 255, 0]).count();
        let draw = |role| {
            let mut c = Canvas::from_rgb(40, 40, &[0u8; 40 * 40 * 3], 2).expect("canvas");
            c.draw(&[Primitive::Circle {
                owner: "ball#0".into(),
                center: (20.0, 20.0),
                radius: 12.0,
                role,
            }]);
            yellow(&c)
        };
        let (solid, dashed) = (draw(CircleRole::Observed), draw(CircleRole::SkewCorrected));
        assert!(solid > 100, "{solid}");
        assert!(
            dashed * 10 > solid * 3 && dashed * 10 < solid * 7,
            "about half drawn: {dashed} of {solid}"
        );
    }
}
