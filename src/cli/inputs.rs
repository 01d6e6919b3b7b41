//! Shared command-line inputs: frame lists, `--size`, `--lut`, progress bars.

use std::path::{Path, PathBuf};

use anyhow::{Context, bail};
use indicatif::{ProgressBar, ProgressStyle};

use crate::blobs::Connectivity;
use crate::frame::{Frame, is_image_file, load_frame};
use crate::lut::LookupTable;

/// File extensions read as raw UYVY frames.
pub const RAW_EXTENSIONS: [&str; 3] = ["uyvy", "yuv", "raw"];

/// Parses `WxH` (e.g. `208x160`).
///
/// # Errors
/// A message saying what is wrong with the text.
pub fn parse_size(text: &str) -> Result<(usize, usize), String> {
    let (w, h) = text
        .split_once(['x', 'X', '×'])
        .ok_or_else(|| format!("'{text}' is not WxH (e.g. 208x160)"))?;
    let w: usize = w
        .trim()
        .parse()
        .map_err(|_| format!("bad width in '{text}'"))?;
    let h: usize = h
        .trim()
        .parse()
        .map_err(|_| format!("bad height in '{text}'"))?;
    if w == 0 || h == 0 {
        return Err(format!("'{text}': width and height must be positive"));
    }
    Ok((w, h))
}

/// Parses a connectivity, `4` or `8`.
///
/// # Errors
/// A message for anything else.
pub fn parse_connectivity(text: &str) -> Result<Connectivity, String> {
    text.trim()
        .parse::<u8>()
        .ok()
        .and_then(Connectivity::from_neighbours)
        .ok_or_else(|| format!("connectivity must be 4 or 8, not '{text}'"))
}

/// True for files the frame loaders read.
#[must_use]
pub fn is_frame_file(path: &Path) -> bool {
    is_image_file(path)
        || path
            .extension()
            .is_some_and(|e| RAW_EXTENSIONS.iter().any(|r| e.eq_ignore_ascii_case(r)))
}

/// Expands the arguments: files stay, folders give their frame files sorted by name.
///
/// # Errors
/// A path that does not exist, or a folder without frames.
pub fn expand_frame_paths(paths: &[PathBuf]) -> anyhow::Result<Vec<PathBuf>> {
    let mut out = Vec::new();
    for p in paths {
        if p.is_dir() {
            let mut found: Vec<PathBuf> = std::fs::read_dir(p)
                .with_context(|| format!("{}: cannot list folder", p.display()))?
                .filter_map(Result::ok)
                .map(|e| e.path())
                .filter(|f| f.is_file() && is_frame_file(f))
                .collect();
            if found.is_empty() {
                bail!(
                    "{}: no frame files (.uyvy, .yuv, .raw, .png, .jpg) in folder",
                    p.display()
                );
            }
            found.sort();
            out.extend(found);
        } else if p.exists() {
            out.push(p.clone());
        } else {
            bail!("{}: no such file or folder", p.display());
        }
    }
    if out.is_empty() {
        bail!("no input frames given");
    }
    Ok(out)
}

/// Loads one frame with the error naming the file.
///
/// # Errors
/// The loader's error.
pub fn load_frame_arg(path: &Path, size: Option<(usize, usize)>) -> anyhow::Result<Frame> {
    Ok(load_frame(path, size)?)
}

/// Loads the `--lut` table.
///
/// # Errors
/// The table loader's error, naming the file.
pub fn load_lut_arg(path: &Path) -> anyhow::Result<LookupTable> {
    Ok(LookupTable::load(path)?)
}

/// A progress bar on stderr that draws only on a terminal (quiet when piped or redirected).
#[must_use]
pub fn progress(len: usize, what: &str) -> ProgressBar {
    let bar = ProgressBar::new(len as u64);
    if let Ok(style) =
        ProgressStyle::with_template("{msg} {wide_bar} {pos}/{len} [{elapsed_precise}, {eta} left]")
    {
        bar.set_style(style);
    }
    bar.set_message(what.to_owned());
    bar
}

/// The name of a frame file for JSON output: the file name without folders.
#[must_use]
pub fn frame_name(path: &Path) -> String {
    path.file_name().map_or_else(
        || path.display().to_string(),
        |n| n.to_string_lossy().into_owned(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_parse_and_reject_nonsense() {
        assert_eq!(parse_size("208x160"), Ok((208, 160)));
        assert_eq!(parse_size("640X480"), Ok((640, 480)));
        assert!(parse_size("208").is_err());
        assert!(parse_size("0x5").is_err());
        assert!(parse_size("axb").is_err());
    }

    #[test]
    fn folders_expand_to_sorted_frame_files() {
        let dir = tempfile::tempdir().unwrap();
        for n in ["b.uyvy", "a.uyvy", "notes.txt", "c.png"] {
            std::fs::write(dir.path().join(n), b"").unwrap();
        }
        let got = expand_frame_paths(&[dir.path().to_owned()]).unwrap();
        let names: Vec<_> = got.iter().map(|p| frame_name(p)).collect();
        assert_eq!(names, ["a.uyvy", "b.uyvy", "c.png"]);
        assert!(expand_frame_paths(&[dir.path().join("nope")]).is_err());
    }
}
