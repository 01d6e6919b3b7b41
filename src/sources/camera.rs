//! A real camera through V4L2 (Linux): USB/UVC cameras delivering YUYV or UYVY, today's
//! equivalent of the original FireWire camera. Frames are captured through memory-mapped
//! buffers and converted to UYVY; frame size, frame rate, exposure and gain are the device's own
//! controls. A machine without `/dev/video*` lists no camera ([`super::available`]); connecting
//! to a path that is not a camera fails with a one-line error naming it.
//!
//! A frame's time is the driver's own timestamp of the buffer (`v4l2_buffer.timestamp`, taken
//! when the frame was captured — `CLOCK_MONOTONIC` for UVC and most drivers), counted from the
//! first frame. A driver that leaves it zero or lets it run backwards gets the time the frame
//! was dequeued instead (`Instant`, also monotonic), so times always increase.

use std::path::{Path, PathBuf};

use v4l::buffer::Type;
use v4l::control::{Control, Value};
use v4l::io::mmap::Stream as MmapStream;
use v4l::io::traits::CaptureStream as _;
use v4l::video::Capture as _;
use v4l::{Device, FourCC};

use super::{
    CameraKind, ControlRange, FrameSource, Resolution, SourceControls, SourceError, SourceFrame,
    SourceInfo, SourceKind, SourceSettings,
};
use crate::frame::Frame;

/// V4L2's `V4L2_CID_EXPOSURE_ABSOLUTE` (100 µs units).
const CID_EXPOSURE_ABSOLUTE: u32 = 0x009a_0902;
/// V4L2's `V4L2_CID_GAIN`.
const CID_GAIN: u32 = 0x0098_0913;
/// Buffers queued in the driver.
const BUFFERS: u32 = 4;
/// How long a grab waits for the camera before it says so, milliseconds.
const GRAB_TIMEOUT_MS: u64 = 2000;

/// The pixel layouts taken from a camera: both are 4:2:2 with the same bytes per pixel.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Packing {
    /// U, Y0, V, Y1 (the pipeline's own layout).
    Uyvy,
    /// Y0, U, Y1, V (most UVC webcams).
    Yuyv,
}

impl Packing {
    fn of(fourcc: FourCC) -> Option<Self> {
        match &fourcc.repr {
            b"UYVY" => Some(Self::Uyvy),
            b"YUYV" => Some(Self::Yuyv),
            _ => None,
        }
    }
}

/// An open camera: the device and, while connected, its capture stream.
pub struct CameraSource {
    path: PathBuf,
    name: String,
    kind: CameraKind,
    device: Option<Device>,
    stream: Option<MmapStream<'static>>,
    format: Option<(u32, u32, Packing)>,
    /// The driver's time of the first frame, microseconds: times start at 0.
    first_us: Option<i64>,
    /// When the first frame was dequeued: the clock for drivers without timestamps.
    first_arrival: Option<std::time::Instant>,
    /// The time given to the latest frame, nanoseconds from the first.
    last_ns: Option<u64>,
}

impl std::fmt::Debug for CameraSource {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("CameraSource")
            .field("path", &self.path)
            .field("name", &self.name)
            .field("connected", &self.stream.is_some())
            .finish_non_exhaustive()
    }
}

impl CameraSource {
    /// The camera at `path` (`/dev/video0`), a robot's or an overhead one, not yet connected.
    #[must_use]
    pub fn new(path: &Path, kind: CameraKind) -> Self {
        Self {
            path: path.to_owned(),
            name: crate::frame::display_name(path),
            kind,
            device: None,
            stream: None,
            format: None,
            first_us: None,
            first_arrival: None,
            last_ns: None,
        }
    }

    fn label(&self) -> String {
        format!("camera {} ({})", self.path.display(), self.name)
    }

    fn device_error(&self, what: &str, e: &std::io::Error) -> SourceError {
        SourceError::Device {
            label: self.label(),
            detail: format!("{what}: {e}"),
        }
    }

    fn device(&self) -> Result<&Device, SourceError> {
        self.device
            .as_ref()
            .ok_or_else(|| SourceError::NotConnected(self.label()))
    }

    /// Sets a 4:2:2 format (the current size, YUYV unless the camera already gives UYVY) and
    /// starts the capture stream.
    fn start_stream(&mut self, size: Option<Resolution>) -> Result<(), SourceError> {
        self.stream = None;
        let dev = self.device()?;
        let mut fmt = dev
            .format()
            .map_err(|e| self.device_error("cannot read its format", &e))?;
        if let Some(r) = size {
            fmt.width = r.width;
            fmt.height = r.height;
        }
        if Packing::of(fmt.fourcc).is_none() {
            fmt.fourcc = FourCC::new(b"YUYV");
        }
        let fmt = dev
            .set_format(&fmt)
            .map_err(|e| self.device_error("cannot set a YUYV format", &e))?;
        let packing = Packing::of(fmt.fourcc).ok_or_else(|| SourceError::Unsupported {
            label: self.label(),
            detail: format!("delivers {} frames, not YUYV or UYVY", fmt.fourcc),
        })?;
        let mut stream = MmapStream::with_buffers(dev, Type::VideoCapture, BUFFERS)
            .map_err(|e| self.device_error("cannot map capture buffers", &e))?;
        stream.set_timeout(std::time::Duration::from_millis(GRAB_TIMEOUT_MS));
        self.format = Some((fmt.width, fmt.height, packing));
        self.stream = Some(stream);
        Ok(())
    }

    fn control_range(&self, id: u32) -> Option<ControlRange> {
        let controls = self.device.as_ref()?.query_controls().ok()?;
        let d = controls.into_iter().find(|c| c.id == id)?;
        Some(ControlRange {
            min: d.minimum,
            max: d.maximum,
            step: i64::try_from(d.step).unwrap_or(1),
        })
    }

    fn control_value(&self, id: u32) -> Option<i64> {
        match self.device.as_ref()?.control(id).ok()?.value {
            Value::Integer(v) => Some(v),
            _ => None,
        }
    }

    fn set_control(&self, id: u32, value: i64, name: &str) -> Result<(), SourceError> {
        let dev = self.device()?;
        dev.set_control(Control {
            id,
            value: Value::Integer(value),
        })
        .map_err(|e| self.device_error(&format!("cannot set its {name} to {value}"), &e))
    }
}

impl FrameSource for CameraSource {
    fn info(&self) -> SourceInfo {
        let stream_source = self.kind.stream_source();
        SourceInfo {
            kind: SourceKind::Camera,
            label: self.label(),
            camera: CameraKind::of_stream_source(&stream_source),
            paths: Vec::new(),
            stream_source,
        }
    }

    fn connect(&mut self) -> Result<(), SourceError> {
        if self.stream.is_some() {
            return Ok(());
        }
        let dev = Device::with_path(&self.path)
            .map_err(|e| self.device_error("cannot open the camera", &e))?;
        if let Ok(caps) = dev.query_caps() {
            self.name = caps.card;
        }
        self.device = Some(dev);
        self.first_us = None;
        self.first_arrival = None;
        self.last_ns = None;
        if let Err(e) = self.start_stream(None) {
            self.device = None;
            return Err(e);
        }
        Ok(())
    }

    fn disconnect(&mut self) {
        self.stream = None;
        self.device = None;
    }

    fn is_connected(&self) -> bool {
        self.stream.is_some()
    }

    fn settings(&self) -> SourceSettings {
        let frame_rate = self
            .device
            .as_ref()
            .and_then(|d| d.params().ok())
            .and_then(|p| {
                let i = p.interval;
                (i.numerator > 0).then(|| f64::from(i.denominator) / f64::from(i.numerator))
            });
        SourceSettings {
            resolution: self
                .format
                .map(|(width, height, _)| Resolution { width, height }),
            frame_rate,
            exposure: self.control_value(CID_EXPOSURE_ABSOLUTE),
            gain: self.control_value(CID_GAIN),
        }
    }

    fn controls(&self) -> SourceControls {
        let Some(dev) = &self.device else {
            return SourceControls::default();
        };
        let Some((w, h, packing)) = self.format else {
            return SourceControls::default();
        };
        let fourcc = FourCC::new(match packing {
            Packing::Uyvy => b"UYVY",
            Packing::Yuyv => b"YUYV",
        });
        let resolutions = dev
            .enum_framesizes(fourcc)
            .unwrap_or_default()
            .into_iter()
            .flat_map(|s| s.size.to_discrete())
            .map(|d| Resolution {
                width: d.width,
                height: d.height,
            })
            .collect();
        let frame_rates = dev
            .enum_frameintervals(fourcc, w, h)
            .unwrap_or_default()
            .into_iter()
            .filter_map(|i| match i.interval {
                v4l::frameinterval::FrameIntervalEnum::Discrete(f) if f.numerator > 0 => {
                    Some(f64::from(f.denominator) / f64::from(f.numerator))
                }
                _ => None,
            })
            .collect();
        SourceControls {
            resolutions,
            frame_rates,
            exposure: self.control_range(CID_EXPOSURE_ABSOLUTE),
            gain: self.control_range(CID_GAIN),
        }
    }

    fn set_settings(&mut self, wanted: &SourceSettings) -> Result<SourceSettings, SourceError> {
        if let Some(r) = wanted.resolution
            && self.format.map(|(w, h, _)| (w, h)) != Some((r.width, r.height))
        {
            self.start_stream(Some(r))?;
        }
        if let Some(fps) = wanted.frame_rate {
            let fps_int = fps.round().clamp(1.0, 1000.0);
            #[expect(
                clippy::cast_possible_truncation,
                clippy::cast_sign_loss,
                reason = "clamped"
            )]
            let params = v4l::video::capture::Parameters::with_fps(fps_int as u32);
            self.device()?
                .set_params(&params)
                .map_err(|e| self.device_error(&format!("cannot set {fps} frames a second"), &e))?;
        }
        if let Some(v) = wanted.exposure {
            self.set_control(CID_EXPOSURE_ABSOLUTE, v, "exposure")?;
        }
        if let Some(v) = wanted.gain {
            self.set_control(CID_GAIN, v, "gain")?;
        }
        Ok(self.settings())
    }

    fn grab(&mut self) -> Result<SourceFrame, SourceError> {
        let label = self.label();
        let (Some(stream), Some((w, h, packing))) = (self.stream.as_mut(), self.format) else {
            return Err(SourceError::NotConnected(label));
        };
        let (buf, meta) = stream.next().map_err(|e| SourceError::Device {
            label: label.clone(),
            detail: format!("no frame: {e}"),
        })?;
        let (w, h) = (w as usize, h as usize);
        let used = (meta.bytesused as usize).min(buf.len());
        let data = to_uyvy(&buf[..used], w, h, packing).ok_or_else(|| SourceError::Device {
            label: label.clone(),
            detail: format!(
                "a frame of {used} bytes is not {w}×{h} 4:2:2 ({} bytes)",
                w * h * 2
            ),
        })?;
        #[allow(
            clippy::useless_conversion,
            reason = "time_t is i64 here but i32 on 32-bit Linux"
        )]
        let us = i64::from(meta.timestamp.sec) * 1_000_000 + i64::from(meta.timestamp.usec);
        let arrival = std::time::Instant::now();
        let first_arrival = *self.first_arrival.get_or_insert(arrival);
        let time_ns = frame_time_ns(
            us,
            &mut self.first_us,
            self.last_ns,
            arrival.duration_since(first_arrival),
        );
        self.last_ns = Some(time_ns);
        let frame = Frame::from_uyvy(w, h, data).map_err(|error| SourceError::Frame {
            source_label: label,
            error,
        })?;
        Ok(SourceFrame::new(time_ns, frame))
    }
}

/// A frame's time in nanoseconds from the first frame: the driver's timestamp `driver_us`
/// (microseconds) when it has one that moves forward, else `since_first_arrival`, the time
/// since the first frame was dequeued. `first_us` is the first driver timestamp seen.
fn frame_time_ns(
    driver_us: i64,
    first_us: &mut Option<i64>,
    last_ns: Option<u64>,
    since_first_arrival: std::time::Duration,
) -> u64 {
    let arrival_ns = u64::try_from(since_first_arrival.as_nanos()).unwrap_or(u64::MAX);
    if driver_us <= 0 {
        return arrival_ns;
    }
    let first = *first_us.get_or_insert(driver_us);
    let driver_ns = u64::try_from(driver_us.saturating_sub(first))
        .unwrap_or(0)
        .saturating_mul(1000);
    match last_ns {
        Some(last) if driver_ns <= last && last > 0 => arrival_ns.max(last + 1),
        _ => driver_ns,
    }
}

/// A 4:2:2 buffer as UYVY bytes; `None` when it is shorter than `width × height` pixels (a
/// truncated frame from a camera unplugged mid-frame).
fn to_uyvy(bytes: &[u8], width: usize, height: usize, packing: Packing) -> Option<Vec<u8>> {
    let n = width.checked_mul(height)?.checked_mul(2)?;
    let bytes = bytes.get(..n)?;
    Some(match packing {
        Packing::Uyvy => bytes.to_vec(),
        Packing::Yuyv => bytes.chunks_exact(2).flat_map(|p| [p[1], p[0]]).collect(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn yuyv_bytes_become_uyvy_and_short_frames_are_refused() {
        let yuyv = [10, 128, 20, 140, 30, 100, 40, 90];
        assert_eq!(
            to_uyvy(&yuyv, 4, 1, Packing::Yuyv).unwrap(),
            [128, 10, 140, 20, 100, 30, 90, 40]
        );
        assert_eq!(to_uyvy(&yuyv, 4, 1, Packing::Uyvy).unwrap(), yuyv);
        assert!(to_uyvy(&yuyv[..6], 4, 1, Packing::Yuyv).is_none());
    }

    #[test]
    fn frame_times_come_from_the_driver_else_from_arrival() {
        use std::time::Duration;
        let mut first = None;
        // The driver's clock: times from the first frame, whatever the arrival.
        assert_eq!(
            frame_time_ns(5_000_000, &mut first, None, Duration::ZERO),
            0
        );
        assert_eq!(
            frame_time_ns(5_033_000, &mut first, Some(0), Duration::from_millis(50)),
            33_000_000
        );
        // A driver that gives no timestamps: the arrival clock.
        let mut none = None;
        assert_eq!(
            frame_time_ns(0, &mut none, Some(0), Duration::from_millis(40)),
            40_000_000
        );
        // A driver timestamp that runs backwards never makes time go back.
        let t = frame_time_ns(
            5_010_000,
            &mut first,
            Some(33_000_000),
            Duration::from_millis(1),
        );
        assert!(t > 33_000_000, "{t}");
    }

    #[test]
    fn connecting_to_a_path_that_is_no_camera_fails_in_one_line_naming_it() {
        let dir = tempfile::tempdir().unwrap();
        let mut c = CameraSource::new(&dir.path().join("video9"), CameraKind::Overhead);
        assert_eq!(c.info().camera, CameraKind::Overhead);
        let e = c.connect().unwrap_err().to_string();
        assert!(e.contains("video9") && !e.contains('\n'), "{e}");
        assert!(!c.is_connected());
        assert!(matches!(c.grab(), Err(SourceError::NotConnected(_))));
        assert_eq!(c.settings().resolution, None);
    }
}
