//! The desktop app (feature `gui`): eframe on wgpu or OpenGL (see `renderer.rs`), embedding the
//! same pipeline as the CLI. Everything that is not a widget is the [`crate::workspace`] (it
//! builds without this feature); this folder draws it and sends [`Command`](crate::workspace::Command)s. Laid out like egui's
//! demo app and rerun's viewer:
//!
//! | file | role |
//! |---|---|
//! | `views.rs` | the enlarged view (zoom, pan, hover, clicks) and the thumbnails |
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
//! | `renderer.rs` | wgpu on a GPU, OpenGL on a software rasteriser: the choice before the window opens |
//!
//! Only this folder names egui/eframe (`scripts/check.sh` checks it).

pub mod bookmarks_panel;
pub mod calibration_window;
pub mod camera_menu;
pub mod classify_panel;
pub mod coverage_panel;
pub mod dock;
pub mod field_view;
pub mod file_dialog;
pub mod inspector;
pub mod menus;
pub mod overhead_menu;
pub mod overhead_overlays;
pub mod overlays;
pub mod params_panel;
pub mod renderer;
pub mod robots_panel;
pub mod sensors_dialog;
pub mod uv_plane;
pub mod views;

use std::path::PathBuf;
use std::time::{Duration, Instant};

use egui::{Color32, ColorImage, Key, KeyboardShortcut, Modifiers, TextureHandle, TextureOptions};

pub use crate::workspace::{Command, Settings, ViewKind, Workspace};

use crate::workspace::{PixelInfo, SPEEDS, median};
use overlays::{FrameTextures, ImageTransform};

/// How much the pixels outside a pending selection are darkened (alpha of black over them).
const PREVIEW_DIM_ALPHA: u8 = 110;

/// Key of the persisted [`Settings`] in eframe's storage.
pub const SETTINGS_KEY: &str = "eotn-settings";

/// How the window starts (`eotn open` and its options).
#[derive(Debug, Clone, Default)]
pub struct RunOptions {
    /// Streams, frames, tables to open; none reopens the last session.
    pub files: Vec<PathBuf>,
    /// `--renderer`: saved and used when given; else the saved setting, else auto.
    pub renderer: Option<crate::cli::open::RendererSetting>,
    /// `--play [--speed]`: start playing at once at this speed.
    pub play: Option<crate::cli::open::PlaySpeed>,
    /// `--quit-after`: close the window after this long.
    pub quit_after: Option<Duration>,
    /// `--all-overlays`: every overlay on.
    pub all_overlays: bool,
}

impl RunOptions {
    /// From `eotn open`'s arguments.
    #[must_use]
    pub fn from_args(args: &crate::cli::open::Args) -> Self {
        Self {
            files: args.files.clone(),
            renderer: args.renderer,
            play: args.play.then_some(args.speed),
            quit_after: args
                .quit_after
                .filter(|s| s.is_finite() && *s >= 0.0)
                .map(|s| Duration::from_secs_f64(s.min(1e9))),
            all_overlays: args.all_overlays,
        }
    }
}

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
    pub setting: crate::cli::open::RendererSetting,
}

/// Opens the app window (streams, frames, tables; none reopens the last session), on the
/// renderer [`renderer::choose`] picks; if that one cannot start, the other is tried once.
///
/// # Errors
/// Neither renderer could create the window (no display, no Vulkan or GL driver).
pub fn run(opts: RunOptions) -> anyhow::Result<()> {
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
    let first = start_window(choice.kind, &choice.reason, setting, &opts);
    let Err(e) = first else { return Ok(()) };
    let other = choice.kind.other();
    eprintln!(
        "eotn: the {} renderer could not start ({e}); trying {}",
        choice.kind.name(),
        other.name()
    );
    let reason = format!("{} could not start", choice.kind.name());
    start_window(other, &reason, setting, &opts)
        .map_err(|e| anyhow::anyhow!("cannot open the app window: {e}"))
}

/// Runs the window on one renderer until it closes.
fn start_window(
    kind: renderer::RendererKind,
    reason: &str,
    setting: crate::cli::open::RendererSetting,
    opts: &RunOptions,
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
            let mut app = EotnApp::new(cc, opts.files.clone());
            app.renderer = Some(info);
            if opts.all_overlays {
                app.state.settings.overlays = crate::workspace::Overlays::all_on();
            }
            app.play_when_shown = opts.play.map(|speed| speed.as_factor());
            app.quit_at = opts.quit_after.map(|d| Instant::now() + d);
            Ok(Box::new(app))
        }),
    )
}

/// The textures of the shown frame and what they were built from.
struct Textures {
    raw: TextureHandle,
    classified: TextureHandle,
    preview: TextureHandle,
    frame_generation: u64,
    preview_generation: u64,
    /// The preview texture holds no highlight (nothing to re-upload while none is pending).
    preview_empty: bool,
}

impl Textures {
    fn ids(&self) -> FrameTextures {
        FrameTextures {
            raw: self.raw.id(),
            classified: self.classified.id(),
            preview: self.preview.id(),
        }
    }
}

/// Display colours of every class code, transparent for unclassified.
#[must_use]
pub fn palette() -> [Color32; 256] {
    let mut p = [Color32::TRANSPARENT; 256];
    for (code, c) in p.iter_mut().enumerate().skip(1) {
        let [r, g, b] = crate::lut::code_display_rgb(u8::try_from(code).unwrap_or(0));
        *c = Color32::from_rgb(r, g, b);
    }
    p
}

/// The images the views are drawn from, before they go to the GPU.
#[derive(Debug, Clone)]
pub struct ViewImages {
    /// The frame in colour.
    pub raw: ColorImage,
    /// Class colours, transparent where unclassified.
    pub classified: ColorImage,
}

/// Builds the colour and class-colour images of the shown frame (`palette` from [`palette`]);
/// `None` when no frame is open. This is the CPU side of a texture update.
#[must_use]
pub fn view_images(state: &Workspace, palette: &[Color32; 256]) -> Option<ViewImages> {
    let frame = state.frame()?;
    let size = [frame.width(), frame.height()];
    // The undistorted view of an overhead frame, when chosen, else the frame as it is.
    let raw = ColorImage::from_rgb(size, &state.view_rgb());
    let classified = ColorImage::new(
        size,
        state
            .view_codes()
            .iter()
            .map(|&c| palette[usize::from(c)])
            .collect(),
    );
    Some(ViewImages { raw, classified })
}

/// The preview highlight image of the pending selection (class colour on selected pixels,
/// dimmed elsewhere; transparent with no selection).
#[must_use]
pub fn preview_image(state: &Workspace, size: [usize; 2]) -> ColorImage {
    let mask = state.preview_mask();
    let colour = state
        .preview_colour()
        .map_or(Color32::TRANSPARENT, |[r, g, b]| Color32::from_rgb(r, g, b));
    if mask.len() != size[0] * size[1] {
        return ColorImage::new(size, vec![Color32::TRANSPARENT; size[0] * size[1]]);
    }
    // Unselected pixels are dimmed, so the highlight shows even where the class colour is
    // the colour of the pixels themselves (orange on an orange ball).
    let dim = Color32::from_black_alpha(PREVIEW_DIM_ALPHA);
    // A dark class colour (black, dark blue) would vanish on the dimmed dark pixels: those
    // classes are previewed in a light colour instead.
    let colour = visible_preview_colour(colour);
    ColorImage::new(
        size,
        mask.iter().map(|&m| if m { colour } else { dim }).collect(),
    )
}

/// The highlight colour of a previewed class: its own colour, or a light magenta for classes
/// too dark to show over dimmed pixels (black's near-black, dark blue).
#[must_use]
pub fn visible_preview_colour(class_colour: Color32) -> Color32 {
    let [r, g, b, a] = class_colour.to_array();
    let luma = 0.299 * f32::from(r) + 0.587 * f32::from(g) + 0.114 * f32::from(b);
    if a > 0 && luma < PREVIEW_MIN_LUMA {
        Color32::from_rgb(255, 96, 255)
    } else {
        class_colour
    }
}

/// Class colours darker than this (0..255 luma) get a light preview colour.
const PREVIEW_MIN_LUMA: f32 = 100.0;

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
}

impl EotnApp {
    /// The app with persisted settings from `cc`, opening `paths` (or the last session's files
    /// when there are none).
    #[must_use]
    pub fn new(cc: &eframe::CreationContext<'_>, paths: Vec<PathBuf>) -> Self {
        let settings = cc
            .storage
            .and_then(|s| eframe::get_value::<Settings>(s, SETTINGS_KEY))
            .unwrap_or_default();
        let mut app = Self::with_state(Workspace::new(settings));
        // A shown robot's new frame repaints at once (no waiting for the next look).
        let ctx = cc.egui_ctx.clone();
        app.state
            .set_wake(std::sync::Arc::new(move || ctx.request_repaint()));
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
        }
    }

    /// Where a file dialog starts: the folder of the file it concerns, else the current one.
    fn dialog_folder(&self, action: file_dialog::FileAction) -> Option<PathBuf> {
        use file_dialog::FileAction as A;
        let file = match action {
            A::OpenTable | A::SaveTableAs => self.state.table_path().map(std::path::Path::to_owned),
            A::OpenParams | A::SaveParams => self.state.params_slot().path.clone(),
            A::OpenPlaces => self.state.places_path().map(std::path::Path::to_owned),
            A::Open | A::ExportView => self.state.settings.last_source.first().cloned(),
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

    fn update_textures(&mut self, ctx: &egui::Context) {
        let Some(frame) = self.state.frame() else {
            return;
        };
        let size = [frame.width(), frame.height()];
        let opts = TextureOptions::NEAREST;
        let fg = self.state.frame_generation();
        let pg = self.state.preview_generation();
        if self
            .textures
            .as_ref()
            .is_some_and(|t| t.frame_generation == fg && t.preview_generation == pg)
        {
            return;
        }
        let t0 = Instant::now();
        let frame_changed = self
            .textures
            .as_ref()
            .is_none_or(|t| t.frame_generation != fg);
        let empty = self.state.selection().is_none();
        if frame_changed
            && let Some(ViewImages { raw, classified }) = view_images(&self.state, &self.palette)
        {
            match &mut self.textures {
                Some(t) => {
                    t.raw.set(raw, opts);
                    t.classified.set(classified, opts);
                }
                None => {
                    let preview = preview_image(&self.state, size);
                    self.textures = Some(Textures {
                        raw: ctx.load_texture("raw", raw, opts),
                        classified: ctx.load_texture("classified", classified, opts),
                        preview: ctx.load_texture("preview", preview, opts),
                        frame_generation: fg,
                        preview_generation: pg,
                        preview_empty: empty,
                    });
                }
            }
        }
        if let Some(t) = &mut self.textures {
            // With nothing selected the preview is not drawn: an empty one is uploaded once,
            // not on every step of playback.
            if t.preview_generation != pg && !(empty && t.preview_empty) {
                t.preview.set(preview_image(&self.state, size), opts);
                t.preview_empty = empty;
            }
            t.frame_generation = fg;
            t.preview_generation = pg;
        }
        if frame_changed {
            self.state.record_upload(t0.elapsed());
        }
    }

    fn keyboard(&self, ctx: &egui::Context, commands: &mut Vec<Command>) -> bool {
        let mut quit = false;
        if ctx.egui_wants_keyboard_input() {
            return quit;
        }
        let menu_open = egui::Popup::is_any_open(ctx);
        ctx.input_mut(|i| {
            let cmd = |k| KeyboardShortcut::new(Modifiers::COMMAND, k);
            if i.consume_shortcut(&KeyboardShortcut::new(
                Modifiers::COMMAND | Modifiers::SHIFT,
                Key::Z,
            )) || i.consume_shortcut(&cmd(Key::Y))
            {
                commands.push(Command::Redo);
            }
            if i.consume_shortcut(&cmd(Key::Z)) {
                commands.push(Command::Undo);
            }
            if i.consume_shortcut(&cmd(Key::S)) {
                commands.push(Command::SaveTable);
            }
            if i.consume_shortcut(&cmd(Key::Q)) {
                quit = true;
            }
            for (key, channel) in [(Key::Y, 0), (Key::U, 1), (Key::V, 2)] {
                let down = i.count_and_consume_key(Modifiers::SHIFT, key) as i32;
                let up = i.count_and_consume_key(Modifiers::NONE, key) as i32;
                if up != down {
                    commands.push(Command::AdjustSensitivity {
                        channel,
                        delta: up - down,
                    });
                }
            }
            for (key, delta) in [(Key::Plus, 1), (Key::Equals, 1), (Key::Minus, -1)] {
                if i.consume_key(Modifiers::NONE, key) {
                    for channel in 0..3 {
                        commands.push(Command::AdjustSensitivity { channel, delta });
                    }
                }
            }
            if self.state.source().is_some() {
                for (key, delta) in [
                    (Key::ArrowRight, 1),
                    (Key::ArrowLeft, -1),
                    (Key::PageDown, 10),
                    (Key::PageUp, -10),
                ] {
                    // Every press counts, even several within one slow frame.
                    let n = i.count_and_consume_key(Modifiers::NONE, key);
                    if n > 0 {
                        commands.push(Command::Step(delta * n as i64));
                    }
                }
                for (key, forward) in [(Key::ArrowRight, true), (Key::ArrowLeft, false)] {
                    if i.consume_key(Modifiers::COMMAND, key) {
                        commands.push(Command::JumpToMark { forward });
                    }
                }
                if i.consume_key(Modifiers::NONE, Key::Home) {
                    commands.push(Command::Seek(0));
                }
                if i.consume_key(Modifiers::NONE, Key::End) {
                    commands.push(Command::Seek(usize::MAX));
                }
                if i.consume_key(Modifiers::NONE, Key::Space) {
                    commands.push(Command::SetPlaying(!self.state.playing()));
                }
            }
            // Escape closes an open menu first; only then does it drop the selection.
            if !menu_open && i.consume_key(Modifiers::NONE, Key::Escape) {
                commands.push(Command::ClearSelection);
            }
        });
        quit
    }

    fn timeline_ui(&self, ui: &mut egui::Ui, commands: &mut Vec<Command>) {
        let Some(src) = self.state.source() else {
            return;
        };
        let len = src.len();
        let index = self.state.index();
        ui.horizontal(|ui| {
            robots_panel::live_controls_ui(ui, &self.state, commands);
            if ui.button("Previous").on_hover_text("Left arrow").clicked() {
                commands.push(Command::Step(-1));
            }
            let play = if self.state.playing() {
                "Pause"
            } else {
                "Play"
            };
            if ui.button(play).on_hover_text("Space").clicked() {
                commands.push(Command::SetPlaying(!self.state.playing()));
            }
            if ui.button("Next").on_hover_text("Right arrow").clicked() {
                commands.push(Command::Step(1));
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
                commands.push(Command::SetSpeed(speed));
            }
            let mut i = index;
            ui.label("frame");
            if ui
                .add(egui::DragValue::new(&mut i).range(0..=len.saturating_sub(1)))
                .on_hover_text("type a frame number to jump")
                .changed()
            {
                commands.push(Command::Seek(i));
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
                commands.push(Command::Seek(j));
            }
            bookmarks_panel::timeline_marks(ui.painter(), slider.rect, &self.state, len);
        });
    }

    fn status_ui(&mut self, ui: &mut egui::Ui) {
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

    fn warnings_window(&mut self, ctx: &egui::Context) {
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
    fn about_window(&mut self, ctx: &egui::Context) {
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

    fn close_dialog(&mut self, ctx: &egui::Context, commands: &mut Vec<Command>) {
        if ctx.input(|i| i.viewport().close_requested()) && self.state.dirty() && !self.allow_close
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
            ui.horizontal(|ui| {
                if self.state.table_path().is_some() && ui.button("Save and quit").clicked() {
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
                commands.push(Command::SaveTable);
                self.allow_close = true;
                self.confirm_close = false;
            }
            Some(2) => {
                // The edits are undone in the journal too: the next start finds the table as
                // saved, with its undo history, and no sign of a crash.
                commands.push(Command::DiscardUnsaved);
                self.allow_close = true;
                self.confirm_close = false;
                ctx.send_viewport_cmd(egui::ViewportCommand::Close);
            }
            Some(_) => self.confirm_close = false,
            None => {}
        }
    }

    /// Applies queued commands; after "Save and quit", closes once the save succeeded.
    fn apply_all(&mut self, ctx: &egui::Context, commands: Vec<Command>) {
        for c in commands {
            let saving_to_quit = c == Command::SaveTable && self.allow_close;
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
        }
    }
}

impl eframe::App for EotnApp {
    fn ui(&mut self, ui: &mut egui::Ui, frame: &mut eframe::Frame) {
        let ctx = ui.ctx().clone();
        let now = Instant::now();
        let cpu = frame.info().cpu_usage;
        let dt = self.last_frame.map_or(Duration::ZERO, |t| now - t);
        self.last_frame = Some(now);
        if dt > Duration::ZERO {
            self.state.record_frame_time(dt);
        }
        // Playback and scans use wall time, capped so a stall does not skip half the stream.
        self.state.tick(dt.min(Duration::from_millis(250)));
        // The first frame has been drawn when the second starts (dt > 0).
        if dt > Duration::ZERO
            && let Some(speed) = self.play_when_shown.take()
        {
            self.state.run(Command::SetSpeed(speed));
            self.state.run(Command::SetPlaying(true));
        }
        if self.play_when_shown.is_some() {
            ctx.request_repaint();
        }

        let mut commands = Vec::new();
        let mut quit = self.keyboard(&ctx, &mut commands);
        self.update_textures(&ctx);
        let tex = self.textures.as_ref().map(Textures::ids);

        egui::Panel::top("menu").show(ui, |ui| {
            let out = menus::menu_bar_ui(ui, &self.state, &mut self.menu_input, &mut commands);
            quit |= out.quit;
            self.show_about |= out.about;
        });
        egui::Panel::bottom("status").show(ui, |ui| self.status_ui(ui));
        if self.state.source().is_some() {
            egui::Panel::bottom("timeline").show(ui, |ui| self.timeline_ui(ui, &mut commands));
        }
        egui::Panel::bottom("thumbnails")
            .resizable(true)
            .default_size(120.0)
            .size_range(60.0..=300.0)
            .show(ui, |ui| {
                views::thumbnails_ui(ui, &self.state, tex.as_ref(), &mut commands)
            });
        egui::Panel::left("classify")
            .resizable(true)
            .default_size(230.0)
            .show(ui, |ui| {
                egui::ScrollArea::vertical().show(ui, |ui| {
                    classify_panel::classify_panel_ui(ui, &self.state, &mut commands);
                });
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
                    commands: &mut commands,
                    dialog: &mut self.menu_input.dialog,
                    view: views::MainViewOutput::default(),
                };
                let out = self.dock.ui(ui, &mut behavior);
                self.hovered = out.hovered;
                self.last_view = out.transform;
            });
        if let Some((action, name)) = self.menu_input.dialog.take() {
            let folder = self.dialog_folder(action);
            self.file_dialogs.open(action, folder.as_deref(), name);
        }
        self.file_dialogs.show(&ctx, &mut commands);
        self.warnings_window(&ctx);
        self.about_window(&ctx);
        menus::open_path_window(&ctx, &mut self.menu_input, &mut commands);
        camera_menu::camera_windows(&ctx, &self.state, &mut self.camera, &mut commands);
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

    fn save(&mut self, storage: &mut dyn eframe::Storage) {
        eframe::set_value(storage, SETTINGS_KEY, &self.state.settings);
    }

    fn on_exit(&mut self, _gl: Option<&eframe::glow::Context>) {
        self.report_stats();
    }
}
