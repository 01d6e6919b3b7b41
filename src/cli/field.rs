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
            "{}: this command reads recorded eotn cameras; live servers and devices are read by `eotn wmd` and the app, SSL-Vision sources by `eotn wmd`, `eotn open` and `eval --truth-ssl`",
            e.source
        );
    };
    let (Some(lut), Some(cal)) = (&e.lut, &e.calibration) else {
        bail!("overhead camera {}: no table or calibration", e.id);
    };
    let lut = load_lut_arg(lut)?;
    let cal = load_usable_calibration(cal)?;
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
    crate::session::load_camera_params(path)
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

/// One camera's frame of a field frame, through its pipeline.
#[derive(Debug, Clone)]
pub struct CameraView {
    /// The camera's session id.
    pub id: MergeCameraId,
    /// Its frame's index in its recording.
    pub index: usize,
    /// Its frame's time, nanoseconds on its recording's clock.
    pub time_ns: u64,
    /// What its pipeline found.
    pub detections: OverheadDetections,
    /// The frame's overhead truth (simulated recordings).
    pub truth: Option<OverheadTruth>,
}

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
/// pipeline; with the (camera, frame time) of each view. See [`camera_views`].
///
/// # Errors
/// As [`camera_views`].
pub fn field_views(
    cameras: &mut [FieldCamera],
    times: &[Vec<u64>],
    i: usize,
    period_ns: u64,
    sizes: &mut [super::overhead::SizeCheck],
) -> anyhow::Result<FieldViews> {
    Ok(camera_views(cameras, times, i, period_ns, sizes)?
        .into_iter()
        .map(|v| ((v.id, v.detections), (v.id, v.time_ns)))
        .unzip())
}

/// One field frame's views, in camera order: the reference camera's frame `i` and each other
/// camera's frame within half a frame period of it (`times` from [`frame_times`]), each read
/// and run through its own pipeline. The cameras run in parallel, on up to every core
/// ([`worker_threads`]): each camera's reading and pipeline are its own.
///
/// # Errors
/// A camera's frame of another shape than its calibration (`sizes`: one check per camera). An
/// unreadable frame is warned about and left out.
pub fn camera_views(
    cameras: &mut [FieldCamera],
    times: &[Vec<u64>],
    i: usize,
    period_ns: u64,
    sizes: &mut [super::overhead::SizeCheck],
) -> anyhow::Result<Vec<CameraView>> {
    let Some(&t_ref) = times.first().and_then(|t| t.get(i)) else {
        return Ok(Vec::new());
    };
    let mut spare: Vec<super::overhead::SizeCheck> = Vec::new();
    spare.resize_with(cameras.len().saturating_sub(sizes.len()), Default::default);
    let jobs: Vec<CameraJob<'_>> = cameras
        .iter_mut()
        .zip(sizes.iter_mut().chain(spare.iter_mut()))
        .enumerate()
        .filter_map(|(k, (camera, size))| {
            let index = if k == 0 {
                Some(i)
            } else {
                times
                    .get(k)
                    .and_then(|t| crate::overhead::merge::frame_near(t, t_ref, period_ns))
            }?;
            Some(CameraJob {
                camera,
                size,
                index,
            })
        })
        .collect();
    let workers = worker_threads().min(jobs.len()).max(1);
    let mut groups: Vec<Vec<CameraJob<'_>>> = (0..workers).map(|_| Vec::new()).collect();
    for (n, job) in jobs.into_iter().enumerate() {
        groups[n % workers].push(job);
    }
    let run_group = |group: Vec<CameraJob<'_>>| -> Vec<anyhow::Result<Option<CameraView>>> {
        group.into_iter().map(CameraJob::run).collect()
    };
    let mut first = groups.remove(0);
    let results: Vec<Vec<anyhow::Result<Option<CameraView>>>> = std::thread::scope(|s| {
        let handles: Vec<_> = groups
            .into_iter()
            .map(|g| s.spawn(move || run_group(g)))
            .collect();
        let mine = run_group(std::mem::take(&mut first));
        std::iter::once(Ok(mine))
            .chain(handles.into_iter().map(|h| h.join()))
            .map(|r| r.unwrap_or_else(|_| vec![Err(anyhow::anyhow!("a camera's thread failed"))]))
            .collect()
    });
    // Back into camera order (job n ran in group n % workers, at place n / workers).
    let mut out = Vec::new();
    let longest = results.iter().map(Vec::len).max().unwrap_or(0);
    let mut results: Vec<std::vec::IntoIter<_>> = results.into_iter().map(Vec::into_iter).collect();
    for _ in 0..longest {
        for group in &mut results {
            if let Some(r) = group.next() {
                out.extend(r?);
            }
        }
    }
    Ok(out)
}

/// One camera's part of a field frame: which of its frames, and its size check.
struct CameraJob<'a> {
    camera: &'a mut FieldCamera,
    size: &'a mut super::overhead::SizeCheck,
    index: usize,
}

impl CameraJob<'_> {
    /// Reads the frame and runs the camera's pipeline on it; `None` (warned) when the frame
    /// cannot be read.
    fn run(self) -> anyhow::Result<Option<CameraView>> {
        let cam = self.camera;
        let f = match cam.read(self.index) {
            Ok(f) => f,
            Err(e) => {
                log::warn!("camera {}: {e:#}; left out of this field frame", cam.id);
                return Ok(None);
            }
        };
        let camera = *cam.pipeline.camera();
        let name = format!("{} frame {}", cam.name, self.index);
        self.size
            .check(&camera, &name, f.frame.width(), f.frame.height())?;
        let detections = cam.pipeline.process(&f.frame).clone();
        Ok(Some(CameraView {
            id: cam.id,
            index: self.index,
            time_ns: f.time_ns,
            detections,
            truth: f.truth,
        }))
    }
}

/// Threads a field frame's cameras run on: every core (`available_parallelism`), decided once.
#[must_use]
pub fn worker_threads() -> usize {
    static THREADS: std::sync::OnceLock<usize> = std::sync::OnceLock::new();
    *THREADS.get_or_init(|| std::thread::available_parallelism().map_or(1, std::num::NonZero::get))
}
