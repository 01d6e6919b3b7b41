//! MCAP streams: round trips, random access, crash recovery, bad files, an independent reader,
//! and the `import`/`export` commands.

use std::ffi::OsStr;
use std::path::{Path, PathBuf};
use std::process::Command;

use eotn::frame::{Frame, Yuv};
use eotn::sensors::SensorReadings;
use eotn::streams::{
    FrameRecord, StreamError, StreamInfo, StreamReader, StreamWriter, WriterOptions,
};

use crate::common::{eotn, python_with_mcap, shared_file};

/// A small frame whose every byte depends on the frame number, so mix-ups show.
fn frame(i: usize, w: usize, h: usize) -> Frame {
    Frame::uyvy_from_fn(w, h, |x, y| {
        Yuv::new(
            ((x * 7 + y * 3 + i * 11) % 220 + 16) as u8,
            ((x + i * 5) % 200 + 20) as u8,
            ((y * 2 + i) % 200 + 30) as u8,
        )
    })
    .unwrap()
}

fn record(i: usize) -> FrameRecord {
    let mut r = FrameRecord::new(1_000_000 + i as u64 * 33_333_333, frame(i, 32, 24));
    if i % 3 != 2 {
        r.sensors = Some(SensorReadings {
            head_pan_rad: Some(0.01 * i as f64),
            ir_far_cm: Some(50.0 + i as f64),
            ..SensorReadings::default()
        });
    }
    if i.is_multiple_of(2) {
        r.ground_truth = Some(serde_json::json!({ "ball": [i, 2 * i] }));
    }
    if i % 4 == 1 {
        r.recognition = Some(serde_json::json!({ "ball": null }));
    }
    if i == 5 {
        r.extra.push((
            "/world_model/robot3".to_owned(),
            serde_json::json!({"x_cm": 12.5}),
        ));
    }
    r
}

fn write_stream(path: &Path, n: usize, frames_per_chunk: usize) -> Vec<FrameRecord> {
    let info = StreamInfo {
        source: "sim:test".into(),
        description: "unit stream".into(),
    };
    let options = WriterOptions {
        frames_per_chunk: Some(frames_per_chunk),
        ..WriterOptions::default()
    };
    let mut w = StreamWriter::create_with(path, &info, options).unwrap();
    let records: Vec<FrameRecord> = (0..n).map(record).collect();
    for r in &records {
        w.write(r).unwrap();
    }
    w.finish().unwrap();
    records
}

#[test]
fn round_trip_keeps_frames_sensors_truth_and_extras() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("s.mcap");
    let records = write_stream(&p, 10, 3);
    assert!(!dir.path().join("s.mcap.partial").exists());
    let mut r = StreamReader::open(&p).unwrap();
    assert!(r.warnings().is_empty(), "{:?}", r.warnings());
    assert_eq!(r.len(), 10);
    assert_eq!(r.chunk_count(), 4);
    assert_eq!(r.info().source, "sim:test");
    assert_eq!(r.info().description, "unit stream");
    for (i, want) in records.iter().enumerate() {
        assert_eq!(&r.read(i).unwrap(), want, "frame {i}");
    }
    assert!(matches!(
        r.read(10),
        Err(StreamError::NoSuchFrame {
            index: 10,
            len: 10,
            ..
        })
    ));
}

#[test]
fn random_access_by_index_and_time() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("s.mcap");
    let records = write_stream(&p, 40, 4);
    let mut r = StreamReader::open(&p).unwrap();
    for &i in &[39usize, 0, 17, 18, 3, 38, 21, 21, 0] {
        assert_eq!(r.read(i).unwrap(), records[i], "frame {i}");
        assert_eq!(r.time_ns(i), Some(records[i].time_ns));
    }
    assert_eq!(r.time_ns(40), None);
    assert_eq!(r.index_at_time(0), 0, "before the first frame");
    assert_eq!(r.index_at_time(records[7].time_ns), 7, "exactly at");
    assert_eq!(r.index_at_time(records[7].time_ns + 1), 7, "just after");
    assert_eq!(
        r.index_at_time(records[8].time_ns - 1),
        7,
        "just before the next"
    );
    assert_eq!(r.index_at_time(u64::MAX), 39);
}

/// Every truncation point keeps the frames of the complete chunks before it, and never panics.
#[test]
fn truncated_files_stay_readable_up_to_their_last_complete_chunk() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("s.mcap");
    let records = write_stream(&p, 12, 2);
    let bytes = std::fs::read(&p).unwrap();
    let cut_path = dir.path().join("cut.mcap");
    let mut last_len = 0;
    let step = bytes.len() / 37;
    let mut cuts: Vec<usize> = (1..37).map(|k| k * step).collect();
    cuts.extend([0, 4, 8, 9, 20, bytes.len() - 1, bytes.len() - 8]);
    cuts.sort_unstable();
    for cut in cuts {
        std::fs::write(&cut_path, &bytes[..cut]).unwrap();
        match StreamReader::open(&cut_path) {
            Err(e) => {
                assert!(cut < 8, "cut at {cut}: {e}");
                assert!(e.to_string().contains("cut.mcap"), "{e}");
            }
            Ok(mut r) => {
                assert!(
                    r.len() >= last_len,
                    "cut at {cut}: fewer frames than a shorter cut"
                );
                assert!(r.len() <= 12);
                assert!(
                    !r.warnings().is_empty(),
                    "cut at {cut}: truncation must be reported"
                );
                if !r.is_empty() {
                    assert_eq!(
                        r.info().source,
                        "sim:test",
                        "metadata sits before the chunks"
                    );
                }
                for (i, want) in records.iter().enumerate().take(r.len()) {
                    assert_eq!(&r.read(i).unwrap(), want, "cut at {cut}, frame {i}");
                }
                last_len = r.len();
            }
        }
    }
    assert_eq!(
        last_len, 12,
        "a file cut inside its summary keeps every frame"
    );
}

/// A writer that dies without `finish` leaves a `.partial` file with its flushed chunks.
#[test]
fn crashed_writer_leaves_a_readable_partial_file() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("live.mcap");
    let options = WriterOptions {
        frames_per_chunk: Some(3),
        ..WriterOptions::default()
    };
    let mut w = StreamWriter::create_with(&p, &StreamInfo::default(), options).unwrap();
    for i in 0..8 {
        w.write(&record(i)).unwrap();
    }
    // A crash: no destructor, no summary, whatever is buffered is lost.
    std::mem::forget(w);
    assert!(!p.exists(), "the final name appears only when finished");
    let mut r = StreamReader::open(&dir.path().join("live.mcap.partial")).unwrap();
    assert_eq!(r.len(), 6, "two complete chunks of three frames");
    assert!(
        r.warnings().iter().any(|w| w.contains("recovered")),
        "{:?}",
        r.warnings()
    );
    assert_eq!(r.read(5).unwrap(), record(5));
}

#[test]
fn garbage_and_empty_files_are_clear_errors() {
    let dir = tempfile::tempdir().unwrap();
    let cases: [(&str, Vec<u8>); 4] = [
        ("empty.mcap", vec![]),
        ("short.mcap", vec![0x89, b'M']),
        (
            "garbage.mcap",
            (0..10_000u32).map(|i| (i * 7919 % 251) as u8).collect(),
        ),
        ("text.mcap", b"this is not a stream at all".to_vec()),
    ];
    for (name, bytes) in cases {
        let p = dir.path().join(name);
        std::fs::write(&p, bytes).unwrap();
        let e = StreamReader::open(&p).unwrap_err().to_string();
        assert!(e.contains(name) && e.contains("not an MCAP"), "{e}");
    }
    let e = StreamReader::open(&dir.path().join("missing.mcap"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("missing.mcap"), "{e}");
}

#[test]
fn magic_followed_by_garbage_opens_empty_with_warnings() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("g.mcap");
    let mut bytes = b"\x89MCAP0\r\n".to_vec();
    bytes.extend((0..5000u32).map(|i| (i * 31 % 256) as u8));
    std::fs::write(&p, bytes).unwrap();
    let r = StreamReader::open(&p).unwrap();
    assert_eq!(r.len(), 0);
    assert!(!r.warnings().is_empty());
}

#[test]
fn damaged_chunk_fails_only_its_frames() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("s.mcap");
    let records = write_stream(&p, 6, 2);
    let mut bytes = std::fs::read(&p).unwrap();
    // Flip bytes inside the second chunk's compressed data (its middle, found through the
    // summary's chunk index, so the damage lands there whatever the schemas' sizes).
    let summary = mcap::Summary::read(&bytes).unwrap().unwrap();
    let chunk = &summary.chunk_indexes[1];
    let mid = usize::try_from(chunk.chunk_start_offset + chunk.chunk_length / 2).unwrap();
    for b in &mut bytes[mid..mid + 16] {
        *b ^= 0x5a;
    }
    std::fs::write(&p, &bytes).unwrap();
    let mut r = StreamReader::open(&p).unwrap();
    let results: Vec<_> = (0..r.len()).map(|i| r.read(i)).collect();
    let failed: Vec<String> = results
        .iter()
        .filter_map(|x| x.as_ref().err().map(ToString::to_string))
        .collect();
    assert!(!failed.is_empty(), "the damage must be noticed");
    assert!(failed.iter().all(|e| e.contains("s.mcap")), "{failed:?}");
    assert_eq!(
        results[0].as_ref().unwrap(),
        &records[0],
        "other chunks still read"
    );
}

/// Foreign MCAP files (ROS 1 `/tf`, unfinished chunks) open with zero frames or fail cleanly:
/// never a panic or a hang.
#[test]
fn foreign_mcap_files_give_zero_frames_or_a_clear_error() {
    for name in [
        "compressed.mcap",
        "uncompressed.mcap",
        "zstd_chunk_with_padding.mcap",
        "chunk_not_closed.mcap",
    ] {
        let Some(p) = shared_file(&format!("data/mcap/{name}")) else {
            return;
        };
        match StreamReader::open(&p) {
            Ok(r) => {
                assert_eq!(r.len(), 0, "{name}");
                assert!(
                    r.notes().iter().any(|w| w.contains("no camera frames")),
                    "{name}: {:?}",
                    r.notes()
                );
            }
            Err(e) => assert!(e.to_string().contains(name), "{e}"),
        }
    }
}

/// Sensor values that are not finite — here Python-style `NaN` written by another tool — are
/// read as missing, with a warning.
#[test]
fn nan_sensor_values_are_sanitised_with_a_warning() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("nan.mcap");
    {
        let file = std::io::BufWriter::new(std::fs::File::create(&p).unwrap());
        let mut w = mcap::Writer::new(file).unwrap();
        let schema = foxglove_raw_image_schema();
        let sid = w.add_schema(&schema.0, "protobuf", &schema.1).unwrap();
        let img = w
            .add_channel(sid, "/camera/image", "protobuf", &Default::default())
            .unwrap();
        let sen = w
            .add_channel(0, "/sensors", "json", &Default::default())
            .unwrap();
        let mut buf = Vec::new();
        eotn::streams::schema::encode_image(
            5,
            &frame(0, 8, 4),
            eotn::streams::schema::ImageEncoding::Yuyv,
            &mut buf,
        )
        .unwrap();
        let header = |channel_id| mcap::records::MessageHeader {
            channel_id,
            sequence: 0,
            log_time: 5,
            publish_time: 5,
        };
        w.write_to_known_channel(&header(img), &buf).unwrap();
        w.write_to_known_channel(
            &header(sen),
            br#"{"head_pan_rad": NaN, "head_tilt_rad": 0.25}"#,
        )
        .unwrap();
        w.finish().unwrap();
    }
    let mut r = StreamReader::open(&p).unwrap();
    assert_eq!(r.len(), 1);
    let rec = r.read(0).unwrap();
    let s = rec.sensors.unwrap();
    assert_eq!(s.head_pan_rad, None);
    assert_eq!(s.head_tilt_rad, Some(0.25));
    assert!(
        r.warnings().iter().any(|w| w.contains("NaN")),
        "{:?}",
        r.warnings()
    );
}

fn foxglove_raw_image_schema() -> (String, Vec<u8>) {
    let s = eotn::streams::schema::raw_image_schema().unwrap();
    (s.name, s.data.into_owned())
}

/// Python's `mcap` + `mcap_protobuf` (an independent implementation) decode our images to the
/// same bytes and our JSON channels to the same values.
#[test]
fn python_reader_decodes_the_same_images() {
    let Some(python) = python_with_mcap() else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("s.mcap");
    let records = write_stream(&p, 7, 3);
    let script = r#"
import hashlib, json, sys
from mcap.reader import make_reader
from mcap_protobuf.decoder import DecoderFactory
with open(sys.argv[1], "rb") as f:
    reader = make_reader(f, validate_crcs=True, decoder_factories=[DecoderFactory()])
    meta = [m for m in reader.iter_metadata()]
    print(json.dumps({"metadata": {m.name: dict(m.metadata) for m in meta}}))
    for schema, channel, message, img in reader.iter_decoded_messages(topics=["/camera/image"]):
        print(json.dumps({"t": message.log_time, "schema": schema.name, "w": img.width,
                          "h": img.height, "enc": img.encoding, "step": img.step,
                          "sha": hashlib.sha256(img.data).hexdigest()}))
    for schema, channel, message in reader.iter_messages(topics=["/sensors"]):
        print(json.dumps({"t": message.log_time, "schema": schema.name,
                          "sensors": json.loads(message.data)}))
"#;
    let out = Command::new(python)
        .args([OsStr::new("-c"), OsStr::new(script), p.as_os_str()])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let lines: Vec<serde_json::Value> = String::from_utf8_lossy(&out.stdout)
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(lines[0]["metadata"]["eotn.stream"]["source"], "sim:test");
    let images: Vec<_> = lines.iter().filter(|l| l.get("sha").is_some()).collect();
    assert_eq!(images.len(), records.len());
    for (img, rec) in images.iter().zip(&records) {
        assert_eq!(img["t"].as_u64(), Some(rec.time_ns));
        assert_eq!(img["schema"], "foxglove.RawImage");
        // Stored as yuyv (Y0 U Y1 V): the frame's UYVY bytes with each pair swapped.
        assert_eq!(img["enc"], "yuyv");
        assert_eq!(img["w"].as_u64(), Some(32));
        assert_eq!(img["step"].as_u64(), Some(64));
        let mut yuyv = rec.frame.data().to_vec();
        for q in yuyv.chunks_exact_mut(4) {
            q.swap(0, 1);
            q.swap(2, 3);
        }
        assert_eq!(img["sha"].as_str().unwrap(), sha256_hex(&yuyv));
    }
    let sensors: Vec<_> = lines
        .iter()
        .filter(|l| l.get("sensors").is_some())
        .collect();
    let ours: Vec<_> = records.iter().filter(|r| r.sensors.is_some()).collect();
    assert_eq!(sensors.len(), ours.len());
    for (s, rec) in sensors.iter().zip(ours) {
        assert_eq!(s["t"].as_u64(), Some(rec.time_ns));
        assert_eq!(s["schema"], "eotn.SensorReadings");
        let back: SensorReadings = serde_json::from_value(s["sensors"].clone()).unwrap();
        assert_eq!(Some(back), rec.sensors);
    }
}

/// SHA-256 via `sha256sum`, so the test needs no extra crate.
fn sha256_hex(bytes: &[u8]) -> String {
    use std::io::Write;
    let mut child = Command::new("sha256sum")
        .stdin(std::process::Stdio::piped())
        .stdout(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    child.stdin.take().unwrap().write_all(bytes).unwrap();
    let out = child.wait_with_output().unwrap();
    String::from_utf8_lossy(&out.stdout)
        .split_whitespace()
        .next()
        .unwrap()
        .to_owned()
}

fn write_frames(dir: &Path, n: usize) -> PathBuf {
    let frames = dir.join("frames");
    std::fs::create_dir_all(&frames).unwrap();
    for i in 0..n {
        std::fs::write(
            frames.join(format!("f{i:02}.uyvy")),
            frame(i, 208, 160).data(),
        )
        .unwrap();
    }
    frames
}

fn run_ok(args: &[&OsStr]) -> std::process::Output {
    let out = eotn(args);
    assert!(
        out.status.success(),
        "{:?}: {}",
        args,
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

#[test]
fn import_then_info_blobs_and_export() {
    let dir = tempfile::tempdir().unwrap();
    let frames = write_frames(dir.path(), 5);
    let csv = dir.path().join("sensors.csv");
    std::fs::write(
        &csv,
        "frame,time_s,head_pan_rad,battery_percent\n0,0.0,0.1,90\n1,0.04,0.2,90\n3,0.12,nan,89\n",
    )
    .unwrap();
    let out_mcap = dir.path().join("s.mcap");
    run_ok(&[
        OsStr::new("import"),
        frames.as_os_str(),
        OsStr::new("--sensors"),
        csv.as_os_str(),
        OsStr::new("--fps"),
        OsStr::new("25"),
        OsStr::new("-o"),
        out_mcap.as_os_str(),
    ]);
    let mut r = StreamReader::open(&out_mcap).unwrap();
    assert_eq!(r.len(), 5);
    assert_eq!(r.info().source, "import");
    let f1 = r.read(1).unwrap();
    assert_eq!(f1.time_ns, 40_000_000);
    assert_eq!(f1.frame, frame(1, 208, 160));
    let s1 = f1.sensors.unwrap();
    assert_eq!(s1.head_pan_rad, Some(0.2));
    assert_eq!(s1.previous_head_pan_rad, Some(0.1), "derived from frame 0");
    assert!((s1.pan_velocity_rad_per_s().unwrap() - 2.5).abs() < 1e-9);
    let f2 = r.read(2).unwrap();
    assert_eq!(f2.sensors, None, "no row for frame 2");
    assert_eq!(f2.time_ns, 80_000_000, "2 / 25 fps");
    assert_eq!(r.read(3).unwrap().sensors.unwrap().head_pan_rad, None);

    let info = run_ok(&[
        OsStr::new("info"),
        out_mcap.as_os_str(),
        OsStr::new("--json"),
    ]);
    let v: serde_json::Value = serde_json::from_slice(&info.stdout).unwrap();
    assert_eq!(v["kind"], "stream");
    assert_eq!(v["frames"], 5);
    assert_eq!(
        (v["width"].as_u64(), v["height"].as_u64()),
        (Some(208), Some(160))
    );

    let lut = dir.path().join("t.lut");
    let mut table = eotn::lut::LookupTable::new(6).unwrap();
    for i in 0..table.cells().len() / 2 {
        table.set(i, eotn::lut::ColourClass::Green);
    }
    table.save(&lut).unwrap();
    let blobs = run_ok(&[
        OsStr::new("blobs"),
        out_mcap.as_os_str(),
        OsStr::new("--lut"),
        lut.as_os_str(),
        OsStr::new("--json"),
    ]);
    let lines: Vec<serde_json::Value> = String::from_utf8_lossy(&blobs.stdout)
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(lines.len(), 5);
    assert_eq!(lines[3]["frame"], "s_000003");
    // The stream's frame 3 and the file it came from give the same blobs.
    let file_blobs = run_ok(&[
        OsStr::new("blobs"),
        frames.join("f03.uyvy").as_os_str(),
        OsStr::new("--lut"),
        lut.as_os_str(),
        OsStr::new("--json"),
    ]);
    let file_line: serde_json::Value = serde_json::from_slice(&file_blobs.stdout).unwrap();
    assert_eq!(lines[3]["blobs"], file_line["blobs"]);

    let out_dir = dir.path().join("png");
    for view in ["raw", "classified", "blobs"] {
        run_ok(&[
            OsStr::new("export"),
            out_mcap.as_os_str(),
            OsStr::new("--lut"),
            lut.as_os_str(),
            OsStr::new("--view"),
            OsStr::new(view),
            OsStr::new("--frames"),
            OsStr::new("1..3"),
            OsStr::new("-o"),
            out_dir.as_os_str(),
        ]);
    }
    let mut names: Vec<String> = std::fs::read_dir(&out_dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(
        names,
        [
            "s_000001.blobs.png",
            "s_000001.classified.png",
            "s_000001.raw.png",
            "s_000002.blobs.png",
            "s_000002.classified.png",
            "s_000002.raw.png"
        ]
    );
    let raw = eotn::frame::load_frame(&out_dir.join("s_000001.raw.png"), None).unwrap();
    assert_eq!((raw.width(), raw.height()), (208, 160));
}

#[test]
fn stream_command_errors_are_one_line_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let frames = write_frames(dir.path(), 2);
    let bad_csv = dir.path().join("bad.csv");
    std::fs::write(&bad_csv, "head_pan,battery_percent\n0.1,90\n").unwrap();
    let garbage = dir.path().join("garbage.mcap");
    std::fs::write(&garbage, b"not a stream").unwrap();
    let out_mcap = dir.path().join("o.mcap");
    let out_dir = dir.path().join("png");
    let cases: Vec<(Vec<&OsStr>, &str)> = vec![
        (
            vec![
                OsStr::new("import"),
                frames.as_os_str(),
                OsStr::new("--sensors"),
                bad_csv.as_os_str(),
                OsStr::new("-o"),
                out_mcap.as_os_str(),
            ],
            "bad.csv",
        ),
        (
            vec![
                OsStr::new("export"),
                garbage.as_os_str(),
                OsStr::new("-o"),
                out_dir.as_os_str(),
            ],
            "garbage.mcap",
        ),
        (
            vec![OsStr::new("info"), garbage.as_os_str()],
            "garbage.mcap",
        ),
    ];
    for (args, name) in cases {
        let out = eotn(&args);
        assert!(!out.status.success(), "{args:?}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(err.trim_end().lines().count(), 1, "one line: {err}");
        assert!(err.contains(name), "{err}");
        assert!(!err.contains("panicked"), "{err}");
    }
    assert!(!out_mcap.exists());
}
