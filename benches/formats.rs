//! Criterion benchmarks of images from other recordings into frames (issue 27):
//! - a 640×480 JPEG into a frame (`decode_jpeg`: zune-jpeg's own YCbCr, mapped to studio range)
//!   against the bare YCbCr decode of the same file in the same run (the target: ≤ 1.25×);
//! - a 640×480 ROS 2 `sensor_msgs/msg/Image` (CDR) into a frame, in `yuv422` (the pixel bytes
//!   copied once, out of the message, and become the frame's) and in `rgb8`, `nv12` and Bayer.
//!
//! The JPEG is the simulator's 640×480 overhead frame encoded by the `image` crate (quality 90).

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use eotn::formats::{ImageMessage, MessageKind, ros2};
use eotn::frame::decode_jpeg;
use eotn::sim::{Scenario, ScenarioKind, Simulator};
use zune_core::colorspace::ColorSpace;
use zune_core::options::DecoderOptions;

/// The simulator's overhead frame as packed RGB, 640×480.
fn rgb_frame() -> Vec<u8> {
    let sim = Simulator::new(Scenario::new(ScenarioKind::OverheadGame, 1));
    let f = sim.frame(3).expect("render").frame;
    assert_eq!((f.width(), f.height()), (640, 480));
    f.to_rgb()
}

fn jpeg_of(rgb: &[u8]) -> Vec<u8> {
    let img = image::RgbImage::from_raw(640, 480, rgb.to_vec()).expect("size");
    let mut out = Vec::new();
    image::codecs::jpeg::JpegEncoder::new_with_quality(&mut out, 90)
        .encode_image(&img)
        .expect("encode");
    out
}

/// The bare decode: zune-jpeg to interleaved YCbCr, nothing more.
fn bare_ycbcr(jpeg: &[u8], out: &mut [u8]) {
    let options = DecoderOptions::default().jpeg_set_out_colorspace(ColorSpace::YCbCr);
    let mut d = zune_jpeg::JpegDecoder::new_with_options(std::io::Cursor::new(jpeg), options);
    d.decode_into(out).expect("decode");
}

fn ros_image(encoding: &str, step: u32, data: Vec<u8>) -> Vec<u8> {
    ros2::encode(&ros2::Image {
        header: ros2::Header::default(),
        height: 480,
        width: 640,
        encoding: ros2::CdrString(encoding.to_owned()),
        is_bigendian: 0,
        step,
        data,
    })
    .expect("encode")
}

fn benches(c: &mut Criterion) {
    let rgb = rgb_frame();
    let jpeg = jpeg_of(&rgb);
    let mut group = c.benchmark_group("jpeg_640x480");
    group.sample_size(40);
    let mut buf = vec![0u8; 640 * 480 * 3];
    group.bench_function("bare_ycbcr_decode", |b| {
        b.iter(|| bare_ycbcr(black_box(&jpeg), &mut buf));
    });
    group.bench_function("to_frame", |b| {
        b.iter(|| decode_jpeg(black_box(&jpeg)).expect("frame"));
    });
    group.finish();

    let uyvy: Vec<u8> = (0..640 * 480 * 2).map(|i| (i % 251) as u8).collect();
    let nv12: Vec<u8> = (0..640 * 480 * 3 / 2).map(|i| (i % 241) as u8).collect();
    let bayer: Vec<u8> = rgb.iter().step_by(3).copied().collect();
    let messages = [
        ("yuv422", ros_image("yuv422", 1280, uyvy)),
        ("rgb8", ros_image("rgb8", 1920, rgb.clone())),
        ("nv12", ros_image("nv12", 640, nv12)),
        ("bayer_rggb8", ros_image("bayer_rggb8", 640, bayer)),
    ];
    let mut group = c.benchmark_group("cdr_image_640x480");
    group.sample_size(30);
    for (name, bytes) in &messages {
        group.bench_function(*name, |b| {
            b.iter(|| {
                ImageMessage::decode(MessageKind::RosImage, black_box(bytes))
                    .and_then(ImageMessage::into_frame)
                    .expect("frame")
            });
        });
    }
    group.finish();
}

criterion_group!(formats, benches);
criterion_main!(formats);
