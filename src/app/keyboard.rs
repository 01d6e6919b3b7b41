//! Keyboard shortcuts of the main window: undo/redo/save/quit, the sensitivity keys, stepping,
//! jumping to marks, playback, Escape.

use egui::{Key, KeyboardShortcut, Modifiers};

use super::{Command, EotnApp};
use crate::workspace::{HintsCommand, PlaybackCommand, TableCommand};

impl EotnApp {
    /// Turns this frame's key presses into commands; true when the window should close.
    /// Ctrl+S on a table without a file opens Save table as (saving needs a name).
    pub(super) fn keyboard(&mut self, ctx: &egui::Context, commands: &mut Vec<Command>) -> bool {
        let mut quit = false;
        if ctx.egui_wants_keyboard_input() {
            return quit;
        }
        let menu_open = egui::Popup::is_any_open(ctx);
        let untitled = self.state.table_path().is_none();
        let mut save_as = false;
        ctx.input_mut(|i| {
            let cmd = |k| KeyboardShortcut::new(Modifiers::COMMAND, k);
            if i.consume_shortcut(&KeyboardShortcut::new(
                Modifiers::COMMAND | Modifiers::SHIFT,
                Key::Z,
            )) || i.consume_shortcut(&cmd(Key::Y))
            {
                commands.push(TableCommand::Redo.into());
            }
            if i.consume_shortcut(&cmd(Key::Z)) {
                commands.push(TableCommand::Undo.into());
            }
            if i.consume_shortcut(&cmd(Key::S)) {
                if untitled {
                    save_as = true;
                } else {
                    commands.push(TableCommand::SaveTable.into());
                }
            }
            if i.consume_shortcut(&cmd(Key::Q)) {
                quit = true;
            }
            for (key, channel) in [(Key::Y, 0), (Key::U, 1), (Key::V, 2)] {
                let down = i.count_and_consume_key(Modifiers::SHIFT, key) as i32;
                let up = i.count_and_consume_key(Modifiers::NONE, key) as i32;
                if up != down {
                    commands.push(
                        TableCommand::AdjustSensitivity {
                            channel,
                            delta: up - down,
                        }
                        .into(),
                    );
                }
            }
            for (key, delta) in [(Key::Plus, 1), (Key::Equals, 1), (Key::Minus, -1)] {
                if i.consume_key(Modifiers::NONE, key) {
                    for channel in 0..3 {
                        commands.push(TableCommand::AdjustSensitivity { channel, delta }.into());
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
                        commands.push(PlaybackCommand::Step(delta * n as i64).into());
                    }
                }
                for (key, forward) in [(Key::ArrowRight, true), (Key::ArrowLeft, false)] {
                    if i.consume_key(Modifiers::COMMAND, key) {
                        commands.push(HintsCommand::JumpToMark { forward }.into());
                    }
                }
                if i.consume_key(Modifiers::NONE, Key::Home) {
                    commands.push(PlaybackCommand::Seek(0).into());
                }
                if i.consume_key(Modifiers::NONE, Key::End) {
                    commands.push(PlaybackCommand::Seek(usize::MAX).into());
                }
                if i.consume_key(Modifiers::NONE, Key::Space) {
                    commands.push(PlaybackCommand::SetPlaying(!self.state.playing()).into());
                }
            }
            // Escape closes an open menu first; only then does it drop the selection.
            if !menu_open && i.consume_key(Modifiers::NONE, Key::Escape) {
                commands.push(TableCommand::ClearSelection.into());
            }
        });
        if save_as {
            self.menu_input.dialog = Some((
                super::file_dialog::FileAction::SaveTableAs,
                Some("table.lut".to_owned()),
            ));
        }
        quit
    }
}
