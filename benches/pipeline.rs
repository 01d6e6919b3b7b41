//! Criterion benchmarks of the hot path: classification and blob formation, per frame size
//! (208×160 robot camera, 640×480 overhead), table resolution (6, 7, 8 bits) and connectivity.
//!
//! Frames are a port of `../shared/bench/peer_pipeline.py`'s sample scene (field, lines, goals,
//! beacon, shaded ball, vignetting, noise) and the table is built from the same colour
//! prototypes, so the figures compare with the peer's and `floors.c`'s on like data.

use std::hint::black_box;

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use eotn::blobs::{BlobSet, Connectivity};
use eotn::classify::{ClassifiedImage, classify_into};
use eotn::frame::{Frame, rgb_to_yuv};
use eotn::lut::{ColourClass, LookupTable};

/// Scene colours (RGB) and their spread (σ in Y, U, V), as the peer's `PROTOS`.
const PROTOS: [(ColourClass, [u8; 3], [f64; 3]); 6] = [
    (ColourClass::Orange, [250, 110, 20], [70.0, 16.0, 16.0]),
    (ColourClass::SkyBlue, [40, 110, 200], [55.0, 14.0, 14.0]),
    (ColourClass::Yellow, [230, 205, 40], [55.0, 14.0, 14.0]),
    (ColourClass::Pink, [245, 100, 170], [55.0, 14.0, 14.0]),
    (ColourClass::Green, [45, 140, 60], [45.0, 12.0, 12.0]),
    (ColourClass::White, [235, 235, 230], [45.0, 12.0, 12.0]),
];

fn table(bits: u8) -> LookupTable {
    let mut t = LookupTable::new(bits).expect("6..=8 bits");
    let n = t.side();
    let step = f64::from(1u32 << (8 - bits));
    let centre = |i: usize| i as f64 * step + (step - 1.0) / 2.0;
    let protos: Vec<_> = PROTOS
        .iter()
        .map(|(c, rgb, s)| {
            let p = rgb_to_yuv(*rgb);
            (*c, [f64::from(p.y), f64::from(p.u), f64::from(p.v)], *s)
        })
        .collect();
    for y in 0..n {
        for u in 0..n {
            for v in 0..n {
                let q = [centre(y), centre(u), centre(v)];
                let best = protos
                    .iter()
                    .map(|(c, p, s)| {
                        (
                            *c,
                            (0..3).map(|k| ((q[k] - p[k]) / s[k]).powi(2)).sum::<f64>(),
                        )
                    })
                    .filter(|(_, d)| *d < 1.0)
                    .min_by(|a, b| a.1.total_cmp(&b.1));
                if let Some((c, _)) = best {
                    let i = t.index_of_cell([y, u, v]);
                    t.set(i, c);
                }
            }
        }
    }
    t
}

fn scene(w: usize, h: usize) -> Frame {
    let (wf, hf) = (w as f64, h as f64);
    let mut seed = 0x9e37_79b9_7f4a_7c15u64;
    let mut noise = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed % 1000) as f64 / 1000.0 - 0.5
    };
    let rgb_at = |x: f64, y: f64| -> [f64; 3] {
        let horizon = 0.32 * hf + 0.04 * hf * (x / wf * 2.0).sin();
        let mut c = if y < 0.12 * hf {
            [70.0, 70.0, 80.0]
        } else {
            [125.0, 112.0, 100.0]
        };
        if y >= horizon {
            c = [45.0, 140.0, 60.0];
            let lw = (hf / 70.0).max(2.0);
            let line = (y - (0.62 * hf + 0.1 * (x - wf / 2.0))).abs() < lw
                || (x - 0.2 * wf - 0.15 * (y - hf)).abs() < lw
                || ((x - 0.5 * wf).hypot((y - 0.95 * hf) * 2.2) - 0.33 * wf).abs() < lw * 1.2;
            if line {
                c = [235.0, 235.0, 230.0];
            }
        }
        if (0.16 * hf..0.36 * hf).contains(&y) {
            if (0.03 * wf..0.25 * wf).contains(&x) {
                c = [230.0, 205.0, 40.0];
            } else if (0.74 * wf..0.95 * wf).contains(&x) {
                c = [40.0, 110.0, 200.0];
            }
        }
        if (0.46 * wf..0.52 * wf).contains(&x) {
            if (0.08 * hf..0.17 * hf).contains(&y) {
                c = [245.0, 100.0, 170.0];
            } else if (0.17 * hf..0.26 * hf).contains(&y) {
                c = [230.0, 205.0, 40.0];
            }
        }
        let (cx, cy, r) = (0.55 * wf, 0.72 * hf, 0.065 * wf);
        if (x - cx).hypot(y - cy) < r {
            let shade = 1.05 - 0.25 * ((y - cy) / r + 1.0) / 2.0;
            c = [250.0 * shade, 110.0 * shade, 20.0 * shade];
        }
        let vig = 1.0
            - 0.35
                * (((x - wf / 2.0) / (wf / 2.0)).powi(2) + ((y - hf / 2.0) / (hf / 2.0)).powi(2))
                / 2.0;
        c.map(|v| v * vig)
    };
    Frame::uyvy_from_fn(w, h, |x, y| {
        let c = rgb_at(x as f64, y as f64).map(|v| eotn::frame::round_u8(v + 6.0 * noise()));
        rgb_to_yuv(c)
    })
    .expect("even width")
}

fn benches(c: &mut Criterion) {
    let tables: Vec<_> = [6u8, 7, 8].into_iter().map(|b| (b, table(b))).collect();
    for (w, h) in [(208, 160), (640, 480)] {
        let frame = scene(w, h);
        let mut group = c.benchmark_group(format!("{w}x{h}"));
        group.throughput(Throughput::Elements((w * h) as u64));
        let mut img = ClassifiedImage::default();
        for (bits, t) in &tables {
            group.bench_function(BenchmarkId::new("classify", format!("b{bits}")), |b| {
                b.iter(|| classify_into(black_box(&frame), t, &mut img));
            });
        }
        classify_into(&frame, &tables[1].1, &mut img);
        let mut set = BlobSet::default();
        for conn in [Connectivity::Eight, Connectivity::Four] {
            group.bench_function(
                BenchmarkId::new("blobs", format!("conn{}", conn.neighbours())),
                |b| {
                    b.iter(|| set.find(black_box(&img), conn));
                },
            );
        }
        for (bits, t) in &tables {
            group.bench_function(
                BenchmarkId::new("classify+blobs", format!("b{bits}_conn8")),
                |b| {
                    b.iter(|| {
                        classify_into(black_box(&frame), t, &mut img);
                        set.find(&img, Connectivity::Eight);
                    });
                },
            );
        }
        group.finish();
    }
}

/// Every kernel set this CPU can run against the portable safe-Rust loops, on the same frame
/// and table (the issue allows `std::arch` only where a benchmark shows the gain).
fn kernels(c: &mut Criterion) {
    use eotn::classify::classify_uyvy_with;
    use eotn::kernels::{cpu, runnable};
    let t = table(7);
    for (w, h) in [(208, 160), (640, 480)] {
        let frame = scene(w, h);
        let mut group = c.benchmark_group(format!("kernels_{w}x{h}"));
        group.throughput(Throughput::Elements((w * h) as u64));
        let mut codes = vec![0u8; w * h];
        let img = ClassifiedImage::from_frame(&frame, &t);
        for set in runnable(cpu()) {
            group.bench_function(format!("classify_b7/{set}"), |b| {
                b.iter(|| classify_uyvy_with(set, black_box(frame.data()), &t, &mut codes));
            });
            let mut blobs = BlobSet::default();
            blobs.set_kernels(set);
            group.bench_function(format!("blobs_conn8/{set}"), |b| {
                b.iter(|| blobs.find(black_box(&img), Connectivity::Eight));
            });
        }
        group.finish();
    }
}

/// The whole recognition step (ball, goals, beacons, pattern signatures) on the classified
/// 208×160 scene, with joint readings so every test runs. Target: under 100 µs median. Then the
/// same with a coloured-pattern marker and six learnt places, and the patterns' own part.
fn recognition(c: &mut Criterion) {
    use eotn::recognition::{RecognitionParams, recognise};
    use eotn::sensors::SensorReadings;
    let frame = scene(208, 160);
    let t = table(7);
    let mut img = ClassifiedImage::default();
    classify_into(&frame, &t, &mut img);
    let blobs = BlobSet::from_image(&img, Connectivity::Eight);
    let params = RecognitionParams::default();
    let readings = SensorReadings {
        head_pan_rad: Some(0.1),
        head_tilt_rad: Some(-0.2),
        neck_tilt_rad: Some(0.0),
        previous_head_pan_rad: Some(0.05),
        ..SensorReadings::default()
    };
    let ctx = params.context_for(208, 160, Some(&readings));
    let mut group = c.benchmark_group("recognition_208x160");
    group.bench_function("recognise", |b| {
        b.iter(|| recognise(black_box(&img), &blobs, &ctx, &params, None));
    });
    // The same frame with a coloured-pattern marker (3 × 3 tiles of 9 px, pink in the middle)
    // in the sky, identified against six learnt places.
    let mut marked = img.clone();
    let tiles = [
        ColourClass::White,
        ColourClass::Green,
        ColourClass::White,
        ColourClass::SkyBlue,
        ColourClass::Pink,
        ColourClass::Yellow,
        ColourClass::Green,
        ColourClass::White,
        ColourClass::Green,
    ];
    for (k, t) in tiles.iter().enumerate() {
        for y in 0..9 {
            for x in 0..9 {
                let (px, py) = (150 + 9 * (k % 3) + x, 2 + 9 * (k / 3) + y);
                marked.codes_mut()[py * 208 + px] = t.code();
            }
        }
    }
    let marked_blobs = BlobSet::from_image(&marked, Connectivity::Eight);
    let seen =
        eotn::recognition::patterns::observe(&marked, &marked_blobs, &ctx, &params.patterns, &[]);
    let memory = eotn::recognition::patterns::PatternMemory {
        objects: (0..6)
            .map(|id| eotn::recognition::patterns::PatternObject {
                id,
                field_cm: [0.0, 0.0],
                height_cm: None,
                // Place 0 is the marker; the others differ from it in two regions.
                patterns: seen
                    .iter()
                    .map(|o| {
                        let mut sig = o.signature;
                        if id > 0 {
                            sig.0[id - 1] = [ColourClass::Orange.code(), 0];
                            sig.0[id + 2] = [ColourClass::Orange.code(), 0];
                        }
                        sig
                    })
                    .collect(),
                views: 10,
                placed_by: eotn::recognition::patterns::Placement::Triangulation,
                residual_cm: 0.0,
            })
            .collect(),
        ..Default::default()
    };
    group.bench_function("recognise_marker_6_places", |b| {
        b.iter(|| {
            recognise(
                black_box(&marked),
                &marked_blobs,
                &ctx,
                &params,
                Some(&memory),
            )
        });
    });
    // The coloured patterns' own share of that: the signature alone, then with identification.
    group.bench_function("patterns_observe_marker", |b| {
        b.iter(|| {
            eotn::recognition::patterns::observe(
                black_box(&marked),
                &marked_blobs,
                &ctx,
                &params.patterns,
                &[],
            )
        });
    });
    group.bench_function("patterns_marker_6_places", |b| {
        b.iter(|| {
            eotn::recognition::patterns::observe(
                black_box(&marked),
                &marked_blobs,
                &ctx,
                &params.patterns,
                &[],
            )
            .into_iter()
            .map(|o| {
                eotn::recognition::patterns::PatternMemory::candidate(
                    Some(&memory),
                    o,
                    &ctx,
                    &params.patterns,
                )
            })
            .collect::<Vec<_>>()
        });
    });
    group.finish();
}

criterion_group!(pipeline, benches, kernels, recognition);
criterion_main!(pipeline);
