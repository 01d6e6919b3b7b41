//! Frame files as a source: `.uyvy`/`.yuv`/`.raw` frames, PNG and JPEG images, each with an
//! optional sensor side file (`NAME.sensors.json`), stepped like a stream at a nominal 25 fps.

use std::path::{Path, PathBuf};

use anyhow::Context as _;

use super::{
    CameraKind, FrameSource, NOMINAL_FRAME_INTERVAL_NS, RecordedSource, SourceError, SourceFrame,
    SourceInfo, SourceKind, SourceSettings,
};
use crate::frame::{is_image_file, load_frame};
use crate::sensors::SensorReadings;

/// File extensions read as raw UYVY frames.
pub const RAW_EXTENSIONS: [&str; 3] = ["uyvy", "yuv", "raw"];

/// True for files the frame loaders read.
#[must_use]
pub fn is_frame_file(path: &Path) -> bool {
    is_image_file(path)
        || path
            .extension()
            .is_some_and(|e| RAW_EXTENSIONS.iter().any(|r| e.eq_ignore_ascii_case(r)))
}

/// Expands the arguments: files (frames and recordings) and rosbag2 folders (with
/// `metadata.yaml`) stay, other folders give their frame files sorted by name.
///
/// # Errors
/// A path that does not exist, or a folder without frames.
pub fn expand_frame_paths(paths: &[PathBuf]) -> anyhow::Result<Vec<PathBuf>> {
    let mut out = Vec::new();
    for p in paths {
        // A rosbag2 bag is a folder too: it stays one recording, never a folder of frames.
        if crate::streams::is_bag_folder(p) {
            out.push(p.clone());
        } else if p.is_dir() {
            let mut found: Vec<PathBuf> = std::fs::read_dir(p)
                .with_context(|| format!("{}: cannot list folder", p.display()))?
                .filter_map(Result::ok)
                .map(|e| e.path())
                .filter(|f| f.is_file() && is_frame_file(f))
                .collect();
            anyhow::ensure!(
                !found.is_empty(),
                "{}: no frame files (.uyvy, .yuv, .raw, .png, .jpg) in folder, and no metadata.yaml, so not a rosbag2 bag either",
                p.display()
            );
            found.sort();
            out.extend(found);
        } else if p.exists() {
            out.push(p.clone());
        } else {
            anyhow::bail!("{}: no such file or folder", p.display());
        }
    }
    anyhow::ensure!(!out.is_empty(), "no input frames given");
    Ok(out)
}

/// A sequence of frame files opened together (`eotn open a.uyvy b.png …`).
#[derive(Debug)]
pub struct FileSource {
    paths: Vec<PathBuf>,
    /// Size of raw files, (width, height) pixels; `None` infers it from the file length.
    size: Option<(usize, usize)>,
    connected: bool,
    /// Frames grabbed so far: [`FrameSource::grab`] gives frame `next % len` next.
    next: usize,
}

impl FileSource {
    /// Frame files, in the given order; raw files of `size` (inferred from the length when
    /// `None`).
    ///
    /// # Errors
    /// When the list is empty.
    pub fn new(paths: Vec<PathBuf>, size: Option<(usize, usize)>) -> Result<Self, SourceError> {
        if paths.is_empty() {
            return Err(SourceError::Empty("no frame files given".to_owned()));
        }
        Ok(Self {
            paths,
            size,
            connected: true,
            next: 0,
        })
    }

    /// The files, in order.
    #[must_use]
    pub fn paths(&self) -> &[PathBuf] {
        &self.paths
    }

    fn label(&self) -> String {
        match self.paths.as_slice() {
            [one] => crate::frame::display_name(one),
            many => format!("{} frame files", many.len()),
        }
    }
}

impl FrameSource for FileSource {
    fn info(&self) -> SourceInfo {
        SourceInfo {
            kind: SourceKind::Files,
            label: self.label(),
            camera: CameraKind::Robot,
            paths: self.paths.clone(),
            stream_source: "files".to_owned(),
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
        SourceSettings {
            frame_rate: Some(1e9 / NOMINAL_FRAME_INTERVAL_NS as f64),
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

impl RecordedSource for FileSource {
    fn len(&self) -> usize {
        self.paths.len()
    }

    fn time_ns(&self, index: usize) -> u64 {
        index as u64 * NOMINAL_FRAME_INTERVAL_NS
    }

    fn index_at_time(&self, time_ns: u64) -> usize {
        usize::try_from(time_ns / NOMINAL_FRAME_INTERVAL_NS)
            .unwrap_or(usize::MAX)
            .min(self.paths.len().saturating_sub(1))
    }

    fn read(&mut self, index: usize) -> Result<SourceFrame, SourceError> {
        let Some(path) = self.paths.get(index) else {
            return Err(SourceError::NoSuchFrame {
                label: self.label(),
                index,
                len: self.paths.len(),
            });
        };
        let mut out = SourceFrame::new(self.time_ns(index), load_frame(path, self.size)?);
        let side = sensor_side_file(path);
        if side.exists() {
            match load_side_sensors(&side) {
                Ok((r, w)) => {
                    out.warnings.extend(w);
                    out.sensors = Some(r);
                }
                Err(e) => out
                    .warnings
                    .push(format!("{e:#}; frame shown without sensor readings")),
            }
        }
        Ok(out)
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
    let bytes = crate::input_file::read_bounded(
        path,
        crate::input_file::MAX_SMALL_FILE_BYTES,
        "a sensor side file",
    )
    .with_context(|| format!("{}: cannot read", path.display()))?;
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

    #[test]
    fn frame_files_grab_in_order_and_start_again_after_the_last_with_later_times() {
        let dir = tempfile::tempdir().unwrap();
        let mut paths = Vec::new();
        for (i, y) in [10u8, 200].into_iter().enumerate() {
            let p = dir.path().join(format!("{i}.uyvy"));
            let mut bytes = vec![128u8; 208 * 160 * 2];
            bytes.iter_mut().skip(1).step_by(2).for_each(|b| *b = y);
            std::fs::write(&p, bytes).unwrap();
            paths.push(p);
        }
        let mut s = FileSource::new(paths, None).unwrap();
        let luma = |f: &SourceFrame| f.frame.pixel(0, 0).unwrap().y;
        let a = s.grab().unwrap();
        let b = s.grab().unwrap();
        let c = s.grab().unwrap();
        assert_eq!((luma(&a), luma(&b), luma(&c)), (10, 200, 10));
        assert_eq!(b.time_ns, NOMINAL_FRAME_INTERVAL_NS);
        assert_eq!(
            c.time_ns,
            2 * NOMINAL_FRAME_INTERVAL_NS,
            "times go on increasing"
        );
        s.disconnect();
        assert!(matches!(s.grab(), Err(SourceError::NotConnected(_))));
        let r = s.recorded().unwrap();
        assert!(matches!(
            r.read(5),
            Err(SourceError::NoSuchFrame { len: 2, .. })
        ));
    }

    #[test]
    fn frame_files_refuse_a_setting_they_do_not_have() {
        let mut s = FileSource::new(vec![PathBuf::from("a.uyvy")], None).unwrap();
        let e = s
            .set_settings(&SourceSettings {
                gain: Some(3),
                ..SourceSettings::default()
            })
            .unwrap_err();
        assert!(e.to_string().contains("gain"), "{e}");
        assert!(FileSource::new(Vec::new(), None).is_err());
    }
}
