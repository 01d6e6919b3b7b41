//! `eotn export`: frames of streams (or frame files) as PNG: the camera image, the classified
//! image, or the camera image with blob boxes.

use std::ops::Range;
use std::path::PathBuf;

use anyhow::{Context, bail};

use super::inputs::{
    FrameInputs, load_lut_arg, parse_connectivity, parse_frame_range, parse_size, progress,
};
use crate::blobs::{BlobSet, Connectivity};
use crate::classify::ClassifiedImage;
use crate::frame::save_rgb_png;
use crate::lut::code_display_rgb;

/// Which picture of a frame to write.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum View {
    /// The camera image in RGB.
    Raw,
    /// Each pixel in its class's display colour (needs `--lut`).
    Classified,
    /// The camera image with a one-pixel box in class colour around each blob (needs `--lut`).
    Blobs,
}

impl View {
    const fn suffix(self) -> &'static str {
        match self {
            Self::Raw => "raw",
            Self::Classified => "classified",
            Self::Blobs => "blobs",
        }
    }
}

/// Arguments of `eotn export`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Streams (`.mcap`), frames (`.uyvy`, `.png`, `.jpg`) or folders of frames.
    #[arg(required = true)]
    pub inputs: Vec<PathBuf>,
    /// Lookup table (`.lut`); needed by the classified and blobs views.
    #[arg(long)]
    pub lut: Option<PathBuf>,
    /// What to draw.
    #[arg(long, value_enum, default_value = "raw")]
    pub view: View,
    /// Folder for the PNGs (`NAME.VIEW.png`; a stream's frames are named `STEM_NNNNNN`); created
    /// if missing.
    #[arg(short, long, value_name = super::paths::OUT_DIR)]
    pub output: PathBuf,
    /// Frames of each stream to export: `A..B` (B excluded), `A..=B`, `A..`, `..B` or `A`.
    #[arg(long, value_parser = parse_frame_range)]
    pub frames: Option<Range<usize>>,
    /// Frame size of raw files, WxH; 208x160 and 640x480 are inferred.
    #[arg(long, value_parser = parse_size)]
    pub size: Option<(usize, usize)>,
    /// Blobs view: 8 lets diagonal neighbours join a blob, 4 does not.
    #[arg(long, default_value = "8", value_parser = parse_connectivity)]
    pub connectivity: Connectivity,
    /// Blobs view: leave out blobs with fewer pixels than this.
    #[arg(long, default_value_t = 4, value_parser = super::values::whole_in::<u32>(0, super::values::MAX_PIXELS))]
    pub min_pixels: u32,
    /// Which camera of the recordings.
    #[command(flatten)]
    pub camera: super::inputs::CameraArg,
}

/// Runs `eotn export`.
///
/// # Errors
/// Unreadable inputs, a missing `--lut` for a view that needs one, unwritable outputs; each
/// naming the file.
pub fn run(args: &Args) -> anyhow::Result<()> {
    let lut = match (&args.lut, args.view) {
        (Some(p), _) => Some(load_lut_arg(p)?),
        (None, View::Raw) => None,
        (None, view) => bail!("--view {} needs --lut TABLE", view.suffix()),
    };
    let mut inputs =
        FrameInputs::open_camera(&args.inputs, args.frames.clone(), args.camera.get())?;
    crate::atomic_file::output_folder(&args.output)
        .with_context(|| format!("{}", args.output.display()))?;
    let mut classified = ClassifiedImage::default();
    let mut blobs = BlobSet::default();
    let mut rgb = Vec::new();
    let bar = progress(inputs.len(), "export");
    for i in 0..inputs.len() {
        let Some(frame) = inputs.load_record_or_skip(i, args.size)?.map(|r| r.frame) else {
            bar.inc(1);
            continue;
        };
        let (w, h) = (frame.width(), frame.height());
        match (args.view, &lut) {
            (View::Classified, Some(lut)) => {
                crate::classify::classify_into(&frame, lut, &mut classified);
                rgb = classified.to_rgb();
            }
            (View::Blobs, Some(lut)) => {
                crate::classify::classify_into(&frame, lut, &mut classified);
                blobs.find(&classified, args.connectivity);
                frame.to_rgb_into(&mut rgb);
                for b in blobs.active().filter(|b| b.pixels >= args.min_pixels) {
                    crate::overlay::outline_box(
                        &mut rgb,
                        w,
                        frame.height(),
                        b.bounds(),
                        code_display_rgb(b.colour),
                    );
                }
            }
            _ => frame.to_rgb_into(&mut rgb),
        }
        let png = args
            .output
            .join(format!("{}.{}.png", inputs.name(i), args.view.suffix()));
        save_rgb_png(&png, w, h, &rgb)?;
        bar.inc(1);
    }
    bar.finish_and_clear();
    Ok(())
}

/// Draws a blob's inclusive bounding box, one pixel wide, into packed RGB of width `w`.
#[cfg(test)]
mod tests {
    use super::*;
    use crate::blobs::BlobSet;
    use crate::classify::ClassifiedImage;

    #[test]
    fn boxes_are_outlines_of_the_blob() {
        let mut codes = vec![0u8; 8 * 6];
        for y in 1..4 {
            for x in 2..6 {
                codes[y * 8 + x] = 1;
            }
        }
        let img = ClassifiedImage::from_codes(8, 6, codes).unwrap();
        let set = BlobSet::from_image(&img, Connectivity::Eight);
        let b = set.active().next().unwrap();
        let mut rgb = vec![0u8; 8 * 6 * 3];
        crate::overlay::outline_box(&mut rgb, 8, 6, b.bounds(), [9, 9, 9]);
        let lit = |x: usize, y: usize| rgb[(y * 8 + x) * 3] == 9;
        assert!(lit(2, 1) && lit(5, 3) && lit(2, 3) && lit(5, 1));
        assert!(!lit(3, 2), "inside stays");
        assert!(!lit(1, 1) && !lit(6, 3), "outside stays");
    }
}
