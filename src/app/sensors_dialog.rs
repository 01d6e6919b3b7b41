//! The sensor dialog: every reading of the current frame with its unit, live during playback,
//! the numeric readings of other channels (a ROS `JointState`'s joints), and plots of head pan,
//! pan velocity, the pan motor's PWM and those channels over the stream with a cursor at the
//! current frame.

use egui::{Color32, Id};
use egui_plot::{Legend, Line, Plot, VLine};

use crate::sensors::{SensorReadings, channel_readings};
use crate::workspace::Workspace;

/// The Sensors window's contents: every reading of the shown frame with units, plots over
/// the stream.
pub fn sensors_ui(ui: &mut egui::Ui, state: &Workspace) {
    let Some(current) = state.current() else {
        ui.label("No frame open.");
        return;
    };
    // With several cameras, the readings are those of the camera shown (focused).
    let camera = match state.cameras() {
        (all, Some(camera)) if all.len() > 1 => format!("camera {}, ", camera.topic()),
        _ => String::new(),
    };
    ui.label(format!(
        "{camera}frame {} at {:.3} s",
        state.index(),
        current.time_ns as f64 / 1e9
    ));
    match &current.sensors {
        None => {
            ui.weak("This frame carries no sensor readings.");
        }
        Some(r) => readings_grid_ui(ui, r),
    }
    let (readings, others): (Vec<_>, Vec<_>) = current
        .extra
        .iter()
        .partition(|(_, value)| !channel_readings(value).is_empty());
    for (channel, value) in readings {
        channel_grid_ui(ui, channel, &channel_readings(value));
    }
    if !others.is_empty() {
        egui::CollapsingHeader::new("Other channels")
            .default_open(false)
            .show(ui, |ui| {
                for (channel, value) in others {
                    ui.monospace(format!("{channel}: {value}"));
                }
            });
    }
    ui.separator();
    series_plots_ui(ui, state, current.time_ns as f64 / 1e9);
}

fn readings_grid_ui(ui: &mut egui::Ui, r: &SensorReadings) {
    egui::Grid::new("sensor_readings")
        .striped(true)
        .num_columns(3)
        .show(ui, |ui| {
            for f in r.fields() {
                ui.label(f.name);
                match f.value {
                    Some(v) => ui.monospace(format!("{v:>10.4}")),
                    None => ui.weak("—"),
                };
                ui.label(f.unit);
                ui.end_row();
            }
            ui.label("pan velocity");
            match r.pan_velocity_rad_per_s() {
                Some(v) => ui.monospace(format!("{v:>10.4}")),
                None => ui.weak("—"),
            };
            ui.label("rad/s");
            ui.end_row();
        });
}

/// One channel's numeric readings (a `JointState`'s joints: name, position in rad).
fn channel_grid_ui(ui: &mut egui::Ui, channel: &str, readings: &[(&str, f64)]) {
    ui.strong(channel);
    egui::Grid::new(("channel_readings", channel))
        .striped(true)
        .num_columns(2)
        .show(ui, |ui| {
            for (name, v) in readings {
                ui.label(*name);
                ui.monospace(format!("{v:>10.4}"));
                ui.end_row();
            }
        });
}

fn series_plots_ui(ui: &mut egui::Ui, state: &Workspace, now_s: f64) {
    let series = &state.sensor_series;
    if series.total == 0 {
        ui.weak("Plots need a recorded stream.");
        return;
    }
    if series.points.len() < series.total {
        ui.add(
            egui::ProgressBar::new(series.points.len() as f32 / series.total as f32)
                .text("reading the stream's sensors…"),
        );
    }
    type Get = fn(&SensorReadings) -> Option<f64>;
    let plots: [(&str, &str, Get, Color32); 3] = [
        ("head pan", "rad", |r| r.head_pan_rad, Color32::LIGHT_BLUE),
        (
            "pan velocity",
            "rad/s",
            SensorReadings::pan_velocity_rad_per_s,
            Color32::LIGHT_GREEN,
        ),
        (
            "pan PWM",
            "duty",
            |r| r.pan_pwm,
            Color32::from_rgb(255, 160, 60),
        ),
    ];
    let link = Id::unique("sensor_plots");
    for (name, unit, get, colour) in plots {
        let points: Vec<[f64; 2]> = series
            .points
            .iter()
            .filter_map(|(t, r)| r.as_ref().and_then(get).map(|v| [*t, v]))
            .collect();
        Plot::new(name)
            .height(110.0)
            .legend(Legend::default())
            .link_axis(link, [true, false])
            .link_cursor(link, [true, false])
            .y_axis_label(unit)
            .show(ui, |p| {
                p.line(Line::new(format!("{name} ({unit})"), points).color(colour));
                p.vline(VLine::new("current frame", now_s).color(Color32::WHITE));
            });
    }
    if !series.channels.is_empty() {
        Plot::new("other channels")
            .height(140.0)
            .legend(Legend::default())
            .link_axis(link, [true, false])
            .link_cursor(link, [true, false])
            .show(ui, |p| {
                for (name, points) in &series.channels {
                    p.line(Line::new(name.clone(), points.clone()));
                }
                p.vline(VLine::new("current frame", now_s).color(Color32::WHITE));
            });
    }
}
