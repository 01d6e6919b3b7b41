//! The second hardening round on files (issue 25): a crashed recording's `.partial` kept, one
//! writer per output, outputs that would overwrite each other, and the inputs of every kind that
//! a command reads refused or bounded. Outputs onto devices, FIFOs, links and folders are in
//! `outputs.rs`.

use std::ffi::OsStr;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use crate::common::{eotn, eotn_ok, repo_file};

/// Runs eotn, expects failure, returns its one `eotn:` line.
pub fn fails(args: &[&OsStr]) -> String {
    let out = eotn(args);
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(!out.status.success(), "eotn {args:?} should fail: {err}");
    let lines: Vec<&str> = err.lines().filter(|l| l.starts_with("eotn:")).collect();
    assert_eq!(lines.len(), 1, "one error line expected: {err}");
    lines[0].to_owned()
}

fn sim_into(out: &Path, frames: &str) -> std::process::Output {
    eotn(&[
        "sim".as_ref(),
        "--scenario".as_ref(),
        "ball-edge".as_ref(),
        "--frames".as_ref(),
        frames.as_ref(),
        "-o".as_ref(),
        out.as_os_str(),
    ])
}

#[test]
fn a_crashed_recording_is_moved_aside_with_a_message_never_truncated() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("rec.mcap");
    let partial = dir.path().join("rec.mcap.partial");
    // A recording cut off by a crash: the first three quarters of a stream.
    let whole = std::fs::read(repo_file("streams/sim-ball-edge.mcap")).unwrap();
    let crashed = whole[..whole.len() * 3 / 4].to_vec();
    std::fs::write(&partial, &crashed).unwrap();
    let o = sim_into(&out, "3");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let err = String::from_utf8_lossy(&o.stderr);
    let aside = dir.path().join("rec.mcap.partial.1");
    assert!(
        err.contains(&aside.display().to_string()),
        "the message names where it went: {err}"
    );
    assert_eq!(
        std::fs::read(&aside).unwrap(),
        crashed,
        "the crashed part changed"
    );
    assert!(!partial.exists());
    assert_eq!(eotn::streams::StreamReader::open(&out).unwrap().len(), 3);
    // The moved file is still a stream by its name: `info` reads its frames.
    let info = eotn_ok(&["info".as_ref(), aside.as_os_str()]);
    assert!(String::from_utf8_lossy(&info.stdout).contains("kind: stream"));
}

#[test]
fn a_second_writer_of_an_output_being_recorded_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let served = crate::live::serve(
        &repo_file("streams/sim-ball-edge.mcap"),
        "127.0.0.1:0",
        &["--loop"],
    );
    let out = dir.path().join("live.mcap");
    let partial = dir.path().join("live.mcap.partial");
    let mut first = Command::new(env!("CARGO_BIN_EXE_eotn"))
        .arg("record")
        .arg(format!("ws://127.0.0.1:{}", served.port))
        .args(["--seconds", "30", "-o"])
        .arg(&out)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let start = Instant::now();
    while std::fs::metadata(&partial).map_or(0, |m| m.len()) == 0 {
        assert!(
            start.elapsed() < Duration::from_secs(20),
            "the first recorder never started"
        );
        std::thread::sleep(Duration::from_millis(50));
    }
    let before = std::fs::metadata(&partial).unwrap().len();
    let o = sim_into(&out, "2");
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success(), "{err}");
    assert!(err.contains("another eotn is writing"), "{err}");
    assert!(
        std::fs::metadata(&partial).unwrap().len() >= before,
        "the first recording was truncated"
    );
    assert!(
        !dir.path().join("live.mcap.partial.1").exists(),
        "the first recorder's file was moved away under it"
    );
    let _ = first.kill();
    let _ = first.wait();
    // Its file reads up to its last complete chunk.
    assert!(eotn::streams::StreamReader::open(&partial).is_ok());
}

#[test]
fn two_inputs_of_the_same_name_do_not_overwrite_each_others_output() {
    let dir = tempfile::tempdir().unwrap();
    for (folder, value) in [("a", 60u8), ("b", 200u8)] {
        std::fs::create_dir(dir.path().join(folder)).unwrap();
        std::fs::write(
            dir.path().join(folder).join("f.uyvy"),
            vec![value; 208 * 160 * 2],
        )
        .unwrap();
    }
    let out = dir.path().join("out");
    let err = fails(&[
        "export".as_ref(),
        dir.path().join("a/f.uyvy").as_os_str(),
        dir.path().join("b/f.uyvy").as_os_str(),
        "-o".as_ref(),
        out.as_os_str(),
    ]);
    assert!(err.contains("written already"), "{err}");
    // The first frame's picture is whole and is the first frame's.
    let png = image::open(out.join("f.uyvy.raw.png")).unwrap().to_rgb8();
    let first = eotn::frame::Frame::uyvy_from_fn(2, 1, |_, _| eotn::frame::Yuv::new(60, 60, 60))
        .unwrap()
        .to_rgb();
    assert_eq!(&png.as_raw()[..3], &first[..3]);
}

/// The inputs a command finds on its own are guarded as those it is given (one guard, which
/// every file read declares itself to): a rosbag2 folder's storage file and `metadata.yaml`,
/// the table and parameters a recording's `REC.cameras.json` names, and that sidecar itself.
/// Each refusal leaves the input byte for byte as it was.
#[test]
fn outputs_never_replace_the_inputs_a_command_finds_on_its_own() {
    let dir = tempfile::tempdir().unwrap();
    // A rosbag2 folder with MCAP storage (eotn's own stream as its storage file).
    let bag = dir.path().join("bag");
    std::fs::create_dir(&bag).unwrap();
    let storage = bag.join("bag_0.mcap");
    std::fs::copy(repo_file("streams/sim-ball-edge.mcap"), &storage).unwrap();
    let metadata = bag.join("metadata.yaml");
    std::fs::write(
        &metadata,
        "rosbag2_bagfile_information:\n  version: 5\n  storage_identifier: mcap\n  \
         relative_file_paths:\n    - bag_0.mcap\n  topics_with_message_count: []\n",
    )
    .unwrap();
    let info = eotn_ok(&["info".as_ref(), "--json".as_ref(), bag.as_os_str()]);
    let info: serde_json::Value = serde_json::from_slice(&info.stdout).unwrap();
    assert_eq!(info["frames"], 15, "the bag opens: {info}");
    let refused = |args: &[&OsStr], input: &Path| {
        let before = std::fs::read(input).unwrap();
        let err = fails(args);
        assert!(
            err.contains("would replace the input") && err.contains(&*input.to_string_lossy()),
            "{args:?}: {err}"
        );
        assert_eq!(std::fs::read(input).unwrap(), before, "{}", input.display());
    };
    for input in [&storage, &metadata] {
        refused(
            &[
                "import".as_ref(),
                bag.as_os_str(),
                "-o".as_ref(),
                input.as_os_str(),
            ],
            input,
        );
    }
    // A recording whose sidecar names its table and parameters; no --lut, no --params.
    let rec = dir.path().join("rec.mcap");
    std::fs::copy(repo_file("streams/sim-ball-edge.mcap"), &rec).unwrap();
    let (lut, params) = (dir.path().join("t.lut"), dir.path().join("p.json"));
    std::fs::copy(repo_file("lookup_tables/sim.lut"), &lut).unwrap();
    std::fs::write(&params, "{}\n").unwrap();
    let sidecar = dir.path().join("rec.mcap.cameras.json");
    std::fs::write(
        &sidecar,
        r#"{"cameras": {"/camera/image": {"lut": "t.lut", "params": "p.json"}}}"#,
    )
    .unwrap();
    eotn_ok(&["detect".as_ref(), "--json".as_ref(), rec.as_os_str()]);
    for input in [&lut, &params, &sidecar] {
        refused(
            &[
                "detect".as_ref(),
                rec.as_os_str(),
                "--annotate".as_ref(),
                input.as_os_str(),
            ],
            input,
        );
    }
}

/// A points file of the shipped overhead stream's landmarks, clicked with 1 px of noise.
fn overhead_points(dir: &Path) -> (PathBuf, serde_json::Value) {
    let points = dir.join("points.json");
    eotn_ok(&[
        "overhead".as_ref(),
        "sim-points".as_ref(),
        "--stream".as_ref(),
        repo_file("streams/sim-overhead-game.mcap").as_os_str(),
        "-o".as_ref(),
        points.as_os_str(),
    ]);
    let v = serde_json::from_slice(&std::fs::read(&points).unwrap()).unwrap();
    (points, v)
}

fn calibrate(points: &Path, out: &Path, extra: &[&str]) -> std::process::Output {
    let mut args: Vec<&OsStr> = vec![
        "overhead".as_ref(),
        "calibrate".as_ref(),
        "--points".as_ref(),
        points.as_os_str(),
        "-o".as_ref(),
        out.as_os_str(),
    ];
    args.extend(extra.iter().map(OsStr::new));
    eotn(&args)
}

#[test]
fn overhead_calibrate_refuses_degenerate_clicks_and_keeps_doubtful_fits_only_when_accepted() {
    let dir = tempfile::tempdir().unwrap();
    let (_, clean) = overhead_points(dir.path());
    let out = dir.path().join("cal.json");
    let bad = dir.path().join("bad.points.json");
    let refused = |edit: &dyn Fn(&mut serde_json::Value), expected: &str| {
        let mut v = clean.clone();
        edit(&mut v);
        std::fs::write(&bad, v.to_string()).unwrap();
        let o = calibrate(&bad, &out, &["--accept"]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "{expected}: {err}");
        assert!(err.contains(expected), "{expected}: {err}");
        assert!(!out.exists(), "{expected}: written anyway");
    };
    refused(
        &|v| {
            for p in v["points"].as_array_mut().unwrap() {
                p["field_cm"][0] = serde_json::json!(0.0);
            }
        },
        "lie on one line",
    );
    refused(
        &|v| {
            let first = v["points"][0].clone();
            v["points"].as_array_mut().unwrap().push(first);
        },
        "clicked twice",
    );
    refused(
        &|v| v["points"][3]["image_px"] = serde_json::json!([700.0, 20.0]),
        "outside the 640x480 image",
    );
    // Two clicks swapped: a fit, but two points far from where the camera puts them.
    let mut v = clean.clone();
    let (a, b) = (
        v["points"][0]["image_px"].clone(),
        v["points"][7]["image_px"].clone(),
    );
    v["points"][0]["image_px"] = b;
    v["points"][7]["image_px"] = a;
    std::fs::write(&bad, v.to_string()).unwrap();
    let o = calibrate(&bad, &out, &[]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success(), "{err}");
    assert!(err.contains("px from where the camera puts it"), "{err}");
    assert!(
        err.contains("not written") && err.contains("--accept"),
        "{err}"
    );
    assert!(!out.exists());
    let o = calibrate(&bad, &out, &["--accept"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(out.exists(), "--accept keeps it");
    // The field in millimetres against a description in centimetres: noted.
    let mut v = clean.clone();
    for p in v["points"].as_array_mut().unwrap() {
        for k in 0..2 {
            let x = p["field_cm"][k].as_f64().unwrap();
            p["field_cm"][k] = serde_json::json!(x * 10.0);
        }
    }
    std::fs::write(&bad, v.to_string()).unwrap();
    let o = calibrate(&bad, &dir.path().join("mm.json"), &[]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("outside the field description"), "{err}");
    assert!(!o.status.success(), "a camera 35 m up is doubtful: {err}");
}

#[test]
fn overhead_detect_stops_on_unusable_calibrations_other_shapes_and_robot_streams() {
    let dir = tempfile::tempdir().unwrap();
    let (points, _) = overhead_points(dir.path());
    let cal = dir.path().join("cal.json");
    let o = calibrate(&points, &cal, &[]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let lut = repo_file("lookup_tables/sim.lut");
    let detect = |frames: &Path, cal: &Path| {
        eotn(&[
            "overhead".as_ref(),
            "detect".as_ref(),
            frames.as_os_str(),
            "--lut".as_ref(),
            lut.as_os_str(),
            "--calibration".as_ref(),
            cal.as_os_str(),
        ])
    };
    // A robot camera's stream.
    let o = detect(&repo_file("streams/sim-ball-edge.mcap"), &cal);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && err.contains("a robot camera's stream"),
        "{err}"
    );
    // The overhead frame at half size (the same shape): scaled, with a warning.
    let frames = dir.path().join("frames");
    eotn_ok(&[
        "export".as_ref(),
        repo_file("streams/sim-overhead-game.mcap").as_os_str(),
        "--frames".as_ref(),
        "0".as_ref(),
        "-o".as_ref(),
        frames.as_os_str(),
    ]);
    let full = image::open(frames.join("sim-overhead-game_000000.raw.png")).unwrap();
    let half = dir.path().join("half.png");
    full.resize_exact(320, 240, image::imageops::FilterType::Triangle)
        .save(&half)
        .unwrap();
    let o = detect(&half, &cal);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    assert!(
        err.contains("is for 640x480 frames, these are 320x240"),
        "{err}"
    );
    // Another shape: stop.
    let wide = dir.path().join("wide.png");
    full.resize_exact(640, 360, image::imageops::FilterType::Triangle)
        .save(&wide)
        .unwrap();
    let o = detect(&wide, &cal);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && err.contains("another shape"),
        "{err}"
    );
    // A camera below the field: not usable.
    let mut v: serde_json::Value = serde_json::from_slice(&std::fs::read(&cal).unwrap()).unwrap();
    v["camera"]["pose"]["position_cm"][2] = serde_json::json!(-300.0);
    let below = dir.path().join("below.json");
    std::fs::write(&below, v.to_string()).unwrap();
    let o = detect(&half, &below);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && err.contains("not a usable calibration"),
        "{err}"
    );
    // eval's overhead options on a robot camera's stream.
    let o = eotn(&[
        "eval".as_ref(),
        repo_file("streams/sim-ball-edge.mcap").as_os_str(),
        "--lut".as_ref(),
        lut.as_os_str(),
        "--calibration".as_ref(),
        cal.as_os_str(),
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && err.contains("a robot camera's stream"),
        "{err}"
    );
}

/// Runs `f` on a thread and fails the test if it has not finished within `secs` seconds (a
/// FIFO opened for reading would wait for a writer for ever).
fn finishes_within<T: Send + 'static>(secs: u64, f: impl FnOnce() -> T + Send + 'static) -> T {
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let _ = tx.send(f());
    });
    rx.recv_timeout(Duration::from_secs(secs))
        .unwrap_or_else(|_| panic!("still waiting after {secs} s: something opened a FIFO"))
}

#[cfg(unix)]
#[test]
fn fifos_named_by_the_last_session_do_not_hang_the_app_at_start() {
    let dir = tempfile::tempdir().unwrap();
    let made = |name: &str| {
        let p = dir.path().join(name);
        assert!(Command::new("mkfifo").arg(&p).status().unwrap().success());
        p
    };
    let settings = eotn::workspace::Settings {
        last_table: Some(made("t.lut")),
        last_params: Some(made("p.json")),
        last_places: Some(made("places.json")),
        last_source: vec![made("s.mcap")],
        ..eotn::workspace::Settings::default()
    };
    let warnings = finishes_within(20, move || {
        let mut w = eotn::workspace::Workspace::new(settings);
        w.reopen_last();
        w.warnings().to_vec()
    });
    let all = warnings.join("\n");
    assert!(
        all.matches("not a regular file").count() >= 4,
        "each FIFO refused: {all}"
    );
    // The overhead files and a journal beside a table: the same.
    let points = made("x.points.json");
    let field = made("f.json");
    let cal = made("c.json");
    finishes_within(20, move || {
        assert!(eotn::overhead::PointsFile::load(&points).is_err());
        assert!(eotn::overhead::FieldDescription::load(&field).is_err());
        assert!(eotn::overhead::Calibration::load(&cal).is_err());
    });
    let table = dir.path().join("j.lut");
    std::fs::write(&table, vec![0u8; 1 << 18]).unwrap();
    let journal = eotn::workspace::journal::journal_path(&table);
    assert!(
        Command::new("mkfifo")
            .arg(&journal)
            .status()
            .unwrap()
            .success()
    );
    let err = finishes_within(20, move || {
        eotn::workspace::journal::replay(&table).unwrap_err()
    });
    assert!(format!("{err:#}").contains("not a regular file"), "{err:#}");
}

#[test]
fn a_stream_whose_frames_are_all_unreadable_is_not_imported_as_an_empty_one() {
    let dir = tempfile::tempdir().unwrap();
    let whole = std::fs::read(repo_file("streams/sim-ball-edge.mcap")).unwrap();
    // Every chunk's compressed bytes damaged: the summary and indexes stay readable.
    let mut bad = whole.clone();
    let mut damaged = 0;
    for i in (0..bad.len().saturating_sub(8)).step_by(4096) {
        // Inside the data section only (the first and last 5 % hold header and summary).
        if i > whole.len() / 20 && i < whole.len() * 19 / 20 {
            bad[i..i + 8].copy_from_slice(&[0xA5; 8]);
            damaged += 1;
        }
    }
    assert!(damaged > 10);
    let input = dir.path().join("damaged.mcap");
    std::fs::write(&input, &bad).unwrap();
    let out = dir.path().join("out.mcap");
    let err = fails(&[
        "import".as_ref(),
        input.as_os_str(),
        "-o".as_ref(),
        out.as_os_str(),
    ]);
    assert!(
        err.contains("none of its") && err.contains("nothing written"),
        "{err}"
    );
    assert!(!out.exists(), "an empty stream was written");
    assert!(
        !dir.path().join("out.mcap.partial").exists(),
        "its partial file stays"
    );
}

#[test]
fn info_reports_every_frame_size_of_a_stream_that_mixes_them() {
    let dir = tempfile::tempdir().unwrap();
    let frames = dir.path().join("frames");
    std::fs::create_dir(&frames).unwrap();
    for (name, w, h) in [("a.png", 64, 48), ("b.png", 64, 48), ("c.png", 32, 32)] {
        image::RgbImage::new(w, h).save(frames.join(name)).unwrap();
    }
    let stream = dir.path().join("mixed.mcap");
    eotn_ok(&[
        "import".as_ref(),
        frames.as_os_str(),
        "-o".as_ref(),
        stream.as_os_str(),
    ]);
    let out = eotn_ok(&["info".as_ref(), "--json".as_ref(), stream.as_os_str()]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["sizes"]["64x48"], 2, "{v}");
    assert_eq!(v["sizes"]["32x32"], 1, "{v}");
    // One size: no list.
    let one = eotn_ok(&[
        "info".as_ref(),
        "--json".as_ref(),
        repo_file("streams/sim-ball-edge.mcap").as_os_str(),
    ]);
    let v: serde_json::Value = serde_json::from_slice(&one.stdout).unwrap();
    assert!(v.get("sizes").is_none(), "{v}");
}

#[test]
fn overhead_calibrate_says_when_the_image_gives_no_lines_to_refine_along() {
    let dir = tempfile::tempdir().unwrap();
    let (points, _) = overhead_points(dir.path());
    // A grey frame of the right size: no painted line anywhere.
    let grey = dir.path().join("grey.png");
    image::RgbImage::from_pixel(640, 480, image::Rgb([90, 90, 90]))
        .save(&grey)
        .unwrap();
    let out = dir.path().join("cal.json");
    let o = calibrate(&points, &out, &["--image", grey.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    assert!(err.contains("line refinement skipped"), "{err}");
    let v: serde_json::Value = serde_json::from_slice(&std::fs::read(&out).unwrap()).unwrap();
    assert_eq!(v["line_samples"], 0, "{v}");
    // With the stream's own frame the lines are found and nothing is said.
    let frames = dir.path().join("frames");
    eotn_ok(&[
        "export".as_ref(),
        repo_file("streams/sim-overhead-game.mcap").as_os_str(),
        "--frames".as_ref(),
        "0".as_ref(),
        "-o".as_ref(),
        frames.as_os_str(),
    ]);
    let frame = frames.join("sim-overhead-game_000000.raw.png");
    let o = calibrate(&points, &out, &["--image", frame.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    assert!(!err.contains("line refinement skipped"), "{err}");
    let v: serde_json::Value = serde_json::from_slice(&std::fs::read(&out).unwrap()).unwrap();
    assert!(v["line_samples"].as_u64().unwrap() >= 10, "{v}");
}

/// Whole-table edits in the app: the undo history stays within its bound, the oldest steps go
/// with a note, and undoing as far as it reaches gives the table as it was after the last
/// dropped step.
#[test]
fn whole_table_edits_drop_the_oldest_undo_steps_with_a_note() {
    use eotn::lut::ColourClass;
    use eotn::lut::edit::MAX_HISTORY_BYTES;
    use eotn::workspace::{Command, HintsCommand, TableCommand, Workspace};
    let mut s = Workspace::default();
    s.apply(Command::from(TableCommand::NewTable(6))).unwrap();
    let all: Vec<usize> = (0..s.lut().cells().len()).collect();
    let class = |i: usize| [ColourClass::Orange, ColourClass::Green][i % 2];
    // 3.25 MiB a step (the cell list, 8 bytes a cell; old codes, 5): 100 steps would hold 325 MiB.
    // Cells selected as a coverage hint's are committed as the class chosen for them.
    for i in 0..100 {
        s.apply(Command::from(HintsCommand::SelectCells(all.clone())))
            .unwrap();
        s.apply(Command::from(TableCommand::SetClass(class(i))))
            .unwrap();
        s.apply(Command::from(TableCommand::Commit)).unwrap();
    }
    let h = s.history();
    let (kept, dropped) = (h.undo_len(), h.dropped());
    assert!(h.held_bytes() <= MAX_HISTORY_BYTES, "{}", h.held_bytes());
    assert!(dropped > 0 && kept + dropped == 100, "{kept} + {dropped}");
    let said = s.warnings().join("\n");
    assert!(said.contains("can no longer be undone"), "{said}");
    for _ in 0..kept {
        s.apply(Command::from(TableCommand::Undo)).unwrap();
    }
    assert!(
        s.apply(Command::from(TableCommand::Undo)).is_err(),
        "nothing older to undo"
    );
    let last_dropped = class(dropped - 1);
    assert_eq!(
        s.lut().class_counts()[usize::from(last_dropped.code())],
        all.len()
    );
}
