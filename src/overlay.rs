//! Draws recognition's primitives onto an RGB image, for `eotn render` and PNG export. The app
//! draws the same primitives with egui's painter instead (crisp at any zoom); this is the
//! headless counterpart, so a PNG shows what the app shows.
//!
//! Images are packed RGB, 3 bytes per pixel, row-major; coordinates are image pixels
//! (FORMATS.md). An optional integer `scale` enlarges the picture first so thin lines stay
//! readable on 208×160 frames.

use crate::frame::{ImagePoint, PixelBox};
use crate::lut::classes::code_display_rgb;
use crate::recognition::{CircleRole, LineRole, Primitive};

/// Outlines the inclusive pixel box `bounds` on a packed RGB image of
/// `width` × `height` at its own resolution (one-pixel lines), clamped to the image: blob boxes in
/// exports and the app's blob view.
pub fn outline_box(rgb: &mut [u8], width: usize, height: usize, bounds: PixelBox, colour: [u8; 3]) {
    if width == 0 || height == 0 || rgb.len() < width * height * 3 {
        return;
    }
    let clamp = |v: u32, max: usize| (v as usize).min(max - 1);
    let (x0, y0) = (clamp(bounds.min_x, width), clamp(bounds.min_y, height));
    let (x1, y1) = (clamp(bounds.max_x, width), clamp(bounds.max_y, height));
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
    pub fn line(&mut self, a: ImagePoint, b: ImagePoint, c: [u8; 3]) {
        let s = self.scale as f64;
        let (x0, y0, x1, y1) = (a.x_px * s, a.y_px * s, b.x_px * s, b.y_px * s);
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
    pub fn circle(&mut self, centre: ImagePoint, r: f64, c: [u8; 3]) {
        self.circle_dashed(centre, r, c, None);
    }

    /// A circle in source-image pixels; with `dash` = Some(n), drawn as dashes n output pixels
    /// long with equal gaps.
    pub fn circle_dashed(&mut self, centre: ImagePoint, r: f64, c: [u8; 3], dash: Option<usize>) {
        if !(r.is_finite() && r > 0.0) {
            return;
        }
        // One segment per output pixel of circumference.
        let n = ((r * self.scale as f64 * 6.3).ceil() as usize).clamp(8, 20_000);
        let mut prev = ImagePoint::new(centre.x_px + r, centre.y_px);
        for i in 1..=n {
            let t = i as f64 / n as f64 * std::f64::consts::TAU;
            let p = ImagePoint::new(centre.x_px + r * t.cos(), centre.y_px + r * t.sin());
            if dash.is_none_or(|d| (i - 1) / d.max(1) % 2 == 0) {
                self.line(prev, p, c);
            }
            prev = p;
        }
    }

    /// An inclusive pixel box's outline.
    pub fn rect(&mut self, bounds: PixelBox, c: [u8; 3]) {
        let (x0, y0) = (f64::from(bounds.min_x), f64::from(bounds.min_y));
        let (x1, y1) = (f64::from(bounds.max_x) + 1.0, f64::from(bounds.max_y) + 1.0);
        let e = 0.5 / self.scale as f64;
        self.outline([x0, y0, x1 - e, y1 - e], c);
    }

    /// The outline of the rectangle `[left, top, right, bottom]` (source-image pixels, the
    /// right and bottom edges drawn on those coordinates).
    fn outline(&mut self, [x0, y0, x1, y1]: [f64; 4], c: [u8; 3]) {
        let corners = [
            ImagePoint::new(x0, y0),
            ImagePoint::new(x1, y0),
            ImagePoint::new(x1, y1),
            ImagePoint::new(x0, y1),
        ];
        for i in 0..4 {
            self.line(corners[i], corners[(i + 1) % 4], c);
        }
    }

    /// A label anchored at `at` (source-image pixels): its text (up to 64 characters) in the
    /// bitmap font on a dark backing just above the anchor, as the app draws it, moved the least
    /// distance that keeps it inside the picture (a ball at the top or bottom edge still shows
    /// its distance).
    pub fn label(&mut self, at: ImagePoint, text: &str, c: [u8; 3]) {
        const PAD: i64 = 2;
        if !at.is_finite() || text.is_empty() {
            return;
        }
        let shown: String = text.chars().take(64).collect();
        let (text_w, text_h) = text_size_px(&shown, 1);
        let (w, h) = (self.width as i64, self.height as i64);
        let box_w = text_w as i64 + 2 * PAD;
        let box_h = text_h as i64 + 2 * PAD;
        let s = self.scale as f64;
        let (ax, ay) = ((at.x_px * s).floor() as i64, (at.y_px * s).floor() as i64);
        let x0 = ax.min(w - box_w).max(0);
        let y0 = (ay - box_h - 2).min(h - box_h).max(0);
        for y in y0..(y0 + box_h).min(h) {
            for x in x0..(x0 + box_w).min(w) {
                let i = (y as usize * self.width + x as usize) * 3;
                for v in &mut self.rgb[i..i + 3] {
                    *v /= 4;
                }
            }
        }
        self.text((x0 + PAD, y0 + PAD), &shown, 1, c);
    }

    /// Writes `text` in the bitmap font (`font8x8`), each font pixel a `scale` × `scale` block
    /// (0 counts as 1), the first character cell's top-left corner at `top_left` output pixels;
    /// only the glyphs' own pixels are set, and those outside the canvas are left out. The one
    /// text routine of the overlays' labels and the evaluation charts.
    pub fn text(&mut self, top_left: (i64, i64), text: &str, scale: usize, c: [u8; 3]) {
        let scale = scale.max(1) as i64;
        let cell = FONT_CELL_PX as i64 * scale;
        for (k, ch) in text.chars().enumerate() {
            let cell_x = top_left.0.saturating_add((k as i64).saturating_mul(cell));
            if cell_x >= self.width as i64 {
                break;
            }
            for (row, bits) in glyph(ch).iter().enumerate() {
                let y = top_left.1.saturating_add(row as i64 * scale);
                for col in (0..8).filter(|col| bits & (1 << col) != 0) {
                    let x = cell_x + col * scale;
                    for dy in 0..scale {
                        for dx in 0..scale {
                            self.put(x.saturating_add(dx), y.saturating_add(dy), c);
                        }
                    }
                }
            }
        }
    }

    /// Draws every primitive, labels in a bitmap font.
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
                            (q.x_px * s).floor() as i64,
                            (q.y_px * s).floor() as i64,
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
                        self.outline([x0 + d, y0 + d, x1 + 1.0 - e - d, y1 + 1.0 - e - d], c);
                    }
                }
                Primitive::Label { at, text, .. } => self.label(*at, text, primitive_rgb(p)),
            }
        }
    }
}

/// Side of a character cell of the bitmap font, font pixels: text is this many pixels high and
/// this many wide per character at scale 1.
pub const FONT_CELL_PX: usize = 8;

/// Width and height of `text` written by [`Canvas::text`] at `scale`, output pixels.
#[must_use]
pub fn text_size_px(text: &str, scale: usize) -> (usize, usize) {
    let cell = FONT_CELL_PX * scale.max(1);
    (text.chars().count() * cell, cell)
}

/// The 8×8 bitmap of `ch` (rows top to bottom, bit 0 the leftmost column): Basic Latin and
/// Latin-1 from `font8x8`, `?` for anything else.
fn glyph(ch: char) -> [u8; 8] {
    use font8x8::UnicodeFonts as _;
    font8x8::BASIC_FONTS
        .get(ch)
        .or_else(|| font8x8::LATIN_FONTS.get(ch))
        .or_else(|| font8x8::BASIC_FONTS.get('?'))
        .unwrap_or([0; 8])
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
    use crate::recognition::ObjectId;

    fn label(at: (f64, f64), text: &str) -> Primitive {
        Primitive::Label {
            owner: ObjectId::Ball(0),
            at: ImagePoint::new(at.0, at.1),
            text: text.into(),
        }
    }

    /// The bounding box of the label's white text pixels, output pixels.
    fn white_text(c: &Canvas) -> Option<[usize; 4]> {
        let mut b: Option<[usize; 4]> = None;
        for (i, p) in c.rgb.chunks(3).enumerate() {
            if p == [255, 255, 255] {
                let (x, y) = (i % c.width, i / c.width);
                b = Some(b.map_or([x, y, x, y], |[a, b_, c_, d]| {
                    [a.min(x), b_.min(y), c_.max(x), d.max(y)]
                }));
            }
        }
        b
    }

    #[test]
    fn a_label_is_drawn_above_its_anchor_on_a_dark_backing() {
        let grey = vec![200u8; 200 * 60 * 3];
        let mut c = Canvas::from_rgb(200, 60, &grey, 1).expect("canvas");
        c.draw(&[label((20.0, 40.0), "ball 123 cm")]);
        let [x0, y0, x1, y1] = white_text(&c).expect("text drawn");
        assert!(x0 >= 20 && x1 < 20 + 11 * 8 + 4, "{x0}..{x1}");
        assert!(y1 < 40 && y0 > 40 - 16, "above the anchor: {y0}..{y1}");
        let untouched = (38 * 200 + 150) * 3;
        assert_eq!(&c.rgb[untouched..untouched + 3], &[200; 3]);
        assert!(
            c.rgb.chunks(3).any(|p| p == [50, 50, 50]),
            "the backing darkens the image"
        );
    }

    #[test]
    fn a_label_at_an_edge_is_kept_inside_the_picture() {
        for at in [(95.0, 2.0), (-30.0, 59.0), (f64::MAX, f64::MAX)] {
            let mut c = Canvas::from_rgb(100, 60, &[0u8; 100 * 60 * 3], 1).expect("canvas");
            c.draw(&[label(at, "goal 452 cm")]);
            let [x0, y0, x1, y1] = white_text(&c).expect("text drawn");
            assert!(x1 - x0 > 60, "whole text visible at {at:?}: {x0}..{x1}");
            assert!(y1 - y0 >= 5 && y1 < 60, "{at:?}: {y0}..{y1}");
        }
        let mut c = Canvas::from_rgb(10, 10, &[0u8; 300], 1).expect("canvas");
        c.draw(&[label((f64::NAN, 1.0), "x"), label((1.0, 1.0), "")]);
        assert!(white_text(&c).is_none(), "nothing drawn for NaN or no text");
    }

    #[test]
    fn text_sets_exactly_the_glyph_pixels_at_its_scale() {
        let (w, h) = (40, 24);
        let mut c = Canvas::from_rgb(w, h, &vec![0u8; w * h * 3], 1).expect("canvas");
        c.text((3, 2), "L-", 2, [255, 255, 255]);
        let lit = |x: usize, y: usize| c.rgb[(y * w + x) * 3] == 255;
        let glyphs = [glyph('L'), glyph('-')];
        let mut count = 0;
        for y in 0..h {
            for x in 0..w {
                let (fx, fy) = (x as i64 - 3, y as i64 - 2);
                let expected = (0..32).contains(&fx)
                    && (0..16).contains(&fy)
                    && glyphs[(fx / 16) as usize][(fy / 2) as usize] & (1 << (fx % 16 / 2)) != 0;
                assert_eq!(lit(x, y), expected, "pixel ({x}, {y})");
                count += usize::from(expected);
            }
        }
        // font8x8's L: a stroke in columns 1-2 and a foot along row 6; its dash: row 3, columns
        // 0-5 (each font pixel 2 × 2 here).
        assert!(lit(5, 6) && lit(7, 11) && !lit(3, 6), "the L's stroke");
        assert!(lit(3, 14) && lit(16, 15), "the L's foot");
        assert!(
            lit(19, 8) && lit(30, 9) && !lit(31, 8) && !lit(19, 10),
            "the dash"
        );
        assert!(count >= 4 * 10, "{count} pixels");
        assert_eq!(text_size_px("L-", 2), (32, 16));
    }

    #[test]
    fn text_past_an_edge_is_clipped_not_wrapped() {
        let (w, h) = (40, 20);
        let white = |c: &Canvas| -> Vec<(usize, usize)> {
            (0..w * h)
                .filter(|i| c.rgb[i * 3] == 255)
                .map(|i| (i % w, i / w))
                .collect()
        };
        let mut c = Canvas::from_rgb(w, h, &vec![0u8; w * h * 3], 1).expect("canvas");
        c.text((35, 15), "WWW", 1, [255, 255, 255]);
        let set = white(&c);
        assert!(!set.is_empty(), "the visible part is drawn");
        assert!(
            set.iter().all(|&(x, y)| x >= 35 && y >= 15),
            "nothing wraps to the left or top: {set:?}"
        );
        let mut c = Canvas::from_rgb(w, h, &vec![0u8; w * h * 3], 1).expect("canvas");
        c.text((-6, -4), "WW", 1, [255, 255, 255]);
        assert!(white(&c).iter().all(|&(x, y)| x < 10 && y < 4));
        c.text((i64::MAX, i64::MIN), "far away", 3, [255, 255, 255]);
        c.text((i64::MIN, i64::MAX), "far away", 3, [255, 255, 255]);
    }

    #[test]
    fn draws_boxes_lines_and_circles_inside_the_canvas_only() {
        let mut c = Canvas::from_rgb(10, 10, &[0u8; 300], 2).expect("canvas");
        assert_eq!((c.width, c.height), (20, 20));
        c.draw(&[
            Primitive::Box {
                owner: ObjectId::Blob(0),
                colour: 1,
                bounds: PixelBox::new(1, 1, 3, 3),
            },
            Primitive::Line {
                owner: ObjectId::Horizon,
                role: LineRole::Horizon,
                from: ImagePoint::new(-5.0, 1.0),
                to: ImagePoint::new(50.0, 1.0),
            },
            Primitive::Circle {
                owner: ObjectId::Ball(0),
                center: ImagePoint::new(5.0, 5.0),
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
                owner: ObjectId::Ball(0),
                center: ImagePoint::new(20.0, 20.0),
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
