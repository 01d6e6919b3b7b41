//! Recognition results as `foxglove.ImageAnnotations`, so a stream processed by eotn shows its
//! overlays in Foxglove and Rerun as it does in eotn (`eotn detect --annotate OUT.mcap`).
//!
//! The annotations hold what was found: the horizon and every accepted object's primitives (box,
//! circles — the skew-corrected one thinner —, posts, gap, scan areas and points, label), in the
//! one palette of [`crate::overlay::primitive_rgb`]. Coordinates are image pixels with the origin
//! at the top-left corner of the top-left pixel, as FORMATS.md and the Foxglove schema agree.

use foxglove::messages::{
    CircleAnnotation, Color, ImageAnnotations, Point2, PointsAnnotation, TextAnnotation, Timestamp,
    points_annotation::Type as PointsType,
};

use crate::frame::ImagePoint;
use crate::overlay::primitive_rgb;
use crate::recognition::{CircleRole, ObjectId, Primitive, Recognition};

/// Line width of outlines, pixels.
const THICKNESS_PX: f64 = 1.0;
/// Line width of the skew-corrected circle, pixels: thinner, as the app draws it.
const THIN_PX: f64 = 0.5;
/// Size of the points found by edge scans, pixels.
const POINT_PX: f64 = 2.0;
/// Font size of labels, pixels.
const FONT_PX: f64 = 10.0;

/// The annotations of one frame's recognition, stamped `time_ns` (nanoseconds, as the frame).
/// `width` × `height` is the frame's size in pixels (the horizon is clipped to it).
#[must_use]
pub fn image_annotations(
    r: &Recognition,
    width: usize,
    height: usize,
    time_ns: u64,
) -> ImageAnnotations {
    let accepted = r.accepted_owners();
    let shown = r
        .primitives(width, height)
        .into_iter()
        .filter(|p| p.owner() == ObjectId::Horizon || accepted.contains(&p.owner()));
    let stamp = timestamp(time_ns);
    let mut out = ImageAnnotations {
        timestamp: Some(stamp),
        ..ImageAnnotations::default()
    };
    for p in shown {
        add(&mut out, &p, stamp);
    }
    out
}

/// Adds one primitive to `out`.
fn add(out: &mut ImageAnnotations, p: &Primitive, stamp: Timestamp) {
    let colour = color(primitive_rgb(p));
    let points = |kind: PointsType, pts: Vec<Point2>, thickness: f64| PointsAnnotation {
        timestamp: Some(stamp),
        r#type: kind as i32,
        points: pts,
        outline_color: Some(colour),
        thickness,
        ..PointsAnnotation::default()
    };
    match p {
        Primitive::Box { bounds, .. } => {
            let [x0, y0, x1, y1] = bounds.to_array().map(f64::from);
            out.points.push(points(
                PointsType::LineLoop,
                rect(x0, y0, x1 + 1.0, y1 + 1.0),
                THICKNESS_PX,
            ));
        }
        Primitive::PatternRegion { bounds, .. } => {
            let [x0, y0, x1, y1] = bounds.map(|v| v as f64);
            out.points.push(points(
                PointsType::LineLoop,
                rect(x0, y0, x1 + 1.0, y1 + 1.0),
                THICKNESS_PX,
            ));
        }
        Primitive::ScanArea { corners, .. } => {
            let pts = corners.iter().copied().map(point2).collect();
            out.points
                .push(points(PointsType::LineLoop, pts, THICKNESS_PX));
        }
        Primitive::ScanPoints { points: pts, .. } => {
            let pts = pts.iter().copied().map(point2).collect();
            out.points.push(points(PointsType::Points, pts, POINT_PX));
        }
        Primitive::Line { from, to, .. } => {
            let pts = vec![point2(*from), point2(*to)];
            out.points
                .push(points(PointsType::LineStrip, pts, THICKNESS_PX));
        }
        Primitive::Circle {
            center,
            radius,
            role,
            ..
        } => out.circles.push(CircleAnnotation {
            timestamp: Some(stamp),
            position: Some(point2(*center)),
            diameter: 2.0 * radius,
            thickness: match role {
                CircleRole::Observed => THICKNESS_PX,
                CircleRole::SkewCorrected => THIN_PX,
            },
            outline_color: Some(colour),
            ..CircleAnnotation::default()
        }),
        Primitive::Label { at, text, .. } => out.texts.push(TextAnnotation {
            timestamp: Some(stamp),
            position: Some(point2(*at)),
            text: text.clone(),
            font_size: FONT_PX,
            text_color: Some(colour),
            background_color: Some(Color {
                r: 0.0,
                g: 0.0,
                b: 0.0,
                a: 0.6,
            }),
            ..TextAnnotation::default()
        }),
    }
}

/// The corners of the pixel-edge rectangle from (x0, y0) to (x1, y1).
/// An image point as Foxglove's point, pixels.
fn point2(p: ImagePoint) -> Point2 {
    Point2 {
        x: p.x_px,
        y: p.y_px,
    }
}

fn rect(x0: f64, y0: f64, x1: f64, y1: f64) -> Vec<Point2> {
    vec![
        Point2 { x: x0, y: y0 },
        Point2 { x: x1, y: y0 },
        Point2 { x: x1, y: y1 },
        Point2 { x: x0, y: y1 },
    ]
}

/// An opaque colour from 8-bit RGB.
fn color([r, g, b]: [u8; 3]) -> Color {
    Color {
        r: f64::from(r) / 255.0,
        g: f64::from(g) / 255.0,
        b: f64::from(b) / 255.0,
        a: 1.0,
    }
}

/// A protobuf timestamp from nanoseconds.
fn timestamp(time_ns: u64) -> Timestamp {
    let sec = u32::try_from(time_ns / 1_000_000_000).unwrap_or(u32::MAX);
    let nsec = u32::try_from(time_ns % 1_000_000_000).unwrap_or(0);
    Timestamp::new(sec, nsec)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_circle_and_a_box_become_annotations_in_the_overlay_palette() {
        let mut out = ImageAnnotations::default();
        let stamp = timestamp(1_500_000_000);
        add(
            &mut out,
            &Primitive::Circle {
                owner: ObjectId::Ball(0),
                center: ImagePoint::new(10.5, 20.0),
                radius: 4.0,
                role: CircleRole::SkewCorrected,
            },
            stamp,
        );
        add(
            &mut out,
            &Primitive::Box {
                owner: ObjectId::Ball(0),
                colour: 1,
                bounds: crate::frame::PixelBox::new(2, 3, 5, 7),
            },
            stamp,
        );
        let c = &out.circles[0];
        assert_eq!(c.diameter, 8.0);
        assert_eq!(c.thickness, THIN_PX);
        let p = c.position.unwrap();
        assert_eq!((p.x, p.y), (10.5, 20.0));
        let b = &out.points[0];
        assert_eq!(b.r#type, PointsType::LineLoop as i32);
        let xs: Vec<(f64, f64)> = b.points.iter().map(|p| (p.x, p.y)).collect();
        assert_eq!(xs, vec![(2.0, 3.0), (6.0, 3.0), (6.0, 8.0), (2.0, 8.0)]);
        let orange = crate::lut::code_display_rgb(1);
        let oc = b.outline_color.unwrap();
        assert_eq!(oc.r, f64::from(orange[0]) / 255.0);
        assert_eq!(stamp.sec(), 1);
    }
}
