//! "Where did something happen?": marks on the timeline. The pipeline's own events (ball found
//! or lost, a goal appears, a frame with a warning), found by a scan run a few frames per UI
//! frame, the frames a pending try-edit changes, and the user's own bookmarks with a note,
//! saved beside the stream as `STREAM.bookmarks.json` (atomically, at every change).

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use serde::{Deserialize, Serialize};

use super::source::Source;
use crate::lut::{ColourClass, LookupTable};
use crate::pipeline::{Pipeline, PipelineParams};

/// What happened at an event mark.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EventKind {
    /// A ball is reported where the frame before had none (or at the first frame).
    BallFound,
    /// No ball where the frame before had one.
    BallLost,
    /// A goal of this colour is reported where the frame before had none.
    GoalAppears(ColourClass),
    /// Reading the frame warned (NaN readings dropped, …) or failed.
    Warning,
    /// The pending try-edit changes this frame's blobs.
    TryEditChange,
    /// The opened labels have an eligible ball here that recognition did not find.
    LabelMissed,
    /// Recognition reports a ball here outside every labelled ball box.
    LabelFalse,
}

impl EventKind {
    /// A short name for lists and hover texts.
    #[must_use]
    pub fn describe(self) -> String {
        match self {
            Self::BallFound => "ball found".to_owned(),
            Self::BallLost => "ball lost".to_owned(),
            Self::GoalAppears(c) => format!("{} goal appears", c.name()),
            Self::Warning => "warning".to_owned(),
            Self::TryEditChange => "try-edit changes blobs".to_owned(),
            Self::LabelMissed => "labelled ball missed".to_owned(),
            Self::LabelFalse => "false ball".to_owned(),
        }
    }
}

/// One event mark.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Event {
    /// Frame index.
    pub frame: usize,
    /// What happened.
    pub kind: EventKind,
    /// Detail (the warning's text, the blob counts), may be empty.
    pub detail: String,
}

/// A bookmark the user set, with a note.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct UserBookmark {
    /// Frame index.
    pub frame: usize,
    /// The user's note (may be empty).
    #[serde(default)]
    pub note: String,
}

/// The bookmarks file beside a stream.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct BookmarkFile {
    /// Format version, 1.
    version: u32,
    /// Bookmarks by frame.
    bookmarks: Vec<UserBookmark>,
}

/// Where the bookmarks of a source are kept: beside its (first) file, `.bookmarks.json` appended.
#[must_use]
pub fn bookmarks_path(source_file: &Path) -> PathBuf {
    let mut name = source_file.as_os_str().to_owned();
    name.push(".bookmarks.json");
    PathBuf::from(name)
}

/// Reads a bookmarks file; a missing file is no bookmarks.
///
/// # Errors
/// The file cannot be read or is not a bookmarks file; the message names it.
pub fn load(path: &Path) -> anyhow::Result<Vec<UserBookmark>> {
    if !path.exists() {
        return Ok(Vec::new());
    }
    let text = crate::input_file::read_text_bounded(
        path,
        crate::input_file::MAX_SIDE_FILE_BYTES,
        "a bookmarks file",
    )
    .map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
    let file: BookmarkFile = serde_json::from_str(&text)
        .map_err(|e| anyhow::anyhow!("{}: not a bookmarks file ({e})", path.display()))?;
    anyhow::ensure!(
        file.version == 1,
        "{}: bookmarks version {} (this eotn reads 1)",
        path.display(),
        file.version
    );
    let mut marks = file.bookmarks;
    marks.sort_by_key(|b| b.frame);
    Ok(marks)
}

/// Writes a bookmarks file atomically.
///
/// # Errors
/// Writing fails; the message names the file.
pub fn save(path: &Path, bookmarks: &[UserBookmark]) -> anyhow::Result<()> {
    let file = BookmarkFile {
        version: 1,
        bookmarks: bookmarks.to_vec(),
    };
    let mut text = serde_json::to_string_pretty(&file)?;
    text.push('\n');
    crate::atomic_file::write_atomic(path, text.as_bytes())
        .map_err(|e| anyhow::anyhow!("{}: cannot save the bookmarks ({e})", path.display()))
}

/// The pipeline run over the whole source to find its events, a few frames per UI frame.
#[derive(Debug)]
pub struct EventScan {
    pipeline: Pipeline,
    /// Next frame to scan.
    pub next: usize,
    /// Frames in the source.
    pub total: usize,
    had_ball: bool,
    had_goals: Vec<ColourClass>,
    /// Events found so far, in frame order.
    pub events: Vec<Event>,
}

impl EventScan {
    /// A scan of `total` frames with this table and these parameters.
    #[must_use]
    pub fn new(lut: &LookupTable, params: PipelineParams, total: usize) -> Self {
        Self {
            pipeline: Pipeline::new(lut.clone(), params),
            next: 0,
            total,
            had_ball: false,
            had_goals: Vec::new(),
            events: Vec::new(),
        }
    }

    /// True when every frame was scanned.
    #[must_use]
    pub fn done(&self) -> bool {
        self.next >= self.total
    }

    /// Scans frames of `src` for up to `budget` of wall time (at least one frame a call).
    pub fn scan(&mut self, src: &mut Source, budget: Duration) {
        let start = Instant::now();
        let mut first = true;
        while !self.done() && (first || start.elapsed() < budget) {
            first = false;
            let i = self.next;
            self.next += 1;
            match src.read_uncached(i) {
                Ok(f) => {
                    for w in &f.warnings {
                        self.push(i, EventKind::Warning, w.clone());
                    }
                    let r = self.pipeline.process(&f.frame, f.sensors.as_ref());
                    let has_ball = r.recognition.ball.ball.is_some();
                    let goals: Vec<ColourClass> =
                        r.recognition.goals.goals().map(|g| g.colour).collect();
                    self.step(i, has_ball, goals);
                }
                Err(e) => self.push(i, EventKind::Warning, e.to_string()),
            }
        }
    }

    /// Records one frame's recognition: events where it differs from the frame before.
    fn step(&mut self, frame: usize, has_ball: bool, goals: Vec<ColourClass>) {
        if has_ball && !self.had_ball {
            self.push(frame, EventKind::BallFound, String::new());
        } else if !has_ball && self.had_ball {
            self.push(frame, EventKind::BallLost, String::new());
        }
        for &g in &goals {
            if !self.had_goals.contains(&g) {
                self.push(frame, EventKind::GoalAppears(g), String::new());
            }
        }
        self.had_ball = has_ball;
        self.had_goals = goals;
    }

    fn push(&mut self, frame: usize, kind: EventKind, detail: String) {
        self.events.push(Event {
            frame,
            kind,
            detail,
        });
    }
}

/// The frame of the next (`forward`) or previous mark from `current`, among `frames` (any
/// order, repeats allowed); `None` when there is none that way.
#[must_use]
pub fn neighbour(
    frames: impl IntoIterator<Item = usize>,
    current: usize,
    forward: bool,
) -> Option<usize> {
    let frames = frames.into_iter();
    if forward {
        frames.filter(|&f| f > current).min()
    } else {
        frames.filter(|&f| f < current).max()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn events_mark_changes_not_states() {
        let mut scan = EventScan::new(
            &LookupTable::new(6).expect("table"),
            PipelineParams::default(),
            6,
        );
        let y = ColourClass::Yellow;
        scan.step(0, false, vec![]);
        scan.step(1, true, vec![y]);
        scan.step(2, true, vec![y]);
        scan.step(3, false, vec![y, ColourClass::SkyBlue]);
        scan.step(4, false, vec![]);
        scan.step(5, true, vec![y]);
        let got: Vec<(usize, EventKind)> = scan.events.iter().map(|e| (e.frame, e.kind)).collect();
        assert_eq!(
            got,
            vec![
                (1, EventKind::BallFound),
                (1, EventKind::GoalAppears(y)),
                (3, EventKind::BallLost),
                (3, EventKind::GoalAppears(ColourClass::SkyBlue)),
                (5, EventKind::BallFound),
                (5, EventKind::GoalAppears(y)),
            ]
        );
    }

    #[test]
    fn next_and_previous_marks() {
        let marks = [7, 3, 12, 3];
        assert_eq!(neighbour(marks, 3, true), Some(7));
        assert_eq!(neighbour(marks, 3, false), None);
        assert_eq!(neighbour(marks, 8, false), Some(7));
        assert_eq!(neighbour(marks, 12, true), None);
        assert_eq!(neighbour(marks, 0, true), Some(3));
    }

    #[test]
    fn bookmarks_round_trip_and_bad_files_are_errors() {
        let dir = tempfile::tempdir().expect("dir");
        let path = bookmarks_path(&dir.path().join("game.mcap"));
        assert!(path.ends_with("game.mcap.bookmarks.json"));
        assert_eq!(load(&path).expect("missing is empty"), vec![]);
        let marks = vec![
            UserBookmark {
                frame: 40,
                note: "kick".to_owned(),
            },
            UserBookmark {
                frame: 2,
                note: String::new(),
            },
        ];
        save(&path, &marks).expect("save");
        let back = load(&path).expect("load");
        assert_eq!(
            back.iter().map(|b| b.frame).collect::<Vec<_>>(),
            vec![2, 40]
        );
        assert_eq!(back[1].note, "kick");
        std::fs::write(&path, "{\"version\": 1, \"bookmarks\": 3}").expect("write");
        let e = load(&path).expect_err("not a list").to_string();
        assert!(e.contains("not a bookmarks file"), "{e}");
        std::fs::write(&path, "{\"version\": 2, \"bookmarks\": []}").expect("write");
        assert!(load(&path).is_err());
    }
}
