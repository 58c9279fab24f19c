//! Exact check of a path: parry3d shapes of the URDF link primitives (not the spheres) against
//! the environment, the fixed body, the other arm and the arm itself (same allowed-collision
//! matrix), at a fine joint resolution. It is the final word on a plan: the spheres are
//! conservative, so a path that passes the sphere checker at its samples normally passes this
//! one; what it can catch is motion between the coarser samples of the planner's edges.

use crate::chain::ArmModel;
use crate::checker::{lerp, object_contact, steps, Contact, Context, Hit, HELD};
use crate::layout::{join, DOF, HAND, NBODIES};
use crate::prim::Prim;
use agrisim_robot::Shape;
use nalgebra::{Isometry3, Point3, UnitQuaternion, Vector3};
use parry3d::math::{Pose as PPose, Rotation, Vector as PVec};
use parry3d::query::intersection_test;
use parry3d::shape::{Ball, Capsule, Cuboid, Cylinder, SharedShape};

/// Default resolution of [`exact_check`]: 0.5 degree per joint between samples.
pub const EXACT_RESOLUTION: f64 = 0.5 * std::f64::consts::PI / 180.0;

/// The first contact along a path.
#[derive(Debug, Clone, PartialEq)]
pub struct PathContact {
    pub contact: Contact,
    /// `body / other` names.
    pub description: String,
    /// The configuration in contact.
    pub q: [f64; DOF],
    /// Index of the path segment (waypoint i -> i + 1) it lies on.
    pub segment: usize,
}

/// A parry shape with its frame relative to its owner (link or world).
#[derive(Clone)]
struct Part {
    shape: SharedShape,
    local: Isometry3<f64>,
}

/// parry's cylinders and capsules are along y; URDF's along z.
fn parry_part(shape: &Shape, origin: Isometry3<f64>) -> Part {
    let y_to_z = Isometry3::rotation(Vector3::x() * std::f64::consts::FRAC_PI_2);
    match *shape {
        Shape::Box { size } => Part {
            shape: SharedShape::new(Cuboid::new(PVec::new(
                size[0] as f32 * 0.5,
                size[1] as f32 * 0.5,
                size[2] as f32 * 0.5,
            ))),
            local: origin,
        },
        Shape::Sphere { radius } => Part { shape: SharedShape::new(Ball::new(radius as f32)), local: origin },
        Shape::Cylinder { radius, length } => {
            Part { shape: SharedShape::new(Cylinder::new(length as f32 * 0.5, radius as f32)), local: origin * y_to_z }
        }
        Shape::Capsule { radius, length } => {
            Part { shape: SharedShape::new(Capsule::new_z(length as f32 * 0.5, radius as f32)), local: origin }
        }
    }
}

pub(crate) fn to_parry(i: &Isometry3<f64>) -> PPose {
    let q: &UnitQuaternion<f64> = &i.rotation;
    let t = i.translation.vector;
    PPose::from_parts(
        PVec::new(t.x as f32, t.y as f32, t.z as f32),
        Rotation::from_xyzw(q.i as f32, q.j as f32, q.k as f32, q.w as f32).normalize(),
    )
}

fn touch(a: &Part, pa: &Isometry3<f64>, b: &Part, pb: &Isometry3<f64>) -> bool {
    // Every primitive pair is supported by parry's default dispatcher; treat the
    // impossible "unsupported" as contact (safe side).
    intersection_test(&to_parry(&(pa * a.local)), &*a.shape, &to_parry(&(pb * b.local)), &*b.shape)
        .map_or(true, |r| r.intersecting)
}

/// The arm's link primitives as parry shapes, per body.
fn arm_parts(arm: &ArmModel) -> Vec<Vec<Part>> {
    arm.colliders
        .iter()
        .map(|cs| cs.iter().map(|c| parry_part(&c.shape, crate::iso::to_iso(&c.origin))).collect())
        .collect()
}

/// Exact contact at one configuration, or `None`.
pub fn exact_contact(ctx: &Context, q: &[f64; DOF]) -> Option<Contact> {
    Exact::new(ctx).contact(q)
}

/// Checks the joint-space polyline `path` at `resolution` (max joint step, rad; use
/// [`EXACT_RESOLUTION`]) and returns the first contact (no padding: real geometry).
pub fn exact_check(ctx: &Context, path: &[[f64; DOF]], resolution: f64) -> Result<(), PathContact> {
    let ex = Exact::new(ctx);
    let report =
        |c: Contact, q: [f64; DOF], segment| PathContact { contact: c, description: c.describe(ctx), q, segment };
    if let Some(q) = path.first() {
        if let Some(c) = ex.contact(q) {
            return Err(report(c, *q, 0));
        }
    }
    for (i, w) in path.windows(2).enumerate() {
        let n = steps(&w[0], &w[1], resolution);
        for k in 1..=n {
            let q = lerp(&w[0], &w[1], k as f64 / n as f64);
            if let Some(c) = ex.contact(&q) {
                return Err(report(c, q, i));
            }
        }
    }
    Ok(())
}

/// One part of the other arm: (body, shape, body pose, body bounding sphere centre, radius).
type OtherPart = (usize, Part, Isometry3<f64>, Point3<f64>, f64);

struct Exact<'a> {
    ctx: &'a Context<'a>,
    arm: Vec<Vec<Part>>,
    body: Vec<(usize, Part, Prim)>,
    other: Vec<OtherPart>,
    objects: Vec<Part>,
    /// The other arm's held sphere in the world.
    other_held: Option<(Part, Isometry3<f64>)>,
}

fn ball(r: f64) -> Part {
    Part { shape: SharedShape::new(Ball::new(r as f32)), local: Isometry3::identity() }
}

impl<'a> Exact<'a> {
    fn new(ctx: &'a Context<'a>) -> Exact<'a> {
        let arm = arm_parts(ctx.arm);
        let body = ctx
            .arm
            .body
            .iter()
            .enumerate()
            .map(|(i, p)| (i, parry_part(&p.collider.shape, p.pose(ctx.lift)), p.prim(ctx.lift)))
            .collect();
        let mut other = Vec::new();
        let mut other_held = None;
        if let Some(o) = &ctx.other {
            let fr = o.arm.frames_x(&join(ctx.lift, &o.q), o.finger);
            if let Some(h) = o.held {
                other_held =
                    Some((ball(h.radius), fr.tcp * Isometry3::translation(h.offset.x, h.offset.y, h.offset.z)));
            }
            for (b, parts) in arm_parts(o.arm).into_iter().enumerate() {
                let bs = &o.arm.spheres.bounds[b];
                for p in parts {
                    other.push((b, p, fr.bodies[b], fr.bodies[b] * bs.center, bs.radius));
                }
            }
        }
        let objects = ctx.scene.objects().iter().map(|o| parry_part(&o.shape, o.pose)).collect();
        Exact { ctx, arm, body, other, objects, other_held }
    }

    // Body indices are the contact's identity and index several parallel arrays at once.
    #[allow(clippy::needless_range_loop)]
    fn contact(&self, q: &[f64; DOF]) -> Option<Contact> {
        let ctx = self.ctx;
        if let Some(m) = ctx.meter {
            m.add_exact_check();
        }
        let a = ctx.arm;
        let fr = a.frames_x(&join(ctx.lift, q), ctx.finger);
        let pose = &fr.bodies;
        // Culling with the bounding spheres, which contain the bodies.
        let bound: [(Point3<f64>, f64); NBODIES] =
            std::array::from_fn(|b| (pose[b] * a.spheres.bounds[b].center, a.spheres.bounds[b].radius));
        let near = |x: &(Point3<f64>, f64), c: &Point3<f64>, r: f64| (x.0 - c).norm() <= x.1 + r;
        for x in 0..NBODIES {
            for y in x + 1..NBODIES {
                if a.acm.pair[x][y]
                    && near(&bound[x], &bound[y].0, bound[y].1)
                    && self.arm[x].iter().any(|p| self.arm[y].iter().any(|r| touch(p, &pose[x], r, &pose[y])))
                {
                    return Some(Contact { body: x, hit: Hit::SelfBody(y) });
                }
            }
        }
        let id = Isometry3::identity();
        for (i, part, prim) in &self.body {
            for b in 0..NBODIES {
                if a.acm.body[*i][b]
                    && prim.overlaps_sphere(&bound[b].0, bound[b].1)
                    && self.arm[b].iter().any(|p| touch(p, &pose[b], part, &id))
                {
                    return Some(Contact { body: b, hit: Hit::RobotBody(*i) });
                }
            }
        }
        for (ob, part, opose, oc, or) in &self.other {
            for b in 0..NBODIES {
                if near(&bound[b], oc, *or) && self.arm[b].iter().any(|p| touch(p, &pose[b], part, opose)) {
                    return Some(Contact { body: b, hit: Hit::OtherArm(*ob) });
                }
            }
        }
        // Environment: the scene's grid, queried with the body's bounding sphere (which
        // contains the body because the sphere model does).
        for b in 0..NBODIES {
            let bs = &a.spheres.bounds[b];
            let c = pose[b] * bs.center;
            let hit = object_contact(ctx.scene, b, &c, bs.radius, |i| {
                self.arm[b].iter().any(|p| touch(p, &pose[b], &self.objects[i], &id))
            });
            if hit.is_some() {
                return hit;
            }
        }
        if let Some((oh, opose)) = &self.other_held {
            for b in 0..HAND {
                if self.arm[b].iter().any(|p| touch(p, &pose[b], oh, opose)) {
                    return Some(Contact { body: b, hit: Hit::OtherArm(HELD) });
                }
            }
        }
        if let Some(h) = ctx.held {
            let hp = fr.tcp * Isometry3::translation(h.offset.x, h.offset.y, h.offset.z);
            let f = ball(h.radius);
            for b in 0..HAND {
                if self.arm[b].iter().any(|p| touch(&f, &hp, p, &pose[b])) {
                    return Some(Contact { body: HELD, hit: Hit::SelfBody(b) });
                }
            }
            for (i, part, _) in &self.body {
                if touch(&f, &hp, part, &id) {
                    return Some(Contact { body: HELD, hit: Hit::RobotBody(*i) });
                }
            }
            for (ob, part, opose, _, _) in &self.other {
                if *ob < HAND && touch(&f, &hp, part, opose) {
                    return Some(Contact { body: HELD, hit: Hit::OtherArm(*ob) });
                }
            }
            let c = Point3::from(hp.translation.vector);
            return object_contact(ctx.scene, HELD, &c, h.radius, |i| touch(&f, &hp, &self.objects[i], &id));
        }
        None
    }
}
