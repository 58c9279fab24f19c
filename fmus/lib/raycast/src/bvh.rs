//! A bounding-volume hierarchy over object AABBs: binned surface-area-heuristic build,
//! flattened nodes (children stored as adjacent pairs), primitives reordered so a leaf's
//! primitives are contiguous in memory.

/// A node: a leaf when `count > 0` (primitives `start .. start + count`), otherwise an
/// interior node whose children are `start` and `start + 1`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Node {
    pub min: [f64; 3],
    pub max: [f64; 3],
    pub start: u32,
    pub count: u32,
}

pub(crate) struct Bvh {
    pub nodes: Vec<Node>,
    /// Primitive indices (into the caller's list) in leaf order.
    pub order: Vec<u32>,
}

const BINS: usize = 16;
const MAX_LEAF: usize = 1;
/// Cost of visiting a node relative to one primitive test (SAH).
const TRAVERSAL_COST: f64 = 0.3;

#[derive(Clone, Copy)]
struct Aabb {
    min: [f64; 3],
    max: [f64; 3],
}

impl Aabb {
    const EMPTY: Aabb = Aabb { min: [f64::INFINITY; 3], max: [f64::NEG_INFINITY; 3] };

    fn grow(&mut self, o: &Aabb) {
        for i in 0..3 {
            self.min[i] = self.min[i].min(o.min[i]);
            self.max[i] = self.max[i].max(o.max[i]);
        }
    }

    fn grow_point(&mut self, p: [f64; 3]) {
        for (i, &v) in p.iter().enumerate() {
            self.min[i] = self.min[i].min(v);
            self.max[i] = self.max[i].max(v);
        }
    }

    fn area(&self) -> f64 {
        let e = [self.max[0] - self.min[0], self.max[1] - self.min[1], self.max[2] - self.min[2]];
        if e[0] < 0.0 {
            return 0.0;
        }
        2.0 * (e[0] * e[1] + e[1] * e[2] + e[2] * e[0])
    }
}

impl Bvh {
    /// Builds over `boxes` (min, max per primitive).
    pub fn build(boxes: &[([f64; 3], [f64; 3])]) -> Bvh {
        let n = boxes.len();
        let aabbs: Vec<Aabb> = boxes
            .iter()
            .map(|&(mn, mx)| {
                // Pad a hair so the slab test stays conservative at exact boundaries.
                let pad = |v: f64| 1e-9 * (1.0 + v.abs());
                Aabb {
                    min: [mn[0] - pad(mn[0]), mn[1] - pad(mn[1]), mn[2] - pad(mn[2])],
                    max: [mx[0] + pad(mx[0]), mx[1] + pad(mx[1]), mx[2] + pad(mx[2])],
                }
            })
            .collect();
        let centroids: Vec<[f64; 3]> = aabbs
            .iter()
            .map(|b| [0.5 * (b.min[0] + b.max[0]), 0.5 * (b.min[1] + b.max[1]), 0.5 * (b.min[2] + b.max[2])])
            .collect();
        let mut order: Vec<u32> = (0..n as u32).collect();
        let mut nodes = Vec::with_capacity(2 * n.max(1));
        nodes.push(Node { min: [0.0; 3], max: [0.0; 3], start: 0, count: 0 });
        if n == 0 {
            // An empty tree: a root that no ray can enter.
            nodes[0] = Node { min: [f64::INFINITY; 3], max: [f64::NEG_INFINITY; 3], start: 0, count: 0 };
            return Bvh { nodes, order };
        }
        // Iterative build: (node index, start, end).
        let mut work = vec![(0usize, 0usize, n)];
        while let Some((ni, s, e)) = work.pop() {
            let mut bounds = Aabb::EMPTY;
            let mut cb = Aabb::EMPTY;
            for &p in &order[s..e] {
                bounds.grow(&aabbs[p as usize]);
                cb.grow_point(centroids[p as usize]);
            }
            nodes[ni].min = bounds.min;
            nodes[ni].max = bounds.max;
            let count = e - s;
            let make_leaf = |nodes: &mut Vec<Node>| {
                nodes[ni].start = s as u32;
                nodes[ni].count = count as u32;
            };
            if count <= MAX_LEAF {
                make_leaf(&mut nodes);
                continue;
            }
            let mid = match best_split(&aabbs, &centroids, &order[s..e], &cb, bounds.area()) {
                Some((axis, pos)) => {
                    let part = partition(&mut order[s..e], |p| centroids[p as usize][axis] < pos);
                    s + part
                }
                None => {
                    // Splitting does not pay (or centroids coincide): keep a leaf if small
                    // enough, else split at the median along the widest axis.
                    if count <= 4 {
                        make_leaf(&mut nodes);
                        continue;
                    }
                    let axis = widest(&cb);
                    order[s..e].sort_by(|&a, &b| centroids[a as usize][axis].total_cmp(&centroids[b as usize][axis]));
                    s + count / 2
                }
            };
            let mid = if mid == s || mid == e { s + count / 2 } else { mid };
            let left = nodes.len();
            nodes.push(Node { min: [0.0; 3], max: [0.0; 3], start: 0, count: 0 });
            nodes.push(Node { min: [0.0; 3], max: [0.0; 3], start: 0, count: 0 });
            nodes[ni].start = left as u32;
            nodes[ni].count = 0;
            work.push((left + 1, mid, e));
            work.push((left, s, mid));
        }
        Bvh { nodes, order }
    }
}

fn widest(cb: &Aabb) -> usize {
    let e = [cb.max[0] - cb.min[0], cb.max[1] - cb.min[1], cb.max[2] - cb.min[2]];
    if e[0] >= e[1] && e[0] >= e[2] {
        0
    } else if e[1] >= e[2] {
        1
    } else {
        2
    }
}

#[allow(clippy::needless_range_loop)]
/// Binned SAH over all three axes: (axis, split position) if splitting beats a leaf.
fn best_split(
    aabbs: &[Aabb],
    centroids: &[[f64; 3]],
    prims: &[u32],
    cb: &Aabb,
    parent_area: f64,
) -> Option<(usize, f64)> {
    let leaf_cost = prims.len() as f64;
    let mut best: Option<(usize, f64)> = None;
    let mut best_cost = leaf_cost;
    for axis in 0..3 {
        let (lo, hi) = (cb.min[axis], cb.max[axis]);
        if hi - lo <= 1e-12 {
            continue;
        }
        let scale = BINS as f64 / (hi - lo);
        let mut bins = [(Aabb::EMPTY, 0usize); BINS];
        for &p in prims {
            let b = (((centroids[p as usize][axis] - lo) * scale) as usize).min(BINS - 1);
            bins[b].0.grow(&aabbs[p as usize]);
            bins[b].1 += 1;
        }
        // Sweep: right-to-left areas/counts, then left-to-right.
        let mut right_area = [0.0; BINS];
        let mut right_count = [0usize; BINS];
        let (mut acc, mut cnt) = (Aabb::EMPTY, 0);
        for i in (1..BINS).rev() {
            acc.grow(&bins[i].0);
            cnt += bins[i].1;
            right_area[i] = acc.area();
            right_count[i] = cnt;
        }
        let (mut acc, mut cnt) = (Aabb::EMPTY, 0);
        for i in 0..BINS - 1 {
            acc.grow(&bins[i].0);
            cnt += bins[i].1;
            let rc = right_count[i + 1];
            if cnt == 0 || rc == 0 {
                continue;
            }
            let cost =
                TRAVERSAL_COST + (acc.area() * cnt as f64 + right_area[i + 1] * rc as f64) / parent_area.max(1e-300);
            if cost < best_cost {
                best_cost = cost;
                best = Some((axis, lo + (i + 1) as f64 / scale));
            }
        }
    }
    best
}

/// In-place partition; returns the number of elements for which `pred` holds (moved first).
fn partition(v: &mut [u32], pred: impl Fn(u32) -> bool) -> usize {
    let mut i = 0;
    for j in 0..v.len() {
        if pred(v[j]) {
            v.swap(i, j);
            i += 1;
        }
    }
    i
}
