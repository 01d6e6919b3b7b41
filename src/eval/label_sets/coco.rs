//! COCO object-detection JSON: `images` (`id`, `file_name`, `width`, `height`), `annotations`
//! (`image_id`, `category_id`, `bbox` `[x, y, width, height]` in pixels from the image's
//! top-left corner), `categories` (`id`, `name`). Other keys (`info`, `licenses`, `area`,
//! `iscrowd`, `segmentation`) are allowed and ignored. An image without annotations is a
//! labelled frame without boxes.

use std::collections::{BTreeMap, HashMap};

use serde::Deserialize;

use super::{ClassMap, FrameBoxes, LabelSetProblem, checked_box};

#[derive(Deserialize)]
struct CocoFile {
    images: Vec<CocoImage>,
    #[serde(default)]
    annotations: Vec<CocoAnnotation>,
    categories: Vec<CocoCategory>,
}

#[derive(Deserialize)]
struct CocoImage {
    id: u64,
    file_name: String,
    #[serde(default)]
    width: Option<usize>,
    #[serde(default)]
    height: Option<usize>,
}

#[derive(Deserialize)]
struct CocoAnnotation {
    image_id: u64,
    category_id: u64,
    bbox: [f64; 4],
}

#[derive(Deserialize)]
struct CocoCategory {
    id: u64,
    name: String,
}

/// Parses a COCO file into frames by image stem, with warnings for boxes skipped (no area).
///
/// # Errors
/// Not COCO JSON, an image id or file stem twice, an annotation of an unknown image or category.
pub fn parse_coco(
    text: &str,
    classes: &ClassMap,
) -> Result<(BTreeMap<String, FrameBoxes>, Vec<String>), LabelSetProblem> {
    let file: CocoFile =
        serde_json::from_str(text).map_err(|e| LabelSetProblem::Coco(e.to_string()))?;
    let categories: HashMap<u64, &str> = file
        .categories
        .iter()
        .map(|c| (c.id, c.name.as_str()))
        .collect();
    let mut stems: HashMap<u64, String> = HashMap::new();
    let mut frames = BTreeMap::new();
    for image in &file.images {
        let stem = super::file_stem(std::path::Path::new(&image.file_name));
        if stems.insert(image.id, stem.clone()).is_some() {
            return Err(LabelSetProblem::Coco(format!(
                "image id {} twice",
                image.id
            )));
        }
        let size = image.width.zip(image.height);
        if frames
            .insert(
                stem.clone(),
                FrameBoxes {
                    size,
                    boxes: vec![],
                },
            )
            .is_some()
        {
            return Err(LabelSetProblem::Coco(format!("image {stem:?} twice")));
        }
    }
    let mut warnings = Vec::new();
    for (k, a) in file.annotations.iter().enumerate() {
        let stem = stems.get(&a.image_id).ok_or_else(|| {
            LabelSetProblem::Coco(format!("annotation {k}: no image {}", a.image_id))
        })?;
        let class = categories.get(&a.category_id).ok_or_else(|| {
            LabelSetProblem::Coco(format!("annotation {k}: no category {}", a.category_id))
        })?;
        let [x, y, w, h] = a.bbox;
        match checked_box(class, classes.object(class), [x, y, x + w, y + h]) {
            Ok(b) => {
                if let Some(f) = frames.get_mut(stem) {
                    f.boxes.push(b);
                }
            }
            Err(e) => warnings.push(format!("annotation {k}: {e}, skipped")),
        }
    }
    Ok((frames, warnings))
}
