//! The run search of `super::encode_row` 64 pixels at a time with AVX-512 BW, chosen at run
//! time (`crate::kernels`).
//!
//! As `avx2.rs` with one 64-byte compare into a mask register per step. Only this file and
//! `avx2.rs` use `unsafe`: two unaligned loads whose bounds are checked by slicing first, and
//! the call into the AVX-512 function after the CPU said it has AVX-512 F and BW. It gives the
//! same runs as the portable word scan (tested).

#![allow(unsafe_code)]

#[cfg(target_arch = "x86_64")]
use super::RowRuns;
use super::Run;

/// Appends the runs of `row`; `false` (and nothing appended) when the CPU lacks AVX-512 F/BW,
/// so the caller falls back to another scan.
#[cfg(target_arch = "x86_64")]
pub(super) fn encode_row(row: &[u8], y: u16, runs: &mut Vec<Run>) -> bool {
    if !std::arch::is_x86_feature_detected!("avx512f")
        || !std::arch::is_x86_feature_detected!("avx512bw")
    {
        return false;
    }
    // SAFETY: the CPU supports AVX-512 F and BW (checked just above), the only requirement of
    // the `#[target_feature]` function.
    unsafe { encode_row_avx512(row, y, runs) };
    true
}

/// Non-x86 targets never take this scan.
#[cfg(not(target_arch = "x86_64"))]
pub(super) fn encode_row(_row: &[u8], _y: u16, _runs: &mut Vec<Run>) -> bool {
    false
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx512bw")]
fn encode_row_avx512(row: &[u8], y: u16, runs: &mut Vec<Run>) {
    use std::arch::x86_64::{_mm512_cmpneq_epi8_mask, _mm512_loadu_si512};

    let Some(&first) = row.first() else { return };
    let mut out = RowRuns::new(runs, y, first);
    // A block compares pixels x..x+64 with their left neighbours x-1..x+63, from x = 1. The
    // last block is moved back to end at the row's end; its boundaries before `x` were already
    // emitted and are masked off.
    let mut x = 1;
    while x < row.len() {
        let at = x.min(row.len().saturating_sub(64)).max(1);
        let (Some(now), Some(left)) = (row.get(at..at + 64), row.get(at - 1..at + 63)) else {
            break;
        };
        // SAFETY: both slices are 64 bytes long (`get` checked it); the loads are unaligned.
        let (a, b) = unsafe {
            (
                _mm512_loadu_si512(now.as_ptr().cast()),
                _mm512_loadu_si512(left.as_ptr().cast()),
            )
        };
        // One bit per pixel that differs from its left neighbour: a run boundary.
        let mut changed = _mm512_cmpneq_epi8_mask(a, b);
        changed &= u64::MAX.checked_shl((x - at) as u32).unwrap_or(0);
        while changed != 0 {
            let p = at + changed.trailing_zeros() as usize;
            changed &= changed - 1;
            out.boundary(p, now[p - at]);
        }
        x = at + 64;
    }
    // Rows shorter than 65 pixels.
    out.scan_tail(row, x);
    out.finish(row.len());
}
