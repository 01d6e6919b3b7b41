//! Several cameras of one recording: which camera is shown (`Command::OpenCamera`, the camera
//! picker), and each camera's own table — remembered per camera in the settings, else the one
//! the recording names for it (its `REC.cameras.json` sidecar, else its `eotn.camera`
//! metadata: [`crate::camera::files_for`]).

use std::path::{Path, PathBuf};

use super::Workspace;
use super::source::Source;
use crate::camera::{CameraFiles, CameraId};

impl Workspace {
    /// The camera shown, as settings remember it: the recording's image topic.
    pub(super) fn camera_id(&self) -> Option<CameraId> {
        self.source
            .as_ref()
            .and_then(Source::camera)
            .map(CameraId::recording)
    }

    /// The camera chosen for recordings (`eotn open --camera`, the camera picker).
    pub(super) fn camera_for(&self, _recording: &Path) -> Option<String> {
        self.camera.clone()
    }

    /// The files of the camera `topic` of `recording`: each the one last used with this camera
    /// (a table only while its file is still there), else the one the recording names for it
    /// (its sidecar, its `eotn.camera` metadata, its parameter set).
    pub(super) fn camera_files(&mut self, recording: &Path, topic: Option<&str>) -> CameraFiles {
        let Some(topic) = topic else {
            return CameraFiles::default();
        };
        let mut remembered = self
            .settings
            .cameras
            .get(&CameraId::recording(topic))
            .cloned()
            .unwrap_or_default();
        remembered.lut = remembered.lut.filter(|p| p.is_file());
        let named = crate::streams::StreamReader::open_camera(recording, Some(topic))
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

    /// The table of the camera `topic` of `recording` ([`Workspace::camera_files`]).
    pub(super) fn camera_table(
        &mut self,
        recording: &Path,
        topic: Option<&str>,
    ) -> Option<PathBuf> {
        self.camera_files(recording, topic).lut
    }

    /// The camera's own parameters file, when it names one that is there (a name not found is
    /// said once, and the parameters in use stay).
    pub(super) fn camera_params(
        &mut self,
        recording: &Path,
        files: &CameraFiles,
    ) -> Option<PathBuf> {
        let name = files.params.as_deref()?;
        let found = super::params::named_param_file(name, recording).filter(|p| p.is_file());
        if found.is_none() {
            self.warn(format!(
                "{}: the camera's parameter set {name} is not found (params/{name}.json beside the recording or above it): the parameters in use stay",
                recording.display()
            ));
        }
        found
    }

    /// After a camera was shown: its own parameters and, for an overhead camera, its
    /// calibration, when it has them; said in the status line.
    fn open_camera_files(&mut self, recording: &Path, files: &CameraFiles) -> anyhow::Result<()> {
        if let Some(p) = self.camera_params(recording, files)
            && self.params_slot().path.as_deref() != Some(p.as_path())
        {
            self.open_params(&p)?;
        }
        if let Some(c) = &files.calibration
            && self.overhead.calibration_path() != Some(c.as_path())
            && self.camera_kind() == crate::sources::CameraKind::Overhead
        {
            self.apply(super::OverheadCommand::OpenCalibration(c.clone()).into())?;
        }
        Ok(())
    }

    /// Shows the camera `topic` of the open recording (`None`: its first), at the frame nearest
    /// the time shown, with that camera's table.
    pub(super) fn open_camera(&mut self, topic: Option<String>) -> anyhow::Result<()> {
        if let Some(t) = &topic
            && self.camera_panes().iter().any(|p| p.topic == t)
        {
            // A camera shown side by side is focused, its neighbours kept.
            return self.focus_camera(t);
        }
        let Some(src) = self.source.as_ref() else {
            anyhow::bail!("no recording is open");
        };
        let Some(path) = src.paths().into_iter().next().filter(|_| src.is_stream()) else {
            anyhow::bail!("the source is not a recording: it has no cameras to choose");
        };
        let time = src.time_ns(self.index);
        let source = Source::stream_camera(&path, topic.as_deref())?;
        let shown = source.camera().map(str::to_owned);
        let index = source.index_at_time(time);
        let files = self.camera_files(&path, shown.as_deref());
        let own_table = files.lut.clone();
        if let Some(t) = &own_table
            && self.dirty
            && self.table_path() != Some(t.as_path())
        {
            // Opening the camera's own table would drop the shown table's edits.
            anyhow::bail!(
                "the table shown has unsaved edits: save them (or discard them) before showing camera {}, which uses {}",
                shown.as_deref().unwrap_or("?"),
                crate::frame::display_name(t)
            );
        }
        anyhow::ensure!(
            !self.params_modified()
                || self
                    .camera_params(&path, &files)
                    .is_none_or(|p| { self.params_slot().path.as_deref() == Some(p.as_path()) }),
            "the recognition parameters were tuned and not saved: save them (or reset them) before showing camera {}, which has parameters of its own",
            shown.as_deref().unwrap_or("?")
        );
        self.set_source(source)?;
        self.camera = topic;
        if let Some(t) = &own_table {
            self.open_table(t)?;
        }
        self.open_camera_files(&path, &files)?;
        self.seek(index)?;
        let camera = shown.as_deref().unwrap_or("?");
        self.status = format!(
            "showing camera {camera} of {}",
            crate::frame::display_name(&path)
        );
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

    /// Chooses the camera (image topic) recordings open on from now (`eotn open --camera`);
    /// `None`: each recording's first.
    pub fn set_camera_choice(&mut self, topic: Option<String>) {
        self.camera = topic;
    }

    /// The cameras of the open recording (the picker's list) and the one shown.
    #[must_use]
    pub fn cameras(&self) -> (&[String], Option<&str>) {
        self.source
            .as_ref()
            .map_or((&[][..], None), |s| (s.cameras(), s.camera()))
    }
}

#[cfg(test)]
mod tests {
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

    /// The bottom camera's own recognition parameters (a ball of at least 77 pixels).
    const BOTTOM_PARAMS: &str = r#"{"ball": {"min_pixels": 77}}"#;

    #[test]
    fn each_camera_opens_with_its_own_parameters_remembered_per_camera() {
        let dir = tempfile::tempdir().unwrap();
        let rec = recording(dir.path());
        let mut ws = Workspace::new(Settings::default());
        ws.run(Command::Open(vec![rec, dir.path().join("top.lut")]));
        let top_min = ws.recognition_params().ball.min_pixels;
        assert_ne!(top_min, 77, "the top camera keeps the defaults");
        ws.apply(Command::OpenCamera(Some("/camera/bottom".into())))
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
        let bottom = &ws.settings.cameras[&CameraId::recording("/camera/bottom")];
        assert!(
            bottom
                .params
                .as_deref()
                .is_some_and(|p| p.ends_with("other.json")),
            "{bottom:?}"
        );
        ws.apply(Command::OpenCamera(Some("/camera/image".into())))
            .unwrap();
        ws.apply(Command::OpenCamera(Some("/camera/bottom".into())))
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
        let e = ws.apply(Command::OpenCamera(Some("/camera/bottom".into())));
        let text = format!("{:#}", e.unwrap_err());
        assert!(text.contains("not saved"), "{text}");
        assert_eq!(ws.cameras().1, Some("/camera/image"), "still shown");
        assert_eq!(ws.recognition_params().ball.min_pixels, 33, "kept");
    }

    #[test]
    fn each_camera_opens_with_its_own_table() {
        let dir = tempfile::tempdir().unwrap();
        let rec = recording(dir.path());
        let mut ws = Workspace::new(Settings::default());
        ws.run(Command::Open(vec![rec.clone(), dir.path().join("top.lut")]));
        assert_eq!(ws.cameras().1, Some("/camera/image"));
        assert_eq!(ws.cameras().0, ["/camera/image", "/camera/bottom"]);
        ws.run(crate::workspace::PlaybackCommand::Seek(2).into());
        ws.run(Command::OpenCamera(Some("/camera/bottom".into())));
        assert_eq!(ws.cameras().1, Some("/camera/bottom"));
        assert_eq!(ws.index(), 2, "the frame nearest the time shown");
        let shown = ws.table_path().map(crate::frame::display_name);
        assert_eq!(
            shown.as_deref(),
            Some("bottom.lut"),
            "the table the recording names"
        );
        ws.run(Command::OpenTable(dir.path().join("top.lut")));
        assert_eq!(
            ws.settings.cameras[&CameraId::recording("/camera/bottom")]
                .lut
                .as_deref()
                .map(crate::frame::display_name)
                .as_deref(),
            Some("top.lut"),
            "remembered for this camera"
        );
        let e = ws.apply(Command::OpenCamera(Some("/camera/side".into())));
        let text = format!("{:#}", e.unwrap_err());
        assert!(text.contains("/camera/image, /camera/bottom"), "{text}");
        assert_eq!(ws.cameras().1, Some("/camera/bottom"), "still shown");
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
        let e = ws.apply(Command::OpenCamera(Some("/camera/bottom".into())));
        let text = format!("{:#}", e.unwrap_err());
        assert!(text.contains("unsaved edits"), "{text}");
        assert!(text.contains("bottom.lut"), "{text}");
        assert_eq!(ws.cameras().1, Some("/camera/image"), "still shown");
        assert_eq!(ws.pipeline.lut(), &edited, "the edits kept");
        // Saved, the camera opens with its own table.
        ws.apply(TableCommand::SaveTable.into()).unwrap();
        ws.run(Command::OpenCamera(Some("/camera/bottom".into())));
        assert_eq!(ws.cameras().1, Some("/camera/bottom"));
    }
}
