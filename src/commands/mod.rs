//! One file (or folder) per subcommand, plus what they share: GPU selection and the
//! validation check.

pub mod bench;
pub mod check;
pub mod gpu_report;
pub mod render;
pub mod scenes;
pub mod tune;
pub mod view;
pub mod xr;

use anyhow::{bail, Result};
use clap::Args;
use fovea::gpu::{GpuContext, GpuOptions, RayQueries};
use fovea::render::TraversalChoice;
use std::sync::Arc;

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
