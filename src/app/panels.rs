//! The main window's layout: the menu bar on top; the status bar, the timeline and the
//! thumbnails at the bottom; the Classify panel on the left; the image with its docked windows
//! in the middle; and the floating windows (file dialogs, warnings, About, Open path, Camera).

use super::file_dialog::FileAction;
use super::textures::Textures;
use super::{Command, EotnApp, camera_menu, classify_panel, dock, menus, views};

impl EotnApp {
    /// Draws the panels around and in the middle of the window; true when the File menu's Quit
    /// was chosen.
    pub(super) fn panels_ui(&mut self, ui: &mut egui::Ui, commands: &mut Vec<Command>) -> bool {
        let mut quit = false;
        let tex = self.textures.as_ref().map(Textures::ids);
        let thumb_tex = self.textures.as_ref().map(Textures::thumb_ids);
        egui::Panel::top("menu").show(ui, |ui| {
            let out = menus::menu_bar_ui(ui, &self.state, &mut self.menu_input, commands);
            quit |= out.quit;
            self.show_about |= out.about;
        });
        egui::Panel::bottom("status").show(ui, |ui| self.status_ui(ui));
        if self.state.source().is_some() {
            egui::Panel::bottom("timeline").show(ui, |ui| self.timeline_ui(ui, commands));
        }
        egui::Panel::bottom("thumbnails")
            .resizable(true)
            .default_size(120.0)
            .size_range(60.0..=300.0)
            .show(ui, |ui| {
                views::thumbnails_ui(ui, &self.state, thumb_tex.as_ref(), commands)
            });
        egui::Panel::left("classify")
            .resizable(true)
            .default_size(230.0)
            .show(ui, |ui| {
                classify_panel::classify_panel_ui(ui, &self.state, commands);
            });
        self.dock.sync(&self.state);
        egui::CentralPanel::default()
            .frame(egui::Frame::NONE)
            .show(ui, |ui| {
                let mut behavior = dock::DockBehavior {
                    state: &self.state,
                    tex: tex.as_ref(),
                    uv_plane: &mut self.uv_plane,
                    overhead_paths: &mut self.overhead,
                    robots: &mut self.robots,
                    commands,
                    dialog: &mut self.menu_input.dialog,
                    view: views::MainViewOutput::default(),
                    beside: &self.beside_textures,
                    panes: Vec::new(),
                };
                let out = self.dock.ui(ui, &mut behavior);
                self.last_panes = behavior.panes;
                self.hovered = out.hovered;
                self.last_view = out.transform;
            });
        quit
    }

    /// The floating windows: a file dialog asked for this frame, warnings, About, Open path and
    /// the Camera menu's dialogs.
    pub(super) fn windows_ui(&mut self, ctx: &egui::Context, commands: &mut Vec<Command>) {
        if let Some((action, name)) = self.menu_input.dialog.take() {
            let folder = self.dialog_folder(action);
            self.file_dialogs.open(action, folder.as_deref(), name);
        }
        self.file_dialogs.show(ctx, commands);
        self.warnings_window(ctx);
        self.about_window(ctx);
        menus::open_path_window(ctx, &mut self.menu_input, commands);
        camera_menu::camera_windows(ctx, &self.state, &mut self.camera, commands);
        if std::mem::take(&mut self.camera.browse_record) {
            let name = self.camera.record_path.trim().to_owned();
            let folder = self.dialog_folder(FileAction::Record);
            self.file_dialogs
                .open(FileAction::Record, folder.as_deref(), Some(name));
        }
    }
}
