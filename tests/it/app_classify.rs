//! Making a table by hand after a new user's round (issue 33), with egui_kittest on the real
//! app: the selection preview counts exactly the pixels a commit changes (on overhead frames
//! too) and hatches them; a click in the image takes the keyboard; Ctrl+S on an untitled table
//! asks for a name; a coverage hint is committed only in a class chosen for it, names the
//! frames it comes from, keeps its row after a commit and splits into cells; Try edit says when
//! its result is for an earlier selection and lists the most changed frames first; the Classify
//! panel's buttons stay in view in an 800-point window.

use std::path::{Path, PathBuf};
use std::time::Duration;

use egui::{Key, PointerButton, Vec2};
use egui_kittest::kittest::{NodeT as _, Queryable as _};
use eotn::frame::{Frame, Yuv};
use eotn::lut::{ColourClass, EditRecord, LookupTable, Region, Sensitivity};
use eotn::workspace::{Command, HintsCommand, SelectionClass, TableCommand, Window, Workspace};

use crate::common::repo_file;
use crate::harness::{
    GREEN, click_at, click_label, fixture, harness_sized, harness_with, pixel_pos, run_until,
    show_window, workspace,
};

/// Pixels whose class differs between two classified images.
fn changed(before: &[u8], after: &[u8]) -> usize {
    before.iter().zip(after).filter(|(a, b)| a != b).count()
}

/// The number before `what` in the label that contains it (`"12 pixels of this frame…"`).
fn number_before(label: &str, what: &str) -> usize {
    let head = &label[..label
        .find(what)
        .unwrap_or_else(|| panic!("{what} in {label}"))];
    head.split_whitespace()
        .last()
        .and_then(|n| n.trim_start_matches('(').parse().ok())
        .unwrap_or_else(|| panic!("a number before {what} in {label}"))
}

#[test]
fn an_overhead_frames_preview_counts_the_pixels_a_commit_changes() {
    let mut w = Workspace::default();
    w.apply(Command::Open(vec![repo_file(
        "streams/sim-overhead-game.mcap",
    )]))
    .unwrap();
    assert!(w.overhead().active());
    // The stream's own table, copied: a commit writes the table's journal beside it.
    let dir = tempfile::tempdir().unwrap();
    let table = dir.path().join("sim-overhead.lut");
    std::fs::copy(repo_file("lookup_tables/sim-overhead.lut"), &table).unwrap();
    w.apply(Command::OpenTable(table)).unwrap();
    // A carpet pixel the overhead table already calls green.
    let green = ColourClass::Green.code();
    let codes = w.classified().codes().to_vec();
    let width = w.image_size().0;
    let at = codes.iter().position(|&c| c == green).expect("carpet");
    let (x, y) = (at % width, at / width);
    w.apply(TableCommand::SetClass(ColourClass::Green).into())
        .unwrap();
    w.apply(TableCommand::SetSensitivity(Sensitivity::uniform(3)).into())
        .unwrap();
    let mut h = harness_with(w);
    h.run();
    click_at(&h, pixel_pos(&h, x, y), PointerButton::Primary);
    h.run();
    let node = h.get_by_label_contains("pixels of this frame change to green");
    let a = node.accesskit_node();
    let label = a.value().or_else(|| a.label()).unwrap_or_default();
    let shown = number_before(&label, "pixels of this frame");
    let already = number_before(&label, "already green");
    let (selected, changing) = workspace(&h).selection_pixel_counts();
    assert_eq!((shown, already), (changing, selected - changing), "{label}");
    assert!(changing > 0 && already > 0, "{label}");
    click_label(&mut h, "Commit");
    let after = workspace(&h).classified().codes();
    assert_eq!(
        changed(&codes, after),
        changing,
        "the count is what the commit changed"
    );
}

/// A frame with a field, an orange ball and a yellow bar, and a table with the field green.
fn one_frame(dir: &Path) -> (PathBuf, PathBuf) {
    let (frames, table) = fixture(dir);
    (frames[0].clone(), table)
}

#[test]
fn pixels_already_in_the_class_are_neither_counted_nor_hatched() {
    use eotn::app::preview_image;
    let dir = tempfile::tempdir().unwrap();
    let (frame, table) = one_frame(dir.path());
    let mut w = Workspace::default();
    w.apply(Command::Open(vec![frame, table])).unwrap();
    w.apply(TableCommand::SetClass(ColourClass::Green).into())
        .unwrap();
    // A green pixel, class green: every selected pixel is green already.
    w.apply(TableCommand::Sample { x: 150, y: 120 }.into())
        .unwrap();
    let (selected, changing) = w.selection_pixel_counts();
    assert!(selected > 20_000, "{selected}");
    assert_eq!(changing, 0);
    let img = preview_image(&w, [208, 160]);
    assert_eq!(img.pixels[120 * 208 + 150], egui::Color32::TRANSPARENT);
    // Class orange: the same pixels would all change, and are hatched in stripes of orange
    // and a contrasting colour, unlike a solid fill in the class's own colour.
    w.apply(TableCommand::SetClass(ColourClass::Orange).into())
        .unwrap();
    assert_eq!(w.selection_pixel_counts(), (selected, selected));
    let img = preview_image(&w, [208, 160]);
    let [r, g, b] = ColourClass::Orange.display_rgb();
    let orange = egui::Color32::from_rgb(r, g, b);
    let row: Vec<egui::Color32> = (148..152).map(|x| img.pixels[120 * 208 + x]).collect();
    assert!(row.contains(&orange), "{row:?}");
    assert!(row.iter().any(|c| *c != orange && c.a() == 255), "{row:?}");
    // Outside the selection (the ball) is dimmed, not hatched.
    assert!(img.pixels[50 * 208 + 65].a() < 255);
}

/// The main view draws the class colours blended over the frame on the CPU (one textured layer
/// for a software rasteriser to fill, not two: issue 33 item 9): each texel is what blending the
/// class layer over the frame at the overlay's opacity gives, `c·a + r·(1 − a)` rounded to
/// nearest, and the frame itself where no class colour is.
#[test]
fn class_colours_blend_over_the_frame_as_the_renderer_would() {
    use egui::{Color32, ColorImage};
    use eotn::app::{blend_classes, blend_texel, classes_alpha};
    assert_eq!(classes_alpha(0.5), 127);
    assert_eq!(classes_alpha(2.0), 255);
    assert_eq!(classes_alpha(f32::NAN), 0);
    for alpha in [0_u8, 1, 64, 127, 128, 200, 254, 255] {
        let a = u32::from(alpha);
        for c in 0..=255_u8 {
            for r in 0..=255_u8 {
                let exact = (u32::from(c) * a + u32::from(r) * (255 - a) + 127) / 255;
                let got = blend_texel(Color32::from_gray(r), Color32::from_gray(c), alpha);
                assert_eq!(u32::from(got.r()), exact, "c {c} r {r} alpha {alpha}");
                assert_eq!((got.g(), got.b(), got.a()), (got.r(), got.r(), 255));
            }
        }
    }
    let raw = Color32::from_rgb(10, 200, 30);
    assert_eq!(blend_texel(raw, Color32::TRANSPARENT, 255), raw);
    let frame = ColorImage::new([2, 1], vec![raw, raw]);
    let classes = ColorImage::new([2, 1], vec![Color32::TRANSPARENT, Color32::WHITE]);
    let blended = blend_classes(&frame, &classes, 255);
    assert_eq!(blended.pixels, vec![raw, Color32::WHITE]);
    // Images of different sizes are not blended.
    let other = ColorImage::new([1, 1], vec![Color32::WHITE]);
    assert_eq!(blend_classes(&frame, &other, 255).pixels, frame.pixels);
}

/// A frame large enough for the view's images to be made on two threads (640×480 at full
/// resolution) gives the same texels as a pixel at a time: each the frame's pixel in colour,
/// its class colour, and their blend over each other.
#[test]
fn large_views_made_on_two_threads_hold_every_pixel_in_its_place() {
    use eotn::app::{blend_classes, blend_texel, classes_alpha, palette, view_images_every};
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("big.png");
    image::RgbImage::from_fn(640, 480, |x, y| {
        image::Rgb([
            (x % 256) as u8,
            (y % 256) as u8,
            ((x * 7 + y * 3) % 256) as u8,
        ])
    })
    .save(&png)
    .unwrap();
    let (_, table) = one_frame(dir.path());
    let mut w = Workspace::default();
    w.apply(Command::Open(vec![png, table])).unwrap();
    let p = palette();
    let images = view_images_every(&w, &p, 1).unwrap();
    let frame = w.frame().unwrap();
    let codes = w.classified().codes();
    assert_eq!(images.raw.size, [640, 480]);
    assert!(codes.iter().any(|&c| c != 0), "some pixels are classified");
    let alpha = classes_alpha(0.5);
    let blended = blend_classes(&images.raw, &images.classified, alpha);
    for (i, (&raw, &class)) in images
        .raw
        .pixels
        .iter()
        .zip(&images.classified.pixels)
        .enumerate()
    {
        let [r, g, b] = eotn::frame::yuv_to_rgb(frame.pixel(i % 640, i / 640).unwrap());
        assert_eq!(raw, egui::Color32::from_rgb(r, g, b), "texel {i}");
        assert_eq!(class, p[usize::from(codes[i])], "texel {i}");
        assert_eq!(
            blended.pixels[i],
            blend_texel(raw, class, alpha),
            "texel {i}"
        );
    }
}

/// Zoomed in past 1:1 on a large image, the layers hold the visible part grown by half its size
/// each way (even columns), keep it while panning stays inside, and hold the whole image again
/// once most of it is visible; the part's images are the frame's pixels there.
#[test]
fn zoomed_in_layers_hold_the_visible_part_and_keep_it_while_it_covers_the_view() {
    use eotn::app::overlays::ImageTransform;
    use eotn::app::{palette, view_images_in, visible_region};
    let view = egui::Rect::from_min_size(egui::pos2(0.0, 0.0), egui::vec2(400.0, 300.0));
    let at = |zoom: f32, cx: f32, cy: f32| ImageTransform {
        view,
        zoom,
        centre: egui::pos2(cx, cy),
        size: [1920.0, 1200.0],
    };
    // 200×150 image pixels visible around (960, 600), grown by 100×75 each way.
    let r = visible_region(&at(2.0, 960.0, 600.0), [1920, 1200], None).unwrap();
    assert_eq!(r, [760, 450, 1160, 750]);
    // A small pan stays inside: kept. A large one leaves it: a new part around the view.
    assert_eq!(
        visible_region(&at(2.0, 1000.0, 620.0), [1920, 1200], Some(r)),
        Some(r)
    );
    let moved = visible_region(&at(2.0, 1500.0, 600.0), [1920, 1200], Some(r)).unwrap();
    assert_eq!(moved, [1300, 450, 1700, 750]);
    // Near the edge the part is cut at the image; most of the image visible: the whole image.
    let edge = visible_region(&at(2.0, 50.0, 50.0), [1920, 1200], None).unwrap();
    assert_eq!(edge[..2], [0, 0]);
    assert_eq!(
        visible_region(&at(0.3, 960.0, 600.0), [1920, 1200], None),
        None
    );
    // The part's images: the frame's pixels and class colours there.
    let dir = tempfile::tempdir().unwrap();
    let (frame, table) = one_frame(dir.path());
    let mut w = Workspace::default();
    w.apply(Command::Open(vec![frame, table])).unwrap();
    let p = palette();
    let part = view_images_in(&w, &p, [40, 30, 120, 90]).unwrap();
    assert_eq!(part.raw.size, [80, 60]);
    let f = w.frame().unwrap();
    let codes = w.classified().codes();
    for (i, (&raw, &class)) in part
        .raw
        .pixels
        .iter()
        .zip(&part.classified.pixels)
        .enumerate()
    {
        let (x, y) = (40 + i % 80, 30 + i / 80);
        let [r, g, b] = eotn::frame::yuv_to_rgb(f.pixel(x, y).unwrap());
        assert_eq!(raw, egui::Color32::from_rgb(r, g, b), "({x}, {y})");
        assert_eq!(class, p[usize::from(codes[y * 208 + x])], "({x}, {y})");
    }
}

/// Thumbnails keep at least 320 texels across, their own layers when that is coarser than
/// the main view's.
#[test]
fn thumbnails_keep_at_least_320_texels_across() {
    use eotn::app::thumbnail_step;
    assert_eq!(thumbnail_step(208), 1);
    assert_eq!(thumbnail_step(640), 2);
    assert_eq!(thumbnail_step(1920), 6);
    assert_eq!(thumbnail_step(0), 1);
}

/// A view smaller than the image keeps one pixel in `step` each way (what nearest filtering
/// shows at that scale): each texel is the image's pixel at (x·step, y·step), raw, classified
/// and preview alike (issue 33 item 9: a 1920×1200 frame fitted into the window was converted
/// and uploaded whole on every step).
#[test]
fn a_view_smaller_than_the_image_keeps_every_steps_pixel() {
    use eotn::app::{
        palette, preview_image, preview_image_every, texture_step, view_images, view_images_every,
    };
    assert_eq!(texture_step(1.0), 1);
    assert_eq!(texture_step(2.5), 1);
    assert_eq!(texture_step(0.5), 2);
    assert_eq!(texture_step(0.34), 2);
    assert_eq!(texture_step(0.33), 3);
    assert_eq!(texture_step(f32::NAN), 1);
    assert_eq!(texture_step(0.0), 1);
    let dir = tempfile::tempdir().unwrap();
    let (frame, table) = one_frame(dir.path());
    let mut w = Workspace::default();
    w.apply(Command::Open(vec![frame, table])).unwrap();
    w.settings.overlays.classified = true;
    w.apply(TableCommand::SetClass(ColourClass::Orange).into())
        .unwrap();
    w.apply(TableCommand::Sample { x: 150, y: 120 }.into())
        .unwrap();
    let p = palette();
    let whole = view_images(&w, &p).unwrap();
    let whole_preview = preview_image(&w, [208, 160]);
    for step in [2, 3, 5] {
        let part = view_images_every(&w, &p, step).unwrap();
        let preview = preview_image_every(&w, [208, 160], step);
        let size = [208_usize.div_ceil(step), 160_usize.div_ceil(step)];
        assert_eq!(part.raw.size, size);
        assert_eq!(part.classified.size, size);
        assert_eq!(preview.size, size);
        for ty in 0..size[1] {
            for tx in 0..size[0] {
                let (t, i) = (ty * size[0] + tx, ty * step * 208 + tx * step);
                assert_eq!(
                    part.raw.pixels[t], whole.raw.pixels[i],
                    "step {step} ({tx}, {ty})"
                );
                assert_eq!(part.classified.pixels[t], whole.classified.pixels[i]);
                // Hatched texels keep their stripes in texels: opaque where the whole
                // preview is, dimmed or clear where it is.
                let (a, b) = (preview.pixels[t], whole_preview.pixels[i]);
                assert_eq!(a.a() == 255, b.a() == 255, "step {step} ({tx}, {ty})");
                if b.a() < 255 {
                    assert_eq!(a, b);
                }
            }
        }
    }
}

#[test]
fn a_click_in_the_image_takes_the_keyboard_from_a_text_field() {
    let dir = tempfile::tempdir().unwrap();
    let (frame, table) = one_frame(dir.path());
    let mut w = Workspace::default();
    w.apply(Command::Open(vec![frame, table])).unwrap();
    let mut h = harness_with(w);
    show_window(&mut h, Window::Parameters);
    let find = h.get_by_label("Find");
    find.focus();
    find.type_text("y");
    h.run();
    let y0 = workspace(&h).settings.sensitivity.y;
    h.key_press(Key::Y);
    h.run();
    assert_eq!(
        workspace(&h).settings.sensitivity.y,
        y0,
        "Y went to the field"
    );
    click_at(&h, pixel_pos(&h, 150, 120), PointerButton::Primary);
    h.run();
    h.key_press(Key::Y);
    h.run();
    assert_eq!(
        workspace(&h).settings.sensitivity.y,
        y0 + 1,
        "Y after the click"
    );
}

#[test]
fn ctrl_s_on_a_table_without_a_file_opens_save_as() {
    use eotn::app::file_dialog::FileAction;
    let dir = tempfile::tempdir().unwrap();
    let (frame, _) = one_frame(dir.path());
    let mut w = Workspace::default();
    w.apply(Command::Open(vec![frame])).unwrap();
    assert!(w.table_path().is_none());
    let mut h = harness_with(w);
    h.run();
    h.key_press_modifiers(egui::Modifiers::COMMAND, Key::S);
    // One step: the dialog (egui_file's, whose text fields have no accessible names) opens.
    h.step();
    assert_eq!(
        h.state().file_dialogs.shown(),
        Some(FileAction::SaveTableAs)
    );
}

/// Frames of two colours the table leaves unclassified: `A` (more pixels) and `B`, on green.
const A: Yuv = Yuv::new(120, 80, 190);
const B: Yuv = Yuv::new(60, 160, 100);

/// Width of the two-colour frames, pixels (208×160: a size raw frame files are known by).
const W: usize = 208;

/// Three 208×160 frames: frame `k` shows `(k + 1) × 10` rows of A and 6 rows of B.
fn two_colour_frames(dir: &Path) -> (Vec<PathBuf>, PathBuf) {
    let mut frames = Vec::new();
    for k in 0..3 {
        let f = Frame::uyvy_from_fn(W, 160, |_, y| {
            if y < (k + 1) * 10 {
                A
            } else if y >= 154 {
                B
            } else {
                GREEN
            }
        })
        .unwrap();
        let p = dir.join(format!("c{k}.uyvy"));
        std::fs::write(&p, f.data()).unwrap();
        frames.push(p);
    }
    let mut lut = LookupTable::new(7).unwrap();
    lut.apply(EditRecord::now(
        ColourClass::Green,
        Region::AroundSample {
            sample: GREEN,
            sensitivity: Sensitivity::uniform(1),
        },
    ));
    let table = dir.join("t.lut");
    lut.save(&table).unwrap();
    (frames, table)
}

fn counted(w: &Workspace) -> bool {
    w.coverage().is_some_and(|c| c.done())
}

#[test]
fn a_coverage_hint_is_committed_only_in_a_class_chosen_for_it() {
    let dir = tempfile::tempdir().unwrap();
    let (mut paths, table) = two_colour_frames(dir.path());
    paths.push(table);
    let mut w = Workspace::default();
    w.apply(Command::Open(paths)).unwrap();
    // The class picked earlier in the Classify panel: not the hint's.
    w.apply(TableCommand::SetClass(ColourClass::Orange).into())
        .unwrap();
    w.apply(HintsCommand::FindUnclassified { first: 0, last: 2 }.into())
        .unwrap();
    let mut h = harness_sized(Vec::new(), Vec2::new(1280.0, 800.0));
    h.state_mut().state = w;
    run_until(&mut h, Duration::from_secs(20), |a| counted(&a.state));
    click_label(&mut h, "hint 1");
    let sel = workspace(&h).selection().unwrap().clone();
    assert_eq!(sel.class, SelectionClass::Unchosen);
    let cells_before = workspace(&h).table_counts()[usize::from(ColourClass::Orange.code())];
    // Right-click commit: refused until a class is chosen for these colours.
    click_at(&h, pixel_pos(&h, 10, 2), PointerButton::Secondary);
    h.run();
    assert_eq!(
        workspace(&h).table_counts()[usize::from(ColourClass::Orange.code())],
        cells_before
    );
    assert!(
        workspace(&h).status.contains("choose the class"),
        "{}",
        workspace(&h).status
    );
    // The preview is neutral (no class colour) while none is chosen.
    assert_eq!(workspace(&h).preview_colour(), Some([235, 235, 235]));
    click_label(&mut h, "class of these colours");
    // The open list's "pink" (the Classify panel lists the classes too).
    h.get_all_by_label("pink").last().unwrap().click();
    h.run();
    assert_eq!(
        workspace(&h).selection().unwrap().class,
        SelectionClass::Chosen(ColourClass::Pink)
    );
    click_label(&mut h, "Commit as pink");
    assert!(
        workspace(&h).table_counts()[usize::from(ColourClass::Pink.code())] > 0,
        "committed as pink"
    );
    assert_eq!(
        workspace(&h).table_counts()[usize::from(ColourClass::Orange.code())],
        cells_before,
        "not as the Classify panel's orange"
    );
}

#[test]
fn coverage_hints_name_their_frames_keep_their_rows_and_split_into_cells() {
    let dir = tempfile::tempdir().unwrap();
    let (mut paths, table) = two_colour_frames(dir.path());
    paths.push(table);
    let mut w = Workspace::default();
    w.apply(Command::Open(paths)).unwrap();
    w.apply(HintsCommand::FindUnclassified { first: 0, last: 2 }.into())
        .unwrap();
    let mut h = harness_sized(Vec::new(), Vec2::new(1280.0, 800.0));
    h.state_mut().state = w;
    run_until(&mut h, Duration::from_secs(20), |a| counted(&a.state));
    let hints = workspace(&h).coverage().unwrap().hints().to_vec();
    assert_eq!(hints.len(), 2, "{hints:?}");
    let lut = workspace(&h).lut().clone();
    assert!(hints[0].cells.contains(&lut.index(A)));
    // A's pixels are most in frame 2 (30 rows), B's the same in each (frame 0 first).
    assert_eq!(hints[0].frames[0], (2, 30 * W as u64));
    assert_eq!(hints[0].frames.len(), 3);
    // The shown frame (0) has 10 rows of A: the "here" column.
    assert_eq!(workspace(&h).pixels_here(&hints[0].cells), 10 * W as u64);
    // "frame 2" goes there with the hint's pixels previewed.
    click_label(&mut h, "frame 2");
    assert_eq!(workspace(&h).index(), 2);
    assert_eq!(
        workspace(&h).selection().map(|s| s.region.clone()),
        Some(Region::Cells {
            indices: hints[0].cells.clone()
        })
    );
    // Committed, hint 1 keeps its row (marked with its class); hint 2 stays second.
    h.state_mut()
        .state
        .run(TableCommand::SetClass(ColourClass::Orange).into());
    h.state_mut().state.run(TableCommand::Commit.into());
    h.run();
    let after = workspace(&h).coverage().unwrap().hints().to_vec();
    assert_eq!(after.len(), 2);
    assert_eq!(after[0].done, Some(ColourClass::Orange));
    assert_eq!(after[1].cells, hints[1].cells);
    assert!(h.query_by_label("now orange").is_some());
    // Re-rank orders afresh: only B is left.
    click_label(&mut h, "Re-rank");
    assert_eq!(workspace(&h).coverage().unwrap().hints().len(), 1);
    // A hint splits into its cells, each selectable alone.
    let cells = workspace(&h).coverage().unwrap().hints()[0].cells.clone();
    click_label(&mut h, &format!("{} cells", cells.len()));
    assert!(h.query_by_label("Cells of hint 1").is_some());
    let first = h.get_all_by_label_contains("cell ").next().unwrap();
    first.click();
    h.run();
    match &workspace(&h).selection().unwrap().region {
        Region::Cells { indices } => assert_eq!(indices.len(), 1),
        other => panic!("{other:?}"),
    }
}

#[test]
fn try_edit_says_when_its_result_is_for_an_earlier_selection() {
    let dir = tempfile::tempdir().unwrap();
    let (mut paths, table) = fixture(dir.path());
    paths.push(table);
    let mut w = Workspace::default();
    w.apply(Command::Open(paths)).unwrap();
    w.apply(TableCommand::SetClass(ColourClass::Orange).into())
        .unwrap();
    w.apply(TableCommand::Sample { x: 65, y: 45 }.into())
        .unwrap();
    w.apply(TableCommand::TryEditOnStream.into()).unwrap();
    let mut h = harness_sized(Vec::new(), Vec2::new(1280.0, 800.0));
    h.state_mut().state = w;
    run_until(&mut h, Duration::from_secs(20), |a| {
        a.state
            .try_edit()
            .is_some_and(eotn::workspace::TryEdit::done)
    });
    assert!(!workspace(&h).try_edit_stale());
    assert!(h.query_by_label("Try again").is_some());
    // Most changed first: the button goes to the frame with most changed pixels.
    let rows = workspace(&h).try_edit().unwrap().stream.rows.clone();
    let most = rows.iter().max_by_key(|r| r.changed_pixels).unwrap();
    click_label(
        &mut h,
        &format!(
            "Go to frame {} ({} px change)",
            most.index, most.changed_pixels
        ),
    );
    assert_eq!(workspace(&h).index(), most.index);
    // Another sensitivity: the result is an earlier selection's, and says so.
    h.state_mut()
        .state
        .run(TableCommand::SetSensitivity(Sensitivity::uniform(4)).into());
    h.run();
    assert!(workspace(&h).try_edit_stale());
    assert!(h.query_by_label_contains("earlier selection").is_some());
    click_label(&mut h, "Try the current selection");
    assert!(!workspace(&h).try_edit_stale());
}

#[test]
fn the_classify_buttons_stay_in_view_in_an_800_point_window() {
    let (stream, table) = (
        repo_file("streams/bhuman2009.mcap"),
        repo_file("lookup_tables/bhuman2009.lut"),
    );
    let mut w = Workspace::default();
    w.apply(Command::Open(vec![stream, table])).unwrap();
    w.apply(TableCommand::Sample { x: 100, y: 200 }.into())
        .unwrap();
    w.apply(Command::ShowWindow(Window::TryEdit, true)).unwrap();
    let mut h = harness_sized(Vec::new(), Vec2::new(1280.0, 800.0));
    h.state_mut().state = w;
    h.run_steps(4);
    for label in ["Commit", "Clear", "Try on whole stream", "Undo", "Redo"] {
        let r = h.get_all_by_label(label).next().unwrap().rect();
        assert!(r.bottom() <= 800.0 && r.top() >= 0.0, "{label} at {r:?}");
    }
}

#[test]
fn on_the_real_ssl_frames_the_count_is_what_a_commit_changes() {
    // Issue 33 reported 10,936 "changing" pixels for a sample that was already green on these
    // frames: the count must be what a commit then changes, pixel for pixel.
    let Some(frame) = crate::common::shared_file("data/ssl-onboard/images/00003.jpg") else {
        return;
    };
    // The table copied: a commit writes the table's journal beside it.
    let dir = tempfile::tempdir().unwrap();
    let table = dir.path().join("ssl-onboard.lut");
    std::fs::copy(repo_file("lookup_tables/ssl-onboard.lut"), &table).unwrap();
    let mut w = Workspace::default();
    w.apply(Command::Open(vec![frame, table])).unwrap();
    let green = ColourClass::Green.code();
    let (width, _) = w.image_size();
    let codes = w.classified().codes().to_vec();
    let at = codes
        .iter()
        .position(|&c| c == green)
        .expect("green carpet");
    w.apply(TableCommand::SetClass(ColourClass::Green).into())
        .unwrap();
    for s in [0u8, 2, 4] {
        w.apply(TableCommand::SetSensitivity(Sensitivity::uniform(s)).into())
            .unwrap();
        w.apply(
            TableCommand::Sample {
                x: at % width,
                y: at / width,
            }
            .into(),
        )
        .unwrap();
        let (_, changing) = w.selection_pixel_counts();
        let before = w.classified().codes().to_vec();
        w.apply(TableCommand::Commit.into()).unwrap();
        assert_eq!(
            changed(&before, w.classified().codes()),
            changing,
            "sensitivity {s}"
        );
        w.apply(TableCommand::Undo.into()).unwrap();
        assert_eq!(w.classified().codes(), &before[..]);
    }
}
