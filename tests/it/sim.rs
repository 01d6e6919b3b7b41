//! The synthetic-data tools as a user runs them: `eotn sim` streams, `eotn lut-from-labels`,
//! and the shipped sample streams with the shipped table.

use std::ffi::OsStr;
use std::path::Path;

use eotn::classify::ClassifiedImage;
use eotn::lut::{ColourClass, LookupTable};
use eotn::sim::GroundTruth;
use eotn::streams::StreamReader;

use crate::common::{SHIPPED_ROBOT_SCENARIOS, eotn, eotn_ok, shipped_first_frame};

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
    eprintln!("the shipped table finds {good_balls} of {checked_balls} balls orange");
    // Restored from before c96e484 lowered it to 10: the re-made streams (05b7319) show the ball
    // in most frames of the ball-named streams again.
    assert!(checked_balls > 20, "{checked_balls}");
    // Balls in the dark, blue-shifted image corners are missed sometimes (as on the robot).
    assert!(
        good_balls * 10 >= checked_balls * 8,
        "{good_balls} of {checked_balls}"
    );
}

/// The shipped sim streams are what `eotn sim` writes today (`--seed 1 --first N`, as the README
/// says they were made): every frame's pixels, time, sensor readings, extra channels and ground
/// truth alike, so a change of the renderer, the scenarios or the ground truth shows here before
/// the shipped streams and the figures measured on them go stale. And each shows its subject:
/// the ball-named streams a ball in most frames, beacon-tour a beacon, goalkeeper a goal.
#[test]
fn shipped_sim_streams_are_what_eotn_sim_writes() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let dir = tempfile::tempdir().unwrap();
    for scenario in SHIPPED_ROBOT_SCENARIOS.into_iter().chain(["overhead-game"]) {
        let mut shipped =
            StreamReader::open(&root.join(format!("streams/sim-{scenario}.mcap"))).unwrap();
        let first = shipped_first_frame(scenario);
        let out = dir.path().join(format!("{scenario}.mcap"));
        eotn_ok(&[
            OsStr::new("sim"),
            OsStr::new("--scenario"),
            OsStr::new(scenario),
            OsStr::new("--frames"),
            OsStr::new(&shipped.len().to_string()),
            OsStr::new("--seed"),
            OsStr::new("1"),
            OsStr::new("--first"),
            OsStr::new(&first.to_string()),
            OsStr::new("-o"),
            out.as_os_str(),
        ]);
        let mut fresh = StreamReader::open(&out).unwrap();
        assert_eq!(fresh.len(), shipped.len(), "{scenario}");
        assert_eq!(fresh.info(), shipped.info(), "{scenario}");
        for i in 0..shipped.len() {
            let (a, b) = (shipped.read(i).unwrap(), fresh.read(i).unwrap());
            assert_eq!(a.time_ns, b.time_ns, "{scenario} frame {i}");
            assert!(
                a.frame == b.frame,
                "{scenario} frame {i}: the pixels differ"
            );
            assert_eq!(a.sensors, b.sensors, "{scenario} frame {i}");
            assert_eq!(a.ground_truth, b.ground_truth, "{scenario} frame {i}");
            assert_eq!(a.extra, b.extra, "{scenario} frame {i}");
        }
    }
}

/// What the shipped robot streams show, counted in their ground truth: frames with the ball in
/// view (any pixel), with a beacon's bands, with a goal.
#[test]
fn shipped_sim_streams_show_what_they_are_named_for() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let count = |scenario: &str, what: &dyn Fn(&eotn::model::truth::RobotViewTruth) -> bool| {
        let mut r = StreamReader::open(&root.join(format!("streams/sim-{scenario}.mcap"))).unwrap();
        (0..r.len())
            .filter(|&i| {
                let truth = r.read(i).unwrap().ground_truth.unwrap();
                match serde_json::from_value(truth).unwrap() {
                    GroundTruth::Robot(t) => what(&t),
                    GroundTruth::Overhead(_) => panic!("{scenario}: a robot stream"),
                }
            })
            .count()
    };
    let ball = |t: &eotn::model::truth::RobotViewTruth| {
        t.ball.as_ref().is_some_and(|b| b.visible_pixels > 0)
    };
    let beacon =
        |t: &eotn::model::truth::RobotViewTruth| t.beacons.iter().any(|b| b.band_pixels > 0);
    let goal =
        |t: &eotn::model::truth::RobotViewTruth| t.goals.iter().any(|g| g.visible_pixels > 0);
    for scenario in ["ball-edge", "walk-and-pan", "orange-clutter"] {
        let n = count(scenario, &ball);
        assert!(n >= 9, "{scenario}: the ball in {n} of 15 frames");
    }
    // Fast pans sweep past the ball: in view a third of the time.
    let n = count("fast-pans", &ball);
    assert!(n >= 5, "fast-pans: the ball in {n} of 15 frames");
    let n = count("beacon-tour", &beacon);
    assert!(n >= 12, "beacon-tour: a beacon in {n} of 15 frames");
    let n = count("goalkeeper", &goal);
    assert!(n >= 12, "goalkeeper: a goal in {n} of 15 frames");
}
