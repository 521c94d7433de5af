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
mod frame_turn;
pub mod gaze;
mod layer_configs;
mod move_speed;
mod render_step;
mod screenshots;
pub mod script;
mod session;
mod title;

pub use controls::KEY_HELP;
pub use script::{Script, ScriptEvent};

use crate::foveation::gaze_trace::GazeTrace;
use crate::foveation::{FoveationConfig, GazeChoice};
use crate::gpu::{GpuError, GpuOptions, PresentPreference};
use crate::render::{FovChoice, Integrator, RenderError};
use crate::scene::SceneError;
use std::path::PathBuf;

/// Where the gaze comes from.
#[derive(Clone, Debug)]
pub enum GazeInput {
    /// The cursor's position in the window.
    Mouse,
    /// A fixed gaze (`--gaze`), as `fovea render` takes it.
    Fixed(GazeChoice),
    /// A recorded trace (`--gaze-trace`): row k is frame k's gaze; the last row holds after.
    Trace(GazeTrace),
}

/// What the window shows.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum DebugMode {
    /// The (accumulated) image.
    #[default]
    Image,
    /// Each pixel tinted by its foveation layer, blend bands darkened.
    Layers,
    /// |foveated − regular| at the same seeds, both accumulated, ×4.
    Difference,
    /// Camera samples per pixel so far, log2 on a colour ramp.
    Heat,
}

impl DebugMode {
    pub fn next(self) -> Self {
        match self {
            DebugMode::Image => DebugMode::Layers,
            DebugMode::Layers => DebugMode::Difference,
            DebugMode::Difference => DebugMode::Heat,
            DebugMode::Heat => DebugMode::Image,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            DebugMode::Image => "image",
            DebugMode::Layers => "layers",
            DebugMode::Difference => "|foveated - regular| x4",
            DebugMode::Heat => "samples/pixel (blue 1/64 .. red 1024, log2)",
        }
    }
}

/// What the frames after the first of a still view add to the running mean.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Refine {
    /// More frames like the first: the mean converges to the foveated image at infinite
    /// samples (the reference inside the fovea; outside, the reference as the layers'
    /// lattices and Catmull-Rom fill see it), so what foveation does stays visible.
    #[default]
    Foveated,
    /// Regular frames (the fovea's samples per pixel everywhere): the mean converges to the
    /// reference everywhere; the first frame after a move is still foveated, fast.
    Regular,
    /// No running mean: every frame keeps the temporal history (`fovea render
    /// --camera-path`'s), which follows the view as it moves and converges to the reference
    /// when it stands still (the image view only; the debug views use the running mean).
    Temporal,
}

/// Everything `fovea view` is asked for.
#[derive(Clone, Debug)]
pub struct ViewerOptions {
    /// A built-in scene name or a .gltf/.glb path.
    pub scene: String,
    /// The window's inner size at start, in pixels.
    pub window_size: [u32; 2],
    /// Render resolution relative to the window (each eye's image is scaled to its half in
    /// stereo); below 1 trades sharpness for speed.
    pub render_scale: f32,
    pub stereo: bool,
    pub fov: FovChoice,
    /// The layer config at start; None starts with foveation off.
    pub foveation: Option<FoveationConfig>,
    /// Samples per target pixel for every layer (None: each layer's own, or 16 without
    /// foveation, as `fovea render`).
    pub spp: Option<u32>,
    pub seed: u32,
    pub integrator: Integrator,
    pub max_bounces: u32,
    pub gaze: GazeInput,
    pub debug: DebugMode,
    /// How still frames refine the image.
    pub refine: Refine,
    /// End after this many frames (frames skipped while minimised count).
    pub frames: Option<u64>,
    pub script: Script,
    /// Where to save the last frame shown when the viewer ends, and the default name for
    /// the screenshot key.
    pub screenshot: Option<PathBuf>,
    pub present: PresentPreference,
    pub gpu: GpuOptions,
}

/// What a run did, for the command to print and tests to check.
#[derive(Clone, Debug, Default)]
pub struct ViewSummary {
    pub frames: u64,
    pub rendered: u64,
    pub presented: u64,
    /// Frames not shown: the window had no area, was occluded or the swapchain was out of date.
    pub not_shown: u64,
    pub swapchain_recreations: u64,
    /// Frames in the running mean when the viewer ended.
    pub accumulated: u32,
    pub screenshots: Vec<PathBuf>,
    /// The device the frames were rendered on.
    pub device: String,
    /// The swapchain's format and present mode.
    pub swapchain: String,
    /// What the validation layer reported (nothing without validation), read after the GPU
    /// context is gone so that leaks reported at destruction are in it.
    pub validation_messages: Vec<String>,
}

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

/// Opens the window and runs until it is closed, Esc is pressed or `options.frames` have
/// been shown.
pub fn run(options: ViewerOptions) -> Result<ViewSummary, ViewError> {
    app::run(options)
}
