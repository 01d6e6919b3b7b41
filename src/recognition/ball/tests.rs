//! Ball recognition on small synthetic scenes.

use super::checks::circle_fill;
use super::*;
use crate::blobs::Connectivity;
use crate::geometry::{Ers7Dimensions, PinholeCamera, Point as GeoPoint};
use crate::recognition::confidence::TestName;
use crate::sensors::SensorReadings;

fn level_context() -> ViewContext {
    let readings = SensorReadings {
        head_pan_rad: Some(0.0),
        head_tilt_rad: Some(-0.2),
        neck_tilt_rad: Some(0.0),
        ..SensorReadings::default()
    };
    ViewContext::from_sensors(PinholeCamera::ers7(), &readings, &Ers7Dimensions::ERS7)
}

/// Green field with an orange disc; `shear` shifts row y by shear·(y − cy) pixels.
fn scene(cx: f64, cy: f64, r: f64, shear: f64) -> ClassifiedImage {
    let (w, h) = (208usize, 160usize);
    let mut codes = vec![ColourClass::Green.code(); w * h];
    for y in 0..h {
        for x in 0..w {
            let yc = y as f64 + 0.5;
            let dx = x as f64 + 0.5 - cx - shear * (yc - cy);
            let dy = yc - cy;
            if dx * dx + dy * dy <= r * r {
                codes[y * w + x] = ColourClass::Orange.code();
            }
        }
    }
    ClassifiedImage::from_codes(w, h, codes).expect("size")
}

fn true_ball(ctx: &ViewContext, x: f64, y: f64) -> (ImagePoint, f64, f64) {
    let pose = ctx.pose.expect("pose");
    let centre = GeoPoint::new(x, y, 4.25);
    let p = pose.image_from_field(&centre).expect("in front");
    let cam = pose.position();
    let dist = cam.distance_to(&centre);
    (p, ctx.camera.focal_px * 4.25 / dist, dist)
}

#[test]
fn finds_a_ball_on_the_field_with_distance_from_the_circle() {
    let ctx = level_context();
    let (c, r, dist) = true_ball(&ctx, 90.0, 10.0);
    let img = scene(c.x_px, c.y_px, r, 0.0);
    let blobs = BlobSet::from_image(&img, Connectivity::Eight);
    let res = recognise_ball(&img, &blobs, &ctx, &BallParams::default());
    let ball = res.ball.clone().expect("ball");
    assert!(ball.from_circle_fit);
    assert!((ball.center_x - c.x_px).abs() < 0.6 && (ball.center_y - c.y_px).abs() < 0.6);
    let err = (ball.camera.distance_cm - dist).abs() / dist;
    assert!(err < 0.05, "distance {} vs {dist}", ball.camera.distance_cm);
    assert!(ball.body.is_some());
    let cand = &res.candidates[ball.candidate];
    assert!(
        cand.confidence
            .test(TestName::HeightCm)
            .is_some_and(|t| t.effect > 0.0)
    );
    assert!(
        cand.confidence
            .test(TestName::GreenBelow)
            .is_some_and(|t| t.effect > 0.0)
    );
    assert!(!res.primitives().is_empty());
}

#[test]
fn ball_points_are_written_as_x_y_arrays_and_read_back() {
    let ctx = level_context();
    let (c, r, _) = true_ball(&ctx, 90.0, 10.0);
    let img = scene(c.x_px, c.y_px, r, 0.0);
    let blobs = BlobSet::from_image(&img, Connectivity::Eight);
    let res = recognise_ball(&img, &blobs, &ctx, &BallParams::default());
    let cand = &res.candidates[0];
    let json = serde_json::to_value(cand).expect("json");
    let centre = &json["center"];
    assert_eq!(centre[0].as_f64(), Some(cand.center.x_px), "{centre}");
    assert_eq!(centre[1].as_f64(), Some(cand.center.y_px), "{centre}");
    let first = &json["edge_points"][0];
    assert_eq!(first[0].as_f64(), Some(cand.edge_points[0].x_px), "{first}");
    assert!(json["bounds"].is_array() && json["observed_center"].is_array());
    // (A whole candidate does not read back: an open test range is written as null.)
    #[derive(serde::Deserialize)]
    struct Points {
        #[serde(with = "xy_array")]
        center: ImagePoint,
        #[serde(with = "xy_array")]
        edge_points: Vec<ImagePoint>,
    }
    let back: Points = serde_json::from_value(json).expect("read back");
    assert_eq!(
        (back.center, back.edge_points),
        (cand.center, cand.edge_points.clone())
    );
}

#[test]
fn an_orange_thing_far_above_the_ground_is_not_a_ball() {
    let ctx = level_context();
    let img = scene(60.0, 12.0, 6.0, 0.0);
    let blobs = BlobSet::from_image(&img, Connectivity::Eight);
    let res = recognise_ball(&img, &blobs, &ctx, &BallParams::default());
    assert!(res.ball.is_none(), "{:?}", res.candidates[0].confidence);
    let height = res.candidates[0]
        .confidence
        .test(TestName::HeightCm)
        .expect("height test");
    assert!(height.value > 20.0 && height.effect < 0.0);
}

#[test]
fn a_ball_cut_by_the_image_edge_keeps_its_distance() {
    let ctx = level_context();
    let pose = ctx.pose.expect("pose");
    // A ball on the field placed so that about a third of it is outside the left edge.
    let (_, r0, _) = true_ball(&ctx, 45.0, 0.0);
    let y = (0..400)
        .map(|i| f64::from(i) * 0.1)
        .min_by(|a, b| {
            let off = |y: f64| (true_ball(&ctx, 45.0, y).0.x_px - 0.4 * r0).abs();
            off(*a).total_cmp(&off(*b))
        })
        .expect("positions");
    let (c, _, dist) = true_ball(&ctx, 45.0, y);
    // Rendered as a sphere, not a circle: a pixel shows the ball when its ray is within the
    // ball's angular radius of the centre's direction (off the optical axis the outline is
    // an ellipse, wider than a circle of the on-axis radius).
    let towards = ctx
        .camera
        .unit_ray(
            pose.image_from_field(&GeoPoint::new(45.0, y, 4.25))
                .expect("in front"),
        )
        .coords;
    let cos_alpha = (4.25 / dist).asin().cos();
    let (w, h) = (208usize, 160usize);
    let codes = (0..w * h)
        .map(|i| {
            let ray = ctx.camera.unit_ray(ImagePoint::pixel_centre(i % w, i / w));
            if ray.coords.dot(&towards) >= cos_alpha {
                ColourClass::Orange.code()
            } else {
                ColourClass::Green.code()
            }
        })
        .collect();
    let img = ClassifiedImage::from_codes(w, h, codes).expect("size");
    let blobs = BlobSet::from_image(&img, Connectivity::Eight);
    let res = recognise_ball(&img, &blobs, &ctx, &BallParams::default());
    let ball = res.ball.expect("ball");
    assert!(ball.cut_off.left && !ball.cut_off.right);
    assert!(ball.from_circle_fit);
    // The visible arc is the flatter inner side of the ellipse: the circle through it sits
    // a little inwards.
    assert!(
        (ball.center_x - c.x_px).abs() < 3.0,
        "{} vs {}",
        ball.center_x,
        c.x_px
    );
    let err = (ball.camera.distance_cm - dist) / dist;
    assert!(
        err.abs() < 0.04,
        "distance {} vs {dist}",
        ball.camera.distance_cm
    );
    // The original's d × 8.5 / diameter reads the stretched outline much too close.
    let naive = ctx.camera.focal_px * 8.5 / (2.0 * ball.radius_px);
    assert!(naive < 0.95 * dist, "naive {naive} vs {dist}");
}

#[test]
fn distance_from_the_subtended_angle_holds_across_the_image() {
    let camera = PinholeCamera::ers7();
    // A sphere 100 cm away at the centre and 25° off the axis: its outline's mean
    // semi-axis (see `distance_from_circle`) gives the distance back within 0.5%.
    for theta_deg in [0.0_f64, 15.0, 25.0] {
        let (t, alpha) = (theta_deg.to_radians(), (4.25_f64 / 100.0).asin());
        let f = camera.focal_px;
        let a = f / 2.0 * ((t + alpha).tan() - (t - alpha).tan());
        let b = f * alpha.sin() / (t.cos().powi(2) - alpha.sin().powi(2)).sqrt();
        let centre_x = camera.centre.x_px + f / 2.0 * ((t + alpha).tan() + (t - alpha).tan());
        let d = distance_from_circle(
            &camera,
            ImagePoint::new(centre_x, camera.centre.y_px),
            (a + b) / 2.0,
            8.5,
        );
        assert!((d - 100.0).abs() < 0.5, "{theta_deg}°: {d}");
    }
}

#[test]
fn skew_correction_restores_the_radius_of_a_sheared_ball() {
    let mut ctx = level_context();
    let (c, r, _) = true_ball(&ctx, 70.0, 0.0);
    let shear = 0.6;
    let img = scene(c.x_px, c.y_px, r, shear);
    let blobs = BlobSet::from_image(&img, Connectivity::Eight);
    let plain = recognise_ball(
        &img,
        &blobs,
        &ctx,
        &BallParams {
            skew_correction: false,
            ..BallParams::default()
        },
    );
    // The pan during one read-out that shifts rows near the image centre by `shear` px each.
    ctx.pan_per_readout_rad = shear * ctx.camera.height_px as f64 / ctx.camera.focal_px;
    let fixed = recognise_ball(&img, &blobs, &ctx, &BallParams::default());
    let e_plain = (plain.ball.expect("plain").radius_px - r).abs();
    let e_fixed = (fixed.ball.expect("fixed").radius_px - r).abs();
    assert!(e_fixed * 2.0 < e_plain, "fixed {e_fixed} plain {e_plain}");
}

#[test]
fn ellipse_fit_gives_the_image_velocity_of_a_moving_ball() {
    let ctx = level_context();
    let (c, r, _) = true_ball(&ctx, 45.0, 0.0);
    // Moving right 0.25 px per line (1200 px/s at 160 lines in 1/30 s), centred on the
    // reference row.
    let img = scene(c.x_px, 80.0, r, 0.25);
    let blobs = BlobSet::from_image(&img, Connectivity::Eight);
    let plain = recognise_ball(&img, &blobs, &ctx, &BallParams::default());
    let plain = plain.ball.expect("plain");
    assert!(plain.image_velocity_px_s.is_none() && plain.ground_velocity_cm_s.is_none());
    let params = BallParams {
        ellipse_fit: true,
        ..BallParams::default()
    };
    let res = recognise_ball(&img, &blobs, &ctx, &params);
    let ball = res.ball.clone().expect("ball");
    let v = ball.image_velocity_px_s.expect("velocity");
    assert!((v[0] - 1200.0).abs() < 120.0 && v[1] == 0.0, "{v:?}");
    assert!(res.candidates[ball.candidate].ellipse.is_some());
    // Moving right in the image, straight ahead: to the robot's right on the ground.
    let g = ball.ground_velocity_cm_s.expect("ground velocity");
    assert!(g[1] < 0.0 && g[1].abs() > 3.0 * g[0].abs(), "{g:?}");
    assert!((ball.radius_px - r).abs() <= (plain.radius_px - r).abs() + 0.2);
}

#[test]
fn soft_orange_joins_and_a_frame_without_orange_has_no_candidates() {
    let ctx = level_context();
    let (c, r, _) = true_ball(&ctx, 80.0, 0.0);
    let mut img = scene(c.x_px, c.y_px, r, 0.0);
    // Paint the lower half of the ball red-orange (shadow).
    let w = img.width();
    let codes = img.codes_mut();
    for (i, code) in codes.iter_mut().enumerate() {
        if *code == ColourClass::Orange.code() && (i / w) as f64 > c.y_px {
            *code = ColourClass::RedOrange.code();
        }
    }
    let blobs = BlobSet::from_image(&img, Connectivity::Eight);
    let res = recognise_ball(&img, &blobs, &ctx, &BallParams::default());
    let ball = res.ball.expect("ball");
    assert!((ball.radius_px - r).abs() < 1.0);
    let green = scene(0.0, 0.0, 0.0, 0.0);
    let none = recognise_ball(
        &green,
        &BlobSet::from_image(&green, Connectivity::Eight),
        &ctx,
        &BallParams::default(),
    );
    assert!(none.ball.is_none() && none.candidates.is_empty());
}

/// A 320×240 green frame (no pose) with an orange disc, white wherever `white(x, y)`.
fn big_scene(cx: f64, cy: f64, r: f64, white: impl Fn(f64, f64) -> bool) -> ClassifiedImage {
    let (w, h) = (320usize, 240usize);
    let codes = (0..w * h)
        .map(|i| {
            let (x, y) = ((i % w) as f64 + 0.5, (i / w) as f64 + 0.5);
            if (x - cx).hypot(y - cy) <= r {
                ColourClass::Orange.code()
            } else if white(x, y) {
                ColourClass::White.code()
            } else {
                ColourClass::Green.code()
            }
        })
        .collect();
    ClassifiedImage::from_codes(w, h, codes).expect("size")
}

#[test]
fn a_large_ball_on_a_white_line_is_round_not_hidden() {
    let ctx = ViewContext::without_pose(PinholeCamera::from_horizontal_fov(
        320,
        240,
        45.0_f64.to_radians(),
    ));
    // A 40-px ball lying on a thick white line that runs behind it, with its white stand
    // below: white borders most of its left, right and bottom sides, but it is round there.
    let img = big_scene(160.0, 120.0, 40.0, |x, y| {
        (95.0..150.0).contains(&y) || ((110.0..210.0).contains(&x) && y > 150.0)
    });
    let blobs = BlobSet::from_image(&img, Connectivity::Eight);
    let res = recognise_ball(&img, &blobs, &ctx, &BallParams::default());
    let ball = res.ball.expect("ball");
    assert!(!ball.cut_off.any(), "{:?}", ball.cut_off);
    assert!(ball.from_circle_fit);
    assert!((ball.radius_px - 40.0).abs() < 1.0, "{}", ball.radius_px);
    // The same ball behind a white robot leg whose straight edge cuts off its right third:
    // a long chord, hidden.
    let img = big_scene(160.0, 120.0, 40.0, |x, _| x > 187.0);
    let mut codes = img.codes().to_vec();
    for (i, c) in codes.iter_mut().enumerate() {
        if (i % 320) as f64 + 0.5 > 187.0 {
            *c = ColourClass::White.code();
        }
    }
    let img = ClassifiedImage::from_codes(320, 240, codes).expect("size");
    let blobs = BlobSet::from_image(&img, Connectivity::Eight);
    let res = recognise_ball(&img, &blobs, &ctx, &BallParams::default());
    let ball = res.ball.expect("ball");
    assert!(
        ball.cut_off.right && !ball.cut_off.left,
        "{:?}",
        ball.cut_off
    );
    assert!((ball.radius_px - 40.0).abs() < 1.5, "{}", ball.radius_px);
    // Taking every bordered side as hidden (the old rule) cuts the ball on the line too. (This
    // scene has no carpet at all: without a pose the field-below test would count against the
    // ball, which is not what this part is about.)
    let old = BallParams {
        hidden_min_chord_share: 0.0,
        hidden_min_overhang_px: f64::NEG_INFINITY,
        field_below_without_pose_weight: TestWeight::new(0.0, 0.0),
        ..BallParams::default()
    };
    let img = big_scene(160.0, 120.0, 40.0, |x, y| {
        (95.0..150.0).contains(&y) || ((110.0..210.0).contains(&x) && y > 150.0)
    });
    let blobs = BlobSet::from_image(&img, Connectivity::Eight);
    let res = recognise_ball(&img, &blobs, &ctx, &old);
    assert!(res.ball.expect("ball").cut_off.any());
}

#[test]
fn a_small_ball_under_a_field_line_is_whole_but_one_under_a_leg_is_hidden() {
    let ctx = ViewContext::without_pose(PinholeCamera::from_horizontal_fov(
        320,
        240,
        45.0_f64.to_radians(),
    ));
    // A 12-px ball whose top touches a white field line running behind it (the sample
    // stream's frame 3): the line borders the top, but the ball is round there.
    let (cx, cy, r) = (160.0, 120.0, 12.0);
    let img = big_scene(cx, cy, r, |_, y| (cy - r - 4.0..cy - r + 1.0).contains(&y));
    let blobs = BlobSet::from_image(&img, Connectivity::Eight);
    let res = recognise_ball(&img, &blobs, &ctx, &BallParams::default());
    let ball = res.ball.expect("ball");
    assert!(!ball.cut_off.any(), "{:?}", ball.cut_off);
    // The same ball with a white leg over its top third: the circle fitted to the rest reaches
    // four pixels beyond the blob, the top is hidden.
    let img = big_scene(cx, cy, r, |_, _| false);
    let mut codes = img.codes().to_vec();
    for (i, c) in codes.iter_mut().enumerate() {
        let (x, y) = ((i % 320) as f64 + 0.5, (i / 320) as f64 + 0.5);
        if y < cy - r + 4.0 && (x - cx).abs() < 30.0 && y > cy - 40.0 {
            *c = ColourClass::White.code();
        }
    }
    let img = ClassifiedImage::from_codes(320, 240, codes).expect("size");
    let blobs = BlobSet::from_image(&img, Connectivity::Eight);
    let res = recognise_ball(&img, &blobs, &ctx, &BallParams::default());
    let ball = res.ball.expect("ball");
    assert!(
        ball.cut_off.top && !ball.cut_off.bottom && !ball.cut_off.left && !ball.cut_off.right,
        "{:?}",
        ball.cut_off
    );
    assert!((ball.radius_px - r).abs() < 1.5, "{}", ball.radius_px);
}

#[test]
fn a_thin_orange_arc_does_not_fill_its_circle() {
    let ctx = level_context();
    // The red-orange rim of a white toe: a 2-px arc of a 20-px circle, white inside.
    let (w, h) = (208usize, 160usize);
    let (cx, cy, r) = (104.0, 110.0, 20.0);
    let codes = (0..w * h)
        .map(|i| {
            let (x, y) = ((i % w) as f64 + 0.5, (i / w) as f64 + 0.5);
            let d = (x - cx).hypot(y - cy);
            if y < cy && (r - 2.0..=r).contains(&d) {
                ColourClass::Orange.code()
            } else if d < r || y >= cy {
                ColourClass::White.code()
            } else {
                ColourClass::Green.code()
            }
        })
        .collect();
    let img = ClassifiedImage::from_codes(w, h, codes).expect("size");
    assert!(circle_fill(&img, ImagePoint::new(cx, cy), r).is_some_and(|f| f < 0.2));
    let blobs = BlobSet::from_image(&img, Connectivity::Eight);
    let res = recognise_ball(&img, &blobs, &ctx, &BallParams::default());
    assert!(res.ball.is_none(), "{:?}", res.candidates[0].confidence);
    let fill = res.candidates[0]
        .confidence
        .test(TestName::CircleFill)
        .expect("circle fill test");
    assert!(fill.effect < 0.0, "{fill:?}");
    // A whole disc fills its circle; one outside the image has no fill.
    let disc = scene(60.0, 60.0, 8.0, 0.0);
    assert!(circle_fill(&disc, ImagePoint::new(60.0, 60.0), 8.0).is_some_and(|f| f > 0.95));
    assert_eq!(circle_fill(&disc, ImagePoint::new(-50.0, 60.0), 8.0), None);
    assert_eq!(
        circle_fill(&disc, ImagePoint::new(60.0, 60.0), f64::NAN),
        None
    );
}

#[test]
fn without_a_pose_field_beneath_rejects_an_orange_light_above_the_field_when_asked() {
    let ctx = ViewContext::without_pose(PinholeCamera::from_horizontal_fov(
        320,
        240,
        45.0_f64.to_radians(),
    ));
    // A 5-px orange light with a speck of carpet right at its foot, and 60 rows of dark
    // audience (black) beneath it before the carpet starts.
    let (cx, cy, r) = (160.0, 40.0, 5.0);
    let img = big_scene(cx, cy, r, |_, _| false);
    let mut codes = img.codes().to_vec();
    for (i, c) in codes.iter_mut().enumerate() {
        let (x, y) = ((i % 320) as f64 + 0.5, (i / 320) as f64 + 0.5);
        let speck = y < cy + r + 5.0 && (x - cx).abs() < 8.0;
        if *c == ColourClass::Green.code() && y < 110.0 && !speck {
            *c = ColourClass::Black.code();
        }
    }
    let light = ClassifiedImage::from_codes(320, 240, codes).expect("size");
    let on = BallParams {
        field_beneath_without_pose_weight: TestWeight::new(0.0, 2.5),
        ..BallParams::default()
    };
    let blobs = BlobSet::from_image(&light, Connectivity::Eight);
    // Off by default: the test is not even listed, and the light passes as a ball.
    let res = recognise_ball(&light, &blobs, &ctx, &BallParams::default());
    assert!(
        res.candidates[0]
            .confidence
            .test(TestName::FieldBeneath)
            .is_none()
    );
    assert!(res.ball.is_some(), "{:?}", res.candidates[0].confidence);
    let off_total = res.candidates[0].confidence.total;
    let res = recognise_ball(&light, &blobs, &ctx, &on);
    let beneath = res.candidates[0]
        .confidence
        .test(TestName::FieldBeneath)
        .expect("field beneath test");
    assert!(beneath.value < 0.5 && beneath.effect < 0.0, "{beneath:?}");
    assert!((res.candidates[0].confidence.total - (off_total - 2.5)).abs() < 1e-9);
    // The same ball on the carpet passes it.
    let ball = big_scene(cx, 150.0, r, |_, _| false);
    let blobs = BlobSet::from_image(&ball, Connectivity::Eight);
    let res = recognise_ball(&ball, &blobs, &ctx, &on);
    let beneath = res.candidates[0]
        .confidence
        .test(TestName::FieldBeneath)
        .expect("test");
    assert!(beneath.value > 0.9 && beneath.effect == 0.0, "{beneath:?}");
    assert!(res.ball.is_some());
}

/// `min_pixels` counts the orange core, not the soft colours joining it (issue 33 item 18: a
/// 4-pixel orange blob on a red shirt was accepted with `min_pixels` 5, the shirt's red-orange
/// around it making up the count). A soft group alone is a candidate only when asked.
#[test]
fn min_pixels_counts_the_orange_core_and_soft_groups_alone_are_candidates_only_when_asked() {
    let ctx = ViewContext::without_pose(PinholeCamera::from_horizontal_fov(
        320,
        240,
        45.0_f64.to_radians(),
    ));
    // A red-orange shirt patch (soft) of 12 × 12 on the carpet, with 2 × 2 orange inside.
    let shirt = |orange: bool| {
        let codes = (0..320 * 240)
            .map(|i| {
                let (x, y) = (i % 320, i / 320);
                if orange && (105..107).contains(&x) && (105..107).contains(&y) {
                    ColourClass::Orange.code()
                } else if (100..112).contains(&x) && (100..112).contains(&y) {
                    ColourClass::RedOrange.code()
                } else {
                    ColourClass::Green.code()
                }
            })
            .collect();
        ClassifiedImage::from_codes(320, 240, codes).expect("size")
    };
    let img = shirt(true);
    let blobs = BlobSet::from_image(&img, Connectivity::Eight);
    let params = BallParams::default();
    assert_eq!(params.min_pixels, 5);
    let res = recognise_ball(&img, &blobs, &ctx, &params);
    // The 4-pixel core makes no candidate; the shirt is scored as a soft group of its own
    // (orange pixels 0), not as a ball with a 4-pixel core.
    assert!(
        res.candidates.iter().all(|c| c.orange_pixels == 0),
        "{:?}",
        res.candidates
    );
    // With soft groups alone off, nothing is a candidate at all.
    let no_soft = BallParams {
        soft_candidates: false,
        ..params
    };
    let res = recognise_ball(&img, &blobs, &ctx, &no_soft);
    assert!(res.candidates.is_empty(), "{:?}", res.candidates);
    // A core of at least min_pixels still joins the soft colours around it.
    let big_core = BallParams {
        min_pixels: 4,
        ..no_soft
    };
    let res = recognise_ball(&img, &blobs, &ctx, &big_core);
    assert_eq!(res.candidates.len(), 1);
    assert_eq!(
        (res.candidates[0].pixels, res.candidates[0].orange_pixels),
        (144, 4)
    );
    // Soft colours alone are still a candidate by default.
    let soft_only = shirt(false);
    let blobs = BlobSet::from_image(&soft_only, Connectivity::Eight);
    assert_eq!(
        recognise_ball(&soft_only, &blobs, &ctx, &params)
            .candidates
            .len(),
        1
    );
    assert!(
        recognise_ball(&soft_only, &blobs, &ctx, &no_soft)
            .candidates
            .is_empty()
    );
}

/// Without a pose, `field_below` may look past the ball's own shadow when asked
/// (`field_below_reach_radii`): the band under a lit ball is dark, the carpet goes on below it;
/// an orange light on a robot has the robot's body all the way down and still fails.
#[test]
fn field_below_looks_past_the_ball_s_shadow_when_asked_but_not_past_a_robot() {
    let ctx = ViewContext::without_pose(PinholeCamera::from_horizontal_fov(
        320,
        240,
        45.0_f64.to_radians(),
    ));
    let (cx, cy, r) = (160.0, 150.0, 5.0);
    // `dark_rows` rows of black right under the ball (its shadow, or a robot's body).
    let scene_with = |dark_rows: f64| {
        let img = big_scene(cx, cy, r, |_, _| false);
        let mut codes = img.codes().to_vec();
        for (i, c) in codes.iter_mut().enumerate() {
            let (x, y) = ((i % 320) as f64 + 0.5, (i / 320) as f64 + 0.5);
            if *c == ColourClass::Green.code()
                && (x - cx).abs() < r + 2.0
                && y > cy + r
                && y < cy + r + dark_rows
            {
                *c = ColourClass::Black.code();
            }
        }
        ClassifiedImage::from_codes(320, 240, codes).expect("size")
    };
    let field_below = |img: &ClassifiedImage, reach: f64| {
        let params = BallParams {
            field_below_reach_radii: reach,
            ..BallParams::default()
        };
        let blobs = BlobSet::from_image(img, Connectivity::Eight);
        let res = recognise_ball(img, &blobs, &ctx, &params);
        let t = res.candidates[0]
            .confidence
            .test(TestName::FieldBelow)
            .expect("field below");
        (t.value, t.effect)
    };
    let shadow = scene_with(4.0);
    let (share, effect) = field_below(&shadow, 0.0);
    assert!(share < 0.5 && effect < 0.0, "at the foot only: {share}");
    let (share, effect) = field_below(&shadow, 1.5);
    assert!(share > 0.9 && effect == 0.0, "past the shadow: {share}");
    let robot = scene_with(60.0);
    let (share, effect) = field_below(&robot, 1.5);
    assert!(share < 0.5 && effect < 0.0, "a robot below: {share}");
}

/// `unclassified_ring_gap_px` reads the unclassified-surroundings ring past a blurred ball's
/// rim: a ball whose outermost pixel ring classifies as nothing (the mix of ball and carpet)
/// fails the test right beside its box and passes one pixel further out.
#[test]
fn the_unclassified_ring_can_lie_past_a_blurred_rim() {
    let ctx = ViewContext::without_pose(PinholeCamera::from_horizontal_fov(
        320,
        240,
        45.0_f64.to_radians(),
    ));
    let (cx, cy, r) = (160.0, 150.0, 5.0);
    let codes = (0..320 * 240)
        .map(|i| {
            let (x, y) = ((i % 320) as f64 + 0.5, (i / 320) as f64 + 0.5);
            let d = (x - cx).hypot(y - cy);
            if d <= r {
                ColourClass::Orange.code()
            } else if d <= r + 1.8 {
                ColourClass::Unclassified.code()
            } else {
                ColourClass::Green.code()
            }
        })
        .collect();
    let img = ClassifiedImage::from_codes(320, 240, codes).expect("size");
    let blobs = BlobSet::from_image(&img, Connectivity::Eight);
    let share = |gap: u32| {
        let params = BallParams {
            unclassified_ring_gap_px: gap,
            ..BallParams::default()
        };
        let res = recognise_ball(&img, &blobs, &ctx, &params);
        let t = res.candidates[0]
            .confidence
            .test(TestName::UnclassifiedAround)
            .expect("unclassified around");
        (t.value, t.effect)
    };
    let (beside, effect) = share(0);
    assert!(
        beside > 0.6 && effect < 0.0,
        "right beside the box: {beside}"
    );
    let (past, effect) = share(1);
    assert!(past < 0.4 && effect == 0.0, "past the rim: {past}");
}
