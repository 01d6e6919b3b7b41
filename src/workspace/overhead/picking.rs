//! Picking calibration points in the image and solving the camera from them: the landmark a
//! left click picks (and the next one not picked after each click, Skip, Undo), Calibrate, and
//! ending the picking so that a click samples colours again.

use anyhow::Context as _;

use super::{MIN_CALIBRATION_POINTS, PickEdit};
use crate::overhead::calibration::{CalibrationParams, calibrate_with};
use crate::overhead::{CalibrationPoint, PointsFile};
use crate::workspace::Workspace;

impl Workspace {
    pub(super) fn choose_landmark(&mut self, name: Option<String>) -> anyhow::Result<()> {
        if let Some(n) = &name {
            anyhow::ensure!(
                self.overhead.field.landmark(n).is_some(),
                "no landmark {n:?} in the field {}",
                self.overhead.field.name
            );
            self.status = format!("click {n} in the image");
        }
        self.overhead.landmark = name;
        Ok(())
    }

    pub(super) fn pick_point(&mut self, x_px: f64, y_px: f64) -> anyhow::Result<()> {
        let name = self
            .overhead
            .landmark
            .clone()
            .context("choose a landmark first (Calibration window)")?;
        let (w, h) = self.image_size();
        anyhow::ensure!(w > 0, "no frame to pick on");
        anyhow::ensure!(
            x_px.is_finite()
                && y_px.is_finite()
                && (0.0..w as f64).contains(&x_px)
                && (0.0..h as f64).contains(&y_px),
            "({x_px:.1}, {y_px:.1}) is outside the {w}×{h} frame"
        );
        let l = self
            .overhead
            .field
            .landmark(&name)
            .with_context(|| format!("no landmark {name:?}"))?
            .clone();
        if (self.overhead.points.width, self.overhead.points.height) != (w, h) {
            anyhow::ensure!(
                self.overhead.points.points.is_empty(),
                "the picked points are for a {}×{} frame, this one is {w}×{h}",
                self.overhead.points.width,
                self.overhead.points.height
            );
            self.overhead.points = PointsFile::new(w, h);
        }
        let replaced = self
            .overhead
            .points
            .points
            .iter()
            .find(|p| p.name == name)
            .cloned();
        self.overhead.points.set(CalibrationPoint {
            name: name.clone(),
            field_cm: l.field_cm,
            height_cm: l.height_cm,
            image_px: [x_px, y_px],
        });
        self.overhead.picks.push(PickEdit {
            name: name.clone(),
            replaced,
        });
        // The next landmark not yet picked, so clicking round the field needs no menu.
        let next = self.next_unpicked_landmark(&name);
        self.status = format!(
            "{name} at ({x_px:.1}, {y_px:.1}) px; {} points{}",
            self.overhead.points.points.len(),
            next.as_ref()
                .map(|n| format!("; next: {n}"))
                .unwrap_or_default()
        );
        self.overhead.landmark = next;
        Ok(())
    }

    /// The first landmark not yet picked after `after` in the field's order, going round to
    /// the start; `None` when every landmark but `after` is picked.
    fn next_unpicked_landmark(&self, after: &str) -> Option<String> {
        let landmarks = &self.overhead.field.landmarks;
        let picked = |n: &str| self.overhead.points.points.iter().any(|p| p.name == n);
        let start = landmarks
            .iter()
            .position(|l| l.name == after)
            .map_or(0, |i| i + 1);
        (0..landmarks.len())
            .map(|k| &landmarks[(start + k) % landmarks.len()].name)
            .find(|n| n.as_str() != after && !picked(n))
            .cloned()
    }

    pub(super) fn skip_landmark(&mut self) -> anyhow::Result<()> {
        let current = self
            .overhead
            .landmark
            .clone()
            .context("not picking: choose a landmark first")?;
        let next = self.next_unpicked_landmark(&current);
        self.status = match &next {
            Some(n) => format!("skipped {current}; click {n} in the image"),
            None => format!("skipped {current}; every other landmark is picked"),
        };
        self.overhead.landmark = next;
        Ok(())
    }

    pub(super) fn undo_pick(&mut self) -> anyhow::Result<()> {
        let edit = self
            .overhead
            .picks
            .pop()
            .context("no picked point to undo")?;
        self.overhead.points.remove(&edit.name);
        if let Some(old) = edit.replaced {
            self.overhead.points.set(old);
        }
        self.overhead.landmark = Some(edit.name.clone());
        self.status = format!("undid the pick of {}", edit.name);
        Ok(())
    }

    pub(super) fn calibrate_from_points(&mut self) -> anyhow::Result<()> {
        let n = self.overhead.points.points.len();
        anyhow::ensure!(
            n >= MIN_CALIBRATION_POINTS,
            "{n} points picked: calibration needs at least {MIN_CALIBRATION_POINTS}"
        );
        let frame = self.frame().cloned();
        let frame = frame.filter(|f| {
            (f.width(), f.height()) == (self.overhead.points.width, self.overhead.points.height)
        });
        let notes =
            crate::overhead::review::check_points(&self.overhead.points, &self.overhead.field)?;
        let cal = calibrate_with(
            &self.overhead.points,
            &self.overhead.field,
            frame.as_ref(),
            &CalibrationParams::default(),
            self.overhead.intrinsics.as_ref().map(|(i, _)| i),
        )?;
        let review = crate::overhead::review::review(&cal);
        for f in notes.iter().chain(&review.findings) {
            self.warn(format!("calibration: {f}"));
        }
        if frame.is_some() && cal.line_samples == 0 {
            self.warn(format!(
                "calibration: line refinement skipped: fewer than {} samples of the field lines found in the frame",
                crate::overhead::calibration::MIN_LINE_SAMPLES
            ));
        }
        self.status = format!(
            "calibrated from {n} points: median error {:.2} px{}",
            cal.median_point_error_px(),
            cal.line_rms_px
                .map(|r| format!(", lines {r:.2} px rms over {} samples", cal.line_samples))
                .unwrap_or_default()
        );
        self.overhead.user_calibration = Some(cal);
        self.overhead.calibration_path = None;
        // Calibrated: picking is over, and the next left click samples for classification
        // (a landmark left armed silently added points the next Calibrate would use).
        self.disarm_landmark_picking();
        self.reprocess();
        Ok(())
    }

    /// Stops picking landmarks: the next left click in the image samples for classification.
    /// Calibrate, choosing a class and closing the Calibration window do this.
    pub(in crate::workspace) fn disarm_landmark_picking(&mut self) {
        self.overhead.landmark = None;
    }

    /// What a left click in the image does now, for the view's corner: "pick ‹landmark›"
    /// while picking calibration points on an overhead frame, else "sample".
    #[must_use]
    pub fn left_click_mode(&self) -> String {
        match self.overhead.landmark() {
            Some(l) if self.overhead.active => format!("left click: pick {l}"),
            _ => format!("left click: sample {}", self.settings.class.name()),
        }
    }
}
