//! The renderer: one ray per pixel against a handful of simple shapes, shaded, then turned into
//! a UYVY frame the way a camera would deliver it.
//!
//! [`World::compile`] turns a [`Scene`] into primitives (spheres, vertical cylinders, boxes
//! turned about the vertical or tilted with a robot's body) grouped into objects with bounding
//! spheres; the ground plane (carpet, lines, floor) and the room's walls and ceiling are
//! analytic. A [`Renderer`] holds the camera-frame ray of every pixel (computed once per camera,
//! undistorted for the overhead lens) and renders a frame from a camera pose *per row*, which is
//! how the rolling shutter comes in: row r is exposed at its own time, while the head moves.
//!
//! Per pixel: nearest hit → material colour × (ambient + direct·cos, unless in shadow) ×
//! exposure × tint → BT.601 studio-range YUV → vignetting (darker, bluer corners) → sensor
//! noise → the two pixels of a pair share the mean of their chroma (UYVY). Besides the frame it
//! returns each pixel's true colour class (for training and scoring tables) and the object it
//! shows (for ground truth: visible fractions, image boxes).

use nalgebra::{Isometry3, Matrix3, Point3, Vector3};

use super::rng::SimRng;
use super::scene::{CameraEffects, GoalColour, Lighting, Material, Scene, Shape};
use crate::frame::{Frame, FrameError};
use crate::geometry::{Ers7Dimensions, OverheadCamera, PinholeCamera, rotation_z};
use crate::lut::ColourClass;

/// Object identities in [`Rendered::objects`]: what each pixel shows.
pub mod object_id {
    /// Ground, lines, floor, walls, ceiling.
    pub const BACKGROUND: u16 = 0;
    /// The ball.
    pub const BALL: u16 = 1;
    /// The yellow goal.
    pub const YELLOW_GOAL: u16 = 2;
    /// The sky-blue goal.
    pub const SKY_BLUE_GOAL: u16 = 3;
    /// Beacon `i` of the scene is `BEACON + i`.
    pub const BEACON: u16 = 10;
    /// The robot with id `n` is `ROBOT + n`.
    pub const ROBOT: u16 = 100;
    /// Clutter item `i` of the scene is `CLUTTER + i`.
    pub const CLUTTER: u16 = 1000;
    /// The overhead marker plate of the robot with id `n` is `ROBOT_MARKER + n`.
    pub const ROBOT_MARKER: u16 = 61_000;
    /// The eight outer tiles and the post of coloured-pattern marker `i` are `MARKER + i`.
    pub const MARKER: u16 = 62_000;
    /// The pink middle tile of marker `i` is `MARKER_PINK + i`.
    pub const MARKER_PINK: u16 = 63_000;
}

/// A rendered image with its per-pixel ground truth.
#[derive(Debug, Clone)]
pub struct Rendered {
    /// The camera frame, UYVY.
    pub frame: Frame,
    /// The true colour class code of each pixel, row-major (`FORMATS.md` codes).
    pub labels: Vec<u8>,
    /// The object each pixel shows, row-major ([`object_id`]).
    pub objects: Vec<u16>,
}

#[derive(Debug, Clone)]
enum Paint {
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
enum Prim {
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
struct Part {
    prim: Prim,
    paint: Paint,
}

#[derive(Debug, Clone)]
struct Object {
    id: u16,
    bound_centre: Vector3<f64>,
    bound_radius: f64,
    parts: Vec<Part>,
    casts_shadow: bool,
}

/// A scene turned into primitives, ready to render many times (compile once per scene state).
#[derive(Debug, Clone)]
pub struct World {
    objects: Vec<Object>,
    field: super::scene::FieldSpec,
    room: super::scene::RoomSpec,
    lighting: Lighting,
    towards_lamp: Vector3<f64>,
}

struct Hit {
    t: f64,
    normal: Vector3<f64>,
    material: Material,
    object: u16,
}

impl World {
    /// Builds the primitives of a scene.
    #[must_use]
    pub fn compile(scene: &Scene) -> Self {
        let mut objects = Vec::new();
        if let Some(ball) = scene.ball {
            objects.push(object(
                object_id::BALL,
                vec![Part {
                    prim: Prim::Sphere {
                        centre: Vector3::new(ball.x_cm, ball.y_cm, ball.radius_cm),
                        radius: ball.radius_cm,
                    },
                    paint: Paint::Solid(Material::BallOrange),
                }],
            ));
        }
        for colour in [GoalColour::Yellow, GoalColour::SkyBlue] {
            let (id, material) = match colour {
                GoalColour::Yellow => (object_id::YELLOW_GOAL, Material::Yellow),
                GoalColour::SkyBlue => (object_id::SKY_BLUE_GOAL, Material::SkyBlue),
            };
            let parts = goal_boxes(&scene.field, colour)
                .into_iter()
                .map(|(centre, half)| Part {
                    prim: oriented_box(centre, 0.0, half),
                    paint: Paint::Solid(material),
                })
                .collect();
            objects.push(object(id, parts));
        }
        for (i, b) in scene.beacons.iter().enumerate() {
            let z1 = b.base_height_cm;
            let z2 = z1 + b.band_height_cm;
            let z3 = z2 + b.band_height_cm;
            objects.push(object(
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
            ));
        }
        for r in &scene.robots {
            let n = u16::try_from(r.id).unwrap_or(0).min(899);
            objects.push(object(object_id::ROBOT + n, robot_parts(r)));
            if let Some(marker) = r.marker {
                objects.push(object(
                    object_id::ROBOT_MARKER + n,
                    vec![marker_plate(&marker, &r.pose)],
                ));
            }
        }
        for (i, c) in scene.clutter.iter().enumerate() {
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
            objects.push(object(
                object_id::CLUTTER + u16::try_from(i).unwrap_or(0).min(60_000),
                vec![Part {
                    prim,
                    paint: Paint::Solid(c.material),
                }],
            ));
        }
        for (i, m) in scene.markers.iter().enumerate() {
            let i = u16::try_from(i).unwrap_or(0).min(999);
            let (frame, pink) = marker_parts(m);
            objects.push(object(object_id::MARKER + i, frame));
            objects.push(object(object_id::MARKER_PINK + i, vec![pink]));
        }
        let l = Vector3::from(scene.lighting.towards_lamp);
        let towards_lamp = if l.norm() > 1e-9 && l.iter().all(|a| a.is_finite()) {
            l.normalize()
        } else {
            Vector3::z()
        };
        Self {
            objects,
            field: scene.field,
            room: scene.room,
            lighting: scene.lighting,
            towards_lamp,
        }
    }

    /// Moves the ball (if the scene has one) so its centre is at `centre` (field cm).
    pub fn move_ball(&mut self, centre: Vector3<f64>) {
        for obj in self.objects.iter_mut().filter(|o| o.id == object_id::BALL) {
            obj.bound_centre = centre;
            for part in &mut obj.parts {
                if let Prim::Sphere { centre: c, .. } = &mut part.prim {
                    *c = centre;
                }
            }
        }
    }

    /// The colour (0..255 sRGB, unclipped) and object seen along a ray, with its material.
    fn trace(
        &self,
        origin: &Vector3<f64>,
        dir: &Vector3<f64>,
        skip: u16,
    ) -> (Vector3<f64>, Material, u16) {
        let mut best = self.background_hit(origin, dir);
        for obj in &self.objects {
            if obj.id == skip || !bound_hit(obj, origin, dir, best.t) {
                continue;
            }
            for part in &obj.parts {
                if let Some((t, normal)) = intersect(&part.prim, origin, dir)
                    && t < best.t
                {
                    let p = origin + dir * t;
                    best = Hit {
                        t,
                        normal,
                        material: paint_at(&part.paint, &part.prim, &p),
                        object: obj.id,
                    };
                }
            }
        }
        let p = origin + dir * best.t;
        let mut n = best.normal;
        if n.dot(dir) > 0.0 {
            n = -n;
        }
        let cos = n.dot(&self.towards_lamp).max(0.0);
        let lit = if cos > 0.0
            && self.lighting.shadows
            && best.object == object_id::BACKGROUND
            && p.z < 0.5
            && self.in_shadow(&p, skip)
        {
            0.0
        } else {
            cos
        };
        let shade = (self.lighting.ambient + self.lighting.direct * lit) * self.lighting.exposure;
        let rgb = best.material.rgb();
        let colour = Vector3::new(
            f64::from(rgb[0]) * shade * self.lighting.tint[0],
            f64::from(rgb[1]) * shade * self.lighting.tint[1],
            f64::from(rgb[2]) * shade * self.lighting.tint[2],
        );
        (colour, best.material, best.object)
    }

    /// Distance (cm) from `origin` along the unit direction `dir` to the first surface, leaving
    /// out object `skip`: what a distance sensor on the head would measure.
    #[must_use]
    pub fn distance_along(
        &self,
        origin: &crate::geometry::Point<crate::geometry::Field>,
        dir: &crate::geometry::Vector<crate::geometry::Field>,
        skip: u16,
    ) -> f64 {
        let o = origin.coords.coords;
        let d = dir.coords.normalize();
        let mut best = self.background_hit(&o, &d).t;
        for obj in &self.objects {
            if obj.id == skip || !bound_hit(obj, &o, &d, best) {
                continue;
            }
            for part in &obj.parts {
                if let Some((t, _)) = intersect(&part.prim, &o, &d) {
                    best = best.min(t);
                }
            }
        }
        best
    }

    fn in_shadow(&self, p: &Vector3<f64>, skip: u16) -> bool {
        let origin = p + Vector3::new(0.0, 0.0, 0.01);
        self.objects.iter().any(|obj| {
            obj.casts_shadow
                && obj.id != skip
                && bound_hit(obj, &origin, &self.towards_lamp, f64::INFINITY)
                && obj
                    .parts
                    .iter()
                    .any(|part| intersect(&part.prim, &origin, &self.towards_lamp).is_some())
        })
    }

    /// Ground (z = 0) or the room's walls and ceiling: always hit from inside the room.
    fn background_hit(&self, o: &Vector3<f64>, d: &Vector3<f64>) -> Hit {
        let mut t_best = f64::INFINITY;
        let mut normal = Vector3::z();
        let mut material = Material::Ceiling;
        if d.z < -1e-12 {
            let t = -o.z / d.z;
            if t > 0.0 {
                t_best = t;
                let p = o + d * t;
                material = self.ground_material(p.x, p.y);
            }
        }
        let room = &self.room;
        let walls = [
            (d.x, room.half_length_cm - o.x, -Vector3::x()),
            (-d.x, room.half_length_cm + o.x, Vector3::x()),
            (d.y, room.half_width_cm - o.y, -Vector3::y()),
            (-d.y, room.half_width_cm + o.y, Vector3::y()),
        ];
        for (speed, gap, n) in walls {
            if speed > 1e-12 {
                let t = gap / speed;
                if t > 0.0 && t < t_best {
                    t_best = t;
                    normal = n;
                    material = Material::Wall;
                }
            }
        }
        if d.z > 1e-12 {
            let t = (room.height_cm - o.z) / d.z;
            if t > 0.0 && t < t_best {
                t_best = t;
                normal = -Vector3::z();
                material = Material::Ceiling;
            }
        }
        if !t_best.is_finite() {
            t_best = 1e6;
        }
        Hit {
            t: t_best,
            normal,
            material,
            object: object_id::BACKGROUND,
        }
    }

    /// The paint of the ground at a field position (cm): carpet, line or floor.
    #[must_use]
    pub fn ground_material(&self, x: f64, y: f64) -> Material {
        let f = &self.field;
        let (ax, ay) = (x.abs(), y.abs());
        if ax > f.carpet_half_length_cm() || ay > f.carpet_half_width_cm() {
            return Material::Floor;
        }
        let (hl, hw, lw) = (f.length_cm / 2.0, f.width_cm / 2.0, f.line_width_cm);
        let half_lw = lw / 2.0;
        let inside = ax <= hl && ay <= hw;
        let side_line = ay >= hw - lw;
        let goal_line = ax >= hl - lw;
        let centre_line = ax <= half_lw;
        let circle = (x.hypot(y) - f.centre_circle_radius_cm).abs() <= half_lw;
        let front = hl - f.penalty_area_depth_cm;
        let pw = f.penalty_area_width_cm / 2.0;
        let penalty = ((ax - front).abs() <= half_lw && ay <= pw + half_lw)
            || ((ay - pw).abs() <= half_lw && ax >= front && ax <= hl);
        let on_line = (inside && (side_line || goal_line || centre_line)) || circle || penalty;
        if on_line {
            Material::Line
        } else {
            Material::Carpet
        }
    }
}

fn object(id: u16, parts: Vec<Part>) -> Object {
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

fn oriented_box(centre: Vector3<f64>, yaw_rad: f64, half: Vector3<f64>) -> Prim {
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
fn marker_parts(m: &super::scene::Marker) -> (Vec<Part>, Part) {
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
fn goal_boxes(
    f: &super::scene::FieldSpec,
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
fn marker_plate(marker: &crate::geometry::RobotMarker, pose: &crate::geometry::RobotPose) -> Part {
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
fn robot_parts(r: &super::scene::Robot) -> Vec<Part> {
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

fn bound_hit(obj: &Object, o: &Vector3<f64>, d: &Vector3<f64>, t_max: f64) -> bool {
    let oc = obj.bound_centre - o;
    let tca = oc.dot(d);
    let r2 = obj.bound_radius * obj.bound_radius;
    let d2 = oc.norm_squared() - tca * tca;
    d2 <= r2 && tca + obj.bound_radius > 0.0 && tca - obj.bound_radius < t_max
}

/// Nearest positive ray parameter and outward normal of a primitive (ray direction unit).
fn intersect(prim: &Prim, o: &Vector3<f64>, d: &Vector3<f64>) -> Option<(f64, Vector3<f64>)> {
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

fn paint_at(paint: &Paint, prim: &Prim, p: &Vector3<f64>) -> Material {
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

/// A camera's pixel rays, computed once, and the frame-making machinery.
#[derive(Debug, Clone)]
pub struct Renderer {
    width: usize,
    height: usize,
    /// Unit ray per pixel in the camera frame; `None` where the lens model has no ray.
    rays: Vec<Option<Vector3<f64>>>,
}

impl Renderer {
    /// For a pinhole camera such as the ERS-7's.
    #[must_use]
    pub fn pinhole(camera: &PinholeCamera) -> Self {
        let mut rays = Vec::with_capacity(camera.width_px * camera.height_px);
        for j in 0..camera.height_px {
            for i in 0..camera.width_px {
                let r = camera.unit_ray(crate::geometry::ImagePoint::pixel_centre(i, j));
                rays.push(Some(r.coords));
            }
        }
        Self {
            width: camera.width_px,
            height: camera.height_px,
            rays,
        }
    }

    /// For a distorted overhead camera.
    #[must_use]
    pub fn overhead(camera: &OverheadCamera) -> Self {
        let mut rays = Vec::with_capacity(camera.width_px * camera.height_px);
        for j in 0..camera.height_px {
            for i in 0..camera.width_px {
                let r = camera.camera_ray(crate::geometry::ImagePoint::pixel_centre(i, j));
                rays.push(r.map(|v| v.coords));
            }
        }
        Self {
            width: camera.width_px,
            height: camera.height_px,
            rays,
        }
    }

    /// Image width × height, pixels.
    #[must_use]
    pub fn size(&self) -> (usize, usize) {
        (self.width, self.height)
    }

    /// Renders a frame. `field_from_camera_at_row(r)` gives the camera pose while row `r` is
    /// exposed (the same pose for every row without a rolling shutter); `skip` leaves one object
    /// out (the observing robot's own body); `rng` draws the sensor noise.
    ///
    /// # Errors
    /// [`FrameError`] only for an odd width (UYVY needs pixel pairs).
    pub fn render(
        &self,
        world: &World,
        field_from_camera_at_row: &dyn Fn(usize) -> Isometry3<f64>,
        effects: &CameraEffects,
        skip: u16,
        rng: &mut SimRng,
    ) -> Result<Rendered, FrameError> {
        self.render_moving_ball(
            world,
            field_from_camera_at_row,
            &|_| None,
            effects,
            skip,
            rng,
        )
    }

    /// [`Self::render`] with the ball's own motion during read-out: `ball_centre_at_row(r)`
    /// gives the ball's centre (field cm) while row `r` is exposed, `None` to leave it where
    /// `world` has it. A ball rolling across the view comes out sheared, as a real rolling
    /// shutter shows it.
    ///
    /// # Errors
    /// [`FrameError`] only for an odd width (UYVY needs pixel pairs).
    pub fn render_moving_ball(
        &self,
        world: &World,
        field_from_camera_at_row: &dyn Fn(usize) -> Isometry3<f64>,
        ball_centre_at_row: &dyn Fn(usize) -> Option<Vector3<f64>>,
        effects: &CameraEffects,
        skip: u16,
        rng: &mut SimRng,
    ) -> Result<Rendered, FrameError> {
        let mut moving: Option<World> = None;
        let (w, h) = (self.width, self.height);
        if !w.is_multiple_of(2) {
            return Err(FrameError::OddWidth { width: w });
        }
        let mut data = Vec::with_capacity(w * h * 2);
        let mut labels = Vec::with_capacity(w * h);
        let mut objects = Vec::with_capacity(w * h);
        let (cx, cy) = (w as f64 / 2.0, h as f64 / 2.0);
        let corner2 = cx * cx + cy * cy;
        let mut row_yuv = vec![[0.0_f64; 3]; w];
        for j in 0..h {
            if let Some(c) = ball_centre_at_row(j) {
                moving.get_or_insert_with(|| world.clone()).move_ball(c);
            }
            let world = moving.as_ref().unwrap_or(world);
            let pose = field_from_camera_at_row(j);
            let rot = pose.rotation.to_rotation_matrix().into_inner();
            let origin = pose.translation.vector;
            for (i, out) in row_yuv.iter_mut().enumerate() {
                let (colour, material, object) = match self.rays.get(j * w + i).copied().flatten() {
                    Some(ray) => world.trace(&origin, &(rot * ray), skip),
                    None => (Vector3::zeros(), Material::Ceiling, object_id::BACKGROUND),
                };
                labels.push(material.class().code());
                objects.push(object);
                let [r, g, b] = [colour.x, colour.y, colour.z];
                let mut y = 16.0 + (65.481 * r + 128.553 * g + 24.966 * b) / 255.0;
                let mut u = 128.0 + (-37.797 * r - 74.203 * g + 112.0 * b) / 255.0;
                let v = 128.0 + (112.0 * r - 93.786 * g - 18.214 * b) / 255.0;
                let (dx, dy) = (i as f64 + 0.5 - cx, j as f64 + 0.5 - cy);
                let rr = (dx * dx + dy * dy) / corner2;
                y = 16.0 + (y - 16.0) * (1.0 - effects.vignetting * rr);
                u += effects.corner_blue_u * rr;
                *out = [y, u, v];
            }
            for pair in row_yuv.chunks_exact(2) {
                let (a, b) = (pair[0], pair[1]);
                let nu = effects.noise_uv * f64::from(rng.fast_normal());
                let nv = effects.noise_uv * f64::from(rng.fast_normal());
                let y0 = a[0] + effects.noise_y * f64::from(rng.fast_normal());
                let y1 = b[0] + effects.noise_y * f64::from(rng.fast_normal());
                data.push(crate::frame::round_u8((a[1] + b[1]) / 2.0 + nu));
                data.push(crate::frame::round_u8(y0));
                data.push(crate::frame::round_u8((a[2] + b[2]) / 2.0 + nv));
                data.push(crate::frame::round_u8(y1));
            }
        }
        Ok(Rendered {
            frame: Frame::from_uyvy(w, h, data)?,
            labels,
            objects,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{BodyPose, HeadJoints, RobotPose, Transform};
    use crate::lut::ColourClass;
    use crate::sim::scene::Ball;

    fn robot_camera_pose(robot: RobotPose, joints: HeadJoints) -> Isometry3<f64> {
        let t: Transform<crate::geometry::Field, crate::geometry::Camera> = BodyPose::ERS7_STANCE
            .field_from_body(&robot)
            * Ers7Dimensions::ERS7.body_from_camera(&joints);
        t.isometry
    }

    #[test]
    fn ball_ahead_appears_orange_at_the_image_centre() {
        let mut scene = Scene::four_legged_2005();
        scene.ball = Some(Ball::at(60.0, 0.0));
        let world = World::compile(&scene);
        let camera = PinholeCamera::ers7();
        let renderer = Renderer::pinhole(&camera);
        // Aim the camera at the ball: camera ~20 cm up, ball centre 4.25 cm up, ~45 cm ahead.
        let joints = HeadJoints {
            tilt1_rad: -0.25,
            pan_rad: 0.0,
            tilt2_rad: -0.1,
        };
        let pose = robot_camera_pose(RobotPose::default(), joints);
        let out = renderer
            .render(
                &world,
                &|_| pose,
                &CameraEffects::NONE,
                0,
                &mut SimRng::new(1),
            )
            .expect("render");
        let orange = out
            .labels
            .iter()
            .filter(|&&c| c == ColourClass::Orange.code())
            .count();
        assert!(orange > 100, "{orange} orange pixels");
        let ball_px = out
            .objects
            .iter()
            .filter(|&&o| o == object_id::BALL)
            .count();
        assert_eq!(ball_px, orange);
        // The carpet fills most of the rest.
        let green = out
            .labels
            .iter()
            .filter(|&&c| c == ColourClass::Green.code())
            .count();
        assert!(green > 208 * 160 / 3, "{green}");
        // Orange pixels look orange: V high, U low.
        let ball: Vec<usize> = out
            .objects
            .iter()
            .enumerate()
            .filter(|(_, o)| **o == object_id::BALL)
            .map(|(k, _)| k)
            .collect();
        let p = ball[ball.len() / 2];
        let yuv = out.frame.pixel(p % 208, p / 208).expect("in image");
        assert!(yuv.v > 150 && yuv.u < 110 && yuv.v > yuv.u + 40, "{yuv:?}");
    }

    #[test]
    fn a_ball_moving_during_readout_comes_out_sheared() {
        let mut scene = Scene::four_legged_2005();
        scene.ball = Some(Ball::at(60.0, 0.0));
        let world = World::compile(&scene);
        let renderer = Renderer::pinhole(&PinholeCamera::ers7());
        let joints = HeadJoints {
            tilt1_rad: -0.25,
            pan_rad: 0.0,
            tilt2_rad: -0.1,
        };
        let pose = robot_camera_pose(RobotPose::default(), joints);
        let render = |ball_at: &dyn Fn(usize) -> Option<Vector3<f64>>| {
            renderer
                .render_moving_ball(
                    &world,
                    &|_| pose,
                    ball_at,
                    &CameraEffects::NONE,
                    0,
                    &mut SimRng::new(1),
                )
                .expect("render")
        };
        // Leftmost ball column of each row that shows the ball.
        let left_edges = |objects: &[u16]| -> Vec<(usize, usize)> {
            (0..160)
                .filter_map(|y| {
                    (0..208)
                        .find(|&x| objects[y * 208 + x] == object_id::BALL)
                        .map(|x| (y, x))
                })
                .collect()
        };
        let still = render(&|_| None);
        assert_eq!(
            still.objects,
            render(&|_| Some(Vector3::new(60.0, 0.0, 4.25))).objects
        );
        // The ball rolls to the right (−y) by 0.1 cm per row read.
        let moving = render(&|row| Some(Vector3::new(60.0, -0.1 * (row as f64 - 80.0), 4.25)));
        let (a, b) = (left_edges(&still.objects), left_edges(&moving.objects));
        let (top_a, bottom_a) = (a[0].1, a[a.len() - 1].1);
        let (top_b, bottom_b) = (b[0].1, b[b.len() - 1].1);
        // Rows read later see it further right: the left edge leans.
        let lean_still = bottom_a as i64 - top_a as i64;
        let lean_moving = bottom_b as i64 - top_b as i64;
        assert!(
            lean_moving >= lean_still + 4,
            "{lean_still} vs {lean_moving}"
        );
    }

    #[test]
    fn rendering_is_deterministic_for_a_seed() {
        let world = World::compile(&Scene::four_legged_2005());
        let renderer = Renderer::pinhole(&PinholeCamera::ers7());
        let pose = robot_camera_pose(RobotPose::new(-100.0, 0.0, 0.0), HeadJoints::default());
        let a = renderer
            .render(
                &world,
                &|_| pose,
                &CameraEffects::ERS7,
                0,
                &mut SimRng::new(5),
            )
            .expect("render");
        let b = renderer
            .render(
                &world,
                &|_| pose,
                &CameraEffects::ERS7,
                0,
                &mut SimRng::new(5),
            )
            .expect("render");
        let c = renderer
            .render(
                &world,
                &|_| pose,
                &CameraEffects::ERS7,
                0,
                &mut SimRng::new(6),
            )
            .expect("render");
        assert_eq!(a.frame, b.frame);
        assert_ne!(a.frame, c.frame);
        assert_eq!(a.labels, c.labels);
    }

    #[test]
    fn ground_paint_follows_the_field_lines() {
        let world = World::compile(&Scene::four_legged_2005());
        assert_eq!(world.ground_material(0.0, 100.0), Material::Line);
        assert_eq!(world.ground_material(50.0, 100.0), Material::Carpet);
        assert_eq!(world.ground_material(18.0, 0.0), Material::Line);
        assert_eq!(world.ground_material(269.0, 10.0), Material::Line);
        assert_eq!(world.ground_material(100.0, 179.0), Material::Line);
        assert_eq!(world.ground_material(100.0, 190.0), Material::Carpet);
        assert_eq!(world.ground_material(320.0, 0.0), Material::Floor);
    }

    #[test]
    fn overhead_sees_the_whole_carpet() {
        let camera = OverheadCamera::above_field_2005();
        let renderer = Renderer::overhead(&camera);
        let world = World::compile(&Scene::four_legged_2005());
        let pose = camera.field_from_camera().isometry;
        let out = renderer
            .render(
                &world,
                &|_| pose,
                &CameraEffects::NONE,
                0,
                &mut SimRng::new(1),
            )
            .expect("render");
        assert_eq!(out.frame.width(), 640);
        let green = out
            .labels
            .iter()
            .filter(|&&c| c == ColourClass::Green.code())
            .count();
        assert!(green > 640 * 480 / 2, "{green}");
        // The ball at the centre spot is at the image centre.
        assert_eq!(out.objects[240 * 640 + 320], object_id::BALL);
        // Both goals appear.
        assert!(out.objects.contains(&object_id::YELLOW_GOAL));
        assert!(out.objects.contains(&object_id::SKY_BLUE_GOAL));
    }
}
