//! The undistorted view: an overhead frame as a pinhole camera with the same focal length and
//! principal point would have seen it, so straight field lines look straight.

use crate::frame::{Frame, FrameError, Yuv};
use crate::geometry::{ImagePoint, OverheadCamera};

/// Resamples `frame` (nearest pixel) through `camera`'s lens model into an undistorted YUV
/// 4:4:4 frame of the same size; pixels whose source lies outside the frame are black.
///
/// # Errors
/// [`FrameError`] only if the frame's size is unusable.
pub fn undistorted(frame: &Frame, camera: &OverheadCamera) -> Result<Frame, FrameError> {
    let (w, h) = (frame.width(), frame.height());
    let map = source_pixel_map(camera, w, h);
    let black = Yuv {
        y: 16,
        u: 128,
        v: 128,
    };
    Frame::yuv444_from_fn(w, h, |x, y| {
        map.get(y * w + x)
            .and_then(|&k| k)
            .and_then(|k| frame.pixel(k as usize % w, k as usize / w))
            .unwrap_or(black)
    })
}

/// Scale from the calibration's image size to a frame of `size` (width, height) pixels.
fn scale(camera: &OverheadCamera, size: (usize, usize)) -> (f64, f64) {
    (
        size.0 as f64 / camera.width_px.max(1) as f64,
        size.1 as f64 / camera.height_px.max(1) as f64,
    )
}

/// For every pixel of the undistorted view of a `width`×`height` frame (row by row), the index
/// (`y · width + x`) of the camera's pixel it shows, or `None` where that lies outside the
/// frame: one table the app remaps its colour and class images with.
#[must_use]
pub fn source_pixel_map(camera: &OverheadCamera, width: usize, height: usize) -> Vec<Option<u32>> {
    let mut out = Vec::with_capacity(width * height);
    for y in 0..height {
        for x in 0..width {
            let p = distorted_point(
                ImagePoint::new(x as f64 + 0.5, y as f64 + 0.5),
                camera,
                (width, height),
            );
            let inside =
                p.x_px >= 0.0 && p.y_px >= 0.0 && p.x_px < width as f64 && p.y_px < height as f64;
            out.push(
                inside
                    .then(|| u32::try_from(p.y_px as usize * width + p.x_px as usize).ok())
                    .flatten(),
            );
        }
    }
    out
}

/// The camera's image point (pixels of a frame of `size`) that the undistorted view shows at
/// `p`.
#[must_use]
pub fn distorted_point(p: ImagePoint, camera: &OverheadCamera, size: (usize, usize)) -> ImagePoint {
    let (sx, sy) = scale(camera, size);
    let u = (p.x_px / sx - camera.centre.x_px) / camera.focal_px;
    let v = (p.y_px / sy - camera.centre.y_px) / camera.focal_y();
    let (ud, vd) = camera.distort(u, v);
    ImagePoint::new(
        (camera.centre.x_px + camera.focal_px * ud) * sx,
        (camera.centre.y_px + camera.focal_y() * vd) * sy,
    )
}

/// Where the camera's image point `p` (pixels of a frame of `size`) is in the undistorted
/// view; `None` where the lens model cannot be inverted.
#[must_use]
pub fn undistorted_point(
    p: ImagePoint,
    camera: &OverheadCamera,
    size: (usize, usize),
) -> Option<ImagePoint> {
    let (sx, sy) = scale(camera, size);
    let ud = (p.x_px / sx - camera.centre.x_px) / camera.focal_px;
    let vd = (p.y_px / sy - camera.centre.y_px) / camera.focal_y();
    let (u, v) = camera.undistort(ud, vd)?;
    Some(ImagePoint::new(
        (camera.centre.x_px + camera.focal_px * u) * sx,
        (camera.centre.y_px + camera.focal_y() * v) * sy,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Point;

    #[test]
    fn view_points_go_there_and_back() {
        let camera = OverheadCamera::above_field_2005();
        for (x, y) in [(10.0, 12.0), (320.0, 240.0), (600.5, 470.25)] {
            let p = ImagePoint::new(x, y);
            let q = undistorted_point(p, &camera, (640, 480)).expect("invertible");
            let back = distorted_point(q, &camera, (640, 480));
            assert!(back.distance_to(&p) < 1e-3, "{p:?} -> {q:?} -> {back:?}");
        }
        // Twice the size: the same place, twice the pixels.
        let p = ImagePoint::new(100.0, 80.0);
        let q1 = undistorted_point(p, &camera, (640, 480)).expect("invertible");
        let q2 = undistorted_point(ImagePoint::new(200.0, 160.0), &camera, (1280, 960))
            .expect("invertible");
        assert!((q2.x_px - 2.0 * q1.x_px).abs() < 1e-6 && (q2.y_px - 2.0 * q1.y_px).abs() < 1e-6);
    }

    #[test]
    fn a_bent_side_line_comes_out_straight() {
        let camera = OverheadCamera::above_field_2005();
        // A frame that is white where the side line y = 178.75 cm projects, grey elsewhere.
        let frame = Frame::yuv444_from_fn(640, 480, |x, y| {
            let g = camera.field_from_image(ImagePoint::pixel_centre(x, y), 0.0);
            let on = g.is_some_and(|g| (g.y() - 178.75).abs() < 1.5 && g.x().abs() < 260.0);
            Yuv {
                y: if on { 235 } else { 60 },
                u: 128,
                v: 128,
            }
        })
        .expect("frame");
        let out = undistorted(&frame, &camera).expect("undistorts");
        // In the pinhole image the line is the row where a pinhole projects y = 178.75.
        let pinhole = OverheadCamera {
            k1: 0.0,
            k2: 0.0,
            ..camera
        };
        let rows: Vec<f64> = [-240.0, 0.0, 240.0]
            .iter()
            .map(|&x| {
                let p = pinhole
                    .image_from_field(&Point::new(x, 178.75, 0.0))
                    .expect("seen");
                let col = p.x_px as usize;
                let bright: Vec<usize> = (0..480)
                    .filter(|&r| out.pixel(col, r).is_some_and(|q| q.y > 150))
                    .collect();
                assert!(!bright.is_empty(), "line at column {col}");
                bright.iter().sum::<usize>() as f64 / bright.len() as f64
            })
            .collect();
        assert!(
            (rows[0] - rows[1]).abs() < 1.5 && (rows[2] - rows[1]).abs() < 1.5,
            "{rows:?}"
        );
    }
}
