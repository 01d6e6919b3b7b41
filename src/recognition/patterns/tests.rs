//! Coloured patterns on small synthetic scenes.

use super::learning::*;
use super::signatures::*;
use super::*;
use crate::blobs::BlobSet;
use crate::blobs::Connectivity;
use crate::classify::ClassifiedImage;
use crate::geometry::PinholeCamera;
use crate::geometry::RobotPose;
use crate::lut::ColourClass;
use crate::recognition::context::ViewContext;

/// A 3×3 arrangement of coloured tiles of `tile` pixels with pink in the middle.
fn tiles(colours: [ColourClass; 9], tile: usize, x0: usize, y0: usize) -> ClassifiedImage {
    let (w, h) = (208, 160);
    let mut codes = vec![ColourClass::Green.code(); w * h];
    for (k, c) in colours.iter().enumerate() {
        let (gx, gy) = (k % 3, k / 3);
        for y in 0..tile {
            for x in 0..tile {
                let (px, py) = (x0 + gx * tile + x, y0 + gy * tile + y);
                if px < w && py < h {
                    codes[py * w + px] = c.code();
                }
            }
        }
    }
    ClassifiedImage::from_codes(w, h, codes).expect("size")
}

const PLACE: [ColourClass; 9] = [
    ColourClass::White,
    ColourClass::Yellow,
    ColourClass::White,
    ColourClass::SkyBlue,
    ColourClass::Pink,
    ColourClass::Yellow,
    ColourClass::White,
    ColourClass::Black,
    ColourClass::White,
];

fn ctx() -> ViewContext {
    ViewContext::without_pose(PinholeCamera::ers7())
}

fn one(img: &ClassifiedImage) -> PatternObservation {
    let blobs = BlobSet::from_image(img, Connectivity::Four);
    let obs = observe(img, &blobs, &ctx(), &PatternParams::default(), &[]);
    assert_eq!(obs.len(), 1);
    obs[0]
}

/// A ray from `from` (field cm, 20 cm up) through the point `to` (field cm).
fn ray(from: [f64; 2], to: [f64; 2]) -> FieldRay {
    FieldRay {
        origin_cm: [from[0], from[1], 20.0],
        heading_rad: (to[1] - from[1]).atan2(to[0] - from[0]),
        slope: 0.0,
    }
}

#[test]
fn signatures_read_the_nine_regions() {
    let obs = one(&tiles(PLACE, 10, 60, 40));
    let firsts: Vec<u8> = obs.signature.0.iter().map(|r| r[0]).collect();
    let want: Vec<u8> = PLACE.iter().map(|c| c.code()).collect();
    assert_eq!(firsts, want);
    assert_eq!(obs.regions_in_image, 9);
    assert!((obs.size_px - 10.0).abs() < 1e-9);
    assert_eq!(obs.region_bounds(0), [60, 40, 69, 49]);
    assert_eq!(obs.region_bounds(8), [80, 60, 89, 69]);
    assert!(obs.ray.is_none(), "no camera pose without joints");
    // A pink square at the left edge: the left column of regions is outside, "nothing".
    let mut codes = vec![ColourClass::Green.code(); 208 * 160];
    for y in 50..60 {
        for x in 0..10 {
            codes[y * 208 + x] = ColourClass::Pink.code();
        }
    }
    let cut = one(&ClassifiedImage::from_codes(208, 160, codes).expect("size"));
    assert_eq!(cut.regions_in_image, 6);
    assert_eq!(cut.signature.0[3], [0, 0], "outside the image: nothing");
    assert_eq!(cut.signature.0[5], [ColourClass::Green.code(), 0]);
}

#[test]
fn regions_follow_the_rolling_shutter_shear() {
    // The tiles of a pan at 0.5 px per row: each row half a pixel further right.
    let (w, h, t, shear) = (208usize, 160usize, 10.0, 0.5);
    let mut codes = vec![ColourClass::Green.code(); w * h];
    for y in 30..60 {
        for x in 0..w {
            let u = x as f64 - 60.0 - shear * (y as f64 - 45.0);
            let col = (u / t).floor();
            if (0.0..3.0).contains(&col) {
                let k = ((y - 30) / 10) * 3 + col as usize;
                codes[y * w + x] = PLACE[k].code();
            }
        }
    }
    let img = ClassifiedImage::from_codes(w, h, codes).expect("size");
    let blobs = BlobSet::from_image(&img, Connectivity::Four);
    let mut panning = ctx();
    // The pan during one read-out that shifts rows near the image centre by `shear` px each.
    panning.pan_per_readout_rad = shear * h as f64 / panning.camera.focal_px;
    let obs = observe(&img, &blobs, &panning, &PatternParams::default(), &[]);
    assert_eq!(obs.len(), 1);
    let firsts: Vec<u8> = obs[0].signature.0.iter().map(|r| r[0]).collect();
    let want: Vec<u8> = PLACE.iter().map(|c| c.code()).collect();
    assert_eq!(firsts, want);
    // Without the shear the box is too wide and the rows above and below miss.
    let plain = observe(&img, &blobs, &ctx(), &PatternParams::default(), &[]);
    assert_eq!(plain[0].shear_px_per_row, 0.0);
    assert!(obs[0].region_bounds(1)[0] <= plain[0].region_bounds(1)[0] - 5);
    assert!(obs[0].region_bounds(7)[0] >= plain[0].region_bounds(7)[0] + 5);
    assert_ne!(plain[0].signature, obs[0].signature);
}

#[test]
fn triangulation_finds_where_rays_cross() {
    let target = [100.0, 220.0];
    let rays: Vec<FieldRay> = [[0.0, 0.0], [60.0, 10.0], [-50.0, 30.0]]
        .iter()
        .map(|&o| ray(o, target))
        .collect();
    let t = triangulate(&rays, &[1.0; 3]).expect("crossing rays");
    assert!((t.field_cm[0] - 100.0).abs() < 1e-6 && (t.field_cm[1] - 220.0).abs() < 1e-6);
    assert!(t.residual_cm < 1e-6);
    assert!(t.spread_deg > 10.0, "{}", t.spread_deg);
    // Parallel rays do not cross; a point behind a ray is refused.
    let parallel = [ray([0.0, 0.0], [1.0, 0.0]), ray([0.0, 5.0], [1.0, 5.0])];
    assert!(triangulate(&parallel, &[1.0; 2]).is_none());
    let away = [
        ray([0.0, 0.0], [100.0, 220.0]),
        ray([200.0, 440.0], [300.0, 660.0]),
    ];
    assert!(triangulate(&away, &[1.0; 2]).is_none());
    assert!(triangulate(&rays[..1], &[1.0]).is_none());
    // Two rays 5° apart: the spread says so.
    let a = ray([0.0, 0.0], [0.0, 200.0]);
    let b = FieldRay {
        heading_rad: a.heading_rad + 5f64.to_radians(),
        origin_cm: [17.5, 0.0, 20.0],
        ..a
    };
    let t = triangulate(&[a, b], &[1.0; 2]).expect("crossing");
    assert!((t.spread_deg - 5.0).abs() < 0.01, "{}", t.spread_deg);
}

#[test]
fn robust_triangulation_drops_a_wrong_ray() {
    let target = [90.0, 225.0];
    let mut views: Vec<(FieldRay, PatternObservation)> = Vec::new();
    let obs = one(&tiles(PLACE, 10, 60, 40));
    for k in 0..8 {
        let from = [-100.0 + 25.0 * f64::from(k), 20.0 * f64::from(k % 3)];
        views.push((ray(from, target), obs));
    }
    // One view of the near-twin 180 cm away.
    views.push((ray([0.0, 0.0], [-90.0, 225.0]), obs));
    let mut g = Group { views };
    let (t, dropped) = g.triangulate(&LearnParams::default());
    let t = t.expect("placed");
    assert_eq!(dropped.len(), 1);
    assert!((t.field_cm[0] - 90.0).abs() < 0.5 && (t.field_cm[1] - 225.0).abs() < 0.5);
}

#[test]
fn size_relation_fit_recovers_the_pinhole_relation() {
    let samples: Vec<[f64; 2]> = [5.0, 7.0, 9.0, 12.0, 15.0]
        .iter()
        .map(|s| [*s, 1535.0 / s + 3.0])
        .chain([[10.0, 900.0]])
        .collect();
    let r = SizeRelation::fit(&samples).expect("fit");
    assert!((r.multiplier_cm_px - 1535.0).abs() < 1e-6, "{r:?}");
    assert!((r.offset_cm - 3.0).abs() < 1e-6);
    assert_eq!(r.samples, 5, "the far-off sample was dropped");
    assert!((r.distance_cm(10.0).expect("distance") - 156.5).abs() < 1e-6);
    assert!(r.distance_cm(0.0).is_none());
    assert!(SizeRelation::fit(&[[10.0, 100.0]]).is_none());
    assert!(
        SizeRelation::fit(&[[10.0, 100.0], [20.0, 300.0]]).is_none(),
        "bigger is nearer"
    );
}

#[test]
fn learns_places_from_robot_positions_and_identifies_them() {
    // Synthetic views of one place from six robot positions: rays aimed at it from the
    // tiles' observation, sizes as a pinhole camera gives them.
    let place: [f64; 2] = [120.0, 225.0];
    let img = tiles(PLACE, 10, 60, 40);
    let base = one(&img);
    let mut views = Vec::new();
    for (k, from) in [
        [-60.0_f64, 0.0],
        [-30.0, 20.0],
        [0.0, 30.0],
        [30.0, 20.0],
        [60.0, 0.0],
        [90.0, -20.0],
    ]
    .iter()
    .enumerate()
    {
        let d = (place[0] - from[0]).hypot(place[1] - from[1]);
        let heading = (place[1] - from[1]).atan2(place[0] - from[0]);
        let obs = PatternObservation {
            size_px: 1535.0 / d,
            ray: Some(GroundRay {
                origin_cm: [0.0, 0.0, 25.0],
                direction: [1.0, 0.0, 0.0],
            }),
            ..base
        };
        views.push(LearnView {
            frame: k,
            robot: RobotPose::new(from[0], from[1], heading),
            observation: obs,
        });
    }
    let params = PatternParams::default();
    let mut memory = PatternMemory::default();
    let report = memory.learn(&views, &params, &LearnParams::default());
    assert_eq!(report.objects_created, vec![0], "{report:?}");
    let o = &memory.objects[0];
    assert!((o.field_cm[0] - 120.0).abs() < 0.5 && (o.field_cm[1] - 225.0).abs() < 0.5);
    assert_eq!(o.placed_by, Placement::Triangulation);
    assert!((o.height_cm.expect("height") - 25.0).abs() < 1e-6);
    let rel = memory.relation.expect("relation");
    assert!((rel.multiplier_cm_px - 1535.0).abs() < 1.0, "{rel:?}");
    // Identification: the same place at 15 px is 102 cm away; another place is unknown.
    let near = PatternObservation {
        size_px: 15.0,
        ..base
    };
    let m = memory.identify(&near, &params).expect("identified");
    assert_eq!((m.id, m.agreement), (0, 9));
    assert!((m.distance_cm.expect("distance") - 102.3).abs() < 1.0);
    let mut other = PLACE;
    other[1] = ColourClass::Red;
    other[3] = ColourClass::Red;
    assert!(
        memory
            .identify(&one(&tiles(other, 10, 60, 40)), &params)
            .is_none()
    );
    // Learning the same views again adds nothing new; a different signature at the same
    // place becomes that object's second pattern.
    let again = memory.learn(&views, &params, &LearnParams::default());
    assert!(again.objects_created.is_empty() && again.views_merged == 6);
    let other_obs = one(&tiles(other, 10, 60, 40));
    let side: Vec<LearnView> = views
        .iter()
        .map(|v| LearnView {
            observation: PatternObservation {
                signature: other_obs.signature,
                ..v.observation
            },
            ..*v
        })
        .collect();
    let r = memory.learn(&side, &params, &LearnParams::default());
    assert_eq!(r.patterns_added, vec![0]);
    assert_eq!(memory.objects[0].patterns.len(), 2);
    assert!(
        memory
            .identify(&one(&tiles(other, 10, 60, 40)), &params)
            .is_some()
    );
}

#[test]
fn equal_agreement_with_two_places_is_ambiguous() {
    let params = PatternParams::default();
    let a = one(&tiles(PLACE, 10, 60, 40));
    let mut twin = PLACE;
    twin[0] = ColourClass::Red;
    twin[8] = ColourClass::Red;
    let b = one(&tiles(twin, 10, 60, 40));
    let object = |id, sig| PatternObject {
        id,
        field_cm: [0.0, 0.0],
        height_cm: None,
        patterns: vec![sig],
        views: 1,
        placed_by: Placement::Triangulation,
        residual_cm: 0.0,
    };
    let memory = PatternMemory {
        objects: vec![object(0, a.signature), object(1, b.signature)],
        ..PatternMemory::default()
    };
    assert_eq!(memory.identify(&a, &params).map(|m| m.id), Some(0));
    assert_eq!(memory.identify(&b, &params).map(|m| m.id), Some(1));
    // Half way between: tile 0 as the first, tile 8 as the second.
    let mut half = PLACE;
    half[0] = ColourClass::Red;
    let h = one(&tiles(half, 10, 60, 40));
    assert!(memory.identify(&h, &params).is_none());
    let c = PatternMemory::candidate(Some(&memory), h, &ctx(), &params);
    assert!(c.ambiguous && !c.accepted);
    let prims = pattern_primitives(std::slice::from_ref(&c));
    assert_eq!(
        prims
            .iter()
            .filter(|p| matches!(p, Primitive::PatternRegion { .. }))
            .count(),
        9
    );
    assert!(
        prims.iter().any(
            |p| matches!(p, Primitive::Label { text, .. } if text.contains("place 0 or 1, tie"))
        )
    );
}

#[test]
fn bad_places_files_are_refused_with_the_reason() {
    let good = PatternMemory {
        objects: vec![PatternObject {
            id: 3,
            field_cm: [1.0, 2.0],
            height_cm: Some(25.0),
            patterns: vec![Signature([[6, 0]; 9])],
            views: 4,
            placed_by: Placement::Triangulation,
            residual_cm: 1.0,
        }],
        relation: Some(SizeRelation {
            multiplier_cm_px: 1500.0,
            offset_cm: 2.0,
            residual_cm: 3.0,
            samples: 4,
        }),
        ..PatternMemory::default()
    };
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("places.json");
    good.save(&path).expect("saved");
    assert_eq!(PatternMemory::load(&path).expect("loads"), good);
    let text = std::fs::read_to_string(&path).expect("read");
    let bad = |t: &str| {
        let e = PatternMemory::from_json(t).expect_err("refused");
        e.to_string()
    };
    assert!(bad("{").contains("not a places file"));
    assert!(bad("[1, 2]").contains("not a places file"));
    assert!(bad(&text.replace("eotn.places", "something")).contains("format"));
    assert!(bad(&text.replace("\"version\": 1", "\"version\": 9")).contains("version 9"));
    assert!(bad(&text.replace("1500.0", "-1500.0")).contains("multiplier"));
    assert!(bad(&text.replacen("6,", "77,", 1)).contains("77 is not a class code"));
    let twice = text.replace(
        "\"objects\": [",
        "\"objects\": [{\"id\": 3, \"field_cm\": [0, 0], \"patterns\": [[[6,0],[6,0],[6,0],[6,0],[4,0],[6,0],[6,0],[6,0],[6,0]]]},",
    );
    assert!(
        bad(&twice).contains("id 3 appears twice"),
        "{}",
        bad(&twice)
    );
    let e = PatternMemory::load(&dir.path().join("missing.json")).expect_err("missing");
    assert!(e.to_string().contains("missing.json"), "{e}");
    std::fs::write(&path, "not json").expect("write");
    let e = PatternMemory::load(&path).expect_err("garbled");
    assert!(e.to_string().contains("places.json") && e.to_string().contains("not a places file"));
}
