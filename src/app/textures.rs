//! The shown frame's textures: the colour and class-colour images built on the CPU, the
//! pending selection's highlight, and their upload when the frame or the preview changes.

use std::time::Instant;

use egui::{Color32, ColorImage, TextureHandle, TextureOptions};

use super::EotnApp;
use super::overlays::{FrameTextures, ImageTransform};
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
    /// Image pixels per texel along each axis ([`texture_step`]).
    step: usize,
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
    view_images_every(state, palette, 1)
}

/// Image pixels per texel (along each axis) for a view drawn at `zoom` screen pixels per image
/// pixel: with nearest filtering a view smaller than the image shows one pixel in `step` of each
/// row and column anyway, so the textures keep just those. A 1920×1200 overhead frame fitted into
/// a 1280×800 window shows a third of its pixels each way: a ninth of the conversion and upload.
#[must_use]
pub fn texture_step(zoom: f32) -> usize {
    if zoom.is_finite() && zoom > 0.0 && zoom < 1.0 {
        (1.0 / zoom).floor().clamp(1.0, 16.0) as usize
    } else {
        1
    }
}

/// [`view_images`] keeping every `step`th pixel of each row and column (the top-left one of
/// each `step`×`step` block): what nearest filtering shows of the image at that scale.
#[must_use]
pub fn view_images_every(
    state: &Workspace,
    palette: &[Color32; 256],
    step: usize,
) -> Option<ViewImages> {
    let frame = state.frame()?;
    let step = step.max(1);
    let (w, h) = (frame.width(), frame.height());
    let size = [w.div_ceil(step), h.div_ceil(step)];
    let codes = state.view_codes();
    let classified = ColorImage::new(
        size,
        sampled(size, step, |x, y| {
            palette[usize::from(codes.get(y * w + x).copied().unwrap_or(0))]
        }),
    );
    // The undistorted view of an overhead frame, when chosen, else the frame as it is.
    let raw = if step == 1 {
        ColorImage::from_rgb(size, &state.view_rgb())
    } else if state.undistorted_view() {
        let rgb = state.view_rgb();
        ColorImage::new(
            size,
            sampled(size, step, |x, y| {
                let i = (y * w + x) * 3;
                rgb.get(i..i + 3)
                    .map_or(Color32::BLACK, |p| Color32::from_rgb(p[0], p[1], p[2]))
            }),
        )
    } else {
        // Straight from the frame's YUV: only the pixels kept are converted.
        ColorImage::new(
            size,
            sampled(size, step, |x, y| {
                frame.pixel(x, y).map_or(Color32::BLACK, |p| {
                    let [r, g, b] = crate::frame::yuv_to_rgb(p);
                    Color32::from_rgb(r, g, b)
                })
            }),
        )
    };
    Some(ViewImages { raw, classified })
}

/// The texels of an image of `size` texels, each the value at image pixel (x·step, y·step).
fn sampled(size: [usize; 2], step: usize, at: impl Fn(usize, usize) -> Color32) -> Vec<Color32> {
    let mut out = Vec::with_capacity(size[0] * size[1]);
    for ty in 0..size[1] {
        for tx in 0..size[0] {
            out.push(at(tx * step, ty * step));
        }
    }
    out
}

/// The preview highlight image of the pending selection: the pixels a commit would change
/// hatched in the class colour (so they stand out from pixels already shown in that colour),
/// selected pixels already of the class left as they are, the rest dimmed; transparent with
/// no selection.
#[must_use]
pub fn preview_image(state: &Workspace, size: [usize; 2]) -> ColorImage {
    preview_image_every(state, size, 1)
}

/// [`preview_image`] of an image of `size` pixels keeping every `step`th pixel of each row and
/// column (as [`view_images_every`]); the hatching keeps its stripes in texels, so it shows at
/// any scale.
#[must_use]
pub fn preview_image_every(state: &Workspace, size: [usize; 2], step: usize) -> ColorImage {
    let step = step.max(1);
    let (w, n) = (size[0], size[0] * size[1]);
    let tex = [size[0].div_ceil(step), size[1].div_ceil(step)];
    let empty = || ColorImage::new(tex, vec![Color32::TRANSPARENT; tex[0] * tex[1]]);
    let Some(class_rgb) = state.preview_colour() else {
        return empty();
    };
    let pixels: Vec<PreviewPixel> = state.preview_pixels().collect();
    if pixels.len() != n {
        return empty();
    }
    let dim = Color32::from_black_alpha(PREVIEW_DIM_ALPHA);
    ColorImage::new(
        tex,
        sampled(tex, step, |x, y| match pixels[y * w + x] {
            PreviewPixel::Outside => dim,
            PreviewPixel::Unchanged => Color32::TRANSPARENT,
            PreviewPixel::Changes => {
                let [r, g, b] = hatch_rgb(x / step, y / step, class_rgb);
                Color32::from_rgb(r, g, b)
            }
        }),
    )
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
        // How much of the image the main view shows: its last zoom, else the zoom that fits
        // the image into the window.
        let zoom = self.last_view.map_or_else(
            || {
                let screen = ctx.content_rect();
                ImageTransform::fit_zoom(screen, [size[0] as f32, size[1] as f32])
            },
            |v| v.zoom,
        ) * ctx.pixels_per_point();
        let step = texture_step(zoom);
        if self.textures.as_ref().is_some_and(|t| {
            t.frame_generation == fg && t.preview_generation == pg && t.step == step
        }) {
            return;
        }
        let t0 = Instant::now();
        let frame_changed = self
            .textures
            .as_ref()
            .is_none_or(|t| t.frame_generation != fg || t.step != step);
        let empty = self.state.selection().is_none();
        if frame_changed
            && let Some(ViewImages { raw, classified }) =
                view_images_every(&self.state, &self.palette, step)
        {
            match &mut self.textures {
                Some(t) => {
                    t.raw.set(raw, opts);
                    t.classified.set(classified, opts);
                    if t.step != step {
                        // The preview's texels must match the others'.
                        t.preview_generation = pg.wrapping_sub(1);
                        t.preview_empty = false;
                    }
                    t.step = step;
                }
                None => {
                    let preview = preview_image_every(&self.state, size, step);
                    self.textures = Some(Textures {
                        raw: ctx.load_texture("raw", raw, opts),
                        classified: ctx.load_texture("classified", classified, opts),
                        preview: ctx.load_texture("preview", preview, opts),
                        frame_generation: fg,
                        preview_generation: pg,
                        preview_empty: empty,
                        step,
                    });
                }
            }
        }
        if let Some(t) = &mut self.textures {
            // With nothing selected the preview is not drawn: an empty one is uploaded once,
            // not on every step of playback.
            if t.preview_generation != pg && !(empty && t.preview_empty) {
                t.preview
                    .set(preview_image_every(&self.state, size, t.step), opts);
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
