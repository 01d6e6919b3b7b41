//! The open recorded source with a small cache of decoded frames, so stepping stays instant
//! however long the recording is.

use std::collections::VecDeque;
use std::path::{Path, PathBuf};

use super::player::Timeline;
use crate::camera::CameraId;
use crate::live::RobotFrames;
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
    /// A recording's canonical path: with the topic, what names its cameras ([`CameraId`]).
    canonical: Option<PathBuf>,
    /// A live robot's camera shown: its cameras are asked for as the robot advertises them.
    robot: Option<RobotFrames>,
    cache: VecDeque<(usize, SourceFrame)>,
    /// A recording's reader on a thread of its own, reading the frame after the one read last.
    prefetch: Option<Prefetch>,
}

/// Reads the frame after the one shown on a thread of its own, with its own reader of the
/// recording, while the shown frame is worked on: playing a 1920×1200 stream, reading and
/// decompressing a frame took as long as classifying it, and the second core was idle.
struct Prefetch {
    wanted: std::sync::mpsc::Sender<usize>,
    ready: std::sync::mpsc::Receiver<(usize, SourceFrame)>,
    /// The frame asked for and not yet taken.
    pending: Option<usize>,
}

impl Prefetch {
    /// A reader of camera `camera` of the recording at `path` on its own thread; `None` when
    /// the thread cannot start (reading goes on without it).
    fn start(path: &Path, camera: Option<&str>) -> Option<Self> {
        let (wanted, requests) = std::sync::mpsc::channel::<usize>();
        let (done, ready) = std::sync::mpsc::channel();
        let (path, camera) = (path.to_owned(), camera.map(str::to_owned));
        std::thread::Builder::new()
            .name("eotn-prefetch".to_owned())
            .spawn(move || {
                let Ok(mut reader) = StreamSource::open_camera(&path, camera.as_deref()) else {
                    return;
                };
                // Ends when the source is dropped (its sender with it).
                while let Ok(index) = requests.recv() {
                    // A failed read is left to the reader of the shown frame to report.
                    if let Ok(frame) = reader.read(index)
                        && done.send((index, frame)).is_err()
                    {
                        return;
                    }
                }
            })
            .ok()?;
        Some(Self {
            wanted,
            ready,
            pending: None,
        })
    }
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
            canonical: None,
            robot: None,
            cache: VecDeque::new(),
            prefetch: None,
        }
    }

    /// One camera of a live robot (its frames as they arrive).
    #[must_use]
    pub fn robot(frames: RobotFrames) -> Self {
        let mut source = Self::new(Box::new(frames.clone()));
        source.robot = Some(frames);
        source
    }

    /// The live robot's camera shown, when the source is one.
    #[must_use]
    pub const fn robot_frames(&self) -> Option<&RobotFrames> {
        self.robot.as_ref()
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
        source.prefetch = Prefetch::start(path, shown.as_deref());
        source.camera = shown;
        source.cameras = cameras;
        source.canonical = Some(std::fs::canonicalize(path).unwrap_or_else(|_| path.to_owned()));
        Ok(source)
    }

    /// The camera shown (its image topic): a recording's or a live robot's; `None` for frame
    /// files and a robot that has not advertised a camera yet.
    #[must_use]
    pub fn camera(&self) -> Option<String> {
        match &self.robot {
            Some(r) => r.camera(),
            None => self.camera.clone(),
        }
    }

    /// Every camera of the recording or live robot, by image topic (the camera picker's list).
    #[must_use]
    pub fn cameras(&self) -> Vec<String> {
        match &self.robot {
            Some(r) => r.cameras(),
            None => self.cameras.clone(),
        }
    }

    /// The camera `topic` of this source as a [`CameraId`]: a recording's robot camera, an
    /// overhead recording's camera, a live robot's image channel; `None` for frame files.
    #[must_use]
    pub fn camera_id_of(&self, topic: &str) -> Option<CameraId> {
        if let Some(r) = &self.robot {
            return Some(CameraId::live(&r.url().to_string(), topic));
        }
        let path = self.canonical.as_deref()?;
        // The stream's kind, not the shown camera's: a session recording's robot cameras keep
        // the ids they had while its overhead camera was shown.
        let kind = match self.info.kind {
            crate::sources::SourceKind::Stream => {
                crate::sources::CameraKind::of_stream_source(&self.info.stream_source)
            }
            _ => self.info.camera,
        };
        Some(match kind {
            crate::sources::CameraKind::Robot => CameraId::recording(path, topic),
            crate::sources::CameraKind::Overhead => {
                CameraId::overhead(&path.to_string_lossy(), topic)
            }
        })
    }

    /// The camera shown as a [`CameraId`].
    #[must_use]
    pub fn camera_id(&self) -> Option<CameraId> {
        self.camera_id_of(&self.camera()?)
    }

    /// Every camera as a [`CameraId`], the picker's order.
    #[must_use]
    pub fn camera_ids(&self) -> Vec<CameraId> {
        self.cameras()
            .iter()
            .filter_map(|t| self.camera_id_of(t))
            .collect()
    }

    /// The recording this source was opened from (its canonical path), for a stream.
    #[must_use]
    pub fn recording(&self) -> Option<&Path> {
        self.canonical.as_deref()
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
        self.take_prefetched(index);
        let frame = if let Some(pos) = self.cache.iter().position(|(i, _)| *i == index)
            && let Some(entry) = self.cache.remove(pos)
        {
            // Most recently used at the back.
            let frame = entry.1.clone();
            self.cache.push_back(entry);
            frame
        } else {
            let frame = self.read_uncached(index)?;
            self.cache_frame(index, frame.clone());
            frame
        };
        self.prefetch_after(index);
        Ok(frame)
    }

    fn cache_frame(&mut self, index: usize, frame: SourceFrame) {
        if self.cache.iter().any(|(i, _)| *i == index) {
            return;
        }
        self.cache.push_back((index, frame));
        while self.cache.len() > CACHE_FRAMES {
            self.cache.pop_front();
        }
    }

    /// Puts what the prefetch thread has read into the cache; when it is reading `index`
    /// right now, waits for it rather than reading it twice.
    fn take_prefetched(&mut self, index: usize) {
        let Some(p) = self.prefetch.as_mut() else {
            return;
        };
        let mut got = Vec::new();
        if p.pending == Some(index) {
            if let Ok(r) = p.ready.recv_timeout(std::time::Duration::from_secs(5)) {
                got.push(r);
            }
            p.pending = None;
        }
        got.extend(p.ready.try_iter());
        if got.iter().any(|(i, _)| Some(*i) == p.pending) {
            p.pending = None;
        }
        for (i, frame) in got {
            self.cache_frame(i, frame);
        }
    }

    /// Asks the prefetch thread for the frame after `index`, unless it is cached or asked for.
    fn prefetch_after(&mut self, index: usize) {
        let next = index + 1;
        if next >= self.len() || self.cache.iter().any(|(i, _)| *i == next) {
            return;
        }
        if let Some(p) = self.prefetch.as_mut()
            && p.pending.is_none()
        {
            if p.wanted.send(next).is_ok() {
                p.pending = Some(next);
            } else {
                self.prefetch = None;
            }
        }
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
    fn a_stream_read_in_order_gives_the_frames_the_recording_holds() {
        use crate::frame::{Frame, Yuv};
        use crate::streams::{FrameRecord, StreamInfo, StreamWriter};
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("s.mcap");
        let info = StreamInfo {
            source: "robot".to_owned(),
            description: "prefetch".to_owned(),
        };
        let mut w = StreamWriter::create(&path, &info).unwrap();
        for k in 0..12u8 {
            let f = Frame::filled_uyvy(16, 8, Yuv::new(20 + k, 128, 128)).unwrap();
            w.write(&FrameRecord::new(u64::from(k) * 1_000_000, f))
                .unwrap();
        }
        w.finish().unwrap();
        let mut s = Source::stream(&path).unwrap();
        // In order (the next frame read ahead on the prefetch thread), then back and forth.
        let order: Vec<usize> = (0..12).chain([3, 4, 11, 0, 1]).collect();
        for i in order {
            let got = s.read(i).unwrap();
            let want = s.read_uncached(i).unwrap();
            assert_eq!(got.frame, want.frame, "frame {i}");
            assert_eq!(got.time_ns, want.time_ns, "frame {i}");
        }
        assert!(s.cached() <= CACHE_FRAMES);
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
