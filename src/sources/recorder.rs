//! Recording any source into an MCAP stream the user names: the frames with their sensor
//! readings and channels, times from the first recorded frame, the source's kind kept as the
//! stream's source so the recording opens as the same camera kind.

use std::path::{Path, PathBuf};

use super::{SourceFrame, SourceInfo};
use crate::streams::{StreamError, StreamInfo, StreamWriter};

/// An MCAP stream being written from a source's frames. The file appears under its name only
/// when [`Recorder::finish`] succeeds (until then it is `NAME.partial`, readable up to its last
/// complete chunk after a crash).
#[derive(Debug)]
pub struct Recorder {
    path: PathBuf,
    writer: StreamWriter,
    /// The first recorded frame's source time, nanoseconds: recorded times start at 0.
    first_ns: Option<u64>,
    /// The last recorded time (relative), nanoseconds: later frames must come after it.
    last_ns: Option<u64>,
    frames: usize,
    skipped: usize,
}

impl Recorder {
    /// Starts recording frames of `source` into `path`.
    ///
    /// # Errors
    /// The file cannot be created, naming it.
    pub fn create(path: &Path, source: &SourceInfo) -> Result<Self, StreamError> {
        let info = StreamInfo {
            source: source.stream_source.clone(),
            description: format!("recorded by eotn from {}", source.label),
        };
        Ok(Self {
            path: path.to_owned(),
            writer: StreamWriter::create(path, &info)?,
            first_ns: None,
            last_ns: None,
            frames: 0,
            skipped: 0,
        })
    }

    /// Appends a frame; returns false (and writes nothing) for a frame not later than the last
    /// one recorded (a recorded source stepped backwards, or a repeat).
    ///
    /// # Errors
    /// The frame cannot be written (odd width, disk full), naming the file.
    pub fn record(&mut self, frame: &SourceFrame) -> Result<bool, StreamError> {
        let first = *self.first_ns.get_or_insert(frame.time_ns);
        let time_ns = frame.time_ns.saturating_sub(first);
        if self.last_ns.is_some_and(|last| time_ns <= last) {
            self.skipped += 1;
            return Ok(false);
        }
        let mut record = frame.clone().into_record();
        record.time_ns = time_ns;
        self.writer.write(&record)?;
        self.last_ns = Some(time_ns);
        self.frames += 1;
        Ok(true)
    }

    /// Frames recorded so far.
    #[must_use]
    pub const fn frames(&self) -> usize {
        self.frames
    }

    /// Frames refused because they were not later than the last one.
    #[must_use]
    pub const fn skipped(&self) -> usize {
        self.skipped
    }

    /// The stream being written.
    #[must_use]
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Writes the index and moves the file into place; returns the frames recorded.
    ///
    /// # Errors
    /// I/O errors naming the file.
    pub fn finish(self) -> Result<usize, StreamError> {
        self.writer.finish()?;
        Ok(self.frames)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sources::{FileSource, FrameSource, StreamSource};

    fn frames_in(dir: &Path, n: usize) -> Vec<PathBuf> {
        (0..n)
            .map(|i| {
                let p = dir.join(format!("{i}.uyvy"));
                let mut bytes = vec![128u8; 208 * 160 * 2];
                bytes
                    .iter_mut()
                    .skip(1)
                    .step_by(2)
                    .for_each(|b| *b = u8::try_from(i * 40).unwrap());
                std::fs::write(&p, bytes).unwrap();
                p
            })
            .collect()
    }

    #[test]
    fn a_recording_reads_back_as_the_frames_it_was_given() {
        let dir = tempfile::tempdir().unwrap();
        let mut files = FileSource::new(frames_in(dir.path(), 3), None).unwrap();
        let out = dir.path().join("rec.mcap");
        let mut rec = Recorder::create(&out, &files.info()).unwrap();
        for _ in 0..3 {
            let mut f = files.grab().unwrap();
            f.extra.push((
                "/world_model/robot2".to_owned(),
                serde_json::json!({"x_cm": 1.0}),
            ));
            assert!(rec.record(&f).unwrap());
        }
        assert_eq!(rec.finish().unwrap(), 3);
        let mut back = StreamSource::open(&out).unwrap();
        assert_eq!(back.info().stream_source, "files");
        let r = back.recorded().unwrap();
        assert_eq!(r.len(), 3);
        let f = r.read(2).unwrap();
        assert_eq!(f.frame.pixel(0, 0).unwrap().y, 80);
        assert_eq!(f.time_ns, 2 * crate::sources::NOMINAL_FRAME_INTERVAL_NS);
        assert!(f.channel("/world_model/robot2").is_some());
    }

    #[test]
    fn a_frame_not_later_than_the_last_is_not_recorded() {
        let dir = tempfile::tempdir().unwrap();
        let mut files = FileSource::new(frames_in(dir.path(), 2), None).unwrap();
        let mut rec = Recorder::create(&dir.path().join("r.mcap"), &files.info()).unwrap();
        let r = files.recorded().unwrap();
        let (a, b) = (r.read(0).unwrap(), r.read(1).unwrap());
        assert!(rec.record(&a).unwrap());
        assert!(rec.record(&b).unwrap());
        assert!(!rec.record(&a).unwrap());
        assert_eq!((rec.frames(), rec.skipped()), (2, 1));
    }
}
