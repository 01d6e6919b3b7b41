//! Colour classification: every pixel of a frame looked up in the table.
//!
//! This is the hottest loop of the pipeline. For UYVY it follows CMVision's shape in safe Rust:
//! the frame is walked in 4-byte pixel pairs, the shared U/V part of the cell index is built once
//! per pair, and the table is a fixed-size array per resolution so the compiler can prove every
//! index in bounds (no checks in the loop). Output goes into a caller-owned
//! [`ClassifiedImage`] reused frame after frame. On x86 CPUs with AVX2 or AVX-512 faster
//! kernels do 16 or 32 pixels per step instead (`avx2.rs`, `avx512.rs`); which runs is the
//! [`KernelSet`] `crate::kernels` chooses for the CPU.

mod avx2;
mod avx512;

use crate::frame::{Frame, PixelLayout, Yuv};
use crate::kernels::{self, KernelSet};
use crate::lut::{ColourClass, LookupTable, code_display_rgb};

/// One class code per pixel, row-major.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct ClassifiedImage {
    width: usize,
    height: usize,
    codes: Vec<u8>,
}

impl ClassifiedImage {
    /// An image of unclassified pixels.
    #[must_use]
    pub fn new(width: usize, height: usize) -> Self {
        Self {
            width,
            height,
            codes: vec![0; width * height],
        }
    }

    /// An image from codes (row-major); `None` when the length is not width × height.
    #[must_use]
    pub fn from_codes(width: usize, height: usize, codes: Vec<u8>) -> Option<Self> {
        (codes.len() == width * height).then_some(Self {
            width,
            height,
            codes,
        })
    }

    /// Classifies a frame into a new image.
    #[must_use]
    pub fn from_frame(frame: &Frame, lut: &LookupTable) -> Self {
        let mut out = Self::default();
        classify_into(frame, lut, &mut out);
        out
    }

    /// Width, pixels.
    #[must_use]
    pub const fn width(&self) -> usize {
        self.width
    }

    /// Height, pixels.
    #[must_use]
    pub const fn height(&self) -> usize {
        self.height
    }

    /// All codes, row-major.
    #[must_use]
    pub fn codes(&self) -> &[u8] {
        &self.codes
    }

    /// All codes, mutable (for drawing test images).
    pub fn codes_mut(&mut self) -> &mut [u8] {
        &mut self.codes
    }

    /// One row of codes, or an empty slice past the bottom.
    #[must_use]
    pub fn row(&self, y: usize) -> &[u8] {
        self.codes
            .get(y * self.width..(y + 1) * self.width)
            .unwrap_or(&[])
    }

    /// The code at (x, y), or `None` outside the image.
    #[must_use]
    pub fn get(&self, x: usize, y: usize) -> Option<u8> {
        (x < self.width && y < self.height).then(|| self.codes[y * self.width + x])
    }

    /// The code at signed coordinates, `None` outside: scans that wander past the edge use this.
    #[must_use]
    pub fn get_signed(&self, x: i64, y: i64) -> Option<u8> {
        let (x, y) = (usize::try_from(x).ok()?, usize::try_from(y).ok()?);
        self.get(x, y)
    }

    /// The code of the pixel holding the point (x, y) in image coordinates (pixels, pixel
    /// (i, j) covering [i, i + 1) × [j, j + 1)), `None` outside or for a NaN. Rotated scans
    /// sample through this: `f64::floor` is a library call on the baseline x86-64 target (no
    /// SSE4.1), which made it a tenth of the recognition step's time.
    #[must_use]
    #[inline]
    pub fn get_at(&self, x: f64, y: f64) -> Option<u8> {
        if !(x >= 0.0 && y >= 0.0) {
            return None;
        }
        // Truncation is the floor for the non-negative; huge values saturate and fall outside.
        self.get(x as usize, y as usize)
    }

    /// The class at (x, y), or `None` outside the image.
    #[must_use]
    pub fn class_at(&self, x: usize, y: usize) -> Option<ColourClass> {
        self.get(x, y).and_then(ColourClass::from_code)
    }

    /// Resizes for a frame of this size (keeps the allocation when it can).
    pub fn resize(&mut self, width: usize, height: usize) {
        self.width = width;
        self.height = height;
        self.codes.resize(width * height, 0);
    }

    /// Pixels per class code (index = code).
    #[must_use]
    pub fn histogram(&self) -> [usize; 256] {
        let mut h = [0usize; 256];
        for &c in &self.codes {
            h[usize::from(c)] += 1;
        }
        h
    }

    /// The image in display colours, packed RGB.
    #[must_use]
    pub fn to_rgb(&self) -> Vec<u8> {
        let mut out = Vec::with_capacity(self.codes.len() * 3);
        for &c in &self.codes {
            out.extend_from_slice(&code_display_rgb(c));
        }
        out
    }
}

/// Classifies `frame` with `lut` into `out`, resizing it to the frame, with the kernels
/// chosen for this CPU ([`kernels::active`]).
pub fn classify_into(frame: &Frame, lut: &LookupTable, out: &mut ClassifiedImage) {
    classify_into_with(kernels::active(), frame, lut, out);
}

/// [`classify_into`] with the kernels of `set` (the portable loop where the CPU lacks them).
pub fn classify_into_with(
    set: KernelSet,
    frame: &Frame,
    lut: &LookupTable,
    out: &mut ClassifiedImage,
) {
    out.resize(frame.width(), frame.height());
    let dst = &mut out.codes;
    match frame.layout() {
        PixelLayout::Uyvy => classify_uyvy_with(set, frame.data(), lut, dst),
        // Pixel i of a 4:4:4 frame is code i: zipped straight through, without the per-pixel
        // division into (x, y) that `for_each_pixel` does, which was four fifths of a decoded
        // 224×224 JPEG frame's classification, blobs and recognition (`benches/ssl_frame.rs`).
        PixelLayout::Yuv444Packed => {
            for (d, p) in dst.iter_mut().zip(frame.data().chunks_exact(3)) {
                *d = lut.classify(Yuv::new(p[0], p[1], p[2]));
            }
        }
        PixelLayout::Yuv444Planar => {
            let n = frame.pixel_count();
            let (ys, rest) = frame.data().split_at(n.min(frame.data().len()));
            let (us, vs) = rest.split_at(n.min(rest.len()));
            for (d, ((&y, &u), &v)) in dst.iter_mut().zip(ys.iter().zip(us).zip(vs)) {
                *d = lut.classify(Yuv::new(y, u, v));
            }
        }
    }
}

/// Classifies raw UYVY bytes into `dst` (one code per pixel); `dst.len()` must be half of
/// `src.len()`, extra bytes of either are left alone. Uses the kernels chosen for this CPU.
pub fn classify_uyvy(src: &[u8], lut: &LookupTable, dst: &mut [u8]) {
    classify_uyvy_with(kernels::active(), src, lut, dst);
}

/// [`classify_uyvy`] with the kernel of `set`; every set gives the same codes. A set the CPU
/// cannot run falls back to [`classify_uyvy_portable`].
pub fn classify_uyvy_with(set: KernelSet, src: &[u8], lut: &LookupTable, dst: &mut [u8]) {
    let (cells, bits) = (lut.cells(), u32::from(lut.bits()));
    let done = match set {
        KernelSet::Portable => 0,
        KernelSet::Avx2 | KernelSet::Avx512 => avx2::classify_uyvy_indexed(src, cells, bits, dst),
        KernelSet::Avx2Gather => avx2::classify_uyvy_gather(src, cells, bits, dst),
        KernelSet::Avx512Gather => avx512::classify_uyvy_gather(src, cells, bits, dst),
    };
    let (src_rest, dst_rest) = (
        src.get(done * 2..).unwrap_or(&[]),
        dst.get_mut(done..).unwrap_or(&mut []),
    );
    classify_uyvy_portable(src_rest, lut, dst_rest);
}

/// [`classify_uyvy`] in safe portable Rust on every CPU (for comparison in benchmarks).
pub fn classify_uyvy_portable(src: &[u8], lut: &LookupTable, dst: &mut [u8]) {
    let cells = lut.cells();
    match lut.bits() {
        6 => {
            if let Ok(t) = <&[u8; 1 << 18]>::try_from(cells) {
                classify_uyvy_b6(src, t, dst);
            }
        }
        7 => {
            if let Ok(t) = <&[u8; 1 << 21]>::try_from(cells) {
                classify_uyvy_b7(src, t, dst);
            }
        }
        _ => {
            if let Ok(t) = <&[u8; 1 << 24]>::try_from(cells) {
                classify_uyvy_b8(src, t, dst);
            }
        }
    }
}

/// One monomorphic loop per table resolution; the array type bounds every index.
macro_rules! classify_uyvy_bits {
    ($name:ident, $bits:literal) => {
        #[inline(never)]
        fn $name(src: &[u8], table: &[u8; 1 << (3 * $bits)], dst: &mut [u8]) {
            const B: u32 = $bits;
            const S: u32 = 8 - B;
            const M: u32 = (1 << B) - 1;
            let (pairs, _) = src.as_chunks::<4>();
            let (outs, _) = dst.as_chunks_mut::<2>();
            for (q, o) in pairs.iter().zip(outs) {
                // Bytes U Y0 V Y1 as one little-endian word: one load per pixel pair.
                let w = u32::from_le_bytes(*q);
                let uv = (((w >> S) & M) << B) | ((w >> (16 + S)) & M);
                let y0 = (w >> (8 + S)) & M;
                let y1 = w >> (24 + S);
                *o = [
                    table[((y0 << (2 * B)) | uv) as usize],
                    table[((y1 << (2 * B)) | uv) as usize],
                ];
            }
        }
    };
}

classify_uyvy_bits!(classify_uyvy_b6, 6);
classify_uyvy_bits!(classify_uyvy_b7, 7);
classify_uyvy_bits!(classify_uyvy_b8, 8);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frame::Yuv;
    use crate::lut::{EditRecord, Region, Sensitivity};

    fn table_with(bits: u8, p: Yuv, class: ColourClass) -> LookupTable {
        let mut t = LookupTable::new(bits).unwrap();
        t.apply(EditRecord::now(
            class,
            Region::AroundSample {
                sample: p,
                sensitivity: Sensitivity::default(),
            },
        ));
        t
    }

    /// 4:4:4 frames, packed and planar, classify pixel i into code i exactly as the table
    /// classifies that pixel (the zipped loop against a per-pixel lookup).
    #[test]
    fn yuv444_frames_classify_each_pixel_into_its_own_code() {
        let mut t = table_with(6, Yuv::new(120, 90, 180), ColourClass::Orange);
        t.apply(EditRecord::now(
            ColourClass::Green,
            Region::AroundSample {
                sample: Yuv::new(100, 110, 100),
                sensitivity: Sensitivity::default(),
            },
        ));
        let (w, h) = (37, 23);
        let mut state = 12345u32;
        let mut next = || {
            state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            (state >> 24) as u8
        };
        let pixels: Vec<Yuv> = (0..w * h)
            .map(|k| match k % 3 {
                0 => Yuv::new(120, 90, 180),
                1 => Yuv::new(100, 110, 100),
                _ => Yuv::new(next(), next(), next()),
            })
            .collect();
        let packed = Frame::yuv444_from_fn(w, h, |x, y| pixels[y * w + x]).unwrap();
        let planar_bytes: Vec<u8> = [0, 1, 2]
            .iter()
            .flat_map(|&c| pixels.iter().map(move |p| [p.y, p.u, p.v][c]))
            .collect();
        let planar = Frame::new(w, h, PixelLayout::Yuv444Planar, planar_bytes).unwrap();
        for frame in [&packed, &planar] {
            let mut out = ClassifiedImage::default();
            classify_into(frame, &t, &mut out);
            let mut classes = std::collections::BTreeSet::new();
            for y in 0..h {
                for x in 0..w {
                    let want = t.classify(pixels[y * w + x]);
                    assert_eq!(out.get(x, y), Some(want), "{:?} at {x},{y}", frame.layout());
                    classes.insert(want);
                }
            }
            assert!(
                classes.len() >= 3,
                "the frame shows several classes: {classes:?}"
            );
        }
    }

    #[test]
    fn fast_path_agrees_with_per_pixel_lookup_for_all_resolutions() {
        let frame = Frame::uyvy_from_fn(16, 8, |x, y| {
            Yuv::new((x * 16 + y) as u8, (y * 31) as u8, (x * 13 + 7) as u8)
        })
        .unwrap();
        for bits in [6, 7, 8] {
            let mut t = LookupTable::new(bits).unwrap();
            for i in 0..t.cells().len() {
                t.set(i, ColourClass::from_code((i % 15) as u8).unwrap());
            }
            let img = ClassifiedImage::from_frame(&frame, &t);
            for y in 0..8 {
                for x in 0..16 {
                    assert_eq!(img.get(x, y), Some(t.classify(frame.pixel(x, y).unwrap())));
                }
            }
        }
    }

    #[test]
    fn every_runnable_kernel_set_equals_the_portable_loop() {
        // Every length around the 16-pixel blocks, every resolution, cells with many codes and
        // pixels that reach the table's last cells (the gather reads whole words). Each kernel
        // set this CPU can run is called by name; an x86-64 CPU without AVX2 can compare none,
        // which is a visible skip (a failure under CI=true).
        let sets = crate::kernels::runnable_saying_the_rest("classify loop");
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        for bits in [6, 7, 8] {
            let mut t = LookupTable::new(bits).unwrap();
            for i in 0..t.cells().len() {
                t.set(i, ColourClass::from_code((next() % 15) as u8).unwrap());
            }
            for pairs in [0usize, 1, 7, 8, 9, 15, 16, 17, 104, 333] {
                let mut src: Vec<u8> = (0..pairs * 4).map(|_| next() as u8).collect();
                if let Some(q) = src.first_chunk_mut::<4>() {
                    *q = [255; 4];
                }
                let mut plain = vec![0u8; pairs * 2];
                classify_uyvy_portable(&src, &t, &mut plain);
                for &set in &sets {
                    let mut fast = vec![0u8; pairs * 2];
                    classify_uyvy_with(set, &src, &t, &mut fast);
                    assert_eq!(fast, plain, "{set}, bits {bits}, {pairs} pairs");
                }
            }
        }
    }

    #[test]
    fn both_pixels_of_a_pair_use_their_own_luma() {
        let frame = Frame::from_uyvy(2, 1, vec![80, 120, 190, 30]).unwrap();
        let t = table_with(7, Yuv::new(120, 80, 190), ColourClass::Orange);
        let img = ClassifiedImage::from_frame(&frame, &t);
        assert_eq!(img.codes(), [1, 0]);
    }

    #[test]
    fn yuv444_frames_classify_too() {
        let frame = Frame::yuv444_from_fn(3, 1, |x, _| {
            if x == 1 {
                Yuv::new(120, 80, 190)
            } else {
                Yuv::new(0, 0, 0)
            }
        })
        .unwrap();
        let t = table_with(6, Yuv::new(120, 80, 190), ColourClass::Orange);
        assert_eq!(ClassifiedImage::from_frame(&frame, &t).codes(), [0, 1, 0]);
    }

    #[test]
    fn signed_access_is_none_outside() {
        let img = ClassifiedImage::new(4, 3);
        assert_eq!(img.get_signed(-1, 0), None);
        assert_eq!(img.get_signed(3, 2), Some(0));
        assert_eq!(img.get_signed(4, 2), None);
        assert!(img.row(3).is_empty());
    }

    #[test]
    fn point_access_takes_the_pixel_holding_the_point() {
        let codes = (0..12).collect();
        let img = ClassifiedImage::from_codes(4, 3, codes).expect("size");
        // Pixel (i, j) covers [i, i + 1) × [j, j + 1): the same as flooring, for any point.
        for (x, y) in [
            (0.0_f64, 0.0_f64),
            (0.99, 0.5),
            (1.0, 1.0),
            (3.999, 2.999),
            (2.5, 1.25),
        ] {
            let floored = img.get_signed(x.floor() as i64, y.floor() as i64);
            assert_eq!(img.get_at(x, y), floored, "({x}, {y})");
            assert!(floored.is_some());
        }
        assert_eq!(img.get_at(2.5, 1.25), Some(6));
        // Just left of or above the image is outside (truncation alone would give column 0),
        // and so are the far edges, NaN and the infinities.
        for (x, y) in [
            (-0.5, 1.0),
            (1.0, -0.01),
            (4.0, 1.0),
            (1.0, 3.0),
            (f64::NAN, 1.0),
            (1.0, f64::NAN),
            (f64::INFINITY, 1.0),
            (f64::NEG_INFINITY, 1.0),
        ] {
            assert_eq!(img.get_at(x, y), None, "({x}, {y})");
        }
    }
}
