//! What `fovea view` is asked for: the options of a run, where the gaze comes from, the
//! debug views and how still frames refine the image.

use super::script::Script;
use crate::foveation::gaze_trace::GazeTrace;
use crate::foveation::{FoveationConfig, GazeChoice};
use crate::gpu::{GpuOptions, PresentPreference};
use crate::render::display::DisplayChoice;
use crate::render::{FovChoice, Integrator};
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
    /// Exposure and tone mapper of the window (each scene's transform follows from it).
    pub display: DisplayChoice,
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
