//! The hand-written C floor `eotn bench` prints beside its own figures: `floors.c` of the
//! project's shared benchmarks (classification + run-length/union-find blobs in plain C with
//! AVX2 run search, compiled `-O3 -march=native`), run on the same frame and table.
//!
//! The floor is a separate program, so it is run as one: the source is compiled once into a
//! temporary folder (or a compiled `floors` is used as given), the frame and table are written
//! there as raw bytes, and the median it prints for `classify+cc8 simd-rle (pipeline)` is read.

use std::path::{Path, PathBuf};
use std::process::Command;

use anyhow::{Context, bail};

use crate::frame::{Frame, PixelLayout};
use crate::lut::LookupTable;

/// The line of `floors` output with the whole classify + 8-connected blobs figure.
const FLOOR_LINE: &str = "classify+cc8 simd-rle (pipeline)";

/// A runnable floor and its scratch folder (removed on drop).
#[derive(Debug)]
pub struct Floor {
    program: PathBuf,
    dir: PathBuf,
    lut: PathBuf,
    /// Where the program came from, for the report.
    pub source: PathBuf,
}

/// Where `floors.c` is looked for when `--floor` is not given: `$EOTN_SHARED/bench/` or
/// `../shared/bench/` (the project's layout).
#[must_use]
pub fn default_source() -> Option<PathBuf> {
    let shared =
        std::env::var_os("EOTN_SHARED").map_or_else(|| PathBuf::from("../shared"), PathBuf::from);
    Some(shared.join("bench/floors.c")).filter(|p| p.is_file())
}

impl Floor {
    /// Compiles `source` (a `.c` file, with `$CC` or `cc`) or takes it as the compiled program,
    /// and writes `lut`'s cells where the program reads them.
    ///
    /// # Errors
    /// A missing source, a compiler that fails or is missing, or an unwritable temporary
    /// folder.
    pub fn prepare(source: &Path, lut: &LookupTable) -> anyhow::Result<Self> {
        if !source.is_file() {
            bail!("the C floor {}: no such file", source.display());
        }
        let dir = std::env::temp_dir().join(format!("eotn-floor-{}", std::process::id()));
        std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
        let mut floor = Self {
            program: source.to_path_buf(),
            lut: dir.join("table.lut"),
            dir,
            source: source.to_path_buf(),
        };
        std::fs::write(&floor.lut, lut.cells())
            .with_context(|| format!("writing {}", floor.lut.display()))?;
        if source.extension().is_some_and(|e| e == "c") {
            floor.program = floor.dir.join("floors");
            let cc = std::env::var_os("CC").unwrap_or_else(|| "cc".into());
            let out = Command::new(&cc)
                .args(["-O3", "-march=native", "-o"])
                .arg(&floor.program)
                .arg(source)
                .output()
                .with_context(|| format!("running {} to build the floor", cc.to_string_lossy()))?;
            if !out.status.success() {
                bail!(
                    "compiling {} failed: {}",
                    source.display(),
                    String::from_utf8_lossy(&out.stderr).trim()
                );
            }
        }
        Ok(floor)
    }

    /// The floor's median ns/pixel for classify + 8-connected blobs on `frame` (UYVY only).
    ///
    /// # Errors
    /// A frame that is not UYVY, or a floor that fails or prints no figure.
    pub fn measure(&self, frame: &Frame) -> anyhow::Result<f64> {
        if frame.layout() != PixelLayout::Uyvy {
            bail!("the C floor reads UYVY frames only");
        }
        let path = self.dir.join("frame.uyvy");
        std::fs::write(&path, frame.data())
            .with_context(|| format!("writing {}", path.display()))?;
        let out = Command::new(&self.program)
            .arg(&path)
            .arg(frame.width().to_string())
            .arg(frame.height().to_string())
            .arg(&self.lut)
            .output()
            .with_context(|| format!("running {}", self.program.display()))?;
        let text = String::from_utf8_lossy(&out.stdout);
        if !out.status.success() {
            bail!(
                "{} failed: {}",
                self.program.display(),
                String::from_utf8_lossy(&out.stderr).trim()
            );
        }
        parse_floor(&text)
            .with_context(|| format!("no `{FLOOR_LINE}` figure from {}", self.program.display()))
    }
}

impl Drop for Floor {
    fn drop(&mut self) {
        // Best effort: a leftover scratch folder in the temporary directory harms nothing.
        let _ = std::fs::remove_dir_all(&self.dir);
    }
}

/// The ns/pixel figure of the pipeline line (`… ms/frame X ns/pixel`).
fn parse_floor(text: &str) -> Option<f64> {
    let line = text.lines().find(|l| l.starts_with(FLOOR_LINE))?;
    let words: Vec<&str> = line.split_whitespace().collect();
    let at = words.iter().position(|&w| w == "ns/pixel")?;
    words
        .get(at.checked_sub(1)?)?
        .parse()
        .ok()
        .filter(|v: &f64| v.is_finite())
}

#[cfg(test)]
mod tests {
    use super::parse_floor;

    #[test]
    fn the_pipeline_figure_is_read_and_garbage_is_not() {
        let out = "# 640x480 lut b=7\nclassify const b=7             0.1500 ms/frame   0.488 ns/pixel\n\
                   classify+cc8 simd-rle (pipeline)    0.2711 ms/frame   0.883 ns/pixel\n";
        assert_eq!(parse_floor(out), Some(0.883));
        assert_eq!(
            parse_floor("classify+cc8 simd-rle (pipeline) x ms/frame nan ns/pixel"),
            None
        );
        assert_eq!(
            parse_floor("classify+cc8 simd-rle (pipeline) 1 ms/frame"),
            None
        );
        assert_eq!(parse_floor(""), None);
    }
}
