//! The Camera menu and its dialogs: connect a source (camera device, synthetic scenario, stream
//! file, robot over the network), disconnect, the source's settings, grab one image, stream
//! live, record into a stream the user names. The dialogs keep only what is being typed; every
//! action is a [`Command`], and they open and close through [`Command::ShowWindow`].

use std::path::PathBuf;

use egui::{Context, Ui};

use crate::sim::ScenarioKind;
use crate::sources::{Available, CameraKind, SourceKind, SourceSettings, SourceSpec, available};
use crate::workspace::{Command, SourceCommand, Window, Workspace};

/// What the Camera dialogs are editing.
#[derive(Debug)]
pub struct CameraDialogs {
    /// The kind of source picked in Connect….
    pub kind: SourceKind,
    /// The camera device picked.
    pub device: Option<PathBuf>,
    /// The camera picked looks down at the field (an overhead camera), not out of a robot.
    pub overhead: bool,
    /// The scenario picked.
    pub scenario: ScenarioKind,
    /// Its seed.
    pub seed: u64,
    /// The stream file typed.
    pub stream_path: String,
    /// The network address typed (`ws://HOST:PORT`).
    pub address: String,
    /// The recording's file typed.
    pub record_path: String,
    /// What was found when Connect… opened (cameras are looked for once, not every frame).
    pub found: Option<Available>,
    /// The settings being edited in Settings….
    pub settings: Option<SourceSettings>,
    /// Browse… was clicked in Record…: the app opens its file dialog for the recording.
    pub browse_record: bool,
}

impl Default for CameraDialogs {
    fn default() -> Self {
        Self {
            kind: SourceKind::Synthetic,
            device: None,
            overhead: false,
            scenario: ScenarioKind::WalkAndPan,
            seed: 1,
            stream_path: String::new(),
            address: "ws://127.0.0.1:8765".to_owned(),
            record_path: "recording.mcap".to_owned(),
            found: None,
            settings: None,
            browse_record: false,
        }
    }
}

/// The Camera menu.
pub fn camera_menu_ui(ui: &mut Ui, state: &Workspace, commands: &mut Vec<Command>) {
    let connected = state.connected_info();
    match &connected {
        Some(info) => ui.weak(format!("{} ({} camera)", info.label, info.camera.name())),
        None => ui.weak("nothing connected"),
    };
    ui.separator();
    item(
        commands,
        ui,
        true,
        "Connect…",
        vec![Command::ShowWindow(Window::Connect, true)],
    );
    item(
        commands,
        ui,
        true,
        "Connect to robot…",
        vec![Command::ShowWindow(Window::Robots, true)],
    );
    item(
        commands,
        ui,
        connected.is_some(),
        "Disconnect",
        vec![Command::Source(SourceCommand::Disconnect)],
    );
    let live = state.live();
    item(
        commands,
        ui,
        live.is_some(),
        "Settings…",
        vec![Command::ShowWindow(Window::SourceSettings, true)],
    );
    item(
        commands,
        ui,
        connected.is_some(),
        "Grab image",
        vec![Command::Source(SourceCommand::GrabImage)],
    );
    if let Some(l) = live {
        let mut on = l.streaming();
        if ui.checkbox(&mut on, "Stream live").changed() {
            commands.push(SourceCommand::SetStreaming(on).into());
        }
    }
    ui.separator();
    let recording = state.recording();
    item(
        commands,
        ui,
        connected.is_some() && recording.is_none(),
        "Start recording…",
        vec![Command::ShowWindow(Window::Record, true)],
    );
    item(
        commands,
        ui,
        recording.is_some(),
        "Stop recording",
        vec![Command::Source(SourceCommand::StopRecording)],
    );
    if let Some(p) = recording {
        ui.weak(format!("recording into {}", p.display()));
    }
    ui.separator();
    let other = state.other_table();
    ui.weak(format!(
        "table of the {} camera in use; {} camera's: {}",
        state.table_kind().name(),
        match state.table_kind() {
            CameraKind::Robot => "overhead",
            CameraKind::Overhead => "robot",
        },
        other
            .path()
            .map_or_else(|| "untitled".to_owned(), crate::frame::display_name)
    ));
}

/// A menu item that sends `cmds` and closes the menu.
fn item(commands: &mut Vec<Command>, ui: &mut Ui, enabled: bool, label: &str, cmds: Vec<Command>) {
    if ui.add_enabled(enabled, egui::Button::new(label)).clicked() {
        commands.extend(cmds);
        ui.close();
    }
}

/// The dialogs, each shown while its window is open.
pub fn camera_windows(
    ctx: &Context,
    state: &Workspace,
    dialogs: &mut CameraDialogs,
    commands: &mut Vec<Command>,
) {
    dialog(ctx, state, Window::Connect, commands, |ui, commands| {
        connect_ui(ui, dialogs, commands);
    });
    if !state.window_open(Window::Connect) {
        dialogs.found = None;
    }
    dialog(
        ctx,
        state,
        Window::SourceSettings,
        commands,
        |ui, commands| {
            settings_ui(ui, state, dialogs, commands);
        },
    );
    if !state.window_open(Window::SourceSettings) {
        dialogs.settings = None;
    }
    dialog(ctx, state, Window::Record, commands, |ui, commands| {
        record_ui(ui, dialogs, commands);
    });
}

fn dialog(
    ctx: &Context,
    state: &Workspace,
    w: Window,
    commands: &mut Vec<Command>,
    body: impl FnOnce(&mut Ui, &mut Vec<Command>),
) {
    if !state.window_open(w) {
        return;
    }
    let mut open = true;
    egui::Window::new(w.name())
        .open(&mut open)
        .collapsible(false)
        .default_pos([320.0, 120.0])
        .show(ctx, |ui| body(ui, commands));
    if !open {
        commands.push(Command::ShowWindow(w, false));
    }
}

fn connect_ui(ui: &mut Ui, d: &mut CameraDialogs, commands: &mut Vec<Command>) {
    let found = d.found.get_or_insert_with(available);
    for kind in [
        SourceKind::Camera,
        SourceKind::Synthetic,
        SourceKind::Stream,
        SourceKind::Network,
    ] {
        ui.radio_value(&mut d.kind, kind, kind.name());
    }
    ui.separator();
    let spec = match d.kind {
        SourceKind::Camera => {
            if let Some(note) = &found.camera_note {
                ui.label(note);
            }
            for (path, name) in &found.cameras {
                let label = format!("{} ({name})", path.display());
                ui.radio_value(&mut d.device, Some(path.clone()), label);
            }
            ui.checkbox(&mut d.overhead, "overhead camera (looks down at the field)");
            let kind = if d.overhead {
                CameraKind::Overhead
            } else {
                CameraKind::Robot
            };
            d.device
                .clone()
                .map(|device| SourceSpec::Camera { device, kind })
        }
        SourceKind::Synthetic => {
            egui::ComboBox::from_label("scenario")
                .selected_text(d.scenario.name())
                .show_ui(ui, |ui| {
                    for k in &found.scenarios {
                        ui.selectable_value(&mut d.scenario, *k, k.name())
                            .on_hover_text(k.description());
                    }
                });
            ui.add(egui::DragValue::new(&mut d.seed).prefix("seed "));
            Some(SourceSpec::Synthetic {
                scenario: d.scenario,
                seed: d.seed,
            })
        }
        SourceKind::Stream | SourceKind::Files => {
            path_field(
                ui,
                &mut d.stream_path,
                "/path/to/stream.mcap",
                "stream file",
            );
            let p = d.stream_path.trim();
            (!p.is_empty()).then(|| SourceSpec::Stream(PathBuf::from(p)))
        }
        SourceKind::Network => {
            ui.add(
                egui::TextEdit::singleline(&mut d.address)
                    .hint_text("ws://HOST:PORT")
                    .desired_width(300.0),
            )
            .labelled_by(ui.label("address").id);
            let a = d.address.trim();
            (!a.is_empty()).then(|| SourceSpec::Network(a.to_owned()))
        }
    };
    if ui
        .add_enabled(spec.is_some(), egui::Button::new("Connect"))
        .clicked()
        && let Some(spec) = spec
    {
        commands.push(SourceCommand::Connect(spec).into());
        commands.push(Command::ShowWindow(Window::Connect, false));
    }
}

fn path_field(ui: &mut Ui, text: &mut String, hint: &str, label: &str) {
    ui.horizontal(|ui| {
        let name = ui.label(label);
        ui.add(
            egui::TextEdit::singleline(text)
                .hint_text(hint)
                .desired_width(320.0),
        )
        .labelled_by(name.id);
    });
}

fn settings_ui(ui: &mut Ui, state: &Workspace, d: &mut CameraDialogs, commands: &mut Vec<Command>) {
    let Some(live) = state.live() else {
        ui.label("No live source connected.");
        return;
    };
    let controls = live.controls();
    let s = d.settings.get_or_insert_with(|| live.settings().clone());
    egui::Grid::new("source_settings")
        .num_columns(2)
        .show(ui, |ui| {
            ui.label("resolution");
            let text = s
                .resolution
                .map_or_else(|| "fixed".to_owned(), |r| r.to_string());
            if controls.resolutions.is_empty() {
                ui.label(text);
            } else {
                egui::ComboBox::from_id_salt("resolution")
                    .selected_text(text)
                    .show_ui(ui, |ui| {
                        for r in &controls.resolutions {
                            ui.selectable_value(&mut s.resolution, Some(*r), r.to_string());
                        }
                    });
            }
            ui.end_row();
            ui.label("frame rate");
            let mut fps = s.frame_rate.unwrap_or(30.0);
            if ui
                .add(
                    egui::DragValue::new(&mut fps)
                        .range(0.5..=120.0)
                        .suffix(" fps"),
                )
                .changed()
            {
                s.frame_rate = Some(fps);
            }
            ui.end_row();
            for (name, value, range) in [
                ("exposure", &mut s.exposure, controls.exposure),
                ("gain", &mut s.gain, controls.gain),
            ] {
                ui.label(name);
                match range {
                    Some(r) => {
                        let mut v = value.unwrap_or(r.min);
                        if ui.add(egui::Slider::new(&mut v, r.min..=r.max)).changed() {
                            *value = Some(v);
                        }
                    }
                    None => {
                        ui.weak("not offered");
                    }
                }
                ui.end_row();
            }
        });
    if ui.button("Apply").clicked() {
        commands.push(SourceCommand::SetSourceSettings(s.clone()).into());
    }
}

fn record_ui(ui: &mut Ui, d: &mut CameraDialogs, commands: &mut Vec<Command>) {
    ui.label("Record every frame of the connected source into an MCAP stream.");
    path_field(ui, &mut d.record_path, "/path/to/recording.mcap", "file");
    ui.horizontal(|ui| {
        if ui
            .button("Browse…")
            .on_hover_text("choose the file in a dialog; recording starts when it is chosen")
            .clicked()
        {
            d.browse_record = true;
            commands.push(Command::ShowWindow(Window::Record, false));
        }
        let p = d.record_path.trim();
        if ui
            .add_enabled(!p.is_empty(), egui::Button::new("Start recording"))
            .clicked()
        {
            commands.push(SourceCommand::StartRecording(PathBuf::from(p)).into());
            commands.push(Command::ShowWindow(Window::Record, false));
        }
    });
}
