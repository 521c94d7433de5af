//! `fovea render`'s single frame: rendered after a warm-up, its layers, samples and passes
//! printed, optionally as its difference from a regular frame, and written as PNG + EXR.

use super::args::{DebugArg, RenderArgs};
use super::frame_report::report;
use super::gaze::with_source_gaze;
use crate::commands::check_validation;
use anyhow::{bail, Result};
use fovea::foveation::{FoveationConfig, GazeSource, GazeTrace, TraceReplay};
use fovea::gpu::GpuContext;
use fovea::render::FrameOptions;
use fovea::render::{
    eye_views, output, DebugView, EyeView, Frame, FrameRequest, RenderSettings, Renderer,
};
use fovea::scene::{self, Scene};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// Renders, reports and writes the frame `args` ask for (`trace`: its gaze trace).
pub fn run(
    ctx: &Arc<GpuContext>,
    args: &RenderArgs,
    config: &FoveationConfig,
    settings: &RenderSettings,
    trace: Option<GazeTrace>,
) -> Result<()> {
    let aspect = settings.width as f32 / settings.height as f32;
    let started = Instant::now();
    let scene = scene::load(&args.scene, aspect)?;
    let read = started.elapsed();
    let mut renderer = load(ctx, &scene, read, args.profile_traversal)?;
    if let Some(lanes) = args.lanes.lanes(ctx)? {
        renderer.set_trace_lanes(lanes);
    }
    let eyes = frame_eyes(args, &scene, settings, trace);
    let request = FrameRequest {
        settings: *settings,
        foveation: config,
        eyes: &eyes,
        debug: match args.debug {
            Some(DebugArg::Layers) => DebugView::Layers,
            _ => DebugView::None,
        },
    };
    warm_up(&mut renderer, &request)?;
    let mut frame = renderer
        .frame(&request, FrameOptions::pixels())
        .map(Option::unwrap)?;
    report(&frame, config, settings, ctx.info.subgroup_size);
    if args.debug == Some(DebugArg::Diff) {
        frame.rgb = difference_from_regular(&mut renderer, &request, &frame)?;
    }
    let out = args.out.clone().unwrap_or_else(|| "fovea.png".into());
    let written = output::write_frame(&frame, &out, &args.display.transform(&args.scene))?;
    for path in written {
        println!("wrote {}", path.display());
    }
    drop(renderer);
    check_validation(ctx)?;
    let s = &frame.stats;
    if s.stack_overflows > 0 {
        bail!(
            "{} BVH traversals overflowed their stack: the image is missing geometry",
            s.stack_overflows
        );
    }
    Ok(())
}

/// The scene's renderer, and what reading (`read`) and building it took.
fn load(
    ctx: &Arc<GpuContext>,
    scene: &Scene,
    read: Duration,
    profile_traversal: bool,
) -> Result<Renderer> {
    let started = Instant::now();
    let mut renderer = Renderer::new(ctx, scene)?;
    renderer.set_traversal_profile(profile_traversal);
    let setup = started.elapsed();
    let memory = renderer.scene_memory();
    let mib = |bytes: u64| bytes as f64 / (1u64 << 20) as f64;
    println!(
        "scene {}: {} triangles, {} boxes, {} spheres, {} textures ({}); read in {:.1} ms, \
         BVH build + upload {:.1} ms; GPU memory {:.2} MiB arrays + {:.2} MiB textures",
        scene.name,
        scene.triangle_count(),
        scene.boxes.len(),
        scene.spheres.len(),
        scene.textures.len(),
        renderer.features().describe(),
        read.as_secs_f64() * 1e3,
        setup.as_secs_f64() * 1e3,
        mib(memory.buffers),
        mib(memory.textures),
    );
    Ok(renderer)
}

/// The frame's eyes: `--gaze`, or the gaze trace's row `--trace-frame`.
fn frame_eyes(
    args: &RenderArgs,
    scene: &Scene,
    settings: &RenderSettings,
    trace: Option<GazeTrace>,
) -> Vec<EyeView> {
    let aspect = settings.width as f32 / settings.height as f32;
    let eyes = eye_views(&scene.camera, aspect, args.fov, args.stereo, args.gaze);
    let Some(trace) = trace else {
        return eyes;
    };
    let row = args.trace.trace_frame.unwrap_or(0) as u64;
    let mut replay = TraceReplay::new(trace);
    let eyes = with_source_gaze(&eyes, &mut replay, row, settings);
    println!(
        "gaze from {} row {row} of {} ({})",
        replay.trace().path.display(),
        replay.trace().rows.len(),
        replay.status().name()
    );
    eyes
}

/// `--debug diff`: the absolute difference between `frame` and a regular frame of the same
/// request (same seed), whose statistics it prints.
fn difference_from_regular(
    renderer: &mut Renderer,
    request: &FrameRequest,
    frame: &Frame,
) -> Result<Vec<f32>> {
    let settings = &request.settings;
    let regular_config = FoveationConfig::regular(settings.spp);
    let regular = renderer
        .frame(
            &FrameRequest {
                foveation: &regular_config,
                ..*request
            },
            FrameOptions::pixels(),
        )
        .map(Option::unwrap)?;
    let diff = difference(frame, &regular);
    println!(
        "difference from a regular frame at {} spp (same seed): mean |Δ| {:.5}, {:.1}% of pixels identical",
        settings.spp,
        diff.mean().iter().sum::<f64>() / 3.0,
        100.0 * identical_fraction(frame, &regular)
    );
    Ok(diff.rgb)
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
    renderer
        .frame(
            &FrameRequest {
                settings,
                ..*request
            },
            FrameOptions::measure(),
        )
        .map(Option::unwrap)?;
    Ok(())
}

/// The warm-up frame's largest side: every pass runs, at almost no cost.
const WARM_UP_SIDE: u32 = 16;

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
