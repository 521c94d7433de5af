//! `fovea render --bench`: GPU time of every built-in scene at the given size, regular and —
//! when a foveation config is given — foveated with forward and corner gaze, measured in one
//! run with the modes interleaved frame by frame (this machine's speed drifts). Reports the
//! ray-count ratio (the ideal speed-up) beside the measured GPU-time ratio. With
//! `--gaze-trace`, a fourth mode follows the trace: measured frame k takes row k. With
//! `--traversal auto` every traversal the device has is measured (software, and ray queries
//! where enabled), interleaved like the modes; a named traversal measures only that one.

use super::args::RenderArgs;
use super::gaze::with_source_gaze;
use crate::commands::check_validation;
use anyhow::{Context, Result};
use fovea::bench::stats::median;
use fovea::foveation::{FoveationConfig, Gaze, GazeChoice, GazeTrace, TraceReplay};
use fovea::gpu::GpuContext;
use fovea::render::FrameOptions;
use fovea::render::{
    eye_views, DebugView, Frame, FrameRequest, FrameStats, RenderSettings, Renderer, Traversal,
    TraversalChoice,
};
use fovea::scene::{self, builtin::BUILTIN_SCENES, Scene};
use std::path::Path;
use std::sync::Arc;

/// One way of rendering a scene, and what its frames cost.
struct Mode {
    name: &'static str,
    traversal: Traversal,
    config: FoveationConfig,
    /// `None`: the gaze trace's row of the frame.
    gaze: Option<Gaze>,
    gpu_ms: Vec<f64>,
    trace_ms: Vec<f64>,
    /// Camera paths per measured frame.
    samples: Vec<u64>,
    /// Rays (camera, bounce and shadow) of the last measured frame.
    rays: u64,
}

impl Mode {
    fn new(
        name: &'static str,
        traversal: Traversal,
        config: FoveationConfig,
        gaze: Option<Gaze>,
    ) -> Self {
        Self {
            name,
            traversal,
            config,
            gaze,
            gpu_ms: Vec::new(),
            trace_ms: Vec::new(),
            samples: Vec::new(),
            rays: 0,
        }
    }

    /// The mode's medians for `--json`.
    fn record(&self, scene: &str) -> serde_json::Value {
        let samples: Vec<f64> = self.samples.iter().map(|&s| s as f64).collect();
        serde_json::json!({
            "scene": scene,
            "mode": self.name,
            "traversal": self.traversal.name(),
            "gpu_ms": median(&self.gpu_ms),
            "trace_ms": median(&self.trace_ms),
            "samples": median(&samples),
            "frames": self.gpu_ms.len(),
        })
    }

    /// Adds a measured frame's times, paths and rays.
    fn add(&mut self, s: &FrameStats) {
        self.gpu_ms.push(s.gpu_ms());
        self.trace_ms.push(
            s.pass_ms
                .iter()
                .filter(|(p, _)| p.ends_with("trace"))
                .map(|(_, ms)| ms)
                .sum(),
        );
        self.samples.push(s.paths);
        self.rays = s.rays;
    }

    /// Mean camera paths of a frame (the trace mode's vary from frame to frame).
    fn mean_samples(&self) -> f64 {
        self.samples.iter().sum::<u64>() as f64 / self.samples.len().max(1) as f64
    }
}

pub fn run(
    ctx: &Arc<GpuContext>,
    args: &RenderArgs,
    config: &FoveationConfig,
    settings: &RenderSettings,
    trace: Option<GazeTrace>,
) -> Result<()> {
    let foveated = !config.is_regular();
    print_header(args, settings, trace.as_ref(), foveated);
    let aspect = settings.width as f32 / settings.height as f32;
    let mut records = Vec::new();
    for (name, _) in BUILTIN_SCENES {
        let scene = scene::builtin::builtin(name, aspect)?;
        let renderer = Renderer::new(ctx, &scene)?;
        let traversals = match args.gpu.traversal {
            TraversalChoice::Auto => renderer.traversals(),
            _ => vec![renderer.traversal()],
        };
        let (modes, replays) = scene_modes(&traversals, config, settings, trace.as_ref());
        let mut timed = SceneTimes {
            name,
            scene,
            renderer,
            modes,
            replays,
        };
        // Frame 0 of each mode is a warm-up (pipeline compilation, first-touch memory).
        for frame_index in 0..=args.bench_frames {
            timed.frame(args, settings, frame_index)?;
        }
        if let Some(path) = &args.json {
            records.extend(timed.modes.iter().map(|m| m.record(name)));
            write_json(path, ctx, args, settings, &records)?;
        }
        for traversal in traversals {
            let of_traversal: Vec<&Mode> = (timed.modes.iter())
                .filter(|m| m.traversal == traversal)
                .collect();
            print_scene(name, traversal, &of_traversal, foveated);
        }
    }
    check_validation(ctx)
}

/// What is measured, and the table's header.
fn print_header(
    args: &RenderArgs,
    settings: &RenderSettings,
    trace: Option<&GazeTrace>,
    foveated: bool,
) {
    if let Some(trace) = trace {
        println!(
            "mode trace: gaze from {} ({} rows; measured frame k takes row k)",
            trace.path.display(),
            trace.rows.len()
        );
    }
    println!(
        "{}x{} per eye, {} eye(s), fov {:?}, {} frames per mode (median), {:?}, depth {}",
        settings.width,
        settings.height,
        if args.stereo { 2 } else { 1 },
        args.fov,
        args.bench_frames,
        settings.integrator,
        settings.max_bounces
    );
    if foveated {
        println!(
            "{:<12} {:<9} {:>10} {:>10} {:>10} | {:>8} {:>8} {:>5} | {:>8} {:>8} {:>5}",
            "scene",
            "traversal",
            "regular",
            "forward",
            "corner",
            "ideal",
            "measured",
            "eff",
            "ideal",
            "measured",
            "eff"
        );
    } else {
        println!(
            "{:<12} {:<9} {:>10} {:>10} {:>12}",
            "scene", "traversal", "gpu ms", "Msamples/s", "Mrays/s"
        );
    }
}

/// Per traversal: regular, then (foveated) forward and corner, then (with a trace) the trace
/// mode, with one replay of the trace per traversal: every scene replays the trace from its
/// first row.
fn scene_modes(
    traversals: &[Traversal],
    config: &FoveationConfig,
    settings: &RenderSettings,
    trace: Option<&GazeTrace>,
) -> (Vec<Mode>, Vec<TraceReplay>) {
    let foveated = !config.is_regular();
    let mut replays = Vec::new();
    let mut modes = Vec::new();
    for &traversal in traversals {
        modes.push(Mode::new(
            "regular",
            traversal,
            FoveationConfig::regular(settings.spp),
            Some(Gaze::Forward),
        ));
        if foveated {
            for (name, gaze) in [("forward", Gaze::Forward), ("corner", Gaze::Corner)] {
                modes.push(Mode::new(name, traversal, config.clone(), Some(gaze)));
            }
        }
        if let Some(trace) = trace {
            modes.push(Mode::new("trace", traversal, config.clone(), None));
            replays.push(TraceReplay::new(trace.clone()));
        }
    }
    (modes, replays)
}

/// One built-in scene and its modes, timed frame by frame.
struct SceneTimes {
    name: &'static str,
    scene: Scene,
    renderer: Renderer,
    modes: Vec<Mode>,
    replays: Vec<TraceReplay>,
}

impl SceneTimes {
    /// Renders frame `frame_index` of every mode, interleaved; frame 0 is not recorded.
    fn frame(
        &mut self,
        args: &RenderArgs,
        settings: &RenderSettings,
        frame_index: u32,
    ) -> Result<()> {
        let aspect = settings.width as f32 / settings.height as f32;
        let mut next_replay = self.replays.iter_mut();
        for mode in &mut self.modes {
            self.renderer.set_traversal(mode.traversal)?;
            let gaze = GazeChoice {
                left: mode.gaze.unwrap_or(Gaze::Forward),
                right: mode.gaze.unwrap_or(Gaze::Forward),
            };
            let mut eyes = eye_views(&self.scene.camera, aspect, args.fov, args.stereo, gaze);
            if let (None, Some(replay)) = (mode.gaze, next_replay.next()) {
                // The warm-up frame uses row 0 too.
                let row = frame_index.saturating_sub(1) as u64;
                eyes = with_source_gaze(&eyes, replay, row, settings);
            }
            let request = FrameRequest {
                settings: *settings,
                foveation: &mode.config,
                eyes: &eyes,
                debug: DebugView::None,
            };
            let frame = render_named(&mut self.renderer, &request, self.name)?;
            if frame_index == 0 {
                continue;
            }
            mode.add(&frame.stats);
        }
        Ok(())
    }
}

/// Prints one scene's row for one traversal: its modes' median GPU times and ratios.
fn print_scene(name: &str, traversal: Traversal, modes: &[&Mode], foveated: bool) {
    let ms: Vec<f64> = modes.iter().map(|m| median(&m.gpu_ms)).collect();
    let traversal = traversal.name();
    if foveated {
        let ratio = |m: &Mode| modes[0].mean_samples() / m.mean_samples().max(1.0);
        let (fwd, cor) = (modes[1], modes[2]);
        println!(
            "{:<12} {:<9} {:>10.1} {:>10.1} {:>10.1} | {:>8.2} {:>8.2} {:>4.0}% | {:>8.2} {:>8.2} {:>4.0}%",
            name,
            traversal,
            ms[0],
            ms[1],
            ms[2],
            ratio(fwd),
            ms[0] / ms[1],
            100.0 * ms[0] / ms[1] / ratio(fwd),
            ratio(cor),
            ms[0] / ms[2],
            100.0 * ms[0] / ms[2] / ratio(cor),
        );
        for m in &modes[1..] {
            println!(
                "{:<12}   {:<8} samples {:>10.0} (regular {:.0}), trace {:.1} ms, plan+resolve {:.1} ms",
                "",
                m.name,
                m.mean_samples(),
                modes[0].mean_samples(),
                median(&m.trace_ms),
                median(&m.gpu_ms) - median(&m.trace_ms)
            );
        }
        if let Some(m) = modes.get(3) {
            println!(
                "{:<12}   {:<8} {:.1} ms, ideal {:.2}, measured {:.2}, eff {:.0}%",
                "",
                m.name,
                ms[3],
                ratio(m),
                ms[0] / ms[3],
                100.0 * ms[0] / ms[3] / ratio(m)
            );
        }
    } else {
        let m = modes[0];
        println!(
            "{:<12} {:<9} {:>10.1} {:>10.2} {:>12.2}",
            name,
            traversal,
            ms[0],
            m.mean_samples() / (ms[0] * 1e3).max(1e-9),
            m.rays as f64 / (ms[0] * 1e3).max(1e-9)
        );
    }
}

/// Writes the records measured so far, with the device and settings they were measured at.
fn write_json(
    path: &Path,
    ctx: &GpuContext,
    args: &RenderArgs,
    settings: &RenderSettings,
    records: &[serde_json::Value],
) -> Result<()> {
    let json = serde_json::json!({
        "device": ctx.info.name,
        "driver": ctx.info.driver,
        "width": settings.width,
        "height": settings.height,
        "eyes": if args.stereo { 2 } else { 1 },
        "fov": format!("{:?}", args.fov),
        "spp": settings.spp,
        "integrator": format!("{:?}", settings.integrator),
        "sampler": settings.sampler.name(),
        "max_bounces": settings.max_bounces,
        "records": records,
    });
    let text = serde_json::to_string_pretty(&json)?;
    std::fs::write(path, text + "\n").with_context(|| {
        format!(
            "cannot write {}: check the directory exists",
            path.display()
        )
    })
}

/// Renders one frame and names the scene on failure.
fn render_named(renderer: &mut Renderer, request: &FrameRequest, name: &str) -> Result<Frame> {
    renderer
        .frame(request, FrameOptions::pixels())
        .map(Option::unwrap)
        .with_context(|| format!("rendering {name}"))
}
