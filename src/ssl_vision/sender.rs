//! Sending SSL-Vision packets over UDP to `HOST:PORT`: a unicast address, or a multicast group
//! (the league's is 224.5.23.2:10006; sent with a time-to-live of 1, so packets stay on the
//! local network, and looped back so a client on this machine hears them too).
//!
//! Each detection frame goes in its own `SSL_WrapperPacket`; the geometry goes in a packet of
//! its own first and again every [`GEOMETRY_EVERY`] (wall time or capture time, whichever comes
//! first), as ssl-vision repeats it for clients that join late. A send that fails (no route,
//! a full buffer) is counted and said once per kind of error; sending goes on.

use std::net::{Ipv4Addr, SocketAddr, ToSocketAddrs, UdpSocket};
use std::time::{Duration, Instant};

use prost::Message as _;

use super::{SslDetectionFrame, SslGeometryData, SslWrapperPacket};

/// How often the geometry is sent again.
pub const GEOMETRY_EVERY: Duration = Duration::from_secs(3);

/// Why sending could not start.
#[derive(Debug, thiserror::Error)]
pub enum SendError {
    /// Not `HOST:PORT`, or a host that does not resolve.
    #[error(
        "--ssl-vision {given}: not HOST:PORT (e.g. {}): {why}",
        super::LEAGUE_ADDRESS
    )]
    Address {
        /// What was given.
        given: String,
        /// Why.
        why: String,
    },
    /// The socket could not be made.
    #[error("--ssl-vision {given}: cannot open a UDP socket: {source}")]
    Socket {
        /// What was given.
        given: String,
        /// The system's error.
        source: std::io::Error,
    },
}

/// See the module documentation.
#[derive(Debug)]
pub struct SslSender {
    socket: UdpSocket,
    target: SocketAddr,
    geometry: Option<SslGeometryData>,
    last_geometry: Option<(Instant, f64)>,
    /// Detection packets sent.
    pub frames_sent: u64,
    /// Geometry packets sent.
    pub geometry_sent: u64,
    /// Sends that failed.
    pub failures: u64,
    /// The last send's error, if the last send failed.
    pub last_error: Option<String>,
    warned: Vec<std::io::ErrorKind>,
}

impl SslSender {
    /// A sender to `HOST:PORT`.
    ///
    /// # Errors
    /// [`SendError`]: an address that does not parse or resolve (port 0 included), or no socket.
    pub fn new(address: &str) -> Result<Self, SendError> {
        let bad = |why: String| SendError::Address {
            given: address.to_owned(),
            why,
        };
        let target = address
            .to_socket_addrs()
            .map_err(|e| bad(e.to_string()))?
            .next()
            .ok_or_else(|| bad("the host has no address".to_owned()))?;
        if target.port() == 0 {
            return Err(bad("port 0 is not a port to send to".to_owned()));
        }
        let local: SocketAddr = if target.is_ipv4() {
            (Ipv4Addr::UNSPECIFIED, 0).into()
        } else {
            (std::net::Ipv6Addr::UNSPECIFIED, 0).into()
        };
        let socket_error = |source| SendError::Socket {
            given: address.to_owned(),
            source,
        };
        let socket = UdpSocket::bind(local).map_err(socket_error)?;
        if target.ip().is_multicast() && target.is_ipv4() {
            socket.set_multicast_ttl_v4(1).map_err(socket_error)?;
            socket.set_multicast_loop_v4(true).map_err(socket_error)?;
        }
        Ok(Self {
            socket,
            target,
            geometry: None,
            last_geometry: None,
            frames_sent: 0,
            geometry_sent: 0,
            failures: 0,
            last_error: None,
            warned: Vec::new(),
        })
    }

    /// Where the packets go.
    #[must_use]
    pub const fn target(&self) -> SocketAddr {
        self.target
    }

    /// The geometry to send first and then every [`GEOMETRY_EVERY`].
    pub fn set_geometry(&mut self, geometry: SslGeometryData) {
        self.geometry = Some(geometry);
        self.last_geometry = None;
    }

    /// Sends one detection frame (after the geometry when it is due).
    pub fn send_frame(&mut self, frame: SslDetectionFrame) {
        let t = frame.t_capture;
        let due = self.last_geometry.is_none_or(|(wall, capture)| {
            wall.elapsed() >= GEOMETRY_EVERY || (t - capture).abs() >= GEOMETRY_EVERY.as_secs_f64()
        });
        if due && let Some(g) = self.geometry.clone() {
            let packet = SslWrapperPacket {
                detection: None,
                geometry: Some(g),
            };
            if self.send(&packet.encode_to_vec()) {
                self.geometry_sent += 1;
            }
            self.last_geometry = Some((Instant::now(), t));
        }
        let packet = SslWrapperPacket {
            detection: Some(frame),
            geometry: None,
        };
        if self.send(&packet.encode_to_vec()) {
            self.frames_sent += 1;
        }
    }

    fn send(&mut self, bytes: &[u8]) -> bool {
        match self.socket.send_to(bytes, self.target) {
            Ok(_) => {
                self.last_error = None;
                true
            }
            Err(e) => {
                self.failures += 1;
                self.last_error = Some(e.to_string());
                if !self.warned.contains(&e.kind()) {
                    self.warned.push(e.kind());
                    log::warn!(
                        "ssl-vision: sending to {} failed: {e} (said once; sending goes on)",
                        self.target
                    );
                }
                false
            }
        }
    }

    /// One line on what was sent.
    #[must_use]
    pub fn summary(&self) -> String {
        let failed = if self.failures > 0 {
            format!(", {} sends failed", self.failures)
        } else {
            String::new()
        };
        format!(
            "ssl-vision: {} detection and {} geometry packets sent to {}{failed}",
            self.frames_sent, self.geometry_sent, self.target
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn geometry_goes_first_then_frames() {
        let receiver = UdpSocket::bind("127.0.0.1:0").expect("socket");
        receiver
            .set_read_timeout(Some(Duration::from_secs(5)))
            .expect("timeout");
        let addr = receiver.local_addr().expect("address").to_string();
        let mut s = SslSender::new(&addr).expect("sender");
        s.set_geometry(SslGeometryData::default());
        s.send_frame(SslDetectionFrame::default());
        s.send_frame(SslDetectionFrame::default());
        let mut buf = [0u8; 2048];
        let mut kinds = Vec::new();
        for _ in 0..3 {
            let n = receiver.recv(&mut buf).expect("a packet");
            let p = SslWrapperPacket::decode(&buf[..n]).expect("decodes");
            kinds.push((p.geometry.is_some(), p.detection.is_some()));
        }
        assert_eq!(kinds, [(true, false), (false, true), (false, true)]);
        assert_eq!((s.frames_sent, s.geometry_sent), (2, 1));
        for bad in ["nowhere", "127.0.0.1:0", "127.0.0.1:99999"] {
            assert!(SslSender::new(bad).is_err(), "{bad}");
        }
    }
}
