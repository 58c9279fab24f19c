//! Fast configuration validity for one arm: its sphere model against itself (allowed-collision
//! matrix), the robot's fixed body, the other arm (spheres at its given configuration) and the
//! environment (closed-form sphere-primitive tests behind the scene's grid). A check is a few
//! microseconds, which is what the RRT's inner loop needs.

use crate::chain::{world_spheres, ArmModel};
use crate::layout::{BODY_NAMES, DOF, HAND, NBODIES};
use crate::prim::Prim;
use crate::scene::{ObstacleKind, Scene};
use crate::spheres::{bodies_touch, spheres_touch};
use nalgebra::{Point3, Vector3};
use std::cell::Cell;

/// A grasped fruit, modelled as a sphere fixed to the TCP. It must not touch the
/// environment (except `Soft` and `Target` objects: the fruit itself may still be in the
/// scene as `Target`), the fixed body, the arm links (link0..link7) or the other arm's links;
/// the hands and fingers of both arms may touch it (grasp and handover).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Held {
    pub radius: f64,
    /// Sphere centre in the TCP frame (usually zero).
    pub offset: Vector3<f64>,
}

/// `Contact::body` of the held object (one past the arm bodies).
pub const HELD: usize = NBODIES;

/// The other arm, frozen at a configuration (it is an obstacle while this arm moves).
#[derive(Debug, Clone, Copy)]
pub struct OtherArm<'a> {
    pub arm: &'a ArmModel,
    pub q: [f64; DOF],
    /// Finger opening (m, per finger).
    pub finger: f64,
    /// What the other arm holds.
    pub held: Option<Held>,
}

/// Everything a collision check of one arm depends on.
#[derive(Debug, Clone, Copy)]
pub struct Context<'a> {
    /// The arm that moves.
    pub arm: &'a ArmModel,
    /// Lift height (m); both arms are on the lift.
    pub lift: f64,
    /// This arm's finger opening (m, per finger, 0..0.04).
    pub finger: f64,
    /// What this arm holds.
    pub held: Option<Held>,
    pub other: Option<OtherArm<'a>>,
    pub scene: &'a Scene,
    /// Safety margin (m) added to this arm's spheres against the environment, the fixed
    /// body and the other arm (not against itself). It also covers the motion between
    /// discretised edge samples, so the exact check of the final path rarely fails.
    pub padding: f64,
    /// Where checks are counted (planning work charged in simulated time), if anywhere.
    pub meter: Option<&'a crate::Meter>,
}

/// Default padding (m).
pub const DEFAULT_PADDING: f64 = 0.01;

impl<'a> Context<'a> {
    /// This arm alone in `scene` at `lift`, fingers open, default padding.
    pub fn new(arm: &'a ArmModel, lift: f64, scene: &'a Scene) -> Context<'a> {
        Context {
            arm,
            lift,
            finger: arm.finger_limits.upper,
            held: None,
            other: None,
            scene,
            padding: DEFAULT_PADDING,
            meter: None,
        }
    }
    pub fn with_other(mut self, arm: &'a ArmModel, q: [f64; DOF], finger: f64) -> Context<'a> {
        self.other = Some(OtherArm { arm, q, finger, held: None });
        self
    }
    /// This arm holds a sphere of `radius` at its TCP (fingers closed on it: set `finger`).
    pub fn holding(mut self, radius: f64) -> Context<'a> {
        self.held = Some(Held { radius, offset: Vector3::zeros() });
        self
    }
    /// The other arm (set by [`Context::with_other`]) holds a sphere of `radius` at its TCP.
    pub fn other_holding(mut self, radius: f64) -> Context<'a> {
        if let Some(o) = &mut self.other {
            o.held = Some(Held { radius, offset: Vector3::zeros() });
        }
        self
    }
}

/// What a body touched.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Hit {
    /// Another body of the same arm (index into [`BODY_NAMES`]).
    SelfBody(usize),
    /// A fixed-body part (index into [`ArmModel::body`]).
    RobotBody(usize),
    /// A body of the other arm.
    OtherArm(usize),
    /// An environment object (index into [`Scene::objects`]).
    Object(usize),
}

/// A contact: body `body` of the moving arm touches `hit`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Contact {
    pub body: usize,
    pub hit: Hit,
}

impl Contact {
    /// Human-readable names, e.g. `left_hand / object "stem_3"`.
    pub fn describe(&self, ctx: &Context) -> String {
        let p = ctx.arm.side.prefix();
        let name = |b: usize| BODY_NAMES.get(b).copied().unwrap_or("held_object");
        let what = match self.hit {
            Hit::SelfBody(b) => format!("{p}{}", name(b)),
            Hit::RobotBody(i) => format!("robot body {}", ctx.arm.body[i].name),
            Hit::OtherArm(b) => format!("{}{}", ctx.arm.side.other().prefix(), name(b)),
            Hit::Object(i) => format!("object \"{}\"", ctx.scene.objects()[i].name),
        };
        format!("{p}{} / {what}", name(self.body))
    }
}

/// The fast checker of one [`Context`]: everything that does not depend on this arm's
/// configuration is precomputed.
pub struct Checker<'a> {
    pub ctx: Context<'a>,
    body: Vec<(usize, Prim)>,
    other: Vec<(Point3<f64>, f64)>,
    other_bounds: [(Point3<f64>, f64); NBODIES],
    /// Every fixed-body part (the held object is checked against all of them).
    body_all: Vec<Prim>,
    other_held: Option<(Point3<f64>, f64)>,
    self_pairs: Vec<(usize, usize)>,
    checks: Cell<u64>,
    buf: std::cell::RefCell<Vec<(Point3<f64>, f64)>>,
}

impl<'a> Checker<'a> {
    pub fn new(ctx: Context<'a>) -> Checker<'a> {
        let arm = ctx.arm;
        let body = arm
            .body
            .iter()
            .enumerate()
            .filter(|(i, _)| arm.acm.body[*i].iter().any(|&e| e))
            .map(|(i, p)| (i, p.prim(ctx.lift)))
            .collect();
        let mut other = Vec::new();
        let (other_bounds, other_held) = match &ctx.other {
            Some(o) => {
                let (b, tcp) = world_spheres(o.arm, ctx.lift, &o.q, o.finger, &mut other);
                (b, o.held.map(|h| (tcp * Point3::from(h.offset), h.radius)))
            }
            None => ([(Point3::origin(), -1.0); NBODIES], None),
        };
        let body_all = arm.body.iter().map(|p| p.prim(ctx.lift)).collect();
        let mut self_pairs = Vec::new();
        for a in 0..NBODIES {
            for b in a + 1..NBODIES {
                if arm.acm.pair[a][b] {
                    self_pairs.push((a, b));
                }
            }
        }
        Checker {
            ctx,
            body,
            other,
            other_bounds,
            body_all,
            other_held,
            self_pairs,
            checks: Cell::new(0),
            buf: Default::default(),
        }
    }

    /// Number of configuration checks so far (statistics).
    pub fn checks(&self) -> u64 {
        self.checks.get()
    }

    /// Within limits and collision-free.
    pub fn is_valid(&self, q: &[f64; DOF]) -> bool {
        self.ctx.arm.within_limits(q) && self.contact(q).is_none()
    }

    /// The first contact found at `q` (search order: self, fixed body, other arm,
    /// environment), or `None`.
    // Body indices are the contact's identity and index several parallel arrays at once.
    #[allow(clippy::needless_range_loop)]
    pub fn contact(&self, q: &[f64; DOF]) -> Option<Contact> {
        self.checks.set(self.checks.get() + 1);
        if let Some(m) = self.ctx.meter {
            m.add_check();
        }
        let ctx = &self.ctx;
        let arm = ctx.arm;
        let pad = ctx.padding;
        let mut buf = self.buf.borrow_mut();
        let (bounds, tcp) = world_spheres(arm, ctx.lift, q, ctx.finger, &mut buf);
        let s = &buf[..];
        let off = &arm.spheres.offsets;
        let rng = |b: usize| off[b]..off[b + 1];
        for &(a, b) in &self.self_pairs {
            if spheres_touch(&bounds[a], &bounds[b], 0.0) && bodies_touch(s, rng(a), s, rng(b), 0.0) {
                return Some(Contact { body: a, hit: Hit::SelfBody(b) });
            }
        }
        for (i, p) in &self.body {
            let en = &arm.acm.body[*i];
            for b in 0..NBODIES {
                if en[b]
                    && p.overlaps_sphere(&bounds[b].0, bounds[b].1 + pad)
                    && s[rng(b)].iter().any(|(c, r)| p.overlaps_sphere(c, r + pad))
                {
                    return Some(Contact { body: b, hit: Hit::RobotBody(*i) });
                }
            }
        }
        if let Some(c) = self.links_contact(s, &bounds) {
            return Some(c);
        }
        let scene = ctx.scene;
        for b in 0..NBODIES {
            let (c, r) = (&bounds[b].0, bounds[b].1 + pad);
            let hit = object_contact(scene, b, c, r, |i| {
                let p = scene.prim(i);
                p.overlaps_sphere(c, r) && s[rng(b)].iter().any(|(c, r)| p.overlaps_sphere(c, r + pad))
            });
            if hit.is_some() {
                return hit;
            }
        }
        if let Some(h) = ctx.held {
            let fruit = [(tcp * Point3::from(h.offset), h.radius)];
            if let Some(c) = self.held_contact(&fruit[0], s, &bounds) {
                return Some(c);
            }
        }
        self.other_held_contact(s, &bounds)
    }

    /// The first contact at `q` between the two arms alone (links, and what each holds), or
    /// `None`: for checking two motions against each other, each already checked against
    /// everything else.
    pub fn arms_contact(&self, q: &[f64; DOF]) -> Option<Contact> {
        self.checks.set(self.checks.get() + 1);
        if let Some(m) = self.ctx.meter {
            m.add_check();
        }
        let ctx = &self.ctx;
        let mut buf = self.buf.borrow_mut();
        let (bounds, tcp) = world_spheres(ctx.arm, ctx.lift, q, ctx.finger, &mut buf);
        let s = &buf[..];
        if let Some(c) = self.links_contact(s, &bounds) {
            return Some(c);
        }
        if let Some(h) = ctx.held {
            let fruit = (tcp * Point3::from(h.offset), h.radius);
            if let Some(c) = self.held_other_contact(&fruit) {
                return Some(c);
            }
        }
        self.other_held_contact(s, &bounds)
    }

    /// This arm's links against the other arm's.
    fn links_contact(&self, s: &[(Point3<f64>, f64)], bounds: &[(Point3<f64>, f64); NBODIES]) -> Option<Contact> {
        let o = self.ctx.other.as_ref()?;
        let (pad, off, ooff) = (self.ctx.padding, &self.ctx.arm.spheres.offsets, &o.arm.spheres.offsets);
        for a in 0..NBODIES {
            for b in 0..NBODIES {
                if spheres_touch(&bounds[a], &self.other_bounds[b], pad)
                    && bodies_touch(s, off[a]..off[a + 1], &self.other, ooff[b]..ooff[b + 1], pad)
                {
                    return Some(Contact { body: a, hit: Hit::OtherArm(b) });
                }
            }
        }
        None
    }

    /// The fruit the other arm holds against this arm's links.
    fn other_held_contact(&self, s: &[(Point3<f64>, f64)], bounds: &[(Point3<f64>, f64); NBODIES]) -> Option<Contact> {
        let f = self.other_held.as_ref()?;
        let (pad, off) = (self.ctx.padding, &self.ctx.arm.spheres.offsets);
        for b in 0..HAND {
            if spheres_touch(f, &bounds[b], pad)
                && bodies_touch(std::slice::from_ref(f), 0..1, s, off[b]..off[b + 1], pad)
            {
                return Some(Contact { body: b, hit: Hit::OtherArm(HELD) });
            }
        }
        None
    }

    /// This arm's held sphere against the other arm's links.
    fn held_other_contact(&self, f: &(Point3<f64>, f64)) -> Option<Contact> {
        let o = self.ctx.other.as_ref()?;
        let (pad, ooff, one) = (self.ctx.padding, &o.arm.spheres.offsets, std::slice::from_ref(f));
        for b in 0..HAND {
            if spheres_touch(f, &self.other_bounds[b], pad)
                && bodies_touch(one, 0..1, &self.other, ooff[b]..ooff[b + 1], pad)
            {
                return Some(Contact { body: HELD, hit: Hit::OtherArm(b) });
            }
        }
        None
    }

    /// This arm's held sphere against its own links, the fixed body, the other arm's links
    /// and the environment.
    fn held_contact(
        &self,
        f: &(Point3<f64>, f64),
        s: &[(Point3<f64>, f64)],
        bounds: &[(Point3<f64>, f64); NBODIES],
    ) -> Option<Contact> {
        let ctx = &self.ctx;
        let pad = ctx.padding;
        let off = &ctx.arm.spheres.offsets;
        let one = std::slice::from_ref(f);
        for b in 0..HAND {
            if spheres_touch(f, &bounds[b], 0.0) && bodies_touch(one, 0..1, s, off[b]..off[b + 1], 0.0) {
                return Some(Contact { body: HELD, hit: Hit::SelfBody(b) });
            }
        }
        for (i, p) in self.body_all.iter().enumerate() {
            if p.overlaps_sphere(&f.0, f.1 + pad) {
                return Some(Contact { body: HELD, hit: Hit::RobotBody(i) });
            }
        }
        if let Some(c) = self.held_other_contact(f) {
            return Some(c);
        }
        let scene = ctx.scene;
        object_contact(scene, HELD, &f.0, f.1 + pad, |i| scene.prim(i).overlaps_sphere(&f.0, f.1 + pad))
    }

    /// Whether the straight joint-space segment a -> b is valid, sampled so that no joint
    /// moves more than `resolution` rad between samples (`a` itself is assumed valid).
    pub fn edge_valid(&self, a: &[f64; DOF], b: &[f64; DOF], resolution: f64) -> bool {
        let n = steps(a, b, resolution);
        (1..=n).all(|k| self.is_valid(&lerp(a, b, k as f64 / n as f64)))
    }
}

/// Whether `body` (an arm body or `HELD`) must not touch an object of this kind: solid
/// objects block everything, the target fruit only the arm links (hands and fingers grasp
/// it, a held fruit may touch it), soft ones nothing.
fn blocks(kind: ObstacleKind, body: usize) -> bool {
    match kind {
        ObstacleKind::Solid => true,
        ObstacleKind::Target => body < HAND,
        ObstacleKind::Soft => false,
    }
}

/// The first scene object near the sphere (`c`, `r`) that `body` must not touch and
/// `touches` says it does, as a contact. Shared by the sphere checker and the exact one,
/// which differ only in the narrow-phase test.
pub(crate) fn object_contact(
    scene: &Scene,
    body: usize,
    c: &Point3<f64>,
    r: f64,
    mut touches: impl FnMut(usize) -> bool,
) -> Option<Contact> {
    scene
        .near(c, r, |i| blocks(scene.objects()[i].kind, body) && touches(i))
        .map(|i| Contact { body, hit: Hit::Object(i) })
}

/// Number of segments so that no joint moves more than `resolution` per segment.
pub fn steps(a: &[f64; DOF], b: &[f64; DOF], resolution: f64) -> usize {
    let m = a.iter().zip(b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max);
    ((m / resolution).ceil() as usize).max(1)
}

pub fn lerp(a: &[f64; DOF], b: &[f64; DOF], t: f64) -> [f64; DOF] {
    std::array::from_fn(|i| a[i] + (b[i] - a[i]) * t)
}
