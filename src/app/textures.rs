//! The shown frame's textures: the colour and class-colour images built on the CPU, the
//! pending selection's highlight, and their upload when the frame or the preview changes.

use std::sync::Arc;
use std::time::Instant;

use egui::{Color32, ColorImage, TextureHandle, TextureOptions};

use super::EotnApp;
use super::overlays::{FrameTextures, ImageTransform};
use crate::workspace::{PreviewPixel, ViewKind, Workspace, hatch_rgb};

/// How much the pixels outside a pending selection are darkened (alpha of black over them).
const PREVIEW_DIM_ALPHA: u8 = 110;

/// The textures of the shown frame and what they were built from. Each layer is uploaded only
/// while something draws it: without a GPU every upload of a 1920×1200 frame's layer is a copy
/// the software rasteriser makes on the UI thread (docs/speed.md).
pub(super) struct Textures {
    /// The main view's layers at `step`.
    raw: Layer,
    classified: Layer,
    /// The classified layer blended over the frame, while the main view shows that.
    blended: Layer,
    preview: TextureHandle,
    /// The images behind `raw` and `classified` at `step` (shared with the upload, not copied),
    /// kept to blend again when the opacity changes and to upload a layer when it is wanted.
    images: (Arc<ColorImage>, Arc<ColorImage>),
    /// The thumbnails' own smaller layers, when they show the frame coarser than the main view.
    thumbs: Option<(Layer, Layer)>,
    frame_generation: u64,
    preview_generation: u64,
    /// The preview texture holds no highlight (nothing to re-upload while none is pending).
    preview_empty: bool,
    /// Image pixels per texel along each axis ([`texture_step`]).
    step: usize,
    /// The part of the image the main view's layers hold (columns x0..x1, rows y0..y1), when
    /// the view is zoomed in past 1:1 on a large image ([`visible_region`]); else all of it.
    region: Option<[usize; 4]>,
    /// Counts the images made: what the main view's layers are stamped with.
    build: u64,
}

/// One uploaded layer and what it holds: the frame generation, the step and (blended) the
/// opacity it was made for.
#[derive(Default)]
struct Layer {
    texture: Option<TextureHandle>,
    holds: Option<(u64, usize, u8)>,
}

impl Layer {
    /// The texture, when it holds `key`.
    fn id_if(&self, key: (u64, usize, u8)) -> Option<egui::TextureId> {
        self.texture
            .as_ref()
            .filter(|_| self.holds == Some(key))
            .map(TextureHandle::id)
    }

    /// Uploads `image` (made for `key`) unless the layer already holds `key`.
    fn upload(
        &mut self,
        ctx: &egui::Context,
        name: &str,
        key: (u64, usize, u8),
        image: impl FnOnce() -> egui::ImageData,
    ) {
        if self.holds == Some(key) && self.texture.is_some() {
            return;
        }
        match &mut self.texture {
            Some(t) => t.set(image(), TextureOptions::NEAREST),
            None => self.texture = Some(ctx.load_texture(name, image(), TextureOptions::NEAREST)),
        }
        self.holds = Some(key);
    }
}

/// Which layers the views draw this frame.
#[derive(Debug, Clone, Copy)]
struct Wanted {
    /// The opacity the main view blends the classes over the frame at, when it does.
    blend: Option<u8>,
    /// The main view draws the frame's colours alone, or its class colours alone.
    raw: bool,
    classified: bool,
    /// Image pixels per texel of the thumbnails' own layers (none when it is the main step).
    thumb_step: Option<usize>,
}

impl Textures {
    fn key(&self, alpha: u8) -> (u64, usize, u8) {
        (self.build, self.step, alpha)
    }

    /// The main view's textures: those holding the shown frame at the current step.
    pub(super) fn ids(&self) -> FrameTextures {
        // The blended layer at any opacity: after the opacity changes it is blended again at
        // the next frame's start, and one frame at the old opacity is not worth two layers.
        let blended = (self.blended.holds)
            .filter(|h| (h.0, h.1) == (self.build, self.step))
            .and_then(|h| self.blended.id_if(h));
        FrameTextures {
            raw: self.raw.id_if(self.key(0)),
            classified: self.classified.id_if(self.key(0)),
            preview: self.preview.id(),
            blended,
            region: self.region.map(|[x0, y0, x1, y1]| {
                egui::Rect::from_min_max(
                    egui::pos2(x0 as f32, y0 as f32),
                    egui::pos2(x1 as f32, y1 as f32),
                )
            }),
        }
    }

    /// The thumbnails' textures: their own smaller layers, else the main view's.
    pub(super) fn thumb_ids(&self) -> FrameTextures {
        match &self.thumbs {
            Some((raw, classified)) => {
                let holding = |l: &Layer| l.holds.filter(|h| h.0 == self.frame_generation);
                FrameTextures {
                    raw: holding(raw).and_then(|h| raw.id_if(h)),
                    classified: holding(classified).and_then(|h| classified.id_if(h)),
                    preview: self.preview.id(),
                    blended: None,
                    region: None,
                }
            }
            None => FrameTextures {
                blended: None,
                region: None,
                ..self.ids()
            },
        }
    }

    /// Uploads the thumbnails' own layers (`images` at a step of their own), or drops them when
    /// the thumbnails share the main view's.
    fn upload_thumbs(&mut self, ctx: &egui::Context, images: Option<(usize, ViewImages)>) {
        let Some((step, ViewImages { raw, classified })) = images else {
            self.thumbs = None;
            return;
        };
        let key = (self.frame_generation, step, 0);
        let (r, c) = self.thumbs.get_or_insert_with(Default::default);
        r.upload(ctx, "thumbnail raw", key, || raw.into());
        c.upload(ctx, "thumbnail classified", key, || classified.into());
    }

    /// Uploads the main view's wanted layers from `images` (blending at the wanted opacity),
    /// and the layers the thumbnails share with it.
    fn upload_wanted(&mut self, ctx: &egui::Context, wanted: Wanted) {
        let shared = wanted.thumb_step.is_none();
        let key = self.key(0);
        if wanted.raw || shared {
            let image = Arc::clone(&self.images.0);
            self.raw.upload(ctx, "raw", key, || image.into());
        }
        if wanted.classified || shared {
            let image = Arc::clone(&self.images.1);
            self.classified
                .upload(ctx, "classified", key, || image.into());
        }
        if let Some(alpha) = wanted.blend {
            let (raw, classified) = (&self.images.0, &self.images.1);
            let key = self.key(alpha);
            self.blended.upload(ctx, "blended", key, || {
                blend_classes(raw, classified, alpha).into()
            });
        }
    }
}

/// The opacity (0–255) the classified layer is drawn at over the frame: the overlay's setting.
#[must_use]
pub fn classes_alpha(opacity: f32) -> u8 {
    (opacity.clamp(0.0, 1.0) * 255.0) as u8
}

/// `classified` drawn over `raw` at `alpha` (0–255) where it has a class colour, as the
/// renderer blends the layer ([`blend_texel`]); the two images must be of one size (else `raw`
/// is returned as it is).
#[must_use]
pub fn blend_classes(raw: &ColorImage, classified: &ColorImage, alpha: u8) -> ColorImage {
    if raw.size != classified.size {
        return raw.clone();
    }
    let blend = |raw: &[Color32], classes: &[Color32]| -> Vec<Color32> {
        raw.iter()
            .zip(classes)
            .map(|(&r, &c)| blend_texel(r, c, alpha))
            .collect()
    };
    let n = raw.pixels.len();
    if n < PARALLEL_TEXELS {
        return ColorImage::new(raw.size, blend(&raw.pixels, &classified.pixels));
    }
    // Two halves on two threads (see `PARALLEL_TEXELS`).
    let (top, bottom) = (
        raw.pixels.split_at(n / 2),
        classified.pixels.split_at(n / 2),
    );
    let mut pixels = std::thread::scope(|s| {
        let first = s.spawn(|| blend(top.0, bottom.0));
        let second = blend(top.1, bottom.1);
        (first.join(), second)
    });
    let mut all = pixels.0.unwrap_or_else(|_| top.0.to_vec());
    all.append(&mut pixels.1);
    ColorImage::new(raw.size, all)
}

/// The class colour `class` over the frame's colour `raw` at `alpha` (0–255), as the renderer
/// blends a layer drawn at that opacity (`c·a + r·(1 − a)` in the images' own sRGB values,
/// rounded to nearest); `raw` where the class colour is transparent (unclassified).
#[must_use]
#[inline]
pub fn blend_texel(raw: Color32, class: Color32, alpha: u8) -> Color32 {
    // Without branches or division, so a whole image's loop vectorises in 16-bit lanes: an
    // unclassified texel blends at opacity 0, which gives `raw` exactly, and
    // `(t + 128 + ((t + 128) >> 8)) >> 8` is t/255 rounded for every t up to 255·255.
    let a = if class.a() == 0 { 0 } else { u16::from(alpha) };
    let mix = |c: u8, r: u8| {
        let t = u16::from(c) * a + u16::from(r) * (255 - a) + 128;
        ((t + (t >> 8)) >> 8) as u8
    };
    Color32::from_rgb(
        mix(class.r(), raw.r()),
        mix(class.g(), raw.g()),
        mix(class.b(), raw.b()),
    )
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
    let undistorted = state.undistorted_view().then(|| state.view_rgb());
    let codes = state.view_codes();
    let classes = || class_texels(&codes, palette, [w, h], step);
    // Large images on two threads, a pass over the frame each: at full resolution (the view
    // zoomed in past 1:1) one after the other took most of a 50 ms frame.
    let (raw, classified) = if size[0] * size[1] >= PARALLEL_TEXELS {
        std::thread::scope(|s| {
            let raw = s.spawn(|| colour_texels(frame, undistorted.as_deref(), step));
            let classified = classes();
            (raw.join(), classified)
        })
    } else {
        (
            Ok(colour_texels(frame, undistorted.as_deref(), step)),
            classes(),
        )
    };
    // The thread only converts pixels; were it to panic, the view shows black, not a crash.
    let raw = raw.unwrap_or_else(|_| vec![Color32::BLACK; size[0] * size[1]]);
    Some(ViewImages {
        raw: ColorImage::new(size, raw),
        classified: ColorImage::new(size, classified),
    })
}

/// The colour and class-colour images of `region` (columns x0..x1, rows y0..y1) of the shown
/// frame at full resolution: what a view zoomed in past 1:1 shows of a large frame.
#[must_use]
pub fn view_images_in(
    state: &Workspace,
    palette: &[Color32; 256],
    region: [usize; 4],
) -> Option<ViewImages> {
    let frame = state.frame()?;
    let [x0, y0, x1, y1] = region;
    let (w, h) = (frame.width(), frame.height());
    let (x1, y1) = (x1.min(w), y1.min(h));
    let size = [x1.saturating_sub(x0), y1.saturating_sub(y0)];
    let raw = frame
        .rgba_in(x0..x1, y0..y1)
        .into_iter()
        .map(|[r, g, b, a]| Color32::from_rgba_premultiplied(r, g, b, a))
        .collect();
    let codes = state.view_codes();
    let mut classified = Vec::with_capacity(size[0] * size[1]);
    for y in y0..y1 {
        match codes.get(y * w + x0..y * w + x1) {
            Some(row) => classified.extend(row.iter().map(|&c| palette[usize::from(c)])),
            None => classified.resize(classified.len() + size[0], Color32::TRANSPARENT),
        }
    }
    Some(ViewImages {
        raw: ColorImage::new(size, raw),
        classified: ColorImage::new(size, classified),
    })
}

/// The part of an image of `size` pixels the layers of `view` (zoomed in past 1:1) should
/// hold: the visible part grown by half its size each way, so that panning rebuilds them only
/// now and then; `kept`, the part held now, while it still covers what is visible. `None` when
/// most of the image is visible anyway. Columns start and end even (UYVY pairs).
#[must_use]
pub fn visible_region(
    view: &ImageTransform,
    size: [usize; 2],
    kept: Option<[usize; 4]>,
) -> Option<[usize; 4]> {
    let (w, h) = (size[0] as f32, size[1] as f32);
    let a = view.to_image(view.view.min);
    let b = view.to_image(view.view.max);
    let (vx0, vy0) = (a.x.clamp(0.0, w), a.y.clamp(0.0, h));
    let (vx1, vy1) = (b.x.clamp(0.0, w), b.y.clamp(0.0, h));
    let (vw, vh) = (vx1 - vx0, vy1 - vy0);
    if !(vw.is_finite() && vh.is_finite()) || vw * vh > 0.4 * w * h {
        return None;
    }
    if let Some([x0, y0, x1, y1]) = kept {
        let inside = vx0 >= x0 as f32 && vy0 >= y0 as f32 && vx1 <= x1 as f32 && vy1 <= y1 as f32;
        if inside {
            return kept;
        }
    }
    let grow = |lo: f32, hi: f32, by: f32, max: f32| {
        (
            (lo - by).clamp(0.0, max) as usize,
            (hi + by).ceil().clamp(0.0, max) as usize,
        )
    };
    let (x0, x1) = grow(vx0, vx1, vw / 2.0, w);
    let (y0, y1) = grow(vy0, vy1, vh / 2.0, h);
    let (x0, x1) = (x0 & !1, (x1 + 1).min(size[0]) & !1);
    Some([x0, y0, x1.max(x0), y1])
}

/// From this many texels on, the view's images are made on two threads.
const PARALLEL_TEXELS: usize = 1 << 18;

/// The frame's colours at `step`: straight from its YUV (only the pixels kept are converted),
/// or from the undistorted view's RGB (`undistorted`) when that is shown.
fn colour_texels(
    frame: &crate::frame::Frame,
    undistorted: Option<&[u8]>,
    step: usize,
) -> Vec<Color32> {
    let (w, h) = (frame.width(), frame.height());
    let Some(rgb) = undistorted else {
        return frame
            .rgba_every(step)
            .into_iter()
            .map(|[r, g, b, a]| Color32::from_rgba_premultiplied(r, g, b, a))
            .collect();
    };
    let mut raw = Vec::with_capacity(w.div_ceil(step) * h.div_ceil(step));
    for y in (0..h).step_by(step) {
        raw.extend((0..w).step_by(step).map(|x| {
            let p = rgb.get((y * w + x) * 3..(y * w + x) * 3 + 3);
            p.map_or(Color32::BLACK, |p| Color32::from_rgb(p[0], p[1], p[2]))
        }));
    }
    raw
}

/// The class colours of `codes` (one a pixel of an image of `size`) at `step`.
fn class_texels(
    codes: &[u8],
    palette: &[Color32; 256],
    size: [usize; 2],
    step: usize,
) -> Vec<Color32> {
    let [w, h] = size;
    let tw = w.div_ceil(step);
    let mut classified = Vec::with_capacity(tw * h.div_ceil(step));
    for y in (0..h).step_by(step) {
        match codes.get(y * w..(y + 1) * w) {
            Some(row) => {
                classified.extend(row.iter().step_by(step).map(|&c| palette[usize::from(c)]));
            }
            None => classified.resize(classified.len() + tw, Color32::TRANSPARENT),
        }
    }
    classified
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

/// Image pixels per texel of the thumbnails' layers: at least 320 texels across, plenty for a
/// thumbnail of a few hundred screen pixels drawn with nearest filtering.
#[must_use]
pub fn thumbnail_step(width: usize) -> usize {
    (width / 320).max(1)
}

impl EotnApp {
    pub(super) fn update_textures(&mut self, ctx: &egui::Context) {
        let Some(frame) = self.state.frame() else {
            return;
        };
        let size = [frame.width(), frame.height()];
        let (fg, pg) = (
            self.state.frame_generation(),
            self.state.preview_generation(),
        );
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
        let wanted = self.wanted_layers(step, size[0]);
        let region = match (&self.last_view, wanted.thumb_step) {
            // Only where the thumbnails have layers of their own: they show the whole image.
            (Some(view), Some(_)) if step == 1 && !self.state.undistorted_view() => {
                visible_region(view, size, self.textures.as_ref().and_then(|t| t.region))
            }
            _ => None,
        };
        let t0 = Instant::now();
        let frame_changed = self
            .textures
            .as_ref()
            .is_none_or(|t| t.frame_generation != fg || t.step != step || t.region != region);
        if frame_changed {
            self.make_images(ctx, step, wanted.thumb_step, region);
        }
        let empty = self.state.selection().is_none();
        if let Some(t) = &mut self.textures {
            // With nothing selected the preview is not drawn: an empty one is uploaded once,
            // not on every step of playback.
            if t.preview_generation != pg && !(empty && t.preview_empty) {
                let preview = preview_image_every(&self.state, size, t.step);
                t.preview.set(preview, TextureOptions::NEAREST);
                t.preview_empty = empty;
            }
            t.preview_generation = pg;
            t.upload_wanted(ctx, wanted);
        }
        if frame_changed {
            self.state.record_upload(t0.elapsed());
        }
    }

    /// The layers the views draw: the main view's by its kind and overlays, the thumbnails' at
    /// [`thumbnail_step`] of their own when that is coarser than the main view's `step`.
    fn wanted_layers(&self, step: usize, width: usize) -> Wanted {
        let o = self.state.settings.overlays;
        let frame_view = matches!(
            self.state.settings.main_view,
            ViewKind::Raw | ViewKind::Objects
        );
        let blend = (frame_view && o.classified).then(|| classes_alpha(o.opacity));
        let thumb_step = thumbnail_step(width);
        Wanted {
            blend,
            raw: frame_view && blend.is_none(),
            classified: !frame_view,
            thumb_step: (thumb_step > step).then_some(thumb_step),
        }
    }

    /// Makes the shown frame's colour and class-colour images at `step`, or of `region` only
    /// (uploaded later, as wanted), and the thumbnails' own layers at `thumb_step`.
    fn make_images(
        &mut self,
        ctx: &egui::Context,
        step: usize,
        thumb_step: Option<usize>,
        region: Option<[usize; 4]>,
    ) {
        let images = match region {
            Some(r) => view_images_in(&self.state, &self.palette, r),
            None => view_images_every(&self.state, &self.palette, step),
        };
        let Some(ViewImages { raw, classified }) = images else {
            return;
        };
        let fg = self.state.frame_generation();
        let images = (Arc::new(raw), Arc::new(classified));
        let thumbs = thumb_step
            .and_then(|ts| Some((ts, view_images_every(&self.state, &self.palette, ts)?)));
        match &mut self.textures {
            Some(t) => {
                if t.step != step {
                    // The preview's texels must match the others'.
                    t.preview_generation = self.state.preview_generation().wrapping_sub(1);
                    t.preview_empty = false;
                }
                t.step = step;
                t.images = images;
                t.frame_generation = fg;
                t.region = region;
                t.build += 1;
                t.upload_thumbs(ctx, thumbs);
            }
            None => {
                let frame_size = self
                    .state
                    .frame()
                    .map_or([0, 0], |f| [f.width(), f.height()]);
                let preview = preview_image_every(&self.state, frame_size, step);
                self.textures = Some(Textures {
                    raw: Layer::default(),
                    classified: Layer::default(),
                    blended: Layer::default(),
                    preview: ctx.load_texture("preview", preview, TextureOptions::NEAREST),
                    images,
                    thumbs: None,
                    frame_generation: fg,
                    preview_generation: self.state.preview_generation(),
                    preview_empty: self.state.selection().is_none(),
                    step,
                    region,
                    build: 0,
                });
                if let Some(t) = &mut self.textures {
                    t.upload_thumbs(ctx, thumbs);
                }
            }
        }
    }
}
