//! Cross-check: our blobs equal OpenCV's `connectedComponentsWithStats` (through
//! `../shared/bench/peer_pipeline.py`) on the same frames and tables, for 4- and 8-connectivity.

use std::ffi::OsStr;
use std::path::Path;
use std::process::Command;

use eotn::frame::{Frame, Yuv};
use eotn::lut::{ColourClass, LookupTable};

use crate::common::{eotn, python_with_opencv, shared_file};

/// A small deterministic generator (xorshift64*), so the frames are the same every run.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }
    fn below(&mut self, n: u64) -> u64 {
        self.next() % n
    }
}

/// A table where every cell gets a pseudo-random class (a quarter unclassified).
fn speckle_table(bits: u8, seed: u64) -> LookupTable {
    let mut rng = Rng(seed);
    let mut t = LookupTable::new(bits).unwrap();
    for i in 0..t.cells().len() {
        let code = if rng.below(4) == 0 {
            0
        } else {
            1 + rng.below(14) as u8
        };
        t.set(i, ColourClass::from_code(code).unwrap());
    }
    t
}

/// Rectangles of random colours with noise: blobs of many sizes, holes, touching corners.
fn blocky_frame(w: usize, h: usize, seed: u64) -> Frame {
    let mut rng = Rng(seed);
    let mut px = vec![Yuv::new(128, 128, 128); w * h];
    for _ in 0..60 {
        let (x0, y0) = (rng.below(w as u64) as usize, rng.below(h as u64) as usize);
        let (bw, bh) = (1 + rng.below(40) as usize, 1 + rng.below(30) as usize);
        let c = Yuv::new(
            rng.below(256) as u8,
            rng.below(256) as u8,
            rng.below(256) as u8,
        );
        for y in y0..(y0 + bh).min(h) {
            for x in x0..(x0 + bw).min(w) {
                px[y * w + x] = c;
            }
        }
    }
    for p in &mut px {
        if rng.below(10) == 0 {
            p.y = p.y.wrapping_add(rng.below(9) as u8);
        }
    }
    Frame::uyvy_from_fn(w, h, |x, y| px[y * w + x]).unwrap()
}

fn write_frame(dir: &Path, name: &str, f: &Frame) {
    std::fs::write(dir.join(name), f.data()).unwrap();
}

fn peer_json(
    python: &Path,
    peer: &Path,
    frames: &Path,
    lut: &Path,
    conn: &str,
    size: (usize, usize),
) -> Vec<serde_json::Value> {
    let out = Command::new(python)
        .arg(peer)
        .arg(frames)
        .arg("--lut")
        .arg(lut)
        .args(["--json", "--connectivity", conn])
        .args([
            "--width",
            &size.0.to_string(),
            "--height",
            &size.1.to_string(),
        ])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "peer failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    parse_lines(&out.stdout)
}

fn our_json(frames: &Path, lut: &Path, conn: &str, size: (usize, usize)) -> Vec<serde_json::Value> {
    let size = format!("{}x{}", size.0, size.1);
    let out = eotn(&[
        OsStr::new("blobs"),
        frames.as_os_str(),
        OsStr::new("--lut"),
        lut.as_os_str(),
        OsStr::new("--json"),
        OsStr::new("--connectivity"),
        OsStr::new(conn),
        OsStr::new("--size"),
        OsStr::new(&size),
    ]);
    assert!(
        out.status.success(),
        "eotn blobs failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    parse_lines(&out.stdout)
}

fn parse_lines(bytes: &[u8]) -> Vec<serde_json::Value> {
    String::from_utf8_lossy(bytes)
        .lines()
        .filter(|l| !l.trim().is_empty())
        .map(|l| serde_json::from_str(l).unwrap())
        .collect()
}

fn assert_same(ours: &[serde_json::Value], peer: &[serde_json::Value], what: &str) {
    assert_eq!(ours.len(), peer.len(), "{what}: frame counts differ");
    for (a, b) in ours.iter().zip(peer) {
        let blobs = a["blobs"].as_array().map_or(0, Vec::len);
        assert!(blobs > 0, "{what}: a frame without blobs proves nothing");
        assert_eq!(a, b, "{what}: frame {} differs", a["frame"]);
    }
}

#[test]
fn blobs_equal_opencv_connected_components() {
    let Some(python) = python_with_opencv() else {
        return;
    };
    let Some(peer) = shared_file("bench/peer_pipeline.py") else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();

    // 1. The peer's own sample scenes and table.
    let status = Command::new(&python)
        .arg(&peer)
        .arg("--make-sample")
        .arg(dir.path())
        .args(["--sample-frames", "2"])
        .output()
        .unwrap();
    assert!(
        status.status.success(),
        "{}",
        String::from_utf8_lossy(&status.stderr)
    );
    let sample_lut = dir.path().join("sample_b7.lut");
    for (w, h) in [(208, 160), (640, 480)] {
        let frames = dir.path().join(format!("{w}x{h}"));
        for conn in ["8", "4"] {
            let what = format!("peer sample {w}x{h} conn {conn}");
            assert_same(
                &our_json(&frames, &sample_lut, conn, (w, h)),
                &peer_json(&python, &peer, &frames, &sample_lut, conn, (w, h)),
                &what,
            );
        }
    }

    // 2. Our own hard cases: speckle tables (thousands of tiny blobs, diagonal contacts) at
    //    every table resolution, on blocky noisy frames of both sizes.
    for (bits, seed) in [(6u8, 1u64), (7, 2), (8, 3)] {
        let lut = dir.path().join(format!("speckle_b{bits}.lut"));
        speckle_table(bits, seed).save(&lut).unwrap();
        for (w, h) in [(208, 160), (640, 480)] {
            let frames = dir.path().join(format!("ours_b{bits}_{w}x{h}"));
            std::fs::create_dir_all(&frames).unwrap();
            for i in 0..2 {
                write_frame(
                    &frames,
                    &format!("f{i}.uyvy"),
                    &blocky_frame(w, h, seed * 10 + i),
                );
            }
            for conn in ["8", "4"] {
                let what = format!("speckle b{bits} {w}x{h} conn {conn}");
                assert_same(
                    &our_json(&frames, &lut, conn, (w, h)),
                    &peer_json(&python, &peer, &frames, &lut, conn, (w, h)),
                    &what,
                );
            }
        }
    }
}
