//! Several cameras (issue 28): two-camera recordings written by tools that are not eotn's
//! (`cameras.py`: a rosbag2 by `rosbags` with `/camera/top/image_raw` `yuv422_yuy2` and
//! `/camera/bottom/image_raw` `rgb8`; a Foxglove SDK MCAP with `/camera/top` and
//! `/camera/bottom`), the bottom camera at half the rate and half the size. `info` lists both;
//! `detect --camera` on each equals `detect` on that camera's frames written alone; `import`
//! keeps both and they reopen; an unknown camera is an error listing them; the sidecar names a
//! camera's table.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;

use crate::common::{eotn, eotn_ok, python_with};

/// Frames of the top camera (the bottom camera has every second one).
const FRAMES: usize = 8;

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// The recordings by name (`bag_two`, `bag_top`, `bag_bottom`, `fox_two`, …), written once.
fn recordings() -> Option<&'static (tempfile::TempDir, serde_json::Value)> {
    static MADE: OnceLock<Option<(tempfile::TempDir, serde_json::Value)>> = OnceLock::new();
    crate::common::made_once(&MADE, "the two-camera recordings", || {
        let python = python_with(
            "import rosbags, foxglove, cv2, mcap_protobuf",
            "rosbags, foxglove-sdk, opencv-python-headless and mcap-protobuf-support",
            "the two-camera recordings tests",
        )?;
        let dir = tempfile::tempdir().unwrap();
        let out = Command::new(python)
            .arg(root().join("tests/it/cameras.py"))
            .arg(root().join("streams/bhuman2009.mcap"))
            .arg(FRAMES.to_string())
            .arg(dir.path())
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "cameras.py: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let made = serde_json::from_slice(&out.stdout).unwrap();
        Some((dir, made))
    })
}

fn path(name: &str) -> Option<PathBuf> {
    recordings().map(|(_, made)| PathBuf::from(made[name].as_str().unwrap()))
}

fn info(path: &Path, camera: Option<&str>) -> serde_json::Value {
    let mut args: Vec<&std::ffi::OsStr> =
        vec!["info".as_ref(), "--json".as_ref(), path.as_os_str()];
    if let Some(c) = camera {
        args.push("--camera".as_ref());
        args.push(c.as_ref());
    }
    serde_json::from_slice(&eotn_ok(&args).stdout).unwrap()
}

/// `eotn detect --json` of a recording's camera, each line without its frame name and timings.
fn detections(path: &Path, camera: Option<&str>, lut: Option<&Path>) -> Vec<serde_json::Value> {
    let mut owned: Vec<std::ffi::OsString> = vec![
        "detect".into(),
        "--json".into(),
        "--params".into(),
        root().join("params/spl2009.json").into_os_string(),
    ];
    if let Some(l) = lut {
        owned.push("--lut".into());
        owned.push(l.as_os_str().to_owned());
    }
    if let Some(c) = camera {
        owned.push("--camera".into());
        owned.push(c.into());
    }
    owned.push(path.as_os_str().to_owned());
    let refs: Vec<&std::ffi::OsStr> = owned.iter().map(|s| s.as_os_str()).collect();
    let out = eotn_ok(&refs);
    String::from_utf8_lossy(&out.stdout)
        .lines()
        .map(|l| {
            let mut v: serde_json::Value = serde_json::from_str(l).unwrap();
            let o = v.as_object_mut().unwrap();
            o.retain(|k, _| k != "frame" && !k.ends_with("_us"));
            v
        })
        .collect()
}

fn bhuman_lut() -> PathBuf {
    root().join("lookup_tables/bhuman2009.lut")
}

#[test]
fn info_lists_both_cameras_with_their_counts_and_sizes() {
    for (name, top, bottom, top_encoding) in [
        (
            "bag_two",
            "/camera/top/image_raw",
            "/camera/bottom/image_raw",
            "yuv422_yuy2",
        ),
        ("fox_two", "/camera/top", "/camera/bottom", "uyvy"),
    ] {
        let Some(p) = path(name) else { return };
        let v = info(&p, None);
        // The interface the issue fixes; each camera's times and rate come beside it.
        let fixed: Vec<serde_json::Value> = v["cameras"]
            .as_array()
            .unwrap()
            .iter()
            .map(|c| {
                let mut c = c.clone();
                let o = c.as_object_mut().unwrap();
                for extra in ["first_time_ns", "last_time_ns", "fps"] {
                    assert!(o.remove(extra).is_some(), "{name}: {extra}");
                }
                c
            })
            .collect();
        assert_eq!(
            serde_json::Value::from(fixed),
            serde_json::json!([
                {"topic": top, "frames": FRAMES, "width": 320, "height": 240, "encoding": top_encoding},
                {"topic": bottom, "frames": FRAMES / 2, "width": 160, "height": 120, "encoding": "rgb8"},
            ]),
            "{name}"
        );
        assert_eq!(v["frames"], FRAMES, "the default camera's count");
        let b = info(&p, Some(bottom));
        assert_eq!(b["camera"].as_str(), Some(bottom));
        assert_eq!(b["frames"].as_u64(), Some(FRAMES as u64 / 2));
        assert_eq!(b["width"].as_u64(), Some(160));
        let out = eotn(&[
            "info".as_ref(),
            p.as_os_str(),
            "--camera".as_ref(),
            "/camera/side".as_ref(),
        ]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success());
        assert!(
            err.contains("no camera /camera/side") && err.contains(top) && err.contains(bottom),
            "{err}"
        );
    }
}

#[test]
fn detect_on_each_camera_equals_detect_on_its_frames_alone() {
    for (two, top, bottom) in [
        (
            "bag_two",
            "/camera/top/image_raw",
            "/camera/bottom/image_raw",
        ),
        ("fox_two", "/camera/top", "/camera/bottom"),
    ] {
        let Some(p) = path(two) else { return };
        let prefix = two.trim_end_matches("_two");
        for (camera, alone) in [(top, "top"), (bottom, "bottom")] {
            let Some(a) = path(&format!("{prefix}_{alone}")) else {
                return;
            };
            let got = detections(&p, Some(camera), Some(&bhuman_lut()));
            let want = detections(&a, None, Some(&bhuman_lut()));
            assert_eq!(got.len(), if alone == "top" { FRAMES } else { FRAMES / 2 });
            assert_eq!(got, want, "{two} {camera}");
        }
        // The default camera is the first.
        assert_eq!(
            detections(&p, None, Some(&bhuman_lut())),
            detections(&p, Some(top), Some(&bhuman_lut()))
        );
    }
}

#[test]
fn import_keeps_both_cameras_and_they_reopen() {
    let Some(p) = path("bag_two") else { return };
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("two.mcap");
    let run = eotn_ok(&[
        "import".as_ref(),
        p.as_os_str(),
        "-o".as_ref(),
        out.as_os_str(),
    ]);
    // Import keeps every camera: no note that one of them is "not read".
    let said = String::from_utf8_lossy(&run.stderr);
    assert!(!said.contains("not read"), "{said}");
    let v = info(&out, None);
    let cams: Vec<(String, u64, u64)> = v["cameras"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| {
            (
                c["topic"].as_str().unwrap().to_owned(),
                c["frames"].as_u64().unwrap(),
                c["width"].as_u64().unwrap(),
            )
        })
        .collect();
    assert_eq!(
        cams,
        [
            ("/camera/top/image_raw".to_owned(), FRAMES as u64, 320),
            (
                "/camera/bottom/image_raw".to_owned(),
                FRAMES as u64 / 2,
                160
            )
        ]
    );
    // No channel of the imported stream is empty (once, an unused `/camera/image` and
    // `/sensors` were written beside the two cameras' own).
    let empty: Vec<&str> = v["channels"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|c| c["messages"].as_u64() == Some(0))
        .map(|c| c["topic"].as_str().unwrap())
        .collect();
    assert!(empty.is_empty(), "empty channels: {empty:?}");
    for camera in ["/camera/top/image_raw", "/camera/bottom/image_raw"] {
        assert_eq!(
            detections(&out, Some(camera), Some(&bhuman_lut())),
            detections(&p, Some(camera), Some(&bhuman_lut())),
            "{camera}"
        );
    }
    // --camera keeps only that one, as a one-camera stream.
    let one = dir.path().join("bottom.mcap");
    eotn_ok(&[
        "import".as_ref(),
        p.as_os_str(),
        "--camera".as_ref(),
        "/camera/bottom/image_raw".as_ref(),
        "-o".as_ref(),
        one.as_os_str(),
    ]);
    let v = info(&one, None);
    assert_eq!(v["cameras"].as_array().unwrap().len(), 1);
    assert_eq!(v["camera"].as_str(), Some("/camera/image"));
    assert_eq!(v["frames"].as_u64(), Some(FRAMES as u64 / 2));
}

#[test]
fn the_sidecar_names_each_camera_s_table() {
    let Some(p) = path("fox_two") else { return };
    let dir = tempfile::tempdir().unwrap();
    let rec = dir.path().join("game.mcap");
    std::fs::copy(&p, &rec).unwrap();
    // Without --lut and without a sidecar: a clear refusal naming the sidecar.
    let out = eotn(&["detect".as_ref(), "--json".as_ref(), rec.as_os_str()]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && err.contains("game.mcap.cameras.json"),
        "{err}"
    );
    std::fs::copy(bhuman_lut(), dir.path().join("bottom.lut")).unwrap();
    std::fs::write(
        dir.path().join("game.mcap.cameras.json"),
        r#"{"cameras": {"/camera/bottom": {"lut": "bottom.lut"}}}"#,
    )
    .unwrap();
    assert_eq!(
        detections(&rec, Some("/camera/bottom"), None),
        detections(&rec, Some("/camera/bottom"), Some(&bhuman_lut())),
        "the sidecar's table"
    );
    let out = eotn(&["detect".as_ref(), "--json".as_ref(), rec.as_os_str()]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && err.contains("no table for /camera/top"),
        "{err}"
    );
}

/// (topic, frames, width) of every camera `info --json` lists.
fn cameras_of(path: &Path) -> Vec<(String, u64, u64)> {
    info(path, None)["cameras"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| {
            (
                c["topic"].as_str().unwrap().to_owned(),
                c["frames"].as_u64().unwrap(),
                c["width"].as_u64().unwrap(),
            )
        })
        .collect()
}

#[test]
fn import_with_two_cameras_named_keeps_those_two() {
    let Some(p) = path("bag_two") else { return };
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("both.mcap");
    let import = |cameras: &[&str], out: &Path| {
        let mut args: Vec<&std::ffi::OsStr> = vec!["import".as_ref(), p.as_os_str()];
        for c in cameras {
            args.extend([std::ffi::OsStr::new("--camera"), std::ffi::OsStr::new(c)]);
        }
        args.extend([std::ffi::OsStr::new("-o"), out.as_os_str()]);
        eotn(&args)
    };
    let top = "/camera/top/image_raw";
    let bottom = "/camera/bottom/image_raw";
    assert!(import(&[bottom, top], &out).status.success());
    let mut cams = cameras_of(&out);
    cams.sort();
    assert_eq!(
        cams,
        [
            (bottom.to_owned(), FRAMES as u64 / 2, 160),
            (top.to_owned(), FRAMES as u64, 320),
        ]
    );
    for camera in [top, bottom] {
        assert_eq!(
            detections(&out, Some(camera), Some(&bhuman_lut())),
            detections(&p, Some(camera), Some(&bhuman_lut())),
            "{camera}"
        );
    }
    // A camera the recording does not have, among two, is an error listing those it has.
    let bad = import(&[top, "/camera/side"], &dir.path().join("bad.mcap"));
    let err = String::from_utf8_lossy(&bad.stderr);
    assert!(!bad.status.success() && err.contains(bottom), "{err}");
    assert!(!dir.path().join("bad.mcap").exists());
}

#[test]
fn the_foxglove_sdk_two_camera_file_is_imported_and_reopens() {
    let Some(p) = path("fox_two") else { return };
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("fox.mcap");
    eotn_ok(&[
        "import".as_ref(),
        p.as_os_str(),
        "-o".as_ref(),
        out.as_os_str(),
    ]);
    assert_eq!(
        cameras_of(&out),
        [
            ("/camera/top".to_owned(), FRAMES as u64, 320),
            ("/camera/bottom".to_owned(), FRAMES as u64 / 2, 160),
        ]
    );
    for camera in ["/camera/top", "/camera/bottom"] {
        assert_eq!(
            detections(&out, Some(camera), Some(&bhuman_lut())),
            detections(&p, Some(camera), Some(&bhuman_lut())),
            "{camera}"
        );
    }
}
