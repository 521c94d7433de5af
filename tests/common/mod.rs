//! Shared set-up for the GPU integration tests: a lavapipe (or GPU) context with the validation
//! layer on, and a check that fails the test on any validation message.

#![allow(dead_code)]

pub mod rays;

use fovea::gpu::{GpuContext, GpuOptions};
use fovea::render::regular_frame;
use fovea::render::{Frame, Integrator, RenderSettings, Renderer, TemporalSettings};
use fovea::scene::Scene;
use std::path::Path;
use std::process::Command;
use std::sync::Arc;

#[path = "../../src/test_dir.rs"]
mod test_dir;
pub use test_dir::TestDir;

/// A new, empty [`TestDir`] named after the test binary's process and `name`, inside the
/// directory Cargo gives integration tests for their files (target/tmp), not the system's.
pub fn test_dir(name: &str) -> TestDir {
    TestDir::new_in(Path::new(env!("CARGO_TARGET_TMPDIR")), name)
}

/// Runs the `fovea` binary with the validation layer on; returns success and all it printed.
/// Fails the test if it panicked: bad input must get a message, never a panic.
pub fn fovea(args: &[&str]) -> (bool, String) {
    fovea_with_env(args, &[])
}

pub fn context() -> Arc<GpuContext> {
    let mut options = GpuOptions::from_env();
    options.validation = true;
    Arc::new(GpuContext::new(&options).expect("a Vulkan device (run tools/setup.sh for lavapipe)"))
}

/// Fails the calling test if the validation layer reported anything.
pub fn assert_no_validation_messages(ctx: &GpuContext) {
    let messages = ctx.take_validation_messages();
    assert!(
        messages.is_empty(),
        "validation messages:\n{}",
        messages.join("\n")
    );
}

pub fn settings(
    width: u32,
    height: u32,
    spp: u32,
    seed: u32,
    integrator: Integrator,
) -> RenderSettings {
    RenderSettings {
        sampler: Default::default(),
        width,
        height,
        spp,
        seed,
        integrator,
        max_bounces: 8,
    }
}

/// Renders `scene` from its own camera and checks the frame is clean.
/// A renderer of `scene` with the temporal history on, at its default settings.
pub fn renderer_with_history(ctx: &Arc<GpuContext>, scene: &Scene) -> Renderer {
    let mut renderer = Renderer::new(ctx, scene).unwrap();
    renderer
        .set_temporal(Some(TemporalSettings::default()))
        .unwrap();
    renderer
}

pub fn render(ctx: &Arc<GpuContext>, scene: &Scene, s: &RenderSettings) -> Frame {
    let mut renderer = Renderer::new(ctx, scene).expect("scene upload");
    let frame = regular_frame(&mut renderer, &scene.camera, s).expect("render");
    drop(renderer);
    assert_no_validation_messages(ctx);
    assert_eq!(
        frame.stats.stack_overflows, 0,
        "BVH stack overflows in {}",
        scene.name
    );
    assert_eq!(
        frame.stats.nonfinite_samples, 0,
        "non-finite samples in {}",
        scene.name
    );
    assert_eq!(
        frame.stats.paths,
        s.width as u64 * s.height as u64 * s.spp as u64
    );
    frame
}

/// Like [`fovea`] (validation on, fails the test on a panic), with extra environment
/// variables, which may also override `FOVEA_VALIDATION`.
/// The run's temporary files (the metric's frames, anything a library puts in the system's
/// temporary directory) go to a directory of its own (`TMPDIR`), removed when it exits: also
/// after a run that a test aborts on purpose.
pub fn fovea_with_env(args: &[&str], env: &[(&str, &str)]) -> (bool, String) {
    static RUNS: std::sync::atomic::AtomicU32 = std::sync::atomic::AtomicU32::new(0);
    let run = RUNS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let tmp = test_dir(&format!("run-{run}-tmp"));
    let out = Command::new(env!("CARGO_BIN_EXE_fovea"))
        .args(args)
        .env("FOVEA_VALIDATION", "1")
        .env("TMPDIR", &*tmp)
        .envs(env.iter().copied())
        .output()
        .unwrap();
    drop(tmp);
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        !text.contains("panicked"),
        "fovea {args:?} with {env:?} panicked:\n{text}"
    );
    (out.status.success(), text)
}

/// A context like [`context`] with GPU-assisted validation on as well: shaders are
/// instrumented to report out-of-bounds descriptor accesses (slow: small dispatches only).
pub fn gpu_assisted_context() -> Arc<GpuContext> {
    let mut options = GpuOptions::from_env();
    options.validation = true;
    options.checks.gpu_assisted = true;
    Arc::new(GpuContext::new(&options).expect("a Vulkan device (run tools/setup.sh for lavapipe)"))
}

/// Where a command that should fail before writing anything is told to write: inside the
/// tests' own directory (target/tmp), so that one which does write leaves nothing elsewhere.
pub const SCRATCH_PNG: &str = concat!(env!("CARGO_TARGET_TMPDIR"), "/fovea-scratch.png");

/// Per block of `block`x`block` pixels and channel: the mean and its standard error (the
/// pixels' spread over the square root of their count).
pub fn block_stats(rgb: &[f32], w: usize, block: usize) -> Vec<[(f64, f64); 3]> {
    let h = rgb.len() / 3 / w;
    let mut out = Vec::new();
    for by in (0..h).step_by(block) {
        for bx in (0..w).step_by(block) {
            out.push(std::array::from_fn(|c| {
                let values: Vec<f64> = (by..by + block)
                    .flat_map(|y| (bx..bx + block).map(move |x| (y, x)))
                    .map(|(y, x)| rgb[3 * (y * w + x) + c] as f64)
                    .collect();
                let n = values.len() as f64;
                let mean = values.iter().sum::<f64>() / n;
                let var = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0);
                (mean, (var / n).sqrt())
            }));
        }
    }
    out
}
