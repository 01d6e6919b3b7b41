//! A hand classification written down as the clicks that made it: per class, the sensitivity
//! (± table cells on Y, U, V), the frame (for a folder of frames) and the pixels clicked — or
//! the cells of a coverage hint clicked. Replayed through the app's own commands (`Seek`,
//! `SetClass`, `SetSensitivity`, `Sample` or `SelectCells`, `Commit`), exactly as a user
//! clicking those pixels (or that hint) in the window would make the table. Shared by
//! `examples/replay_clicks` and the tests.

use std::path::{Path, PathBuf};

use anyhow::Context;
use eotn::eval::label_sets::is_held_out;
use eotn::lut::{ColourClass, Sensitivity};
use eotn::workspace::{Command, HintsCommand, PlaybackCommand, TableCommand, Workspace};
use serde::Deserialize;

/// A clicks file (`*.clicks.json`).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Clicks {
    /// Bits per channel of the new table (6, 7 or 8).
    pub bits: u8,
    /// One entry per class, sensitivity and frame, in the order they were clicked.
    pub clicks: Vec<ClickGroup>,
}

/// Pixels clicked with one class and one sensitivity, on one frame.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ClickGroup {
    /// Class name as the app shows it (`"sky blue"`).
    pub class: String,
    /// ± table cells on Y, U, V (of a pixel click; a hint's cells are taken as they are).
    #[serde(default)]
    pub sensitivity: [u8; 3],
    /// The frame clicked on, a file name in the folder of frames (`"00054.jpg"`); absent when
    /// one frame or stream is open (its shown frame).
    #[serde(default)]
    pub frame: Option<String>,
    /// Why these pixels: what they are in the frame (a note for the reader, not replayed).
    #[serde(default)]
    pub note: Option<String>,
    /// The clicked pixels `[x, y]`.
    #[serde(default)]
    pub pixels: Vec<[usize; 2]>,
    /// The table cells of a coverage hint clicked (Classify ▸ What is still unclassified?),
    /// by index: one click, committed as one edit (`HintsCommand::SelectCells`).
    #[serde(default)]
    pub cells: Vec<usize>,
}

impl Clicks {
    /// Reads a clicks file.
    pub fn load(path: &Path) -> anyhow::Result<Self> {
        let text = std::fs::read_to_string(path).with_context(|| format!("{}", path.display()))?;
        serde_json::from_str(&text).with_context(|| format!("{}", path.display()))
    }

    /// Number of clicks: every pixel, and every hint.
    pub fn len(&self) -> usize {
        self.clicks
            .iter()
            .map(|g| g.pixels.len() + usize::from(!g.cells.is_empty()))
            .sum()
    }

    /// Every frame of `folder` that is not held out (numbers ending in 0–6), sorted by name:
    /// what a table is made on. The held-out frames are never opened.
    pub fn tuning_frames(folder: &Path) -> anyhow::Result<Vec<PathBuf>> {
        let mut out = Vec::new();
        for entry in std::fs::read_dir(folder).with_context(|| format!("{}", folder.display()))? {
            let path = entry?.path();
            let stem = path.file_stem().and_then(|s| s.to_str()).unwrap_or("");
            let frame = path
                .extension()
                .and_then(|e| e.to_str())
                .is_some_and(|e| ["jpg", "jpeg", "png"].contains(&e.to_ascii_lowercase().as_str()));
            if frame && !is_held_out(stem) {
                out.push(path);
            }
        }
        out.sort();
        anyhow::ensure!(!out.is_empty(), "{}: no tuning frames", folder.display());
        Ok(out)
    }

    /// The frames the groups name, in order of first use, as files of `folder`. Held-out frames
    /// (numbers ending in 7, 8 or 9) are refused: no table edit may look at them.
    pub fn frames(&self, folder: &Path) -> anyhow::Result<Vec<PathBuf>> {
        let mut out: Vec<PathBuf> = Vec::new();
        for name in self.clicks.iter().filter_map(|g| g.frame.as_deref()) {
            let stem = Path::new(name)
                .file_stem()
                .and_then(|s| s.to_str())
                .unwrap_or(name);
            anyhow::ensure!(
                !is_held_out(stem),
                "{name}: a held-out frame (number ends in 7, 8 or 9)"
            );
            let path = folder.join(name);
            if !out.contains(&path) {
                out.push(path);
            }
        }
        Ok(out)
    }

    /// Starts a new table in `ws` (whose frame must be open) and clicks every pixel.
    pub fn replay(&self, ws: &mut Workspace) -> anyhow::Result<()> {
        ws.apply(TableCommand::NewTable(self.bits).into())?;
        self.click(ws, &[])
    }

    /// Clicks every pixel onto the table open in `ws`: for each group the frame is shown
    /// (`frames` as opened, in order, see [`Self::frames`]), then per pixel a left click
    /// (`Sample`) and a right click (`Commit`), as in the window.
    pub fn click(&self, ws: &mut Workspace, frames: &[PathBuf]) -> anyhow::Result<()> {
        anyhow::ensure!(
            ws.lut().bits() == self.bits,
            "the clicks were made on a {}-bit table, the open table has {} bits",
            self.bits,
            ws.lut().bits()
        );
        for g in &self.clicks {
            if let Some(name) = &g.frame {
                let index = frames
                    .iter()
                    .position(|p| p.file_name().is_some_and(|f| f == name.as_str()))
                    .with_context(|| format!("frame {name} is not open"))?;
                ws.apply(Command::Playback(PlaybackCommand::Seek(index)))?;
            }
            let class = ColourClass::parse(&g.class)
                .with_context(|| format!("unknown class {:?}", g.class))?;
            let [y, u, v] = g.sensitivity;
            ws.apply(TableCommand::SetClass(class).into())?;
            ws.apply(TableCommand::SetSensitivity(Sensitivity { y, u, v }).into())?;
            if !g.cells.is_empty() {
                ws.apply(HintsCommand::SelectCells(g.cells.clone()).into())?;
                // A hint's colours are committed as the class chosen for them (Commit as…).
                ws.apply(TableCommand::SetClass(class).into())?;
                ws.apply(TableCommand::Commit.into())
                    .with_context(|| format!("{} hint of {} cells", g.class, g.cells.len()))?;
            }
            for &[x, y] in &g.pixels {
                ws.apply(TableCommand::Sample { x, y }.into())?;
                ws.apply(TableCommand::Commit.into()).with_context(|| {
                    format!(
                        "{} at ({x}, {y}) of {}",
                        g.class,
                        g.frame.as_deref().unwrap_or("the frame")
                    )
                })?;
            }
        }
        Ok(())
    }
}
