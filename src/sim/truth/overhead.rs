//! The truth of an overhead frame: the ball and every robot in field and image coordinates,
//! with how much of each robot's marker plate shows.

use super::super::render::object_id;
use super::{coverage, covered_fraction};
use crate::geometry::{ImagePoint, OverheadCamera, Point, RobotMarker};
use crate::model::scene::{Robot, Scene};
use crate::model::truth::{OverheadMarkerTruth, OverheadObject, OverheadRobot, OverheadTruth};

/// Builds the truth of an overhead frame.
#[must_use]
pub fn overhead_truth(
    scene: &Scene,
    time_s: f64,
    camera: &OverheadCamera,
    objects: &[u16],
) -> OverheadTruth {
    let w = camera.width_px;
    OverheadTruth {
        time_s,
        camera: *camera,
        ball: scene.ball.map(|b| OverheadObject {
            field_cm: [b.x_cm, b.y_cm],
            image: camera.image_from_field(&Point::new(b.x_cm, b.y_cm, b.radius_cm)),
            visible_pixels: coverage(objects, w, object_id::BALL).pixels,
        }),
        robots: scene
            .robots
            .iter()
            .map(|r| OverheadRobot {
                id: r.id,
                team: r.team,
                field_cm: [r.pose.x_cm, r.pose.y_cm],
                heading_rad: r.pose.heading_rad,
                image: camera.image_from_field(&Point::new(
                    r.pose.x_cm,
                    r.pose.y_cm,
                    r.body.height_cm,
                )),
                visible_pixels: coverage(
                    objects,
                    w,
                    object_id::ROBOT + u16::try_from(r.id).unwrap_or(0).min(899),
                )
                .pixels,
                marker: r
                    .marker
                    .map(|m| overhead_marker_truth(&m, r, camera, objects)),
            })
            .collect(),
    }
}

fn overhead_marker_truth(
    m: &RobotMarker,
    r: &Robot,
    camera: &OverheadCamera,
    objects: &[u16],
) -> OverheadMarkerTruth {
    let n = u16::try_from(r.id).unwrap_or(0).min(899);
    let pixels = coverage(objects, camera.width_px, object_id::ROBOT_MARKER + n).pixels;
    // The plate's full image area: the projected outline as a 64-gon (shoelace formula).
    let radius = crate::geometry::marker::PLATE_DIAMETER_CM / 2.0;
    let outline: Option<Vec<ImagePoint>> = (0..64)
        .map(|k| {
            let a = f64::from(k) * std::f64::consts::TAU / 64.0;
            camera.image_from_field(&Point::new(
                r.pose.x_cm + radius * a.cos(),
                r.pose.y_cm + radius * a.sin(),
                m.plate_height_cm,
            ))
        })
        .collect();
    let area = outline.map_or(0.0, |o| {
        let twice: f64 = o
            .iter()
            .zip(o.iter().cycle().skip(1))
            .map(|(a, b)| a.x_px * b.y_px - b.x_px * a.y_px)
            .sum();
        twice.abs() / 2.0
    });
    OverheadMarkerTruth {
        team: m.team,
        identity: m.identity,
        plate_height_cm: m.plate_height_cm,
        image: camera.image_from_field(&Point::new(r.pose.x_cm, r.pose.y_cm, m.plate_height_cm)),
        visible_fraction: covered_fraction(pixels, area),
    }
}
