//! 3-vectors and 3x3 matrices as plain `[f64; 3]` / row-major `[[f64; 3]; 3]`: the few
//! products the models need, written once instead of per crate, without a linear-algebra
//! dependency in the FMUs and the ray caster.
//!
//! Each function fixes its floating-point operation order (left to right, no fused
//! multiply-add), which the byte-compared camera images, point clouds and trial logs depend
//! on: do not reorder an expression here. All are `#[inline(always)]` because the ray
//! caster calls them in its innermost loops, across the crate boundary.

/// A vector (or point) in 3-D.
pub type Vec3 = [f64; 3];
/// A row-major 3x3 matrix: `m[row][column]`.
pub type Mat3 = [[f64; 3]; 3];

pub const IDENTITY: Mat3 = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

/// `a + b`.
#[inline(always)]
pub fn add(a: Vec3, b: Vec3) -> Vec3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

/// `a - b`.
#[inline(always)]
pub fn sub(a: Vec3, b: Vec3) -> Vec3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// `a k`.
#[inline(always)]
pub fn scale(a: Vec3, k: f64) -> Vec3 {
    [a[0] * k, a[1] * k, a[2] * k]
}

/// `a . b`, summed x, y, z in that order.
#[inline(always)]
pub fn dot(a: Vec3, b: Vec3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// `a x b` (right-handed).
#[inline(always)]
pub fn cross(a: Vec3, b: Vec3) -> Vec3 {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

/// Euclidean length `|a|`.
#[inline(always)]
pub fn norm(a: Vec3) -> f64 {
    dot(a, a).sqrt()
}

/// `a / |a|`, each component divided (not multiplied by `1 / |a|`). A zero vector gives NaN:
/// callers check their input where one can occur.
#[inline(always)]
pub fn normalize(a: Vec3) -> Vec3 {
    let n = norm(a);
    [a[0] / n, a[1] / n, a[2] / n]
}

/// `m v`.
#[inline(always)]
pub fn mat_vec(m: &Mat3, v: Vec3) -> Vec3 {
    [dot(m[0], v), dot(m[1], v), dot(m[2], v)]
}

/// `m^T v`, without forming the transpose (a local frame's coordinates of a map vector when
/// `m` rotates local -> map).
#[inline(always)]
pub fn mat_t_vec(m: &Mat3, v: Vec3) -> Vec3 {
    [0, 1, 2].map(|j| m[0][j] * v[0] + m[1][j] * v[1] + m[2][j] * v[2])
}

/// `a b`.
#[inline(always)]
pub fn mat_mul(a: &Mat3, b: &Mat3) -> Mat3 {
    [0, 1, 2].map(|i| [0, 1, 2].map(|j| a[i][0] * b[0][j] + a[i][1] * b[1][j] + a[i][2] * b[2][j]))
}

/// `m^T`.
#[inline(always)]
pub fn transpose(m: &Mat3) -> Mat3 {
    [[m[0][0], m[1][0], m[2][0]], [m[0][1], m[1][1], m[2][1]], [m[0][2], m[1][2], m[2][2]]]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Rng;

    fn random_vec(rng: &mut Rng) -> Vec3 {
        [rng.range(-10.0, 10.0), rng.range(-10.0, 10.0), rng.range(-10.0, 10.0)]
    }

    fn random_mat(rng: &mut Rng) -> Mat3 {
        [random_vec(rng), random_vec(rng), random_vec(rng)]
    }

    #[test]
    fn analytic_cases() {
        let (x, y, z) = ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]);
        assert_eq!(cross(x, y), z);
        assert_eq!(cross(y, z), x);
        assert_eq!(cross(z, x), y);
        assert_eq!(cross(y, x), [0.0, 0.0, -1.0]);
        assert_eq!(dot([1.0, 2.0, 3.0], [4.0, -5.0, 6.0]), 12.0);
        assert_eq!(add([1.0, 2.0, 3.0], [0.5, -2.0, 1.0]), [1.5, 0.0, 4.0]);
        assert_eq!(sub([1.0, 2.0, 3.0], [0.5, -2.0, 1.0]), [0.5, 4.0, 2.0]);
        assert_eq!(scale([1.0, -2.0, 3.0], -2.0), [-2.0, 4.0, -6.0]);
        assert_eq!(norm([3.0, 4.0, 12.0]), 13.0);
        assert_eq!(normalize([0.0, -3.0, 4.0]), [0.0, -0.6, 0.8]);
        assert!(normalize([0.0; 3]).iter().all(|v| v.is_nan()));
        // A quarter turn about z: x -> y; its transpose turns back.
        let rz = [[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]];
        assert_eq!(mat_vec(&rz, x), y);
        assert_eq!(mat_t_vec(&rz, y), x);
        assert_eq!(transpose(&rz), [[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]);
        assert_eq!(mat_mul(&rz, &transpose(&rz)), IDENTITY);
        assert_eq!(mat_mul(&rz, &rz), [[-1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, 1.0]]);
        let a = [[1.0, 2.0, 3.0], [4.0, 5.0, 6.0], [7.0, 8.0, 10.0]];
        let b = [[2.0, 0.0, 1.0], [1.0, 3.0, 0.0], [0.0, 1.0, 4.0]];
        assert_eq!(mat_mul(&a, &b), [[4.0, 9.0, 13.0], [13.0, 21.0, 28.0], [22.0, 34.0, 47.0]]);
        assert_eq!(mat_mul(&IDENTITY, &a), a);
    }

    /// The cross product is orthogonal to both inputs and obeys Lagrange's identity
    /// |a x b|^2 + (a . b)^2 = |a|^2 |b|^2; the matrix products agree with each other.
    #[test]
    fn identities_hold_for_random_inputs() {
        let mut rng = Rng::scene(7);
        for _ in 0..10_000 {
            let (a, b) = (random_vec(&mut rng), random_vec(&mut rng));
            let c = cross(a, b);
            let scale2 = dot(a, a) * dot(b, b);
            let tol = 1e-12 * scale2.max(1.0);
            assert!(dot(c, a).abs() <= 1e-12 * norm(a) * norm(a) * norm(b), "{a:?} {b:?}");
            assert!(dot(c, b).abs() <= 1e-12 * norm(a) * norm(b) * norm(b), "{a:?} {b:?}");
            assert!((dot(c, c) + dot(a, b) * dot(a, b) - scale2).abs() <= tol, "{a:?} {b:?}");
            assert_eq!(cross(b, a), scale(c, -1.0));
            assert!((norm(normalize(a)) - 1.0).abs() < 1e-15);

            let (m, n) = (random_mat(&mut rng), random_mat(&mut rng));
            assert_eq!(mat_t_vec(&m, a), mat_vec(&transpose(&m), a));
            assert_eq!(transpose(&transpose(&m)), m);
            // (m n) a = m (n a) up to rounding, bounded by the sums of magnitudes.
            let (mn_a, m_na) = (mat_vec(&mat_mul(&m, &n), a), mat_vec(&m, mat_vec(&n, a)));
            let abs = |m: Mat3| m.map(|r| r.map(f64::abs));
            let bound = mat_vec(&abs(m), mat_vec(&abs(n), a.map(f64::abs)));
            for k in 0..3 {
                assert!((mn_a[k] - m_na[k]).abs() <= 1e-14 * bound[k], "{m:?} {n:?} {a:?}");
            }
        }
    }
}
