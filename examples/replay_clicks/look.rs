//! `replay_clicks --look`: what the app's windows show after the clicks, printed, for choosing
//! the next ones — the opened labels' report on the tuning frames (Events and bookmarks), the
//! coverage hints (Classify ▸ What is still unclassified?) with where each shows most, and the
//! whole-set preview of a tried click (Try selection on whole stream) with the labels' report
//! while it is committed. Everything goes through the workspace's commands, as the window's
//! clicks do; only "where a hint shows" is counted here (the window highlights it instead).

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::time::Duration;

use anyhow::Context as _;
use eotn::eval::ball_boxes::BoxReport;
use eotn::eval::label_sets::Split;
use eotn::frame::{load_frame, yuv_to_rgb};
use eotn::lut::{ColourClass, Sensitivity};
use eotn::workspace::{Command, HintsCommand, PlaybackCommand, TableCommand, Workspace};

/// What to show.
#[derive(Debug, Default)]
pub struct Look {
    /// A label set to open over the frames (scored on the tuning split).
    pub labels: Option<PathBuf>,
    /// Recognition parameters to open first (File ▸ Open parameters…).
    pub params: Option<PathBuf>,
    /// How many coverage hints to list (0: none).
    pub hints: usize,
    /// The frames the hints count, by name (first and last, inclusive): every frame when
    /// not given (the window's "frames from … to …").
    pub hint_range: Option<(String, String)>,
    /// Clicks to preview.
    pub tries: Vec<Try>,
    /// Where to draw each listed hint over the frame showing most of it (`hint-K.png`: the
    /// frame, and beside it the hint's pixels in magenta, as the window highlights them).
    pub hint_pngs: Option<PathBuf>,
}

/// One click to preview: `CLASS:Y,U,V:FRAME:X,Y` (sensitivity in ± cells).
#[derive(Debug)]
pub struct Try {
    class: ColourClass,
    sensitivity: Sensitivity,
    frame: String,
    x: usize,
    y: usize,
}

impl Try {
    /// Reads `orange:1,1,1:00012.jpg:175,113`.
    pub fn parse(text: &str) -> anyhow::Result<Self> {
        let parts: Vec<&str> = text.split(':').collect();
        let [class, sens, frame, xy] = parts.as_slice() else {
            anyhow::bail!("--try CLASS:Y,U,V:FRAME:X,Y, not {text}");
        };
        let numbers = |s: &str| -> anyhow::Result<Vec<usize>> {
            s.split(',')
                .map(|v| {
                    v.trim()
                        .parse::<usize>()
                        .with_context(|| format!("{v} in {text}"))
                })
                .collect()
        };
        let s = numbers(sens)?;
        let p = numbers(xy)?;
        anyhow::ensure!(s.len() == 3 && p.len() == 2, "--try CLASS:Y,U,V:FRAME:X,Y");
        let cell = |v: usize| u8::try_from(v).context("a sensitivity over 255");
        Ok(Self {
            class: ColourClass::parse(class).with_context(|| format!("class {class}"))?,
            sensitivity: Sensitivity {
                y: cell(s[0])?,
                u: cell(s[1])?,
                v: cell(s[2])?,
            },
            frame: (*frame).to_owned(),
            x: p[0],
            y: p[1],
        })
    }
}

/// Ticks the workspace (its background scans, a few frames a tick) until `done`.
fn settle(ws: &mut Workspace, done: impl Fn(&Workspace) -> bool) {
    while !done(ws) {
        ws.tick(Duration::ZERO);
    }
}

fn labels_done(ws: &Workspace) -> bool {
    ws.labels().is_none_or(eotn::workspace::OpenLabels::done)
}

fn print_report(title: &str, r: &BoxReport) {
    let pct = |v: Option<f64>| v.map_or_else(|| "-".to_owned(), |v| format!("{:.1}%", v * 100.0));
    println!(
        "{title}: recall {}/{} = {}, precision {}/{} = {} (false: {} robot, {} elsewhere)",
        r.found,
        r.eligible,
        pct(r.recall),
        r.correct,
        r.reported,
        pct(r.precision),
        r.false_in_robot,
        r.false_elsewhere + r.false_in_goal + r.false_in_other
    );
    let bands: Vec<String> = r
        .by_size
        .iter()
        .map(|b| format!("{}px {}/{}", b.from_px, b.found, b.eligible))
        .collect();
    println!("  by size: {}", bands.join(", "));
    println!("  missed: {}", r.missed_frames.join(" "));
    println!("  false: {}", r.false_frames.join(" "));
}

impl Look {
    /// Prints what the windows show for the table open in `ws` over `frames`.
    pub fn print(&self, ws: &mut Workspace, frames: &[PathBuf]) -> anyhow::Result<()> {
        if let Some(params) = &self.params {
            ws.apply(eotn::workspace::ParamsCommand::OpenParams(params.clone()).into())?;
        }
        let before = if let Some(labels) = &self.labels {
            ws.apply(Command::OpenLabels(labels.clone()))?;
            ws.apply(Command::SetLabelsSplit(Split::Tuning))?;
            settle(ws, labels_done);
            let r = ws.labels().context("labels open")?.report();
            print_report("labels (tuning frames)", &r);
            Some(r)
        } else {
            None
        };
        if self.hints > 0 {
            let range = match &self.hint_range {
                Some((a, b)) => {
                    let at = |n: &str| {
                        frames
                            .iter()
                            .position(|p| name(p) == n)
                            .with_context(|| format!("{n} is not a tuning frame here"))
                    };
                    at(a)?..=at(b)?
                }
                None => 0..=frames.len().saturating_sub(1),
            };
            print_hints(ws, frames, range, self.hints, self.hint_pngs.as_deref())?;
        }
        for t in &self.tries {
            try_click(ws, frames, t, before.as_ref())?;
        }
        Ok(())
    }
}

/// The coverage hints over every open frame, each with the frames that show it most.
fn print_hints(
    ws: &mut Workspace,
    frames: &[PathBuf],
    range: std::ops::RangeInclusive<usize>,
    n: usize,
    pngs: Option<&Path>,
) -> anyhow::Result<()> {
    let (first, last) = (*range.start(), *range.end());
    ws.apply(HintsCommand::FindUnclassified { first, last }.into())?;
    settle(ws, |w| w.coverage().is_some_and(|c| c.done()));
    // One more tick ranks the last frames counted.
    ws.tick(Duration::ZERO);
    let hints: Vec<_> = ws
        .coverage()
        .context("coverage")?
        .hints()
        .iter()
        .take(n)
        .cloned()
        .collect();
    let mut hint_of: HashMap<usize, usize> = HashMap::new();
    for (i, h) in hints.iter().enumerate() {
        for &c in &h.cells {
            hint_of.insert(c, i);
        }
    }
    // Per hint and frame: pixels, and their box.
    let mut seen: HashMap<(usize, usize), (usize, [usize; 4])> = HashMap::new();
    let lut = ws.lut().clone();
    for (f, path) in frames.iter().enumerate().take(last + 1).skip(first) {
        let frame = load_frame(path, None).with_context(|| format!("{}", path.display()))?;
        frame.for_each_pixel(|x, y, p| {
            if let Some(&h) = hint_of.get(&lut.index(p)) {
                let e = seen.entry((h, f)).or_insert((0, [x, y, x, y]));
                e.0 += 1;
                e.1 = [e.1[0].min(x), e.1[1].min(y), e.1[2].max(x), e.1[3].max(y)];
            }
        });
    }
    for (i, h) in hints.iter().enumerate() {
        let rgb = yuv_to_rgb(h.mean);
        println!(
            "hint {i}: {} px, mean YUV ({}, {}, {}) RGB ({}, {}, {}), {} cells",
            h.pixels,
            h.mean.y,
            h.mean.u,
            h.mean.v,
            rgb[0],
            rgb[1],
            rgb[2],
            h.cells.len()
        );
        let mut where_: Vec<(usize, usize, [usize; 4])> = seen
            .iter()
            .filter(|((hh, _), _)| *hh == i)
            .map(|((_, f), (n, b))| (*f, *n, *b))
            .collect();
        where_.sort_by_key(|w| std::cmp::Reverse(w.1));
        println!("  in {} frames; most in:", where_.len());
        for (f, n, b) in where_.iter().take(4) {
            println!(
                "    {} {n} px in ({},{})-({},{})",
                name(&frames[*f]),
                b[0],
                b[1],
                b[2],
                b[3]
            );
        }
        println!("  cells: {:?}", h.cells);
        if let (Some(dir), Some((f, _, _))) = (pngs, where_.first()) {
            let cells: std::collections::HashSet<usize> = h.cells.iter().copied().collect();
            draw_hint(
                &dir.join(format!("hint-{i}.png")),
                &frames[*f],
                &lut,
                &cells,
            )?;
        }
    }
    Ok(())
}

/// The frame at twice its size, and beside it the same with the pixels of `cells` magenta.
fn draw_hint(
    out: &Path,
    frame: &Path,
    lut: &eotn::lut::LookupTable,
    cells: &std::collections::HashSet<usize>,
) -> anyhow::Result<()> {
    let f = load_frame(frame, None)?;
    let (w, h) = (f.width(), f.height());
    let mut rgb = vec![0u8; 4 * w * 2 * h * 3];
    f.for_each_pixel(|x, y, p| {
        let plain = yuv_to_rgb(p);
        let marked = if cells.contains(&lut.index(p)) {
            [255, 0, 255]
        } else {
            plain
        };
        for (panel, colour) in [(0, plain), (2 * w, marked)] {
            for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                let i = ((2 * y + dy) * 4 * w + panel + 2 * x + dx) * 3;
                rgb[i..i + 3].copy_from_slice(&colour);
            }
        }
    });
    eotn::frame::save_rgb_png(out, 4 * w, 2 * h, &rgb)?;
    Ok(())
}

fn name(path: &Path) -> String {
    path.file_name()
        .map_or_else(String::new, |n| n.to_string_lossy().into_owned())
}

/// The whole-set preview of one click, then the labels' report with it committed (undone after).
fn try_click(
    ws: &mut Workspace,
    frames: &[PathBuf],
    t: &Try,
    before: Option<&BoxReport>,
) -> anyhow::Result<()> {
    let index = frames
        .iter()
        .position(|p| name(p) == t.frame)
        .with_context(|| format!("{} is not a tuning frame here", t.frame))?;
    ws.apply(PlaybackCommand::Seek(index).into())?;
    ws.apply(TableCommand::SetClass(t.class).into())?;
    ws.apply(TableCommand::SetSensitivity(t.sensitivity).into())?;
    ws.apply(TableCommand::Sample { x: t.x, y: t.y }.into())?;
    let pixel = ws
        .frame()
        .and_then(|f| f.pixel(t.x, t.y))
        .context("pixel")?;
    println!(
        "try {} ±{},{},{} at {} ({}, {}): YUV ({}, {}, {}), now {}",
        t.class.name(),
        t.sensitivity.y,
        t.sensitivity.u,
        t.sensitivity.v,
        t.frame,
        t.x,
        t.y,
        pixel.y,
        pixel.u,
        pixel.v,
        ws.lut().class_of(pixel).name()
    );
    ws.apply(TableCommand::TryEditOnStream.into())?;
    settle(ws, |w| w.try_edit().is_none_or(|e| e.done()));
    let rows = ws
        .try_edit()
        .map(|e| e.stream.rows.clone())
        .unwrap_or_default();
    let total: usize = rows.iter().map(|r| r.changed_pixels).sum();
    println!(
        "  changes {total} px in {} of {} frames; most:",
        rows.len(),
        frames.len()
    );
    let mut sorted = rows;
    sorted.sort_by_key(|r| std::cmp::Reverse(r.changed_pixels));
    let most: Vec<String> = sorted
        .iter()
        .take(8)
        .map(|r| format!("{} {}", name(&frames[r.index]), r.changed_pixels))
        .collect();
    println!("    {}", most.join(", "));
    if before.is_some() {
        ws.apply(TableCommand::Commit.into())?;
        settle(ws, labels_done);
        if let Some(l) = ws.labels() {
            print_report("  labels with it", &l.report());
        }
        ws.apply(TableCommand::Undo.into())?;
    }
    Ok(())
}
