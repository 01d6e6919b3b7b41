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
        let cal = eotn::overhead::Calibration::load(cam.calibration.as_deref().unwrap()).unwrap();
        // The solved camera is close to the true one.
        let d = t.camera.pose.position_cm[0] - cal.camera.pose.position_cm[0];
        assert!(d.abs() < 10.0, "camera {k}: {d} cm off in x");
        assert!(eotn::lut::LookupTable::load(cam.lut.as_deref().unwrap()).is_ok());
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
    if !args.contains(&OsStr::new("--floor")) {
        all.push(OsStr::new("--no-floor"));
    }
    let out = eotn_ok(&all);
    serde_json::from_slice(&out.stdout).unwrap()
}

#[test]
fn the_bench_runs_a_whole_field_and_checks_it_against_the_truth() {
    let dir = tempfile::tempdir().unwrap();
    let session = sim_field(dir.path(), 2, "480x300", 2, 8);
    let floor = crate::common::shared_file("bench/floors.c");
    let mut args = vec![
        OsStr::new("--session"),
        session.as_os_str(),
        OsStr::new("--threads"),
        OsStr::new("2"),
    ];
    if let Some(f) = &floor {
        args.extend([OsStr::new("--floor"), f.as_os_str()]);
    }
    let j = bench_json(&args);
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
    // Where a frame's time goes: every stage, recognition's parts within it.
    let st = &j["stages"];
    for key in [
        "classify_ms",
        "blobs_ms",
        "recognition_ms",
        "ball_ms",
        "markers_ms",
        "undistortion_ms",
        "points_to_image",
        "points_to_field",
        "merge_ms",
    ] {
        assert!(st[key].as_f64().unwrap() > 0.0, "{key}: {st}");
    }
    let parts = st["ball_ms"].as_f64().unwrap() + st["markers_ms"].as_f64().unwrap();
    assert!(
        parts <= 1.01 * st["recognition_ms"].as_f64().unwrap() + 0.01,
        "{st}"
    );
    for key in ["to_image_ns", "to_field_ns", "to_image_pose_per_point_ns"] {
        assert!(st["projection"][key].as_f64().unwrap() > 0.0, "{key}: {st}");
    }
    if floor.is_some() {
        let f = &j["floor"];
        for key in [
            "frame_copy_ms",
            "classify_ms",
            "blobs_ms",
            "pipeline_ms",
            "pipeline_ratio",
        ] {
            assert!(f[key].as_f64().unwrap() > 0.0, "{key}: {f}");
        }
    }
    // The merged pictures against the truth: every robot once, none twice.
    let field = &j["field_accuracy"];
    assert_eq!(field["cameras"], 2, "{field}");
    assert_eq!(field["duplicates"], 0, "{field}");
    let merged = &field["merged"];
    assert_eq!(merged["frames"], 2, "{field}");
    assert_eq!(merged["identity_right"], merged["robots_found"], "{field}");
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
    // Every camera's frame with its id, in session order (the cameras run in parallel), and its
    // own frame time: the reference's is the line's, the others' within half a period of it.
    for line in &lines {
        let t_ref = line["time_ns"].as_u64().unwrap();
        let cams = line["cameras"].as_array().unwrap();
        let ids: Vec<u64> = cams.iter().map(|c| c["id"].as_u64().unwrap()).collect();
        assert_eq!(ids, vec![0, 1, 2, 3], "{line}");
        for c in cams {
            let t = c["time_ns"]
                .as_u64()
                .unwrap_or_else(|| panic!("time_ns: {line}"));
            assert!(2 * t.abs_diff(t_ref) <= 13_333_334, "{line}");
        }
        assert_eq!(cams[0]["time_ns"].as_u64(), Some(t_ref));
    }
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

/// Limits of the merged pictures of `a_whole_field_is_scored_merged_against_the_truth`, about 3x
/// what its field gave (2026-12-07: ball median 0.52 cm, robots 0.10 cm, heading 0.08°).
const BALL_LIMIT_CM: f64 = 1.5;
const ROBOT_LIMIT_CM: f64 = 0.3;
const HEADING_LIMIT_DEG: f64 = 0.25;

#[test]
fn a_whole_field_is_scored_merged_against_the_truth() {
    let dir = tempfile::tempdir().unwrap();
    let session = sim_field(dir.path(), 4, "640x400", 3, 16);
    let out = eotn_ok(&[
        OsStr::new("eval"),
        OsStr::new("--session"),
        session.as_os_str(),
        OsStr::new("--json"),
    ]);
    let j: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let field = &j["field"];
    assert_eq!(field["cameras"], 4, "{j}");
    assert_eq!(j["field_frames"], 3, "{j}");
    let m = &field["merged"];
    let eligible = m["robots_eligible"].as_u64().unwrap();
    // Every robot of the game shows whole in some camera, and each is found once, identified.
    assert_eq!(eligible, 3 * true_robots(&session).len() as u64, "{m}");
    assert_eq!(m["robots_found"].as_u64(), Some(eligible), "{m}");
    assert_eq!(m["identity_right"].as_u64(), Some(eligible), "{m}");
    assert_eq!(m["robots_false"], 0, "{m}");
    assert_eq!(field["duplicates"], 0, "{field}");
    assert!(
        field["robots_seen_by_several"].as_u64().unwrap() >= 1,
        "{field}"
    );
    let p50 = |v: &serde_json::Value| v["p50"].as_f64().unwrap();
    assert!(p50(&m["heading_error_deg"]) < HEADING_LIMIT_DEG, "{m}");
    assert!(p50(&m["robot_error_cm"]) < ROBOT_LIMIT_CM, "{m}");
    if m["ball_eligible"].as_u64().unwrap() > 0 {
        assert_eq!(m["ball_found"], m["ball_eligible"], "{field}");
        assert!(p50(&m["ball_error_cm"]) < BALL_LIMIT_CM, "{m}");
    }
    assert_eq!(m["ball_false"], 0, "{m}");
    // The cameras alone, before merging, are scored beside it.
    assert!(
        field["per_camera"]["robots_eligible"].as_u64().unwrap() >= eligible,
        "{field}"
    );
    // A session brings its own tables: --lut beside it is refused.
    let out = eotn(&[
        OsStr::new("eval"),
        OsStr::new("--session"),
        session.as_os_str(),
        OsStr::new("--lut"),
        dir.path().join("cam0.lut").as_os_str(),
    ]);
    assert!(!out.status.success(), "--session with --lut is refused");
}

/// Field points on a 10 cm grid over the field and round it, centimetres.
fn field_grid() -> Vec<[f64; 2]> {
    (-40..=40)
        .flat_map(|i| (-30..=30).map(move |j| [f64::from(i) * 10.0, f64::from(j) * 10.0]))
        .collect()
}

/// Camera `k`'s true camera and frame size, from its recording's truth.
fn true_camera(session: &Session, k: usize) -> (eotn::geometry::OverheadCamera, usize, usize) {
    let SessionSource::Recording(p) = &session.overhead[k].source else {
        panic!("a recording expected");
    };
    let record = eotn::streams::StreamReader::open(p)
        .unwrap()
        .read(0)
        .unwrap();
    let GroundTruth::Overhead(t) =
        serde_json::from_value::<GroundTruth>(record.ground_truth.unwrap()).unwrap()
    else {
        panic!("overhead truth expected");
    };
    (t.camera, record.frame.width(), record.frame.height())
}

#[test]
fn a_session_opened_in_the_workspace_draws_each_cameras_coverage_and_who_saw_what() {
    use eotn::workspace::overhead::FrameState;
    use eotn::workspace::{Command, PlaybackCommand, Workspace};
    let dir = tempfile::tempdir().unwrap();
    let path = sim_field(dir.path(), 3, "320x200", 6, 6);
    // Camera 2 stops delivering after two frames: the same rig's camera 2, recorded shorter.
    let short = tempfile::tempdir().unwrap();
    sim_field(short.path(), 3, "320x200", 2, 6);
    let mut file: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    for (key, name) in [
        ("source", "cam2.mcap"),
        ("lut", "cam2.lut"),
        ("calibration", "cam2.cal.json"),
    ] {
        file["overhead"][2][key] = short.path().join(name).to_string_lossy().into();
    }
    std::fs::write(&path, file.to_string()).unwrap();
    let session = Session::load(&path).unwrap();

    let mut w = Workspace::default();
    w.apply(Command::Open(vec![path.clone()])).unwrap();
    let cameras = w.overhead().field_cameras();
    assert_eq!(cameras.session(), Some(path.as_path()));
    let shown = cameras.cameras();
    let ids: Vec<u8> = shown.iter().map(|c| c.id.0).collect();
    assert_eq!(ids, [0, 1, 2], "one entry per camera, the reference first");
    // Each camera's coverage holds the carpet points its true camera sees well inside its
    // frame, and none it sees well outside (the coverage is of its solved calibration).
    for (k, c) in shown.iter().enumerate() {
        let coverage = c.coverage.expect("every camera has its coverage");
        assert_eq!(coverage.camera, c.id);
        let (truth, width, height) = true_camera(&session, k);
        let margin = 0.1 * width as f64;
        let (mut inside, mut outside) = (0, 0);
        for p in field_grid() {
            let Some(q) = truth.image_from_field(&eotn::geometry::Point::new(p[0], p[1], 0.0))
            else {
                continue;
            };
            let within = |m: f64| {
                q.x_px > m && q.x_px < width as f64 - m && q.y_px > m && q.y_px < height as f64 - m
            };
            if within(margin) {
                inside += 1;
                assert!(coverage.contains(p), "camera {k} sees {p:?} at {q:?}");
            } else if !within(-margin) {
                outside += 1;
                assert!(
                    !coverage.contains(p),
                    "camera {k} does not see {p:?} ({q:?})"
                );
            }
        }
        assert!(
            inside > 50 && outside > 50,
            "camera {k}: {inside} in, {outside} out"
        );
        assert!(
            matches!(c.frame, FrameState::Current { .. }),
            "camera {k} at the first frame: {:?}",
            c.frame
        );
    }
    // Who saw what: every merged robot names the cameras that saw it, all of them current.
    let picture = cameras.picture().expect("a merged picture");
    assert!(picture.robots.len() >= 4, "{picture:?}");
    let mut seen_by: Vec<u8> = picture
        .robots
        .iter()
        .flat_map(|r| r.camera_ids.iter().map(|id| id.0))
        .collect();
    seen_by.sort_unstable();
    seen_by.dedup();
    assert!(
        seen_by.len() >= 2,
        "robots seen by several cameras: {seen_by:?}"
    );
    assert!(picture.robots.iter().all(|r| !r.camera_ids.is_empty()));

    // Past camera 2's last frame it is stale; the others go on.
    w.apply(PlaybackCommand::Seek(5).into()).unwrap();
    let shown = w.overhead().field_cameras().cameras();
    assert!(matches!(
        shown[0].frame,
        FrameState::Current { index: 5, .. }
    ));
    assert!(matches!(shown[1].frame, FrameState::Current { .. }));
    let FrameState::Stale { last_time_ns } = shown[2].frame else {
        panic!("camera 2 stopped delivering: {:?}", shown[2].frame);
    };
    let SessionSource::Recording(cam2) = &session.overhead[2].source else {
        panic!("a recording expected");
    };
    let cam2 = eotn::streams::StreamReader::open(cam2).unwrap();
    assert_eq!(last_time_ns, cam2.time_ns(1), "its last frame");
    let picture = w
        .overhead()
        .field_cameras()
        .picture()
        .expect("the others' picture");
    assert!(
        picture
            .robots
            .iter()
            .all(|r| r.camera_ids.iter().all(|id| id.0 != 2)),
        "a stale camera saw nothing of this field frame"
    );
}

#[test]
fn a_single_overhead_stream_has_one_cameras_coverage() {
    use eotn::workspace::overhead::FrameState;
    use eotn::workspace::{Command, Workspace};
    let stream = Path::new(env!("CARGO_MANIFEST_DIR")).join("streams/sim-overhead-game.mcap");
    let mut w = Workspace::default();
    w.apply(Command::Open(vec![stream])).unwrap();
    let cameras = w.overhead().field_cameras();
    assert_eq!(cameras.session(), None);
    let shown = cameras.cameras();
    assert_eq!(shown.len(), 1);
    assert!(matches!(
        shown[0].frame,
        FrameState::Current { index: 0, .. }
    ));
    let coverage = shown[0]
        .coverage
        .expect("the stream's own camera's coverage");
    let truth = w.overhead().truth().expect("the stream's truth");
    for r in truth.robots.iter().filter(|r| r.visible_pixels > 200) {
        assert!(
            coverage.contains(r.field_cm),
            "robot {} at {:?}",
            r.id,
            r.field_cm
        );
    }
    let picture = cameras.picture().expect("the camera's picture");
    assert!(!picture.robots.is_empty());
    assert!(
        picture
            .robots
            .iter()
            .all(|r| r.camera_ids == [SslCameraId(0)])
    );
}
