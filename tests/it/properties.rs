//! Properties over random input (proptest): blob formation against a plain flood fill, table
//! edits undone to the identity, camera rays projected back to their pixel.

use eotn::blobs::{BlobSet, Connectivity};
use eotn::classify::ClassifiedImage;
use eotn::frame::Yuv;
use eotn::geometry::camera::{ImagePoint, PinholeCamera};
use eotn::lut::edit::{EditHistory, EditRecord, Region, Sensitivity};
use eotn::lut::{ColourClass, LookupTable};
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
            history.commit(&mut lut, EditRecord { class, region, time_unix_ms: 0 });
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
