//! Recordings as teams make them today, written by tools that are not eotn's (`rosbags`,
//! `mcap-ros2-support`, the Foxglove SDK; `recordings.py`) from the same 24 frames of the real
//! B-Human stream: every one opens, and recognition on it equals recognition on the original
//! UYVY frames (ball centre within 0.5 px for lossless encodings, 1.5 px for JPEG and nv12, 2 px
//! for Bayer); mono8 opens with every frame. Also `eotn import` of them, and a live server sending
//! ROS 2 `cdr` channels as foxglove_bridge does.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::OnceLock;

use eotn::live::{ClientOptions, LiveRobot, RobotUrl};
use eotn::streams::StreamReader;

use crate::common::{eotn, eotn_ok, python_with};
use crate::live::{free_port, wait_for};

/// Frames taken from the stream.
const FRAMES: usize = 24;

#[derive(Debug, Clone)]
pub(crate) struct Recording {
    pub(crate) name: String,
    pub(crate) path: PathBuf,
    /// What its frames must match: exact, jpeg, nv12, bayer, grey, pose.
    matches: String,
}

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn script() -> PathBuf {
    root().join("tests/it/recordings.py")
}

fn source() -> PathBuf {
    root().join("streams/bhuman2009.mcap")
}

/// A python with the three writers and OpenCV, or `None` (skipped, outside CI).
fn writers_python() -> Option<PathBuf> {
    python_with(
        "import rosbags, mcap_ros2, foxglove, cv2, mcap_protobuf",
        "rosbags, mcap-ros2-support, foxglove-sdk and opencv-python-headless",
        "the third-party recordings tests",
    )
}

/// A rosbag2 folder written by `rosbags` (MCAP storage, `rgb8` images) with
/// `sensor_msgs/msg/JointState` (`HeadYaw` 0.1, `HeadPitch` 0.2 rad) on `/joint_states` with
/// every frame; `None` (a skip line) without the writers, outside CI.
#[cfg(feature = "gui")]
pub(crate) fn joint_state_bag() -> Option<PathBuf> {
    let (_, list) = recordings()?;
    list.iter()
        .find(|r| r.name == "rosbag2 mcap sensor_msgs/Image rgb8 step+0")
        .map(|r| r.path.clone())
}

/// The recordings, written once for all tests of this file.
fn recordings() -> Option<&'static (tempfile::TempDir, Vec<Recording>)> {
    static MADE: OnceLock<Option<(tempfile::TempDir, Vec<Recording>)>> = OnceLock::new();
    crate::common::made_once(&MADE, "the third-party recordings", || {
        let python = writers_python()?;
        let dir = tempfile::tempdir().unwrap();
        let out = Command::new(python)
            .arg(script())
            .arg(source())
            .arg(FRAMES.to_string())
            .arg(dir.path())
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "recordings.py: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let manifest: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        let list = manifest
            .as_array()
            .unwrap()
            .iter()
            .map(|r| Recording {
                name: r["name"].as_str().unwrap().to_owned(),
                path: PathBuf::from(r["path"].as_str().unwrap()),
                matches: r["match"].as_str().unwrap().to_owned(),
            })
            .collect();
        Some((dir, list))
    })
}

/// Ball centres of `eotn detect --json` on `path`, one per frame (`None`: no ball).
fn ball_centres(path: &Path) -> Vec<Option<(f64, f64)>> {
    let out = eotn_ok(&[
        "detect".as_ref(),
        "--json".as_ref(),
        "--lut".as_ref(),
        root().join("lookup_tables/bhuman2009.lut").as_os_str(),
        "--params".as_ref(),
        root().join("params/spl2009.json").as_os_str(),
        path.as_os_str(),
    ]);
    String::from_utf8_lossy(&out.stdout)
        .lines()
        .map(|l| {
            let v: serde_json::Value = serde_json::from_str(l).unwrap();
            let b = &v["ball"];
            b["center_x"].as_f64().zip(b["center_y"].as_f64())
        })
        .collect()
}

fn info(path: &Path) -> serde_json::Value {
    let out = eotn_ok(&["info".as_ref(), "--json".as_ref(), path.as_os_str()]);
    serde_json::from_slice(&out.stdout).unwrap()
}

#[test]
fn every_recording_opens_and_recognition_matches_the_original_frames() {
    let Some((_, list)) = recordings() else {
        return;
    };
    let reference = ball_centres(&list[0].path);
    let found = reference.iter().filter(|b| b.is_some()).count();
    assert!(found >= FRAMES * 3 / 4, "the reference finds {found} balls");
    let (mut report, mut lost_to_pose) = (Vec::new(), Vec::new());
    for r in list {
        let i = info(&r.path);
        assert_eq!(i["frames"], FRAMES, "{}: {i}", r.name);
        let balls = ball_centres(&r.path);
        assert_eq!(balls.len(), FRAMES, "{}", r.name);
        if r.matches == "grey" {
            let warnings = i["warnings"].to_string();
            assert!(
                warnings.contains("cannot classify"),
                "{}: {warnings}",
                r.name
            );
            continue;
        }
        let limit = match r.matches.as_str() {
            "exact" | "pose" => 0.5,
            "jpeg" | "nv12" => 1.5,
            "bayer" => 2.0,
            other => panic!("unknown match {other}"),
        };
        let mut worst = 0.0f64;
        for (k, (a, b)) in reference.iter().zip(&balls).enumerate() {
            match (a, b) {
                (Some(a), Some(b)) => worst = worst.max((a.0 - b.0).hypot(a.1 - b.1)),
                // With a camera pose from /tf_static the ball's height above the ground is
                // tested, and the pose recordings.py gives (25 cm up, level) is not the Nao's:
                // a ball lost there must be lost to that test alone.
                (Some(a), None) if r.matches == "pose" => {
                    assert_lost_to_the_height_test_alone(&r.path, k, *a);
                    lost_to_pose.push(format!("{} frame {k}", r.name));
                }
                (a, b) => panic!(
                    "{}: frame {k}: ball {a:?} in the original, {b:?} here",
                    r.name
                ),
            }
        }
        assert!(
            worst <= limit,
            "{}: a ball centre {worst:.2} px off",
            r.name
        );
        report.push(format!("{}: {worst:.2} px", r.name));
    }
    eprintln!(
        "largest ball-centre difference per recording:\n{}\nballs lost to the /tf_static \
         pose's height test: {lost_to_pose:?}",
        report.join("\n")
    );
    // 2026-12-07: frames 13, 14, 21 and 23 of each pose recording (balls low in the image,
    // cut by its bottom edge, whose centre the level camera 25 cm up puts under the ground).
    assert!(lost_to_pose.len() <= 8, "{lost_to_pose:?}");
}

/// Asserts that frame `k` of `path`, whose ball the original frames show at `original`, has a
/// ball candidate there that fails the height-above-ground test (which only a camera pose
/// enables) and would have been accepted without it.
fn assert_lost_to_the_height_test_alone(path: &Path, k: usize, original: (f64, f64)) {
    use eotn::recognition::confidence::{TestName, TestOutcome};
    let lut = eotn::lut::LookupTable::load(&root().join("lookup_tables/bhuman2009.lut")).unwrap();
    let params = eotn::pipeline::PipelineParams {
        recognition: eotn::recognition::params_file::load(&root().join("params/spl2009.json"))
            .unwrap(),
        ..Default::default()
    };
    let record = StreamReader::open(path).unwrap().read(k).unwrap();
    assert!(
        record.sensors.is_some(),
        "frame {k}: the pose reached the readings"
    );
    let mut pipeline = eotn::pipeline::Pipeline::new(lut, params);
    let result = pipeline.process(&record.frame, record.sensors.as_ref());
    let explained = result.recognition.ball.candidates.iter().any(|c| {
        let at = (c.center.x_px - original.0).hypot(c.center.y_px - original.1) <= 2.0;
        let height = c
            .confidence
            .tests
            .iter()
            .find(|t| t.test == TestName::HeightCm && t.outcome == TestOutcome::Failed);
        at && height.is_some_and(|h| c.confidence.total - h.effect > 0.0)
    });
    assert!(
        explained,
        "{} frame {k}: the ball at {original:?} lost to something else than the pose's height \
         test: {:#?}",
        path.display(),
        result.recognition.ball.candidates
    );
}

#[test]
fn a_camera_pose_from_tf_static_and_the_calibration_reach_the_readings() {
    let Some((_, list)) = recordings() else {
        return;
    };
    for r in list.iter().filter(|r| r.matches == "pose") {
        let mut reader = StreamReader::open(&r.path).unwrap();
        let s = reader
            .read(3)
            .unwrap()
            .sensors
            .expect("readings from /tf_static");
        // recordings.py: the optical frame 25 cm above base_footprint, looking level.
        assert!(
            (s.camera_height_cm.unwrap() - 25.0).abs() < 1e-6,
            "{}: {s:?}",
            r.name
        );
        assert!(
            s.camera_pitch_rad.unwrap().abs() < 1e-9,
            "{}: {s:?}",
            r.name
        );
        // recordings.py: CameraInfo with fx = 200 px, calibrated at the frame's size.
        assert_eq!(s.camera_focal_px, Some(200.0), "{}: {s:?}", r.name);
    }
}

#[test]
fn import_keeps_each_image_message_unchanged_with_its_channels() {
    let Some((dir, list)) = recordings() else {
        return;
    };
    for r in list.iter().filter(|r| r.matches != "reference") {
        let out = dir.path().join(format!(
            "imported_{}.mcap",
            r.name.replace(|c: char| !c.is_ascii_alphanumeric(), "_")
        ));
        eotn_ok(&[
            "import".as_ref(),
            r.path.as_os_str(),
            "-o".as_ref(),
            out.as_os_str(),
        ]);
        let mut original = StreamReader::open(&r.path).unwrap();
        let mut imported = StreamReader::open(&out).unwrap();
        assert_eq!(imported.len(), FRAMES, "{}", r.name);
        for i in [0, FRAMES - 1] {
            let (a, ia) = original.read_with_image(i).unwrap();
            let (b, ib) = imported.read_with_image(i).unwrap();
            assert_eq!(a.frame, b.frame, "{} frame {i}", r.name);
            assert_eq!(a.sensors, b.sensors, "{} frame {i}", r.name);
            let channels = |rec: &eotn::streams::FrameRecord| {
                rec.extra
                    .iter()
                    .map(|(t, v)| (t.clone(), v.clone()))
                    .collect::<Vec<_>>()
            };
            assert_eq!(channels(&a), channels(&b), "{} frame {i}", r.name);
            let plain_422 = ["uyvy", "yuyv", "yuv422", "yuv422_yuy2"].contains(&ia.encoding());
            if !plain_422 {
                assert_eq!(ia.body, ib.body, "{} frame {i}: image changed", r.name);
            }
        }
    }
}

#[test]
fn folders_that_are_not_bags_and_unknown_encodings_say_so() {
    // An image encoding eotn does not know (`8UC3`, OpenCV's name for 3 bytes a pixel, written
    // over `rgb8` in every image of a `rosbags` recording) is named with the known ones, by the
    // command a user runs.
    if let Some((dir, list)) = recordings() {
        let unknown = dir.path().join("encoding_8uc3.mcap");
        copy_mcap_editing_images(&rgb8_storage_file(list), &unknown, |_, data| {
            let rgb8 = b"\x05\x00\x00\x00rgb8\x00";
            let at = data
                .windows(rgb8.len())
                .position(|w| w == rgb8)
                .expect("the encoding field");
            data[at + 4..at + 8].copy_from_slice(b"8UC3");
        });
        let out = eotn(&[
            "detect".as_ref(),
            "--lut".as_ref(),
            root().join("lookup_tables/bhuman2009.lut").as_os_str(),
            unknown.as_os_str(),
        ]);
        let err = String::from_utf8_lossy(&out.stderr);
        eprintln!("detect on 8UC3 images: {:?}\n{err}", out.status);
        assert!(
            err.contains("8UC3") && err.contains("bayer_rggb8") && err.contains("rgb8"),
            "{err}"
        );
    }
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("notes.txt"), "x").unwrap();
    let out = eotn(&["info".as_ref(), dir.path().as_os_str()]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("not a rosbag2 bag"), "{err}");
    let out = eotn(&[
        "detect".as_ref(),
        "--lut".as_ref(),
        root().join("lookup_tables/sample.lut").as_os_str(),
        dir.path().as_os_str(),
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && err.contains("metadata.yaml"),
        "{err}"
    );
}

/// A foxglove_bridge-style server (the Foxglove SDK's, sending `rosbags`-serialised ROS 2
/// messages as `cdr` channels with `ros2msg` schemas) is watched and recorded bit-exact.
#[test]
fn a_ros2_bridge_sending_cdr_is_watched_and_recorded_bit_exact() {
    let Some((dir, list)) = recordings() else {
        return;
    };
    let Some(python) = writers_python() else {
        return;
    };
    let port = free_port();
    let mut server = Command::new(python)
        .arg(script())
        .arg("--serve")
        .arg(source())
        .arg(FRAMES.to_string())
        .arg(port.to_string())
        .stdout(Stdio::null())
        .spawn()
        .unwrap();
    let url: RobotUrl = format!("ws://127.0.0.1:{port}").parse().unwrap();
    let options = ClientOptions {
        backoff_min: std::time::Duration::from_millis(100),
        ..ClientOptions::default()
    };
    let robot = LiveRobot::connect(url, options, 1 << 26, None).unwrap();
    let recording = dir.path().join("live_cdr.mcap");
    let connected = wait_for(30.0, || robot.len() >= 2);
    robot.start_recording(&recording).unwrap();
    let start = robot.len();
    let got = wait_for(30.0, || robot.len() >= start + FRAMES);
    let (path, frames) = robot.stop_recording().unwrap().unwrap();
    let _ = server.kill();
    let _ = server.wait();
    assert!(
        connected && got,
        "frames {}; log {:?}",
        robot.len(),
        robot.log()
    );
    assert!(frames >= FRAMES, "{frames} recorded");
    // Live frames are the rgb8 bag's frames.
    let rgb8 = list
        .iter()
        .find(|r| r.name.contains("mcap sensor_msgs/Image rgb8"))
        .unwrap();
    let mut bag = StreamReader::open(&rgb8.path).unwrap();
    let bag_frames: Vec<_> = (0..FRAMES).map(|i| bag.read(i).unwrap().frame).collect();
    let live = robot.frame(start).unwrap();
    assert!(
        bag_frames.contains(&live.record.frame),
        "a live frame is none of the bag's"
    );
    assert!(
        live.record.extra.iter().any(|(t, _)| t == "/joint_states"),
        "{:?}",
        live.record.extra
    );
    // The bridge's CameraInfo reaches the readings recognition uses.
    assert_eq!(
        live.record.sensors.and_then(|s| s.camera_focal_px),
        Some(200.0)
    );
    // Bit-exact: every recorded image payload is one the bag's writer serialised.
    let payloads = |p: &Path, topic: &str| -> Vec<Vec<u8>> {
        let bytes = std::fs::read(p).unwrap();
        mcap::MessageStream::new(&bytes)
            .unwrap()
            .filter_map(Result::ok)
            .filter(|m| m.channel.topic == topic)
            .map(|m| m.data.into_owned())
            .collect()
    };
    let bag_file = std::fs::read_dir(&rgb8.path)
        .unwrap()
        .filter_map(Result::ok)
        .map(|e| e.path())
        .find(|p| p.extension().is_some_and(|e| e == "mcap"))
        .unwrap();
    let sent = payloads(&bag_file, "/camera/image_raw");
    let recorded = payloads(&path, "/camera/image_raw");
    assert!(recorded.len() >= FRAMES, "{} recorded", recorded.len());
    assert!(
        recorded.iter().all(|p| sent.contains(p)),
        "a recorded payload changed"
    );
    let mut reread = StreamReader::open(&path).unwrap();
    assert_eq!(reread.len(), recorded.len());
    assert!(bag_frames.contains(&reread.read(0).unwrap().frame));
}

/// Real bags written by the C++ rosbag2 (its own test bags, `tests/data/rosbag2/`: SQLite and
/// MCAP storage, `metadata.yaml` versions 4 to 6), given as a user would — the folder, its
/// `metadata.yaml`, its storage file alone — to `info`, `detect`, `eval`, `import` and the app's
/// Open: each is read as a bag whose topics are named (they hold no images, so each says that it
/// has no camera image topic), never as a folder of frames or a lookup table.
#[test]
fn real_rosbag2_bags_open_as_recordings_in_every_command() {
    let bags = root().join("tests/data/rosbag2");
    let lut = root().join("lookup_tables/sample.lut");
    let not_as = |what: &str, text: &str| {
        for wrong in [
            "lookup table",
            "lookup-table",
            "frame file",
            "no frames found",
        ] {
            assert!(!text.contains(wrong), "{what} read as {wrong}: {text}");
        }
    };
    let mut checked = 0;
    for entry in std::fs::read_dir(&bags).unwrap() {
        let folder = entry.unwrap().path();
        if !folder.is_dir() {
            continue;
        }
        let storage = std::fs::read_dir(&folder)
            .unwrap()
            .map(|e| e.unwrap().path())
            .find(|p| p.extension().is_some_and(|e| e == "db3" || e == "mcap"))
            .unwrap();
        let meta = std::fs::read_to_string(folder.join("metadata.yaml")).unwrap();
        for given in [folder.clone(), folder.join("metadata.yaml"), storage] {
            let what = given.display().to_string();
            // info: a stream of 0 frames, its topics named, the missing image said.
            let i = info(&given);
            assert_eq!(i["kind"], "stream", "{what}: {i}");
            assert_eq!(i["frames"], 0, "{what}: {i}");
            // MCAP storage says these as notes (facts, not problems), SQLite as warnings.
            let warnings = format!("{} {}", i["warnings"], i["notes"]);
            assert!(warnings.contains("no camera image"), "{what}: {warnings}");
            let first_topic = meta
                .lines()
                .find_map(|l| l.trim().strip_prefix("name: "))
                .unwrap();
            assert!(warnings.contains(first_topic), "{what}: {warnings}");
            not_as(&what, &warnings);
            // detect and eval: a clear refusal about frames.
            for args in [
                vec![
                    "detect".as_ref(),
                    "--lut".as_ref(),
                    lut.as_os_str(),
                    given.as_os_str(),
                ],
                vec![
                    "eval".as_ref(),
                    "--lut".as_ref(),
                    lut.as_os_str(),
                    given.as_os_str(),
                ],
            ] {
                let out = eotn(&args);
                let err = String::from_utf8_lossy(&out.stderr);
                assert!(!out.status.success(), "{args:?}: {err}");
                assert!(
                    err.contains("no camera frames") || err.contains("no frame with"),
                    "{args:?}: {err}"
                );
                not_as(&what, &err);
            }
            // import: the bag read, its missing image said, nothing invented or written.
            let out_dir = tempfile::tempdir().unwrap();
            let imported = out_dir.path().join("out.mcap");
            let out = eotn(&[
                "import".as_ref(),
                given.as_os_str(),
                "-o".as_ref(),
                imported.as_os_str(),
            ]);
            let err = String::from_utf8_lossy(&out.stderr);
            assert!(!out.status.success(), "{what}: {err}");
            assert!(err.contains("no camera frames to import"), "{what}: {err}");
            assert!(err.contains("no camera image"), "{what}: {err}");
            assert!(!imported.exists(), "{what}: an empty import was written");
            not_as(&what, &err);
            // The app's Open reads it as a stream and says it has no frames.
            let mut state = eotn::workspace::Workspace::default();
            let err = state
                .apply(eotn::workspace::Command::Open(vec![given.clone()]))
                .expect_err("a bag without images opens no source");
            let err = format!("{err:#}");
            assert!(err.contains("holds no camera frames"), "{what}: {err}");
            not_as(&what, &err);
            checked += 1;
        }
    }
    assert_eq!(checked, 12, "four bags, three ways each");
}

/// A bag written by `rosbags` with one image message cut short and one joint-state message
/// turned to garbage: the cut image costs its frame only, with one warning naming it; the
/// garbage costs its reading only; every other frame reads as before.
#[test]
fn a_damaged_message_costs_its_frame_only() {
    let Some((dir, list)) = recordings() else {
        return;
    };
    let original = list
        .iter()
        .find(|r| r.name == "rosbag2 sqlite sensor_msgs/Image uyvy step+0")
        .unwrap();
    let damaged = dir.path().join("damaged_uyvy");
    std::fs::create_dir_all(&damaged).unwrap();
    for e in std::fs::read_dir(&original.path).unwrap() {
        let p = e.unwrap().path();
        std::fs::copy(&p, damaged.join(p.file_name().unwrap())).unwrap();
    }
    let db3 = std::fs::read_dir(&damaged)
        .unwrap()
        .map(|e| e.unwrap().path())
        .find(|p| p.extension().is_some_and(|e| e == "db3"))
        .unwrap();
    let nth_of = |conn: &rusqlite::Connection, topic: &str, n: i64| -> i64 {
        conn.query_row(
            "SELECT m.id FROM messages m JOIN topics t ON t.id = m.topic_id \
             WHERE t.name = ?1 ORDER BY m.timestamp, m.id LIMIT 1 OFFSET ?2",
            rusqlite::params![topic, n],
            |r| r.get(0),
        )
        .unwrap()
    };
    {
        let conn = rusqlite::Connection::open(&db3).unwrap();
        let image = nth_of(&conn, "/camera/image_raw", 5);
        conn.execute(
            "UPDATE messages SET data = substr(data, 1, 60) WHERE id = ?1",
            [image],
        )
        .unwrap();
        let joints = nth_of(&conn, "/joint_states", 9);
        conn.execute(
            "UPDATE messages SET data = X'00010000FFFFFFFF' WHERE id = ?1",
            [joints],
        )
        .unwrap();
    }
    let mut good = StreamReader::open(&original.path).unwrap();
    let mut bad = StreamReader::open(&damaged).unwrap();
    assert_eq!(bad.len(), FRAMES);
    for i in 0..FRAMES {
        let want = good.read(i).unwrap();
        match bad.read(i) {
            Err(e) => assert_eq!(i, 5, "frame {i} lost: {e}"),
            Ok(got) => {
                assert_ne!(i, 5, "the cut image read");
                assert_eq!(got.frame, want.frame, "frame {i}");
                let joints = |r: &eotn::streams::FrameRecord| {
                    r.extra.iter().any(|(t, _)| t == "/joint_states")
                };
                assert_eq!(joints(&got), i != 9, "frame {i}: {:?}", got.extra);
            }
        }
    }
    // detect: 23 frames and the lost one named once.
    let out = eotn(&[
        "detect".as_ref(),
        "--json".as_ref(),
        "--lut".as_ref(),
        root().join("lookup_tables/bhuman2009.lut").as_os_str(),
        damaged.as_os_str(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let lines = String::from_utf8_lossy(&out.stdout).lines().count();
    assert_eq!(lines, FRAMES - 1);
    let err = String::from_utf8_lossy(&out.stderr);
    let named = err.lines().filter(|l| l.contains("frame 5")).count();
    assert_eq!(named, 1, "{err}");
}

/// A `mono8` recording shows and steps in the app's workspace as any other: every frame in turn,
/// grey (U = V = 128) with its own luma, the note that a colour table cannot classify it shown.
#[test]
fn a_mono8_recording_steps_frame_by_frame_in_the_workspace() {
    use eotn::workspace::{Command, PlaybackCommand, Workspace};
    let Some((_, list)) = recordings() else {
        return;
    };
    let mono = list.iter().find(|r| r.matches == "grey").unwrap();
    let mut w = Workspace::default();
    w.apply(Command::Open(vec![
        mono.path.clone(),
        root().join("lookup_tables/bhuman2009.lut"),
    ]))
    .unwrap();
    let said = format!("{} {:?}", w.status, w.warnings());
    assert!(said.contains("cannot classify"), "{}: {said}", mono.name);
    let mut reference = StreamReader::open(&list[0].path).unwrap();
    let mut lumas = Vec::new();
    for i in 0..FRAMES {
        if i > 0 {
            w.apply(PlaybackCommand::Step(1).into()).unwrap();
        }
        assert_eq!(w.index(), i, "{}", mono.name);
        let frame = w.frame().expect("a frame shown");
        let want = reference.read(i).unwrap().frame;
        assert_eq!(
            (frame.width(), frame.height()),
            (want.width(), want.height())
        );
        let mut luma = 0u64;
        frame.for_each_pixel(|_, _, p| {
            assert_eq!((p.u, p.v), (128, 128), "frame {i}: grey");
            luma += u64::from(p.y);
        });
        lumas.push(luma);
    }
    lumas.dedup();
    assert!(lumas.len() > FRAMES / 2, "the frames differ: {lumas:?}");
    // Stepping past the end stays on the last frame.
    w.apply(PlaybackCommand::Step(1).into()).unwrap();
    assert_eq!(w.index(), FRAMES - 1);
}

/// The storage file of the `rosbags` rgb8 bag copied message by message into `out` (an MCAP file
/// with its `ros2msg` schemas and `cdr` channels), `edit` given the index and CDR bytes of each
/// `/camera/image_raw` message on the way.
fn copy_mcap_editing_images(src: &Path, out: &Path, mut edit: impl FnMut(usize, &mut Vec<u8>)) {
    let bytes = std::fs::read(src).unwrap();
    let mut writer =
        mcap::Writer::new(std::io::BufWriter::new(std::fs::File::create(out).unwrap())).unwrap();
    let mut images = 0;
    for message in mcap::MessageStream::new(&bytes).unwrap() {
        let mut message = message.unwrap();
        if message.channel.topic == "/camera/image_raw" {
            let mut data = message.data.into_owned();
            edit(images, &mut data);
            message.data = data.into();
            images += 1;
        }
        writer.write(&message).unwrap();
    }
    writer.finish().unwrap();
    assert_eq!(images, FRAMES, "{}", src.display());
}

fn rgb8_storage_file(list: &[Recording]) -> PathBuf {
    list.iter()
        .find(|r| r.name == "rosbag2 storage file (.mcap) alone")
        .unwrap()
        .path
        .clone()
}

/// A truncated CDR image inside an MCAP file (not only in SQLite storage) costs its frame only:
/// the other 23 read as in the original file, and `detect` names the lost frame once.
#[test]
fn a_truncated_cdr_message_in_an_mcap_file_costs_its_frame_only() {
    let Some((dir, list)) = recordings() else {
        return;
    };
    let original = rgb8_storage_file(list);
    let cut = dir.path().join("cut_image_5.mcap");
    copy_mcap_editing_images(&original, &cut, |i, data| {
        if i == 5 {
            data.truncate(60);
        }
    });
    let mut good = StreamReader::open(&original).unwrap();
    let mut bad = StreamReader::open(&cut).unwrap();
    assert_eq!(bad.len(), FRAMES);
    for i in 0..FRAMES {
        match bad.read(i) {
            Err(e) => assert_eq!(i, 5, "frame {i} lost: {e}"),
            Ok(got) => {
                assert_ne!(i, 5, "the cut image read");
                assert_eq!(got.frame, good.read(i).unwrap().frame, "frame {i}");
            }
        }
    }
    let out = eotn(&[
        "detect".as_ref(),
        "--json".as_ref(),
        "--lut".as_ref(),
        root().join("lookup_tables/bhuman2009.lut").as_os_str(),
        cut.as_os_str(),
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert_eq!(
        String::from_utf8_lossy(&out.stdout).lines().count(),
        FRAMES - 1
    );
    let named = err.lines().filter(|l| l.contains("frame 5")).count();
    assert_eq!(named, 1, "{err}");
}

/// A split bag's channels are those of all its files (each topic's messages summed over both),
/// and every message of it is given in stored order, SQLite storage included, with channel ids
/// of that list.
#[test]
fn a_split_bag_lists_the_channels_and_messages_of_all_its_files() {
    let Some((_, list)) = recordings() else {
        return;
    };
    let split: Vec<&Recording> = list
        .iter()
        .filter(|r| r.name.starts_with("split rosbag2"))
        .collect();
    assert_eq!(split.len(), 2, "the mcap and sqlite split bags");
    for r in split {
        let mut reader = StreamReader::open(&r.path).unwrap();
        let channels = reader.channels().to_vec();
        for topic in ["/camera/image_raw", "/joint_states", "/camera/camera_info"] {
            let c: Vec<_> = channels.iter().filter(|c| c.topic == topic).collect();
            assert_eq!(c.len(), 1, "{}: {topic} in {channels:?}", r.name);
            assert_eq!(
                c[0].message_count, FRAMES as u64,
                "{}: {topic}: both files' messages",
                r.name
            );
            assert_eq!(c[0].message_encoding, "cdr");
        }
        let mut per_channel = std::collections::BTreeMap::<u16, u64>::new();
        reader
            .for_each_message(|m| *per_channel.entry(m.channel).or_default() += 1)
            .unwrap_or_else(|e| panic!("{}: {e}", r.name));
        let listed: std::collections::BTreeMap<u16, u64> = channels
            .iter()
            .map(|c| (c.id, c.message_count))
            .filter(|(_, n)| *n > 0)
            .collect();
        assert_eq!(per_channel, listed, "{}", r.name);
    }
}
