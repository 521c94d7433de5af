//! The frame: scene upload, per-eye planning, the passes in order, timing and read-back.

pub mod accumulate;
mod brdf_probe;
#[cfg(any(test, feature = "test-hooks"))]
mod compose;
mod counters;
pub mod display;
pub mod display_stage;
mod eye_params;
mod frame;
mod graph;
mod history;
mod in_flight;
pub mod output;
mod passes;
mod pipelines;
mod probe;
mod record;
mod regular;
mod renderer;
mod request;
mod sampler;
mod scene_buffers;
mod scene_textures;
mod settings;
mod slots;
mod targets;
mod trace_lanes;
mod version;
mod visibility;

pub use brdf_probe::MAX_BRDF_QUERIES;
#[cfg(any(test, feature = "test-hooks"))]
pub use compose::LatticePoint;
pub use frame::{EyeCounters, Frame, FrameStats, TraversalCounts};
pub use history::TemporalSettings;
pub use regular::regular_frame;
pub use renderer::{preferred_trace_lanes, Renderer};
pub use request::{
    eye_views, AfterFrame, DebugView, EyeView, FovChoice, FrameOptions, FrameRequest, IPD,
};
pub use scene_buffers::SceneMemory;
pub use settings::{Integrator, RenderSettings, Sampler, Traversal, TraversalChoice, MAX_SIDE};
pub use slots::MAX_FRAMES_IN_FLIGHT;
pub use trace_lanes::TraceLanes;
pub use version::renderer_version;

use crate::gpu::GpuError;
use crate::scene::SceneError;

#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    #[error(transparent)]
    Gpu(#[from] GpuError),
    #[error(transparent)]
    Scene(#[from] SceneError),
    #[error("{0}")]
    Settings(String),
    #[error("cannot write '{path}': {problem}")]
    Output { path: String, problem: String },
}
