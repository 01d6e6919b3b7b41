//! The run search of [`super::encode_row`] 32 pixels at a time with AVX2, chosen at run time.
//!
//! `floors.c` showed that finding run boundaries with 256-bit compares beats the 64-bit word
//! scan by about a third on camera frames; the criterion bench `blobs_run_search` measures the
//! same here. Only this file uses `unsafe`: two unaligned loads whose bounds are checked by
//! slicing first, and the call into the AVX2 function after the CPU said it has AVX2. Every
//! other CPU (and non-x86 targets) takes the portable word scan, which gives the same
//! runs (tested).

#![allow(unsafe_code)]

#[cfg(target_arch = "x86_64")]
use super::RowRuns;
use super::Run;

/// Appends the runs of `row` with the AVX2 scan; `false` (and nothing appended) when the CPU
/// has no AVX2, so the caller falls back to the portable scan.
#[cfg(target_arch = "x86_64")]
pub(super) fn encode_row(row: &[u8], y: u16, runs: &mut Vec<Run>) -> bool {
    if !std::arch::is_x86_feature_detected!("avx2") {
        return false;
    }
    // SAFETY: the CPU supports AVX2 (checked just above), the only requirement of a
    // `#[target_feature(enable = "avx2")]` function.
    unsafe { encode_row_avx2(row, y, runs) };
    true
}

/// Non-x86 targets always take the portable scan.
#[cfg(not(target_arch = "x86_64"))]
pub(super) fn encode_row(_row: &[u8], _y: u16, _runs: &mut Vec<Run>) -> bool {
    false
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn encode_row_avx2(row: &[u8], y: u16, runs: &mut Vec<Run>) {
    use std::arch::x86_64::{__m256i, _mm256_cmpeq_epi8, _mm256_loadu_si256, _mm256_movemask_epi8};

    let Some(&first) = row.first() else { return };
    let mut out = RowRuns::new(runs, y, first);
    // A block compares pixels x..x+32 with their left neighbours x-1..x+31, from x = 1. The
    // last block is moved back to end at the row's end; its boundaries before `x` were already
    // emitted and are masked off.
    let mut x = 1;
    while x < row.len() {
        let at = x.min(row.len().saturating_sub(32)).max(1);
        let (Some(now), Some(left)) = (row.get(at..at + 32), row.get(at - 1..at + 31)) else {
            break;
        };
        // SAFETY: both slices are 32 bytes long (`get` checked it); the loads are unaligned.
        let (a, b) = unsafe {
            (
                _mm256_loadu_si256(now.as_ptr().cast::<__m256i>()),
                _mm256_loadu_si256(left.as_ptr().cast::<__m256i>()),
            )
        };
        // One bit per pixel that differs from its left neighbour: a run boundary.
        let mut changed = !(_mm256_movemask_epi8(_mm256_cmpeq_epi8(a, b)).cast_unsigned());
        changed &= u32::MAX.checked_shl((x - at) as u32).unwrap_or(0);
        while changed != 0 {
            let p = at + changed.trailing_zeros() as usize;
            changed &= changed - 1;
            out.boundary(p, now[p - at]);
        }
        x = at + 32;
    }
    // Rows shorter than 33 pixels.
    out.scan_tail(row, x);
    out.finish(row.len());
}
