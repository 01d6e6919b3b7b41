//! A hand classification written down as the clicks that made it: per class, the sensitivity
//! (± table cells on Y, U, V) and the pixels clicked. Replayed through the app's own commands
//! (`SetClass`, `SetSensitivity`, `Sample`, `Commit`), exactly as a user clicking those pixels in
//! the window would make the table. Shared by `examples/replay_clicks` and the tests.

use std::path::Path;

use anyhow::Context;
use eotn::lut::{ColourClass, Sensitivity};
use eotn::workspace::{TableCommand, Workspace};
use serde::Deserialize;

/// A clicks file (`*.clicks.json`).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Clicks {
    /// Bits per channel of the new table (6, 7 or 8).
    pub bits: u8,
    /// One entry per class and sensitivity, in the order they were clicked.
    pub clicks: Vec<ClickGroup>,
}

/// Pixels clicked with one class and one sensitivity.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ClickGroup {
    /// Class name as the app shows it (`"sky blue"`).
    pub class: String,
    /// ± table cells on Y, U, V.
    pub sensitivity: [u8; 3],
    /// The clicked pixels `[x, y]`.
    pub pixels: Vec<[usize; 2]>,
}

impl Clicks {
    /// Reads a clicks file.
    pub fn load(path: &Path) -> anyhow::Result<Self> {
        let text = std::fs::read_to_string(path).with_context(|| format!("{}", path.display()))?;
        serde_json::from_str(&text).with_context(|| format!("{}", path.display()))
    }

    /// Number of clicks.
    pub fn len(&self) -> usize {
        self.clicks.iter().map(|g| g.pixels.len()).sum()
    }

    /// Starts a new table in `ws` (whose frame must be open) and clicks every pixel: left
    /// click (`Sample`) then right click (`Commit`), as in the window.
    pub fn replay(&self, ws: &mut Workspace) -> anyhow::Result<()> {
        ws.apply(TableCommand::NewTable(self.bits).into())?;
        for g in &self.clicks {
            let class = ColourClass::parse(&g.class)
                .with_context(|| format!("unknown class {:?}", g.class))?;
            let [y, u, v] = g.sensitivity;
            ws.apply(TableCommand::SetClass(class).into())?;
            ws.apply(TableCommand::SetSensitivity(Sensitivity { y, u, v }).into())?;
            for &[x, y] in &g.pixels {
                ws.apply(TableCommand::Sample { x, y }.into())?;
                ws.apply(TableCommand::Commit.into())
                    .with_context(|| format!("{} at ({x}, {y})", g.class))?;
            }
        }
        Ok(())
    }
}
