//! Boxed labels over the open frames (issue 29 item 2): a label set as teams keep it (YOLO
//! folder, COCO JSON, Pascal VOC folder; `crate::eval::label_sets`) opened beside a folder of
//! frames or a stream. Its boxes are drawn over each frame by class, recognition is scored
//! against them frame by frame as `eotn eval --labels` scores it (`crate::eval::ball_boxes`, a
//! few frames per UI frame), the missed and false frames become events to step between, and the
//! report's figures are shown by the Events and bookmarks window. No egui here.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use anyhow::Context as _;

use super::Workspace;
use super::bookmarks::{Event, EventKind};
use super::source::Source;
use crate::eval::ball_boxes::{BoxFrameEval, BoxReport, BoxScoring, evaluate_box_frame};
use crate::eval::label_sets::{FrameBoxes, LabelSet, ReadOptions, file_stem};
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
    pipeline: Pipeline,
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
            pipeline: Pipeline::new(lut.clone(), params),
            next: 0,
            scored: Vec::new(),
        }
    }

    /// The set's key of source frame `index`, if that frame is labelled.
    fn key(&self, index: usize) -> Option<String> {
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
        self.set.frame_in_pixels(&self.key(index)?, width, height)
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
        let labels = OpenLabels::new(path, set, src, self.pipeline.lut(), *self.pipeline.params());
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

    /// Advances the label scoring (called from [`Workspace::tick`]).
    pub(super) fn tick_labels(&mut self) {
        let (Some(src), Some(labels)) = (self.source.as_mut(), self.labels.as_mut()) else {
            return;
        };
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
mod tests {
    use std::time::Duration;

    use super::*;
    use crate::frame::save_rgb_png;
    use crate::lut::{ColourClass, Sensitivity};
    use crate::workspace::{Command, HintsCommand, TableCommand};

    const W: usize = 96;
    const H: usize = 72;

    /// Green carpet, with an orange disc of radius 6 px at (cx, cy) when given.
    fn frame(path: &Path, ball: Option<(f64, f64)>) {
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
