//! A robust sphere fit to the visible cap of a fruit.
//!
//! A depth camera sees at most the half of a sphere facing it, so a plain algebraic fit is
//! ill-conditioned along the view ray: a small error of the cap's curvature moves the centre
//! a lot. The fit here is geometric (distances to the surface), starts from the cap's
//! centroid pushed back along the view ray by half a radius (the centroid of a hemisphere),
//! keeps the radius within known bounds, pulls it weakly toward a prior, and reweights the
//! points (Tukey's biweight on a MAD scale), so stray points of a leaf or a neighbour in the
//! segment do not drag the centre.

use nalgebra::{Matrix4, Vector3, Vector4};

/// What the fit may assume about the fruit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SphereBounds {
    pub min_radius: f64,
    pub max_radius: f64,
    /// The radius the fit is pulled toward when the cap says little [m].
    pub prior_radius: f64,
    /// Weight of that pull: as many points as this, each 1 mm off the surface, cost as much
    /// as the radius `prior_sigma` off the prior.
    pub prior_weight: f64,
    pub prior_sigma: f64,
}

impl Default for SphereBounds {
    fn default() -> Self {
        SphereBounds {
            min_radius: 0.020,
            max_radius: 0.045,
            prior_radius: 0.031,
            prior_weight: 2.0,
            prior_sigma: 0.010,
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sphere {
    pub center: [f64; 3],
    pub radius: f64,
    /// RMS distance of the inliers to the surface [m].
    pub rms: f64,
    /// Fraction of the points with non-zero weight in the last iteration.
    pub inlier_fraction: f64,
    /// Whether the radius ended on one of its bounds (the data wanted a smaller or larger one).
    pub at_bound: bool,
}

/// Tukey's cut-off for residuals `res`: 4.685 times the normal scale of their median absolute
/// value (MAD), kept between 3 and 15 mm, so a fit dragged by many stray points still sheds
/// the ones a few centimetres off. `abs` is a buffer kept across calls.
#[inline(always)]
fn tukey_scale(res: &[f64], abs: &mut Vec<u64>) -> f64 {
    const K: f64 = 4.685 * 1.4826;
    const LO: f64 = 0.003;
    const HI: f64 = 0.015;
    let (n, mid) = (res.len(), res.len() / 2);
    // A median past a bound needs no selection: K |e| rises with |e|, so the median's cut-off
    // reaches HI exactly when at least n - mid residuals' do (and LO alike). Counting is a
    // fraction of the selection's cost, and on the perception benchmark's frames 7 in 10 of
    // the fits' iterations end at HI. The result is the same number either way.
    let (mut above, mut below, mut nan) = (0usize, 0usize, 0usize);
    for e in res {
        let x = K * e.abs();
        above += (x >= HI) as usize;
        below += (x <= LO) as usize;
        nan += x.is_nan() as usize;
    }
    // A NaN residual is never counted and sorts last by its bits: with NaNs the count above
    // could say HI of a NaN median (the count below cannot be wrong).
    if nan == 0 && above >= n - mid {
        return HI;
    }
    if below > mid {
        return LO;
    }
    // |e| as its bits: a non-negative float orders as its bit pattern, so the median is the
    // same number, selected on integers (cheaper than f64::total_cmp). The median by
    // selection (linear) rather than a sort: the sort was a quarter of the detector's time.
    abs.clear();
    abs.extend(res.iter().map(|e| e.abs().to_bits()));
    let mad = f64::from_bits(*abs.select_nth_unstable(mid).1);
    (K * mad).clamp(LO, HI)
}

/// The weighted normal equations `H = sum w j j^T`, `g = sum w j e` of one Gauss-Newton step,
/// with `j = [u, -1]` and `u = -(p - c)/|p - c|`. The -1 of `j` is taken out of the sums
/// (every product with it is an exact negation, and `0.0 - sum` is the sum of the negated
/// terms to the bit, the sign of a zero included), so with `b = [u, 1]` and `t = w b` the
/// sums are four rows of four lanes: `t_a b` for the rows of `H` (the last lane `t_a` is
/// the negated last column) and `t e` for `g` (the last lane `w e`), one 256-bit multiply
/// and add per row with AVX2. Rust never fuses a multiply and an add, so each lane is the
/// same bits as one `h[(a, b)] += (w j_a) j_b` per entry.
#[inline(always)]
fn normal_equations(
    cloud: &Cloud,
    res: &[f64],
    w: &[f64],
    dist: &[f64],
    c: &Vector3<f64>,
) -> (Matrix4<f64>, Vector4<f64>) {
    let mut acc = [[0.0f64; 4]; 4];
    let mut sw = 0.0;
    let n = res.len();
    let (xs, ys, zs, w, dist) = (&cloud.x[..n], &cloud.y[..n], &cloud.z[..n], &w[..n], &dist[..n]);
    for i in 0..n {
        let (wi, dn, e) = (w[i], dist[i], res[i]);
        if wi == 0.0 || dn < 1e-9 {
            continue;
        }
        let b = [-(xs[i] - c.x) / dn, -(ys[i] - c.y) / dn, -(zs[i] - c.z) / dn, 1.0];
        let t = [wi * b[0], wi * b[1], wi * b[2], wi * b[3]];
        for (row, ta) in acc[..3].iter_mut().zip(t) {
            for k in 0..4 {
                row[k] += ta * b[k];
            }
        }
        for k in 0..4 {
            acc[3][k] += t[k] * e;
        }
        sw += wi;
    }
    let mut h = Matrix4::<f64>::zeros();
    let mut g = Vector4::<f64>::zeros();
    for a in 0..3 {
        for b in 0..3 {
            h[(a, b)] = acc[a][b];
        }
        h[(a, 3)] = 0.0 - acc[a][3];
        h[(3, a)] = 0.0 - acc[a][3];
        g[a] = acc[3][a];
    }
    h[(3, 3)] = sw;
    g[3] = 0.0 - acc[3][3];
    (h, g)
}

/// Fits a sphere to `points` seen from the origin (the camera's optical centre). `None` for
/// fewer than 8 points or a degenerate set.
pub fn fit_sphere(points: &[[f64; 3]], bounds: &SphereBounds) -> Option<Sphere> {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU has AVX2, checked just above.
        return unsafe { fit_sphere_avx2(points, bounds) };
    }
    fit_sphere_body(points, bounds)
}

/// The same fit compiled for AVX2: the normal equations' 16 lanes in four 256-bit registers.
/// AVX2 brings no fused multiply-add (that is the separate `fma` feature), so its sums are
/// the same bits as the baseline build's.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn fit_sphere_avx2(points: &[[f64; 3]], bounds: &SphereBounds) -> Option<Sphere> {
    fit_sphere_body(points, bounds)
}

/// The points as three arrays (x, y, z), so a pass over them loads whole registers of each
/// coordinate.
struct Cloud {
    x: Vec<f64>,
    y: Vec<f64>,
    z: Vec<f64>,
}

impl Cloud {
    /// Each point's distance to `c`, as nalgebra's `(p - c).norm()` computes it to the bit
    /// (`(dx dx + dy dy) + dz dz`, then the root), and its residual from the radius `r`.
    #[inline(always)]
    fn distances(&self, c: &Vector3<f64>, r: f64, dist: &mut [f64], res: &mut [f64]) {
        let n = dist.len();
        let (xs, ys, zs, res) = (&self.x[..n], &self.y[..n], &self.z[..n], &mut res[..n]);
        for i in 0..n {
            let (dx, dy, dz) = (xs[i] - c.x, ys[i] - c.y, zs[i] - c.z);
            let d = (dx * dx + dy * dy + dz * dz).sqrt();
            dist[i] = d;
            res[i] = d - r;
        }
    }
}

#[inline(always)]
fn fit_sphere_body(points: &[[f64; 3]], bounds: &SphereBounds) -> Option<Sphere> {
    if points.len() < 8 {
        return None;
    }
    let pts: Vec<Vector3<f64>> = points.iter().map(|p| Vector3::new(p[0], p[1], p[2])).collect();
    let n = pts.len() as f64;
    let mean = pts.iter().sum::<Vector3<f64>>() / n;
    let view = mean.try_normalize(1e-9)?;
    // Lateral spread about the centroid: a disc of radius r seen face on has variance r^2/4
    // along each lateral axis.
    let lateral: f64 = pts
        .iter()
        .map(|p| {
            let d = p - mean;
            (d - view * d.dot(&view)).norm_squared()
        })
        .sum::<f64>()
        / n;
    let r0 = (2.0 * (lateral / 2.0).sqrt()).clamp(bounds.min_radius, bounds.max_radius);
    let mut c = mean + view * (0.5 * r0);
    let mut r = r0;
    let mut w = vec![1.0; pts.len()];
    let mut at_bound = false;
    // Each point's distance to the centre and residual in this iteration, and the buffer of
    // the median, kept across iterations (the distance once per point and iteration).
    let (mut dist, mut res, mut abs) = (vec![0.0; pts.len()], vec![0.0; pts.len()], Vec::with_capacity(pts.len()));
    let cloud = Cloud {
        x: points.iter().map(|p| p[0]).collect(),
        y: points.iter().map(|p| p[1]).collect(),
        z: points.iter().map(|p| p[2]).collect(),
    };
    for it in 0..30 {
        // Residuals and robust weights (after the first pass).
        cloud.distances(&c, r, &mut dist, &mut res);
        if it > 0 {
            let scale = tukey_scale(&res, &mut abs);
            for (wi, e) in w.iter_mut().zip(&res) {
                let u = e / scale;
                *wi = if u.abs() < 1.0 { (1.0 - u * u).powi(2) } else { 0.0 };
            }
        }
        // Gauss-Newton on (c, r): residual e_i = |p_i - c| - r, de/dc = -(p_i - c)/|p_i - c|,
        // de/dr = -1; the prior adds sqrt(lambda) (r - r_prior) with unit scale in mm.
        let (mut h, mut g) = normal_equations(&cloud, &res, &w, &dist, &c);
        let lambda = bounds.prior_weight * (0.001 / bounds.prior_sigma).powi(2);
        h[(3, 3)] += lambda;
        g[3] += lambda * (r - bounds.prior_radius);
        // A touch of damping keeps the step finite on a flat or tiny cap.
        for k in 0..4 {
            h[(k, k)] += 1e-6 + 1e-3 * h[(k, k)];
        }
        let step = h.lu().solve(&(-g))?;
        c += Vector3::new(step[0], step[1], step[2]);
        r += step[3];
        at_bound = !(bounds.min_radius..=bounds.max_radius).contains(&r);
        r = r.clamp(bounds.min_radius, bounds.max_radius);
        // The centre lies behind the visible surface.
        let depth_gap = (c - mean).dot(&view);
        if depth_gap < 0.0 {
            c -= view * depth_gap;
        }
        if step.norm() < 1e-7 {
            break;
        }
    }
    if !c.iter().all(|v| v.is_finite()) {
        return None;
    }
    let (mut sw, mut se2, mut inl) = (0.0, 0.0, 0usize);
    for (p, wi) in pts.iter().zip(&w) {
        if *wi > 0.0 {
            let e = (p - c).norm() - r;
            sw += 1.0;
            se2 += e * e;
            inl += 1;
        }
    }
    if inl == 0 {
        return None;
    }
    Some(Sphere {
        center: [c.x, c.y, c.z],
        radius: r,
        rms: (se2 / sw).sqrt(),
        inlier_fraction: inl as f64 / n,
        at_bound,
    })
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// A small seeded generator (SplitMix64) for the test data.
    pub(crate) struct Mix(pub u64);
    impl Mix {
        pub fn next(&mut self) -> f64 {
            self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut z = self.0;
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
        }
        pub fn normal(&mut self) -> f64 {
            let (u, v) = (self.next().max(1e-300), self.next());
            (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
        }
    }

    /// Points of the cap of a sphere visible from the origin, seen through a pinhole camera:
    /// for pixels on a grid, the ray's first hit, with depth noise of `sigma` along z, and
    /// only within `max_angle` of the cap's middle (a partly hidden fruit shows less).
    pub(crate) fn cap(
        c: [f64; 3],
        r: f64,
        sigma: f64,
        keep: impl Fn(f64, f64) -> bool,
        rng: &mut Mix,
    ) -> Vec<[f64; 3]> {
        let f = 400.0;
        let (u0, v0) = (c[0] / c[2] * f, c[1] / c[2] * f);
        let span = (r / (c[2] - r) * f).ceil() as i32 + 1;
        let mut out = vec![];
        for dv in -span..=span {
            for du in -span..=span {
                let (u, v) = (u0 + du as f64, v0 + dv as f64);
                if !keep(du as f64 / span as f64, dv as f64 / span as f64) {
                    continue;
                }
                let d = Vector3::new(u / f, v / f, 1.0).normalize();
                let cc = Vector3::new(c[0], c[1], c[2]);
                let b = d.dot(&cc);
                let disc = b * b - (cc.norm_squared() - r * r);
                if disc < 0.0 {
                    continue;
                }
                let t = b - disc.sqrt();
                let p = d * t;
                let z = p.z + sigma * rng.normal();
                let s = z / p.z;
                out.push([p.x * s, p.y * s, z]);
            }
        }
        out
    }

    fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
        ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
    }

    /// The cut-off by counting past the bounds is the cut-off by selecting the median, to the
    /// bit: 20 000 random residual sets of 8-600 points, their medians spread over and around
    /// both bounds, with residuals placed exactly on a bound's preimage, and NaNs.
    #[test]
    fn counting_past_the_bounds_gives_the_median_cut_off() {
        let k = 4.685 * 1.4826;
        let by_median = |res: &[f64]| {
            let mut a: Vec<u64> = res.iter().map(|e| e.abs().to_bits()).collect();
            let mid = a.len() / 2;
            (k * f64::from_bits(*a.select_nth_unstable(mid).1)).clamp(0.003, 0.015)
        };
        let mut rng = Mix(42);
        let mut buf = Vec::new();
        let (mut at_lo, mut at_hi, mut between) = (0, 0, 0);
        for case in 0..20_000 {
            let n = 8 + (rng.next() * 593.0) as usize;
            // A typical size of residual between 0.1 and 6 mm, so medians fall on both sides
            // of both bounds (0.43 and 2.16 mm).
            let size = 1e-4 * 60f64.powf(rng.next());
            let mut res: Vec<f64> = (0..n).map(|_| size * rng.normal()).collect();
            match case % 5 {
                // Residuals whose cut-off is exactly a bound.
                1 => res.iter_mut().step_by(3).for_each(|e| *e = 0.015 / k),
                2 => res.iter_mut().step_by(2).for_each(|e| *e = -0.003 / k),
                // One NaN; or half of them, the rest past the upper bound (for an even count,
                // the median is then a NaN although half the residuals are past the bound).
                3 if case % 50 == 13 => res[0] = f64::NAN,
                3 if case % 50 == 3 => {
                    res.iter_mut().for_each(|e| *e = 0.01 + e.abs());
                    res[..n / 2].fill(f64::NAN);
                }
                _ => {}
            }
            let (want, got) = (by_median(&res), tukey_scale(&res, &mut buf));
            assert_eq!(want.to_bits(), got.to_bits(), "case {case}: {want} != {got}");
            if got == 0.003 {
                at_lo += 1;
            } else if got == 0.015 {
                at_hi += 1;
            } else {
                between += 1;
            }
        }
        // Every branch was taken many times.
        assert!(at_lo > 1000 && at_hi > 1000 && between > 1000, "{at_lo} {at_hi} {between}");
    }

    /// The lanes of `normal_equations` are the per-entry sums `h[(a, b)] += (w j_a) j_b`,
    /// `g[a] += (w j_a) e` to the bit, over 5 000 random point sets with zero weights, a point
    /// on the centre (skipped), and residuals of both signs.
    #[test]
    fn the_normal_equations_lanes_are_the_per_entry_sums() {
        let mut rng = Mix(11);
        for case in 0..5_000 {
            let n = 1 + (rng.next() * 300.0) as usize;
            let c = Vector3::new(rng.normal(), rng.normal(), 1.0 + rng.next());
            let cloud = Cloud {
                x: (0..n).map(|_| c.x + 0.05 * rng.normal()).collect(),
                y: (0..n).map(|_| c.y + 0.05 * rng.normal()).collect(),
                z: (0..n).map(|_| c.z + 0.05 * rng.normal()).collect(),
            };
            let (mut dist, mut res) = (vec![0.0; n], vec![0.0; n]);
            cloud.distances(&c, 0.03, &mut dist, &mut res);
            if case % 7 == 0 {
                dist[0] = 0.0;
            }
            let w: Vec<f64> = (0..n).map(|_| if rng.next() < 0.2 { 0.0 } else { rng.next() }).collect();
            let (mut h, mut g) = (Matrix4::<f64>::zeros(), Vector4::<f64>::zeros());
            for i in 0..n {
                let p = Vector3::new(cloud.x[i], cloud.y[i], cloud.z[i]);
                assert_eq!(dist[i].to_bits(), if case % 7 == 0 && i == 0 { 0 } else { (p - c).norm().to_bits() });
                if w[i] == 0.0 || dist[i] < 1e-9 {
                    continue;
                }
                let u = -(p - c) / dist[i];
                let j = [u.x, u.y, u.z, -1.0];
                for a in 0..4 {
                    for b in 0..4 {
                        h[(a, b)] += w[i] * j[a] * j[b];
                    }
                    g[a] += w[i] * j[a] * res[i];
                }
            }
            let (h2, g2) = normal_equations(&cloud, &res, &w, &dist, &c);
            let bits = |m: &[f64]| m.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(h.as_slice()), bits(h2.as_slice()), "case {case}");
            assert_eq!(bits(g.as_slice()), bits(g2.as_slice()), "case {case}");
        }
    }

    /// The fit compiled for AVX2 (where the CPU has it) returns the baseline build's fit to
    /// the bit: 2 000 random caps, whole and half hidden, with stray points.
    #[test]
    fn the_avx2_fit_is_the_baseline_fit() {
        let mut rng = Mix(5);
        for case in 0..2_000 {
            let r = 0.02 + 0.025 * rng.next();
            let c = [0.3 * (rng.next() - 0.5), 0.3 * (rng.next() - 0.5), 0.4 + 0.8 * rng.next()];
            let mut pts = cap(c, r, 0.003 * rng.next(), |du, dv| case % 3 != 1 || du + dv < 0.2, &mut rng);
            for _ in 0..(case % 4) * pts.len() / 10 {
                let p = pts[(rng.next() * pts.len() as f64) as usize];
                pts.push([p[0] + 0.02 * rng.normal(), p[1], p[2] - 0.04 * rng.next()]);
            }
            let (base, fast) =
                (fit_sphere_body(&pts, &SphereBounds::default()), fit_sphere(&pts, &SphereBounds::default()));
            assert_eq!(format!("{base:?}"), format!("{fast:?}"), "case {case}");
        }
    }

    /// Noise-free caps give the sphere back to well under a millimetre.
    #[test]
    fn exact_cap_is_recovered() {
        let mut rng = Mix(1);
        for (c, r) in [([0.05, -0.02, 0.6], 0.03), ([-0.2, 0.1, 0.9], 0.022), ([0.0, 0.0, 0.45], 0.04)] {
            let pts = cap(c, r, 0.0, |_, _| true, &mut rng);
            let s = fit_sphere(&pts, &SphereBounds::default()).unwrap();
            assert!(dist(s.center, c) < 2e-4, "{c:?} {r}: {s:?}");
            assert!((s.radius - r).abs() < 2e-4, "{c:?} {r}: {s:?}");
        }
    }

    /// Stereo-like noise (2 mm at 0.7 m) and a cap half hidden: the centre within 4 mm and
    /// the radius within 3 mm, over many seeds (the statistics of the fit, not one lucky draw).
    #[test]
    fn noisy_and_partial_caps_stay_close() {
        let mut rng = Mix(7);
        let mut errs = vec![];
        for k in 0..40 {
            let r = 0.025 + 0.015 * rng.next();
            let c = [0.2 * (rng.next() - 0.5), 0.2 * (rng.next() - 0.5), 0.55 + 0.3 * rng.next()];
            let half = k % 2 == 1;
            let pts = cap(c, r, 0.002, |du, _| !half || du < 0.1, &mut rng);
            let s = fit_sphere(&pts, &SphereBounds::default()).unwrap();
            assert!((s.radius - r).abs() < 0.006, "radius {} vs {r}", s.radius);
            errs.push(dist(s.center, c));
        }
        errs.sort_by(f64::total_cmp);
        let p90 = errs[errs.len() * 9 / 10];
        assert!(p90 < 0.004, "p90 centre error {p90}, all {errs:?}");
    }

    /// A fifth of the points from a leaf 5 cm in front do not move the centre much.
    #[test]
    fn outliers_are_rejected() {
        let mut rng = Mix(3);
        let c = [0.03, 0.01, 0.7];
        let mut pts = cap(c, 0.03, 0.001, |_, _| true, &mut rng);
        let n = pts.len() / 5;
        for i in 0..n {
            let p = pts[i * 4];
            pts.push([p[0] + 0.01, p[1], p[2] - 0.05]);
        }
        let s = fit_sphere(&pts, &SphereBounds::default()).unwrap();
        assert!(dist(s.center, c) < 0.003, "{s:?}");
        assert!(s.inlier_fraction < 0.9, "the leaf points were not down-weighted: {s:?}");
    }

    #[test]
    fn too_few_points_or_a_plane_is_no_sphere_of_the_right_size() {
        assert!(fit_sphere(&[[0.0, 0.0, 1.0]; 5], &SphereBounds::default()).is_none());
        let mut plane = vec![];
        for i in 0..20 {
            for j in 0..20 {
                plane.push([-0.05 + 0.005 * i as f64, -0.05 + 0.005 * j as f64, 0.8]);
            }
        }
        // A flat patch 10 cm across is no fruit: no fit, or one at the radius bound or far off.
        if let Some(s) = fit_sphere(&plane, &SphereBounds::default()) {
            assert!(s.at_bound || s.rms > 0.004 || s.inlier_fraction < 0.6, "{s:?}");
        }
    }
}
