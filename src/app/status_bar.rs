//! The status bar (warnings button, step timings, the last command's message, the renderer)
//! and the two windows it opens: the warnings list and Help ▸ About.

use std::time::Duration;

use super::{EotnApp, views};
use crate::workspace::median;

impl EotnApp {
    /// The status bar's contents.
    pub(super) fn status_ui(&mut self, ui: &mut egui::Ui) {
        ui.horizontal(|ui| {
            let n = self.state.warnings().len();
            let label = match n {
                0 => "no warnings".to_owned(),
                1 => "1 warning".to_owned(),
                _ => format!("{n} warnings"),
            };
            let button = egui::Button::new(label).selected(self.show_warnings);
            if ui.add_enabled(n > 0, button).clicked() {
                self.show_warnings = !self.show_warnings;
            }
            let s = self.state.timings.last_step;
            let ms = |d: Duration| d.as_secs_f64() * 1e3;
            if self.state.settings.show_timings {
            ui.monospace(format!(
                "step {:.1} ms (read {:.1} classify {:.1} blobs {:.1} recognition {:.1} prep {:.1} upload {:.1}) | frame {:.1} ms",
                ms(s.total()),
                ms(s.read),
                ms(s.classify),
                ms(s.blobs),
                ms(s.recognition),
                ms(s.prepare),
                ms(s.upload),
                self.state.timings.frames_ms.last().copied().unwrap_or(0.0),
            ))
            .on_hover_text(format!(
                "medians: step {:.2} ms, frame {:.2} ms, playing {:.2} ms",
                median(&self.state.timings.steps_ms),
                median(&self.state.timings.frames_ms),
                median(&self.state.timings.playing_frames_ms),
            ));
            }
            ui.separator();
            ui.label(&self.state.status);
            if let Some(r) = &self.renderer {
                ui.with_layout(egui::Layout::right_to_left(egui::Align::Center), |ui| {
                    let b = ui
                        .small_button(r.kind.name())
                        .on_hover_text(format!("{}: {}", r.adapter, r.reason));
                    if b.clicked() {
                        self.show_about = !self.show_about;
                    }
                });
            }
        });
        // This frame's own problems (NaN sensor readings, skipped channels) stay in view while
        // it is shown, not only in the warnings list.
        if let Some(c) = self.state.current()
            && !c.warnings.is_empty()
        {
            let colour = ui.visuals().warn_fg_color;
            for w in &c.warnings {
                ui.colored_label(colour, format!("this frame: {w}"));
            }
        }
        ui.horizontal(|ui| {
            views::pixel_readout_ui(ui, self.hovered.as_ref());
            // Why this pixel has its class: the edit that last set its cell. A "|", not a
            // separator: a styled widget appearing costs egui two more repaints.
            if let Some(o) = self
                .hovered
                .as_ref()
                .and_then(|h| self.state.pixel_origin(h.x, h.y))
            {
                ui.monospace(format!("| {o}"));
            }
        });
    }

    pub(super) fn warnings_window(&mut self, ctx: &egui::Context) {
        if !self.show_warnings {
            return;
        }
        let mut open = true;
        let mut clear = false;
        egui::Window::new("Warnings")
            .open(&mut open)
            .default_width(520.0)
            .show(ctx, |ui| {
                if ui.button("Clear").clicked() {
                    clear = true;
                }
                egui::ScrollArea::vertical()
                    .max_height(300.0)
                    .show(ui, |ui| {
                        for w in self.state.warnings().iter().rev() {
                            ui.label(w);
                        }
                    });
            });
        if clear {
            self.state.clear_warnings();
            open = false;
        }
        self.show_warnings = open;
    }

    /// Help ▸ About: the version and what draws the window.
    pub(super) fn about_window(&mut self, ctx: &egui::Context) {
        if !self.show_about {
            return;
        }
        let mut open = true;
        egui::Window::new("About eotn")
            .open(&mut open)
            .default_width(420.0)
            .show(ctx, |ui| {
                ui.label(concat!(
                    "eotn ",
                    env!("CARGO_PKG_VERSION"),
                    ": Eye Of The NUbot and the World Model Debugger"
                ));
                ui.separator();
                match &self.renderer {
                    Some(r) => {
                        egui::Grid::new("about-renderer")
                            .num_columns(2)
                            .show(ui, |ui| {
                                ui.label("Renderer");
                                ui.label(r.kind.name());
                                ui.end_row();
                                ui.label("Adapter");
                                ui.label(&r.adapter);
                                ui.end_row();
                                ui.label("Why");
                                ui.label(&r.reason);
                                ui.end_row();
                                ui.label("Setting");
                                ui.label(format!(
                                    "{} (eotn open --renderer auto|wgpu|gl changes it)",
                                    r.setting.name()
                                ));
                                ui.end_row();
                            });
                    }
                    None => {
                        ui.label("Renderer: none (headless)");
                    }
                }
            });
        self.show_about = open;
    }
}
