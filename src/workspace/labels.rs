//! Boxed labels over the open frames (issue 29 item 2): a label set as teams keep it (YOLO
//! folder, COCO JSON, Pascal VOC folder; `crate::eval::label_sets`) opened beside a folder of
//! frames or a stream. Its boxes are drawn over each frame by class, recognition is scored
//! against them frame by frame as `eotn eval --labels` scores it (`crate::eval::ball_boxes`, a
//! few frames per UI frame), the missed and false frames become events to step between, and the
//! report's figures are shown by the Events and bookmarks window. The scoring follows the table
//! and parameters in use: an edit, an undo or a changed parameter starts it again, so the
//! figures answer "what did that click do?" while a table is made. A split
//! ([`Split::Tuning`] or [`Split::HeldOut`]) scores only its frames. No egui here.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use anyhow::Context as _;

use super::Workspace;
use super::bookmarks::{Event, EventKind};
use super::source::Source;
use crate::eval::ball_boxes::{BoxFrameEval, BoxReport, BoxScoring, evaluate_box_frame};
use crate::eval::label_sets::{FrameBoxes, LabelSet, ReadOptions, Split, file_stem};
use crate::lut::LookupTable;
use crate::pipeline::{Pipeline, PipelineParams};

/// A label set opened over the source, and its scoring so far.
#[derive(Debug)]
pub struct OpenLabels {
    /// The label set's file or folder.
    pub path: PathBuf,
    set: LabelSet,
    /// The label set's name of each source frame (its file's stem, or its index).
    names: Vec<String>,
    /// Which frames are scored.
    split: Split,
    /// The table and parameters scored with: a copy of the workspace's, renewed when they change.
    pipeline: Pipeline,
    /// The workspace's table generation the copy was taken at.
    table_generation: u64,
    /// Next frame to score.
    next: usize,
    /// Scored frames: source index and how it went, in frame order.
    scored: Vec<(usize, BoxFrameEval)>,
}

impl OpenLabels {
    /// The labels of a source: each frame matched by its file's stem (a stream's frames by
    /// index, written with or without leading zeros).
    fn new(
        path: &Path,
        set: LabelSet,
        src: &Source,
        lut: &LookupTable,
        params: PipelineParams,
        table_generation: u64,
    ) -> Self {
        let files = src.paths();
        let names = (0..src.len())
            .map(|i| match files.get(i) {
                Some(p) if files.len() == src.len() => file_stem(p),
                _ => i.to_string(),
            })
            .collect();
        Self {
            path: path.to_owned(),
            set,
            names,
            split: Split::All,
            pipeline: Pipeline::new(lut.clone(), params),
            table_generation,
            next: 0,
            scored: Vec::new(),
        }
    }

    /// Which frames are scored.
    #[must_use]
    pub const fn split(&self) -> Split {
        self.split
    }

    /// Scores again from the first frame, with `lut` and `params` when given.
    fn restart(&mut self, with: Option<(&LookupTable, PipelineParams, u64)>) {
        if let Some((lut, params, generation)) = with {
            self.pipeline.set_lut(lut.clone());
            self.pipeline.set_params(params);
            self.table_generation = generation;
        }
        self.next = 0;
        self.scored.clear();
    }

    /// The set's key of source frame `index`, if that frame is labelled and in the split.
    fn key(&self, index: usize) -> Option<String> {
        self.labelled_key(index).filter(|k| self.split.takes(k))
    }

    /// The set's key of source frame `index`, if that frame is labelled (whatever the split).
    fn labelled_key(&self, index: usize) -> Option<String> {
        let name = self.names.get(index)?;
        if self.set.frames.contains_key(name) {
            return Some(name.clone());
        }
        let n: usize = name.parse().ok()?;
        self.set
            .frames
            .keys()
            .find(|k| k.parse::<usize>().ok() == Some(n))
            .cloned()
    }

    /// The boxes of frame `index` in pixels of a `width` × `height` image; `None` when the
    /// frame is not labelled.
    #[must_use]
    pub fn boxes(&self, index: usize, width: usize, height: usize) -> Option<FrameBoxes> {
        self.set
            .frame_in_pixels(&self.labelled_key(index)?, width, height)
    }

    /// True when every frame was scored.
    #[must_use]
    pub fn done(&self) -> bool {
        self.next >= self.names.len()
    }

    /// Frames scored so far, of the source's frames.
    #[must_use]
    pub fn progress(&self) -> (usize, usize) {
        (self.next.min(self.names.len()), self.names.len())
    }

    /// The sums over the frames scored so far (as `eotn eval --labels` reports them).
    #[must_use]
    pub fn report(&self) -> BoxReport {
        let frames: Vec<BoxFrameEval> = self.scored.iter().map(|(_, f)| f.clone()).collect();
        BoxReport::from_frames(&frames)
    }

    /// How frame `index` went, once scored.
    #[must_use]
    pub fn frame_eval(&self, index: usize) -> Option<&BoxFrameEval> {
        self.scored
            .iter()
            .find(|(i, _)| *i == index)
            .map(|(_, f)| f)
    }

    /// The missed frames (an eligible ball not found) and the false ones (a ball reported
    /// outside every ball box) as events.
    #[must_use]
    pub fn events(&self) -> Vec<Event> {
        let mut out = Vec::new();
        for (i, f) in &self.scored {
            if f.missed() {
                out.push(Event {
                    frame: *i,
                    kind: EventKind::LabelMissed,
                    detail: format!("{}: labelled ball not found", f.name),
                });
            }
            if let Some(place) = f.false_place {
                out.push(Event {
                    frame: *i,
                    kind: EventKind::LabelFalse,
                    detail: format!("{}: false ball ({place:?})", f.name),
                });
            }
        }
        out
    }

    /// Scores frames of `src` for up to `budget` of wall time (at least one frame a call).
    fn scan(&mut self, src: &mut Source, budget: Duration) -> Vec<String> {
        let start = Instant::now();
        let mut warnings = Vec::new();
        let mut first = true;
        let scoring = BoxScoring::default();
        while !self.done() && (first || start.elapsed() < budget) {
            first = false;
            let i = self.next;
            self.next += 1;
            let Some(key) = self.key(i) else {
                continue;
            };
            match src.read_uncached(i) {
                Ok(f) => {
                    let (w, h) = (f.frame.width(), f.frame.height());
                    let Some(labels) = self.set.frame_in_pixels(&key, w, h) else {
                        continue;
                    };
                    if labels.size.is_some_and(|s| s != (w, h)) {
                        warnings.push(format!(
                            "{}: frame {key} is labelled for another image size; not scored",
                            self.path.display()
                        ));
                        continue;
                    }
                    let r = self.pipeline.process(&f.frame, f.sensors.as_ref());
                    let eval = evaluate_box_frame(&key, r.recognition, &labels, &scoring);
                    self.scored.push((i, eval));
                }
                Err(e) => warnings.push(format!("frame {i}: {e}")),
            }
        }
        warnings
    }
}

impl Workspace {
    /// Opens a label set over the open source and starts scoring it.
    pub(super) fn open_labels(&mut self, path: &Path) -> anyhow::Result<()> {
        let src = self
            .source
            .as_ref()
            .context("open the frames first, then their labels")?;
        let set = LabelSet::load(path, &ReadOptions::default())?;
        let warnings = set.warnings.clone();
        let labels = OpenLabels::new(
            path,
            set,
            src,
            self.pipeline.lut(),
            *self.pipeline.params(),
            self.table_generation,
        );
        let labelled = (0..src.len()).filter(|&i| labels.key(i).is_some()).count();
        anyhow::ensure!(
            labelled > 0,
            "{}: no frame of {} is labelled there",
            path.display(),
            src.label()
        );
        self.status = format!(
            "opened labels {}: {labelled} of {} frames labelled",
            path.display(),
            src.len()
        );
        for w in warnings {
            self.warn(w);
        }
        self.labels = Some(labels);
        self.settings.show_bookmarks = true;
        Ok(())
    }

    /// Scores only the frames of `split` (the held-out frames, numbers ending in 7, 8 or 9, or
    /// the others), from the first frame again.
    pub(super) fn set_labels_split(&mut self, split: Split) -> anyhow::Result<()> {
        let labels = self.labels.as_mut().context("no labels open")?;
        labels.split = split;
        labels.restart(None);
        let n = (0..labels.names.len())
            .filter(|&i| labels.key(i).is_some())
            .count();
        self.status = format!("labels: scoring {n} labelled frames ({split:?})");
        Ok(())
    }

    /// Advances the label scoring (called from [`Workspace::tick`]), first starting it again
    /// when the table or the parameters changed since it began.
    pub(super) fn tick_labels(&mut self) {
        let (Some(src), Some(labels)) = (self.source.as_mut(), self.labels.as_mut()) else {
            return;
        };
        if labels.table_generation != self.table_generation
            || labels.pipeline.params() != self.pipeline.params()
        {
            labels.restart(Some((
                self.pipeline.lut(),
                *self.pipeline.params(),
                self.table_generation,
            )));
        }
        if labels.done() {
            return;
        }
        for w in labels.scan(src, super::SCAN_BUDGET) {
            self.warn(w);
        }
    }

    /// The label set opened over the source, with its scoring so far.
    #[must_use]
    pub const fn labels(&self) -> Option<&OpenLabels> {
        self.labels.as_ref()
    }

    /// The shown frame's labelled boxes, in pixels.
    #[must_use]
    pub fn shown_label_boxes(&self) -> Option<FrameBoxes> {
        let labels = self.labels.as_ref()?;
        let frame = self.frame()?;
        labels.boxes(self.index, frame.width(), frame.height())
    }
}

#[cfg(test)]
mod tests_support {
    use std::path::Path;

    use crate::frame::save_rgb_png;

    pub const W: usize = 96;
    pub const H: usize = 72;

    /// Green carpet, with an orange disc of radius 6 px at (cx, cy) when given.
    pub fn frame(path: &Path, ball: Option<(f64, f64)>) {
        let mut rgb = Vec::with_capacity(W * H * 3);
        for i in 0..W * H {
            let (x, y) = ((i % W) as f64 + 0.5, (i / W) as f64 + 0.5);
            let px = match ball {
                Some((cx, cy)) if (x - cx).hypot(y - cy) <= 6.0 => [250, 110, 20],
                _ => [45, 140, 60],
            };
            rgb.extend_from_slice(&px);
        }
        save_rgb_png(path, W, H, &rgb).unwrap();
    }
}

#[cfg(test)]
mod tests {
    use std::time::Duration;

    use super::*;
    use crate::lut::{ColourClass, Sensitivity};
    use crate::workspace::{Command, HintsCommand, TableCommand};

    use super::tests_support::{H, W, frame};

    #[test]
    fn labels_over_frames_draw_score_and_mark_missed_and_false_frames() {
        let dir = tempfile::tempdir().unwrap();
        let frames = dir.path().join("frames");
        let labels = dir.path().join("labels");
        std::fs::create_dir_all(&frames).unwrap();
        std::fs::create_dir_all(&labels).unwrap();
        // 00: a ball, labelled; 01: a ball labelled where there is none (missed); 02: an
        // unlabelled ball (false), with a robot box elsewhere.
        frame(&frames.join("00.png"), Some((48.0, 40.0)));
        frame(&frames.join("01.png"), None);
        frame(&frames.join("02.png"), Some((30.0, 30.0)));
        let yolo =
            |cx: f64, cy: f64, s: f64| format!("{cx} {cy} {} {}", s / W as f64, s / H as f64);
        std::fs::write(labels.join("classes.txt"), "robot\nball\ngoal\n").unwrap();
        std::fs::write(
            labels.join("00.txt"),
            format!("1 {}\n", yolo(0.5, 40.0 / 72.0, 12.0)),
        )
        .unwrap();
        std::fs::write(
            labels.join("01.txt"),
            format!("1 {}\n", yolo(0.5, 0.5, 12.0)),
        )
        .unwrap();
        std::fs::write(
            labels.join("02.txt"),
            format!("0 {}\n", yolo(0.8, 0.3, 20.0)),
        )
        .unwrap();

        let mut ws = Workspace::default();
        // Labels need frames first.
        assert!(ws.apply(Command::OpenLabels(labels.clone())).is_err());
        ws.apply(Command::Open(vec![frames])).unwrap();
        ws.apply(TableCommand::NewTable(6).into()).unwrap();
        ws.apply(TableCommand::SetSensitivity(Sensitivity::uniform(1)).into())
            .unwrap();
        for (class, x, y) in [(ColourClass::Green, 5, 5), (ColourClass::Orange, 48, 40)] {
            ws.apply(TableCommand::SetClass(class).into()).unwrap();
            ws.apply(TableCommand::Sample { x, y }.into()).unwrap();
            ws.apply(TableCommand::Commit.into()).unwrap();
        }
        ws.apply(Command::OpenLabels(labels)).unwrap();
        for _ in 0..100 {
            if ws.labels().is_some_and(OpenLabels::done) {
                break;
            }
            ws.tick(Duration::ZERO);
        }
        let opened = ws.labels().expect("labels open");
        assert!(opened.done());
        let r = opened.report();
        assert_eq!((r.frames, r.eligible, r.found), (3, 2, 1));
        assert_eq!((r.reported, r.correct, r.false_in_robot), (2, 1, 0));
        assert_eq!(r.missed_frames, vec!["01".to_owned()]);
        assert_eq!(r.false_frames, vec!["02".to_owned()]);
        // The shown frame's boxes, in pixels, for the overlay.
        let boxes = ws.shown_label_boxes().expect("frame 0 is labelled");
        assert_eq!(boxes.boxes.len(), 1);
        assert!(
            (boxes.boxes[0].min_x - 42.0).abs() < 1e-6,
            "{:?}",
            boxes.boxes[0]
        );
        // The missed and false frames are events to step between.
        let kinds: Vec<(usize, EventKind)> =
            ws.events().iter().map(|e| (e.frame, e.kind)).collect();
        assert_eq!(
            kinds,
            vec![(1, EventKind::LabelMissed), (2, EventKind::LabelFalse)]
        );
        ws.apply(HintsCommand::JumpToMark { forward: true }.into())
            .unwrap();
        assert_eq!(ws.index(), 1);
        ws.apply(HintsCommand::JumpToMark { forward: true }.into())
            .unwrap();
        assert_eq!(ws.index(), 2);
        assert!(
            ws.apply(HintsCommand::JumpToMark { forward: true }.into())
                .is_err()
        );
    }
}

#[cfg(test)]
mod follow_tests {
    use std::time::Duration;

    use super::tests_support::frame;
    use super::*;
    use crate::lut::{ColourClass, Sensitivity};
    use crate::workspace::{Command, ParamsCommand, TableCommand};

    fn score_all(ws: &mut Workspace) -> BoxReport {
        for _ in 0..100 {
            ws.tick(Duration::ZERO);
            if ws.labels().is_some_and(OpenLabels::done) {
                break;
            }
        }
        let labels = ws.labels().expect("labels open");
        assert!(labels.done());
        labels.report()
    }

    /// The scoring follows the table and the parameters in use (not a copy taken at open),
    /// and scores only the chosen split.
    #[test]
    fn labels_are_scored_again_after_an_edit_an_undo_or_a_parameter_and_by_split() {
        let dir = tempfile::tempdir().unwrap();
        let frames = dir.path().join("frames");
        let labels = dir.path().join("labels");
        std::fs::create_dir_all(&frames).unwrap();
        std::fs::create_dir_all(&labels).unwrap();
        std::fs::write(labels.join("classes.txt"), "robot\nball\ngoal\n").unwrap();
        // A ball on every frame, labelled; 17 is a held-out frame (its number ends in 7).
        for name in ["10", "11", "17"] {
            frame(&frames.join(format!("{name}.png")), Some((48.0, 36.0)));
            std::fs::write(
                labels.join(format!("{name}.txt")),
                "1 0.5 0.5 0.125 0.1666667\n",
            )
            .unwrap();
        }
        let mut ws = Workspace::default();
        ws.apply(Command::Open(vec![frames])).unwrap();
        ws.apply(TableCommand::NewTable(6).into()).unwrap();
        ws.apply(TableCommand::SetSensitivity(Sensitivity::uniform(1)).into())
            .unwrap();
        ws.apply(TableCommand::SetClass(ColourClass::Green).into())
            .unwrap();
        ws.apply(TableCommand::Sample { x: 5, y: 5 }.into())
            .unwrap();
        ws.apply(TableCommand::Commit.into()).unwrap();
        // Opened before the orange is classified: nothing is found.
        ws.apply(Command::OpenLabels(labels)).unwrap();
        let r = score_all(&mut ws);
        assert_eq!((r.eligible, r.found), (3, 0));
        // The orange click is scored at once.
        ws.apply(TableCommand::SetClass(ColourClass::Orange).into())
            .unwrap();
        ws.apply(TableCommand::Sample { x: 48, y: 36 }.into())
            .unwrap();
        ws.apply(TableCommand::Commit.into()).unwrap();
        let r = score_all(&mut ws);
        assert_eq!((r.eligible, r.found, r.reported), (3, 3, 3));
        // A parameter that drops every candidate (min_pixels above the ball's), then back.
        ws.apply(
            ParamsCommand::SetParamValue {
                pointer: "/ball/min_pixels".to_owned(),
                value: serde_json::json!(1000),
            }
            .into(),
        )
        .unwrap();
        assert_eq!(score_all(&mut ws).found, 0);
        ws.apply(ParamsCommand::ResetParams.into()).unwrap();
        assert_eq!(score_all(&mut ws).found, 3);
        // The split: held-out frames only, then the tuning frames.
        ws.apply(Command::SetLabelsSplit(Split::HeldOut)).unwrap();
        let r = score_all(&mut ws);
        assert_eq!((r.frames, r.eligible, r.found), (1, 1, 1));
        ws.apply(Command::SetLabelsSplit(Split::Tuning)).unwrap();
        assert_eq!(score_all(&mut ws).eligible, 2);
        // An undo is scored too.
        ws.apply(TableCommand::Undo.into()).unwrap();
        let r = score_all(&mut ws);
        assert_eq!((r.eligible, r.found), (2, 0));
        // Boxes are drawn on every labelled frame, whatever the split.
        ws.apply(crate::workspace::PlaybackCommand::Seek(2).into())
            .unwrap();
        assert!(ws.shown_label_boxes().is_some());
    }
}
