//! The overhead camera's side of the workspace: frames of an overhead source go through the
//! [`OverheadPipeline`] (classification, blobs, ball and robot markers in field coordinates)
//! instead of the robot-camera [`crate::pipeline::Pipeline`], with the calibration in use; the
//! calibration tools (open, save, pick landmarks, solve) and the one robot selection.
//!
//! The calibration in use is, in this order: one the user opened or solved in the app (a user's
//! choice beats a default; Overhead ▸ Close calibration goes back), the stream's own camera (a
//! synthetic stream's `/ground_truth` carries the camera that made it), or none — then the
//! frame is classified and its blobs found, but nothing is placed on the field, and the status
//! line says so.

use std::path::{Path, PathBuf};

use anyhow::Context as _;

use super::Workspace;
use super::command::OverheadCommand;
use super::field_model::FieldModel;
use crate::geometry::{ImagePoint, OverheadCamera};
use crate::overhead::calibration::Calibration;
use crate::overhead::intrinsics::Intrinsics;
use crate::overhead::{
    CalibrationPoint, FieldDescription, OverheadDetections, OverheadParams, OverheadPipeline,
    PointsFile,
};
use crate::recognition::Recognition;
use crate::sources::SourceFrame;

/// Fewest picked points the solver is asked to work with (pose, focal, centre, k1, k2).
pub const MIN_CALIBRATION_POINTS: usize = crate::overhead::review::MIN_POINTS;

/// One robot as the overhead camera identifies it: team colour and marker identity. The one
/// robot selection of the workspace (field view, image overlays) is one of these.
pub use crate::model::world_model::RobotKey;

pub mod field_cameras;
mod picking;

pub use field_cameras::{CameraShown, FieldCameras, FrameState};

/// The undistorted view's pixel map and the camera and frame size it was made for.
#[derive(Debug, Clone)]
struct ViewMap {
    camera: OverheadCamera,
    size: (usize, usize),
    /// Per view pixel, the camera pixel it shows (`undistort::source_pixel_map`).
    map: Vec<Option<u32>>,
}

/// Where the camera in use comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CalibrationSource {
    /// Opened from a file or solved in the app.
    User,
    /// The stream's own camera (a synthetic stream's truth).
    Stream,
}

/// One picked point's change, for undo: the point's name and what it replaced.
#[derive(Debug, Clone, PartialEq)]
struct PickEdit {
    name: String,
    replaced: Option<CalibrationPoint>,
}

/// The overhead state; see the module documentation.
#[derive(Debug)]
pub struct Overhead {
    pipeline: OverheadPipeline,
    /// The shown frame went through the overhead pipeline.
    active: bool,
    detections: Option<OverheadDetections>,
    user_calibration: Option<Calibration>,
    calibration_path: Option<PathBuf>,
    stream_camera: Option<OverheadCamera>,
    /// The shown frame's own ground truth (a synthetic stream's `/ground_truth`), if any.
    truth: Option<crate::model::truth::OverheadTruth>,
    field: FieldDescription,
    field_path: Option<PathBuf>,
    /// The lens's checkerboard intrinsics and their file: Calibrate then fits only the pose.
    intrinsics: Option<(Intrinsics, PathBuf)>,
    points: PointsFile,
    points_path: Option<PathBuf>,
    picks: Vec<PickEdit>,
    landmark: Option<String>,
    selected: Option<RobotKey>,
    synced_table: Option<u64>,
    /// The undistorted view's pixel map, when that view is shown.
    view_map: Option<ViewMap>,
    /// The field's lines projected through the camera in use (image polylines), the camera
    /// and the field generation they were made for: made once per calibration, not once per
    /// UI frame (at 2 cm steps through the lens model they cost milliseconds).
    projected_lines: Option<(OverheadCamera, u64, Vec<Vec<ImagePoint>>)>,
    /// Counts field changes (the projected lines follow them).
    field_generation: u64,
    empty_recognition: Recognition,
    /// The field view's model: trails, world models, errors over time.
    pub field_model: FieldModel,
    /// The field's cameras: coverage, a session's other cameras, the merged picture.
    cameras: FieldCameras,
    /// The calibration's and the frame's size last warned about (the warning is said once a
    /// pair, not once a frame).
    size_warned: Option<((usize, usize), (usize, usize))>,
    /// The SSL-Vision output, while sending (`workspace/ssl_out.rs`).
    pub(super) ssl_out: Option<super::ssl_out::SslOutState>,
    /// The session's robot cameras and the WMD layout requests (`workspace/wmd.rs`).
    pub(super) wmd: super::wmd::WmdState,
}

impl Default for Overhead {
    fn default() -> Self {
        let field = FieldDescription::four_legged_2005();
        Self {
            pipeline: OverheadPipeline::new(
                crate::lut::LookupTable::new(6).unwrap_or_else(|_| super::seven_bit_table()),
                OverheadCamera::above_field_2005(),
                params_for(
                    &field,
                    &crate::recognition::OverheadRecognitionParams::default(),
                ),
            ),
            active: false,
            detections: None,
            user_calibration: None,
            calibration_path: None,
            stream_camera: None,
            truth: None,
            field,
            field_path: None,
            intrinsics: None,
            points: PointsFile::new(0, 0),
            points_path: None,
            picks: Vec::new(),
            landmark: None,
            selected: None,
            synced_table: None,
            view_map: None,
            projected_lines: None,
            field_generation: 0,
            empty_recognition: Recognition::default(),
            field_model: FieldModel::default(),
            cameras: FieldCameras::default(),
            size_warned: None,
            ssl_out: None,
            wmd: super::wmd::WmdState::default(),
        }
    }
}

/// The recogniser's settings: the field's ball radius and plate height, the rest from the
/// recognition parameters' `overhead` section.
fn params_for(
    field: &FieldDescription,
    recogniser: &crate::recognition::OverheadRecognitionParams,
) -> OverheadParams {
    OverheadParams {
        ball_radius_cm: field.ball_radius_cm,
        plate_height_cm: field.plate_height_cm,
        recogniser: *recogniser,
    }
}

impl Overhead {
    /// True when the shown frame went through the overhead pipeline.
    #[must_use]
    pub const fn active(&self) -> bool {
        self.active
    }

    /// The shown frame's ball and robots in field coordinates; `None` for a robot-camera frame
    /// or when no calibration is set.
    #[must_use]
    pub const fn detections(&self) -> Option<&OverheadDetections> {
        self.detections.as_ref()
    }

    /// The camera in use and where it comes from.
    #[must_use]
    pub fn camera(&self) -> Option<(&OverheadCamera, CalibrationSource)> {
        self.user_calibration
            .as_ref()
            .map(|c| (&c.camera, CalibrationSource::User))
            .or_else(|| {
                self.stream_camera
                    .as_ref()
                    .map(|c| (c, CalibrationSource::Stream))
            })
    }

    /// The calibration opened or solved in the app (with each point's reprojection error).
    #[must_use]
    pub const fn calibration(&self) -> Option<&Calibration> {
        self.user_calibration.as_ref()
    }

    /// The calibration's file, if it was opened or saved.
    #[must_use]
    pub fn calibration_path(&self) -> Option<&Path> {
        self.calibration_path.as_deref()
    }

    /// The shown frame's ground truth, where the stream carries it (a synthetic stream):
    /// the field view draws it beside what the camera found.
    #[must_use]
    pub const fn truth(&self) -> Option<&crate::model::truth::OverheadTruth> {
        self.truth.as_ref()
    }

    /// The intrinsics Calibrate uses (then only the pose is fitted) and their file.
    #[must_use]
    pub fn intrinsics(&self) -> Option<(&Intrinsics, &Path)> {
        self.intrinsics.as_ref().map(|(i, p)| (i, p.as_path()))
    }

    /// The field description (landmarks by name, lines).
    #[must_use]
    pub const fn field(&self) -> &FieldDescription {
        &self.field
    }

    /// The field's lines and arcs as image polylines through the camera in use (its own
    /// pixels, at the calibration's size; `overhead::lines::projected_field_lines`); empty
    /// with no camera.
    #[must_use]
    pub fn projected_field_lines(&self) -> &[Vec<ImagePoint>] {
        self.projected_lines
            .as_ref()
            .map_or(&[], |(_, _, lines)| lines.as_slice())
    }

    /// Makes the projected field lines for `camera`, unless they were made for it already.
    fn refresh_projected_lines(&mut self, camera: Option<OverheadCamera>) {
        let fresh = match (&self.projected_lines, camera) {
            (Some((c, g, _)), Some(cam)) => *c == cam && *g == self.field_generation,
            (None, None) => true,
            _ => false,
        };
        if !fresh {
            self.projected_lines = camera.map(|c| {
                let lines = crate::overhead::lines::projected_field_lines(&self.field, &c);
                (c, self.field_generation, lines)
            });
        }
    }

    /// The picked points.
    #[must_use]
    pub const fn points(&self) -> &PointsFile {
        &self.points
    }

    /// The points file, if it was opened or saved.
    #[must_use]
    pub fn points_path(&self) -> Option<&Path> {
        self.points_path.as_deref()
    }

    /// The landmark the next click in the image picks, if one is chosen.
    #[must_use]
    pub fn landmark(&self) -> Option<&str> {
        self.landmark.as_deref()
    }

    /// How many picks can be undone.
    #[must_use]
    pub fn picks_to_undo(&self) -> usize {
        self.picks.len()
    }

    /// The field's cameras: each one's coverage and frame, the merged field picture.
    #[must_use]
    pub const fn field_cameras(&self) -> &FieldCameras {
        &self.cameras
    }

    /// The selected robot (field view, overlays).
    #[must_use]
    pub const fn selected(&self) -> Option<RobotKey> {
        self.selected
    }

    /// The stage timings of the last overhead frame.
    #[must_use]
    pub fn timings(&self) -> crate::overhead::pipeline::OverheadTimings {
        self.pipeline.timings()
    }

    /// One line on the calibration in use, for the status line.
    #[must_use]
    pub fn calibration_status(&self) -> String {
        match self.camera() {
            None => "overhead: no calibration set (Overhead > Open calibration…, or pick points and Calibrate): nothing is placed on the field".to_owned(),
            Some((_, CalibrationSource::Stream)) => "overhead: the stream's own camera".to_owned(),
            Some((_, CalibrationSource::User)) => {
                let name = self
                    .calibration_path
                    .as_deref()
                    .map_or_else(|| "solved in the app".to_owned(), crate::frame::display_name);
                let median = self
                    .user_calibration
                    .as_ref()
                    .map_or(f64::NAN, Calibration::median_point_error_px);
                format!("overhead: calibration {name} (median point error {median:.2} px)")
            }
        }
    }
}

impl Workspace {
    /// The overhead camera's state: detections, calibration, picked points, selection.
    #[must_use]
    pub const fn overhead(&self) -> &Overhead {
        &self.overhead
    }

    /// The shown frame's overhead detections (ball and robots in field coordinates), when it
    /// is an overhead frame with a calibration in use.
    #[must_use]
    pub const fn overhead_detections(&self) -> Option<&OverheadDetections> {
        self.overhead.detections()
    }

    /// Recognition results for the views: the robot pipeline's, or none for an overhead frame.
    pub(super) fn shown_recognition(&self) -> &Recognition {
        if self.overhead.active {
            &self.overhead.empty_recognition
        } else {
            self.pipeline.result().recognition
        }
    }

    /// Classified image of the shown frame, from whichever pipeline ran.
    pub(super) fn shown_classified(&self) -> &crate::classify::ClassifiedImage {
        if self.overhead.active {
            self.overhead.pipeline.classified()
        } else {
            self.pipeline.result().classified
        }
    }

    /// Blobs of the shown frame, from whichever pipeline ran.
    pub(super) fn shown_blobs(&self) -> &crate::blobs::BlobSet {
        if self.overhead.active {
            self.overhead.pipeline.blobs()
        } else {
            self.pipeline.result().blobs
        }
    }

    /// Whether `camera` (the calibration in use) can place objects on `frame`: a frame of
    /// another size with the same shape is scaled to (with a warning), one of another shape
    /// is not (with a warning: the calibration was made for another camera or view). Each
    /// pair of sizes is warned about once.
    fn frame_fits(&mut self, camera: &OverheadCamera, frame: &crate::frame::Frame) -> bool {
        use crate::overhead::pipeline::{FrameFit, frame_fit};
        let fit = frame_fit(camera, frame.width(), frame.height());
        let key = (
            (camera.width_px, camera.height_px),
            (frame.width(), frame.height()),
        );
        if fit != FrameFit::Same && self.overhead.size_warned != Some(key) {
            self.overhead.size_warned = Some(key);
            let what = match fit {
                FrameFit::Mismatch { .. } => format!("{fit}; nothing is placed on these frames"),
                _ => fit.to_string(),
            };
            self.warn(format!("overhead calibration: {what}"));
        }
        !matches!(fit, FrameFit::Mismatch { .. })
    }

    /// Runs the overhead pipeline on an overhead frame with the table in use and the
    /// calibration in use; returns the stage timings in the robot pipeline's shape.
    pub(super) fn run_overhead(&mut self, loaded: &SourceFrame) -> crate::pipeline::StageTimings {
        if self.overhead.synced_table != Some(self.table_generation) {
            self.overhead.pipeline.set_lut(self.pipeline.lut().clone());
            self.overhead.synced_table = Some(self.table_generation);
        }
        self.overhead.truth = truth_of(loaded);
        self.overhead.stream_camera = self.overhead.truth.as_ref().map(|t| t.camera);
        let camera = self.overhead.camera().map(|(c, _)| *c);
        if let Some(c) = camera {
            self.overhead.pipeline.set_camera(c);
        }
        self.overhead.refresh_projected_lines(camera);
        let fits = camera.is_none_or(|c| self.frame_fits(&c, &loaded.frame));
        // The parameters in use (tuned in the Parameters window, or a file's `overhead`).
        let params = params_for(&self.overhead.field, &self.recognition_params().overhead);
        if *self.overhead.pipeline.params() != params {
            self.overhead.pipeline.set_params(params);
        }
        self.overhead.pipeline.process(&loaded.frame);
        self.overhead.active = true;
        if (self.overhead.points.width, self.overhead.points.height) == (0, 0) {
            self.overhead.points = PointsFile::new(loaded.frame.width(), loaded.frame.height());
        }
        self.overhead.detections = camera
            .filter(|_| fits)
            .map(|_| self.overhead.pipeline.detections().clone());
        self.refresh_view_map((loaded.frame.width(), loaded.frame.height()));
        self.primitives.clear();
        self.accepted_owners.clear();
        self.selected_object = None;
        self.frame_counts = self.overhead.pipeline.classified().histogram();
        let index = self.index_of_frame(loaded);
        let size = (loaded.frame.width(), loaded.frame.height());
        self.sync_field_cameras(index, loaded.time_ns, size);
        self.overhead.field_model.set_field(&self.overhead.field);
        let extra = self.with_session_world_models(loaded);
        self.overhead.field_model.observe(
            index,
            loaded.time_ns,
            self.overhead.cameras.picture(),
            &extra,
        );
        self.send_ssl_out(loaded.time_ns);
        let t = self.overhead.pipeline.timings();
        crate::pipeline::StageTimings {
            classify: t.classify,
            blobs: t.blobs,
            recognition: t.recognition,
        }
    }

    /// The index a frame is shown at (live frames count on; recorded ones by their index).
    fn index_of_frame(&self, loaded: &SourceFrame) -> usize {
        self.source
            .as_ref()
            .map_or(self.index, |s| s.index_at_time(loaded.time_ns))
    }

    /// Applies an overhead command.
    pub(super) fn apply_overhead(&mut self, command: OverheadCommand) -> anyhow::Result<()> {
        match command {
            OverheadCommand::OpenCalibration(p) => self.open_calibration(p)?,
            OverheadCommand::SaveCalibration(p) => self.save_calibration(p)?,
            OverheadCommand::CloseCalibration => {
                self.overhead.user_calibration = None;
                self.overhead.calibration_path = None;
                self.reprocess();
                self.status = self.overhead.calibration_status();
            }
            OverheadCommand::OpenIntrinsics(p) => self.open_intrinsics(Some(p))?,
            OverheadCommand::CloseIntrinsics => self.open_intrinsics(None)?,
            OverheadCommand::OpenField(p) => {
                let field = FieldDescription::resolve(&p.to_string_lossy())?;
                self.overhead.pipeline = OverheadPipeline::new(
                    self.pipeline.lut().clone(),
                    *self.overhead.pipeline.camera(),
                    params_for(&field, &self.recognition_params().overhead),
                );
                self.overhead.synced_table = Some(self.table_generation);
                self.status = format!(
                    "field {}: {} landmarks, {} lines",
                    field.name,
                    field.landmarks.len(),
                    field.lines.len()
                );
                self.overhead.field = field;
                self.overhead.field_generation += 1;
                self.overhead.field_path = Some(p);
                self.overhead.landmark = None;
                self.reprocess();
            }
            OverheadCommand::OpenPoints(p) => {
                let (points, warnings) = PointsFile::load_with_warnings(&p)?;
                for w in warnings {
                    self.warn(w);
                }
                self.status = format!("opened {} points from {}", points.points.len(), p.display());
                self.overhead.points = points;
                self.overhead.points_path = Some(p);
                self.overhead.picks.clear();
            }
            OverheadCommand::SavePoints(p) => {
                anyhow::ensure!(
                    !self.overhead.points.points.is_empty(),
                    "no points picked yet: choose a landmark and click it in the image"
                );
                self.overhead.points.save(&p)?;
                self.status = format!(
                    "saved {} points as {}",
                    self.overhead.points.points.len(),
                    p.display()
                );
                self.overhead.points_path = Some(p);
            }
            OverheadCommand::ChooseLandmark(name) => self.choose_landmark(name)?,
            OverheadCommand::PickPoint { x_px, y_px } => self.pick_point(x_px, y_px)?,
            OverheadCommand::SkipLandmark => self.skip_landmark()?,
            OverheadCommand::UndoPick => self.undo_pick()?,
            OverheadCommand::Calibrate => self.calibrate_from_points()?,
            OverheadCommand::SetOverheadCamera(overhead) => self.set_overhead_camera(overhead)?,
            OverheadCommand::SelectRobot(key) => {
                self.overhead.selected = key;
                if let Some(k) = key {
                    self.status = format!("selected robot {k}");
                }
                self.show_selected_robot_camera(key);
            }
            OverheadCommand::WmdLayout => self.request_wmd_layout(),
            OverheadCommand::SendSslVision(address) => self.set_ssl_out(address)?,
            OverheadCommand::SetView(v) => {
                self.settings.overhead = v;
                self.refresh_view_map(self.image_size());
                self.frame_generation += 1;
            }
        }
        Ok(())
    }

    /// Uses the calibration file `p` (refused when its review finds it unusable; its doubts
    /// are warnings).
    fn open_calibration(&mut self, p: PathBuf) -> anyhow::Result<()> {
        let cal = Calibration::load(&p)?;
        let review = crate::overhead::review::review(&cal);
        if let Some(refusal) = review.refusal() {
            anyhow::bail!("{}: not usable: {refusal}", p.display());
        }
        for f in &review.findings {
            self.warn(format!("{}: {f}", p.display()));
        }
        self.status = format!(
            "opened calibration {}: {} points, median error {:.2} px",
            p.display(),
            cal.points.len(),
            cal.median_point_error_px()
        );
        let canonical = std::fs::canonicalize(&p).unwrap_or_else(|_| p.clone());
        self.remember_for_camera(|f| f.calibration = Some(canonical));
        self.overhead.user_calibration = Some(cal);
        self.overhead.calibration_path = Some(p);
        self.reprocess();
        Ok(())
    }

    /// Saves the calibration opened or solved as `p`, and remembers it for the camera.
    fn save_calibration(&mut self, p: PathBuf) -> anyhow::Result<()> {
        let cal = self
            .overhead
            .user_calibration
            .as_ref()
            .context("no calibration to save: open one or Calibrate first")?;
        cal.save(&p)?;
        let canonical = std::fs::canonicalize(&p).unwrap_or_else(|_| p.clone());
        self.remember_for_camera(|f| f.calibration = Some(canonical));
        self.overhead.calibration_path = Some(p.clone());
        self.status = format!("saved calibration {}", p.display());
        Ok(())
    }

    /// Tells whether the open frame files come from an overhead camera: the frames are then
    /// recognised as overhead frames (with the overhead table) or as a robot's.
    fn set_overhead_camera(&mut self, overhead: bool) -> anyhow::Result<()> {
        use crate::sources::{CameraKind, SourceKind};
        let src = self.source.as_mut().context("no frames open")?;
        anyhow::ensure!(
            self.live.is_none() && src.info().kind == SourceKind::Files,
            "only frame files (JPEG, PNG, raw frames) can be told which camera made them; {} says it itself",
            src.label()
        );
        let kind = if overhead {
            CameraKind::Overhead
        } else {
            CameraKind::Robot
        };
        src.set_camera_kind(kind);
        self.reset_overhead_for_source();
        // The table of that kind of camera; it re-runs the shown frame.
        self.use_table_of(kind);
        self.reprocess();
        self.status = if overhead {
            format!(
                "overhead camera: the overhead recogniser runs; {}",
                self.overhead.calibration_status()
            )
        } else {
            "robot camera: the robot's recognisers run".to_owned()
        };
        Ok(())
    }

    /// Uses the intrinsics of `p` for Calibrate, or none.
    fn open_intrinsics(&mut self, p: Option<PathBuf>) -> anyhow::Result<()> {
        let Some(p) = p else {
            self.overhead.intrinsics = None;
            self.status = "no intrinsics: Calibrate fits the lens too".into();
            return Ok(());
        };
        let mut i =
            crate::streams::camera_info::load_intrinsics(&p, None).map_err(anyhow::Error::msg)?;
        if i.camera_name.is_empty() {
            i.camera_name = p.display().to_string();
        }
        self.status = format!(
            "intrinsics {}: {}x{}, fx {:.1} px, {}; Calibrate fits only the pose",
            p.display(),
            i.width_px,
            i.height_px,
            i.fx,
            i.lens.ros_name()
        );
        self.overhead.intrinsics = Some((i, p));
        Ok(())
    }

    /// Makes or drops the undistorted view's pixel map for the shown frame and camera.
    pub(super) fn refresh_view_map(&mut self, size: (usize, usize)) {
        let wanted = self.settings.overhead.undistorted && self.overhead.active;
        let camera = self.overhead.camera().map(|(c, _)| *c);
        match (wanted, camera) {
            (true, Some(c)) => {
                let fresh = self
                    .overhead
                    .view_map
                    .as_ref()
                    .is_some_and(|m| m.camera == c && m.size == size);
                if !fresh {
                    let map = crate::overhead::undistort::source_pixel_map(&c, size.0, size.1);
                    self.overhead.view_map = Some(ViewMap {
                        camera: c,
                        size,
                        map,
                    });
                }
            }
            _ => self.overhead.view_map = None,
        }
    }

    /// Where pixel (x, y)'s centre lies on the ground, centimetres: through the calibration in
    /// use (scaled to a frame of another size with its shape), for an overhead frame only.
    #[must_use]
    pub fn field_point_of_pixel(&self, x: usize, y: usize) -> Option<[f64; 2]> {
        use crate::overhead::pipeline::{FrameFit, frame_fit};
        if !self.overhead.active {
            return None;
        }
        let (camera, _) = self.overhead.camera()?;
        let (w, h) = self.image_size();
        let camera = match frame_fit(camera, w, h) {
            FrameFit::Same => *camera,
            FrameFit::Scaled { .. } => camera.scaled_to(w, h),
            FrameFit::Mismatch { .. } => return None,
        };
        let p = camera.field_from_image(ImagePoint::new(x as f64 + 0.5, y as f64 + 0.5), 0.0)?;
        Some([p.x(), p.y()])
    }

    /// True when the views show the undistorted image.
    #[must_use]
    pub const fn undistorted_view(&self) -> bool {
        self.overhead.view_map.is_some()
    }

    /// The shown frame as packed RGB as the views show it (undistorted when chosen).
    #[must_use]
    pub fn view_rgb(&self) -> std::borrow::Cow<'_, [u8]> {
        let Some(ViewMap { map, .. }) = &self.overhead.view_map else {
            return std::borrow::Cow::Borrowed(self.rgb());
        };
        let rgb = self.rgb();
        let mut out = vec![0u8; map.len() * 3];
        for (o, k) in out.chunks_exact_mut(3).zip(map) {
            if let Some(src) = k.and_then(|k| rgb.get(k as usize * 3..k as usize * 3 + 3)) {
                o.copy_from_slice(src);
            }
        }
        std::borrow::Cow::Owned(out)
    }

    /// One class code per pixel as the views show it (undistorted when chosen).
    #[must_use]
    pub fn view_codes(&self) -> std::borrow::Cow<'_, [u8]> {
        let codes = self.classified().codes();
        let Some(ViewMap { map, .. }) = &self.overhead.view_map else {
            return std::borrow::Cow::Borrowed(codes);
        };
        std::borrow::Cow::Owned(
            map.iter()
                .map(|k| k.and_then(|k| codes.get(k as usize).copied()).unwrap_or(0))
                .collect(),
        )
    }

    /// The camera's image point a view point (pixels) shows: itself, or through the lens
    /// model in the undistorted view. Clicks are turned into camera pixels with this.
    #[must_use]
    pub fn camera_point_of_view(&self, p: ImagePoint) -> ImagePoint {
        match &self.overhead.view_map {
            Some(m) => crate::overhead::undistort::distorted_point(p, &m.camera, m.size),
            None => p,
        }
    }

    /// Marks the shown frame as a robot-camera frame (the robot pipeline ran on it).
    pub(super) fn overhead_inactive(&mut self) {
        self.overhead.active = false;
        self.overhead.detections = None;
        self.overhead.view_map = None;
    }

    /// Forgets the per-stream overhead state when another source is opened.
    pub(super) fn reset_overhead_for_source(&mut self) {
        self.overhead.active = false;
        self.overhead.detections = None;
        self.overhead.stream_camera = None;
        self.overhead.truth = None;
        self.overhead.field_model = FieldModel::default();
        self.overhead.cameras = FieldCameras::default();
        self.overhead.wmd.forget_session();
    }

    /// Where an image point (pixels of the camera's image) is drawn in the views: itself, or
    /// its place in the undistorted view when that is shown.
    #[must_use]
    pub fn overhead_view_point(&self, p: ImagePoint) -> Option<ImagePoint> {
        match &self.overhead.view_map {
            Some(m) => crate::overhead::undistort::undistorted_point(p, &m.camera, m.size),
            None => Some(p),
        }
    }
}

/// The overhead truth a synthetic frame carries, if any.
pub(super) fn truth_of(loaded: &SourceFrame) -> Option<crate::model::truth::OverheadTruth> {
    let value = loaded.channel(crate::streams::GROUND_TRUTH_TOPIC)?;
    match serde_json::from_value::<crate::model::truth::GroundTruth>(value.clone()) {
        Ok(crate::model::truth::GroundTruth::Overhead(t)) => Some(*t),
        _ => None,
    }
}
