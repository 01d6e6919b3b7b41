//! "Where did something happen?": the pipeline's events (ball found or lost, goal appears,
//! warnings, the frames a try-edit changes) and the user's bookmarks with notes, as lists with
//! next/previous jumps, and as marks on the timeline.

use egui::{Color32, Painter, Rect, Stroke, Ui, pos2};

use crate::workspace::bookmarks::EventKind;
use crate::workspace::{Command, HintsCommand, PlaybackCommand, Workspace};

/// Colour of the user's bookmarks on the timeline.
const BOOKMARK_COLOUR: Color32 = Color32::from_rgb(80, 170, 255);

/// Jumps, the note field, the user's bookmarks and the events.
pub fn bookmarks_ui(ui: &mut Ui, state: &Workspace, commands: &mut Vec<Command>) {
    if state.source().is_none() {
        ui.label("Open a stream or frames first.");
        return;
    }
    ui.horizontal(|ui| {
        if ui
            .button("Previous mark")
            .on_hover_text("Ctrl+Left: the previous event or bookmark")
            .clicked()
        {
            commands.push(HintsCommand::JumpToMark { forward: false }.into());
        }
        if ui
            .button("Next mark")
            .on_hover_text("Ctrl+Right: the next event or bookmark")
            .clicked()
        {
            commands.push(HintsCommand::JumpToMark { forward: true }.into());
        }
    });
    let id = egui::Id::unique("bookmark_note");
    let mut note: String = ui.data(|d| d.get_temp(id)).unwrap_or_default();
    ui.horizontal(|ui| {
        let label = ui.label("note");
        ui.add(egui::TextEdit::singleline(&mut note).desired_width(160.0))
            .labelled_by(label.id);
        if ui
            .button("Bookmark this frame")
            .on_hover_text("saved beside the stream as STREAM.bookmarks.json")
            .clicked()
        {
            commands.push(HintsCommand::AddBookmark(std::mem::take(&mut note)).into());
        }
    });
    ui.data_mut(|d| d.insert_temp(id, note));
    user_bookmarks_ui(ui, state, commands);
    ui.separator();
    labels_ui(ui, state, commands);
    events_ui(ui, state, commands);
}

/// The opened labels' report, as `eotn eval --labels` gives it, over the frames scored so far
/// with the table and parameters in use (scored again when they change), and the split scored.
fn labels_ui(ui: &mut Ui, state: &Workspace, commands: &mut Vec<Command>) {
    use crate::eval::label_sets::Split;
    let Some(labels) = state.labels() else {
        return;
    };
    let r = labels.report();
    let (done, total) = labels.progress();
    ui.label(format!("Labels: {}", labels.path.display()));
    ui.horizontal(|ui| {
        ui.label("Score");
        for (split, name, hover) in [
            (Split::All, "all frames", "every labelled frame"),
            (
                Split::Tuning,
                "tuning",
                "frames whose number ends in 0–6: the ones to make the table on",
            ),
            (
                Split::HeldOut,
                "held out",
                "frames whose number ends in 7, 8 or 9: kept for reporting, never tuned on",
            ),
        ] {
            if ui
                .selectable_label(labels.split() == split, name)
                .on_hover_text(hover)
                .clicked()
                && labels.split() != split
            {
                commands.push(Command::SetLabelsSplit(split));
            }
        }
    });
    if !labels.done() {
        ui.add(
            egui::ProgressBar::new(done as f32 / total.max(1) as f32)
                .text(format!("scored {done} / {total} frames")),
        );
    }
    let pct = |v: Option<f64>| v.map_or_else(|| "—".to_owned(), |v| format!("{:.1}%", v * 100.0));
    egui::Grid::new("labels_report").show(ui, |ui| {
        ui.label("frame recall");
        ui.label(format!("{} / {} = {}", r.found, r.eligible, pct(r.recall)));
        ui.end_row();
        ui.label("precision");
        ui.label(format!(
            "{} / {} = {}",
            r.correct,
            r.reported,
            pct(r.precision)
        ));
        ui.end_row();
        ui.label("false balls");
        ui.label(format!(
            "{} in robot boxes, {} in goal boxes, {} in other boxes, {} elsewhere",
            r.false_in_robot, r.false_in_goal, r.false_in_other, r.false_elsewhere
        ));
        ui.end_row();
        if let Some(c) = &r.centre_error {
            ui.label("centre error");
            ui.label(format!("median {:.2}, p90 {:.2} of the box", c.p50, c.p90));
            ui.end_row();
        }
        ui.label("labelled frames");
        ui.label(format!(
            "{} scored, {} with a ball",
            r.frames, r.frames_with_ball
        ));
        ui.end_row();
    });
    ui.separator();
}

fn user_bookmarks_ui(ui: &mut Ui, state: &Workspace, commands: &mut Vec<Command>) {
    let marks = state.bookmarks();
    if marks.is_empty() {
        ui.weak("No bookmarks.");
        return;
    }
    egui::Grid::new("user_bookmarks")
        .striped(true)
        .show(ui, |ui| {
            for b in marks {
                if ui
                    .selectable_label(b.frame == state.index(), format!("frame {}", b.frame))
                    .clicked()
                {
                    commands.push(PlaybackCommand::Seek(b.frame).into());
                }
                ui.label(&b.note);
                if ui
                    .small_button("Remove")
                    .on_hover_text(format!("remove the bookmark at frame {}", b.frame))
                    .clicked()
                {
                    commands.push(HintsCommand::RemoveBookmark(b.frame).into());
                }
                ui.end_row();
            }
        });
}

fn events_ui(ui: &mut Ui, state: &Workspace, commands: &mut Vec<Command>) {
    ui.horizontal(|ui| {
        if ui
            .button("Find events")
            .on_hover_text("run the pipeline over every frame: ball found or lost, goals, warnings")
            .clicked()
        {
            commands.push(HintsCommand::FindEvents.into());
        }
        if let Some(scan) = state.event_scan().filter(|s| !s.done()) {
            ui.add(
                egui::ProgressBar::new(scan.next as f32 / scan.total.max(1) as f32)
                    .text(format!("{} / {}", scan.next, scan.total)),
            );
        }
    });
    let events = state.events();
    if events.is_empty() {
        ui.weak("No events (Find events; a pending try-edit adds the frames it changes).");
        return;
    }
    egui::Grid::new("events").striped(true).show(ui, |ui| {
        for e in &events {
            if ui
                .selectable_label(e.frame == state.index(), format!("frame {}", e.frame))
                .clicked()
            {
                commands.push(PlaybackCommand::Seek(e.frame).into());
            }
            ui.colored_label(event_colour(e.kind), e.kind.describe());
            ui.label(&e.detail);
            ui.end_row();
        }
    });
}

/// The colour of an event's mark: the ball's orange, the goal's colour, warnings red.
fn event_colour(kind: EventKind) -> Color32 {
    let rgb = match kind {
        EventKind::BallFound => [255, 140, 0],
        EventKind::BallLost => [150, 90, 40],
        EventKind::GoalAppears(c) => c.display_rgb(),
        EventKind::Warning => [230, 50, 50],
        EventKind::TryEditChange => [255, 0, 255],
        EventKind::LabelMissed => [255, 200, 0],
        EventKind::LabelFalse => [255, 60, 160],
    };
    Color32::from_rgb(rgb[0], rgb[1], rgb[2])
}

/// Marks on the timeline slider (`rect`, frames `0..len`): events as short ticks below its
/// middle, bookmarks as taller blue ticks.
pub fn timeline_marks(painter: &Painter, rect: Rect, state: &Workspace, len: usize) {
    if len < 2 {
        return;
    }
    // The slider's handle travels between its ends less its radius.
    let inset = rect.height() / 2.0;
    let x_of = |frame: usize| {
        rect.left() + inset + (rect.width() - 2.0 * inset) * frame as f32 / (len - 1) as f32
    };
    for e in state.events() {
        let x = x_of(e.frame);
        painter.line_segment(
            [pos2(x, rect.center().y), pos2(x, rect.bottom())],
            Stroke::new(2.0, event_colour(e.kind)),
        );
    }
    for b in state.bookmarks() {
        let x = x_of(b.frame);
        painter.line_segment(
            [pos2(x, rect.top()), pos2(x, rect.bottom())],
            Stroke::new(2.0, BOOKMARK_COLOUR),
        );
    }
}
