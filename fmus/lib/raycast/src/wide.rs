//! The traversal structure: the binary SAH tree of [`crate::bvh`] collapsed into a 4-wide tree
//! with f32 child boxes stored lane-wise, so one node visit tests four boxes in a few SIMD
//! instructions and the tree takes a quarter of the memory of the f64 binary one.
//!
//! f32 boxes only cull; every primitive test stays exact f64, so results are those of the
//! exact caster as long as the culling is conservative. It is: box corners are rounded
//! outward and padded by 0.1 mm + 1 ppm (covering the rounding of the ray's origin and
//! direction to f32 over the greenhouse's extent), and the exit distance is scaled up by
//! 1 + 2 gamma(3) as in Ize's robust traversal ("Robust BVH Ray Traversal", JCGT 2013), which
//! bounds the f32 slab arithmetic's own error.

use crate::bvh::Node;
use std::mem::MaybeUninit;

/// A child slot that holds nothing.
pub(crate) const EMPTY: u32 = u32::MAX;
/// Leaf references: this bit set, primitive count - 1 in bits 26..31, first primitive below.
const LEAF: u32 = 1 << 31;
const COUNT_SHIFT: u32 = 26;
const START_MASK: u32 = (1 << COUNT_SHIFT) - 1;
/// Most primitives a leaf reference can carry.
pub(crate) const MAX_LEAF_PRIMS: usize = 32;

/// Exit-distance scale of the robust slab test: 1 + 2 gamma(3) for f32, rounded up.
const EXIT_SCALE: f32 = 1.000_000_4;

/// Four child boxes, lane-wise (`b[0][axis][lane]` the min corners, `b[1]` the max), and what
/// each child is. Corners are indexed so a ray picks its near and far planes per axis by its
/// direction's sign ([`Ray32::near`]) instead of ordering two distances at every node.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
pub(crate) struct Node4 {
    pub b: [[[f32; 4]; 3]; 2],
    /// Interior node index, a leaf reference ([`leaf_ref`]) or [`EMPTY`].
    pub child: [u32; 4],
}

pub(crate) fn leaf_ref(start: u32, count: u32) -> u32 {
    debug_assert!(count >= 1 && count as usize <= MAX_LEAF_PRIMS && start <= START_MASK);
    LEAF | ((count - 1) << COUNT_SHIFT) | start
}

/// (first primitive, count) of a leaf reference, None for an interior node.
#[inline(always)]
pub(crate) fn as_leaf(c: u32) -> Option<(usize, usize)> {
    (c & LEAF != 0).then(|| ((c & START_MASK) as usize, (((c & !LEAF) >> COUNT_SHIFT) + 1) as usize))
}

/// The largest f32 not above `v`.
pub(crate) fn down(v: f64) -> f32 {
    let f = v as f32;
    if f as f64 > v {
        f.next_down()
    } else {
        f
    }
}

/// The smallest f32 not below `v`.
pub(crate) fn up(v: f64) -> f32 {
    let f = v as f32;
    if (f as f64) < v {
        f.next_up()
    } else {
        f
    }
}

/// Outward padding of a box coordinate [m].
fn pad(v: f64) -> f64 {
    1e-4 + 1e-6 * v.abs()
}

/// The 4-wide tree of a binary one. Node 0 is the root; an empty tree has no nodes.
pub(crate) fn collapse(bin: &[Node], prims: usize) -> Vec<Node4> {
    let mut out = Vec::new();
    if prims == 0 || bin.is_empty() {
        return out;
    }
    assert!(prims <= START_MASK as usize, "{prims} primitives: more than a leaf reference can address");
    // Work: (binary node whose children become the slots, index of its Node4).
    out.push(empty_node());
    let mut work = vec![(0usize, 0usize)];
    while let Some((b, at)) = work.pop() {
        // The slots: start from the node itself (a leaf root becomes one leaf slot), then open
        // the interior slot with the largest surface area until four are filled.
        let mut slots: Vec<usize> =
            if bin[b].count > 0 { vec![b] } else { vec![bin[b].start as usize, bin[b].start as usize + 1] };
        while slots.len() < 4 {
            let open = slots
                .iter()
                .enumerate()
                .filter(|(_, &s)| bin[s].count == 0)
                .max_by(|a, b| area(&bin[*a.1]).total_cmp(&area(&bin[*b.1])).then(b.0.cmp(&a.0)))
                .map(|(k, _)| k);
            let Some(k) = open else { break };
            let s = slots.remove(k);
            slots.insert(k, bin[s].start as usize + 1);
            slots.insert(k, bin[s].start as usize);
        }
        for (lane, &s) in slots.iter().enumerate() {
            let n = &bin[s];
            for a in 0..3 {
                out[at].b[0][a][lane] = down(n.min[a] - pad(n.min[a]));
                out[at].b[1][a][lane] = up(n.max[a] + pad(n.max[a]));
            }
            out[at].child[lane] = if n.count > 0 {
                leaf_ref(n.start, n.count)
            } else {
                out.push(empty_node());
                work.push((s, out.len() - 1));
                (out.len() - 1) as u32
            };
        }
    }
    out
}

/// Every lane empty: a box at +inf is met by no ray (with finite `inv`, its slab distances
/// are both +inf or both -inf).
fn empty_node() -> Node4 {
    Node4 { b: [[[f32::INFINITY; 4]; 3]; 2], child: [EMPTY; 4] }
}

fn area(n: &Node) -> f64 {
    let e = [n.max[0] - n.min[0], n.max[1] - n.min[1], n.max[2] - n.min[2]];
    e[0] * e[1] + e[1] * e[2] + e[2] * e[0]
}

/// A ray in the form the slab test wants.
pub(crate) struct Ray32 {
    pub o: [f32; 3],
    pub inv: [f32; 3],
    /// Per axis, which corners of a box ([`Node4::b`]) the ray meets first: 0 (min) where it
    /// goes up the axis, 1 (max) where it goes down.
    pub near: [usize; 3],
}

impl Ray32 {
    pub(crate) fn new(o: [f64; 3], d: [f64; 3]) -> Ray32 {
        let inv = d.map(inverse);
        Ray32 { o: o.map(|v| v as f32), inv, near: inv.map(near_corner) }
    }
}

/// The corner index ([`Node4::b`]) of the planes met first along an axis whose inverse
/// direction is `inv` (never 0 or NaN, see [`inverse`]). The distance to them is then never
/// above the distance to the other (rounding is monotonic), so no ordering is needed.
#[inline(always)]
pub(crate) fn near_corner(inv: f32) -> usize {
    (inv < 0.0) as usize
}

/// The f32 inverse of a direction component. A zero (or vanishing) component becomes a tiny
/// one: no 0 * inf NaN in the slabs, and the direction moves by less than any distance that
/// matters.
#[inline(always)]
pub(crate) fn inverse(v: f64) -> f32 {
    let f = v as f32;
    let f = if f.abs() < 1e-30 { 1e-30f32.copysign(f) } else { f };
    1.0 / f
}

/// Entry distances of the four boxes and a bit mask of those the ray meets within
/// [tmin, tmax] (`tmax` already holds the robust slack, see [`far`]). Plain comparisons so the
/// loops become SSE min/max. Empty lanes hold boxes at +inf, which no ray meets.
#[inline(always)]
pub(crate) fn slab4(n: &Node4, r: &Ray32, tmin: f32, tmax: f32) -> ([f32; 4], u32) {
    let mut t0 = [tmin; 4];
    let mut t1 = [tmax; 4];
    for a in 0..3 {
        let (near, far) = (&n.b[r.near[a]][a], &n.b[1 - r.near[a]][a]);
        for i in 0..4 {
            let lo = (near[i] - r.o[a]) * r.inv[a];
            let hi = (far[i] - r.o[a]) * r.inv[a];
            t0[i] = if lo > t0[i] { lo } else { t0[i] };
            t1[i] = if hi < t1[i] { hi } else { t1[i] };
        }
    }
    let mut mask = 0;
    for i in 0..4 {
        mask |= ((t0[i] <= t1[i]) as u32) << i;
    }
    (t0, mask)
}

/// What a traversal does at leaves.
pub(crate) trait Visit {
    /// Current far limit as an f32 that is never below the exact one (see [`far`]): boxes
    /// entered beyond it are skipped.
    fn t_max(&self) -> f32;
    /// Tests primitives `start .. start + count`; true stops the traversal.
    fn leaf(&mut self, start: usize, count: usize) -> bool;
    fn node(&mut self) {}
}

/// The f32 far limit of an f64 one, with the robust test's slack. For distances (t >= 0) it is
/// [`up`] without its branch, which is taken for about half of all distances and so
/// mispredicted as often (it was a third of the packet leaf's time): there one ulp up is the
/// next bit pattern.
#[inline(always)]
pub(crate) fn far(t: f64) -> f32 {
    if t < 0.0 {
        return up(t) * EXIT_SCALE;
    }
    let f = t as f32;
    f32::from_bits(f.to_bits() + ((f as f64) < t) as u32) * EXIT_SCALE
}

const STACK: usize = 96;

/// Visits the leaves whose boxes the ray meets, nearest box first, skipping boxes entered
/// beyond `v.t_max()` (which may shrink as leaves are tested). Returns true if stopped.
pub(crate) fn traverse<V: Visit>(nodes: &[Node4], o: [f64; 3], d: [f64; 3], tmin: f64, v: &mut V) -> bool {
    if nodes.is_empty() {
        return false;
    }
    let r = Ray32::new(o, d);
    walk(nodes, 0, &r, down(tmin), v)
}

/// The traversal loop. Branches are few and predictable where it matters: one hit child is
/// followed without touching the stack, two are ordered by one comparison, only three or four
/// are sorted.
fn walk<V: Visit>(nodes: &[Node4], root: u32, r: &Ray32, tmin: f32, v: &mut V) -> bool {
    // Uninitialised: zeroing it cost as much as a node visit per ray.
    let mut stack = [const { MaybeUninit::<(u32, f32)>::uninit() }; STACK];
    let stack = &mut stack;
    let mut sp = 0usize;
    let mut cur = root;
    'next: loop {
        // `cur` is a node or a leaf to visit.
        if let Some((s, count)) = as_leaf(cur) {
            if v.leaf(s, count) {
                return true;
            }
        } else {
            v.node();
            let n = &nodes[cur as usize];
            let (t, mut mask) = slab4(n, r, tmin, v.t_max());
            if mask != 0 {
                let a = mask.trailing_zeros() as usize;
                mask &= mask - 1;
                if mask == 0 {
                    cur = n.child[a];
                    continue 'next;
                }
                let b = mask.trailing_zeros() as usize;
                mask &= mask - 1;
                if mask == 0 {
                    let (near, far_c, tf) = if t[a] <= t[b] { (a, b, t[b]) } else { (b, a, t[a]) };
                    if !push(stack, &mut sp, n.child[far_c], tf, nodes, r, tmin, v) {
                        return true;
                    }
                    cur = n.child[near];
                    continue 'next;
                }
                // Three or four: farthest pushed first, nearest followed.
                let mut kids = [(n.child[a], t[a]), (n.child[b], t[b]), (0, 0.0), (0, 0.0)];
                let mut k = 2;
                while mask != 0 {
                    let i = mask.trailing_zeros() as usize;
                    mask &= mask - 1;
                    kids[k] = (n.child[i], t[i]);
                    k += 1;
                }
                kids[..k].sort_unstable_by(|x, y| y.1.total_cmp(&x.1));
                for &(c, tc) in &kids[..k - 1] {
                    if !push(stack, &mut sp, c, tc, nodes, r, tmin, v) {
                        return true;
                    }
                }
                cur = kids[k - 1].0;
                continue 'next;
            }
        }
        // Pop the next child that can still hold a nearer (or equally near) hit.
        loop {
            if sp == 0 {
                return false;
            }
            sp -= 1;
            // SAFETY: every entry below `sp` was written by `push`.
            let (c, tc) = unsafe { stack[sp].assume_init() };
            if tc <= v.t_max() {
                cur = c;
                continue 'next;
            }
        }
    }
}

/// Pushes a child for later; on a full stack (a pathologically deep tree) visits it now.
/// False when the traversal was stopped.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn push<V: Visit>(
    stack: &mut [MaybeUninit<(u32, f32)>; STACK],
    sp: &mut usize,
    c: u32,
    t: f32,
    nodes: &[Node4],
    r: &Ray32,
    tmin: f32,
    v: &mut V,
) -> bool {
    if *sp < STACK {
        stack[*sp].write((c, t));
        *sp += 1;
        true
    } else {
        !walk(nodes, c, r, tmin, v)
    }
}
