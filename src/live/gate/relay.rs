//! One viewer of `eotn serve`, from its TCP connection to its end: the handshake (within its
//! deadline, closed early when the gate needs the room), admission, then the relay to the
//! `foxglove` server: the viewer's messages go through as they come; the server's wait in the
//! viewer's own [`Outbox`], so a viewer that does not read loses its oldest frames (counted)
//! and holds up no one. Once its outbox has had to drop while it read nothing for half a
//! second, its subscriptions are held back at the server until it has read everything queued
//! ([`Paused`]): a viewer that never reads costs the server no work, and the frames it missed
//! meanwhile are counted too.

use std::net::SocketAddr;
use std::sync::atomic::Ordering;
use std::sync::{Arc, Mutex};
use std::time::Instant;

use futures_util::{SinkExt, StreamExt};
use tokio::net::TcpStream;
use tokio::sync::{Notify, oneshot, watch};
use tokio_tungstenite::tungstenite::Message;
use tokio_tungstenite::tungstenite::handshake::server::{ErrorResponse, Request, Response};
use tokio_tungstenite::tungstenite::protocol::WebSocketConfig;
use tokio_tungstenite::tungstenite::protocol::frame::CloseFrame;
use tokio_tungstenite::tungstenite::protocol::frame::coding::CloseCode;
use tokio_tungstenite::{WebSocketStream, tungstenite};

use super::outbox::{Dropped, Kind, Outbox};
use super::traffic::{Traffic, ViewerOp};
use super::{Shared, lock};

/// The Foxglove subprotocols the `foxglove` server speaks, newest first.
const SUBPROTOCOLS: [&str; 2] = ["foxglove.sdk.v1.1", "foxglove.sdk.v1"];

/// Largest message a viewer may send, bytes: viewers send subscriptions, not data.
const MAX_VIEWER_MESSAGE: usize = 1 << 20;

/// A viewer whose outbox is full and that has not taken in one message for this long is held
/// back (see [`Paused`]).
const STALLED: std::time::Duration = std::time::Duration::from_millis(500);

/// Time to open the connection to the `foxglove` server on loopback.
const INNER_TIMEOUT: std::time::Duration = std::time::Duration::from_secs(5);

/// The subprotocol to answer with: the newest Foxglove one the viewer offered.
fn negotiate(request: &Request) -> Option<&'static str> {
    let offered: Vec<String> = request
        .headers()
        .get_all("sec-websocket-protocol")
        .iter()
        .flat_map(|h| h.to_str().unwrap_or_default().split(','))
        .map(|p| p.trim().to_owned())
        .collect();
    SUBPROTOCOLS
        .into_iter()
        .find(|p| offered.iter().any(|o| o == p))
}

/// An HTTP 400 answer to a request the handshake cannot take.
fn bad_request(text: &str) -> ErrorResponse {
    let mut response = ErrorResponse::new(Some(text.to_owned()));
    *response.status_mut() = tungstenite::http::StatusCode::BAD_REQUEST;
    response
}

/// Runs one viewer: `id` is its handshake's place among the open ones, `evicted` fires when the
/// gate closes it to make room.
pub(super) async fn viewer(
    stream: TcpStream,
    peer: SocketAddr,
    shared: Arc<Shared>,
    id: u64,
    evicted: oneshot::Receiver<()>,
) {
    let _ = stream.set_nodelay(true);
    let mut subprotocol = None;
    #[expect(
        clippy::result_large_err,
        reason = "tungstenite's handshake callback returns its error response by value"
    )]
    let callback = |request: &Request, mut response: Response| {
        let Some(chosen) = negotiate(request) else {
            return Err(bad_request(
                "Missing expected sec-websocket-protocol header (foxglove.sdk.v1)",
            ));
        };
        response.headers_mut().insert(
            "sec-websocket-protocol",
            tungstenite::http::HeaderValue::from_static(chosen),
        );
        subprotocol = Some(chosen);
        Ok(response)
    };
    let config = WebSocketConfig::default().max_message_size(Some(MAX_VIEWER_MESSAGE));
    let handshake = tokio_tungstenite::accept_hdr_async_with_config(stream, callback, Some(config));
    let counters = &shared.counters;
    let outcome = tokio::select! {
        r = tokio::time::timeout(shared.options.handshake_timeout, handshake) => r,
        _ = evicted => return,
    };
    if !shared.close_handshake(id) {
        return;
    }
    let ws = match outcome {
        Ok(Ok(ws)) => ws,
        Ok(Err(_)) => {
            counters.handshake_failures.fetch_add(1, Ordering::Relaxed);
            return;
        }
        Err(_) => {
            counters.handshake_timeouts.fetch_add(1, Ordering::Relaxed);
            return;
        }
    };
    let Some(subprotocol) = subprotocol else {
        return;
    };
    let Some(_place) = shared.admit() else {
        let max = shared.max_clients;
        log::info!("eotn serve: {peer} refused: {max} viewers connected");
        close(ws, CloseCode::Again, &format!("eotn serve: {max} viewers connected, the most --max-clients allows; try again later")).await;
        return;
    };
    match connect_inner(shared.inner, subprotocol).await {
        Ok(inner) => relay(ws, inner, &shared, peer).await,
        Err(e) => {
            log::warn!("eotn serve: {peer}: cannot reach the Foxglove server: {e}");
            close(ws, CloseCode::Error, "eotn serve: internal error").await;
        }
    }
}

/// Sends a close frame with `reason` (waiting at most a second for a viewer that does not read).
async fn close(mut ws: WebSocketStream<TcpStream>, code: CloseCode, reason: &str) {
    let frame = CloseFrame {
        code,
        reason: reason.to_owned().into(),
    };
    let _ = tokio::time::timeout(std::time::Duration::from_secs(1), ws.close(Some(frame))).await;
}

type Inner = WebSocketStream<tokio_tungstenite::MaybeTlsStream<TcpStream>>;

/// Connects to the `foxglove` server as the viewer would, with the subprotocol it chose.
async fn connect_inner(inner: SocketAddr, subprotocol: &'static str) -> Result<Inner, String> {
    let connect = async {
        let stream = TcpStream::connect(inner).await.map_err(|e| e.to_string())?;
        let _ = stream.set_nodelay(true);
        let mut request =
            tungstenite::client::IntoClientRequest::into_client_request(format!("ws://{inner}/"))
                .map_err(|e| e.to_string())?;
        request.headers_mut().insert(
            "sec-websocket-protocol",
            tungstenite::http::HeaderValue::from_static(subprotocol),
        );
        let (ws, _) = tokio_tungstenite::client_async_with_config(
            request,
            tokio_tungstenite::MaybeTlsStream::Plain(stream),
            None,
        )
        .await
        .map_err(|e| e.to_string())?;
        Ok(ws)
    };
    tokio::time::timeout(INNER_TIMEOUT, connect)
        .await
        .map_err(|_| "timed out".to_owned())?
}

/// Adds the images an outbox dropped since `before` to the gate's count (as it happens: the
/// count is read while viewers are connected).
fn count_dropped(counters: &super::Counters, before: Dropped, now: Dropped) {
    counters
        .dropped_frames
        .fetch_add(now.frames - before.frames, Ordering::Relaxed);
}

/// Why a relay ended.
enum End {
    /// The viewer closed or dropped the connection.
    Viewer,
    /// The server closed (it is stopping).
    Server,
    /// The viewer let control messages pile up.
    Overflow(String),
}

/// A viewer's subscriptions held back at the server while it does not read: from the moment
/// its outbox had to drop message data while it had taken in nothing for [`STALLED`], until
/// everything queued for it has gone out. Meanwhile the
/// server sends it nothing (a viewer that never reads costs no work), and the frames sent to
/// the others are counted as dropped for it.
#[derive(Debug, Default)]
struct Paused {
    /// The frame count of the stand-in robot when the pause began; `None` while not paused.
    since_frame: Option<u64>,
    /// Frames the robot sent while this viewer was paused (and subscribed to images).
    missed: u64,
}

/// Relays until either side ends; the viewer's outbox is the only queue.
async fn relay(
    viewer: WebSocketStream<TcpStream>,
    inner: Inner,
    shared: &Shared,
    peer: SocketAddr,
) {
    let (mut to_viewer, mut from_viewer) = viewer.split();
    let (mut to_server, mut from_server) = inner.split();
    let outbox = Mutex::new(Outbox::new(shared.options.queue));
    let traffic = Mutex::new(Traffic::new());
    let ready = Notify::new();
    // The pause the outbox asks for (true: hold back, false: go on); applied by `viewer` below,
    // the only one that writes to the server.
    let (want_pause, mut pause_asked) = watch::channel(false);
    let mut paused = Paused::default();
    // When the send under way began: a viewer stuck on one send for STALLED reads nothing.
    let sending_since: Mutex<Option<Instant>> = Mutex::new(None);
    let writer = async {
        loop {
            let next = lock(&outbox).pop();
            match next {
                Some(m) => {
                    *lock(&sending_since) = Some(Instant::now());
                    let sent = to_viewer.send(m).await;
                    *lock(&sending_since) = None;
                    if sent.is_err() {
                        return End::Viewer;
                    }
                }
                None => {
                    // Everything sent: the viewer reads again.
                    want_pause.send_if_modified(|p| std::mem::replace(p, false));
                    ready.notified().await;
                }
            }
        }
    };
    let server = async {
        while let Some(Ok(m)) = from_server.next().await {
            let (kind, len) = match &m {
                Message::Text(t) => {
                    lock(&traffic).from_server(t.as_str());
                    (Kind::Control, t.len())
                }
                Message::Binary(b) => (lock(&traffic).kind_of_binary(b), b.len()),
                Message::Close(_) => break,
                _ => continue,
            };
            let (pushed, dropped) = {
                let mut outbox = lock(&outbox);
                let before = outbox.dropped();
                let pushed = outbox.push(m, kind, len);
                count_dropped(&shared.counters, before, outbox.dropped());
                (pushed, outbox.dropped() != before)
            };
            if let Err(e) = pushed {
                return End::Overflow(e.to_string());
            }
            // A viewer that reads, only slowly, just loses its oldest; one that has read nothing
            // for a while is held back.
            let stalled = lock(&sending_since).is_some_and(|t| t.elapsed() >= STALLED);
            if dropped && stalled {
                want_pause.send_if_modified(|p| !std::mem::replace(p, true));
            }
            ready.notify_one();
        }
        End::Server
    };
    let viewer = async {
        loop {
            tokio::select! {
                m = from_viewer.next() => {
                    let Some(Ok(m)) = m else { return End::Viewer };
                    let op = match &m {
                        Message::Text(t) => lock(&traffic).from_viewer(t.as_str()),
                        Message::Binary(_) => ViewerOp::Other,
                        Message::Close(_) => return End::Viewer,
                        _ => continue,
                    };
                    // While paused, subscriptions are followed but reach the server on resume.
                    let held = paused.since_frame.is_some() && op != ViewerOp::Other;
                    if !held && to_server.send(m).await.is_err() {
                        return End::Server;
                    }
                }
                changed = pause_asked.changed() => {
                    if changed.is_err() {
                        return End::Server;
                    }
                    let pause = *pause_asked.borrow_and_update();
                    if !apply_pause(pause, &mut paused, &traffic, &mut to_server, shared).await {
                        return End::Server;
                    }
                }
            }
        }
    };
    let end = tokio::select! {
        e = writer => e,
        e = server => e,
        e = viewer => e,
    };
    let _ = apply_pause(false, &mut paused, &traffic, &mut to_server, shared).await;
    let _ = to_server.close().await;
    let dropped = lock(&outbox).dropped().frames + paused.missed;
    let counters = &shared.counters;
    if dropped > 0 {
        let line = format!(
            "eotn serve: viewer {peer} left; it read too slowly: {dropped} frames dropped for it"
        );
        if counters.said_slow_viewer.swap(true, Ordering::Relaxed) {
            log::info!("{line}");
        } else {
            log::warn!("{line} (later slow viewers are counted in the summary)");
        }
    }
    if matches!(end, End::Server) {
        // The server is stopping: what it sent last still goes out (within a second).
        let until = tokio::time::Instant::now() + std::time::Duration::from_secs(1);
        loop {
            let next = lock(&outbox).pop();
            let Some(m) = next else { break };
            if !matches!(
                tokio::time::timeout_at(until, to_viewer.send(m)).await,
                Ok(Ok(()))
            ) {
                break;
            }
        }
    }
    let mut viewer = match to_viewer.reunite(from_viewer) {
        Ok(v) => v,
        Err(_) => return,
    };
    let reason = match end {
        End::Viewer => return,
        End::Server => (CloseCode::Away, "eotn serve stopped".to_owned()),
        End::Overflow(why) => {
            counters.overflowed.fetch_add(1, Ordering::Relaxed);
            (CloseCode::Policy, format!("eotn serve: {why}"))
        }
    };
    let frame = CloseFrame {
        code: reason.0,
        reason: reason.1.into(),
    };
    let _ =
        tokio::time::timeout(std::time::Duration::from_secs(1), viewer.close(Some(frame))).await;
}

/// Pauses (`pause`) or resumes the viewer's subscriptions at the server when that changes its
/// state; frames sent meanwhile are counted as dropped for it. False when the server is gone.
async fn apply_pause(
    pause: bool,
    paused: &mut Paused,
    traffic: &Mutex<Traffic>,
    to_server: &mut futures_util::stream::SplitSink<Inner, Message>,
    shared: &Shared,
) -> bool {
    let frames = shared.frames_sent.load(Ordering::Relaxed);
    let (request, images) = {
        let traffic = lock(traffic);
        let request = match (pause, paused.since_frame) {
            (true, None) => traffic.pause_request(),
            (false, Some(_)) => traffic.resume_request(),
            _ => return true,
        };
        (request, traffic.has_image_subscription())
    };
    if pause {
        paused.since_frame = Some(frames);
    } else if let Some(since) = paused.since_frame.take()
        && images
    {
        let missed = frames.saturating_sub(since);
        paused.missed += missed;
        shared
            .counters
            .dropped_frames
            .fetch_add(missed, Ordering::Relaxed);
    }
    match request {
        Some(text) => to_server.send(Message::text(text)).await.is_ok(),
        None => true,
    }
}
