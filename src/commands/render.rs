//! `fovea render`: one frame, mono or stereo, regular or foveated, written as PNG + EXR; or,
//! with `--bench`, timings of every built-in scene.

use super::{check_validation, gpu_context, GpuArgs};
use anyhow::{bail, Context, Result};
use clap::Args;
use fovea::foveation::{
    FoveationConfig, GazeChoice, GazeSource, GazeTrace, ImageGeometry, TraceReplay,
};
use fovea::render::{
    eye_views, output, DebugView, EyeView, FovChoice, Frame, FrameRequest, Integrator,
    RenderSettings, Renderer, TemporalSettings, TraversalCounts, MAX_SIDE,
};
use fovea::scene::{self, Camera};
use std::path::PathBuf;
use std::time::Instant;

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
    /// Instead of one image, time every built-in scene: regular, and with --foveation other
    /// than off also forward and corner gaze (and the trace's gaze with --gaze-trace).
    #[arg(long)]
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
    #[arg(long, value_name = "FILE", conflicts_with_all = ["bench", "debug", "trace_frame"])]
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

pub fn run(args: &RenderArgs) -> Result<()> {
    let config = args.foveation()?;
    let settings = args.settings(&config);
    settings.validate().map_err(anyhow::Error::msg)?;
    if args.bench && args.bench_frames == 0 {
        bail!("--bench-frames 0 times nothing: give 1 or more frames per scene and mode");
    }
    // Read before any GPU work: a bad trace should fail at once.
    let trace = args
        .trace
        .gaze_trace
        .as_deref()
        .map(GazeTrace::read)
        .transpose()?;
    if args.bench && trace.is_some() && config.is_regular() {
        bail!(
            "--gaze-trace with --bench times foveated frames following the gaze; give \
             --foveation (e.g. thesis)"
        );
    }
    let ctx = gpu_context(&args.gpu)?;
    println!(
        "device: {} ({}; {})",
        ctx.info.name, ctx.info.kind, ctx.info.driver
    );
    if args.bench {
        return super::render_bench::run(&ctx, args, &config, &settings, trace);
    }
    if let Some(path) = &args.sequence.camera_path {
        return super::render_sequence::run(&ctx, args, path, &config, &settings, trace);
    }
    let aspect = settings.width as f32 / settings.height as f32;
    let scene = scene::load(&args.scene, aspect)?;
    let started = Instant::now();
    let mut renderer = Renderer::new(&ctx, &scene)?;
    renderer.set_traversal_profile(args.profile_traversal);
    let setup = started.elapsed();
    println!(
        "scene {}: {} triangles, {} boxes, {} spheres ({}); BVH build + upload {:.1} ms",
        scene.name,
        scene.triangle_count(),
        scene.boxes.len(),
        scene.spheres.len(),
        renderer.features().describe(),
        setup.as_secs_f64() * 1e3
    );
    let mut eyes = eye_views(&scene.camera, aspect, args.fov, args.stereo, args.gaze);
    if let Some(trace) = trace {
        let row = args.trace.trace_frame.unwrap_or(0) as u64;
        let mut replay = TraceReplay::new(trace);
        eyes = with_source_gaze(&eyes, &mut replay, row, &settings);
        println!(
            "gaze from {} row {row} of {} ({})",
            replay.trace().path.display(),
            replay.trace().rows.len(),
            replay.status().name()
        );
    }
    let request = FrameRequest {
        settings,
        foveation: &config,
        eyes: &eyes,
        debug: match args.debug {
            Some(DebugArg::Layers) => DebugView::Layers,
            _ => DebugView::None,
        },
    };
    warm_up(&mut renderer, &request)?;
    let mut frame = renderer.render_frame(&request)?;
    report(&frame, &config, &settings, ctx.info.subgroup_size);
    if args.debug == Some(DebugArg::Diff) {
        let regular_config = FoveationConfig::regular(settings.spp);
        let regular = renderer.render_frame(&FrameRequest {
            foveation: &regular_config,
            ..request
        })?;
        let diff = difference(&frame, &regular);
        println!(
            "difference from a regular frame at {} spp (same seed): mean |Δ| {:.5}, {:.1}% of pixels identical",
            settings.spp,
            diff.mean().iter().sum::<f64>() / 3.0,
            100.0 * identical_fraction(&frame, &regular)
        );
        frame.rgb = diff.rgb;
    }
    let out = args.out.clone().unwrap_or_else(|| "fovea.png".into());
    let written = output::write_frame(&frame, &out)?;
    for path in written {
        println!("wrote {}", path.display());
    }
    drop(renderer);
    check_validation(&ctx)?;
    let s = &frame.stats;
    if s.stack_overflows > 0 {
        bail!(
            "{} BVH traversals overflowed their stack: the image is missing geometry",
            s.stack_overflows
        );
    }
    Ok(())
}

/// Renders `request` once at a tiny size, untimed, so that the frame's timings are its own:
/// drivers compile shader variants at their first dispatch (lavapipe took 960 ms for the first
/// resolve of a 512x512 frame, 4 ms warm), and the pipelines are the same at any size.
fn warm_up(renderer: &mut Renderer, request: &FrameRequest) -> Result<()> {
    let settings = RenderSettings {
        width: request.settings.width.min(WARM_UP_SIDE),
        height: request.settings.height.min(WARM_UP_SIDE),
        ..request.settings
    };
    renderer.measure_frame(&FrameRequest {
        settings,
        ..*request
    })?;
    Ok(())
}

/// The warm-up frame's largest side: every pass runs, at almost no cost.
const WARM_UP_SIDE: u32 = 16;

/// Prints what the frame traced, per layer, and what it cost.
fn report(frame: &Frame, config: &FoveationConfig, settings: &RenderSettings, subgroup_size: u32) {
    let s = &frame.stats;
    for (e, (gaze, fix)) in frame.gazes.iter().enumerate() {
        let which = match (frame.gazes.len(), e) {
            (1, _) => "eye",
            (_, 0) => "left eye",
            _ => "right eye",
        };
        println!(
            "{which}: gaze at pixel ({:.1}, {:.1}){}",
            gaze[0],
            gaze[1],
            match fix {
                fovea::foveation::gaze::GazeFix::None => "",
                fovea::foveation::gaze::GazeFix::NotFinite =>
                    " (requested gaze not finite: view axis used)",
                fovea::foveation::gaze::GazeFix::Clamped =>
                    " (requested gaze off the image: clamped to its border)",
            }
        );
    }
    println!(
        "{:<6} {:>8} {:>8} {:>5} {:>12}",
        "layer", "radius", "spacing", "spp", "samples"
    );
    for (k, (layer, samples)) in config.layers.iter().zip(&s.layer_samples).enumerate() {
        let radius = layer
            .radius_deg
            .map_or("rest".to_string(), |r| format!("{r}°"));
        println!(
            "{:<6} {:>8} {:>8} {:>5} {:>12}",
            k + 1,
            radius,
            layer.spacing,
            layer.spp,
            samples
        );
    }
    let planned: u64 = s.layer_samples.iter().sum();
    let full = frame.width as u64 * frame.height as u64 * settings.spp as u64;
    println!(
        "samples traced: {planned} ({:.2}% of a regular frame's {full}); CPU: planned in {:.3} ms, recorded in {:.3} ms",
        100.0 * planned as f64 / full as f64,
        s.plan_ms,
        s.record_ms
    );
    for (pass, ms) in &s.pass_ms {
        println!("gpu pass {pass}: {ms:.2} ms");
    }
    println!(
        "{}x{} {:?}, {} traversal: {:.2} ms GPU, {:.2} Msamples/s, {} rays ({:.2} Mrays/s)",
        frame.width,
        frame.height,
        settings.integrator,
        s.traced_with.name(),
        s.gpu_ms(),
        s.msamples_per_s(),
        s.rays,
        s.rays as f64 / (s.gpu_ms() * 1e3).max(1e-9)
    );
    println!(
        "non-finite samples dropped: {}, BVH stack overflows: {}",
        s.nonfinite_samples, s.stack_overflows
    );
    if let Some(t) = &s.traversal {
        report_traversal(t, s.rays, subgroup_size);
    }
}

/// The traversal profile per ray, and the traversal loop's SIMD occupancy at each BVH level.
fn report_traversal(t: &TraversalCounts, rays: u64, subgroup_size: u32) {
    let per_ray = |n: u64| n as f64 / rays.max(1) as f64;
    println!(
        "traversal per ray: {:.2} TLAS nodes, {:.2} BLAS nodes, {:.2} triangle tests, {:.2} box/sphere tests, {:.2} TLAS steps, {:.2} BLAS steps",
        per_ray(t.tlas_nodes),
        per_ray(t.blas_nodes),
        per_ray(t.triangles),
        per_ray(t.primitives),
        per_ray(t.tlas_lane_steps),
        per_ray(t.blas_lane_steps),
    );
    let occupancy = |lane, group| {
        TraversalCounts::occupancy(lane, group, subgroup_size)
            .map_or("-".to_string(), |o| format!("{:.1}%", 100.0 * o))
    };
    println!(
        "traversal SIMD occupancy ({subgroup_size} lanes): TLAS level {}, BLAS level {}",
        occupancy(t.tlas_lane_steps, t.tlas_group_steps),
        occupancy(t.blas_lane_steps, t.blas_group_steps),
    );
}

/// |a - b| per channel.
fn difference(a: &Frame, b: &Frame) -> Frame {
    Frame {
        rgb: a
            .rgb
            .iter()
            .zip(&b.rgb)
            .map(|(x, y)| (x - y).abs())
            .collect(),
        ..a.clone()
    }
}

fn identical_fraction(a: &Frame, b: &Frame) -> f64 {
    let same = a
        .rgb
        .chunks_exact(3)
        .zip(b.rgb.chunks_exact(3))
        .filter(|(x, y)| x == y)
        .count();
    same as f64 / (a.rgb.len() / 3).max(1) as f64
}

/// The eyes with the gazes `source` gives for frame `frame` (time: `frame` at 90 Hz, a
/// headset's rate; the sources here do not look at it).
pub fn with_source_gaze(
    eyes: &[EyeView],
    source: &mut dyn GazeSource,
    frame: u64,
    settings: &RenderSettings,
) -> Vec<EyeView> {
    let views: Vec<(Camera, ImageGeometry)> = eyes
        .iter()
        .map(|e| (e.camera, e.image(settings.width, settings.height)))
        .collect();
    let gazes = source.gaze(frame, frame as f64 / 90.0, &views);
    eyes.iter()
        .zip(gazes)
        .map(|(e, gaze)| EyeView { gaze, ..*e })
        .collect()
}

/// Renders one frame and names the scene on failure.
pub fn render_named(renderer: &mut Renderer, request: &FrameRequest, name: &str) -> Result<Frame> {
    renderer
        .render_frame(request)
        .with_context(|| format!("rendering {name}"))
}
