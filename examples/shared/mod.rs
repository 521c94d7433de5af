//! What the measuring examples share: a square regular frame of a scene, its error against a
//! reference, and their command-line numbers.
// Each example uses part of this module.
#![allow(dead_code)]

use std::sync::Arc;

use fovea::gpu::GpuContext;
use fovea::render::{regular_frame, Integrator, RenderSettings, Renderer};
use fovea::scene::Scene;

/// The linear RGB of a `size` × `size` regular frame of `scene` (path tracer, 8 bounces).
pub fn render_rgb(
    ctx: &Arc<GpuContext>,
    scene: &Scene,
    size: u32,
    spp: u32,
    seed: u32,
) -> Result<Vec<f32>, Box<dyn std::error::Error>> {
    let mut renderer = Renderer::new(ctx, scene)?;
    Ok(regular_frame(&mut renderer, &scene.camera, &square(size, spp, seed))?.rgb)
}

/// A `size` × `size` frame of the path tracer at 8 bounces, with the `--sampler` given to
/// the example ([`choose_sampler`]; zsobol by default).
pub fn square(size: u32, spp: u32, seed: u32) -> RenderSettings {
    RenderSettings {
        sampler: fovea::render::Sampler::chosen(),
        width: size,
        height: size,
        spp,
        seed,
        integrator: Integrator::Pt,
        max_bounces: 8,
    }
}

/// sqrt(Σ (image − reference)² / Σ reference²) over every pixel and channel.
pub fn relative_error(image: &[f32], reference: &[f32]) -> f64 {
    let num: f64 = (image.iter().zip(reference))
        .map(|(a, b)| ((a - b) as f64).powi(2))
        .sum();
    let den: f64 = reference.iter().map(|b| (*b as f64).powi(2)).sum();
    (num / den).sqrt()
}

/// The number after `name` on the command line, or `default`.
pub fn arg(name: &str, default: u32) -> u32 {
    let args: Vec<String> = std::env::args().collect();
    (args.iter().position(|a| a == name))
        .and_then(|i| args.get(i + 1)?.parse().ok())
        .unwrap_or(default)
}

/// `--sampler independent|zsobol` on the example's command line, as `fovea --sampler` takes it.
pub fn choose_sampler() -> Result<(), String> {
    let args: Vec<String> = std::env::args().collect();
    let Some(i) = args.iter().position(|a| a == "--sampler") else {
        return Ok(());
    };
    let sampler = match args.get(i + 1).map(String::as_str) {
        Some("zsobol") => fovea::render::Sampler::Zsobol,
        Some("independent") => fovea::render::Sampler::Independent,
        other => return Err(format!("--sampler {other:?}: give zsobol or independent")),
    };
    fovea::render::Sampler::choose_for_process(sampler);
    Ok(())
}
