//! Beacons per frame: each true beacon (band pixels, visible fraction, cut sides, distance) and
//! each candidate (kind, box, distance, confidence and the tests that failed).

use eotn::eval::EvalParams;
use eotn::eval::beacons::beacon_is_whole;
use eotn::lut::ColourClass;
use eotn::model::truth::GroundTruth;
use eotn::pipeline::{Pipeline, PipelineParams};
use eotn::sim::{Scenario, ScenarioKind, Simulator};

use crate::debug_setup;

/// `EOTN_DEBUG_SCENARIO=orange-clutter cargo run --example debug_recognition
/// --no-default-features -- beacons`.
pub fn debug_beacons() {
    let name = std::env::var("EOTN_DEBUG_SCENARIO").unwrap_or_else(|_| "beacon-tour".into());
    let kind = ScenarioKind::from_name(&name).expect("scenario name");
    let (lut, seed, count) = debug_setup();
    let sim = Simulator::new(Scenario::new(kind, seed));
    let mut pipeline = Pipeline::new(lut, PipelineParams::default());
    let p = EvalParams::default();
    for i in 0..count {
        let f = sim.frame(i).expect("frame");
        let GroundTruth::Robot(truth) = &f.ground_truth else {
            continue;
        };
        let r = pipeline.process(&f.frame, f.sensors.as_ref());
        // The true edges: the near side of each beacon on its axis at 40, 30 and 20 cm,
        // projected with the camera at mid read-out.
        let pose = eotn::geometry::CameraPose {
            camera: eotn::geometry::PinholeCamera::ers7(),
            field_from_camera: truth.camera_pose.to_transform(),
        };
        let scene = eotn::model::Scene::four_legged_2005();
        for t in truth.beacons.iter().filter(|t| t.visible_pixels > 0) {
            if let Some(b) = scene.beacons.iter().find(|b| b.name == t.name) {
                let c = pose.position();
                let (dx, dy) = (b.x_cm - c.x(), b.y_cm - c.y());
                let d = dx.hypot(dy);
                let near = |z: f64| {
                    pose.image_from_field(&eotn::geometry::Point::new(
                        b.x_cm - dx / d * b.radius_cm,
                        b.y_cm - dy / d * b.radius_cm,
                        z,
                    ))
                    .map(|p| format!("({:.2}, {:.2})", p.x_px, p.y_px))
                };
                eprintln!(
                    "#{i} truth edges {:?} {:?} {:?}; camera z {:.1} cm",
                    near(40.0),
                    near(30.0),
                    near(20.0),
                    c.z()
                );
            }
            eprintln!(
                "#{i} truth {} pixels {} bands {} ({:.2} visible, cut {:?}) box {:?} distance \
                 {:.1} cm{}",
                t.name,
                t.visible_pixels,
                t.band_pixels,
                t.bands_visible_fraction,
                t.bands_cut_off,
                t.bands_box.map(|b| b.to_array()),
                t.relative.camera_distance_cm,
                if beacon_is_whole(t, &p) { " WHOLE" } else { "" }
            );
        }
        for b in &r.recognition.beacons {
            let failed: Vec<String> = b
                .confidence
                .tests
                .iter()
                .filter(|t| t.effect < 0.0)
                .map(|t| format!("{:?} {:.2}", t.test, t.value))
                .collect();
            let edges: Vec<String> = b
                .edges
                .iter()
                .map(|p| format!("({:.2}, {:.2})", p.x_px, p.y_px))
                .collect();
            eprintln!(
                "#{i}   found {} {:?} cut {} edges {edges:?} {:?} distance {:.1} cm confidence \
                 {:.1}{} {failed:?}",
                b.kind.name(),
                b.bounds.to_array(),
                b.cut_off,
                b.distance_from,
                b.camera.distance_cm,
                b.confidence.total,
                if b.accepted { " ACCEPTED" } else { "" }
            );
        }
        if let Ok(at) = std::env::var("EOTN_DEBUG_PIXELS") {
            // "x0,y0,x1,y1": the classified codes there, one hex digit a pixel.
            let v: Vec<usize> = at.split(',').filter_map(|s| s.parse().ok()).collect();
            if let [x0, y0, x1, y1] = v[..] {
                for y in y0..=y1 {
                    let row: String = (x0..=x1)
                        .map(|x| format!("{:x}", r.classified.get(x, y).unwrap_or(0)))
                        .collect();
                    eprintln!("#{i}   {y:3} {row}");
                }
            }
        }
        let count = |c: ColourClass| r.blobs.of_class(c).filter(|b| b.pixels >= 6).count();
        if std::env::var_os("EOTN_DEBUG_BLOBS").is_some() {
            for c in [ColourClass::Pink, ColourClass::Yellow, ColourClass::SkyBlue] {
                for b in r.blobs.of_class(c).filter(|b| b.pixels >= 6) {
                    eprintln!(
                        "#{i}   blob {} {:?} {} px",
                        c.name(),
                        b.bounds().to_array(),
                        b.pixels
                    );
                }
            }
            eprintln!(
                "#{i}   pink {} yellow {} sky blue {}",
                count(ColourClass::Pink),
                count(ColourClass::Yellow),
                count(ColourClass::SkyBlue)
            );
        }
    }
}
