//! The ray caster: a BVH over the static objects (built once) plus a short list of dynamic
//! objects (robot links, placed obstacles) tested per call; nearest hits, packets, moving
//! sets and shadow rays (see the crate documentation for the guarantees).

use crate::bvh::Bvh;
use crate::packet::{traverse_packet, Packet, PacketVisit, MAX_PACKET};
use crate::primitives::{self, Prim};
use crate::wide::{self, far, traverse, Node4, Visit};
use agrisim_math::vec3::{mat_t_vec, mat_vec, sub};
use agrisim_scene::{Object, Placement};
use std::mem::MaybeUninit;

/// A ray hit: distance along the (unit) direction, the object's id, outward surface normal.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    pub distance: f64,
    pub object: u32,
    pub normal: [f64; 3],
}

/// Objects prepared for ray casting: the static scene (built once), or a frame's moving
/// objects (robot links, placed obstacles: build one per pose and pass it to
/// [`RayCaster::cast_among`], so no ray re-derives their transforms).
#[derive(Clone)]
pub struct RayCaster {
    pub(crate) nodes: Vec<Node4>,
    /// Primitives in BVH leaf order, with their object ids.
    pub(crate) prims: Vec<Prim>,
    pub(crate) ids: Vec<u32>,
    /// The primitives' exact bounding boxes (for [`RayCaster::subset`] and [`SunColumns`](crate::SunColumns)).
    pub(crate) boxes: Vec<([f64; 3], [f64; 3])>,
}

impl RayCaster {
    /// Builds the BVH over `objects` (any ids; they are reported back in [`Hit::object`]).
    pub fn new(objects: &[Object]) -> RayCaster {
        let prims: Vec<_> = objects.iter().map(Prim::from_object).collect();
        let ids: Vec<_> = objects.iter().map(|o| o.id).collect();
        let boxes: Vec<_> = objects.iter().map(Object::aabb).collect();
        RayCaster::from_prims(&prims, &ids, &boxes)
    }

    /// The tree over primitives given with their ids and bounding boxes (any order).
    fn from_prims(prims: &[Prim], ids: &[u32], boxes: &[([f64; 3], [f64; 3])]) -> RayCaster {
        let bvh = Bvh::build(boxes);
        RayCaster {
            nodes: wide::collapse(&bvh.nodes, prims.len()),
            prims: bvh.order.iter().map(|&i| prims[i as usize]).collect(),
            ids: bvh.order.iter().map(|&i| ids[i as usize]).collect(),
            boxes: bvh.order.iter().map(|&i| boxes[i as usize]).collect(),
        }
    }

    /// The objects for which `keep(id)` holds, in a tree of their own: answers for rays that
    /// only these can meet, without walking past the others.
    pub fn subset(&self, keep: impl Fn(u32) -> bool) -> RayCaster {
        let k: Vec<usize> = (0..self.prims.len()).filter(|&k| keep(self.ids[k])).collect();
        let prims: Vec<_> = k.iter().map(|&k| self.prims[k]).collect();
        let ids: Vec<_> = k.iter().map(|&k| self.ids[k]).collect();
        let boxes: Vec<_> = k.iter().map(|&k| self.boxes[k]).collect();
        RayCaster::from_prims(&prims, &ids, &boxes)
    }

    /// Number of objects.
    pub fn len(&self) -> usize {
        self.prims.len()
    }

    pub fn is_empty(&self) -> bool {
        self.prims.is_empty()
    }

    /// Number of (4-wide) BVH nodes (for diagnostics).
    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    /// Nearest hit along origin + t*dir (dir unit), t in [min, max]. `dynamic` are extra
    /// objects (moving robot links, placed obstacles) tested too, each one per ray: for more
    /// than a few, prepare them once with [`RayCaster::new`] and use [`RayCaster::cast_among`].
    /// A ray starting inside a solid reports where it leaves it.
    pub fn cast(&self, origin: [f64; 3], dir: [f64; 3], min: f64, max: f64, dynamic: &[Object]) -> Option<Hit> {
        let mut best = Best { t: max, id: u32::MAX, normal: [0.0; 3] };
        self.nearest(origin, dir, min, &mut best, &mut ());
        for o in dynamic {
            if let Some((t, n)) = Prim::from_object(o).intersect(origin, dir, min, best.t) {
                best.offer(t, o.id, n);
            }
        }
        best.hit()
    }

    /// Nearest hit among this scene and `movers` (a prepared set of moving objects).
    pub fn cast_among(&self, origin: [f64; 3], dir: [f64; 3], min: f64, max: f64, movers: &RayCaster) -> Option<Hit> {
        let mut best = Best { t: max, id: u32::MAX, normal: [0.0; 3] };
        self.nearest(origin, dir, min, &mut best, &mut ());
        movers.nearest(origin, dir, min, &mut best, &mut ());
        best.hit()
    }

    /// [`RayCaster::cast_among`] for up to [`MAX_PACKET`] rays from one origin (a camera
    /// tile), traversing together: `out[i]` is exactly what `cast_among` gives for `dirs[i]`,
    /// at a fraction of the node work when the rays are coherent.
    pub fn cast_packet(
        &self,
        origin: [f64; 3],
        dirs: &[[f64; 3]],
        min: f64,
        max: f64,
        movers: &RayCaster,
        out: &mut [Option<Hit>],
    ) {
        self.cast_packet_beyond(origin, dirs, &[min], max, movers, out);
    }

    /// [`RayCaster::cast_packet`] with a near limit per ray (`mins[i]`, or one for all): rays
    /// going on past the surfaces they met (a camera tile's rays seeing through glass).
    pub fn cast_packet_beyond(
        &self,
        origin: [f64; 3],
        dirs: &[[f64; 3]],
        mins: &[f64],
        max: f64,
        movers: &RayCaster,
        out: &mut [Option<Hit>],
    ) {
        assert!(
            dirs.len() <= MAX_PACKET && (mins.len() == 1 || mins.len() == dirs.len()),
            "a packet of {} rays (at most {MAX_PACKET}) with {} near limits",
            dirs.len(),
            mins.len()
        );
        let mut best = [Best { t: max, id: u32::MAX, normal: [0.0; 3] }; MAX_PACKET];
        // The packet culls from the nearest limit; each ray's primitive tests keep its own.
        let min = mins.iter().fold(f64::INFINITY, |m, &v| m.min(v));
        match Packet::new(&[origin], dirs, max) {
            // The movers (the robot's links, seen by every tile at the image's bottom) with the
            // same packet, each ray's far limit already lowered to its static hit.
            Some(mut packet) => {
                for set in [self, movers] {
                    let mut v = PacketNearest { caster: set, origins: &[origin], dirs, tmins: mins, best: &mut best };
                    traverse_packet(&set.nodes, &mut packet, min, &mut v);
                }
            }
            None => {
                for (i, d) in dirs.iter().enumerate() {
                    let min = mins[i.min(mins.len() - 1)];
                    self.nearest(origin, *d, min, &mut best[i], &mut ());
                    movers.nearest(origin, *d, min, &mut best[i], &mut ());
                }
            }
        }
        for (b, o) in best.iter().zip(out.iter_mut()) {
            *o = b.hit();
        }
    }

    /// [`RayCaster::cast_among_posed`] for up to [`MAX_PACKET`] coherent rays with their own
    /// origins and mover poses (a run of LiDAR firings while the base moves): `out[i]` is
    /// exactly the single-ray answer for ray i among this scene, `placed` (further objects
    /// in the map frame: moved scene objects; often empty) and the posed `movers`.
    #[allow(clippy::too_many_arguments)]
    pub fn cast_packet_posed(
        &self,
        origins: &[[f64; 3]],
        dirs: &[[f64; 3]],
        min: f64,
        max: f64,
        placed: &RayCaster,
        movers: &RayCaster,
        poses: &[RigidPose],
        out: &mut [Option<Hit>],
    ) {
        assert!(
            origins.len() == dirs.len() && poses.len() == dirs.len(),
            "cast_packet_posed: {} origins, {} rays, {} poses",
            origins.len(),
            dirs.len(),
            poses.len()
        );
        let n = dirs.len();
        assert!(n <= MAX_PACKET, "a packet of {n} rays (at most {MAX_PACKET})");
        let mut best = [Best { t: max, id: u32::MAX, normal: [0.0; 3] }; MAX_PACKET];
        nearest_in_packets(self, origins, dirs, min, max, &mut best);
        if !placed.is_empty() {
            nearest_in_packets(placed, origins, dirs, min, max, &mut best);
        }
        if movers.is_empty() {
            for i in 0..n {
                out[i] = best[i].hit();
            }
            return;
        }
        let before: [(f64, u32); MAX_PACKET] = std::array::from_fn(|i| (best[i].t, best[i].id));
        // The movers with the rays taken into their frame, each by its own pose, as packets
        // whose far limits are the static hits.
        let mut lo = [[0.0; 3]; MAX_PACKET];
        let mut ld = [[0.0; 3]; MAX_PACKET];
        for i in 0..n {
            let pose = &poses[i];
            (lo[i], ld[i]) = (pose.local_of(sub(origins[i], pose.translation)), pose.local_of(dirs[i]));
        }
        nearest_in_packets(movers, &lo[..n], &ld[..n], min, max, &mut best);
        for i in 0..n {
            if (best[i].t, best[i].id) != before[i] {
                best[i].normal = poses[i].map_of(best[i].normal);
            }
            out[i] = best[i].hit();
        }
    }

    /// Nearest hit among this scene and `movers`, whose objects are given in a moving frame
    /// that sits at `pose` (robot links in base_link, the base at its pose): the ray is taken
    /// into that frame instead of the objects out of it, so a moving set is built once, not
    /// at every pose. Distances are those of the map-frame ray; normals come back in the map.
    pub fn cast_among_posed(
        &self,
        origin: [f64; 3],
        dir: [f64; 3],
        min: f64,
        max: f64,
        movers: &RayCaster,
        pose: &RigidPose,
    ) -> Option<Hit> {
        let mut best = Best { t: max, id: u32::MAX, normal: [0.0; 3] };
        self.nearest(origin, dir, min, &mut best, &mut ());
        let before = (best.t, best.id);
        let (o, d) = (pose.local_of(sub(origin, pose.translation)), pose.local_of(dir));
        movers.nearest(o, d, min, &mut best, &mut ());
        if (best.t, best.id) != before {
            best.normal = pose.map_of(best.normal);
        }
        best.hit()
    }

    /// What a ray from `origin` along `dir` (t in [min, max]) passes through, over this scene
    /// and `movers`: None if an object for which `opaque(id)` holds blocks it, else the number
    /// of surfaces of other (translucent: glass, film) objects it crosses, counted as a walk
    /// from hit to hit restarting 0.1 mm past each would count them. One traversal that stops
    /// at the first opaque object found: a shadow ray.
    pub fn pass_through(
        &self,
        origin: [f64; 3],
        dir: [f64; 3],
        min: f64,
        max: f64,
        movers: &RayCaster,
        opaque: impl Fn(u32) -> bool,
    ) -> Option<u32> {
        let (mut t, mut len) = ([MaybeUninit::uninit(); MAX_CROSSINGS], 0);
        for set in [self, movers] {
            let mut v = Through {
                caster: set,
                o: origin,
                d: dir,
                tmin: min,
                tmax: max,
                far: far(max),
                opaque: &opaque,
                at: Crossings { t: &mut t, len: &mut len },
            };
            if traverse(&set.nodes, origin, dir, min, &mut v) {
                return None;
            }
        }
        Some(Crossings { t: &mut t, len: &mut len }.count(min))
    }

    /// [`RayCaster::pass_through`] for up to [`MAX_PACKET`] rays with their own origins and a
    /// common direction (shadow rays toward the sun from a camera tile's surface points):
    /// `out[i]` is exactly the single-ray answer for origin i.
    #[allow(clippy::too_many_arguments)]
    pub fn pass_through_packet(
        &self,
        origins: &[[f64; 3]],
        dir: [f64; 3],
        min: f64,
        max: f64,
        movers: &RayCaster,
        opaque: impl Fn(u32) -> bool,
        out: &mut [Option<u32>],
    ) {
        self.pass_through_cached(origins, dir, min, max, movers, opaque, &mut Occluders::default(), out);
    }

    /// [`RayCaster::pass_through_packet`] that first tries the opaque objects that blocked
    /// earlier rays (`recent`, which it keeps up to date): a ray one of them blocks is in
    /// shadow whatever else lies on it, so it needs no traversal. Neighbouring surface points
    /// are often shaded by the same leaf. The answers are the same whatever `recent` holds.
    #[allow(clippy::too_many_arguments)]
    pub fn pass_through_cached(
        &self,
        origins: &[[f64; 3]],
        dir: [f64; 3],
        min: f64,
        max: f64,
        movers: &RayCaster,
        opaque: impl Fn(u32) -> bool,
        recent: &mut Occluders,
        out: &mut [Option<u32>],
    ) {
        let n = origins.len();
        assert!(n <= MAX_PACKET && out.len() == n, "pass_through_packet: {n} rays, {} results", out.len());
        // Rays not blocked by a recent occluder go on, compacted into one packet.
        let mut live = [0usize; MAX_PACKET];
        let mut sub = [[0.0; 3]; MAX_PACKET];
        let mut m = 0;
        // Each checked against these sets (an entry from another scene is passed over or, if
        // it names an opaque primitive here, still a correct test).
        let occluders = recent.slots.map(|r| {
            r.and_then(|(in_movers, k)| {
                let (set, k) = (if in_movers { movers } else { self }, k as usize);
                (k < set.prims.len() && opaque(set.ids[k])).then(|| set.prims[k].along(dir))
            })
        });
        for (i, o) in origins.iter().enumerate() {
            out[i] = None;
            if !occluders.iter().flatten().any(|a| a.intersect(*o, min, max).is_some()) {
                (live[m], sub[m]) = (i, *o);
                m += 1;
            }
        }
        if m == 0 {
            return;
        }
        let sub = &sub[..m];
        let Some(mut packet) = Packet::new(sub, &[dir], max) else {
            for q in 0..m {
                out[live[q]] = self.pass_through(sub[q], dir, min, max, movers, &opaque);
            }
            return;
        };
        // Per ray: its crossings (not cleared: only the first `len` are ever read) and `len`.
        let mut ts = [[MaybeUninit::uninit(); MAX_CROSSINGS]; MAX_PACKET];
        let mut lens = [0; MAX_PACKET];
        let mut blocked = [false; MAX_PACKET];
        // The scene, then the movers with the same packet (blocked rays have left it), each
        // ray continuing its crossing list.
        for (in_movers, set) in [(false, self), (true, movers)] {
            let mut v = PacketThrough {
                caster: set,
                origins: sub,
                d: dir,
                tmin: min,
                tmax: max,
                opaque: &opaque,
                ts: &mut ts,
                lens: &mut lens,
                blocked: &mut blocked,
                blocker: None,
            };
            traverse_packet(&set.nodes, &mut packet, min, &mut v);
            if let Some(k) = v.blocker {
                recent.remember(in_movers, k);
            }
        }
        for q in 0..m {
            out[live[q]] = (!blocked[q]).then(|| Crossings { t: &mut ts[q], len: &mut lens[q] }.count(min));
        }
    }

    /// Work done for one ray: (BVH nodes visited, primitive tests). For tuning and reports.
    pub fn traversal_stats(&self, origin: [f64; 3], dir: [f64; 3], min: f64, max: f64) -> (usize, usize) {
        let mut best = Best { t: max, id: u32::MAX, normal: [0.0; 3] };
        let mut c = Counts(0, 0);
        self.nearest(origin, dir, min, &mut best, &mut c);
        (c.0, c.1)
    }

    fn nearest<S: Stats>(&self, o: [f64; 3], d: [f64; 3], tmin: f64, best: &mut Best, stats: &mut S) {
        let far = far(best.t);
        let mut v = Nearest { caster: self, o, d, tmin, best, far, stats };
        traverse(&self.nodes, o, d, tmin, &mut v);
    }
}

impl std::fmt::Debug for RayCaster {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "RayCaster({} objects, {} nodes)", self.prims.len(), self.nodes.len())
    }
}

/// A rigid placement of a moving frame: local -> map rotation (row-major) and translation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RigidPose {
    pub rotation: [[f64; 3]; 3],
    pub translation: [f64; 3],
}

impl RigidPose {
    pub fn of(p: &Placement) -> RigidPose {
        RigidPose { rotation: p.matrix(), translation: p.translation }
    }

    /// A yaw about map z at (x, y, z), as a base pose is.
    pub fn yawed(x: f64, y: f64, z: f64, yaw: f64) -> RigidPose {
        let (s, c) = yaw.sin_cos();
        RigidPose { rotation: [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]], translation: [x, y, z] }
    }

    /// R^T v: a map vector in the local frame.
    #[inline(always)]
    fn local_of(&self, v: [f64; 3]) -> [f64; 3] {
        mat_t_vec(&self.rotation, v)
    }

    /// R v: a local vector in the map.
    #[inline(always)]
    fn map_of(&self, v: [f64; 3]) -> [f64; 3] {
        mat_vec(&self.rotation, v)
    }
}

/// Nearest-hit traversal.
struct Nearest<'a, S> {
    caster: &'a RayCaster,
    o: [f64; 3],
    d: [f64; 3],
    tmin: f64,
    best: &'a mut Best,
    /// `best.t` as the traversal's f32 limit.
    far: f32,
    stats: &'a mut S,
}

impl<S: Stats> Visit for Nearest<'_, S> {
    #[inline(always)]
    fn t_max(&self) -> f32 {
        self.far
    }

    #[inline(always)]
    fn leaf(&mut self, start: usize, count: usize) -> bool {
        for k in start..start + count {
            self.stats.prim();
            if let Some((t, n)) = self.caster.prims[k].intersect(self.o, self.d, self.tmin, self.best.t) {
                self.best.offer(t, self.caster.ids[k], n);
                self.far = far(self.best.t);
            }
        }
        false
    }

    fn node(&mut self) {
        self.stats.node();
    }
}

/// Nearest hits in `set` of up to [`MAX_PACKET`] rays with their own origins (a run of LiDAR
/// firings), each ray lowering its `best` (whose distance is its far limit on entry): one
/// packet when the directions share their signs on every axis, else one packet per octant of
/// directions (a packet whose directions have both signs on an axis has an interval bound
/// that culls nothing; a quarter of the LiDAR's packets straddle an axis), a lone ray alone.
/// Each ray's answer is its single-ray answer whatever packet it goes in.
fn nearest_in_packets(
    set: &RayCaster,
    origins: &[[f64; 3]],
    dirs: &[[f64; 3]],
    min: f64,
    max: f64,
    best: &mut [Best; MAX_PACKET],
) {
    if packet_nearest(set, origins, dirs, min, max, best) {
        return;
    }
    // The rays of each octant (bit a: the direction's inverse along axis a is positive, as
    // the packet bound reads it), one bit per ray.
    let mut octants = [0u64; 8];
    for (i, d) in dirs.iter().enumerate() {
        let k = (0..3).fold(0, |k, a| k | ((wide::inverse(d[a]) > 0.0) as usize) << a);
        octants[k] |= 1 << i;
    }
    let mut lanes = [0usize; MAX_PACKET];
    let mut sub_o = [[0.0; 3]; MAX_PACKET];
    let mut sub_d = [[0.0; 3]; MAX_PACKET];
    let mut sub_best = [Best { t: max, id: u32::MAX, normal: [0.0; 3] }; MAX_PACKET];
    for mut m in octants {
        let mut k = 0;
        while m != 0 {
            let i = m.trailing_zeros() as usize;
            m &= m - 1;
            (lanes[k], sub_o[k], sub_d[k], sub_best[k]) = (i, origins[i], dirs[i], best[i]);
            k += 1;
        }
        // A lone ray, or rays whose bound still fails (NaN directions): one at a time.
        if k < 2 || !packet_nearest(set, &sub_o[..k], &sub_d[..k], min, max, &mut sub_best) {
            for q in 0..k {
                set.nearest(sub_o[q], sub_d[q], min, &mut sub_best[q], &mut ());
            }
        }
        for q in 0..k {
            best[lanes[q]] = sub_best[q];
        }
    }
}

/// [`nearest_in_packets`] as one packet; false (nothing done) when the rays' directions do not
/// share their signs on some axis.
fn packet_nearest(
    set: &RayCaster,
    origins: &[[f64; 3]],
    dirs: &[[f64; 3]],
    min: f64,
    max: f64,
    best: &mut [Best; MAX_PACKET],
) -> bool {
    let Some(mut packet) = Packet::new(origins, dirs, max) else { return false };
    for i in 0..dirs.len() {
        packet.far[i] = far(best[i].t);
    }
    let mut v = PacketNearest { caster: set, origins, dirs, tmins: &[min], best };
    traverse_packet(&set.nodes, &mut packet, min, &mut v);
    true
}

/// Nearest-hit traversal of a packet: each ray keeps its own best hit.
struct PacketNearest<'a> {
    caster: &'a RayCaster,
    /// One origin for all rays, or one per ray.
    origins: &'a [[f64; 3]],
    dirs: &'a [[f64; 3]],
    /// One near limit for all rays, or one per ray.
    tmins: &'a [f64],
    best: &'a mut [Best; MAX_PACKET],
}

impl PacketVisit for PacketNearest<'_> {
    fn leaf(&mut self, packet: &mut Packet, start: usize, count: usize, rays: u64) {
        // Primitive by primitive: with one origin for all rays (a camera tile) each primitive
        // takes it into its frame once. Each ray still meets the primitives in leaf order, so
        // its answer is the one it gets alone.
        // Rays offered a hit (their far limit is recomputed; unchanged if the offer was not
        // taken), one bit each.
        let mut offered = 0u64;
        for k in start..start + count {
            let prim = &self.caster.prims[k];
            let shared = match self.origins {
                [o] => Some(prim.seen_from(*o)),
                _ => None,
            };
            let mut m = rays;
            while m != 0 {
                let i = m.trailing_zeros() as usize;
                m &= m - 1;
                let d = &self.dirs[i];
                let seen = shared.unwrap_or_else(|| prim.seen_from(self.origins[i]));
                let best = &mut self.best[i];
                if let Some((t, n)) = seen.intersect(*d, self.tmins[i.min(self.tmins.len() - 1)], best.t) {
                    best.offer(t, self.caster.ids[k], n);
                    offered |= 1 << i;
                }
            }
        }
        while offered != 0 {
            let i = offered.trailing_zeros() as usize;
            offered &= offered - 1;
            packet.far[i] = far(self.best[i].t);
        }
    }
}

/// Shadow traversal of a packet ([`RayCaster::pass_through_packet`]): a blocked ray leaves
/// the packet (its far limit drops below every box).
struct PacketThrough<'a, F> {
    caster: &'a RayCaster,
    origins: &'a [[f64; 3]],
    d: [f64; 3],
    tmin: f64,
    tmax: f64,
    opaque: &'a F,
    ts: &'a mut [[MaybeUninit<f64>; MAX_CROSSINGS]; MAX_PACKET],
    lens: &'a mut [u8; MAX_PACKET],
    blocked: &'a mut [bool; MAX_PACKET],
    /// The last primitive found blocking a ray.
    blocker: Option<u32>,
}

impl<F: Fn(u32) -> bool> PacketVisit for PacketThrough<'_, F> {
    fn leaf(&mut self, packet: &mut Packet, start: usize, count: usize, rays: u64) {
        // Primitive by primitive, each taking the shared direction into its frame once; each
        // ray still meets them in leaf order and stops at the first opaque one, as
        // [`cross_leaf`] has it.
        let mut live = rays;
        for k in start..start + count {
            let along = self.caster.prims[k].along(self.d);
            let mut opaque = None;
            let mut m = live;
            while m != 0 {
                let i = m.trailing_zeros() as usize;
                m &= m - 1;
                if cross(
                    &along,
                    self.origins[i],
                    self.tmin,
                    self.tmax,
                    || *opaque.get_or_insert_with(|| (self.opaque)(self.caster.ids[k])),
                    &mut Crossings { t: &mut self.ts[i], len: &mut self.lens[i] },
                ) {
                    self.blocker = Some(k as u32);
                    self.blocked[i] = true;
                    packet.far[i] = f32::NEG_INFINITY;
                    live &= !(1 << i);
                }
            }
        }
    }
}

/// Most recent occluders [`RayCaster::pass_through_cached`] tries first. One: on the camera's
/// frames (`camera_fps`, both views, with and without `sensors.toml`'s sky) it stops 20-28 %
/// of all shadow rays, about three quarters of the blocked ones; a second or third cost the
/// lit rays more tests than they saved (2 % slower frames).
const OCCLUDERS: usize = 1;

/// The opaque primitives that blocked the latest shadow rays, newest first (for
/// [`RayCaster::pass_through_cached`]; one per thread). Any content gives correct answers:
/// an entry is used only if it names an opaque primitive of the sets it is used with.
#[derive(Clone, Copy, Debug, Default)]
pub struct Occluders {
    /// (in the movers, primitive index).
    slots: [Option<(bool, u32)>; OCCLUDERS],
}

impl Occluders {
    /// How many occluders it holds.
    pub fn held(&self) -> usize {
        self.slots.iter().flatten().count()
    }

    fn remember(&mut self, in_movers: bool, k: u32) {
        let new = Some((in_movers, k));
        if self.slots[0] != new {
            self.slots.copy_within(0..OCCLUDERS - 1, 1);
            self.slots[0] = new;
        }
    }
}

/// Shadow traversal of [`RayCaster::pass_through`]: stops at an opaque hit, collects where the
/// ray crosses the surfaces of translucent ones (at most two per convex object: in and out).
struct Through<'a, F> {
    caster: &'a RayCaster,
    o: [f64; 3],
    d: [f64; 3],
    tmin: f64,
    tmax: f64,
    far: f32,
    opaque: &'a F,
    at: Crossings<'a>,
}

/// Most translucent surface crossings a shadow ray records (beyond: treated as dark).
const MAX_CROSSINGS: usize = 16;

/// A shadow ray's translucent surface crossings, kept where the ray's traversal keeps them:
/// `t[..len]` are set, the rest is never read and not cleared either (a packet's 64 lists of
/// zeros were 8.7 KB written per shadow packet, 2 % of a camera frame).
struct Crossings<'a> {
    t: &'a mut [MaybeUninit<f64>; MAX_CROSSINGS],
    len: &'a mut u8,
}

impl Crossings<'_> {
    /// The crossings recorded.
    fn recorded(&mut self) -> &mut [f64] {
        let len = *self.len as usize;
        // SAFETY: `push` wrote t[..len] before raising len, and MaybeUninit<f64> has f64's layout.
        unsafe { &mut *std::ptr::slice_from_raw_parts_mut(self.t.as_mut_ptr().cast::<f64>(), len) }
    }

    /// Counts as the walk would: a surface within one restart step of the last one counted
    /// (a pane resting on another) is passed over with it. A full list counts as at least
    /// [`MAX_CROSSINGS`].
    fn count(&mut self, tmin: f64) -> u32 {
        let t = self.recorded();
        t.sort_unstable_by(f64::total_cmp);
        let mut n = 0;
        let mut last = f64::NEG_INFINITY;
        for &x in t.iter() {
            if x >= last + RESTART + tmin {
                n += 1;
                last = x;
            }
        }
        n + (*self.len as usize == MAX_CROSSINGS) as u32 * MAX_CROSSINGS as u32
    }

    fn push(&mut self, t: f64) {
        let len = *self.len as usize;
        if len < MAX_CROSSINGS {
            self.t[len].write(t);
            *self.len += 1;
        }
    }
}

/// Restart offset past a translucent surface [m].
const RESTART: f64 = 1e-4;

impl<F: Fn(u32) -> bool> Visit for Through<'_, F> {
    fn t_max(&self) -> f32 {
        self.far
    }

    fn leaf(&mut self, start: usize, count: usize) -> bool {
        cross_leaf(self.caster, start, count, self.o, self.d, self.tmin, self.tmax, self.opaque, &mut self.at)
    }
}

/// One shadow ray through the primitives `start..start + count` of a leaf: true at an opaque
/// hit, else the translucent ones' surface crossings (in and out) go to `at`.
#[allow(clippy::too_many_arguments)]
fn cross_leaf(
    caster: &RayCaster,
    start: usize,
    count: usize,
    o: [f64; 3],
    d: [f64; 3],
    tmin: f64,
    tmax: f64,
    opaque: &impl Fn(u32) -> bool,
    at: &mut Crossings,
) -> bool {
    (start..start + count).any(|k| cross(&caster.prims[k].along(d), o, tmin, tmax, || opaque(caster.ids[k]), at))
}

/// One shadow ray from `o` across one primitive: true if it meets it and the primitive is
/// opaque (asked only then), else the translucent surfaces it crosses (in and out) go to `at`.
#[inline(always)]
fn cross(
    along: &primitives::Along<'_>,
    o: [f64; 3],
    tmin: f64,
    tmax: f64,
    opaque: impl FnOnce() -> bool,
    at: &mut Crossings,
) -> bool {
    let Some((t, _)) = along.intersect(o, tmin, tmax) else { return false };
    if opaque() {
        return true;
    }
    at.push(t);
    if let Some((t2, _)) = along.intersect(o, t + RESTART, tmax) {
        at.push(t2);
    }
    false
}

/// Counters for [`RayCaster::traversal_stats`]; `()` counts nothing and compiles away.
trait Stats {
    fn node(&mut self) {}
    fn prim(&mut self) {}
}

impl Stats for () {}

struct Counts(usize, usize);

impl Stats for Counts {
    fn node(&mut self) {
        self.0 += 1;
    }
    fn prim(&mut self) {
        self.1 += 1;
    }
}

/// The nearest hit so far; ties go to the lower id, so the answer does not depend on the
/// order objects are visited in.
#[derive(Clone, Copy)]
struct Best {
    t: f64,
    id: u32,
    normal: [f64; 3],
}

impl Best {
    #[inline(always)]
    fn offer(&mut self, t: f64, id: u32, n: [f64; 3]) {
        if t < self.t || (t == self.t && id < self.id) {
            self.t = t;
            self.id = id;
            self.normal = n;
        }
    }

    fn hit(&self) -> Option<Hit> {
        (self.id != u32::MAX).then_some(Hit { distance: self.t, object: self.id, normal: self.normal })
    }
}

/// Reference implementation: the nearest hit over all `objects` by brute force (for tests
/// and for tiny scenes).
pub fn cast_brute_force(objects: &[Object], origin: [f64; 3], dir: [f64; 3], min: f64, max: f64) -> Option<Hit> {
    let mut best = Best { t: max, id: u32::MAX, normal: [0.0; 3] };
    for o in objects {
        if let Some((t, n)) = Prim::from_object(o).intersect(origin, dir, min, best.t) {
            best.offer(t, o.id, n);
        }
    }
    best.hit()
}
