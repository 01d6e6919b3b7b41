//! [`World`]: a scene compiled into objects, and what a ray from the camera sees in it — the
//! nearest object or the analytic ground, walls and ceiling, lit by the lamp, in shadow or not.

use nalgebra::Vector3;

use super::object_id;
use super::shapes::{
    Object, Prim, ball_object, beacon_object, bound_hit, clutter_object, goal_object, intersect,
    marker_parts, marker_plate, object, paint_at, robot_parts,
};
use crate::model::scene::{GoalColour, Lighting, Material, Scene};

/// A scene turned into primitives, ready to render many times (compile once per scene state).
#[derive(Debug, Clone)]
pub struct World {
    objects: Vec<Object>,
    field: crate::model::scene::FieldSpec,
    room: crate::model::scene::RoomSpec,
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
            objects.push(ball_object(&ball));
        }
        for colour in [GoalColour::Yellow, GoalColour::SkyBlue] {
            objects.push(goal_object(&scene.field, colour));
        }
        for (i, b) in scene.beacons.iter().enumerate() {
            objects.push(beacon_object(i, b));
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
            objects.push(clutter_object(i, c));
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
    pub(super) fn trace(
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
