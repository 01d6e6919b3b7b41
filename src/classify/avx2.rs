//! UYVY classification 16 pixels at a time with AVX2, in two kernels chosen at run time.
//!
//! Both turn 32 bytes of UYVY (16 pixels, 8 pairs) into 16 cell indices with vector shifts and
//! masks. [`classify_uyvy_gather`] then looks the cells up with two gathers: the table is bytes,
//! so each gather reads the aligned 4-byte word that holds the cell (`index & !3`, always inside
//! the table because its length is a multiple of 4) and shifts the cell's byte down. Gathers are
//! fast on AMD Zen 4/5 and slow on Zen 2 or under Intel's Gather Data Sampling mitigation, so
//! [`classify_uyvy_indexed`] instead stores the 16 indices and reads each cell with a scalar
//! load (loads are cheap everywhere; it is the index arithmetic that costs the portable loop).
//! `crate::kernels` decides which runs. Only this file and its AVX-512 sibling use `unsafe`:
//! loads, stores, gathers and unchecked table reads whose bounds are shown beforehand, and the
//! calls into `#[target_feature]` functions after the CPU said it has AVX2. Every kernel gives
//! the same codes as the portable loop (tested).

#![allow(unsafe_code)]

#[cfg(target_arch = "x86_64")]
use std::arch::x86_64::{
    __m256i, _mm256_and_si256, _mm256_loadu_si256, _mm256_or_si256, _mm256_set1_epi32,
    _mm256_sllv_epi32, _mm256_srlv_epi32,
};

/// Whether the table fits the kernels: `bits` in 6..=8 and `1 << (3 * bits)` cells, so every
/// index built from 8-bit Y, U, V is inside it.
#[cfg(target_arch = "x86_64")]
fn table_fits(table: &[u8], bits: u32) -> bool {
    (6..=8).contains(&bits) && table.len() == 1 << (3 * bits)
}

/// Classifies whole 16-pixel blocks of `src` into `dst` with AVX2 gathers and returns how many
/// pixels it did (the caller finishes the rest); 0 when the CPU has no AVX2 or the table does
/// not fit.
#[cfg(target_arch = "x86_64")]
pub(super) fn classify_uyvy_gather(src: &[u8], table: &[u8], bits: u32, dst: &mut [u8]) -> usize {
    if !table_fits(table, bits) || !std::arch::is_x86_feature_detected!("avx2") {
        return 0;
    }
    // SAFETY: the CPU supports AVX2 (checked just above), the only requirement of a
    // `#[target_feature(enable = "avx2")]` function; its own bounds rest on `table_fits`.
    unsafe { classify_uyvy_avx2(src, table, bits, dst) }
}

/// As [`classify_uyvy_gather`], with scalar loads of the cells instead of gathers.
#[cfg(target_arch = "x86_64")]
pub(super) fn classify_uyvy_indexed(src: &[u8], table: &[u8], bits: u32, dst: &mut [u8]) -> usize {
    if !table_fits(table, bits) || !std::arch::is_x86_feature_detected!("avx2") {
        return 0;
    }
    // SAFETY: as in `classify_uyvy_gather`.
    unsafe { classify_uyvy_avx2_indexed(src, table, bits, dst) }
}

/// Non-x86 targets always take the portable loop.
#[cfg(not(target_arch = "x86_64"))]
pub(super) fn classify_uyvy_gather(_: &[u8], _: &[u8], _: u32, _: &mut [u8]) -> usize {
    0
}

/// Non-x86 targets always take the portable loop.
#[cfg(not(target_arch = "x86_64"))]
pub(super) fn classify_uyvy_indexed(_: &[u8], _: &[u8], _: u32, _: &mut [u8]) -> usize {
    0
}

/// The cell indices of 16 pixels from 32 bytes of UYVY, `bits` per channel: lane k of the first
/// vector is pixel 2k's, of the second pixel 2k + 1's.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[inline]
fn cell_indices(block: &[u8; 32], bits: i32) -> (__m256i, __m256i) {
    let shift = 8 - bits;
    let count = |n: i32| _mm256_set1_epi32(n);
    let mask = count((1 << bits) - 1);
    // SAFETY: `block` is 32 bytes; the load is unaligned.
    let q = unsafe { _mm256_loadu_si256(block.as_ptr().cast::<__m256i>()) };
    // Each 32-bit lane is one pair U Y0 V Y1 (little-endian).
    let field = |at: i32| _mm256_and_si256(_mm256_srlv_epi32(q, count(at)), mask);
    let uv = _mm256_or_si256(
        _mm256_sllv_epi32(field(shift), count(bits)),
        field(16 + shift),
    );
    let to_y = count(2 * bits);
    (
        _mm256_or_si256(_mm256_sllv_epi32(field(8 + shift), to_y), uv),
        _mm256_or_si256(_mm256_sllv_epi32(field(24 + shift), to_y), uv),
    )
}

/// The indexed kernel: indices by vector, cells by scalar loads, 8 codes packed per store.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn classify_uyvy_avx2_indexed(src: &[u8], table: &[u8], bits: u32, dst: &mut [u8]) -> usize {
    use std::arch::x86_64::{
        _mm256_permute2x128_si256, _mm256_storeu_si256, _mm256_unpackhi_epi32,
        _mm256_unpacklo_epi32,
    };

    let (blocks, _) = src.as_chunks::<32>();
    let (outs, _) = dst.as_chunks_mut::<16>();
    let mut done = 0;
    let mut index = [0u32; 16];
    for (block, out) in blocks.iter().zip(outs) {
        let (first, second) = cell_indices(block, bits.cast_signed());
        // Pixel order: pairs interleaved within each 128-bit half, then the halves arranged.
        let (lo, hi) = (
            _mm256_unpacklo_epi32(first, second),
            _mm256_unpackhi_epi32(first, second),
        );
        // SAFETY: `index` is 64 bytes, two unaligned 32-byte stores.
        unsafe {
            let at = index.as_mut_ptr().cast::<__m256i>();
            _mm256_storeu_si256(at, _mm256_permute2x128_si256::<0x20>(lo, hi));
            _mm256_storeu_si256(at.add(1), _mm256_permute2x128_si256::<0x31>(lo, hi));
        }
        for (half, bytes) in index
            .as_chunks::<8>()
            .0
            .iter()
            .zip(out.as_chunks_mut::<8>().0)
        {
            let mut word = 0u64;
            for (k, &i) in half.iter().enumerate() {
                // SAFETY: every index is below `1 << (3 * bits)` = `table.len()` (`table_fits`).
                word |= u64::from(unsafe { *table.get_unchecked(i as usize) }) << (8 * k);
            }
            *bytes = word.to_le_bytes();
        }
        done += 16;
    }
    done
}

/// The gather kernel. `table_fits(table, bits)` must hold.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn classify_uyvy_avx2(src: &[u8], table: &[u8], bits: u32, dst: &mut [u8]) -> usize {
    use std::arch::x86_64::{
        __m128i, _mm_storeu_si128, _mm256_castsi256_si128, _mm256_i32gather_epi32,
        _mm256_packus_epi32, _mm256_permute4x64_epi64,
    };

    let low_byte = _mm256_set1_epi32(0xff);
    let word_start = _mm256_set1_epi32(!3);
    let byte_in_word = _mm256_set1_epi32(3);
    let (times_8, by_a_byte) = (_mm256_set1_epi32(3), _mm256_set1_epi32(8));

    // One table cell, gathered as its aligned word and shifted down to the low byte.
    let lookup = |index: __m256i| -> __m256i {
        let words = _mm256_and_si256(index, word_start);
        // SAFETY: every index is below `table.len()` (a multiple of 4), so each aligned word
        // lies wholly inside the table; gathers need no alignment.
        let got = unsafe { _mm256_i32gather_epi32::<1>(table.as_ptr().cast::<i32>(), words) };
        let bit_offset = _mm256_sllv_epi32(_mm256_and_si256(index, byte_in_word), times_8);
        _mm256_and_si256(_mm256_srlv_epi32(got, bit_offset), low_byte)
    };

    let (blocks, _) = src.as_chunks::<32>();
    let (outs, _) = dst.as_chunks_mut::<16>();
    let mut done = 0;
    for (block, out) in blocks.iter().zip(outs) {
        let (even, odd) = cell_indices(block, bits.cast_signed());
        let (first, second) = (lookup(even), lookup(odd));
        // Lane k holds pixel 2k in its low byte and pixel 2k + 1 in the next.
        let pairs = _mm256_or_si256(first, _mm256_sllv_epi32(second, by_a_byte));
        // Dwords to words within each 128-bit half, then the two halves' low quads together.
        let packed = _mm256_permute4x64_epi64::<0b00_00_10_00>(_mm256_packus_epi32(pairs, pairs));
        // SAFETY: `out` is 16 bytes; the store is unaligned.
        unsafe {
            _mm_storeu_si128(
                out.as_mut_ptr().cast::<__m128i>(),
                _mm256_castsi256_si128(packed),
            )
        };
        done += 16;
    }
    done
}
