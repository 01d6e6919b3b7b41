//! [`RobotClient`]: one robot's Foxglove WebSocket connection on a thread of its own.
//!
//! The thread connects, subscribes to every channel the robot advertises, hands each message to
//! the owner's handler (on this thread), pings the robot when it is quiet, and reconnects with a
//! growing back-off when the connection drops or the robot sends something malformed or
//! oversized. One robot's faults never reach another's thread.

use std::collections::HashMap;
use std::io::ErrorKind;
use std::net::{TcpStream, ToSocketAddrs};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use tungstenite::client::IntoClientRequest;
use tungstenite::protocol::WebSocketConfig;
use tungstenite::{Message, WebSocket};

use super::protocol::{
    AdvertisedChannel, ServerMessage, parse_binary, parse_text, subscribe_request,
};
use super::{RobotUrl, SUBPROTOCOLS, unix_time_ns};

/// How a [`RobotClient`] connects and when it gives up on a connection.
#[derive(Debug, Clone)]
pub struct ClientOptions {
    /// Largest message accepted, bytes; a larger one closes the connection.
    pub max_message_bytes: usize,
    /// Time to open the TCP connection and finish the WebSocket handshake.
    pub connect_timeout: Duration,
    /// A ping is sent after this long without hearing from the robot.
    pub ping_after: Duration,
    /// The connection is dropped after this long without hearing from the robot.
    pub silence_timeout: Duration,
    /// First wait before reconnecting; doubled after each failed attempt.
    pub backoff_min: Duration,
    /// Longest wait between reconnection attempts.
    pub backoff_max: Duration,
}

impl Default for ClientOptions {
    fn default() -> Self {
        Self {
            max_message_bytes: 64 << 20,
            connect_timeout: Duration::from_secs(3),
            ping_after: Duration::from_secs(2),
            silence_timeout: Duration::from_secs(10),
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
    /// A status message from the robot.
    Status(String),
    /// The connection failed or ended; the client retries after `retry_in`.
    Disconnected {
        /// Why, in one line.
        reason: String,
        /// Wait before the next attempt.
        retry_in: Duration,
    },
}

/// A robot's connection thread; stops (and joins) when dropped or [`RobotClient::stop`]ped.
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

    /// Closes the connection and waits for the thread to end (at most about 100 ms).
    pub fn stop(mut self) {
        self.shutdown();
    }

    fn shutdown(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

impl Drop for RobotClient {
    fn drop(&mut self) {
        self.shutdown();
    }
}

/// Read timeout of the socket: how often the thread looks at the stop flag and the ping timer.
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
        let reason = match connect(url, options) {
            Ok(mut ws) => {
                let reason = session(&mut ws, options, stop, &mut handler, &mut got_info);
                let _ = ws.close(None);
                let _ = ws.flush();
                reason
            }
            Err(reason) => Some(reason.to_string()),
        };
        let Some(reason) = reason else { return };
        if got_info {
            backoff = options.backoff_min;
        }
        handler(LiveEvent::Disconnected {
            reason,
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
    #[error("handshake timed out")]
    HandshakeTimeout,
}

fn connect(url: &RobotUrl, options: &ClientOptions) -> Result<WebSocket<TcpStream>, ConnectError> {
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
        .find_map(
            |a| match TcpStream::connect_timeout(a, options.connect_timeout) {
                Ok(s) => Some(s),
                Err(e) => {
                    last = ConnectError::Connect(e);
                    None
                }
            },
        )
        .ok_or(last)?;
    stream.set_nodelay(true).map_err(ConnectError::Socket)?;
    stream
        .set_read_timeout(Some(options.connect_timeout))
        .map_err(ConnectError::Socket)?;
    stream
        .set_write_timeout(Some(options.connect_timeout))
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
        .max_message_size(Some(options.max_message_bytes))
        .max_frame_size(Some(options.max_message_bytes));
    let (ws, _response) = tungstenite::client::client_with_config(request, stream, Some(config))
        .map_err(|e| match e {
            tungstenite::HandshakeError::Failure(e) => ConnectError::Handshake(e),
            tungstenite::HandshakeError::Interrupted(_) => ConnectError::HandshakeTimeout,
        })?;
    ws.get_ref()
        .set_read_timeout(Some(POLL))
        .map_err(ConnectError::Socket)?;
    Ok(ws)
}

/// Runs one connection until it ends: `None` when stopped, otherwise why it ended.
fn session(
    ws: &mut WebSocket<TcpStream>,
    options: &ClientOptions,
    stop: &AtomicBool,
    handler: &mut impl FnMut(LiveEvent),
    got_info: &mut bool,
) -> Option<String> {
    let mut channels = Channels::new();
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
                let quiet = last_heard.elapsed();
                if quiet > options.silence_timeout {
                    return Some(format!("nothing heard for {:.1} s", quiet.as_secs_f64()));
                }
                if quiet > options.ping_after && !pinged {
                    pinged = true;
                    if let Err(e) = ws.send(Message::Ping(Vec::new().into())) {
                        return Some(describe(&e, options));
                    }
                }
                continue;
            }
            Err(e) => return Some(describe(&e, options)),
        };
        let received_ns = unix_time_ns();
        last_heard = Instant::now();
        pinged = false;
        let parsed = match parse_message(&message) {
            Ok(Some(p)) => p,
            Ok(None) => continue,
            Err(why) => return Some(why),
        };
        if matches!(parsed, ServerMessage::ServerInfo { .. }) {
            *got_info = true;
        }
        if let Err(why) = channels.handle(parsed, received_ns, ws, options, handler) {
            return Some(why);
        }
    }
}

/// A received message parsed: `None` for the WebSocket's own (ping, pong), `Err` with why the
/// session ends for a close or a malformed message.
fn parse_message(message: &Message) -> Result<Option<ServerMessage<'_>>, String> {
    let parsed = match message {
        Message::Text(t) => parse_text(t.as_str()),
        Message::Binary(b) => parse_binary(b),
        Message::Close(frame) => {
            return Err(match frame {
                Some(f) if !f.reason.is_empty() => {
                    format!("the robot closed the connection: {}", f.reason)
                }
                _ => "the robot closed the connection".to_owned(),
            });
        }
        Message::Ping(_) | Message::Pong(_) | Message::Frame(_) => return Ok(None),
    };
    parsed
        .map(Some)
        .map_err(|e| format!("malformed message: {e}"))
}

/// The channels one session has seen advertised and the subscriptions it made to them.
struct Channels {
    channels: HashMap<u32, Arc<AdvertisedChannel>>,
    subscriptions: HashMap<u32, Arc<AdvertisedChannel>>,
    next_subscription: u32,
}

impl Channels {
    fn new() -> Self {
        Self {
            channels: HashMap::new(),
            subscriptions: HashMap::new(),
            next_subscription: 1,
        }
    }

    /// Acts on one server message: subscribes to new channels, forgets withdrawn ones, hands
    /// the rest to `handler`; `Err` with why the session ends when a subscription cannot be
    /// sent.
    fn handle(
        &mut self,
        parsed: ServerMessage<'_>,
        received_ns: u64,
        ws: &mut WebSocket<TcpStream>,
        options: &ClientOptions,
        handler: &mut impl FnMut(LiveEvent),
    ) -> Result<(), String> {
        match parsed {
            ServerMessage::ServerInfo { name } => {
                handler(LiveEvent::Connected { server_name: name });
            }
            ServerMessage::Advertise(list) => {
                let mut new = Vec::new();
                let mut subs = Vec::new();
                for c in list {
                    let c = Arc::new(c);
                    if self.channels.insert(c.id, Arc::clone(&c)).is_none() {
                        subs.push((self.next_subscription, c.id));
                        self.subscriptions
                            .insert(self.next_subscription, Arc::clone(&c));
                        self.next_subscription = self.next_subscription.wrapping_add(1);
                        new.push(c);
                    }
                }
                if !subs.is_empty()
                    && let Err(e) = ws.send(Message::text(subscribe_request(&subs)))
                {
                    return Err(describe(&e, options));
                }
                handler(LiveEvent::Advertised(new));
            }
            ServerMessage::Unadvertise(ids) => {
                for id in ids {
                    self.channels.remove(&id);
                    self.subscriptions.retain(|_, c| c.id != id);
                }
            }
            ServerMessage::MessageData {
                subscription_id,
                log_time_ns,
                payload,
            } => {
                if let Some(channel) = self.subscriptions.get(&subscription_id) {
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
                handler(LiveEvent::Status(format!("{kind}: {message}")));
            }
            ServerMessage::Time(_) | ServerMessage::Other(_) => {}
        }
        Ok(())
    }
}

fn describe(e: &tungstenite::Error, options: &ClientOptions) -> String {
    match e {
        tungstenite::Error::Capacity(c) => format!(
            "message too large ({c}; the limit is {} MiB)",
            options.max_message_bytes >> 20
        ),
        tungstenite::Error::ConnectionClosed | tungstenite::Error::AlreadyClosed => {
            "the connection closed".to_owned()
        }
        tungstenite::Error::Io(io) if io.kind() == ErrorKind::UnexpectedEof => {
            "the robot dropped the connection".to_owned()
        }
        tungstenite::Error::Protocol(p) => format!("the robot broke the WebSocket protocol: {p}"),
        other => other.to_string(),
    }
}
