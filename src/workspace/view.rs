//! The workspace's view options: which view is enlarged, overlays, blob connectivity and filter,
//! zoom and pan, Export view, the U–V plane's Y, the timings readout; and which windows are open.

use super::{ViewCommand, ViewTransform, Window, Workspace, ZOOM_RANGE};
use crate::frame::save_rgb_png;

impl Workspace {
    /// Applies the view commands (the rest of [`Workspace::apply`]).
    pub(super) fn apply_view(&mut self, command: ViewCommand) -> anyhow::Result<()> {
        match command {
            ViewCommand::SetMainView(v) => self.settings.main_view = v,
            ViewCommand::SetOverlays(o) => {
                let mut o = o;
                o.opacity = if o.opacity.is_finite() {
                    o.opacity.clamp(0.0, 1.0)
                } else {
                    0.5
                };
                self.settings.overlays = o;
            }
            ViewCommand::SetConnectivity(c) => {
                self.settings.connectivity = c;
                let mut params = *self.pipeline.params();
                params.connectivity = c;
                self.pipeline.set_params(params);
                self.reprocess();
            }
            ViewCommand::SetBlobFilter { min_pixels, hidden } => {
                self.settings.min_blob_pixels = min_pixels;
                self.settings.hidden_blob_classes = hidden;
            }
            ViewCommand::SetZoom(z) => {
                self.settings.transform.zoom = z.filter(|z| z.is_finite()).map(clamp_zoom);
            }
            ViewCommand::ZoomAbout { factor, about, fit } => self.zoom_about(factor, about, fit)?,
            ViewCommand::Pan(d) => {
                let size = self.image_size_f32();
                let t = &mut self.settings.transform;
                let c = t.effective_centre(size);
                t.centre = Some([c[0] - d[0], c[1] - d[1]]);
            }
            ViewCommand::ResetView => self.settings.transform = ViewTransform::default(),
            ViewCommand::ExportView(p) => {
                let (w, h, rgb) = self.compose_view_rgb(self.settings.main_view)?;
                save_rgb_png(&p, w, h, &rgb)?;
                self.status = format!("view saved as {}", p.display());
            }
            ViewCommand::SetUvPlaneY(y) => self.settings.uv_plane_y = y,
            ViewCommand::ShowTimings(on) => self.settings.show_timings = on,
        }
        Ok(())
    }

    fn zoom_about(&mut self, factor: f32, about: [f32; 2], fit: f32) -> anyhow::Result<()> {
        anyhow::ensure!(
            factor.is_finite() && factor > 0.0 && fit.is_finite() && fit > 0.0,
            "bad zoom factor"
        );
        let size = self.image_size_f32();
        let t = &mut self.settings.transform;
        let old = t.effective_zoom(fit);
        let new = clamp_zoom(old * factor);
        let c = t.effective_centre(size);
        // Keep `about` at the same screen offset from the view centre.
        let k = old / new;
        t.centre = Some([
            about[0] - (about[0] - c[0]) * k,
            about[1] - (about[1] - c[1]) * k,
        ]);
        t.zoom = Some(new);
        Ok(())
    }

    /// Whether a window is open.
    #[must_use]
    pub const fn window_open(&self, w: Window) -> bool {
        match w {
            Window::Sensors => self.settings.show_sensors,
            Window::UvPlane => self.settings.show_uv_plane,
            Window::TryEdit => self.settings.show_try_edit,
            Window::Inspector => self.settings.show_inspector,
            Window::Connect => self.settings.show_connect,
            Window::SourceSettings => self.settings.show_source_settings,
            Window::Record => self.settings.show_record,
            Window::FieldView => self.settings.show_field_view,
            Window::Calibration => self.settings.show_calibration,
            Window::Robots => self.settings.show_robots,
            Window::Coverage => self.settings.show_coverage,
            Window::Bookmarks => self.settings.show_bookmarks,
            Window::Parameters => self.settings.show_params,
        }
    }

    pub(super) fn window_flag(&mut self, w: Window) -> &mut bool {
        match w {
            Window::Sensors => &mut self.settings.show_sensors,
            Window::UvPlane => &mut self.settings.show_uv_plane,
            Window::TryEdit => &mut self.settings.show_try_edit,
            Window::Inspector => &mut self.settings.show_inspector,
            Window::Connect => &mut self.settings.show_connect,
            Window::SourceSettings => &mut self.settings.show_source_settings,
            Window::Record => &mut self.settings.show_record,
            Window::FieldView => &mut self.settings.show_field_view,
            Window::Calibration => &mut self.settings.show_calibration,
            Window::Robots => &mut self.settings.show_robots,
            Window::Coverage => &mut self.settings.show_coverage,
            Window::Bookmarks => &mut self.settings.show_bookmarks,
            Window::Parameters => &mut self.settings.show_params,
        }
    }

    fn image_size_f32(&self) -> [f32; 2] {
        let (w, h) = self.image_size();
        [w as f32, h as f32]
    }
}

fn clamp_zoom(z: f32) -> f32 {
    z.clamp(ZOOM_RANGE.0, ZOOM_RANGE.1)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zoom_about_keeps_the_point_under_the_cursor() {
        let mut s = Workspace::default();
        // No frame: image size 0; centre defaults to (0, 0).
        s.apply(
            ViewCommand::ZoomAbout {
                factor: 2.0,
                about: [10.0, 20.0],
                fit: 1.0,
            }
            .into(),
        )
        .unwrap();
        let t = s.settings.transform;
        assert_eq!(t.zoom, Some(2.0));
        // Screen offset of `about` from the centre: before (10 - 0) * 1, after (10 - c) * 2.
        let c = t.centre.unwrap();
        assert!(((10.0 - c[0]) * 2.0 - 10.0).abs() < 1e-4);
        assert!(((20.0 - c[1]) * 2.0 - 20.0).abs() < 1e-4);
        s.apply(ViewCommand::SetZoom(Some(1000.0)).into()).unwrap();
        assert_eq!(s.settings.transform.zoom, Some(ZOOM_RANGE.1));
        s.apply(ViewCommand::ResetView.into()).unwrap();
        assert_eq!(s.settings.transform, ViewTransform::default());
    }
}
