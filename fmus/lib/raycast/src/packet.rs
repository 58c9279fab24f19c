//! Ray packets: up to [`MAX_PACKET`] coherent rays (a camera tile from one origin, a run of
//! LiDAR firings from nearby origins) traverse the 4-wide
//! tree together. A node is entered when the interval of the packet's inverse directions
//! says some ray may meet it (a conservative test: culling by it never loses a hit of any
//! ray); at a leaf every ray is tested against the leaf's box in SIMD lanes, and only rays
//! that pass get the exact f64 primitive test. Each ray keeps its own nearest hit, so the
//! answers are exactly those of single-ray casts; the node work is shared by the packet.
//!
//! The interval bound: per axis the origins lie in [o_lo, o_hi] and the inverse directions in
//! [lo, hi] of one sign; a slab plane's distance (p - o) inv is bilinear in (o, inv), so over
//! the packet it lies between the smallest and largest of its four corner values, and since
//! rounding is monotonic the same holds for the f32 values each ray computes alone.

use crate::wide::{as_leaf, down, far, inverse, near_corner, Node4};
use std::mem::MaybeUninit;

/// Most rays in a packet (at most 64: the visitors keep one bit per ray in a `u64`).
pub const MAX_PACKET: usize = 64;
const _: () = assert!(MAX_PACKET <= 64 && MAX_PACKET.is_multiple_of(8));

/// The rays of a packet, lane-wise (structure of arrays) for the leaf tests.
pub(crate) struct Packet {
    o: [[f32; MAX_PACKET]; 3],
    /// Origin interval per axis.
    o_lo: [f32; 3],
    o_hi: [f32; 3],
    inv: [[f32; MAX_PACKET]; 3],
    /// Per-ray far limit (f32, robust slack included); unused lanes hold -inf.
    pub far: [f32; MAX_PACKET],
    /// Inverse-direction interval per axis.
    lo: [f32; 3],
    hi: [f32; 3],
    /// Per axis, the box corners every ray of the packet meets first (as
    /// [`Ray32::near`](crate::wide::Ray32::near): the rays' directions share their signs).
    near: [usize; 3],
    /// Rays in use (lanes from here on are idle).
    len: usize,
}

impl Packet {
    /// `len` rays at the origin with no extent and no reach (every far limit -inf): lanes
    /// that [`Packet::new`] then fills.
    #[inline(always)]
    fn idle(len: usize) -> Packet {
        Packet {
            o: [[0.0; MAX_PACKET]; 3],
            o_lo: [0.0; 3],
            o_hi: [0.0; 3],
            inv: [[0.0; MAX_PACKET]; 3],
            far: [f32::NEG_INFINITY; MAX_PACKET],
            lo: [0.0; 3],
            hi: [0.0; 3],
            near: [0; 3],
            len,
        }
    }

    /// None when some axis has directions of both signs: the interval test would cull nothing.
    /// `origins` and `dirs` each hold one for all rays or one per ray. Axis by axis over the
    /// lanes, so the conversions, inverses and bounds run in SIMD; inlined so the packet is
    /// built where it is used rather than moved there.
    #[inline(always)]
    pub(crate) fn new(origins: &[[f64; 3]], dirs: &[[f64; 3]], tmax: f64) -> Option<Packet> {
        let n = origins.len().max(dirs.len());
        debug_assert!(
            n <= MAX_PACKET && (origins.len() == 1 || origins.len() == n) && (dirs.len() == 1 || dirs.len() == n)
        );
        let mut p = Packet::idle(n);
        for a in 0..3 {
            let o = &mut p.o[a][..n];
            (p.o_lo[a], p.o_hi[a]) = match origins {
                [one] => {
                    o.fill(one[a] as f32);
                    (one[a] as f32, one[a] as f32)
                }
                _ => {
                    o.iter_mut().zip(origins).for_each(|(v, s)| *v = s[a] as f32);
                    bounds(o)
                }
            };
            // The same inverse as a single ray's (`Ray32::new`).
            let inv = &mut p.inv[a][..n];
            (p.lo[a], p.hi[a]) = match dirs {
                [one] => {
                    inv.fill(inverse(one[a]));
                    (inverse(one[a]), inverse(one[a]))
                }
                _ => {
                    inv.iter_mut().zip(dirs).for_each(|(v, d)| *v = inverse(d[a]));
                    bounds(inv)
                }
            };
        }
        p.far[..n].fill(far(tmax));
        p.near = p.lo.map(near_corner);
        (0..3).all(|a| p.lo[a] > 0.0 || p.hi[a] < 0.0).then_some(p)
    }

    /// The largest far limit: in lanes of 8 (independent running maxima, so SIMD; one chain
    /// through 64 lanes was as long as a node test). The far limits are never NaN, so the
    /// order of the comparisons does not change the result.
    fn far_max(&self) -> f32 {
        // Lanes past `len` hold -inf: whole chunks of 8 are read.
        let mut m = [f32::NEG_INFINITY; 8];
        for c in self.far.chunks_exact(8).take(self.len.div_ceil(8)) {
            for j in 0..8 {
                m[j] = if c[j] > m[j] { c[j] } else { m[j] };
            }
        }
        m.iter().fold(f32::NEG_INFINITY, |a, &f| if f > a { f } else { a })
    }

    /// The rays that may meet the box in lane `lane` of node `n`, one bit each (each ray's
    /// own robust slab test, lane-wise over rays): visitors walk the set bits rather than
    /// test a flag per lane. On x86-64, four rays at a time in SSE (part of every x86-64 CPU)
    /// with the comparisons packed straight into bits: the same operations in the same order
    /// as [`Packet::rays_meeting_scalar`], so the same bits (tested); packing a flag per ray
    /// one by one was a seventh of a LiDAR packet's node work.
    #[inline(always)]
    fn rays_meeting(&self, n: &Node4, lane: usize, tmin: f32) -> u64 {
        #[cfg(target_arch = "x86_64")]
        {
            self.rays_meeting_sse(n, lane, tmin)
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            self.rays_meeting_scalar(n, lane, tmin)
        }
    }

    /// [`Packet::rays_meeting`] one ray at a time: the reference, and the code on other CPUs.
    #[cfg_attr(target_arch = "x86_64", allow(dead_code))]
    #[inline(always)]
    fn rays_meeting_scalar(&self, n: &Node4, lane: usize, tmin: f32) -> u64 {
        let bmin = [n.b[0][0][lane], n.b[0][1][lane], n.b[0][2][lane]];
        let bmax = [n.b[1][0][lane], n.b[1][1][lane], n.b[1][2][lane]];
        let mut hit = [false; MAX_PACKET];
        for i in 0..self.len {
            let mut t0 = tmin;
            let mut t1 = self.far[i];
            for k in 0..3 {
                let x = (bmin[k] - self.o[k][i]) * self.inv[k][i];
                let y = (bmax[k] - self.o[k][i]) * self.inv[k][i];
                let (l, h) = if x < y { (x, y) } else { (y, x) };
                t0 = if l > t0 { l } else { t0 };
                t1 = if h < t1 { h } else { t1 };
            }
            hit[i] = t0 <= t1;
        }
        hit[..self.len].iter().enumerate().fold(0, |m, (i, &h)| m | (h as u64) << i)
    }

    /// [`Packet::rays_meeting`] in SSE. `minps(a, b)` is `a < b ? a : b` and `maxps(a, b)`
    /// is `a > b ? a : b` (the second operand when either is NaN), which are the scalar
    /// version's selects operand for operand. Lanes past `len` are masked off.
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    fn rays_meeting_sse(&self, n: &Node4, lane: usize, tmin: f32) -> u64 {
        use std::arch::x86_64::*;
        let mut bits = 0u64;
        // SAFETY: SSE is part of the x86-64 baseline; every load reads 4 f32 inside an array
        // of MAX_PACKET (a multiple of 4) at an index below it.
        unsafe {
            let bmin = [0, 1, 2].map(|k| _mm_set1_ps(n.b[0][k][lane]));
            let bmax = [0, 1, 2].map(|k| _mm_set1_ps(n.b[1][k][lane]));
            let t_min = _mm_set1_ps(tmin);
            let mut i = 0;
            while i < self.len {
                let mut t0 = t_min;
                let mut t1 = _mm_loadu_ps(self.far.as_ptr().add(i));
                for k in 0..3 {
                    let o = _mm_loadu_ps(self.o[k].as_ptr().add(i));
                    let inv = _mm_loadu_ps(self.inv[k].as_ptr().add(i));
                    let x = _mm_mul_ps(_mm_sub_ps(bmin[k], o), inv);
                    let y = _mm_mul_ps(_mm_sub_ps(bmax[k], o), inv);
                    // l = x < y ? x : y, h = x < y ? y : x.
                    let (l, h) = (_mm_min_ps(x, y), _mm_max_ps(y, x));
                    t0 = _mm_max_ps(l, t0);
                    t1 = _mm_min_ps(h, t1);
                }
                bits |= (_mm_movemask_ps(_mm_cmple_ps(t0, t1)) as u64) << i;
                i += 4;
            }
        }
        bits & u64::MAX.checked_shr((MAX_PACKET - self.len) as u32).unwrap_or(0)
    }

    /// Packet slab test of a node's four boxes: entry bound and mask of possibly met boxes.
    #[inline(always)]
    fn slab4(&self, n: &Node4, tmin: f32, tmax: f32) -> ([f32; 4], u32) {
        let mut t0 = [tmin; 4];
        let mut t1 = [tmax; 4];
        for k in 0..3 {
            let (near, far) = (&n.b[self.near[k]][k], &n.b[1 - self.near[k]][k]);
            for i in 0..4 {
                // Each plane's distance over the packet's (origin, inverse direction) box: its
                // corner values bound every ray's. The entry is the least over the near plane,
                // the exit the greatest over the far one (each ray's near distance is below its
                // far one, so the other plane's corners could not change them).
                let (a0, a1) = (near[i] - self.o_hi[k], near[i] - self.o_lo[k]);
                let (b0, b1) = (far[i] - self.o_hi[k], far[i] - self.o_lo[k]);
                let (lo, hi) = (self.lo[k], self.hi[k]);
                let (ca, cb) = ([a0 * lo, a0 * hi, a1 * lo, a1 * hi], [b0 * lo, b0 * hi, b1 * lo, b1 * hi]);
                let mut entry = ca[0];
                let mut exit = cb[0];
                for j in 1..4 {
                    entry = if ca[j] < entry { ca[j] } else { entry };
                    exit = if cb[j] > exit { cb[j] } else { exit };
                }
                t0[i] = if entry > t0[i] { entry } else { t0[i] };
                t1[i] = if exit < t1[i] { exit } else { t1[i] };
            }
        }
        let mut mask = 0;
        for i in 0..4 {
            mask |= ((t0[i] <= t1[i]) as u32) << i;
        }
        (t0, mask)
    }
}

/// Smallest and largest of `v` (no NaN), over 8 lanes at a time: one running bound through
/// all of `v` was a chain of dependent compares the compiler could not split.
#[inline(always)]
fn bounds(v: &[f32]) -> (f32, f32) {
    let (mut lo, mut hi) = ([f32::INFINITY; 8], [f32::NEG_INFINITY; 8]);
    let mut chunks = v.chunks_exact(8);
    for c in &mut chunks {
        for j in 0..8 {
            lo[j] = if c[j] < lo[j] { c[j] } else { lo[j] };
            hi[j] = if c[j] > hi[j] { c[j] } else { hi[j] };
        }
    }
    for (j, &x) in chunks.remainder().iter().enumerate() {
        lo[j] = if x < lo[j] { x } else { lo[j] };
        hi[j] = if x > hi[j] { x } else { hi[j] };
    }
    let lo = lo.iter().fold(f32::INFINITY, |m, &x| if x < m { x } else { m });
    let hi = hi.iter().fold(f32::NEG_INFINITY, |m, &x| if x > m { x } else { m });
    (lo, hi)
}

/// What a packet traversal does at leaves.
pub(crate) trait PacketVisit {
    /// Tests primitives `start .. start + count` for the rays whose bits `rays` sets,
    /// lowering `packet.far` of the rays whose nearest hit moved closer.
    fn leaf(&mut self, packet: &mut Packet, start: usize, count: usize, rays: u64);
}

const STACK: usize = 96;

/// Orders the first `k` (at most 4) children by entry distance, farthest first, so the
/// nearest is popped first: an insertion sort inline (the library sort's call cost more than
/// the sorting of four).
#[inline(always)]
fn far_first(kids: &mut [(u32, f32); 4], k: usize) {
    for i in 1..k {
        let x = kids[i];
        let mut j = i;
        while j > 0 && kids[j - 1].1.total_cmp(&x.1).is_lt() {
            kids[j] = kids[j - 1];
            j -= 1;
        }
        kids[j] = x;
    }
}

/// Visits, for each ray, every leaf whose box it may meet before its current far limit.
pub(crate) fn traverse_packet<V: PacketVisit>(nodes: &[Node4], p: &mut Packet, tmin: f64, v: &mut V) {
    if nodes.is_empty() {
        return;
    }
    let tmin = down(tmin);
    let mut stack = [const { MaybeUninit::<(u32, f32)>::uninit() }; STACK];
    let mut sp = 0usize;
    let mut cur = 0u32;
    let mut far_max = p.far_max();
    // `cur` is always an interior node: leaves are tested where their parent's lane (their
    // box) is at hand.
    'next: loop {
        let n = &nodes[cur as usize];
        let (t, mut mask) = p.slab4(n, tmin, far_max);
        // Leaves now (their rays tested lane-wise), interior children ordered near to far.
        let mut kids = [(0u32, 0f32); 4];
        let mut k = 0;
        while mask != 0 {
            let i = mask.trailing_zeros() as usize;
            mask &= mask - 1;
            match as_leaf(n.child[i]) {
                Some((s, count)) => {
                    let rays = p.rays_meeting(n, i, tmin);
                    if rays != 0 {
                        v.leaf(p, s, count, rays);
                        far_max = p.far_max();
                    }
                }
                None => {
                    kids[k] = (n.child[i], t[i]);
                    k += 1;
                }
            }
        }
        far_first(&mut kids, k);
        for &(c, tc) in &kids[..k] {
            if sp < STACK {
                stack[sp].write((c, tc));
                sp += 1;
            } else {
                // A pathologically deep tree: finish this child recursively.
                traverse_from(nodes, c, p, tmin, v);
                far_max = p.far_max();
            }
        }
        loop {
            if sp == 0 {
                return;
            }
            sp -= 1;
            // SAFETY: every entry below `sp` was written above.
            let (c, tc) = unsafe { stack[sp].assume_init() };
            if tc <= far_max {
                cur = c;
                continue 'next;
            }
        }
    }
}

/// [`traverse_packet`] from an interior node other than the root (stack overflow fallback).
fn traverse_from<V: PacketVisit>(nodes: &[Node4], root: u32, p: &mut Packet, tmin: f32, v: &mut V) {
    let n = &nodes[root as usize];
    let (_, mask) = p.slab4(n, tmin, p.far_max());
    for i in 0..4 {
        if mask & (1 << i) == 0 {
            continue;
        }
        match as_leaf(n.child[i]) {
            Some((s, count)) => {
                let rays = p.rays_meeting(n, i, tmin);
                if rays != 0 {
                    v.leaf(p, s, count, rays);
                }
            }
            None => traverse_from(nodes, n.child[i], p, tmin, v),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use agrisim_math::Rng;

    /// A value for a lane: mostly ordinary, sometimes a tie, zero, an infinity or NaN.
    fn value(rng: &mut Rng, scale: f32) -> f32 {
        match rng.below(40) {
            0 => f32::NAN,
            1 => f32::INFINITY,
            2 => f32::NEG_INFINITY,
            3 => 0.0,
            4 => -0.0,
            5 => 1.0,
            _ => ((2.0 * rng.uniform() - 1.0) as f32) * scale,
        }
    }

    /// The far limits' maximum in lanes of 8 is the plain one, for every packet length.
    #[test]
    fn far_max_is_the_largest_far_limit() {
        let mut rng = Rng::new(16);
        for len in 1..=MAX_PACKET {
            let dirs: Vec<[f64; 3]> = (0..len).map(|_| [0.5, 0.25, -0.75]).collect();
            let mut p = Packet::new(&[[0.0; 3]], &dirs, 100.0).expect("one sign per axis");
            for i in 0..len {
                p.far[i] = value(&mut rng, 30.0).abs();
            }
            let plain = p.far[..len].iter().fold(f32::NEG_INFINITY, |m, &f| if f > m { f } else { m });
            assert_eq!(p.far_max().to_bits(), plain.to_bits(), "len {len}");
        }
    }

    /// The SSE test gives the bits of the scalar reference on random packets of every length,
    /// boxes and near limits, special values included (NaN, infinities, signed zeros, ties).
    #[cfg(target_arch = "x86_64")]
    #[test]
    fn rays_meeting_in_sse_equals_the_scalar_reference() {
        let mut rng = Rng::new(15);
        let mut set = 0u64;
        for case in 0..20_000 {
            let len = 1 + case % MAX_PACKET;
            let mut p = Packet::idle(len);
            for i in 0..len {
                for k in 0..3 {
                    p.o[k][i] = value(&mut rng, 4.0);
                    p.inv[k][i] = value(&mut rng, 50.0);
                }
                p.far[i] = value(&mut rng, 20.0).abs();
            }
            let mut n = Node4 { b: [[[0.0; 4]; 3]; 2], child: [0; 4] };
            for lane in 0..4 {
                for k in 0..3 {
                    let (a, b) = (value(&mut rng, 3.0), value(&mut rng, 3.0));
                    (n.b[0][k][lane], n.b[1][k][lane]) = if a < b { (a, b) } else { (b, a) };
                }
            }
            let tmin = if rng.below(10) == 0 { value(&mut rng, 1.0) } else { 0.0 };
            for lane in 0..4 {
                let (sse, scalar) = (p.rays_meeting_sse(&n, lane, tmin), p.rays_meeting_scalar(&n, lane, tmin));
                assert_eq!(sse, scalar, "case {case}, lane {lane}, len {len}");
                set += scalar.count_ones() as u64;
            }
        }
        // Not a vacuous comparison: many rays do meet their boxes.
        assert!(set > 100_000, "{set} bits set");
    }
}
