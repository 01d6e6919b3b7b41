//! A camera's intrinsics from a checkerboard calibration: a ROS `camera_info` YAML file as
//! `camera_calibration` writes it (`image_width`, `image_height`, `camera_name`,
//! `camera_matrix`, `distortion_model`, `distortion_coefficients`, `rectification_matrix`,
//! `projection_matrix`), or the same fields of a `sensor_msgs/CameraInfo` message
//! ([`CameraInfoFields`], the hook a recording's decoder fills).
//!
//! With intrinsics the overhead calibration fits only the camera's pose: teams calibrate the
//! lens once with a checkerboard, and a pose is determined by far fewer, less spread clicks
//! than a pose and a lens together.
//!
//! Conventions: ROS puts pixel centres at whole numbers, eotn at +0.5 (`FORMATS.md`), so the
//! principal point moves by half a pixel. The rectification and projection matrices describe
//! the rectified (stereo) image, not the raw one eotn reads, and are not used; a camera matrix
//! with skew is refused (`camera_calibration` never writes one). Intrinsics made at one frame
//! size serve frames a whole factor smaller or larger (the same sensor binned or resampled):
//! focal lengths and principal point scale, the lens model does not.

use std::path::Path;

use serde::Deserialize;

use crate::geometry::{ImagePoint, LensModel, OverheadCamera};

/// Largest image side an intrinsics file may give, pixels.
const MAX_SIDE_PX: usize = 100_000;

/// A checkerboard-calibrated camera's intrinsics, in eotn's pixel convention.
#[derive(Debug, Clone, PartialEq)]
pub struct Intrinsics {
    /// `camera_name` of the file (may be empty).
    pub camera_name: String,
    /// Image width the intrinsics were calibrated at, pixels.
    pub width_px: usize,
    /// Image height, pixels.
    pub height_px: usize,
    /// Horizontal focal length, pixels.
    pub fx: f64,
    /// Vertical focal length, pixels.
    pub fy: f64,
    /// The principal point, pixels (pixel centres at +0.5: ROS's `cx + 0.5`).
    pub centre: ImagePoint,
    /// The lens.
    pub lens: LensModel,
}

/// The fields of a ROS camera info that eotn uses, as both the YAML file and a
/// `sensor_msgs/CameraInfo` message carry them (`k` row-major; `d` in the model's order).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CameraInfoFields<'a> {
    /// `width` / `image_width`, pixels.
    pub width: usize,
    /// `height` / `image_height`, pixels.
    pub height: usize,
    /// `camera_name` (the message has none: its frame id, or empty).
    pub camera_name: &'a str,
    /// `k` / `camera_matrix.data`: `fx 0 cx / 0 fy cy / 0 0 1`, pixel centres at whole numbers.
    pub k: [f64; 9],
    /// `distortion_model`.
    pub distortion_model: &'a str,
    /// `d` / `distortion_coefficients.data`.
    pub d: &'a [f64],
}

/// Why intrinsics could not be read or used.
#[derive(Debug, thiserror::Error)]
pub enum IntrinsicsError {
    /// The file could not be read or is not a usable camera info.
    #[error("{path}: {what}")]
    File {
        /// The file.
        path: String,
        /// What is wrong.
        what: String,
    },
    /// The frames are not a whole factor of the intrinsics' size.
    #[error(
        "the intrinsics{name} are for {iw}x{ih} frames, these are {w}x{h}: not the same size or a whole factor of it (calibrate the intrinsics at this size)"
    )]
    FrameSize {
        /// ` of CAMERA_NAME`, or empty.
        name: String,
        /// The intrinsics' width, pixels.
        iw: usize,
        /// The intrinsics' height, pixels.
        ih: usize,
        /// The frames' width, pixels.
        w: usize,
        /// The frames' height, pixels.
        h: usize,
    },
}

/// A matrix as `camera_calibration` writes one.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct YamlMatrix {
    rows: usize,
    cols: usize,
    data: Vec<f64>,
}

/// The `camera_info` YAML file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct CameraInfoYaml {
    image_width: usize,
    image_height: usize,
    #[serde(default)]
    camera_name: String,
    camera_matrix: YamlMatrix,
    distortion_model: String,
    distortion_coefficients: YamlMatrix,
    #[serde(default)]
    rectification_matrix: Option<YamlMatrix>,
    #[serde(default)]
    projection_matrix: Option<YamlMatrix>,
}

impl YamlMatrix {
    /// The data, checked against `rows`×`cols` (and the shape wanted, when given).
    fn data(&self, key: &str, shape: Option<(usize, usize)>) -> Result<&[f64], String> {
        if self.rows.checked_mul(self.cols) != Some(self.data.len()) {
            return Err(format!(
                "{key}: rows {} × cols {} but {} values",
                self.rows,
                self.cols,
                self.data.len()
            ));
        }
        if let Some((r, c)) = shape
            && (self.rows, self.cols) != (r, c)
        {
            return Err(format!(
                "{key} is {}x{}, expected {r}x{c}",
                self.rows, self.cols
            ));
        }
        Ok(&self.data)
    }
}

impl Intrinsics {
    /// Reads a ROS `camera_info` YAML file.
    ///
    /// # Errors
    /// [`IntrinsicsError::File`] for a missing or oversized file, YAML of another shape (an
    /// unknown key named), or values that are not a camera.
    pub fn load(path: &Path) -> Result<Self, IntrinsicsError> {
        let err = |what: String| IntrinsicsError::File {
            path: path.display().to_string(),
            what,
        };
        let text = crate::input_file::read_text_bounded(
            path,
            crate::input_file::MAX_SMALL_FILE_BYTES,
            "a camera_info YAML file",
        )
        .map_err(|e| err(e.to_string()))?;
        Self::from_yaml(&text).map_err(err)
    }

    /// Parses a `camera_info` YAML text.
    ///
    /// # Errors
    /// What is wrong, as a message.
    pub fn from_yaml(text: &str) -> Result<Self, String> {
        let y: CameraInfoYaml = serde_saphyr::from_str(text)
            .map_err(|e| format!("not a ROS camera_info YAML file: {e}"))?;
        let k = y.camera_matrix.data("camera_matrix", Some((3, 3)))?;
        let d = y
            .distortion_coefficients
            .data("distortion_coefficients", None)?;
        if let Some(m) = &y.rectification_matrix {
            m.data("rectification_matrix", Some((3, 3)))?;
        }
        if let Some(m) = &y.projection_matrix {
            m.data("projection_matrix", Some((3, 4)))?;
        }
        let k: [f64; 9] = k.try_into().map_err(|_| "camera_matrix: 9 values")?;
        Self::from_camera_info(&CameraInfoFields {
            width: y.image_width,
            height: y.image_height,
            camera_name: &y.camera_name,
            k,
            distortion_model: &y.distortion_model,
            d,
        })
    }

    /// The intrinsics of a recording's camera-info message (`sensor_msgs/CameraInfo` or
    /// `foxglove.CameraCalibration`); the camera is named by the message's frame id.
    ///
    /// # Errors
    /// As [`Intrinsics::from_camera_info`].
    pub fn from_message(m: &crate::formats::CameraInfoMessage) -> Result<Self, String> {
        let size = |v: u32| usize::try_from(v).unwrap_or(usize::MAX);
        Self::from_camera_info(&CameraInfoFields {
            width: size(m.width),
            height: size(m.height),
            camera_name: &m.frame_id,
            k: m.k,
            distortion_model: &m.distortion_model,
            d: &m.d,
        })
    }

    /// The intrinsics of a camera info's fields (a YAML file's or a recording message's).
    ///
    /// # Errors
    /// A size of 0 or beyond `MAX_SIDE_PX`, a camera matrix that is not `fx 0 cx / 0 fy cy /
    /// 0 0 1` with positive finite focal lengths, or a distortion model eotn does not know.
    pub fn from_camera_info(info: &CameraInfoFields<'_>) -> Result<Self, String> {
        let (w, h) = (info.width, info.height);
        if !(1..=MAX_SIDE_PX).contains(&w) || !(1..=MAX_SIDE_PX).contains(&h) {
            return Err(format!(
                "image size {w}x{h}: each side must be 1–{MAX_SIDE_PX} pixels"
            ));
        }
        let k = info.k;
        if !k.iter().all(|v| v.is_finite()) {
            return Err("camera_matrix has a value that is not a finite number".into());
        }
        let [fx, skew, cx, k3, fy, cy, k6, k7, k8] = k;
        if skew != 0.0 {
            return Err(format!(
                "camera_matrix has skew {skew} (its second value): eotn's cameras have none"
            ));
        }
        if [k3, k6, k7] != [0.0; 3] || (k8 - 1.0).abs() > 1e-9 {
            return Err("camera_matrix is not fx 0 cx / 0 fy cy / 0 0 1".into());
        }
        if !(fx > 0.0 && fy > 0.0) {
            return Err(format!(
                "camera_matrix focal lengths fx {fx}, fy {fy}: must be positive"
            ));
        }
        let lens = LensModel::from_ros(info.distortion_model, info.d)?;
        Ok(Self {
            camera_name: info.camera_name.to_owned(),
            width_px: w,
            height_px: h,
            fx,
            fy,
            centre: ImagePoint::new(cx + 0.5, cy + 0.5),
            lens,
        })
    }

    /// The intrinsics for frames of `width`×`height`: these, or scaled by a whole factor.
    ///
    /// # Errors
    /// [`IntrinsicsError::FrameSize`] for any other size.
    pub fn for_frame(&self, width: usize, height: usize) -> Result<Self, IntrinsicsError> {
        let (iw, ih) = (self.width_px, self.height_px);
        let whole = |big: usize, small: usize, big2: usize, small2: usize| {
            small > 0
                && big.is_multiple_of(small)
                && big / small >= 2
                && big2 == (big / small) * small2
        };
        let scale = if (width, height) == (iw, ih) {
            1.0
        } else if whole(width, iw, height, ih) {
            (width / iw) as f64
        } else if whole(iw, width, ih, height) {
            1.0 / (iw / width) as f64
        } else {
            return Err(IntrinsicsError::FrameSize {
                name: if self.camera_name.is_empty() {
                    String::new()
                } else {
                    format!(" of {:?}", self.camera_name)
                },
                iw,
                ih,
                w: width,
                h: height,
            });
        };
        Ok(Self {
            width_px: width,
            height_px: height,
            fx: self.fx * scale,
            fy: self.fy * scale,
            centre: ImagePoint::new(self.centre.x_px * scale, self.centre.y_px * scale),
            ..self.clone()
        })
    }

    /// `camera` with these intrinsics (size, focal lengths, principal point, lens); its pose
    /// kept.
    #[must_use]
    pub fn applied_to(&self, camera: OverheadCamera) -> OverheadCamera {
        OverheadCamera {
            width_px: self.width_px,
            height_px: self.height_px,
            focal_px: self.fx,
            focal_y_px: (self.fy != self.fx).then_some(self.fy),
            centre: self.centre,
            k1: 0.0,
            k2: 0.0,
            lens: Some(self.lens),
            ..camera
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A `camera_calibration` file of a 1280×720 fisheye (the shape `camera_calibration`'s
    /// `ost.yaml` has).
    pub(crate) const FISHEYE_YAML: &str = "image_width: 1280
image_height: 720
camera_name: overhead_fisheye
camera_matrix:
  rows: 3
  cols: 3
  data: [522.0, 0.0, 639.5, 0.0, 521.0, 359.5, 0.0, 0.0, 1.0]
distortion_model: equidistant
distortion_coefficients:
  rows: 1
  cols: 4
  data: [-0.02, 0.004, -0.003, 0.0005]
rectification_matrix:
  rows: 3
  cols: 3
  data: [1, 0, 0, 0, 1, 0, 0, 0, 1]
projection_matrix:
  rows: 3
  cols: 4
  data: [522.0, 0, 639.5, 0, 0, 521.0, 359.5, 0, 0, 0, 1, 0]
";

    #[test]
    fn a_camera_calibration_file_reads_in_eotn_pixels() {
        let i = Intrinsics::from_yaml(FISHEYE_YAML).expect("reads");
        assert_eq!(i.camera_name, "overhead_fisheye");
        assert_eq!((i.width_px, i.height_px), (1280, 720));
        assert_eq!((i.fx, i.fy), (522.0, 521.0));
        // ROS pixel centres at whole numbers: the image centre 639.5 is eotn's 640.
        assert_eq!(i.centre, ImagePoint::new(640.0, 360.0));
        assert_eq!(i.lens.ros_name(), "equidistant");
        let cam = i.applied_to(OverheadCamera::above_field_2005());
        assert_eq!(cam.focal_y(), 521.0);
        assert_eq!(cam.lens, Some(i.lens));
    }

    #[test]
    fn a_whole_factor_scales_and_other_sizes_are_refused() {
        let i = Intrinsics::from_yaml(FISHEYE_YAML).expect("reads");
        let half = i.for_frame(640, 360).expect("half");
        assert_eq!((half.fx, half.fy), (261.0, 260.5));
        assert_eq!(half.centre, ImagePoint::new(320.0, 180.0));
        let double = i.for_frame(2560, 1440).expect("double");
        assert_eq!(double.fx, 1044.0);
        let err = i.for_frame(1000, 600).expect_err("not whole");
        let text = err.to_string();
        assert!(
            text.contains("1280x720") && text.contains("1000x600"),
            "{text}"
        );
        // A whole factor in one direction only is another shape.
        assert!(i.for_frame(640, 720).is_err());
    }

    #[test]
    fn broken_files_say_what_is_wrong() {
        let bad = |from: &str, to: &str| {
            Intrinsics::from_yaml(&FISHEYE_YAML.replace(from, to)).expect_err(to)
        };
        assert!(bad("camera_name", "camera_nmae").contains("camera_nmae"));
        assert!(bad("cols: 4\n  data: [-0.02", "cols: 5\n  data: [-0.02").contains("cols 5"));
        assert!(bad("equidistant", "fisheye").contains("plumb_bob, rational_polynomial"));
        assert!(bad("data: [522.0, 0.0,", "data: [522.0, 3.0,").contains("skew"));
        assert!(bad("data: [522.0, 0.0,", "data: [-522.0, 0.0,").contains("positive"));
        assert!(bad("image_width: 1280", "image_width: 0").contains("1–100000"));
        assert!(bad("image_width: 1280", "image_width: [1]").contains("not a ROS camera_info"));
    }
}
