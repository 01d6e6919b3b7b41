//! A box goal seen from beside: the outline's outer edge is the side wall's back corner; the
//! post is at its front corner, found from the wall's descending foot.

use crate::classify::ClassifiedImage;
use crate::geometry::ImagePoint;
use crate::lut::ColourClass;
use crate::recognition::fit::{LineFit, fit_line};

/// How much higher (sample rows) the foot of a side wall seen from outside must be at the
/// outline, and just beyond the wall's front corner, than at the corner. One row is the
/// classification's own noise along a goal's bottom: a partly covered row of pixels shows in
/// some columns only.
pub(super) const FOOT_STEP_ROWS: usize = 2;

/// The lowest foot of a side wall seen from outside lies at least this many columns (pixels)
/// inside the outline. Two are seen on goals from in front: a partly covered bottom row can put
/// a chroma pair of goal colour below the rest next to the post. A narrower wall moves the
/// post by only about two pixels.
pub(super) const MIN_WALL_COLUMNS: usize = 3;

/// A corner of a side wall seen from outside: where the wall ends towards the mouth on one
/// level row.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct WallCorner {
    /// The corner, level frame, pixels.
    pub at: ImagePoint,
    /// Its distance inside the outline along the row, pixels.
    pub offset: f64,
}

/// The front corner of a side wall seen from outside, found by [`front_corner`]: at its foot
/// and, when the top shows it too, at its top.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct SideWall {
    /// The corner on the lowest foot row.
    pub foot: WallCorner,
    /// The corner on the highest top row, when it is clear and its offset differs from the
    /// foot's by at most [`SideWall::MAX_LEAN`] of the rows between them.
    pub top: Option<WallCorner>,
}

impl SideWall {
    /// Largest accepted difference between the top's and the foot's offsets, as a fraction of
    /// the rows between them. Both corners lie on one upright edge, which leans (rolling
    /// shutter, perspective) as the back corner does, but the outline's fit through a few
    /// scans of that far edge can lean a pixel or two differently; a larger difference is
    /// noise at the top.
    const MAX_LEAN: f64 = 0.2;

    /// The offset inside the outline at level row `y`, pixels: between the foot's and the
    /// top's, linearly (the foot's alone when the top gave none).
    pub(super) fn offset_at(&self, y: f64) -> f64 {
        let f = self.foot;
        match self.top {
            Some(t) if (f.at.y_px - t.at.y_px).abs() > f64::EPSILON => {
                f.offset + (t.offset - f.offset) * (f.at.y_px - y) / (f.at.y_px - t.at.y_px)
            }
            _ => f.offset,
        }
    }
}

/// A box goal's side wall seen from outside (the camera beyond the wall's outer face, beside
/// the goal). The outline's outer edge on that side is then the wall's back corner, and the
/// post, the wall's front end, lies inside the goal-coloured region. Being nearer, the post is
/// the side's tallest stretch: the wall's foot descends from the back corner to it, and just
/// beyond it the carpet inside the mouth shows under the back wall, which is farther away and
/// so ends higher (and its top lower). Seen from in front, the outline's edge is the post
/// itself and the foot is lowest right there, so none of this applies.
///
/// `outline`: the side's scan points in the level frame; `dir`: +1 for the left side (inward
/// is +x), −1 for the right; `far_side_cut`: the other side is cut off by the image edge;
/// `level`: the image centre and horizon angle of the level frame. Columns run parallel to the
/// outline one pixel apart; in each, the lowest and the highest goal sample within half the
/// height of the extent's bottom and top. The front corner is accepted when every sign is
/// there: the lowest foot at least [`MIN_WALL_COLUMNS`] inside the outline (in the near half
/// of the goal, or across it when the other side is cut off) and [`FOOT_STEP_ROWS`] lower than
/// at it, carpet (green or a white line) under the slanting foot in at least half of those
/// columns (not a robot in front of the post), the foot higher again in the next two columns
/// beyond the corner, by [`FOOT_STEP_ROWS`] in one of them, with carpet there, and the top at
/// the corner at most a row lower than at the outline. Each corner is placed to 1/64 px by
/// bisection along its row.
pub(super) fn front_corner(
    img: &ClassifiedImage,
    is_goal: &impl Fn(u8) -> bool,
    outline: &[ImagePoint],
    e: [f64; 4],
    dir: f64,
    far_side_cut: bool,
    (centre, angle): (ImagePoint, f64),
) -> Option<SideWall> {
    let line = fit_line(outline).filter(|f| f.steep)?;
    let height = e[3] - e[1];
    if !(height.is_finite() && height > 0.0 && e[2] > e[0]) {
        return None;
    }
    // Level frame → image: `ImagePoint::rotated_about` by −angle with its sine and cosine taken once.
    let (sin, cos) = (-angle).sin_cos();
    let side = SideColumns {
        img,
        is_goal,
        line,
        dir,
        centre,
        sin,
        cos,
        extent: e,
        rows: (height / 2.0).ceil() as usize,
    };
    let columns = (e[2] - e[0]).floor() as usize;
    // The corner lies in the near half of the goal (anywhere across it when the other side is
    // cut off) and no farther inside than the goal is tall: a side wall shows at most its
    // depth, and the 2005 goals' walls are as deep as they are tall (30 cm).
    let search = if far_side_cut { columns } else { columns / 2 }.min(height.ceil() as usize);
    // Seen from in front, the outline's foot is the lowest already (most goals): done.
    if (0..2).filter_map(|k| side.foot_of(k)).max()? < FOOT_STEP_ROWS {
        return None;
    }
    // Per column: the sample row of its lowest goal sample (smaller = farther out); the tops
    // are looked at only once the feet show a corner.
    let feet: Vec<Option<usize>> = (0..columns.min(search + 4))
        .map(|k| side.foot_of(k))
        .collect();
    let slope = FootSlope::find(&feet, search)?;
    if !side.back_wall_beyond(&feet, slope) || !side.carpet_under(&feet, slope.k0) {
        return None;
    }
    let foot_corner = side.crossing(slope.k1, side.foot_y(slope.lowest));
    let top = side.top_corner(feet.len(), slope, foot_corner)?;
    Some(SideWall {
        foot: foot_corner,
        top,
    })
}

/// One side of a goal in the level frame, sampled in columns parallel to its outline, one
/// pixel apart, and in rows counted from below the extent's bottom (feet) or from above its top
/// (tops).
struct SideColumns<'a, G: Fn(u8) -> bool> {
    img: &'a ClassifiedImage,
    is_goal: &'a G,
    /// The outline's line, level frame.
    line: LineFit,
    /// +1 for the left side (inward is +x), −1 for the right.
    dir: f64,
    /// The level frame's centre in the image, pixels.
    centre: ImagePoint,
    /// Sine and cosine of the level frame → image rotation.
    sin: f64,
    cos: f64,
    /// The goal's extent, level frame: min x, min y, max x, max y, pixels.
    extent: [f64; 4],
    /// Sample rows searched for a foot or a top: half the extent's height.
    rows: usize,
}

impl<G: Fn(u8) -> bool> SideColumns<'_, G> {
    /// The outline's x at level row `y`.
    fn edge_x(&self, y: f64) -> f64 {
        self.line.at(y).x_px
    }

    /// The class code at a level-frame point (`None` outside the image).
    fn code_at(&self, x: f64, y: f64) -> Option<u8> {
        let (dx, dy) = (x - self.centre.x_px, y - self.centre.y_px);
        self.img.get_at(
            self.centre.x_px + self.cos * dx - self.sin * dy,
            self.centre.y_px + self.sin * dx + self.cos * dy,
        )
    }

    fn goal_at(&self, x: f64, y: f64) -> bool {
        self.code_at(x, y).is_some_and(self.is_goal)
    }

    /// Carpet: green or a white line.
    fn ground_at(&self, x: f64, y: f64) -> bool {
        self.code_at(x, y)
            .is_some_and(|c| c == ColourClass::Green.code() || c == ColourClass::White.code())
    }

    /// Level y of foot sample row `i`.
    fn foot_y(&self, i: usize) -> f64 {
        self.extent[3] + 0.5 - i as f64
    }

    /// Level y of top sample row `i`.
    fn top_y(&self, i: usize) -> f64 {
        self.extent[1] - 0.5 + i as f64
    }

    /// Level x of column `k` at row `y`.
    fn column_x(&self, k: usize, y: f64) -> f64 {
        self.edge_x(y) + self.dir * (k as f64 + 0.5)
    }

    /// Column `k`'s lowest goal sample, as a foot sample row.
    fn foot_of(&self, k: usize) -> Option<usize> {
        (0..self.rows).find(|&i| self.goal_at(self.column_x(k, self.foot_y(i)), self.foot_y(i)))
    }

    /// Column `k`'s highest goal sample, as a top sample row.
    fn top_of(&self, k: usize) -> Option<usize> {
        (0..self.rows).find(|&i| self.goal_at(self.column_x(k, self.top_y(i)), self.top_y(i)))
    }

    /// Beyond the corner the foot jumps up (after at most one column between) and stays up:
    /// the back wall's bottom, with carpet under it. On a goal seen from in front the feet go
    /// on down towards a nearer post instead. Outside the image nothing is known.
    fn back_wall_beyond(&self, feet: &[Option<usize>], slope: FootSlope) -> bool {
        let FootSlope { lowest, k1, .. } = slope;
        let foot = |k: usize| feet.get(k).copied().flatten();
        let yf = self.foot_y(lowest);
        let up = |k: usize, step: usize| {
            k < feet.len()
                && self.code_at(self.column_x(k, yf), yf).is_some()
                && foot(k).is_none_or(|f| f >= lowest + step)
        };
        let jumps = up(k1 + 1, 1)
            && up(k1 + 2, 1)
            && (up(k1 + 1, FOOT_STEP_ROWS) || up(k1 + 2, FOOT_STEP_ROWS));
        jumps && (1..=3).any(|d| self.ground_at(self.column_x(k1 + d, yf), yf))
    }

    /// Carpet under the slanting foot, in at least half of the `k0` columns before the lowest
    /// foot (the first row under it is often a mixed pixel): not a robot standing in front of
    /// the post.
    fn carpet_under(&self, feet: &[Option<usize>], k0: usize) -> bool {
        let carpet_under = (0..k0)
            .filter(|&k| {
                feet.get(k).copied().flatten().is_some_and(|f| {
                    (1..=2).any(|d| {
                        let y = self.foot_y(f) + d as f64;
                        self.ground_at(self.column_x(k, y), y)
                    })
                })
            })
            .count();
        carpet_under * 2 >= k0
    }

    /// The corner on the top's side, checked against the foot's corner: `None` (no side wall)
    /// when the tops rise more than a row towards the corner; `Some(None)` when the top shows
    /// no clear corner. The corner is nearer, so its top is no lower than the outline's; it
    /// rises less than the foot descends when the camera is below the goal's top, and a row of
    /// it is noise.
    fn top_corner(
        &self,
        columns: usize,
        slope: FootSlope,
        foot_corner: WallCorner,
    ) -> Option<Option<WallCorner>> {
        let FootSlope { k0, k1, .. } = slope;
        let tops: Vec<Option<usize>> = (0..columns).map(|k| self.top_of(k)).collect();
        let top = |k: usize| tops.get(k).copied().flatten();
        let top_at_edge = (0..2).filter_map(top).min()?;
        let highest = (0..=k1).filter_map(top).min()?;
        if (k0..=k1).filter_map(top).min()? > top_at_edge + 1 {
            return None;
        }
        // The end of the highest top's plateau, the top lower in the next two columns (the
        // back wall's, farther away).
        let yf = foot_corner.at.y_px;
        Some((0..=k1).find(|&k| top(k) == Some(highest)).and_then(|k| {
            let end = plateau_end(&top, k, highest);
            let lower = |k: usize| k < tops.len() && top(k).is_none_or(|t| t > highest);
            let yt = self.top_y(highest);
            let corner = self.crossing(end, yt);
            (lower(end + 1)
                && lower(end + 2)
                && self.code_at(self.column_x(end + 1, yt), yt).is_some()
                && (corner.offset - foot_corner.offset).abs() <= SideWall::MAX_LEAN * (yf - yt))
                .then_some(corner)
        }))
    }

    /// Where row `y` leaves the goal colour between columns `k` and `k + 1`, to 1/64 px by
    /// bisection.
    fn crossing(&self, k: usize, y: f64) -> WallCorner {
        let (mut inside, mut outside) = (self.column_x(k, y), self.column_x(k + 1, y));
        for _ in 0..6 {
            let m = (inside + outside) / 2.0;
            if self.goal_at(m, y) {
                inside = m;
            } else {
                outside = m;
            }
        }
        let x = (inside + outside) / 2.0;
        WallCorner {
            at: ImagePoint::new(x, y),
            offset: self.dir * (x - self.edge_x(y)),
        }
    }
}

/// The slanting foot of a side wall: its lowest foot (sample row `lowest`) from column `k0`
/// (the first, counted from the outline) to `k1` (the end of its plateau).
#[derive(Debug, Clone, Copy)]
struct FootSlope {
    k0: usize,
    k1: usize,
    lowest: usize,
}

impl FootSlope {
    /// The lowest foot among the first `search` columns, when it is at least
    /// [`MIN_WALL_COLUMNS`] inside, every column before it has a foot, and the foot at the
    /// outline is [`FOOT_STEP_ROWS`] higher.
    fn find(feet: &[Option<usize>], search: usize) -> Option<Self> {
        let foot = |k: usize| feet.get(k).copied().flatten();
        let (k0, lowest) = (0..search)
            .filter_map(|k| foot(k).map(|f| (k, f)))
            .min_by_key(|&(k, f)| (f, k))?;
        let foot_at_edge = (0..2).filter_map(foot).max()?;
        if k0 < MIN_WALL_COLUMNS
            || (0..k0).any(|k| foot(k).is_none())
            || foot_at_edge < lowest + FOOT_STEP_ROWS
        {
            return None;
        }
        Some(Self {
            k0,
            k1: plateau_end(&foot, k0, lowest),
            lowest,
        })
    }
}

/// The last column of a plateau of `value` starting at column `from` in a profile: a single
/// column one row off inside it is noise.
pub(super) fn plateau_end(
    profile: &impl Fn(usize) -> Option<usize>,
    from: usize,
    value: usize,
) -> usize {
    let mut end = from;
    let mut k = from + 1;
    while let Some(v) = profile(k) {
        if v == value {
            end = k;
        } else if !(v == value + 1 && profile(k + 1) == Some(value)) {
            break;
        }
        k += 1;
    }
    end
}
