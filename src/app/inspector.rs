//! The object inspector: every recognition candidate of the shown frame, accepted or rejected,
//! in a list; the selected one's confidence breakdown (test, measured value, range, effect,
//! outcome), why it was accepted or rejected, where it is (distance, bearing, elevation) and its
//! flags. Selecting a candidate highlights its overlays in every view and dims the others.
//!
//! [`candidates`] turns a [`Recognition`] into plain rows (tested without a window);
//! [`inspector_ui`] draws them (docked beside the image, `dock.rs`).

use egui::{Color32, RichText, Ui};

use crate::frame::PixelBox;
use crate::lut::ColourClass;
use crate::recognition::confidence::{Confidence, TestOutcome};
use crate::recognition::patterns::PatternMemory;
use crate::recognition::scan::CutOff;
use crate::recognition::{ObjectId, Recognition, Relative};
use crate::workspace::{Command, Workspace};

/// One candidate as the inspector lists it.
#[derive(Debug, Clone, PartialEq)]
pub struct CandidateInfo {
    /// The object its primitives belong to (shown as `ball#0`, `goal:yellow#1`, `beacon#0`).
    pub owner: ObjectId,
    /// What it would be: `"ball"`, `"yellow goal"`, `"beacon pink over yellow"`.
    pub kind: String,
    /// Accepted as an object.
    pub accepted: bool,
    /// The confidence with every test.
    pub confidence: Confidence,
    /// Why it was accepted or rejected, in words.
    pub reason: String,
    /// Camera-relative distance (cm), bearing and elevation (radians).
    pub camera: Relative,
    /// Body-relative placement, when the joints were known.
    pub body: Option<Relative>,
    /// The distance is only an upper bound (the object is cut off at top or bottom).
    pub distance_is_max: bool,
    /// Sides not seen, each with why: `left (image edge)`, `top (hidden)` (robot colours
    /// against it), …
    pub cut_sides: Vec<&'static str>,
    /// Further evidence: circle fit refused, posts without a line, pixel counts.
    pub notes: Vec<String>,
    /// For a pink marker: its nine regions and how they compare with the closest place.
    pub pattern: Option<PatternInfo>,
}

/// A pink marker's coloured pattern as the inspector shows it.
#[derive(Debug, Clone, PartialEq)]
pub struct PatternInfo {
    /// Each region's two most common class codes, row by row (0: nothing).
    pub regions: [[u8; 2]; 9],
    /// Whether each region's most common colour agrees with the closest place's best pattern
    /// (`None` without a places file or a place).
    pub agrees: Option<[bool; 9]>,
    /// The closest place and how many regions agree with it.
    pub closest: Option<(usize, usize)>,
    /// The next closest place and its agreement.
    pub runner_up: Option<(usize, usize)>,
    /// The place it was identified as.
    pub identified: Option<usize>,
    /// The pink blob's size, pixels.
    pub size_px: f64,
    /// A places file was open.
    pub with_places: bool,
}

impl PatternInfo {
    /// One region as text: `yellow / white`, `nothing`.
    #[must_use]
    pub fn region_text(&self, k: usize) -> String {
        let name = |c: u8| ColourClass::from_code(c).map_or("?", ColourClass::name);
        match self.regions.get(k) {
            Some([0, _]) | None => "nothing".to_owned(),
            Some([a, 0]) => name(*a).to_owned(),
            Some([a, b]) => format!("{} / {}", name(*a), name(*b)),
        }
    }
}

/// The inspector's rows for the pink markers of `r` (`places`: the open places file).
fn pattern_candidates(r: &Recognition, places: Option<&PatternMemory>) -> Vec<CandidateInfo> {
    r.patterns
        .iter()
        .enumerate()
        .map(|(i, c)| {
            let obs = &c.observation;
            let agrees = c.closest.and_then(|best| {
                let object = places?.object(best.id)?;
                let pattern = object.patterns.iter().max_by_key(|p| {
                    (
                        p.agreement(&obs.signature),
                        p.both_colours_agreement(&obs.signature),
                    )
                })?;
                Some(std::array::from_fn(|k| {
                    pattern.0[k][0] == obs.signature.0[k][0]
                }))
            });
            let kind = match (&c.identification, &c.closest) {
                (Some(m), _) => format!("pink marker: place {}", m.id),
                (None, _) if places.is_none() => "pink marker (no places file)".to_owned(),
                (None, _) if c.ambiguous => "pink marker: ambiguous".to_owned(),
                (None, _) => "pink marker: unknown place".to_owned(),
            };
            let mut notes = vec![format!(
                "{} pixels, size {:.1} px; {} of 9 regions in the image",
                obs.pixels, obs.size_px, obs.regions_in_image
            )];
            if let Some(b) = c.closest {
                notes.push(format!(
                    "closest place {}: {}/9 regions agree ({} with both colours)",
                    b.id, b.agreement, b.both_colours
                ));
            }
            if let Some(n) = c.runner_up {
                notes.push(format!("next place {}: {}/9", n.id, n.agreement));
            }
            if let Some(o) = c.identification.and_then(|m| places?.object(m.id)) {
                notes.push(format!(
                    "place {} is at ({:.0}, {:.0}) cm on the field, learnt from {} views",
                    o.id, o.field_cm[0], o.field_cm[1], o.views
                ));
            }
            let reason = match (places, &c.identification) {
                (None, _) => {
                    "not identified: no places file open (Classification > Open places…)".to_owned()
                }
                (Some(_), Some(m)) => format!(
                    "accepted: place {}, {}/9 regions agree; confidence {:+.2}",
                    m.id, m.agreement, c.confidence.total
                ),
                (Some(_), None) => reason(&c.confidence, false),
            };
            let (bearing, elevation) = (obs.bearing_rad, obs.elevation_rad);
            CandidateInfo {
                owner: ObjectId::Pattern(i),
                kind,
                accepted: c.accepted,
                confidence: c.confidence.clone(),
                reason,
                camera: c.camera.unwrap_or(Relative {
                    distance_cm: f64::NAN,
                    bearing_rad: bearing,
                    elevation_rad: elevation,
                }),
                body: c.body,
                distance_is_max: false,
                cut_sides: if c.cut_off {
                    vec!["regions outside the image"]
                } else {
                    vec![]
                },
                notes,
                pattern: Some(PatternInfo {
                    regions: obs.signature.0,
                    agrees,
                    closest: c.closest.map(|b| (b.id, b.agreement)),
                    runner_up: c.runner_up.map(|b| (b.id, b.agreement)),
                    identified: c.identification.map(|m| m.id),
                    size_px: obs.size_px,
                    with_places: places.is_some(),
                }),
            }
        })
        .collect()
}

/// The sides not seen, each saying why: at the image's edge ("cut off"), or inside the image
/// with robot colours against it ("hidden"; a ball in the middle of the image is never cut off).
fn sides(cut: CutOff, bounds: PixelBox, image_size: (usize, usize)) -> Vec<&'static str> {
    let [minx, miny, maxx, maxy] = bounds.to_array().map(|v| v as usize);
    let (w, h) = image_size;
    [
        (cut.left, minx == 0, "left (image edge)", "left (hidden)"),
        (
            cut.right,
            maxx + 1 >= w,
            "right (image edge)",
            "right (hidden)",
        ),
        (cut.top, miny == 0, "top (image edge)", "top (hidden)"),
        (
            cut.bottom,
            maxy + 1 >= h,
            "bottom (image edge)",
            "bottom (hidden)",
        ),
    ]
    .into_iter()
    .filter(|(on, ..)| *on)
    .map(|(_, edge, at_edge, hidden)| if edge { at_edge } else { hidden })
    .collect()
}

/// Why a candidate ended as it did, from its confidence and whether it was accepted.
fn reason(c: &Confidence, accepted: bool) -> String {
    let failed: Vec<&str> = c
        .tests
        .iter()
        .filter(|t| t.outcome == TestOutcome::Failed)
        .map(|t| t.test.as_str())
        .collect();
    let failed = if failed.is_empty() {
        "no test failed".to_owned()
    } else {
        format!("failed: {}", failed.join(", "))
    };
    if accepted {
        format!("accepted: confidence {:+.2} > 0; {failed}", c.total)
    } else if c.total > 0.0 {
        format!(
            "rejected although confidence {:+.2} > 0: another candidate won; {failed}",
            c.total
        )
    } else {
        format!("rejected: confidence {:+.2} ≤ 0; {failed}", c.total)
    }
}

/// Every candidate of `r`: balls, goals, beacons, pink markers, in that order (`places`: the
/// open places file pink markers were identified against; `image_size`: the frame's, pixels,
/// which tells sides cut off at the image edge from hidden ones).
#[must_use]
pub fn candidates(
    r: &Recognition,
    places: Option<&PatternMemory>,
    image_size: (usize, usize),
) -> Vec<CandidateInfo> {
    let mut out = ball_candidates(r, image_size);
    out.extend(goal_candidates(r, image_size));
    out.extend(beacon_candidates(r));
    out.extend(pattern_candidates(r, places));
    out
}

/// The inspector's rows for the ball candidates of `r` (`image_size`, pixels: see [`sides`]).
fn ball_candidates(r: &Recognition, image_size: (usize, usize)) -> Vec<CandidateInfo> {
    let mut out = Vec::new();
    for (i, c) in r.ball.candidates.iter().enumerate() {
        let mut notes = vec![format!(
            "{} pixels, {} orange; radius {:.1} px",
            c.pixels, c.orange_pixels, c.radius_px
        )];
        match (&c.fit, &c.fit_rejected) {
            (Some(_), _) => {
                notes.push(format!("circle fit on {} edge points", c.edge_points.len()))
            }
            (None, Some(why)) => notes.push(format!("no circle fit: {why}")),
            (None, None) => {}
        }
        let (seen, fixed) = (c.observed_center, c.center);
        notes.push(if seen.distance_to(&fixed) > 0.5 {
            format!(
                "centre ({:.1}, {:.1}) px in the image; ({:.1}, {:.1}) px skew-corrected \
                     (dashed circle)",
                seen.x_px, seen.y_px, fixed.x_px, fixed.y_px
            )
        } else {
            format!("centre ({:.1}, {:.1}) px", fixed.x_px, fixed.y_px)
        });
        // The accepted ball may carry a fused (ground-plane) placement.
        let (camera, body) = match &r.ball.ball {
            Some(b) if b.candidate == i => (b.camera, b.body),
            _ => (c.camera, None),
        };
        out.push(CandidateInfo {
            owner: ObjectId::Ball(i),
            kind: "ball".to_owned(),
            accepted: c.accepted,
            reason: reason(&c.confidence, c.accepted),
            confidence: c.confidence.clone(),
            camera,
            body,
            distance_is_max: false,
            cut_sides: sides(c.cut_off, c.bounds, image_size),
            notes,
            pattern: None,
        });
    }
    out
}

/// The inspector's rows for the goal candidates of `r` (`image_size`, pixels: see [`sides`]).
fn goal_candidates(r: &Recognition, image_size: (usize, usize)) -> Vec<CandidateInfo> {
    let mut out = Vec::new();
    for (i, g) in r.goals.candidates.iter().enumerate() {
        let mut notes = vec![format!(
            "{} pixels in {} blobs; height {:.1} px{}",
            g.pixels,
            g.blobs.len(),
            g.height_px,
            if g.distance_from_ir {
                "; distance from the IR sensor"
            } else {
                ""
            }
        )];
        notes.push(format!(
            "{} posts fitted{}",
            g.posts.len(),
            g.gap
                .as_ref()
                .map(|gap| format!("; gap {:.0} px wide", gap.width_px))
                .unwrap_or_default()
        ));
        notes.extend(
            g.rejected_posts
                .iter()
                .map(|p| format!("post refused: {p}")),
        );
        out.push(CandidateInfo {
            owner: ObjectId::Goal(g.colour, i),
            kind: format!("{} goal", g.colour.name()),
            accepted: g.accepted,
            reason: reason(&g.confidence, g.accepted),
            confidence: g.confidence.clone(),
            camera: g.camera,
            body: g.body,
            distance_is_max: g.distance_is_max,
            cut_sides: sides(g.cut_off, g.bounds, image_size),
            notes,
            pattern: None,
        });
    }
    out
}

/// The inspector's rows for the beacon candidates of `r`.
fn beacon_candidates(r: &Recognition) -> Vec<CandidateInfo> {
    let mut out = Vec::new();
    for (i, b) in r.beacons.iter().enumerate() {
        out.push(CandidateInfo {
            owner: ObjectId::Beacon(i),
            kind: format!("beacon {}", b.kind.name()),
            accepted: b.accepted,
            reason: reason(&b.confidence, b.accepted),
            confidence: b.confidence.clone(),
            camera: b.camera,
            body: b.body,
            distance_is_max: b.cut_off,
            cut_sides: if b.cut_off {
                vec!["top or bottom"]
            } else {
                vec![]
            },
            notes: Vec::new(),
            pattern: None,
        });
    }
    out
}

/// Width of the candidate list, points.
const LIST_WIDTH: f32 = 230.0;

/// Green for accepted, red for rejected.
fn verdict_colour(accepted: bool) -> Color32 {
    if accepted {
        Color32::from_rgb(90, 200, 90)
    } else {
        Color32::from_rgb(230, 90, 80)
    }
}

/// The inspector's contents: every candidate of the shown frame with its confidence breakdown.
pub fn inspector_ui(ui: &mut Ui, state: &Workspace, commands: &mut Vec<Command>) {
    if state.frame().is_none() {
        ui.label("No frame open.");
        return;
    }
    if state.overhead().active() {
        overhead_results_ui(ui, state, commands);
        return;
    }
    let list = candidates(state.recognition(), state.places(), state.image_size());
    if list.is_empty() {
        ui.label(
            "No candidates in this frame: no ball, goal, beacon or pink marker colour large \
             enough.",
        );
        return;
    }
    let selected = state.selected_object();
    ui.horizontal(|ui| {
        let accepted = list.iter().filter(|c| c.accepted).count();
        ui.label(format!("{} candidates, {accepted} accepted", list.len()));
        if selected.is_some() && ui.button("Show all alike").clicked() {
            commands.push(Command::SelectObject(None));
        }
    });
    ui.separator();
    let details = |ui: &mut Ui| match list.iter().find(|c| Some(c.owner) == selected) {
        None => {
            ui.weak("Select a candidate to see its confidence breakdown and highlight it.");
        }
        Some(c) => details_ui(ui, c),
    };
    if ui.available_width() >= LIST_WIDTH + DETAILS_MIN_WIDTH {
        ui.horizontal_top(|ui| {
            ui.vertical(|ui| {
                ui.set_width(LIST_WIDTH);
                candidate_list_ui(ui, &list, selected, 360.0, commands);
            });
            ui.add_space(8.0);
            ui.vertical(details);
        });
    } else {
        // Docked beside the image the window is narrow: the list above, the breakdown below at
        // the window's full width (side by side the breakdown's columns were cut off).
        candidate_list_ui(ui, &list, selected, 150.0, commands);
        ui.separator();
        details(ui);
    }
}

/// Width the confidence breakdown needs beside the list (its five columns), points.
const DETAILS_MIN_WIDTH: f32 = 420.0;

/// The candidates, each a row that selects it (or clears the selection when it is selected).
fn candidate_list_ui(
    ui: &mut Ui,
    list: &[CandidateInfo],
    selected: Option<ObjectId>,
    max_height: f32,
    commands: &mut Vec<Command>,
) {
    egui::ScrollArea::vertical()
        .id_salt("inspector_list")
        .max_height(max_height)
        .show(ui, |ui| {
            for c in list {
                let is_sel = selected == Some(c.owner);
                let text = RichText::new(format!(
                    "{} {}  {:+.2}",
                    if c.accepted { "accepted" } else { "rejected" },
                    c.owner,
                    c.confidence.total
                ))
                .color(verdict_colour(c.accepted));
                let r = ui.selectable_label(is_sel, text).on_hover_text(&c.kind);
                if r.clicked() {
                    commands.push(Command::SelectObject((!is_sel).then_some(c.owner)));
                }
            }
        });
}

fn details_ui(ui: &mut Ui, c: &CandidateInfo) {
    ui.heading(format!("{} ({})", c.kind, c.owner));
    ui.colored_label(verdict_colour(c.accepted), &c.reason);
    let deg = f64::to_degrees;
    let distance = if c.camera.distance_cm.is_finite() {
        format!(
            "{}{:.0} cm",
            if c.distance_is_max { "≤ " } else { "" },
            c.camera.distance_cm
        )
    } else {
        "distance unknown".to_owned()
    };
    ui.label(format!(
        "camera: {distance}, bearing {:+.1}°, elevation {:+.1}°",
        deg(c.camera.bearing_rad),
        deg(c.camera.elevation_rad)
    ));
    if let Some(b) = &c.body {
        ui.label(format!(
            "body: {:.0} cm, bearing {:+.1}°, elevation {:+.1}°",
            b.distance_cm,
            deg(b.bearing_rad),
            deg(b.elevation_rad)
        ));
    }
    let mut flags = Vec::new();
    if c.distance_is_max {
        flags.push("distance is a maximum".to_owned());
    }
    if !c.cut_sides.is_empty() {
        flags.push(format!("not seen: {}", c.cut_sides.join(", ")));
    }
    if !flags.is_empty() {
        ui.label(format!("flags: {}", flags.join("; ")));
    }
    for n in &c.notes {
        ui.weak(n);
    }
    if let Some(p) = &c.pattern {
        pattern_regions_ui(ui, c.owner, p);
    }
    ui.separator();
    egui::Grid::new(("breakdown", c.owner))
        .striped(true)
        .num_columns(5)
        .show(ui, |ui| {
            for h in ["test", "value", "range", "effect", "result"] {
                ui.strong(h);
            }
            ui.end_row();
            for t in &c.confidence.tests {
                ui.monospace(t.test.as_str());
                ui.monospace(format!("{:.2}", t.value));
                ui.monospace(format!("{:.2}–{:.2}", t.range[0], t.range[1]));
                ui.monospace(format!("{:+.2}", t.effect));
                let (text, colour) = match t.outcome {
                    TestOutcome::Passed => ("pass", verdict_colour(true)),
                    TestOutcome::Failed => ("fail", verdict_colour(false)),
                    TestOutcome::Skipped => ("skip", Color32::GRAY),
                };
                ui.colored_label(colour, text);
                ui.end_row();
            }
            ui.strong("total");
            ui.label("");
            ui.label("");
            ui.monospace(format!("{:+.2}", c.confidence.total));
            ui.label("");
            ui.end_row();
        });
}

/// The nine regions in their 3 × 3 layout: colours, and whether each agrees with the closest
/// place.
fn pattern_regions_ui(ui: &mut Ui, owner: ObjectId, p: &PatternInfo) {
    ui.separator();
    ui.label(match (p.closest, p.with_places) {
        (Some((id, a)), _) => {
            format!("regions (most common / second colour), against place {id}: {a}/9 agree")
        }
        (None, true) => "regions (most common / second colour); no place to compare".to_owned(),
        (None, false) => "regions (most common / second colour)".to_owned(),
    });
    egui::Grid::new(("pattern_regions", owner))
        .striped(false)
        .num_columns(3)
        .show(ui, |ui| {
            for k in 0..9 {
                let code = p.regions[k][0];
                let [r, g, b] = crate::overlay::pattern_region_rgb(code);
                let mut text = RichText::new(p.region_text(k)).color(Color32::from_rgb(r, g, b));
                if k == 4 {
                    text = text.strong();
                }
                let verdict = match p.agrees.map(|a| a[k]) {
                    Some(true) => " agrees",
                    Some(false) => " differs",
                    None => "",
                };
                ui.horizontal(|ui| {
                    ui.label(text);
                    if !verdict.is_empty() {
                        ui.colored_label(verdict_colour(verdict == " agrees"), verdict.trim());
                    }
                });
                if k % 3 == 2 {
                    ui.end_row();
                }
            }
        });
}

/// An overhead frame's results: the ball and each robot with field position, heading and
/// confidence, and the candidates turned down with their reasons; clicking a robot selects it
/// in every view.
fn overhead_results_ui(ui: &mut Ui, state: &Workspace, commands: &mut Vec<Command>) {
    use crate::workspace::{OverheadCommand, RobotKey};
    let overhead = state.overhead();
    let Some(d) = overhead.detections() else {
        ui.label(overhead.calibration_status());
        return;
    };
    match &d.ball {
        Some(b) => ui.label(format!(
            "ball at ({:.1}, {:.1}) cm, image ({:.1}, {:.1}) px, radius {:.1} px, confidence {:.2}",
            b.field_cm[0], b.field_cm[1], b.image.x_px, b.image.y_px, b.radius_px, b.confidence
        )),
        None => ui.label("no ball"),
    };
    let selected = overhead.selected();
    egui::Grid::new("overhead-robots")
        .striped(true)
        .show(ui, |ui| {
            for h in ["robot", "field (cm)", "heading (°)", "confidence"] {
                ui.strong(h);
            }
            ui.end_row();
            for r in &d.robots {
                let key = RobotKey {
                    team: r.team,
                    identity: r.identity,
                };
                let mine = selected == Some(key);
                if ui.selectable_label(mine, key.to_string()).clicked() {
                    let next = if mine { None } else { Some(key) };
                    commands.push(OverheadCommand::SelectRobot(next).into());
                }
                ui.monospace(format!("{:7.1} {:7.1}", r.field_cm[0], r.field_cm[1]));
                ui.monospace(format!("{:6.1}", r.heading_rad.to_degrees()));
                ui.monospace(format!("{:.2}", r.confidence));
                ui.end_row();
            }
        });
    if !d.rejected.is_empty() {
        ui.collapsing(format!("{} rejected candidates", d.rejected.len()), |ui| {
            for c in &d.rejected {
                let [x0, y0, x1, y1] = c.bounds.to_array();
                ui.add(
                    egui::Label::new(format!(
                        "{} blob at ({x0}, {y0})–({x1}, {y1}) px: {}",
                        crate::lut::ColourClass::from_code(c.colour)
                            .map_or_else(|| format!("class {}", c.colour), |k| k.name().to_owned()),
                        c.reason
                    ))
                    .wrap(),
                );
            }
        });
    }
}
