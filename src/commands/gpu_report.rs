//! `fovea gpu-report OUT_DIR`: is fovea real-time on this device (see fovea::realtime)?
//! tools/gpu-bundle.sh packs it for a GPU machine; its run-report.sh calls it.

use super::{check_validation, gpu_context, GpuArgs};
use anyhow::{bail, Result};
use clap::Args;
use fovea::foveation::{DisplayProfile, FoveationConfig};
use fovea::realtime::{self, RealtimePlan};
use std::path::PathBuf;
use std::time::Instant;

#[derive(Args)]
pub struct GpuReportArgs {
    /// Where the report goes (created): frames.csv, passes.csv, spp.csv, spp-probes.csv,
    /// sessions.csv, report.json, report.md and one folder per headset session.
    pub out: PathBuf,
    /// Fewer layer configs and frames (60 timed per case): within 2 minutes on a GPU.
    #[arg(long)]
    pub quick: bool,
    /// The headset whose eyes' fields of view the frames cover, and whose panel is each eye's
    /// image unless --size says otherwise.
    #[arg(long = "display", value_name = "HEADSET", value_enum, default_value_t = DisplayProfile::ViveProEye)]
    pub display_profile: DisplayProfile,
    /// Each eye's image, WIDTHxHEIGHT. Default: the --display's panel (1440x1600 for the Vive
    /// Pro Eye, 3840x3744 for the Varjo XR-4).
    #[arg(long, value_parser = super::parse_size)]
    pub size: Option<[u32; 2]>,
    /// Only these scenes, comma-separated: built-in ones or .gltf/.glb files (default: every
    /// built-in scene).
    #[arg(long, value_delimiter = ',')]
    pub scenes: Vec<String>,
    /// Also time this layer config, NAME=FILE.toml (repeatable): its rows are named NAME.
    #[arg(long = "config", value_name = "NAME=FILE")]
    pub configs: Vec<String>,
    /// Time every frame with the temporal history on, the camera still (as a headset shows
    /// it; the denoiser and the lattice filter run only with it).
    #[arg(long)]
    pub history: bool,
    #[command(flatten)]
    pub lanes: super::trace_lanes_args::TraceLaneArgs,
    #[command(flatten)]
    pub gpu: GpuArgs,
}

/// NAME=FILE of `--config`.
fn named_config(text: &str) -> Result<(&str, &str)> {
    match text.split_once('=') {
        Some((name, path)) if !name.is_empty() && !path.is_empty() => Ok((name, path)),
        _ => {
            bail!("--config '{text}': give NAME=FILE.toml (a layer config, see assets/foveation/)")
        }
    }
}

pub fn run(args: &GpuReportArgs) -> Result<()> {
    let (panel_width, panel_height) = args.display_profile.eye_size();
    let [width, height] = args.size.unwrap_or([panel_width, panel_height]);
    let mut plan = match args.quick {
        true => RealtimePlan::quick(width, height),
        false => RealtimePlan::full(width, height),
    };
    plan.display = args.display_profile;
    if !args.scenes.is_empty() {
        let known = &plan.scenes;
        let missing = |s: &String| match fovea::scene::is_scene_file(s) {
            true => !std::path::Path::new(s).is_file(),
            false => !known.contains(s),
        };
        if let Some(unknown) = args.scenes.iter().find(|s| missing(s)) {
            bail!(
                "--scenes: '{unknown}' is neither a built-in scene nor a .gltf/.glb file that \
                 exists; give some of {known:?} or a glTF file's path"
            );
        }
        plan.scenes = args.scenes.clone();
    }
    for named in &args.configs {
        let (name, path) = named_config(named)?;
        plan.add_mode(name, FoveationConfig::load(std::path::Path::new(path))?);
    }
    plan.history = args.history;
    let ctx = gpu_context(&args.gpu)?;
    plan.trace_lanes = args.lanes.lanes(&ctx)?;
    println!(
        "fovea gpu-report on {} ({}, Vulkan {}): {} scenes at {width}x{height} per eye over the \
         {}'s field of view{}",
        ctx.info.name,
        ctx.info.driver,
        ctx.info.api_version,
        plan.scenes.len(),
        plan.display.name(),
        if plan.quick { ", --quick" } else { "" }
    );
    let started = Instant::now();
    let command = std::env::args().collect::<Vec<_>>().join(" ");
    realtime::run(&ctx, &plan, &args.out, command, &mut |what| {
        println!("[{:6.1} s] {what}", started.elapsed().as_secs_f64())
    })
    .map_err(anyhow::Error::msg)?;
    check_validation(&ctx)?;
    println!(
        "wrote {} in {:.1} s (report.md first)",
        args.out.display(),
        started.elapsed().as_secs_f64()
    );
    Ok(())
}
