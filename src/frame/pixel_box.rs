//! [`PixelBox`]: an inclusive box of whole pixels, the bounds of a blob or an object; [`CutOff`]:
//! which sides of an object's outline are not seen.

use serde::{Deserialize, Serialize};

/// An inclusive box of whole pixels: columns `min_x..=max_x`, rows `min_y..=max_y`. Written to
/// JSON as `[min_x, min_y, max_x, max_y]`, the form the boxes had before they had a type.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
#[serde(from = "[u32; 4]", into = "[u32; 4]")]
pub struct PixelBox {
    /// Leftmost column, pixels.
    pub min_x: u32,
    /// Top row, pixels.
    pub min_y: u32,
    /// Rightmost column, pixels (inclusive).
    pub max_x: u32,
    /// Bottom row, pixels (inclusive).
    pub max_y: u32,
}

impl PixelBox {
    /// The box from its leftmost and rightmost columns and top and bottom rows, inclusive.
    #[must_use]
    pub const fn new(min_x: u32, min_y: u32, max_x: u32, max_y: u32) -> Self {
        Self {
            min_x,
            min_y,
            max_x,
            max_y,
        }
    }

    /// `[min_x, min_y, max_x, max_y]`.
    #[must_use]
    pub const fn to_array(self) -> [u32; 4] {
        [self.min_x, self.min_y, self.max_x, self.max_y]
    }

    /// Columns covered, pixels (0 for a box whose right edge is left of its left edge).
    #[must_use]
    pub const fn width_px(&self) -> u32 {
        (self.max_x + 1).saturating_sub(self.min_x)
    }

    /// Rows covered, pixels (0 for a box upside down).
    #[must_use]
    pub const fn height_px(&self) -> u32 {
        (self.max_y + 1).saturating_sub(self.min_y)
    }

    /// Pixels covered.
    #[must_use]
    pub fn area_px(&self) -> f64 {
        f64::from(self.width_px()) * f64::from(self.height_px())
    }

    /// Whether this box lies wholly within `outer` (its edges may touch `outer`'s).
    #[must_use]
    pub const fn is_within(&self, outer: &Self) -> bool {
        self.min_x >= outer.min_x
            && self.min_y >= outer.min_y
            && self.max_x <= outer.max_x
            && self.max_y <= outer.max_y
    }

    /// The share of this box that `other` covers, 0..=1 (0 for an empty box).
    #[must_use]
    pub fn overlap_fraction(&self, other: &Self) -> f64 {
        let w = (self.max_x.min(other.max_x) + 1).saturating_sub(self.min_x.max(other.min_x));
        let h = (self.max_y.min(other.max_y) + 1).saturating_sub(self.min_y.max(other.min_y));
        let area = self.area_px();
        if area > 0.0 {
            f64::from(w) * f64::from(h) / area
        } else {
            0.0
        }
    }

    /// Whether at most `gap_px` columns and rows of pixels lie between the two boxes (0: they
    /// touch or overlap).
    #[must_use]
    pub const fn is_near(&self, other: &Self, gap_px: u32) -> bool {
        self.min_x <= other.max_x + gap_px + 1
            && other.min_x <= self.max_x + gap_px + 1
            && self.min_y <= other.max_y + gap_px + 1
            && other.min_y <= self.max_y + gap_px + 1
    }
}

impl From<[u32; 4]> for PixelBox {
    fn from([min_x, min_y, max_x, max_y]: [u32; 4]) -> Self {
        Self::new(min_x, min_y, max_x, max_y)
    }
}

impl From<PixelBox> for [u32; 4] {
    fn from(b: PixelBox) -> Self {
        b.to_array()
    }
}

/// Which sides of an object's outline are not seen: cut off by the image border (the ground
/// truth's only reason) or, in recognition, hidden by something in front. JSON: an object of four
/// booleans.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub struct CutOff {
    /// Left side not visible.
    pub left: bool,
    /// Right side not visible.
    pub right: bool,
    /// Top not visible.
    pub top: bool,
    /// Bottom not visible.
    pub bottom: bool,
}

impl CutOff {
    /// True when any side is cut off.
    #[must_use]
    pub fn any(&self) -> bool {
        self.left || self.right || self.top || self.bottom
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_box_counts_its_edge_pixels() {
        let b = PixelBox::new(2, 3, 5, 3);
        assert_eq!((b.width_px(), b.height_px()), (4, 1));
        assert_eq!(b.area_px(), 4.0);
        assert_eq!(PixelBox::new(5, 0, 2, 0).width_px(), 0);
    }

    #[test]
    fn a_box_is_within_another_when_its_edges_are_inside_or_on_them() {
        let outer = PixelBox::new(10, 10, 20, 20);
        assert!(PixelBox::new(10, 12, 20, 15).is_within(&outer));
        assert!(outer.is_within(&outer));
        assert!(!PixelBox::new(9, 12, 15, 15).is_within(&outer));
        assert!(!PixelBox::new(12, 12, 15, 21).is_within(&outer));
    }

    #[test]
    fn overlap_is_the_share_of_the_first_box_the_second_covers() {
        let a = PixelBox::new(0, 0, 9, 9);
        assert_eq!(a.overlap_fraction(&PixelBox::new(5, 0, 30, 9)), 0.5);
        assert_eq!(a.overlap_fraction(&PixelBox::new(5, 5, 30, 30)), 0.25);
        assert_eq!(a.overlap_fraction(&PixelBox::new(10, 0, 30, 9)), 0.0);
        assert_eq!(
            PixelBox::new(5, 5, 30, 30).overlap_fraction(&a),
            25.0 / 676.0
        );
        assert_eq!(PixelBox::new(5, 0, 2, 0).overlap_fraction(&a), 0.0);
    }

    #[test]
    fn boxes_are_near_when_at_most_the_gap_lies_between_them() {
        let a = PixelBox::new(0, 0, 4, 4);
        assert!(a.is_near(&PixelBox::new(5, 0, 9, 4), 0), "touching");
        assert!(
            !a.is_near(&PixelBox::new(6, 0, 9, 4), 0),
            "one column between"
        );
        assert!(a.is_near(&PixelBox::new(6, 0, 9, 4), 1));
        assert!(a.is_near(&PixelBox::new(7, 7, 9, 9), 2), "diagonal");
        assert!(!a.is_near(&PixelBox::new(7, 8, 9, 9), 2));
        assert_eq!(
            a.is_near(&PixelBox::new(7, 8, 9, 9), 3),
            PixelBox::new(7, 8, 9, 9).is_near(&a, 3),
            "symmetric"
        );
    }

    #[test]
    fn json_keeps_the_four_number_form() {
        let b = PixelBox::new(1, 2, 3, 4);
        assert_eq!(serde_json::to_string(&b).unwrap(), "[1,2,3,4]");
        assert_eq!(serde_json::from_str::<PixelBox>("[1,2,3,4]").unwrap(), b);
        assert_eq!(PixelBox::from([1, 2, 3, 4]), b);
        assert_eq!(<[u32; 4]>::from(b), [1, 2, 3, 4]);
    }
}
