//! `fovea check`: the numerical stress report — watertightness, scale invariance, the white
//! furnace, enormous emission and convergence — at a chosen size, with the counts that must be
//! zero. Exits non-zero if any check fails. With `--json`, the report so far is rewritten after
//! every section, so an interrupted run keeps what it measured.

use super::{check_validation, gpu_context, GpuArgs};
use anyhow::{bail, Context, Result};
use clap::{Args, ValueEnum};
use fovea::check::convergence::{self, ConvergenceOptions};
use fovea::check::report::CheckReport;
use fovea::check::{gltf_furnace, materials, scale, watertight};
use fovea::gpu::GpuContext;
use fovea::render::{RenderSettings, Traversal};
use fovea::scene::{self, builtin::builtin};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;

/// Most watertightness rays a run may ask for: a billion takes hours on lavapipe.
const MAX_RAYS: u64 = 1_000_000_000;

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Section {
    Watertight,
    Scale,
    Furnace,
    Emission,
    Convergence,
}

#[derive(Args)]
pub struct CheckArgs {
    /// Sections to run, comma-separated (default: all).
    #[arg(long, value_enum, value_delimiter = ',')]
    only: Vec<Section>,
    /// Rays for the watertightness check, split over the three closed meshes.
    #[arg(long, default_value_t = 1_000_000)]
    rays: u64,
    /// Image side in pixels of the scale, furnace and emission renders.
    #[arg(long, default_value_t = 32)]
    size: u32,
    /// Samples per pixel of those renders.
    #[arg(long, default_value_t = 64)]
    spp: u32,
    /// Scenes of the convergence study (built-in names or glTF files).
    #[arg(long, value_delimiter = ',', default_value = "cornell,mirror-room")]
    convergence_scenes: Vec<String>,
    /// Image side of the convergence renders.
    #[arg(long, default_value_t = 48)]
    convergence_size: u32,
    /// Samples per pixel of the converged references (at least 8 x 64).
    #[arg(long, default_value_t = 1024)]
    reference_spp: u32,
    /// Also write the report as JSON here (rewritten after each section).
    #[arg(long)]
    json: Option<PathBuf>,
    #[command(flatten)]
    gpu: GpuArgs,
}

pub fn run(args: &CheckArgs) -> Result<()> {
    let convergence_options = checked_options(args)?;
    let wanted = |s: Section| args.only.is_empty() || args.only.contains(&s);
    let ctx = gpu_context(&args.gpu)?;
    let mut report = CheckReport {
        device: format!(
            "{} ({}), by fovea {}",
            ctx.info.name,
            ctx.info.driver,
            fovea::build_version()
        ),
        ..CheckReport::default()
    };
    if wanted(Section::Watertight) {
        watertight_section(args, &ctx, &mut report)?;
    }
    if wanted(Section::Scale) {
        scale_section(args, &ctx, &mut report)?;
    }
    if wanted(Section::Furnace) {
        furnace_section(args, &ctx, &mut report)?;
    }
    if wanted(Section::Emission) {
        emission_section(args, &ctx, &mut report)?;
    }
    if wanted(Section::Convergence) {
        convergence_section(args, &ctx, &convergence_options, &mut report)?;
    }
    check_validation(&ctx)?;
    print_verdict(&report)
}

/// Rejects out-of-range options before any GPU work; the convergence study's options.
fn checked_options(args: &CheckArgs) -> Result<ConvergenceOptions> {
    if args.rays == 0 || args.rays > MAX_RAYS {
        bail!("--rays {} is out of range: use 1 to {MAX_RAYS}", args.rays);
    }
    RenderSettings {
        width: args.size,
        height: args.size,
        spp: args.spp,
        ..RenderSettings::default()
    }
    .validate()
    .map_err(anyhow::Error::msg)?;
    let convergence_options = ConvergenceOptions {
        width: args.convergence_size,
        height: args.convergence_size,
        reference_spp: args.reference_spp,
        ..ConvergenceOptions::default()
    };
    convergence_options
        .validate()
        .map_err(anyhow::Error::msg)
        .context("convergence options")?;
    Ok(convergence_options)
}

/// Says how long a section took and rewrites `--json` with the report so far.
fn section_done(
    args: &CheckArgs,
    name: &str,
    report: &CheckReport,
    started: Instant,
) -> Result<()> {
    eprintln!("{name}: done in {:.1} s", started.elapsed().as_secs_f64());
    if let Some(path) = &args.json {
        write_json(path, report)?;
    }
    Ok(())
}

fn watertight_section(
    args: &CheckArgs,
    ctx: &Arc<GpuContext>,
    report: &mut CheckReport,
) -> Result<()> {
    let t = Instant::now();
    eprintln!(
        "watertight: {} rays from inside closed meshes...",
        args.rays
    );
    report.watertight = watertight::run(ctx, args.rays, 1, Traversal::preferred(ctx))?;
    section_done(args, "watertight", report, t)
}

fn scale_section(args: &CheckArgs, ctx: &Arc<GpuContext>, report: &mut CheckReport) -> Result<()> {
    let t = Instant::now();
    eprintln!("scale: a lit plane at scales 1e-3..1e5 and 1e5 from the origin, cornell scaled...");
    let scales = [1e-3, 1e-2, 1e-1, 1.0, 1e1, 1e2, 1e3, 1e4, 1e5];
    report.plane = scale::plane_radiance(ctx, args.size, args.spp, &scales, 1e5)?;
    let cornell = builtin("cornell", 1.0)?;
    report.scaled = scale::scaled_scene(
        ctx,
        &cornell,
        args.size,
        args.spp.div_ceil(4),
        &[1e-3, 1e-2, 1e-1, 1e1, 1e3, 1e5],
    )?;
    section_done(args, "scale", report, t)
}

fn furnace_section(
    args: &CheckArgs,
    ctx: &Arc<GpuContext>,
    report: &mut CheckReport,
) -> Result<()> {
    let t = Instant::now();
    eprintln!("furnace: every material extreme, and glTF's BRDF, in a white furnace...");
    report.furnace = materials::white_furnace(ctx, args.size, args.spp)?;
    report.gltf_furnace = gltf_furnace::gltf_furnace(ctx, args.size, args.spp)?;
    section_done(args, "furnace", report, t)
}

fn emission_section(
    args: &CheckArgs,
    ctx: &Arc<GpuContext>,
    report: &mut CheckReport,
) -> Result<()> {
    let t = Instant::now();
    eprintln!("emission: cornell with its light x1e10, x1e20, x1e28...");
    let cornell = builtin("cornell", 1.0)?;
    report.emission =
        materials::emission_scaling(ctx, &cornell, args.size, args.spp, &[1e10, 1e20, 1e28])?;
    section_done(args, "emission", report, t)
}

/// The convergence study on each scene, its progress every 10%.
fn convergence_section(
    args: &CheckArgs,
    ctx: &Arc<GpuContext>,
    options: &ConvergenceOptions,
    report: &mut CheckReport,
) -> Result<()> {
    for name in &args.convergence_scenes {
        let t = Instant::now();
        eprintln!("convergence: {name}, pt and seed against converged references...");
        let scene = scene::load(name, 1.0)?;
        let mut last_percent = u64::MAX;
        let mut progress = |done: u64, total: u64| {
            let percent = 100 * done / total.max(1);
            if percent / 10 != last_percent / 10 {
                eprintln!("  {percent}%");
                last_percent = percent;
            }
        };
        report
            .convergence
            .push(convergence::measure(ctx, &scene, options, &mut progress)?);
        section_done(args, &format!("convergence on {name}"), report, t)?;
    }
    Ok(())
}

/// Prints the report; fails naming every check that did not pass.
fn print_verdict(report: &CheckReport) -> Result<()> {
    println!("fovea check on {}", report.device);
    for line in report.lines() {
        println!("{line}");
    }
    let failures = report.failures();
    if !failures.is_empty() {
        bail!(
            "{} check(s) failed:\n  {}",
            failures.len(),
            failures.join("\n  ")
        );
    }
    println!("all checks passed");
    Ok(())
}

fn write_json(path: &Path, report: &CheckReport) -> Result<()> {
    let text = serde_json::to_string_pretty(report)?;
    // Written whole to a temporary name and renamed, so a kill never leaves half a file.
    let tmp = path.with_extension("json.partial");
    std::fs::write(&tmp, text)
        .and_then(|()| std::fs::rename(&tmp, path))
        .with_context(|| format!("cannot write the report to '{}'", path.display()))
}
