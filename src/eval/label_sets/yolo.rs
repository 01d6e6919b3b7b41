//! YOLO label folders: `NAME.txt` per frame, one box per line as `class cx cy w h` (class number,
//! centre and size as fractions of the image), the class names one a line in `classes.txt`
//! (or given with `--class-names`). Frames without boxes have an empty file.

use std::path::{Path, PathBuf};

use super::{
    ClassMap, FrameBoxes, LabelFormat, LabelSet, LabelSetError, LabelSetProblem, ReadOptions,
    checked_box, file_stem, read_text,
};

/// The class names of `classes.txt`: one a line, blank lines ignored.
#[must_use]
pub fn parse_yolo_classes(text: &str) -> Vec<String> {
    text.lines()
        .map(str::trim)
        .filter(|l| !l.is_empty())
        .map(str::to_owned)
        .collect()
}

/// One frame's YOLO file: boxes as fractions of the image (edges, `[0, 1]` inside it). Lines
/// whose box has no area are skipped and named in the returned warnings.
///
/// # Errors
/// A line that is not `class cx cy w h` with finite numbers, or a class without a name.
pub fn parse_yolo_frame(
    text: &str,
    names: &[String],
    classes: &ClassMap,
) -> Result<(FrameBoxes, Vec<String>), LabelSetProblem> {
    let mut frame = FrameBoxes::default();
    let mut warnings = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let line_no = i + 1;
        let fields: Vec<&str> = line.split_whitespace().collect();
        if fields.is_empty() {
            continue;
        }
        let bad = |why: &str| LabelSetProblem::YoloLine {
            line: line_no,
            why: why.to_owned(),
        };
        let [class, cx, cy, w, h] = fields[..] else {
            return Err(bad("not `class cx cy w h`"));
        };
        let class: usize = class.parse().map_err(|_| bad("class is not a number"))?;
        let mut v = [0.0; 4];
        for (slot, text) in v.iter_mut().zip([cx, cy, w, h]) {
            *slot = text
                .parse::<f64>()
                .ok()
                .filter(|x| x.is_finite())
                .ok_or_else(|| bad("not a finite number"))?;
        }
        let name = names.get(class).ok_or(LabelSetProblem::YoloClass {
            line: line_no,
            class,
            names: names.len(),
        })?;
        let [cx, cy, w, h] = v;
        let edges = [cx - w / 2.0, cy - h / 2.0, cx + w / 2.0, cy + h / 2.0];
        match checked_box(name, classes.object(name), edges) {
            Ok(b) => frame.boxes.push(b),
            Err(e) => warnings.push(format!("line {line_no}: {e}, skipped")),
        }
    }
    Ok((frame, warnings))
}

/// Reads a YOLO folder: `classes.txt` (unless `--class-names` names them) and every other `.txt`.
pub(super) fn load_folder(
    dir: &Path,
    txt: &[&PathBuf],
    options: &ReadOptions,
) -> Result<LabelSet, LabelSetError> {
    let classes_file = dir.join("classes.txt");
    let names = match &options.class_names {
        Some(names) => names.clone(),
        None if classes_file.is_file() => parse_yolo_classes(&read_text(&classes_file)?),
        None => {
            return Err(LabelSetError::Invalid {
                path: dir.display().to_string(),
                problem: LabelSetProblem::YoloNoClassNames,
            });
        }
    };
    let mut set = LabelSet::empty(LabelFormat::Yolo, true);
    for p in txt {
        if p.file_name().is_some_and(|n| n == "classes.txt") {
            continue;
        }
        let text = read_text(p)?;
        let (frame, warnings) =
            parse_yolo_frame(&text, &names, &options.classes).map_err(|problem| {
                LabelSetError::Invalid {
                    path: p.display().to_string(),
                    problem,
                }
            })?;
        set.warnings.extend(
            warnings
                .into_iter()
                .map(|w| format!("{}: {w}", p.display())),
        );
        set.frames.insert(file_stem(p), frame);
    }
    Ok(set)
}
