//! A session's overhead cameras opened for the command line: each camera's pipeline (its own
//! table, calibration, recogniser settings) and its recording, shared by `eotn overhead bench
//! --session` and `eotn overhead detect --session`.

use std::path::Path;

use anyhow::{Context, bail};

use super::inputs::load_lut_arg;
use super::overhead::{load_usable_calibration, params_for};
use crate::model::GroundTruth;
use crate::model::truth::OverheadTruth;
use crate::overhead::merge::SslCameraId as MergeCameraId;
use crate::overhead::recognise::{OverheadDetections, OverheadParams};
use crate::overhead::{FieldDescription, OverheadPipeline};
use crate::session::{OverheadEntry, Session, SessionSource, SslCameraId};
use crate::streams::StreamReader;

/// One overhead camera of a session, ready to run.
#[derive(Debug)]
pub struct FieldCamera {
    /// Its session id.
    pub id: SslCameraId,
    /// Its pipeline: its own table, calibration and settings.
    pub pipeline: OverheadPipeline,
    /// Its recording.
    pub reader: StreamReader,
    /// The recording's path, for messages.
    pub name: String,
}

/// A frame read from a camera's recording, with its truth when the recording has one.
#[derive(Debug, Clone)]
pub struct FieldFrame {
    /// Capture time, nanoseconds on the recording's clock.
    pub time_ns: u64,
    /// The frame.
    pub frame: crate::frame::Frame,
    /// The overhead truth (simulated recordings).
    pub truth: Option<OverheadTruth>,
}

/// Opens every overhead camera of `session`, in session order (the reference first).
///
/// # Errors
/// A camera whose source is not a recording (live and device sources are not read here), an
/// unreadable table, calibration, parameter file or recording: each named with the camera.
pub fn open_cameras(session: &Session) -> anyhow::Result<(FieldDescription, Vec<FieldCamera>)> {
    say_unused_intrinsics(session);
    let field = session
        .field
        .load()
        .with_context(|| format!("{}: field", session.path.display()))?;
    let cameras = session
        .overhead
        .iter()
        .map(|e| {
            open_camera(e, &field)
                .with_context(|| format!("{}: camera {}", session.path.display(), e.id))
        })
        .collect::<anyhow::Result<Vec<_>>>()?;
    Ok((field, cameras))
}

/// Warns about each camera's `intrinsics`, which no command reading a session uses (the
/// calibration holds the lens; intrinsics are for `eotn overhead calibrate --intrinsics`).
pub(super) fn say_unused_intrinsics(session: &Session) {
    for (i, e) in session.overhead.iter().enumerate() {
        if let Some(p) = &e.intrinsics {
            log::warn!(
                "overhead[{i}] (id {}): intrinsics {}: not read here: the calibration holds the \
                 lens used (intrinsics are for `eotn overhead calibrate --intrinsics`)",
                e.id,
                p.display()
            );
        }
    }
}

fn open_camera(e: &OverheadEntry, field: &FieldDescription) -> anyhow::Result<FieldCamera> {
    let SessionSource::Recording(path) = &e.source else {
        bail!(
            "source {:?}: this command reads recorded cameras; live servers and devices are read by the app",
            e.source
        );
    };
    let lut = load_lut_arg(&e.lut)?;
    let cal = load_usable_calibration(&e.calibration)?;
    let params = match &e.params {
        Some(p) => load_params(p)?,
        None => params_for(field),
    };
    let reader = StreamReader::open_camera(path, e.camera.as_deref())?;
    Ok(FieldCamera {
        id: e.id,
        pipeline: OverheadPipeline::new(lut, cal.camera, params),
        reader,
        name: crate::frame::display_name(path),
    })
}

/// The overhead recogniser's settings from a JSON file; unknown keys refused.
pub(super) fn load_params(path: &Path) -> anyhow::Result<OverheadParams> {
    let text = crate::input_file::read_text_bounded(
        path,
        crate::input_file::MAX_SMALL_FILE_BYTES,
        "overhead parameters",
    )
    .with_context(|| format!("{}", path.display()))?;
    let given: serde_json::Value =
        serde_json::from_str(&text).with_context(|| format!("{}: not JSON", path.display()))?;
    let params: OverheadParams = serde_json::from_value(given.clone())
        .with_context(|| format!("{}: not overhead parameters", path.display()))?;
    let known = serde_json::to_value(params)?;
    if let Some(key) = crate::input_file::unknown_keys(&given, &known).first() {
        bail!("{}: unknown key '{key}'", path.display());
    }
    Ok(params)
}

impl FieldCamera {
    /// Number of frames in its recording.
    #[must_use]
    pub fn len(&self) -> usize {
        self.reader.len()
    }

    /// Frame `i` of its recording, with its overhead truth when it has one.
    ///
    /// # Errors
    /// An unreadable frame, naming the recording.
    pub fn read(&mut self, i: usize) -> anyhow::Result<FieldFrame> {
        let record = self
            .reader
            .read(i)
            .with_context(|| format!("{} frame {i}", self.name))?;
        let truth = record
            .ground_truth
            .and_then(|t| serde_json::from_value::<GroundTruth>(t).ok())
            .and_then(|t| match t {
                GroundTruth::Overhead(o) => Some(*o),
                GroundTruth::Robot(_) => None,
            });
        Ok(FieldFrame {
            time_ns: record.time_ns,
            frame: record.frame,
            truth,
        })
    }
}

/// One field frame's detections by camera, and each camera's frame time (nanoseconds).
pub type FieldViews = (
    Vec<(MergeCameraId, OverheadDetections)>,
    Vec<(MergeCameraId, u64)>,
);

/// Each camera's frame times, nanoseconds on its recording's clock, in frame order.
#[must_use]
pub fn frame_times(cameras: &[FieldCamera]) -> Vec<Vec<u64>> {
    cameras
        .iter()
        .map(|c| {
            (0..c.reader.len())
                .filter_map(|i| c.reader.time_ns(i))
                .collect()
        })
        .collect()
}

/// One field frame's views: the reference camera's frame `i` and each other camera's frame
/// within half a frame period of it (`times` from [`frame_times`]), each through its own
/// pipeline; with the (camera, frame time) of each view.
///
/// # Errors
/// A camera's frame of another shape than its calibration. An unreadable frame is warned about
/// and left out.
pub fn field_views(
    cameras: &mut [FieldCamera],
    times: &[Vec<u64>],
    i: usize,
    period_ns: u64,
    sizes: &mut [super::overhead::SizeCheck],
) -> anyhow::Result<FieldViews> {
    let Some(&t_ref) = times.first().and_then(|t| t.get(i)) else {
        return Ok((Vec::new(), Vec::new()));
    };
    let (mut views, mut frames) = (Vec::new(), Vec::new());
    for (k, cam) in cameras.iter_mut().enumerate() {
        let index = if k == 0 {
            Some(i)
        } else {
            times
                .get(k)
                .and_then(|t| crate::overhead::merge::frame_near(t, t_ref, period_ns))
        };
        let Some(index) = index else { continue };
        let f = match cam.read(index) {
            Ok(f) => f,
            Err(e) => {
                log::warn!("camera {}: {e:#}; left out of this field frame", cam.id);
                continue;
            }
        };
        let camera = *cam.pipeline.camera();
        let name = format!("{} frame {index}", cam.name);
        if let Some(size) = sizes.get_mut(k) {
            size.check(&camera, &name, f.frame.width(), f.frame.height())?;
        }
        views.push((cam.id, cam.pipeline.process(&f.frame).clone()));
        frames.push((cam.id, f.time_ns));
    }
    Ok((views, frames))
}
