//! `fovea view`: a desktop window (winit; X11 or Wayland through ash-window) showing the path
//! tracer live. The mouse is the gaze, keys switch foveation, debug views, scenes, samples
//! and layer configs, the camera flies with WASD and a mouse drag, and while camera and gaze
//! stand still frames accumulate into a converging image (progressive refinement).
//!
//! Per frame: the renderer draws the eyes (the same passes as `fovea render`), the
//! accumulation pass adds the frame to the running mean and writes what is shown back into
//! the frame image, and that image is blitted into the swapchain and presented. A screenshot
//! reads the same image back and writes it through `render::output`, as `fovea render` does.

mod actions;
mod app;
pub mod controls;
mod error;
mod frame_turn;
pub mod gaze;
mod layer_configs;
mod move_speed;
mod options;
mod render_step;
mod screenshots;
pub mod script;
mod session;
mod summary;
mod title;

pub use app::run;
pub use controls::KEY_HELP;
pub use error::ViewError;
pub use options::{DebugMode, GazeInput, Refine, ViewerOptions};
pub use script::{Script, ScriptEvent};
pub use summary::ViewSummary;
