//! What persists between runs and what the views are: the settings, the four views, the
//! overlay switches, zoom and pan.
//!
//! The settings file (`settings.json` in the app's storage folder) is read and written by this
//! version of eotn and by others: a key it does not know is named in a warning and the rest is
//! kept, a key whose value it cannot read keeps its default (also with a warning), and the file
//! is written through [`crate::atomic_file`] like every other output.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::blobs::Connectivity;
use crate::lut::{ColourClass, Sensitivity};

/// How many warnings the status area keeps (oldest dropped first).
pub const MAX_WARNINGS: usize = 200;
/// How many recent files the File menu lists.
pub const MAX_RECENT: usize = 10;
/// Zoom limits, screen points per image pixel.
pub const ZOOM_RANGE: (f32, f32) = (0.1, 64.0);
/// Zoom presets of the View menu, screen points per image pixel.
pub const ZOOM_PRESETS: [f32; 6] = [0.5, 1.0, 2.0, 4.0, 8.0, 16.0];
/// Playback speeds offered, × recorded rate; 0 plays every frame as fast as the machine can.
pub const SPEEDS: [f32; 7] = [0.25, 0.5, 1.0, 2.0, 4.0, 8.0, 0.0];

/// The four image views; one is enlarged, the others are thumbnails.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
pub enum ViewKind {
    /// The camera image in colour.
    #[default]
    Raw,
    /// Every pixel in its class's display colour.
    Classified,
    /// The classified image dimmed, with each blob's box.
    Blobs,
    /// The colour image with the recognised objects: ball, goals with posts and gap, beacons,
    /// labelled with distance and bearing.
    Objects,
}

impl ViewKind {
    /// All views in thumbnail order.
    pub const ALL: [Self; 4] = [Self::Raw, Self::Classified, Self::Blobs, Self::Objects];

    /// The name shown under a thumbnail and in menus.
    #[must_use]
    pub const fn name(self) -> &'static str {
        match self {
            Self::Raw => "Raw",
            Self::Classified => "Classified",
            Self::Blobs => "Blobs",
            Self::Objects => "Objects",
        }
    }
}

/// Which overlays are drawn on the enlarged view.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Overlays {
    /// Classified colours over the colour image (raw and objects views).
    pub classified: bool,
    /// Opacity of the classified overlay, 0..=1.
    pub opacity: f32,
    /// Blob boxes on every view.
    pub blob_boxes: bool,
    /// Class names beside the boxes.
    pub labels: bool,
    /// The pending selection's preview highlight.
    pub preview: bool,
    /// Recognition: the horizon (needs the camera pose from sensor readings).
    pub horizon: bool,
    /// Recognition: every candidate's box, accepted or rejected.
    pub candidates: bool,
    /// Recognition: the scanned areas (green below a ball).
    pub scan_areas: bool,
    /// Recognition: edge points found by the ball's and the posts' scans.
    pub scan_points: bool,
    /// Recognition: the ball's fitted circle.
    pub circles: bool,
    /// Recognition: fitted goal posts.
    pub posts: bool,
    /// Recognition: a goal's largest gap and its scan line.
    pub gaps: bool,
    /// Recognition: labels of accepted objects with distance (cm) and bearing (degrees).
    pub object_labels: bool,
    /// Recognition: the nine regions around each pink marker and its place.
    pub patterns: bool,
}

impl Overlays {
    /// Every overlay on, the classified colours at half opacity: the heaviest view.
    #[must_use]
    pub fn all_on() -> Self {
        Self {
            classified: true,
            ..Self::default()
        }
    }

    /// Switches every recognition overlay on or off.
    pub fn set_recognition(&mut self, on: bool) {
        self.horizon = on;
        self.candidates = on;
        self.scan_areas = on;
        self.scan_points = on;
        self.circles = on;
        self.posts = on;
        self.gaps = on;
        self.object_labels = on;
        self.patterns = on;
    }
}

impl Default for Overlays {
    fn default() -> Self {
        Self {
            classified: false,
            opacity: 0.5,
            blob_boxes: true,
            labels: true,
            preview: true,
            horizon: true,
            candidates: true,
            scan_areas: true,
            scan_points: true,
            circles: true,
            posts: true,
            gaps: true,
            object_labels: true,
            patterns: true,
        }
    }
}

/// Zoom and pan of the enlarged view, in image pixels so they survive a window resize.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(default)]
pub struct ViewTransform {
    /// Screen points per image pixel; `None` fits the image to the view.
    pub zoom: Option<f32>,
    /// The image point (pixels) shown at the centre of the view; `None` is the image centre.
    pub centre: Option<[f32; 2]>,
}

impl ViewTransform {
    /// The zoom in effect when the fitted zoom is `fit`.
    #[must_use]
    pub fn effective_zoom(&self, fit: f32) -> f32 {
        self.zoom.unwrap_or(fit)
    }

    /// The centre in effect for an image of `size` (width, height) pixels.
    #[must_use]
    pub fn effective_centre(&self, size: [f32; 2]) -> [f32; 2] {
        self.centre.unwrap_or([size[0] / 2.0, size[1] / 2.0])
    }
}

/// View options of the overhead camera's image.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(default)]
pub struct OverheadView {
    /// The field lines projected through the calibration in use.
    pub field_lines: bool,
    /// The image as a pinhole camera would see it (the lens's bending removed).
    pub undistorted: bool,
    /// Each picked calibration point with its reprojection error.
    pub points: bool,
    /// Each overhead camera's view of the carpet on the field view (outline and light fill in
    /// the camera's colour).
    pub coverage: bool,
}

impl Default for OverheadView {
    fn default() -> Self {
        Self {
            field_lines: true,
            undistorted: false,
            points: true,
            coverage: true,
        }
    }
}

/// Settings that persist between runs (eframe storage).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Settings {
    /// Recently opened files, newest first.
    pub recent: Vec<PathBuf>,
    /// The robot camera's table to reopen at start.
    pub last_table: Option<PathBuf>,
    /// The overhead camera's table to reopen at start.
    pub last_overhead_table: Option<PathBuf>,
    /// Each camera's files (table, parameters, calibration) as last used with it, by camera
    /// (its source and image topic): a recording's `/camera/bottom` reopens with the table last
    /// used on it. Entries an older eotn keyed by topic alone are dropped when read.
    #[serde(deserialize_with = "crate::camera::deserialize_camera_map")]
    pub cameras: std::collections::BTreeMap<crate::camera::CameraId, crate::camera::CameraFiles>,
    /// The places file (learnt coloured patterns) to reopen at start.
    pub last_places: Option<PathBuf>,
    /// The recognition parameters file to reopen at start (`None`: the defaults).
    pub last_params: Option<PathBuf>,
    /// The stream or frame files to reopen at start.
    pub last_source: Vec<PathBuf>,
    /// The frame that was shown.
    pub last_index: usize,
    /// The class being defined.
    pub class: ColourClass,
    /// Selection reach per channel, table cells.
    pub sensitivity: Sensitivity,
    /// Overlay switches.
    pub overlays: Overlays,
    /// The enlarged view.
    pub main_view: ViewKind,
    /// Zoom and pan of the enlarged view.
    pub transform: ViewTransform,
    /// Playback speed, × recorded rate (0 = every frame, as fast as possible).
    pub speed: f32,
    /// Blob connectivity.
    pub connectivity: Connectivity,
    /// Blobs smaller than this many pixels get no box or label.
    pub min_blob_pixels: u32,
    /// Classes whose blobs get no box or label (green and white by default: the carpet and
    /// the lines make dozens of boxes that hide the objects).
    pub hidden_blob_classes: Vec<ColourClass>,
    /// Bits of a new table.
    pub new_table_bits: u8,
    /// Sensor dialog open.
    pub show_sensors: bool,
    /// U–V plane window open.
    pub show_uv_plane: bool,
    /// The Y value whose layer the U–V plane shows, 0..=255.
    pub uv_plane_y: u8,
    /// "Try edit on the stream" window open.
    pub show_try_edit: bool,
    /// The step and frame-time readout in the status bar.
    pub show_timings: bool,
    /// The object inspector window open.
    pub show_inspector: bool,
    /// The overhead field view open.
    pub show_field_view: bool,
    /// The overhead calibration window open.
    pub show_calibration: bool,
    /// Overhead view options.
    pub overhead: OverheadView,
    /// The Parameters window open.
    pub show_params: bool,
    /// The Connect dialog open (not kept between runs, like the other Camera dialogs).
    #[serde(skip)]
    pub show_connect: bool,
    /// The source settings dialog open.
    #[serde(skip)]
    pub show_source_settings: bool,
    /// The "Start recording" dialog open.
    #[serde(skip)]
    pub show_record: bool,
    /// The robots window (Camera ▸ Connect to robot…) open.
    #[serde(skip)]
    pub show_robots: bool,
    /// The unclassified-colours (coverage hints) window open.
    pub show_coverage: bool,
    /// The events-and-bookmarks window open.
    pub show_bookmarks: bool,
}

impl Default for Settings {
    fn default() -> Self {
        Self {
            recent: Vec::new(),
            last_table: None,
            last_overhead_table: None,
            cameras: std::collections::BTreeMap::new(),
            last_places: None,
            last_params: None,
            last_source: Vec::new(),
            last_index: 0,
            class: ColourClass::Orange,
            sensitivity: Sensitivity::uniform(1),
            overlays: Overlays::default(),
            main_view: ViewKind::Raw,
            transform: ViewTransform::default(),
            speed: 1.0,
            connectivity: Connectivity::default(),
            min_blob_pixels: 10,
            hidden_blob_classes: vec![ColourClass::Green, ColourClass::White],
            new_table_bits: 7,
            show_sensors: false,
            show_uv_plane: false,
            uv_plane_y: 128,
            show_try_edit: false,
            show_timings: true,
            show_inspector: false,
            show_field_view: false,
            show_calibration: false,
            overhead: OverheadView::default(),
            show_params: false,
            show_connect: false,
            show_source_settings: false,
            show_record: false,
            show_robots: false,
            show_coverage: false,
            show_bookmarks: false,
        }
    }
}

/// The settings file's name in the app's storage folder.
pub const SETTINGS_FILE_NAME: &str = "settings.json";

impl Settings {
    /// Settings from a settings file's text, with warnings: keys this version does not know are
    /// named and ignored, a key whose value it cannot read keeps its default, text that is not
    /// a JSON object gives the defaults.
    #[must_use]
    pub fn from_json(text: &str) -> (Self, Vec<String>) {
        let given: serde_json::Value = match serde_json::from_str(text) {
            Ok(v @ serde_json::Value::Object(_)) => v,
            Ok(_) => {
                return (
                    Self::default(),
                    vec!["not a JSON object; defaults used".into()],
                );
            }
            Err(e) => {
                return (
                    Self::default(),
                    vec![format!("not JSON ({e}); defaults used")],
                );
            }
        };
        let mut warnings = Vec::new();
        let mut merged = serde_json::to_value(Self::default()).unwrap_or_default();
        if let (Some(keys), Some(target)) = (given.as_object(), merged.as_object_mut()) {
            for (key, value) in keys {
                let before = target.insert(key.clone(), value.clone());
                let readable =
                    serde_json::from_value::<Self>(serde_json::Value::Object(target.clone()))
                        .is_ok();
                if !readable {
                    warnings.push(format!(
                        "setting '{key}' has a value this version cannot read; its default is kept"
                    ));
                    match before {
                        Some(b) => target.insert(key.clone(), b),
                        None => target.remove(key),
                    };
                }
            }
        }
        let settings: Self = serde_json::from_value(merged).unwrap_or_default();
        let known = serde_json::to_value(&settings).unwrap_or_default();
        warnings.extend(
            crate::input_file::unknown_keys(&given, &known)
                .into_iter()
                .map(|k| format!("unknown setting '{k}' ignored (from another version of eotn?)")),
        );
        (settings, warnings)
    }

    /// Reads the settings file at `path`; a missing file gives the defaults quietly, one that
    /// cannot be read (not a regular file, too large, not JSON) the defaults with a warning.
    /// Every warning names the file.
    #[must_use]
    pub fn load(path: &Path) -> (Self, Vec<String>) {
        let text = match crate::input_file::read_text_bounded(
            path,
            crate::input_file::MAX_SMALL_FILE_BYTES,
            "a settings file",
        ) {
            Ok(t) => t,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return (Self::default(), vec![]),
            Err(e) => {
                return (
                    Self::default(),
                    vec![format!("{}: {e}; defaults used", path.display())],
                );
            }
        };
        let (settings, warnings) = Self::from_json(&text);
        let warnings = warnings
            .into_iter()
            .map(|w| format!("{}: {w}", path.display()))
            .collect();
        (settings, warnings)
    }

    /// Writes the settings file (pretty JSON, through [`crate::atomic_file`]).
    ///
    /// # Errors
    /// The file cannot be written.
    pub fn save(&self, path: &Path) -> std::io::Result<()> {
        let mut text = serde_json::to_string_pretty(self).map_err(std::io::Error::other)?;
        text.push('\n');
        crate::atomic_file::write_atomic(path, text.as_bytes())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn settings_round_trip_through_their_file() {
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join(SETTINGS_FILE_NAME);
        let mut s = Settings {
            speed: 4.0,
            recent: vec![PathBuf::from("/x/a.mcap")],
            ..Settings::default()
        };
        s.overlays.opacity = 0.25;
        s.save(&path).expect("saves");
        assert_eq!(Settings::load(&path), (s, vec![]));
        assert_eq!(
            Settings::load(&dir.path().join("none.json")),
            (Settings::default(), vec![])
        );
    }

    #[test]
    fn another_version_s_settings_keep_what_this_one_reads() {
        let text = r#"{"speed": 2.0, "main_view": "Blobs", "dark_mode": true,
            "overlays": {"opacity": 0.3, "glow": 1}, "min_blob_pixels": "many"}"#;
        let (s, warnings) = Settings::from_json(text);
        assert_eq!(s.speed, 2.0);
        assert_eq!(s.main_view, ViewKind::Blobs);
        assert_eq!(s.overlays.opacity, 0.3);
        assert_eq!(s.min_blob_pixels, Settings::default().min_blob_pixels);
        let all = warnings.join("\n");
        assert!(all.contains("'min_blob_pixels' has a value"), "{all}");
        assert!(all.contains("unknown setting 'dark_mode'"), "{all}");
        assert!(all.contains("unknown setting 'overlays.glow'"), "{all}");
        assert_eq!(warnings.len(), 3, "{all}");
        let (s, warnings) = Settings::from_json("[1, 2]");
        assert_eq!((s, warnings.len()), (Settings::default(), 1));
    }

    #[cfg(unix)]
    #[test]
    fn a_fifo_as_the_settings_file_gives_the_defaults_without_waiting() {
        let dir = tempfile::tempdir().expect("tempdir");
        let fifo = dir.path().join(SETTINGS_FILE_NAME);
        if !crate::input_file::make_fifo(&fifo) {
            return;
        }
        let (s, warnings) = Settings::load(&fifo);
        assert_eq!(s, Settings::default());
        assert!(warnings[0].contains("not a regular file"), "{warnings:?}");
    }
}
