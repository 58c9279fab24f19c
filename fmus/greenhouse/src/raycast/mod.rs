//! Ray casting against the scene: a BVH over the static objects (built once) plus a short
//! list of dynamic objects (robot links, placed obstacles) tested per call. Exact analytic
//! intersection, f64 throughout; the nearest hit wins, ties go to the lower object id, so the
//! result equals a brute-force scan over all objects.

mod bvh;
mod primitives;

use crate::scene::Object;
use bvh::{slab, Bvh, Node};
use primitives::Prim;

/// A ray hit: distance along the (unit) direction, the object's id, outward surface normal.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    pub distance: f64,
    pub object: u32,
    pub normal: [f64; 3],
}

/// Static scene prepared for ray casting.
pub struct RayCaster {
    nodes: Vec<Node>,
    /// Primitives in BVH leaf order, with their object ids.
    prims: Vec<Prim>,
    ids: Vec<u32>,
}

impl RayCaster {
    /// Builds the BVH over `objects` (any ids; they are reported back in [`Hit::object`]).
    pub fn new(objects: &[Object]) -> RayCaster {
        let boxes: Vec<_> = objects.iter().map(Object::aabb).collect();
        let bvh = Bvh::build(&boxes);
        let prims = bvh.order.iter().map(|&i| Prim::from_object(&objects[i as usize])).collect();
        let ids = bvh.order.iter().map(|&i| objects[i as usize].id).collect();
        RayCaster { nodes: bvh.nodes, prims, ids }
    }

    /// Number of static objects.
    pub fn len(&self) -> usize {
        self.prims.len()
    }

    pub fn is_empty(&self) -> bool {
        self.prims.is_empty()
    }

    /// Number of BVH nodes (for diagnostics).
    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    /// Nearest hit along origin + t*dir (dir unit), t in [min, max]. `dynamic` are extra
    /// objects (moving robot links, placed obstacles) tested too. A ray starting inside a
    /// solid reports where it leaves it.
    pub fn cast(&self, origin: [f64; 3], dir: [f64; 3], min: f64, max: f64, dynamic: &[Object]) -> Option<Hit> {
        let mut best = Best { t: max, id: u32::MAX, normal: [0.0; 3] };
        self.cast_static(origin, dir, min, &mut best, &mut ());
        for o in dynamic {
            if let Some((t, n)) = Prim::from_object(o).intersect(origin, dir, min, best.t) {
                best.offer(t, o.id, n);
            }
        }
        best.hit()
    }

    /// Work done for one ray: (BVH nodes visited, primitive tests). For tuning and reports.
    pub fn traversal_stats(&self, origin: [f64; 3], dir: [f64; 3], min: f64, max: f64) -> (usize, usize) {
        let mut best = Best { t: max, id: u32::MAX, normal: [0.0; 3] };
        let mut c = Counts(0, 0);
        self.cast_static(origin, dir, min, &mut best, &mut c);
        (c.0, c.1)
    }

    fn cast_static<S: Stats>(&self, o: [f64; 3], d: [f64; 3], tmin: f64, best: &mut Best, stats: &mut S) {
        if self.prims.is_empty() {
            return;
        }
        let inv = [1.0 / d[0], 1.0 / d[1], 1.0 / d[2]];
        let root = &self.nodes[0];
        if slab(&root.min, &root.max, &o, &inv, tmin, best.t).is_none() {
            return;
        }
        // Far children wait on the stack with their entry distance, so a pop can discard a
        // node behind the current best hit without touching it again.
        let mut stack = [(0u32, 0.0f64); 64];
        let mut sp = 0usize;
        let mut ni = 0usize;
        loop {
            let node = &self.nodes[ni];
            stats.node();
            if node.count > 0 {
                let s = node.start as usize;
                for k in s..s + node.count as usize {
                    stats.prim();
                    if let Some((t, n)) = self.prims[k].intersect(o, d, tmin, best.t) {
                        best.offer(t, self.ids[k], n);
                    }
                }
            } else {
                let l = node.start as usize;
                let (a, b) = (&self.nodes[l], &self.nodes[l + 1]);
                let ta = slab(&a.min, &a.max, &o, &inv, tmin, best.t);
                let tb = slab(&b.min, &b.max, &o, &inv, tmin, best.t);
                match (ta, tb) {
                    (Some(x), Some(y)) => {
                        let (near, far, tfar) = if x <= y { (l, l + 1, y) } else { (l + 1, l, x) };
                        if sp < stack.len() {
                            stack[sp] = (far as u32, tfar);
                            sp += 1;
                        } else {
                            // Pathologically deep tree: finish the far side recursively.
                            self.cast_from(far, o, d, &inv, tmin, best);
                        }
                        ni = near;
                        continue;
                    }
                    (Some(_), None) => {
                        ni = l;
                        continue;
                    }
                    (None, Some(_)) => {
                        ni = l + 1;
                        continue;
                    }
                    (None, None) => {}
                }
            }
            // Pop the next node that can still hold a nearer (or equally near) hit.
            loop {
                if sp == 0 {
                    return;
                }
                sp -= 1;
                let (n, t) = stack[sp];
                if t <= best.t {
                    ni = n as usize;
                    break;
                }
            }
        }
    }

    fn cast_from(&self, ni: usize, o: [f64; 3], d: [f64; 3], inv: &[f64; 3], tmin: f64, best: &mut Best) {
        let node = &self.nodes[ni];
        if slab(&node.min, &node.max, &o, inv, tmin, best.t).is_none() {
            return;
        }
        if node.count > 0 {
            let s = node.start as usize;
            for k in s..s + node.count as usize {
                if let Some((t, n)) = self.prims[k].intersect(o, d, tmin, best.t) {
                    best.offer(t, self.ids[k], n);
                }
            }
        } else {
            self.cast_from(node.start as usize, o, d, inv, tmin, best);
            self.cast_from(node.start as usize + 1, o, d, inv, tmin, best);
        }
    }
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
