//! Streams with several cameras: written in the layout of docs/formats.md ("Several cameras")
//! and read back one camera at a time.

use std::path::Path;

use crate::camera::CameraFiles;
use crate::frame::{Frame, Yuv};
use crate::sensors::SensorReadings;
use crate::streams::{FrameRecord, StreamError, StreamInfo, StreamReader, StreamWriter};

/// A stream of two cameras: `/camera/image` (8×4, 5 frames, 40 ms apart) and `/camera/bottom`
/// (4×2, 3 frames, 60 ms apart), each with its own sensor readings and recognition, and one
/// shared extra channel.
fn two_cameras(path: &Path) {
    let info = StreamInfo {
        source: "robot".into(),
        description: "two cameras".into(),
    };
    let mut w = StreamWriter::create(path, &info).unwrap();
    w.name_camera_files(
        "/camera/bottom",
        &CameraFiles {
            lut: Some("bottom.lut".into()),
            ..CameraFiles::default()
        },
    )
    .unwrap();
    let record = |t: u64, w: usize, h: usize, y: u8, tilt: f64| {
        let mut r = FrameRecord::new(t, Frame::filled_uyvy(w, h, Yuv::new(y, 128, 128)).unwrap());
        r.sensors = Some(SensorReadings {
            head_tilt_rad: Some(tilt),
            ..SensorReadings::default()
        });
        r.recognition = Some(serde_json::json!({ "y": y }));
        r
    };
    for i in 0..5u8 {
        let t = u64::from(i) * 40;
        let mut top = record(t, 8, 4, 10 + i, 0.1);
        top.extra
            .push(("/world_model".into(), serde_json::json!(i)));
        w.write_camera("/camera/image", &top, None).unwrap();
        if i < 3 {
            let bottom = record(u64::from(i) * 60 + 1, 4, 2, 100 + i, -0.5);
            w.write_camera("/camera/bottom", &bottom, None).unwrap();
        }
    }
    w.finish().unwrap();
}

#[test]
fn each_camera_reads_its_own_frames_and_channels() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("two.mcap");
    two_cameras(&p);
    let mut top = StreamReader::open(&p).unwrap();
    assert_eq!(top.camera(), Some("/camera/image"));
    let topics: Vec<&str> = top
        .image_topics()
        .iter()
        .map(|t| t.topic.as_str())
        .collect();
    assert_eq!(topics, ["/camera/image", "/camera/bottom"]);
    assert_eq!(top.len(), 5);
    for i in 0..5 {
        let r = top.read(i).unwrap();
        assert_eq!((r.frame.width(), r.frame.height()), (8, 4));
        assert_eq!(
            r.frame.pixel(0, 0).unwrap().y,
            10 + u8::try_from(i).unwrap()
        );
        assert_eq!(r.sensors.unwrap().head_tilt_rad, Some(0.1), "frame {i}");
        assert_eq!(r.recognition.unwrap()["y"], 10 + i);
        assert_eq!(r.extra, [("/world_model".to_owned(), serde_json::json!(i))]);
    }
    let mut bottom = StreamReader::open_camera(&p, Some("/camera/bottom")).unwrap();
    assert_eq!(bottom.camera(), Some("/camera/bottom"));
    assert_eq!(bottom.len(), 3);
    for i in 0..3 {
        let r = bottom.read(i).unwrap();
        assert_eq!(r.time_ns, i as u64 * 60 + 1);
        assert_eq!((r.frame.width(), r.frame.height()), (4, 2));
        assert_eq!(
            r.frame.pixel(0, 0).unwrap().y,
            100 + u8::try_from(i).unwrap()
        );
        assert_eq!(
            r.sensors.unwrap().head_tilt_rad,
            Some(-0.5),
            "never the top camera's"
        );
        assert_eq!(r.recognition.unwrap()["y"], 100 + i);
    }
    assert!(bottom.warnings().is_empty(), "{:?}", bottom.warnings());
    let files = bottom.camera_files().unwrap();
    assert_eq!(files.lut, Some(dir.path().join("bottom.lut")));
    assert!(
        top.camera_files().unwrap().lut.is_none(),
        "the top camera names none"
    );
}

#[test]
fn an_unknown_camera_is_an_error_listing_the_cameras() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("two.mcap");
    two_cameras(&p);
    let e = StreamReader::open_camera(&p, Some("/camera/side")).unwrap_err();
    assert!(matches!(e, StreamError::NoSuchCamera { .. }), "{e}");
    let text = e.to_string();
    assert!(
        text.contains("no camera /camera/side") && text.contains("/camera/image, /camera/bottom"),
        "{text}"
    );
}

#[test]
fn a_one_camera_stream_is_written_as_before_whichever_call_writes_it() {
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = (dir.path().join("a.mcap"), dir.path().join("b.mcap"));
    let info = StreamInfo::default();
    let mut wa = StreamWriter::create(&a, &info).unwrap();
    let mut wb = StreamWriter::create(&b, &info).unwrap();
    for i in 0..20u8 {
        let mut r = FrameRecord::new(
            u64::from(i),
            Frame::filled_uyvy(8, 4, Yuv::new(i, 1, 2)).unwrap(),
        );
        r.recognition = Some(serde_json::json!({ "i": i }));
        wa.write(&r).unwrap();
        wb.write_camera(crate::streams::IMAGE_TOPIC, &r, None)
            .unwrap();
    }
    wa.finish().unwrap();
    wb.finish().unwrap();
    assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
    let r = StreamReader::open(&a).unwrap();
    let topics: Vec<&str> = r.channels().iter().map(|c| c.topic.as_str()).collect();
    assert_eq!(topics, ["/camera/image", "/sensors", "/recognition"]);
    assert_eq!(
        r.counts().metadata,
        1,
        "no camera record unless one is named"
    );
}
