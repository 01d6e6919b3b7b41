//! The gate in front of `eotn serve`'s Foxglove server: admission and flow control the
//! `foxglove` crate's server (0.30) does not have.
//!
//! That server speaks the protocol (serverInfo, advertise, subscriptions, schemas) and bounds
//! each client's queue by a message count (`message_backlog_size`), but it stops accepting for
//! good at the first `accept` error (out of file descriptors: `EMFILE`), has no limit on
//! clients, no deadline on a handshake, and does not say what it dropped. So the public port is
//! the gate's own: it accepts (backing off and retrying on any error, logging `EMFILE` once),
//! closes a handshake that takes longer than its deadline (and the oldest unfinished handshake
//! when too many are open, or descriptors run out), refuses clients past `--max-clients` with a
//! close reason, keeps viewers and handshakes within the process's descriptor limit (with room
//! for the `foxglove` server, whose `accept` must never see `EMFILE`), and relays each admitted
//! viewer to the `foxglove` server on loopback through an [`outbox::Outbox`] of its own: a slow
//! viewer's oldest frames are dropped and counted, its subscriptions held back until it reads
//! again, and no other viewer waits for it (`relay`).

pub mod outbox;
mod relay;
pub mod traffic;

use std::collections::VecDeque;
use std::net::SocketAddr;
use std::sync::atomic::{AtomicBool, AtomicU64, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex, MutexGuard};
use std::time::Duration;

use tokio::net::TcpListener;
use tokio::sync::oneshot;
use tokio::task::JoinSet;

pub use outbox::QueueBound;

/// What the gate admits and how long it waits.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct GateOptions {
    /// Viewers connected at once; the next is refused with a close reason.
    pub max_clients: usize,
    /// Time a new connection has to finish its WebSocket handshake.
    pub handshake_timeout: Duration,
    /// Handshakes open at once; a new connection past it closes the oldest.
    pub max_pending: usize,
    /// Each viewer's outbox.
    pub queue: QueueBound,
}

impl Default for GateOptions {
    fn default() -> Self {
        Self {
            max_clients: 64,
            handshake_timeout: Duration::from_secs(5),
            max_pending: 256,
            queue: QueueBound::default(),
        }
    }
}

/// The gate's figures since it started.
#[derive(Debug, Default, Clone, Copy, PartialEq, Eq)]
pub struct GateFigures {
    /// Viewers connected now.
    pub clients: usize,
    /// Viewers admitted in all.
    pub served: u64,
    /// Viewers refused because `max_clients` were connected.
    pub refused: u64,
    /// Connections closed because their handshake took longer than its deadline.
    pub handshake_timeouts: u64,
    /// Handshakes that failed (not WebSocket, no Foxglove subprotocol).
    pub handshake_failures: u64,
    /// Unfinished handshakes closed to make room (too many open, or out of descriptors).
    pub evicted: u64,
    /// Errors of `accept` (each retried).
    pub accept_errors: u64,
    /// Viewers disconnected because they let control messages pile up.
    pub overflowed: u64,
    /// Frames dropped for slow viewers (with them their JSON): dropped from their outboxes, or
    /// sent while their subscriptions were held back.
    pub dropped_frames: u64,
}

/// Counters shared by the gate's tasks.
#[derive(Debug, Default)]
struct Counters {
    clients: AtomicUsize,
    served: AtomicU64,
    refused: AtomicU64,
    handshake_timeouts: AtomicU64,
    handshake_failures: AtomicU64,
    evicted: AtomicU64,
    accept_errors: AtomicU64,
    overflowed: AtomicU64,
    dropped_frames: AtomicU64,
    /// `EMFILE` has been logged (it is said once).
    said_out_of_descriptors: AtomicBool,
    /// A slow viewer has been logged (the first is a warning, the rest informational).
    said_slow_viewer: AtomicBool,
}

/// The open handshakes, oldest first: each a way to tell its task to close.
#[derive(Debug, Default)]
struct Pending {
    next_id: u64,
    open: VecDeque<(u64, oneshot::Sender<()>)>,
}

/// Descriptors kept free for the process itself (stdio, the stream, runtimes, listeners) and
/// for the `foxglove` server's own `accept`, which stops for good at its first `EMFILE`.
const RESERVED_FDS: u64 = 48;

/// Descriptors one admitted viewer holds: its socket, the relay's connection to the `foxglove`
/// server and that server's end of it.
const FDS_PER_VIEWER: u64 = 3;

/// The process's limit on open files (`ulimit -n`), from `/proc/self/limits` (Linux); `None`
/// when it cannot be read or is unlimited.
fn open_files_limit() -> Option<u64> {
    let limits = std::fs::read_to_string("/proc/self/limits").ok()?;
    let line = limits.lines().find(|l| l.starts_with("Max open files"))?;
    line.split_whitespace().nth(3)?.parse().ok()
}

/// The viewers and open handshakes that fit in `limit` descriptors with room to spare:
/// `options`' own, or fewer (at least 1 viewer and 4 handshakes).
fn fit_descriptors(options: GateOptions, limit: Option<u64>) -> (usize, usize) {
    let Some(limit) = limit else {
        return (options.max_clients, options.max_pending);
    };
    let spare = usize::try_from(limit.saturating_sub(RESERVED_FDS)).unwrap_or(usize::MAX);
    let per_viewer = FDS_PER_VIEWER as usize;
    // Half the spare descriptors for viewers at most, the rest for handshakes.
    let clients = options.max_clients.min(spare / 2 / per_viewer).max(1);
    let pending = options
        .max_pending
        .min(spare.saturating_sub(clients * per_viewer))
        .max(4);
    (clients, pending)
}

/// What the gate's tasks share.
#[derive(Debug)]
struct Shared {
    options: GateOptions,
    /// Viewers admitted at once: `max_clients`, or fewer when the descriptors allow fewer.
    max_clients: usize,
    /// Handshakes open at once: `max_pending`, or fewer when descriptors are short; lowered
    /// when `accept` runs out of them.
    pending_cap: AtomicUsize,
    /// The `foxglove` server on loopback.
    inner: SocketAddr,
    /// Frames the stand-in robot has sent so far (what a paused viewer misses is counted from
    /// it).
    frames_sent: Arc<AtomicU64>,
    counters: Counters,
    pending: Mutex<Pending>,
}

fn lock<T>(m: &Mutex<T>) -> MutexGuard<'_, T> {
    m.lock().unwrap_or_else(std::sync::PoisonError::into_inner)
}

impl Shared {
    /// Registers a new handshake; closes the oldest when too many are open. Its id and the
    /// receiver that says "close".
    fn open_handshake(&self) -> (u64, oneshot::Receiver<()>) {
        let (tx, rx) = oneshot::channel();
        let mut pending = lock(&self.pending);
        let id = pending.next_id;
        pending.next_id += 1;
        pending.open.push_back((id, tx));
        while pending.open.len() > self.pending_cap.load(Ordering::Relaxed) {
            pending.open.pop_front();
            self.counters.evicted.fetch_add(1, Ordering::Relaxed);
        }
        (id, rx)
    }

    /// The handshake `id` ended; false when it had been closed to make room meanwhile.
    fn close_handshake(&self, id: u64) -> bool {
        let mut pending = lock(&self.pending);
        let before = pending.open.len();
        pending.open.retain(|(i, _)| *i != id);
        pending.open.len() < before
    }

    /// Out of descriptors: lowers the cap on open handshakes to what fits, less room for the
    /// `foxglove` server and a viewer to come, closing the oldest above it (dropping a sender
    /// tells its task). False when no handshake was open to close.
    fn make_room(&self) -> bool {
        let mut pending = lock(&self.pending);
        let cap = pending.open.len().saturating_sub(HEADROOM).max(4);
        self.pending_cap.fetch_min(cap, Ordering::Relaxed);
        let mut closed = false;
        while pending.open.len() > cap || (!closed && !pending.open.is_empty()) {
            pending.open.pop_front();
            self.counters.evicted.fetch_add(1, Ordering::Relaxed);
            closed = true;
        }
        closed
    }

    /// Takes a viewer's place when fewer than `max_clients` are connected.
    fn admit(self: &Arc<Self>) -> Option<Admitted> {
        let clients = &self.counters.clients;
        let mut now = clients.load(Ordering::Relaxed);
        loop {
            if now >= self.max_clients {
                self.counters.refused.fetch_add(1, Ordering::Relaxed);
                return None;
            }
            match clients.compare_exchange(now, now + 1, Ordering::AcqRel, Ordering::Relaxed) {
                Ok(_) => break,
                Err(actual) => now = actual,
            }
        }
        self.counters.served.fetch_add(1, Ordering::Relaxed);
        Some(Admitted(Arc::clone(self)))
    }

    fn figures(&self) -> GateFigures {
        let c = &self.counters;
        let get = |a: &AtomicU64| a.load(Ordering::Relaxed);
        GateFigures {
            clients: c.clients.load(Ordering::Relaxed),
            served: get(&c.served),
            refused: get(&c.refused),
            handshake_timeouts: get(&c.handshake_timeouts),
            handshake_failures: get(&c.handshake_failures),
            evicted: get(&c.evicted),
            accept_errors: get(&c.accept_errors),
            overflowed: get(&c.overflowed),
            dropped_frames: get(&c.dropped_frames),
        }
    }
}

/// A viewer's place among the `max_clients`; given back when dropped.
struct Admitted(Arc<Shared>);

impl Drop for Admitted {
    fn drop(&mut self) {
        self.0.counters.clients.fetch_sub(1, Ordering::AcqRel);
    }
}

/// The running gate: its port and figures. Dropping it does not stop it; [`Gate::stop`] does.
#[derive(Debug)]
pub struct Gate {
    port: u16,
    shared: Arc<Shared>,
    accept: tokio::task::JoinHandle<()>,
}

impl Gate {
    /// Listens on `host:port` (port 0: any free port) on `runtime`, relaying to the Foxglove
    /// server at `inner`, whose frames `frames_sent` counts.
    ///
    /// # Errors
    /// The OS's error when the address cannot be listened on.
    pub fn start(
        runtime: &tokio::runtime::Handle,
        (host, port): (&str, u16),
        inner: SocketAddr,
        frames_sent: Arc<AtomicU64>,
        options: GateOptions,
    ) -> std::io::Result<Self> {
        let listener = runtime.block_on(TcpListener::bind((host, port)))?;
        let port = listener.local_addr()?.port();
        let limit = open_files_limit();
        let (max_clients, max_pending) = fit_descriptors(options, limit);
        if max_clients < options.max_clients || max_pending < options.max_pending {
            log::warn!(
                "eotn serve: `ulimit -n` is {}: at most {max_clients} viewers (of --max-clients {}) and {max_pending} unfinished handshakes; raise it to serve more",
                limit.unwrap_or(0),
                options.max_clients
            );
        }
        let shared = Arc::new(Shared {
            options,
            max_clients,
            pending_cap: AtomicUsize::new(max_pending),
            inner,
            frames_sent,
            counters: Counters::default(),
            pending: Mutex::new(Pending::default()),
        });
        let accept = runtime.spawn(accept_loop(listener, Arc::clone(&shared)));
        Ok(Self {
            port,
            shared,
            accept,
        })
    }

    /// The port it listens on.
    #[must_use]
    pub const fn port(&self) -> u16 {
        self.port
    }

    /// Viewers it admits at once: `max_clients`, or fewer when the process's descriptor limit
    /// allows fewer.
    #[must_use]
    pub fn max_clients(&self) -> usize {
        self.shared.max_clients
    }

    /// Its figures now.
    #[must_use]
    pub fn figures(&self) -> GateFigures {
        self.shared.figures()
    }

    /// Stops accepting and closes every connection (their tasks end with the accept loop's).
    pub fn stop(&self) {
        self.accept.abort();
    }
}

/// Shortest and longest wait before `accept` is tried again after an error it cannot work
/// around.
const ACCEPT_BACKOFF: (Duration, Duration) = (Duration::from_millis(10), Duration::from_secs(1));

/// Descriptors left free below the count at which `accept` failed: for the `foxglove` server's
/// end of a viewer's relay, and a viewer about to be admitted.
const HEADROOM: usize = 8;

/// True for the errors that say the process or system is out of descriptors or memory.
fn out_of_resources(e: &std::io::Error) -> bool {
    // EMFILE 24, ENFILE 23, ENOBUFS 105, ENOMEM 12 on Linux.
    matches!(e.raw_os_error(), Some(24 | 23 | 105 | 12))
}

/// Accepts for as long as the gate runs: an error is never the end of serving.
async fn accept_loop(listener: TcpListener, shared: Arc<Shared>) {
    let mut tasks = JoinSet::new();
    let mut backoff = ACCEPT_BACKOFF.0;
    loop {
        while tasks.try_join_next().is_some() {}
        match listener.accept().await {
            Ok((stream, peer)) => {
                backoff = ACCEPT_BACKOFF.0;
                let (id, close) = shared.open_handshake();
                tasks.spawn(relay::viewer(stream, peer, Arc::clone(&shared), id, close));
            }
            Err(e) => {
                shared
                    .counters
                    .accept_errors
                    .fetch_add(1, Ordering::Relaxed);
                if out_of_resources(&e) {
                    if !shared
                        .counters
                        .said_out_of_descriptors
                        .swap(true, Ordering::Relaxed)
                    {
                        log::warn!(
                            "eotn serve: cannot accept more connections ({e}) with {} viewers and {} handshakes open: closing the oldest handshakes, fewer from now on, and retrying; raise `ulimit -n` to serve more (said once)",
                            shared.counters.clients.load(Ordering::Relaxed),
                            lock(&shared.pending).open.len()
                        );
                    }
                    if shared.make_room() {
                        // The closed handshakes' tasks close their sockets when next polled.
                        tokio::time::sleep(Duration::from_millis(2)).await;
                        continue;
                    }
                } else {
                    log::info!("eotn serve: accept failed ({e}); retrying");
                }
                tokio::time::sleep(backoff).await;
                backoff = (backoff * 2).min(ACCEPT_BACKOFF.1);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn viewers_and_handshakes_fit_the_descriptor_limit_with_room_to_spare() {
        let options = GateOptions::default();
        assert_eq!(fit_descriptors(options, None), (64, 256));
        assert_eq!(fit_descriptors(options, Some(20_000)), (64, 256));
        // 1024: 976 spare, 64 viewers hold 192, 256 handshakes fit.
        assert_eq!(fit_descriptors(options, Some(1024)), (64, 256));
        // 128: 80 spare; 13 viewers (39), 41 handshakes.
        assert_eq!(fit_descriptors(options, Some(128)), (13, 41));
        assert_eq!(fit_descriptors(options, Some(10)), (1, 4));
        assert!(open_files_limit().is_some_and(|n| n > 0));
    }
}
