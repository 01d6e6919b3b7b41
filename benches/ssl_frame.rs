//! Criterion benchmark of one real 224×224 JPEG frame of the SSL on-board set (issue 29 item 5):
//! decoded into a frame (zune-jpeg's own YCbCr, mapped to studio range), classified with
//! `lookup_tables/ssl-onboard.lut`, blobs, and the ball recognised with `params/ssl-onboard.json`
//! (no pose, no readings) — what `eotn eval` does per frame, the file read aside. Stages apart
//! too: decode alone, and classify + blobs + recognition of the decoded frame.
//!
//! The frames are not in the repository: they are read from `../shared/data/ssl-onboard/images/`
//! beside the project (or `EOTN_SHARED`); without them the benchmark prints "SKIPPED" and
//! measures nothing. Frame 00406 (a tuning frame: a 12-px ball, a robot, the lab's wall).

use std::hint::black_box;
use std::path::{Path, PathBuf};

use criterion::{Criterion, criterion_group, criterion_main};
use eotn::frame::decode_jpeg;
use eotn::lut::LookupTable;
use eotn::pipeline::{Pipeline, PipelineParams};
use eotn::recognition::params_file;

fn repo(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(rel)
}

fn shared_frame() -> Option<Vec<u8>> {
    let shared = std::env::var_os("EOTN_SHARED").map_or_else(|| repo("../shared"), PathBuf::from);
    let path = shared.join("data/ssl-onboard/images/00406.jpg");
    match std::fs::read(&path) {
        Ok(bytes) => Some(bytes),
        Err(e) => {
            eprintln!("SKIPPED ssl_frame: {}: {e}", path.display());
            None
        }
    }
}

fn benches(c: &mut Criterion) {
    let Some(jpeg) = shared_frame() else {
        return;
    };
    let lut = LookupTable::load(&repo("lookup_tables/ssl-onboard.lut")).expect("table");
    let recognition = params_file::load(&repo("params/ssl-onboard.json")).expect("params");
    let params = PipelineParams {
        recognition,
        ..PipelineParams::default()
    };
    let mut pipeline = Pipeline::new(lut, params);
    let frame = decode_jpeg(&jpeg).expect("decode");
    assert_eq!((frame.width(), frame.height()), (224, 224));
    // The benchmark frame's ball is found (else the figure would time an empty pipeline).
    assert!(
        pipeline
            .process(&frame, None)
            .recognition
            .ball
            .ball
            .is_some()
    );
    let mut group = c.benchmark_group("ssl_frame_224x224");
    group.bench_function("decode", |b| {
        b.iter(|| black_box(decode_jpeg(black_box(&jpeg)).expect("decode")));
    });
    group.bench_function("classify_blobs_recognise", |b| {
        b.iter(|| {
            let r = pipeline.process(black_box(&frame), None);
            black_box(r.recognition.ball.ball.is_some())
        });
    });
    group.bench_function("decode_classify_blobs_recognise", |b| {
        b.iter(|| {
            let frame = decode_jpeg(black_box(&jpeg)).expect("decode");
            let r = pipeline.process(&frame, None);
            black_box(r.recognition.ball.ball.is_some())
        });
    });
    group.finish();
}

criterion_group!(ssl, benches);
criterion_main!(ssl);
