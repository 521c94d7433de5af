//! `fovea render`: one frame, mono or stereo, regular or foveated, written as PNG + EXR; or,
//! with `--bench`, timings of every built-in scene; or, with `--camera-path`, a sequence.
//!
//! One direction: this file is the entry, which checks the options and dispatches to `frame`
//! (one frame, printed by `frame_report`), `bench` or `sequence`; none of them imports it.
//! What they share is below them: `args` (the options) and `gaze` (a gaze source's eyes).

pub mod args;
mod bench;
mod frame;
mod frame_report;
mod gaze;
mod sequence;

pub use args::RenderArgs;

use super::gpu_context;
use anyhow::{bail, Result};
use fovea::foveation::GazeTrace;

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
        return bench::run(&ctx, args, &config, &settings, trace);
    }
    if let Some(path) = &args.sequence.camera_path {
        return sequence::run(&ctx, args, path, &config, &settings, trace);
    }
    frame::run(&ctx, args, &config, &settings, trace)
}
