//! The desktop app (feature `gui`): eframe on wgpu or OpenGL (see `renderer.rs`), embedding the
//! same pipeline as the CLI. Everything that is not a widget is the [`crate::workspace`] (it
//! builds without this feature); this folder draws it and sends [`Command`](crate::workspace::Command)s. Laid out like egui's
//! demo app and rerun's viewer:
//!
//! | file | role |
//! |---|---|
//! | `mod.rs` | the app shell: [`EotnApp`](crate::app::EotnApp), starting the window, one UI frame in order (clock, keys, textures, panels, windows, commands) |
//! | `panels.rs` | the window's layout: menu bar, status bar, timeline, thumbnails, Classify panel, the dock; the floating windows |
//! | `status_bar.rs` | the status bar, the warnings window, Help ▸ About |
//! | `timeline.rs` | the timeline bar: play, step, speed, frame number, slider with marks |
//! | `keyboard.rs` | the keyboard shortcuts |
//! | `textures.rs` | the shown frame's images and highlight, uploaded when they change |
//! | `views.rs` | the enlarged view (zoom, pan, hover, clicks) and the thumbnails |
//! | `side_by_side.rs` | cameras side by side: one column each, its own table's classes and recognition; a click focuses a camera |
//! | `overlays.rs` | drawing in image pixels through one transform: boxes, labels, markers |
//! | `classify_panel.rs` | class picker, sensitivity, commit/undo/redo, try-on-stream |
//! | `inspector.rs` | every recognition candidate with its confidence breakdown; selection |
//! | `sensors_dialog.rs` | every sensor reading with units, plots over the stream |
//! | `uv_plane.rs` | the table's U–V plane with the frame's histogram, selection both ways |
//! | `coverage_panel.rs` | the colours the table leaves unclassified, ranked; select to commit |
//! | `bookmarks_panel.rs` | the pipeline's events and the user's bookmarks; timeline marks |
//! | `robots_panel.rs` | Camera ▸ Connect to robot…: the robots list, the Live switch |
//! | `params_panel.rs` | the recognition parameters: tune each value, reset, save, try on the stream |
//! | `dock.rs` | the image and the windows docked beside it, stacked, then as tabs (`egui_tiles`) |
//! | `file_dialog.rs` | in-app file dialogs (`egui_file`): no desktop portal needed |
//! | `menus.rs` | File, Classification, View, Stream, Camera, Windows, Help |
//! | `camera_menu.rs` | the Camera menu and its dialogs: connect, settings, grab, record |
//! | `overhead_overlays.rs` | the overhead camera's overlays: field lines, ball, robot markers, picked points |
//! | `overhead_menu.rs` | the Overhead menu: calibration files, view options, windows |
//! | `calibration_window.rs` | pick landmarks by name, solve, each point's reprojection error |
//! | `field_view.rs` | the top-down field: ball, robots, trails, world models and their errors |
//! | `wmd_errors.rs`, `wmd_overlay.rs`, `wmd_robots.rs` | the World Model Debugger: errors, spreads, jumps and plots; world models over the overhead image; the session's robots list |
//! | `field_cameras.rs` | the field view's cameras: coverage, legend (current or stale), who saw what |
//! | `renderer.rs` | wgpu on a GPU, OpenGL on a software rasteriser: the choice before the window opens |
//!
//! Only this folder names egui/eframe (`scripts/check.sh` checks it).

pub mod bookmarks_panel;
pub mod calibration_window;
pub mod camera_menu;
pub mod classify_panel;
pub mod coverage_panel;
pub mod dock;
pub mod field_cameras;
pub mod field_view;
pub mod file_dialog;
pub mod inspector;
mod keyboard;
pub mod menus;
pub mod overhead_menu;
pub mod overhead_overlays;
pub mod overlays;
mod panels;
pub mod params_panel;
pub mod renderer;
pub mod robots_panel;
pub mod sensors_dialog;
pub mod side_by_side;
mod status_bar;
mod textures;
mod timeline;
pub mod uv_plane;
pub mod views;
pub mod wmd_errors;
mod wmd_overlay;
mod wmd_robots;

use std::path::PathBuf;
use std::time::{Duration, Instant};

use egui::Color32;

pub use crate::workspace::{Command, PlaybackCommand, Settings, TableCommand, ViewKind, Workspace};

use crate::app_options::{RendererSetting, RunOptions};
pub use textures::{
    ViewImages, blend_classes, blend_texel, classes_alpha, palette, preview_image,
    preview_image_every, texture_step, thumbnail_step, view_images, view_images_every,
    view_images_in, visible_preview_colour, visible_region,
};

use crate::workspace::{PixelInfo, median};
use overlays::ImageTransform;
use textures::Textures;

/// Key of the [`Settings`] in eframe's storage, where versions before 2026-12-04 kept them.
pub const SETTINGS_KEY: &str = "eotn-settings";

/// What draws the window, for the status bar and the About window.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RendererInfo {
    /// The renderer running.
    pub kind: renderer::RendererKind,
    /// Why it was chosen.
    pub reason: String,
    /// The adapter it runs on, as it names itself (wgpu adapter, or GL_RENDERER and version).
    pub adapter: String,
    /// The setting it came from (`auto`, `wgpu`, `gl`).
    pub setting: RendererSetting,
}

/// Opens the app window (streams, frames, tables; none reopens the last session), on the
/// renderer [`renderer::choose`] picks; if that one cannot start, the other is tried once.
///
/// # Errors
/// Neither renderer could create the window (no display, no Vulkan or GL driver).
pub fn run(opts: RunOptions) -> anyhow::Result<()> {
    let launched = Instant::now();
    let setting = match opts.renderer {
        Some(s) => {
            if let Err(e) = renderer::save_setting(s) {
                log::warn!("the renderer setting is not saved: {e}");
            }
            s
        }
        None => renderer::saved_setting(),
    };
    let choice = renderer::choose(setting);
    let first = start_window(choice.kind, &choice.reason, setting, &opts, launched);
    let Err(e) = first else { return Ok(()) };
    let other = choice.kind.other();
    eprintln!(
        "eotn: the {} renderer could not start ({e}); trying {}",
        choice.kind.name(),
        other.name()
    );
    let reason = format!("{} could not start", choice.kind.name());
    start_window(other, &reason, setting, &opts, launched)
        .map_err(|e| anyhow::anyhow!("cannot open the app window: {e}"))
}

/// Runs the window on one renderer until it closes.
fn start_window(
    kind: renderer::RendererKind,
    reason: &str,
    setting: RendererSetting,
    opts: &RunOptions,
    launched: Instant,
) -> Result<(), eframe::Error> {
    let options = eframe::NativeOptions {
        viewport: egui::ViewportBuilder::default()
            .with_title("eotn")
            .with_app_id("eotn")
            .with_inner_size([1280.0, 800.0])
            .with_min_inner_size([640.0, 400.0]),
        renderer: kind.eframe(),
        // The views are whole-pixel NEAREST images and flat panels: dithering buys nothing
        // there and costs a full-screen pass on a software rasteriser.
        dithering: false,
        ..Default::default()
    };
    let opts = opts.clone();
    let reason = reason.to_owned();
    eframe::run_native(
        "eotn",
        options,
        Box::new(move |cc| {
            let info = RendererInfo {
                kind,
                reason,
                adapter: renderer::live_adapter(cc),
                setting,
            };
            eprintln!(
                "eotn: drawing with {} on {} ({})",
                info.kind.name(),
                info.adapter,
                info.reason
            );
            let mut app = EotnApp::new(cc, opts.files.clone(), opts.camera.clone());
            app.renderer = Some(info);
            if let Some(labels) = &opts.labels {
                app.state.run(Command::OpenLabels(labels.clone()));
            }
            if let Some(address) = &opts.ssl_vision {
                app.state.run(
                    crate::workspace::OverheadCommand::SendSslVision(Some(address.clone())).into(),
                );
            }
            if opts.all_overlays {
                app.state.settings.overlays = crate::workspace::Overlays::all_on();
            }
            app.play_when_shown = opts.play.map(|speed| speed.as_factor());
            app.launched = Some(launched);
            app.quit_at = opts.quit_after.map(|d| Instant::now() + d);
            Ok(Box::new(app))
        }),
    )
}

/// The eframe application: the state plus the runtime resources of the window.
pub struct EotnApp {
    /// Everything that is not a widget.
    pub state: Workspace,
    textures: Option<Textures>,
    menu_input: menus::MenuInput,
    /// What the Camera dialogs are editing.
    pub camera: camera_menu::CameraDialogs,
    /// The file names typed in the overhead calibration window.
    pub overhead: calibration_window::OverheadPaths,
    /// What the robots window is editing.
    pub robots: robots_panel::RobotsPanel,
    uv_plane: uv_plane::UvPlane,
    /// The image and the docked windows.
    pub dock: dock::Dock,
    /// The in-app file dialog.
    pub file_dialogs: file_dialog::FileDialogs,
    hovered: Option<PixelInfo>,
    /// Where the enlarged view was last drawn (tests click pixels through it).
    pub last_view: Option<ImageTransform>,
    /// Where the timeline's marks were last spread: the slider's track (tests compare it
    /// with the slider's own rectangle).
    pub last_timeline_track: Option<egui::Rect>,
    /// Cameras side by side: each pane as last drawn (where, how many primitives), left to
    /// right.
    pub last_panes: Vec<side_by_side::DrawnPane>,
    beside_textures: side_by_side::BesideTextures,
    confirm_close: bool,
    allow_close: bool,
    show_warnings: bool,
    title: String,
    last_frame: Option<Instant>,
    palette: [Color32; 256],
    was_playing: bool,
    /// What draws the window (`None` in headless tests).
    pub renderer: Option<RendererInfo>,
    show_about: bool,
    /// `--quit-after`: when to close.
    quit_at: Option<Instant>,
    /// `--play`: the speed to start at once the first frame is on screen. Starting the clock
    /// before it would count the window's first, slow frame (fonts, shaders, first uploads:
    /// about 100 ms on a software renderer) as two or three dropped frames.
    play_when_shown: Option<f32>,
    /// The settings file (`settings.json` in eframe's storage folder); `None` when the app
    /// runs without storage (tests).
    settings_file: Option<PathBuf>,
    /// When `app::run` started (the first frame's time after launch is measured from it).
    launched: Option<Instant>,
    /// The last UI frame had input (its successor's interval is a response time).
    had_input: bool,
}

impl EotnApp {
    /// The app with persisted settings from `cc`, opening `paths` (or the last session's files
    /// when there are none).
    #[must_use]
    pub fn new(
        cc: &eframe::CreationContext<'_>,
        paths: Vec<PathBuf>,
        camera: Option<String>,
    ) -> Self {
        // Settings live in their own file (written through `atomic_file`); versions before
        // 2026-12-04 kept them in eframe's storage, read when there is no file yet.
        let settings_file = cc
            .storage
            .and_then(|_| eframe::storage_dir("eotn"))
            .map(|d| d.join(crate::workspace::SETTINGS_FILE_NAME));
        let state = match &settings_file {
            Some(p) if std::fs::symlink_metadata(p).is_ok() => Workspace::with_settings_file(p),
            _ => Workspace::new(
                cc.storage
                    .and_then(|s| eframe::get_value::<Settings>(s, SETTINGS_KEY))
                    .unwrap_or_default(),
            ),
        };
        let mut app = Self::with_state(state);
        app.settings_file = settings_file;
        // A shown robot's new frame repaints at once (no waiting for the next look).
        let ctx = cc.egui_ctx.clone();
        app.state
            .set_wake(std::sync::Arc::new(move || ctx.request_repaint()));
        app.state.set_camera_choice(camera);
        if paths.is_empty() {
            app.state.reopen_last();
        } else {
            app.state.run(Command::Open(paths));
        }
        app
    }

    /// The app around an existing state (tests build the state first).
    #[must_use]
    pub fn with_state(state: Workspace) -> Self {
        Self {
            state,
            textures: None,
            menu_input: menus::MenuInput::default(),
            camera: camera_menu::CameraDialogs::default(),
            overhead: calibration_window::OverheadPaths::default(),
            robots: robots_panel::RobotsPanel::default(),
            uv_plane: uv_plane::UvPlane::default(),
            dock: dock::Dock::default(),
            file_dialogs: file_dialog::FileDialogs::default(),
            hovered: None,
            last_view: None,
            last_timeline_track: None,
            last_panes: Vec::new(),
            beside_textures: side_by_side::BesideTextures::default(),
            confirm_close: false,
            allow_close: false,
            show_warnings: false,
            title: String::new(),
            last_frame: None,
            palette: palette(),
            was_playing: false,
            renderer: None,
            show_about: false,
            quit_at: None,
            play_when_shown: None,
            settings_file: None,
            launched: None,
            had_input: false,
        }
    }

    /// Where a file dialog starts: the folder of the file it concerns, else the current one.
    fn dialog_folder(&self, action: file_dialog::FileAction) -> Option<PathBuf> {
        use file_dialog::FileAction as A;
        let file = match action {
            A::OpenTable | A::SaveTableAs => self.state.table_path().map(std::path::Path::to_owned),
            A::OpenParams | A::SaveParams => self.state.params_slot().path.clone(),
            A::OpenPlaces => self.state.places_path().map(std::path::Path::to_owned),
            A::OpenCalibration | A::SaveCalibration => self
                .state
                .overhead()
                .calibration_path()
                .map(std::path::Path::to_owned),
            A::OpenPoints | A::SavePoints => self
                .state
                .overhead()
                .points_path()
                .map(std::path::Path::to_owned),
            A::Open | A::ExportView | A::Record => self.state.settings.last_source.first().cloned(),
            // Label sets lie beside their frames: the folder holding the opened frames' folder.
            A::OpenLabelsFolder | A::OpenLabelsFile => self.state.labels().map_or_else(
                || self.state.settings.last_source.first().cloned(),
                |l| Some(l.path.clone()),
            ),
        };
        file.and_then(|f| f.parent().map(std::path::Path::to_owned))
            .filter(|d| !d.as_os_str().is_empty())
    }

    /// The pixel the pointer was over in the last frame.
    #[must_use]
    pub const fn hovered(&self) -> Option<&PixelInfo> {
        self.hovered.as_ref()
    }

    /// True while the "unsaved changes" question is shown.
    #[must_use]
    pub const fn confirming_close(&self) -> bool {
        self.confirm_close
    }

    fn close_dialog(&mut self, ctx: &egui::Context, commands: &mut Vec<Command>) {
        let unsaved_beside = self.state.unsaved_beside().join(", ");
        if ctx.input(|i| i.viewport().close_requested())
            && (self.state.dirty() || !unsaved_beside.is_empty())
            && !self.allow_close
        {
            ctx.send_viewport_cmd(egui::ViewportCommand::CancelClose);
            self.confirm_close = true;
        }
        if !self.confirm_close {
            return;
        }
        let mut choice = None;
        egui::Modal::new(egui::Id::unique("confirm_close")).show(ctx, |ui| {
            ui.heading("Unsaved changes");
            ui.label(format!(
                "{} has edits that are not saved.",
                self.state.title()
            ));
            if !unsaved_beside.is_empty() {
                // Save and quit saves the focused camera's table only.
                ui.label(format!(
                    "The tables of {unsaved_beside} (side by side) have unsaved edits too: focus each and save it first."
                ));
            }
            ui.horizontal(|ui| {
                if self.state.table_path().is_some()
                    && unsaved_beside.is_empty()
                    && ui.button("Save and quit").clicked()
                {
                    choice = Some(1);
                }
                if ui.button("Quit without saving").clicked() {
                    choice = Some(2);
                }
                if ui.button("Cancel").clicked() {
                    choice = Some(0);
                }
            });
        });
        match choice {
            Some(1) => {
                commands.push(TableCommand::SaveTable.into());
                self.allow_close = true;
                self.confirm_close = false;
            }
            Some(2) => {
                // The edits are undone in the journal too: the next start finds the table as
                // saved, with its undo history, and no sign of a crash.
                commands.push(TableCommand::DiscardUnsaved.into());
                self.allow_close = true;
                self.confirm_close = false;
                ctx.send_viewport_cmd(egui::ViewportCommand::Close);
            }
            Some(_) => self.confirm_close = false,
            None => {}
        }
    }

    /// Measures the UI frame interval and moves playback and the scans on by it; starts
    /// `--play` once the first frame is on screen.
    fn advance_clock(&mut self, ctx: &egui::Context, now: Instant) {
        let dt = self.last_frame.map_or(Duration::ZERO, |t| now - t);
        self.last_frame = Some(now);
        if dt > Duration::ZERO {
            self.state.record_frame_time(dt);
            if self.had_input {
                self.state.record_input_frame_time(dt);
            }
        }
        self.had_input = ctx.input(|i| !i.events.is_empty());
        if self.had_input && self.launched.is_some() && std::env::var_os("EOTN_STATS").is_some() {
            // Measuring: the frame after one with input starts as soon as that one is on
            // screen, so its interval is how long the window took to answer, not the pause
            // until the next key.
            ctx.request_repaint();
        }
        // The first frame is on screen when the second starts: it is asked for at once, so
        // the time from launch to the first frame is measured (`EOTN_STATS`).
        match self.launched {
            Some(t) if dt > Duration::ZERO && self.state.timings.first_frame_ms.is_none() => {
                self.state.timings.first_frame_ms = Some((now - t).as_secs_f64() * 1e3);
            }
            Some(_) if self.state.timings.first_frame_ms.is_none() => ctx.request_repaint(),
            _ => {}
        }
        // Playback and scans use wall time, capped so a stall does not skip half the stream.
        self.state.tick(dt.min(Duration::from_millis(250)));
        // The first frame has been drawn when the second starts (dt > 0).
        if dt > Duration::ZERO
            && let Some(speed) = self.play_when_shown.take()
        {
            self.state.run(PlaybackCommand::SetSpeed(speed).into());
            self.state.run(PlaybackCommand::SetPlaying(true).into());
        }
        if self.play_when_shown.is_some() {
            ctx.request_repaint();
        }
    }

    /// After the commands: the window title, when to draw again, the UI-time records and the
    /// end-of-playback report.
    fn after_commands(&mut self, ctx: &egui::Context, now: Instant, cpu: Option<f32>) {
        let title = self.state.title();
        if title != self.title {
            ctx.send_viewport_cmd(egui::ViewportCommand::Title(title.clone()));
            self.title = title;
        }
        // Playback redraws when the next frame is due, not as fast as it can: an unchanged
        // frame costs the renderer as much as a new one.
        if let Some(due) = self.state.next_frame_due() {
            ctx.request_repaint_after(due);
        }
        let busy = self.state.try_edit().is_some_and(|t| !t.done())
            || self.state.hints_busy()
            || self
                .state
                .params_slot()
                .try_run
                .as_ref()
                .is_some_and(|t| !t.done())
            || (self.state.settings.show_sensors
                && self.state.sensor_series.points.len() < self.state.sensor_series.total);
        self.state.record_ui_time(now.elapsed(), cpu);
        if self.was_playing && !self.state.playing() {
            // The end of a playback is when its figures are complete.
            self.report_stats();
        }
        self.was_playing = self.state.playing();
        if busy {
            ctx.request_repaint();
        }
    }

    /// Applies queued commands; after "Save and quit", closes once the save succeeded.
    fn apply_all(&mut self, ctx: &egui::Context, commands: Vec<Command>) {
        for c in commands {
            let saving_to_quit = c == Command::Table(TableCommand::SaveTable) && self.allow_close;
            self.state.run(c);
            if saving_to_quit {
                if self.state.dirty() {
                    // The save failed: stay open, the error is in the status area.
                    self.allow_close = false;
                } else {
                    ctx.send_viewport_cmd(egui::ViewportCommand::Close);
                }
            }
        }
    }

    /// Prints the measured medians (`EOTN_STATS=1`), for the figures in the notes.
    fn report_stats(&self) {
        if std::env::var_os("EOTN_STATS").is_some() {
            let t = &self.state.timings;
            let input_max = t.input_frames_ms.iter().copied().fold(0.0, f64::max);
            eprintln!(
                "eotn stats: first frame {:.0} ms after launch; input frames {} median {:.2} ms max {:.1} ms",
                t.first_frame_ms.unwrap_or(f64::NAN),
                t.input_frames_ms.len(),
                median(&t.input_frames_ms),
                input_max,
            );
            eprintln!(
                "eotn stats: steps {} median {:.2} ms; frames {} median {:.2} ms; playing frames {} median {:.2} ms max {:.1} ms (our UI code {:.2} ms, eframe CPU {:.2} ms); played {} dropped {} late {}; renderer {}",
                t.steps_ms.len(),
                median(&t.steps_ms),
                t.frames_ms.len(),
                median(&t.frames_ms),
                t.playing_frames_ms.len(),
                median(&t.playing_frames_ms),
                t.playing_frames_ms.iter().copied().fold(0.0, f64::max),
                median(&t.playing_ui_ms),
                median(&t.playing_cpu_ms),
                t.played_frames,
                t.dropped_frames,
                t.late_frames,
                self.renderer.as_ref().map_or("none", |r| r.kind.name()),
            );
            let parts: Vec<String> = t
                .step_part_medians()
                .iter()
                .map(|(name, ms)| format!("{name} {ms:.2}"))
                .collect();
            eprintln!(
                "eotn stats: step parts, medians in ms: {}",
                parts.join(", ")
            );
        }
    }
}

impl eframe::App for EotnApp {
    fn ui(&mut self, ui: &mut egui::Ui, frame: &mut eframe::Frame) {
        let ctx = ui.ctx().clone();
        let now = Instant::now();
        let cpu = frame.info().cpu_usage;
        self.advance_clock(&ctx, now);
        let mut commands = Vec::new();
        let mut quit = self.keyboard(&ctx, &mut commands);
        self.update_textures(&ctx);
        self.beside_textures
            .update(&ctx, &self.state, &self.palette);
        quit |= self.panels_ui(ui, &mut commands);
        self.windows_ui(&ctx, &mut commands);
        if let Some(at) = self.quit_at {
            if now >= at {
                // Unsaved table edits still get the question: a timer never discards work.
                self.quit_at = None;
                quit = true;
            } else {
                ctx.request_repaint_after(at - now);
            }
        }
        if quit {
            ctx.send_viewport_cmd(egui::ViewportCommand::Close);
        }
        self.close_dialog(&ctx, &mut commands);
        self.apply_all(&ctx, commands);
        self.after_commands(&ctx, now, cpu);
    }

    fn save(&mut self, _storage: &mut dyn eframe::Storage) {
        let Some(path) = &self.settings_file else {
            return;
        };
        let written = path
            .parent()
            .map_or(Ok(()), std::fs::create_dir_all)
            .and_then(|()| self.state.settings.save(path));
        if let Err(e) = written {
            log::warn!("{}: the settings are not saved: {e}", path.display());
        }
    }

    fn on_exit(&mut self, _gl: Option<&eframe::glow::Context>) {
        self.report_stats();
    }
}
