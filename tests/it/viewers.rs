//! Streams every viewer shows: the shipped streams and an annotated one, read by a real
//! third-party reader, Rerun's MCAP importer (`rerun mcap convert|check` from the pinned
//! `rerun-sdk` in `.venv/`). Before the streams stored `yuyv`, Rerun dropped every frame
//! (`expected one of [..., "yuyv", ...], got uyvy`).

use std::path::{Path, PathBuf};
use std::process::Command;

use crate::common::{eotn_ok, test_python};

/// The `rerun` command installed beside the tests' Python, or `None` with a "skipped" line
/// outside CI. Under `CI=true` its absence fails the test.
fn rerun() -> Option<PathBuf> {
    let python = test_python();
    let beside = python.parent().map(|d| d.join("rerun"));
    let candidate = beside
        .filter(|p| p.exists())
        .unwrap_or_else(|| "rerun".into());
    let ok = Command::new(&candidate)
        .arg("--version")
        .output()
        .is_ok_and(|o| o.status.success());
    if ok {
        return Some(candidate);
    }
    crate::common::skipped(
        "rerun not found; the Rerun import check did not run",
        "scripts/deps.sh --test installs rerun-sdk into .venv/",
    );
    None
}

/// Runs `rerun ARGS` with its own empty configuration (analytics off), returning stdout and
/// stderr together.
fn run_rerun(rerun: &Path, home: &Path, args: &[&std::ffi::OsStr]) -> (bool, String) {
    let mut cmd = Command::new(rerun);
    cmd.env("HOME", home)
        .env("XDG_CONFIG_HOME", home.join("config"))
        .env("XDG_DATA_HOME", home.join("data"))
        .env("NO_COLOR", "1")
        .env("RUST_LOG", "info");
    let _ = Command::new(rerun)
        .env("HOME", home)
        .env("XDG_CONFIG_HOME", home.join("config"))
        .args(["analytics", "disable"])
        .output();
    let out = cmd.args(args).output().expect("rerun runs");
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    (out.status.success(), text)
}

/// `rerun mcap convert` of `stream`: succeeds with no ERROR line and imports every entity of
/// `entities`.
fn assert_rerun_imports(rerun: &Path, home: &Path, stream: &Path, entities: &[&str]) {
    let rrd = home.join("out.rrd");
    let (ok, text) = run_rerun(
        rerun,
        home,
        &[
            "mcap".as_ref(),
            "convert".as_ref(),
            stream.as_os_str(),
            "-o".as_ref(),
            rrd.as_os_str(),
        ],
    );
    assert!(ok, "rerun mcap convert {}: {text}", stream.display());
    let errors: Vec<&str> = text.lines().filter(|l| l.contains("ERROR")).collect();
    assert!(
        errors.is_empty(),
        "rerun reported errors importing {}:\n{}",
        stream.display(),
        errors.join("\n")
    );
    let listed = text
        .split("Entities:")
        .nth(1)
        .unwrap_or_else(|| panic!("rerun listed no entities for {}: {text}", stream.display()));
    for e in entities {
        assert!(
            listed.lines().any(|l| l.trim().trim_end_matches(',') == *e),
            "rerun did not import {e} from {}: {text}",
            stream.display()
        );
    }
    assert!(std::fs::metadata(&rrd).is_ok_and(|m| m.len() > 0));
}

/// The shipped streams (`streams/*.mcap`).
fn shipped_streams() -> Vec<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("streams");
    let mut out: Vec<PathBuf> = std::fs::read_dir(&dir)
        .expect("streams/ exists")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "mcap"))
        .collect();
    out.sort();
    assert!(!out.is_empty(), "no shipped streams in {}", dir.display());
    out
}

#[test]
fn rerun_imports_the_images_of_every_shipped_stream() {
    let Some(rerun) = rerun() else { return };
    let home = tempfile::tempdir().unwrap();
    for stream in shipped_streams() {
        assert_rerun_imports(&rerun, home.path(), &stream, &["/camera/image"]);
    }
}

#[test]
fn rerun_checks_every_channel_of_every_shipped_stream_ok() {
    let Some(rerun) = rerun() else { return };
    let home = tempfile::tempdir().unwrap();
    for stream in shipped_streams() {
        let (ok, text) = run_rerun(
            &rerun,
            home.path(),
            &["mcap".as_ref(), "check".as_ref(), stream.as_os_str()],
        );
        assert!(ok, "rerun mcap check {}: {text}", stream.display());
        // The table: "Status  ID  Chunks  Topic  Issues", then one row per channel.
        let rows: Vec<&str> = text
            .lines()
            .skip_while(|l| !l.starts_with("Status"))
            .skip(2)
            .filter(|l| !l.trim().is_empty())
            .collect();
        assert!(
            rows.iter().any(|r| r.contains("/camera/image")),
            "{}: {text}",
            stream.display()
        );
        for r in rows {
            assert!(
                r.trim_start().starts_with("ok"),
                "{}: channel not ok: {r}",
                stream.display()
            );
        }
    }
}

#[test]
fn rerun_imports_the_recognition_annotations_of_detect_annotate() {
    let Some(rerun) = rerun() else { return };
    let dir = tempfile::tempdir().unwrap();
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let out = dir.path().join("annotated.mcap");
    eotn_ok(&[
        "detect".as_ref(),
        root.join("streams/sample.mcap").as_os_str(),
        "--lut".as_ref(),
        root.join("lookup_tables/sample.lut").as_os_str(),
        "--annotate".as_ref(),
        out.as_os_str(),
    ]);
    assert_rerun_imports(
        &rerun,
        dir.path(),
        &out,
        &["/camera/image", "/camera/annotations", "/recognition"],
    );
}

/// The `foxglove.RawImage` encodings of a stream's image messages, read with the `mcap` crate
/// (not our reader).
fn image_encodings(path: &Path) -> Vec<String> {
    use foxglove::Decode as _;
    let bytes = std::fs::read(path).unwrap();
    let mut out = Vec::new();
    for m in mcap::MessageStream::new(&bytes).unwrap() {
        let m = m.unwrap();
        if m.channel.topic == "/camera/image" {
            let img = foxglove::messages::RawImage::decode(&m.data[..]).unwrap();
            out.push(img.encoding);
        }
    }
    out
}

#[test]
fn detect_annotate_keeps_every_frame_and_circles_each_found_ball() {
    use eotn::streams::StreamReader;
    let dir = tempfile::tempdir().unwrap();
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let input = root.join("streams/sim-walk-and-pan.mcap");
    let out = dir.path().join("annotated.mcap");
    eotn_ok(&[
        "detect".as_ref(),
        input.as_os_str(),
        "--lut".as_ref(),
        root.join("lookup_tables/sim.lut").as_os_str(),
        "--annotate".as_ref(),
        out.as_os_str(),
    ]);
    let mut a = StreamReader::open(&input).unwrap();
    let mut b = StreamReader::open(&out).unwrap();
    assert_eq!(a.len(), b.len());
    assert_eq!(a.info().source, b.info().source);
    let mut circled = 0;
    for i in 0..a.len() {
        let (ra, rb) = (a.read(i).unwrap(), b.read(i).unwrap());
        assert_eq!(ra.frame, rb.frame, "frame {i} changed");
        assert_eq!(ra.time_ns, rb.time_ns);
        assert_eq!(ra.sensors, rb.sensors);
        assert_eq!(ra.ground_truth, rb.ground_truth);
        let rec = rb.recognition.expect("each frame has its /recognition");
        let ann = rb
            .annotations
            .expect("each frame has its /camera/annotations");
        if let Some(ball) = rec.get("ball").filter(|b| !b.is_null()) {
            let (x, y) = (
                ball["center_x"].as_f64().unwrap(),
                ball["center_y"].as_f64().unwrap(),
            );
            let r = ball["radius_px"].as_f64().unwrap();
            // The circle is drawn where the image shows the ball, and a second one where the
            // skew correction puts it (the JSON's centre) when that is over 0.5 px away.
            assert!(
                ann.circles.iter().any(|c| {
                    let p = c.position.unwrap();
                    (p.x - x).hypot(p.y - y) <= 0.5 + 1e-9 && (c.diameter - 2.0 * r).abs() < 1e-9
                }),
                "frame {i}: no circle at the ball ({x}, {y}) r {r}"
            );
            assert!(
                ann.texts.iter().any(|t| t.text.starts_with("ball")),
                "frame {i}: no ball label"
            );
            circled += 1;
        } else {
            assert!(ann.circles.is_empty(), "frame {i}: a circle without a ball");
        }
    }
    // The shipped walk-and-pan stream shows the ball in every frame, and detect finds it.
    assert_eq!(circled, a.len(), "a circled ball in every frame");
    assert!(image_encodings(&out).iter().all(|e| e == "yuyv"));
}

#[test]
fn detect_annotate_refuses_to_replace_its_input() {
    let dir = tempfile::tempdir().unwrap();
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let copy = dir.path().join("in.mcap");
    std::fs::copy(root.join("streams/sample.mcap"), &copy).unwrap();
    let before = std::fs::read(&copy).unwrap();
    let out = crate::common::eotn(&[
        "detect".as_ref(),
        copy.as_os_str(),
        "--lut".as_ref(),
        root.join("lookup_tables/sample.lut").as_os_str(),
        "--annotate".as_ref(),
        copy.as_os_str(),
    ]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("would replace the input"));
    assert_eq!(std::fs::read(&copy).unwrap(), before);
}

#[test]
fn import_rewrites_a_stream_in_either_byte_order_with_the_same_frames() {
    use eotn::streams::StreamReader;
    let dir = tempfile::tempdir().unwrap();
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let input = root.join("streams/sim-goalkeeper.mcap");
    for (encoding, name) in [("uyvy", "u.mcap"), ("yuyv", "y.mcap")] {
        let out = dir.path().join(name);
        eotn_ok(&[
            "import".as_ref(),
            input.as_os_str(),
            "-o".as_ref(),
            out.as_os_str(),
            "--image-encoding".as_ref(),
            encoding.as_ref(),
        ]);
        let encodings = image_encodings(&out);
        assert!(!encodings.is_empty() && encodings.iter().all(|e| e == encoding));
        let mut a = StreamReader::open(&input).unwrap();
        let mut b = StreamReader::open(&out).unwrap();
        assert_eq!(a.len(), b.len());
        assert_eq!(a.info(), b.info());
        for i in 0..a.len() {
            assert_eq!(
                a.read(i).unwrap(),
                b.read(i).unwrap(),
                "frame {i} ({encoding})"
            );
        }
    }
}
