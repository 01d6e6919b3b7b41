//! Properties over random input (proptest): blob formation against a plain flood fill, table
//! edits undone to the identity, camera rays projected back to their pixel, line and circle fits
//! on exact and degenerate points, rotations and transforms against their inverses, the overhead
//! camera's image ↔ field round trip.

use eotn::blobs::{BlobSet, Connectivity};
use eotn::classify::ClassifiedImage;
use eotn::frame::Yuv;
use eotn::geometry::camera::{ImagePoint, PinholeCamera};
use eotn::geometry::overhead::OverheadCamera;
use eotn::geometry::{Body, Camera, Point, Transform, rotation_x, rotation_y, rotation_z};
use eotn::lut::edit::{EditHistory, EditRecord, Region, Sensitivity};
use eotn::lut::{ColourClass, LookupTable};
use eotn::recognition::fit::{fit_circle, fit_line};
use proptest::prelude::*;

/// (colour, pixels, minx, miny, maxx, maxy) of every blob, sorted: what both finders must agree on.
type BlobKey = (u8, u32, u32, u32, u32, u32);

/// The reference: a breadth-first flood fill from every unvisited classified pixel.
fn flood_fill_blobs(w: usize, h: usize, codes: &[u8], eight: bool) -> Vec<BlobKey> {
    let mut seen = vec![false; w * h];
    let mut out = Vec::new();
    for start in 0..w * h {
        if seen[start] || codes[start] == 0 {
            continue;
        }
        let colour = codes[start];
        let (mut n, mut b) = (0u32, [u32::MAX, u32::MAX, 0, 0]);
        let mut queue = vec![start];
        seen[start] = true;
        while let Some(i) = queue.pop() {
            let (x, y) = (i % w, i / w);
            n += 1;
            b = [
                b[0].min(x as u32),
                b[1].min(y as u32),
                b[2].max(x as u32),
                b[3].max(y as u32),
            ];
            for dy in -1i64..=1 {
                for dx in -1i64..=1 {
                    if (dx == 0 && dy == 0) || (!eight && dx != 0 && dy != 0) {
                        continue;
                    }
                    let (nx, ny) = (x as i64 + dx, y as i64 + dy);
                    if nx < 0 || ny < 0 || nx >= w as i64 || ny >= h as i64 {
                        continue;
                    }
                    let j = ny as usize * w + nx as usize;
                    if !seen[j] && codes[j] == colour {
                        seen[j] = true;
                        queue.push(j);
                    }
                }
            }
        }
        out.push((colour, n, b[0], b[1], b[2], b[3]));
    }
    out.sort_unstable();
    out
}

/// Random class images: few colours, so that blobs touch and wind around each other.
fn images() -> impl Strategy<Value = (usize, usize, Vec<u8>)> {
    (1usize..40, 1usize..24).prop_flat_map(|(w, h)| {
        (
            Just(w),
            Just(h),
            proptest::collection::vec(
                prop_oneof![Just(0u8), Just(1u8), Just(5u8), Just(6u8)],
                w * h,
            ),
        )
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    #[test]
    fn blobs_equal_a_flood_fill_with_either_connectivity((w, h, codes) in images()) {
        let img = ClassifiedImage::from_codes(w, h, codes.clone()).unwrap();
        for (conn, eight) in [(Connectivity::Four, false), (Connectivity::Eight, true)] {
            let mut set = BlobSet::default();
            set.find(&img, conn);
            let mut ours: Vec<BlobKey> = set
                .active()
                .map(|b| (b.colour, b.pixels, b.minx, b.miny, b.maxx, b.maxy))
                .collect();
            ours.sort_unstable();
            prop_assert_eq!(ours, flood_fill_blobs(w, h, &codes, eight));
        }
    }

    #[test]
    fn table_edits_undone_give_the_table_back_and_redone_give_the_edit_again(
        edits in proptest::collection::vec((any::<[u8; 3]>(), 0u8..6, 0usize..15), 1..6),
        bits in prop_oneof![Just(6u8), Just(7u8)],
    ) {
        let mut lut = LookupTable::new(bits).unwrap();
        let original = lut.clone();
        let mut history = EditHistory::default();
        for ([y, u, v], reach, class) in &edits {
            let class = ColourClass::ALL[*class % ColourClass::ALL.len()];
            let region = Region::AroundSample {
                sample: Yuv::new(*y, *u, *v),
                sensitivity: Sensitivity::uniform(*reach),
            };
            history.commit(&mut lut, EditRecord { class, region, time_unix_ms: 0, sampled_at: None });
        }
        let edited = lut.clone();
        while history.undo(&mut lut).is_some() {}
        prop_assert!(lut == original, "undoing every edit changed the table");
        while history.redo(&mut lut).is_some() {}
        prop_assert!(lut == edited, "redoing every edit did not give the edited table");
    }

    #[test]
    fn a_pixel_ray_projects_back_to_its_pixel(x in 0.0f64..208.0, y in 0.0f64..160.0, fov in 20.0f64..120.0) {
        for cam in [PinholeCamera::ers7(), PinholeCamera::from_horizontal_fov(208, 160, fov.to_radians())] {
            let p = ImagePoint { x_px: x, y_px: y };
            let back = cam.project_direction(&cam.ray(p)).unwrap();
            prop_assert!((back.x_px - x).abs() < 1e-9 && (back.y_px - y).abs() < 1e-9, "{:?} -> {:?}", p, back);
        }
    }
}

/// An image point, pixels.
fn pt(x: f64, y: f64) -> ImagePoint {
    ImagePoint::new(x, y)
}

/// Coordinates a fit meets in images: up to a few thousand pixels, either side of the image.
fn coordinate() -> impl Strategy<Value = f64> {
    -2000.0f64..2000.0
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    #[test]
    fn a_line_through_points_on_a_line_is_that_line(
        x0 in coordinate(), y0 in coordinate(), angle in 0.0f64..std::f64::consts::PI,
        steps in proptest::collection::vec(-300.0f64..300.0, 2..40),
    ) {
        let (dx, dy) = (angle.cos(), angle.sin());
        let points: Vec<_> = steps.iter().map(|t| pt(x0 + t * dx, y0 + t * dy)).collect();
        let spread = steps.iter().fold(f64::MIN, |a, &t| a.max(t)) - steps.iter().fold(f64::MAX, |a, &t| a.min(t));
        match fit_line(&points) {
            // Only points that (nearly) coincide have no line.
            None => prop_assert!(spread < 1e-6, "no line through {points:?}"),
            Some(line) => {
                prop_assume!(spread > 1e-3);
                // Every point lies on the fitted line, whichever way it was regressed.
                for &ImagePoint { x_px: x, y_px: y } in &points {
                    let on = if line.steep { line.at(y) } else { line.at(x) };
                    prop_assert!((on.x_px - x).abs() + (on.y_px - y).abs() < 1e-6 * (1.0 + x.abs() + y.abs()), "{line:?} misses ({x}, {y})");
                }
                prop_assert!(line.slope.abs() <= 1.0 + 1e-9, "the regression is not the flatter way round: {line:?}");
                prop_assert!(line.residual_variance < 1e-6 * (1.0 + x0.abs() + y0.abs()));
            }
        }
    }

    #[test]
    fn vertical_horizontal_and_two_point_lines_are_exact(c in coordinate(), a in coordinate(), len in 1.0f64..500.0) {
        let vertical = fit_line(&[pt(c, a), pt(c, a + len), pt(c, a + len / 2.0)]).unwrap();
        prop_assert!(vertical.steep && vertical.slope.abs() < 1e-12 && (vertical.intercept - c).abs() < 1e-9);
        let horizontal = fit_line(&[pt(a, c), pt(a + len, c)]).unwrap();
        prop_assert!(!horizontal.steep && horizontal.slope.abs() < 1e-12 && (horizontal.intercept - c).abs() < 1e-9);
        prop_assert_eq!(horizontal.residual_variance, 0.0);
        prop_assert!(fit_line(&[pt(c, a), pt(c, a), pt(c, a)]).is_none(), "coincident points gave a line");
        prop_assert!(fit_line(&[pt(c, a)]).is_none() && fit_line(&[]).is_none());
    }

    #[test]
    fn a_circle_through_points_on_a_circle_is_that_circle(
        cx in coordinate(), cy in coordinate(), r in 2.0f64..400.0,
        start in 0.0f64..std::f64::consts::TAU, arc in 0.6f64..std::f64::consts::TAU, n in 3usize..40,
    ) {
        // Arcs down to about a tenth of the circle: a ball cut off by the image edge.
        let points: Vec<_> = (0..n)
            .map(|i| start + arc * i as f64 / n as f64)
            .map(|t| pt(cx + r * t.cos(), cy + r * t.sin()))
            .collect();
        let fit = fit_circle(&points).unwrap();
        let tolerance = 1e-6 * (1.0 + cx.abs() + cy.abs() + r);
        prop_assert!((fit.center_x - cx).abs() < tolerance && (fit.center_y - cy).abs() < tolerance && (fit.radius - r).abs() < tolerance,
            "({cx}, {cy}) r {r} fitted as {fit:?}");
        prop_assert!(fit.residual_sd < tolerance);
        prop_assert_eq!(fit.points, n);
    }

    #[test]
    fn degenerate_circles_give_none_or_a_finite_circle_never_a_panic(
        x0 in coordinate(), y0 in coordinate(), angle in 0.0f64..std::f64::consts::PI,
        steps in proptest::collection::vec(-300.0f64..300.0, 0..20), repeat in 1usize..4,
    ) {
        let (dx, dy) = (angle.cos(), angle.sin());
        // Collinear points, each possibly repeated (coincident), or fewer than three.
        let points: Vec<_> = steps.iter().flat_map(|t| std::iter::repeat_n(pt(x0 + t * dx, y0 + t * dy), repeat)).collect();
        if let Some(fit) = fit_circle(&points) {
            prop_assert!(fit.center_x.is_finite() && fit.center_y.is_finite() && fit.radius.is_finite() && fit.radius >= 0.0, "{fit:?}");
        }
        prop_assert!(fit_circle(&[pt(x0, y0), pt(x0, y0), pt(x0, y0)]).is_none(), "three coincident points gave a circle");
        prop_assert!(fit_circle(&[pt(x0, y0), pt(f64::NAN, y0), pt(x0 + 1.0, y0 + 5.0)]).is_none());
    }

    #[test]
    fn a_rotation_about_a_centre_is_undone_by_its_opposite(
        px in coordinate(), py in coordinate(), cx in coordinate(), cy in coordinate(), angle in -7.0f64..7.0,
    ) {
        let (p, centre) = (pt(px, py), pt(cx, cy));
        let turned = p.rotated_about(centre, angle);
        let back = turned.rotated_about(centre, -angle);
        prop_assert!((back.x_px - px).abs() < 1e-9 && (back.y_px - py).abs() < 1e-9, "{:?} came back as {:?}", p, back);
        // Distances from the centre are kept.
        let r0 = p.distance_to(&centre);
        let r1 = turned.distance_to(&centre);
        prop_assert!((r0 - r1).abs() < 1e-9 * (1.0 + r0));
    }

    #[test]
    fn a_camera_transform_and_its_inverse_give_every_point_back(
        yaw in -3.2f64..3.2, pitch in -1.6f64..1.6, roll in -3.2f64..3.2,
        t in proptest::array::uniform3(-500.0f64..500.0), p in proptest::array::uniform3(-1000.0f64..1000.0),
    ) {
        let rotation = rotation_z(yaw) * rotation_y(pitch) * rotation_x(roll);
        let body_from_camera: Transform<Body, Camera> = Transform::new(t.into(), rotation);
        let point = Point::<Camera>::new(p[0], p[1], p[2]);
        let there = body_from_camera * point;
        let back = body_from_camera.inverse() * there;
        prop_assert!(back.distance_to(&point) < 1e-9 * (1.0 + point.to_vector().coords.norm()), "{point:?} came back as {back:?}");
        let origin = body_from_camera.origin();
        prop_assert!((origin.distance_to(&there) - point.to_vector().coords.norm()).abs() < 1e-8, "the transform is not rigid");
    }

    #[test]
    fn an_overhead_pixel_on_the_carpet_maps_to_the_field_and_back(
        x in 0.0f64..640.0, y in 0.0f64..480.0, height in 250.0f64..450.0, k1 in -0.25f64..0.0, z in 0.0f64..30.0,
    ) {
        let camera = OverheadCamera::looking_down(640, 480, height, 420.0, k1, 0.03);
        let pixel = ImagePoint { x_px: x, y_px: y };
        let field = camera.field_from_image(pixel, z).unwrap();
        prop_assert!((field.z() - z).abs() < 1e-9);
        let back = camera.image_from_field(&field).unwrap();
        prop_assert!((back.x_px - x).abs() < 1e-6 && (back.y_px - y).abs() < 1e-6, "{pixel:?} -> {field:?} -> {back:?}");
    }
}

/// Found by the property above: three equal points at x = −484.91… have a mean that differs from
/// them by rounding, and gave a line of slope 0.
#[test]
fn three_equal_points_off_the_origin_are_no_line() {
    let p = pt(-484.911_564_243_466_44, 0.0);
    assert!(fit_line(&[p, p, p]).is_none());
}
