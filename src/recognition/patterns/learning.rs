//! Learning, multi-frame and offline (like `lut::learn`): views grouped by signature,
//! triangulated from the robot's poses, the size → distance relation fitted, and the groups
//! merged into the memory's places.

use serde::{Deserialize, Serialize};

use super::{
    FieldRay, PatternMemory, PatternObject, PatternObservation, PatternParams, Placement,
    Signature, SizeRelation,
};
use crate::geometry::RobotPose;

/// Settings of the learning phase.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct LearnParams {
    /// A group of views placed within this distance of a known object adds its signature to
    /// that object instead of making a new one, centimetres.
    pub same_object_cm: f64,
    /// Views a group needs to be learnt.
    pub min_views: usize,
    /// Smallest spread of the bearing rays for triangulation, degrees: below it the baseline
    /// is too short and the position comes from the size relation.
    pub min_spread_deg: f64,
    /// A ray passing farther than this from the triangulated position is dropped as an
    /// outlier (and may form another object), centimetres.
    pub outlier_cm: f64,
}

impl Default for LearnParams {
    fn default() -> Self {
        Self {
            same_object_cm: 30.0,
            min_views: 4,
            min_spread_deg: 4.0,
            outlier_cm: 20.0,
        }
    }
}

/// One observation with the robot's pose when it was made: the input of learning.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LearnView {
    /// Where the view came from (frame number across the inputs), for the report.
    pub frame: usize,
    /// The robot's field pose.
    pub robot: RobotPose,
    /// What was seen.
    pub observation: PatternObservation,
}

/// A least-squares intersection of rays on the ground.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Triangulation {
    /// The point, field centimetres.
    pub field_cm: [f64; 2],
    /// Root mean square distance of the rays from it, centimetres.
    pub residual_cm: f64,
    /// Spread of the ray directions, degrees (the angle two rays would need to give the same
    /// conditioning).
    pub spread_deg: f64,
}

/// The point closest to every ray on the ground in the weighted least-squares sense (`weights`
/// per ray; perpendicular distances), or `None` when the rays are (nearly) parallel or the point
/// lies behind one of them.
#[must_use]
pub fn triangulate(rays: &[FieldRay], weights: &[f64]) -> Option<Triangulation> {
    let t = least_squares_point(rays, weights)?;
    rays.iter()
        .all(|r| along_and_across(r, t.field_cm).0 > 0.0)
        .then_some(t)
}

/// [`triangulate`] without the check that the point lies ahead of every ray (robust
/// triangulation drops the rays it lies behind).
pub(super) fn least_squares_point(rays: &[FieldRay], weights: &[f64]) -> Option<Triangulation> {
    if rays.len() < 2 || weights.len() != rays.len() {
        return None;
    }
    let (mut a, mut b, mut total) = ([[0.0f64; 2]; 2], [0.0f64; 2], 0.0);
    for (r, &w) in rays.iter().zip(weights) {
        let n = [-r.heading_rad.sin(), r.heading_rad.cos()];
        let no = n[0] * r.origin_cm[0] + n[1] * r.origin_cm[1];
        for i in 0..2 {
            for j in 0..2 {
                a[i][j] += w * n[i] * n[j];
            }
            b[i] += w * n[i] * no;
        }
        total += w;
    }
    let det = a[0][0] * a[1][1] - a[0][1] * a[1][0];
    let trace = a[0][0] + a[1][1];
    if !(total > 0.0 && det.is_finite()) {
        return None;
    }
    // Smaller eigenvalue over the total weight = sin²(spread / 2) for two rays.
    let lambda_min = trace / 2.0 - ((trace / 2.0).powi(2) - det).max(0.0).sqrt();
    let spread_deg = 2.0
        * (lambda_min / total)
            .clamp(0.0, 1.0)
            .sqrt()
            .asin()
            .to_degrees();
    if det.abs() < 1e-12 * total * total {
        return None;
    }
    let p = [
        (a[1][1] * b[0] - a[0][1] * b[1]) / det,
        (a[0][0] * b[1] - a[1][0] * b[0]) / det,
    ];
    let ss: f64 = rays.iter().map(|r| along_and_across(r, p).1.powi(2)).sum();
    Some(Triangulation {
        field_cm: p,
        residual_cm: (ss / rays.len() as f64).sqrt(),
        spread_deg,
    })
    .filter(|t| t.field_cm.iter().all(|v| v.is_finite()))
}

/// Distance on the ground from a ray's origin to a point, and the point's perpendicular
/// distance from the ray (centimetres); the first is negative behind the ray.
pub(super) fn along_and_across(r: &FieldRay, p: [f64; 2]) -> (f64, f64) {
    let (dx, dy) = (p[0] - r.origin_cm[0], p[1] - r.origin_cm[1]);
    let (s, c) = r.heading_rad.sin_cos();
    (c * dx + s * dy, (-s * dx + c * dy).abs())
}

/// What one learning run did.
#[derive(Debug, Clone, PartialEq, Default, Serialize)]
pub struct LearnReport {
    /// Views given.
    pub views: usize,
    /// Views without a camera pose (no joint readings): they have no ray.
    pub views_without_ray: usize,
    /// Views with too little colour around the pink to be a place.
    pub views_without_colour: usize,
    /// Objects made new.
    pub objects_created: Vec<usize>,
    /// Objects that got another pattern.
    pub patterns_added: Vec<usize>,
    /// Objects whose further pattern was refused as too close to another object's (within one
    /// region of a match).
    pub patterns_refused: Vec<usize>,
    /// Views added to an object whose pattern they already matched.
    pub views_merged: usize,
    /// Groups that could not be learnt, with the reason.
    pub groups_dropped: Vec<String>,
    /// Pairs of objects whose patterns match each other: identification cannot tell them
    /// apart.
    pub indistinct: Vec<(usize, usize)>,
}

/// A group's result before it is merged into the memory.
#[derive(Debug, Clone, Copy)]
pub(super) struct Learnt {
    /// The group's consensus signature.
    signature: Signature,
    /// Where it was placed, field centimetres.
    at: [f64; 2],
    /// Its height, centimetres (triangulated groups).
    height: Option<f64>,
    /// Views in the group.
    views: usize,
    /// How it was placed.
    placed_by: Placement,
    /// Triangulation residual, centimetres.
    residual_cm: f64,
}

/// A group of views taken to show one marker.
#[derive(Debug, Clone)]
pub(super) struct Group {
    pub views: Vec<(FieldRay, PatternObservation)>,
}

impl Group {
    /// The region-by-region consensus: each region's most common first colour and, among views
    /// with it, the most common second colour.
    pub(super) fn consensus(&self) -> Signature {
        let mut out = [[0u8; 2]; 9];
        for (k, slot) in out.iter_mut().enumerate() {
            let mut first = [0usize; 16];
            for (_, o) in &self.views {
                if let Some(n) = first.get_mut(usize::from(o.signature.0[k][0])) {
                    *n += 1;
                }
            }
            let top = (0..16u8)
                .max_by_key(|&c| (first[usize::from(c)], std::cmp::Reverse(c)))
                .unwrap_or(0);
            let mut second = [0usize; 16];
            for (_, o) in self
                .views
                .iter()
                .filter(|(_, o)| o.signature.0[k][0] == top)
            {
                if let Some(n) = second.get_mut(usize::from(o.signature.0[k][1])) {
                    *n += 1;
                }
            }
            let next = (0..16u8)
                .max_by_key(|&c| (second[usize::from(c)], std::cmp::Reverse(c)))
                .unwrap_or(0);
            *slot = [top, next];
        }
        Signature(out)
    }

    /// Robust triangulation: weighted so that every ray's angle counts alike (weights 1 /
    /// distance²), the worst ray dropped while it passes farther than `outlier_cm`. Returns the
    /// result and the dropped views.
    pub(super) fn triangulate(
        &mut self,
        p: &LearnParams,
    ) -> (Option<Triangulation>, Vec<(FieldRay, PatternObservation)>) {
        let mut dropped = Vec::new();
        loop {
            let rays: Vec<FieldRay> = self.views.iter().map(|v| v.0).collect();
            let mut weights = vec![1.0; rays.len()];
            let mut t = least_squares_point(&rays, &weights);
            for _ in 0..3 {
                let Some(tt) = t else { break };
                for (w, r) in weights.iter_mut().zip(&rays) {
                    let (along, _) = along_and_across(r, tt.field_cm);
                    *w = 1.0 / along.max(20.0).powi(2);
                }
                t = least_squares_point(&rays, &weights).or(t);
            }
            let Some(tt) = t else {
                return (None, dropped);
            };
            // The worst ray: one the point lies behind, else the one passing farthest off.
            let worst = rays
                .iter()
                .enumerate()
                .map(|(i, r)| {
                    let (along, across) = along_and_across(r, tt.field_cm);
                    (i, if along <= 0.0 { f64::INFINITY } else { across })
                })
                .max_by(|a, b| a.1.total_cmp(&b.1));
            match worst {
                Some((i, off)) if off > p.outlier_cm && self.views.len() > 2 => {
                    dropped.push(self.views.swap_remove(i));
                }
                Some((_, off)) if off.is_infinite() => return (None, dropped),
                _ => return (Some(tt), dropped),
            }
        }
    }
}

/// Theil–Sen line d = m · (1 / s) + o through `(s, d)` samples: m the median of the pairwise
/// slopes (at most about 250 000 pairs, evenly picked), o the median of d − m / s.
pub(super) fn theil_sen(samples: &[[f64; 2]]) -> Option<(f64, f64)> {
    let n = samples.len();
    if n < 2 {
        return None;
    }
    let stride = (n * n / 2 / 250_000).max(1);
    let mut slopes = Vec::new();
    let mut k = 0usize;
    for i in 0..n {
        for j in i + 1..n {
            k += 1;
            if !k.is_multiple_of(stride) {
                continue;
            }
            let dx = 1.0 / samples[j][0] - 1.0 / samples[i][0];
            if dx.abs() > 1e-12 {
                slopes.push((samples[j][1] - samples[i][1]) / dx);
            }
        }
    }
    if slopes.is_empty() {
        return None;
    }
    let m = median(&slopes);
    let o = median(&samples.iter().map(|s| s[1] - m / s[0]).collect::<Vec<_>>());
    (m.is_finite() && o.is_finite()).then_some((m, o))
}

/// The median of `v` (0 for none).
pub(super) fn median(v: &[f64]) -> f64 {
    crate::stats::median(v).unwrap_or(0.0)
}

/// A group of views with its triangulated position.
type Placed = (Group, Triangulation);

impl PatternMemory {
    /// Learning phase: adds what `views` show to the memory (see the module documentation) and
    /// refits the size relation over every sample learnt so far.
    pub fn learn(
        &mut self,
        views: &[LearnView],
        recognition: &PatternParams,
        p: &LearnParams,
    ) -> LearnReport {
        let mut report = LearnReport {
            views: views.len(),
            ..LearnReport::default()
        };
        let groups = group_by_signature(views, recognition, &mut report);
        let (placed, narrow) = triangulate_groups(groups, p, &mut report);
        let heights = self.add_size_samples(&placed);
        self.relation = SizeRelation::fit(&self.samples).or(self.relation);
        // Objects from triangulated groups, then from narrow ones placed by size.
        let mut learnt: Vec<Learnt> = placed
            .iter()
            .zip(&heights)
            .map(|((g, t), &z)| Learnt {
                signature: g.consensus(),
                at: t.field_cm,
                height: Some(z),
                views: g.views.len(),
                placed_by: Placement::Triangulation,
                residual_cm: t.residual_cm,
            })
            .collect();
        learnt.extend(place_by_size(narrow, self.relation, &mut report));
        self.merge(learnt, recognition, p, &mut report);
        self.refuse_near_twins(recognition, &mut report);
        for (i, a) in self.objects.iter().enumerate() {
            for b in &self.objects[i + 1..] {
                let matches = a.patterns.iter().any(|x| {
                    b.patterns
                        .iter()
                        .any(|y| x.agreement(y) >= recognition.min_agreement)
                });
                if matches {
                    report.indistinct.push((a.id, b.id));
                }
            }
        }
        report
    }

    /// Size samples `(size px, distance cm)` from every view of a triangulated marker; returns
    /// each group's height (the median of what its rays' elevations give), centimetres.
    fn add_size_samples(&mut self, placed: &[Placed]) -> Vec<f64> {
        let mut heights = Vec::new();
        for (g, t) in placed {
            let mut zs = Vec::new();
            for (r, _) in &g.views {
                let (along, _) = along_and_across(r, t.field_cm);
                zs.push(r.origin_cm[2] + along * r.slope);
            }
            let z = median(&zs);
            heights.push(z);
            for (r, o) in &g.views {
                let (along, _) = along_and_across(r, t.field_cm);
                let d = along.hypot(z - r.origin_cm[2]);
                self.samples.push([o.size_px, d]);
            }
        }
        heights
    }

    /// Merges learnt groups into the memory, the best-seen groups first: they place the
    /// objects, groups merged into them later only add their patterns (a handful of views of a
    /// cut or misread marker would only pull a well-triangulated position off).
    fn merge(
        &mut self,
        mut learnt: Vec<Learnt>,
        recognition: &PatternParams,
        p: &LearnParams,
        report: &mut LearnReport,
    ) {
        learnt.sort_by_key(|l| {
            (
                l.placed_by != Placement::Triangulation,
                std::cmp::Reverse(l.views),
            )
        });
        for l in learnt {
            let Learnt {
                signature: sig,
                at,
                height,
                views: n,
                placed_by: how,
                residual_cm: residual,
            } = l;
            let near = self
                .objects
                .iter_mut()
                .filter(|o| {
                    (o.field_cm[0] - at[0]).hypot(o.field_cm[1] - at[1]) <= p.same_object_cm
                })
                .min_by(|a, b| {
                    let d =
                        |o: &PatternObject| (o.field_cm[0] - at[0]).hypot(o.field_cm[1] - at[1]);
                    d(a).total_cmp(&d(b))
                });
            match near {
                Some(o) => {
                    if o.patterns
                        .iter()
                        .any(|q| q.agreement(&sig) >= recognition.min_agreement)
                    {
                        report.views_merged += n;
                    } else {
                        o.patterns.push(sig);
                        report.patterns_added.push(o.id);
                    }
                    // A size-placed object (from an earlier run) takes a triangulated position.
                    if how == Placement::Triangulation && o.placed_by == Placement::SizeRelation {
                        o.field_cm = at;
                        o.height_cm = height;
                        o.placed_by = how;
                        o.residual_cm = residual;
                    }
                    o.views += n;
                }
                None => {
                    let id = self.objects.iter().map(|o| o.id + 1).max().unwrap_or(0);
                    self.objects.push(PatternObject {
                        id,
                        field_cm: at,
                        height_cm: height,
                        patterns: vec![sig],
                        views: n,
                        placed_by: how,
                        residual_cm: residual,
                    });
                    report.objects_created.push(id);
                }
            }
        }
    }

    /// A further pattern of an object that comes within one region of another object's
    /// pattern is refused: it would let a single misread region of the other object's marker
    /// be identified as this one (a cut or misread view of one of two near-twin markers
    /// otherwise becomes the other twin's pattern). Each object keeps its first pattern.
    fn refuse_near_twins(&mut self, recognition: &PatternParams, report: &mut LearnReport) {
        let near_miss = recognition.min_agreement.saturating_sub(1);
        let snapshot: Vec<(usize, Vec<Signature>)> = self
            .objects
            .iter()
            .map(|o| (o.id, o.patterns.clone()))
            .collect();
        for o in &mut self.objects {
            let id = o.id;
            let mut k = 0;
            o.patterns.retain(|sig| {
                k += 1;
                let close = snapshot.iter().any(|(other, pats)| {
                    *other != id && pats.iter().any(|q| q.agreement(sig) >= near_miss)
                });
                let keep = k == 1 || !close;
                if !keep {
                    report.patterns_refused.push(id);
                }
                keep
            });
        }
    }
}

/// Views grouped by signature (each joins the group whose first view agrees best, at least
/// `min_agreement` regions); views without a ray or with too few coloured regions are counted
/// and left out.
fn group_by_signature(
    views: &[LearnView],
    recognition: &PatternParams,
    report: &mut LearnReport,
) -> Vec<Group> {
    let mut groups: Vec<Group> = Vec::new();
    for v in views {
        let Some(ray) = v.observation.ray else {
            report.views_without_ray += 1;
            continue;
        };
        if v.observation.signature.coloured_regions() < recognition.min_coloured_regions {
            report.views_without_colour += 1;
            continue;
        }
        let item = (ray.in_field(&v.robot), v.observation);
        let sig = v.observation.signature;
        let best = groups
            .iter_mut()
            .map(|g| {
                let a = g.views[0].1.signature.agreement(&sig);
                (a, g)
            })
            .filter(|(a, _)| *a >= recognition.min_agreement)
            .max_by_key(|(a, _)| *a);
        match best {
            Some((_, g)) => g.views.push(item),
            None => groups.push(Group { views: vec![item] }),
        }
    }
    groups
}

/// Triangulates every group; rays that do not fit form groups of their own (the same
/// signature at another place, or a view grouped with the wrong near-twin). Returns the
/// groups placed and those seen from too narrow a baseline.
fn triangulate_groups(
    groups: Vec<Group>,
    p: &LearnParams,
    report: &mut LearnReport,
) -> (Vec<Placed>, Vec<Group>) {
    let mut placed: Vec<Placed> = Vec::new();
    let mut narrow: Vec<Group> = Vec::new();
    let mut queue = groups;
    let mut rounds = 0;
    while let Some(mut g) = queue.pop() {
        rounds += 1;
        if g.views.len() < p.min_views || rounds > 10_000 {
            report.groups_dropped.push(format!(
                "{} view(s) of {}: fewer than {}",
                g.views.len(),
                g.consensus().short_text(),
                p.min_views
            ));
            continue;
        }
        let (t, dropped) = g.triangulate(p);
        if dropped.len() >= p.min_views.max(1) {
            queue.push(Group { views: dropped });
        } else if !dropped.is_empty() {
            report.groups_dropped.push(format!(
                "{} outlier view(s) of {}",
                dropped.len(),
                g.consensus().short_text()
            ));
        }
        match t {
            Some(t) if t.spread_deg >= p.min_spread_deg && g.views.len() >= p.min_views => {
                placed.push((g, t));
            }
            _ => narrow.push(g),
        }
    }
    (placed, narrow)
}

/// Groups seen from too narrow a baseline, placed along their rays by the size relation (the
/// median of where each view's distance puts it); without a relation they are dropped.
fn place_by_size(
    narrow: Vec<Group>,
    relation: Option<SizeRelation>,
    report: &mut LearnReport,
) -> Vec<Learnt> {
    let mut learnt = Vec::new();
    for g in narrow {
        let Some(rel) = relation else {
            report.groups_dropped.push(format!(
                "{} view(s) of {}: baseline too short to triangulate and no size relation",
                g.views.len(),
                g.consensus().short_text()
            ));
            continue;
        };
        let (mut xs, mut ys) = (Vec::new(), Vec::new());
        for (r, o) in &g.views {
            if let Some(d) = rel.distance_cm(o.size_px) {
                let ground = d / r.slope.hypot(1.0);
                xs.push(r.origin_cm[0] + ground * r.heading_rad.cos());
                ys.push(r.origin_cm[1] + ground * r.heading_rad.sin());
            }
        }
        if xs.is_empty() {
            continue;
        }
        learnt.push(Learnt {
            signature: g.consensus(),
            at: [median(&xs), median(&ys)],
            height: None,
            views: g.views.len(),
            placed_by: Placement::SizeRelation,
            residual_cm: 0.0,
        });
    }
    learnt
}
