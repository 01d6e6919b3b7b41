//! Several overhead cameras on one field (issue 31): the simulated rig, its session, the
//! benchmark and the merged detections.

use std::ffi::OsStr;
use std::path::{Path, PathBuf};

use eotn::model::GroundTruth;
use eotn::session::{Session, SessionSource, SslCameraId};

use crate::common::{eotn, eotn_ok};

/// `eotn overhead sim-field` of `cameras` small cameras into `dir`: its `SESSION.json`.
pub fn sim_field(dir: &Path, cameras: usize, size: &str, frames: usize, seed: u64) -> PathBuf {
    let (c, f, s) = (cameras.to_string(), frames.to_string(), seed.to_string());
    eotn_ok(&[
        OsStr::new("overhead"),
        OsStr::new("sim-field"),
        OsStr::new("--cameras"),
        OsStr::new(&c),
        OsStr::new("--size"),
        OsStr::new(size),
        OsStr::new("--frames"),
        OsStr::new(&f),
        OsStr::new("--seed"),
        OsStr::new(&s),
        OsStr::new("-o"),
        dir.as_os_str(),
    ]);
    dir.join("SESSION.json")
}

#[test]
fn the_simulated_field_is_a_session_of_cameras_with_their_own_tables_calibrations_and_truth() {
    let dir = tempfile::tempdir().unwrap();
    let path = sim_field(dir.path(), 2, "320x200", 3, 6);
    let session = Session::load(&path).unwrap();
    assert_eq!(session.overhead.len(), 2);
    let mut cameras = Vec::new();
    for (k, cam) in session.overhead.iter().enumerate() {
        assert_eq!(cam.id, SslCameraId(u8::try_from(k).unwrap()));
        let SessionSource::Recording(p) = &cam.source else {
            panic!("a recording expected");
        };
        let mut reader = eotn::streams::StreamReader::open(p).unwrap();
        assert_eq!(reader.len(), 3);
        let record = reader.read(2).unwrap();
        assert_eq!((record.frame.width(), record.frame.height()), (320, 200));
        let truth = serde_json::from_value::<GroundTruth>(record.ground_truth.unwrap()).unwrap();
        let GroundTruth::Overhead(t) = truth else {
            panic!("overhead truth expected");
        };
        assert!(t.robots.len() >= 4);
        let cal = eotn::overhead::Calibration::load(&cam.calibration).unwrap();
        // The solved camera is close to the true one.
        let d = t.camera.pose.position_cm[0] - cal.camera.pose.position_cm[0];
        assert!(d.abs() < 10.0, "camera {k}: {d} cm off in x");
        assert!(eotn::lut::LookupTable::load(&cam.lut).is_ok());
        cameras.push(t.camera);
    }
    assert_ne!(cameras[0], cameras[1]);
}

#[test]
fn a_rig_camera_beyond_1920x1200_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let out = eotn(&[
        OsStr::new("overhead"),
        OsStr::new("sim-field"),
        OsStr::new("--size"),
        OsStr::new("2000x1200"),
        OsStr::new("-o"),
        dir.path().as_os_str(),
    ]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("1920x1200"), "{err}");
}

/// `eotn overhead bench ARGS… --json` parsed.
fn bench_json(args: &[&OsStr]) -> serde_json::Value {
    let mut all = vec![OsStr::new("overhead"), OsStr::new("bench")];
    all.extend_from_slice(args);
    all.extend([
        OsStr::new("--seconds"),
        OsStr::new("0.2"),
        OsStr::new("--json"),
    ]);
    let out = eotn_ok(&all);
    serde_json::from_slice(&out.stdout).unwrap()
}

#[test]
fn the_bench_runs_a_whole_field_and_checks_it_against_the_truth() {
    let dir = tempfile::tempdir().unwrap();
    let session = sim_field(dir.path(), 2, "480x300", 2, 8);
    let j = bench_json(&[
        OsStr::new("--session"),
        session.as_os_str(),
        OsStr::new("--threads"),
        OsStr::new("2"),
    ]);
    for key in ["frames_per_s", "median_frame_ms", "p99_frame_ms"] {
        assert!(j[key].as_f64().unwrap() > 0.0, "{key}: {j}");
        assert!(j["one_thread"][key].as_f64().unwrap() > 0.0, "{key}: {j}");
    }
    assert_eq!(j["threads"], 2);
    assert_eq!(j["one_thread"]["threads"], 1);
    assert_eq!(
        (j["width"].as_u64(), j["height"].as_u64()),
        (Some(480), Some(300))
    );
    assert_eq!(j["cameras"], 2);
    assert_eq!(j["distinct_frames"], 4);
    assert!(j["stages"]["classify_ms"].as_f64().unwrap() > 0.0, "{j}");
    let acc = &j["accuracy"];
    let eligible = acc["robots_eligible"].as_u64().unwrap();
    assert!(eligible >= 4, "{acc}");
    // Small frames: most robots are found, and every one found is identified.
    let found = acc["robots_found"].as_u64().unwrap();
    assert!(4 * found >= 3 * eligible, "{acc}");
    assert_eq!(acc["identity_right"].as_u64(), Some(found), "{acc}");
    assert_eq!(acc["robots_false"], 0, "{acc}");
}

#[test]
fn the_bench_runs_one_cameras_frames_without_truth_and_refuses_bad_input() {
    let dir = tempfile::tempdir().unwrap();
    sim_field(dir.path(), 1, "320x200", 2, 9);
    let (mcap, lut, cal) = (
        dir.path().join("cam0.mcap"),
        dir.path().join("cam0.lut"),
        dir.path().join("cam0.cal.json"),
    );
    let j = bench_json(&[
        mcap.as_os_str(),
        OsStr::new("--lut"),
        lut.as_os_str(),
        OsStr::new("--calibration"),
        cal.as_os_str(),
        OsStr::new("--threads"),
        OsStr::new("1"),
    ]);
    assert_eq!(j["threads"], 1);
    assert_eq!(j["width"], 320);
    // Without --lut the frames cannot be read; a session naming a missing table is refused.
    let out = eotn(&[
        OsStr::new("overhead"),
        OsStr::new("bench"),
        mcap.as_os_str(),
        OsStr::new("--calibration"),
        cal.as_os_str(),
    ]);
    assert!(!out.status.success());
    let text = std::fs::read_to_string(dir.path().join("SESSION.json")).unwrap();
    let bad = dir.path().join("BAD.json");
    std::fs::write(&bad, text.replace("cam0.lut", "gone.lut")).unwrap();
    let out = eotn(&[
        OsStr::new("overhead"),
        OsStr::new("bench"),
        OsStr::new("--session"),
        bad.as_os_str(),
    ]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("overhead[0] (id 0)") && err.contains("gone.lut"),
        "{err}"
    );
}

/// The true robots of camera 0's first frame: `(team, id) → (x, y, heading)` (every robot of
/// the game is in every camera's truth).
fn true_robots(session: &Path) -> Vec<(String, u64, [f64; 3])> {
    let mut reader =
        eotn::streams::StreamReader::open(&session.with_file_name("cam0.mcap")).unwrap();
    let truth = reader.read(0).unwrap().ground_truth.unwrap();
    let GroundTruth::Overhead(t) = serde_json::from_value::<GroundTruth>(truth).unwrap() else {
        panic!("overhead truth expected");
    };
    t.robots
        .iter()
        .map(|r| {
            let m = r.marker.unwrap();
            (
                m.team.name().to_owned(),
                u64::from(m.identity.value()),
                [r.field_cm[0], r.field_cm[1], r.heading_rad],
            )
        })
        .collect()
}

#[test]
fn four_cameras_merge_into_one_field_picture_with_each_robot_once() {
    let dir = tempfile::tempdir().unwrap();
    let session = sim_field(dir.path(), 4, "640x400", 2, 12);
    let out = eotn_ok(&[
        OsStr::new("overhead"),
        OsStr::new("detect"),
        OsStr::new("--session"),
        session.as_os_str(),
        OsStr::new("--json"),
    ]);
    let lines: Vec<serde_json::Value> = String::from_utf8_lossy(&out.stdout)
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(lines.len(), 2, "one line per reference frame");
    let first = &lines[0];
    assert_eq!(first["time_ns"], 0);
    let cams = first["cameras"].as_array().unwrap();
    assert_eq!(cams.len(), 4, "{first}");
    let truth = true_robots(&session);
    let robots = first["robots"].as_array().unwrap();
    assert_eq!(robots.len(), truth.len(), "each robot once: {first}");
    let mut seen_twice = 0;
    for (team, id, [x, y, heading]) in &truth {
        let r = robots
            .iter()
            .find(|r| r["team"] == team.as_str() && r["id"] == *id)
            .unwrap_or_else(|| panic!("{team} {id} missing: {first}"));
        let err = (r["x_cm"].as_f64().unwrap() - x).hypot(r["y_cm"].as_f64().unwrap() - y);
        assert!(err < 3.0, "{team} {id}: {err} cm");
        let dh = (r["heading_rad"].as_f64().unwrap() - heading + std::f64::consts::PI)
            .rem_euclid(std::f64::consts::TAU)
            - std::f64::consts::PI;
        assert!(dh.abs().to_degrees() < 3.0, "{team} {id}: {dh} rad");
        seen_twice += usize::from(r["camera_ids"].as_array().unwrap().len() >= 2);
    }
    assert!(seen_twice >= 1, "no robot in an overlap: {first}");
    if let Some(b) = first["ball"].as_object() {
        assert!(!b["camera_ids"].as_array().unwrap().is_empty());
    }
}

#[test]
fn a_camera_that_stops_delivering_leaves_the_others_going() {
    let dir = tempfile::tempdir().unwrap();
    let session = sim_field(dir.path(), 2, "320x200", 3, 13);
    // Camera 1's recording ends after its first frame.
    let short = tempfile::tempdir().unwrap();
    sim_field(short.path(), 2, "320x200", 1, 13);
    std::fs::copy(short.path().join("cam1.mcap"), dir.path().join("cam1.mcap")).unwrap();
    let out = eotn_ok(&[
        OsStr::new("overhead"),
        OsStr::new("detect"),
        OsStr::new("--session"),
        session.as_os_str(),
        OsStr::new("--json"),
    ]);
    let counts: Vec<usize> = String::from_utf8_lossy(&out.stdout)
        .lines()
        .map(|l| {
            let v: serde_json::Value = serde_json::from_str(l).unwrap();
            v["cameras"].as_array().unwrap().len()
        })
        .collect();
    assert_eq!(counts, vec![2, 1, 1]);
}
