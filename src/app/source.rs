//! Where the app's frames come from: a list of frame files or a recorded stream, read on demand
//! by index with a small cache, so stepping stays instant however long the recording is.

use std::collections::VecDeque;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use anyhow::Context as _;

use crate::frame::{Frame, load_frame};
use crate::sensors::SensorReadings;
use crate::streams as streams_api;

/// Nominal interval between frames that carry no time (frame files), nanoseconds: 25 fps.
pub const NOMINAL_FRAME_INTERVAL_NS: u64 = 40_000_000;

/// How many decoded frames the cache keeps.
pub const CACHE_FRAMES: usize = 8;

/// One frame as the app uses it, wherever it came from.
#[derive(Debug, Clone)]
pub struct LoadedFrame {
    /// The image.
    pub frame: Arc<Frame>,
    /// Capture time, nanoseconds since the start of the stream (frame files: index × 40 ms).
    pub time_ns: u64,
    /// The robot's sensor readings, when the source has them (NaN values already removed).
    pub sensors: Option<SensorReadings>,
    /// Other per-frame data of the source as (channel, JSON), shown as text.
    pub extra: Vec<(String, serde_json::Value)>,
    /// Problems found while reading this frame (NaN readings dropped, …).
    pub warnings: Vec<String>,
}

/// A sequence of frame files opened together (`eotn open a.uyvy b.png …`), stepped like a stream.
#[derive(Debug)]
pub struct FileSequence {
    paths: Vec<PathBuf>,
}

/// A recorded MCAP stream read through [`streams_api::StreamReader`].
pub struct StreamSource {
    path: PathBuf,
    reader: streams_api::StreamReader,
}

impl std::fmt::Debug for StreamSource {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("StreamSource")
            .field("path", &self.path)
            .field("frames", &self.reader.len())
            .finish()
    }
}

/// What is open.
#[derive(Debug)]
enum Kind {
    Files(FileSequence),
    Stream(Box<StreamSource>),
}

/// An open frame source with its cache.
#[derive(Debug)]
pub struct Source {
    kind: Kind,
    cache: VecDeque<(usize, LoadedFrame)>,
}

impl Source {
    /// Frame files, in the given order.
    ///
    /// # Errors
    /// When the list is empty.
    pub fn files(paths: Vec<PathBuf>) -> anyhow::Result<Self> {
        anyhow::ensure!(!paths.is_empty(), "no frame files given");
        Ok(Self {
            kind: Kind::Files(FileSequence { paths }),
            cache: VecDeque::new(),
        })
    }

    /// A recorded stream (reads only its index now; frames on demand).
    ///
    /// # Errors
    /// The reader's error, naming the file; a stream without frames.
    pub fn stream(path: &Path) -> anyhow::Result<Self> {
        let reader = streams_api::StreamReader::open(path)?;
        anyhow::ensure!(
            !reader.is_empty(),
            "{}: the stream holds no camera frames",
            path.display()
        );
        Ok(Self {
            kind: Kind::Stream(Box::new(StreamSource {
                path: path.to_owned(),
                reader,
            })),
            cache: VecDeque::new(),
        })
    }

    /// The files this source was opened from (for "reopen at start" and recent files).
    #[must_use]
    pub fn paths(&self) -> Vec<PathBuf> {
        match &self.kind {
            Kind::Files(f) => f.paths.clone(),
            Kind::Stream(s) => vec![s.path.clone()],
        }
    }

    /// True for a recorded stream (sensor readings, recorded times).
    #[must_use]
    pub const fn is_stream(&self) -> bool {
        matches!(self.kind, Kind::Stream(_))
    }

    /// A short description for the title and status line.
    #[must_use]
    pub fn label(&self) -> String {
        match &self.kind {
            Kind::Files(f) if f.paths.len() == 1 => crate::frame::display_name(&f.paths[0]),
            Kind::Files(f) => format!("{} frame files", f.paths.len()),
            Kind::Stream(s) => {
                let info = s.reader.info();
                format!("{} ({})", crate::frame::display_name(&s.path), info.source)
            }
        }
    }

    /// Number of frames.
    #[must_use]
    pub fn len(&self) -> usize {
        match &self.kind {
            Kind::Files(f) => f.paths.len(),
            Kind::Stream(s) => s.reader.len(),
        }
    }

    /// Never true: an empty source is refused when opening.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Time of frame `index`, nanoseconds since the stream's first frame.
    #[must_use]
    pub fn time_ns(&self, index: usize) -> u64 {
        match &self.kind {
            Kind::Files(_) => index as u64 * NOMINAL_FRAME_INTERVAL_NS,
            Kind::Stream(s) => {
                let first = s.reader.time_ns(0).unwrap_or(0);
                s.reader
                    .time_ns(index)
                    .map_or(0, |t| t.saturating_sub(first))
            }
        }
    }

    /// The last frame at or before `time_ns` (relative to the first frame).
    #[must_use]
    pub fn index_at_time(&self, time_ns: u64) -> usize {
        match &self.kind {
            Kind::Files(f) => usize::try_from(time_ns / NOMINAL_FRAME_INTERVAL_NS)
                .unwrap_or(usize::MAX)
                .min(f.paths.len().saturating_sub(1)),
            Kind::Stream(s) => {
                let first = s.reader.time_ns(0).unwrap_or(0);
                s.reader
                    .index_at_time(first.saturating_add(time_ns))
                    .min(s.reader.len().saturating_sub(1))
            }
        }
    }

    /// Problems the reader collected (skipped messages, unknown channels, truncation).
    #[must_use]
    pub fn warnings(&self) -> Vec<String> {
        match &self.kind {
            Kind::Files(_) => Vec::new(),
            Kind::Stream(s) => s.reader.warnings().to_vec(),
        }
    }

    /// Frame `index`, from the cache or read now (and cached).
    ///
    /// # Errors
    /// Index out of range; the file's read error, naming it.
    pub fn read(&mut self, index: usize) -> anyhow::Result<LoadedFrame> {
        if let Some(pos) = self.cache.iter().position(|(i, _)| *i == index) {
            // Most recently used at the back.
            if let Some(entry) = self.cache.remove(pos) {
                let frame = entry.1.clone();
                self.cache.push_back(entry);
                return Ok(frame);
            }
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
    pub fn read_uncached(&mut self, index: usize) -> anyhow::Result<LoadedFrame> {
        anyhow::ensure!(
            index < self.len(),
            "frame {index} is past the end ({} frames)",
            self.len()
        );
        let time_ns = self.time_ns(index);
        match &mut self.kind {
            Kind::Files(f) => {
                let path = &f.paths[index];
                let frame = load_frame(path, None)?;
                let mut warnings = Vec::new();
                let side = sensor_side_file(path);
                let sensors = if side.exists() {
                    match load_side_sensors(&side) {
                        Ok((r, w)) => {
                            warnings.extend(w);
                            Some(r)
                        }
                        Err(e) => {
                            warnings.push(format!("{e:#}; frame shown without sensor readings"));
                            None
                        }
                    }
                } else {
                    None
                };
                Ok(LoadedFrame {
                    frame: Arc::new(frame),
                    time_ns,
                    sensors,
                    extra: Vec::new(),
                    warnings,
                })
            }
            Kind::Stream(s) => {
                let seen = s.reader.warnings().len();
                let record = s
                    .reader
                    .read(index)
                    .with_context(|| format!("frame {index}"))?;
                // What the reader repaired in this frame (NaN readings read as missing, bad
                // JSON skipped) belongs to this frame's warnings too.
                let label = crate::frame::display_name(&s.path);
                let mut warnings: Vec<String> = s.reader.warnings()
                    [seen.min(s.reader.warnings().len())..]
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
                    extra.insert(0, ("/ground_truth".to_owned(), g));
                }
                if let Some(r) = record.recognition {
                    extra.insert(0, ("/recognition".to_owned(), r));
                }
                Ok(LoadedFrame {
                    frame: Arc::new(record.frame),
                    time_ns,
                    sensors,
                    extra,
                    warnings,
                })
            }
        }
    }
}

/// The sensor side file of a frame file: `NAME.sensors.json` beside `NAME.uyvy` (or `.png`…),
/// one JSON object with the fields of the sensor schema.
#[must_use]
pub fn sensor_side_file(frame: &Path) -> PathBuf {
    let stem = frame
        .file_stem()
        .map_or_else(|| "frame".into(), |s| s.to_string_lossy().into_owned());
    frame.with_file_name(format!("{stem}.sensors.json"))
}

/// Reads a sensor side file. `NaN`, `Infinity` (as Python writes them) and non-finite values are
/// read as missing; the second value names each such reading, as warnings for the status area.
///
/// # Errors
/// An unreadable file, text that is not JSON, or JSON that is not a sensor reading, naming the
/// file.
pub fn load_side_sensors(path: &Path) -> anyhow::Result<(SensorReadings, Vec<String>)> {
    let bytes = std::fs::read(path).with_context(|| format!("{}: cannot read", path.display()))?;
    let (value, replaced) = crate::streams::schema::parse_json_lenient(&bytes)
        .map_err(|e| anyhow::anyhow!("{}: not JSON ({e})", path.display()))?;
    let mut dropped: Vec<String> = if replaced {
        non_finite_keys(&String::from_utf8_lossy(&bytes), &value)
    } else {
        Vec::new()
    };
    let readings: SensorReadings = serde_json::from_value(value)
        .with_context(|| format!("{}: not a sensor reading", path.display()))?;
    let (clean, more) = readings.sanitised();
    dropped.extend(more.into_iter().map(str::to_owned));
    let warnings = if dropped.is_empty() {
        Vec::new()
    } else {
        vec![format!(
            "{}: non-finite sensor readings read as missing: {}",
            path.display(),
            dropped.join(", ")
        )]
    };
    Ok((clean, warnings))
}

/// Keys of the top-level object that became `null` because the text gave them `NaN`,
/// `Infinity` or `-Infinity`.
fn non_finite_keys(text: &str, value: &serde_json::Value) -> Vec<String> {
    let Some(obj) = value.as_object() else {
        return Vec::new();
    };
    obj.iter()
        .filter(|(_, v)| v.is_null())
        .filter(|(k, _)| {
            let quoted = format!("\"{k}\"");
            text.match_indices(&quoted).any(|(at, _)| {
                let rest = text[at + quoted.len()..].trim_start();
                rest.strip_prefix(':').is_some_and(|r| {
                    let r = r.trim_start();
                    ["NaN", "Infinity", "-Infinity"]
                        .iter()
                        .any(|t| r.starts_with(t))
                })
            })
        })
        .map(|(k, _)| k.clone())
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn side_file_names_non_finite_readings_and_keeps_the_rest() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("f.sensors.json");
        std::fs::write(
            &p,
            r#"{"head_pan_rad": NaN, "head_tilt_rad": -0.2, "pan_pwm": -Infinity, "neck_tilt_rad": null}"#,
        )
        .unwrap();
        let (r, w) = load_side_sensors(&p).unwrap();
        assert_eq!(r.head_pan_rad, None);
        assert_eq!(r.head_tilt_rad, Some(-0.2));
        assert_eq!(r.pan_pwm, None);
        assert_eq!(w.len(), 1);
        assert!(
            w[0].contains("head_pan_rad") && w[0].contains("pan_pwm"),
            "{w:?}"
        );
        assert!(
            !w[0].contains("neck_tilt_rad"),
            "null is missing, not NaN: {w:?}"
        );
        assert!(w[0].contains("f.sensors.json"));
    }

    #[test]
    fn side_file_errors_name_the_file() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("g.sensors.json");
        std::fs::write(&p, "{\"head_pan_rad\": ").unwrap();
        let e = format!("{:#}", load_side_sensors(&p).unwrap_err());
        assert!(
            e.contains("g.sensors.json") && e.contains("not JSON"),
            "{e}"
        );
        std::fs::write(&p, "{\"head_pan_rad\": \"left\"}").unwrap();
        let e = format!("{:#}", load_side_sensors(&p).unwrap_err());
        assert!(e.contains("not a sensor reading"), "{e}");
        assert_eq!(
            sensor_side_file(Path::new("/x/a.uyvy")),
            Path::new("/x/a.sensors.json")
        );
    }
}
