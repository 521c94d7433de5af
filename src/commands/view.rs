//! `fovea view`: the desktop viewer (see `fovea::viewer`). Options name the same things as
//! `fovea render`'s, so a view and a rendered frame can be made to match.

use super::GpuArgs;
use anyhow::{bail, Context, Result};
use clap::Args;
use fovea::foveation::gaze_trace::GazeTrace;
use fovea::foveation::{FoveationConfig, GazeChoice};
use fovea::gpu::PresentPreference;
use fovea::render::{FovChoice, Integrator, RenderSettings, MAX_SIDE};
use fovea::viewer::{self, DebugMode, GazeInput, Refine, Script, ViewerOptions, KEY_HELP};
use std::path::PathBuf;

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum ViewDebugArg {
    /// Colour each pixel by the layer it comes from (blend bands darkened).
    Layers,
    /// |foveated − regular| at the same seeds, both accumulated, ×4.
    Diff,
    /// Camera samples per pixel so far, log2 on a colour ramp.
    Heat,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum RefineArg {
    /// More foveated frames: converges to the foveated image at infinite samples.
    Foveated,
    /// Regular frames after the first: converges to the reference everywhere.
    Regular,
    /// The temporal history instead of a running mean: follows the view as it moves.
    Temporal,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum PresentArg {
    /// Mailbox or immediate where offered: never wait for the display.
    Fastest,
    /// FIFO: wait for vertical blank.
    Vsync,
}

#[derive(Args)]
#[command(after_help = format!("Keys:\n{KEY_HELP}"))]
pub struct ViewArgs {
    /// A built-in scene (see `fovea scenes`) or a .gltf/.glb file.
    #[arg(long, default_value = "cornell")]
    pub scene: String,
    /// Width of the window in pixels (both eyes side by side with --stereo).
    #[arg(long, default_value_t = 800)]
    pub width: u32,
    /// Height of the window in pixels.
    #[arg(long, default_value_t = 600)]
    pub height: u32,
    /// Render resolution relative to the window, e.g. 0.5 on a CPU device.
    #[arg(long, default_value_t = 1.0)]
    pub scale: f32,
    /// Both eyes (IPD 63 mm) side by side; the eye under the cursor looks at it, the other
    /// at the same point in the scene.
    #[arg(long)]
    pub stereo: bool,
    /// Field of view of the eyes: the scene camera's, or the Vive Pro Eye's per-eye one.
    #[arg(long, value_enum, default_value_t = FovChoice::Scene)]
    pub fov: FovChoice,
    /// Foveation layers at start: off, thesis or a TOML file; F toggles, L cycles.
    #[arg(long, default_value = "thesis")]
    pub foveation: String,
    /// Samples per target pixel of every layer, per frame (default: each layer's own; 16
    /// with --foveation off).
    #[arg(long)]
    pub spp: Option<u32>,
    /// Seed of the first frame of every running mean (frame n uses seed + n).
    #[arg(long, default_value_t = 1)]
    pub seed: u32,
    #[arg(long, value_enum, default_value_t = Integrator::Pt)]
    pub integrator: Integrator,
    #[arg(long, default_value_t = 8)]
    pub max_bounces: u32,
    /// A fixed gaze instead of the mouse: forward, corner or X,Y in pixels of the eye's
    /// image; LEFT:RIGHT per eye with --stereo.
    #[arg(long, allow_hyphen_values = true, conflicts_with = "gaze_trace")]
    pub gaze: Option<GazeChoice>,
    /// Replay a recorded gaze trace (CSV, one row per frame) instead of the mouse.
    #[arg(long)]
    pub gaze_trace: Option<PathBuf>,
    /// The debug view at start (V cycles).
    #[arg(long, value_enum)]
    pub debug: Option<ViewDebugArg>,
    /// What the image view shows: the temporal history (the default: what the headset
    /// shows, moving or not), or a running mean of still frames: foveated frames (the mean
    /// converges to the foveated image) or, after the first, regular ones (it converges to
    /// the reference).
    #[arg(long, value_enum, default_value_t = RefineArg::Temporal)]
    pub refine: RefineArg,
    /// End after this many frames.
    #[arg(long)]
    pub frames: Option<u64>,
    /// Timed events (mouse, resize, minimise, keys, camera, screenshots); see
    /// fovea::viewer::script for the format.
    #[arg(long)]
    pub script: Option<PathBuf>,
    /// Save the image shown when the viewer ends (.png with a linear .exr beside it, or
    /// .exr); the screenshot key saves NAME-1.png, NAME-2.png, ...
    #[arg(long)]
    pub screenshot: Option<PathBuf>,
    #[arg(long, value_enum, default_value_t = PresentArg::Fastest)]
    pub present: PresentArg,
    #[command(flatten)]
    pub display: super::DisplayArgs,
    #[command(flatten)]
    pub gpu: GpuArgs,
}

impl ViewArgs {
    fn options(&self) -> Result<ViewerOptions> {
        for (name, v) in [("--width", self.width), ("--height", self.height)] {
            if v == 0 || v > MAX_SIDE {
                bail!("{name} {v} is out of range: give 1 to {MAX_SIDE} pixels");
            }
        }
        if !(self.scale.is_finite() && self.scale > 0.0 && self.scale <= 4.0) {
            bail!(
                "--scale {} is out of range: give a factor above 0 and at most 4",
                self.scale
            );
        }
        // The same ranges and messages as `fovea render`.
        RenderSettings {
            spp: self.spp.unwrap_or(1),
            max_bounces: self.max_bounces,
            ..RenderSettings::default()
        }
        .validate()
        .map_err(anyhow::Error::msg)?;
        let foveation = FoveationConfig::from_arg(&self.foveation)?;
        if let Some(c) = &foveation {
            c.validate()?;
        }
        let gaze = match (&self.gaze, &self.gaze_trace) {
            (Some(g), _) => GazeInput::Fixed(*g),
            (None, Some(path)) => GazeInput::Trace(GazeTrace::read(path)?),
            (None, None) => GazeInput::Mouse,
        };
        let script = match &self.script {
            Some(path) => Script::load(path).map_err(anyhow::Error::msg)?,
            None => Script::default(),
        };
        let gpu = self.gpu.options();
        Ok(ViewerOptions {
            scene: self.scene.clone(),
            display: self.display.choice(),
            window_size: [self.width, self.height],
            render_scale: self.scale,
            stereo: self.stereo,
            fov: self.fov,
            foveation,
            spp: self.spp,
            seed: self.seed,
            integrator: self.integrator,
            max_bounces: self.max_bounces,
            gaze,
            debug: match self.debug {
                None => DebugMode::Image,
                Some(ViewDebugArg::Layers) => DebugMode::Layers,
                Some(ViewDebugArg::Diff) => DebugMode::Difference,
                Some(ViewDebugArg::Heat) => DebugMode::Heat,
            },
            refine: match self.refine {
                RefineArg::Foveated => Refine::Foveated,
                RefineArg::Regular => Refine::Regular,
                RefineArg::Temporal => Refine::Temporal,
            },
            frames: self.frames,
            script,
            screenshot: self.screenshot.clone(),
            present: match self.present {
                PresentArg::Fastest => PresentPreference::Fastest,
                PresentArg::Vsync => PresentPreference::Vsync,
            },
            gpu,
        })
    }
}

pub fn run(args: &ViewArgs) -> Result<()> {
    let options = args.options()?;
    if options.frames.is_none() {
        println!("fovea view: the mouse is the gaze. Keys:\n{KEY_HELP}");
    }
    let summary = viewer::run(options).context("fovea view")?;
    println!("device: {}", summary.device);
    println!("swapchain: {}", summary.swapchain);
    println!("display: {}", summary.display);
    println!(
        "refine: {}",
        match args.refine {
            RefineArg::Temporal => "temporal history (what the headset shows)",
            RefineArg::Foveated => "running mean of still foveated frames",
            RefineArg::Regular => "running mean of still frames, regular after the first",
        }
    );
    println!(
        "frames: {} ({} rendered, {} presented, {} not shown), swapchain recreated {} times, {} frame(s) in the final running mean",
        summary.frames,
        summary.rendered,
        summary.presented,
        summary.not_shown,
        summary.swapchain_recreations,
        summary.accumulated
    );
    let messages = &summary.validation_messages;
    if !messages.is_empty() {
        bail!(
            "the Vulkan validation layer reported {} message(s):\n{}",
            messages.len(),
            messages.join("\n")
        );
    }
    Ok(())
}
