//! Coloured patterns against the truth: was each marker in view identified as the place learnt
//! for it, as another place, or not at all, and how far off is the distance.
//!
//! Learnt places carry their own ids, so each is matched to the scene's marker nearest its
//! learnt field position (within [`PatternEvalParams::place_match_cm`]); a place matched to no
//! marker counts every identification as wrong.

use serde::{Deserialize, Serialize};

use super::Percentiles;
use crate::model::truth::{MarkerTruth, RobotViewTruth};
use crate::recognition::Recognition;
use crate::recognition::patterns::PatternMemory;

/// When a marker has to be identified, and when a learnt place is a marker.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct PatternEvalParams {
    /// The pink tile must show at least this many pixels...
    pub min_pink_pixels: usize,
    /// ... at least this fraction of it (not hidden, not cut)...
    pub min_visible_fraction: f64,
    /// ... the whole panel must be in the image, and seen at most this far from head-on,
    /// degrees.
    pub max_view_angle_deg: f64,
    /// A learnt place is the marker nearest it within this distance, centimetres.
    pub place_match_cm: f64,
}

impl Default for PatternEvalParams {
    fn default() -> Self {
        Self {
            min_pink_pixels: 9,
            min_visible_fraction: 0.8,
            max_view_angle_deg: 70.0,
            place_match_cm: 60.0,
        }
    }
}

/// How the pink markers of one frame went.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct PatternFrameEval {
    /// Frame index.
    pub frame: usize,
    /// Markers that had to be identified.
    pub eligible: usize,
    /// Of those, identified as their own place.
    pub correct: usize,
    /// Of those, identified as another place.
    pub wrong: usize,
    /// Of those, seen but not identified, or not seen.
    pub missed: usize,
    /// Pink things that are no marker identified as a marker's place.
    pub false_identifications: usize,
    /// Relative distance errors of correct identifications with a distance.
    pub distance_errors: Vec<f64>,
    /// The same in centimetres (signed, measured − true).
    pub distance_errors_cm: Vec<f64>,
}

/// The scene marker each learnt place stands for: `(place id, marker id)`.
#[must_use]
pub fn place_markers(
    memory: &PatternMemory,
    markers: &[MarkerTruth],
    p: &PatternEvalParams,
) -> Vec<(usize, Option<usize>)> {
    memory
        .objects
        .iter()
        .map(|o| {
            let nearest = markers
                .iter()
                .map(|m| {
                    let d = (m.relative.field_cm[0] - o.field_cm[0])
                        .hypot(m.relative.field_cm[1] - o.field_cm[1]);
                    (m.id, d)
                })
                .min_by(|a, b| a.1.total_cmp(&b.1))
                .filter(|(_, d)| *d <= p.place_match_cm)
                .map(|(id, _)| id);
            (o.id, nearest)
        })
        .collect()
}

/// Compares one frame's pink markers with the truth.
#[must_use]
pub fn evaluate_patterns(
    frame: usize,
    r: &Recognition,
    t: &RobotViewTruth,
    places: &[(usize, Option<usize>)],
    p: &PatternEvalParams,
) -> PatternFrameEval {
    let mut e = PatternFrameEval {
        frame,
        ..PatternFrameEval::default()
    };
    let marker_of = |place: usize| {
        places
            .iter()
            .find(|(id, _)| *id == place)
            .and_then(|(_, m)| *m)
    };
    let mut used = vec![false; r.patterns.len()];
    for m in &t.markers {
        let Some(b) = m.image_box else { continue };
        let eligible = m.pink_pixels >= p.min_pink_pixels
            && m.pink_visible_fraction >= p.min_visible_fraction
            && m.panel_in_image
            && m.view_angle_rad.to_degrees() <= p.max_view_angle_deg;
        // The candidate whose pink blob holds the marker's pink box centre.
        let (cx, cy) = ((b.min_x + b.max_x) / 2, (b.min_y + b.max_y) / 2);
        let found = r.patterns.iter().position(|c| {
            let [x0, y0, x1, y1] = c.observation.bounds.to_array();
            (x0..=x1).contains(&cx) && (y0..=y1).contains(&cy)
        });
        if let Some(k) = found {
            used[k] = true;
        }
        if !eligible {
            continue;
        }
        e.eligible += 1;
        match found.and_then(|k| r.patterns[k].identification) {
            Some(id) if marker_of(id.id) == Some(m.id) => {
                e.correct += 1;
                if let Some(d) = id.distance_cm {
                    let truth = m.relative.camera_distance_cm;
                    e.distance_errors.push((d - truth).abs() / truth);
                    e.distance_errors_cm.push(d - truth);
                }
            }
            Some(_) => e.wrong += 1,
            None => e.missed += 1,
        }
    }
    // A pink thing that is no marker identified as a marker's place. (Places that stand for
    // no marker, learnt from other pink things, are not scored.)
    e.false_identifications = r
        .patterns
        .iter()
        .zip(&used)
        .filter(|(c, used)| !**used && c.identification.is_some_and(|m| marker_of(m.id).is_some()))
        .count();
    e
}

/// The sum over frames.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct PatternEvalReport {
    /// Frames compared.
    pub frames: usize,
    /// Markers that had to be identified.
    pub eligible: usize,
    /// Identified as their own place.
    pub correct: usize,
    /// Identified as another place.
    pub wrong: usize,
    /// Not identified.
    pub missed: usize,
    /// Pink things that are no marker identified as a marker's place.
    pub false_identifications: usize,
    /// Correct / eligible.
    pub correct_rate: Option<f64>,
    /// Relative distance errors of correct identifications.
    pub distance_error: Option<Percentiles>,
    /// Median signed distance error, centimetres.
    pub distance_bias_cm: Option<f64>,
    /// Learnt places and the marker each stands for (`None`: no marker near it).
    pub places: Vec<(usize, Option<usize>)>,
    /// Frames with a wrong identification.
    pub wrong_frames: Vec<usize>,
}

impl PatternEvalReport {
    /// Sums frame evaluations.
    #[must_use]
    pub fn from_frames(frames: &[PatternFrameEval], places: Vec<(usize, Option<usize>)>) -> Self {
        let mut r = Self {
            frames: frames.len(),
            places,
            ..Self::default()
        };
        let (mut rel, mut cm) = (Vec::new(), Vec::new());
        for f in frames {
            r.eligible += f.eligible;
            r.correct += f.correct;
            r.wrong += f.wrong;
            r.missed += f.missed;
            r.false_identifications += f.false_identifications;
            if f.wrong > 0 {
                r.wrong_frames.push(f.frame);
            }
            rel.extend(&f.distance_errors);
            cm.extend(&f.distance_errors_cm);
        }
        r.correct_rate = (r.eligible > 0).then(|| r.correct as f64 / r.eligible as f64);
        r.distance_error = Percentiles::of(&rel);
        r.distance_bias_cm = Percentiles::median_of(&cm);
        r
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frames_sum_into_rates_and_percentiles() {
        let frames = vec![
            PatternFrameEval {
                frame: 0,
                eligible: 2,
                correct: 2,
                distance_errors: vec![0.02, 0.04],
                distance_errors_cm: vec![-3.0, 5.0],
                ..PatternFrameEval::default()
            },
            PatternFrameEval {
                frame: 1,
                eligible: 2,
                correct: 1,
                wrong: 1,
                distance_errors: vec![0.06],
                distance_errors_cm: vec![9.0],
                ..PatternFrameEval::default()
            },
        ];
        let r = PatternEvalReport::from_frames(&frames, vec![(0, Some(1))]);
        assert_eq!((r.eligible, r.correct, r.wrong, r.missed), (4, 3, 1, 0));
        assert_eq!(r.correct_rate, Some(0.75));
        assert_eq!(r.distance_error.map(|p| (p.n, p.p50)), Some((3, 0.04)));
        assert_eq!(r.distance_bias_cm, Some(5.0));
        assert_eq!(r.wrong_frames, vec![1]);
    }
}
