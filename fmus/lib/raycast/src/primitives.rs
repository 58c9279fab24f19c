//! Exact ray intersection with the analytic primitives (oriented box, finite capped cylinder,
//! sphere), precomputed per object in the form the inner loop wants.
//!
//! Semantics, for every shape: the hit is the first crossing of the shape's *surface* with
//! `t` in `[tmin, tmax]` — so a ray starting inside a solid reports where it leaves it — and
//! the normal is the outward surface normal there (not flipped toward the ray).

use agrisim_math::vec3::{dot, mat_t_vec, mat_vec, sub, transpose, IDENTITY};
use agrisim_scene::{Object, Shape};

/// An object ready for intersection: centre, map->local rotation (rows of R^T), sizes.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Prim {
    Sphere {
        c: [f64; 3],
        r: f64,
    },
    /// Box with identity rotation (floor, walls, gutters, most obstacles): no transform.
    AaBox {
        c: [f64; 3],
        half: [f64; 3],
    },
    /// Cylinder whose axis is map axis `axis` (stems, posts, heating pipes): no transform.
    AxisCylinder {
        c: [f64; 3],
        axis: usize,
        r: f64,
        h: f64,
    },
    Box {
        c: [f64; 3],
        rt: [[f64; 3]; 3],
        half: [f64; 3],
    },
    Cylinder {
        c: [f64; 3],
        rt: [[f64; 3]; 3],
        r: f64,
        h: f64,
    },
}

impl Prim {
    /// A primitive no ray within a greenhouse's reach meets: a point 1.7e9 m away (a moved
    /// object's place in the tree it was built in, see `moved`).
    pub(crate) const NEVER: Prim = Prim::Sphere { c: [1e9; 3], r: 0.0 };

    pub(crate) fn from_object(o: &Object) -> Prim {
        let c = o.placement.translation;
        match o.shape {
            Shape::Sphere { radius } => Prim::Sphere { c, r: radius },
            Shape::Box { half } => {
                let m = o.placement.matrix();
                if m == IDENTITY {
                    Prim::AaBox { c, half }
                } else {
                    Prim::Box { c, rt: transpose(&m), half }
                }
            }
            Shape::Cylinder { radius, half_height } => {
                let m = o.placement.matrix();
                // The local z axis (third column) along a map axis, exactly (up to sign).
                let col = [m[0][2], m[1][2], m[2][2]];
                match (0..3).find(|&k| col[k].abs() == 1.0 && col[(k + 1) % 3] == 0.0 && col[(k + 2) % 3] == 0.0) {
                    Some(axis) => Prim::AxisCylinder { c, axis, r: radius, h: half_height },
                    None => Prim::Cylinder { c, rt: transpose(&m), r: radius, h: half_height },
                }
            }
        }
    }

    /// First surface crossing along `o + t d` with `t` in `[tmin, tmax]`: (t, outward normal).
    #[inline]
    pub(crate) fn intersect(&self, o: [f64; 3], d: [f64; 3], tmin: f64, tmax: f64) -> Option<(f64, [f64; 3])> {
        self.local_hit(self.local_origin(o), self.local_dir(d), tmin, tmax)
    }

    /// The primitive as rays from `o` see it: `o` taken into its frame once for all of them
    /// (the rays of a camera tile share their origin).
    #[inline(always)]
    pub(crate) fn seen_from(&self, o: [f64; 3]) -> Seen<'_> {
        Seen { prim: self, lo: self.local_origin(o) }
    }

    /// The primitive as rays along `d` see it: `d` taken into its frame once for all of them
    /// (shadow rays toward the sun).
    #[inline(always)]
    pub(crate) fn along(&self, d: [f64; 3]) -> Along<'_> {
        Along { prim: self, ld: self.local_dir(d) }
    }

    /// A map point in the primitive's frame (centred; rotated for the rotated shapes).
    #[inline(always)]
    fn local_origin(&self, o: [f64; 3]) -> [f64; 3] {
        match *self {
            Prim::Sphere { c, .. } | Prim::AaBox { c, .. } | Prim::AxisCylinder { c, .. } => sub(o, c),
            Prim::Box { c, ref rt, .. } | Prim::Cylinder { c, ref rt, .. } => mat_vec(rt, sub(o, c)),
        }
    }

    /// A map direction in the primitive's frame.
    #[inline(always)]
    fn local_dir(&self, d: [f64; 3]) -> [f64; 3] {
        match *self {
            Prim::Sphere { .. } | Prim::AaBox { .. } | Prim::AxisCylinder { .. } => d,
            Prim::Box { ref rt, .. } | Prim::Cylinder { ref rt, .. } => mat_vec(rt, d),
        }
    }

    /// The crossing of a ray given in the primitive's frame, normal back in the map.
    #[inline(always)]
    fn local_hit(&self, lo: [f64; 3], ld: [f64; 3], tmin: f64, tmax: f64) -> Option<(f64, [f64; 3])> {
        match *self {
            Prim::Sphere { r, .. } => sphere(lo, r, ld, tmin, tmax),
            Prim::AaBox { half, .. } => box_local(half, lo, ld, tmin, tmax),
            Prim::Box { ref rt, half, .. } => {
                let (t, n) = box_local(half, lo, ld, tmin, tmax)?;
                Some((t, mat_t_vec(rt, n)))
            }
            Prim::AxisCylinder { axis, r, h, .. } => {
                // Swizzle so the axis is local z: (u, v, w) = (axis + 1, axis + 2, axis), a
                // cyclic permutation (a proper rotation).
                let (i, j) = ((axis + 1) % 3, (axis + 2) % 3);
                let (t, n) = cylinder_local(r, h, [lo[i], lo[j], lo[axis]], [ld[i], ld[j], ld[axis]], tmin, tmax)?;
                Some((
                    t,
                    [0, 1, 2].map(|k| {
                        if k == axis {
                            n[2]
                        } else if k == i {
                            n[0]
                        } else {
                            n[1]
                        }
                    }),
                ))
            }
            Prim::Cylinder { ref rt, r, h, .. } => {
                let (t, n) = cylinder_local(r, h, lo, ld, tmin, tmax)?;
                Some((t, mat_t_vec(rt, n)))
            }
        }
    }
}

/// A primitive and a ray origin in its frame (see [`Prim::seen_from`]).
#[derive(Clone, Copy)]
pub(crate) struct Seen<'a> {
    prim: &'a Prim,
    lo: [f64; 3],
}

impl Seen<'_> {
    /// [`Prim::intersect`] from the origin this was made for.
    #[inline(always)]
    pub(crate) fn intersect(&self, d: [f64; 3], tmin: f64, tmax: f64) -> Option<(f64, [f64; 3])> {
        self.prim.local_hit(self.lo, self.prim.local_dir(d), tmin, tmax)
    }
}

/// A primitive and a ray direction in its frame (see [`Prim::along`]).
#[derive(Clone, Copy)]
pub(crate) struct Along<'a> {
    prim: &'a Prim,
    ld: [f64; 3],
}

impl Along<'_> {
    /// [`Prim::intersect`] along the direction this was made for.
    #[inline(always)]
    pub(crate) fn intersect(&self, o: [f64; 3], tmin: f64, tmax: f64) -> Option<(f64, [f64; 3])> {
        self.prim.local_hit(self.prim.local_origin(o), self.ld, tmin, tmax)
    }
}

/// Sphere centred at the origin, ray origin `oc` relative to its centre.
#[inline]
fn sphere(oc: [f64; 3], r: f64, d: [f64; 3], tmin: f64, tmax: f64) -> Option<(f64, [f64; 3])> {
    let a = dot(d, d);
    let b = dot(oc, d);
    let cc = dot(oc, oc) - r * r;
    let disc = b * b - a * cc;
    if disc < 0.0 {
        return None;
    }
    let s = disc.sqrt();
    // Numerically stable roots (avoid cancellation in -b +- s).
    let q = if b > 0.0 { -(b + s) } else { -b + s };
    let (mut t0, mut t1) = if q != 0.0 { (q / a, cc / q) } else { (0.0, 0.0) };
    if t0 > t1 {
        std::mem::swap(&mut t0, &mut t1);
    }
    let t = if t0 >= tmin && t0 <= tmax {
        t0
    } else if t1 >= tmin && t1 <= tmax {
        t1
    } else {
        return None;
    };
    let inv = 1.0 / r;
    Some((t, [(oc[0] + t * d[0]) * inv, (oc[1] + t * d[1]) * inv, (oc[2] + t * d[2]) * inv]))
}

/// Box centred at the origin, axis-aligned, ray in its frame.
#[inline(always)]
fn box_local(half: [f64; 3], lo: [f64; 3], ld: [f64; 3], tmin: f64, tmax: f64) -> Option<(f64, [f64; 3])> {
    let (mut tn, mut tf) = (f64::NEG_INFINITY, f64::INFINITY);
    let (mut an, mut af) = (usize::MAX, usize::MAX);
    for i in 0..3 {
        if ld[i] == 0.0 {
            if lo[i].abs() > half[i] {
                return None;
            }
            continue;
        }
        let inv = 1.0 / ld[i];
        let mut t1 = (-half[i] - lo[i]) * inv;
        let mut t2 = (half[i] - lo[i]) * inv;
        if t1 > t2 {
            std::mem::swap(&mut t1, &mut t2);
        }
        if t1 > tn {
            tn = t1;
            an = i;
        }
        if t2 < tf {
            tf = t2;
            af = i;
        }
    }
    if tn > tf {
        return None;
    }
    let (t, axis, sign) = if tn >= tmin && tn <= tmax && an != usize::MAX {
        (tn, an, -ld[an].signum())
    } else if tf >= tmin && tf <= tmax && af != usize::MAX {
        (tf, af, ld[af].signum())
    } else {
        return None;
    };
    // Built by selects: a store at a variable index, read back as a vector, stalled the
    // store forwarding on every hit.
    Some((t, [0, 1, 2].map(|k| if k == axis { sign } else { 0.0 })))
}

/// Cylinder centred at the origin along z, ray in its frame.
#[inline(always)]
fn cylinder_local(r: f64, h: f64, lo: [f64; 3], ld: [f64; 3], tmin: f64, tmax: f64) -> Option<(f64, [f64; 3])> {
    let mut best = f64::INFINITY;
    let mut n = [0.0; 3];
    // Side: (ox + t dx)^2 + (oy + t dy)^2 = r^2, |z| <= h.
    let a = ld[0] * ld[0] + ld[1] * ld[1];
    if a > 0.0 {
        let b = lo[0] * ld[0] + lo[1] * ld[1];
        let cc = lo[0] * lo[0] + lo[1] * lo[1] - r * r;
        let disc = b * b - a * cc;
        if disc >= 0.0 {
            let s = disc.sqrt();
            let q = if b > 0.0 { -(b + s) } else { -b + s };
            if q != 0.0 {
                for t in [q / a, cc / q] {
                    if t >= tmin && t <= tmax && t < best {
                        let z = lo[2] + t * ld[2];
                        if z.abs() <= h {
                            best = t;
                            n = [(lo[0] + t * ld[0]) / r, (lo[1] + t * ld[1]) / r, 0.0];
                        }
                    }
                }
            }
        }
    }
    // Caps: z = +-h, x^2 + y^2 <= r^2.
    if ld[2] != 0.0 {
        let inv = 1.0 / ld[2];
        for sz in [-1.0, 1.0] {
            let t = (sz * h - lo[2]) * inv;
            if t >= tmin && t <= tmax && t < best {
                let x = lo[0] + t * ld[0];
                let y = lo[1] + t * ld[1];
                if x * x + y * y <= r * r {
                    best = t;
                    n = [0.0, 0.0, sz];
                }
            }
        }
    }
    if best.is_finite() {
        Some((best, n))
    } else {
        None
    }
}
