//! Why a viewer run ended early.

use crate::gpu::GpuError;
use crate::render::RenderError;
use crate::scene::SceneError;

#[derive(Debug, thiserror::Error)]
pub enum ViewError {
    #[error("cannot open a window ({0}); fovea view needs a desktop session (X11 or Wayland: DISPLAY or WAYLAND_DISPLAY set); use `fovea render` without one")]
    Window(String),
    #[error(transparent)]
    Gpu(#[from] GpuError),
    #[error(transparent)]
    Render(#[from] RenderError),
    #[error(transparent)]
    Scene(#[from] SceneError),
    #[error("{0}")]
    Input(String),
}
