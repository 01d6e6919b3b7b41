//! `eotn wmd -o SESSION.mcap`: the whole session in one recording, in the layout of several
//! cameras (docs/formats.md, "World Model Debugger sessions"), written through
//! [`StreamWriter`] (as `SESSION.mcap.partial`, renamed when finished: the one safe writer).
//!
//! Per field frame, at the reference camera's frame time: the reference camera's frame on
//! `/camera/image` with each world model paired with it on `/world_model/TEAM-ID` (the message as
//! the robot sent it) and the `--json` line on [`LINE_TOPIC`]; every other overhead camera's frame
//! on `/overhead/camera<ID>` (its own time); the field as a `foxglove.SceneUpdate` on
//! [`SCENE_TOPIC`]. Each live robot's camera frames, when it sends them, on `/robot/TEAM-ID` (a
//! session's robot) or `/robot/N` (the N-th `--robot`), their recognition beside them when the
//! session gives the robot a table. The stream's source is
//! [`SESSION_SOURCE`]: `eotn wmd` reading it back takes the world models at their log times (the
//! frames they were paired with), so a replay prints the same lines.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use anyhow::Context;
use foxglove::Encode as _;

use crate::camera::CameraFiles;
use crate::formats::ImageMessage;
use crate::frame::Frame;
use crate::model::world_model::{RobotKey, WorldModelMessage};
use crate::overhead::merge::SslCameraId;
use crate::pipeline::Pipeline;
use crate::streams::{FrameRecord, IMAGE_TOPIC, RawChannelSpec, StreamInfo, StreamWriter};

/// The stream source of a session recording (it names "overhead": the app opens it as the
/// overhead camera's stream).
pub const SESSION_SOURCE: &str = crate::streams::WMD_SESSION_SOURCE;
/// The topic of each field frame's `eotn wmd --json` line.
pub const LINE_TOPIC: &str = "/wmd/frame";
/// The topic of each field frame's `foxglove.SceneUpdate`.
pub const SCENE_TOPIC: &str = "/wmd/scene";

/// The topic of a robot's world models in a session recording.
#[must_use]
pub fn world_model_topic(key: RobotKey) -> String {
    format!("/world_model/{}-{}", key.team.name(), key.identity.value())
}

/// The image topic of an overhead camera in a session recording: the reference camera is the
/// stream's first camera.
#[must_use]
pub fn overhead_topic(id: SslCameraId, reference: bool) -> String {
    if reference {
        IMAGE_TOPIC.to_owned()
    } else {
        format!("/overhead/camera{}", id.0)
    }
}

/// An overhead camera as the recording names it: id, whether it is the reference, its files.
#[derive(Debug, Clone)]
pub struct RecordedCamera {
    /// Its session id.
    pub id: SslCameraId,
    /// Its table and calibration (named in the recording's `eotn.camera` metadata, so the app
    /// opens the stream with them).
    pub files: CameraFiles,
}

/// One overhead camera frame of a field frame.
#[derive(Debug, Clone, Copy)]
pub struct CameraFrame<'a> {
    /// Which camera.
    pub id: SslCameraId,
    /// Its time, nanoseconds.
    pub time_ns: u64,
    /// The frame.
    pub frame: &'a Frame,
}

/// A robot frame waiting for its place in time order.
struct RobotFrame {
    time_ns: u64,
    topic: String,
    record: FrameRecord,
    image: ImageMessage,
}

/// The session recording being written.
pub struct SessionRecorder {
    writer: StreamWriter,
    path: PathBuf,
    reference: SslCameraId,
    scene: RawChannelSpec,
    /// Robot frames not yet written: each goes in before the first field frame after it.
    robot_frames: Vec<RobotFrame>,
    /// A robot's recogniser, by its frames' topic.
    recognisers: BTreeMap<String, Pipeline>,
    field_frames: usize,
    robot_frames_written: usize,
}

impl std::fmt::Debug for SessionRecorder {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SessionRecorder")
            .field("path", &self.path)
            .field("field_frames", &self.field_frames)
            .finish_non_exhaustive()
    }
}

impl SessionRecorder {
    /// Starts the recording at `path`; `cameras` the overhead cameras, the reference first.
    ///
    /// # Errors
    /// The file cannot be made; the `foxglove.SceneUpdate` schema is missing.
    pub fn create(path: &Path, cameras: &[RecordedCamera]) -> anyhow::Result<Self> {
        let info = StreamInfo {
            source: SESSION_SOURCE.to_owned(),
            description: "eotn wmd session: overhead cameras, detections, the robots' world \
                          models and camera frames"
                .to_owned(),
        };
        let mut writer = StreamWriter::create(path, &info)?;
        let reference = cameras.first().map_or(SslCameraId(0), |c| c.id);
        for (i, c) in cameras.iter().enumerate() {
            if !c.files.is_empty() {
                writer.name_camera_files(&overhead_topic(c.id, i == 0), &c.files)?;
            }
        }
        let schema = foxglove::messages::SceneUpdate::get_schema()
            .context("the foxglove.SceneUpdate schema is not available")?;
        let scene = RawChannelSpec {
            topic: SCENE_TOPIC.to_owned(),
            message_encoding: "protobuf".to_owned(),
            schema_name: schema.name.clone(),
            schema_encoding: schema.encoding.clone(),
            schema: schema.data.to_vec(),
        };
        Ok(Self {
            writer,
            path: path.to_owned(),
            reference,
            scene,
            robot_frames: Vec::new(),
            recognisers: BTreeMap::new(),
            field_frames: 0,
            robot_frames_written: 0,
        })
    }

    /// Recognises the frames of the robot camera `topic` with `pipeline` (its table and
    /// parameters): their recognition goes beside them (`TOPIC/recognition`,
    /// `TOPIC/annotations`).
    pub fn recognise(&mut self, topic: &str, pipeline: Pipeline) {
        self.recognisers.insert(topic.to_owned(), pipeline);
    }

    /// Names the table and parameters of the robot camera `topic` in the recording (the
    /// session entry's), so the app reopens that camera with them.
    ///
    /// # Errors
    /// The file cannot be written.
    pub fn name_robot_camera(&mut self, topic: &str, files: &CameraFiles) -> anyhow::Result<()> {
        if !files.is_empty() {
            self.writer.name_camera_files(topic, files)?;
        }
        Ok(())
    }

    /// Queues a robot's camera frame (`topic`: its place in the recording); it is written in
    /// time order with the field frames.
    ///
    /// # Errors
    /// Pixels that do not make a frame (warned about by the caller).
    pub fn robot_frame(
        &mut self,
        topic: &str,
        time_ns: u64,
        image: ImageMessage,
    ) -> anyhow::Result<()> {
        let frame = image.clone().into_frame()?;
        let mut record = FrameRecord::new(time_ns, frame);
        if let Some(p) = self.recognisers.get_mut(topic) {
            let result = p.process(&record.frame, None);
            let line = super::detect::detect_json(String::new(), result.recognition, 0.0, false);
            record.annotations = Some(crate::annotate::image_annotations(
                result.recognition,
                record.frame.width(),
                record.frame.height(),
                time_ns,
            ));
            record.recognition = Some(serde_json::to_value(&line)?);
        }
        self.robot_frames.push(RobotFrame {
            time_ns,
            topic: topic.to_owned(),
            record,
            image,
        });
        Ok(())
    }

    /// Writes one field frame (see the module documentation): `cameras` its overhead frames (the
    /// reference first), `models` the world models paired with it, `line` its `--json` line,
    /// `scene` the field as Foxglove draws it. Robot frames queued before it go in first.
    ///
    /// # Errors
    /// The file cannot be written.
    pub fn field_frame(
        &mut self,
        time_ns: u64,
        cameras: &[CameraFrame<'_>],
        models: &[&WorldModelMessage],
        line: &serde_json::Value,
        scene: &foxglove::messages::SceneUpdate,
    ) -> anyhow::Result<()> {
        self.flush_robot_frames(Some(time_ns))?;
        for c in cameras {
            let reference = c.id == self.reference;
            let t = if reference { time_ns } else { c.time_ns };
            let mut record = FrameRecord::new(t, c.frame.clone());
            if reference {
                record.extra = models
                    .iter()
                    .map(|m| (world_model_topic(m.robot), m.to_json()))
                    .collect();
                record.extra.push((LINE_TOPIC.to_owned(), line.clone()));
            }
            self.writer
                .write_camera(&overhead_topic(c.id, reference), &record, None)?;
        }
        let mut bytes = Vec::with_capacity(scene.encoded_len().unwrap_or(0));
        scene.encode(&mut bytes).context("encoding a SceneUpdate")?;
        self.writer.write_raw(&self.scene, time_ns, &bytes)?;
        self.field_frames += 1;
        Ok(())
    }

    /// Writes the queued robot frames up to `until_ns` (all with `None`), oldest first.
    fn flush_robot_frames(&mut self, until_ns: Option<u64>) -> anyhow::Result<()> {
        self.robot_frames.sort_by_key(|f| f.time_ns);
        let due = self
            .robot_frames
            .iter()
            .take_while(|f| until_ns.is_none_or(|t| f.time_ns <= t))
            .count();
        for f in self.robot_frames.drain(..due) {
            self.writer
                .write_camera(&f.topic, &f.record, Some(&f.image))?;
            self.robot_frames_written += 1;
        }
        Ok(())
    }

    /// Finishes the recording (indexed, renamed into place); says what it holds. Nothing
    /// written: no file (the `.partial` removed), and an error.
    ///
    /// # Errors
    /// The file cannot be finished; no field frame was written.
    pub fn finish(mut self) -> anyhow::Result<PathBuf> {
        self.flush_robot_frames(None)?;
        if self.field_frames == 0 {
            self.writer.discard()?;
            anyhow::bail!(
                "{}: not written: the session had no overhead frame",
                self.path.display()
            );
        }
        self.writer.finish()?;
        eprintln!(
            "{}: {} field frames, {} robot camera frames",
            self.path.display(),
            self.field_frames,
            self.robot_frames_written
        );
        Ok(self.path)
    }
}
