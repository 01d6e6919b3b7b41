//! The World Model Debugger in the workspace (issue 30): which robots' cameras the app can show
//! beside the overhead camera, and showing the selected robot's; a session file's robots' own
//! world models, read from their recordings and paired with the shown frame; the world models
//! placed on the overhead image; the robots list; the WMD layout request the app's dock follows.
//!
//! A robot's camera is, in this order: the camera of its session-file entry whose `source` is a
//! recording (its own table and parameters from the entry), or the camera `/robot/TEAM-ID` of
//! a recorded session (`eotn wmd -o`; its files as the recording and the settings name them).
//! Selecting a robot that has one ([`super::OverheadCommand::SelectRobot`]) shows it side by side
//! with the overhead camera through the cameras-side-by-side mechanism
//! (`side_by_side.rs`): the overhead camera stays focused, the robot's camera is recognised
//! with its own table.

use std::borrow::Cow;
use std::collections::BTreeMap;

use super::Workspace;
use crate::camera::{CameraFiles, CameraId};
use crate::geometry::{ImagePoint, Point};
use crate::model::world_model::RobotKey;
use crate::session::{RobotEntry, SessionSource};
use crate::sources::SourceFrame;
use crate::streams::world_models::{RobotModels, read_world_models};

/// A session-file robot whose camera the app can show.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RobotCamera {
    /// The robot, by its marker.
    pub robot: RobotKey,
    /// Its camera: a recording's image topic.
    pub camera: CameraId,
    /// Its table and parameters, from the session entry.
    pub files: CameraFiles,
}

/// The WMD state of the workspace: the session file's robot cameras and world models, the
/// layout requests.
#[derive(Debug, Default)]
pub struct WmdState {
    /// The session file's robots whose source is a recording with camera frames.
    pub(super) robots: Vec<RobotCamera>,
    /// The world models of the session file's robots read from their recordings, each robot's
    /// in time order on its clock.
    models: RobotModels,
    /// Each of those robots' clock offset: overhead time − robot time, nanoseconds.
    offsets: BTreeMap<RobotKey, i64>,
    /// The overhead frames' period, nanoseconds: a world model within half of it of a frame is
    /// shown with it.
    period_ns: u64,
    /// Counts the requests for the WMD layout (the dock arranges itself when it changes).
    pub(super) layout_requests: u64,
}

impl WmdState {
    /// Forgets the session's robots (another source is opened); the layout requests stay.
    pub(super) fn forget_session(&mut self) {
        *self = Self {
            layout_requests: self.layout_requests,
            ..Self::default()
        };
    }
}

impl RobotCamera {
    /// The camera of a session entry whose source is a recording of camera frames; `None` for
    /// live robots, devices, and recordings of world models only.
    #[must_use]
    pub fn of_entry(entry: &RobotEntry) -> Option<Self> {
        let SessionSource::Recording(path) = &entry.source else {
            return None;
        };
        let reader =
            crate::streams::StreamReader::open_camera(path, entry.camera.as_deref()).ok()?;
        if reader.is_empty() {
            return None;
        }
        let topic = reader.camera()?.to_owned();
        let canonical = std::fs::canonicalize(path).unwrap_or_else(|_| path.clone());
        let kind = crate::sources::CameraKind::of_stream_source(&reader.info().source);
        let camera = match kind {
            crate::sources::CameraKind::Robot => CameraId::recording(&canonical, &topic),
            crate::sources::CameraKind::Overhead => {
                CameraId::overhead(&canonical.to_string_lossy(), &topic)
            }
        };
        Some(Self {
            robot: RobotKey {
                team: entry.team,
                identity: entry.robot_id,
            },
            camera,
            files: CameraFiles {
                lut: entry.lut.clone(),
                params: entry
                    .params
                    .as_deref()
                    .map(|p| p.to_string_lossy().into_owned()),
                calibration: None,
            },
        })
    }
}

/// One world model placed on the overhead image (pixels of the camera's frame).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WorldModelMark {
    /// The robot whose world model it is.
    pub robot: RobotKey,
    /// Where it believes it is.
    pub own: Option<ImagePoint>,
    /// A point 30 cm ahead of it along the heading it believes.
    pub heading: Option<ImagePoint>,
    /// Where it believes the ball is.
    pub ball: Option<ImagePoint>,
}

/// One robot of the WMD robots list.
#[derive(Debug, Clone)]
pub struct WmdRobotRow<'a> {
    /// The robot, by its marker.
    pub robot: RobotKey,
    /// Its camera, when the session has it (shown beside the overhead camera when selected).
    pub camera: Option<CameraId>,
    /// Its errors over the frames seen so far, once a world model of it was seen.
    pub summary: Option<&'a crate::wmd::summary::RobotSummary>,
}

/// How far ahead of a robot its heading mark is drawn, centimetres.
const HEADING_MARK_CM: f64 = 30.0;

impl Workspace {
    /// The camera of robot `robot` the app can show beside the overhead camera, with the
    /// files it is recognised with when the session names them; `None` when it has none.
    #[must_use]
    pub fn robot_camera(&self, robot: RobotKey) -> Option<(CameraId, Option<&CameraFiles>)> {
        if let Some(r) = self.overhead.wmd.robots.iter().find(|r| r.robot == robot) {
            return Some((r.camera.clone(), Some(&r.files)));
        }
        let src = self.source.as_ref()?;
        let topic = robot.camera_topic();
        src.cameras()
            .contains(&topic)
            .then(|| src.camera_id_of(&topic))
            .flatten()
            .map(|c| (c, None))
    }

    /// The session's robots: those whose world models were seen and those with a camera, blue
    /// team first, then by identity.
    #[must_use]
    pub fn wmd_robots(&self) -> Vec<WmdRobotRow<'_>> {
        let summaries = self.overhead.field_model.summaries();
        let mut rows = Vec::new();
        for team in [
            crate::geometry::MarkerTeam::Blue,
            crate::geometry::MarkerTeam::Yellow,
        ] {
            for identity in (0..16).filter_map(crate::geometry::MarkerIdentity::new) {
                let robot = RobotKey { team, identity };
                let camera = self.robot_camera(robot).map(|(c, _)| c);
                let summary = summaries.iter().find(|s| s.robot == robot);
                if camera.is_some() || summary.is_some() {
                    rows.push(WmdRobotRow {
                        robot,
                        camera,
                        summary,
                    });
                }
            }
        }
        rows
    }

    /// Whether `camera` is a session robot's camera from another recording than the source's.
    pub(super) fn session_robot_files(&self, camera: &CameraId) -> Option<&CameraFiles> {
        self.overhead
            .wmd
            .robots
            .iter()
            .find(|r| &r.camera == camera)
            .map(|r| &r.files)
    }

    /// The session file's robots (set when a session opens): those with a camera the app can
    /// show, and the world models of those whose source is a recording that holds them, each
    /// robot's clock taken as the overhead frames' (`frames_ns`, period `period_ns`) when their
    /// times overlap, else lined up by the first message and frame (`wmd::clock`'s start; the
    /// offset search `eotn wmd` does runs the overhead recogniser over the whole recording).
    /// A recording without world models is said as a warning.
    pub(super) fn set_session_robots(
        &mut self,
        entries: &[RobotEntry],
        frames_ns: &[u64],
        period_ns: u64,
    ) {
        let mut wmd = super::wmd::WmdState {
            robots: entries.iter().filter_map(RobotCamera::of_entry).collect(),
            period_ns,
            layout_requests: self.overhead.wmd.layout_requests,
            ..super::wmd::WmdState::default()
        };
        for e in entries {
            let SessionSource::Recording(path) = &e.source else {
                continue;
            };
            let key = RobotKey {
                team: e.team,
                identity: e.robot_id,
            };
            if let Err(err) = read_world_models(path, Some(key), &mut wmd.models) {
                self.warn(format!("robot {key}: {err:#}"));
            }
        }
        for (key, models) in &wmd.models {
            let own: Vec<(u64, [f64; 2])> = models
                .iter()
                .map(|(t, m)| (*t, [m.own.x_cm, m.own.y_cm]))
                .collect();
            let offset =
                crate::wmd::clock::estimate_offset(frames_ns, period_ns, |_| None, &own, 0);
            wmd.offsets.insert(*key, offset.offset_ns);
        }
        self.overhead.wmd = wmd;
    }

    /// A frame's channels with the session robots' world models paired with it (each robot's
    /// message nearest the frame's time within half a frame period, as
    /// `/world_model/TEAM-ID`) in place of any the frame carries for those robots; the frame's
    /// own channels when the session has none.
    pub(super) fn with_session_world_models<'a>(
        &self,
        loaded: &'a SourceFrame,
    ) -> Cow<'a, [(String, serde_json::Value)]> {
        let wmd = &self.overhead.wmd;
        if wmd.models.is_empty() {
            return Cow::Borrowed(&loaded.extra);
        }
        let half = i128::from(wmd.period_ns / 2);
        let mut out: Vec<(String, serde_json::Value)> = loaded
            .extra
            .iter()
            .filter(|(topic, v)| {
                !crate::model::world_model::is_world_model_topic(topic)
                    || crate::model::world_model::from_value(v)
                        .map_or(true, |m| !wmd.models.contains_key(&m.robot))
            })
            .cloned()
            .collect();
        for (key, models) in &wmd.models {
            let offset = i128::from(wmd.offsets.get(key).copied().unwrap_or(0));
            let at = |i: usize| {
                models.get(i).map(|(t, m)| {
                    (
                        (i128::from(*t) + offset - i128::from(loaded.time_ns)).abs(),
                        m,
                    )
                })
            };
            let target = i128::from(loaded.time_ns) - offset;
            let i = models.partition_point(|(t, _)| i128::from(*t) < target);
            let nearest = [i.checked_sub(1).and_then(at), at(i)]
                .into_iter()
                .flatten()
                .filter(|(d, _)| *d <= half)
                .min_by_key(|(d, _)| *d);
            if let Some((_, m)) = nearest {
                out.push((
                    format!("/world_model/{}-{}", key.team.name(), key.identity.value()),
                    m.to_json(),
                ));
            }
        }
        Cow::Owned(out)
    }

    /// After robot `robot` was selected: its camera beside the overhead camera, when it has one
    /// (a robot without one, or none selected: the overhead camera alone again, if a robot's
    /// camera was beside it). What cannot be shown is said, and the selection stays.
    pub(super) fn show_selected_robot_camera(&mut self, robot: Option<RobotKey>) {
        if self.camera_kind() != crate::sources::CameraKind::Overhead {
            return;
        }
        let Some(shown) = self.cameras().1 else {
            return;
        };
        let wanted = robot.and_then(|k| self.robot_camera(k)).map(|(c, _)| c);
        // Only a robot's camera beside is closed again (other cameras shown side by side stay).
        let beside_robot = self.camera_panes().iter().any(|p| {
            !p.focused
                && (p
                    .topic
                    .starts_with(crate::camera::SESSION_ROBOT_TOPIC_PREFIX)
                    || self.session_robot_files(p.camera).is_some())
        });
        let cameras = match &wanted {
            Some(c) => vec![shown, c.clone()],
            None if beside_robot => vec![shown],
            None => return,
        };
        match self.show_side_by_side(&cameras) {
            Ok(()) => {
                if let (Some(k), Some(c)) = (robot, wanted) {
                    self.status = format!(
                        "robot {k}: its camera {} beside the overhead camera",
                        c.topic()
                    );
                }
            }
            Err(e) => self.warn(format!("the robot's camera cannot be shown: {e:#}")),
        }
    }

    /// The shown frame's world models placed on the overhead image through the calibration in
    /// use (field centimetres on the ground → the frame's pixels); empty without a calibration.
    #[must_use]
    pub fn world_model_marks(&self) -> Vec<WorldModelMark> {
        let Some((camera, _)) = self.overhead.camera() else {
            return Vec::new();
        };
        let (w, h) = self.image_size();
        // The calibration's size scaled to the frame's, as the field lines are.
        let s = [
            w as f64 / camera.width_px.max(1) as f64,
            h as f64 / camera.height_px.max(1) as f64,
        ];
        let at = |p: [f64; 2]| {
            camera
                .image_from_field(&Point::new(p[0], p[1], 0.0))
                .map(|i| ImagePoint::new(i.x_px * s[0], i.y_px * s[1]))
        };
        self.overhead
            .field_model
            .world_models()
            .iter()
            .map(|m| {
                let ahead = [
                    m.own[0] + HEADING_MARK_CM * m.own[2].cos(),
                    m.own[1] + HEADING_MARK_CM * m.own[2].sin(),
                ];
                WorldModelMark {
                    robot: m.robot,
                    own: at([m.own[0], m.own[1]]),
                    heading: at(ahead),
                    ball: m.ball.and_then(at),
                }
            })
            .collect()
    }

    /// How many times the WMD layout was asked for (the dock arranges itself when it changes).
    #[must_use]
    pub const fn wmd_layout_requests(&self) -> u64 {
        self.overhead.wmd.layout_requests
    }

    /// Asks for the WMD layout: the overhead view, the field view and the robots list.
    pub(super) fn request_wmd_layout(&mut self) {
        self.settings.show_field_view = true;
        self.settings.show_robots = true;
        self.overhead.wmd.layout_requests += 1;
    }

    /// Whether the source shown is a recorded World Model Debugger session (`eotn wmd -o`):
    /// the app shows it in the WMD layout.
    pub(super) fn source_is_recorded_session(&self) -> bool {
        self.source.as_ref().is_some_and(|s| {
            s.info().kind == crate::sources::SourceKind::Stream
                && s.info().stream_source == crate::streams::WMD_SESSION_SOURCE
        })
    }
}
