//! Triangulation of the analytic primitives, for export and for mesh-based peers. Vertices
//! lie on the true surface (inscribed polygons), winding counter-clockwise seen from outside.

use agrisim_scene::{Object, Shape};

/// Segments around a cylinder and a sphere, and latitude bands of a sphere.
pub const CYLINDER_SEGMENTS: usize = 16;
pub const SPHERE_SEGMENTS: usize = 16;
pub const SPHERE_RINGS: usize = 8;

/// Appends the triangulated `o` (map frame) to `verts` / `tris`.
pub fn append(o: &Object, verts: &mut Vec<[f32; 3]>, tris: &mut Vec<[u32; 3]>) {
    let base = verts.len() as u32;
    let (lv, lt) = local(&o.shape);
    verts.extend(lv.iter().map(|&p| {
        let q = o.placement.transform_point(p);
        [q[0] as f32, q[1] as f32, q[2] as f32]
    }));
    tris.extend(lt.iter().map(|t| [t[0] + base, t[1] + base, t[2] + base]));
}

/// The shape in its own frame.
pub fn local(shape: &Shape) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
    match *shape {
        Shape::Box { half: [x, y, z] } => {
            let v: Vec<[f64; 3]> = (0..8)
                .map(|k| {
                    [if k & 1 != 0 { x } else { -x }, if k & 2 != 0 { y } else { -y }, if k & 4 != 0 { z } else { -z }]
                })
                .collect();
            // Faces as quads (a, b, c, d) counter-clockwise from outside.
            let quads = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
            let t = quads.iter().flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]]).collect();
            (v, t)
        }
        Shape::Cylinder { radius, half_height } => {
            let n = CYLINDER_SEGMENTS as u32;
            let mut v = Vec::with_capacity(2 * n as usize + 2);
            for z in [-half_height, half_height] {
                for k in 0..n {
                    let a = std::f64::consts::TAU * k as f64 / n as f64;
                    v.push([radius * a.cos(), radius * a.sin(), z]);
                }
            }
            v.push([0.0, 0.0, -half_height]);
            v.push([0.0, 0.0, half_height]);
            let (cb, ct) = (2 * n, 2 * n + 1);
            let mut t = Vec::with_capacity(4 * n as usize);
            for k in 0..n {
                let k1 = (k + 1) % n;
                t.push([k, k1, n + k1]);
                t.push([k, n + k1, n + k]);
                t.push([cb, k1, k]);
                t.push([ct, n + k, n + k1]);
            }
            (v, t)
        }
        Shape::Sphere { radius } => {
            let (s, r) = (SPHERE_SEGMENTS as u32, SPHERE_RINGS as u32);
            let mut v = vec![[0.0, 0.0, -radius], [0.0, 0.0, radius]];
            for i in 1..r {
                let lat = -std::f64::consts::FRAC_PI_2 + std::f64::consts::PI * i as f64 / r as f64;
                for k in 0..s {
                    let lon = std::f64::consts::TAU * k as f64 / s as f64;
                    v.push([radius * lat.cos() * lon.cos(), radius * lat.cos() * lon.sin(), radius * lat.sin()]);
                }
            }
            let ring = |i: u32, k: u32| 2 + (i - 1) * s + (k % s);
            let mut t = Vec::new();
            for k in 0..s {
                t.push([0, ring(1, k + 1), ring(1, k)]);
                t.push([1, ring(r - 1, k), ring(r - 1, k + 1)]);
            }
            for i in 1..r - 1 {
                for k in 0..s {
                    t.push([ring(i, k), ring(i, k + 1), ring(i + 1, k + 1)]);
                    t.push([ring(i, k), ring(i + 1, k + 1), ring(i + 1, k)]);
                }
            }
            (v, t)
        }
    }
}
