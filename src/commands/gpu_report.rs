//! `fovea gpu-report OUT_DIR`: is fovea real-time on this device (see fovea::realtime)?
//! tools/gpu-bundle.sh packs it for a GPU machine; its run-report.sh calls it.

use super::{check_validation, gpu_context, GpuArgs};
use anyhow::{bail, Result};
use clap::Args;
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
    /// Each eye's image, WIDTHxHEIGHT (the Vive Pro Eye's 1440x1600 by default).
    #[arg(long, value_parser = super::parse_size, default_value = "1440x1600")]
    pub size: [u32; 2],
    /// Only these built-in scenes, comma-separated (default: all of them).
    #[arg(long, value_delimiter = ',')]
    pub scenes: Vec<String>,
    #[command(flatten)]
    pub gpu: GpuArgs,
}

pub fn run(args: &GpuReportArgs) -> Result<()> {
    let [width, height] = args.size;
    let mut plan = match args.quick {
        true => RealtimePlan::quick(width, height),
        false => RealtimePlan::full(width, height),
    };
    if !args.scenes.is_empty() {
        let known = &plan.scenes;
        if let Some(unknown) = args.scenes.iter().find(|s| !known.contains(s)) {
            bail!("--scenes: '{unknown}' is not a built-in scene; give some of {known:?}");
        }
        plan.scenes = args.scenes.clone();
    }
    let ctx = gpu_context(&args.gpu)?;
    println!(
        "fovea gpu-report on {} ({}, Vulkan {}): {} scenes at {width}x{height} per eye{}",
        ctx.info.name,
        ctx.info.driver,
        ctx.info.api_version,
        plan.scenes.len(),
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
