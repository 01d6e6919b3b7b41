//! The one conversion of other colour spaces into the YUV the lookup tables are indexed by:
//! BT.601 studio range (Y 16..235, U and V 16..240), as [`super::rgb_to_yuv`] defines it.
//!
//! - RGB (PNG, `rgb8`/`bgr8`/… images, demosaiced Bayer): [`RgbToYuv`], a table form of
//!   [`super::rgb_to_yuv`] (16.16 fixed point, the same results but for values within 10⁻⁴ of
//!   a rounding boundary, which may land one level apart).
//! - JPEG: its decoder's own YCbCr, full range (JFIF), mapped to studio range without going
//!   through RGB: `Y' = 16 + 219·Y/255`, `C' = 128 + 224·(C − 128)/255`, rounded
//!   ([`full_to_studio_luma`], [`full_to_studio_chroma`]). JFIF's YCbCr is BT.601 of the same
//!   RGB, so this is [`super::rgb_to_yuv`] of the RGB the JPEG encoded, without the clamp of that
//!   RGB to 0..255 that a round trip through RGB adds.

use std::sync::OnceLock;

use super::Yuv;

/// Fixed-point scale of the tables: 16 fractional bits.
const ONE: i32 = 1 << 16;

/// RGB → studio-range YUV by table look-up: nine 256-entry tables of each channel's share.
#[derive(Debug)]
pub struct RgbToYuv {
    y: [[i32; 256]; 3],
    u: [[i32; 256]; 3],
    v: [[i32; 256]; 3],
}

/// The BT.601 weights of [`super::rgb_to_yuv`] (studio range, per 255 of input): rows Y, U, V;
/// columns R, G, B.
const WEIGHTS: [[f64; 3]; 3] = [
    [65.481, 128.553, 24.966],
    [-37.797, -74.203, 112.0],
    [112.0, -93.786, -18.214],
];

impl RgbToYuv {
    fn build() -> Self {
        let table = |w: f64| {
            let mut t = [0i32; 256];
            for (i, slot) in t.iter_mut().enumerate() {
                // |w·255/255| ≤ 128.6, so the product fits an i32 at 16 fractional bits.
                #[expect(clippy::cast_possible_truncation, reason = "at most 2^24 in magnitude")]
                let fixed = (w * i as f64 / 255.0 * f64::from(ONE)).round() as i32;
                *slot = fixed;
            }
            t
        };
        let row = |r: [f64; 3]| [table(r[0]), table(r[1]), table(r[2])];
        Self {
            y: row(WEIGHTS[0]),
            u: row(WEIGHTS[1]),
            v: row(WEIGHTS[2]),
        }
    }

    /// The shared tables (built once, on first use).
    #[must_use]
    pub fn get() -> &'static Self {
        static TABLES: OnceLock<RgbToYuv> = OnceLock::new();
        TABLES.get_or_init(Self::build)
    }

    /// One pixel.
    #[inline]
    #[must_use]
    pub fn convert(&self, r: u8, g: u8, b: u8) -> Yuv {
        let (r, g, b) = (usize::from(r), usize::from(g), usize::from(b));
        let y = 16 * ONE + self.y[0][r] + self.y[1][g] + self.y[2][b];
        let u = 128 * ONE + self.u[0][r] + self.u[1][g] + self.u[2][b];
        let v = 128 * ONE + self.v[0][r] + self.v[1][g] + self.v[2][b];
        Yuv::new(fixed_to_u8(y), fixed_to_u8(u), fixed_to_u8(v))
    }
}

/// Rounds a 16.16 fixed-point value to the nearest integer, clamped to 0..=255.
#[inline]
fn fixed_to_u8(v: i32) -> u8 {
    let rounded = (v + ONE / 2) >> 16;
    u8::try_from(rounded.clamp(0, 255)).unwrap_or(u8::MAX)
}

/// Full-range (JFIF) luma → studio range: `16 + 219·Y/255`, rounded.
#[must_use]
pub fn full_to_studio_luma(y: u8) -> u8 {
    studio_maps().0[usize::from(y)]
}

/// Full-range (JFIF) chroma → studio range: `128 + 224·(C − 128)/255`, rounded.
#[must_use]
pub fn full_to_studio_chroma(c: u8) -> u8 {
    studio_maps().1[usize::from(c)]
}

/// The two full→studio maps (luma, chroma), built once.
#[must_use]
pub fn studio_maps() -> &'static ([u8; 256], [u8; 256]) {
    static MAPS: OnceLock<([u8; 256], [u8; 256])> = OnceLock::new();
    MAPS.get_or_init(|| {
        let mut luma = [0u8; 256];
        let mut chroma = [0u8; 256];
        for i in 0..=255u8 {
            let v = f64::from(i);
            luma[usize::from(i)] = super::round_u8(16.0 + 219.0 * v / 255.0);
            chroma[usize::from(i)] = super::round_u8(128.0 + 224.0 * (v - 128.0) / 255.0);
        }
        (luma, chroma)
    })
}

/// The full→studio maps in 16-bit fixed point, one form for both channels:
/// `16 + ((256·x + c) · m) >> 24`, with `(c, m)` = (148, 56 285) for luma (`16 + 219·x/255`) and
/// (14, 57 575) for chroma (`128 + 224·(x − 128)/255`), rounded. Found by search over all 256
/// values and equal to [`full_to_studio_luma`] and [`full_to_studio_chroma`] for every value
/// (tested). `256·x + c` fits 16 bits, and `(… · m) >> 16` is a 16-bit high multiply, so the
/// loop below runs 8 or 16 lanes at a time on plain SSE2.
const LUMA_FIXED: (u16, u16) = (148, 56_285);
/// See [`LUMA_FIXED`].
const CHROMA_FIXED: (u16, u16) = (14, 57_575);

#[inline]
fn map_fixed(x: u8, (c, m): (u16, u16)) -> u8 {
    let t = (u16::from(x) << 8) | c;
    let high = (u32::from(t) * u32::from(m)) >> 16;
    // high < 2^16, so high >> 8 ≤ 224 (chroma) or 219 (luma): no overflow adding 16.
    16 + (high >> 8) as u8
}

/// Full-range luma → studio range (equal to [`full_to_studio_luma`] for every value; tested).
#[inline]
fn luma_fixed(y: u8) -> u8 {
    map_fixed(y, LUMA_FIXED)
}

/// Full-range chroma → studio range (equal to [`full_to_studio_chroma`] for every value;
/// tested).
#[inline]
fn chroma_fixed(c: u8) -> u8 {
    map_fixed(c, CHROMA_FIXED)
}

/// Pixels of a block of [`full_to_studio_in_place`]: 16 pixels, 48 bytes, whole vectors.
const BLOCK_PIXELS: usize = 16;

/// Each byte's `(c, m)` in a block of interleaved Y, Cb, Cr: the channel of every lane is fixed,
/// so the loop is the same arithmetic on every lane and vectorises.
const BLOCK_CONSTANTS: ([u16; 3 * BLOCK_PIXELS], [u16; 3 * BLOCK_PIXELS]) = {
    let mut c = [0u16; 3 * BLOCK_PIXELS];
    let mut m = [0u16; 3 * BLOCK_PIXELS];
    let mut k = 0;
    while k < 3 * BLOCK_PIXELS {
        let (ck, mk) = if k % 3 == 0 { LUMA_FIXED } else { CHROMA_FIXED };
        c[k] = ck;
        m[k] = mk;
        k += 1;
    }
    (c, m)
};

/// Converts interleaved full-range YCbCr (3 bytes a pixel) to studio range in place: 16 pixels
/// at a time with every lane's constants known, so the compiler vectorises it (16-bit high
/// multiplies); the last pixels one by one.
pub fn full_to_studio_in_place(ycbcr: &mut [u8]) {
    let (cs, ms) = &BLOCK_CONSTANTS;
    let mut blocks = ycbcr.chunks_exact_mut(3 * BLOCK_PIXELS);
    for block in &mut blocks {
        for ((b, &c), &m) in block.iter_mut().zip(cs).zip(ms) {
            *b = map_fixed(*b, (c, m));
        }
    }
    for p in blocks.into_remainder().chunks_exact_mut(3) {
        p[0] = luma_fixed(p[0]);
        p[1] = chroma_fixed(p[1]);
        p[2] = chroma_fixed(p[2]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frame::rgb_to_yuv;

    #[test]
    fn tables_agree_with_the_defining_formula() {
        // Every 3rd value of each channel (5.6 M colours): at most one level apart, and
        // almost always equal.
        let t = RgbToYuv::get();
        let (mut total, mut differ) = (0u64, 0u64);
        for r in (0..=255u8).step_by(3) {
            for g in (0..=255u8).step_by(3) {
                for b in 0..=255u8 {
                    let (a, e) = (t.convert(r, g, b), rgb_to_yuv([r, g, b]));
                    total += 1;
                    let d =
                        a.y.abs_diff(e.y)
                            .max(a.u.abs_diff(e.u))
                            .max(a.v.abs_diff(e.v));
                    assert!(d <= 1, "{r} {g} {b}: {a:?} vs {e:?}");
                    differ += u64::from(d > 0);
                }
            }
        }
        assert!(differ * 10_000 < total, "{differ} of {total} differ");
    }

    #[test]
    fn fixed_point_maps_equal_the_rounded_formula() {
        for v in 0..=255u8 {
            assert_eq!(luma_fixed(v), full_to_studio_luma(v), "luma {v}");
            assert_eq!(chroma_fixed(v), full_to_studio_chroma(v), "chroma {v}");
        }
        let mut long: Vec<u8> = (0..300u32).map(|i| (i * 7 % 256) as u8).collect();
        let want: Vec<u8> = long
            .iter()
            .enumerate()
            .map(|(i, &v)| {
                if i % 3 == 0 {
                    full_to_studio_luma(v)
                } else {
                    full_to_studio_chroma(v)
                }
            })
            .collect();
        full_to_studio_in_place(&mut long);
        assert_eq!(long, want);
        // Every value in every lane of a block: 256 blocks, lane k of block v holding v.
        let mut every: Vec<u8> = (0..=255u8).flat_map(|v| [v; 3 * BLOCK_PIXELS]).collect();
        full_to_studio_in_place(&mut every);
        for (i, &got) in every.iter().enumerate() {
            let (v, lane) = ((i / (3 * BLOCK_PIXELS)) as u8, i % (3 * BLOCK_PIXELS));
            let want = if lane % 3 == 0 {
                full_to_studio_luma(v)
            } else {
                full_to_studio_chroma(v)
            };
            assert_eq!(got, want, "value {v} in lane {lane}");
        }
    }

    #[test]
    fn full_range_maps_to_studio_range_ends() {
        assert_eq!(full_to_studio_luma(0), 16);
        assert_eq!(full_to_studio_luma(255), 235);
        assert_eq!(full_to_studio_chroma(128), 128);
        assert_eq!(full_to_studio_chroma(0), 16);
        assert_eq!(full_to_studio_chroma(255), 240);
        let mut px = [255, 128, 0];
        full_to_studio_in_place(&mut px);
        assert_eq!(px, [235, 128, 16]);
    }

    #[test]
    fn jfif_ycbcr_of_an_rgb_maps_onto_rgb_to_yuv_of_it() {
        // JFIF: Y = 0.299R + 0.587G + 0.114B, Cb = 128 − 0.168736R − 0.331264G + 0.5B,
        // Cr = 128 + 0.5R − 0.418688G − 0.081312B.
        for rgb in [
            [250u8, 110, 20],
            [45, 140, 60],
            [40, 110, 200],
            [255, 255, 255],
        ] {
            let [r, g, b] = rgb.map(f64::from);
            let y = crate::frame::round_u8(0.299 * r + 0.587 * g + 0.114 * b);
            let cb = crate::frame::round_u8(128.0 - 0.168_736 * r - 0.331_264 * g + 0.5 * b);
            let cr = crate::frame::round_u8(128.0 + 0.5 * r - 0.418_688 * g - 0.081_312 * b);
            let via = Yuv::new(
                full_to_studio_luma(y),
                full_to_studio_chroma(cb),
                full_to_studio_chroma(cr),
            );
            let direct = rgb_to_yuv(rgb);
            for (a, b) in [(via.y, direct.y), (via.u, direct.u), (via.v, direct.v)] {
                assert!(a.abs_diff(b) <= 1, "{rgb:?}: {via:?} vs {direct:?}");
            }
        }
    }
}
