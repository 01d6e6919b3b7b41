//! The field's overhead cameras in the app: the shown camera and, when a session file
//! (`SESSION.json`, docs/formats.md) is open, the session's other cameras — each with its own
//! table, calibration and recogniser settings, its frame nearest the shown frame (within half a
//! frame period, as `eotn overhead detect --session` pairs them) run through its own pipeline —
//! merged into one field picture ([`crate::overhead::merge`]: which cameras saw each robot and
//! the ball); each camera's coverage of the field ([`crate::overhead::coverage`]), made once per
//! calibration and frame size, not once per paint; and whether each camera's frame is current or
//! stale (none within half a frame period of the shown one: the camera stopped delivering or has
//! a gap). The field view draws this.
//!
//! The session's first camera (the reference) is the workspace's source: its frames are shown,
//! stepped and classified as any overhead stream's, with its own table and calibration opened
//! (so clicks, edits and Calibrate go to it). The app reads a session's recorded cameras; live
//! servers and devices are refused with a clear error (`eotn wmd --session` reads those).

use std::path::{Path, PathBuf};

use anyhow::Context as _;

use super::super::Workspace;
use super::super::command::OverheadCommand;
use crate::geometry::OverheadCamera;
use crate::overhead::coverage::{CameraCoverage, coverage_polygon};
use crate::overhead::merge::{FieldPicture, SslCameraId, frame_near, merge_detections, one_camera};
use crate::overhead::pipeline::{FrameFit, frame_fit};
use crate::overhead::{FieldDescription, OverheadDetections, OverheadPipeline};
use crate::session::{FieldRef, OverheadEntry, Session, SessionSource};
use crate::streams::StreamReader;

/// Frames of the reference camera whose spacing gives the frame period (the pairing window).
const PERIOD_FRAMES: usize = 200;

/// Whether one camera's frame is in the shown field frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FrameState {
    /// Its frame `index` (of its recording), taken at `time_ns` on its clock, is in the shown
    /// field frame.
    Current {
        /// The frame's index in the camera's recording.
        index: usize,
        /// The frame's time, nanoseconds.
        time_ns: u64,
    },
    /// None of its frames lies within half a frame period of the shown one: it stopped
    /// delivering, or has a gap here. Its last frame before the shown time, nanoseconds, if any.
    Stale {
        /// Its last frame's time before the shown one, nanoseconds.
        last_time_ns: Option<u64>,
    },
}

/// One camera as the field view shows it.
#[derive(Debug, Clone, Copy)]
pub struct CameraShown<'a> {
    /// Its session id (0 for a single overhead stream).
    pub id: SslCameraId,
    /// Its recording, for the legend.
    pub name: &'a str,
    /// Its view of the carpet, if its calibration fits its frames.
    pub coverage: Option<&'a CameraCoverage>,
    /// Whether its frame is in the shown field frame.
    pub frame: FrameState,
}

/// A session camera other than the shown one.
#[derive(Debug)]
struct OtherCamera {
    id: SslCameraId,
    name: String,
    pipeline: OverheadPipeline,
    reader: StreamReader,
    /// Its frames' times, nanoseconds, in frame order.
    times_ns: Vec<u64>,
    /// Its coverage and the frame size it was made for.
    coverage: Option<((usize, usize), CameraCoverage)>,
    frame: FrameState,
    /// What its pipeline found on its frame in the shown field frame (`None` when its frames
    /// do not fit its calibration, or none is current).
    detections: Option<OverheadDetections>,
    /// A frame that did not fit its calibration or could not be read was said.
    warned: bool,
}

/// See the module documentation.
#[derive(Debug)]
pub struct FieldCameras {
    /// The session file open, if the cameras are a session's.
    session: Option<PathBuf>,
    /// The shown camera's id: the session's first, else 0.
    reference: SslCameraId,
    /// The shown camera's recording, for the legend.
    reference_name: String,
    /// The shown camera's coverage, with the camera and frame size it was made for.
    reference_coverage: Option<(OverheadCamera, (usize, usize), Option<CameraCoverage>)>,
    /// The shown frame's index and time, nanoseconds.
    reference_frame: FrameState,
    others: Vec<OtherCamera>,
    /// The reference camera's frame period, nanoseconds: other cameras' frames within half of
    /// it join the shown field frame.
    period_ns: u64,
    /// The shown field frame: every current camera's detections, merged.
    picture: Option<FieldPicture>,
}

impl Default for FieldCameras {
    fn default() -> Self {
        Self {
            session: None,
            reference: SslCameraId(0),
            reference_name: String::new(),
            reference_coverage: None,
            reference_frame: FrameState::Stale { last_time_ns: None },
            others: Vec::new(),
            period_ns: 0,
            picture: None,
        }
    }
}

impl FieldCameras {
    /// The session file open, if any.
    #[must_use]
    pub fn session(&self) -> Option<&Path> {
        self.session.as_deref()
    }

    /// The shown field frame: one camera's detections, or a session's cameras' merged, each
    /// robot and the ball with the ids of the cameras that saw it. `None` with no calibration
    /// in use and no other camera.
    #[must_use]
    pub const fn picture(&self) -> Option<&FieldPicture> {
        self.picture.as_ref()
    }

    /// Every camera, the shown one first (the session's order).
    #[must_use]
    pub fn cameras(&self) -> Vec<CameraShown<'_>> {
        let shown = CameraShown {
            id: self.reference,
            name: &self.reference_name,
            coverage: self
                .reference_coverage
                .as_ref()
                .and_then(|(_, _, c)| c.as_ref()),
            frame: self.reference_frame,
        };
        std::iter::once(shown)
            .chain(self.others.iter().map(|c| CameraShown {
                id: c.id,
                name: &c.name,
                coverage: c.coverage.as_ref().map(|(_, cov)| cov),
                frame: c.frame,
            }))
            .collect()
    }

    /// Makes the shown camera's coverage for `camera` and a frame of `size`, unless it was made
    /// for them already.
    fn refresh_reference_coverage(&mut self, camera: Option<OverheadCamera>, size: (usize, usize)) {
        let fresh = matches!(
            (&self.reference_coverage, camera),
            (Some((c, s, _)), Some(cam)) if *c == cam && *s == size
        );
        if !fresh {
            self.reference_coverage = camera.map(|c| {
                let polygon = coverage_polygon(&c, size.0, size.1, 0.0);
                let coverage = polygon.map(|polygon_cm| CameraCoverage {
                    camera: self.reference,
                    polygon_cm,
                });
                (c, size, coverage)
            });
        }
    }

    /// Runs every other camera's frame of the field frame at `time_ns` (each camera on its own
    /// thread; a camera whose frame is the one it ran last is not run again); returns what is
    /// to be warned about.
    fn run_others(&mut self, time_ns: u64) -> Vec<String> {
        let period = self.period_ns;
        std::thread::scope(|s| {
            let jobs: Vec<_> = self
                .others
                .iter_mut()
                .map(|c| s.spawn(move || c.show_at(time_ns, period)))
                .collect();
            jobs.into_iter()
                .filter_map(|j| {
                    j.join()
                        .unwrap_or_else(|_| Some("a camera's thread failed".into()))
                })
                .collect()
        })
    }

    /// Merges the shown camera's detections (`own`) with every current other camera's.
    fn merge(&mut self, own: Option<&OverheadDetections>) {
        if self.session.is_none() {
            self.picture = own.map(|d| one_camera(self.reference, d));
            return;
        }
        let views: Vec<(SslCameraId, &OverheadDetections)> = own
            .map(|d| (self.reference, d))
            .into_iter()
            .chain(
                self.others
                    .iter()
                    .filter_map(|c| c.detections.as_ref().map(|d| (c.id, d))),
            )
            .collect();
        self.picture = (!views.is_empty()).then(|| merge_detections(&views));
    }
}

impl OtherCamera {
    /// Opens a session camera: its recording, table, calibration (refused when its review
    /// finds it unusable) and recogniser settings (its file, else the field's with defaults),
    /// and its coverage from its first frame's size.
    fn open(e: &OverheadEntry, field: &FieldDescription) -> anyhow::Result<Self> {
        let SessionSource::Recording(path) = &e.source else {
            anyhow::bail!(
                "{}: the app opens a session's recorded cameras (`eotn wmd --session` reads live servers, devices and SSL-Vision)",
                e.source
            );
        };
        let (Some(lut_path), Some(calibration)) = (&e.lut, &e.calibration) else {
            anyhow::bail!("overhead camera {}: no table or calibration", e.id);
        };
        let lut = crate::lut::LookupTable::load(lut_path)
            .with_context(|| format!("table {}", lut_path.display()))?;
        let camera = usable_calibration(calibration)?;
        let params = match &e.params {
            Some(p) => crate::session::load_camera_params(p)?,
            None => crate::overhead::OverheadParams {
                ball_radius_cm: field.ball_radius_cm,
                plate_height_cm: field.plate_height_cm,
                ..crate::overhead::OverheadParams::default()
            },
        };
        let mut reader = StreamReader::open_camera(path, e.camera.as_deref())
            .with_context(|| format!("{}", path.display()))?;
        let times_ns: Vec<u64> = (0..reader.len())
            .filter_map(|i| reader.time_ns(i))
            .collect();
        anyhow::ensure!(!times_ns.is_empty(), "{}: no frames", path.display());
        let first = reader
            .read(0)
            .with_context(|| format!("{} frame 0", path.display()))?;
        let size = (first.frame.width(), first.frame.height());
        let mut cam = Self {
            id: e.id,
            name: crate::frame::display_name(path),
            pipeline: OverheadPipeline::new(lut, camera, params),
            reader,
            times_ns,
            coverage: None,
            frame: FrameState::Stale { last_time_ns: None },
            detections: None,
            warned: false,
        };
        cam.refresh_coverage(size);
        Ok(cam)
    }

    /// Makes its coverage for frames of `size` unless it was made for that size.
    fn refresh_coverage(&mut self, size: (usize, usize)) {
        if self.coverage.as_ref().is_some_and(|(s, _)| *s == size) {
            return;
        }
        let camera = self.pipeline.camera();
        self.coverage = coverage_polygon(camera, size.0, size.1, 0.0).map(|polygon_cm| {
            (
                size,
                CameraCoverage {
                    camera: self.id,
                    polygon_cm,
                },
            )
        });
    }

    /// Shows its frame of the field frame at `time_ns`: the nearest within half of
    /// `period_ns`, run through its pipeline; else it is stale. Returns a warning the first
    /// time a frame cannot be read or does not fit its calibration.
    fn show_at(&mut self, time_ns: u64, period_ns: u64) -> Option<String> {
        let Some(index) = frame_near(&self.times_ns, time_ns, period_ns) else {
            let before = self.times_ns.partition_point(|&t| t <= time_ns);
            self.frame = FrameState::Stale {
                last_time_ns: before.checked_sub(1).map(|k| self.times_ns[k]),
            };
            self.detections = None;
            return None;
        };
        if matches!(self.frame, FrameState::Current { index: i, .. } if i == index) {
            return None;
        }
        let record = match self.reader.read(index) {
            Ok(r) => r,
            Err(e) => {
                self.frame = FrameState::Stale {
                    last_time_ns: self.times_ns.get(index).copied(),
                };
                self.detections = None;
                return self.warn_once(format!("{} frame {index}: {e}", self.name));
            }
        };
        self.frame = FrameState::Current {
            index,
            time_ns: record.time_ns,
        };
        let (w, h) = (record.frame.width(), record.frame.height());
        self.refresh_coverage((w, h));
        if let FrameFit::Mismatch { .. } = frame_fit(self.pipeline.camera(), w, h) {
            self.detections = None;
            return self.warn_once(format!(
                "{} frame {index}: {w}x{h} is not the shape of its calibration; nothing of it is placed on the field",
                self.name
            ));
        }
        self.detections = Some(self.pipeline.process(&record.frame).clone());
        None
    }

    fn warn_once(&mut self, what: String) -> Option<String> {
        (!std::mem::replace(&mut self.warned, true)).then(|| format!("camera {}: {what}", self.id))
    }
}

/// The camera of a calibration file, refused when its review finds it unusable.
fn usable_calibration(path: &Path) -> anyhow::Result<OverheadCamera> {
    let cal = crate::overhead::calibration::Calibration::load(path)?;
    if let Some(refusal) = crate::overhead::review::review(&cal).refusal() {
        anyhow::bail!("{}: not a usable calibration: {refusal}", path.display());
    }
    Ok(cal.camera)
}

/// Whether `path` is a session file: a JSON object whose `overhead` is a list of cameras (the
/// recognition parameters' `overhead` is an object).
#[must_use]
pub fn is_session_file(path: &Path) -> bool {
    crate::input_file::read_text_bounded(
        path,
        crate::input_file::MAX_SMALL_FILE_BYTES,
        "a JSON file",
    )
    .ok()
    .and_then(|text| serde_json::from_str::<serde_json::Value>(&text).ok())
    .is_some_and(|v| v.get("overhead").is_some_and(serde_json::Value::is_array))
}

impl Workspace {
    /// Opens a session file: its field, its first camera shown as the source with its own
    /// table and calibration, the other cameras beside it; the field view window opens.
    ///
    /// # Errors
    /// The session file's errors (named entries), a camera that is not a recording, an
    /// unreadable table, calibration, parameter file or recording, each naming its camera.
    pub(in crate::workspace) fn open_session(&mut self, path: &Path) -> anyhow::Result<()> {
        let session = Session::load(path)?;
        let at = |e: &OverheadEntry| format!("{}: camera {}", path.display(), e.id);
        let field = session
            .field
            .load()
            .with_context(|| format!("{}: field", path.display()))?;
        let (reference, rest) = session
            .overhead
            .split_first()
            .with_context(|| format!("{}: no overhead camera", path.display()))?;
        let SessionSource::Recording(recording) = &reference.source else {
            anyhow::bail!(
                "{}: {}: the app opens a session's recorded cameras (`eotn wmd --session` reads live servers, devices and SSL-Vision)",
                at(reference),
                reference.source
            );
        };
        let (Some(lut), Some(calibration)) = (&reference.lut, &reference.calibration) else {
            anyhow::bail!("{}: no table or calibration", at(reference));
        };
        let others = rest
            .iter()
            .map(|e| OtherCamera::open(e, &field).with_context(|| at(e)))
            .collect::<anyhow::Result<Vec<_>>>()?;
        let source =
            super::super::source::Source::stream_camera(recording, reference.camera.as_deref())
                .with_context(|| at(reference))?;
        self.set_source(source).with_context(|| at(reference))?;
        let field_name = match &session.field {
            FieldRef::File(p) => p.clone(),
            FieldRef::Shipped(name) => PathBuf::from(name),
        };
        self.apply_overhead(OverheadCommand::OpenField(field_name))?;
        self.open_table(lut).with_context(|| at(reference))?;
        self.open_calibration(calibration.clone())
            .with_context(|| at(reference))?;
        if let Some(p) = &reference.params {
            self.warn(format!(
                "{}: params {}: the shown camera is recognised with the Parameters window's overhead section; open the file there to use it",
                at(reference),
                p.display()
            ));
        }
        let times: Vec<u64> = self.source.as_ref().map_or_else(Vec::new, |s| {
            (0..s.len().min(PERIOD_FRAMES))
                .map(|i| s.time_ns(i))
                .collect()
        });
        let period_ns = crate::wmd::clock::frame_period_ns(&times);
        self.overhead.cameras = FieldCameras {
            session: Some(path.to_owned()),
            reference: reference.id,
            reference_name: crate::frame::display_name(recording),
            period_ns,
            others,
            ..FieldCameras::default()
        };
        self.remember_recent(path);
        let frames_ns: Vec<u64> = self
            .source
            .as_ref()
            .map_or_else(Vec::new, |s| (0..s.len()).map(|i| s.time_ns(i)).collect());
        self.set_session_robots(&session.robots, &frames_ns, period_ns);
        self.request_wmd_layout();
        self.reprocess();
        self.status = format!(
            "opened session {}: {} overhead cameras, camera {} shown",
            path.display(),
            session.overhead.len(),
            reference.id
        );
        Ok(())
    }

    /// Brings the field's cameras to the shown frame (`index` at `time_ns`, `size` pixels):
    /// the shown camera's coverage, each other camera's frame, the merged picture.
    pub(in crate::workspace) fn sync_field_cameras(
        &mut self,
        index: usize,
        time_ns: u64,
        size: (usize, usize),
    ) {
        let camera = self.overhead.camera().map(|(c, _)| *c);
        if self.overhead.cameras.session.is_none() {
            self.overhead.cameras.reference_name = self
                .source
                .as_ref()
                .map(super::super::source::Source::label)
                .unwrap_or_default();
        }
        let cams = &mut self.overhead.cameras;
        cams.refresh_reference_coverage(camera, size);
        cams.reference_frame = FrameState::Current { index, time_ns };
        let warnings = cams.run_others(time_ns);
        cams.merge(self.overhead.detections.as_ref());
        for w in warnings {
            self.warn(w);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::super::Command;
    use super::*;

    #[test]
    fn a_session_is_told_from_parameters_and_a_live_camera_is_refused_clearly() {
        let dir = tempfile::tempdir().expect("temp");
        for f in ["a.lut", "a.cal.json"] {
            std::fs::write(dir.path().join(f), b"").expect("write");
        }
        let session = dir.path().join("SESSION.json");
        std::fs::write(
            &session,
            r#"{"field": "four-legged-2005", "overhead": [{"id": 0, "source": "ws://127.0.0.1:9",
                "lut": "a.lut", "calibration": "a.cal.json"}]}"#,
        )
        .expect("write");
        let params = dir.path().join("params.json");
        std::fs::write(&params, r#"{"overhead": {}}"#).expect("write");
        assert!(is_session_file(&session));
        assert!(
            !is_session_file(&params),
            "parameters' overhead is a section"
        );
        let mut w = Workspace::default();
        let e = w
            .apply(Command::Open(vec![session]))
            .expect_err("a live camera is not opened");
        let said = format!("{e:#}");
        assert!(
            said.contains("camera 0") && said.contains("recorded cameras"),
            "{said}"
        );
        assert!(w.overhead().field_cameras().session().is_none());
    }
}
