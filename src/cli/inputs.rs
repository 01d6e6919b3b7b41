//! Shared command-line inputs: frame lists (files, folders, MCAP streams), `--size`, `--lut`,
//! `--frames`, progress bars.

use std::ops::Range;
use std::path::{Path, PathBuf};

use anyhow::{Context as _, anyhow, bail};
use indicatif::{ProgressBar, ProgressStyle};

pub use crate::sources::{RAW_EXTENSIONS, expand_frame_paths, is_frame_file};

use crate::blobs::Connectivity;
use crate::frame::{Frame, load_frame};
use crate::lut::LookupTable;
use crate::sources::{
    FileSource, NOMINAL_FRAME_INTERVAL_NS, RecordedSource, SourceFrame, StreamSource,
};
use crate::streams::is_recording;

/// Parses `WxH` (e.g. `208x160`).
///
/// # Errors
/// A message saying what is wrong with the text.
pub fn parse_size(text: &str) -> anyhow::Result<(usize, usize)> {
    let (w, h) = text
        .split_once(['x', 'X', '×'])
        .with_context(|| format!("'{text}' is not WxH (e.g. 208x160)"))?;
    let w: usize = w
        .trim()
        .parse()
        .with_context(|| format!("bad width in '{text}'"))?;
    let h: usize = h
        .trim()
        .parse()
        .with_context(|| format!("bad height in '{text}'"))?;
    if w == 0 || h == 0 {
        bail!("'{text}': width and height must be positive");
    }
    Ok((w, h))
}

/// Parses a connectivity, `4` or `8`.
///
/// # Errors
/// A message for anything else.
pub fn parse_connectivity(text: &str) -> anyhow::Result<Connectivity> {
    text.trim()
        .parse::<u8>()
        .ok()
        .and_then(Connectivity::from_neighbours)
        .with_context(|| format!("connectivity must be 4 or 8, not '{text}'"))
}

/// Parses a frame range: `A..B` (B excluded), `A..=B`, `A..`, `..B`, or a single index `A`.
///
/// # Errors
/// A message for anything else.
pub fn parse_frame_range(text: &str) -> anyhow::Result<Range<usize>> {
    let bad = || anyhow!("'{text}' is not a frame range (A..B, A..=B, A.., ..B or A)");
    let num = |s: &str| s.trim().parse::<usize>().map_err(|_| bad());
    let Some((a, b)) = text.split_once("..") else {
        let a = num(text)?;
        return Ok(a..a.saturating_add(1));
    };
    let start = if a.trim().is_empty() { 0 } else { num(a)? };
    let end = if let Some(b) = b.strip_prefix('=') {
        num(b)?.saturating_add(1)
    } else if b.trim().is_empty() {
        usize::MAX
    } else {
        num(b)?
    };
    if end < start {
        return Err(bad());
    }
    Ok(start..end)
}

/// One frame to process: a frame file, or one frame of a stream.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum FrameInput {
    /// A `.uyvy`/PNG/JPEG file.
    File(PathBuf),
    /// Frame `index` of the recording at `path` (an MCAP stream or a ROS 2 bag).
    Stream {
        /// The recording: a file, or a bag's folder.
        path: PathBuf,
        /// Frame index within the stream.
        index: usize,
    },
}

impl FrameInput {
    /// The name used in JSON output and output file names: the file name, or for a stream
    /// frame `STEM_NNNNNN` (stem of the stream file, 6-digit frame index).
    #[must_use]
    pub fn name(&self) -> String {
        match self {
            Self::File(p) => crate::frame::display_name(p),
            Self::Stream { path, index } => {
                let stem = path
                    .file_stem()
                    .map_or_else(|| "stream".to_owned(), |s| s.to_string_lossy().into_owned());
                format!("{stem}_{index:06}")
            }
        }
    }
}

/// The arguments every frame-processing command takes (`classify`, `blobs`, `bench`, `detect`,
/// `render`), flattened into each command's own arguments.
#[derive(Debug, clap::Args)]
pub struct InputArgs {
    /// Frames (`.uyvy`, `.png`, `.jpg`), folders of them, or recordings (which carry their own
    /// sensor readings): MCAP streams (`.mcap`), ROS 2 bags (a folder with `metadata.yaml`, or
    /// its `.db3`/`.mcap` file).
    #[arg(required = true)]
    pub frames: Vec<PathBuf>,
    /// Lookup table (`.lut`, 6, 7 or 8 bits per channel); default: the table the first
    /// recording names for its camera (its `REC.cameras.json` sidecar, else its metadata).
    #[arg(long)]
    pub lut: Option<PathBuf>,
    /// Frame size of raw files, WxH; 208x160 and 640x480 are inferred from the file length.
    #[arg(long, value_parser = parse_size)]
    pub size: Option<(usize, usize)>,
    /// Which camera of the recordings.
    #[command(flatten)]
    pub camera: CameraArg,
}

/// `--camera TOPIC`: which camera of a recording to read, for every command that reads frames.
#[derive(Debug, Clone, Default, clap::Args)]
pub struct CameraArg {
    /// The camera (image topic) of the recordings to read, e.g. `/camera/bottom`; default: the
    /// first. An unknown topic is an error listing the cameras there are.
    #[arg(long = "camera", value_name = "TOPIC")]
    pub topic: Option<String>,
}

impl CameraArg {
    /// The topic asked for.
    #[must_use]
    pub fn get(&self) -> Option<&str> {
        self.topic.as_deref()
    }
}

impl InputArgs {
    /// Loads the table and opens the frames, the first step of every frame command.
    ///
    /// # Errors
    /// An unreadable table or frame file, naming it; no `--lut` and no table named for the
    /// first recording's camera.
    pub fn open(&self) -> anyhow::Result<(LookupTable, FrameInputs)> {
        let inputs = FrameInputs::open_camera(&self.frames, None, self.camera.get())?;
        let lut = match &self.lut {
            Some(path) => load_lut_arg(path)?,
            None => load_lut_arg(&camera_table(&inputs)?)?,
        };
        Ok((lut, inputs))
    }
}

/// The table the first recording among the inputs names for the camera read (sidecar, else
/// metadata), for a command given no `--lut`.
///
/// # Errors
/// No recording among the inputs, or its camera names no table.
pub fn camera_table(inputs: &FrameInputs) -> anyhow::Result<PathBuf> {
    let Some(path) = inputs.items.iter().find_map(|i| match i {
        FrameInput::Stream { path, .. } => Some(path),
        FrameInput::File(_) => None,
    }) else {
        bail!("--lut is needed: the inputs are frame files, which name no table");
    };
    camera_table_of(path, inputs.camera.as_deref())
}

/// `--lut` when given, else the table the first recording among `paths` names for the camera
/// read (for commands that take paths rather than [`InputArgs`]: `eval`).
///
/// # Errors
/// No `--lut` and no recording among `paths`, or its camera names no table.
pub fn table_or_camera_s(
    explicit: Option<&Path>,
    paths: &[PathBuf],
    camera: Option<&str>,
) -> anyhow::Result<PathBuf> {
    if let Some(p) = explicit {
        return Ok(p.to_owned());
    }
    let Some(rec) = paths.iter().find(|p| is_recording(p)) else {
        bail!("--lut is needed: the inputs are no recordings, which would name a table");
    };
    camera_table_of(rec, camera)
}

/// The table the recording `path` names for its camera `camera` (`None`: its first).
fn camera_table_of(path: &Path, camera: Option<&str>) -> anyhow::Result<PathBuf> {
    let reader = crate::streams::StreamReader::open_camera(path, camera)?;
    let camera = reader.camera().unwrap_or("its camera").to_owned();
    reader.camera_files()?.lut.ok_or_else(|| {
        anyhow!(
            "--lut is needed: {} names no table for {camera} (in {} or its metadata)",
            path.display(),
            crate::camera::sidecar_path(path).display()
        )
    })
}

/// The frames named on a command line, in order: frame files, folders of them, and MCAP streams
/// (every frame of each, or those in `--frames`), read through the frame sources of
/// [`crate::sources`] as the app reads them. Streams are read one frame at a time, so a long
/// stream costs no more memory than a short one.
#[derive(Debug)]
pub struct FrameInputs {
    items: Vec<FrameInput>,
    stream: Option<StreamSource>,
    skipped: SkippedFrames,
    /// The streams among the inputs whose camera looks down at the field (their source kind
    /// says so): the robot camera's recogniser means nothing on them.
    overhead_streams: Vec<PathBuf>,
    /// The other streams: robot cameras' (the overhead recogniser means nothing on them).
    robot_streams: Vec<PathBuf>,
    /// The camera (image topic) read from every recording; `None`: each one's first.
    camera: Option<String>,
}

/// Runs of consecutive stream frames skipped as unreadable, warned about once per run (when the
/// run ends, or when the inputs are dropped).
#[derive(Debug, Default)]
struct SkippedFrames {
    run: Option<(PathBuf, usize, usize, String)>,
}

impl SkippedFrames {
    fn note(&mut self, path: &Path, index: usize, why: &str) {
        if let Some((p, _, last, _)) = self.run.as_mut()
            && p == path
            && *last + 1 == index
        {
            *last = index;
            return;
        }
        self.flush();
        self.run = Some((path.to_owned(), index, index, why.to_owned()));
    }

    fn flush(&mut self) {
        if let Some((path, first, last, why)) = self.run.take() {
            let frames = if first == last {
                format!("frame {first}")
            } else {
                format!("frames {first}–{last}")
            };
            log::warn!("{}: {frames} skipped, unreadable: {why}", path.display());
        }
    }
}

impl Drop for SkippedFrames {
    fn drop(&mut self) {
        self.flush();
    }
}

impl FrameInputs {
    /// Expands the arguments; `range` limits the frames taken from each stream.
    ///
    /// # Errors
    /// A path that does not exist, a folder without frames, an unreadable stream, or a stream
    /// without frames (each naming the file).
    pub fn open(paths: &[PathBuf], range: Option<Range<usize>>) -> anyhow::Result<Self> {
        Self::open_camera(paths, range, None)
    }

    /// Like [`FrameInputs::open`], reading the camera `camera` (an image topic) of every
    /// recording; `None` reads each one's first.
    ///
    /// # Errors
    /// As [`FrameInputs::open`]; a recording without that camera (the error lists its cameras).
    pub fn open_camera(
        paths: &[PathBuf],
        range: Option<Range<usize>>,
        camera: Option<&str>,
    ) -> anyhow::Result<Self> {
        let mut items = Vec::new();
        let (mut overhead_streams, mut robot_streams) = (Vec::new(), Vec::new());
        for p in expand_frame_paths(paths)? {
            if is_recording(&p) {
                let stream = StreamSource::open_camera(&p, camera)?;
                if crate::sources::FrameSource::info(&stream).camera
                    == crate::sources::CameraKind::Overhead
                {
                    overhead_streams.push(p.clone());
                } else {
                    robot_streams.push(p.clone());
                }
                for w in stream.warnings() {
                    log::warn!("{}: {w}", p.display());
                }
                let all = 0..stream.len();
                let take = range
                    .clone()
                    .map_or(all.clone(), |r| r.start.min(all.end)..r.end.min(all.end));
                if take.is_empty() {
                    bail!(
                        "{}: --frames selects none of its {} frames",
                        p.display(),
                        stream.len()
                    );
                }
                items.extend(take.map(|index| FrameInput::Stream {
                    path: p.clone(),
                    index,
                }));
            } else {
                items.push(FrameInput::File(p));
            }
        }
        Ok(Self {
            items,
            stream: None,
            skipped: SkippedFrames::default(),
            overhead_streams,
            robot_streams,
            camera: camera.map(str::to_owned),
        })
    }

    /// The streams among the inputs recorded by an overhead camera.
    #[must_use]
    pub fn overhead_streams(&self) -> &[PathBuf] {
        &self.overhead_streams
    }

    /// The streams among the inputs recorded by a robot's camera (any stream whose source kind
    /// does not name an overhead camera).
    #[must_use]
    pub fn robot_streams(&self) -> &[PathBuf] {
        &self.robot_streams
    }

    /// Number of frames.
    #[must_use]
    pub fn len(&self) -> usize {
        self.items.len()
    }

    /// True when there are no frames.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.items.is_empty()
    }

    /// The inputs in order.
    #[must_use]
    pub fn items(&self) -> &[FrameInput] {
        &self.items
    }

    /// The name of frame `i` (see [`FrameInput::name`]).
    #[must_use]
    pub fn name(&self, i: usize) -> String {
        self.items.get(i).map(FrameInput::name).unwrap_or_default()
    }

    /// Loads frame `i` (raw files with `size`, inferred when `None`).
    ///
    /// # Errors
    /// The loader's error, naming the file.
    pub fn load(&mut self, i: usize, size: Option<(usize, usize)>) -> anyhow::Result<Frame> {
        Ok(self.load_with_sensors(i, size)?.0)
    }

    /// Loads frame `i` with the sensor readings its stream recorded (none for frame files).
    ///
    /// # Errors
    /// The loader's error, naming the file.
    pub fn load_with_sensors(
        &mut self,
        i: usize,
        size: Option<(usize, usize)>,
    ) -> anyhow::Result<(Frame, Option<crate::sensors::SensorReadings>)> {
        let f = self.load_source_frame(i, size)?;
        let frame = std::sync::Arc::unwrap_or_clone(f.frame);
        Ok((frame, f.sensors))
    }

    /// Like [`Self::load_record`], but a frame of a stream that cannot be read (a damaged
    /// chunk) is skipped: `None`, with one warning per run of lost frames naming them. Frame files
    /// that cannot be read are still errors (the user named them one by one).
    ///
    /// # Errors
    /// A frame file that cannot be read, or a stream that cannot be opened.
    pub fn load_record_or_skip(
        &mut self,
        i: usize,
        size: Option<(usize, usize)>,
    ) -> anyhow::Result<Option<crate::streams::FrameRecord>> {
        let Some(FrameInput::Stream { path, index }) = self.items.get(i).cloned() else {
            return self.load_record(i, size).map(Some);
        };
        if self.stream.as_ref().is_none_or(|s| s.path() != path) {
            self.stream = Some(StreamSource::open_camera(&path, self.camera.as_deref())?);
        }
        let Some(stream) = self.stream.as_mut() else {
            bail!("{}: stream not open", path.display());
        };
        match stream.read(index) {
            Ok(f) => Ok(Some(f.into_record())),
            Err(e) => {
                self.skipped.note(&path, index, &e.to_string());
                Ok(None)
            }
        }
    }

    /// Loads frame `i` with everything its stream recorded for it (readings, truth, other
    /// channels); a frame file gets a record of the image alone, timed at the nominal 25 fps.
    ///
    /// # Errors
    /// The loader's error, naming the file.
    pub fn load_record(
        &mut self,
        i: usize,
        size: Option<(usize, usize)>,
    ) -> anyhow::Result<crate::streams::FrameRecord> {
        Ok(self.load_source_frame(i, size)?.into_record())
    }

    /// Loads frame `i` as its source delivers it: for a stream frame, with its sensor readings
    /// and channels; for a frame file, the image alone (the CLI ignores sensor side files), timed
    /// at the nominal 25 fps by its place in the list.
    ///
    /// # Errors
    /// The loader's error, naming the file.
    pub fn load_source_frame(
        &mut self,
        i: usize,
        size: Option<(usize, usize)>,
    ) -> anyhow::Result<SourceFrame> {
        match self.items.get(i) {
            None => bail!("no input frame {i}"),
            Some(FrameInput::File(p)) => {
                let mut file = FileSource::new(vec![p.clone()], size)?;
                let mut f = file.read(0)?;
                f.sensors = None;
                f.warnings.clear();
                let t = u64::try_from(i).unwrap_or(u64::MAX / NOMINAL_FRAME_INTERVAL_NS);
                f.time_ns = t.saturating_mul(NOMINAL_FRAME_INTERVAL_NS);
                Ok(f)
            }
            Some(FrameInput::Stream { path, index }) => {
                if self.stream.as_ref().is_none_or(|s| s.path() != path) {
                    self.stream = Some(StreamSource::open_camera(path, self.camera.as_deref())?);
                }
                let Some(stream) = self.stream.as_mut() else {
                    bail!("{}: stream not open", path.display());
                };
                Ok(stream.read(*index)?)
            }
        }
    }
}

/// Loads one frame with the error naming the file.
///
/// # Errors
/// The loader's error.
pub fn load_frame_arg(path: &Path, size: Option<(usize, usize)>) -> anyhow::Result<Frame> {
    if size.is_some() && crate::frame::is_image_file(path) {
        static WARNED: std::sync::Once = std::sync::Once::new();
        WARNED.call_once(|| {
            log::warn!(
                "--size applies to raw frames only; {} and other PNG/JPEG frames keep their own size",
                path.display()
            );
        });
    }
    Ok(load_frame(path, size)?)
}

/// Loads the `--lut` table.
///
/// # Errors
/// The table loader's error, naming the file.
pub fn load_lut_arg(path: &Path) -> anyhow::Result<LookupTable> {
    Ok(LookupTable::load(path)?)
}

/// A progress bar on stderr that draws only on a terminal (quiet when piped or redirected).
#[must_use]
pub fn progress(len: usize, what: &str) -> ProgressBar {
    let bar = ProgressBar::new(len as u64);
    if let Ok(style) =
        ProgressStyle::with_template("{msg} {wide_bar} {pos}/{len} [{elapsed_precise}, {eta} left]")
    {
        bar.set_style(style);
    }
    bar.set_message(what.to_owned());
    bar
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_parse_and_reject_nonsense() {
        assert_eq!(parse_size("208x160").ok(), Some((208, 160)));
        assert_eq!(parse_size("640X480").ok(), Some((640, 480)));
        assert!(parse_size("208").is_err());
        let zero = parse_size("0x5").expect_err("zero width").to_string();
        assert!(zero.contains("must be positive"), "{zero}");
        let text = parse_size("axb").expect_err("letters").to_string();
        assert_eq!(text, "bad width in 'axb'");
    }

    #[test]
    fn folders_expand_to_sorted_frame_files() {
        let dir = tempfile::tempdir().unwrap();
        for n in ["b.uyvy", "a.uyvy", "notes.txt", "c.png"] {
            std::fs::write(dir.path().join(n), b"").unwrap();
        }
        let got = expand_frame_paths(&[dir.path().to_owned()]).unwrap();
        let names: Vec<_> = got.iter().map(|p| crate::frame::display_name(p)).collect();
        assert_eq!(names, ["a.uyvy", "b.uyvy", "c.png"]);
        assert!(expand_frame_paths(&[dir.path().join("nope")]).is_err());
    }

    #[test]
    fn frame_ranges_parse() {
        assert_eq!(parse_frame_range("2..5").ok(), Some(2..5));
        assert_eq!(parse_frame_range("2..=5").ok(), Some(2..6));
        assert_eq!(parse_frame_range("..3").ok(), Some(0..3));
        assert_eq!(parse_frame_range("7..").ok(), Some(7..usize::MAX));
        assert_eq!(parse_frame_range("4").ok(), Some(4..5));
        assert!(parse_frame_range("5..2").is_err());
        assert!(parse_frame_range("a..b").is_err());
    }

    /// Every command that reads frames of recordings — an input argument named `frames`,
    /// `files`, `inputs`, `streams` or `stream` — takes `--camera TOPIC`.
    #[test]
    fn every_command_reading_recordings_takes_camera() {
        use clap::CommandFactory as _;
        fn walk(cmd: &clap::Command, path: &str, missing: &mut Vec<String>, seen: &mut usize) {
            let name = format!("{path} {}", cmd.get_name());
            let reads = cmd.get_arguments().any(|a| {
                ["frames", "files", "inputs", "streams", "stream"].contains(&a.get_id().as_str())
                    && crate::cli::paths::path_role(a) == Some(crate::cli::paths::PathRole::Input)
            });
            if reads {
                *seen += 1;
                let camera = cmd.get_arguments().find(|a| a.get_long() == Some("camera"));
                let named = camera.and_then(|a| a.get_value_names().map(<[_]>::to_vec));
                if named.is_none_or(|n| n.iter().all(|v| v.as_str() != "TOPIC")) {
                    missing.push(name.clone());
                }
            }
            for sub in cmd.get_subcommands() {
                walk(sub, &name, missing, seen);
            }
        }
        let (mut missing, mut seen) = (Vec::new(), 0);
        walk(&crate::cli::Cli::command(), "", &mut missing, &mut seen);
        assert!(missing.is_empty(), "no --camera TOPIC: {missing:?}");
        assert!(seen >= 15, "only {seen} commands read recordings");
    }
}
