//! What the scene's things are made of: primitives (spheres, vertical cylinders, oriented
//! boxes) with their paint, grouped into objects with bounding spheres; the ray–primitive
//! intersections and the paint at a hit.

use nalgebra::{Matrix3, Point3, Vector3};

use super::object_id;
use crate::geometry::{Ers7Dimensions, rotation_z};
use crate::lut::ColourClass;
use crate::model::scene::{Ball, Beacon, Clutter, FieldSpec, GoalColour, Material, Shape};

#[derive(Debug, Clone)]
/// How a part is painted.
pub(super) enum Paint {
    Solid(Material),
    /// Bands by world height: `(upper z in cm, material)`, ascending.
    BandsZ(Vec<(f64, Material)>),
    /// An overhead robot marker's top: dots by position relative to the plate's centre (field
    /// x, y, cm) turned by the robot's heading (radians); black on the plate's rim.
    Marker {
        marker: crate::geometry::RobotMarker,
        centre: [f64; 2],
        heading_rad: f64,
    },
    /// A band across a box's local x range, `base` elsewhere.
    BandX {
        base: Material,
        band: Material,
        from_x: f64,
        to_x: f64,
    },
}

#[derive(Debug, Clone)]
/// A part's shape, field coordinates (cm).
pub(super) enum Prim {
    Sphere {
        centre: Vector3<f64>,
        radius: f64,
    },
    /// Vertical cylinder from `base.z` up by `height`.
    Cylinder {
        base: Vector3<f64>,
        radius: f64,
        height: f64,
    },
    /// An oriented box: `local = rot_t · (p − centre)`, inside when |local| ≤ half.
    Box {
        centre: Vector3<f64>,
        rot_t: Matrix3<f64>,
        half: Vector3<f64>,
    },
}

#[derive(Debug, Clone)]
/// One shape with its paint.
pub(super) struct Part {
    pub(super) prim: Prim,
    pub(super) paint: Paint,
}

#[derive(Debug, Clone)]
/// One thing of the scene ([`object_id`]): its parts within a bounding sphere.
pub(super) struct Object {
    pub(super) id: u16,
    pub(super) bound_centre: Vector3<f64>,
    pub(super) bound_radius: f64,
    pub(super) parts: Vec<Part>,
    pub(super) casts_shadow: bool,
}

/// The ball: one orange sphere.
pub(super) fn ball_object(ball: &Ball) -> Object {
    object(
        object_id::BALL,
        vec![Part {
            prim: Prim::Sphere {
                centre: Vector3::new(ball.x_cm, ball.y_cm, ball.radius_cm),
                radius: ball.radius_cm,
            },
            paint: Paint::Solid(Material::BallOrange),
        }],
    )
}

/// A goal: its boxes in the goal's colour.
pub(super) fn goal_object(field: &FieldSpec, colour: GoalColour) -> Object {
    let (id, material) = match colour {
        GoalColour::Yellow => (object_id::YELLOW_GOAL, Material::Yellow),
        GoalColour::SkyBlue => (object_id::SKY_BLUE_GOAL, Material::SkyBlue),
    };
    let parts = goal_boxes(field, colour)
        .into_iter()
        .map(|(centre, half)| Part {
            prim: oriented_box(centre, 0.0, half),
            paint: Paint::Solid(material),
        })
        .collect();
    object(id, parts)
}

/// Beacon `i`: a cylinder in three bands, white at the foot.
pub(super) fn beacon_object(i: usize, b: &Beacon) -> Object {
    let z1 = b.base_height_cm;
    let z2 = z1 + b.band_height_cm;
    let z3 = z2 + b.band_height_cm;
    object(
        object_id::BEACON + u16::try_from(i).unwrap_or(0).min(89),
        vec![Part {
            prim: Prim::Cylinder {
                base: Vector3::new(b.x_cm, b.y_cm, 0.0),
                radius: b.radius_cm,
                height: z3,
            },
            paint: Paint::BandsZ(vec![
                (z1, Material::White),
                (z2, b.bottom),
                (f64::INFINITY, b.top),
            ]),
        }],
    )
}

/// Clutter item `i`: one box, cylinder or sphere.
pub(super) fn clutter_object(i: usize, c: &Clutter) -> Object {
    let [x, y, z] = c.position_cm;
    let prim = match c.shape {
        Shape::Box {
            length_cm,
            width_cm,
            height_cm,
        } => oriented_box(
            Vector3::new(x, y, z + height_cm / 2.0),
            c.yaw_rad,
            Vector3::new(length_cm / 2.0, width_cm / 2.0, height_cm / 2.0),
        ),
        Shape::Cylinder {
            radius_cm,
            height_cm,
        } => Prim::Cylinder {
            base: Vector3::new(x, y, z),
            radius: radius_cm,
            height: height_cm,
        },
        Shape::Sphere { radius_cm } => Prim::Sphere {
            centre: Vector3::new(x, y, z + radius_cm),
            radius: radius_cm,
        },
    };
    object(
        object_id::CLUTTER + u16::try_from(i).unwrap_or(0).min(60_000),
        vec![Part {
            prim,
            paint: Paint::Solid(c.material),
        }],
    )
}

pub(super) fn object(id: u16, parts: Vec<Part>) -> Object {
    // Bounding sphere: centre of the parts' extents, radius covering every part.
    let extents: Vec<(Vector3<f64>, f64)> = parts
        .iter()
        .map(|p| match &p.prim {
            Prim::Sphere { centre, radius } => (*centre, *radius),
            Prim::Cylinder {
                base,
                radius,
                height,
            } => (
                base + Vector3::new(0.0, 0.0, height / 2.0),
                radius.hypot(height / 2.0),
            ),
            Prim::Box { centre, half, .. } => (*centre, half.norm()),
        })
        .collect();
    let n = extents.len().max(1);
    let centre = extents.iter().map(|e| e.0).sum::<Vector3<f64>>() / n as f64;
    let radius = extents
        .iter()
        .map(|(c, r)| (c - centre).norm() + r)
        .fold(0.0, f64::max);
    Object {
        id,
        bound_centre: centre,
        bound_radius: radius,
        parts,
        casts_shadow: true,
    }
}

pub(super) fn oriented_box(centre: Vector3<f64>, yaw_rad: f64, half: Vector3<f64>) -> Prim {
    Prim::Box {
        centre,
        rot_t: rotation_z(yaw_rad)
            .to_rotation_matrix()
            .matrix()
            .transpose(),
        half,
    }
}

/// Thickness of a marker's panel, centimetres.
const MARKER_PANEL_CM: f64 = 1.0;

/// A marker's eight outer tiles and its post (one object), and its pink middle tile (its own
/// object, so the truth can count its pixels).
pub(super) fn marker_parts(m: &crate::model::scene::Marker) -> (Vec<Part>, Part) {
    let (s, c) = m.facing_rad.sin_cos();
    // Tile boxes sit behind the face plane, so the painted face is where the marker says.
    let back = -MARKER_PANEL_CM / 2.0;
    let tile = |k: usize| {
        let (col, row) = ((k % 3) as f64 - 1.0, 1.0 - (k / 3) as f64);
        let [x, y, z] = m.face_point(col, row);
        Part {
            prim: oriented_box(
                Vector3::new(x + back * c, y + back * s, z),
                m.facing_rad,
                Vector3::new(MARKER_PANEL_CM / 2.0, m.tile_cm / 2.0, m.tile_cm / 2.0),
            ),
            paint: Paint::Solid(m.tiles[k]),
        }
    };
    let mut frame: Vec<Part> = (0..9).filter(|&k| k != 4).map(tile).collect();
    let bottom = (m.centre_height_cm - 1.5 * m.tile_cm).max(0.0);
    if bottom > 0.0 {
        let behind = -(MARKER_PANEL_CM + 1.5);
        frame.push(Part {
            prim: Prim::Cylinder {
                base: Vector3::new(m.x_cm + behind * c, m.y_cm + behind * s, 0.0),
                radius: 1.5,
                height: bottom + 0.5 * m.tile_cm,
            },
            // Dark grey like clothing: wood's brown classifies orange here and there.
            paint: Paint::Solid(Material::Cloth),
        });
    }
    (frame, tile(4))
}

/// Centres and half sizes of a goal's back and side walls (cm).
pub(super) fn goal_boxes(
    f: &crate::model::scene::FieldSpec,
    colour: GoalColour,
) -> Vec<(Vector3<f64>, Vector3<f64>)> {
    let s = match colour {
        GoalColour::Yellow => 1.0,
        GoalColour::SkyBlue => -1.0,
    };
    let (hl, w, h, d, t) = (
        f.length_cm / 2.0,
        f.goal_width_cm / 2.0,
        f.goal_height_cm,
        f.goal_depth_cm,
        f.goal_wall_cm,
    );
    vec![
        (
            Vector3::new(s * (hl + d + t / 2.0), 0.0, h / 2.0),
            Vector3::new(t / 2.0, w + t, h / 2.0),
        ),
        (
            Vector3::new(s * (hl + d / 2.0), w + t / 2.0, h / 2.0),
            Vector3::new(d / 2.0, t / 2.0, h / 2.0),
        ),
        (
            Vector3::new(s * (hl + d / 2.0), -(w + t / 2.0), h / 2.0),
            Vector3::new(d / 2.0, t / 2.0, h / 2.0),
        ),
    ]
}

/// Thickness of an overhead marker's plate, centimetres.
const MARKER_PLATE_THICKNESS_CM: f64 = 0.5;

/// An overhead marker's plate: a thin black disc whose top is at the plate height, painted with
/// the team and identity dots.
pub(super) fn marker_plate(
    marker: &crate::geometry::RobotMarker,
    pose: &crate::geometry::RobotPose,
) -> Part {
    let top = marker.plate_height_cm;
    Part {
        prim: Prim::Cylinder {
            base: Vector3::new(pose.x_cm, pose.y_cm, top - MARKER_PLATE_THICKNESS_CM),
            radius: crate::geometry::marker::PLATE_DIAMETER_CM / 2.0,
            height: MARKER_PLATE_THICKNESS_CM,
        },
        paint: Paint::Marker {
            marker: *marker,
            centre: [pose.x_cm, pose.y_cm],
            heading_rad: pose.heading_rad,
        },
    }
}

/// The ERS-7 as boxes and a sphere: body with a uniform band, four black legs, white head with
/// a black face. A robot wearing an overhead marker has no head: the plate above it hides the
/// head from the overhead camera, and the head would poke through the plate at 22.5 cm.
pub(super) fn robot_parts(r: &crate::model::scene::Robot) -> Vec<Part> {
    let field_from_body = r.body.field_from_body(&r.pose);
    let rot = field_from_body.rotation().to_rotation_matrix().into_inner();
    let to_field = |p: Vector3<f64>| {
        (field_from_body * crate::geometry::Point::<crate::geometry::Body>::from(Point3::from(p)))
            .coords
            .coords
    };
    let mut parts = vec![Part {
        prim: Prim::Box {
            centre: to_field(Vector3::zeros()),
            rot_t: rot.transpose(),
            half: Vector3::new(12.0, 7.0, 5.0),
        },
        paint: Paint::BandX {
            base: Material::White,
            band: r.team.uniform(),
            from_x: -6.0,
            to_x: 5.0,
        },
    }];
    for (lx, ly) in [(9.0, 5.5), (9.0, -5.5), (-9.0, 5.5), (-9.0, -5.5)] {
        let top = to_field(Vector3::new(lx, ly, -3.0));
        let height = top.z.max(0.5);
        parts.push(Part {
            prim: oriented_box(
                Vector3::new(top.x, top.y, height / 2.0),
                r.pose.heading_rad,
                Vector3::new(1.6, 1.6, height / 2.0),
            ),
            paint: Paint::Solid(Material::RobotBlack),
        });
    }
    if r.marker.is_some() {
        return parts;
    }
    let body_from_head = Ers7Dimensions::ERS7.body_from_head(&r.joints);
    let field_from_head = field_from_body * body_from_head;
    let head_rot = field_from_head.rotation().to_rotation_matrix().into_inner();
    let head_centre = (field_from_head
        * crate::geometry::Point::<crate::geometry::Head>::new(2.0, 0.0, 0.0))
    .coords
    .coords;
    parts.push(Part {
        prim: Prim::Sphere {
            centre: head_centre,
            radius: 5.0,
        },
        paint: Paint::Solid(Material::White),
    });
    let face = (field_from_head
        * crate::geometry::Point::<crate::geometry::Head>::new(7.0, 0.0, -1.0))
    .coords
    .coords;
    parts.push(Part {
        prim: Prim::Box {
            centre: face,
            rot_t: head_rot.transpose(),
            half: Vector3::new(2.5, 2.5, 2.0),
        },
        paint: Paint::Solid(Material::RobotBlack),
    });
    parts
}

pub(super) fn bound_hit(obj: &Object, o: &Vector3<f64>, d: &Vector3<f64>, t_max: f64) -> bool {
    let oc = obj.bound_centre - o;
    let tca = oc.dot(d);
    let r2 = obj.bound_radius * obj.bound_radius;
    let d2 = oc.norm_squared() - tca * tca;
    d2 <= r2 && tca + obj.bound_radius > 0.0 && tca - obj.bound_radius < t_max
}

/// Nearest positive ray parameter and outward normal of a primitive (ray direction unit).
pub(super) fn intersect(
    prim: &Prim,
    o: &Vector3<f64>,
    d: &Vector3<f64>,
) -> Option<(f64, Vector3<f64>)> {
    const EPS: f64 = 1e-6;
    match prim {
        Prim::Sphere { centre, radius } => {
            let oc = o - centre;
            let b = oc.dot(d);
            let c = oc.norm_squared() - radius * radius;
            let disc = b * b - c;
            if disc < 0.0 {
                return None;
            }
            let s = disc.sqrt();
            let t = if -b - s > EPS { -b - s } else { -b + s };
            (t > EPS).then(|| (t, (o + d * t - centre) / *radius))
        }
        Prim::Cylinder {
            base,
            radius,
            height,
        } => {
            let mut best: Option<(f64, Vector3<f64>)> = None;
            let (ox, oy) = (o.x - base.x, o.y - base.y);
            let a = d.x * d.x + d.y * d.y;
            if a > 1e-12 {
                let b = ox * d.x + oy * d.y;
                let c = ox * ox + oy * oy - radius * radius;
                let disc = b * b - a * c;
                if disc >= 0.0 {
                    let s = disc.sqrt();
                    for t in [(-b - s) / a, (-b + s) / a] {
                        let z = o.z + d.z * t - base.z;
                        if t > EPS && (0.0..=*height).contains(&z) {
                            let n = Vector3::new(ox + d.x * t, oy + d.y * t, 0.0) / *radius;
                            best = Some((t, n));
                            break;
                        }
                    }
                }
            }
            // Top cap.
            if d.z.abs() > 1e-12 {
                let t = (base.z + height - o.z) / d.z;
                if t > EPS && best.is_none_or(|(bt, _)| t < bt) {
                    let (x, y) = (ox + d.x * t, oy + d.y * t);
                    if x * x + y * y <= radius * radius {
                        best = Some((t, Vector3::z()));
                    }
                }
            }
            best
        }
        Prim::Box {
            centre,
            rot_t,
            half,
        } => {
            let lo = rot_t * (o - centre);
            let ld = rot_t * d;
            let (mut t0, mut t1) = (f64::NEG_INFINITY, f64::INFINITY);
            let mut axis = 0;
            let mut sign = 1.0;
            for k in 0..3 {
                if ld[k].abs() < 1e-12 {
                    if lo[k].abs() > half[k] {
                        return None;
                    }
                    continue;
                }
                let a = (-half[k] - lo[k]) / ld[k];
                let b = (half[k] - lo[k]) / ld[k];
                let (near, far) = if a < b { (a, b) } else { (b, a) };
                if near > t0 {
                    t0 = near;
                    axis = k;
                    sign = if ld[k] > 0.0 { -1.0 } else { 1.0 };
                }
                t1 = t1.min(far);
            }
            if t0 > t1 || t1 < EPS {
                return None;
            }
            if t0 > EPS {
                let mut n_local = Vector3::zeros();
                n_local[axis] = sign;
                Some((t0, rot_t.transpose() * n_local))
            } else {
                // Inside the box: treat the exit as the hit (rare; cameras stay outside).
                Some((t1, -d))
            }
        }
    }
}

pub(super) fn paint_at(paint: &Paint, prim: &Prim, p: &Vector3<f64>) -> Material {
    match paint {
        Paint::Solid(m) => *m,
        Paint::BandsZ(bands) => bands
            .iter()
            .find(|(top, _)| p.z <= *top)
            .or(bands.last())
            .map_or(Material::White, |b| b.1),
        Paint::Marker {
            marker,
            centre,
            heading_rad,
        } => {
            let (dx, dy) = (p.x - centre[0], p.y - centre[1]);
            let (s, c) = heading_rad.sin_cos();
            let class = marker.class_at(c * dx + s * dy, -s * dx + c * dy);
            match class {
                Some(ColourClass::Pink) => Material::Pink,
                Some(ColourClass::Green) => Material::Carpet,
                Some(ColourClass::SkyBlue) => Material::SkyBlue,
                Some(ColourClass::Yellow) => Material::Yellow,
                _ => Material::RobotBlack,
            }
        }
        Paint::BandX {
            base,
            band,
            from_x,
            to_x,
        } => {
            let local_x = match prim {
                Prim::Box { centre, rot_t, .. } => (rot_t * (p - centre)).x,
                _ => 0.0,
            };
            if (*from_x..=*to_x).contains(&local_x) {
                *band
            } else {
                *base
            }
        }
    }
}
