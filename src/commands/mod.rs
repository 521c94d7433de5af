//! One file (or folder) per subcommand, plus what they share: GPU selection, the validation
//! check and the eye-size parser. `main.rs` dispatches to each; none imports another's
//! entry.

pub mod bench;
pub mod check;
mod environment;
mod error_text;
pub mod gpu_report;
pub mod render;
pub mod scenes;
pub mod trace_lanes_args;
pub mod tune;
pub mod view;
pub mod xr;

pub use environment::EnvArgs;
pub use error_text::error_text;

use anyhow::{bail, Result};
use clap::Args;
use fovea::gpu::{GpuContext, GpuOptions, RayQueries};
use fovea::render::display::{DisplayChoice, DisplayTransform, Tonemap};
use fovea::render::TraversalChoice;
use std::sync::Arc;

/// What a display shows of the scene-referred radiance (fovea::render::display).
#[derive(Args, Clone, Copy, Debug)]
pub struct DisplayArgs {
    /// Exposure in stops for what is shown (PNG; the EXR beside it stays scene-referred):
    /// radiance × 2^EV before tone mapping.
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true, value_parser = exposure)]
    pub exposure: f32,
    /// Tone mapper for what is shown: `clamp` (clip at 1; the built-in scenes' default) or
    /// `pbr-neutral` (Khronos PBR Neutral; the default for .gltf/.glb files).
    #[arg(long, value_enum)]
    pub tonemap: Option<Tonemap>,
}

impl DisplayArgs {
    /// What was asked, for every scene of the command.
    pub fn choice(&self) -> DisplayChoice {
        DisplayChoice {
            exposure: self.exposure,
            tonemap: self.tonemap,
        }
    }

    /// The transform for `scene` (its default tone mapper follows its kind).
    pub fn transform(&self, scene: &str) -> DisplayTransform {
        self.choice().transform(scene)
    }
}

fn exposure(text: &str) -> Result<f32, String> {
    match text.parse::<f32>() {
        Ok(ev) if ev.is_finite() && ev.abs() <= 30.0 => Ok(ev),
        _ => Err(format!(
            "'{text}' is not an exposure in stops from -30 to 30"
        )),
    }
}

#[derive(Args)]
pub struct GpuArgs {
    /// Use the Vulkan device whose name contains this text (e.g. "llvmpipe").
    #[arg(long)]
    pub device: Option<String>,
    /// Enable the Vulkan validation layer; any message it reports makes the command fail.
    #[arg(long)]
    pub validate: bool,
    /// How rays find what they hit: `software` (fovea's own BVH traversal, any device),
    /// `rayquery` (VK_KHR_ray_query: the GPU's ray-tracing hardware) or `auto` (ray queries
    /// where the device has them, else software).
    #[arg(long, value_enum, default_value_t = TraversalChoice::Auto)]
    pub traversal: TraversalChoice,
}

impl GpuArgs {
    /// The device options these flags ask for, over the environment's (GpuOptions::from_env).
    pub fn options(&self) -> GpuOptions {
        let mut options = GpuOptions::from_env();
        if self.device.is_some() {
            options.device = self.device.clone();
        }
        options.validation |= self.validate;
        // The renderer traces with ray queries whenever its context has them enabled.
        options.ray_queries = match self.traversal {
            TraversalChoice::Software => RayQueries::Off,
            TraversalChoice::Rayquery => RayQueries::Required,
            TraversalChoice::Auto => RayQueries::IfAvailable,
        };
        options
    }
}

pub fn gpu_context(args: &GpuArgs) -> Result<Arc<GpuContext>> {
    Ok(Arc::new(GpuContext::new(&args.options())?))
}

pub fn check_validation(ctx: &GpuContext) -> Result<()> {
    check_validation_messages(&ctx.take_validation_messages())
}

/// Fails with the messages, if the validation layer reported any.
pub fn check_validation_messages(messages: &[String]) -> Result<()> {
    if !messages.is_empty() {
        bail!(
            "the Vulkan validation layer reported {} message(s):\n{}",
            messages.len(),
            messages.join("\n")
        );
    }
    Ok(())
}

/// A per-eye image size WIDTHxHEIGHT (`xr --size`, `gpu-report --size`).
pub fn parse_size(text: &str) -> Result<[u32; 2], String> {
    let bad = || format!("size '{text}' is not understood: give WIDTHxHEIGHT, e.g. 720x800");
    let (w, h) = text.split_once('x').ok_or_else(bad)?;
    let w: u32 = w.trim().parse().map_err(|_| bad())?;
    let h: u32 = h.trim().parse().map_err(|_| bad())?;
    if w == 0 || h == 0 || w > fovea::render::MAX_SIDE || h > fovea::render::MAX_SIDE {
        return Err(format!(
            "size {w}x{h}: each side must be from 1 to {}",
            fovea::render::MAX_SIDE
        ));
    }
    Ok([w, h])
}
