//! Object recognition on a classified frame and its blobs: the ball, goals with posts and the
//! open gap, beacons, coloured patterns and the horizon. Every candidate carries a
//! [`confidence::Confidence`] breakdown, and every scan is kept as drawing data, so the app and
//! the JSON show why an object was or was not recognised.

pub mod ball;
pub mod confidence;
pub mod context;
pub mod draw;
pub mod fit;
pub mod goals;
pub mod scan;
