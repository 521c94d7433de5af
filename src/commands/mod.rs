//! One file per subcommand, plus what they share: GPU selection and the validation check.

pub mod bench;
pub mod check;
pub mod render;
pub mod render_bench;
pub mod scenes;
pub mod view;
pub mod xr;

use anyhow::{bail, Result};
use clap::Args;
use fovea::gpu::{GpuContext, GpuOptions};
use std::sync::Arc;

#[derive(Args)]
pub struct GpuArgs {
    /// Use the Vulkan device whose name contains this text (e.g. "llvmpipe").
    #[arg(long)]
    pub device: Option<String>,
    /// Enable the Vulkan validation layer; any message it reports makes the command fail.
    #[arg(long)]
    pub validate: bool,
}

pub fn gpu_context(args: &GpuArgs) -> Result<Arc<GpuContext>> {
    let mut options = GpuOptions::from_env();
    if args.device.is_some() {
        options.device = args.device.clone();
    }
    options.validation |= args.validate;
    Ok(Arc::new(GpuContext::new(&options)?))
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
