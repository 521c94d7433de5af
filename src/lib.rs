//! fovea: a foveated path tracer for eye-tracked VR headsets, on raw Vulkan (ash).
//!
//! `scene` describes what to render, `gpu` owns every Vulkan handle, `render` drives a frame.

pub mod bench;
pub mod check;
pub mod foveation;
pub mod gpu;
pub mod metrics;
pub mod realtime;
pub mod render;
pub mod scene;
pub mod shader_layout;
pub mod tune;
pub mod viewer;
pub mod xr;

#[cfg(test)]
mod test_dir;

/// The version and commit this binary was built from (build.rs), as reports name it, e.g.
/// `0.1.0 (commit 1a2b3c4d5e6f)`; `+changes` marks a build with uncommitted changes.
pub fn build_version() -> String {
    format!(
        "{} (commit {})",
        env!("CARGO_PKG_VERSION"),
        env!("FOVEA_COMMIT")
    )
}
