//! `eotn overhead calibrate`: a points file (and optionally a frame to refine along its lines,
//! and the lens's checkerboard intrinsics) → a calibration file, with each fitted parameter's
//! standard deviation and every finding of the review printed; a doubtful calibration is
//! written only with `--accept`.

use std::path::Path;

use anyhow::{Context, bail};
use serde::Serialize;

use super::inputs::load_frame_arg;
use super::overhead::{CalibrateArgs, load_field};
use crate::geometry::OverheadCamera;
use crate::overhead::calibration::{
    Calibration, CalibrationParams, MIN_LINE_SAMPLES, calibrate_with,
};
use crate::overhead::field::FieldDescription;
use crate::overhead::intrinsics::Intrinsics;
use crate::overhead::lines::projected_field_lines;
use crate::overhead::points::PointsFile;
use crate::overhead::review::{Finding, Severity, check_points, review};

/// A finding in `--json`.
#[derive(Debug, Serialize)]
struct FindingJson {
    /// `note`, `doubt` or `refuse`.
    severity: &'static str,
    /// What was found.
    message: String,
}

/// `eotn overhead calibrate --json`: one object.
#[derive(Debug, Serialize)]
struct CalibrateJson<'a> {
    /// The calibration file.
    output: String,
    /// Whether it was written (not when doubtful without `--accept`).
    written: bool,
    /// Median reprojection error of the clicked points, pixels.
    median_error_px: f64,
    /// The calibration, with each parameter's standard deviation in `uncertainty`.
    calibration: &'a Calibration,
    /// Notes and doubts, worst first.
    findings: Vec<FindingJson>,
}

fn severity_name(f: &Finding) -> &'static str {
    match f.severity() {
        Severity::Note => "note",
        Severity::Doubt => "doubt",
        Severity::Refuse => "refuse",
    }
}

/// The intrinsics of `--intrinsics`, named by their file when the file gives no camera name.
fn load_intrinsics(path: &Path, camera: Option<&str>) -> anyhow::Result<Intrinsics> {
    let mut i =
        crate::streams::camera_info::load_intrinsics(path, camera).map_err(anyhow::Error::msg)?;
    if i.camera_name.is_empty() {
        i.camera_name = path.display().to_string();
    }
    Ok(i)
}

/// Runs `eotn overhead calibrate`.
///
/// # Errors
/// Unreadable inputs, a refusal (named), or a doubtful calibration without `--accept`.
pub fn run(a: &CalibrateArgs) -> anyhow::Result<()> {
    // The lines over the image go beside the calibration (not beside a device or FIFO).
    let png = crate::atomic_file::beside_output(&a.output, "lines.png");
    let field = load_field(a.field.as_deref())?;
    let points = PointsFile::load(&a.points)?;
    let intrinsics = a
        .intrinsics
        .as_deref()
        .map(|p| load_intrinsics(p, a.intrinsics_camera.as_deref()))
        .transpose()?;
    let frame = a
        .image
        .as_deref()
        .map(|p| load_frame_arg(p, a.size))
        .transpose()?;
    if let (Some(f), Some(path)) = (&frame, &a.image)
        && (f.width(), f.height()) != (points.width, points.height)
    {
        bail!(
            "{}: the frame is {}x{}, the points are for {}x{}",
            path.display(),
            f.width(),
            f.height(),
            points.width,
            points.height
        );
    }
    let notes = check_points(&points, &field)
        .map_err(|f| anyhow::anyhow!("{}: {f}", a.points.display()))?;
    let params = CalibrationParams {
        refine_lines: !a.no_lines,
        ..CalibrationParams::default()
    };
    let cal = calibrate_with(
        &points,
        &field,
        frame.as_ref(),
        &params,
        intrinsics.as_ref(),
    )
    .with_context(|| match &a.intrinsics {
        Some(i) => format!("{} with {}", a.points.display(), i.display()),
        None => a.points.display().to_string(),
    })?;
    let review = review(&cal);
    let findings: Vec<&Finding> = notes.iter().chain(&review.findings).collect();
    let doubts = findings
        .iter()
        .filter(|f| f.severity() == Severity::Doubt)
        .count();
    let written = doubts == 0 || a.accept;
    if a.json {
        let json = CalibrateJson {
            output: a.output.display().to_string(),
            written,
            median_error_px: cal.median_point_error_px(),
            calibration: &cal,
            findings: findings
                .iter()
                .map(|f| FindingJson {
                    severity: severity_name(f),
                    message: f.to_string(),
                })
                .collect(),
        };
        println!("{}", serde_json::to_string(&json)?);
    } else {
        print_calibration(&cal);
    }
    for f in &findings {
        log::warn!("{}: {f}", a.points.display());
    }
    if frame.is_some() && !a.no_lines && cal.line_samples == 0 {
        log::warn!(
            "line refinement skipped: fewer than {MIN_LINE_SAMPLES} samples of the field lines were found in the image (is it this camera's frame?); the fit rests on the clicked points alone"
        );
    }
    if !written {
        bail!(
            "{}: not written: the calibration is doubtful ({doubts} warnings above); check the clicks, the field description and its units, or give --accept to keep it",
            a.output.display(),
        );
    }
    cal.save(&a.output)?;
    if let (Some(f), Some(png)) = (&frame, &png) {
        write_lines_png(png, f, &field, &cal.camera)?;
        if !a.json {
            println!("field lines over the image: {}", png.display());
        }
    }
    Ok(())
}

/// ` ± SD` when the standard deviation is known.
fn pm(sd: Option<f64>, digits: usize) -> String {
    sd.map(|v| format!(" ± {v:.digits$}")).unwrap_or_default()
}

fn print_calibration(cal: &Calibration) {
    let c = &cal.camera;
    let u = cal.uncertainty.as_ref();
    let [x, y, z] = c.pose.position_cm;
    let sd = |k: usize| u.map(|u| u.position_cm[k]);
    println!(
        "camera at ({x:.1}{}, {y:.1}{}, {z:.1}{}) cm, yaw {:.2}° pitch {:.2}° roll {:.2}°",
        pm(sd(0), 1),
        pm(sd(1), 1),
        pm(sd(2), 1),
        c.pose.yaw_rad.to_degrees(),
        c.pose.pitch_rad.to_degrees(),
        c.pose.roll_rad.to_degrees()
    );
    if let Some(u) = u {
        let [a, b, g] = u.rotation_deg;
        println!(
            "  rotation ± ({a:.2}°, {b:.2}°, {g:.2}°) about field x, y, z; standard deviations for {:.2} px of click error",
            u.residual_sd_px
        );
    }
    match (&cal.intrinsics, c.lens) {
        (Some(source), Some(lens)) => println!(
            "intrinsics from {source}: fx {:.2} px, fy {:.2} px, principal point ({:.2}, {:.2}) px, {} {:?} (only the pose was fitted)",
            c.focal_px,
            c.focal_y(),
            c.centre.x_px,
            c.centre.y_px,
            lens.ros_name(),
            lens.coefficients()
        ),
        _ => println!(
            "focal {:.2}{} px, principal point ({:.2}{}, {:.2}{}) px, k1 {:.5}{}, k2 {:.5}{}",
            c.focal_px,
            pm(u.and_then(|u| u.focal_px), 2),
            c.centre.x_px,
            pm(u.and_then(|u| u.centre_px.map(|p| p[0])), 2),
            c.centre.y_px,
            pm(u.and_then(|u| u.centre_px.map(|p| p[1])), 2),
            c.k1,
            pm(u.and_then(|u| u.k1), 5),
            c.k2,
            pm(u.and_then(|u| u.k2), 5),
        ),
    }
    println!("reprojection error per point:");
    for p in &cal.points {
        println!(
            "  {:<42} {:6.2} px  (clicked {:.1}, {:.1})",
            p.name, p.error_px, p.image_px[0], p.image_px[1]
        );
    }
    println!(
        "median {:.3} px over {} points",
        cal.median_point_error_px(),
        cal.points.len()
    );
    if let Some(rms) = cal.line_rms_px {
        println!(
            "line refinement: {} samples, rms {rms:.3} px",
            cal.line_samples
        );
    }
}

/// The frame with the field lines projected through `camera` drawn over it, as a PNG.
fn write_lines_png(
    path: &Path,
    frame: &crate::frame::Frame,
    field: &FieldDescription,
    camera: &OverheadCamera,
) -> anyhow::Result<()> {
    let mut canvas =
        crate::overlay::Canvas::from_rgb(frame.width(), frame.height(), &frame.to_rgb(), 1)
            .context("frame size")?;
    for curve in projected_field_lines(field, camera) {
        for pair in curve.windows(2) {
            canvas.line(pair[0], pair[1], [255, 40, 200]);
        }
    }
    crate::frame::save_rgb_png(path, canvas.width, canvas.height, &canvas.rgb)?;
    Ok(())
}
