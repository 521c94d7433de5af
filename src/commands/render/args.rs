//! `fovea render`'s options: what to render, how, and where to write it, as clap parses
//! them; the layer config and frame settings they ask for.

use crate::commands::{DisplayArgs, GpuArgs};
use anyhow::Result;
use clap::Args;
use fovea::foveation::{FoveationConfig, GazeChoice};
use fovea::render::{FovChoice, Integrator, RenderSettings, TemporalSettings, MAX_SIDE};
use std::path::PathBuf;

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum DebugArg {
    /// Colour each pixel by the layer it comes from (blend bands darkened).
    Layers,
    /// The absolute difference between the foveated frame and a regular one (same seed).
    Diff,
}

#[derive(Args)]
pub struct RenderArgs {
    /// A built-in scene (see `fovea scenes`) or a .gltf/.glb file.
    #[arg(long, default_value = "cornell")]
    pub scene: String,
    /// Width of one eye's image in pixels.
    #[arg(long, default_value_t = 512, allow_negative_numbers = true,
          value_parser = whole_number(format!("a width in pixels from 1 to {MAX_SIDE}")))]
    pub width: u32,
    #[arg(long, default_value_t = 512, allow_negative_numbers = true,
          value_parser = whole_number(format!("a height in pixels from 1 to {MAX_SIDE}")))]
    pub height: u32,
    /// Samples per target pixel. Default: 16 without foveation, each layer's own (4 in the
    /// thesis config) with it; given with foveation, it replaces every layer's.
    #[arg(long, allow_negative_numbers = true, value_parser = whole_number(format!(
        "a number of samples per pixel from 1 to {}",
        RenderSettings::MAX_SPP
    )))]
    pub spp: Option<u32>,
    /// Random seed: the same seed gives a bit-identical image.
    #[arg(long, default_value_t = 1, allow_negative_numbers = true,
          value_parser = whole_number(format!("a seed from 0 to {}", u32::MAX)))]
    pub seed: u32,
    #[arg(long, value_enum, default_value_t = Integrator::Pt)]
    pub integrator: Integrator,
    /// Maximum number of bounces after the camera ray's hit.
    #[arg(long, default_value_t = 8, allow_negative_numbers = true, value_parser = whole_number(
        format!("a number of bounces from 0 to {}", RenderSettings::MAX_BOUNCES)
    ))]
    pub max_bounces: u32,
    /// Foveation layers: off (regular rendering), thesis (6°/10°/20° + background, spacings
    /// 1-4, 4 spp), or a TOML file (see assets/foveation/).
    #[arg(long, default_value = "off")]
    pub foveation: String,
    /// Gaze: forward (the view axis), corner (top left) or X,Y in pixels; LEFT:RIGHT per eye.
    #[arg(long, default_value = "forward", allow_hyphen_values = true)]
    pub gaze: GazeChoice,
    #[command(flatten)]
    pub trace: Box<TraceArgs>,
    #[command(flatten)]
    pub sequence: Box<SequenceArgs>,
    /// Render both eyes (IPD 63 mm), side by side in one image.
    #[arg(long)]
    pub stereo: bool,
    /// Field of view of the eyes: the scene camera's, or the Vive Pro Eye's per-eye one.
    #[arg(long, value_enum, default_value_t = FovChoice::Scene)]
    pub fov: FovChoice,
    /// A debug view instead of the image.
    #[arg(long, value_enum)]
    pub debug: Option<DebugArg>,
    /// Output image: .png (an .exr with linear radiance is written beside it) or .exr;
    /// default fovea.png. With --camera-path, the directory the frames go to (default
    /// frames).
    #[arg(long)]
    pub out: Option<PathBuf>,
    #[command(flatten)]
    pub display: DisplayArgs,
    /// Instead of one image, time every built-in scene: regular, and with --foveation other
    /// than off also forward and corner gaze (and the trace's gaze with --gaze-trace).
    #[arg(long, conflicts_with_all = ["trace_split", "samples_per_lane", "trace_threads"])]
    pub bench: bool,
    /// Frames timed per scene and mode in --bench (the median is reported).
    #[arg(long, default_value_t = 3, allow_negative_numbers = true,
          value_parser = whole_number("a number of frames, 1 or more".into()))]
    pub bench_frames: u32,
    /// With --bench: also write the table as JSON, one record per scene and mode (scene,
    /// mode, and the medians gpu_ms, trace_ms, samples), rewritten after every scene.
    #[arg(long, value_name = "FILE", requires = "bench")]
    pub json: Option<PathBuf>,
    /// Count the trace's BVH traversal work (nodes, triangle and primitive tests, SIMD
    /// occupancy of the traversal loop per BVH level) and print it per ray; the image is
    /// unchanged, the frame is slower. See tools/profile-trace.sh.
    #[arg(long, conflicts_with = "bench")]
    pub profile_traversal: bool,
    #[command(flatten)]
    pub lanes: crate::commands::trace_lanes_args::TraceLaneArgs,
    #[command(flatten)]
    pub gpu: GpuArgs,
}

/// The gaze-trace options, boxed: they would make every `Command` as large as `render`'s.
#[derive(Args)]
pub struct TraceArgs {
    /// Gaze from a recorded trace (CSV: frame,time_s,left_tan_x,left_tan_y,right_tan_x,
    /// right_tan_y,status). One frame uses row --trace-frame; --bench gives each measured
    /// frame the next row.
    #[arg(long, value_name = "FILE", conflicts_with = "gaze")]
    pub gaze_trace: Option<PathBuf>,
    /// The row of --gaze-trace a single frame uses (0 = the first; past the end, the last).
    #[arg(long, value_name = "N", requires = "gaze_trace", allow_negative_numbers = true,
          value_parser = whole_number("a row of the gaze trace, 0 or more".into()))]
    pub trace_frame: Option<u32>,
}

/// The sequence options (boxed, as TraceArgs).
#[derive(Args)]
pub struct SequenceArgs {
    /// Render a sequence: one frame per row of a camera path (CSV: frame,dx,dy,dz,yaw_deg,
    /// pitch_deg,roll_deg; the scene camera moved along its own right, up and forward axes
    /// in metres, then turned right, up and clockwise in degrees), written to the --out
    /// directory as frame_NNNN.png and .exr. Frame k uses seed --seed + k and, with
    /// --gaze-trace, row k of the trace.
    #[arg(
        long,
        value_name = "FILE",
        conflicts_with_all = ["bench", "debug", "trace_frame", "trace_split", "samples_per_lane", "trace_threads"]
    )]
    pub camera_path: Option<PathBuf>,
    /// With --camera-path: keep a temporal history (every pixel accumulates the samples
    /// traced at it, reprojected as the camera moves; sparse layers shift their lattices
    /// every frame). Default on.
    #[arg(long, value_enum, requires = "camera_path")]
    pub temporal: Option<OnOff>,
    /// While the camera moves, a pixel's history counts at most this many samples.
    #[arg(long, default_value_t = TemporalSettings::default().cap, requires = "camera_path",
          value_parser = whole_number("a number of samples, 1 or more".into()))]
    pub temporal_cap: u32,
    /// With --camera-path: after each frame's line, its GPU time per pass (timestamp
    /// queries), as a single frame prints them.
    #[arg(long, requires = "camera_path")]
    pub pass_times: bool,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum OnOff {
    On,
    Off,
}

impl RenderArgs {
    /// The layer config asked for, with --spp applied.
    pub fn foveation(&self) -> Result<FoveationConfig> {
        if let Some(spp) = self.spp {
            // The same range and message as any frame's settings.
            RenderSettings {
                spp,
                ..RenderSettings::default()
            }
            .validate()
            .map_err(anyhow::Error::msg)?;
        }
        let config = match FoveationConfig::from_arg(&self.foveation)? {
            None => FoveationConfig::regular(self.spp.unwrap_or(16)),
            Some(c) => match self.spp {
                Some(spp) => c.with_spp(spp),
                None => c,
            },
        };
        config.validate()?;
        Ok(config)
    }

    pub fn settings(&self, config: &FoveationConfig) -> RenderSettings {
        RenderSettings {
            sampler: fovea::render::Sampler::chosen(),
            width: self.width,
            height: self.height,
            // A regular frame compared with this one uses the innermost layer's spp.
            spp: config.layers[0].spp,
            seed: self.seed,
            integrator: self.integrator,
            max_bounces: self.max_bounces,
        }
    }
}

/// A clap parser for a whole-number option whose message says what the option takes; clap's
/// own says "invalid digit found in string" for `-5` or `1e9`. `what`: "a width in pixels
/// from 1 to 16384". Ranges are checked with the other settings.
pub fn whole_number(what: String) -> impl Fn(&str) -> Result<u32, String> + Clone + Send + Sync {
    move |text: &str| {
        let text = text.trim();
        let (negative, digits) = match text.strip_prefix('-') {
            Some(rest) => (true, rest),
            None => (false, text.strip_prefix('+').unwrap_or(text)),
        };
        if digits.is_empty() || !digits.bytes().all(|b| b.is_ascii_digit()) {
            return Err(format!("not a whole number; give {what}"));
        }
        if negative && digits.bytes().any(|b| b != b'0') {
            return Err(format!("negative; give {what}"));
        }
        digits
            .parse::<u32>()
            .map_err(|_| format!("far too large; give {what}"))
    }
}
