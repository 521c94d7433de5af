//! The per-eye frame: scene upload, passes in order, timing and read-back.

mod frame;
pub mod output;
mod renderer;
mod settings;

pub use frame::{Frame, FrameStats};
pub use renderer::Renderer;
pub use settings::{Integrator, RenderSettings};

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
