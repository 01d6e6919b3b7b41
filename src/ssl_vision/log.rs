//! The league's game logs (ssl.robocup.org, "Game Logs"): the header `SSL_LOG_FILE` and a
//! 32-bit format version (1), then messages, each a 64-bit receiver timestamp (nanoseconds), a
//! 32-bit message type, a 32-bit size and that many bytes of payload; every integer big-endian.
//! The league publishes them gzip-compressed (`.log.gz`): those are read through the
//! decompressor, told by the gzip magic, not the name.
//!
//! Message types: 0 blank (ignored), 1 unknown (the payload is tried as a vision packet),
//! 2 vision (2010), 3 referee (2013), 4 vision (2014), 5 vision tracker (2020), 6 index (2021,
//! the last message of an indexed file, not protobuf). Vision packets are read; the rest are
//! counted by type and skipped. A vision payload that does not decode is counted and skipped;
//! a log cut off inside a message keeps what came before it, with a note.
//!
//! Reading is message by message from any reader, so a log of any length is read in bounded
//! memory per message ([`MAX_MESSAGE_BYTES`]); [`read_log`] keeps the decoded detection frames
//! up to a cap ([`MAX_FRAMES`]), saying when it stops.

use std::collections::BTreeMap;
use std::io::{BufReader, Read};
use std::path::Path;

use super::{CameraFrame, SslGeometryData, decode_packet};

/// The first bytes of every log.
pub const LOG_MAGIC: &[u8; 12] = b"SSL_LOG_FILE";

/// The one format version there is.
pub const LOG_VERSION: i32 = 1;

/// Largest message payload read, bytes (a vision packet fits a UDP datagram; a referee
/// message is smaller; an index is 8 bytes per message, so this allows two million).
pub const MAX_MESSAGE_BYTES: usize = 16 << 20;

/// Most detection frames [`read_log`] keeps (a whole game at 4 cameras × 75 Hz is about 3
/// million; this is an hour of one camera at 75 Hz, about 1 GB of memory at most).
pub const MAX_FRAMES: usize = 2_000_000;

/// A log message's type, by the league's numbers.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum MessageType {
    /// 0: to be ignored.
    Blank,
    /// 1: not said; tried as a vision packet.
    Unknown,
    /// 2: an ssl-vision packet (2010).
    Vision2010,
    /// 3: a referee message (2013).
    Refbox2013,
    /// 4: an ssl-vision packet (2014).
    Vision2014,
    /// 5: a vision tracker packet (2020).
    VisionTracker2020,
    /// 6: the index at the end of an indexed log (2021).
    Index2021,
    /// Any other number.
    Other(i32),
}

impl MessageType {
    /// The type of a number.
    #[must_use]
    pub const fn from_code(code: i32) -> Self {
        match code {
            0 => Self::Blank,
            1 => Self::Unknown,
            2 => Self::Vision2010,
            3 => Self::Refbox2013,
            4 => Self::Vision2014,
            5 => Self::VisionTracker2020,
            6 => Self::Index2021,
            other => Self::Other(other),
        }
    }

    /// Its number.
    #[must_use]
    pub const fn code(self) -> i32 {
        match self {
            Self::Blank => 0,
            Self::Unknown => 1,
            Self::Vision2010 => 2,
            Self::Refbox2013 => 3,
            Self::Vision2014 => 4,
            Self::VisionTracker2020 => 5,
            Self::Index2021 => 6,
            Self::Other(c) => c,
        }
    }

    /// A name for counts and messages.
    #[must_use]
    pub fn name(self) -> String {
        match self {
            Self::Blank => "blank".to_owned(),
            Self::Unknown => "unknown".to_owned(),
            Self::Vision2010 => "vision (2010)".to_owned(),
            Self::Refbox2013 => "referee".to_owned(),
            Self::Vision2014 => "vision".to_owned(),
            Self::VisionTracker2020 => "vision tracker".to_owned(),
            Self::Index2021 => "index".to_owned(),
            Self::Other(c) => format!("type {c}"),
        }
    }
}

/// Why a log cannot be read.
#[derive(Debug, thiserror::Error)]
pub enum LogError {
    /// The file cannot be read.
    #[error("cannot read: {0}")]
    Io(#[from] std::io::Error),
    /// No `SSL_LOG_FILE` header.
    #[error("not an SSL-Vision log: it does not start with SSL_LOG_FILE")]
    NotSslLog,
    /// No `SSL_LOG_FILE` header, and the file is a B-Human robot log (also `.log`).
    #[error(
        "a B-Human robot log, not an SSL-Vision game log: `eotn import --bhuman {path} -o OUT.mcap` turns it into a stream eotn opens"
    )]
    BhumanLog {
        /// The file.
        path: String,
    },
    /// A format version this reader does not know.
    #[error("SSL log format version {version}; only version {LOG_VERSION} is known")]
    Version {
        /// The version the header gives.
        version: i32,
    },
}

/// One message of a log, as stored.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct LogMessage {
    /// The receiver's timestamp, nanoseconds.
    pub receiver_ns: i64,
    /// Its type.
    pub kind: MessageType,
    /// Its payload.
    pub payload: Vec<u8>,
}

/// A log read message by message.
#[derive(Debug)]
pub struct LogReader<R> {
    inner: R,
    offset: u64,
    /// Set when the log ends inside a message: what was wrong, and where.
    pub cut_off: Option<String>,
}

impl<R: Read> LogReader<R> {
    /// Reads and checks the header.
    ///
    /// # Errors
    /// [`LogError::NotSslLog`] without the magic, [`LogError::Version`] for another version,
    /// [`LogError::Io`] when reading fails.
    pub fn new(mut inner: R) -> Result<Self, LogError> {
        let mut header = [0u8; 16];
        let got = read_up_to(&mut inner, &mut header)?;
        if got < LOG_MAGIC.len() || &header[..12] != LOG_MAGIC {
            return Err(LogError::NotSslLog);
        }
        if got < 16 {
            return Err(LogError::Version { version: -1 });
        }
        let version = i32::from_be_bytes([header[12], header[13], header[14], header[15]]);
        if version != LOG_VERSION {
            return Err(LogError::Version { version });
        }
        Ok(Self {
            inner,
            offset: 16,
            cut_off: None,
        })
    }

    /// The next message, `None` at the end (or where the log is cut off: see `cut_off`).
    ///
    /// # Errors
    /// [`LogError::Io`] when reading fails.
    pub fn next_message(&mut self) -> Result<Option<LogMessage>, LogError> {
        if self.cut_off.is_some() {
            return Ok(None);
        }
        let mut head = [0u8; 16];
        let got = read_up_to(&mut self.inner, &mut head)?;
        if got == 0 {
            return Ok(None);
        }
        let at = self.offset;
        if got < 16 {
            self.cut_off = Some(format!("cut off inside a message header at byte {at}"));
            return Ok(None);
        }
        let receiver_ns = i64::from_be_bytes([
            head[0], head[1], head[2], head[3], head[4], head[5], head[6], head[7],
        ]);
        let kind =
            MessageType::from_code(i32::from_be_bytes([head[8], head[9], head[10], head[11]]));
        let size = i32::from_be_bytes([head[12], head[13], head[14], head[15]]);
        let Some(size) = usize::try_from(size)
            .ok()
            .filter(|s| *s <= MAX_MESSAGE_BYTES)
        else {
            self.cut_off = Some(format!(
                "a message at byte {at} claims {size} bytes (at most {MAX_MESSAGE_BYTES}): the rest is not read"
            ));
            return Ok(None);
        };
        let mut payload = vec![0u8; size];
        let got = read_up_to(&mut self.inner, &mut payload)?;
        if got < size {
            self.cut_off = Some(format!(
                "cut off at byte {}: the message at byte {at} needs {size} bytes, {got} are left",
                at + 16 + got as u64
            ));
            return Ok(None);
        }
        self.offset = at + 16 + size as u64;
        Ok(Some(LogMessage {
            receiver_ns,
            kind,
            payload,
        }))
    }
}

/// Reads until `buf` is full or the input ends; the bytes read.
fn read_up_to(r: &mut impl Read, buf: &mut [u8]) -> std::io::Result<usize> {
    let mut got = 0;
    while got < buf.len() {
        match r.read(&mut buf[got..]) {
            Ok(0) => break,
            Ok(n) => got += n,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            Err(e) => return Err(e),
        }
    }
    Ok(got)
}

/// A detection frame of a log with the receiver's timestamp.
#[derive(Debug, Clone, PartialEq)]
pub struct LoggedFrame {
    /// When the logger received it, nanoseconds.
    pub receiver_ns: i64,
    /// The camera's detections.
    pub frame: CameraFrame,
}

/// What a log holds for eotn: its detection frames (in file order), its last geometry, and
/// counts of everything else.
#[derive(Debug, Clone, Default)]
pub struct SslLog {
    /// The detection frames, in file order.
    pub frames: Vec<LoggedFrame>,
    /// The last geometry message, if any.
    pub geometry: Option<SslGeometryData>,
    /// Vision packets read (with detections, geometry or both).
    pub vision_packets: usize,
    /// Messages skipped, by type name (referee, tracker, blank, index, …).
    pub skipped: BTreeMap<String, usize>,
    /// Vision payloads that did not decode, and the first reason.
    pub undecodable: (usize, Option<String>),
    /// Objects left out of frames for non-finite coordinates.
    pub dropped_objects: usize,
    /// Where the log ended early, if it did.
    pub cut_off: Option<String>,
    /// Set when [`MAX_FRAMES`] was reached and later frames were not kept.
    pub capped: bool,
}

impl SslLog {
    /// One line on what was read and skipped, for the status line and stderr.
    #[must_use]
    pub fn summary(&self) -> String {
        let mut parts = vec![format!(
            "{} detection frames from {} vision packets",
            self.frames.len(),
            self.vision_packets
        )];
        if !self.skipped.is_empty() {
            let skipped: Vec<String> = self
                .skipped
                .iter()
                .map(|(k, n)| format!("{n} {k}"))
                .collect();
            parts.push(format!("skipped {}", skipped.join(", ")));
        }
        if let (n @ 1.., Some(why)) = (self.undecodable.0, &self.undecodable.1) {
            parts.push(format!("{n} vision packets did not decode (first: {why})"));
        }
        if self.dropped_objects > 0 {
            parts.push(format!(
                "{} objects with non-finite coordinates left out",
                self.dropped_objects
            ));
        }
        if let Some(c) = &self.cut_off {
            parts.push(c.clone());
        }
        if self.capped {
            parts.push(format!("only the first {MAX_FRAMES} frames kept"));
        }
        parts.join("; ")
    }

    fn take(&mut self, m: &LogMessage) {
        let vision = matches!(
            m.kind,
            MessageType::Vision2010 | MessageType::Vision2014 | MessageType::Unknown
        );
        if !vision {
            *self.skipped.entry(m.kind.name()).or_default() += 1;
            return;
        }
        match decode_packet(&m.payload) {
            Ok(p) => {
                self.vision_packets += 1;
                if let Some(g) = p.geometry {
                    self.geometry = Some(g);
                }
                if let Some(d) = p.detection {
                    let frame = CameraFrame::from_message(&d);
                    self.dropped_objects += frame.dropped;
                    if self.frames.len() < MAX_FRAMES {
                        self.frames.push(LoggedFrame {
                            receiver_ns: m.receiver_ns,
                            frame,
                        });
                    } else {
                        self.capped = true;
                    }
                }
            }
            Err(_) if m.kind == MessageType::Unknown => {
                *self.skipped.entry(m.kind.name()).or_default() += 1;
            }
            Err(e) => {
                self.undecodable.0 += 1;
                self.undecodable.1.get_or_insert_with(|| e.to_string());
            }
        }
    }
}

/// Reads a whole log from `input` (see the module documentation).
///
/// # Errors
/// [`LogError`] for a missing header, another version or a read failure; damage after the
/// header is counted and noted, not an error.
pub fn read_log(input: impl Read) -> Result<SslLog, LogError> {
    let mut reader = LogReader::new(input)?;
    let mut log = SslLog::default();
    while let Some(m) = reader.next_message()? {
        log.take(&m);
    }
    log.cut_off = reader.cut_off.take();
    Ok(log)
}

/// Reads a log held in memory (the fuzz target's entry).
///
/// # Errors
/// As [`read_log`].
pub fn parse_log(bytes: &[u8]) -> Result<SslLog, LogError> {
    read_log(bytes)
}

/// Whether a file starts as an SSL-Vision log does (plain or gzip-compressed).
#[must_use]
pub fn is_ssl_log(path: &Path) -> bool {
    open_reader(path)
        .ok()
        .and_then(|mut r| {
            let mut magic = [0u8; 12];
            read_up_to(&mut r, &mut magic).ok().map(|n| (n, magic))
        })
        .is_some_and(|(n, magic)| n == 12 && &magic == LOG_MAGIC)
}

/// The file's bytes, through the gzip decompressor when it starts with gzip's magic.
fn open_reader(path: &Path) -> std::io::Result<Box<dyn Read>> {
    let meta = std::fs::metadata(path)?;
    if !meta.is_file() {
        return Err(std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            "not a regular file",
        ));
    }
    let mut file = BufReader::new(std::fs::File::open(path)?);
    let mut magic = [0u8; 2];
    let got = read_up_to(&mut file, &mut magic)?;
    let head = std::io::Cursor::new(magic[..got].to_vec());
    let whole = head.chain(file);
    Ok(if got == 2 && magic == [0x1f, 0x8b] {
        Box::new(BufReader::new(flate2::read::MultiGzDecoder::new(whole)))
    } else {
        Box::new(whole)
    })
}

/// Largest file tried as a B-Human log when the SSL header is missing, bytes.
const MAX_BHUMAN_PROBE_BYTES: u64 = 256 << 20;

/// Reads a log file (plain or gzip-compressed). A file without the header that is a B-Human
/// robot log (the same `.log` name) is told apart, so the error can point to its importer.
///
/// # Errors
/// As [`read_log`]; [`LogError::BhumanLog`]; a path that is not a regular file.
pub fn read_log_file(path: &Path) -> Result<SslLog, LogError> {
    match read_log(open_reader(path)?) {
        Err(LogError::NotSslLog) if is_bhuman_log(path) => Err(LogError::BhumanLog {
            path: path.display().to_string(),
        }),
        other => other,
    }
}

/// Whether B-Human's log reader takes the file (`import::bhuman::parse_log`).
fn is_bhuman_log(path: &Path) -> bool {
    crate::input_file::read_bounded(path, MAX_BHUMAN_PROBE_BYTES, "a B-Human log")
        .ok()
        .is_some_and(|bytes| crate::import::bhuman::parse_log(&bytes).is_ok())
}

/// Appends a log's header to `out`.
pub fn write_header(out: &mut Vec<u8>) {
    out.extend_from_slice(LOG_MAGIC);
    out.extend_from_slice(&LOG_VERSION.to_be_bytes());
}

/// Appends one message to `out`, as [`LogReader`] reads it.
///
/// # Panics
/// Never for a payload that fits a log (`i32` bytes); a longer one is a caller's bug.
pub fn write_message(out: &mut Vec<u8>, receiver_ns: i64, kind: MessageType, payload: &[u8]) {
    out.extend_from_slice(&receiver_ns.to_be_bytes());
    out.extend_from_slice(&kind.code().to_be_bytes());
    let size = i32::try_from(payload.len()).unwrap_or(i32::MAX);
    out.extend_from_slice(&size.to_be_bytes());
    out.extend_from_slice(payload);
}

#[cfg(test)]
mod tests {
    use prost::Message as _;

    use super::*;
    use crate::ssl_vision::SslWrapperPacket;
    use crate::ssl_vision::messages::SslDetectionFrame;

    fn vision(camera: u32, n: u32) -> Vec<u8> {
        SslWrapperPacket {
            detection: Some(SslDetectionFrame {
                frame_number: n,
                t_capture: f64::from(n) / 60.0,
                camera_id: camera,
                ..SslDetectionFrame::default()
            }),
            geometry: None,
        }
        .encode_to_vec()
    }

    #[test]
    fn vision_is_read_the_rest_counted_and_a_cut_off_tail_noted() {
        let mut log = Vec::new();
        write_header(&mut log);
        write_message(&mut log, 1, MessageType::Vision2014, &vision(0, 1));
        write_message(&mut log, 2, MessageType::Refbox2013, b"\x08\x01");
        write_message(&mut log, 3, MessageType::Vision2014, &[0xff, 0xff]);
        write_message(&mut log, 4, MessageType::Blank, &[]);
        write_message(&mut log, 5, MessageType::Vision2010, &vision(1, 2));
        let whole = log.len();
        write_message(&mut log, 6, MessageType::Vision2014, &vision(0, 3));
        log.truncate(whole + 20);
        let read = parse_log(&log).expect("a log");
        assert_eq!(read.frames.len(), 2);
        assert_eq!(read.frames[1].frame.camera_id, 1);
        assert_eq!(read.skipped.get("referee"), Some(&1));
        assert_eq!(read.skipped.get("blank"), Some(&1));
        assert_eq!(read.undecodable.0, 1);
        assert!(
            read.cut_off
                .as_deref()
                .is_some_and(|c| c.contains("cut off"))
        );
        assert!(
            read.summary().contains("2 detection frames"),
            "{}",
            read.summary()
        );
    }

    #[test]
    fn a_wrong_header_or_version_is_refused() {
        assert!(matches!(parse_log(b"HELLO"), Err(LogError::NotSslLog)));
        let mut v2 = LOG_MAGIC.to_vec();
        v2.extend_from_slice(&2i32.to_be_bytes());
        assert!(matches!(
            parse_log(&v2),
            Err(LogError::Version { version: 2 })
        ));
        // A huge size claim stops reading without allocating it.
        let mut log = Vec::new();
        write_header(&mut log);
        log.extend_from_slice(&0i64.to_be_bytes());
        log.extend_from_slice(&4i32.to_be_bytes());
        log.extend_from_slice(&i32::MAX.to_be_bytes());
        let read = parse_log(&log).expect("header fine");
        assert!(read.cut_off.is_some_and(|c| c.contains("claims")));
    }

    #[test]
    fn a_gzip_log_reads_as_the_plain_one() {
        use std::io::Write as _;
        let dir = tempfile::tempdir().expect("temp");
        let mut log = Vec::new();
        write_header(&mut log);
        write_message(&mut log, 1, MessageType::Vision2014, &vision(2, 7));
        let path = dir.path().join("game.log.gz");
        let mut gz = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
        gz.write_all(&log).expect("compress");
        std::fs::write(&path, gz.finish().expect("compress")).expect("write");
        assert!(is_ssl_log(&path));
        let read = read_log_file(&path).expect("reads");
        assert_eq!(read.frames.len(), 1);
        assert_eq!(read.frames[0].frame.frame_number, 7);
    }
}
