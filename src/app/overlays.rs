//! Drawing in image-pixel coordinates: one [`ImageTransform`] owns zoom and pan, so no overlay
//! does screen maths. Blob boxes, recognition's primitives (candidate boxes, scan areas and
//! points, circles, posts, gaps, the horizon, coloured-pattern regions, object labels), the
//! sampled pixel and the preview highlight.

use egui::{
    Align2, Color32, FontId, Painter, Pos2, Rect, Stroke, StrokeKind, TextureId, pos2, vec2,
};

use crate::blobs::Blob;
use crate::frame::ImagePoint;
use crate::recognition::{CircleRole, ObjectId, Primitive};
use crate::workspace::{PrimitiveFilter, ViewKind, Workspace, box_colour};

/// Alpha of the overlays of objects other than the selected one.
const DIMMED_ALPHA: f32 = 0.25;

/// Blobs get a label outside the objects view when at least this many times the minimum size.
const LABEL_SIZE_FACTOR: u32 = 20;

/// Maps image pixels to screen points for one view: `screen = view_centre + (image − centre) · zoom`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImageTransform {
    /// The view's rectangle on screen.
    pub view: Rect,
    /// Screen points per image pixel.
    pub zoom: f32,
    /// The image point (pixels) at the centre of the view.
    pub centre: Pos2,
    /// Image size, pixels.
    pub size: [f32; 2],
}

impl ImageTransform {
    /// The zoom that fits an image of `size` pixels into `view`.
    #[must_use]
    pub fn fit_zoom(view: Rect, size: [f32; 2]) -> f32 {
        if size[0] <= 0.0 || size[1] <= 0.0 {
            return 1.0;
        }
        (view.width() / size[0])
            .min(view.height() / size[1])
            .max(0.01)
    }

    /// The transform of the enlarged view with the state's zoom and pan.
    #[must_use]
    pub fn for_state(view: Rect, state: &Workspace) -> Self {
        let (w, h) = state.image_size();
        let size = [w as f32, h as f32];
        let t = state.settings.transform;
        let zoom = t.effective_zoom(Self::fit_zoom(view, size));
        let c = t.effective_centre(size);
        Self {
            view,
            zoom,
            centre: pos2(c[0], c[1]),
            size,
        }
    }

    /// A fitted, centred transform (thumbnails).
    #[must_use]
    pub fn fitted(view: Rect, size: [f32; 2]) -> Self {
        Self {
            view,
            zoom: Self::fit_zoom(view, size),
            centre: pos2(size[0] / 2.0, size[1] / 2.0),
            size,
        }
    }

    /// Image point (pixels, 0,0 = top-left corner of the first pixel) → screen point.
    #[must_use]
    pub fn to_screen(&self, p: Pos2) -> Pos2 {
        self.view.center() + (p - self.centre) * self.zoom
    }

    /// Screen point → image point (pixels).
    #[must_use]
    pub fn to_image(&self, s: Pos2) -> Pos2 {
        self.centre + (s - self.view.center()) / self.zoom
    }

    /// The pixel under a screen point, if inside the image.
    #[must_use]
    pub fn pixel_at(&self, s: Pos2) -> Option<(usize, usize)> {
        let p = self.to_image(s);
        let inside = p.x >= 0.0 && p.y >= 0.0 && p.x < self.size[0] && p.y < self.size[1];
        inside.then_some((p.x as usize, p.y as usize))
    }

    /// The screen centre of pixel (x, y).
    #[must_use]
    pub fn pixel_centre(&self, x: usize, y: usize) -> Pos2 {
        self.to_screen(pos2(x as f32 + 0.5, y as f32 + 0.5))
    }

    /// The whole image on screen.
    #[must_use]
    pub fn image_rect(&self) -> Rect {
        Rect::from_min_max(
            self.to_screen(Pos2::ZERO),
            self.to_screen(pos2(self.size[0], self.size[1])),
        )
    }
}

/// The textures of the shown frame.
#[derive(Debug, Clone, Copy)]
pub struct FrameTextures {
    /// The colour image (`None` while it is not uploaded: nothing draws it).
    pub raw: Option<TextureId>,
    /// Class colours, transparent where unclassified (`None` as `raw`).
    pub classified: Option<TextureId>,
    /// The preview highlight, transparent elsewhere.
    pub preview: TextureId,
    /// The class colours already blended over the colour image at the overlay's opacity: drawn
    /// instead of the two layers when there is one.
    pub blended: Option<TextureId>,
    /// The part of the image (pixels) `raw`, `classified` and `blended` hold, when not all of
    /// it (a large image zoomed in past 1:1).
    pub region: Option<Rect>,
}

/// The view's image layers: the frame, its class colours over it (blended, or two layers), or
/// the class colours alone on black.
fn paint_layers(
    painter: &Painter,
    xf: &ImageTransform,
    kind: ViewKind,
    o: crate::workspace::Overlays,
    tex: &FrameTextures,
    with_overlays: bool,
) {
    let uv = Rect::from_min_max(Pos2::ZERO, pos2(1.0, 1.0));
    // The whole image, or the part of it the layers hold.
    let whole = xf.image_rect();
    let img = tex.region.map_or(whole, |r| {
        Rect::from_min_max(xf.to_screen(r.min), xf.to_screen(r.max))
    });
    match kind {
        ViewKind::Raw | ViewKind::Objects => {
            let with_classes = o.classified && with_overlays;
            match tex.blended.filter(|_| with_classes) {
                Some(blended) => {
                    painter.image(blended, img, uv, Color32::WHITE);
                }
                None => {
                    if let Some(raw) = tex.raw {
                        painter.image(raw, img, uv, Color32::WHITE);
                    }
                    if let Some(classes) = tex.classified.filter(|_| with_classes) {
                        let a = super::textures::classes_alpha(o.opacity);
                        painter.image(classes, img, uv, Color32::from_white_alpha(a));
                    }
                }
            }
        }
        ViewKind::Classified | ViewKind::Blobs => {
            painter.rect_filled(whole, 0.0, Color32::BLACK);
            let tint = if kind == ViewKind::Blobs {
                Color32::from_gray(110)
            } else {
                Color32::WHITE
            };
            if let Some(classes) = tex.classified {
                painter.image(classes, img, uv, tint);
            }
        }
    }
}

/// Paints one view of the shown frame, clipped to the transform's view; returns how many of
/// recognition's primitives it drew.
pub fn paint_view(
    painter: &Painter,
    xf: &ImageTransform,
    kind: ViewKind,
    state: &Workspace,
    tex: &FrameTextures,
    with_overlays: bool,
) -> usize {
    let painter = painter.with_clip_rect(xf.view);
    let img = xf.image_rect();
    let uv = Rect::from_min_max(Pos2::ZERO, pos2(1.0, 1.0));
    let o = state.settings.overlays;
    paint_layers(&painter, xf, kind, o, tex, with_overlays);
    if with_overlays && o.preview && state.selection().is_some() {
        painter.image(tex.preview, img, uv, Color32::WHITE);
    }
    let boxes = match kind {
        ViewKind::Objects => Vec::new(),
        ViewKind::Blobs => state.drawn_blobs(),
        _ if with_overlays && o.blob_boxes => state.drawn_blobs(),
        _ => Vec::new(),
    };
    let labels = with_overlays && o.labels;
    // Outside the objects view only sizeable blobs get a label, or the field drowns in text.
    let label_min = state
        .settings
        .min_blob_pixels
        .saturating_mul(LABEL_SIZE_FACTOR);
    if state.undistorted_view() {
        // Boxes are in the camera's pixels: in the undistorted view each outline goes through
        // the lens model (a box becomes a curved quadrilateral, clipped to the image); no
        // labels there.
        let inside = painter.with_clip_rect(painter.clip_rect().intersect(xf.image_rect()));
        for b in &boxes {
            undistorted_blob_box(&inside, xf, state, b);
        }
    } else {
        for b in &boxes {
            blob_box(&painter, xf, b);
        }
    }
    if labels && !state.undistorted_view() {
        // Largest first, and none over another: a crowded frame shows its main blobs' labels
        // instead of a heap of text.
        let mut labelled: Vec<&Blob> = boxes.iter().filter(|b| b.pixels >= label_min).collect();
        labelled.sort_by_key(|b| std::cmp::Reverse(b.pixels));
        let mut placed: Vec<Rect> = Vec::new();
        for b in labelled {
            blob_label(&painter, xf, b, &mut placed);
        }
    }
    let mut drawn = 0;
    if kind == ViewKind::Objects || (with_overlays && kind != ViewKind::Blobs) {
        let filter = if kind == ViewKind::Objects {
            let mut f = PrimitiveFilter::objects(o, state.accepted_owners());
            // A thumbnail is too small for text.
            f.overlays.object_labels = with_overlays;
            f
        } else {
            PrimitiveFilter::all(o)
        };
        drawn = paint_primitives(
            &painter,
            xf,
            state.primitives(),
            &filter,
            state.selected_object(),
        );
    }
    if with_overlays
        && !state.undistorted_view()
        && let Some((x, y)) = state.selection().and_then(|s| s.pixel)
    {
        sample_marker(&painter, xf, x, y);
    }
    if with_overlays && !state.undistorted_view() {
        label_boxes(&painter, xf, state);
    }
    super::overhead_overlays::paint_overhead(&painter, xf, kind, state, with_overlays);
    drawn
}

/// The opened labels' boxes of the shown frame (`Command::OpenLabels`), dashed, by class: balls
/// orange, robots blue, goals yellow, other classes grey; each with its class name above it.
fn label_boxes(painter: &Painter, xf: &ImageTransform, state: &Workspace) {
    use crate::eval::label_sets::LabelObject;
    let Some(frame) = state.shown_label_boxes() else {
        return;
    };
    for b in &frame.boxes {
        let colour = match b.object {
            LabelObject::Ball => Color32::from_rgb(255, 120, 0),
            LabelObject::Robot => Color32::from_rgb(60, 140, 255),
            LabelObject::Goal => Color32::from_rgb(255, 230, 0),
            LabelObject::Other => Color32::from_gray(200),
        };
        let rect = Rect::from_min_max(
            xf.to_screen(pos2(b.min_x as f32, b.min_y as f32)),
            xf.to_screen(pos2(b.max_x as f32, b.max_y as f32)),
        );
        let stroke = Stroke::new(1.5, colour);
        let corners = [
            rect.left_top(),
            rect.right_top(),
            rect.right_bottom(),
            rect.left_bottom(),
            rect.left_top(),
        ];
        for side in corners.windows(2) {
            painter.extend(egui::Shape::dashed_line(side, stroke, 4.0, 3.0));
        }
        painter.text(
            rect.left_top() - vec2(0.0, 2.0),
            egui::Align2::LEFT_BOTTOM,
            &b.class,
            FontId::proportional(10.0),
            colour,
        );
    }
}

/// A blob's box on screen (pixel edges inclusive).
fn blob_rect(xf: &ImageTransform, b: &Blob) -> Rect {
    pixel_box_rect(xf, b.bounds().to_array().map(|v| v as f32))
}

/// One blob's box in its class's box colour.
pub fn blob_box(painter: &Painter, xf: &ImageTransform, b: &Blob) {
    let [r, g, bl] = box_colour(b.colour);
    let colour = Color32::from_rgb(r, g, bl);
    painter.rect_stroke(
        blob_rect(xf, b),
        0.0,
        Stroke::new(1.5, colour),
        StrokeKind::Outside,
    );
}

/// One blob's box in the undistorted view: its outline, a few points a side, each placed
/// through the lens model.
fn undistorted_blob_box(painter: &Painter, xf: &ImageTransform, state: &Workspace, b: &Blob) {
    const STEPS: usize = 4;
    let [x0, y0, x1, y1] = b.bounds().to_array().map(|v| v as f64);
    let (x1, y1) = (x1 + 1.0, y1 + 1.0);
    let corners = [(x0, y0), (x1, y0), (x1, y1), (x0, y1), (x0, y0)];
    let mut points = Vec::with_capacity(4 * STEPS + 1);
    for side in corners.windows(2) {
        let ((ax, ay), (bx, by)) = (side[0], side[1]);
        for k in 0..STEPS {
            let t = k as f64 / STEPS as f64;
            let p = ImagePoint::new(ax + (bx - ax) * t, ay + (by - ay) * t);
            if let Some(v) = state.overhead_view_point(p) {
                points.push(xf.to_screen(pos2(v.x_px as f32, v.y_px as f32)));
            }
        }
    }
    let [r, g, bl] = box_colour(b.colour);
    painter.add(egui::Shape::closed_line(
        points,
        Stroke::new(1.5, Color32::from_rgb(r, g, bl)),
    ));
}

/// A blob's class and size below its box, unless it would cover a label in `placed`; the
/// label drawn is added to `placed`.
pub fn blob_label(painter: &Painter, xf: &ImageTransform, b: &Blob, placed: &mut Vec<Rect>) {
    let [r, g, bl] = box_colour(b.colour);
    let colour = Color32::from_rgb(r, g, bl);
    let text = format!("{} {}×{}", b.class().name(), b.width(), b.height());
    // Below the box: above it go recognition's object labels. A box at the bottom of the view
    // gets its label above it instead, and a box partly outside the view its label at the edge.
    let rect = blob_rect(xf, b);
    let galley = painter.layout_no_wrap(text, FontId::proportional(11.0), colour);
    let view = painter.clip_rect();
    let mut bg =
        Rect::from_min_size(rect.left_bottom() + vec2(0.0, 3.0), galley.size()).expand(1.0);
    if bg.max.y > view.max.y {
        bg = bg.translate(vec2(0.0, -(rect.height() + bg.height() + 6.0)));
    }
    let bg = keep_inside(bg, view);
    if placed.iter().any(|p| p.intersects(bg)) {
        return;
    }
    placed.push(bg);
    painter.rect_filled(bg, 2.0, Color32::from_black_alpha(160));
    painter.galley(bg.min + vec2(1.0, 1.0), galley, colour);
}

/// The colour of a primitive: the one palette of `eotn render`, the app and the annotations.
fn primitive_colour(p: &Primitive) -> Color32 {
    let [r, g, b] = crate::overlay::primitive_rgb(p);
    Color32::from_rgb(r, g, b)
}

/// Draws recognition's primitives through the view's transform; returns how many it drew (those
/// the filter shows). With a `selected` owner, its primitives are drawn thicker and every other
/// object's are dimmed (the horizon stays).
pub fn paint_primitives(
    painter: &Painter,
    xf: &ImageTransform,
    primitives: &[Primitive],
    filter: &PrimitiveFilter<'_>,
    selected: Option<ObjectId>,
) -> usize {
    let at = |p: ImagePoint| xf.to_screen(pos2(p.x_px as f32, p.y_px as f32));
    // Edge points: a dot about a pixel wide, never smaller than 1.5 points.
    let dot = (xf.zoom * 0.5).clamp(1.5, 4.0);
    let clip = painter.clip_rect().expand(8.0);
    let mut drawn = 0;
    for p in primitives.iter().filter(|p| filter.shows(p)) {
        drawn += 1;
        let mine = selected == Some(p.owner());
        let dim = selected.is_some() && !mine && p.owner() != ObjectId::Horizon;
        let mut colour = primitive_colour(p);
        if dim {
            colour = colour.gamma_multiply(DIMMED_ALPHA);
        }
        let width = if mine { 3.0 } else { 1.5 };
        let stroke = Stroke::new(width, colour);
        match p {
            Primitive::Box { bounds, .. } => {
                let rect = pixel_box_rect(xf, bounds.to_array().map(|v| v as f32));
                painter.rect_stroke(rect, 0.0, stroke, StrokeKind::Outside);
            }
            Primitive::ScanArea { corners, .. } => {
                let pts: Vec<Pos2> = corners.iter().map(|&c| at(c)).collect();
                painter.add(egui::Shape::closed_line(pts, stroke));
            }
            Primitive::ScanPoints { points, .. } => {
                // One mesh for all points: hundreds of separate circles cost far more to
                // tessellate and rasterise.
                let mut mesh = egui::Mesh::default();
                for &q in points {
                    let c = at(q);
                    if clip.contains(c) {
                        mesh.add_colored_rect(Rect::from_center_size(c, vec2(dot, dot)), colour);
                    }
                }
                painter.add(mesh);
            }
            Primitive::Circle {
                center,
                radius,
                role,
                ..
            } => {
                paint_circle(
                    painter,
                    at(*center),
                    (*radius as f32) * xf.zoom,
                    *role,
                    stroke,
                );
            }
            Primitive::Line { from, to, .. } => {
                painter.line_segment([at(*from), at(*to)], stroke);
            }
            Primitive::PatternRegion { bounds, centre, .. } => {
                let rect = pixel_box_rect(xf, bounds.map(|v| v as f32));
                let stroke = if *centre {
                    Stroke::new(width + 1.0, colour)
                } else {
                    stroke
                };
                painter.rect_stroke(rect.shrink(1.0), 0.0, stroke, StrokeKind::Inside);
            }
            Primitive::Label { at: pos, text, .. } => {
                paint_label(painter, at(*pos), text, colour, dim);
            }
        }
    }
    drawn
}

/// The screen rectangle of an inclusive pixel box `[minx, miny, maxx, maxy]` (pixels; the
/// right and bottom edges are those of the last column and row).
fn pixel_box_rect(xf: &ImageTransform, [x0, y0, x1, y1]: [f32; 4]) -> Rect {
    Rect::from_min_max(
        xf.to_screen(pos2(x0, y0)),
        xf.to_screen(pos2(x1 + 1.0, y1 + 1.0)),
    )
}

/// A circle of `radius` (screen points) about `centre`: solid where the ball is seen, thin and
/// dashed where the skew correction puts it. Nothing for a radius that is not positive.
fn paint_circle(painter: &Painter, centre: Pos2, radius: f32, role: CircleRole, stroke: Stroke) {
    let r = radius;
    if !(r.is_finite() && r > 0.0) {
        return;
    }
    match role {
        CircleRole::Observed => {
            painter.circle_stroke(centre, r, stroke);
        }
        CircleRole::SkewCorrected => {
            // Thin and dashed: where the skew correction puts the ball, beside the solid
            // circle on the ball's pixels.
            let n = ((r * 0.8) as usize).clamp(16, 256);
            let pts: Vec<Pos2> = (0..=n)
                .map(|i| {
                    let t = i as f32 / n as f32 * std::f32::consts::TAU;
                    centre + vec2(r * t.cos(), r * t.sin())
                })
                .collect();
            let thin = Stroke::new(stroke.width * 0.6, stroke.color);
            painter.extend(egui::Shape::dashed_line(&pts, thin, 4.0, 3.0));
        }
    }
}

/// An object's label just above `anchor` (screen) on a dark backing (fainter when `dim`).
fn paint_label(painter: &Painter, anchor: Pos2, text: &str, colour: Color32, dim: bool) {
    let galley = painter.layout_no_wrap(text.to_owned(), FontId::proportional(12.0), colour);
    let bg =
        Rect::from_min_size(anchor - vec2(0.0, galley.size().y + 2.0), galley.size()).expand(2.0);
    // Kept inside the view: a ball at the top edge, or outside the view when zoomed in, still
    // shows its distance at the edge nearest to it.
    let bg = keep_inside(bg, painter.clip_rect());
    let bg_alpha = if dim { 60 } else { 180 };
    painter.rect_filled(bg, 3.0, Color32::from_black_alpha(bg_alpha));
    painter.galley(bg.min + vec2(2.0, 2.0), galley, colour);
}

/// `bg` moved the least distance that puts it inside `view` (pinned to the nearest edge).
#[must_use]
pub fn keep_inside(bg: Rect, view: Rect) -> Rect {
    let dx = (view.max.x - bg.max.x).min(0.0) + (view.min.x - bg.min.x).max(0.0);
    let dy = (view.max.y - bg.max.y).min(0.0) + (view.min.y - bg.min.y).max(0.0);
    bg.translate(vec2(dx, dy))
}

/// A cross on the sampled pixel.
pub fn sample_marker(painter: &Painter, xf: &ImageTransform, x: usize, y: usize) {
    let c = xf.pixel_centre(x, y);
    let r = (xf.zoom * 0.5).max(4.0) + 3.0;
    for stroke in [
        Stroke::new(3.0, Color32::BLACK),
        Stroke::new(1.0, Color32::WHITE),
    ] {
        painter.line_segment([c - vec2(r, 0.0), c + vec2(r, 0.0)], stroke);
        painter.line_segment([c - vec2(0.0, r), c + vec2(0.0, r)], stroke);
    }
}

/// A short text with a dark background at a corner of the view (zoom level, frame time, what
/// a left click does).
pub fn corner_text(painter: &Painter, view: Rect, align: Align2, text: String) {
    let galley = painter.layout_no_wrap(text, FontId::monospace(11.0), Color32::WHITE);
    let size = galley.size() + vec2(6.0, 4.0);
    let rect = align.align_size_within_rect(size, view.shrink(4.0));
    painter.rect_filled(rect, 3.0, Color32::from_black_alpha(170));
    painter.galley(rect.min + vec2(3.0, 2.0), galley, Color32::WHITE);
}
