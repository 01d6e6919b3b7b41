//! Other teams' real tables and the real B-Human 2009 Nao log, read from `../shared/data/`, and
//! the B-Human stream shipped in `streams/` scored against its hand labels.
//!
//! The shared files are not ours (most are GPL), so they stay outside the repository: each test
//! that reads them skips with a "SKIPPED" line when the shared folder is absent, and fails under
//! `CI=true`. The shipped stream, its table and labels are in the repository and never skip.

use std::path::Path;

use eotn::blobs::{BlobSet, Connectivity};
use eotn::classify::ClassifiedImage;
use eotn::import::bhuman;
use eotn::lut::convert::{Converted, SourceFormat, convert_file};
use eotn::lut::{ColourClass, LookupTable};

use crate::common::{figure, repo_file, sampled, shared_file};

fn convert(rel: &str, format: SourceFormat) -> Option<Converted> {
    let path = shared_file(rel)?;
    // Auto-detection must agree with the named format on every real file.
    let auto = convert_file(&path, None, None).unwrap();
    assert_eq!(auto.format, format, "{rel}");
    let named = convert_file(&path, Some(format), None).unwrap();
    assert_eq!(named.table, auto.table);
    Some(named)
}

fn count(t: &LookupTable, c: ColourClass) -> usize {
    t.class_counts()[usize::from(c.code())]
}

/// Mean (Y, U, V) of a class's cells, in 8-bit units.
fn centroid(t: &LookupTable, c: ColourClass) -> [f64; 3] {
    let (mut sum, mut n) = ([0.0; 3], 0.0);
    let half = f64::from(1u32 << t.shift()) / 2.0;
    for (i, &code) in t.cells().iter().enumerate() {
        if code == c.code() {
            let cell = t.cell_of_index(i);
            for k in 0..3 {
                sum[k] += (cell[k] as f64) * f64::from(1u32 << t.shift()) + half;
            }
            n += 1.0;
        }
    }
    sum.map(|s| s / n)
}

/// Orange lies at low U / high V, blue at high U / low V, green below 128 on V: the checks
/// that catch a swapped U/V axis order.
fn assert_colours_where_they_belong(t: &LookupTable, blue: ColourClass, what: &str) {
    let o = centroid(t, ColourClass::Orange);
    assert!(o[2] > 150.0 && o[1] < 120.0, "{what}: orange at {o:?}");
    let b = centroid(t, blue);
    assert!(b[1] > 140.0 && b[2] < 140.0, "{what}: blue at {b:?}");
    let g = centroid(t, ColourClass::Green);
    assert!(g[2] < 128.0, "{what}: green at {g:?}");
}

#[test]
fn runswift_2005_cal() {
    let Some(c) = convert("data/luts/runswift2005-nnmc.cal", SourceFormat::RunswiftCal) else {
        return;
    };
    let t = &c.table;
    assert_eq!(t.bits(), 7);
    use ColourClass as C;
    for (class, n) in [
        (C::Unclassified, 641_456),
        (C::Orange, 68_080),
        (C::SkyBlue, 144_072),
        (C::Yellow, 23_017),
        (C::Pink, 24_432),
        (C::DarkBlue, 20_758),
        (C::Red, 56_086),
        (C::Green, 103_815),
        (C::Black, 8_629 + 689),
        (C::White, 1_006_118),
    ] {
        assert_eq!(count(t, class), n, "{class}");
    }
    assert_colours_where_they_belong(t, C::SkyBlue, "rUNSWift");
    assert!(c.notes.is_empty(), "{:?}", c.notes);
}

#[test]
fn nubots_2013_luts() {
    use ColourClass as C;
    let Some(c) = convert("data/luts/nubots2013-default1.lut", SourceFormat::NubotsLut) else {
        return;
    };
    assert_eq!(c.table.bits(), 7);
    for (class, n) in [
        (C::Unclassified, 1_945_692),
        (C::White, 2_694),
        (C::Green, 41_453),
        (C::Orange, 63_677),
        (C::Yellow, 43_636),
    ] {
        assert_eq!(count(&c.table, class), n, "{class}");
    }
    let Some(c) = convert(
        "data/luts/nubots2013-lab-NUbot2.lut",
        SourceFormat::NubotsLut,
    ) else {
        return;
    };
    for (class, n) in [
        (C::Unclassified, 1_947_509),
        (C::White, 46_777),
        (C::Green, 49_265),
        (C::Pink, 144),
        (C::Orange, 15_804),
        (C::YellowOrange, 252),
        (C::Yellow, 9_740),
        (C::SkyBlue, 27_661),
    ] {
        assert_eq!(count(&c.table, class), n, "{class}");
    }
    assert_colours_where_they_belong(&c.table, C::SkyBlue, "NUbots");
    // Our layout already: the bytes are the source's with codes renumbered.
    let src = std::fs::read(shared_file("data/luts/nubots2013-lab-NUbot2.lut").unwrap()).unwrap();
    let i = src.iter().position(|&v| v == 6).unwrap();
    assert_eq!(c.table.cells()[i], C::Orange.code());
}

#[test]
fn upenn_2016_raw() {
    let Some(c) = convert(
        "data/luts/upenn2016-Germany2016_10am_Top.raw",
        SourceFormat::UpennRaw,
    ) else {
        return;
    };
    use ColourClass as C;
    assert_eq!(c.table.bits(), 6);
    for (class, n) in [
        (C::Unclassified, 259_240),
        (C::Black, 464),
        (C::Green, 421),
        (C::White, 2_019),
    ] {
        assert_eq!(count(&c.table, class), n, "{class}");
    }
    // Bit 1 (the ball) holds dark, colourless cells in 2016: the black-and-white ball.
    assert!(c.notes.iter().any(|n| n.contains("black")), "{:?}", c.notes);
    let w = centroid(&c.table, C::White);
    let k = centroid(&c.table, C::Black);
    assert!(w[0] > 150.0 && k[0] < 100.0, "white {w:?} black {k:?}");
    assert!(centroid(&c.table, C::Green)[2] < 100.0);
}

#[test]
fn ssl_vision_2024_xml() {
    let Some(c) = convert(
        "data/luts/ssl-vision-2024-cam-0-lut-yuv.xml",
        SourceFormat::SslXml,
    ) else {
        return;
    };
    use ColourClass as C;
    assert_eq!(c.table.bits(), 6);
    assert_eq!(c.source_bits, [4, 6, 6]);
    // Each 4/6/6 source cell covers 4 output cells.
    for (class, n) in [
        (C::Unclassified, 49_240),
        (C::Green, 2_028 + 1_646),
        (C::Orange, 3_571),
        (C::Yellow, 1_513),
        (C::DarkBlue, 1_960),
        (C::Pink, 2_769),
        (C::White, 404),
        (C::Black, 2_405),
    ] {
        assert_eq!(count(&c.table, class), 4 * n, "{class}");
    }
    assert_colours_where_they_belong(&c.table, C::DarkBlue, "ssl-vision");
    let y = centroid(&c.table, C::Yellow);
    assert!(y[1] < 100.0 && y[2] > 140.0, "yellow at {y:?}");
}

#[test]
fn tekkotsu_threshold_map_with_col() {
    let Some(c) = convert("data/luts/tekkotsu-7general.tm", SourceFormat::TekkotsuTm) else {
        return;
    };
    use ColourClass as C;
    assert_eq!(c.table.bits(), 6);
    assert_eq!(c.source_bits, [4, 6, 6]);
    for (class, n) in [
        (C::Unclassified, 8_220),
        (C::White, 8_673),
        (C::Green, 16_030),
        (C::Yellow, 3_550),
        (C::Orange, 4_586),
        (C::Pink, 6_034),
        (C::SkyBlue, 18_443),
    ] {
        assert_eq!(count(&c.table, class), 4 * n, "{class}");
    }
    assert_colours_where_they_belong(&c.table, C::SkyBlue, "Tekkotsu");
    let names: Vec<&str> = c.source_classes.iter().map(|s| s.name.as_str()).collect();
    assert_eq!(
        names,
        [
            "unclassified",
            "unsaturated",
            "green",
            "yellow",
            "orange",
            "pink",
            "blue"
        ]
    );
}

fn bhuman_table() -> Option<LookupTable> {
    let c = convert("data/bhuman2009/coltable.c64", SourceFormat::BhumanC64)?;
    Some(c.table)
}

#[test]
fn bhuman_coltables() {
    let Some(t) = bhuman_table() else { return };
    use ColourClass as C;
    assert_eq!(t.bits(), 6);
    for (class, n) in [
        (C::Unclassified, 257_518),
        (C::Orange, 1_051),
        (C::Yellow, 683),
        (C::SkyBlue, 707),
        (C::White, 1_126),
        (C::Green, 1_059),
    ] {
        assert_eq!(count(&t, class), n, "{class}");
    }
    assert_colours_where_they_belong(&t, C::SkyBlue, "B-Human");
    let Some(sim) = convert(
        "data/bhuman2009/coltable-simulator.c64",
        SourceFormat::BhumanC64,
    ) else {
        return;
    };
    assert_eq!(sim.table.cells().len(), 1 << 18);
    assert!(count(&sim.table, C::Orange) > 0 && count(&sim.table, C::Green) > 0);
}

fn bhuman_log() -> Option<bhuman::BhumanLog> {
    let path = shared_file("data/bhuman2009/logfile.log")?;
    Some(bhuman::read_log(&path).unwrap())
}

#[test]
fn bhuman_log_frames_sensors_and_frame_80() {
    let (Some(log), Some(table)) = (bhuman_log(), bhuman_table()) else {
        return;
    };
    assert_eq!(log.frames.len(), 160);
    assert!(log.warnings.is_empty(), "{:?}", log.warnings);
    assert_eq!(log.message_counts.get(&bhuman::ids::JOINT_DATA), Some(&274));
    assert!(log.frames.windows(2).all(|w| w[0].time_ms < w[1].time_ms));
    let span = log.frames[159].time_ms - log.frames[0].time_ms;
    assert!((30_000..36_000).contains(&span), "{span} ms");
    for f in &log.frames {
        assert_eq!((f.frame.width(), f.frame.height()), (320, 240));
        let pan = f.sensors.head_pan_rad.unwrap();
        let tilt = f.sensors.head_tilt_rad.unwrap();
        assert!(pan.abs() < 2.1 && tilt.abs() < 0.8, "{pan} {tilt}");
    }
    // Upright robot: the accelerometer measures about +1 g up (the median; walking shakes it).
    let mut az: Vec<f64> = log
        .frames
        .iter()
        .map(|f| f.sensors.accel_z_mps2.unwrap())
        .collect();
    az.sort_by(f64::total_cmp);
    assert!((8.5..11.0).contains(&az[80]), "median {}", az[80]);
    assert!(log.frames[1].sensors.frame_interval_s.unwrap() > 0.0);

    // Frame 80 as B-Human's published figures (ours: 49,900 / 12,339 / 3,832; the ball one blob
    // of 3,606 pixels, plus two specks of 52 and 36): ~49,600 green, 12,300 white, 3,900 orange.
    let img = ClassifiedImage::from_frame(&log.frames[80].frame, &table);
    let h = img.histogram();
    let n = |c: ColourClass| h[usize::from(c.code())] as f64;
    eprintln!(
        "frame 80: green {} white {} orange {}",
        n(ColourClass::Green),
        n(ColourClass::White),
        n(ColourClass::Orange)
    );
    let near = |got: f64, want: f64, tol: f64| (got - want).abs() <= want * tol;
    assert!(
        near(n(ColourClass::Green), 49_600.0, 0.1),
        "green {}",
        n(ColourClass::Green)
    );
    assert!(
        near(n(ColourClass::White), 12_300.0, 0.15),
        "white {}",
        n(ColourClass::White)
    );
    assert!(
        near(n(ColourClass::Orange), 3_900.0, 0.15),
        "orange {}",
        n(ColourClass::Orange)
    );
    let blobs = BlobSet::from_image(&img, Connectivity::Eight);
    let balls: Vec<_> = blobs
        .of_class(ColourClass::Orange)
        .filter(|b| b.pixels >= 100)
        .collect();
    assert_eq!(balls.len(), 1, "{balls:?}");
    let ball = balls[0];
    assert!(
        f64::from(ball.pixels) >= 0.9 * n(ColourClass::Orange),
        "{ball:?}"
    );
    // Round-ish: its box is about as wide as tall and well filled.
    let aspect = f64::from(ball.width()) / f64::from(ball.height());
    assert!((0.6..1.6).contains(&aspect), "{ball:?}");
    assert!(
        f64::from(ball.pixels) > 0.5 * ball.area() as f64,
        "{ball:?}"
    );
    // Green is the most common class: the field (the decoding is neither inverted nor swapped).
    let top = (1..15).max_by_key(|&c| h[c]).unwrap();
    assert_eq!(top, usize::from(ColourClass::Green.code()));
}

#[test]
fn lut_convert_cli_writes_a_loadable_table() {
    let Some(src) = shared_file("data/bhuman2009/coltable.c64") else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("b.lut");
    let o = crate::common::eotn(&[
        "lut".as_ref(),
        "convert".as_ref(),
        src.as_os_str(),
        "-o".as_ref(),
        out.as_os_str(),
        "--json".as_ref(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["format"], "bhuman-c64");
    assert_eq!(v["bits"], 6);
    assert_eq!(v["cells_per_class"]["orange"], 1051);
    let t = LookupTable::load(&out).unwrap();
    assert_eq!(t.bits(), 6);
    // A wrong format is a one-line error naming the file.
    let o = crate::common::eotn(&[
        "lut".as_ref(),
        "convert".as_ref(),
        src.as_os_str(),
        "--format".as_ref(),
        "ssl-xml".as_ref(),
        "-o".as_ref(),
        dir.path().join("x.lut").as_os_str(),
    ]);
    assert!(!o.status.success());
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(e.contains("coltable.c64") && e.contains("ssl-xml"), "{e}");
    assert!(!Path::new(&dir.path().join("x.lut")).exists());
}

#[test]
fn import_bhuman_cli_writes_a_readable_stream() {
    let Some(log) = shared_file("data/bhuman2009/logfile.log") else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("b.mcap");
    let o = crate::common::eotn(&[
        "import".as_ref(),
        "--bhuman".as_ref(),
        log.as_os_str(),
        "-o".as_ref(),
        out.as_os_str(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let mut r = eotn::streams::StreamReader::open(&out).unwrap();
    assert_eq!(r.len(), 160);
    assert_eq!(r.info().source, "bhuman2009");
    assert!(r.info().description.contains("http://www.b-human.de"));
    assert!(r.warnings().is_empty(), "{:?}", r.warnings());
    assert_eq!(r.time_ns(0), Some(0));
    assert!((0..159).all(|i| r.time_ns(i) < r.time_ns(i + 1)));
    let rec = r.read(80).unwrap();
    assert_eq!((rec.frame.width(), rec.frame.height()), (320, 240));
    assert!(rec.sensors.unwrap().head_pan_rad.is_some());
    let raw = rec.extra.iter().find(|(t, _)| t == "/bhuman2009").unwrap();
    assert!(raw.1["image_time_ms"].as_u64().unwrap() > 0);
    // The shipped sample is this stream.
    let shipped = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("streams/bhuman2009.mcap");
    let mut s = eotn::streams::StreamReader::open(&shipped).unwrap();
    assert_eq!(s.len(), 160);
    let shipped_80 = s.read(80).unwrap();
    assert_eq!(shipped_80.frame, rec.frame);
    // ... with the current import's readings (camera pose, head angles at the image time), to
    // the last bit but one: the shipped stream was written while serde_json parsed numbers to
    // within an ulp (before `float_roundtrip`), and re-making it would add 15 MB to the history.
    let as_json = |s: &Option<eotn::sensors::SensorReadings>| serde_json::to_value(s).unwrap();
    let (old, new) = (as_json(&shipped_80.sensors), as_json(&rec.sensors));
    let (old, new) = (old.as_object().unwrap(), new.as_object().unwrap());
    assert_eq!(
        old.keys().collect::<Vec<_>>(),
        new.keys().collect::<Vec<_>>()
    );
    for (k, v) in old {
        match (v.as_f64(), new[k].as_f64()) {
            (Some(a), Some(b)) => assert!(
                (a - b).abs() <= 4.0 * f64::EPSILON * a.abs().max(b.abs()),
                "{k}: {a} shipped, {b} imported"
            ),
            _ => assert_eq!(v, &new[k], "{k}"),
        }
    }
    assert!(rec.sensors.unwrap().camera_height_cm.is_some());
}

#[test]
fn bhuman_camera_matrices_give_the_naos_pose_and_horizon() {
    let Some(log) = bhuman_log() else {
        return;
    };
    // Every image has its cycle's camera matrix; B-Human marks frames 138–159 invalid (the
    // robot picked up after its goal), and those carry no pose.
    assert!(log.frames.iter().all(|f| f.camera_matrix.is_some()));
    let valid: Vec<usize> = (0..160)
        .filter(|&i| log.frames[i].camera_matrix.is_some_and(|m| m.is_valid))
        .collect();
    assert_eq!(valid, (0..138).collect::<Vec<_>>());
    for (i, f) in log.frames.iter().enumerate() {
        let h = f.sensors.camera_height_cm;
        if i < 138 {
            // A standing, walking or crouching Nao: the camera 40–50 cm up.
            assert!(h.is_some_and(|h| (40.0..50.0).contains(&h)), "{i}: {h:?}");
        } else {
            assert_eq!(h, None, "{i}");
        }
    }
    // With B-Human's own focal length (their camera info, kept raw) the horizon through the
    // pose runs where their ImageCoordinateSystem of the same cycle puts it.
    let mut worst = 0.0_f64;
    for &i in &valid {
        let f = &log.frames[i];
        let ics = &f.raw["image_coordinate_system"];
        let focal = ics["focal_length_px"].as_f64().unwrap();
        let params = eotn::recognition::RecognitionParams {
            other_camera_fov_deg: (2.0 * (160.0 / focal).atan()).to_degrees(),
            ..eotn::recognition::RecognitionParams::default()
        };
        let ctx = params.context_for(320, 240, Some(&f.sensors));
        let (ox, oy) = (
            ics["horizon_origin_px"][0].as_f64().unwrap(),
            ics["horizon_origin_px"][1].as_f64().unwrap(),
        );
        let ours = ctx.horizon.unwrap().y_at(ox).unwrap();
        worst = worst.max((ours - oy).abs());
    }
    eprintln!("horizon: ours vs B-Human's ImageCoordinateSystem, worst {worst:.2} px");
    assert!(worst < 1.0, "{worst}");
    // Head tilt keeps B-Human's sign (positive up): the camera looks further down as it falls.
    let (t, p): (Vec<f64>, Vec<f64>) = valid
        .iter()
        .map(|&i| {
            let s = &log.frames[i].sensors;
            (s.head_tilt_rad.unwrap(), s.camera_pitch_rad.unwrap())
        })
        .unzip();
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    let (mt, mp) = (mean(&t), mean(&p));
    let cov: f64 = t.iter().zip(&p).map(|(a, b)| (a - mt) * (b - mp)).sum();
    let var = |v: &[f64], m: f64| v.iter().map(|a| (a - m).powi(2)).sum::<f64>();
    let r = cov / (var(&t, mt) * var(&p, mp)).sqrt();
    assert!(r < -0.95, "head tilt vs camera pitch r = {r}");
}

/// A file of this repository.
/// Whether B-Human frame `i` is held out: its number ends in 7, 8 or 9 (48 of 160;
/// `docs/recognition.md`, "Held-out frames"). No tuning looks at these frames.
fn held_out(i: usize) -> bool {
    i % 10 >= 7
}

/// Recognition on the shipped B-Human stream scored against its hand labels: all frames, and the
/// held-out ones alone.
fn bhuman_labels_reports(
    params: eotn::recognition::RecognitionParams,
) -> [eotn::eval::labels::LabelsReport; 2] {
    use eotn::eval::labels::{Labels, LabelsReport, evaluate_labelled_frame};
    let labels = Labels::load(&repo_file("streams/bhuman2009.labels.json")).unwrap();
    let lut = LookupTable::load(&repo_file("lookup_tables/bhuman2009.lut")).unwrap();
    let mut reader =
        eotn::streams::StreamReader::open(&repo_file("streams/bhuman2009.mcap")).unwrap();
    let mut pipeline = eotn::pipeline::Pipeline::new(
        lut,
        eotn::pipeline::PipelineParams {
            recognition: params,
            ..eotn::pipeline::PipelineParams::default()
        },
    );
    let ep = eotn::eval::EvalParams::default();
    let frames: Vec<_> = (0..reader.len())
        .map(|i| {
            let rec = reader.read(i).unwrap();
            let label = labels.frame(i).expect("every frame is labelled");
            let r = pipeline.process(&rec.frame, rec.sensors.as_ref());
            evaluate_labelled_frame(r.recognition, label, 320.0, 240.0, &ep)
        })
        .collect();
    let kept: Vec<_> = frames
        .iter()
        .enumerate()
        .filter(|(i, _)| held_out(*i))
        .map(|(_, f)| f.clone())
        .collect();
    [
        LabelsReport::from_frames(&frames),
        LabelsReport::from_frames(&kept),
    ]
}

/// One line of a labels report.
fn labels_line(what: &str, r: &eotn::eval::labels::LabelsReport) -> String {
    format!(
        "{what}: {} frames; ball {}/{} (cut {}/{}), false {}, centre error median {:.2} px p90 \
         {:.2} (n = {}), radius error median {:.2} px; goals {}/{}, false {}",
        r.frames,
        r.ball_found,
        r.ball_visible,
        r.ball_cut_found,
        r.ball_cut,
        r.ball_false,
        figure(r.ball_center_error_px, |p| p.p50),
        figure(r.ball_center_error_px, |p| p.p90),
        r.ball_center_error_px.map_or(0, |p| p.n),
        figure(r.ball_radius_error_px, |p| p.p50),
        r.goals_found,
        r.goals_visible,
        r.goals_false
    )
}

#[test]
fn bhuman_stream_against_its_hand_labels() {
    // The stream, its table, the labels and the 2009 SPL parameters are all in the repository.
    let labels =
        eotn::eval::labels::Labels::load(&repo_file("streams/bhuman2009.labels.json")).unwrap();
    assert_eq!(labels.frames.len(), 160);
    let text = std::fs::read_to_string(repo_file("params/spl2009.json")).unwrap();
    let spl: eotn::recognition::RecognitionParams = serde_json::from_str(&text).unwrap();
    // Every key of the shipped file is a parameter (serde would pass over a misspelt one).
    let given: serde_json::Value = serde_json::from_str(&text).unwrap();
    let used = serde_json::to_value(spl).unwrap();
    for (section, values) in given.as_object().unwrap() {
        match values.as_object() {
            Some(fields) => {
                for (k, v) in fields {
                    assert_eq!(&used[section][k], v, "params/spl2009.json: {section}.{k}");
                }
            }
            None => assert_eq!(&used[section], values, "params/spl2009.json: {section}"),
        }
    }
    let [r, kept] = bhuman_labels_reports(spl);
    eprintln!(
        "{}",
        labels_line("B-Human stream, spl2009 parameters, all", &r)
    );
    eprintln!(
        "{}",
        labels_line(
            "B-Human stream, spl2009 parameters, held out (7, 8, 9)",
            &kept
        )
    );
    // Measured 2026-12-01: every labelled ball found (107, the 7 cut by the image edge
    // included), none false (the robot's own red toe at frame 113, its red arms at 28–38 and
    // 59–61), centre error median 0.29 px, every goal found, none false.
    assert_eq!(r.ball_visible, 107);
    assert_eq!(r.ball_found, 107, "missed {:?}", r.ball_missed_frames);
    assert_eq!(r.ball_cut_found, r.ball_cut);
    assert_eq!(r.ball_false, 0, "false {:?}", r.ball_false_frames);
    let centre = sampled(r.ball_center_error_px, 90, "B-Human ball centres");
    assert!(centre.p50 < 0.5 && centre.p90 < 1.5, "{centre:?}");
    let radius = sampled(r.ball_radius_error_px, 90, "B-Human ball radii");
    assert!(radius.p50 < 0.75, "{radius:?}");
    let cut = sampled(r.ball_center_error_cut_px, 5, "B-Human cut balls");
    assert!(cut.p50 < 2.0, "{cut:?}");
    assert_eq!(r.goals_visible, 66);
    assert_eq!(r.goals_found, 66, "missed {:?}", r.goal_missed_frames);
    assert_eq!(r.goals_false, 0, "false {:?}", r.goal_false_frames);
    // The held-out frames alone (numbers ending in 7, 8, 9), which no tuning from 2026-12-04 on
    // looks at; `params/spl2009.json` and `field_below` were tuned on all 160 before the split.
    assert_eq!(kept.frames, 48);
    assert!(kept.ball_visible >= 25, "{}", kept.ball_visible);
    assert_eq!(
        kept.ball_found, kept.ball_visible,
        "missed {:?}",
        kept.ball_missed_frames
    );
    assert_eq!(kept.ball_false, 0, "false {:?}", kept.ball_false_frames);
    let kept_centre = sampled(
        kept.ball_center_error_px,
        25,
        "held-out B-Human ball centres",
    );
    assert!(
        kept_centre.p50 < 0.75 && kept_centre.p90 < 3.0,
        "{kept_centre:?}"
    );
    assert!(kept.goals_visible >= 15, "{}", kept.goals_visible);
    assert_eq!(
        kept.goals_found, kept.goals_visible,
        "missed {:?}",
        kept.goal_missed_frames
    );
    assert_eq!(kept.goals_false, 0, "false {:?}", kept.goal_false_frames);
    // The defaults (ERS-7 goals, a pose taken as exact): the three far balls right after the
    // kick, where the camera matrix is 4–6° off, fail the height test; still nothing false.
    let [d, _] = bhuman_labels_reports(eotn::recognition::RecognitionParams::default());
    assert!(d.ball_found >= 104, "missed {:?}", d.ball_missed_frames);
    assert_eq!(d.ball_false, 0, "false {:?}", d.ball_false_frames);
}

#[test]
fn eval_labels_cli_reports_json_and_refuses_bad_input() {
    let (stream, lut, labels, params) = (
        repo_file("streams/bhuman2009.mcap"),
        repo_file("lookup_tables/bhuman2009.lut"),
        repo_file("streams/bhuman2009.labels.json"),
        repo_file("params/spl2009.json"),
    );
    let o = crate::common::eotn(&[
        "eval".as_ref(),
        stream.as_os_str(),
        "--lut".as_ref(),
        lut.as_os_str(),
        "--labels".as_ref(),
        labels.as_os_str(),
        "--params".as_ref(),
        params.as_os_str(),
        "--json".as_ref(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["report"]["frames"], 160);
    assert_eq!(v["report"]["ball_found"], 107);
    assert_eq!(v["report"]["ball_false"], 0);
    assert_eq!(v["frames"].as_array().unwrap().len(), 160);
    assert!(v["unlabelled_frames"].as_array().unwrap().is_empty());
    // Goals with both ends in view: their size-based distance against their foot's.
    let ratio = &v["goal_size_over_foot"];
    assert!(ratio["n"].as_u64().unwrap() >= 30, "{ratio}");
    let median = ratio["p50"].as_f64().unwrap();
    assert!((0.9..1.25).contains(&median), "{ratio}");
    // `--split held-out`: the frames whose index ends in 7, 8 or 9, and only those.
    let o = crate::common::eotn(&[
        "eval".as_ref(),
        stream.as_os_str(),
        "--lut".as_ref(),
        lut.as_os_str(),
        "--labels".as_ref(),
        labels.as_os_str(),
        "--params".as_ref(),
        params.as_os_str(),
        "--split".as_ref(),
        "held-out".as_ref(),
        "--json".as_ref(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["split"], "held-out");
    assert_eq!(v["report"]["frames"], 48);
    let scored: Vec<u64> = v["frames"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|f| f["frame"].as_u64())
        .collect();
    assert_eq!(scored.len(), 48);
    assert!(scored.iter().all(|n| n % 10 >= 7), "{scored:?}");
    // Two streams, or a file that is not labels: a one-line error naming the problem.
    let o = crate::common::eotn(&[
        "eval".as_ref(),
        stream.as_os_str(),
        stream.as_os_str(),
        "--lut".as_ref(),
        lut.as_os_str(),
        "--labels".as_ref(),
        labels.as_os_str(),
    ]);
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("one stream"));
    let o = crate::common::eotn(&[
        "eval".as_ref(),
        stream.as_os_str(),
        "--lut".as_ref(),
        lut.as_os_str(),
        "--labels".as_ref(),
        params.as_os_str(),
    ]);
    assert!(!o.status.success());
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(e.contains("spl2009.json"), "{e}");
}
