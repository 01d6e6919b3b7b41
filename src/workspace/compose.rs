//! The enlarged view composed on the CPU as packed RGB (what Export view writes), and which
//! recognition primitives each view draws.

use super::Workspace;
use super::settings::{Overlays, ViewKind};
use crate::lut::ColourClass;
use crate::recognition::{LineRole, ObjectId, Primitive};

/// Which recognition primitives a view draws.
#[derive(Debug, Clone, Copy)]
pub struct PrimitiveFilter<'a> {
    /// The overlay switches.
    pub overlays: Overlays,
    /// Only these owners (the objects view: accepted objects); `None` draws every candidate.
    pub owners: Option<&'a [ObjectId]>,
}

impl<'a> PrimitiveFilter<'a> {
    /// Every candidate, as the switches say.
    #[must_use]
    pub const fn all(overlays: Overlays) -> Self {
        Self {
            overlays,
            owners: None,
        }
    }

    /// Accepted objects only, always with their boxes and labels (the objects view).
    #[must_use]
    pub const fn objects(overlays: Overlays, accepted: &'a [ObjectId]) -> Self {
        let mut o = overlays;
        o.candidates = true;
        o.object_labels = true;
        Self {
            overlays: o,
            owners: Some(accepted),
        }
    }

    /// Whether `p` is drawn.
    #[must_use]
    pub fn shows(&self, p: &Primitive) -> bool {
        let o = &self.overlays;
        let on = match p {
            Primitive::Box { .. } => o.candidates,
            Primitive::ScanArea { .. } => o.scan_areas,
            Primitive::ScanPoints { .. } => o.scan_points,
            Primitive::Circle { .. } => o.circles,
            Primitive::Line { role, .. } => match role {
                LineRole::Horizon => o.horizon,
                LineRole::Post => o.posts,
                LineRole::Gap | LineRole::Scan => o.gaps,
            },
            Primitive::PatternRegion { .. } => o.patterns,
            Primitive::Label { owner, .. } => {
                o.object_labels && (o.patterns || !owner.is_pattern())
            }
        };
        let horizon = matches!(
            p,
            Primitive::Line {
                role: LineRole::Horizon,
                ..
            }
        );
        on && (horizon || self.owners.is_none_or(|w| w.contains(&p.owner())))
    }
}

fn mix(a: u8, b: u8, t: f32) -> u8 {
    (f32::from(a) * (1.0 - t) + f32::from(b) * t).round() as u8
}

/// The colour blob boxes of class `code` are drawn in: the class colour, white for black blobs
/// would vanish otherwise.
#[must_use]
pub fn box_colour(code: u8) -> [u8; 3] {
    match code {
        9 => [255, 255, 255],
        c => crate::lut::code_display_rgb(c),
    }
}

impl Workspace {
    /// The view `kind` with the current overlays as packed RGB (what Export view writes):
    /// (width, height, pixels).
    ///
    /// # Errors
    /// No frame open.
    pub fn compose_view_rgb(&self, kind: ViewKind) -> anyhow::Result<(usize, usize, Vec<u8>)> {
        let (w, h) = self.image_size();
        anyhow::ensure!(w > 0, "no frame to export");
        let codes = self.classified().codes();
        let o = self.settings.overlays;
        let mut out = match kind {
            ViewKind::Raw | ViewKind::Objects => {
                let mut rgb = self.rgb().to_vec();
                if o.classified {
                    let a = o.opacity;
                    for (px, &c) in rgb.chunks_exact_mut(3).zip(codes) {
                        if c != 0 {
                            let k = crate::lut::code_display_rgb(c);
                            for i in 0..3 {
                                px[i] = mix(px[i], k[i], a);
                            }
                        }
                    }
                }
                rgb
            }
            ViewKind::Classified => self.classified().to_rgb(),
            ViewKind::Blobs => {
                let mut rgb = self.classified().to_rgb();
                rgb.iter_mut().for_each(|v| *v /= 2);
                rgb
            }
        };
        if o.preview
            && let Some(k) = self.preview_colour()
        {
            for (i, (px, p)) in out
                .chunks_exact_mut(3)
                .zip(self.preview_pixels())
                .enumerate()
            {
                match p {
                    PreviewPixel::Changes => px.copy_from_slice(&hatch_rgb(i % w, i / w, k)),
                    PreviewPixel::Unchanged => {}
                    // As on screen: the rest is dimmed so the highlight always shows.
                    PreviewPixel::Outside => {
                        px.iter_mut().for_each(|v| *v = mix(*v, 0, 110.0 / 255.0));
                    }
                }
            }
        }
        let boxes = match kind {
            ViewKind::Objects => Vec::new(),
            ViewKind::Blobs => self.drawn_blobs(),
            _ if o.blob_boxes => self.drawn_blobs(),
            _ => Vec::new(),
        };
        for b in boxes {
            crate::overlay::outline_box(&mut out, w, h, b.bounds(), box_colour(b.colour));
        }
        let filter = match kind {
            ViewKind::Objects => Some(PrimitiveFilter::objects(o, &self.accepted_owners)),
            ViewKind::Raw | ViewKind::Classified => Some(PrimitiveFilter::all(o)),
            ViewKind::Blobs => None,
        };
        if let Some(f) = filter {
            let shown: Vec<Primitive> = self
                .primitives
                .iter()
                .filter(|p| f.shows(p))
                .cloned()
                .collect();
            if let Some(mut canvas) = crate::overlay::Canvas::from_rgb(w, h, &out, 1) {
                canvas.draw(&shown);
                out = canvas.rgb;
            }
        }
        Ok((w, h, out))
    }

    /// The colour of the preview highlight: the class being defined (magenta for
    /// unclassified, which erases), made light when the class colour is too dark to show
    /// ([`visible_preview_rgb`]).
    #[must_use]
    pub fn preview_colour(&self) -> Option<[u8; 3]> {
        self.selection.as_ref()?;
        Some(match self.selection_class() {
            // A coverage hint's colours before a class is chosen for them: neutral white.
            None => [235, 235, 235],
            Some(ColourClass::Unclassified) => [255, 0, 255],
            Some(c) => visible_preview_rgb(c.display_rgb()),
        })
    }

    /// How the selection preview shows each pixel of the shown frame, row by row: outside the
    /// selection, selected but already of the class (a commit leaves it), or selected and
    /// changed by a commit. Empty with no selection. The classification compared is the shown
    /// frame's, from whichever pipeline ran (robot or overhead).
    pub fn preview_pixels(&self) -> impl Iterator<Item = PreviewPixel> + '_ {
        // With no class chosen (a coverage hint) every selected pixel is previewed.
        let code = self.selection_class().map(ColourClass::code);
        let codes = self.shown_classified().codes();
        // A mask of another frame's size (none pending) previews nothing.
        let n = if codes.len() == self.preview_mask.len() {
            codes.len()
        } else {
            0
        };
        self.preview_mask
            .iter()
            .zip(codes)
            .take(n)
            .map(move |(&m, &c)| match (m, Some(c) == code) {
                (false, _) => PreviewPixel::Outside,
                (true, true) => PreviewPixel::Unchanged,
                (true, false) => PreviewPixel::Changes,
            })
    }
}

/// How the selection preview shows one pixel.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PreviewPixel {
    /// Not selected: dimmed, so that the selection stands out.
    Outside,
    /// Selected, but already of the class: a commit does not change it, so it is left as it
    /// is (neither dimmed nor hatched).
    Unchanged,
    /// Selected, and a commit changes its class: hatched.
    Changes,
}

/// The colour of a hatched preview pixel at (`x`, `y`): diagonal stripes two pixels wide of
/// the class colour `class_rgb` and of black or white, whichever contrasts with it. Hatched,
/// the pixels a commit would change can be told from pixels already shown in the class's
/// colour (a solid fill in the class colour cannot).
#[must_use]
pub fn hatch_rgb(x: usize, y: usize, class_rgb: [u8; 3]) -> [u8; 3] {
    if (x + y) % 4 < 2 {
        class_rgb
    } else if luma(class_rgb) > 128.0 {
        [0, 0, 0]
    } else {
        [255, 255, 255]
    }
}

/// Rec. 601 luma of an RGB colour, 0..255.
fn luma([r, g, b]: [u8; 3]) -> f32 {
    0.299 * f32::from(r) + 0.587 * f32::from(g) + 0.114 * f32::from(b)
}

/// Class colours darker than this (0..255 luma) are previewed in a light colour.
const PREVIEW_MIN_LUMA: f32 = 100.0;

/// The highlight colour of a previewed class: its own colour, or a light magenta for classes
/// too dark to show over dimmed pixels (black's near-black, dark blue).
#[must_use]
pub fn visible_preview_rgb(class_rgb: [u8; 3]) -> [u8; 3] {
    if luma(class_rgb) < PREVIEW_MIN_LUMA {
        [255, 96, 255]
    } else {
        class_rgb
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frame::{ImagePoint, PixelBox};

    fn boxed(owner: ObjectId) -> Primitive {
        Primitive::Box {
            owner,
            colour: 1,
            bounds: PixelBox::new(0, 0, 3, 3),
        }
    }

    fn label(owner: ObjectId) -> Primitive {
        Primitive::Label {
            owner,
            at: ImagePoint::new(1.0, 1.0),
            text: "x".to_owned(),
        }
    }

    #[test]
    fn the_objects_view_draws_the_accepted_objects_and_the_horizon_only() {
        let accepted = [ObjectId::Ball(1), ObjectId::Goal(ColourClass::Yellow, 0)];
        let f = PrimitiveFilter::objects(Overlays::all_on(), &accepted);
        assert!(f.shows(&boxed(ObjectId::Ball(1))));
        assert!(f.shows(&boxed(ObjectId::Goal(ColourClass::Yellow, 0))));
        assert!(!f.shows(&boxed(ObjectId::Ball(0))), "a rejected ball");
        assert!(!f.shows(&boxed(ObjectId::Goal(ColourClass::SkyBlue, 0))));
        let horizon = Primitive::Line {
            owner: ObjectId::Horizon,
            role: LineRole::Horizon,
            from: ImagePoint::new(0.0, 5.0),
            to: ImagePoint::new(10.0, 5.0),
        };
        assert!(f.shows(&horizon));
        assert!(PrimitiveFilter::all(Overlays::all_on()).shows(&boxed(ObjectId::Ball(0))));
    }

    #[test]
    fn a_patterns_label_follows_the_patterns_switch_and_other_labels_do_not() {
        let mut o = Overlays::all_on();
        o.patterns = false;
        let f = PrimitiveFilter::all(o);
        assert!(!f.shows(&label(ObjectId::Pattern(0))));
        assert!(f.shows(&label(ObjectId::Ball(0))));
        o.patterns = true;
        assert!(PrimitiveFilter::all(o).shows(&label(ObjectId::Pattern(0))));
    }
}
