//! Bad input a hostile but fair user gives: each case ends with one clear line (or a warning and
//! the rest of the work done), never an abort, a hang, or a replaced input.

use std::ffi::OsStr;
use std::io::{BufRead as _, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

use crate::common::{eotn, eotn_ok, sim_stream};

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn sim_lut() -> PathBuf {
    root().join("lookup_tables/sim.lut")
}

/// Runs eotn, expects failure, returns stderr (one line is asserted).
fn fails(args: &[&OsStr]) -> String {
    let out = eotn(args);
    assert!(!out.status.success(), "eotn {args:?} should fail");
    let err = String::from_utf8_lossy(&out.stderr).trim().to_owned();
    let lines: Vec<&str> = err.lines().filter(|l| l.starts_with("eotn:")).collect();
    assert_eq!(lines.len(), 1, "one error line expected: {err}");
    err
}

#[test]
fn an_image_larger_than_any_frame_is_refused_before_it_is_decoded() {
    let dir = tempfile::tempdir().unwrap();
    let big = dir.path().join("big.png");
    image::GrayImage::new(4100, 4100).save(&big).unwrap();
    let err = fails(&[
        "render".as_ref(),
        big.as_os_str(),
        "--lut".as_ref(),
        sim_lut().as_os_str(),
        "-o".as_ref(),
        dir.path().join("out").as_os_str(),
        "--scale".as_ref(),
        "16".as_ref(),
    ]);
    assert!(err.contains("4100×4100 is larger than"), "{err}");
}

#[test]
fn a_scale_that_makes_a_huge_picture_is_refused_up_front() {
    let dir = tempfile::tempdir().unwrap();
    let frame = dir.path().join("f.png");
    image::RgbImage::new(2000, 1500).save(&frame).unwrap();
    let err = fails(&[
        "render".as_ref(),
        frame.as_os_str(),
        "--lut".as_ref(),
        sim_lut().as_os_str(),
        "-o".as_ref(),
        dir.path().join("out").as_os_str(),
        "--scale".as_ref(),
        "16".as_ref(),
    ]);
    assert!(
        err.contains("--scale 16") && err.contains("smaller --scale"),
        "{err}"
    );
}

#[test]
fn devices_given_as_frames_or_tables_are_refused_unread() {
    let err = fails(&[
        "classify".as_ref(),
        "/dev/zero".as_ref(),
        "--lut".as_ref(),
        sim_lut().as_os_str(),
    ]);
    assert!(err.contains("not a regular file"), "{err}");
    let frame = root().join("streams/sample.mcap");
    let err = fails(&[
        "classify".as_ref(),
        frame.as_os_str(),
        "--lut".as_ref(),
        "/dev/zero".as_ref(),
    ]);
    assert!(err.contains("not a regular file"), "{err}");
}

#[test]
fn commands_refuse_to_replace_their_own_inputs() {
    let dir = tempfile::tempdir().unwrap();
    let a = dir.path().join("a.uyvy");
    let b = dir.path().join("b.uyvy");
    std::fs::write(&a, vec![128u8; 208 * 160 * 2]).unwrap();
    std::fs::write(&b, vec![90u8; 208 * 160 * 2]).unwrap();
    let before = std::fs::read(&b).unwrap();
    let err = fails(&[
        "import".as_ref(),
        a.as_os_str(),
        b.as_os_str(),
        "-o".as_ref(),
        b.as_os_str(),
    ]);
    assert!(err.contains("would replace the input"), "{err}");
    assert_eq!(std::fs::read(&b).unwrap(), before);

    // A label mask is an input of lut-from-labels too.
    let mask = dir.path().join("a.cls");
    std::fs::write(&mask, vec![5u8; 208 * 160]).unwrap();
    let err = fails(&[
        "lut-from-labels".as_ref(),
        a.as_os_str(),
        "-o".as_ref(),
        mask.as_os_str(),
    ]);
    assert!(err.contains("would replace the input"), "{err}");
    assert_eq!(std::fs::read(&mask).unwrap(), vec![5u8; 208 * 160]);
}

#[test]
fn a_damaged_chunk_costs_only_its_frames_with_a_warning_naming_them() {
    let dir = tempfile::tempdir().unwrap();
    let good = sim_stream(dir.path(), "walk-and-pan", 40, None);
    let mut bytes = std::fs::read(&good).unwrap();
    let middle = bytes.len() / 2;
    bytes[middle] ^= 0xff;
    let bad = dir.path().join("bad.mcap");
    std::fs::write(&bad, &bytes).unwrap();
    let out = eotn_ok(&[
        "detect".as_ref(),
        bad.as_os_str(),
        "--lut".as_ref(),
        sim_lut().as_os_str(),
        "--json".as_ref(),
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    // One warning naming the frames lost: "frames A–B skipped, unreadable: … CRC …".
    let named: Vec<usize> = err
        .split("frames ")
        .nth(1)
        .and_then(|rest| rest.split(" skipped, unreadable").next())
        .map(|range| range.split('–').filter_map(|n| n.parse().ok()).collect())
        .unwrap_or_default();
    let [from, to] = named[..] else {
        panic!("a warning naming the skipped frames: {err}");
    };
    assert!(from > 0 && to < 39 && from <= to, "{err}");
    assert!(err.contains("CRC"), "says why: {err}");
    // Every other frame is detected, in order, and only those.
    let frames: Vec<usize> = String::from_utf8_lossy(&out.stdout)
        .lines()
        .map(|l| {
            let v: serde_json::Value = serde_json::from_str(l).unwrap();
            let name = v["frame"].as_str().unwrap().to_owned();
            name.rsplit('_').next().unwrap().parse().unwrap()
        })
        .collect();
    let expected: Vec<usize> = (0..40).filter(|i| !(from..=to).contains(i)).collect();
    assert_eq!(frames, expected, "{err}");
    // info still describes a stream whose first chunk is damaged.
    let mut bytes = std::fs::read(&good).unwrap();
    bytes[3000] ^= 0xff;
    let first = dir.path().join("first.mcap");
    std::fs::write(&first, &bytes).unwrap();
    let out = eotn_ok(&["info".as_ref(), first.as_os_str()]);
    assert!(String::from_utf8_lossy(&out.stdout).contains("first_readable_frame"));
}

#[test]
fn a_partial_stream_left_by_a_crash_opens_by_its_own_name_and_can_be_finished() {
    let dir = tempfile::tempdir().unwrap();
    let good = sim_stream(dir.path(), "walk-and-pan", 40, None);
    let bytes = std::fs::read(&good).unwrap();
    // A writer killed after its second chunk: no summary, the rest cut off.
    let partial = dir.path().join("rec.mcap.partial");
    std::fs::write(&partial, &bytes[..bytes.len() * 3 / 4]).unwrap();
    let out = eotn_ok(&["info".as_ref(), partial.as_os_str()]);
    assert!(String::from_utf8_lossy(&out.stdout).contains("kind: stream"));
    // Not into rec.mcap: its writer's temporary would be the file being read.
    let err = fails(&[
        "import".as_ref(),
        partial.as_os_str(),
        "-o".as_ref(),
        dir.path().join("rec.mcap").as_os_str(),
    ]);
    assert!(err.contains("another name"), "{err}");
    assert_eq!(std::fs::read(&partial).unwrap().len(), bytes.len() * 3 / 4);
    let finished = dir.path().join("rec-recovered.mcap");
    eotn_ok(&[
        "import".as_ref(),
        partial.as_os_str(),
        "-o".as_ref(),
        finished.as_os_str(),
    ]);
    let r = eotn::streams::StreamReader::open(&finished).unwrap();
    assert!(
        (10..40).contains(&r.len()) && r.warnings().is_empty(),
        "{} {:?}",
        r.len(),
        r.warnings()
    );
}

#[test]
fn wrong_parameter_and_sensor_files_are_errors_naming_the_field() {
    let dir = tempfile::tempdir().unwrap();
    let frame = dir.path().join("f.png");
    image::RgbImage::new(208, 160).save(&frame).unwrap();
    let run = |flag: &str, text: &str| {
        let p = dir.path().join("side.json");
        std::fs::write(&p, text).unwrap();
        fails(&[
            "detect".as_ref(),
            frame.as_os_str(),
            "--lut".as_ref(),
            sim_lut().as_os_str(),
            flag.as_ref(),
            p.as_os_str(),
        ])
    };
    assert!(run("--params", r#"{"bal": {}}"#).contains("unknown parameter 'bal'"));
    assert!(run("--params", r#"{"ball": {"diameter_cm": -1}}"#).contains("ball.diameter_cm"));
    assert!(run("--params", r#"{"other_camera_fov_deg": 180}"#).contains("other_camera_fov_deg"));
    assert!(run("--sensors", r#"{"head_pna_rad": 0.1}"#).contains("'head_pna_rad'"));
    assert!(run("--sensors", r#"{"head_pan_rad": 1e300}"#).contains("head_pan_rad"));
    // NaN, as Python writes it, is read as missing.
    let p = dir.path().join("nan.json");
    std::fs::write(&p, r#"{"head_pan_rad": NaN}"#).unwrap();
    eotn_ok(&[
        "detect".as_ref(),
        frame.as_os_str(),
        "--lut".as_ref(),
        sim_lut().as_os_str(),
        "--sensors".as_ref(),
        p.as_os_str(),
    ]);
}

#[test]
fn a_closed_output_pipe_ends_quietly_with_success() {
    let mut child = Command::new(env!("CARGO_BIN_EXE_eotn"))
        .arg("detect")
        .arg(root().join("streams/bhuman2009.mcap"))
        .arg("--lut")
        .arg(root().join("lookup_tables/bhuman2009.lut"))
        .arg("--json")
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut first = String::new();
    BufReader::new(child.stdout.take().unwrap())
        .read_line(&mut first)
        .unwrap();
    // The reader goes away, as `| head -1` does.
    let out = child.wait_with_output().unwrap();
    assert!(first.starts_with('{'));
    assert!(out.status.success(), "{:?}", out.status);
    assert!(
        !String::from_utf8_lossy(&out.stderr).contains("Broken pipe"),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

#[test]
fn sim_refuses_zero_frames_and_import_a_silly_rate_in_one_short_line() {
    let dir = tempfile::tempdir().unwrap();
    let err = fails(&[
        "sim".as_ref(),
        "--scenario".as_ref(),
        "walk-and-pan".as_ref(),
        "--frames".as_ref(),
        "0".as_ref(),
        "-o".as_ref(),
        dir.path().join("z.mcap").as_os_str(),
    ]);
    assert!(
        err.contains("'--frames <FRAMES>'") && err.contains("1..="),
        "{err}"
    );
    let frame = dir.path().join("f.uyvy");
    std::fs::write(&frame, vec![128u8; 208 * 160 * 2]).unwrap();
    let err = fails(&[
        "import".as_ref(),
        frame.as_os_str(),
        "--fps=1e-300".as_ref(),
        "-o".as_ref(),
        dir.path().join("x.mcap").as_os_str(),
    ]);
    assert!(
        err.len() < 160 && err.contains("from 0.001 to 10000"),
        "{err}"
    );
}

#[test]
fn a_record_length_inside_a_chunk_damaged_to_exabytes_is_skipped_not_an_abort() {
    // Found by fuzz/mcap_stream: a sim stream with bytes changed inside a chunk so that a record
    // in it claims 8·10^18 bytes. mcap's chunk reader allocated that much and aborted.
    let damaged = root().join("fuzz/regressions/mcap_stream/chunk-record-length-exabytes.mcap");
    let dir = tempfile::tempdir().unwrap();
    let stream = dir.path().join("damaged.mcap");
    std::fs::copy(&damaged, &stream).unwrap();
    if let Ok(mut reader) = eotn::streams::StreamReader::open(&stream) {
        for index in 0..reader.len() {
            let _ = reader.read(index);
        }
    }
    // The command line says so in words and exits, instead of dying of SIGABRT.
    let out = eotn(&["info".as_ref(), stream.as_os_str()]);
    assert!(
        out.status.code().is_some(),
        "eotn info was killed by a signal"
    );
}
