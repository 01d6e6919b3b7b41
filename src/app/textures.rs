//! The shown frame's textures: the colour and class-colour images built on the CPU, the
//! pending selection's highlight, and their upload when the frame or the preview changes.

use std::time::Instant;

use egui::{Color32, ColorImage, TextureHandle, TextureOptions};

use super::EotnApp;
use super::overlays::FrameTextures;
use crate::workspace::{PreviewPixel, Workspace, hatch_rgb};

/// How much the pixels outside a pending selection are darkened (alpha of black over them).
const PREVIEW_DIM_ALPHA: u8 = 110;

/// The textures of the shown frame and what they were built from.
pub(super) struct Textures {
    raw: TextureHandle,
    classified: TextureHandle,
    preview: TextureHandle,
    frame_generation: u64,
    preview_generation: u64,
    /// The preview texture holds no highlight (nothing to re-upload while none is pending).
    preview_empty: bool,
}

impl Textures {
    pub(super) fn ids(&self) -> FrameTextures {
        FrameTextures {
            raw: self.raw.id(),
            classified: self.classified.id(),
            preview: self.preview.id(),
        }
    }
}

/// Display colours of every class code, transparent for unclassified.
#[must_use]
pub fn palette() -> [Color32; 256] {
    let mut p = [Color32::TRANSPARENT; 256];
    for (code, c) in p.iter_mut().enumerate().skip(1) {
        let [r, g, b] = crate::lut::code_display_rgb(u8::try_from(code).unwrap_or(0));
        *c = Color32::from_rgb(r, g, b);
    }
    p
}

/// The images the views are drawn from, before they go to the GPU.
#[derive(Debug, Clone)]
pub struct ViewImages {
    /// The frame in colour.
    pub raw: ColorImage,
    /// Class colours, transparent where unclassified.
    pub classified: ColorImage,
}

/// Builds the colour and class-colour images of the shown frame (`palette` from [`palette`]);
/// `None` when no frame is open. This is the CPU side of a texture update.
#[must_use]
pub fn view_images(state: &Workspace, palette: &[Color32; 256]) -> Option<ViewImages> {
    let frame = state.frame()?;
    let size = [frame.width(), frame.height()];
    // The undistorted view of an overhead frame, when chosen, else the frame as it is.
    let raw = ColorImage::from_rgb(size, &state.view_rgb());
    let classified = ColorImage::new(
        size,
        state
            .view_codes()
            .iter()
            .map(|&c| palette[usize::from(c)])
            .collect(),
    );
    Some(ViewImages { raw, classified })
}

/// The preview highlight image of the pending selection: the pixels a commit would change
/// hatched in the class colour (so they stand out from pixels already shown in that colour),
/// selected pixels already of the class left as they are, the rest dimmed; transparent with
/// no selection.
#[must_use]
pub fn preview_image(state: &Workspace, size: [usize; 2]) -> ColorImage {
    let n = size[0] * size[1];
    let Some(class_rgb) = state.preview_colour() else {
        return ColorImage::new(size, vec![Color32::TRANSPARENT; n]);
    };
    let rgb = |[r, g, b]: [u8; 3]| Color32::from_rgb(r, g, b);
    let dim = Color32::from_black_alpha(PREVIEW_DIM_ALPHA);
    let w = size[0].max(1);
    let mut pixels: Vec<Color32> = state
        .preview_pixels()
        .enumerate()
        .map(|(i, p)| match p {
            PreviewPixel::Outside => dim,
            PreviewPixel::Unchanged => Color32::TRANSPARENT,
            PreviewPixel::Changes => rgb(hatch_rgb(i % w, i / w, class_rgb)),
        })
        .collect();
    if pixels.len() != n {
        pixels = vec![Color32::TRANSPARENT; n];
    }
    ColorImage::new(size, pixels)
}

/// The highlight colour of a previewed class: its own colour, or a light magenta for classes
/// too dark to show over dimmed pixels (black's near-black, dark blue).
#[must_use]
pub fn visible_preview_colour(class_colour: Color32) -> Color32 {
    let [r, g, b, a] = class_colour.to_array();
    if a == 0 {
        return class_colour;
    }
    let [r, g, b] = crate::workspace::visible_preview_rgb([r, g, b]);
    Color32::from_rgb(r, g, b)
}

impl EotnApp {
    pub(super) fn update_textures(&mut self, ctx: &egui::Context) {
        let Some(frame) = self.state.frame() else {
            return;
        };
        let size = [frame.width(), frame.height()];
        let opts = TextureOptions::NEAREST;
        let fg = self.state.frame_generation();
        let pg = self.state.preview_generation();
        if self
            .textures
            .as_ref()
            .is_some_and(|t| t.frame_generation == fg && t.preview_generation == pg)
        {
            return;
        }
        let t0 = Instant::now();
        let frame_changed = self
            .textures
            .as_ref()
            .is_none_or(|t| t.frame_generation != fg);
        let empty = self.state.selection().is_none();
        if frame_changed
            && let Some(ViewImages { raw, classified }) = view_images(&self.state, &self.palette)
        {
            match &mut self.textures {
                Some(t) => {
                    t.raw.set(raw, opts);
                    t.classified.set(classified, opts);
                }
                None => {
                    let preview = preview_image(&self.state, size);
                    self.textures = Some(Textures {
                        raw: ctx.load_texture("raw", raw, opts),
                        classified: ctx.load_texture("classified", classified, opts),
                        preview: ctx.load_texture("preview", preview, opts),
                        frame_generation: fg,
                        preview_generation: pg,
                        preview_empty: empty,
                    });
                }
            }
        }
        if let Some(t) = &mut self.textures {
            // With nothing selected the preview is not drawn: an empty one is uploaded once,
            // not on every step of playback.
            if t.preview_generation != pg && !(empty && t.preview_empty) {
                t.preview.set(preview_image(&self.state, size), opts);
                t.preview_empty = empty;
            }
            t.frame_generation = fg;
            t.preview_generation = pg;
        }
        if frame_changed {
            self.state.record_upload(t0.elapsed());
        }
    }
}
