use super::*;
use crate::blobs::Connectivity;
use crate::classify::ClassifiedImage;
use crate::geometry::PinholeCamera;

/// A 208×160 image of `background` with the given boxes (x0..x1, y0..y1) painted in.
fn image(
    background: ColourClass,
    bands: &[(usize, usize, usize, usize, ColourClass)],
) -> ClassifiedImage {
    let (w, h) = (208, 160);
    let mut codes = vec![background.code(); w * h];
    for &(x0, x1, y0, y1, c) in bands {
        for y in y0..y1 {
            for x in x0..x1 {
                codes[y * w + x] = c.code();
            }
        }
    }
    ClassifiedImage::from_codes(w, h, codes).expect("size")
}

fn found(img: &ClassifiedImage) -> Vec<Beacon> {
    let blobs = BlobSet::from_image(img, Connectivity::Eight);
    let ctx = ViewContext::without_pose(PinholeCamera::ers7());
    recognise_beacons(img, &blobs, &ctx, &BeaconParams::default())
}

#[test]
fn pink_over_yellow_is_found_with_distance_from_its_edges() {
    // Bands of 10 rows centred on the optical axis's row (80): each edge's elevation gives
    // tan e = (z − z_camera) / D, so 20 rows for 20 cm at a focal length of 191.9 px put the
    // near side at 191.9 cm, the axis one radius (5 cm) beyond it.
    let img = image(
        ColourClass::Green,
        &[
            (99, 109, 70, 80, ColourClass::Pink),
            (99, 109, 80, 90, ColourClass::Yellow),
            (99, 109, 90, 110, ColourClass::White),
            (20, 30, 40, 50, ColourClass::SkyBlue),
        ],
    );
    let all = found(&img);
    let b = all.iter().find(|b| b.accepted).expect("beacon");
    assert_eq!(
        b.kind,
        BeaconKind {
            top: ColourClass::Pink,
            bottom: ColourClass::Yellow
        }
    );
    assert_eq!(b.distance_from, DistanceSource::BandEdges);
    assert_eq!(b.edges.len(), 3, "{:?}", b.edges);
    let f = PinholeCamera::ers7().focal_px;
    let near = f * 20.0 / 20.0;
    assert!(
        (b.camera.distance_cm - (near + 5.0)).abs() < 0.02 * near,
        "{} cm",
        b.camera.distance_cm
    );
    assert!(!beacon_primitives(&all).is_empty());
}

#[test]
fn unrelated_pink_and_blue_are_not_a_beacon() {
    let img = image(
        ColourClass::Green,
        &[
            (100, 110, 40, 50, ColourClass::Pink),
            (20, 30, 90, 100, ColourClass::SkyBlue),
        ],
    );
    assert!(found(&img).iter().all(|b| !b.accepted));
}

#[test]
fn a_sliver_of_pink_at_the_image_top_still_makes_the_beacon() {
    // A near beacon cut by the image top: only the middle columns of the pink band's bottom
    // show (the band's lower edge is an arch seen from below). The sliver's width says nothing.
    let img = image(
        ColourClass::Green,
        &[
            (140, 150, 0, 2, ColourClass::Pink),
            (130, 160, 2, 40, ColourClass::Yellow),
            (130, 160, 40, 100, ColourClass::White),
        ],
    );
    let all = found(&img);
    let b = all.iter().find(|b| b.accepted).expect("beacon");
    assert_eq!(b.kind.top, ColourClass::Pink);
    assert!(b.cut_off);
    assert!(
        b.confidence
            .test(TestName::WidthRatio)
            .is_some_and(|t| t.outcome == crate::recognition::confidence::TestOutcome::Skipped)
    );
}

#[test]
fn a_yellow_band_on_its_white_base_under_the_image_top_is_pink_over_yellow() {
    let img = image(
        ColourClass::Green,
        &[
            (89, 119, 0, 30, ColourClass::Yellow),
            (89, 119, 30, 100, ColourClass::White),
        ],
    );
    let all = found(&img);
    let b = all.iter().find(|b| b.accepted).expect("beacon");
    assert_eq!(
        b.kind,
        BeaconKind {
            top: ColourClass::Pink,
            bottom: ColourClass::Yellow
        }
    );
    assert!(b.cut_off);
    // From its width: 30 px across at the centre column, 65 px above the optical axis (its
    // middle row, 15): the rays through its sides are 2·atan(15 / √(f² + 65²)) apart, which a
    // cylinder of radius 5 cm subtends at 5 / sin(atan(15 / √(f² + 65²))) ≈ 67.7 cm.
    let f = PinholeCamera::ers7().focal_px;
    let expected = 5.0 / (15.0 / f.hypot(65.0)).atan().sin();
    assert_eq!(b.distance_from, DistanceSource::Width);
    assert!(
        (b.camera.distance_cm - expected).abs() < 0.5,
        "{} cm, expected {expected:.1}",
        b.camera.distance_cm
    );
}

#[test]
fn a_goal_cut_by_the_image_top_over_a_field_line_is_no_beacon() {
    // A wide yellow wall with a white line below it running on to both sides.
    let img = image(
        ColourClass::Green,
        &[
            (60, 150, 0, 30, ColourClass::Yellow),
            (20, 200, 30, 34, ColourClass::White),
        ],
    );
    assert!(found(&img).iter().all(|b| !b.accepted), "{:?}", found(&img));
    // Nor a yellow band over green.
    let img = image(
        ColourClass::Green,
        &[(130, 160, 0, 30, ColourClass::Yellow)],
    );
    assert!(found(&img).iter().all(|b| !b.accepted));
}
