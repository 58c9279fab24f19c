//! The arm's dimensions every module shares: the number of joints, the collision bodies of
//! one arm in their crate-wide order, and the chain variables `x = [lift, q1..q7]`.

/// Number of arm joints.
pub const DOF: usize = 7;

/// Collision bodies of one arm, in this order everywhere in the crate.
pub const BODY_NAMES: [&str; NBODIES] =
    ["link0", "link1", "link2", "link3", "link4", "link5", "link6", "link7", "hand", "finger1", "finger2"];
/// Number of collision bodies of one arm.
pub const NBODIES: usize = 11;
/// Index of the hand in [`BODY_NAMES`]; the fingers follow it.
pub const HAND: usize = 8;

/// `[lift, q1..q7]`.
pub(crate) fn join(lift: f64, q: &[f64; DOF]) -> [f64; 8] {
    let mut x = [lift; 8];
    x[1..].copy_from_slice(q);
    x
}

pub(crate) fn split(x: &[f64; 8]) -> (f64, [f64; DOF]) {
    (x[0], x[1..].try_into().unwrap())
}
