//! Criterion benchmark of the app stepping to a new frame of an MCAP stream: read on demand
//! (never from the 8-frame cache), classify, blobs, recognition, the primitives, the RGB
//! conversion, and building the view images that become textures. The GPU upload itself needs a
//! window and a GPU and is not timed here (the app's status line shows it as `upload`).
//!
//! Streams: a 640×480 stream rendered by the simulator (overhead game: robots, ball, goals,
//! beacons) written to a temporary file at start, and the bundled 208×160 robot-camera stream
//! `streams/sim-walk-and-pan.mcap`; both classified with `lookup_tables/sim.lut`. And the 640×480
//! frames stored as JPEG (`foxglove.CompressedImage`): each step decodes a JPEG (issue 27).

use std::hint::black_box;
use std::path::{Path, PathBuf};

use criterion::{Criterion, criterion_group, criterion_main};
use eotn::app::{palette, view_images};
use eotn::formats::{ImageBody, ImageMessage};
use eotn::sim::{Scenario, ScenarioKind, Simulator};
use eotn::streams::{FrameRecord, StreamInfo, StreamWriter};
use eotn::workspace::{Command, PlaybackCommand, Workspace};

/// More frames than the app's cache holds, so every step reads and decodes.
const FRAMES: usize = 24;

fn repo(relative: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(relative)
}

fn overhead_stream(dir: &Path) -> PathBuf {
    let path = dir.join("overhead-640x480.mcap");
    let sim = Simulator::new(Scenario::new(ScenarioKind::OverheadGame, 1));
    let mut w = StreamWriter::create(&path, &StreamInfo::default()).expect("create");
    for i in 0..FRAMES {
        let f = sim.frame(i as u64).expect("render");
        assert_eq!((f.frame.width(), f.frame.height()), (640, 480));
        let mut r = FrameRecord::new(f.time_ns, f.frame);
        r.sensors = f.sensors;
        w.write(&r).expect("write");
    }
    w.finish().expect("finish");
    path
}

/// The same overhead frames stored as JPEG (`foxglove.CompressedImage`, quality 90), as a camera
/// that compresses would record them: each step decodes a JPEG.
fn jpeg_stream(dir: &Path) -> PathBuf {
    let path = dir.join("overhead-640x480-jpeg.mcap");
    let sim = Simulator::new(Scenario::new(ScenarioKind::OverheadGame, 1));
    let mut w = StreamWriter::create(&path, &StreamInfo::default()).expect("create");
    for i in 0..FRAMES {
        let f = sim.frame(i as u64).expect("render");
        let img = image::RgbImage::from_raw(640, 480, f.frame.to_rgb()).expect("size");
        let mut jpeg = Vec::new();
        image::codecs::jpeg::JpegEncoder::new_with_quality(&mut jpeg, 90)
            .encode_image(&img)
            .expect("encode");
        let message = ImageMessage {
            timestamp_ns: Some(f.time_ns),
            frame_id: "camera".to_owned(),
            body: ImageBody::Compressed {
                format: "jpeg".to_owned(),
                data: jpeg,
            },
        };
        let mut r = FrameRecord::new(f.time_ns, f.frame);
        r.sensors = f.sensors;
        w.write_with_image(&r, Some(&message)).expect("write");
    }
    w.finish().expect("finish");
    path
}

fn bench_stream(c: &mut Criterion, name: &str, stream: PathBuf) {
    let mut state = Workspace::default();
    state
        .apply(Command::Open(vec![stream, repo("lookup_tables/sim.lut")]))
        .expect("open");
    let len = state.source().expect("open").len();
    let palette = palette();
    let mut group = c.benchmark_group(name);
    group.sample_size(30);
    let mut k = 0usize;
    // Forward by 9 frames: never a cache hit (8 frames cached), like scrubbing through a stream.
    group.bench_function("step_and_view_images", |b| {
        b.iter(|| {
            k = (k + 9) % len;
            state.apply(PlaybackCommand::Seek(k).into()).expect("seek");
            black_box(view_images(&state, &palette))
        });
    });
    group.bench_function("view_images_only", |b| {
        b.iter(|| black_box(view_images(&state, &palette)));
    });
    group.finish();
}

fn app_step(c: &mut Criterion) {
    let dir = tempfile::tempdir().expect("temporary folder");
    bench_stream(c, "app_step_640x480", overhead_stream(dir.path()));
    bench_stream(c, "app_step_640x480_jpeg", jpeg_stream(dir.path()));
    bench_stream(c, "app_step_208x160", repo("streams/sim-walk-and-pan.mcap"));
}

criterion_group!(benches, app_step);
criterion_main!(benches);
