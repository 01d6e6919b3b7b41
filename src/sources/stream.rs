//! A recorded MCAP stream as a source, read through [`StreamReader`] one frame at a time.

use std::path::{Path, PathBuf};

use super::{
    CameraKind, FrameSource, RecordedSource, SourceError, SourceFrame, SourceInfo, SourceKind,
    SourceSettings,
};
use crate::streams::{GROUND_TRUTH_TOPIC, RECOGNITION_TOPIC, StreamReader};

/// A recorded stream: frames by index and time, with their sensor readings and channels.
pub struct StreamSource {
    path: PathBuf,
    reader: StreamReader,
    connected: bool,
    /// Frames grabbed so far: [`FrameSource::grab`] gives frame `next % len` next.
    next: usize,
}

impl std::fmt::Debug for StreamSource {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("StreamSource")
            .field("path", &self.path)
            .field("frames", &self.reader.len())
            .finish_non_exhaustive()
    }
}

impl StreamSource {
    /// Opens a stream (reads only its index now; frames on demand).
    ///
    /// # Errors
    /// The reader's error, naming the file; a stream without frames.
    pub fn open(path: &Path) -> Result<Self, SourceError> {
        Self::open_camera(path, None)
    }

    /// Opens the camera `camera` (an image topic) of a recording; `None`: its first.
    ///
    /// # Errors
    /// As [`StreamSource::open`]; a camera the recording does not have (listing those it has).
    pub fn open_camera(path: &Path, camera: Option<&str>) -> Result<Self, SourceError> {
        let reader = StreamReader::open_camera(path, camera)?;
        if reader.is_empty() {
            return Err(SourceError::Empty(format!(
                "{}: the stream holds no camera frames",
                path.display()
            )));
        }
        Ok(Self {
            path: path.to_owned(),
            reader,
            connected: true,
            next: 0,
        })
    }

    /// The camera read (its image topic).
    #[must_use]
    pub fn camera(&self) -> Option<&str> {
        self.reader.camera()
    }

    /// Every camera of the recording, by image topic.
    #[must_use]
    pub fn cameras(&self) -> Vec<String> {
        self.reader
            .image_topics()
            .iter()
            .map(|t| t.topic.clone())
            .collect()
    }

    /// The files the camera read is recognised with (the stream's defaults, the sidecar's in
    /// their place).
    ///
    /// # Errors
    /// A sidecar that is there but cannot be used.
    pub fn camera_files(&self) -> Result<crate::camera::CameraFiles, crate::camera::SidecarError> {
        self.reader.camera_files()
    }

    /// The stream file.
    #[must_use]
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The stream's metadata (source kind, description).
    #[must_use]
    pub fn stream_info(&self) -> &crate::streams::StreamInfo {
        self.reader.info()
    }

    fn label(&self) -> String {
        format!(
            "{} ({})",
            crate::frame::display_name(&self.path),
            self.reader.info().source
        )
    }
}

impl FrameSource for StreamSource {
    fn info(&self) -> SourceInfo {
        let source = self.reader.info().source.clone();
        SourceInfo {
            kind: SourceKind::Stream,
            label: self.label(),
            camera: CameraKind::of_stream_camera(&source, self.reader.camera()),
            paths: vec![self.path.clone()],
            stream_source: source,
        }
    }

    fn connect(&mut self) -> Result<(), SourceError> {
        self.connected = true;
        Ok(())
    }

    fn disconnect(&mut self) {
        self.connected = false;
    }

    fn is_connected(&self) -> bool {
        self.connected
    }

    fn settings(&self) -> SourceSettings {
        let n = self.reader.len();
        let span_ns = self.time_ns(n.saturating_sub(1));
        let frame_rate = (n > 1 && span_ns > 0).then(|| (n - 1) as f64 * 1e9 / span_ns as f64);
        SourceSettings {
            frame_rate,
            ..SourceSettings::default()
        }
    }

    fn grab(&mut self) -> Result<SourceFrame, SourceError> {
        if !self.connected {
            return Err(SourceError::NotConnected(self.label()));
        }
        let next = self.next;
        self.next += 1;
        super::grab_looping(self, next)
    }

    fn recorded(&mut self) -> Option<&mut dyn RecordedSource> {
        Some(self)
    }
}

impl RecordedSource for StreamSource {
    fn len(&self) -> usize {
        self.reader.len()
    }

    fn time_ns(&self, index: usize) -> u64 {
        let first = self.reader.time_ns(0).unwrap_or(0);
        self.reader
            .time_ns(index)
            .map_or(0, |t| t.saturating_sub(first))
    }

    fn start_ns(&self) -> u64 {
        self.reader.time_ns(0).unwrap_or(0)
    }

    fn index_at_time(&self, time_ns: u64) -> usize {
        let first = self.reader.time_ns(0).unwrap_or(0);
        self.reader
            .index_at_time(first.saturating_add(time_ns))
            .min(self.reader.len().saturating_sub(1))
    }

    fn read(&mut self, index: usize) -> Result<SourceFrame, SourceError> {
        let time_ns = self.time_ns(index);
        let seen = self.reader.warnings().len();
        let record = self.reader.read(index)?;
        // What the reader repaired in this frame (NaN readings read as missing, bad JSON
        // skipped) belongs to this frame's warnings too.
        let label = crate::frame::display_name(&self.path);
        let all = self.reader.warnings();
        let mut warnings: Vec<String> = all[seen.min(all.len())..]
            .iter()
            .map(|w| format!("{label}: {w}"))
            .collect();
        let sensors = record.sensors.map(|r| {
            let (clean, dropped) = r.sanitised();
            if !dropped.is_empty() {
                warnings.push(format!(
                    "frame {index}: non-finite sensor readings dropped: {}",
                    dropped.join(", ")
                ));
            }
            clean
        });
        let mut extra = record.extra;
        if let Some(g) = record.ground_truth {
            extra.insert(0, (GROUND_TRUTH_TOPIC.to_owned(), g));
        }
        if let Some(r) = record.recognition {
            extra.insert(0, (RECOGNITION_TOPIC.to_owned(), r));
        }
        Ok(SourceFrame {
            frame: std::sync::Arc::new(record.frame),
            time_ns,
            sensors,
            extra,
            warnings,
        })
    }

    fn warnings(&self) -> Vec<String> {
        self.reader.warnings().to_vec()
    }
}
