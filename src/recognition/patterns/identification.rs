//! Identification, per frame: a signature against the memory's places; the best place with
//! enough agreeing regions, refused when another agrees as well.

use super::{
    Closest, PatternCandidate, PatternMatch, PatternMemory, PatternObservation, PatternParams,
    Signature,
};
use crate::recognition::confidence::{Confidence, TestName};
use crate::recognition::context::ViewContext;

impl PatternMemory {
    /// The best-agreeing object and the best other one: by agreement, then by regions sharing
    /// both colours.
    pub(super) fn ranked(&self, sig: &Signature) -> (Option<Closest>, Option<Closest>) {
        let mut scores: Vec<Closest> = self
            .objects
            .iter()
            .filter_map(|o| {
                o.patterns
                    .iter()
                    .map(|p| Closest {
                        id: o.id,
                        agreement: p.agreement(sig),
                        both_colours: p.both_colours_agreement(sig),
                    })
                    .max_by_key(|c| (c.agreement, c.both_colours))
            })
            .collect();
        scores.sort_by_key(|c| std::cmp::Reverse((c.agreement, c.both_colours)));
        (scores.first().copied(), scores.get(1).copied())
    }

    /// Identification phase: the best stored object with at least
    /// [`PatternParams::min_agreement`] agreeing regions, unless another object agrees as well
    /// (same agreement and same both-colour score) or the observation shows too few coloured
    /// regions to be a place.
    #[must_use]
    pub fn identify(
        &self,
        obs: &PatternObservation,
        params: &PatternParams,
    ) -> Option<PatternMatch> {
        let (best, next) = self.ranked(&obs.signature);
        self.identify_ranked(obs, best, next, params)
    }

    pub(super) fn identify_ranked(
        &self,
        obs: &PatternObservation,
        best: Option<Closest>,
        next: Option<Closest>,
        params: &PatternParams,
    ) -> Option<PatternMatch> {
        let best = best?;
        let tied = next
            .is_some_and(|n| (n.agreement, n.both_colours) == (best.agreement, best.both_colours));
        (best.agreement >= params.min_agreement
            && !tied
            && obs.signature.coloured_regions() >= params.min_coloured_regions)
            .then(|| PatternMatch {
                id: best.id,
                agreement: best.agreement,
                both_colours: best.both_colours,
                distance_cm: self.relation.and_then(|r| r.distance_cm(obs.size_px)),
            })
    }

    /// An observation as a candidate: identified against this memory (or not, with `None`),
    /// with its confidence breakdown and placement.
    #[must_use]
    pub fn candidate(
        memory: Option<&Self>,
        obs: PatternObservation,
        ctx: &ViewContext,
        params: &PatternParams,
    ) -> PatternCandidate {
        let cut_off = obs.regions_in_image < 9;
        let mut c = PatternCandidate {
            observation: obs,
            identification: None,
            closest: None,
            runner_up: None,
            camera: None,
            body: None,
            cut_off,
            ambiguous: false,
            confidence: Confidence::default(),
            accepted: false,
        };
        let Some(memory) = memory else {
            return c;
        };
        let (best, next) = memory.ranked(&obs.signature);
        c.closest = best;
        c.runner_up = next;
        let conf = &mut c.confidence;
        let coloured = obs.signature.coloured_regions();
        conf.range_test(
            TestName::ColouredRegions,
            coloured as f64,
            [params.min_coloured_regions as f64, 9.0],
            params.coloured_weight,
        );
        let agreement = best.map_or(0, |b| b.agreement);
        conf.range_test(
            TestName::Agreement,
            agreement as f64,
            [params.min_agreement as f64, 9.0],
            params.agreement_weight,
        );
        match (best, next) {
            (Some(b), Some(n)) => {
                // Regions apart, with the both-colour score as the fraction that breaks ties.
                let margin = (b.agreement - n.agreement) as f64
                    + 0.1 * (b.both_colours as f64 - n.both_colours as f64);
                c.ambiguous = margin <= 0.0;
                conf.range_test(TestName::Margin, margin, [0.1, 9.0], params.margin_weight);
            }
            _ => conf.skipped(TestName::Margin, [0.1, 9.0]),
        }
        c.identification = memory.identify_ranked(&obs, best, next, params);
        c.accepted = c.identification.is_some() && c.confidence.accepted();
        if !c.accepted {
            c.identification = None;
        }
        if let Some(d) = c.identification.and_then(|m| m.distance_cm) {
            let centre = ctx.unskew_at(obs.centre(), d, true);
            c.camera = Some(ctx.camera_relative(centre, d));
            c.body = ctx.body_relative(centre, d);
        }
        c
    }
}
