//! The undistorted view: an overhead frame as a pinhole camera with the same focal length and
//! principal point would have seen it, so straight field lines look straight.

use crate::frame::{Frame, FrameError, Yuv};
use crate::geometry::OverheadCamera;

/// Resamples `frame` (nearest pixel) through `camera`'s lens model into an undistorted YUV
/// 4:4:4 frame of the same size; pixels whose source lies outside the frame are black.
///
/// # Errors
/// [`FrameError`] only if the frame's size is unusable.
pub fn undistorted(frame: &Frame, camera: &OverheadCamera) -> Result<Frame, FrameError> {
    let (w, h) = (frame.width(), frame.height());
    // The calibration may be for another size: scale pixel positions to this frame.
    let sx = w as f64 / camera.width_px.max(1) as f64;
    let sy = h as f64 / camera.height_px.max(1) as f64;
    let black = Yuv {
        y: 16,
        u: 128,
        v: 128,
    };
    Frame::yuv444_from_fn(w, h, |x, y| {
        let u = ((x as f64 + 0.5) / sx - camera.centre.x_px) / camera.focal_px;
        let v = ((y as f64 + 0.5) / sy - camera.centre.y_px) / camera.focal_px;
        let (ud, vd) = camera.distort(u, v);
        let (px, py) = (
            (camera.centre.x_px + camera.focal_px * ud) * sx,
            (camera.centre.y_px + camera.focal_px * vd) * sy,
        );
        if px >= 0.0 && py >= 0.0 && px.is_finite() && py.is_finite() {
            frame.pixel(px as usize, py as usize).unwrap_or(black)
        } else {
            black
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{ImagePoint, Point};

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
