//! The overhead recogniser's tunable settings, as the `overhead` section of a recognition
//! parameters file: what the field's markers and ball look like from above (their sizes, how
//! round and full a blob must be, how well the identity dots must match the layout). The
//! defaults are eotn's own printed marker (`geometry::marker`); a field whose markers differ
//! (the real SSL 2008 frame: team dots of 50 mm) is set up here without code.
//!
//! The ball's radius and the plates' height belong to the field description, not here.

use serde::{Deserialize, Serialize};

use crate::geometry::marker::{ID_DOT_DIAMETER_CM, ID_DOT_RADIUS_CM, TEAM_DOT_DIAMETER_CM};

/// The overhead recogniser's settings that a parameters file can change.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct OverheadRecognitionParams {
    /// Smallest and largest blob area accepted, as a share of the area a ball or team dot is
    /// expected to cover at its place in the image (the calibration gives that area):
    /// `[low, high]`, no unit.
    pub area_ratio: [f64; 2],
    /// Smallest share (0 to 1) of the samples on the ring through the identity dots that must
    /// agree with the marker layout at the best heading for a robot to be reported.
    pub min_layout_agreement: f64,
    /// Smallest share (0 to 1) of its bounding box an orange blob must fill to be the ball: a
    /// ball's shaded side often classifies in speckles, leaving holes.
    pub ball_min_fill: f64,
    /// Smallest share (0 to 1) of its bounding box a team dot's blob must fill (a disc fills
    /// π/4 of its box).
    pub team_dot_min_fill: f64,
    /// Diameter of the team dot at the plate's centre, centimetres.
    pub team_dot_diameter_cm: f64,
    /// Diameter of each of the four identity dots, centimetres.
    pub id_dot_diameter_cm: f64,
    /// Distance of the identity dots' centres from the plate's centre, centimetres.
    pub id_dot_ring_radius_cm: f64,
}

impl Default for OverheadRecognitionParams {
    fn default() -> Self {
        Self {
            area_ratio: [0.35, 1.8],
            min_layout_agreement: 0.75,
            ball_min_fill: 0.3,
            team_dot_min_fill: 0.5,
            team_dot_diameter_cm: TEAM_DOT_DIAMETER_CM,
            id_dot_diameter_cm: ID_DOT_DIAMETER_CM,
            id_dot_ring_radius_cm: ID_DOT_RADIUS_CM,
        }
    }
}
