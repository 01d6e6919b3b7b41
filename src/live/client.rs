//! [`RobotClient`]: one robot's Foxglove WebSocket connection on a thread of its own.
//!
//! The thread connects, subscribes to every channel the robot advertises, hands each message to
//! the owner's handler (on this thread), pings the robot when it is quiet, and reconnects with a
//! growing back-off when the connection drops or the robot sends something malformed or
//! oversized. One robot's faults never reach another's thread.
//!
//! Every wait has a deadline and every store a bound, both in [`Limits`]: the TCP connect, the
//! whole handshake, the robot's first message, silence; channels, names, schemas, messages.
//! [`RobotClient::stop`] waits at most half a second; dropping a client does not wait at all.

use std::io::ErrorKind;
use std::net::{TcpStream, ToSocketAddrs};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use tungstenite::client::IntoClientRequest;
use tungstenite::protocol::WebSocketConfig;
use tungstenite::{Message, WebSocket};

use super::channels::{Channels, cut};
use super::protocol::{
    AdvertisedChannel, ServerMessage, parse_binary, parse_text, subscribe_request,
};
use super::{RobotUrl, SUBPROTOCOLS, unix_time_ns};

/// Every bound the live client keeps, in one place: what a robot can make it hold in memory or
/// wait for. A robot past a bound is dropped (a message too large, a deadline missed: the
/// connection closes and is retried) or trimmed (channels and names: the excess is not
/// subscribed, with a warning, and the rest goes on).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Limits {
    /// Channels subscribed on one connection; later ones are refused with a warning.
    pub max_channels: usize,
    /// Longest topic, encoding or schema name of a channel, bytes (such a channel is refused),
    /// and longest server name (cut to it).
    pub max_name_bytes: usize,
    /// Largest schema of a channel, bytes (such a channel is refused).
    pub max_schema_bytes: usize,
    /// Largest message, bytes; a larger one closes the connection.
    pub max_message_bytes: usize,
    /// JSON messages held while they wait for their frame's image, at most this many…
    pub queue_messages: usize,
    /// …and at most this many bytes (older ones are let go first).
    pub queue_bytes: usize,
    /// Time to open the TCP connection (each address the name resolves to).
    pub connect_timeout: Duration,
    /// Time for the whole WebSocket handshake, however slowly the robot answers.
    pub handshake_timeout: Duration,
    /// Time from the handshake to the robot's `serverInfo`, its first message.
    pub first_message_timeout: Duration,
    /// A ping is sent after this long without hearing from the robot.
    pub ping_after: Duration,
    /// The connection is dropped after this long without hearing from the robot.
    pub silence_timeout: Duration,
}

impl Default for Limits {
    fn default() -> Self {
        Self {
            max_channels: 256,
            max_name_bytes: 255,
            max_schema_bytes: 256 << 10,
            max_message_bytes: 64 << 20,
            queue_messages: 64,
            queue_bytes: 16 << 20,
            connect_timeout: Duration::from_secs(3),
            handshake_timeout: Duration::from_secs(3),
            first_message_timeout: Duration::from_secs(5),
            ping_after: Duration::from_secs(2),
            silence_timeout: Duration::from_secs(10),
        }
    }
}

/// How a [`RobotClient`] connects: its [`Limits`] and how it retries.
#[derive(Debug, Clone)]
pub struct ClientOptions {
    /// What a robot can make the client hold or wait for.
    pub limits: Limits,
    /// First wait before reconnecting; doubled after each failed attempt.
    pub backoff_min: Duration,
    /// Longest wait between reconnection attempts.
    pub backoff_max: Duration,
}

impl Default for ClientOptions {
    fn default() -> Self {
        Self {
            limits: Limits::default(),
            backoff_min: Duration::from_millis(100),
            backoff_max: Duration::from_secs(2),
        }
    }
}

/// What happened on a robot's connection, handed to the owner's handler in order.
#[derive(Debug, Clone)]
pub enum LiveEvent {
    /// The handshake succeeded and the robot named itself (`serverInfo`).
    Connected {
        /// The server's name.
        server_name: String,
    },
    /// The robot advertised channels (already subscribed).
    Advertised(Vec<Arc<AdvertisedChannel>>),
    /// One message, its payload exactly as sent.
    Message {
        /// The channel it came on.
        channel: Arc<AdvertisedChannel>,
        /// The sender's log time, nanoseconds since the Unix epoch.
        log_time_ns: u64,
        /// When it was read off the socket, nanoseconds since the Unix epoch (this machine).
        received_ns: u64,
        /// The message bytes.
        payload: Vec<u8>,
    },
    /// A status message from the robot (cut to [`MAX_STATUS_BYTES`]).
    Status(String),
    /// Something the robot did that the client trimmed or worked around (a limit reached, a
    /// long name cut, a channel advertised again), in one line.
    Warning(String),
    /// The connection failed or ended; the client retries after `retry_in`.
    Disconnected {
        /// Why, in one line.
        reason: String,
        /// True when the robot misbehaved (garbage, a message too large, a deadline missed in
        /// the handshake) rather than went away.
        fault: bool,
        /// Wait before the next attempt.
        retry_in: Duration,
    },
}

/// Why a connection ended, in one line, and whether the robot was at fault.
#[derive(Debug, Clone, PartialEq, Eq)]
struct Ending {
    reason: String,
    fault: bool,
}

impl Ending {
    /// The robot misbehaved.
    fn fault(reason: String) -> Self {
        Self {
            reason,
            fault: true,
        }
    }

    /// The robot went away or could not be reached.
    fn ordinary(reason: String) -> Self {
        Self {
            reason,
            fault: false,
        }
    }
}

/// Longest status message passed on, bytes (a robot's text is cut to it).
pub const MAX_STATUS_BYTES: usize = 500;

/// Longest [`RobotClient::stop`] waits for the thread to end; past it the thread is left to end
/// on its own (it looks at its stop flag every [`POLL`], or after a TCP connect attempt).
const STOP_WAIT: Duration = Duration::from_millis(500);

/// A robot's connection thread. [`RobotClient::stop`] ends it, waiting at most `STOP_WAIT`;
/// dropping it only tells the thread to end and returns at once (the UI never waits on a
/// socket).
#[derive(Debug)]
pub struct RobotClient {
    url: RobotUrl,
    stop: Arc<AtomicBool>,
    thread: Option<JoinHandle<()>>,
}

impl RobotClient {
    /// Starts the connection thread; `handler` receives every [`LiveEvent`] on that thread.
    ///
    /// # Errors
    /// The OS's error when the thread cannot be started.
    pub fn spawn(
        url: RobotUrl,
        options: ClientOptions,
        handler: impl FnMut(LiveEvent) + Send + 'static,
    ) -> std::io::Result<Self> {
        let stop = Arc::new(AtomicBool::new(false));
        let thread = std::thread::Builder::new()
            .name(format!("robot {url}"))
            .spawn({
                let (url, stop) = (url.clone(), Arc::clone(&stop));
                move || run(&url, &options, &stop, handler)
            })?;
        Ok(Self {
            url,
            stop,
            thread: Some(thread),
        })
    }

    /// The robot's address.
    #[must_use]
    pub fn url(&self) -> &RobotUrl {
        &self.url
    }

    /// Tells the thread to end, without waiting (to stop several clients at once before
    /// [`RobotClient::stop`] waits for each).
    pub fn request_stop(&self) {
        self.stop.store(true, Ordering::Relaxed);
    }

    /// Closes the connection and waits for the thread to end, at most `STOP_WAIT` (a thread
    /// inside a TCP connect attempt ends when the attempt does, on its own). True when it ended.
    pub fn stop(mut self) -> bool {
        self.stop.store(true, Ordering::Relaxed);
        let Some(thread) = self.thread.take() else {
            return true;
        };
        let until = Instant::now() + STOP_WAIT;
        while !thread.is_finished() && Instant::now() < until {
            std::thread::sleep(Duration::from_millis(2));
        }
        let ended = thread.is_finished();
        if ended {
            let _ = thread.join();
        }
        ended
    }
}

impl Drop for RobotClient {
    /// Tells the thread to end, without waiting for it.
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
    }
}

/// Read timeout of the socket: how often the thread looks at the stop flag, the deadlines and
/// the ping timer.
const POLL: Duration = Duration::from_millis(50);

fn run(
    url: &RobotUrl,
    options: &ClientOptions,
    stop: &AtomicBool,
    mut handler: impl FnMut(LiveEvent),
) {
    let mut backoff = options.backoff_min;
    while !stop.load(Ordering::Relaxed) {
        let mut got_info = false;
        let ending = match connect(url, &options.limits, stop) {
            Ok(mut ws) => {
                let ending = session(&mut ws, &options.limits, stop, &mut handler, &mut got_info);
                let _ = ws.close(None);
                let _ = ws.flush();
                ending
            }
            Err(ConnectError::Stopped) => None,
            Err(e) if e.is_fault() => Some(Ending::fault(e.to_string())),
            Err(e) => Some(Ending::ordinary(e.to_string())),
        };
        let Some(Ending { reason, fault }) = ending else {
            return;
        };
        if got_info {
            backoff = options.backoff_min;
        }
        handler(LiveEvent::Disconnected {
            reason,
            fault,
            retry_in: backoff,
        });
        let until = Instant::now() + backoff;
        while Instant::now() < until {
            if stop.load(Ordering::Relaxed) {
                return;
            }
            std::thread::sleep(POLL.min(until.saturating_duration_since(Instant::now())));
        }
        backoff = (backoff * 2).min(options.backoff_max);
    }
}

/// Why a connection could not be opened (said in [`LiveEvent::Disconnected`]'s reason).
#[derive(Debug, thiserror::Error)]
enum ConnectError {
    /// The host name does not resolve.
    #[error("cannot resolve {host}: {source}")]
    Resolve {
        /// The robot's host.
        host: String,
        /// What the resolver said.
        source: std::io::Error,
    },
    /// The host resolved to no address.
    #[error("{host} has no address")]
    NoAddress {
        /// The robot's host.
        host: String,
    },
    /// No address accepted the connection (the last address's error).
    #[error("cannot connect: {0}")]
    Connect(#[source] std::io::Error),
    /// The socket's options could not be set.
    #[error("socket: {0}")]
    Socket(#[source] std::io::Error),
    /// The URL is no WebSocket request.
    #[error("bad address: {0}")]
    Address(#[source] tungstenite::Error),
    /// The WebSocket handshake failed.
    #[error("handshake failed: {0}")]
    Handshake(#[source] tungstenite::Error),
    /// The robot did not finish the handshake in time.
    #[error("no WebSocket handshake within {:.1} s", .0.as_secs_f64())]
    HandshakeTimeout(Duration),
    /// The client was told to stop.
    #[error("stopped")]
    Stopped,
}

impl ConnectError {
    /// True when the robot answered but wrongly or too slowly (not when it was unreachable).
    fn is_fault(&self) -> bool {
        matches!(self, Self::Handshake(_) | Self::HandshakeTimeout(_))
    }
}

fn connect(
    url: &RobotUrl,
    limits: &Limits,
    stop: &AtomicBool,
) -> Result<WebSocket<TcpStream>, ConnectError> {
    let addrs: Vec<_> = (url.host.as_str(), url.port)
        .to_socket_addrs()
        .map_err(|source| ConnectError::Resolve {
            host: url.host.clone(),
            source,
        })?
        .collect();
    let mut last = ConnectError::NoAddress {
        host: url.host.clone(),
    };
    let stream = addrs
        .iter()
        .take_while(|_| !stop.load(Ordering::Relaxed))
        .find_map(
            |a| match TcpStream::connect_timeout(a, limits.connect_timeout) {
                Ok(s) => Some(s),
                Err(e) => {
                    last = ConnectError::Connect(e);
                    None
                }
            },
        )
        .ok_or(last)?;
    stream.set_nodelay(true).map_err(ConnectError::Socket)?;
    // Short timeouts: the handshake below goes round in POLL steps, looking at the stop flag
    // and its own deadline between them, so a robot answering byte by byte cannot hold it.
    stream
        .set_read_timeout(Some(POLL))
        .map_err(ConnectError::Socket)?;
    stream
        .set_write_timeout(Some(POLL))
        .map_err(ConnectError::Socket)?;
    let mut request = url
        .to_string()
        .into_client_request()
        .map_err(ConnectError::Address)?;
    request.headers_mut().insert(
        "Sec-WebSocket-Protocol",
        tungstenite::http::HeaderValue::from_static(SUBPROTOCOLS),
    );
    let config = WebSocketConfig::default()
        .max_message_size(Some(limits.max_message_bytes))
        .max_frame_size(Some(limits.max_message_bytes));
    let deadline = Instant::now() + limits.handshake_timeout;
    let mut attempt = tungstenite::client::client_with_config(request, stream, Some(config));
    loop {
        match attempt {
            Ok((ws, _response)) => {
                // Reads keep their POLL timeout (the session looks at its stop flag and deadlines
                // between them); a robot that takes longer than the handshake's deadline to take
                // in a subscription or a ping is given up on.
                ws.get_ref()
                    .set_write_timeout(Some(limits.handshake_timeout))
                    .map_err(ConnectError::Socket)?;
                return Ok(ws);
            }
            Err(tungstenite::HandshakeError::Failure(e)) => return Err(ConnectError::Handshake(e)),
            Err(tungstenite::HandshakeError::Interrupted(mid)) => {
                if stop.load(Ordering::Relaxed) {
                    return Err(ConnectError::Stopped);
                }
                if Instant::now() >= deadline {
                    return Err(ConnectError::HandshakeTimeout(limits.handshake_timeout));
                }
                attempt = mid.handshake();
            }
        }
    }
}

/// Runs one connection until it ends: `None` when stopped, otherwise why it ended.
fn session(
    ws: &mut WebSocket<TcpStream>,
    limits: &Limits,
    stop: &AtomicBool,
    handler: &mut impl FnMut(LiveEvent),
    got_info: &mut bool,
) -> Option<Ending> {
    let mut channels = Channels::new(limits.clone());
    let opened = Instant::now();
    let mut last_heard = Instant::now();
    let mut pinged = false;
    loop {
        if stop.load(Ordering::Relaxed) {
            return None;
        }
        let message = match ws.read() {
            Ok(m) => m,
            Err(tungstenite::Error::Io(e))
                if matches!(e.kind(), ErrorKind::WouldBlock | ErrorKind::TimedOut) =>
            {
                if !*got_info && opened.elapsed() > limits.first_message_timeout {
                    return Some(Ending::fault(format!(
                        "connected, but no serverInfo within {:.1} s",
                        limits.first_message_timeout.as_secs_f64()
                    )));
                }
                let quiet = last_heard.elapsed();
                if quiet > limits.silence_timeout {
                    return Some(Ending::ordinary(format!(
                        "nothing heard for {:.1} s",
                        quiet.as_secs_f64()
                    )));
                }
                if quiet > limits.ping_after && !pinged {
                    pinged = true;
                    if let Err(e) = ws.send(Message::Ping(Vec::new().into())) {
                        return Some(describe(&e, limits));
                    }
                }
                continue;
            }
            Err(e) => return Some(describe(&e, limits)),
        };
        let received_ns = unix_time_ns();
        last_heard = Instant::now();
        pinged = false;
        let parsed = match parse_message(&message, limits.max_channels) {
            Ok(Some(p)) => p,
            Ok(None) => continue,
            Err(why) => return Some(why),
        };
        if matches!(parsed, ServerMessage::ServerInfo { .. }) {
            *got_info = true;
        }
        if let Err(why) = handle(&mut channels, parsed, received_ns, ws, limits, handler) {
            return Some(why);
        }
    }
}

/// A received message parsed: `None` for the WebSocket's own (ping, pong), `Err` with why the
/// session ends for a close or a malformed message.
fn parse_message(
    message: &Message,
    max_channels: usize,
) -> Result<Option<ServerMessage<'_>>, Ending> {
    let parsed = match message {
        Message::Text(t) => parse_text(t.as_str(), max_channels),
        Message::Binary(b) => parse_binary(b),
        Message::Close(frame) => {
            return Err(Ending::ordinary(match frame {
                Some(f) if !f.reason.is_empty() => format!(
                    "the robot closed the connection: {}",
                    one_line(&f.reason, MAX_STATUS_BYTES)
                ),
                _ => "the robot closed the connection".to_owned(),
            }));
        }
        Message::Ping(_) | Message::Pong(_) | Message::Frame(_) => return Ok(None),
    };
    parsed.map(Some).map_err(|e| {
        Ending::fault(format!(
            "malformed message: {}",
            one_line(&e.to_string(), MAX_STATUS_BYTES)
        ))
    })
}

/// A robot's own text made one line: control characters (line breaks) become spaces, cut to
/// `max` bytes.
fn one_line(text: &str, max: usize) -> String {
    let line: String = text
        .chars()
        .map(|c| if c.is_control() { ' ' } else { c })
        .collect();
    cut(&line, max)
}

/// Acts on one server message: subscribes to new channels, forgets withdrawn ones, hands the
/// rest to `handler`; `Err` with why the session ends when a subscription cannot be sent.
fn handle(
    channels: &mut Channels,
    parsed: ServerMessage<'_>,
    received_ns: u64,
    ws: &mut WebSocket<TcpStream>,
    limits: &Limits,
    handler: &mut impl FnMut(LiveEvent),
) -> Result<(), Ending> {
    match parsed {
        ServerMessage::ServerInfo { name } => {
            let server_name = one_line(&name, limits.max_name_bytes);
            if name.len() > limits.max_name_bytes {
                handler(LiveEvent::Warning(format!(
                    "the robot's name is {} bytes long: cut to {}",
                    name.len(),
                    limits.max_name_bytes
                )));
            }
            handler(LiveEvent::Connected { server_name });
        }
        ServerMessage::Advertise {
            channels: list,
            beyond,
        } => {
            let outcome = channels.advertise(list, beyond);
            for w in outcome.warnings {
                handler(LiveEvent::Warning(w));
            }
            if !outcome.subscribe.is_empty()
                && let Err(e) = ws.send(Message::text(subscribe_request(&outcome.subscribe)))
            {
                return Err(describe(&e, limits));
            }
            if !outcome.channels.is_empty() {
                handler(LiveEvent::Advertised(outcome.channels));
            }
        }
        ServerMessage::Unadvertise(ids) => channels.unadvertise(&ids),
        ServerMessage::MessageData {
            subscription_id,
            log_time_ns,
            payload,
        } => {
            if let Some(channel) = channels.subscription(subscription_id) {
                handler(LiveEvent::Message {
                    channel: Arc::clone(channel),
                    log_time_ns,
                    received_ns,
                    payload: payload.to_vec(),
                });
            }
        }
        ServerMessage::Status { level, message } => {
            let kind = match level {
                0 => "info",
                1 => "warning",
                _ => "error",
            };
            let text = one_line(&message, MAX_STATUS_BYTES);
            handler(LiveEvent::Status(format!("{kind}: {text}")));
        }
        ServerMessage::Time(_) | ServerMessage::Other(_) => {}
    }
    Ok(())
}

fn describe(e: &tungstenite::Error, limits: &Limits) -> Ending {
    match e {
        tungstenite::Error::Capacity(c) => Ending::fault(format!(
            "message too large ({c}; the limit is {} MiB)",
            limits.max_message_bytes >> 20
        )),
        tungstenite::Error::ConnectionClosed | tungstenite::Error::AlreadyClosed => {
            Ending::ordinary("the connection closed".to_owned())
        }
        tungstenite::Error::Io(io) if io.kind() == ErrorKind::UnexpectedEof => {
            Ending::ordinary("the robot dropped the connection".to_owned())
        }
        tungstenite::Error::Protocol(p) => {
            Ending::fault(format!("the robot broke the WebSocket protocol: {p}"))
        }
        other => Ending::ordinary(other.to_string()),
    }
}
