//! Evaluation: recognition compared with ground truth, frame by frame, summed into rates and
//! error percentiles — the numbers the recognition issue's targets are stated in.
//!
//! Pure functions on [`Recognition`] and the renderer's [`RobotViewTruth`]; `eotn eval` reads
//! streams and runs the pipeline, this module only compares.

pub mod ball_boxes;
pub mod beacons;
pub mod label_sets;
pub mod labels;
pub mod overhead;
pub mod overhead_field;
pub mod patterns;
pub mod plots;
pub mod skew;

use serde::{Deserialize, Serialize};

use crate::geometry::ImagePoint;
use crate::lut::ColourClass;
use crate::model::scene::GoalColour;
use crate::model::truth::{GoalGap, GoalTruth, RobotViewTruth};
use crate::recognition::Recognition;
use crate::recognition::goals::Post;

/// When an object counts as "should have been found", and when a detection matches.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct EvalParams {
    /// The ball must be found when at least this fraction of it is visible...
    pub ball_min_visible_fraction: f64,
    /// ... and its image diameter is at least this, pixels.
    pub ball_min_diameter_px: f64,
    /// A ball detection matches when its centre is within this fraction of the true radius
    /// (at least [`Self::ball_match_min_px`]).
    pub ball_match_radius_fraction: f64,
    /// Smallest matching tolerance, pixels.
    pub ball_match_min_px: f64,
    /// A goal must be found when at least this fraction of its mouth (the area between the
    /// posts, feet to tops) is inside the image.
    pub goal_min_mouth_fraction: f64,
    /// ... and it shows at least this many pixels.
    pub goal_min_pixels: usize,
    /// A goal's second largest open stretch is as good an answer as its largest when it is at
    /// most this much narrower, pixels (the gap target's tolerance).
    pub gap_tie_px: f64,
    /// A beacon must be found when no image border cuts its two bands, at least this fraction
    /// of them is in view ...
    pub beacon_min_visible_fraction: f64,
    /// ... and they show at least this many pixels.
    pub beacon_min_band_pixels: usize,
}

impl Default for EvalParams {
    fn default() -> Self {
        Self {
            ball_min_visible_fraction: 0.6,
            ball_min_diameter_px: 6.0,
            ball_match_radius_fraction: 0.5,
            ball_match_min_px: 4.0,
            goal_min_mouth_fraction: 0.5,
            goal_min_pixels: 30,
            gap_tie_px: 3.0,
            beacon_min_visible_fraction: 0.9,
            beacon_min_band_pixels: 40,
        }
    }
}

/// How one frame went.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct FrameEval {
    /// Frame index in its stream.
    pub frame: usize,
    /// The ball had to be found.
    pub ball_eligible: bool,
    /// A ball was reported.
    pub ball_reported: bool,
    /// The reported ball matches the true one.
    pub ball_correct: bool,
    /// The reported ball is at least near the true one (within two radii): not a false ball,
    /// though perhaps badly placed.
    pub ball_near: bool,
    /// A ball was reported where there is none (or far from it).
    pub ball_false: bool,
    /// The true ball is cut off by the image edge.
    pub ball_cut: bool,
    /// Relative distance error of a correct ball (|reported − true| / true).
    pub ball_distance_error: Option<f64>,
    /// Bearing error of a correct ball, radians.
    pub ball_bearing_error_rad: Option<f64>,
    /// Radius error of a reported ball near the true one, pixels.
    pub ball_radius_error_px: Option<f64>,
    /// Goals that had to be found.
    pub goals_eligible: usize,
    /// Of those, found with the right colour.
    pub goals_found: usize,
    /// Goals reported that are not in view.
    pub goals_false: usize,
    /// Post position errors, pixels (worst of top and foot).
    pub post_errors_px: Vec<f64>,
    /// Gap end errors, pixels (worst of both ends).
    pub gap_errors_px: Vec<f64>,
    /// Relative distance errors of found goals with uncut top and bottom.
    pub goal_distance_errors: Vec<f64>,
    /// True camera distance of the ball when it had to be found, centimetres (for rates per
    /// distance band).
    pub ball_true_distance_cm: Option<f64>,
    /// True and reported camera distance of a correct ball, centimetres.
    pub ball_distances_cm: Option<(f64, f64)>,
    /// Each goal that had to be found: its true camera distance (cm) and whether it was.
    pub goal_detections: Vec<(f64, bool)>,
    /// Found goals with uncut top and bottom: true and reported distance and the height used.
    pub goal_distances_cm: Vec<GoalDistance>,
    /// Beacons that had to be found ([`beacons::beacon_is_whole`]).
    pub beacons_eligible: usize,
    /// Of those, found where they are.
    pub beacons_found: usize,
    /// Of those found, with the right colours top and bottom.
    pub beacons_colours_right: usize,
    /// Accepted beacons over no beacon.
    pub beacons_false: usize,
    /// Each found eligible beacon's true and reported distance.
    pub beacon_distances_cm: Vec<beacons::BeaconDistance>,
}

/// A found goal's distance against the truth (the data of plots and calibration).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct GoalDistance {
    /// True camera distance of the goal mouth's centre, centimetres.
    pub true_cm: f64,
    /// Reported camera distance, centimetres.
    pub measured_cm: f64,
    /// Height the distance came from, pixels.
    pub height_px: f64,
    /// The sky-blue goal (else the yellow one).
    pub sky_blue: bool,
}

/// The class code of a goal colour.
#[must_use]
pub fn goal_class(c: GoalColour) -> ColourClass {
    match c {
        GoalColour::Yellow => ColourClass::Yellow,
        GoalColour::SkyBlue => ColourClass::SkyBlue,
    }
}

/// Share of a goal's mouth — the quadrilateral between the two posts' feet and tops — that lies
/// inside the image (sampled on a 21 × 21 grid); 0 when a post does not project.
#[must_use]
pub fn mouth_fraction_in_image(g: &crate::model::truth::GoalTruth, width: f64, height: f64) -> f64 {
    let [a, b] = &g.posts;
    let (Some(lb), Some(lt), Some(rb), Some(rt)) =
        (a.image_base, a.image_top, b.image_base, b.image_top)
    else {
        return 0.0;
    };
    let n = 20;
    let mut inside = 0usize;
    for i in 0..=n {
        let u = f64::from(i) / f64::from(n);
        for j in 0..=n {
            let v = f64::from(j) / f64::from(n);
            let lerp = |p: f64, q: f64, r: f64, s: f64| {
                (1.0 - v) * ((1.0 - u) * p + u * q) + v * ((1.0 - u) * r + u * s)
            };
            let x = lerp(lt.x_px, rt.x_px, lb.x_px, rb.x_px);
            let y = lerp(lt.y_px, rt.y_px, lb.y_px, rb.y_px);
            if x >= 0.0 && y >= 0.0 && x < width && y < height {
                inside += 1;
            }
        }
    }
    inside as f64 / f64::from((n + 1) * (n + 1))
}

/// Compares one frame's recognition with its truth.
#[must_use]
pub fn evaluate_frame(
    frame: usize,
    r: &Recognition,
    t: &RobotViewTruth,
    width: f64,
    height: f64,
    p: &EvalParams,
) -> FrameEval {
    let mut e = FrameEval {
        frame,
        ..FrameEval::default()
    };
    score_ball(&mut e, r, t, p);
    beacons::score_beacons(&mut e, r, t, p);
    for tg in &t.goals {
        score_goal(&mut e, r, tg, width, height, p);
    }
    let in_view: Vec<ColourClass> = t
        .goals
        .iter()
        .filter(|g| g.visible_pixels > 0)
        .map(|g| goal_class(g.colour))
        .collect();
    e.goals_false = r
        .goals
        .goals()
        .filter(|g| !in_view.contains(&g.colour))
        .count();
    e
}

/// The ball: eligible, reported, matched (then its distance, bearing and radius errors), false.
fn score_ball(e: &mut FrameEval, r: &Recognition, t: &RobotViewTruth, p: &EvalParams) {
    let reported = r.ball.ball.as_ref();
    e.ball_reported = reported.is_some();
    let truth = t.ball.as_ref().filter(|b| b.visible_pixels > 0);
    if let Some(tb) = truth {
        let radius = tb.image_radius_px.unwrap_or(0.0);
        e.ball_eligible = tb.visible_fraction >= p.ball_min_visible_fraction
            && 2.0 * radius >= p.ball_min_diameter_px;
        e.ball_cut = tb.cut_off.left || tb.cut_off.right || tb.cut_off.top || tb.cut_off.bottom;
        if e.ball_eligible {
            e.ball_true_distance_cm = Some(tb.relative.camera_distance_cm);
        }
        if let (Some(b), Some(img)) = (reported, tb.relative.image) {
            // A ball cut by the image edge is matched within its radius, an uncut one within
            // half of it; anything within two radii is at least the ball (not a false one).
            let fraction = if e.ball_cut {
                1.0
            } else {
                p.ball_match_radius_fraction
            };
            let tol = (fraction * radius).max(p.ball_match_min_px);
            let off = (b.center_x - img.x_px).hypot(b.center_y - img.y_px);
            e.ball_correct = off <= tol;
            e.ball_near = off <= 2.0 * radius + p.ball_match_min_px;
            if e.ball_correct {
                let d = tb.relative.camera_distance_cm;
                e.ball_distance_error = Some((b.camera.distance_cm - d).abs() / d);
                e.ball_distances_cm = Some((d, b.camera.distance_cm));
                e.ball_bearing_error_rad =
                    Some((b.camera.bearing_rad - tb.relative.camera_bearing_rad).abs());
            }
            if e.ball_near {
                e.ball_radius_error_px = Some((b.radius_px - radius).abs());
            }
        }
    }
    e.ball_false = e.ball_reported && !e.ball_near;
}

/// One true goal: eligible and found, and the found goal's distance, post and gap errors.
fn score_goal(
    e: &mut FrameEval,
    r: &Recognition,
    tg: &GoalTruth,
    width: f64,
    height: f64,
    p: &EvalParams,
) {
    let class = goal_class(tg.colour);
    let mouth = mouth_fraction_in_image(tg, width, height);
    let eligible = mouth >= p.goal_min_mouth_fraction && tg.visible_pixels >= p.goal_min_pixels;
    let found = r.goals.goals().find(|g| g.colour == class);
    if eligible {
        e.goals_eligible += 1;
        e.goal_detections
            .push((tg.relative.camera_distance_cm, found.is_some()));
    }
    let Some(g) = found else { return };
    if eligible {
        e.goals_found += 1;
    }
    if !g.cut_off.top && !g.cut_off.bottom && !g.distance_from_ir {
        let d = tg.relative.camera_distance_cm;
        e.goal_distance_errors
            .push((g.camera.distance_cm - d).abs() / d);
        e.goal_distances_cm.push(GoalDistance {
            true_cm: d,
            measured_cm: g.camera.distance_cm,
            height_px: g.height_px,
            sky_blue: class == ColourClass::SkyBlue,
        });
    }
    for post in &g.posts {
        let best = post_error_px(post, tg, width, height);
        if best.is_finite() {
            e.post_errors_px.push(best);
        }
    }
    if let (Some(gap), Some(largest)) = (&g.gap, &tg.largest_gap) {
        // Scored against the largest open stretch, or against the second when that is as
        // wide within the tie tolerance and nearer (either is "the largest").
        let error = |t: &GoalGap| {
            let left = (gap.left.x_px - t.from_x_px as f64).abs();
            let right = (gap.right.x_px - (t.to_x_px as f64 + 1.0)).abs();
            left.max(right)
        };
        let width = |t: &GoalGap| (t.to_x_px - t.from_x_px) as f64;
        let tied = tg
            .second_gap
            .filter(|s| width(s) + p.gap_tie_px >= width(largest))
            .map_or(f64::INFINITY, |s| error(&s));
        e.gap_errors_px.push(error(largest).min(tied));
    }
}

/// A found post's error against the true post nearest it, pixels: infinite when that post is
/// not scored because one of its ends is outside the image (a post whose partner runs out of
/// the image is not compared with the goal's other post instead).
fn post_error_px(post: &Post, tg: &GoalTruth, width: f64, height: f64) -> f64 {
    let inside =
        |q: &ImagePoint| q.x_px >= 0.0 && q.x_px <= width && q.y_px >= 0.0 && q.y_px <= height;
    tg.posts
        .iter()
        .filter_map(|tp| Some((tp.image_base?, tp.image_top?)))
        .map(|(base, top)| {
            // The truth projects at the reference row's time: compare the post moved there
            // (the line through its skew-corrected ends).
            let (a, b) = (post.reference_top, post.reference_bottom);
            let at = |y: f64| {
                if (b.y_px - a.y_px).abs() > 1e-9 {
                    a.x_px + (b.x_px - a.x_px) * (y - a.y_px) / (b.y_px - a.y_px)
                } else {
                    a.x_px
                }
            };
            let error = (at(base.y_px) - base.x_px)
                .abs()
                .max((at(top.y_px) - top.x_px).abs());
            (error, inside(&base) && inside(&top))
        })
        .min_by(|a, b| a.0.total_cmp(&b.0))
        .filter(|(_, scored)| *scored)
        .map_or(f64::INFINITY, |(error, _)| error)
}

/// 50th, 90th and 95th percentiles and the count of a sample that has at least one value. An
/// empty sample has no percentiles: [`Percentiles::of`] gives `None` (`null` in JSON, "—" in
/// text), never zeros that would read as "no error".
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Percentiles {
    /// Number of values (at least 1).
    pub n: usize,
    /// Median.
    pub p50: f64,
    /// 90th percentile.
    pub p90: f64,
    /// 95th percentile.
    pub p95: f64,
}

impl Percentiles {
    /// Percentiles by nearest rank; `None` for a sample without values. NaN values are left
    /// out.
    #[must_use]
    pub fn of(values: &[f64]) -> Option<Self> {
        let mut v: Vec<f64> = values.iter().copied().filter(|x| !x.is_nan()).collect();
        if v.is_empty() {
            return None;
        }
        v.sort_by(f64::total_cmp);
        let rank = |q: f64| v[((q * v.len() as f64).ceil() as usize).clamp(1, v.len()) - 1];
        Some(Self {
            n: v.len(),
            p50: rank(0.5),
            p90: rank(0.9),
            p95: rank(0.95),
        })
    }

    /// The median by nearest rank, `None` for a sample without values.
    #[must_use]
    pub fn median_of(values: &[f64]) -> Option<f64> {
        Self::of(values).map(|p| p.p50)
    }
}

/// How many values a percentile summary was taken over: 0 when there were none.
#[must_use]
pub fn sample_size(p: Option<&Percentiles>) -> usize {
    p.map_or(0, |p| p.n)
}

/// One figure of a percentile summary as text, `pick(p) × scale` with `decimals` decimals and
/// `unit` after it, or "—" when the sample was empty.
#[must_use]
pub fn percentile_text(
    p: Option<&Percentiles>,
    pick: fn(&Percentiles) -> f64,
    scale: f64,
    decimals: usize,
    unit: &str,
) -> String {
    p.map_or_else(
        || "—".to_owned(),
        |p| format!("{:.*}{unit}", decimals, pick(p) * scale),
    )
}

fn rate(num: usize, den: usize) -> Option<f64> {
    (den > 0).then(|| num as f64 / den as f64)
}

/// A whole evaluation.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct EvalReport {
    /// Frames compared.
    pub frames: usize,
    /// Frames where the ball had to be found.
    pub ball_eligible: usize,
    /// Of those, found correctly.
    pub ball_found: usize,
    /// Found / eligible.
    pub ball_found_rate: Option<f64>,
    /// Frames with a false ball.
    pub ball_false: usize,
    /// False balls / frames.
    pub ball_false_rate: Option<f64>,
    /// Relative distance errors, balls not cut off.
    pub ball_distance_error: Option<Percentiles>,
    /// Relative distance errors, balls cut off by the image edge.
    pub ball_distance_error_cut: Option<Percentiles>,
    /// Median signed relative distance error (measured − true) / true of balls not cut off:
    /// positive when distances read long (a bias, which the absolute error hides).
    #[serde(default)]
    pub ball_distance_bias: Option<f64>,
    /// The same for balls cut off by the image edge.
    #[serde(default)]
    pub ball_distance_bias_cut: Option<f64>,
    /// Bearing errors, degrees.
    pub ball_bearing_error_deg: Option<Percentiles>,
    /// Radius errors, pixels.
    pub ball_radius_error_px: Option<Percentiles>,
    /// Goals that had to be found.
    pub goals_eligible: usize,
    /// Of those, found.
    pub goals_found: usize,
    /// Found / eligible.
    pub goal_found_rate: Option<f64>,
    /// Goals reported that are not in view.
    pub goals_false: usize,
    /// Goal distance errors (relative), uncut goals.
    pub goal_distance_error: Option<Percentiles>,
    /// Post errors, pixels.
    pub post_error_px: Option<Percentiles>,
    /// Share of posts within 2 px.
    pub posts_within_2px: Option<f64>,
    /// Gap end errors, pixels.
    pub gap_error_px: Option<Percentiles>,
    /// Share of gaps with both ends within 3 px.
    pub gaps_within_3px: Option<f64>,
    /// Frames where an eligible ball was missed.
    pub ball_misses: Vec<usize>,
    /// Frames with a false ball.
    pub ball_false_frames: Vec<usize>,
    /// Frames where an eligible goal was missed.
    pub goal_misses: Vec<usize>,
    /// Frames with a goal reported that is not in view (a yellow or sky-blue thing taken for
    /// a goal).
    pub goal_false_frames: Vec<usize>,
    /// Beacons that had to be found (both bands whole in the image).
    #[serde(default)]
    pub beacons_eligible: usize,
    /// Of those, found where they are.
    #[serde(default)]
    pub beacons_found: usize,
    /// Found / eligible.
    #[serde(default)]
    pub beacon_found_rate: Option<f64>,
    /// Of those found, with the right colours top and bottom.
    #[serde(default)]
    pub beacons_colours_right: usize,
    /// Accepted beacons over no beacon.
    #[serde(default)]
    pub beacons_false: usize,
    /// Relative distance errors of found whole beacons.
    #[serde(default)]
    pub beacon_distance_error: Option<Percentiles>,
    /// Median signed relative distance error of those (positive: reads long).
    #[serde(default)]
    pub beacon_distance_bias: Option<f64>,
    /// Frames where a beacon that had to be found was not.
    #[serde(default)]
    pub beacon_misses: Vec<usize>,
    /// Frames with a false beacon.
    #[serde(default)]
    pub beacon_false_frames: Vec<usize>,
}

impl EvalReport {
    /// Sums frame evaluations.
    #[must_use]
    pub fn from_frames(frames: &[FrameEval]) -> Self {
        let mut r = Self {
            frames: frames.len(),
            ..Self::default()
        };
        let (mut d, mut dc, mut b, mut rad, mut gd, mut posts, mut gaps) =
            (vec![], vec![], vec![], vec![], vec![], vec![], vec![]);
        let (mut s, mut sc) = (vec![], vec![]);
        let (mut bd, mut bs) = (vec![], vec![]);
        for f in frames {
            if f.ball_eligible {
                r.ball_eligible += 1;
                if f.ball_correct {
                    r.ball_found += 1;
                } else {
                    r.ball_misses.push(f.frame);
                }
            }
            if f.ball_false {
                r.ball_false += 1;
                r.ball_false_frames.push(f.frame);
            }
            if let Some(x) = f.ball_distance_error {
                if f.ball_cut { dc.push(x) } else { d.push(x) }
            }
            if let Some((t, m)) = f.ball_distances_cm.filter(|(t, _)| *t > 0.0) {
                if f.ball_cut { &mut sc } else { &mut s }.push((m - t) / t);
            }
            b.extend(f.ball_bearing_error_rad.map(f64::to_degrees));
            rad.extend(f.ball_radius_error_px);
            r.goals_eligible += f.goals_eligible;
            r.goals_found += f.goals_found;
            if f.goals_found < f.goals_eligible {
                r.goal_misses.push(f.frame);
            }
            r.goals_false += f.goals_false;
            if f.goals_false > 0 {
                r.goal_false_frames.push(f.frame);
            }
            gd.extend(&f.goal_distance_errors);
            r.beacons_eligible += f.beacons_eligible;
            r.beacons_found += f.beacons_found;
            r.beacons_colours_right += f.beacons_colours_right;
            r.beacons_false += f.beacons_false;
            if f.beacons_found < f.beacons_eligible {
                r.beacon_misses.push(f.frame);
            }
            if f.beacons_false > 0 {
                r.beacon_false_frames.push(f.frame);
            }
            for d in f.beacon_distances_cm.iter().filter(|d| d.true_cm > 0.0) {
                let signed = (d.measured_cm - d.true_cm) / d.true_cm;
                bd.push(signed.abs());
                bs.push(signed);
            }
            posts.extend(&f.post_errors_px);
            gaps.extend(&f.gap_errors_px);
        }
        r.ball_found_rate = rate(r.ball_found, r.ball_eligible);
        r.ball_false_rate = rate(r.ball_false, r.frames);
        r.ball_distance_error = Percentiles::of(&d);
        r.ball_distance_error_cut = Percentiles::of(&dc);
        r.ball_distance_bias = Percentiles::median_of(&s);
        r.ball_distance_bias_cut = Percentiles::median_of(&sc);
        r.ball_bearing_error_deg = Percentiles::of(&b);
        r.ball_radius_error_px = Percentiles::of(&rad);
        r.goal_found_rate = rate(r.goals_found, r.goals_eligible);
        r.goal_distance_error = Percentiles::of(&gd);
        r.post_error_px = Percentiles::of(&posts);
        r.posts_within_2px = rate(posts.iter().filter(|e| **e <= 2.0).count(), posts.len());
        r.gap_error_px = Percentiles::of(&gaps);
        r.gaps_within_3px = rate(gaps.iter().filter(|e| **e <= 3.0).count(), gaps.len());
        r.beacon_found_rate = rate(r.beacons_found, r.beacons_eligible);
        r.beacon_distance_error = Percentiles::of(&bd);
        r.beacon_distance_bias = Percentiles::median_of(&bs);
        r
    }
}

/// Fits distance = multiplier / height + offset to (height px, true distance cm) pairs by least
/// squares in 1/height ([`crate::stats::fit_inverse_size`]); `None` with fewer than two distinct
/// heights.
#[must_use]
pub fn fit_inverse_size(samples: &[(f64, f64)]) -> Option<(f64, f64)> {
    crate::stats::fit_inverse_size(samples)
}

/// Fits only the multiplier of distance = multiplier / height + `offset` (the offset kept), by
/// least squares; for samples whose heights span too little to separate the two. `None`
/// without a usable sample.
#[must_use]
pub fn fit_inverse_size_multiplier(samples: &[(f64, f64)], offset: f64) -> Option<f64> {
    let (sxy, sxx) = samples
        .iter()
        .filter(|(h, d)| *h > 0.0 && h.is_finite() && d.is_finite())
        .fold((0.0, 0.0), |(a, b), (h, d)| {
            (a + (d - offset) / h, b + 1.0 / (h * h))
        });
    (sxx > 0.0).then(|| sxy / sxx)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn percentiles_by_nearest_rank() {
        let v: Vec<f64> = (1..=100).map(f64::from).collect();
        let p = Percentiles::of(&v).expect("a sample");
        assert_eq!((p.n, p.p50, p.p90, p.p95), (100, 50.0, 90.0, 95.0));
        assert_eq!(Percentiles::of(&[]), None, "no data, no percentiles");
        assert_eq!(Percentiles::of(&[f64::NAN]), None);
        assert_eq!(Percentiles::median_of(&[f64::NAN, 3.0]), Some(3.0));
        assert_eq!(sample_size(None), 0);
        assert_eq!(percentile_text(None, |p| p.p50, 100.0, 1, "%"), "—");
        assert_eq!(
            percentile_text(Some(&p), |p| p.p90, 0.5, 1, " px"),
            "45.0 px"
        );
        // An empty summary is null in JSON, not zeros.
        let r = EvalReport::from_frames(&[]);
        let json = serde_json::to_value(&r).expect("json");
        assert!(json["ball_distance_error"].is_null(), "{json}");
        assert!(json["beacon_distance_error"].is_null(), "{json}");
    }

    #[test]
    fn inverse_size_fit_recovers_the_relation() {
        let samples: Vec<(f64, f64)> = [10.0, 20.0, 40.0]
            .iter()
            .map(|h| (*h, 5757.0 / h + 12.0))
            .collect();
        let (m, o) = fit_inverse_size(&samples).expect("fit");
        assert!((m - 5757.0).abs() < 1e-6 && (o - 12.0).abs() < 1e-6);
        assert!(fit_inverse_size(&[(10.0, 5.0)]).is_none());
        let m = fit_inverse_size_multiplier(&samples, 12.0).expect("fit");
        assert!((m - 5757.0).abs() < 1e-6);
        assert!(fit_inverse_size_multiplier(&[(0.0, 5.0)], 0.0).is_none());
    }

    #[test]
    fn report_counts_misses_and_false_balls() {
        let frames = vec![
            FrameEval {
                frame: 0,
                ball_eligible: true,
                ball_reported: true,
                ball_correct: true,
                ball_distance_error: Some(0.02),
                ball_distances_cm: Some((100.0, 98.0)),
                ..FrameEval::default()
            },
            FrameEval {
                frame: 1,
                ball_eligible: true,
                ..FrameEval::default()
            },
            FrameEval {
                frame: 2,
                ball_reported: true,
                ball_false: true,
                ..FrameEval::default()
            },
        ];
        let r = EvalReport::from_frames(&frames);
        assert_eq!((r.ball_eligible, r.ball_found, r.ball_false), (2, 1, 1));
        assert_eq!(r.ball_misses, vec![1]);
        assert_eq!(r.ball_false_frames, vec![2]);
        assert_eq!(r.ball_found_rate, Some(0.5));
        assert_eq!(r.ball_distance_error.map(|p| (p.n, p.p50)), Some((1, 0.02)));
        assert_eq!(r.ball_distance_error_cut, None);
        assert_eq!(
            r.ball_distance_bias,
            Some(-0.02),
            "signed: the ball read short"
        );
        assert_eq!(r.ball_distance_bias_cut, None);
    }
}
