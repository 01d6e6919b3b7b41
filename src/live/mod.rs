//! Live streams from robots over the Foxglove WebSocket protocol: the same channels as a
//! recorded stream (`/camera/image` as `foxglove.RawImage`, `/sensors` as JSON, any other JSON
//! channel), so a robot that logs to Foxglove needs nothing new.
//!
//! [`protocol`] parses one server message (pure: bytes in, typed message or typed error out);
//! [`channels`] keeps one connection's channels within the client's [`Limits`]; [`client`] runs
//! one robot's connection on its own thread with deadlines and reconnection; [`robot`] turns its
//! messages into frames with statistics ([`gaps`]: lost frames) and an optional bit-exact
//! recording ([`recorder`]); [`serve`] plays a stream as a Foxglove WebSocket server (`eotn
//! serve`, a stand-in robot) behind a [`gate`] that bounds its viewers;
//! [`source`] is a robot as a [`crate::sources::FrameSource`] for the workspace and the app.

mod attach;
mod camera_frames;
pub mod channels;
pub mod client;
pub mod gaps;
pub mod gate;
pub mod protocol;
pub mod recorder;
pub mod robot;
pub mod serve;
pub mod source;

use std::fmt;

pub use client::{ClientOptions, Limits, LiveEvent, RobotClient};
pub use recorder::LiveRecorder;
pub use robot::{Connection, LiveFrame, LiveRobot, RobotFrames, RobotStats};
pub use source::NetworkSource;

/// WebSocket subprotocols the client offers: the SDK's (its servers accept only this one since
/// 0.30) and the older name other servers use.
pub const SUBPROTOCOLS: &str = "foxglove.sdk.v1, foxglove.websocket.v1";

/// Port Foxglove servers listen on unless told otherwise.
pub const DEFAULT_PORT: u16 = 8765;

/// A robot's address: `ws://HOST:PORT[/PATH]`, or `HOST[:PORT]` for short.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct RobotUrl {
    /// Host name or IP address.
    pub host: String,
    /// TCP port.
    pub port: u16,
    /// Path of the WebSocket endpoint (`/` for Foxglove servers).
    pub path: String,
}

/// Why a robot address was not understood.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum UrlError {
    /// Not `ws://HOST:PORT` or `HOST:PORT`.
    #[error("'{0}' is not a robot address (ws://HOST:PORT or HOST:PORT)")]
    Malformed(String),
    /// `wss://` needs TLS, which eotn does not speak.
    #[error("'{0}': wss:// (TLS) is not supported; use ws://")]
    Tls(String),
}

impl std::str::FromStr for RobotUrl {
    type Err = UrlError;

    fn from_str(text: &str) -> Result<Self, Self::Err> {
        let t = text.trim();
        if t.starts_with("wss://") {
            return Err(UrlError::Tls(text.to_owned()));
        }
        let rest = t.strip_prefix("ws://").unwrap_or(t);
        let (authority, path) = match rest.find('/') {
            Some(i) => (&rest[..i], &rest[i..]),
            None => (rest, "/"),
        };
        let bad = || UrlError::Malformed(text.to_owned());
        let (host, port) = match authority.rsplit_once(':') {
            Some((h, p)) if !h.ends_with(']') || h.starts_with('[') => {
                (h, p.parse::<u16>().map_err(|_| bad())?)
            }
            _ => (authority, DEFAULT_PORT),
        };
        let host = host.trim_start_matches('[').trim_end_matches(']');
        if host.is_empty() || host.contains(char::is_whitespace) || rest.contains("://") {
            return Err(bad());
        }
        Ok(Self {
            host: host.to_owned(),
            port,
            path: path.to_owned(),
        })
    }
}

impl fmt::Display for RobotUrl {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.host.contains(':') {
            write!(f, "ws://[{}]:{}{}", self.host, self.port, self.path)
        } else {
            write!(f, "ws://{}:{}{}", self.host, self.port, self.path)
        }
    }
}

/// This machine's clock, nanoseconds since the Unix epoch (0 before 1970).
#[must_use]
pub fn unix_time_ns() -> u64 {
    std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| u64::try_from(d.as_nanos()).unwrap_or(u64::MAX))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn robot_addresses_parse_with_and_without_scheme_and_port() {
        let u: RobotUrl = "ws://10.0.0.3:9000"
            .parse()
            .unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(
            (u.host.as_str(), u.port, u.path.as_str()),
            ("10.0.0.3", 9000, "/")
        );
        let u: RobotUrl = "robot4".parse().unwrap_or_else(|e| panic!("{e}"));
        assert_eq!((u.host.as_str(), u.port), ("robot4", DEFAULT_PORT));
        assert_eq!(u.to_string(), "ws://robot4:8765/");
        assert!(matches!(
            "wss://x:1".parse::<RobotUrl>(),
            Err(UrlError::Tls(_))
        ));
        assert!(matches!(
            "x:port".parse::<RobotUrl>(),
            Err(UrlError::Malformed(_))
        ));
        assert!(matches!(
            "http://x:1".parse::<RobotUrl>(),
            Err(UrlError::Malformed(_))
        ));
    }
}
