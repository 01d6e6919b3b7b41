//! Goal candidates: blobs of the goal colour and its soft colours joined, then merged when
//! near, lined up, or (in the level frame) sharing tops and bottoms; their level extent and cut-off.

use super::*;
use crate::blobs::{Blob, BlobSet};
use crate::geometry::ImagePoint;
use crate::lut::ColourClass;
use crate::recognition::context::ViewContext;
use crate::recognition::scan::CutOff;

/// A candidate while it is being built: the joined blob and its basic-colour part.
#[derive(Debug, Clone)]
pub(super) struct Group {
    pub all: Blob,
    pub basic: Blob,
    pub members: Vec<u32>,
}

/// The level-frame extent `[min x, min y, max x, max y]` (pixels) of image points rotated by
/// `angle` about `centre`; infinite (min above max) for none.
fn rotated_extent(
    points: impl IntoIterator<Item = ImagePoint>,
    centre: ImagePoint,
    angle: f64,
) -> [f64; 4] {
    let mut e = [
        f64::INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::NEG_INFINITY,
    ];
    let rotation = angle.sin_cos();
    for p in points {
        let q = p.rotated_by(centre, rotation);
        e[0] = e[0].min(q.x_px);
        e[1] = e[1].min(q.y_px);
        e[2] = e[2].max(q.x_px);
        e[3] = e[3].max(q.y_px);
    }
    e
}

/// Level-frame extent of a blob's box (its corners, rotated), pixels.
pub(super) fn level_extent(b: &Blob, centre: ImagePoint, angle: f64) -> [f64; 4] {
    let corners = [
        ImagePoint::new(f64::from(b.minx), f64::from(b.miny)),
        ImagePoint::new(f64::from(b.maxx + 1), f64::from(b.miny)),
        ImagePoint::new(f64::from(b.maxx + 1), f64::from(b.maxy + 1)),
        ImagePoint::new(f64::from(b.minx), f64::from(b.maxy + 1)),
    ];
    rotated_extent(corners, centre, angle)
}

/// Level-frame extent of the pixels of some blobs (their runs' ends, rotated), tighter than
/// the rotated box when the horizon is tilted: a tilted box's corners add w·sin θ to its height.
pub(super) fn pixel_level_extent(
    blobs: &BlobSet,
    members: impl Iterator<Item = u32>,
    centre: ImagePoint,
    angle: f64,
) -> Option<[f64; 4]> {
    let run_ends = members.flat_map(|m| blobs.runs_of(m)).flat_map(|r| {
        let (x0, x1, y) = (f64::from(r.x0), f64::from(r.x1), f64::from(r.y));
        [
            ImagePoint::new(x0, y),
            ImagePoint::new(x1, y),
            ImagePoint::new(x0, y + 1.0),
            ImagePoint::new(x1, y + 1.0),
        ]
    });
    let e = rotated_extent(run_ends, centre, angle);
    (e[0] < e[2] && e[1] < e[3]).then_some(e)
}

pub(super) fn build_groups(
    blobs: &BlobSet,
    colour: ColourClass,
    ctx: &ViewContext,
    p: &GoalParams,
) -> Vec<Group> {
    let soft: Vec<&Blob> = blobs
        .active()
        .filter(|b| {
            ColourClass::from_code(b.colour).is_some_and(|c| c != colour && c.may_be_class(colour))
        })
        .collect();
    let mut used = vec![false; soft.len()];
    let mut groups: Vec<Group> = Vec::new();
    for b in blobs
        .of_class(colour)
        .filter(|b| b.pixels >= p.min_blob_pixels)
    {
        let mut g = Group {
            all: *b,
            basic: *b,
            members: vec![b.number],
        };
        for (i, s) in soft.iter().enumerate() {
            if !used[i] && g.all.bounds().is_near(&s.bounds(), p.join_px) {
                g.all = g.all.merged_with(s);
                g.members.push(s.number);
                used[i] = true;
            }
        }
        groups.push(g);
    }
    // Merge until stable: near, lined up, or split by a goalkeeper (level tops/bottoms equal).
    let centre = ctx.camera.centre;
    let angle = ctx.horizon_angle();
    loop {
        let mut merged = false;
        'outer: for i in 0..groups.len() {
            for j in i + 1..groups.len() {
                let (a, b) = (&groups[i].all, &groups[j].all);
                let (ha, hb) = (
                    f64::from(a.maxy - a.miny + 1),
                    f64::from(b.maxy - b.miny + 1),
                );
                let overlap =
                    (f64::from(a.maxy.min(b.maxy)) - f64::from(a.miny.max(b.miny)) + 1.0).max(0.0);
                let lined_up = overlap >= p.line_up_overlap * ha.min(hb);
                let (ea, eb) = (
                    level_extent(a, centre, angle),
                    level_extent(b, centre, angle),
                );
                let tol = p.split_tolerance * (ea[3] - ea[1]).max(eb[3] - eb[1]);
                let split = (ea[1] - eb[1]).abs() <= tol && (ea[3] - eb[3]).abs() <= tol;
                if a.bounds().is_near(&b.bounds(), p.join_px) || lined_up && split {
                    let other = groups.swap_remove(j);
                    let g = &mut groups[i];
                    g.all = g.all.merged_with(&other.all);
                    g.basic = g.basic.merged_with(&other.basic);
                    g.members.extend(other.members);
                    merged = true;
                    break 'outer;
                }
            }
        }
        if !merged {
            break;
        }
    }
    groups.retain(|g| g.all.pixels >= p.min_candidate_pixels);
    groups.sort_by_key(|g| std::cmp::Reverse(g.all.pixels));
    groups
}

/// Cut-off detection: the level box's 8 points (corners and side midpoints), rotated back into
/// the image; a side is cut off when two or more of its three points are near or outside the edge.
pub(super) fn detect_cut_off(
    e: [f64; 4],
    centre: ImagePoint,
    angle: f64,
    w: f64,
    h: f64,
    margin: f64,
) -> CutOff {
    let un = |x: f64, y: f64| ImagePoint::new(x, y).rotated_about(centre, -angle);
    let (mx, my) = ((e[0] + e[2]) / 2.0, (e[1] + e[3]) / 2.0);
    let at_edge = |p: ImagePoint| {
        p.x_px <= margin || p.y_px <= margin || p.x_px >= w - margin || p.y_px >= h - margin
    };
    let count = |pts: [ImagePoint; 3]| pts.iter().filter(|p| at_edge(**p)).count() >= 2;
    CutOff {
        left: count([un(e[0], e[1]), un(e[0], my), un(e[0], e[3])]),
        right: count([un(e[2], e[1]), un(e[2], my), un(e[2], e[3])]),
        top: count([un(e[0], e[1]), un(mx, e[1]), un(e[2], e[1])]),
        bottom: count([un(e[0], e[3]), un(mx, e[3]), un(e[2], e[3])]),
    }
}

pub(super) fn is_goal_colour(colour: ColourClass) -> impl Fn(u8) -> bool {
    move |code| ColourClass::from_code(code).is_some_and(|c| c == colour || c.may_be_class(colour))
}
