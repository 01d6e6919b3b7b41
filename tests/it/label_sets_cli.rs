//! `eotn eval IMAGES --labels` through the command line on a small set made here (no shared
//! data): `--plots` with box labels, IMAGES given as a stream (`eotn import`), `--class-names`
//! for a YOLO folder without `classes.txt`, `--classes` for a Pascal VOC folder whose class names
//! are not eotn's.

use std::path::{Path, PathBuf};

use eotn::frame::{rgb_to_yuv, save_rgb_png};
use eotn::lut::{ColourClass, EditRecord, LookupTable, Region, Sensitivity};
use serde_json::Value;

use crate::common::{eotn, eotn_ok};

const W: usize = 96;
const H: usize = 72;
const CARPET: [u8; 3] = [45, 140, 60];
const BALL: [u8; 3] = [250, 110, 20];
/// Ball centres of frames 0–3 (frame 3 has none); radius 6 px.
const BALLS: [Option<(f64, f64)>; 4] = [
    Some((30.0, 30.0)),
    Some((60.0, 40.0)),
    Some((45.0, 50.0)),
    None,
];

/// Frames `00000.png`…`00003.png`, a table that knows the carpet and the ball, and the
/// labels: frames 0 and 1 with their ball, frame 2 with a ball box where there is none (so
/// it is missed, and its ball is false), frame 3 with a robot box only.
struct Set {
    frames: PathBuf,
    table: PathBuf,
    /// YOLO boxes of each frame: `class cx cy w h` (fractions), classes robot, ball, goal.
    yolo: Vec<String>,
}

fn make_set(dir: &Path) -> Set {
    let frames = dir.join("frames");
    std::fs::create_dir_all(&frames).unwrap();
    for (n, ball) in BALLS.iter().enumerate() {
        let mut rgb = Vec::with_capacity(W * H * 3);
        for i in 0..W * H {
            let (x, y) = ((i % W) as f64 + 0.5, (i / W) as f64 + 0.5);
            let inside = ball.is_some_and(|(cx, cy)| (x - cx).hypot(y - cy) <= 6.0);
            rgb.extend_from_slice(if inside { &BALL } else { &CARPET });
        }
        save_rgb_png(&frames.join(format!("{n:05}.png")), W, H, &rgb).unwrap();
    }
    let mut lut = LookupTable::new(6).unwrap();
    for (class, rgb) in [(ColourClass::Green, CARPET), (ColourClass::Orange, BALL)] {
        lut.apply(EditRecord::now(
            class,
            Region::AroundSample {
                sample: rgb_to_yuv(rgb),
                sensitivity: Sensitivity::uniform(3),
            },
        ));
    }
    let table = dir.join("t.lut");
    lut.save(&table).unwrap();
    let ball = |cx: f64, cy: f64| {
        format!(
            "1 {} {} {} {}",
            cx / W as f64,
            cy / H as f64,
            12.0 / W as f64,
            12.0 / H as f64
        )
    };
    let yolo = vec![
        ball(30.0, 30.0),
        ball(60.0, 40.0),
        ball(80.0, 15.0),
        "0 0.5 0.5 0.2 0.2".to_owned(),
    ];
    Set {
        frames,
        table,
        yolo,
    }
}

/// A YOLO folder of the set's boxes, with `classes.txt` when `names` is given.
fn yolo_folder(dir: &Path, set: &Set, names: Option<&str>) -> PathBuf {
    std::fs::create_dir_all(dir).unwrap();
    if let Some(names) = names {
        std::fs::write(dir.join("classes.txt"), names).unwrap();
    }
    for (n, line) in set.yolo.iter().enumerate() {
        std::fs::write(dir.join(format!("{n:05}.txt")), format!("{line}\n")).unwrap();
    }
    dir.to_owned()
}

/// The set's boxes as a Pascal VOC folder, the ball class named `orange`, the robot `bot`.
fn voc_folder(dir: &Path, set: &Set) -> PathBuf {
    std::fs::create_dir_all(dir).unwrap();
    for (n, line) in set.yolo.iter().enumerate() {
        let v: Vec<f64> = line
            .split_whitespace()
            .map(|t| t.parse().unwrap())
            .collect();
        let name = if v[0] == 1.0 { "orange" } else { "bot" };
        let (cx, cy, w, h) = (
            v[1] * W as f64,
            v[2] * H as f64,
            v[3] * W as f64,
            v[4] * H as f64,
        );
        let xml = format!(
            "<annotation><filename>{n:05}.png</filename><size><width>{W}</width><height>{H}</height><depth>3</depth></size>\
             <object><name>{name}</name><bndbox><xmin>{}</xmin><ymin>{}</ymin><xmax>{}</xmax><ymax>{}</ymax></bndbox></object></annotation>",
            cx - w / 2.0,
            cy - h / 2.0,
            cx + w / 2.0,
            cy + h / 2.0
        );
        std::fs::write(dir.join(format!("{n:05}.xml")), xml).unwrap();
    }
    dir.to_owned()
}

fn eval_json(images: &Path, labels: &Path, table: &Path, extra: &[&str]) -> Value {
    let mut args: Vec<&std::ffi::OsStr> = vec![
        "eval".as_ref(),
        images.as_os_str(),
        "--labels".as_ref(),
        labels.as_os_str(),
        "--lut".as_ref(),
        table.as_os_str(),
        "--json".as_ref(),
    ];
    args.extend(extra.iter().map(|a| std::ffi::OsStr::new(*a)));
    let out = eotn_ok(&args);
    let mut v: Value = serde_json::from_slice(&out.stdout).expect("eval --json");
    // Wall time and the charts written differ between runs and are compared separately.
    v.as_object_mut().unwrap().remove("seconds");
    v.as_object_mut().unwrap().remove("plots");
    v
}

#[test]
fn class_names_and_classes_name_a_set_s_objects_through_the_command_line() {
    let dir = tempfile::tempdir().unwrap();
    let set = make_set(dir.path());
    let named = yolo_folder(&dir.path().join("yolo"), &set, Some("robot\nball\ngoal\n"));
    let reference = eval_json(&set.frames, &named, &set.table, &[]);
    let r = &reference["report"];
    // Frames 0 and 1 found; frame 2 missed, its ball false (outside every box).
    assert_eq!(
        (
            r["eligible"].as_u64(),
            r["found"].as_u64(),
            r["reported"].as_u64()
        ),
        (Some(3), Some(2), Some(3)),
        "{r}"
    );
    assert_eq!(r["missed_frames"], serde_json::json!(["00002"]));
    // The same folder without classes.txt: refused, naming --class-names; with it, the same.
    let bare = yolo_folder(&dir.path().join("bare"), &set, None);
    let refused = eotn(&[
        "eval".as_ref(),
        set.frames.as_os_str(),
        "--labels".as_ref(),
        bare.as_os_str(),
        "--lut".as_ref(),
        set.table.as_os_str(),
    ]);
    assert!(!refused.status.success());
    let err = String::from_utf8_lossy(&refused.stderr);
    assert!(err.contains("--class-names"), "{err}");
    let given = eval_json(
        &set.frames,
        &bare,
        &set.table,
        &["--class-names", "robot,ball,goal"],
    );
    assert_eq!(given["report"], reference["report"]);
    // Class numbers named otherwise: frame 3's robot box is the only "ball" (not found), and
    // the balls of frames 0 and 1 are reported inside "robot" boxes.
    let swapped = eval_json(
        &set.frames,
        &bare,
        &set.table,
        &["--class-names", "ball,robot,goal"],
    );
    let r = &swapped["report"];
    assert_eq!(
        (
            r["eligible"].as_u64(),
            r["found"].as_u64(),
            r["false_in_robot"].as_u64()
        ),
        (Some(1), Some(0), Some(2)),
        "{r}"
    );
    // A VOC folder naming the ball "orange" and the robot "bot": --classes maps them.
    let voc = voc_folder(&dir.path().join("voc"), &set);
    let unmapped = eval_json(&set.frames, &voc, &set.table, &[]);
    assert_eq!(unmapped["report"]["eligible"].as_u64(), Some(0));
    let mapped = eval_json(
        &set.frames,
        &voc,
        &set.table,
        &["--classes", "orange=ball,bot=robot"],
    );
    assert_eq!(mapped["format"].as_str(), Some("voc"));
    assert_eq!(mapped["report"]["found"], reference["report"]["found"]);
    assert_eq!(
        mapped["report"]["missed_frames"],
        reference["report"]["missed_frames"]
    );
    // A bad --classes entry is refused with the rule.
    let bad = eotn(&[
        "eval".as_ref(),
        set.frames.as_os_str(),
        "--labels".as_ref(),
        voc.as_os_str(),
        "--lut".as_ref(),
        set.table.as_os_str(),
        "--classes".as_ref(),
        "orange".as_ref(),
    ]);
    assert!(!bad.status.success());
    assert!(
        String::from_utf8_lossy(&bad.stderr).contains("name=object"),
        "{}",
        String::from_utf8_lossy(&bad.stderr)
    );
}

#[test]
fn a_stream_of_the_frames_scores_as_the_folder_and_plots_are_drawn() {
    let dir = tempfile::tempdir().unwrap();
    let set = make_set(dir.path());
    let labels = yolo_folder(&dir.path().join("yolo"), &set, Some("robot\nball\ngoal\n"));
    let stream = dir.path().join("frames.mcap");
    eotn_ok(&[
        "import".as_ref(),
        set.frames.as_os_str(),
        "-o".as_ref(),
        stream.as_os_str(),
    ]);
    let plots = dir.path().join("plots");
    let folder = eval_json(&set.frames, &labels, &set.table, &[]);
    let streamed = eval_json(
        &stream,
        &labels,
        &set.table,
        &["--plots", plots.to_str().unwrap()],
    );
    // Stream frames are matched by index (the labels' names carry leading zeros); the frames
    // went through 4:2:2 on import, which moves no ball across a box edge.
    let (f, s) = (&folder["report"], &streamed["report"]);
    for key in ["frames", "eligible", "found", "reported", "correct"] {
        assert_eq!(f[key], s[key], "{key}: {f} vs {s}");
    }
    assert_eq!(s["missed_frames"].as_array().map(Vec::len), Some(1), "{s}");
    for chart in ["ball_detection.png", "ball_centre_error.png"] {
        let png = plots.join(chart);
        let bytes = std::fs::read(&png).unwrap_or_else(|e| panic!("{}: {e}", png.display()));
        assert!(bytes.starts_with(b"\x89PNG\r\n\x1a\n"), "{chart} is a PNG");
        let frame = eotn::frame::load_frame(&png, None).expect("the chart decodes");
        assert!(frame.width() >= 200 && frame.height() >= 100, "{chart}");
    }
}
