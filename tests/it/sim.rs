//! The synthetic-data tools as a user runs them: `eotn sim` streams, `eotn lut-from-labels`,
//! and the shipped sample streams with the shipped table.

use std::ffi::OsStr;
use std::path::Path;

use eotn::classify::ClassifiedImage;
use eotn::lut::{ColourClass, LookupTable};
use eotn::sim::GroundTruth;
use eotn::streams::StreamReader;

use crate::common::{SHIPPED_ROBOT_SCENARIOS, eotn, eotn_ok};

fn sim(dir: &Path, scenario: &str, frames: &str, seed: &str) -> std::path::PathBuf {
    let out = dir.join(format!("{scenario}-{seed}.mcap"));
    let run = eotn(&[
        OsStr::new("sim"),
        OsStr::new("--scenario"),
        OsStr::new(scenario),
        OsStr::new("--frames"),
        OsStr::new(frames),
        OsStr::new("--seed"),
        OsStr::new(seed),
        OsStr::new("-o"),
        out.as_os_str(),
    ]);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    out
}

#[test]
fn sim_writes_frames_sensors_and_ground_truth() {
    let dir = tempfile::tempdir().unwrap();
    let path = sim(dir.path(), "fast-pans", "3", "2");
    let mut reader = StreamReader::open(&path).unwrap();
    assert_eq!(reader.len(), 3);
    assert_eq!(reader.info().source, "sim:fast-pans");
    let r = reader.read(1).unwrap();
    assert_eq!((r.frame.width(), r.frame.height()), (208, 160));
    let sensors = r.sensors.unwrap();
    assert!(sensors.head_pan_rad.is_some() && sensors.previous_head_pan_rad.is_some());
    let truth: GroundTruth = serde_json::from_value(r.ground_truth.unwrap()).unwrap();
    let GroundTruth::Robot(truth) = truth else {
        panic!("robot view expected");
    };
    assert_eq!(truth.sensors, sensors);
    assert!(truth.ball.is_some());
    assert_eq!(truth.goals.len(), 2);
    assert_eq!(truth.beacons.len(), 4);
    // Same seed, same frames.
    let second = dir.path().join("again");
    std::fs::create_dir(&second).unwrap();
    let again = sim(&second, "fast-pans", "3", "2");
    let mut other = StreamReader::open(&again).unwrap();
    assert_eq!(other.read(2).unwrap().frame, reader.read(2).unwrap().frame);
}

#[test]
fn overhead_game_has_a_world_model_channel_per_robot() {
    let dir = tempfile::tempdir().unwrap();
    let path = sim(dir.path(), "overhead-game", "2", "4");
    let mut reader = StreamReader::open(&path).unwrap();
    let r = reader.read(0).unwrap();
    assert_eq!((r.frame.width(), r.frame.height()), (640, 480));
    let truth: GroundTruth = serde_json::from_value(r.ground_truth.unwrap()).unwrap();
    let GroundTruth::Overhead(truth) = truth else {
        panic!("overhead view expected");
    };
    assert!((4..=8).contains(&truth.robots.len()));
    assert_eq!(r.extra.len(), truth.robots.len());
    assert!(
        r.extra
            .iter()
            .any(|(topic, _)| topic == "/world_model/robot1")
    );
}

#[test]
fn unknown_scenario_is_a_one_line_error_listing_the_known_ones() {
    let dir = tempfile::tempdir().unwrap();
    let out = eotn(&[
        OsStr::new("sim"),
        OsStr::new("--scenario"),
        OsStr::new("nope"),
        OsStr::new("-o"),
        dir.path().join("x.mcap").as_os_str(),
    ]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("nope") && err.contains("walk-and-pan"),
        "{err}"
    );
    assert_eq!(err.trim().lines().count(), 1, "{err}");
}

#[test]
fn lut_from_labels_scores_well_on_held_back_frames() {
    let dir = tempfile::tempdir().unwrap();
    let lut = dir.path().join("learned.lut");
    let out = eotn_ok(&[
        OsStr::new("lut-from-labels"),
        OsStr::new("--sim"),
        OsStr::new("ball-edge"),
        OsStr::new("--frames-per-scenario"),
        OsStr::new("12"),
        OsStr::new("-o"),
        lut.as_os_str(),
        OsStr::new("--json"),
    ]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let accuracy = v["colour_accuracy"].as_f64().unwrap();
    assert!(accuracy > 0.9, "{v}");
    assert_eq!(v["held_back_frames"], 3);
    assert!(LookupTable::load(&lut).is_ok());
}

#[test]
fn lut_from_labels_needs_masks_beside_frames() {
    let dir = tempfile::tempdir().unwrap();
    let frame = dir.path().join("f.uyvy");
    std::fs::write(&frame, vec![128_u8; 208 * 160 * 2]).unwrap();
    let out = eotn(&[
        OsStr::new("lut-from-labels"),
        frame.as_os_str(),
        OsStr::new("-o"),
        dir.path().join("t.lut").as_os_str(),
    ]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("f.cls"), "{err}");
    std::fs::write(dir.path().join("f.cls"), [0_u8; 10]).unwrap();
    let out = eotn(&[
        OsStr::new("lut-from-labels"),
        frame.as_os_str(),
        OsStr::new("-o"),
        dir.path().join("t.lut").as_os_str(),
    ]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("10 bytes"));
}

/// Every shipped sim stream reads back, and the shipped table finds the ball where the ground
/// truth says it is.
#[test]
fn shipped_sim_streams_classify_with_the_shipped_table() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let table = LookupTable::load(&root.join("lookup_tables/sim.lut")).unwrap();
    let mut streams: Vec<_> = std::fs::read_dir(root.join("streams"))
        .unwrap()
        .filter_map(Result::ok)
        .map(|e| e.path())
        .filter(|p| {
            p.file_name()
                .and_then(|n| n.to_str())
                .is_some_and(|n| n.starts_with("sim-") && n.ends_with(".mcap"))
        })
        .collect();
    streams.sort();
    assert!(streams.len() >= 5, "{streams:?}");
    let (mut checked_balls, mut good_balls) = (0, 0);
    for path in &streams {
        let mut reader = StreamReader::open(path).unwrap();
        assert!(
            reader.warnings().is_empty(),
            "{}: {:?}",
            path.display(),
            reader.warnings()
        );
        for i in 0..reader.len() {
            let r = reader.read(i).unwrap();
            let truth: GroundTruth = serde_json::from_value(r.ground_truth.unwrap()).unwrap();
            let GroundTruth::Robot(truth) = truth else {
                continue;
            };
            let Some(ball) = truth.ball.filter(|b| b.visible_pixels >= 60) else {
                continue;
            };
            let Some(b) = ball.image_box else { continue };
            let img = ClassifiedImage::from_frame(&r.frame, &table);
            let mut orange = 0;
            for y in b.min_y..=b.max_y {
                for x in b.min_x..=b.max_x {
                    if img.get(x as usize, y as usize) == Some(ColourClass::Orange.code()) {
                        orange += 1;
                    }
                }
            }
            if orange * 2 >= ball.visible_pixels {
                good_balls += 1;
            } else {
                eprintln!(
                    "{} frame {i}: {orange} orange of {} ball pixels",
                    path.display(),
                    ball.visible_pixels
                );
            }
            checked_balls += 1;
        }
    }
    assert!(checked_balls >= 10, "{checked_balls}");
    // Balls in the dark, blue-shifted image corners are missed sometimes (as on the robot).
    assert!(
        good_balls * 10 >= checked_balls * 8,
        "{good_balls} of {checked_balls}"
    );
}

/// The shipped sim streams are what `eotn sim` writes today (`--seed 1`, as the README says they
/// were made): every frame's pixels, time, sensor readings and extra channels alike, and every
/// ground-truth value they hold equal to rounding (1e-9 relative), so a change of the renderer,
/// the scenarios or the ground truth shows here before the shipped streams and the figures
/// measured on them go stale. Two known differences: the robot-camera streams predate a few truth
/// fields (`eotn sim` adds them), and their goals' `largest_gap` was measured by an earlier gap
/// scan whose ends lay a pixel to the side (the streams were not re-made for it).
#[test]
fn shipped_sim_streams_are_what_eotn_sim_writes() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let dir = tempfile::tempdir().unwrap();
    for scenario in SHIPPED_ROBOT_SCENARIOS.into_iter().chain(["overhead-game"]) {
        let mut shipped =
            StreamReader::open(&root.join(format!("streams/sim-{scenario}.mcap"))).unwrap();
        let fresh = sim(dir.path(), scenario, &shipped.len().to_string(), "1");
        let mut fresh = StreamReader::open(&fresh).unwrap();
        assert_eq!(fresh.len(), shipped.len(), "{scenario}");
        for i in 0..shipped.len() {
            let (a, b) = (shipped.read(i).unwrap(), fresh.read(i).unwrap());
            assert_eq!(a.time_ns, b.time_ns, "{scenario} frame {i}");
            assert!(
                a.frame == b.frame,
                "{scenario} frame {i}: the pixels differ"
            );
            assert_eq!(a.sensors, b.sensors, "{scenario} frame {i}");
            let (old, new) = (a.ground_truth.unwrap(), b.ground_truth.unwrap());
            assert!(
                json_within(&old, &new),
                "{scenario} frame {i}: shipped truth {old}\n is not within today's {new}"
            );
            assert_eq!(a.extra, b.extra, "{scenario} frame {i}");
        }
    }
}

/// Whether every value of `old` is in `new` where `old` has it (objects may gain keys), numbers
/// to 1e-9 relative; `largest_gap` is passed over (see the test above).
fn json_within(old: &serde_json::Value, new: &serde_json::Value) -> bool {
    use serde_json::Value;
    match (old, new) {
        (Value::Object(a), Value::Object(b)) => a
            .iter()
            .filter(|(k, _)| k.as_str() != "largest_gap")
            .all(|(k, v)| b.get(k).is_some_and(|w| json_within(v, w))),
        (Value::Array(a), Value::Array(b)) => {
            a.len() == b.len() && a.iter().zip(b).all(|(v, w)| json_within(v, w))
        }
        (Value::Number(a), Value::Number(b)) => match (a.as_f64(), b.as_f64()) {
            (Some(x), Some(y)) => (x - y).abs() <= 1e-9 * x.abs().max(1.0),
            _ => a == b,
        },
        _ => old == new,
    }
}
