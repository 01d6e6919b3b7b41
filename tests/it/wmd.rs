//! `eotn wmd` on recordings: a simulated overhead game whose robots' world models carry known
//! errors (`eotn sim --world-model-error`, no noise), read back through the overhead camera's
//! own table and calibration. The robots' recordings are written here with the `mcap` crate
//! from the simulator's messages (a robot's own recording: `/world_model` only, on its clock).

use std::collections::BTreeMap;
use std::ffi::OsStr;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use eotn::model::GroundTruth;
use eotn::model::truth::OverheadTruth;
use eotn::streams::StreamReader;
use serde_json::Value;

use crate::common::{eotn, eotn_ok};

/// Robot 1: 30 cm, −40 cm off (50 cm), 10° turned, distances 10 % long. Robot 2: −20° turned.
const ERRORS: [&str; 2] = ["1:30,-40,10,10", "2:0,0,-20"];

pub struct Fixture {
    pub dir: tempfile::TempDir,
    pub stream: PathBuf,
    pub table: PathBuf,
    pub cal: PathBuf,
}

pub fn fixture() -> &'static Fixture {
    static FIXTURE: OnceLock<Fixture> = OnceLock::new();
    FIXTURE.get_or_init(|| {
        let dir = tempfile::tempdir().unwrap();
        let stream = dir.path().join("game.mcap");
        let mut args: Vec<&OsStr> = ["sim", "--scenario", "overhead-game", "--frames", "45"]
            .map(OsStr::new)
            .to_vec();
        args.extend(["--seed", "4", "--world-model-noise", "0"].map(OsStr::new));
        for e in ERRORS {
            args.extend([OsStr::new("--world-model-error"), OsStr::new(e)]);
        }
        args.extend([OsStr::new("-o"), stream.as_os_str()]);
        eotn_ok(&args);
        let table = dir.path().join("overhead.lut");
        let sim = eotn::sim::Simulator::new(eotn::sim::Scenario::new(
            eotn::sim::ScenarioKind::OverheadGame,
            99,
        ));
        let mut builder = eotn::lut::learn::TableBuilder::new(7).unwrap();
        for index in (0..300).step_by(30) {
            let f = sim.frame(index).unwrap();
            builder.add_frame(&f.frame, &f.labels).unwrap();
        }
        builder
            .build(&eotn::lut::learn::LearnParams::default())
            .save(&table)
            .unwrap();
        let points = dir.path().join("cam.points.json");
        let cal = dir.path().join("cam.json");
        eotn_ok(&[
            OsStr::new("overhead"),
            OsStr::new("sim-points"),
            OsStr::new("--stream"),
            stream.as_os_str(),
            OsStr::new("-o"),
            points.as_os_str(),
        ]);
        // The first frame, for the refinement along the field lines.
        let first = eotn::sim::Simulator::new(eotn::sim::Scenario::new(
            eotn::sim::ScenarioKind::OverheadGame,
            4,
        ))
        .frame(0)
        .unwrap();
        let png = dir.path().join("frame0.png");
        eotn::frame::save_rgb_png(&png, 640, 480, &first.frame.to_rgb()).unwrap();
        eotn_ok(&[
            OsStr::new("overhead"),
            OsStr::new("calibrate"),
            OsStr::new("--points"),
            points.as_os_str(),
            OsStr::new("-o"),
            cal.as_os_str(),
            OsStr::new("--image"),
            png.as_os_str(),
        ]);
        Fixture {
            dir,
            stream,
            table,
            cal,
        }
    })
}

/// One simulated frame: time, truth, world models (topic, message).
type SimFrame = (u64, OverheadTruth, Vec<(String, Value)>);

/// Every frame's truth and world models of the simulated stream.
fn frames() -> Vec<SimFrame> {
    let mut r = StreamReader::open(&fixture().stream).unwrap();
    (0..r.len())
        .map(|i| {
            let rec = r.read(i).unwrap();
            let GroundTruth::Overhead(t) =
                serde_json::from_value(rec.ground_truth.unwrap()).unwrap()
            else {
                panic!("overhead truth expected");
            };
            (rec.time_ns, *t, rec.extra)
        })
        .collect()
}

/// The marker robot `n` of the truth wears, as `(team, id)`.
pub fn marker_of(n: u32) -> (String, u64) {
    let (_, t, _) = &frames()[0];
    let m = t.robots.iter().find(|r| r.id == n).unwrap().marker.unwrap();
    (m.team.name().to_owned(), u64::from(m.identity.value()))
}

/// A robot's own recording: its world models on `/world_model`, each logged (and stamped,
/// `time_ns`) at `keep(t)` on its clock; `edit(t, message)` changes a message.
fn robot_recording(
    name: &str,
    robot: u32,
    keep: impl Fn(u64) -> Option<u64>,
    edit: impl Fn(u64, &mut Value),
) -> PathBuf {
    let path = fixture().dir.path().join(name);
    let file = std::io::BufWriter::new(std::fs::File::create(&path).unwrap());
    let mut w = mcap::Writer::new(file).unwrap();
    let channel = w
        .add_channel(0, "/world_model", "json", &BTreeMap::new())
        .unwrap();
    let topic = format!("/world_model/robot{robot}");
    for (sequence, (t, _, extra)) in frames().into_iter().enumerate() {
        let Some(log_time) = keep(t) else { continue };
        let (_, v) = extra.iter().find(|(k, _)| *k == topic).unwrap();
        let mut v = v.clone();
        assert_eq!(v["time_ns"], t, "the simulator stamps its world models");
        v["time_ns"] = log_time.into();
        edit(t, &mut v);
        let header = mcap::records::MessageHeader {
            channel_id: channel,
            sequence: u32::try_from(sequence).unwrap(),
            log_time,
            publish_time: log_time,
        };
        w.write_to_known_channel(&header, &serde_json::to_vec(&v).unwrap())
            .unwrap();
    }
    w.finish().unwrap();
    path
}

fn wmd(robots: &[&Path], extra: &[&str]) -> (Vec<Value>, String) {
    let f = fixture();
    let mut args: Vec<&OsStr> = vec![
        OsStr::new("wmd"),
        OsStr::new("--overhead"),
        f.stream.as_os_str(),
        OsStr::new("--lut"),
        f.table.as_os_str(),
        OsStr::new("--calibration"),
        f.cal.as_os_str(),
    ];
    for r in robots {
        args.extend([OsStr::new("--robot"), r.as_os_str()]);
    }
    args.extend(extra.iter().map(OsStr::new));
    let out = eotn_ok(&args);
    let lines = String::from_utf8_lossy(&out.stdout)
        .lines()
        .filter(|l| l.starts_with('{'))
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    (lines, String::from_utf8_lossy(&out.stderr).into_owned())
}

/// The world model of `(team, id)` in a line, and whether the overhead camera read that marker.
pub fn entry<'a>(line: &'a Value, who: &(String, u64)) -> (Option<&'a Value>, bool) {
    let is = |v: &&Value| v["team"] == who.0.as_str() && v["id"] == who.1;
    let model = line["world_models"].as_array().unwrap().iter().find(is);
    let seen = line["robots"].as_array().unwrap().iter().any(|r| is(&r));
    (model, seen)
}

#[test]
fn known_errors_come_out_matched_by_marker_in_every_frame() {
    let (lines, _) = wmd(&[&fixture().stream], &["--json"]);
    assert_eq!(lines.len(), 45);
    let one = marker_of(1);
    let two = marker_of(2);
    let mut seen_frames = 0;
    for line in &lines {
        for key in ["time_ns", "ball", "robots", "world_models"] {
            assert!(line.get(key).is_some(), "{key}: {line}");
        }
        let (model, seen) = entry(line, &one);
        let model = model.expect("robot 1 sends every frame");
        if !seen {
            continue;
        }
        seen_frames += 1;
        assert_eq!(model["matched"], "marker", "{model}");
        let p = model["position_error_cm"].as_f64().unwrap();
        assert!((p - 50.0).abs() < 8.0, "{p}");
        let h = model["heading_error_deg"].as_f64().unwrap();
        assert!((h - 10.0).abs() < 4.0, "{h}");
        for m in model["measurements"].as_array().unwrap() {
            if m["object"] == "ball" && line["ball"].is_null() {
                assert!(m["true_cm"].is_null(), "no ball seen from above: {m}");
                continue;
            }
            let (measured, truth) = (
                m["measured_cm"].as_f64().unwrap(),
                m["true_cm"].as_f64().unwrap(),
            );
            // 10 % long, against distances from the overhead camera's places (a few cm off).
            assert!((measured / truth - 1.1).abs() < 0.05, "{m}");
            assert!(m["bearing_error_deg"].as_f64().unwrap().abs() < 4.0, "{m}");
        }
        let (two_model, two_seen) = entry(line, &two);
        if two_seen {
            let two_model = two_model.unwrap();
            assert_eq!(two_model["matched"], "marker");
            assert!((two_model["heading_error_deg"].as_f64().unwrap() + 20.0).abs() < 4.0);
            assert!(two_model["position_error_cm"].as_f64().unwrap() < 8.0);
        }
    }
    assert!(
        seen_frames >= 40,
        "robot 1's marker read in {seen_frames} of 45 frames"
    );
    // The table per robot: medians and p95.
    let out = eotn_ok(&[
        OsStr::new("wmd"),
        OsStr::new("--overhead"),
        fixture().stream.as_os_str(),
        OsStr::new("--robot"),
        fixture().stream.as_os_str(),
        OsStr::new("--lut"),
        fixture().table.as_os_str(),
        OsStr::new("--calibration"),
        fixture().cal.as_os_str(),
    ]);
    let text = String::from_utf8_lossy(&out.stdout);
    let row = text
        .lines()
        .find(|l| l.starts_with(&format!("{} {} ", one.0, one.1)))
        .unwrap_or_else(|| panic!("{text}"));
    let median: f64 = row
        .split_whitespace()
        .nth(6)
        .unwrap()
        .split('/')
        .next()
        .unwrap()
        .parse()
        .unwrap();
    assert!((median - 50.0).abs() < 8.0, "{row}");
}

#[test]
fn a_robot_whose_marker_is_not_read_is_matched_by_position_and_says_so() {
    // Robot 1 names a marker no robot wears (as when its own is covered): its world model goes
    // to the nearest robot no world model claims — its own.
    let (team, id) = marker_of(1);
    let claimed: Vec<u64> = frames()[0]
        .1
        .robots
        .iter()
        .filter_map(|r| r.marker)
        .filter(|m| m.team.name() == team)
        .map(|m| u64::from(m.identity.value()))
        .collect();
    let free = (0..16).find(|i| !claimed.contains(i)).unwrap();
    let hidden = robot_recording("hidden.mcap", 1, Some, |_, v| {
        v["robot_id"] = free.into();
    });
    let (lines, _) = wmd(&[&hidden], &["--json"]);
    let mut by_position = 0;
    for line in &lines {
        let (model, _) = entry(line, &(team.clone(), free));
        let model = model.unwrap();
        let (_, seen) = entry(line, &(team.clone(), id));
        if seen {
            assert_eq!(model["matched"], "position", "{model}");
            assert_eq!(model["overhead_robot"]["id"], id);
            assert!((model["position_error_cm"].as_f64().unwrap() - 50.0).abs() < 8.0);
            by_position += 1;
        } else {
            assert_ne!(model["matched"], "marker");
        }
    }
    assert!(by_position >= 40, "{by_position}");
}

#[test]
fn a_clock_offset_is_found_and_shown() {
    // Robot 2's clock runs 0.4 s ahead of the overhead camera's.
    let ahead = robot_recording("ahead.mcap", 2, |t| Some(t + 400_000_000), |_, _| {});
    let (lines, stderr) = wmd(&[&ahead], &["--json"]);
    let two = marker_of(2);
    let line = stderr
        .lines()
        .find(|l| l.starts_with(&format!("{} {}: clock offset", two.0, two.1)))
        .unwrap_or_else(|| panic!("{stderr}"));
    let offset: f64 = line.split_whitespace().nth(4).unwrap().parse().unwrap();
    // Within three frames: a slow robot's dip is shallow, and offsets within 2 cm of the best
    // are taken nearer 0 (src/wmd/clock.rs).
    assert!((offset + 0.4).abs() <= 0.1, "{line}");
    let errors: Vec<f64> = lines
        .iter()
        .filter_map(|l| entry(l, &two).0)
        .filter_map(|m| m["position_error_cm"].as_f64())
        .collect();
    assert!(errors.len() >= 25, "{}", errors.len());
    assert!(errors.iter().all(|&e| e < 8.0), "{errors:?}");
    // Without the search the pairing is 0.4 s off: the errors grow with the robots' speed.
    let (lines, _) = wmd(&[&ahead], &["--json", "--max-clock-offset", "0"]);
    let off: Vec<f64> = lines
        .iter()
        .filter_map(|l| entry(l, &two).0)
        .filter_map(|m| m["position_error_cm"].as_f64())
        .collect();
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    assert!(mean(&off) > mean(&errors) + 5.0, "{off:?}");
}

#[test]
fn a_robot_that_stops_sending_is_listed_until_then_and_warned_about() {
    let stop = 700_000_000;
    let quiet = robot_recording("quiet.mcap", 2, |t| (t < stop).then_some(t), |_, _| {});
    let (lines, stderr) = wmd(&[&quiet, &fixture().stream], &["--json"]);
    let two = marker_of(2);
    for line in &lines {
        let t = line["time_ns"].as_u64().unwrap();
        let models = line["world_models"].as_array().unwrap();
        let twos = models
            .iter()
            .filter(|m| m["team"] == two.0.as_str() && m["id"] == two.1)
            .count();
        // Before the stop robot 2 is there (once: its own recording and the game's messages
        // are one robot); after it, the game's stream still carries it.
        assert_eq!(twos, 1, "{t}");
    }
    let (lines, stderr_alone) = wmd(&[&quiet], &["--json"]);
    let last = lines
        .iter()
        .filter(|l| entry(l, &two).0.is_some())
        .map(|l| l["time_ns"].as_u64().unwrap())
        .max()
        .unwrap();
    assert!(last < stop && last + 40_000_000 >= stop, "{last}");
    assert!(
        stderr_alone.contains("no world model after"),
        "{stderr_alone}"
    );
    assert!(!stderr.contains("no world model after"), "{stderr}");
}

#[test]
fn bad_world_models_are_skipped_with_a_reason_and_a_camera_device_is_no_robot() {
    let bad = robot_recording("bad.mcap", 1, Some, |_, v| v["team"] = "green".into());
    let f = fixture();
    let out = eotn(&[
        OsStr::new("wmd"),
        OsStr::new("--overhead"),
        f.stream.as_os_str(),
        OsStr::new("--robot"),
        bad.as_os_str(),
        OsStr::new("--lut"),
        f.table.as_os_str(),
        OsStr::new("--calibration"),
        f.cal.as_os_str(),
    ]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("unknown team"), "{err}");
    assert!(err.contains("no world model"), "{err}");
    let out = eotn(&[
        OsStr::new("wmd"),
        OsStr::new("--overhead"),
        f.stream.as_os_str(),
        OsStr::new("--robot"),
        OsStr::new("/dev/video99"),
        OsStr::new("--lut"),
        f.table.as_os_str(),
        OsStr::new("--calibration"),
        f.cal.as_os_str(),
    ]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("is a camera device"), "{err}");
}

#[test]
fn a_jump_in_a_robots_error_is_marked_once_where_it_happens() {
    // Robot 1 (50 cm off all along) is a further 150 cm off from 1 s on: one jump, there.
    let at = 1_000_000_000;
    let jumpy = robot_recording("jumpy.mcap", 1, Some, |t, v| {
        if t >= at {
            let x = v["self"]["x_cm"].as_f64().unwrap();
            v["self"]["x_cm"] = (x + 150.0).into();
        }
    });
    let (lines, _) = wmd(&[&jumpy], &["--json"]);
    let one = marker_of(1);
    let jumps: Vec<u64> = lines
        .iter()
        .filter(|l| entry(l, &one).0.is_some_and(|m| m["jump"] == true))
        .map(|l| l["time_ns"].as_u64().unwrap())
        .collect();
    assert!(!jumps.is_empty(), "no jump marked");
    // Marked at the first frame after the jump that reads its marker, and not again at once
    // (the 15-frame median catches up with the new error).
    assert!(jumps[0] >= at && jumps[0] < at + 200_000_000, "{jumps:?}");
    assert!(
        jumps.iter().all(|&t| t < at + 600_000_000),
        "jumps go on: {jumps:?}"
    );
    let before = lines
        .iter()
        .filter(|l| l["time_ns"].as_u64().unwrap() < at)
        .filter_map(|l| entry(l, &one).0)
        .all(|m| m["jump"] == false);
    assert!(before, "a jump marked before it happened");
}

/// A session file in the fixture's folder: the fixture's camera twice (ids 0 and 3, so every
/// robot is seen by both and merged into one), robot 1 from its own recording, robot 2 from the
/// game's stream (its other robots' world models left out).
fn session_file(robot1: &Path, extra_camera_keys: &str, field: &str) -> PathBuf {
    let f = fixture();
    let (one, two) = (marker_of(1), marker_of(2));
    let camera = |id: u8, extra: &str| {
        format!(
            r#"{{"id": {id}, "source": "{}", "lut": "{}", "calibration": "{}"{extra}}}"#,
            f.stream.display(),
            f.table.display(),
            f.cal.display()
        )
    };
    let json = format!(
        r#"{{"field": "{field}",
  "overhead": [{}, {}],
  "robots": [{{"team": "{}", "robot_id": {}, "source": "{}"}},
             {{"team": "{}", "robot_id": {}, "source": "{}", "lut": "{}"}}]}}"#,
        camera(0, ""),
        camera(3, extra_camera_keys),
        one.0,
        one.1,
        robot1.display(),
        two.0,
        two.1,
        f.stream.display(),
        f.table.display(),
    );
    let path = f.dir.path().join(format!("session-{field}.json"));
    std::fs::write(&path, json).unwrap();
    path
}

#[test]
fn a_session_file_merges_its_cameras_and_reads_each_robots_own_world_models() {
    let own = robot_recording("own1.mcap", 1, Some, |_, _| {});
    let cal = fixture().cal.display().to_string();
    let session = session_file(
        &own,
        &format!(r#", "intrinsics": "{cal}""#),
        "four-legged-2005",
    );
    let out = eotn_ok(&[
        OsStr::new("wmd"),
        OsStr::new("--session"),
        session.as_os_str(),
        OsStr::new("--json"),
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    // Keys the command does not use are said, never ignored silently.
    assert!(
        stderr.contains("overhead[1] (id 3): intrinsics"),
        "{stderr}"
    );
    assert!(
        stderr.contains("robots[1]") && stderr.contains("lut not used"),
        "{stderr}"
    );
    let lines: Vec<Value> = String::from_utf8_lossy(&out.stdout)
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(lines.len(), 45);
    let (one, two) = (marker_of(1), marker_of(2));
    let mut both = 0;
    for line in &lines {
        let cameras: Vec<u64> = line["cameras"]
            .as_array()
            .unwrap()
            .iter()
            .map(|c| c["id"].as_u64().unwrap())
            .collect();
        assert_eq!(cameras, [0, 3], "{line}");
        for r in line["robots"].as_array().unwrap() {
            assert_eq!(r["camera_ids"], serde_json::json!([0, 3]), "one robot: {r}");
        }
        let models = line["world_models"].as_array().unwrap();
        // Only the session's two robots, though the game's stream carries more.
        assert!(models.len() <= 2, "{models:?}");
        let (m1, seen1) = entry(line, &one);
        let (m2, _) = entry(line, &two);
        if let (Some(m1), true, Some(_)) = (m1, seen1, m2) {
            assert_eq!(m1["matched"], "marker");
            let p = m1["position_error_cm"].as_f64().unwrap();
            assert!((p - 50.0).abs() < 8.0, "{p}");
            both += 1;
        }
    }
    assert!(both >= 40, "both robots compared in {both} of 45 frames");
    // Every shipped field is a session's field (the session once knew only two).
    let session = session_file(&own, "", "ssl-div-a");
    let out = eotn(&[
        OsStr::new("wmd"),
        OsStr::new("--session"),
        session.as_os_str(),
        OsStr::new("--json"),
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!stderr.contains("not a shipped field"), "{stderr}");
}

/// An independent reader's view of a session recording: messages per topic, the scene
/// updates' entity ids and frame ids (the `mcap` and `mcap-protobuf-support` Python packages).
const READ_SESSION_PY: &str = r#"
import json, sys
from mcap.reader import make_reader
from mcap_protobuf.decoder import DecoderFactory
topics, ids, frames, scenes, ball_z = {}, set(), set(), 0, None
with open(sys.argv[1], "rb") as f:
    reader = make_reader(f, decoder_factories=[DecoderFactory()])
    for schema, channel, message in reader.iter_messages():
        topics[channel.topic] = topics.get(channel.topic, 0) + 1
    f.seek(0)
    reader = make_reader(f, decoder_factories=[DecoderFactory()])
    for schema, channel, message, scene in reader.iter_decoded_messages(topics=["/wmd/scene"]):
        assert schema.name == "foxglove.SceneUpdate", schema.name
        scenes += 1
        for e in scene.entities:
            ids.add(e.id)
            frames.add(e.frame_id)
            if e.id == "ball":
                ball_z = e.spheres[0].pose.position.z
print(json.dumps({"topics": topics, "ids": sorted(ids), "frames": sorted(frames),
                  "scenes": scenes, "ball_z": ball_z}))
"#;

#[test]
fn a_recorded_session_replays_to_the_same_lines_and_shows_in_foxglove_and_the_app() {
    let f = fixture();
    // Robot 2 (20° turned), its clock 0.3 s ahead: the offset found is baked into the recording.
    let own = robot_recording("own2.mcap", 2, |t| Some(t + 300_000_000), |_, _| {});
    let out_path = f.dir.path().join("recorded-session.mcap");
    let (lines, stderr) = wmd(&[&own], &["--json", "-o", out_path.to_str().unwrap()]);
    assert!(stderr.contains("45 field frames"), "{stderr}");
    assert!(!out_path.with_extension("mcap.partial").exists());
    // Replayed from the recording alone: the same lines (the world models were logged at the
    // frames they were paired with; the clock offset found is already in them).
    let again = eotn_ok(&[
        OsStr::new("wmd"),
        OsStr::new("--overhead"),
        out_path.as_os_str(),
        OsStr::new("--robot"),
        out_path.as_os_str(),
        OsStr::new("--lut"),
        f.table.as_os_str(),
        OsStr::new("--calibration"),
        f.cal.as_os_str(),
        OsStr::new("--json"),
    ]);
    let replayed: Vec<Value> = String::from_utf8_lossy(&again.stdout)
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(replayed.len(), lines.len());
    for (a, b) in lines.iter().zip(&replayed) {
        assert_eq!(a, b);
    }
    // The app's field view: the stream is an overhead camera's, names its table, and each frame
    // carries the world models the field model compares.
    let mut r = StreamReader::open(&out_path).unwrap();
    assert!(r.info().source.contains("overhead"), "{:?}", r.info());
    assert_eq!(
        r.camera_files().unwrap().lut.as_deref(),
        Some(f.table.as_path())
    );
    let rec = r.read(20).unwrap();
    let lut = eotn::lut::LookupTable::load(&f.table).unwrap();
    let cal = eotn::overhead::calibration::Calibration::load(&f.cal).unwrap();
    let mut pipeline = eotn::overhead::OverheadPipeline::new(
        lut,
        cal.camera,
        eotn::overhead::recognise::OverheadParams::default(),
    );
    let detections = pipeline.process(&rec.frame).clone();
    let mut model = eotn::workspace::field_model::FieldModel::default();
    let picture = eotn::overhead::merge::one_camera(eotn::session::SslCameraId(0), &detections);
    model.observe(20, rec.time_ns, Some(&picture), &rec.extra);
    assert!(
        model
            .world_models()
            .iter()
            .any(|w| w.matched == eotn::wmd::Matched::Marker),
        "{:?}",
        model.world_models()
    );
    // Foxglove: an independent reader finds the scene updates and decodes them.
    let Some(python) = crate::common::python_with_mcap() else {
        return;
    };
    let out = std::process::Command::new(python)
        .args(["-c", READ_SESSION_PY])
        .arg(&out_path)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let seen: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(seen["scenes"], 45);
    assert_eq!(seen["topics"]["/camera/image"], 45);
    assert_eq!(seen["topics"]["/wmd/frame"], 45);
    assert_eq!(seen["frames"], serde_json::json!(["field"]));
    let ids: Vec<&str> = seen["ids"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(Value::as_str)
        .collect();
    let one = marker_of(2);
    for want in [
        "field".to_owned(),
        "ball".to_owned(),
        format!("robot/{}/{}", one.0, one.1),
        format!("world_model/{}/{}", one.0, one.1),
    ] {
        assert!(ids.contains(&want.as_str()), "{want}: {ids:?}");
    }
    let topic = format!("/world_model/{}-{}", one.0, one.1);
    assert!(seen["topics"][&topic].as_u64().unwrap() >= 42, "{seen}");
    // The ball's sphere sits on the ground, in metres.
    assert!(
        (seen["ball_z"].as_f64().unwrap() - 0.0425).abs() < 1e-9,
        "{seen}"
    );
}

/// `eotn wmd --ssl-vision` sends what it compares: each overhead frame's ball and robots as
/// SSL-Vision packets (decoded by the independent reader of `ssl_vision.py`), at the positions
/// its `--json` lines print (≤ 1 mm apart), camera 0, numbered in order.
#[test]
fn wmd_sends_its_overhead_detections_as_ssl_vision_packets() {
    let Some(python) =
        crate::common::python_with("import struct, socket, json", "python3", "the SSL reader")
    else {
        return;
    };
    let f = fixture();
    let dir = tempfile::tempdir().unwrap();
    let (decoded, log) = (
        dir.path().join("decoded.json"),
        dir.path().join("received.log"),
    );
    let mut reader = std::process::Command::new(&python)
        .arg(crate::common::repo_file("tests/it/ssl_vision.py"))
        .args(["receive".as_ref(), decoded.as_os_str(), log.as_os_str()])
        .args(["45", "60"])
        .stdout(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let mut port = String::new();
    std::io::BufRead::read_line(
        &mut std::io::BufReader::new(reader.stdout.take().unwrap()),
        &mut port,
    )
    .unwrap();
    let target = format!("127.0.0.1:{}", port.trim());
    let (lines, stderr) = wmd(&[&f.stream], &["--json", "--ssl-vision", target.as_str()]);
    assert!(reader.wait().unwrap().success());
    assert!(stderr.contains("camera 0: distortion κ ="), "{stderr}");
    assert!(stderr.contains("45 detection and"), "{stderr}");
    let got: Value = serde_json::from_str(&std::fs::read_to_string(&decoded).unwrap()).unwrap();
    let sent = got["detections"].as_array().unwrap();
    assert_eq!(sent.len(), lines.len());
    let mm = |v: &Value, key: &str| v[key].as_f64().unwrap() * 10.0;
    let mut robots_compared = 0;
    for (k, (packet, line)) in sent.iter().zip(&lines).enumerate() {
        assert_eq!(packet["camera_id"], 0);
        assert_eq!(packet["frame_number"], k);
        match (&line["ball"], packet.get("balls")) {
            (Value::Null, None) => {}
            (b, Some(balls)) => {
                assert!((balls[0]["x"].as_f64().unwrap() - mm(b, "x_cm")).abs() <= 1.0);
                assert!((balls[0]["y"].as_f64().unwrap() - mm(b, "y_cm")).abs() <= 1.0);
            }
            (b, None) => panic!("frame {k}: ball {b} not sent"),
        }
        let mut by_key: BTreeMap<(String, u64), &Value> = BTreeMap::new();
        for (team, key) in [("blue", "robots_blue"), ("yellow", "robots_yellow")] {
            for r in packet
                .get(key)
                .and_then(Value::as_array)
                .into_iter()
                .flatten()
            {
                by_key.insert((team.to_owned(), r["robot_id"].as_u64().unwrap()), r);
            }
        }
        let printed = line["robots"].as_array().unwrap();
        assert_eq!(by_key.len(), printed.len(), "frame {k}");
        for r in printed {
            let key = (
                r["team"].as_str().unwrap().to_owned(),
                r["id"].as_u64().unwrap(),
            );
            let s = by_key[&key];
            assert!((s["x"].as_f64().unwrap() - mm(r, "x_cm")).abs() <= 1.0);
            assert!((s["y"].as_f64().unwrap() - mm(r, "y_cm")).abs() <= 1.0);
            robots_compared += 1;
        }
    }
    assert!(robots_compared >= 45, "{robots_compared} robots compared");
}
