//! Criterion benchmarks of stream access: opening a stream (summary + message indexes) and
//! reading a random frame (one chunk read and decompressed), on a 300-frame 640×480 stream of
//! noisy synthetic frames with sensor readings, chunks chosen by the writer (2 frames each);
//! and opening the same frames written unchunked by the `mcap` crate (no summary indexes: the
//! data section is walked record by record).

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use eotn::frame::{Frame, Yuv};
use eotn::sensors::SensorReadings;
use eotn::streams::{FrameRecord, StreamInfo, StreamReader, StreamWriter};

const FRAMES: usize = 300;

fn frame(i: usize) -> Frame {
    // A gradient with a moving bright patch and hashed noise: compresses like a camera image.
    Frame::uyvy_from_fn(640, 480, |x, y| {
        let noise = ((x * 7919 + y * 104_729 + i * 31) % 13) as u8;
        let patch = (x + 4 * i) % 640 < 80 && (200..280).contains(&y);
        Yuv::new(
            if patch { 200 } else { 60 + (y / 4) as u8 } + noise,
            110 + (x / 32) as u8,
            120 + noise / 2,
        )
    })
    .expect("even width")
}

fn benches(c: &mut Criterion) {
    let dir = tempfile::tempdir().expect("temporary folder");
    let path = dir.path().join("bench.mcap");
    let mut w = StreamWriter::create(&path, &StreamInfo::default()).expect("create");
    for i in 0..FRAMES {
        let mut r = FrameRecord::new(i as u64 * 33_333_333, frame(i));
        r.sensors = Some(SensorReadings {
            head_pan_rad: Some(0.01 * i as f64),
            ..SensorReadings::default()
        });
        w.write(&r).expect("write");
    }
    w.finish().expect("finish");
    let unchunked = dir.path().join("unchunked.mcap");
    write_unchunked(&path, &unchunked);
    let check = StreamReader::open(&unchunked).expect("open");
    assert_eq!(
        (check.len(), check.warnings().len()),
        (FRAMES, 0),
        "every frame, no warning"
    );

    let mut group = c.benchmark_group("stream_640x480");
    group.sample_size(20);
    group.bench_function("open", |b| {
        b.iter(|| StreamReader::open(black_box(&path)).expect("open"));
    });
    let mut reader = StreamReader::open(&path).expect("open");
    let mut k = 0usize;
    group.bench_function("read_random_frame", |b| {
        b.iter(|| {
            // A stride coprime with the length visits frames all over the file, never the
            // cached chunk twice in a row.
            k = (k + 97) % FRAMES;
            reader.read(black_box(k)).expect("read")
        });
    });
    group.bench_function("read_sequential_frame", |b| {
        b.iter(|| {
            k = (k + 1) % FRAMES;
            reader.read(black_box(k)).expect("read")
        });
    });
    group.bench_function("open_unchunked", |b| {
        b.iter(|| StreamReader::open(black_box(&unchunked)).expect("open"));
    });
    group.finish();
}

/// Every message of `from` rewritten into `to` outside chunks, by the `mcap` crate's writer.
fn write_unchunked(from: &std::path::Path, to: &std::path::Path) {
    let bytes = std::fs::read(from).expect("read");
    let file = std::io::BufWriter::new(std::fs::File::create(to).expect("create"));
    let mut w = mcap::WriteOptions::new()
        .use_chunks(false)
        .create(file)
        .expect("writer");
    for m in mcap::MessageStream::new(&bytes).expect("stream") {
        w.write(&m.expect("message")).expect("write");
    }
    w.finish().expect("finish");
}

criterion_group!(streams, benches);
criterion_main!(streams);
