//! The robot as the world sees it: the shared URDF model of `agrisim_robot` (forward
//! kinematics from the world's scalar inputs, finger pads, harvest box), which the ray-casting
//! sensors pose the same way.

pub use agrisim_robot::model::*;
