//! UYVY classification 32 pixels at a time with AVX-512 gathers, chosen at run time.
//!
//! The AVX2 gather kernel (`avx2.rs`) widened: 64 bytes of UYVY (32 pixels, 16 pairs) become two
//! vectors of 16 cell indices, each looked up by one gather of the aligned 4-byte words holding
//! the cells, and the 32 codes are narrowed with one `vpmovdw`. `crate::kernels` chooses it
//! only on CPUs whose gathers were measured fast. Only this file and `avx2.rs` use `unsafe`
//! (loads, stores, gathers whose bounds are shown beforehand, and the call after the CPU said it
//! has AVX-512 F and BW); it gives the same codes as the portable loop (tested).

#![allow(unsafe_code)]

/// Classifies whole 32-pixel blocks of `src` into `dst` and returns how many pixels it did (the
/// caller finishes the rest); 0 when the CPU lacks AVX-512 F/BW or the table does not fit.
#[cfg(target_arch = "x86_64")]
pub(super) fn classify_uyvy_gather(src: &[u8], table: &[u8], bits: u32, dst: &mut [u8]) -> usize {
    if !(6..=8).contains(&bits)
        || table.len() != 1 << (3 * bits)
        || !std::arch::is_x86_feature_detected!("avx512f")
        || !std::arch::is_x86_feature_detected!("avx512bw")
    {
        return 0;
    }
    // SAFETY: the CPU supports AVX-512 F and BW (checked just above), the only requirement of
    // the `#[target_feature]` function; its own bounds rest on the length check.
    unsafe { classify_uyvy_avx512(src, table, bits, dst) }
}

/// Non-x86 targets always take the portable loop.
#[cfg(not(target_arch = "x86_64"))]
pub(super) fn classify_uyvy_gather(_: &[u8], _: &[u8], _: u32, _: &mut [u8]) -> usize {
    0
}

/// The kernel. `table.len()` must be `1 << (3 * bits)` with `bits` in 6..=8: every cell index
/// built from 8-bit Y, U, V is then below the length, and so is its word's start.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx512bw")]
fn classify_uyvy_avx512(src: &[u8], table: &[u8], bits: u32, dst: &mut [u8]) -> usize {
    use std::arch::x86_64::{
        __m256i, __m512i, _mm256_storeu_si256, _mm512_and_si512, _mm512_cvtepi32_epi16,
        _mm512_i32gather_epi32, _mm512_loadu_si512, _mm512_or_si512, _mm512_set1_epi32,
        _mm512_sllv_epi32, _mm512_srlv_epi32,
    };

    let b = bits.cast_signed();
    let shift = 8 - b;
    let count = |n: i32| _mm512_set1_epi32(n);
    let mask = count((1 << b) - 1);
    let (low_byte, word_start, byte_in_word) = (count(0xff), count(!3), count(3));
    let (to_u, to_y, times_8, by_a_byte) = (count(b), count(2 * b), count(3), count(8));

    // One table cell, gathered as its aligned word and shifted down to the low byte.
    let lookup = |index: __m512i| -> __m512i {
        let words = _mm512_and_si512(index, word_start);
        // SAFETY: every index is below `table.len()` (a multiple of 4), so each aligned word
        // lies wholly inside the table; gathers need no alignment.
        let got = unsafe { _mm512_i32gather_epi32::<1>(words, table.as_ptr().cast::<i32>()) };
        let bit_offset = _mm512_sllv_epi32(_mm512_and_si512(index, byte_in_word), times_8);
        _mm512_and_si512(_mm512_srlv_epi32(got, bit_offset), low_byte)
    };

    let (blocks, _) = src.as_chunks::<64>();
    let (outs, _) = dst.as_chunks_mut::<32>();
    let mut done = 0;
    for (block, out) in blocks.iter().zip(outs) {
        // SAFETY: `block` is 64 bytes; the load is unaligned.
        let q = unsafe { _mm512_loadu_si512(block.as_ptr().cast()) };
        // Each 32-bit lane is one pair U Y0 V Y1 (little-endian).
        let field = |at: i32| _mm512_and_si512(_mm512_srlv_epi32(q, count(at)), mask);
        let uv = _mm512_or_si512(_mm512_sllv_epi32(field(shift), to_u), field(16 + shift));
        let first = lookup(_mm512_or_si512(
            _mm512_sllv_epi32(field(8 + shift), to_y),
            uv,
        ));
        let second = lookup(_mm512_or_si512(
            _mm512_sllv_epi32(field(24 + shift), to_y),
            uv,
        ));
        // Lane k holds pixel 2k in its low byte and pixel 2k + 1 in the next; narrow to words.
        let pairs = _mm512_or_si512(first, _mm512_sllv_epi32(second, by_a_byte));
        // SAFETY: `out` is 32 bytes; the store is unaligned.
        unsafe {
            _mm256_storeu_si256(
                out.as_mut_ptr().cast::<__m256i>(),
                _mm512_cvtepi32_epi16(pairs),
            );
        };
        done += 32;
    }
    done
}
