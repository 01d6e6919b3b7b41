//! The confidence system: every candidate object starts at zero, each named test adds or
//! subtracts an amount depending on a measured value, and the candidate is accepted when the
//! total is positive. The whole breakdown is kept, accepted or not, so the app and the JSON can
//! show *why* an object was or was not recognised.

use serde::{Deserialize, Serialize};

/// What one test concluded.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum TestOutcome {
    /// The measured value was in the expected range.
    Passed,
    /// The measured value was outside the expected range.
    Failed,
    /// The test could not be applied (for example the scan area lay outside the image).
    Skipped,
}

/// The name of one confidence test: which measurement a [`TestResult`] is about. Serialised in
/// snake case (`"pixel_ratio"`), as the JSON and the inspector show it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum TestName {
    /// Ball: share of basic orange among the candidate's pixels.
    OrangeFraction,
    /// Ball: share of ball colours inside the fitted circle where the image shows it.
    CircleFill,
    /// Ball: share of unclassified pixels on the ring just outside the box.
    UnclassifiedAround,
    /// Ball cut on one axis: its extent along the cut axis over the other.
    CutExtent,
    /// Ball: the circle fit's residual spread, pixels (a penalty only).
    CircleResidualPx,
    /// Ball: outline points the circle fit used (a bonus only).
    CircleFitPoints,
    /// Ball: enough outline points, but no circle through them (a straight edge).
    CircleFit,
    /// Ball: pixels over box area.
    PixelRatio,
    /// Ball: box width over height.
    Roundness,
    /// Ball: centre height above the ground through the camera pose, centimetres.
    HeightCm,
    /// Ball and goals: share of green below (a bonus only for the ball).
    GreenBelow,
    /// Ball without a camera pose: share of field colours (green, white) right at its foot.
    FieldBelow,
    /// Ball without a camera pose: share of field colours (green, white) in the strip beneath it,
    /// down several radii (applied only when its weight has a penalty).
    FieldBeneath,
    /// Goal: pixels of the basic goal colour.
    Pixels,
    /// Goal: real width from the box width at its distance, centimetres.
    ApparentWidthCm,
    /// Goal: height of its foot above the ground, centimetres.
    BottomHeightCm,
    /// Goal: elevation of its centre, radians.
    ElevationRad,
    /// Goal: size-based over foot-based distance.
    DistanceAgreement,
    /// Goal: green or white right at its foot.
    GroundAtFoot,
    /// Goal: sides cut off by the image edge.
    CutSides,
    /// Goal: share of its box a recognised beacon covers.
    BeaconOverlap,
    /// Goal cut off at the top: share of green (white not counted) below its foot.
    GreenBelowCut,
    /// Goal: upright posts found on the sides in view.
    UprightPosts,
    /// Beacon: pink band width over the other band's.
    WidthRatio,
    /// Beacon: horizontal offset of the bands over their width.
    Alignment,
    /// Beacon: gap between the two bands, pixels.
    Gap,
    /// Beacon: height over width of both bands (of the one band, when it stands on its base).
    Aspect,
    /// Beacon seen as one band on its base: share of white right below the band.
    WhiteBase,
    /// Beacon seen as one band on its base: share of white beside the base.
    BaseFlanks,
    /// Coloured pattern: regions with a colour, of nine.
    ColouredRegions,
    /// Coloured pattern: regions agreeing with the closest place, of nine.
    Agreement,
    /// Coloured pattern: agreement over the next closest place's.
    Margin,
}

impl TestName {
    /// The name as the JSON spells it.
    #[must_use]
    pub const fn as_str(self) -> &'static str {
        match self {
            Self::OrangeFraction => "orange_fraction",
            Self::CircleFill => "circle_fill",
            Self::UnclassifiedAround => "unclassified_around",
            Self::CutExtent => "cut_extent",
            Self::CircleResidualPx => "circle_residual_px",
            Self::CircleFitPoints => "circle_fit_points",
            Self::CircleFit => "circle_fit",
            Self::PixelRatio => "pixel_ratio",
            Self::Roundness => "roundness",
            Self::HeightCm => "height_cm",
            Self::GreenBelow => "green_below",
            Self::FieldBelow => "field_below",
            Self::FieldBeneath => "field_beneath",
            Self::Pixels => "pixels",
            Self::ApparentWidthCm => "apparent_width_cm",
            Self::BottomHeightCm => "bottom_height_cm",
            Self::ElevationRad => "elevation_rad",
            Self::DistanceAgreement => "distance_agreement",
            Self::GroundAtFoot => "ground_at_foot",
            Self::CutSides => "cut_sides",
            Self::BeaconOverlap => "beacon_overlap",
            Self::GreenBelowCut => "green_below_cut",
            Self::UprightPosts => "upright_posts",
            Self::WidthRatio => "width_ratio",
            Self::Alignment => "alignment",
            Self::Gap => "gap",
            Self::Aspect => "aspect",
            Self::WhiteBase => "white_base",
            Self::BaseFlanks => "base_flanks",
            Self::ColouredRegions => "coloured_regions",
            Self::Agreement => "agreement",
            Self::Margin => "margin",
        }
    }
}

impl std::fmt::Display for TestName {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

/// One line of a confidence breakdown.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TestResult {
    /// Which test.
    pub test: TestName,
    /// The measured value (units depend on the test; see its `range`).
    pub value: f64,
    /// The accepted range `[min, max]` of the measured value.
    pub range: [f64; 2],
    /// Passed, failed or skipped.
    pub outcome: TestOutcome,
    /// The amount added to the confidence (negative when it counts against).
    pub effect: f64,
}

/// The running confidence of one candidate with its breakdown.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct Confidence {
    /// Sum of all effects.
    pub total: f64,
    /// Every test applied, in order.
    pub tests: Vec<TestResult>,
}

/// How much a test adds when it passes and subtracts when it fails.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct TestWeight {
    /// Added when the value is inside the range.
    pub reward: f64,
    /// Subtracted when the value is outside the range (give a positive number).
    pub penalty: f64,
}

impl TestWeight {
    /// A test that adds `reward` on success and subtracts `penalty` on failure.
    #[must_use]
    pub const fn new(reward: f64, penalty: f64) -> Self {
        Self { reward, penalty }
    }
}

impl Confidence {
    /// Applies a range test: `value` within `range` (inclusive) rewards, otherwise penalises. A
    /// non-finite value counts as a failure, so NaN can never make a candidate look better.
    pub fn range_test(&mut self, test: TestName, value: f64, range: [f64; 2], weight: TestWeight) {
        let inside = value.is_finite() && value >= range[0] && value <= range[1];
        let (outcome, effect) = if inside {
            (TestOutcome::Passed, weight.reward)
        } else {
            (TestOutcome::Failed, -weight.penalty)
        };
        self.push(test, value, range, outcome, effect);
    }

    /// Records a test that could not be applied; it changes nothing but stays visible.
    pub fn skipped(&mut self, test: TestName, range: [f64; 2]) {
        self.push(test, f64::NAN, range, TestOutcome::Skipped, 0.0);
    }

    /// A test that can only help: rewards inside the range, records a zero effect otherwise.
    pub fn bonus_test(&mut self, test: TestName, value: f64, range: [f64; 2], reward: f64) {
        self.range_test(test, value, range, TestWeight::new(reward, 0.0));
    }

    fn push(
        &mut self,
        test: TestName,
        value: f64,
        range: [f64; 2],
        outcome: TestOutcome,
        effect: f64,
    ) {
        self.total += effect;
        self.tests.push(TestResult {
            test,
            value,
            range,
            outcome,
            effect,
        });
    }

    /// The original's rule: accepted when the total is positive.
    #[must_use]
    pub fn accepted(&self) -> bool {
        self.total > 0.0
    }

    /// The result of the named test, if it was applied.
    #[must_use]
    pub fn test(&self, name: TestName) -> Option<&TestResult> {
        self.tests.iter().find(|t| t.test == name)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn breakdown_sums_effects_and_keeps_every_test() {
        let mut c = Confidence::default();
        c.range_test(
            TestName::PixelRatio,
            0.7,
            [0.5, 1.0],
            TestWeight::new(2.0, 3.0),
        );
        c.range_test(
            TestName::HeightCm,
            40.0,
            [-5.0, 15.0],
            TestWeight::new(1.0, 4.0),
        );
        c.skipped(TestName::GreenBelow, [0.3, 1.0]);
        assert_eq!(c.tests.len(), 3);
        assert!((c.total - (2.0 - 4.0)).abs() < 1e-12);
        assert!(!c.accepted());
        assert_eq!(
            c.test(TestName::HeightCm).map(|t| t.outcome),
            Some(TestOutcome::Failed)
        );
        assert_eq!(c.test(TestName::GreenBelow).map(|t| t.effect), Some(0.0));
    }

    #[test]
    fn nan_fails_and_bonus_never_penalises() {
        let mut c = Confidence::default();
        c.bonus_test(TestName::GreenBelow, 0.1, [0.3, 1.0], 1.5);
        assert_eq!(c.total, 0.0);
        c.range_test(
            TestName::PixelRatio,
            f64::NAN,
            [0.0, 1.0],
            TestWeight::new(1.0, 1.0),
        );
        assert_eq!(c.total, -1.0);
        c.bonus_test(TestName::GreenBelow, 0.5, [0.3, 1.0], 1.5);
        assert!(c.accepted());
    }
}
