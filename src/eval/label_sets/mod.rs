//! Label sets as teams keep them: boxes around objects per frame, in the three formats that
//! labelling tools write — a YOLO folder (`NAME.txt` per frame, `class cx cy w h` as fractions
//! of the image, class names in `classes.txt` or given), a COCO JSON file (`images`,
//! `annotations` with `bbox` `[x, y, w, h]` in pixels, `categories`) and a Pascal VOC folder
//! (`NAME.xml` per frame, `<object><name>` with `<bndbox>` `xmin ymin xmax ymax` in pixels).
//! [`LabelSet::load`] tells them apart by content, not by name.
//!
//! All three are read into one shape: frames by name (the image file's stem), each with its
//! boxes in image coordinates — pixel edges, so pixel `x` spans `[x, x + 1)` and its centre is
//! `x + 0.5` (`FORMATS.md`) — and the class each box names mapped to one of eotn's
//! [`LabelObject`]s. VOC's `xmin`/`xmax` are read as those edges (the width is `xmax − xmin`),
//! the way YOLO converters and COCO exporters read them, so the three formats of one set give
//! the same boxes.

mod coco;
mod voc;
mod yolo;

use std::collections::BTreeMap;
use std::path::Path;

use serde::{Deserialize, Serialize};
use thiserror::Error;

pub use coco::parse_coco;
pub use voc::parse_voc;
pub use yolo::{parse_yolo_classes, parse_yolo_frame};

/// What a labelled box is, as far as eotn's recognition is concerned. Only the ball is scored;
/// everything else is "not a ball" (a ball reported inside it is a false ball).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum LabelObject {
    /// A ball.
    Ball,
    /// A robot (eotn has no robot recogniser: drawn and counted as not a ball).
    Robot,
    /// A goal (an SSL goal is not one of eotn's goals: drawn, not scored).
    Goal,
    /// Any other class.
    Other,
}

impl LabelObject {
    /// Every object, in drawing order.
    pub const ALL: [Self; 4] = [Self::Ball, Self::Robot, Self::Goal, Self::Other];

    /// The object's name on the command line and in reports.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::Ball => "ball",
            Self::Robot => "robot",
            Self::Goal => "goal",
            Self::Other => "other",
        }
    }

    /// The object of a name (`ball`, `robot`, `goal`, `other`), case-insensitive.
    #[must_use]
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL
            .into_iter()
            .find(|o| o.name().eq_ignore_ascii_case(name.trim()))
    }
}

/// One labelled box in image coordinates (pixel edges), pixels.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LabelBox {
    /// The class as the label set names it.
    pub class: String,
    /// What eotn takes it for.
    pub object: LabelObject,
    /// Left edge, pixels.
    pub min_x: f64,
    /// Top edge, pixels.
    pub min_y: f64,
    /// Right edge, pixels.
    pub max_x: f64,
    /// Bottom edge, pixels.
    pub max_y: f64,
}

impl LabelBox {
    /// Width, pixels.
    #[must_use]
    pub fn width(&self) -> f64 {
        self.max_x - self.min_x
    }

    /// Height, pixels.
    #[must_use]
    pub fn height(&self) -> f64 {
        self.max_y - self.min_y
    }

    /// The larger side, pixels (a ball's size in the reports), to 1/1000 px: a YOLO box, whose
    /// fractions carry six decimals, then has the size of the pixel box it was written from
    /// (9.99999 px is 10 px) and falls in the same size band.
    #[must_use]
    pub fn larger_side(&self) -> f64 {
        (self.width().max(self.height()) * 1000.0).round() / 1000.0
    }

    /// The centre, pixels `[x, y]`.
    #[must_use]
    pub fn centre(&self) -> [f64; 2] {
        [
            (self.min_x + self.max_x) / 2.0,
            (self.min_y + self.max_y) / 2.0,
        ]
    }

    /// Whether the point `(x, y)` lies in the box grown by `margin` pixels on every side.
    #[must_use]
    pub fn contains(&self, x: f64, y: f64, margin: f64) -> bool {
        x >= self.min_x - margin
            && x <= self.max_x + margin
            && y >= self.min_y - margin
            && y <= self.max_y + margin
    }
}

/// One frame's labels.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct FrameBoxes {
    /// The image size the labels give, pixels (COCO and VOC say it; YOLO does not).
    pub size: Option<(usize, usize)>,
    /// The boxes.
    pub boxes: Vec<LabelBox>,
}

impl FrameBoxes {
    /// The ball boxes.
    pub fn balls(&self) -> impl Iterator<Item = &LabelBox> {
        self.boxes.iter().filter(|b| b.object == LabelObject::Ball)
    }
}

/// Which of the three formats a set was read from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum LabelFormat {
    /// A YOLO folder.
    Yolo,
    /// A COCO JSON file.
    Coco,
    /// A Pascal VOC folder.
    Voc,
}

/// How class names become eotn objects: by default `ball`, `robot` and `goal` are themselves
/// and anything else is [`LabelObject::Other`]; `--classes name=object,…` adds or overrides.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ClassMap {
    /// Class name (lower case) → object.
    pub names: BTreeMap<String, LabelObject>,
}

impl ClassMap {
    /// Parses `name=object,…` (objects: `ball`, `robot`, `goal`, `other`).
    ///
    /// # Errors
    /// An entry without `=`, an empty name, or an unknown object.
    pub fn parse(text: &str) -> Result<Self, LabelSetProblem> {
        let mut names = BTreeMap::new();
        for entry in text.split(',').filter(|e| !e.trim().is_empty()) {
            let (name, object) = entry
                .split_once('=')
                .ok_or_else(|| LabelSetProblem::ClassMapping(entry.to_owned()))?;
            let object = LabelObject::from_name(object)
                .ok_or_else(|| LabelSetProblem::ClassMapping(entry.to_owned()))?;
            let name = name.trim().to_lowercase();
            if name.is_empty() {
                return Err(LabelSetProblem::ClassMapping(entry.to_owned()));
            }
            names.insert(name, object);
        }
        Ok(Self { names })
    }

    /// The object a class name stands for.
    #[must_use]
    pub fn object(&self, class: &str) -> LabelObject {
        let key = class.trim().to_lowercase();
        self.names
            .get(&key)
            .copied()
            .or_else(|| LabelObject::from_name(&key))
            .unwrap_or(LabelObject::Other)
    }
}

/// How a set is read: the class mapping and, for a YOLO folder without `classes.txt`, the
/// class names in order of their numbers.
#[derive(Debug, Clone, Default)]
pub struct ReadOptions {
    /// Class name → object.
    pub classes: ClassMap,
    /// YOLO class names by number (`--class-names`); overrides `classes.txt`.
    pub class_names: Option<Vec<String>>,
}

/// A whole label set: frames by name (the image's file stem).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LabelSet {
    /// The format it was read from.
    pub format: LabelFormat,
    /// Frames by image stem. YOLO boxes are in fractions until [`Self::frame_in_pixels`] gives
    /// them an image size.
    pub frames: BTreeMap<String, FrameBoxes>,
    /// Whether the boxes are fractions of the image (YOLO) rather than pixels.
    pub fractional: bool,
    /// Files or entries skipped with the reason (unreadable lines, boxes without area).
    pub warnings: Vec<String>,
}

/// Why a label set cannot be used.
#[derive(Debug, Error)]
pub enum LabelSetError {
    /// Reading a file or folder failed.
    #[error("{path}: {source}")]
    Io {
        /// The file or folder.
        path: String,
        /// What the OS said.
        source: std::io::Error,
    },
    /// The contents are not a label set.
    #[error("{path}: {problem}")]
    Invalid {
        /// The file.
        path: String,
        /// What is wrong.
        #[source]
        problem: LabelSetProblem,
    },
}

/// What is wrong with a label set's contents.
#[derive(Debug, Error, PartialEq)]
pub enum LabelSetProblem {
    /// A YOLO line that is not `class cx cy w h` with fractions.
    #[error("line {line}: {why}")]
    YoloLine {
        /// 1-based line number.
        line: usize,
        /// What is wrong.
        why: String,
    },
    /// A YOLO class number beyond the class names.
    #[error("line {line}: class {class} has no name ({names} class names)")]
    YoloClass {
        /// 1-based line number.
        line: usize,
        /// The class number.
        class: usize,
        /// How many names there are.
        names: usize,
    },
    /// A YOLO folder whose class names are unknown.
    #[error("no classes.txt: name the class numbers with --class-names robot,ball,goal")]
    YoloNoClassNames,
    /// Not COCO JSON.
    #[error("COCO: {0}")]
    Coco(String),
    /// Not a Pascal VOC annotation.
    #[error("Pascal VOC: {0}")]
    Voc(String),
    /// A box that is not finite or has no area.
    #[error("box {values:?} of class {class:?} is not a box")]
    NotABox {
        /// The class.
        class: String,
        /// The values as read.
        values: [f64; 4],
    },
    /// A `--classes` entry that is not `name=object`.
    #[error("{0:?} is not name=object (objects: ball, robot, goal, other)")]
    ClassMapping(String),
    /// Neither a YOLO, COCO nor VOC set.
    #[error(
        "neither a YOLO folder (NAME.txt), a Pascal VOC folder (NAME.xml) nor a COCO JSON file"
    )]
    UnknownFormat,
    /// A set without a single labelled frame.
    #[error("no labelled frame")]
    Empty,
}

/// Checks a box's values and makes it, or says why not.
///
/// # Errors
/// [`LabelSetProblem::NotABox`]: a non-finite value or no area.
pub fn checked_box(
    class: &str,
    object: LabelObject,
    [min_x, min_y, max_x, max_y]: [f64; 4],
) -> Result<LabelBox, LabelSetProblem> {
    let values = [min_x, min_y, max_x, max_y];
    if !values.iter().all(|v| v.is_finite()) || max_x <= min_x || max_y <= min_y {
        return Err(LabelSetProblem::NotABox {
            class: class.to_owned(),
            values,
        });
    }
    Ok(LabelBox {
        class: class.to_owned(),
        object,
        min_x,
        min_y,
        max_x,
        max_y,
    })
}

/// Largest label file read, bytes (a COCO file of a large set is tens of MiB).
const MAX_LABEL_FILE_BYTES: u64 = crate::input_file::MAX_SIDE_FILE_BYTES;

fn read_text(path: &Path) -> Result<String, LabelSetError> {
    crate::input_file::read_text_bounded(path, MAX_LABEL_FILE_BYTES, "a label file").map_err(
        |source| LabelSetError::Io {
            path: path.display().to_string(),
            source,
        },
    )
}

impl LabelSet {
    /// Reads a YOLO folder, a Pascal VOC folder or a COCO JSON file, told apart by content: a
    /// file is COCO; a folder holding `.xml` files whose root is `<annotation>` is VOC, one
    /// holding `.txt` files is YOLO. Files of a folder that cannot be read are errors; boxes
    /// without area are skipped with a warning.
    ///
    /// # Errors
    /// [`LabelSetError`] naming the file.
    pub fn load(path: &Path, options: &ReadOptions) -> Result<Self, LabelSetError> {
        let invalid = |p: &Path, problem| LabelSetError::Invalid {
            path: p.display().to_string(),
            problem,
        };
        let set = if path.is_dir() {
            let files = folder_files(path)?;
            let xml: Vec<_> = files.iter().filter(|p| has_ext(p, "xml")).collect();
            let txt: Vec<_> = files.iter().filter(|p| has_ext(p, "txt")).collect();
            if xml.len() >= txt.len() && !xml.is_empty() {
                let mut set = Self::empty(LabelFormat::Voc, false);
                for p in xml {
                    let text = read_text(p)?;
                    let (named, frame) =
                        parse_voc(&text, &options.classes).map_err(|e| invalid(p, e))?;
                    // The XML file's own name pairs it with its image (as labelImg and
                    // CVAT write them); a different <filename> is only worth a warning.
                    let stem = file_stem(p);
                    if let Some(named) = named.filter(|n| *n != stem) {
                        set.warnings.push(format!(
                            "{}: <filename> names {named:?}, read as frame {stem:?}",
                            p.display()
                        ));
                    }
                    set.frames.insert(stem, frame);
                }
                set
            } else if !txt.is_empty() {
                yolo::load_folder(path, &txt, options)?
            } else {
                return Err(invalid(path, LabelSetProblem::UnknownFormat));
            }
        } else {
            let text = read_text(path)?;
            let mut set = Self::empty(LabelFormat::Coco, false);
            let (frames, warnings) =
                parse_coco(&text, &options.classes).map_err(|e| invalid(path, e))?;
            set.frames = frames;
            set.warnings = warnings;
            set
        };
        if set.frames.is_empty() {
            return Err(invalid(path, LabelSetProblem::Empty));
        }
        Ok(set)
    }

    fn empty(format: LabelFormat, fractional: bool) -> Self {
        Self {
            format,
            frames: BTreeMap::new(),
            fractional,
            warnings: Vec::new(),
        }
    }

    /// The labels of the frame named `stem`, in pixels of a `width` × `height` image.
    #[must_use]
    pub fn frame_in_pixels(&self, stem: &str, width: usize, height: usize) -> Option<FrameBoxes> {
        let frame = self.frames.get(stem)?;
        if !self.fractional {
            return Some(frame.clone());
        }
        let (w, h) = (width as f64, height as f64);
        Some(FrameBoxes {
            size: Some((width, height)),
            boxes: frame
                .boxes
                .iter()
                .map(|b| LabelBox {
                    min_x: b.min_x * w,
                    max_x: b.max_x * w,
                    min_y: b.min_y * h,
                    max_y: b.max_y * h,
                    ..b.clone()
                })
                .collect(),
        })
    }
}

fn has_ext(p: &Path, ext: &str) -> bool {
    p.extension().is_some_and(|e| e.eq_ignore_ascii_case(ext))
}

/// A file's name without its extension (the frame's name in a label set).
#[must_use]
pub fn file_stem(p: &Path) -> String {
    p.file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default()
}

fn folder_files(dir: &Path) -> Result<Vec<std::path::PathBuf>, LabelSetError> {
    let io = |source| LabelSetError::Io {
        path: dir.display().to_string(),
        source,
    };
    let mut files = Vec::new();
    for entry in std::fs::read_dir(dir).map_err(io)? {
        let p = entry.map_err(io)?.path();
        if p.is_file() {
            files.push(p);
        }
    }
    files.sort();
    Ok(files)
}

/// Frames held out of every decision (table edits, parameters, code): those whose number — the
/// last run of digits in the name — ends in 7, 8 or 9. The rest are the tuning frames.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "kebab-case")]
pub enum Split {
    /// Every frame.
    All,
    /// Frames whose number ends in 0–6 (or that have no number).
    Tuning,
    /// Frames whose number ends in 7, 8 or 9.
    HeldOut,
}

impl Split {
    /// Whether the frame named `name` belongs to this split.
    #[must_use]
    pub fn takes(self, name: &str) -> bool {
        match self {
            Self::All => true,
            Self::Tuning => !is_held_out(name),
            Self::HeldOut => is_held_out(name),
        }
    }
}

/// Whether the frame named `name` (a file stem or a stream frame's number) is held out: its
/// last digit is 7, 8 or 9.
#[must_use]
pub fn is_held_out(name: &str) -> bool {
    name.chars()
        .rev()
        .find(char::is_ascii_digit)
        .is_some_and(|d| matches!(d, '7' | '8' | '9'))
}

#[cfg(test)]
mod tests;
