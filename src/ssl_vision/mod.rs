//! SSL-Vision, the Small Size League's shared vision system, spoken both ways: eotn's overhead
//! detections sent as `SSL_WrapperPacket`s (so any SSL team's software can use an eotn camera
//! where it would use ssl-vision), and ssl-vision's packets read live or from the league's game
//! logs (so its detections show beside eotn's and can serve as the truth of `eotn eval`).
//!
//! | file | role |
//! |---|---|
//! | `messages.rs` | the protobuf messages, declared by hand from the protocol's field numbers (`prost` derive, no `protoc`) |
//! | `mod.rs` | [`decode_packet`] (bounded, typed errors), [`CameraFrame`] (one camera's detections as plain eotn data: centimetres, [`MarkerTeam`]), [`detection_frame`] (eotn's detections → a detection message) |
//! | `geometry.rs` | the field (size, lines, arcs) from a field description; each camera's calibration in ssl-vision's model, its one distortion coefficient fitted to eotn's lens |
//! | `sender.rs` | [`sender::SslSender`]: packets to `HOST:PORT` (unicast or multicast), geometry every few seconds |
//! | `out.rs` | [`out::SslOut`]: eotn's detections as numbered detection frames with the geometry, what the CLI's `--ssl-vision` and the app send |
//! | `listener.rs` | [`listener::Listener`]: a thread receiving `udp://GROUP:PORT` (multicast joined) or a unicast port, bounded |
//! | `log.rs` | the league's log files (`SSL_LOG_FILE`, version 1; gzip too): read message by message, vision kept, the rest counted |
//! | `truth.rs` | detection frames as the truth of an overhead stream: paired by capture time, merged over cameras, as an [`crate::model::truth::OverheadTruth`] |
//!
//! Units on the wire are the league's: millimetres, radians, pixels, seconds. eotn's field frame
//! is the league's (origin at the centre, x along the length towards the yellow goal, y to the
//! left), so positions are only scaled (cm ↔ mm).

pub mod geometry;
pub mod listener;
pub mod log;
pub mod messages;
pub mod out;
pub mod sender;
pub mod truth;

use prost::Message as _;

use crate::geometry::{MarkerTeam, OverheadCamera};
use crate::overhead::OverheadDetections;
pub use messages::{SslDetectionFrame, SslGeometryData, SslWrapperPacket};

/// The league's multicast group and port for ssl-vision's detection packets.
pub const LEAGUE_ADDRESS: &str = "224.5.23.2:10006";

/// The largest UDP payload over IPv4, bytes: no packet can be longer.
pub const MAX_PACKET_BYTES: usize = 65_507;

/// Why a packet is not an SSL-Vision packet.
#[derive(Debug, thiserror::Error)]
pub enum PacketError {
    /// Longer than any UDP datagram.
    #[error("{len} bytes, more than a UDP packet can hold ({MAX_PACKET_BYTES})")]
    TooLarge {
        /// Its length.
        len: usize,
    },
    /// Not protobuf of the wrapper's shape.
    #[error("not an SSL_WrapperPacket ({len} bytes): {source}")]
    Decode {
        /// Its length.
        len: usize,
        /// What the decoder said.
        source: prost::DecodeError,
    },
    /// Decodes, but holds neither detections nor geometry.
    #[error("an SSL_WrapperPacket with neither detection nor geometry ({len} bytes)")]
    Empty {
        /// Its length.
        len: usize,
    },
}

/// Decodes one packet (a UDP datagram or a log message's payload).
///
/// # Errors
/// [`PacketError`]: too long, not protobuf of the wrapper's shape, or empty.
pub fn decode_packet(bytes: &[u8]) -> Result<SslWrapperPacket, PacketError> {
    let len = bytes.len();
    if len > MAX_PACKET_BYTES {
        return Err(PacketError::TooLarge { len });
    }
    let packet =
        SslWrapperPacket::decode(bytes).map_err(|source| PacketError::Decode { len, source })?;
    if packet.detection.is_none() && packet.geometry.is_none() {
        return Err(PacketError::Empty { len });
    }
    Ok(packet)
}

/// A ball of a detection frame, in eotn's units.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SslBall {
    /// Field position `[x, y]`, centimetres.
    pub field_cm: [f64; 2],
    /// Image position `[x, y]`, pixels.
    pub image_px: [f64; 2],
    /// Confidence, 0–1.
    pub confidence: f64,
}

/// A robot of a detection frame, in eotn's units.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SslRobot {
    /// Its team: blue robots come from `robots_blue`, yellow from `robots_yellow`.
    pub team: MarkerTeam,
    /// Its pattern's id, when the packet gives one.
    pub robot_id: Option<u32>,
    /// Field position `[x, y]`, centimetres.
    pub field_cm: [f64; 2],
    /// Heading, radians counter-clockwise from +x, when the packet gives one.
    pub heading_rad: Option<f64>,
    /// Image position `[x, y]`, pixels.
    pub image_px: [f64; 2],
    /// Confidence, 0–1.
    pub confidence: f64,
}

/// One camera's detections of one frame, as plain eotn data.
#[derive(Debug, Clone, PartialEq)]
pub struct CameraFrame {
    /// The camera (`camera_id`).
    pub camera_id: u32,
    /// The camera's frame counter.
    pub frame_number: u32,
    /// Capture time, seconds (ssl-vision: Unix time; eotn: the recording's clock).
    pub t_capture_s: f64,
    /// Send time, seconds.
    pub t_sent_s: f64,
    /// Balls.
    pub balls: Vec<SslBall>,
    /// Robots of both teams.
    pub robots: Vec<SslRobot>,
    /// Objects left out because a coordinate was not a finite number.
    pub dropped: usize,
}

impl CameraFrame {
    /// The detections of a detection message, millimetres turned into centimetres; objects with
    /// a coordinate that is not a finite number are left out (counted in `dropped`).
    #[must_use]
    pub fn from_message(m: &SslDetectionFrame) -> Self {
        let finite = |v: &[f32]| v.iter().all(|x| x.is_finite());
        let mut dropped = 0;
        let balls = m
            .balls
            .iter()
            .filter(|b| {
                let ok = finite(&[b.x, b.y, b.pixel_x, b.pixel_y, b.confidence]);
                dropped += usize::from(!ok);
                ok
            })
            .map(|b| SslBall {
                field_cm: [f64::from(b.x) / 10.0, f64::from(b.y) / 10.0],
                image_px: [f64::from(b.pixel_x), f64::from(b.pixel_y)],
                confidence: f64::from(b.confidence),
            })
            .collect();
        let teams = [
            (MarkerTeam::Blue, &m.robots_blue),
            (MarkerTeam::Yellow, &m.robots_yellow),
        ];
        let mut robots = Vec::new();
        for (team, list) in teams {
            for r in list {
                let heading = r.orientation.filter(|o| o.is_finite()).map(f64::from);
                if !finite(&[r.x, r.y, r.pixel_x, r.pixel_y, r.confidence]) {
                    dropped += 1;
                    continue;
                }
                robots.push(SslRobot {
                    team,
                    robot_id: r.robot_id,
                    field_cm: [f64::from(r.x) / 10.0, f64::from(r.y) / 10.0],
                    heading_rad: heading,
                    image_px: [f64::from(r.pixel_x), f64::from(r.pixel_y)],
                    confidence: f64::from(r.confidence),
                });
            }
        }
        Self {
            camera_id: m.camera_id,
            frame_number: m.frame_number,
            t_capture_s: m.t_capture,
            t_sent_s: m.t_sent,
            balls,
            robots,
            dropped,
        }
    }

    /// The capture time in nanoseconds, `None` when it is negative, not finite or beyond
    /// `u64` (a packet that says nothing usable about its time).
    #[must_use]
    pub fn t_capture_ns(&self) -> Option<u64> {
        let ns = self.t_capture_s * 1e9;
        (ns.is_finite() && ns >= 0.0 && ns < u64::MAX as f64).then(|| ns.round() as u64)
    }
}

/// eotn's detections of one frame as a detection message: positions in millimetres (field
/// centimetres × 10), each robot's heading as `orientation`, its identity as `robot_id`, the
/// marker plate's height as `height`, blue robots in `robots_blue` and yellow ones in
/// `robots_yellow`; the ball's blob area from its image radius.
#[must_use]
pub fn detection_frame(
    camera_id: u32,
    frame_number: u32,
    times_s: (f64, f64),
    detections: &OverheadDetections,
    plate_height_cm: f64,
) -> SslDetectionFrame {
    let mm = |cm: f64| (cm * 10.0) as f32;
    let balls = detections
        .ball
        .iter()
        .map(|b| messages::SslDetectionBall {
            confidence: b.confidence as f32,
            area: Some((std::f64::consts::PI * b.radius_px * b.radius_px).round() as u32),
            x: mm(b.field_cm[0]),
            y: mm(b.field_cm[1]),
            z: Some(0.0),
            pixel_x: b.image.x_px as f32,
            pixel_y: b.image.y_px as f32,
        })
        .collect();
    let robot = |r: &crate::overhead::recognise::OverheadRobot| messages::SslDetectionRobot {
        confidence: r.confidence as f32,
        robot_id: Some(u32::from(r.identity.value())),
        x: mm(r.field_cm[0]),
        y: mm(r.field_cm[1]),
        orientation: Some(r.heading_rad as f32),
        pixel_x: r.image.x_px as f32,
        pixel_y: r.image.y_px as f32,
        height: Some(mm(plate_height_cm)),
    };
    let of_team = |team: MarkerTeam| {
        detections
            .robots
            .iter()
            .filter(|r| r.team == team)
            .map(robot)
            .collect()
    };
    SslDetectionFrame {
        frame_number,
        t_capture: times_s.0,
        t_sent: times_s.1,
        camera_id,
        balls,
        robots_yellow: of_team(MarkerTeam::Yellow),
        robots_blue: of_team(MarkerTeam::Blue),
        t_capture_camera: None,
    }
}

/// A camera's calibration and id, as the geometry message needs them.
#[derive(Debug, Clone, Copy)]
pub struct CameraEntry {
    /// The `camera_id` its detection frames carry.
    pub camera_id: u32,
    /// Its calibration.
    pub camera: OverheadCamera,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{ImagePoint, MarkerIdentity};
    use crate::overhead::recognise::{OverheadBall, OverheadRobot};

    fn detections() -> OverheadDetections {
        let p = ImagePoint::new(100.25, 50.5);
        let robot = |team, id, x| OverheadRobot {
            team,
            identity: MarkerIdentity::new(id).expect("identity"),
            field_cm: [x, -20.0],
            heading_rad: 0.75,
            image: p,
            dots: [p; 4],
            confidence: 0.9,
        };
        OverheadDetections {
            ball: Some(OverheadBall {
                field_cm: [12.34, -56.78],
                image: p,
                radius_px: 4.0,
                confidence: 0.8,
            }),
            robots: vec![
                robot(MarkerTeam::Blue, 3, 100.0),
                robot(MarkerTeam::Yellow, 9, -150.0),
            ],
            rejected: Vec::new(),
        }
    }

    #[test]
    fn a_frame_round_trips_through_the_wire_in_millimetres() {
        let m = detection_frame(4, 17, (1.5, 1.6), &detections(), 22.5);
        assert_eq!(m.robots_blue.len(), 1);
        assert_eq!(m.robots_yellow.len(), 1);
        assert_eq!(m.robots_blue[0].robot_id, Some(3));
        assert!((m.balls[0].x - 123.4).abs() < 1e-3);
        let bytes = SslWrapperPacket {
            detection: Some(m),
            geometry: None,
        }
        .encode_to_vec();
        let back = decode_packet(&bytes).expect("decodes");
        let frame = CameraFrame::from_message(&back.detection.expect("detection"));
        assert_eq!((frame.camera_id, frame.frame_number), (4, 17));
        assert!((frame.balls[0].field_cm[0] - 12.34).abs() < 1e-4);
        let yellow = frame
            .robots
            .iter()
            .find(|r| r.team == MarkerTeam::Yellow)
            .expect("yellow robot");
        assert_eq!(yellow.robot_id, Some(9));
        assert!((yellow.field_cm[0] + 150.0).abs() < 1e-4);
        assert!((yellow.heading_rad.expect("heading") - 0.75).abs() < 1e-6);
        assert_eq!(frame.t_capture_ns(), Some(1_500_000_000));
    }

    #[test]
    fn bad_packets_say_why() {
        assert!(matches!(
            decode_packet(&[0xff, 0xff, 0xff]),
            Err(PacketError::Decode { .. })
        ));
        assert!(matches!(decode_packet(&[]), Err(PacketError::Empty { .. })));
        assert!(matches!(
            decode_packet(&vec![0; MAX_PACKET_BYTES + 1]),
            Err(PacketError::TooLarge { .. })
        ));
        // A detection with a NaN position keeps its other objects.
        let mut m = detection_frame(0, 0, (0.0, 0.0), &detections(), 22.5);
        m.robots_blue[0].x = f32::NAN;
        let frame = CameraFrame::from_message(&m);
        assert_eq!((frame.robots.len(), frame.dropped), (1, 1));
        let never = CameraFrame {
            t_capture_s: f64::NAN,
            ..frame
        };
        assert_eq!(never.t_capture_ns(), None);
    }
}
