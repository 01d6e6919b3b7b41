//! The colour classes of `FORMATS.md`: codes, names, display colours, and what each *soft*
//! colour may really be.
//!
//! Soft colours mark table cells that the person classifying could not decide on (the shadowed
//! side of a yellow goal looks both yellow and green). Recognition treats them as "maybe one of
//! these basic colours", which is what [`ColourClass::may_be`] answers.

use serde::{Deserialize, Serialize};

/// A colour class; its `u8` value is the code stored in lookup tables.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[repr(u8)]
pub enum ColourClass {
    /// No class; forms no blobs.
    Unclassified = 0,
    /// The ball.
    Orange = 1,
    /// Blue goal, beacons.
    SkyBlue = 2,
    /// Yellow goal, beacons.
    Yellow = 3,
    /// Beacons, coloured landmarks.
    Pink = 4,
    /// Field carpet.
    Green = 5,
    /// Lines, robots, walls.
    White = 6,
    /// Team uniform.
    Red = 7,
    /// Team uniform.
    DarkBlue = 8,
    /// Robot parts, shadows, markers.
    Black = 9,
    /// Soft: yellow or orange.
    YellowOrange = 10,
    /// Soft: red or orange.
    RedOrange = 11,
    /// Soft: pink or orange.
    PinkOrange = 12,
    /// Soft: sky blue or dark blue.
    ShadowBlue = 13,
    /// Soft: yellow or green (goal sides in shadow).
    ShadowYellow = 14,
}

/// Whether a class is a decided colour or an undecided (soft) one.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum ClassKind {
    /// Code 0.
    Unclassified,
    /// A decided colour (codes 1..=9).
    Basic,
    /// "May be one of these" (codes 10..=14).
    Soft,
}

/// Number of defined class codes (0..=14).
pub const CLASS_COUNT: usize = 15;

impl ColourClass {
    /// All classes in code order.
    pub const ALL: [Self; CLASS_COUNT] = [
        Self::Unclassified,
        Self::Orange,
        Self::SkyBlue,
        Self::Yellow,
        Self::Pink,
        Self::Green,
        Self::White,
        Self::Red,
        Self::DarkBlue,
        Self::Black,
        Self::YellowOrange,
        Self::RedOrange,
        Self::PinkOrange,
        Self::ShadowBlue,
        Self::ShadowYellow,
    ];

    /// The class of a table code, or `None` for an undefined code.
    ///
    /// ```
    /// use eotn::lut::ColourClass;
    /// assert_eq!(ColourClass::from_code(1), Some(ColourClass::Orange));
    /// assert_eq!(ColourClass::from_code(15), None);
    /// ```
    #[must_use]
    pub fn from_code(code: u8) -> Option<Self> {
        Self::ALL.get(usize::from(code)).copied()
    }

    /// The code stored in tables.
    #[must_use]
    pub const fn code(self) -> u8 {
        self as u8
    }

    /// The class's name as users see it ("sky blue").
    #[must_use]
    pub const fn name(self) -> &'static str {
        match self {
            Self::Unclassified => "unclassified",
            Self::Orange => "orange",
            Self::SkyBlue => "sky blue",
            Self::Yellow => "yellow",
            Self::Pink => "pink",
            Self::Green => "green",
            Self::White => "white",
            Self::Red => "red",
            Self::DarkBlue => "dark blue",
            Self::Black => "black",
            Self::YellowOrange => "yellow-orange",
            Self::RedOrange => "red-orange",
            Self::PinkOrange => "pink-orange",
            Self::ShadowBlue => "shadow blue",
            Self::ShadowYellow => "shadow yellow",
        }
    }

    /// Looks a class up by name, ignoring case, spaces, dashes and underscores
    /// (`"sky-blue"`, `"SkyBlue"` and `"sky blue"` all work), or by its code as text.
    #[must_use]
    pub fn parse(text: &str) -> Option<Self> {
        if let Ok(code) = text.trim().parse::<u8>() {
            return Self::from_code(code);
        }
        let key = |s: &str| {
            s.chars()
                .filter(char::is_ascii_alphanumeric)
                .map(|c| c.to_ascii_lowercase())
                .collect::<String>()
        };
        let want = key(text);
        Self::ALL.into_iter().find(|c| key(c.name()) == want)
    }

    /// Basic, soft, or unclassified.
    #[must_use]
    pub const fn kind(self) -> ClassKind {
        match self as u8 {
            0 => ClassKind::Unclassified,
            1..=9 => ClassKind::Basic,
            _ => ClassKind::Soft,
        }
    }

    /// The display colour (sRGB) used for classified images and overlays.
    #[must_use]
    pub const fn display_rgb(self) -> [u8; 3] {
        match self {
            Self::Unclassified => [0, 0, 0],
            Self::Orange => [255, 128, 0],
            Self::SkyBlue => [60, 170, 255],
            Self::Yellow => [255, 235, 0],
            Self::Pink => [255, 105, 190],
            Self::Green => [30, 150, 40],
            Self::White => [250, 250, 250],
            Self::Red => [220, 20, 30],
            Self::DarkBlue => [20, 30, 150],
            Self::Black => [70, 70, 70],
            Self::YellowOrange => [255, 190, 60],
            Self::RedOrange => [240, 80, 40],
            Self::PinkOrange => [255, 150, 130],
            Self::ShadowBlue => [60, 100, 200],
            Self::ShadowYellow => [170, 190, 40],
        }
    }

    /// The basic classes this class may really be: itself for a basic class, the two candidates
    /// for a soft class, none for unclassified.
    #[must_use]
    pub const fn may_be(self) -> &'static [Self] {
        match self {
            Self::Unclassified => &[],
            Self::Orange => &[Self::Orange],
            Self::SkyBlue => &[Self::SkyBlue],
            Self::Yellow => &[Self::Yellow],
            Self::Pink => &[Self::Pink],
            Self::Green => &[Self::Green],
            Self::White => &[Self::White],
            Self::Red => &[Self::Red],
            Self::DarkBlue => &[Self::DarkBlue],
            Self::Black => &[Self::Black],
            Self::YellowOrange => &[Self::Yellow, Self::Orange],
            Self::RedOrange => &[Self::Red, Self::Orange],
            Self::PinkOrange => &[Self::Pink, Self::Orange],
            Self::ShadowBlue => &[Self::SkyBlue, Self::DarkBlue],
            Self::ShadowYellow => &[Self::Yellow, Self::Green],
        }
    }

    /// True when this class is `basic` or a soft class that may be `basic`.
    #[must_use]
    pub fn may_be_class(self, basic: Self) -> bool {
        self.may_be().contains(&basic)
    }

    /// The soft classes that may be `basic` (for orange: yellow-orange, red-orange, pink-orange).
    pub fn soft_classes_of(basic: Self) -> impl Iterator<Item = Self> {
        Self::ALL
            .into_iter()
            .filter(move |c| c.kind() == ClassKind::Soft && c.may_be_class(basic))
    }
}

impl std::fmt::Display for ColourClass {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// Display colour of a raw class code; reserved codes show magenta so they stand out.
#[must_use]
pub fn code_display_rgb(code: u8) -> [u8; 3] {
    ColourClass::from_code(code).map_or([255, 0, 255], ColourClass::display_rgb)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn codes_round_trip_and_match_formats_md() {
        for (i, c) in ColourClass::ALL.iter().enumerate() {
            assert_eq!(usize::from(c.code()), i);
            assert_eq!(ColourClass::from_code(c.code()), Some(*c));
        }
        assert_eq!(ColourClass::Green.code(), 5);
        assert_eq!(ColourClass::ShadowYellow.code(), 14);
        assert_eq!(ColourClass::from_code(200), None);
    }

    #[test]
    fn soft_colours_name_their_basic_colours() {
        assert_eq!(ColourClass::Orange.kind(), ClassKind::Basic);
        assert_eq!(ColourClass::PinkOrange.kind(), ClassKind::Soft);
        let soft_orange: Vec<_> = ColourClass::soft_classes_of(ColourClass::Orange).collect();
        assert_eq!(
            soft_orange,
            [
                ColourClass::YellowOrange,
                ColourClass::RedOrange,
                ColourClass::PinkOrange
            ]
        );
        assert!(ColourClass::ShadowYellow.may_be_class(ColourClass::Green));
        assert!(!ColourClass::ShadowYellow.may_be_class(ColourClass::Orange));
        assert!(ColourClass::Unclassified.may_be().is_empty());
    }

    #[test]
    fn names_parse_loosely() {
        assert_eq!(ColourClass::parse("sky-blue"), Some(ColourClass::SkyBlue));
        assert_eq!(ColourClass::parse("SkyBlue"), Some(ColourClass::SkyBlue));
        assert_eq!(ColourClass::parse("7"), Some(ColourClass::Red));
        assert_eq!(ColourClass::parse("purple"), None);
    }
}
