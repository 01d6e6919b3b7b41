//! The timeline bar under the views: previous/play/next, speed, the frame number, the time and
//! the slider with the events' and bookmarks' marks.

use super::{Command, EotnApp, bookmarks_panel, menus, robots_panel};
use crate::workspace::{PlaybackCommand, SPEEDS};

impl EotnApp {
    /// The timeline bar's contents (nothing without an open source).
    pub(super) fn timeline_ui(&mut self, ui: &mut egui::Ui, commands: &mut Vec<Command>) {
        let Some(src) = self.state.source() else {
            return;
        };
        let len = src.len();
        let index = self.state.index();
        ui.horizontal(|ui| {
            robots_panel::live_controls_ui(ui, &self.state, commands);
            if ui.button("Previous").on_hover_text("Left arrow").clicked() {
                commands.push(PlaybackCommand::Step(-1).into());
            }
            let play = if self.state.playing() {
                "Pause"
            } else {
                "Play"
            };
            if ui.button(play).on_hover_text("Space").clicked() {
                commands.push(PlaybackCommand::SetPlaying(!self.state.playing()).into());
            }
            if ui.button("Next").on_hover_text("Right arrow").clicked() {
                commands.push(PlaybackCommand::Step(1).into());
            }
            let mut speed = self.state.settings.speed;
            egui::ComboBox::from_label("speed")
                .selected_text(menus::speed_name(speed))
                .width(90.0)
                .show_ui(ui, |ui| {
                    for s in SPEEDS {
                        ui.selectable_value(&mut speed, s, menus::speed_name(s));
                    }
                });
            if (speed - self.state.settings.speed).abs() > f32::EPSILON {
                commands.push(PlaybackCommand::SetSpeed(speed).into());
            }
            let mut i = index;
            ui.label("frame");
            if ui
                .add(egui::DragValue::new(&mut i).range(0..=len.saturating_sub(1)))
                .on_hover_text("type a frame number to jump")
                .changed()
            {
                commands.push(PlaybackCommand::Seek(i).into());
            }
            let t = src.time_ns(index) as f64 / 1e9;
            let end = src.time_ns(len.saturating_sub(1)) as f64 / 1e9;
            ui.monospace(format!(
                "/ {}  {t:8.3} s / {end:.3} s",
                len.saturating_sub(1)
            ));
            ui.spacing_mut().slider_width = (ui.available_width() - 70.0).max(100.0);
            let mut j = index;
            let slider = ui.add(
                egui::Slider::new(&mut j, 0..=len.saturating_sub(1))
                    .show_value(false)
                    .text("timeline"),
            );
            if slider.changed() {
                commands.push(PlaybackCommand::Seek(j).into());
            }
            // The marks go along the slider's track: its response also covers the text after
            // it, and marks spread over that ended a label's width past the last frame.
            let track = egui::Rect::from_min_size(
                slider.rect.min,
                egui::vec2(ui.spacing().slider_width, slider.rect.height()),
            );
            bookmarks_panel::timeline_marks(ui.painter(), track, &self.state, len);
            self.last_timeline_track = Some(track);
        });
    }
}
