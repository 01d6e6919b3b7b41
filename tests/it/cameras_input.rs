//! Several cameras, what a recording names and what goes wrong (issue 28 items 3 and 5): a
//! camera's recognition parameters named by the recording (its sidecar) are used when no
//! `--params` is given; cameras at different frame rates, one ending early and one changing its
//! frame size are each said in `info`'s warnings, and `detect` says where a size changes;
//! `import` keeps each camera's named files, `eval` and `lut-from-labels` read the camera's
//! table and frames.

use std::ffi::OsStr;
use std::path::{Path, PathBuf};

use eotn::frame::{Frame, Yuv};
use eotn::lut::LookupTable;
use eotn::streams::{FrameRecord, StreamInfo, StreamWriter};

use crate::common::{eotn, eotn_ok};

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// `eotn detect --json ARGS`, each line without its timings.
fn detect(args: &[&OsStr]) -> Vec<serde_json::Value> {
    let mut all = vec![OsStr::new("detect"), OsStr::new("--json")];
    all.extend_from_slice(args);
    String::from_utf8_lossy(&eotn_ok(&all).stdout)
        .lines()
        .map(|l| {
            let mut v: serde_json::Value = serde_json::from_str(l).unwrap();
            v.as_object_mut()
                .unwrap()
                .retain(|k, _| !k.ends_with("_us"));
            v
        })
        .collect()
}

#[test]
fn a_camera_s_named_parameters_apply_when_no_params_are_given() {
    let dir = tempfile::tempdir().unwrap();
    let rec = dir.path().join("game.mcap");
    std::fs::copy(root().join("streams/bhuman2009.mcap"), &rec).unwrap();
    let lut = root().join("lookup_tables/bhuman2009.lut");
    // A wider field of view than the Nao's moves every distance.
    let wide = dir.path().join("wide.json");
    std::fs::write(&wide, r#"{"other_camera_fov_deg": 90}"#).unwrap();
    let plain = dir.path().join("plain.json");
    std::fs::write(&plain, "{}").unwrap();
    let sidecar = eotn::camera::sidecar_path(&rec);
    let name = |params: &str| {
        let v = serde_json::json!({"cameras": {"/camera/image": {"lut": lut, "params": params}}});
        std::fs::write(&sidecar, v.to_string()).unwrap();
    };
    name("wide.json");
    let named = detect(&[rec.as_os_str()]);
    let explicit = detect(&[rec.as_os_str(), OsStr::new("--params"), wide.as_os_str()]);
    let default = detect(&[rec.as_os_str(), OsStr::new("--params"), plain.as_os_str()]);
    assert_eq!(named.len(), 160);
    assert_eq!(named, explicit, "the camera's named parameters");
    assert_ne!(named, default, "the parameters make a difference here");
    // A set's name: params/NAME.json beside the recording, as the app finds it.
    std::fs::create_dir(dir.path().join("params")).unwrap();
    std::fs::copy(&wide, dir.path().join("params/wide.json")).unwrap();
    name("wide");
    assert_eq!(detect(&[rec.as_os_str()]), explicit);
    // An explicit --params wins over the named set.
    assert_eq!(
        detect(&[rec.as_os_str(), OsStr::new("--params"), plain.as_os_str()]),
        default
    );
    name("nowhere");
    let out = eotn(&[OsStr::new("detect"), rec.as_os_str()]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && err.contains("params/nowhere.json"),
        "{err}"
    );
}

/// `uneven.mcap`: `/camera/image` 8×4 at 25 fps for 2.36 s (60 frames) and `/camera/bottom` at
/// 12.5 fps ending after 0.72 s (10 frames), 8×4 for its first five frames and 16×8 after;
/// `blank.lut` beside it.
fn uneven(dir: &Path) -> (PathBuf, PathBuf) {
    let p = dir.join("uneven.mcap");
    let mut w = StreamWriter::create(&p, &StreamInfo::default()).unwrap();
    let grey = Yuv::new(90, 128, 128);
    let ms = 1_000_000;
    for i in 0..60u64 {
        let top = FrameRecord::new(i * 40 * ms, Frame::filled_uyvy(8, 4, grey).unwrap());
        w.write_camera("/camera/image", &top, None).unwrap();
        if i < 10 {
            let (fw, fh) = if i < 5 { (8, 4) } else { (16, 8) };
            let bottom = FrameRecord::new(i * 80 * ms, Frame::filled_uyvy(fw, fh, grey).unwrap());
            w.write_camera("/camera/bottom", &bottom, None).unwrap();
        }
    }
    w.finish().unwrap();
    let lut = dir.join("blank.lut");
    LookupTable::new(6).unwrap().save(&lut).unwrap();
    (p, lut)
}

#[test]
fn info_says_which_camera_ends_early_runs_slower_or_changes_size() {
    let dir = tempfile::tempdir().unwrap();
    let (rec, _) = uneven(dir.path());
    let out = eotn_ok(&[OsStr::new("info"), rec.as_os_str(), OsStr::new("--json")]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let cameras = v["cameras"].as_array().unwrap();
    assert_eq!(cameras.len(), 2);
    let fps = |c: &serde_json::Value| c["fps"].as_f64().unwrap();
    assert!((fps(&cameras[0]) - 25.0).abs() < 0.01, "{}", cameras[0]);
    assert!((fps(&cameras[1]) - 12.5).abs() < 0.01, "{}", cameras[1]);
    assert_eq!(cameras[1]["last_time_ns"], 720_000_000);
    assert_eq!(
        cameras[1]["sizes"],
        serde_json::json!(["8x4: 5 frames", "16x8: 5 frames"])
    );
    assert!(
        cameras[0].get("sizes").is_none(),
        "the top camera keeps its size"
    );
    let warnings: Vec<&str> = v["warnings"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|w| w.as_str())
        .collect();
    for expected in [
        "camera /camera/bottom: the frame size changes mid-recording (8x4: 5 frames, 16x8: 5 frames)",
        "camera /camera/bottom ends 1.64 s before the recording's last frame",
        "the cameras run at different frame rates (/camera/image 25.0 fps, /camera/bottom 12.5 fps)",
    ] {
        assert!(
            warnings.iter().any(|w| w.starts_with(expected)),
            "{expected}: {warnings:?}"
        );
    }
    assert!(
        !warnings.iter().any(|w| w.contains("camera /camera/image")),
        "nothing said of the top camera: {warnings:?}"
    );
}

#[test]
fn detect_says_where_a_camera_s_frame_size_changes_and_detects_every_frame() {
    let dir = tempfile::tempdir().unwrap();
    let (rec, lut) = uneven(dir.path());
    let out = eotn_ok(&[
        OsStr::new("detect"),
        rec.as_os_str(),
        OsStr::new("--lut"),
        lut.as_os_str(),
        OsStr::new("--camera"),
        OsStr::new("/camera/bottom"),
        OsStr::new("--json"),
    ]);
    assert_eq!(String::from_utf8_lossy(&out.stdout).lines().count(), 10);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("uneven_000005: the frame size changes from 8x4 to 16x8"),
        "{err}"
    );
    assert_eq!(err.matches("the frame size changes").count(), 1, "{err}");
    // The top camera keeps its size: nothing said.
    let out = eotn_ok(&[
        OsStr::new("detect"),
        rec.as_os_str(),
        OsStr::new("--lut"),
        lut.as_os_str(),
    ]);
    assert_eq!(String::from_utf8_lossy(&out.stdout).lines().count(), 60);
    assert!(!String::from_utf8_lossy(&out.stderr).contains("frame size"));
}

/// The image topics and other channels of an MCAP file with their message counts, read with the
/// `mcap` crate.
fn topic_counts(path: &Path) -> std::collections::BTreeMap<String, usize> {
    let bytes = std::fs::read(path).unwrap();
    let mut counts = std::collections::BTreeMap::new();
    for m in mcap::MessageStream::new(&bytes).unwrap() {
        *counts.entry(m.unwrap().channel.topic.clone()).or_insert(0) += 1;
    }
    counts
}

#[test]
fn record_keeps_every_camera_of_a_robot_unless_told_which() {
    let Some(python) = crate::common::python_with_foxglove() else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let script = root().join("tests/it/foxglove_sender.py");
    let mut made = Vec::new();
    for (name, only) in [("all.mcap", None), ("top.mcap", Some("/camera/image"))] {
        let port = crate::live::free_port();
        let mut sender = std::process::Command::new(&python)
            .arg(&script)
            .args(["--port", &port.to_string(), "--frames", "15", "--bottom"])
            .stdout(std::process::Stdio::null())
            .spawn()
            .unwrap();
        let out = dir.path().join(name);
        let address = format!("ws://127.0.0.1:{port}");
        let mut args = vec![
            OsStr::new("record"),
            OsStr::new(&address),
            OsStr::new("-o"),
            out.as_os_str(),
            OsStr::new("--seconds"),
            OsStr::new("4"),
        ];
        if let Some(c) = only {
            args.extend([OsStr::new("--camera"), OsStr::new(c)]);
        }
        let result = eotn(&args);
        let _ = sender.kill();
        let _ = sender.wait();
        assert!(
            result.status.success(),
            "{}",
            String::from_utf8_lossy(&result.stderr)
        );
        made.push(topic_counts(&out));
    }
    let (all, top) = (&made[0], &made[1]);
    for topic in [
        "/camera/image",
        "/sensors",
        "/camera/bottom",
        "/camera/bottom/sensors",
    ] {
        assert!(all.get(topic).is_some_and(|&n| n >= 10), "{topic}: {all:?}");
    }
    assert!(
        top.get("/camera/image").is_some_and(|&n| n >= 10),
        "{top:?}"
    );
    assert!(top.contains_key("/sensors"), "{top:?}");
    assert!(
        !top.contains_key("/camera/bottom") && !top.contains_key("/camera/bottom/sensors"),
        "the bottom camera and its readings are left out: {top:?}"
    );
    // The recording of both opens on either camera.
    let out = eotn_ok(&[
        OsStr::new("info"),
        dir.path().join("all.mcap").as_os_str(),
        OsStr::new("--json"),
    ]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let topics: Vec<&str> = v["cameras"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|c| c["topic"].as_str())
        .collect();
    assert_eq!(topics, ["/camera/image", "/camera/bottom"]);
}

/// `two.mcap` in `dir`: `/camera/image` 8×4 (Y 50) and `/camera/bottom` 4×2 (Y 200), three
/// frames each; each camera names its table (`top.lut`, `tables/bottom.lut`, relative to the
/// recording's folder).
fn named_two(dir: &Path) -> PathBuf {
    let p = dir.join("two.mcap");
    let mut w = StreamWriter::create(&p, &StreamInfo::default()).unwrap();
    for (topic, lut) in [
        ("/camera/image", "top.lut"),
        ("/camera/bottom", "tables/bottom.lut"),
    ] {
        let files = eotn::camera::CameraFiles {
            lut: Some(lut.into()),
            ..Default::default()
        };
        w.name_camera_files(topic, &files).unwrap();
    }
    for i in 0..3u64 {
        let top = FrameRecord::new(
            i * 40,
            Frame::filled_uyvy(8, 4, Yuv::new(50, 1, 2)).unwrap(),
        );
        w.write_camera("/camera/image", &top, None).unwrap();
        let bottom = FrameRecord::new(
            i * 40 + 5,
            Frame::filled_uyvy(4, 2, Yuv::new(200, 1, 2)).unwrap(),
        );
        w.write_camera("/camera/bottom", &bottom, None).unwrap();
    }
    w.finish().unwrap();
    p
}

#[test]
fn import_keeps_each_camera_s_named_files() {
    let dir = tempfile::tempdir().unwrap();
    let rec = named_two(dir.path());
    let elsewhere = tempfile::tempdir().unwrap();
    let files = |path: &Path, camera: Option<&str>| {
        eotn::streams::StreamReader::open_camera(path, camera)
            .unwrap()
            .camera_files()
            .unwrap()
            .lut
    };
    // Written beside the recording: the names as they were, resolved as before.
    let beside = dir.path().join("copy.mcap");
    eotn_ok(&[
        OsStr::new("import"),
        rec.as_os_str(),
        OsStr::new("-o"),
        beside.as_os_str(),
    ]);
    for camera in ["/camera/image", "/camera/bottom"] {
        assert_eq!(
            files(&beside, Some(camera)),
            files(&rec, Some(camera)),
            "{camera}"
        );
    }
    // Written elsewhere: still the recording's tables (their paths made absolute).
    let far = elsewhere.path().join("far.mcap");
    eotn_ok(&[
        OsStr::new("import"),
        rec.as_os_str(),
        OsStr::new("-o"),
        far.as_os_str(),
    ]);
    let bottom = std::fs::canonicalize(dir.path())
        .unwrap()
        .join("tables/bottom.lut");
    assert_eq!(files(&far, Some("/camera/bottom")), Some(bottom.clone()));
    // One camera kept: the one-camera stream's camera names that camera's table.
    let one = elsewhere.path().join("bottom.mcap");
    eotn_ok(&[
        OsStr::new("import"),
        rec.as_os_str(),
        OsStr::new("--camera"),
        OsStr::new("/camera/bottom"),
        OsStr::new("-o"),
        one.as_os_str(),
    ]);
    assert_eq!(files(&one, None), Some(bottom));
}

#[test]
fn eval_without_lut_takes_the_camera_s_table() {
    let dir = tempfile::tempdir().unwrap();
    let rec = dir.path().join("goal.mcap");
    std::fs::copy(root().join("streams/sim-goalkeeper.mcap"), &rec).unwrap();
    let lut = root().join("lookup_tables/sim.lut");
    let eval = |extra: &[&OsStr]| {
        let mut args = vec![OsStr::new("eval"), rec.as_os_str(), OsStr::new("--json")];
        args.extend_from_slice(extra);
        eotn(&args)
    };
    let refused = eval(&[]);
    let err = String::from_utf8_lossy(&refused.stderr);
    assert!(
        !refused.status.success() && err.contains("--lut is needed"),
        "{err}"
    );
    let v = serde_json::json!({"cameras": {"/camera/image": {"lut": lut}}});
    std::fs::write(eotn::camera::sidecar_path(&rec), v.to_string()).unwrap();
    let report = |out: std::process::Output| {
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        serde_json::from_slice::<serde_json::Value>(&out.stdout).unwrap()
    };
    assert_eq!(
        report(eval(&[])),
        report(eval(&[OsStr::new("--lut"), lut.as_os_str()])),
        "the camera's table"
    );
}

#[test]
fn lut_from_labels_reads_the_camera_given_of_a_recording() {
    let dir = tempfile::tempdir().unwrap();
    let rec = named_two(dir.path());
    // Masks named as `eotn classify --raw` names a stream's frames, sized for the bottom
    // camera (4×2): every pixel orange.
    for i in 0..3 {
        let mask = dir.path().join(format!("two_{i:06}.cls"));
        std::fs::write(mask, [eotn::lut::ColourClass::Orange.code(); 8]).unwrap();
    }
    let table = dir.path().join("learnt.lut");
    let learn = |camera: Option<&str>| {
        let mut args = vec![
            OsStr::new("lut-from-labels"),
            rec.as_os_str(),
            OsStr::new("--holdout-every"),
            OsStr::new("1000"),
            OsStr::new("--margin"),
            OsStr::new("0"),
            OsStr::new("-o"),
            table.as_os_str(),
        ];
        if let Some(c) = camera {
            args.extend([OsStr::new("--camera"), OsStr::new(c)]);
        }
        eotn(&args)
    };
    let out = learn(Some("/camera/bottom"));
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let t = LookupTable::load(&table).unwrap();
    assert_eq!(
        t.class_of(Yuv::new(200, 1, 2)),
        eotn::lut::ColourClass::Orange,
        "the bottom camera's colour"
    );
    assert_ne!(
        t.class_of(Yuv::new(50, 1, 2)),
        eotn::lut::ColourClass::Orange
    );
    // The first camera's frames (8×4) do not fit the bottom camera's masks: refused, named.
    let out = learn(None);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && err.contains("two_000000.cls"),
        "{err}"
    );
}
