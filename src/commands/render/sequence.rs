//! `fovea render --camera-path FILE --out DIR`: one frame per row of a camera path, each
//! written as DIR/frame_NNNN.png (+ .exr), with a temporal history carried from frame to
//! frame unless `--temporal off`.

use super::args::{OnOff, RenderArgs};
use super::gaze::with_source_gaze;
use crate::commands::check_validation;
use anyhow::{bail, Context, Result};
use fovea::foveation::{FoveationConfig, GazeTrace, TraceReplay};
use fovea::gpu::GpuContext;
use fovea::render::accumulate::frame_seed;
use fovea::render::{
    eye_views, output, DebugView, FrameRequest, RenderSettings, Renderer, TemporalSettings,
};
use fovea::render::{FrameOptions, FrameStats};
use fovea::scene::{self, CameraPath};
use std::path::{Path, PathBuf};
use std::sync::Arc;

pub fn run(
    ctx: &Arc<GpuContext>,
    args: &RenderArgs,
    path: &Path,
    config: &FoveationConfig,
    settings: &RenderSettings,
    trace: Option<GazeTrace>,
) -> Result<()> {
    let camera_path = CameraPath::read(path)?;
    let dir = args.out.clone().unwrap_or_else(|| PathBuf::from("frames"));
    if dir.extension().is_some_and(|e| e == "png" || e == "exr") {
        bail!(
            "--out {} names an image, but --camera-path writes one image per frame into a \
             directory: give a directory (e.g. --out frames)",
            dir.display()
        );
    }
    std::fs::create_dir_all(&dir)
        .with_context(|| format!("cannot create the output directory {}", dir.display()))?;
    let aspect = settings.width as f32 / settings.height as f32;
    let scene = scene::load(&args.scene, aspect)?;
    let display = args.display.transform(&args.scene);
    let mut renderer = Renderer::new(ctx, &scene)?;
    let temporal = args.sequence.temporal != Some(OnOff::Off);
    renderer.set_temporal(temporal.then_some(TemporalSettings {
        cap: args.sequence.temporal_cap.max(1),
    }))?;
    let mut replay = trace.map(TraceReplay::new);
    println!(
        "{} frames from {}, temporal history {}",
        camera_path.poses.len(),
        path.display(),
        if temporal { "on" } else { "off" }
    );
    let mut overflows = 0;
    for (k, pose) in camera_path.poses.iter().enumerate() {
        let camera = pose.apply(&scene.camera);
        let mut eyes = eye_views(&camera, aspect, args.fov, args.stereo, args.gaze);
        let frame_settings = RenderSettings {
            seed: frame_seed(settings.seed, k as u32),
            ..*settings
        };
        if let Some(replay) = &mut replay {
            eyes = with_source_gaze(&eyes, replay, k as u64, &frame_settings);
        }
        let frame = renderer
            .frame(
                &FrameRequest {
                    settings: frame_settings,
                    foveation: config,
                    eyes: &eyes,
                    debug: DebugView::None,
                },
                FrameOptions::pixels(),
            )
            .map(Option::unwrap)
            .with_context(|| format!("rendering frame {k} of {}", path.display()))?;
        let file = dir.join(format!("frame_{k:04}.png"));
        output::write_frame(&frame, &file, &display)?;
        let s = &frame.stats;
        overflows += s.stack_overflows;
        print_frame(k, s, &file, args.sequence.pass_times);
    }
    drop(renderer);
    check_validation(ctx)?;
    if overflows > 0 {
        bail!("{overflows} BVH traversals overflowed their stack: frames are missing geometry");
    }
    Ok(())
}

/// Frame k's line: its GPU time, what history and denoising cost of it, its samples and its
/// file; with `pass_times`, every pass's time after it.
fn print_frame(k: usize, s: &FrameStats, file: &Path, pass_times: bool) {
    let ms_of = |pass: &str| -> f64 {
        s.pass_ms
            .iter()
            .filter(|(name, _)| name.ends_with(pass))
            .fold(0.0, |sum, (_, ms)| sum + ms)
    };
    println!(
        "frame {k}: {:.2} ms GPU (temporal {:.2}, denoise {:.2}), {} samples, wrote {}",
        s.gpu_ms(),
        ms_of("temporal"),
        ms_of("denoise"),
        s.paths,
        file.display()
    );
    if pass_times {
        for (pass, ms) in &s.pass_ms {
            println!("  gpu pass {pass}: {ms:.2} ms");
        }
    }
}
