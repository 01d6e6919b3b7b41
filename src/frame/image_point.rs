//! [`ImagePoint`]: the one type of a position in an image, in pixels, used by blobs, the
//! cameras, recognition's scans and fits, the overlays and the evaluation; and [`xy_array`], the
//! serde adapter that writes it as an `[x, y]` array where recognition's JSON always had that
//! form.

use std::ops::{Add, Sub};

use serde::{Deserialize, Serialize};

/// A position in an image, pixels, `FORMATS.md` convention (x right, y down, pixel centres at
/// i + 0.5). Also a displacement between two such positions (`a - b`, pixels), and a position
/// in a frame turned about an image point (recognition's *level* frame, [`Self::rotated_about`]),
/// still in pixels.
///
/// Written to JSON as `{"x_px": …, "y_px": …}`; fields that have always been `[x, y]` arrays
/// (recognition's scan points, posts, circles) keep that with [`xy_array`].
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct ImagePoint {
    /// Column, pixels from the left edge.
    pub x_px: f64,
    /// Row, pixels from the top edge.
    pub y_px: f64,
}

impl ImagePoint {
    /// A point from its column and row, pixels.
    #[must_use]
    pub const fn new(x_px: f64, y_px: f64) -> Self {
        Self { x_px, y_px }
    }

    /// The centre of pixel (i, j): (i + 0.5, j + 0.5).
    #[must_use]
    pub fn pixel_centre(i: usize, j: usize) -> Self {
        Self::new(i as f64 + 0.5, j as f64 + 0.5)
    }

    /// Euclidean distance to another image point, pixels.
    #[must_use]
    pub fn distance_to(&self, other: &Self) -> f64 {
        (self.x_px - other.x_px).hypot(self.y_px - other.y_px)
    }

    /// The point halfway to `other`.
    #[must_use]
    pub fn midpoint(self, other: Self) -> Self {
        Self::new(
            (self.x_px + other.x_px) / 2.0,
            (self.y_px + other.y_px) / 2.0,
        )
    }

    /// This point rotated about `centre` by `angle_rad` (counter-clockwise on screen for a
    /// positive angle in x-right, y-up terms; with y down it appears clockwise). Recognition
    /// turns image points by the horizon's angle about the image centre to work "parallel to
    /// the horizon", and turns results back by the negative angle.
    ///
    /// ```
    /// use eotn::frame::ImagePoint;
    /// let p = ImagePoint::new(11.0, 5.0).rotated_about(ImagePoint::new(10.0, 5.0), std::f64::consts::FRAC_PI_2);
    /// assert!((p.x_px - 10.0).abs() < 1e-12 && (p.y_px - 6.0).abs() < 1e-12);
    /// ```
    #[must_use]
    pub fn rotated_about(self, centre: Self, angle_rad: f64) -> Self {
        self.rotated_by(centre, angle_rad.sin_cos())
    }

    /// [`rotated_about`](Self::rotated_about) with the angle's `(sine, cosine)` taken once by
    /// the caller: loops that rotate every pixel of a scan by one angle spent more time in
    /// `sin_cos` than in reading pixels. The same arithmetic, so the same result to the bit.
    #[must_use]
    #[inline]
    pub fn rotated_by(self, centre: Self, (s, c): (f64, f64)) -> Self {
        let (dx, dy) = (self.x_px - centre.x_px, self.y_px - centre.y_px);
        Self::new(centre.x_px + c * dx - s * dy, centre.y_px + s * dx + c * dy)
    }

    /// Whether both coordinates are finite.
    #[must_use]
    pub fn is_finite(&self) -> bool {
        self.x_px.is_finite() && self.y_px.is_finite()
    }
}

impl Add for ImagePoint {
    type Output = Self;

    /// Moves a point by a displacement, pixels.
    fn add(self, other: Self) -> Self {
        Self::new(self.x_px + other.x_px, self.y_px + other.y_px)
    }
}

impl Sub for ImagePoint {
    type Output = Self;

    /// The displacement from `other` to this point, pixels.
    fn sub(self, other: Self) -> Self {
        Self::new(self.x_px - other.x_px, self.y_px - other.y_px)
    }
}

/// Serde adapter writing image points as `[x, y]` arrays of pixels, the form recognition's
/// results (posts, gaps, scan points, circles, drawing primitives) had before they shared
/// [`ImagePoint`]: `#[serde(with = "crate::frame::xy_array")]` on a field of an
/// `ImagePoint`, or of `Vec`s, `[_; 4]`, `Option`s and pairs of them.
pub mod xy_array {
    use serde::de::DeserializeOwned;
    use serde::{Deserialize, Deserializer, Serialize, Serializer};

    use super::ImagePoint;

    /// A value with image points inside, and its form with each point as an `(x, y)` pair.
    pub trait XyForm: Sized {
        /// The same shape with `(f64, f64)` in place of each [`ImagePoint`].
        type Form: Serialize + DeserializeOwned;
        /// The pair form.
        fn to_form(&self) -> Self::Form;
        /// Back from the pair form.
        fn from_form(form: Self::Form) -> Self;
    }

    impl XyForm for ImagePoint {
        type Form = (f64, f64);
        fn to_form(&self) -> Self::Form {
            (self.x_px, self.y_px)
        }
        fn from_form((x_px, y_px): Self::Form) -> Self {
            Self::new(x_px, y_px)
        }
    }

    impl<T: XyForm> XyForm for Vec<T> {
        type Form = Vec<T::Form>;
        fn to_form(&self) -> Self::Form {
            self.iter().map(XyForm::to_form).collect()
        }
        fn from_form(form: Self::Form) -> Self {
            form.into_iter().map(T::from_form).collect()
        }
    }

    impl<T: XyForm> XyForm for [T; 4] {
        type Form = [T::Form; 4];
        fn to_form(&self) -> Self::Form {
            [
                self[0].to_form(),
                self[1].to_form(),
                self[2].to_form(),
                self[3].to_form(),
            ]
        }
        fn from_form(form: Self::Form) -> Self {
            form.map(T::from_form)
        }
    }

    impl<T: XyForm> XyForm for Option<T> {
        type Form = Option<T::Form>;
        fn to_form(&self) -> Self::Form {
            self.as_ref().map(XyForm::to_form)
        }
        fn from_form(form: Self::Form) -> Self {
            form.map(T::from_form)
        }
    }

    impl<A: XyForm, B: XyForm> XyForm for (A, B) {
        type Form = (A::Form, B::Form);
        fn to_form(&self) -> Self::Form {
            (self.0.to_form(), self.1.to_form())
        }
        fn from_form((a, b): Self::Form) -> Self {
            (A::from_form(a), B::from_form(b))
        }
    }

    /// Writes `value` with its points as `[x, y]` arrays.
    ///
    /// # Errors
    /// Whatever the serializer reports.
    pub fn serialize<T: XyForm, S: Serializer>(
        value: &T,
        serializer: S,
    ) -> Result<S::Ok, S::Error> {
        value.to_form().serialize(serializer)
    }

    /// Reads a value whose points are `[x, y]` arrays.
    ///
    /// # Errors
    /// Input that is not that shape.
    pub fn deserialize<'de, T: XyForm, D: Deserializer<'de>>(
        deserializer: D,
    ) -> Result<T, D::Error> {
        T::Form::deserialize(deserializer).map(T::from_form)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rotating_there_and_back_returns_the_point() {
        let centre = ImagePoint::new(10.0, 5.0);
        let p = ImagePoint::new(11.0, 5.0).rotated_about(centre, std::f64::consts::FRAC_PI_2);
        assert!((p.x_px - 10.0).abs() < 1e-12 && (p.y_px - 6.0).abs() < 1e-12);
        let back = p.rotated_about(centre, -std::f64::consts::FRAC_PI_2);
        assert!(back.distance_to(&ImagePoint::new(11.0, 5.0)) < 1e-12);
    }

    #[test]
    fn differences_and_midpoints_work_per_coordinate() {
        let (a, b) = (ImagePoint::new(1.0, 2.0), ImagePoint::new(4.0, 6.0));
        assert_eq!(b - a, ImagePoint::new(3.0, 4.0));
        assert_eq!(a + (b - a), b);
        assert_eq!(a.midpoint(b), ImagePoint::new(2.5, 4.0));
        assert_eq!(a.distance_to(&b), 5.0);
        assert!(!ImagePoint::new(f64::NAN, 0.0).is_finite() && a.is_finite());
    }

    #[derive(Debug, PartialEq, Serialize, Deserialize)]
    struct Shapes {
        plain: ImagePoint,
        #[serde(with = "xy_array")]
        one: ImagePoint,
        #[serde(with = "xy_array")]
        many: Vec<ImagePoint>,
        #[serde(with = "xy_array")]
        corners: [ImagePoint; 4],
        #[serde(with = "xy_array")]
        segment: Option<(ImagePoint, ImagePoint)>,
    }

    /// [`Shapes`] as it was written before the adapter: points as tuples.
    #[derive(Serialize)]
    struct Tuples {
        plain: ImagePoint,
        one: (f64, f64),
        many: Vec<(f64, f64)>,
        corners: [(f64, f64); 4],
        segment: Option<((f64, f64), (f64, f64))>,
    }

    #[test]
    fn the_adapter_writes_the_array_form_and_reads_it_back() {
        let p = |x: f64, y: f64| ImagePoint::new(x, y);
        let shapes = Shapes {
            plain: p(1.0, 2.5),
            one: p(1.0, 2.5),
            many: vec![p(0.0, 1.0), p(2.0, 3.0)],
            corners: [p(0.0, 0.0), p(1.0, 0.0), p(1.0, 1.0), p(0.0, 1.0)],
            segment: Some((p(3.0, 4.0), p(5.0, 6.0))),
        };
        let json = serde_json::to_string(&shapes).expect("json");
        // Byte for byte what the `(f64, f64)` tuples used to write.
        let tuples = Tuples {
            plain: p(1.0, 2.5),
            one: (1.0, 2.5),
            many: vec![(0.0, 1.0), (2.0, 3.0)],
            corners: [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)],
            segment: Some(((3.0, 4.0), (5.0, 6.0))),
        };
        assert_eq!(json, serde_json::to_string(&tuples).expect("json"));
        assert_eq!(serde_json::from_str::<Shapes>(&json).expect("back"), shapes);
        let none = json.replace(r#""segment":[[3.0,4.0],[5.0,6.0]]"#, r#""segment":null"#);
        assert_eq!(
            serde_json::from_str::<Shapes>(&none).expect("null").segment,
            None
        );
    }
}
