//! Frames without sensor readings (a folder of PNGs, a phone photo of the field): no camera
//! pose, so no horizon and no height test. The renderer's scenarios are detected with and
//! without their readings; off-field orange (the orange-clutter scenario's chair, bag and the
//! toy ball on a table in the audience, above the field in the image) must not be reported as
//! the ball, and the real ball must win over it, on the seed the test was tuned on (7) and on
//! held-out seeds (11, 23). The real B-Human frames, stripped of their readings, must report no
//! ball where their hand labels have none and no ball other than the one chosen with readings.
//! The figures are in `docs/recognition.md`.

use eotn::eval::labels::{Labels, evaluate_labelled_frame};
use eotn::eval::{EvalParams, evaluate_frame};
use eotn::frame::Frame;
use eotn::lut::LookupTable;
use eotn::model::truth::GroundTruth;
use eotn::pipeline::{Pipeline, PipelineParams};
use eotn::recognition::confidence::TestWeight;
use eotn::recognition::{RecognitionParams, params_file};
use eotn::sensors::SensorReadings;
use eotn::sim::{Scenario, ScenarioKind, Simulator};
use eotn::streams::StreamReader;

use crate::recognition::learnt_table;

/// What detection made of one scenario's frames.
#[derive(Debug, Default, Clone, Copy, PartialEq, Eq)]
struct BallChoices {
    /// Frames.
    frames: usize,
    /// Frames where no pixel of the true ball is in view.
    without_ball: usize,
    /// ... of which a ball was reported in (a false ball).
    false_balls: usize,
    /// Frames where the true ball is in view.
    with_ball: usize,
    /// ... of which a ball was reported somewhere else (off-field orange chosen: a wrong choice).
    wrong_choices: usize,
    /// Frames where the ball had to be found (eligible).
    eligible: usize,
    /// ... of which it was found where it is.
    found: usize,
}

/// How a scenario is detected.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Setting {
    /// With the frames' sensor readings.
    WithReadings,
    /// Without readings, the field-below test switched off (as before 2026-12-03).
    WithoutReadingsBefore,
    /// Without readings, as shipped.
    WithoutReadings,
}

fn choices(kind: ScenarioKind, seed: u64, lut: &LookupTable, setting: Setting) -> BallChoices {
    let sim = Simulator::new(Scenario::new(kind, seed));
    let mut params = PipelineParams::default();
    if setting == Setting::WithoutReadingsBefore {
        params.recognition.ball.field_below_without_pose_weight = TestWeight::new(0.0, 0.0);
    }
    let with_readings = setting == Setting::WithReadings;
    let mut pipeline = Pipeline::new(lut.clone(), params);
    let mut c = BallChoices::default();
    for i in 0..90 {
        let f = sim.frame(i).expect("frame");
        let GroundTruth::Robot(truth) = &f.ground_truth else {
            panic!("robot scenario gave an overhead frame");
        };
        let readings = if with_readings {
            f.sensors.as_ref()
        } else {
            None
        };
        let r = pipeline.process(&f.frame, readings);
        let (w, h) = (f.frame.width() as f64, f.frame.height() as f64);
        let e = evaluate_frame(
            i as usize,
            r.recognition,
            truth,
            w,
            h,
            &EvalParams::default(),
        );
        let seen = truth
            .ball
            .as_ref()
            .filter(|b| b.visible_pixels > 0)
            .and_then(|b| b.image_box);
        let reported = r.recognition.ball.ball.as_ref();
        let mut found_real_ball = false;
        c.frames += 1;
        if let Some(b) = seen {
            c.with_ball += 1;
            // The real ball was chosen when the reported circle, where the image shows it,
            // reaches the true ball's pixels (give or take 2 px; a ball cut by the image edge
            // has its centre outside them). Without readings there is no pan velocity, so no
            // skew correction, and a fast pan's ball is reported where the image shows it
            // rather than where the truth puts it at the reference row: not a wrong choice.
            let reaches = |p: eotn::geometry::ImagePoint, r: f64| {
                let (x, y) = (p.x_px, p.y_px);
                let dx = (b.min_x as f64 - x)
                    .max(x - (b.max_x as f64 + 1.0))
                    .max(0.0);
                let dy = (b.min_y as f64 - y)
                    .max(y - (b.max_y as f64 + 1.0))
                    .max(0.0);
                dx.hypot(dy) <= r + 2.0
            };
            found_real_ball =
                reported.is_some_and(|ball| reaches(ball.observed_center, ball.radius_px));
            if let Some(ball) = reported
                && !found_real_ball
            {
                c.wrong_choices += 1;
                let cand = &r.recognition.ball.candidates[ball.candidate];
                eprintln!(
                    "{} seed {seed} {setting:?} frame {i}: wrong choice at {:?} r {:.1}, ball in {b:?}: {:?}",
                    kind.name(),
                    ball.observed_center,
                    ball.radius_px,
                    cand.confidence
                        .tests
                        .iter()
                        .map(|t| format!("{} {:.2} {:+}", t.test, t.value, t.effect))
                        .collect::<Vec<_>>()
                );
            }
        } else {
            c.without_ball += 1;
            if let Some(ball) = reported {
                c.false_balls += 1;
                let cand = &r.recognition.ball.candidates[ball.candidate];
                eprintln!(
                    "{} seed {seed} {setting:?} frame {i}: false ball at {:?}: {:?}",
                    kind.name(),
                    ball.observed_center,
                    cand.confidence
                        .tests
                        .iter()
                        .map(|t| format!("{} {:.2} {:+}", t.test, t.value, t.effect))
                        .collect::<Vec<_>>()
                );
            }
        }
        c.eligible += usize::from(e.ball_eligible);
        c.found += usize::from(e.ball_eligible && found_real_ball);
    }
    c
}

/// The six robot scenarios point 5 of issue 15 was measured on.
const KINDS: [ScenarioKind; 6] = [
    ScenarioKind::OrangeClutter,
    ScenarioKind::WalkAndPan,
    ScenarioKind::BallEdge,
    ScenarioKind::Goalkeeper,
    ScenarioKind::FastPans,
    ScenarioKind::BeaconTour,
];

impl BallChoices {
    fn add(&mut self, c: Self) {
        self.frames += c.frames;
        self.without_ball += c.without_ball;
        self.false_balls += c.false_balls;
        self.with_ball += c.with_ball;
        self.wrong_choices += c.wrong_choices;
        self.eligible += c.eligible;
        self.found += c.found;
    }
}

#[test]
fn no_false_ball_and_the_real_ball_chosen_with_or_without_readings() {
    let lut = learnt_table();
    let settings = [
        Setting::WithReadings,
        Setting::WithoutReadingsBefore,
        Setting::WithoutReadings,
    ];
    let mut totals = [BallChoices::default(); 3];
    for kind in KINDS {
        for (t, setting) in totals.iter_mut().zip(settings) {
            let c = choices(kind, 7, &lut, setting);
            eprintln!("{} {setting:?}: {c:?}", kind.name());
            t.add(c);
        }
    }
    let [with, before, without] = totals;
    eprintln!(
        "with readings: {with:?}\nwithout, before: {before:?}\nwithout readings: {without:?}"
    );
    // Without the field-below test, off-field orange wins in frames without readings.
    assert!(
        before.false_balls + before.wrong_choices > 0,
        "the scenarios must show the problem: {before:?}"
    );
    assert!(
        without.without_ball >= 20 && without.with_ball >= 100,
        "the scenarios must have frames with and without the ball: {without:?}"
    );
    for (what, c) in [("with readings", with), ("without readings", without)] {
        assert_eq!(
            c.false_balls, 0,
            "{what}: a ball reported where none is: {c:?}"
        );
        assert_eq!(c.wrong_choices, 0, "{what}: off-field orange chosen: {c:?}");
    }
    // Rejecting what has no field colour below must not cost the real ball: without a pose
    // nearly every eligible ball is still found.
    assert!(
        without.found as f64 >= 0.95 * without.eligible as f64,
        "without readings: {without:?}"
    );
}

#[test]
fn held_out_seeds_11_and_23_no_false_ball_and_the_real_ball_chosen_without_readings() {
    // The field-below penalty was chosen on seed 7; seeds 11 and 23 were not looked at before
    // it was. Only the orange-clutter scenario has off-field orange, so only it is also run as
    // before the test (to show these seeds have the problem).
    let lut = learnt_table();
    for seed in [11, 23] {
        let mut with = BallChoices::default();
        let mut without = BallChoices::default();
        for kind in KINDS {
            let c = choices(kind, seed, &lut, Setting::WithReadings);
            let d = choices(kind, seed, &lut, Setting::WithoutReadings);
            eprintln!("seed {seed} {}: with {c:?}\n    without {d:?}", kind.name());
            with.add(c);
            without.add(d);
        }
        let before = choices(
            ScenarioKind::OrangeClutter,
            seed,
            &lut,
            Setting::WithoutReadingsBefore,
        );
        eprintln!(
            "seed {seed}: with readings {with:?}\n\
             seed {seed}: without readings {without:?}\n\
             seed {seed}: orange-clutter without readings, before {before:?}"
        );
        assert!(
            before.false_balls + before.wrong_choices > 0,
            "seed {seed} must show the problem: {before:?}"
        );
        for (what, c) in [("with readings", with), ("without readings", without)] {
            assert_eq!(c.false_balls, 0, "seed {seed} {what}: {c:?}");
            assert_eq!(c.wrong_choices, 0, "seed {seed} {what}: {c:?}");
        }
        assert!(
            without.found as f64 >= 0.95 * without.eligible as f64 && without.eligible >= 100,
            "seed {seed} without readings: {without:?}"
        );
    }
}

/// Where a frame's reported ball is: observed centre and radius, pixels.
type Choice = Option<(eotn::geometry::ImagePoint, f64)>;

/// What detection made of real frames against their hand labels.
#[derive(Debug, Default, Clone, PartialEq)]
struct LabelledChoices {
    /// Frames.
    frames: usize,
    /// Frames labelled without a ball.
    without_ball: usize,
    /// ... in which a ball was reported (a false ball).
    false_balls: Vec<usize>,
    /// Frames with a labelled ball.
    with_ball: usize,
    /// ... in which a ball was reported more than two radii from it (a wrong choice).
    wrong_choices: Vec<usize>,
    /// ... in which it was found (within the labels' match tolerance).
    found: usize,
    /// ... in which it was not found (no ball, or one reported near but off).
    missed: Vec<usize>,
}

/// Real frames, each with the readings recorded beside it.
type RealFrames = Vec<(Frame, Option<SensorReadings>)>;

fn repo_file(relative: &str) -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(relative)
}

/// The shipped B-Human stream's 160 frames with their readings.
fn bhuman_stream_frames() -> RealFrames {
    let mut reader = StreamReader::open(&repo_file("streams/bhuman2009.mcap")).unwrap();
    (0..reader.len())
        .map(|i| {
            let rec = reader.read(i).unwrap();
            (rec.frame, rec.sensors)
        })
        .collect()
}

/// Detects every frame with its readings or without any, against the labels.
fn labelled_choices(
    frames: &RealFrames,
    labels: &Labels,
    lut: &LookupTable,
    recognition: RecognitionParams,
    with_readings: bool,
) -> (LabelledChoices, Vec<Choice>) {
    let params = PipelineParams {
        recognition,
        ..PipelineParams::default()
    };
    let mut pipeline = Pipeline::new(lut.clone(), params);
    let ep = EvalParams::default();
    let mut c = LabelledChoices::default();
    let mut per_frame = Vec::with_capacity(frames.len());
    for (i, (frame, sensors)) in frames.iter().enumerate() {
        let readings = if with_readings {
            sensors.as_ref()
        } else {
            None
        };
        let r = pipeline.process(frame, readings);
        let label = labels.frame(i).expect("every frame is labelled");
        let (w, h) = (frame.width() as f64, frame.height() as f64);
        let e = evaluate_labelled_frame(r.recognition, label, w, h, &ep);
        let ball = r.recognition.ball.ball.as_ref();
        per_frame.push(ball.map(|b| (b.observed_center, b.radius_px)));
        c.frames += 1;
        if e.ball_visible {
            c.with_ball += 1;
            if e.ball_found {
                c.found += 1;
            } else {
                c.missed.push(i);
                for cand in r
                    .recognition
                    .ball
                    .candidates
                    .iter()
                    .filter(|c| c.pixels >= 20)
                {
                    eprintln!(
                        "  missed frame {i} (readings: {with_readings}): candidate {:?} {} px, \
                         confidence {:.2}: {:?}",
                        cand.bounds,
                        cand.pixels,
                        cand.confidence.total,
                        cand.confidence
                            .tests
                            .iter()
                            .map(|t| format!("{} {:.2} {:+}", t.test, t.value, t.effect))
                            .collect::<Vec<_>>()
                    );
                }
            }
            if e.ball_reported && !e.ball_near {
                c.wrong_choices.push(i);
            }
        } else {
            c.without_ball += 1;
            if e.ball_reported {
                c.false_balls.push(i);
            }
        }
    }
    (c, per_frame)
}

/// Frames whose ball choice differs: reported in one and not the other, or centres more than
/// `tolerance_px` apart.
fn differing_choices(a: &[Choice], b: &[Choice], tolerance_px: f64) -> Vec<usize> {
    a.iter()
        .zip(b)
        .enumerate()
        .filter(|(_, (x, y))| match (x, y) {
            (None, None) => false,
            (Some((p, _)), Some((q, _))) => p.distance_to(q) > tolerance_px,
            _ => true,
        })
        .map(|(i, _)| i)
        .collect()
}

/// B-Human frames whose ball is missed without readings, and why (2026-12-03,
/// `docs/recognition.md`): 49–51 and 64, a big ball lying on a field line, the band below it
/// all line (white counts only beside green); 112, a ball cut by the top edge whose shadowed
/// lower half classifies black, so the band below its orange part is on the ball itself.
const BHUMAN_MISSED_WITHOUT_READINGS: [usize; 5] = [49, 50, 51, 64, 112];

#[test]
fn real_bhuman_frames_without_readings_report_no_false_ball_and_no_other_choice() {
    let frames = bhuman_stream_frames();
    assert_eq!(frames.len(), 160);
    let labels = Labels::load(&repo_file("streams/bhuman2009.labels.json")).unwrap();
    let lut = LookupTable::load(&repo_file("lookup_tables/bhuman2009.lut")).unwrap();
    let spl = params_file::load(&repo_file("params/spl2009.json")).unwrap();
    let mut spl_before = spl;
    spl_before.ball.field_below_without_pose_weight = TestWeight::new(0.0, 0.0);
    let (with, a) = labelled_choices(&frames, &labels, &lut, spl, true);
    let (without, b) = labelled_choices(&frames, &labels, &lut, spl, false);
    let (before, _) = labelled_choices(&frames, &labels, &lut, spl_before, false);
    let differ = differing_choices(&a, &b, 1.0);
    eprintln!(
        "B-Human stream, spl2009:\n  with readings {with:?}\n  without readings {without:?}\n  \
         without readings, before {before:?}\n  choices differ in {differ:?}"
    );
    for &i in &differ {
        eprintln!("    frame {i}: with {:?}, without {:?}", a[i], b[i]);
    }
    assert_eq!((with.with_ball, with.without_ball), (107, 53));
    assert_eq!(with.found, 107, "with readings: {with:?}");
    for (what, c) in [("with readings", &with), ("without readings", &without)] {
        assert!(c.false_balls.is_empty(), "{what}: false balls {c:?}");
        assert!(c.wrong_choices.is_empty(), "{what}: wrong choices {c:?}");
    }
    // Without readings a ball is either the one chosen with them or none: where both report
    // one it is the same ball (frame 63's is cut by the image's bottom edge and fitted a few
    // pixels apart), and the only frames that lose it are the known ones.
    for &i in &differ {
        match (a[i], b[i]) {
            (Some((p, r)), Some((q, _))) => {
                assert!(p.distance_to(&q) < r, "frame {i}: {p:?} vs {q:?}");
            }
            (Some(_), None) => assert!(
                BHUMAN_MISSED_WITHOUT_READINGS.contains(&i),
                "frame {i}: the ball is lost without readings"
            ),
            _ => panic!("frame {i}: a ball without readings and none with them"),
        }
    }
    assert!(
        without
            .missed
            .iter()
            .all(|i| BHUMAN_MISSED_WITHOUT_READINGS.contains(i)),
        "{without:?}"
    );
}
