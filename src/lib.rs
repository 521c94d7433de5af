//! fovea: a foveated path tracer for eye-tracked VR headsets, on raw Vulkan (ash).
//!
//! `scene` describes what to render, `gpu` owns every Vulkan handle, `render` drives a frame.

pub mod bench;
pub mod check;
pub mod foveation;
pub mod gpu;
pub mod metrics;
pub mod render;
pub mod scene;
pub mod tune;
pub mod viewer;
pub mod xr;
