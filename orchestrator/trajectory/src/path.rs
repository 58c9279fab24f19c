//! A geometric joint-space path q(s): what time parameterization consumes.

use std::fmt;

/// A twice-differentiable joint path over the path parameter interval `[s_start, s_end]`.
///
/// TOPP-RA only needs q'(s) and q''(s) at grid points; the sampler also needs q(s).
pub trait JointPath {
    /// Number of joints.
    fn dof(&self) -> usize;
    /// Path parameter interval `(s_start, s_end)`.
    fn interval(&self) -> (f64, f64);
    /// Writes q(s), dq/ds and d²q/ds² into the three slices (each of length `dof`).
    /// Arguments outside the interval are clamped to it.
    fn eval(&self, s: f64, q: &mut [f64], dq: &mut [f64], ddq: &mut [f64]);
    /// Interior path parameters where d²q/ds² jumps; the automatic TOPP-RA grid includes them.
    /// (A cubic spline's d²q/ds² is continuous: none.)
    fn breakpoints(&self) -> Vec<f64> {
        Vec::new()
    }
}

/// Why a path could not be built.
#[derive(Debug, Clone, PartialEq)]
pub enum PathError {
    /// No waypoints, or waypoints of different lengths, or zero joints.
    BadWaypoints(String),
    /// Path parameters not strictly increasing or not finite.
    BadParameters(String),
}

impl fmt::Display for PathError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            PathError::BadWaypoints(m) => write!(f, "bad waypoints: {m}"),
            PathError::BadParameters(m) => write!(f, "bad path parameters: {m}"),
        }
    }
}

impl std::error::Error for PathError {}
