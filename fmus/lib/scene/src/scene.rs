//! The scene every part of agrisim agrees on: a list of solid primitives with ids, names and
//! kinds, in the map frame (REP 103/105: x along the rows, y across, z up; metres).
//!
//! The world FMU builds its rapier colliders from it, the LiDAR and camera cast rays at it,
//! the navigation stack rasterizes its occupancy map from it, and `agrisim scene export`
//! writes it as glTF. All generated deterministically from a scenario and a seed.

use agrisim_math::vec3::{add, mat_vec};

/// What an object is (for labels, collision reports, colours).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, serde::Serialize, serde::Deserialize)]
pub enum Kind {
    Floor,
    Wall,
    Roof,
    Post,
    Gutter,
    HeatingPipe,
    Stem,
    Leaf,
    Truss,
    /// A tomato; `ripeness` is the USDA stage 1 (green) .. 6 (red).
    Fruit {
        ripeness: u8,
    },
    Obstacle,
    /// A robot link (added at run time by the FMUs that move it).
    Robot,
}

/// A solid primitive in its own frame (centred at the origin).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum Shape {
    /// Axis-aligned box with half extents (x, y, z) before the object's rotation.
    Box {
        half: [f64; 3],
    },
    /// Cylinder along the local z axis.
    Cylinder {
        radius: f64,
        half_height: f64,
    },
    Sphere {
        radius: f64,
    },
}

/// Rigid placement: translation and a unit quaternion (x, y, z, w).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Placement {
    pub translation: [f64; 3],
    pub rotation: [f64; 4],
}

impl Placement {
    pub const IDENTITY: Placement = Placement { translation: [0.0; 3], rotation: [0.0, 0.0, 0.0, 1.0] };

    pub fn at(x: f64, y: f64, z: f64) -> Placement {
        Placement { translation: [x, y, z], rotation: [0.0, 0.0, 0.0, 1.0] }
    }
}

#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Object {
    /// Unique within the scene, dense from 0 (usable as an index and as a label value).
    pub id: u32,
    /// Stable human-readable name, e.g. `row3/plant12/fruit2_4` (fruit 4 of truss 2);
    /// see [`crate::generate`] for the full scheme.
    pub name: String,
    pub kind: Kind,
    pub shape: Shape,
    pub placement: Placement,
}

impl Placement {
    /// A rotation of `angle` radians about the unit `axis`.
    pub fn axis_angle(translation: [f64; 3], axis: [f64; 3], angle: f64) -> Placement {
        let (s, c) = (0.5 * angle).sin_cos();
        Placement { translation, rotation: [axis[0] * s, axis[1] * s, axis[2] * s, c] }
    }

    /// Yaw (about +z) then translation.
    pub fn yawed(translation: [f64; 3], yaw: f64) -> Placement {
        Placement::axis_angle(translation, [0.0, 0.0, 1.0], yaw)
    }

    /// The rotation as a row-major 3x3 matrix (local -> map).
    pub fn matrix(&self) -> [[f64; 3]; 3] {
        let [x, y, z, w] = self.rotation;
        [
            [1.0 - 2.0 * (y * y + z * z), 2.0 * (x * y - z * w), 2.0 * (x * z + y * w)],
            [2.0 * (x * y + z * w), 1.0 - 2.0 * (x * x + z * z), 2.0 * (y * z - x * w)],
            [2.0 * (x * z - y * w), 2.0 * (y * z + x * w), 1.0 - 2.0 * (x * x + y * y)],
        ]
    }

    /// Local point -> map frame.
    pub fn transform_point(&self, p: [f64; 3]) -> [f64; 3] {
        add(mat_vec(&self.matrix(), p), self.translation)
    }
}

impl Object {
    /// Tight axis-aligned bounds in the map frame: (min, max).
    pub fn aabb(&self) -> ([f64; 3], [f64; 3]) {
        let m = self.placement.matrix();
        let t = self.placement.translation;
        let ext: [f64; 3] = match self.shape {
            Shape::Sphere { radius } => [radius; 3],
            // Oriented box: |R| * half.
            Shape::Box { half } => {
                let mut e = [0.0; 3];
                for (i, ei) in e.iter_mut().enumerate() {
                    *ei = m[i][0].abs() * half[0] + m[i][1].abs() * half[1] + m[i][2].abs() * half[2];
                }
                e
            }
            // Cylinder: axis a = R e_z; extent = |a_i| h + r sqrt(1 - a_i^2) (exact for a disc cap).
            Shape::Cylinder { radius, half_height } => {
                let mut e = [0.0; 3];
                for (i, ei) in e.iter_mut().enumerate() {
                    let a = m[i][2];
                    *ei = a.abs() * half_height + radius * (1.0 - a * a).max(0.0).sqrt();
                }
                e
            }
        };
        ([t[0] - ext[0], t[1] - ext[1], t[2] - ext[2]], [t[0] + ext[0], t[1] + ext[1], t[2] + ext[2]])
    }
}

/// Hamilton product a * b of unit quaternions (x, y, z, w): rotate by b, then by a.
pub fn quat_mul(a: [f64; 4], b: [f64; 4]) -> [f64; 4] {
    let [ax, ay, az, aw] = a;
    let [bx, by, bz, bw] = b;
    [
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
        aw * bw - ax * bx - ay * by - az * bz,
    ]
}

/// Quaternion of a rotation of `angle` about the unit `axis`.
pub fn quat_axis_angle(axis: [f64; 3], angle: f64) -> [f64; 4] {
    Placement::axis_angle([0.0; 3], axis, angle).rotation
}
