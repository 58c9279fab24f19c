//! The scene every part of agrisim agrees on: a list of solid primitives with ids, names and
//! kinds, in the map frame (REP 103/105: x along the rows, y across, z up; metres).
//!
//! The world FMU builds its rapier colliders from it, the LiDAR and camera cast rays at it,
//! the navigation stack rasterizes its occupancy map from it, and `agrisim scene export`
//! writes it as glTF. All generated deterministically from a scenario and a seed.

/// What an object is (for labels, collision reports, colours).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
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
    Fruit { ripeness: u8 },
    Obstacle,
    /// A robot link (added at run time by the FMUs that move it).
    Robot,
}

/// A solid primitive in its own frame (centred at the origin).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Shape {
    /// Axis-aligned box with half extents (x, y, z) before the object's rotation.
    Box { half: [f64; 3] },
    /// Cylinder along the local z axis.
    Cylinder { radius: f64, half_height: f64 },
    Sphere { radius: f64 },
}

/// Rigid placement: translation and a unit quaternion (x, y, z, w).
#[derive(Clone, Copy, Debug, PartialEq)]
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

#[derive(Clone, Debug, PartialEq)]
pub struct Object {
    /// Unique within the scene, dense from 0 (usable as an index and as a label value).
    pub id: u32,
    /// Stable human-readable name, e.g. `row3/plant12/truss2/fruit4`.
    pub name: String,
    pub kind: Kind,
    pub shape: Shape,
    pub placement: Placement,
}
