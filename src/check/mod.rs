//! Numerical stress checks behind `fovea check` and the accuracy tests: watertight traversal of
//! closed meshes, scale and self-intersection invariance, material extremes under a white
//! furnace, and convergence of both integrators against converged references. Each check
//! returns counts and measured figures; the caller decides what is a failure.

pub mod brdf_sampling;
pub mod chi_square;
pub mod closed_meshes;
pub mod convergence;
pub mod gltf_brdf;
pub mod gltf_furnace;
pub mod materials;
pub mod report;
pub(crate) mod rng;
pub mod scale;
pub mod watertight;
