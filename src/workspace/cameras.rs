//! Several cameras of one recording or live robot: which camera is shown
//! (`Command::OpenCamera`, the camera picker), and each camera's own files — its table,
//! recognition parameters and, for an overhead camera, calibration — remembered per camera
//! ([`CameraId`]: the source and its image topic) in the settings, else those the recording
//! names for it (its `REC.cameras.json` sidecar, else its `eotn.camera` metadata:
//! [`crate::camera::files_for`]). Opening a recording applies its camera's files the same way.

use std::path::{Path, PathBuf};

use anyhow::Context as _;

use super::Workspace;
use super::source::Source;
use crate::camera::{CameraFiles, CameraId};
use crate::sources::CameraKind;

/// The recording a camera belongs to, when it is one (not a live robot or device).
fn recording_of(id: &CameraId) -> Option<PathBuf> {
    match id {
        CameraId::Recording { recording, .. } => Some(recording.clone()),
        CameraId::Overhead { source, .. } => {
            Some(PathBuf::from(source)).filter(|p| crate::streams::is_recording(p))
        }
        CameraId::Live { .. } => None,
    }
}

impl Workspace {
    /// The camera shown: a recording's (robot or overhead), a live robot's image channel, or
    /// a connected overhead device; `None` for frame files and robot-camera devices.
    #[must_use]
    pub fn camera_id(&self) -> Option<CameraId> {
        if let Some(src) = &self.source {
            return src.camera_id();
        }
        let info = self.live.as_ref()?.info();
        (info.camera == CameraKind::Overhead).then(|| {
            let source = info
                .paths
                .first()
                .map_or_else(|| info.label.clone(), |p| p.to_string_lossy().into_owned());
            CameraId::overhead(&source, crate::camera::IMAGE_TOPIC)
        })
    }

    /// The camera (image topic) `recording` opens on: the one last picked for it, else the one
    /// `eotn open --camera` names, else (`None`) its first.
    pub(super) fn camera_for(&self, recording: &Path) -> Option<String> {
        let canonical = std::fs::canonicalize(recording).unwrap_or_else(|_| recording.to_owned());
        match &self.camera {
            Some(id) if recording_of(id).as_deref() == Some(canonical.as_path()) => {
                Some(id.topic().to_owned())
            }
            _ => self.open_topic.clone(),
        }
    }

    /// The files of camera `id`: each the one last used with this camera (a table only while
    /// its file is still there), else the one its recording names for it (its sidecar, its
    /// `eotn.camera` metadata).
    pub(super) fn camera_files(&mut self, id: &CameraId) -> CameraFiles {
        let mut remembered = self.settings.cameras.get(id).cloned().unwrap_or_default();
        remembered.lut = remembered.lut.filter(|p| p.is_file());
        let Some(recording) = recording_of(id) else {
            return remembered;
        };
        let named = crate::streams::StreamReader::open_camera(&recording, Some(id.topic()))
            .map_err(|e| e.to_string())
            .and_then(|r| r.camera_files().map_err(|e| e.to_string()));
        match named {
            Ok(files) => files.overridden_by(&remembered),
            Err(e) => {
                self.warn(format!("{}: {e}", recording.display()));
                remembered
            }
        }
    }

    /// Remembers a file for the camera shown (its table, parameters or calibration: `set`
    /// writes it into the camera's entry of the settings), to reopen with that camera.
    pub(super) fn remember_for_camera(&mut self, set: impl FnOnce(&mut CameraFiles)) {
        if let Some(id) = self.camera_id() {
            set(self.settings.cameras.entry(id).or_default());
        }
    }

    /// The camera's own parameters file, when it names one that is there (a name not found is
    /// said once, and the parameters in use stay).
    pub(super) fn camera_params(&mut self, id: &CameraId, files: &CameraFiles) -> Option<PathBuf> {
        let name = files.params.as_deref()?;
        let beside = recording_of(id).unwrap_or_default();
        let found = super::params::named_param_file(name, &beside).filter(|p| p.is_file());
        if found.is_none() {
            self.warn(format!(
                "camera {}: its parameter set {name} is not found (params/{name}.json beside the recording or above it): the parameters in use stay",
                id.topic()
            ));
        }
        found
    }

    /// After camera `id` was shown: its own parameters and, for an overhead camera, its
    /// calibration, when it has them. Parameters tuned and not saved are never replaced (said
    /// as a warning); an overhead camera without a calibration of its own says which one stays
    /// in use.
    pub(super) fn open_camera_files(
        &mut self,
        id: &CameraId,
        files: &CameraFiles,
    ) -> anyhow::Result<()> {
        if let Some(p) = self.camera_params(id, files)
            && self.params_slot().path.as_deref() != Some(p.as_path())
        {
            if self.params_modified() {
                self.warn(format!(
                    "camera {}: its parameters {} are not applied: the parameters tuned are not saved",
                    id.topic(),
                    crate::frame::display_name(&p)
                ));
            } else {
                self.open_params(&p)?;
            }
        }
        if self.camera_kind() != CameraKind::Overhead {
            return Ok(());
        }
        match &files.calibration {
            Some(c) if self.overhead.calibration_path() != Some(c.as_path()) => {
                self.apply(super::OverheadCommand::OpenCalibration(c.clone()).into())?;
            }
            Some(_) => {}
            None => {
                if let Some(c) = self.overhead.calibration_path() {
                    // Never a silent swap: the calibration kept was made for another camera.
                    let c = crate::frame::display_name(c);
                    self.warn(format!(
                        "camera {} has no calibration of its own (none used with it, none its recording names): {c} stays in use",
                        id.topic()
                    ));
                }
            }
        }
        Ok(())
    }

    /// Shows camera `id` of the open recording or live robot (`None`: its first), at the frame
    /// nearest the time shown, with that camera's table, parameters and calibration.
    pub(super) fn open_camera(&mut self, id: Option<CameraId>) -> anyhow::Result<()> {
        if let Some(id) = &id
            && self.camera_panes().iter().any(|p| p.camera == id)
        {
            // A camera shown side by side is focused, its neighbours kept.
            return self.focus_camera(id);
        }
        let src = self
            .source
            .as_ref()
            .context("no recording or robot is shown")?;
        let ids = src.camera_ids();
        let Some(first) = ids.first().cloned() else {
            anyhow::bail!("the source is not a recording or robot: it has no cameras to choose");
        };
        let id = id.unwrap_or(first);
        anyhow::ensure!(
            ids.iter().any(|i| i.same_source(&id)),
            "camera {id} is not of the source shown ({})",
            src.label()
        );
        let cursor = src.start_ns().saturating_add(src.time_ns(self.index));
        let source = match src.robot_frames() {
            Some(robot) => {
                anyhow::ensure!(
                    ids.contains(&id),
                    "robot {} has no camera {}: its cameras are {}",
                    robot.name(),
                    id.topic(),
                    src.cameras().join(", ")
                );
                Source::robot(robot.camera_view(id.topic()))
            }
            None => {
                let path = src
                    .paths()
                    .into_iter()
                    .next()
                    .context("no recording is open")?;
                Source::stream_camera(&path, Some(id.topic()))?
            }
        };
        let index = super::side_by_side::nearest_index(&source, cursor);
        let files = self.camera_files(&id);
        self.refuse_losing_unsaved(&id, &files)?;
        let live = source.robot_frames().is_some();
        if live {
            self.show_robot_camera(source)?;
        } else {
            self.set_source(source)?;
        }
        self.camera = Some(id.clone());
        let own_table = files.lut.clone();
        if let Some(t) = &own_table {
            self.open_table(t)?;
        }
        self.open_camera_files(&id, &files)?;
        if !(live && self.following_live()) {
            self.seek(index)?;
        }
        let camera = id.topic();
        self.status = format!("showing camera {camera} of {}", self.source_label());
        if own_table.is_none()
            && let Some(t) = self.table_path().map(crate::frame::display_name)
        {
            // Never a silent swap: the table kept is said to be another camera's.
            self.warn(format!(
                "camera {camera} has no table of its own (none used with it, none its recording names): {t} stays in use"
            ));
        }
        Ok(())
    }

    /// Refuses to show camera `id` when that would drop the shown table's unsaved edits or
    /// replace tuned, unsaved parameters with the camera's own.
    fn refuse_losing_unsaved(&mut self, id: &CameraId, files: &CameraFiles) -> anyhow::Result<()> {
        if let Some(t) = &files.lut
            && self.dirty
            && self.table_path() != Some(t.as_path())
        {
            anyhow::bail!(
                "the table shown has unsaved edits: save them (or discard them) before showing camera {}, which uses {}",
                id.topic(),
                crate::frame::display_name(t)
            );
        }
        let own_params = self.camera_params(id, files);
        anyhow::ensure!(
            !self.params_modified()
                || own_params
                    .is_none_or(|p| self.params_slot().path.as_deref() == Some(p.as_path())),
            "the recognition parameters were tuned and not saved: save them (or reset them) before showing camera {}, which has parameters of its own",
            id.topic()
        );
        Ok(())
    }

    /// The label of the source shown (a recording's file name, a robot's name).
    fn source_label(&self) -> String {
        let Some(src) = &self.source else {
            return String::new();
        };
        match (src.robot_frames(), src.paths().first()) {
            (Some(r), _) => r.name(),
            (None, Some(p)) => crate::frame::display_name(p),
            (None, None) => src.label(),
        }
    }

    /// Chooses the camera (image topic) recordings open on from now (`eotn open --camera`);
    /// `None`: each recording's first.
    pub fn set_camera_choice(&mut self, topic: Option<String>) {
        self.open_topic = topic;
    }

    /// The cameras of the open recording or shown robot (the picker's list) and the one shown.
    #[must_use]
    pub fn cameras(&self) -> (Vec<CameraId>, Option<CameraId>) {
        self.source
            .as_ref()
            .map_or((Vec::new(), None), |s| (s.camera_ids(), s.camera_id()))
    }
}

#[cfg(test)]
pub(super) mod tests {
    use crate::camera::{CameraFiles, CameraId};
    use crate::frame::{Frame, Yuv};
    use crate::lut::{ColourClass, LookupTable};
    use crate::streams::{FrameRecord, StreamInfo, StreamWriter};
    use crate::workspace::{Command, Settings, Workspace};

    /// A recording with `/camera/image` (8×4) and `/camera/bottom` (4×2), the bottom camera
    /// naming `bottom.lut`; tables `top.lut` and `bottom.lut` beside it.
    fn recording(dir: &std::path::Path) -> std::path::PathBuf {
        let p = dir.join("two.mcap");
        let mut w = StreamWriter::create(&p, &StreamInfo::default()).unwrap();
        w.name_camera_files(
            "/camera/bottom",
            &CameraFiles {
                lut: Some("bottom.lut".into()),
                params: Some("bottom.json".into()),
                ..CameraFiles::default()
            },
        )
        .unwrap();
        for i in 0..4u64 {
            let top = FrameRecord::new(
                i * 40,
                Frame::filled_uyvy(8, 4, Yuv::new(50, 1, 2)).unwrap(),
            );
            w.write_camera("/camera/image", &top, None).unwrap();
            let bottom = FrameRecord::new(
                i * 40 + 5,
                Frame::filled_uyvy(4, 2, Yuv::new(90, 1, 2)).unwrap(),
            );
            w.write_camera("/camera/bottom", &bottom, None).unwrap();
        }
        w.finish().unwrap();
        for (name, class) in [
            ("top.lut", ColourClass::Orange),
            ("bottom.lut", ColourClass::Green),
        ] {
            let mut t = LookupTable::new(6).unwrap();
            for y in [50, 90] {
                let i = t.index(Yuv::new(y, 1, 2));
                t.set(i, class);
            }
            t.save(&dir.join(name)).unwrap();
        }
        std::fs::write(dir.join("bottom.json"), BOTTOM_PARAMS).unwrap();
        p
    }

    /// Camera `topic` of the source `ws` shows (of a recording that is not there when it shows
    /// none).
    pub(in crate::workspace) fn cam(ws: &Workspace, topic: &str) -> CameraId {
        ws.cameras().0.first().map_or_else(
            || CameraId::recording(std::path::Path::new("/nowhere.mcap"), topic),
            |c| c.with_topic(topic),
        )
    }

    /// Cameras `topics` of the source `ws` shows.
    pub(in crate::workspace) fn cams(ws: &Workspace, topics: &[&str]) -> Vec<CameraId> {
        topics.iter().map(|t| cam(ws, t)).collect()
    }

    /// The image topic of the camera shown.
    pub(in crate::workspace) fn shown(ws: &Workspace) -> Option<String> {
        ws.cameras().1.map(|c| c.topic().to_owned())
    }

    /// The bottom camera's own recognition parameters (a ball of at least 77 pixels).
    const BOTTOM_PARAMS: &str = r#"{"ball": {"min_pixels": 77}}"#;

    #[test]
    fn a_recording_opened_on_a_camera_gets_that_camera_s_table_and_parameters() {
        let dir = tempfile::tempdir().unwrap();
        let rec = recording(dir.path());
        let mut ws = Workspace::new(Settings::default());
        ws.set_camera_choice(Some("/camera/bottom".into()));
        ws.apply(Command::Open(vec![rec.clone()])).unwrap();
        assert_eq!(shown(&ws), Some("/camera/bottom".to_owned()));
        let table = ws.table_path().map(crate::frame::display_name);
        assert_eq!(table.as_deref(), Some("bottom.lut"));
        assert_eq!(ws.recognition_params().ball.min_pixels, 77, "its own set");
        // Parameters given with the recording win over the camera's own.
        let given = dir.path().join("given.json");
        std::fs::write(&given, r#"{"ball": {"min_pixels": 44}}"#).unwrap();
        ws.apply(Command::Open(vec![rec, given])).unwrap();
        assert_eq!(ws.recognition_params().ball.min_pixels, 44);
    }

    #[test]
    fn a_recording_s_camera_never_takes_another_recording_s_table() {
        // Every one-camera stream eotn writes has the topic /camera/image: a topic alone names
        // no camera, and a robot stream's table must never reach an overhead stream.
        let repo = |p: &str| std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(p);
        let (robot_a, robot_c) = (
            repo("streams/sim-walk-and-pan.mcap"),
            repo("streams/sim-goalkeeper.mcap"),
        );
        let overhead_b = repo("streams/sim-overhead-game.mcap");
        let dir = tempfile::tempdir().unwrap();
        let (x, y) = (dir.path().join("x.lut"), dir.path().join("y.lut"));
        for (p, class) in [(&x, ColourClass::Orange), (&y, ColourClass::Green)] {
            let mut t = LookupTable::new(6).unwrap();
            t.set(0, class);
            t.save(p).unwrap();
        }
        let name = |ws: &Workspace| ws.table_path().map(crate::frame::display_name);
        let mut ws = Workspace::new(Settings::default());
        ws.apply(Command::Open(vec![robot_a.clone(), x.clone()]))
            .unwrap();
        ws.apply(Command::Open(vec![overhead_b])).unwrap();
        assert_eq!(ws.camera_kind(), crate::sources::CameraKind::Overhead);
        // The overhead stream's sidecar names its own table: that one, never the robot's x.lut.
        assert_eq!(
            name(&ws).as_deref(),
            Some("sim-overhead.lut"),
            "not the robot stream's x.lut"
        );
        ws.apply(Command::Open(vec![robot_c.clone(), y])).unwrap();
        ws.apply(Command::Open(vec![robot_a])).unwrap();
        assert_eq!(name(&ws).as_deref(), Some("x.lut"), "its own, not C's");
        ws.apply(Command::Open(vec![robot_c])).unwrap();
        assert_eq!(name(&ws).as_deref(), Some("y.lut"));
    }

    #[test]
    fn a_camera_without_a_table_of_its_own_keeps_the_one_shown_and_says_so() {
        let dir = tempfile::tempdir().unwrap();
        let rec = dir.path().join("unnamed.mcap");
        let mut w = StreamWriter::create(&rec, &StreamInfo::default()).unwrap();
        for (i, topic) in ["/camera/image", "/camera/bottom"].into_iter().enumerate() {
            let f = FrameRecord::new(
                i as u64,
                Frame::filled_uyvy(4, 2, Yuv::new(50, 1, 2)).unwrap(),
            );
            w.write_camera(topic, &f, None).unwrap();
        }
        w.finish().unwrap();
        let top = dir.path().join("top.lut");
        LookupTable::new(6).unwrap().save(&top).unwrap();
        let mut ws = Workspace::new(Settings::default());
        ws.apply(Command::Open(vec![rec, top])).unwrap();
        ws.apply(Command::OpenCamera(Some(cam(&ws, "/camera/bottom"))))
            .unwrap();
        assert_eq!(shown(&ws), Some("/camera/bottom".to_owned()));
        let table = ws.table_path().map(crate::frame::display_name);
        assert_eq!(table.as_deref(), Some("top.lut"), "kept");
        let said = "camera /camera/bottom has no table of its own (none used with it, none its recording names): top.lut stays in use";
        assert!(
            ws.warnings().iter().any(|w| w == said),
            "{:?}",
            ws.warnings()
        );
    }

    #[test]
    fn each_camera_opens_with_its_own_parameters_remembered_per_camera() {
        let dir = tempfile::tempdir().unwrap();
        let rec = recording(dir.path());
        let mut ws = Workspace::new(Settings::default());
        ws.run(Command::Open(vec![rec, dir.path().join("top.lut")]));
        let top_min = ws.recognition_params().ball.min_pixels;
        assert_ne!(top_min, 77, "the top camera keeps the defaults");
        ws.apply(Command::OpenCamera(Some(cam(&ws, "/camera/bottom"))))
            .unwrap();
        assert_eq!(ws.recognition_params().ball.min_pixels, 77, "its own set");
        let slot = ws
            .params_slot()
            .path
            .as_deref()
            .map(crate::frame::display_name);
        assert_eq!(slot.as_deref(), Some("bottom.json"));
        // Parameters opened for a camera are remembered for it, and only for it.
        let other = dir.path().join("other.json");
        std::fs::write(&other, r#"{"ball": {"min_pixels": 55}}"#).unwrap();
        ws.apply(crate::workspace::ParamsCommand::OpenParams(other).into())
            .unwrap();
        let bottom = &ws.settings.cameras[&cam(&ws, "/camera/bottom")];
        assert!(
            bottom
                .params
                .as_deref()
                .is_some_and(|p| p.ends_with("other.json")),
            "{bottom:?}"
        );
        ws.apply(Command::OpenCamera(Some(cam(&ws, "/camera/image"))))
            .unwrap();
        ws.apply(Command::OpenCamera(Some(cam(&ws, "/camera/bottom"))))
            .unwrap();
        assert_eq!(
            ws.recognition_params().ball.min_pixels,
            55,
            "the remembered set overrides the recording's"
        );
    }

    #[test]
    fn tuned_unsaved_parameters_are_not_replaced_by_another_camera_s() {
        let dir = tempfile::tempdir().unwrap();
        let rec = recording(dir.path());
        let mut ws = Workspace::new(Settings::default());
        ws.run(Command::Open(vec![rec, dir.path().join("top.lut")]));
        let tune = crate::workspace::ParamsCommand::SetParamValue {
            pointer: "/ball/min_pixels".into(),
            value: serde_json::json!(33),
        };
        ws.apply(tune.into()).unwrap();
        let e = ws.apply(Command::OpenCamera(Some(cam(&ws, "/camera/bottom"))));
        let text = format!("{:#}", e.unwrap_err());
        assert!(text.contains("not saved"), "{text}");
        assert_eq!(shown(&ws), Some("/camera/image".to_owned()), "still shown");
        assert_eq!(ws.recognition_params().ball.min_pixels, 33, "kept");
    }

    #[test]
    fn each_camera_opens_with_its_own_table() {
        let dir = tempfile::tempdir().unwrap();
        let rec = recording(dir.path());
        let mut ws = Workspace::new(Settings::default());
        ws.run(Command::Open(vec![rec.clone(), dir.path().join("top.lut")]));
        assert_eq!(shown(&ws), Some("/camera/image".to_owned()));
        assert_eq!(
            ws.cameras().0,
            cams(&ws, &["/camera/image", "/camera/bottom"])
        );
        ws.run(crate::workspace::PlaybackCommand::Seek(2).into());
        ws.run(Command::OpenCamera(Some(cam(&ws, "/camera/bottom"))));
        assert_eq!(shown(&ws), Some("/camera/bottom".to_owned()));
        assert_eq!(ws.index(), 2, "the frame nearest the time shown");
        let table = ws.table_path().map(crate::frame::display_name);
        assert_eq!(
            table.as_deref(),
            Some("bottom.lut"),
            "the table the recording names"
        );
        ws.run(Command::OpenTable(dir.path().join("top.lut")));
        assert_eq!(
            ws.settings.cameras[&cam(&ws, "/camera/bottom")]
                .lut
                .as_deref()
                .map(crate::frame::display_name)
                .as_deref(),
            Some("top.lut"),
            "remembered for this camera"
        );
        let e = ws.apply(Command::OpenCamera(Some(cam(&ws, "/camera/side"))));
        let text = format!("{:#}", e.unwrap_err());
        assert!(text.contains("/camera/image, /camera/bottom"), "{text}");
        assert_eq!(shown(&ws), Some("/camera/bottom".to_owned()), "still shown");
    }

    #[test]
    fn another_camera_s_table_never_drops_unsaved_edits() {
        use crate::workspace::TableCommand;
        let dir = tempfile::tempdir().unwrap();
        let rec = recording(dir.path());
        let mut ws = Workspace::new(Settings::default());
        ws.run(Command::Open(vec![rec, dir.path().join("top.lut")]));
        ws.apply(TableCommand::SetClass(ColourClass::White).into())
            .unwrap();
        ws.apply(TableCommand::Sample { x: 1, y: 1 }.into())
            .unwrap();
        ws.apply(TableCommand::Commit.into()).unwrap();
        let edited = ws.pipeline.lut().clone();
        let e = ws.apply(Command::OpenCamera(Some(cam(&ws, "/camera/bottom"))));
        let text = format!("{:#}", e.unwrap_err());
        assert!(text.contains("unsaved edits"), "{text}");
        assert!(text.contains("bottom.lut"), "{text}");
        assert_eq!(shown(&ws), Some("/camera/image".to_owned()), "still shown");
        assert_eq!(ws.pipeline.lut(), &edited, "the edits kept");
        // Saved, the camera opens with its own table.
        ws.apply(TableCommand::SaveTable.into()).unwrap();
        ws.run(Command::OpenCamera(Some(cam(&ws, "/camera/bottom"))));
        assert_eq!(shown(&ws), Some("/camera/bottom".to_owned()));
    }
}
