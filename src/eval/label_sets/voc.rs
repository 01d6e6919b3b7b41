//! Pascal VOC annotations: one XML file per frame, root `<annotation>` with `<filename>`,
//! `<size>` (`width`, `height`) and an `<object>` per box (`<name>`, `<bndbox>` with `xmin`,
//! `ymin`, `xmax`, `ymax` in pixels). Other elements (`pose`, `truncated`, `difficult`,
//! `source`, `segmented`, `path`) are ignored. Read with quick-xml's event reader, so a file is
//! walked once and its depth is bounded.

use quick_xml::Reader;
use quick_xml::events::Event;

use super::{ClassMap, FrameBoxes, LabelSetProblem, checked_box};

/// Deepest element nesting read (a VOC file is 4 deep).
const MAX_DEPTH: usize = 32;

/// The object being read: its class and box values as far as seen.
#[derive(Default)]
struct PendingObject {
    name: Option<String>,
    edges: [Option<f64>; 4],
}

/// What a VOC file says so far.
#[derive(Default)]
struct Reading {
    filename: Option<String>,
    width: Option<usize>,
    height: Option<usize>,
    objects: Vec<PendingObject>,
}

impl Reading {
    /// Takes the text of the element at `path` (names from the root down).
    fn text(&mut self, path: &[String], text: &str) -> Result<(), LabelSetProblem> {
        let names: Vec<&str> = path.iter().map(String::as_str).collect();
        let number = || {
            text.trim()
                .parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| {
                    LabelSetProblem::Voc(format!("{}: {text:?} is not a number", names.join("/")))
                })
        };
        match names[..] {
            ["annotation", "filename"] => self.filename = Some(text.trim().to_owned()),
            ["annotation", "size", "width"] => self.width = Some(whole(number()?)),
            ["annotation", "size", "height"] => self.height = Some(whole(number()?)),
            ["annotation", "object", "name"] => {
                if let Some(o) = self.objects.last_mut() {
                    o.name = Some(text.trim().to_owned());
                }
            }
            ["annotation", "object", "bndbox", edge] => {
                let slot = ["xmin", "ymin", "xmax", "ymax"]
                    .iter()
                    .position(|e| *e == edge);
                if let (Some(slot), Some(o)) = (slot, self.objects.last_mut()) {
                    o.edges[slot] = Some(number()?);
                }
            }
            _ => {}
        }
        Ok(())
    }
}

/// A size value as a whole number of pixels (negative or huge values become 0, which then
/// matches no image).
fn whole(v: f64) -> usize {
    if (0.0..1e9).contains(&v) {
        v as usize
    } else {
        0
    }
}

/// Parses one VOC file: the frame's stem (from `<filename>`, when given) and its boxes.
///
/// # Errors
/// Not XML, a root other than `<annotation>`, too deep, a number that is not one, an object
/// without a name or a complete box, or a box without area.
pub fn parse_voc(
    text: &str,
    classes: &ClassMap,
) -> Result<(Option<String>, FrameBoxes), LabelSetProblem> {
    let mut reader = Reader::from_str(text);
    let mut path: Vec<String> = Vec::new();
    let mut reading = Reading::default();
    let mut text_buf = String::new();
    let mut saw_root = false;
    loop {
        let event = reader
            .read_event()
            .map_err(|e| LabelSetProblem::Voc(e.to_string()))?;
        match event {
            Event::Start(e) => {
                let name = String::from_utf8_lossy(e.local_name().as_ref()).into_owned();
                if path.is_empty() {
                    if name != "annotation" || saw_root {
                        return Err(LabelSetProblem::Voc(format!(
                            "root element is <{name}>, not <annotation>"
                        )));
                    }
                    saw_root = true;
                }
                if path.len() == 1 && name == "object" {
                    reading.objects.push(PendingObject::default());
                }
                path.push(name);
                if path.len() > MAX_DEPTH {
                    return Err(LabelSetProblem::Voc(format!(
                        "nested deeper than {MAX_DEPTH}"
                    )));
                }
                text_buf.clear();
            }
            Event::Text(t) => {
                let s = t
                    .decode()
                    .map_err(|e| LabelSetProblem::Voc(e.to_string()))?;
                text_buf.push_str(&s);
            }
            Event::GeneralRef(r) => {
                let c = r
                    .resolve_char_ref()
                    .map_err(|e| LabelSetProblem::Voc(e.to_string()))?;
                let named = r
                    .decode()
                    .map_err(|e| LabelSetProblem::Voc(e.to_string()))?;
                let resolved = c.or(match named.as_ref() {
                    "amp" => Some('&'),
                    "lt" => Some('<'),
                    "gt" => Some('>'),
                    "quot" => Some('"'),
                    "apos" => Some('\''),
                    _ => None,
                });
                if let Some(c) = resolved {
                    text_buf.push(c);
                }
            }
            Event::End(_) => {
                reading.text(&path, &text_buf)?;
                text_buf.clear();
                path.pop();
            }
            Event::Eof => break,
            _ => {}
        }
    }
    if let Some(open) = path.last() {
        return Err(LabelSetProblem::Voc(format!("<{open}> is not closed")));
    }
    if !saw_root {
        return Err(LabelSetProblem::Voc("no <annotation> element".to_owned()));
    }
    frame_of(reading, classes)
}

fn frame_of(
    reading: Reading,
    classes: &ClassMap,
) -> Result<(Option<String>, FrameBoxes), LabelSetProblem> {
    let mut frame = FrameBoxes {
        size: reading.width.zip(reading.height),
        boxes: Vec::new(),
    };
    for (k, o) in reading.objects.into_iter().enumerate() {
        let name = o
            .name
            .ok_or_else(|| LabelSetProblem::Voc(format!("object {k} has no <name>")))?;
        let [Some(x0), Some(y0), Some(x1), Some(y1)] = o.edges else {
            return Err(LabelSetProblem::Voc(format!(
                "object {k} ({name}) has no complete <bndbox>"
            )));
        };
        frame
            .boxes
            .push(checked_box(&name, classes.object(&name), [x0, y0, x1, y1])?);
    }
    let stem = reading
        .filename
        .filter(|f| !f.is_empty())
        .map(|f| super::file_stem(std::path::Path::new(&f)));
    Ok((stem, frame))
}
