//! The printable marker: an SVG drawing at real size (millimetres), made from the same layout
//! numbers the renderer paints and the recogniser reads (`geometry::marker`).
//!
//! `eotn overhead marker --team blue --id 5 -o marker.svg` writes one; printed at 100% it is a
//! 30 cm plate. The drawing's "up" is the robot's forward, with a small arrow and a caption
//! under the plate saying so, its team and identity.

use crate::geometry::marker::{
    ID_DOT_DIAMETER_CM, PLATE_DIAMETER_CM, TEAM_DOT_DIAMETER_CM, id_dot_offsets_cm,
};
use crate::geometry::{MarkerIdentity, MarkerTeam};
use crate::lut::ColourClass;
use crate::model::scene::Material;

/// The SVG fill of a class as the simulator paints it (sRGB hex).
fn fill(class: ColourClass) -> String {
    let material = match class {
        ColourClass::SkyBlue => Material::SkyBlue,
        ColourClass::Yellow => Material::Yellow,
        ColourClass::Pink => Material::Pink,
        ColourClass::Green => Material::Carpet,
        _ => Material::RobotBlack,
    };
    let [r, g, b] = material.rgb();
    format!("#{r:02x}{g:02x}{b:02x}")
}

/// The marker of a team and identity as an SVG document, sizes in millimetres.
#[must_use]
pub fn marker_svg(team: MarkerTeam, identity: MarkerIdentity) -> String {
    let mm = |cm: f64| cm * 10.0;
    let plate_r = mm(PLATE_DIAMETER_CM / 2.0);
    let margin = 10.0;
    let caption = 14.0;
    let side = 2.0 * (plate_r + margin);
    let c = plate_r + margin;
    let mut svg = format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{side}mm\" height=\"{h}mm\" \
         viewBox=\"0 0 {side} {h}\">\n\
         <title>eotn overhead robot marker: team {team}, identity {identity}</title>\n\
         <rect width=\"{side}\" height=\"{h}\" fill=\"#ffffff\"/>\n\
         <circle cx=\"{c}\" cy=\"{c}\" r=\"{plate_r}\" fill=\"{black}\"/>\n\
         <circle cx=\"{c}\" cy=\"{c}\" r=\"{team_r}\" fill=\"{team_fill}\"/>\n",
        h = side + caption,
        team = team.name(),
        black = fill(ColourClass::Black),
        team_r = mm(TEAM_DOT_DIAMETER_CM / 2.0),
        team_fill = fill(team.class()),
    );
    let bits = identity.bits();
    for (k, [forward, left]) in id_dot_offsets_cm().into_iter().enumerate() {
        // Seen from above with forward up: left is towards −x of the drawing.
        let (x, y) = (c - mm(left), c - mm(forward));
        let class = if bits[k] {
            ColourClass::Pink
        } else {
            ColourClass::Green
        };
        svg.push_str(&format!(
            "<circle cx=\"{x:.3}\" cy=\"{y:.3}\" r=\"{r}\" fill=\"{f}\"/>\n",
            r = mm(ID_DOT_DIAMETER_CM / 2.0),
            f = fill(class),
        ));
    }
    // Forward arrow on the plate's rim (black on white, outside the dots).
    let tip = c - plate_r - 2.0;
    svg.push_str(&format!(
        "<path d=\"M {c} {tip} l -6 8 h 12 z\" fill=\"#000000\"/>\n\
         <text x=\"{c}\" y=\"{ty}\" font-family=\"sans-serif\" font-size=\"7\" \
         text-anchor=\"middle\">team {team}, id {identity} (bits {b0}{b1}{b2}{b3}): forward is \
         up; print at 100% (plate 300 mm)</text>\n</svg>\n",
        ty = side + caption - 4.0,
        team = team.name(),
        b0 = u8::from(bits[0]),
        b1 = u8::from(bits[1]),
        b2 = u8::from(bits[2]),
        b3 = u8::from(bits[3]),
    ));
    svg
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_drawing_is_real_size_with_the_layout_dots() {
        let id = MarkerIdentity::new(0b0001).expect("in range");
        let svg = marker_svg(MarkerTeam::Blue, id);
        assert!(svg.contains("width=\"320mm\""), "{svg}");
        assert_eq!(svg.matches("<circle").count(), 6);
        // Bit 0 (pink) is front left: above and left of the centre (160, 160).
        let pink = fill(ColourClass::Pink);
        let line = svg
            .lines()
            .find(|l| l.contains(&pink))
            .expect("one pink dot");
        let x: f64 = line
            .split("cx=\"")
            .nth(1)
            .and_then(|s| s.split('"').next())
            .and_then(|s| s.parse().ok())
            .expect("cx");
        let y: f64 = line
            .split("cy=\"")
            .nth(1)
            .and_then(|s| s.split('"').next())
            .and_then(|s| s.parse().ok())
            .expect("cy");
        assert!(x < 160.0 && y < 160.0, "{line}");
        assert!(((x - 160.0).hypot(y - 160.0) - 100.0).abs() < 1e-2);
        assert_eq!(svg.matches(&pink).count(), 1);
    }
}
