//! The open recorded source with a small cache of decoded frames, so stepping stays instant
//! however long the recording is.

use std::collections::VecDeque;
use std::path::{Path, PathBuf};

use super::player::Timeline;
use crate::sources::{
    FileSource, RecordedSource, SourceError, SourceFrame, SourceInfo, SourceKind, StreamSource,
};

/// How many decoded frames the cache keeps.
pub const CACHE_FRAMES: usize = 8;

/// A recorded source (stream or frame files) with its cache.
pub struct Source {
    inner: Box<dyn RecordedSource>,
    info: SourceInfo,
    /// A recording's camera shown (its image topic), and every camera it has.
    camera: Option<String>,
    cameras: Vec<String>,
    cache: VecDeque<(usize, SourceFrame)>,
}

impl std::fmt::Debug for Source {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Source")
            .field("info", &self.info)
            .field("frames", &self.inner.len())
            .field("cached", &self.cache.len())
            .finish_non_exhaustive()
    }
}

impl Source {
    /// Any recorded source.
    #[must_use]
    pub fn new(inner: Box<dyn RecordedSource>) -> Self {
        let info = inner.info();
        Self {
            inner,
            info,
            camera: None,
            cameras: Vec::new(),
            cache: VecDeque::new(),
        }
    }

    /// Frame files, in the given order.
    ///
    /// # Errors
    /// When the list is empty.
    pub fn files(paths: Vec<PathBuf>) -> Result<Self, SourceError> {
        Ok(Self::new(Box::new(FileSource::new(paths, None)?)))
    }

    /// A recorded stream (reads only its index now; frames on demand).
    ///
    /// # Errors
    /// The reader's error, naming the file; a stream without frames.
    pub fn stream(path: &Path) -> Result<Self, SourceError> {
        Self::stream_camera(path, None)
    }

    /// The camera `camera` (an image topic; `None`: the first) of a recording.
    ///
    /// # Errors
    /// As [`Source::stream`]; a camera the recording does not have (listing those it has).
    pub fn stream_camera(path: &Path, camera: Option<&str>) -> Result<Self, SourceError> {
        let stream = StreamSource::open_camera(path, camera)?;
        let shown = stream.camera().map(str::to_owned);
        let cameras = stream.cameras();
        let mut source = Self::new(Box::new(stream));
        source.camera = shown;
        source.cameras = cameras;
        Ok(source)
    }

    /// The recording's camera shown (its image topic); `None` for frame files and live sources.
    #[must_use]
    pub fn camera(&self) -> Option<&str> {
        self.camera.as_deref()
    }

    /// Every camera of the recording, by image topic (the camera picker's list).
    #[must_use]
    pub fn cameras(&self) -> &[String] {
        &self.cameras
    }

    /// What it is: kind, label, camera kind, files.
    #[must_use]
    pub const fn info(&self) -> &SourceInfo {
        &self.info
    }

    /// Says which camera made the frames: frame files (JPEG, PNG, …) do not say it themselves,
    /// so the user does (Overhead ▸ This is an overhead camera).
    pub fn set_camera_kind(&mut self, kind: crate::sources::CameraKind) {
        self.info.camera = kind;
    }

    /// Asks the source again what it is (a robot names itself once connected).
    pub fn refresh_info(&mut self) {
        self.info = self.inner.info();
    }

    /// The files this source was opened from (for "reopen at start" and recent files).
    #[must_use]
    pub fn paths(&self) -> Vec<PathBuf> {
        self.info.paths.clone()
    }

    /// True for a recorded stream (sensor readings, recorded times).
    #[must_use]
    pub fn is_stream(&self) -> bool {
        self.info.kind == SourceKind::Stream
    }

    /// A short description for the title and status line.
    #[must_use]
    pub fn label(&self) -> String {
        self.info.label.clone()
    }

    /// Number of frames.
    #[must_use]
    pub fn len(&self) -> usize {
        self.inner.len()
    }

    /// Never true: an empty source is refused when opening.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The first frame that can be read (0 except for a live robot's, whose oldest frames may
    /// have left memory).
    #[must_use]
    pub fn first_index(&self) -> usize {
        self.inner.first_index()
    }

    /// Time of frame `index`, nanoseconds since the first frame.
    #[must_use]
    pub fn time_ns(&self, index: usize) -> u64 {
        self.inner.time_ns(index)
    }

    /// The first frame's own time, nanoseconds on the recording's clock (see
    /// [`RecordedSource::start_ns`]).
    #[must_use]
    pub fn start_ns(&self) -> u64 {
        self.inner.start_ns()
    }

    /// The last frame at or before `time_ns` (relative to the first frame).
    #[must_use]
    pub fn index_at_time(&self, time_ns: u64) -> usize {
        self.inner.index_at_time(time_ns)
    }

    /// Problems the reader collected (skipped messages, unknown channels, truncation).
    #[must_use]
    pub fn warnings(&self) -> Vec<String> {
        self.inner.warnings()
    }

    /// Frame `index`, from the cache or read now (and cached).
    ///
    /// # Errors
    /// Index out of range; the file's read error, naming it.
    pub fn read(&mut self, index: usize) -> Result<SourceFrame, SourceError> {
        if self.info.kind == SourceKind::Network {
            // A robot's frames are in memory already, and the newest one may still gain the
            // sensor readings that follow its image: never serve it from a stale copy.
            return self.inner.read(index);
        }
        if let Some(pos) = self.cache.iter().position(|(i, _)| *i == index)
            && let Some(entry) = self.cache.remove(pos)
        {
            // Most recently used at the back.
            let frame = entry.1.clone();
            self.cache.push_back(entry);
            return Ok(frame);
        }
        let frame = self.read_uncached(index)?;
        self.cache.push_back((index, frame.clone()));
        while self.cache.len() > CACHE_FRAMES {
            self.cache.pop_front();
        }
        Ok(frame)
    }

    /// Number of frames in the cache (for tests and the status line).
    #[must_use]
    pub fn cached(&self) -> usize {
        self.cache.len()
    }

    /// Frame `index` read now, bypassing the cache (whole-stream scans must not evict the frames
    /// the user is stepping through).
    ///
    /// # Errors
    /// Index out of range; the file's read error, naming it.
    pub fn read_uncached(&mut self, index: usize) -> Result<SourceFrame, SourceError> {
        self.inner.read(index)
    }
}

impl Timeline for Source {
    fn frames(&self) -> usize {
        self.len()
    }

    fn time_ns(&self, index: usize) -> u64 {
        self.inner.time_ns(index)
    }

    fn index_at_time(&self, time_ns: u64) -> usize {
        self.inner.index_at_time(time_ns)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frames(dir: &Path, n: usize) -> Vec<PathBuf> {
        (0..n)
            .map(|i| {
                let p = dir.join(format!("{i:02}.uyvy"));
                std::fs::write(&p, vec![128u8; 208 * 160 * 2]).unwrap();
                p
            })
            .collect()
    }

    #[test]
    fn the_cache_keeps_the_most_recently_read_frames_only() {
        let dir = tempfile::tempdir().unwrap();
        let mut s = Source::files(frames(dir.path(), CACHE_FRAMES + 3)).unwrap();
        for i in 0..CACHE_FRAMES + 3 {
            s.read(i).unwrap();
        }
        assert_eq!(s.cached(), CACHE_FRAMES);
        s.read_uncached(0).unwrap();
        assert_eq!(
            s.cached(),
            CACHE_FRAMES,
            "uncached reads leave the cache alone"
        );
        for gone in ["00.uyvy", "10.uyvy"] {
            std::fs::remove_file(dir.path().join(gone)).unwrap();
        }
        assert!(s.read(10).is_ok(), "a cached frame is not read again");
        assert!(s.read(0).is_err(), "an evicted frame is read again");
    }

    #[test]
    fn frame_files_are_a_robot_camera_source_that_is_not_a_stream() {
        let dir = tempfile::tempdir().unwrap();
        let s = Source::files(frames(dir.path(), 2)).unwrap();
        assert!(!s.is_stream());
        assert_eq!(s.info().camera, crate::sources::CameraKind::Robot);
        assert_eq!(s.label(), "2 frame files");
    }
}
