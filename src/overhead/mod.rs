//! The World Model Debugger's overhead side: an overhead camera over the whole field says where
//! the ball and every robot really are.
//!
//! - [`field`]: field descriptions (landmarks by name, painted lines, heights).
//! - [`points`]: calibration points files (`*.points.json`, `FORMATS.md`).
//! - [`calibration`]: camera pose, focal length, principal point and radial distortion by
//!   Levenberg–Marquardt from clicked points, refined along the lines ([`lines`]); saved as a
//!   file; [`review`]: whether a calibration can be trusted (refusals, doubts, notes).
//! - [`recognise`]: ball and robot markers in a classified image → field coordinates;
//!   [`pipeline`] runs classification, blobs and it on a frame.
//! - [`merge`]: several cameras' detections of one instant → one field picture (robots by
//!   identity, the ball by confidence), and which frames form one field frame.
//! - [`coverage`]: each camera's view of the field as a polygon (from its calibration and
//!   frame size), and which cameras see a field point.
//! - [`undistort`]: the undistorted view; [`drawing`]: the printable marker (SVG).
//!
//! The marker's layout itself is a geometry type (`geometry::marker`) because the simulator
//! paints it too.

pub mod calibration;
pub mod coverage;
pub mod drawing;
pub mod field;
pub mod intrinsics;
pub mod lines;
pub mod merge;
pub mod pipeline;
pub mod points;
pub mod recognise;
pub mod review;
pub mod undistort;

pub use calibration::{Calibration, CalibrationError, CalibrationParams, calibrate};
pub use field::FieldDescription;
pub use pipeline::OverheadPipeline;
pub use points::{CalibrationPoint, PointsFile};
pub use recognise::{OverheadDetections, OverheadParams, recognise_overhead};
