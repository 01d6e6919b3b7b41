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
    /// The table's bits per channel (which fixed-depth classify line is its).
    bits: u8,
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
            bits: lut.bits(),
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
        let text = self.run(frame)?;
        parse_floor(&text)
            .with_context(|| format!("no `{FLOOR_LINE}` figure from {}", self.program.display()))
    }

    /// The floor's median of each stage it has on `frame` (UYVY only), milliseconds a frame.
    ///
    /// # Errors
    /// A frame that is not UYVY, or a floor that fails or misses a figure.
    pub fn measure_stages(&self, frame: &Frame) -> anyhow::Result<FloorStages> {
        let text = self.run(frame)?;
        let get = |label: &str| {
            parse_ms(&text, label)
                .with_context(|| format!("no `{label}` figure from {}", self.program.display()))
        };
        let classify = format!("classify const b={}", self.bits);
        Ok(FloorStages {
            frame_copy_ms: get("memcpy frame (UYVY bytes)")?,
            classify_ms: get(&classify)?,
            blobs_ms: get("rle(avx2)+uf cc conn=8")?,
            pipeline_ms: get(FLOOR_LINE)?,
        })
    }

    /// The floor's output on `frame`.
    fn run(&self, frame: &Frame) -> anyhow::Result<String> {
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
        if !out.status.success() {
            bail!(
                "{} failed: {}",
                self.program.display(),
                String::from_utf8_lossy(&out.stderr).trim()
            );
        }
        Ok(String::from_utf8_lossy(&out.stdout).into_owned())
    }
}

impl Drop for Floor {
    fn drop(&mut self) {
        // Best effort: a leftover scratch folder in the temporary directory harms nothing.
        let _ = std::fs::remove_dir_all(&self.dir);
    }
}

/// The C floor's median of each stage on one frame, milliseconds a frame.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct FloorStages {
    /// Copying the frame's bytes (`memcpy`): no stage can be faster than reading its input.
    pub frame_copy_ms: f64,
    /// The table lookup of every pixel, the table's bit depth fixed at compile time.
    pub classify_ms: f64,
    /// Run-length encoding (AVX2 run search) and union-find, 8-connected.
    pub blobs_ms: f64,
    /// Both in a row.
    pub pipeline_ms: f64,
}

/// The ms/frame figure of the line starting with `label` (`LABEL X ms/frame Y ns/pixel`).
fn parse_ms(text: &str, label: &str) -> Option<f64> {
    let rest = text.lines().find_map(|l| l.strip_prefix(label))?;
    let words: Vec<&str> = rest.split_whitespace().collect();
    let at = words.iter().position(|&w| w == "ms/frame")?;
    words
        .get(at.checked_sub(1)?)?
        .parse()
        .ok()
        .filter(|v: &f64| v.is_finite())
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
    use super::{parse_floor, parse_ms};

    #[test]
    fn each_stage_figure_is_read_by_its_label() {
        let out = "memcpy frame (UYVY bytes)      0.2100 ms/frame   0.091 ns/pixel\n\
                   classify const b=7             1.0500 ms/frame   0.456 ns/pixel\n\
                   rle(avx2)+uf cc conn=8         0.3000 ms/frame   0.130 ns/pixel\n";
        assert_eq!(parse_ms(out, "classify const b=7"), Some(1.05));
        assert_eq!(parse_ms(out, "rle(avx2)+uf cc conn=8"), Some(0.3));
        assert_eq!(parse_ms(out, "memcpy frame (UYVY bytes)"), Some(0.21));
        assert_eq!(parse_ms(out, "classify const b=6"), None);
        assert_eq!(
            parse_ms("classify const b=7 nan ms/frame", "classify const b=7"),
            None
        );
    }

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
