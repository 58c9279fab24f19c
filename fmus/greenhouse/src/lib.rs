//! Greenhouse scene.
pub mod scene;
