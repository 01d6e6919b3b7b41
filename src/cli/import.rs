//! `eotn import`: a folder of frames plus a table of sensor readings → one MCAP stream; or one
//! stream rewritten in today's layout.

use std::path::PathBuf;

use anyhow::{Context, bail};

use super::inputs::{expand_frame_paths, load_frame_arg, parse_size, progress};
use crate::sensors::SensorReadings;
use crate::streams::schema::ImageEncoding;
use crate::streams::sensor_table::SensorTable;
use crate::streams::{
    Compression, FrameRecord, StreamInfo, StreamReader, StreamWriter, WriterOptions, is_recording,
};

/// Chunk compression on the command line.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum CompressionArg {
    /// Zstandard: smallest files.
    Zstd,
    /// LZ4: fastest.
    Lz4,
    /// No compression.
    None,
}

/// Arguments of `eotn import`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Frames (`.uyvy`, `.png`, `.jpg`) or folders of them; a folder's frames are taken in name
    /// order. PNG/JPEG frames are stored as UYVY. One recording instead — an MCAP stream, another
    /// tool's MCAP, a ROS 2 bag (its folder or its `.db3`/`.mcap` file) — becomes an eotn stream:
    /// every frame with its readings and channels, images stored as they came (any encoding,
    /// JPEG/PNG unchanged; eotn's own 4:2:2 frames in `--image-encoding`).
    #[arg(required_unless_present = "bhuman")]
    pub frames: Vec<PathBuf>,
    /// Import a B-Human 2009 Nao log (`logfile.log`) instead of frame files: its camera images
    /// as 320×240 UYVY, joint and sensor data as readings, raw records on `/bhuman2009`.
    #[arg(long, conflicts_with_all = ["frames", "sensors", "size"])]
    pub bhuman: Option<PathBuf>,
    /// Sensor readings: a CSV file with a header row of sensor field names (plus optional `frame`
    /// and `time_s` columns), or a `.json` array of objects with the same keys. Frames without a
    /// row get no readings.
    #[arg(long)]
    pub sensors: Option<PathBuf>,
    /// Frame size of raw files, WxH; 208x160 and 640x480 are inferred.
    #[arg(long, value_parser = parse_size)]
    pub size: Option<(usize, usize)>,
    /// Frames per second, for frame times when the sensor table has no `time_s` column.
    #[arg(long, default_value_t = 30.0, value_parser = super::values::number_in(0.001, 10_000.0))]
    pub fps: f64,
    /// Kind of source stored in the stream's metadata (`robot`, `overhead`, `sim:NAME`, …).
    #[arg(long, default_value = "import")]
    pub source: String,
    /// Free description stored in the stream's metadata.
    #[arg(long, default_value = "")]
    pub description: String,
    /// Chunk compression.
    #[arg(long, value_enum, default_value = "zstd")]
    pub compression: CompressionArg,
    /// Frames per chunk (default: about 1 MiB of images per chunk).
    #[arg(long, value_parser = super::values::whole_in::<usize>(1, 100_000))]
    pub frames_per_chunk: Option<usize>,
    /// Byte order of the stored frames: `yuyv` (read by Foxglove and Rerun) or `uyvy` (read by
    /// Foxglove; the cameras' own order). The same samples either way.
    #[arg(long, default_value = "yuyv")]
    pub image_encoding: ImageEncoding,
    /// Import only this camera (image topic) of a recording; repeat for several. Default: every
    /// camera. One camera is written as a one-camera stream (`/camera/image`), several each on
    /// its own topic with its own channels (docs/formats.md, "Several cameras").
    #[arg(long = "camera", value_name = "TOPIC")]
    pub cameras: Vec<String>,
    /// The stream to write (`.mcap`); written as `OUT.partial` and renamed when complete.
    #[arg(short, long, value_name = super::paths::OUT)]
    pub output: PathBuf,
}

/// Runs `eotn import`.
///
/// # Errors
/// Unreadable frames or sensor table, bad times, an unwritable output, each naming the file.
pub fn run(args: &Args) -> anyhow::Result<()> {
    if let Some(log) = &args.bhuman {
        let n = super::import_bhuman::run(log, &args.output, writer_options(args))?;
        eprintln!("eotn: wrote {n} frames to {}", args.output.display());
        return Ok(());
    }
    if !(args.fps.is_finite() && (0.001..=10_000.0).contains(&args.fps)) {
        bail!(
            "--fps must be between 0.001 and 10000 frames a second, not {:.3e}",
            args.fps
        );
    }
    if let [stream] = args.frames.as_slice()
        && is_recording(stream)
    {
        return rewrite_stream(stream, args);
    }
    if !args.cameras.is_empty() {
        bail!("--camera chooses cameras of a recording; frame files have none to choose");
    }
    let paths = expand_frame_paths(&args.frames)?;
    if let Some(stream) = paths.iter().find(|p| is_recording(p)) {
        bail!(
            "{}: import reads frame files, or one stream to rewrite on its own",
            stream.display()
        );
    }
    let table = match &args.sensors {
        Some(p) => Some(load_sensor_table(p, paths.len())?),
        None => None,
    };
    let options = writer_options(args);
    let info = StreamInfo {
        source: args.source.clone(),
        description: args.description.clone(),
    };
    let mut writer = StreamWriter::create_with(&args.output, &info, options)?;
    let bar = progress(paths.len(), "import");
    let mut previous: Option<(u64, Option<SensorReadings>)> = None;
    for (i, path) in paths.iter().enumerate() {
        let frame = load_frame_arg(path, args.size)?;
        let row = table.as_ref().and_then(|t| t.for_frame(i));
        let time_ns = frame_time_ns(i, row, path, args)?;
        if let Some((before, _)) = previous.as_ref()
            && time_ns < *before
        {
            log::warn!(
                "{}: frame {i} is at {:.3} s, before frame {} ({:.3} s): times go backwards",
                args.sensors.as_deref().unwrap_or(path).display(),
                ns_to_seconds(time_ns),
                i - 1,
                ns_to_seconds(*before)
            );
        }
        let mut sensors = row.map(|r| r.readings);
        if let (Some(s), Some((t0, before))) = (sensors.as_mut(), previous.as_ref()) {
            fill_from_previous(s, *t0, time_ns, before.as_ref());
        }
        let mut record = FrameRecord::new(time_ns, frame);
        record.sensors = sensors;
        writer
            .write(&record)
            .with_context(|| format!("frame {}", path.display()))?;
        previous = Some((time_ns, sensors));
        bar.inc(1);
    }
    bar.finish_and_clear();
    writer.finish()?;
    eprintln!(
        "eotn: wrote {} frames to {}",
        paths.len(),
        args.output.display()
    );
    Ok(())
}

/// Loads the sensor table, warning about its own warnings and about rows that name frames
/// beyond the `frames` given.
fn load_sensor_table(path: &std::path::Path, frames: usize) -> anyhow::Result<SensorTable> {
    let t = SensorTable::load(path)?;
    for w in t.warnings() {
        log::warn!("{}: {w}", path.display());
    }
    let unmatched = t
        .rows()
        .iter()
        .enumerate()
        .filter(|(i, r)| r.frame.unwrap_or(*i) >= frames)
        .count();
    if unmatched > 0 {
        log::warn!(
            "{}: {unmatched} rows name frames beyond the {frames} given; ignored",
            path.display(),
        );
    }
    Ok(t)
}

/// Frame `i`'s time, nanoseconds: its row's `time_s`, else `i` frames at `--fps`.
fn frame_time_ns(
    i: usize,
    row: Option<&crate::streams::sensor_table::SensorRow>,
    path: &std::path::Path,
    args: &Args,
) -> anyhow::Result<u64> {
    Ok(match row.and_then(|r| r.time_s) {
        Some(t) => seconds_to_ns(t).with_context(|| {
            format!(
                "{}: time_s {t} of frame {i} is not a time",
                args.sensors.as_deref().unwrap_or(path).display()
            )
        })?,
        None => seconds_to_ns(frame_seconds(i, args.fps))
            .with_context(|| format!("frame {i} at {:.3} fps is too late", args.fps))?,
    })
}

/// True for an unpadded UYVY or YUYV image: eotn's own frames, rewritten in the chosen order.
fn is_plain_422(image: &crate::formats::ImageMessage) -> bool {
    use crate::frame::PixelEncoding;
    matches!(&image.body, crate::formats::ImageBody::Raw { width, encoding, step, .. }
        if matches!(PixelEncoding::from_name(encoding), Some(PixelEncoding::Uyvy | PixelEncoding::Yuyv))
            && u64::from(*step) == 2 * u64::from(*width))
}

/// `eotn import REC -o NEW.mcap`: a recording (an eotn stream, another tool's MCAP, a ROS 2 bag)
/// as an eotn stream in the chosen options (compression, chunking; eotn's own 4:2:2 frames in the
/// chosen byte order), every frame with its channels; images in any other encoding, and
/// compressed ones, are stored unchanged. Frames that cannot be read are skipped with a warning
/// naming them.
fn rewrite_stream(input: &std::path::Path, args: &Args) -> anyhow::Result<()> {
    if args.sensors.is_some() || args.size.is_some() {
        bail!("--sensors and --size are for frame files; a stream keeps its own readings");
    }
    let first = StreamReader::open(input)?;
    let topics: Vec<String> = if args.cameras.is_empty() {
        first
            .image_topics()
            .iter()
            .map(|t| t.topic.clone())
            .collect()
    } else {
        args.cameras.clone()
    };
    if topics.len() <= 1 && args.cameras.is_empty() {
        return rewrite_cameras(input, args, vec![first]);
    }
    if topics.len() == 1 {
        let reader = StreamReader::open_camera(input, topics.first().map(String::as_str))?;
        return rewrite_cameras(input, args, vec![reader]);
    }
    let readers = topics
        .iter()
        .map(|t| StreamReader::open_camera(input, Some(t)))
        .collect::<Result<Vec<_>, _>>()?;
    rewrite_cameras(input, args, readers)
}

/// The stream's cameras into one stream: one reader gives a one-camera stream as always;
/// several are merged by time, each camera on its own topic (the first camera `/camera/image`
/// stays so), a channel shared by the cameras written once, with the first camera's frames.
fn rewrite_cameras(
    input: &std::path::Path,
    args: &Args,
    mut readers: Vec<StreamReader>,
) -> anyhow::Result<()> {
    let several = readers.len() > 1;
    if let Some(first) = readers.first() {
        // One camera's reader says what every camera's would (the same file).
        for w in first.warnings() {
            log::warn!("{}: {w}", input.display());
        }
        for n in first.notes() {
            if several && n.contains(crate::streams::CAMERA_CHOICE_NOTE) {
                continue;
            }
            log::warn!("{}: note: {n}", input.display());
        }
    }
    let total: usize = readers.iter().map(StreamReader::len).sum();
    if total == 0 {
        // The notes above say why (no image channel, one in an encoding eotn does not read).
        bail!(
            "{}: no camera frames to import; nothing written to {}",
            input.display(),
            args.output.display()
        );
    }
    let Some(head) = readers.first() else {
        bail!("{}: no camera to import", input.display());
    };
    let info = imported_info(head.info(), input, args);
    let topics: Vec<String> = readers
        .iter()
        .map(|r| r.camera().unwrap_or(crate::streams::IMAGE_TOPIC).to_owned())
        .collect();
    let mut writer = StreamWriter::create_with(&args.output, &info, writer_options(args))?;
    if let Some(param_set) = head.param_set().filter(|_| several) {
        writer.name_param_set(param_set)?;
    }
    name_kept_cameras(&mut writer, head, &topics, input, &args.output)?;
    let bar = progress(total, "import");
    let (mut written, mut skipped) = (0usize, Vec::new());
    let mut next = vec![0usize; readers.len()];
    // The camera whose next frame is earliest, each camera in its own order.
    while let Some(c) = (0..readers.len())
        .filter(|&c| next[c] < readers[c].len())
        .min_by_key(|&c| (readers[c].time_ns(next[c]).unwrap_or(u64::MAX), c))
    {
        let index = next[c];
        next[c] += 1;
        bar.inc(1);
        match readers[c].read_with_image(index) {
            Ok((mut record, image)) => {
                // eotn's own 4:2:2 frames take the chosen byte order; every other image is
                // stored as the message it came in (converted only when read).
                let keep = (!is_plain_422(&image)).then_some(&image);
                if several {
                    own_channels(&mut record, &topics[c], c == 0);
                    writer.write_camera(&topics[c], &record, keep)
                } else {
                    writer.write_with_image(&record, keep)
                }
                .with_context(|| format!("{}: frame {index}", args.output.display()))?;
                written += 1;
            }
            Err(e) => {
                let camera = if several {
                    format!(" of {}", topics[c])
                } else {
                    String::new()
                };
                log::warn!("{}: frame {index}{camera} skipped: {e}", input.display());
                skipped.push(index);
            }
        }
    }
    bar.finish_and_clear();
    if written == 0 {
        writer.discard()?;
        bail!(
            "{}: none of its {} frames could be read; nothing written to {}",
            input.display(),
            skipped.len(),
            args.output.display()
        );
    }
    writer.finish()?;
    let cameras = if several {
        format!(" of {} cameras", topics.len())
    } else {
        String::new()
    };
    eprintln!(
        "eotn: wrote {written} frames{cameras} to {} ({} skipped)",
        args.output.display(),
        skipped.len()
    );
    Ok(())
}

/// Each camera kept keeps the files its recording names for it (`eotn.camera`), under its topic
/// in the new stream (one camera: the stream's first, `/camera/image`).
fn name_kept_cameras(
    writer: &mut StreamWriter,
    head: &StreamReader,
    topics: &[String],
    input: &std::path::Path,
    output: &std::path::Path,
) -> anyhow::Result<()> {
    let first = |t: &str| crate::camera::is_default_camera(t);
    for topic in topics {
        let named =
            (head.camera_metadata().iter()).find(|(t, _)| t == topic || (first(t) && first(topic)));
        if let Some((_, files)) = named {
            let written = if topics.len() > 1 {
                topic.as_str()
            } else {
                crate::streams::IMAGE_TOPIC
            };
            writer.name_camera_files(written, &carried_files(files, input, output))?;
        }
    }
    Ok(())
}

/// A camera's files as the new stream names them: as they are when it is written in the
/// recording's folder, else relative paths made absolute (resolved against the recording's
/// folder, as readers resolve them); a shipped parameter set's name stays a name.
fn carried_files(
    files: &crate::camera::CameraFiles,
    input: &std::path::Path,
    output: &std::path::Path,
) -> crate::camera::CameraFiles {
    let folder = |p: &std::path::Path| {
        let parent = p.parent().filter(|f| !f.as_os_str().is_empty());
        std::fs::canonicalize(parent.unwrap_or(std::path::Path::new(".")))
    };
    match (folder(input), folder(output)) {
        (Ok(a), Ok(b)) if a == b => files.clone(),
        (Ok(a), _) => files.clone().relative_to(&a),
        (Err(_), _) => files.clone(),
    }
}

/// The stream's description: the recording's own, or for another tool's recording the import's
/// source kind and a note of where from.
fn imported_info(
    info: &crate::streams::StreamInfo,
    input: &std::path::Path,
    args: &Args,
) -> crate::streams::StreamInfo {
    let mut info = info.clone();
    if info.source == "unknown" {
        info.source.clone_from(&args.source);
        info.description = if args.description.is_empty() {
            format!("imported from {}", input.display())
        } else {
            args.description.clone()
        };
    }
    info
}

/// A frame's extra channels as one camera of several writes them: its camera intrinsics
/// under its own name (`CAMERA/camera_info`); the channels every camera reads (joints, world
/// models) with the first camera only, so they are written once.
fn own_channels(record: &mut crate::streams::FrameRecord, camera: &str, first: bool) {
    let info_topic = crate::camera::CameraChannel::CameraInfo.topic(camera);
    record.extra.retain_mut(|(topic, _)| {
        if topic.ends_with("/camera_info") || topic.ends_with("/camera_calibration") {
            topic.clone_from(&info_topic);
            true
        } else {
            first
        }
    });
}

/// The writer options of the command line.
fn writer_options(args: &Args) -> WriterOptions {
    WriterOptions {
        compression: match args.compression {
            CompressionArg::Zstd => Compression::Zstd,
            CompressionArg::Lz4 => Compression::Lz4,
            CompressionArg::None => Compression::None,
        },
        frames_per_chunk: args.frames_per_chunk,
        image_encoding: args.image_encoding,
    }
}

/// Fills the readings derived from the previous frame when the table left them out: previous pan
/// and tilt, and the frame interval (used for the pan velocity).
fn fill_from_previous(
    s: &mut SensorReadings,
    t0_ns: u64,
    t_ns: u64,
    before: Option<&SensorReadings>,
) {
    if s.frame_interval_s.is_none() && t_ns > t0_ns {
        s.frame_interval_s = Some(ns_to_seconds(t_ns - t0_ns));
    }
    if let Some(b) = before {
        s.previous_head_pan_rad = s.previous_head_pan_rad.or(b.head_pan_rad);
        s.previous_head_tilt_rad = s.previous_head_tilt_rad.or(b.head_tilt_rad);
    }
}

fn frame_seconds(i: usize, fps: f64) -> f64 {
    i as f64 / fps
}

fn ns_to_seconds(ns: u64) -> f64 {
    ns as f64 / 1e9
}

/// Seconds → nanoseconds, `None` for negative, non-finite or absurd (> 500 years) times.
fn seconds_to_ns(s: f64) -> Option<u64> {
    let ns = (s * 1e9).round();
    if !(s.is_finite() && (0.0..1.6e19).contains(&ns)) {
        return None;
    }
    #[expect(
        clippy::cast_possible_truncation,
        clippy::cast_sign_loss,
        reason = "checked: finite, non-negative and below 1.6e19"
    )]
    let n = ns as u64;
    Some(n)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn times_convert_and_reject_nonsense() {
        assert_eq!(seconds_to_ns(1.5), Some(1_500_000_000));
        assert_eq!(seconds_to_ns(-0.1), None);
        assert_eq!(seconds_to_ns(f64::NAN), None);
        assert_eq!(seconds_to_ns(1e30), None);
    }

    #[test]
    fn previous_pan_and_interval_are_derived() {
        let before = SensorReadings {
            head_pan_rad: Some(0.1),
            ..SensorReadings::default()
        };
        let mut now = SensorReadings {
            head_pan_rad: Some(0.3),
            ..SensorReadings::default()
        };
        fill_from_previous(&mut now, 0, 40_000_000, Some(&before));
        assert_eq!(now.previous_head_pan_rad, Some(0.1));
        let v = now.pan_velocity_rad_per_s().unwrap();
        assert!((v - 5.0).abs() < 1e-9, "{v}");
    }
}
