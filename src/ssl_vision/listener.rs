//! Listening for SSL-Vision packets: `udp://GROUP:PORT` joins a multicast group (the league's
//! is `udp://224.5.23.2:10006`) on every interface with the port shared (`SO_REUSEADDR`, as
//! ssl-vision's clients do, so eotn listens beside them); `udp://HOST:PORT` with a unicast
//! address binds that address alone (a port in use is then an error).
//!
//! A thread receives datagrams and hands them on decoded through a bounded channel: when the
//! reader falls behind, packets are dropped and counted, never queued without bound. A packet
//! that does not decode is passed on as [`Received::Bad`] with the reason, and the thread goes
//! on. Dropping the [`Listener`] stops and joins the thread within [`POLL`].

use std::net::{Ipv4Addr, SocketAddr, SocketAddrV4, ToSocketAddrs, UdpSocket};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::mpsc::{Receiver, SyncSender, TrySendError, sync_channel};
use std::thread::JoinHandle;
use std::time::Duration;

use super::{MAX_PACKET_BYTES, SslWrapperPacket, decode_packet};

/// How often the thread looks at its stop flag.
pub const POLL: Duration = Duration::from_millis(100);

/// Packets held for the reader before new ones are dropped.
pub const QUEUE: usize = 4096;

/// What the listener hands on.
#[derive(Debug, Clone)]
pub enum Received {
    /// A packet that decoded, with its arrival time (nanoseconds since the Unix epoch).
    Packet {
        /// Arrival, nanoseconds since the Unix epoch.
        received_ns: i64,
        /// The packet.
        packet: Box<SslWrapperPacket>,
        /// Its bytes as they came (for logs).
        bytes: Vec<u8>,
    },
    /// A datagram that is not an SSL-Vision packet.
    Bad {
        /// Who sent it.
        from: SocketAddr,
        /// Why it was refused.
        why: String,
    },
}

/// Why listening could not start.
#[derive(Debug, thiserror::Error)]
pub enum ListenError {
    /// Not `udp://HOST:PORT`.
    #[error(
        "{given}: not an SSL-Vision address (udp://GROUP:PORT, e.g. udp://{})",
        super::LEAGUE_ADDRESS
    )]
    Address {
        /// What was given.
        given: String,
    },
    /// The port is taken by another program.
    #[error("{given}: port in use by another program ({source}); close it or choose another port")]
    PortInUse {
        /// The address.
        given: String,
        /// The system's error.
        source: std::io::Error,
    },
    /// The multicast group cannot be joined.
    #[error(
        "{given}: cannot join multicast group {group} ({source}); is there a network interface with a multicast route (on Linux: `ip route add 224.0.0.0/4 dev IFACE`)?"
    )]
    Join {
        /// The address.
        given: String,
        /// The group.
        group: Ipv4Addr,
        /// The system's error.
        source: std::io::Error,
    },
    /// Another socket error.
    #[error("{given}: cannot listen: {source}")]
    Socket {
        /// The address.
        given: String,
        /// The system's error.
        source: std::io::Error,
    },
}

/// The address of `udp://HOST:PORT`, `None` for anything else.
#[must_use]
pub fn parse_udp_url(text: &str) -> Option<SocketAddrV4> {
    let rest = text.strip_prefix("udp://")?;
    rest.to_socket_addrs().ok()?.find_map(|a| match a {
        SocketAddr::V4(v4) if v4.port() != 0 => Some(v4),
        _ => None,
    })
}

/// Whether a command-line source names a UDP address rather than a file.
#[must_use]
pub fn is_udp_url(text: &str) -> bool {
    text.starts_with("udp://")
}

/// A running listener; see the module documentation.
#[derive(Debug)]
pub struct Listener {
    rx: Receiver<Received>,
    stop: Arc<AtomicBool>,
    dropped: Arc<AtomicU64>,
    thread: Option<JoinHandle<()>>,
    address: SocketAddrV4,
}

impl Listener {
    /// Starts listening on `udp://HOST:PORT`.
    ///
    /// # Errors
    /// [`ListenError`]: a malformed address, a port in use, a group that cannot be joined.
    pub fn start(url: &str) -> Result<Self, ListenError> {
        let address = parse_udp_url(url).ok_or_else(|| ListenError::Address {
            given: url.to_owned(),
        })?;
        let socket = bind(url, address)?;
        socket
            .set_read_timeout(Some(POLL))
            .map_err(|source| ListenError::Socket {
                given: url.to_owned(),
                source,
            })?;
        let (tx, rx) = sync_channel(QUEUE);
        let stop = Arc::new(AtomicBool::new(false));
        let dropped = Arc::new(AtomicU64::new(0));
        let thread = std::thread::Builder::new()
            .name("ssl-vision listener".to_owned())
            .spawn({
                let (stop, dropped) = (Arc::clone(&stop), Arc::clone(&dropped));
                move || receive(&socket, &tx, &stop, &dropped)
            })
            .map_err(|source| ListenError::Socket {
                given: url.to_owned(),
                source,
            })?;
        Ok(Self {
            rx,
            stop,
            dropped,
            thread: Some(thread),
            address,
        })
    }

    /// What arrived since the last call, oldest first.
    pub fn drain(&self) -> Vec<Received> {
        self.rx.try_iter().collect()
    }

    /// Waits up to `timeout` for the next item; `None` when nothing came.
    #[must_use]
    pub fn next_timeout(&self, timeout: Duration) -> Option<Received> {
        self.rx.recv_timeout(timeout).ok()
    }

    /// Packets dropped because the reader fell behind.
    #[must_use]
    pub fn dropped(&self) -> u64 {
        self.dropped.load(Ordering::Relaxed)
    }

    /// The address listened on.
    #[must_use]
    pub const fn address(&self) -> SocketAddrV4 {
        self.address
    }
}

impl Drop for Listener {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

fn bind(url: &str, address: SocketAddrV4) -> Result<UdpSocket, ListenError> {
    let socket_error = |source| ListenError::Socket {
        given: url.to_owned(),
        source,
    };
    if !address.ip().is_multicast() {
        return UdpSocket::bind(address).map_err(|source| {
            if source.kind() == std::io::ErrorKind::AddrInUse {
                ListenError::PortInUse {
                    given: url.to_owned(),
                    source,
                }
            } else {
                socket_error(source)
            }
        });
    }
    use socket2::{Domain, Protocol, Socket, Type};
    let socket =
        Socket::new(Domain::IPV4, Type::DGRAM, Some(Protocol::UDP)).map_err(socket_error)?;
    socket.set_reuse_address(true).map_err(socket_error)?;
    let any = SocketAddrV4::new(Ipv4Addr::UNSPECIFIED, address.port());
    socket.bind(&any.into()).map_err(|source| {
        if source.kind() == std::io::ErrorKind::AddrInUse {
            ListenError::PortInUse {
                given: url.to_owned(),
                source,
            }
        } else {
            socket_error(source)
        }
    })?;
    socket
        .join_multicast_v4(address.ip(), &Ipv4Addr::UNSPECIFIED)
        .map_err(|source| ListenError::Join {
            given: url.to_owned(),
            group: *address.ip(),
            source,
        })?;
    Ok(socket.into())
}

fn now_ns() -> i64 {
    std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| i64::try_from(d.as_nanos()).unwrap_or(i64::MAX))
}

fn receive(socket: &UdpSocket, tx: &SyncSender<Received>, stop: &AtomicBool, dropped: &AtomicU64) {
    let mut buf = vec![0u8; MAX_PACKET_BYTES + 1];
    while !stop.load(Ordering::Relaxed) {
        let (len, from) = match socket.recv_from(&mut buf) {
            Ok(got) => got,
            Err(e)
                if matches!(
                    e.kind(),
                    std::io::ErrorKind::WouldBlock
                        | std::io::ErrorKind::TimedOut
                        | std::io::ErrorKind::Interrupted
                ) =>
            {
                continue;
            }
            Err(e) => {
                // A socket error that is not a timeout (rare: the interface went away): said
                // once a poll, never a busy loop.
                let _ = tx.try_send(Received::Bad {
                    from: SocketAddr::V4(SocketAddrV4::new(Ipv4Addr::UNSPECIFIED, 0)),
                    why: format!("receive failed: {e}"),
                });
                std::thread::sleep(POLL);
                continue;
            }
        };
        let bytes = &buf[..len];
        let item = match decode_packet(bytes) {
            Ok(packet) => Received::Packet {
                received_ns: now_ns(),
                packet: Box::new(packet),
                bytes: bytes.to_vec(),
            },
            Err(e) => Received::Bad {
                from,
                why: e.to_string(),
            },
        };
        match tx.try_send(item) {
            Ok(()) => {}
            Err(TrySendError::Full(_)) => {
                dropped.fetch_add(1, Ordering::Relaxed);
            }
            Err(TrySendError::Disconnected(_)) => return,
        }
    }
}

#[cfg(test)]
mod tests {
    use prost::Message as _;

    use super::*;

    #[test]
    fn urls_parse_and_a_port_in_use_is_said() {
        assert_eq!(
            parse_udp_url("udp://224.5.23.2:10006"),
            Some(SocketAddrV4::new(Ipv4Addr::new(224, 5, 23, 2), 10006))
        );
        assert_eq!(parse_udp_url("224.5.23.2:10006"), None);
        assert_eq!(parse_udp_url("udp://224.5.23.2:0"), None);
        assert!(matches!(
            Listener::start("udp://nowhere"),
            Err(ListenError::Address { .. })
        ));
        let taken = UdpSocket::bind("127.0.0.1:0").expect("a free port");
        let url = format!("udp://{}", taken.local_addr().expect("address"));
        let err = Listener::start(&url).expect_err("in use");
        assert!(err.to_string().contains("port in use"), "{err}");
    }

    #[test]
    fn packets_and_bad_datagrams_arrive_in_order() {
        let probe = UdpSocket::bind("127.0.0.1:0").expect("a free port");
        let port = probe.local_addr().expect("address").port();
        drop(probe);
        let listener = Listener::start(&format!("udp://127.0.0.1:{port}")).expect("listens");
        let sender = UdpSocket::bind("127.0.0.1:0").expect("socket");
        let good = SslWrapperPacket {
            detection: Some(super::super::SslDetectionFrame {
                camera_id: 3,
                ..Default::default()
            }),
            geometry: None,
        }
        .encode_to_vec();
        sender
            .send_to(&[0xff, 0xff], ("127.0.0.1", port))
            .expect("send");
        sender.send_to(&good, ("127.0.0.1", port)).expect("send");
        let first = listener.next_timeout(Duration::from_secs(5)).expect("one");
        assert!(matches!(first, Received::Bad { .. }), "{first:?}");
        let second = listener.next_timeout(Duration::from_secs(5)).expect("two");
        let Received::Packet { packet, .. } = second else {
            panic!("{second:?}");
        };
        assert_eq!(packet.detection.map(|d| d.camera_id), Some(3));
    }
}
