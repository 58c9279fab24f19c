//! What a return's intensity is made of: the surface's diffuse reflectivity at the laser's
//! 905 nm and the angle it is seen at.
//!
//! `intensity` follows Livox's reflectivity scale: 0-150 for diffuse targets of 0-100 %
//! reflectivity (151-255 are retro-reflectors, which the scene has none of). A Lambertian
//! surface returns in proportion to cos(incidence), so intensity = 150 x rho x cos(theta).
//!
//! The reflectivities are typical near-infrared figures, not measurements of this greenhouse:
//! green leaves are bright in the NIR (the "red edge" plateau, about 0.45-0.5); fruit and
//! stems somewhat less; concrete about 0.25; galvanised steel and aluminium 0.3-0.4 diffuse;
//! white paint 0.6-0.8; glass and clear polycarbonate send little back diffusely.

use agrisim_scene::Kind;

pub fn of_kind(kind: Kind) -> f64 {
    match kind {
        Kind::Floor => 0.25,
        Kind::Wall | Kind::Roof => 0.08,
        Kind::Post | Kind::Gutter => 0.35,
        Kind::HeatingPipe => 0.6,
        Kind::Stem | Kind::Truss => 0.4,
        Kind::Leaf => 0.5,
        Kind::Fruit { .. } => 0.45,
        Kind::Obstacle | Kind::Robot => 0.3,
    }
}

/// Livox-scale intensity of a return from a surface of reflectivity `rho` seen at `cos_incidence`.
pub fn intensity(rho: f64, cos_incidence: f64) -> f32 {
    (150.0 * rho * cos_incidence.abs().min(1.0)) as f32
}
