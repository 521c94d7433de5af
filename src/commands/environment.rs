//! `--env FILE` and its options, global to every command: the HDR environment that lights
//! every scene in place of its sky (fovea::scene::env_map, env_choice).

use std::path::PathBuf;

use anyhow::Result;
use clap::Args;
use fovea::scene::env_choice::{set_environment, EnvChoice};
use fovea::scene::EnvSampling;

#[derive(Args, Clone, Debug)]
pub struct EnvArgs {
    /// Light every scene by this HDR environment (equirectangular .exr or .hdr, 2:1, oriented
    /// as Blender's Environment Texture for a glTF scene) in place of its sky.
    #[arg(long, global = true, value_name = "FILE.exr|.hdr")]
    env: Option<PathBuf>,
    /// Turn the environment about the up axis by DEG degrees (right-handed: +X toward −Z).
    #[arg(long, global = true, value_name = "DEG", default_value_t = 0.0,
          allow_negative_numbers = true, value_parser = finite)]
    env_rotate: f32,
    /// Multiply the environment's radiance by X.
    #[arg(long, global = true, value_name = "X", default_value_t = 1.0, value_parser = non_negative)]
    env_intensity: f32,
    /// How next-event estimation picks directions of the environment: `importance`
    /// (luminance × sin θ) or `uniform` (over the sphere; for comparison).
    #[arg(long, global = true, value_enum, default_value_t = EnvSampling::Importance)]
    env_sampling: EnvSampling,
}

impl EnvArgs {
    /// Reads the environment (if one was given) for every scene the command loads.
    pub fn apply(&self) -> Result<()> {
        let Some(path) = &self.env else {
            return Ok(());
        };
        let started = std::time::Instant::now();
        let path = std::path::absolute(path).unwrap_or_else(|_| path.clone());
        let clamped = set_environment(EnvChoice {
            path: path.clone(),
            rotate_deg: self.env_rotate,
            intensity: self.env_intensity,
            sampling: self.env_sampling,
        })?;
        // Lossy EXR compression (Blender's own environments are DWAB) leaves a few slightly
        // negative texels: set to 0 and said, not refused.
        if clamped > 0 {
            tracing::info!("{}: {clamped} negative texel(s) set to 0", path.display());
        }
        tracing::info!(
            "{}: read in {:.0} ms",
            path.display(),
            started.elapsed().as_secs_f64() * 1e3
        );
        Ok(())
    }
}

fn finite(text: &str) -> Result<f32, String> {
    match text.parse::<f32>() {
        Ok(v) if v.is_finite() => Ok(v),
        _ => Err(format!("'{text}' is not a number of degrees")),
    }
}

fn non_negative(text: &str) -> Result<f32, String> {
    match text.parse::<f32>() {
        Ok(v) if v.is_finite() && v >= 0.0 => Ok(v),
        _ => Err(format!("'{text}' is not a factor ≥ 0")),
    }
}
