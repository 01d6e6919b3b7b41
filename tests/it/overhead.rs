//! The overhead side end to end: markers in the simulator, calibration from noisy clicks with
//! line refinement, recognition in field coordinates, the CLI (`eotn overhead …`, `eotn eval`
//! on overhead streams). The streams are rendered at test time.

use std::ffi::OsStr;
use std::path::Path;

use eotn::eval::overhead::{OverheadEvalParams, OverheadEvalReport, evaluate_overhead_frame};
use eotn::frame::save_rgb_png;
use eotn::geometry::{OverheadCamera, Point};
use eotn::lut::LookupTable;
use eotn::lut::learn::{LearnParams, TableBuilder};
use eotn::model::truth::{GroundTruth, OverheadTruth};
use eotn::overhead::{
    CalibrationParams, FieldDescription, OverheadParams, OverheadPipeline, calibrate,
};
use eotn::sim::{Scenario, ScenarioKind, SimFrame, Simulator};

use crate::common::{eotn_ok, sampled, sim_stream};

fn overhead_truth(f: &SimFrame) -> &OverheadTruth {
    match &f.ground_truth {
        GroundTruth::Overhead(t) => t,
        GroundTruth::Robot(_) => panic!("overhead view expected"),
    }
}

/// A table learnt from the labels of a few frames of another seed (as a user would build one
/// for their overhead camera).
fn overhead_table() -> LookupTable {
    let sim = Simulator::new(Scenario::new(ScenarioKind::OverheadGame, 99));
    let mut builder = TableBuilder::new(7).unwrap();
    for index in (0..300).step_by(30) {
        let f = sim.frame(index).unwrap();
        builder.add_frame(&f.frame, &f.labels).unwrap();
    }
    builder.build(&LearnParams::default())
}

/// Largest image distance (pixels) between two cameras' projections over the carpet, at the
/// heights that matter (ground, ball centre, plates), on a 20 cm grid inside the image.
fn projection_errors_px(a: &OverheadCamera, b: &OverheadCamera) -> Vec<f64> {
    let mut out = Vec::new();
    for z in [0.0, 4.25, 22.5] {
        for i in -15..=15 {
            for j in -10..=10 {
                let p = Point::new(f64::from(i) * 20.0, f64::from(j) * 20.0, z);
                if let (Some(u), Some(v)) = (a.image_from_field(&p), b.image_from_field(&p))
                    && u.x_px > 0.0
                    && u.y_px > 0.0
                    && u.x_px < 640.0
                    && u.y_px < 480.0
                {
                    out.push(u.distance_to(&v));
                }
            }
        }
    }
    out
}

#[test]
fn every_robot_of_the_overhead_game_wears_a_marker_with_its_truth() {
    let sim = Simulator::new(Scenario::new(ScenarioKind::OverheadGame, 6));
    let f = sim.frame(10).unwrap();
    let truth = overhead_truth(&f);
    assert!(truth.robots.len() >= 4);
    let mut seen = std::collections::HashSet::new();
    for r in &truth.robots {
        let m = r.marker.expect("a marker on every robot");
        assert_eq!(m.plate_height_cm, 22.5);
        assert!(
            seen.insert((m.team, m.identity)),
            "identities differ within a team"
        );
        if m.fully_visible() {
            // The team dot's colour shows at the plate's centre.
            let c = m.image.expect("in view");
            let k = (c.y_px as usize) * 640 + c.x_px as usize;
            assert_eq!(f.labels[k], m.team.class().code(), "robot {}", r.id);
        }
    }
    assert!(
        truth
            .robots
            .iter()
            .filter(|r| r.marker.unwrap().fully_visible())
            .count()
            >= 2
    );
}

/// The issue's figures on three seeds (three cameras): calibration from every visible landmark
/// clicked with 1 px noise, refined along the lines of the first frame; then ball and robots
/// over a few seconds of play.
#[test]
fn calibrated_from_noisy_clicks_the_overhead_recogniser_meets_the_figures() {
    let table = overhead_table();
    let field = FieldDescription::four_legged_2005();
    let (mut frames, mut reprojection) = (Vec::new(), Vec::new());
    for seed in [1, 2, 3] {
        let sim = Simulator::new(Scenario::new(ScenarioKind::OverheadGame, seed));
        let first = sim.frame(0).unwrap();
        let truth_camera = overhead_truth(&first).camera;
        let clicks = eotn::cli::overhead::simulated_clicks(&truth_camera, &field, 1.0, seed);
        let cal = calibrate(
            &clicks,
            &field,
            Some(&first.frame),
            &CalibrationParams::default(),
        )
        .unwrap();
        assert!(
            cal.line_samples > 100,
            "seed {seed}: {} line samples",
            cal.line_samples
        );
        let errors = projection_errors_px(&truth_camera, &cal.camera);
        let m = eotn::stats::median(&errors).unwrap();
        reprojection.push(m);
        let mut pipeline =
            OverheadPipeline::new(table.clone(), cal.camera, OverheadParams::default());
        for index in (0..300).step_by(15) {
            let f = sim.frame(index).unwrap();
            let d = pipeline.process(&f.frame).clone();
            frames.push(evaluate_overhead_frame(
                frames.len(),
                &d,
                overhead_truth(&f),
                &OverheadEvalParams::default(),
            ));
        }
    }
    let r = OverheadEvalReport::from_frames(&frames, &[]);
    eprintln!("reprojection medians {reprojection:?} px; {r:#?}");
    assert!(reprojection.iter().all(|m| *m < 0.5), "{reprojection:?}");
    assert!(
        r.ball_found as f64 >= 0.95 * r.ball_eligible as f64,
        "{r:?}"
    );
    // Limits at about 2.5× what is achieved (2026-12-04: ball median 0.45 cm, p95 1.5 cm, n = 58;
    // robots 0.27 cm, 0.54 cm, n = 363; headings 0.13°, n = 350; no false robot); the issue's
    // targets (3 cm, 8 cm, 3°) are far above.
    let ball = sampled(r.ball_error_cm, 30, "overhead ball errors");
    assert!(ball.p50 < 1.2 && ball.p95 < 4.0, "{ball:?}");
    let robots = sampled(r.robot_error_cm, 100, "overhead robot errors");
    assert!(robots.p50 < 0.7 && robots.p95 < 1.4, "{robots:?}");
    assert!(r.identity_rate.unwrap() >= 0.99, "{r:?}");
    let heading = sampled(r.heading_error_deg, 100, "overhead headings");
    assert!(heading.p50 < 0.35, "{heading:?}");
    assert_eq!(r.robots_false, 0, "{r:?}");
}

#[test]
fn the_overhead_command_line_calibrates_detects_and_evaluates() {
    let dir = tempfile::tempdir().unwrap();
    let stream = sim_stream(dir.path(), "overhead-game", 3, Some(4));
    // `eotn sim`'s overhead scene puts a marker on every robot, with its truth.
    let mut reader = eotn::streams::StreamReader::open(&stream).unwrap();
    for i in 0..reader.len() {
        let truth = reader.read(i).unwrap().ground_truth.unwrap();
        let GroundTruth::Overhead(t) = serde_json::from_value::<GroundTruth>(truth).unwrap() else {
            panic!("overhead truth expected");
        };
        assert!(t.robots.len() >= 4);
        assert!(t.robots.iter().all(|r| r.marker.is_some()), "frame {i}");
    }
    let points = dir.path().join("cam.points.json");
    eotn_ok(&[
        OsStr::new("overhead"),
        OsStr::new("sim-points"),
        OsStr::new("--stream"),
        stream.as_os_str(),
        OsStr::new("-o"),
        points.as_os_str(),
    ]);
    // The first frame as a PNG, for the line refinement and the drawing of the lines.
    let sim = Simulator::new(Scenario::new(ScenarioKind::OverheadGame, 4));
    let first = sim.frame(0).unwrap();
    let png = dir.path().join("frame0.png");
    save_rgb_png(&png, 640, 480, &first.frame.to_rgb()).unwrap();
    let cal = dir.path().join("cam.json");
    let out = eotn_ok(&[
        OsStr::new("overhead"),
        OsStr::new("calibrate"),
        OsStr::new("--points"),
        points.as_os_str(),
        OsStr::new("-o"),
        cal.as_os_str(),
        OsStr::new("--image"),
        png.as_os_str(),
    ]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("reprojection error per point"), "{text}");
    assert!(text.contains("centre circle left"), "{text}");
    // The fitted parameters: pose, focal length, principal point, distortion.
    for what in ["camera at (", "yaw", "focal", "principal point", "k1", "k2"] {
        assert!(text.contains(what), "{what}: {text}");
    }
    // The field lines over the frame, beside CAL.json: the frame with lines drawn on it.
    let drawn = image::open(dir.path().join("cam.lines.png"))
        .unwrap()
        .to_rgb8();
    assert_eq!(drawn.dimensions(), (640, 480));
    let plain = first.frame.to_rgb();
    let changed = drawn
        .as_raw()
        .chunks(3)
        .zip(plain.chunks(3))
        .filter(|(a, b)| a != b)
        .count();
    assert!(
        (1000..640 * 480 / 10).contains(&changed),
        "{changed} pixels drawn"
    );
    let lut = Path::new(env!("CARGO_MANIFEST_DIR")).join("lookup_tables/sim.lut");
    let table = dir.path().join("overhead.lut");
    overhead_table().save(&table).unwrap();
    let out = eotn_ok(&[
        OsStr::new("overhead"),
        OsStr::new("detect"),
        stream.as_os_str(),
        OsStr::new("--lut"),
        table.as_os_str(),
        OsStr::new("--calibration"),
        cal.as_os_str(),
        OsStr::new("--json"),
    ]);
    let lines: Vec<serde_json::Value> = String::from_utf8_lossy(&out.stdout)
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(lines.len(), 3);
    // Without --lut and --calibration: the ones the recording's sidecar names for its camera
    // (issue 28), the same detections.
    let sidecar = eotn::camera::sidecar_path(&stream);
    let named =
        serde_json::json!({"cameras": {"/camera/image": {"lut": table, "calibration": cal}}});
    std::fs::write(&sidecar, named.to_string()).unwrap();
    let out = eotn_ok(&[
        OsStr::new("overhead"),
        OsStr::new("detect"),
        stream.as_os_str(),
        OsStr::new("--json"),
    ]);
    let without_times = |text: &[u8]| -> Vec<serde_json::Value> {
        String::from_utf8_lossy(text)
            .lines()
            .map(|l| {
                let mut v: serde_json::Value = serde_json::from_str(l).unwrap();
                v.as_object_mut().unwrap().remove("overhead_us");
                v
            })
            .collect()
    };
    let mut explicit = lines.clone();
    for l in &mut explicit {
        l.as_object_mut().unwrap().remove("overhead_us");
    }
    assert_eq!(without_times(&out.stdout), explicit);
    std::fs::remove_file(&sidecar).unwrap();
    let line = &lines[0];
    let keys: Vec<&str> = line
        .as_object()
        .unwrap()
        .keys()
        .map(String::as_str)
        .collect();
    assert_eq!(keys, ["ball", "frame", "overhead_us", "robots"]);
    let robots = line["robots"].as_array().unwrap();
    assert!(!robots.is_empty());
    let robot_keys: Vec<&str> = robots[0]
        .as_object()
        .unwrap()
        .keys()
        .map(String::as_str)
        .collect();
    assert_eq!(
        robot_keys,
        ["confidence", "heading_rad", "id", "team", "x_cm", "y_cm"]
    );
    let team = robots[0]["team"].as_str().unwrap();
    assert!(team == "blue" || team == "yellow");
    if !line["ball"].is_null() {
        let ball_keys: Vec<&str> = line["ball"]
            .as_object()
            .unwrap()
            .keys()
            .map(String::as_str)
            .collect();
        assert_eq!(
            ball_keys,
            ["confidence", "image_px", "radius_px", "x_cm", "y_cm"]
        );
    }
    let out = eotn_ok(&[
        OsStr::new("eval"),
        stream.as_os_str(),
        OsStr::new("--lut"),
        table.as_os_str(),
        OsStr::new("--calibration"),
        cal.as_os_str(),
        OsStr::new("--json"),
    ]);
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let overhead = &report["overhead"];
    assert_eq!(overhead["frames"], 3);
    let models = overhead["world_models"].as_array().unwrap();
    assert!(models.len() >= 4);
    // Each robot's world model against the overhead detection of its marker, not only the truth.
    let seen: Vec<&serde_json::Value> = models
        .iter()
        .filter(|m| m["self_error_vs_overhead_cm"]["n"].as_u64().unwrap_or(0) > 0)
        .collect();
    assert!(seen.len() >= 2, "{overhead}");
    for m in &seen {
        assert!(
            m["heading_error_vs_overhead_deg"]["n"]
                .as_u64()
                .unwrap_or(0)
                > 0,
            "{m}"
        );
    }
    assert!(
        overhead["robot_error_cm"]["n"].as_u64().unwrap_or(0) >= 8,
        "{overhead}"
    );
    let robot_p50 = overhead["robot_error_cm"]["p50"].as_f64().unwrap();
    eprintln!("eval --json: robot error median {robot_p50:.2} cm");
    // About 2.5× what is achieved (2026-12-07: median 0.56 cm on these 3 frames of seed 4).
    assert!(robot_p50 < 1.4, "{overhead}");
    // The robot-camera table still reads the stream (the command is the same either way).
    eotn_ok(&[
        OsStr::new("eval"),
        stream.as_os_str(),
        OsStr::new("--lut"),
        lut.as_os_str(),
    ]);
}

#[test]
fn the_printable_marker_is_written_and_bad_ids_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let svg = dir.path().join("m.svg");
    eotn_ok(&[
        OsStr::new("overhead"),
        OsStr::new("marker"),
        OsStr::new("--team"),
        OsStr::new("blue"),
        OsStr::new("--id"),
        OsStr::new("5"),
        OsStr::new("-o"),
        svg.as_os_str(),
    ]);
    let text = std::fs::read_to_string(&svg).unwrap();
    assert!(text.starts_with("<svg") && text.contains("320mm"));
    let bad = crate::common::eotn(&[
        OsStr::new("overhead"),
        OsStr::new("marker"),
        OsStr::new("--team"),
        OsStr::new("blue"),
        OsStr::new("--id"),
        OsStr::new("16"),
        OsStr::new("-o"),
        svg.as_os_str(),
    ]);
    assert!(!bad.status.success());
    let err = String::from_utf8_lossy(&bad.stderr);
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.contains("0-15"), "{err}");
}

/// The printable markers shipped in `assets/markers/` are what `eotn overhead marker --all`
/// draws today (generated by the project, never edited by hand).
#[test]
fn the_shipped_markers_are_the_generated_ones() {
    let dir = tempfile::tempdir().unwrap();
    eotn_ok(&[
        OsStr::new("overhead"),
        OsStr::new("marker"),
        OsStr::new("--all"),
        OsStr::new("-o"),
        dir.path().as_os_str(),
    ]);
    let shipped = Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/markers");
    let mut names: Vec<String> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(names.len(), 32);
    assert_eq!(names[0], "blue-00.svg");
    for name in &names {
        let made = std::fs::read(dir.path().join(name)).unwrap();
        let ours = std::fs::read(shipped.join(name)).unwrap_or_default();
        assert!(
            made == ours,
            "assets/markers/{name} differs from the drawing: run \
             `eotn overhead marker --all -o assets/markers`"
        );
    }
    assert_eq!(std::fs::read_dir(&shipped).unwrap().count(), 32);
}

#[test]
fn a_points_file_with_too_few_points_fails_in_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let points = dir.path().join("few.points.json");
    std::fs::write(
        &points,
        r#"{"width": 640, "height": 480, "points": [{"name": "centre", "field_cm": [0, 0], "image_px": [320, 240]}]}"#,
    )
    .unwrap();
    let out = crate::common::eotn(&[
        OsStr::new("overhead"),
        OsStr::new("calibrate"),
        OsStr::new("--points"),
        points.as_os_str(),
        OsStr::new("-o"),
        dir.path().join("c.json").as_os_str(),
    ]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.contains("at least 6"), "{err}");
    assert!(!dir.path().join("c.json").exists());
    // Writing the calibration over its own points file is refused, the file kept.
    let before = std::fs::read(&points).unwrap();
    let out = crate::common::eotn(&[
        OsStr::new("overhead"),
        OsStr::new("calibrate"),
        OsStr::new("--points"),
        points.as_os_str(),
        OsStr::new("-o"),
        points.as_os_str(),
    ]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.contains("would replace the input"), "{err}");
    assert_eq!(std::fs::read(&points).unwrap(), before);
}
