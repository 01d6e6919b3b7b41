//! The robots' world-model message (docs/formats.md, "World models"): one JSON object per robot
//! per update, on `/world_model` or `/world_model/<anything>`. [`parse`] reads one message's
//! bytes and says why it refuses one ([`Rejection`]); the caller warns and skips it.

use serde_json::{Map, Value, json};

use crate::geometry::{MarkerIdentity, MarkerTeam};

/// Whether `topic` carries world models: `/world_model` or `/world_model/<anything>`.
#[must_use]
pub fn is_world_model_topic(topic: &str) -> bool {
    topic == "/world_model"
        || topic
            .strip_prefix("/world_model/")
            .is_some_and(|r| !r.is_empty())
}

/// A robot named by the marker it wears: the one robot identity of the world-model debugger,
/// the field view and the workspace's robot selection.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct RobotKey {
    /// The marker's team.
    pub team: MarkerTeam,
    /// The marker's identity, 0–15.
    pub identity: MarkerIdentity,
}

impl Ord for RobotKey {
    /// Blue team first, then by identity (listings, trails).
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        let rank = |k: &Self| (k.team == MarkerTeam::Yellow, k.identity);
        rank(self).cmp(&rank(other))
    }
}

impl PartialOrd for RobotKey {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

impl std::fmt::Display for RobotKey {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{} {}", self.team.name(), self.identity.value())
    }
}

impl RobotKey {
    /// The image topic of this robot's camera in a session recording (`eotn wmd -o`):
    /// `/robot/TEAM-ID`.
    #[must_use]
    pub fn camera_topic(self) -> String {
        format!(
            "{}{}-{}",
            crate::camera::SESSION_ROBOT_TOPIC_PREFIX,
            self.team.name(),
            self.identity.value()
        )
    }
}

/// A robot's estimate of itself.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SelfEstimate {
    /// Field x, centimetres.
    pub x_cm: f64,
    /// Field y, centimetres.
    pub y_cm: f64,
    /// Heading, radians counter-clockwise from +x.
    pub heading_rad: f64,
    /// Its position's standard deviation, centimetres.
    pub sd_cm: Option<f64>,
    /// Its heading's standard deviation, radians.
    pub sd_heading_rad: Option<f64>,
}

/// What a `seen` measurement is of.
#[derive(Debug, Clone, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum SeenObject {
    /// The ball.
    Ball,
    /// The centre of the yellow goal's mouth on the ground.
    YellowGoal,
    /// The centre of the blue goal's mouth on the ground.
    BlueGoal,
    /// A landmark of the field file, by name (its foot).
    Landmark(String),
}

impl SeenObject {
    /// The object's name as the message writes it.
    #[must_use]
    pub fn name(&self) -> &str {
        match self {
            Self::Ball => "ball",
            Self::YellowGoal => "yellow_goal",
            Self::BlueGoal => "blue_goal",
            Self::Landmark(n) => n,
        }
    }

    /// The object a message names.
    #[must_use]
    pub fn from_name(name: &str) -> Self {
        match name {
            "ball" => Self::Ball,
            "yellow_goal" => Self::YellowGoal,
            "blue_goal" => Self::BlueGoal,
            other => Self::Landmark(other.to_owned()),
        }
    }
}

/// One measurement of the robot's vision, from its body centre on the ground.
#[derive(Debug, Clone, PartialEq)]
pub struct Seen {
    /// What it measured.
    pub object: SeenObject,
    /// Distance, centimetres.
    pub distance_cm: f64,
    /// Bearing, radians counter-clockwise from the robot's heading.
    pub bearing_rad: f64,
}

/// One world-model message.
#[derive(Debug, Clone, PartialEq)]
pub struct WorldModelMessage {
    /// The robot, by the marker it wears.
    pub robot: RobotKey,
    /// Its estimate of itself.
    pub own: SelfEstimate,
    /// Its estimate of the ball, field `[x, y]` centimetres; `None` when it has none.
    pub ball: Option<[f64; 2]>,
    /// When, nanoseconds on the robot's clock.
    pub time_ns: Option<u64>,
    /// What its vision measured this frame.
    pub seen: Vec<Seen>,
}

/// Why a message was refused.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum Rejection {
    /// The bytes are not JSON (a robot writing `NaN` or `Infinity` lands here too).
    #[error("not JSON: {0}")]
    NotJson(String),
    /// The bytes hold `NaN` or `Infinity`, which JSON does not have.
    #[error("a number is NaN or infinite")]
    NotFinite,
    /// The message is not a JSON object.
    #[error("not a JSON object")]
    NotAnObject,
    /// eotn's simulator before the format was fixed (`time_s`, the uniform as `team`).
    #[error("an older eotn simulator's message (`time_s`, uniform team); re-run `eotn sim`")]
    OldSimulatorFormat,
    /// A required key is missing.
    #[error("missing key '{0}'")]
    Missing(String),
    /// A key the format does not have.
    #[error("unknown key '{0}'")]
    UnknownKey(String),
    /// `team` is not `blue` or `yellow`.
    #[error("unknown team {0:?} (blue or yellow, the marker's team)")]
    UnknownTeam(String),
    /// `robot_id` is not a marker identity.
    #[error("robot_id {0} is not a marker identity (0-15)")]
    IdOutOfRange(String),
    /// A key holds a value of the wrong kind (`"12"` for a number).
    #[error("'{0}' is not {1}")]
    WrongType(String, &'static str),
}

const TOP_KEYS: [&str; 6] = ["team", "robot_id", "self", "ball", "time_ns", "seen"];
const SELF_KEYS: [&str; 5] = ["x_cm", "y_cm", "heading_rad", "sd_cm", "sd_heading_rad"];

/// Reads one message's bytes.
///
/// # Errors
/// [`Rejection`]: why the message cannot be used.
pub fn parse(bytes: &[u8]) -> Result<WorldModelMessage, Rejection> {
    let value: Value = serde_json::from_slice(bytes).map_err(|e| {
        let text = String::from_utf8_lossy(bytes);
        if text.contains("NaN") || text.contains("Infinity") {
            Rejection::NotFinite
        } else {
            Rejection::NotJson(e.to_string())
        }
    })?;
    from_value(&value)
}

/// Reads one message already parsed as JSON.
///
/// # Errors
/// [`Rejection`]: why the message cannot be used.
pub fn from_value(value: &Value) -> Result<WorldModelMessage, Rejection> {
    let o = value.as_object().ok_or(Rejection::NotAnObject)?;
    if o.contains_key("time_s") || o.get("team").and_then(Value::as_str) == Some("red") {
        return Err(Rejection::OldSimulatorFormat);
    }
    known_keys(o, &TOP_KEYS, "")?;
    let team_text = o
        .get("team")
        .ok_or_else(|| Rejection::Missing("team".into()))?;
    let team = team_text
        .as_str()
        .and_then(MarkerTeam::from_name)
        .ok_or_else(|| Rejection::UnknownTeam(team_text.to_string()))?;
    let id_value = o
        .get("robot_id")
        .ok_or_else(|| Rejection::Missing("robot_id".into()))?;
    let identity = id_value
        .as_u64()
        .and_then(|v| u8::try_from(v).ok())
        .and_then(MarkerIdentity::new)
        .ok_or_else(|| Rejection::IdOutOfRange(id_value.to_string()))?;
    let own = o
        .get("self")
        .ok_or_else(|| Rejection::Missing("self".into()))?;
    let own = own
        .as_object()
        .ok_or_else(|| Rejection::WrongType("self".into(), "an object"))?;
    known_keys(own, &SELF_KEYS, "self.")?;
    let own = SelfEstimate {
        x_cm: number(own, "x_cm", "self.")?,
        y_cm: number(own, "y_cm", "self.")?,
        heading_rad: number(own, "heading_rad", "self.")?,
        sd_cm: optional_number(own, "sd_cm", "self.")?,
        sd_heading_rad: optional_number(own, "sd_heading_rad", "self.")?,
    };
    let ball = match o.get("ball") {
        None | Some(Value::Null) => None,
        Some(Value::Object(b)) => {
            known_keys(b, &["x_cm", "y_cm", "sd_cm"], "ball.")?;
            Some([number(b, "x_cm", "ball.")?, number(b, "y_cm", "ball.")?])
        }
        Some(_) => return Err(Rejection::WrongType("ball".into(), "an object or null")),
    };
    let time_ns = match o.get("time_ns") {
        None | Some(Value::Null) => None,
        Some(v) => Some(
            v.as_u64()
                .ok_or_else(|| Rejection::WrongType("time_ns".into(), "a whole number"))?,
        ),
    };
    let seen = match o.get("seen") {
        None | Some(Value::Null) => Vec::new(),
        Some(Value::Array(items)) => items
            .iter()
            .enumerate()
            .map(|(k, item)| seen(item, k))
            .collect::<Result<_, _>>()?,
        Some(_) => return Err(Rejection::WrongType("seen".into(), "a list")),
    };
    Ok(WorldModelMessage {
        robot: RobotKey { team, identity },
        own,
        ball,
        time_ns,
        seen,
    })
}

fn seen(item: &Value, k: usize) -> Result<Seen, Rejection> {
    let at = format!("seen[{k}].");
    let m = item
        .as_object()
        .ok_or_else(|| Rejection::WrongType(format!("seen[{k}]"), "an object"))?;
    known_keys(m, &["object", "distance_cm", "bearing_rad"], &at)?;
    let object = m
        .get("object")
        .ok_or_else(|| Rejection::Missing(format!("{at}object")))?
        .as_str()
        .ok_or_else(|| Rejection::WrongType(format!("{at}object"), "a name"))?;
    Ok(Seen {
        object: SeenObject::from_name(object),
        distance_cm: number(m, "distance_cm", &at)?,
        bearing_rad: number(m, "bearing_rad", &at)?,
    })
}

fn known_keys(o: &Map<String, Value>, known: &[&str], at: &str) -> Result<(), Rejection> {
    match o.keys().find(|k| !known.contains(&k.as_str())) {
        Some(k) => Err(Rejection::UnknownKey(format!("{at}{k}"))),
        None => Ok(()),
    }
}

fn number(o: &Map<String, Value>, key: &str, at: &str) -> Result<f64, Rejection> {
    optional_number(o, key, at)?.ok_or_else(|| Rejection::Missing(format!("{at}{key}")))
}

fn optional_number(o: &Map<String, Value>, key: &str, at: &str) -> Result<Option<f64>, Rejection> {
    match o.get(key) {
        None | Some(Value::Null) => Ok(None),
        Some(v) => match v.as_f64() {
            Some(x) if x.is_finite() => Ok(Some(x)),
            Some(_) => Err(Rejection::NotFinite),
            None => Err(Rejection::WrongType(format!("{at}{key}"), "a number")),
        },
    }
}

impl WorldModelMessage {
    /// The message as JSON, as robots (and `eotn sim`) send it.
    #[must_use]
    pub fn to_json(&self) -> Value {
        let mut own = json!({
            "x_cm": self.own.x_cm,
            "y_cm": self.own.y_cm,
            "heading_rad": self.own.heading_rad,
        });
        if let Some(sd) = self.own.sd_cm {
            own["sd_cm"] = json!(sd);
        }
        if let Some(sd) = self.own.sd_heading_rad {
            own["sd_heading_rad"] = json!(sd);
        }
        let mut out = json!({
            "team": self.robot.team.name(),
            "robot_id": self.robot.identity.value(),
            "self": own,
            "ball": self.ball.map(|[x, y]| json!({"x_cm": x, "y_cm": y})),
        });
        if let Some(t) = self.time_ns {
            out["time_ns"] = json!(t);
        }
        if !self.seen.is_empty() {
            out["seen"] = Value::Array(
                self.seen
                    .iter()
                    .map(|s| {
                        json!({
                            "object": s.object.name(),
                            "distance_cm": s.distance_cm,
                            "bearing_rad": s.bearing_rad,
                        })
                    })
                    .collect(),
            );
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn good() -> Value {
        json!({
            "team": "yellow", "robot_id": 7,
            "self": {"x_cm": 10.0, "y_cm": -20.5, "heading_rad": 0.5, "sd_cm": 12.0},
            "ball": {"x_cm": 100.0, "y_cm": 0.0},
            "time_ns": 1_000_000_u64,
            "seen": [{"object": "yellow_goal", "distance_cm": 250.0, "bearing_rad": 0.1},
                     {"object": "centre", "distance_cm": 22.0, "bearing_rad": -1.0}]
        })
    }

    #[test]
    fn a_message_round_trips() {
        let m = from_value(&good()).unwrap();
        assert_eq!(m.robot.team, MarkerTeam::Yellow);
        assert_eq!(m.robot.identity.value(), 7);
        assert_eq!(m.own.sd_cm, Some(12.0));
        assert_eq!(m.own.sd_heading_rad, None);
        assert_eq!(m.ball, Some([100.0, 0.0]));
        assert_eq!(m.seen[0].object, SeenObject::YellowGoal);
        assert_eq!(m.seen[1].object, SeenObject::Landmark("centre".into()));
        assert_eq!(from_value(&m.to_json()).unwrap(), m);
        let bytes = serde_json::to_vec(&good()).unwrap();
        assert_eq!(parse(&bytes).unwrap(), m);
    }

    #[test]
    fn bad_messages_say_why() {
        let with = |key: &str, v: Value| {
            let mut g = good();
            g[key] = v;
            from_value(&g)
        };
        assert_eq!(
            with("team", json!("red")),
            Err(Rejection::OldSimulatorFormat)
        );
        assert!(matches!(
            with("team", json!("green")),
            Err(Rejection::UnknownTeam(_))
        ));
        assert!(matches!(
            with("robot_id", json!(16)),
            Err(Rejection::IdOutOfRange(_))
        ));
        assert!(matches!(
            with("robot_id", json!(-1)),
            Err(Rejection::IdOutOfRange(_))
        ));
        assert!(matches!(with("colour", json!(1)), Err(Rejection::UnknownKey(k)) if k == "colour"));
        assert!(matches!(
            with("ball", json!(3)),
            Err(Rejection::WrongType(..))
        ));
        assert!(matches!(
            with("self", json!({"x_cm": 1.0, "y_cm": 2.0})),
            Err(Rejection::Missing(k)) if k == "self.heading_rad"
        ));
        assert!(matches!(
            with("time_s", json!(1.0)),
            Err(Rejection::OldSimulatorFormat)
        ));
        let nan = br#"{"team":"blue","robot_id":1,"self":{"x_cm":NaN,"y_cm":0,"heading_rad":0},"ball":null}"#;
        assert_eq!(parse(nan), Err(Rejection::NotFinite));
        assert!(matches!(parse(b"{"), Err(Rejection::NotJson(_))));
        assert_eq!(from_value(&json!([1])), Err(Rejection::NotAnObject));
    }

    #[test]
    fn world_model_topics() {
        assert!(is_world_model_topic("/world_model"));
        assert!(is_world_model_topic("/world_model/robot3"));
        assert!(!is_world_model_topic("/world_model/"));
        assert!(!is_world_model_topic("/world_models"));
    }
}
