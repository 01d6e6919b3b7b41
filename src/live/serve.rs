//! [`StandInRobot`]: a Foxglove WebSocket server (the SDK's own, the `foxglove` crate) that
//! plays a stream's frames at their recorded rate, as a robot would send them: `eotn serve`.
//!
//! The `foxglove` server listens on loopback only; viewers connect to the [`Gate`] in front of
//! it, which bounds clients, handshakes and each viewer's queue (see [`super::gate`]). A frame
//! that cannot be read (a damaged chunk) is skipped with a warning, as `eotn detect` skips it.
//!
//! Each frame goes out as its `foxglove.RawImage` (encoding `yuyv`, the streams' default) on
//! `/camera/image`, then its sensor readings on
//! `/sensors` and its other JSON channels, all with the same log time: the moment it is sent
//! (this machine's clock), so a viewer can measure its latency.

use std::collections::HashMap;
use std::net::SocketAddr;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, OnceLock};
use std::time::{Duration, Instant};

use foxglove::websocket::{ChannelView, Client, ServerListener};
use foxglove::{ChannelBuilder, Context, PartialMetadata, RawChannel, Schema, WebSocketServer};

use super::gate::{Gate, GateFigures, GateOptions};
use super::unix_time_ns;
use crate::streams::schema::{
    EXTRA_SCHEMA_NAME, GROUND_TRUTH_SCHEMA_NAME, ImageEncoding, ImageMessageError,
    RECOGNITION_SCHEMA_NAME, SENSORS_SCHEMA_NAME, any_json_schema, encode_image,
    object_json_schema, raw_image_schema, sensors_json_schema,
};
use crate::streams::{
    FrameRecord, GROUND_TRUTH_TOPIC, IMAGE_TOPIC, RECOGNITION_TOPIC, SENSORS_TOPIC, StreamError,
    StreamReader,
};

/// Why the stand-in robot could not start or play.
#[derive(Debug, thiserror::Error)]
pub enum ServeError {
    /// The server could not listen (port in use, bad host).
    #[error("cannot listen on {addr}: {detail}")]
    Listen {
        /// The address asked for.
        addr: String,
        /// What the SDK said.
        detail: String,
    },
    /// A channel could not be made.
    #[error("cannot make channel {topic}: {detail}")]
    Channel {
        /// The topic.
        topic: String,
        /// What the SDK said.
        detail: String,
    },
    /// The stream could not be read.
    #[error(transparent)]
    Stream(#[from] StreamError),
    /// No frame of the stream could be read or sent (every chunk damaged).
    #[error("none of the stream's {frames} frames could be read")]
    Unreadable {
        /// Frames the stream has.
        frames: usize,
    },
    /// A frame could not be sent.
    #[error("frame {index}: {error}")]
    Frame {
        /// The frame.
        index: usize,
        /// What is wrong.
        #[source]
        error: SendError,
    },
}

/// Why one frame could not be sent ([`StandInRobot::send`]).
#[derive(Debug, thiserror::Error)]
pub enum SendError {
    /// Its image cannot become a `foxglove.RawImage` (odd width, too large).
    #[error(transparent)]
    Image(#[from] ImageMessageError),
    /// A value of a JSON channel (sensor readings, ground truth, …) cannot be written as JSON.
    #[error("{topic}: {source}")]
    Json {
        /// The channel's topic.
        topic: String,
        /// What serde said.
        source: serde_json::Error,
    },
    /// A JSON channel could not be made.
    #[error("cannot make channel {topic}: {detail}")]
    Channel {
        /// The topic.
        topic: String,
        /// What the SDK said.
        detail: String,
    },
}

/// Sets a flag when a viewer subscribes to the image channel.
struct ViewerFlag(Arc<AtomicBool>);

impl ServerListener for ViewerFlag {
    fn on_subscribe(&self, _client: Client, channel: ChannelView) {
        if channel.topic() == IMAGE_TOPIC {
            self.0.store(true, Ordering::Relaxed);
        }
    }
}

/// Messages the `foxglove` server queues per viewer. Its queues feed the gate's relays, which
/// drain them at once; the viewers' own bounds are the gate's [`super::gate::QueueBound`].
const INNER_BACKLOG: usize = 64;

/// The tokio runtime every stand-in robot of this process runs on (the gate's tasks and the
/// `foxglove` server's), started with the first.
fn runtime() -> Result<&'static tokio::runtime::Runtime, String> {
    static RUNTIME: OnceLock<Result<tokio::runtime::Runtime, String>> = OnceLock::new();
    RUNTIME
        .get_or_init(|| {
            tokio::runtime::Builder::new_multi_thread()
                .worker_threads(2)
                .thread_name("eotn-serve")
                .enable_all()
                .build()
                .map_err(|e| e.to_string())
        })
        .as_ref()
        .map_err(Clone::clone)
}

/// A running Foxglove WebSocket server with the stream's channels.
pub struct StandInRobot {
    context: Arc<Context>,
    handle: Option<foxglove::WebSocketServerHandle>,
    gate: Gate,
    /// Frames sent so far (shared with the gate, which counts what slow viewers miss).
    frames_sent: Arc<AtomicU64>,
    /// Frames skipped because they could not be read, in all passes.
    skipped: usize,
    image: Arc<RawChannel>,
    sensors: Arc<RawChannel>,
    json: HashMap<String, Arc<RawChannel>>,
    viewer: Arc<AtomicBool>,
    port: u16,
    buf: Vec<u8>,
}

impl std::fmt::Debug for StandInRobot {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("StandInRobot")
            .field("port", &self.port)
            .finish_non_exhaustive()
    }
}

impl StandInRobot {
    /// Starts the server on `host:port` (port 0: any free port) under the server name `name`,
    /// with the gate's default bounds.
    ///
    /// # Errors
    /// [`ServeError::Listen`] when it cannot listen.
    pub fn start(name: &str, host: &str, port: u16) -> Result<Self, ServeError> {
        Self::start_with(name, host, port, GateOptions::default())
    }

    /// Starts the server on `host:port` (port 0: any free port) under the server name `name`,
    /// admitting viewers as `options` say.
    ///
    /// # Errors
    /// [`ServeError::Listen`] when it cannot listen.
    pub fn start_with(
        name: &str,
        host: &str,
        port: u16,
        options: GateOptions,
    ) -> Result<Self, ServeError> {
        let listen_error = |detail: String| ServeError::Listen {
            addr: format!("{host}:{port}"),
            detail,
        };
        let runtime = runtime().map_err(listen_error)?;
        let context = Context::new();
        let viewer = Arc::new(AtomicBool::new(false));
        let channel = |topic: &str, encoding: &str, schema: Option<Schema>| {
            ChannelBuilder::new(topic)
                .context(&context)
                .message_encoding(encoding)
                .schema(schema)
                .build_raw()
                .map_err(|e| ServeError::Channel {
                    topic: topic.to_owned(),
                    detail: e.to_string(),
                })
        };
        let image = channel(IMAGE_TOPIC, "protobuf", raw_image_schema())?;
        let sensors = channel(
            SENSORS_TOPIC,
            "json",
            Some(json_schema(SENSORS_SCHEMA_NAME, &sensors_json_schema())),
        )?;
        let server = WebSocketServer::new()
            .name(name)
            .bind("127.0.0.1", 0)
            .context(&context)
            .message_backlog_size(INNER_BACKLOG)
            .listener(Arc::new(ViewerFlag(Arc::clone(&viewer))));
        // Started inside our runtime, the server runs its tasks on it.
        let handle = runtime
            .block_on(server.start())
            .map_err(|e| listen_error(e.to_string()))?;
        let inner = SocketAddr::from(([127, 0, 0, 1], handle.port()));
        let frames_sent = Arc::new(AtomicU64::new(0));
        let gate = match Gate::start(
            runtime.handle(),
            (host, port),
            inner,
            Arc::clone(&frames_sent),
            options,
        ) {
            Ok(gate) => gate,
            Err(e) => {
                drop(handle.stop());
                return Err(listen_error(e.to_string()));
            }
        };
        let port = gate.port();
        Ok(Self {
            context,
            handle: Some(handle),
            gate,
            frames_sent,
            skipped: 0,
            image,
            sensors,
            json: HashMap::new(),
            viewer,
            port,
            buf: Vec::new(),
        })
    }

    /// The port it listens on.
    #[must_use]
    pub fn port(&self) -> u16 {
        self.port
    }

    /// The gate's figures: viewers, refusals, frames dropped for slow viewers.
    #[must_use]
    pub fn figures(&self) -> GateFigures {
        self.gate.figures()
    }

    /// Frames skipped so far because they could not be read (damaged chunks).
    #[must_use]
    pub const fn skipped(&self) -> usize {
        self.skipped
    }

    /// True once a viewer has subscribed to the images.
    #[must_use]
    pub fn has_viewer(&self) -> bool {
        self.viewer.load(Ordering::Relaxed)
    }

    /// Sends one frame now: its image, then its sensor readings and JSON channels, with this
    /// machine's clock as their log time; returns that time, nanoseconds since the Unix epoch.
    ///
    /// # Errors
    /// [`SendError`] when the frame cannot be encoded or a channel made.
    pub fn send(&mut self, record: &FrameRecord) -> Result<u64, SendError> {
        encode_image(
            record.time_ns,
            &record.frame,
            ImageEncoding::default(),
            &mut self.buf,
        )?;
        let meta = PartialMetadata::with_log_time(unix_time_ns());
        let log_time = meta.log_time.unwrap_or(0);
        self.image.log_with_meta(&self.buf, meta);
        self.frames_sent.fetch_add(1, Ordering::Relaxed);
        if let Some(s) = &record.sensors {
            let json = serde_json::to_vec(&s.sanitised().0).map_err(|source| SendError::Json {
                topic: SENSORS_TOPIC.to_owned(),
                source,
            })?;
            self.sensors.log_with_meta(&json, meta);
        }
        let fixed = [
            (GROUND_TRUTH_TOPIC, record.ground_truth.as_ref()),
            (RECOGNITION_TOPIC, record.recognition.as_ref()),
        ];
        let extra = record.extra.iter().map(|(t, v)| (t.as_str(), Some(v)));
        for (topic, value) in fixed.into_iter().chain(extra) {
            let Some(value) = value else { continue };
            let json = serde_json::to_vec(value).map_err(|source| SendError::Json {
                topic: topic.to_owned(),
                source,
            })?;
            self.json_channel(topic)?.log_with_meta(&json, meta);
        }
        Ok(log_time)
    }

    /// The JSON channel of `topic`, made the first time it is asked for.
    fn json_channel(&mut self, topic: &str) -> Result<&Arc<RawChannel>, SendError> {
        use std::collections::hash_map::Entry;
        let slot = match self.json.entry(topic.to_owned()) {
            Entry::Occupied(made) => return Ok(made.into_mut()),
            Entry::Vacant(slot) => slot,
        };
        let schema = match topic {
            GROUND_TRUTH_TOPIC => json_schema(
                GROUND_TRUTH_SCHEMA_NAME,
                &object_json_schema(GROUND_TRUTH_SCHEMA_NAME, "Ground truth."),
            ),
            RECOGNITION_TOPIC => json_schema(
                RECOGNITION_SCHEMA_NAME,
                &object_json_schema(RECOGNITION_SCHEMA_NAME, "Recognition results."),
            ),
            _ => json_schema(EXTRA_SCHEMA_NAME, &any_json_schema()),
        };
        let channel = ChannelBuilder::new(topic)
            .context(&self.context)
            .message_encoding("json")
            .schema(schema)
            .build_raw()
            .map_err(|e| SendError::Channel {
                topic: topic.to_owned(),
                detail: e.to_string(),
            })?;
        Ok(slot.insert(channel))
    }

    /// Plays a stream at its recorded rate (again and again with `looping`) until it ends or
    /// `stop` is set; returns the frames sent. With `wait_for_viewer` nothing is sent before a
    /// viewer has subscribed to the images. A frame that cannot be read or encoded (a damaged
    /// chunk) is skipped, with a warning naming the frames on the first pass.
    ///
    /// # Errors
    /// [`ServeError::Unreadable`] when no frame of a pass could be sent; [`ServeError::Frame`]
    /// when a channel cannot be made.
    pub fn play(
        &mut self,
        reader: &mut StreamReader,
        looping: bool,
        wait_for_viewer: bool,
        stop: &AtomicBool,
    ) -> Result<usize, ServeError> {
        let stopped = || stop.load(Ordering::Relaxed);
        while wait_for_viewer && !self.has_viewer() && !stopped() {
            std::thread::sleep(Duration::from_millis(10));
        }
        let mut sent = 0;
        let mut first_pass = true;
        loop {
            let mut skipped = SkippedRun::default();
            let start = Instant::now();
            let first = reader.time_ns(0).unwrap_or(0);
            let mut sent_in_pass = 0;
            for index in 0..reader.len() {
                let offset = reader.time_ns(index).unwrap_or(first).saturating_sub(first);
                let due = start + Duration::from_nanos(offset);
                while Instant::now() < due {
                    if stopped() {
                        return Ok(sent);
                    }
                    let left = due.saturating_duration_since(Instant::now());
                    std::thread::sleep(left.min(Duration::from_millis(20)));
                }
                if stopped() {
                    return Ok(sent);
                }
                let sent_frame = match reader.read(index) {
                    Ok(record) => match self.send(&record) {
                        Ok(_) => Ok(()),
                        Err(error @ SendError::Channel { .. }) => {
                            return Err(ServeError::Frame { index, error });
                        }
                        Err(e) => Err(format!("{}: {e}", reader.path().display())),
                    },
                    Err(e) => Err(e.to_string()),
                };
                match sent_frame {
                    Ok(()) => {
                        sent += 1;
                        sent_in_pass += 1;
                    }
                    Err(why) => {
                        self.skipped += 1;
                        if first_pass {
                            skipped.note(index, why);
                        }
                    }
                }
            }
            drop(skipped);
            first_pass = false;
            if sent_in_pass == 0 && !reader.is_empty() {
                return Err(ServeError::Unreadable {
                    frames: reader.len(),
                });
            }
            if !looping || reader.is_empty() {
                return Ok(sent);
            }
            // One frame period between the last frame and the first again.
            let period = reader
                .time_ns(1)
                .map_or(33_000_000, |t| t.saturating_sub(first).max(1));
            std::thread::sleep(Duration::from_nanos(period));
        }
    }

    /// Stops the server, letting queued messages go out first (waiting at most a second for
    /// viewers that do not read); the gate's figures at the end.
    pub fn stop(mut self) -> GateFigures {
        self.shutdown(true);
        self.gate.figures()
    }

    fn shutdown(&mut self, wait: bool) {
        if let Some(h) = self.handle.take() {
            let stopping = h.stop();
            if wait {
                stopping.wait_blocking();
                // The relays pass on what is queued and close their viewers.
                let until = Instant::now() + Duration::from_secs(1);
                while self.gate.figures().clients > 0 && Instant::now() < until {
                    std::thread::sleep(Duration::from_millis(10));
                }
            } else {
                stopping.detach_all();
            }
        }
        self.gate.stop();
    }
}

impl Drop for StandInRobot {
    /// Stops the server without waiting.
    fn drop(&mut self) {
        self.shutdown(false);
    }
}

/// Consecutive skipped frames, said as one warning when the run ends (as `eotn detect` says
/// them).
#[derive(Default)]
struct SkippedRun(Option<(usize, usize, String)>);

impl SkippedRun {
    fn note(&mut self, index: usize, why: String) {
        if let Some((_, last, _)) = self.0.as_mut()
            && *last + 1 == index
        {
            *last = index;
            return;
        }
        self.flush();
        self.0 = Some((index, index, why));
    }

    fn flush(&mut self) {
        if let Some((first, last, why)) = self.0.take() {
            let frames = if first == last {
                format!("frame {first}")
            } else {
                format!("frames {first}–{last}")
            };
            log::warn!("eotn serve: {frames} skipped, unreadable: {why}");
        }
    }
}

impl Drop for SkippedRun {
    fn drop(&mut self) {
        self.flush();
    }
}

fn json_schema(name: &str, schema: &serde_json::Value) -> Schema {
    Schema::new(name, "jsonschema", schema.to_string().into_bytes())
}
