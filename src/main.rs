//! The `fovea` command line: `render` one frame, list `scenes`.

use anyhow::{bail, Context, Result};
use clap::{Args, Parser, Subcommand};
use fovea::gpu::{GpuContext, GpuOptions};
use fovea::render::{output, Integrator, RenderSettings, Renderer};
use fovea::scene::{self, builtin::BUILTIN_SCENES, SceneFeatures};
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;

#[derive(Parser)]
#[command(
    name = "fovea",
    version,
    about = "A foveated path tracer for eye-tracked VR headsets"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Render one frame headless and write it as PNG (+ linear EXR) or EXR.
    Render(RenderArgs),
    /// List the built-in scenes with their triangle counts and what they need.
    Scenes,
}

#[derive(Args)]
struct GpuArgs {
    /// Use the Vulkan device whose name contains this text (e.g. "llvmpipe").
    #[arg(long)]
    device: Option<String>,
    /// Enable the Vulkan validation layer; any message it reports makes the command fail.
    #[arg(long)]
    validate: bool,
}

#[derive(Args)]
struct RenderArgs {
    /// A built-in scene (see `fovea scenes`) or a .gltf/.glb file.
    #[arg(long, default_value = "cornell")]
    scene: String,
    #[arg(long, default_value_t = 512)]
    width: u32,
    #[arg(long, default_value_t = 512)]
    height: u32,
    /// Samples (paths) per pixel.
    #[arg(long, default_value_t = 16)]
    spp: u32,
    /// Random seed: the same seed gives a bit-identical image.
    #[arg(long, default_value_t = 1)]
    seed: u32,
    #[arg(long, value_enum, default_value_t = Integrator::Pt)]
    integrator: Integrator,
    /// Maximum number of bounces after the camera ray's hit.
    #[arg(long, default_value_t = 8)]
    max_bounces: u32,
    /// Output image: .png (an .exr with linear radiance is written beside it) or .exr.
    #[arg(long, default_value = "fovea.png")]
    out: PathBuf,
    /// Instead of one image, report Msamples/s for every built-in scene at this size and spp.
    #[arg(long)]
    bench: bool,
    #[command(flatten)]
    gpu: GpuArgs,
}

fn gpu_context(args: &GpuArgs) -> Result<Arc<GpuContext>> {
    let mut options = GpuOptions::from_env();
    if args.device.is_some() {
        options.device = args.device.clone();
    }
    options.validation |= args.validate;
    Ok(Arc::new(GpuContext::new(&options)?))
}

fn check_validation(ctx: &GpuContext) -> Result<()> {
    let messages = ctx.take_validation_messages();
    if !messages.is_empty() {
        bail!(
            "the Vulkan validation layer reported {} message(s):\n{}",
            messages.len(),
            messages.join("\n")
        );
    }
    Ok(())
}

fn render(args: &RenderArgs) -> Result<()> {
    let settings = RenderSettings {
        width: args.width,
        height: args.height,
        spp: args.spp,
        seed: args.seed,
        integrator: args.integrator,
        max_bounces: args.max_bounces,
    };
    settings.validate().map_err(anyhow::Error::msg)?;
    let ctx = gpu_context(&args.gpu)?;
    println!(
        "device: {} ({}; {})",
        ctx.info.name, ctx.info.kind, ctx.info.driver
    );
    if args.bench {
        return bench(&ctx, &settings);
    }
    let aspect = settings.width as f32 / settings.height as f32;
    let scene = scene::load(&args.scene, aspect)?;
    let started = Instant::now();
    let mut renderer = Renderer::new(&ctx, &scene)?;
    let setup = started.elapsed();
    let frame = renderer.render(&scene.camera, &settings)?;
    let s = &frame.stats;
    println!(
        "scene {}: {} triangles, {} boxes, {} spheres ({}); BVH build + upload {:.1} ms",
        scene.name,
        scene.triangle_count(),
        scene.boxes.len(),
        scene.spheres.len(),
        renderer.features().describe(),
        setup.as_secs_f64() * 1e3
    );
    for (pass, ms) in &s.pass_ms {
        println!("gpu pass {pass}: {ms:.2} ms");
    }
    println!(
        "{}x{} at {} spp, {:?}: {:.2} Msamples/s, {} rays ({:.2} Mrays/s)",
        settings.width,
        settings.height,
        settings.spp,
        settings.integrator,
        s.msamples_per_s(),
        s.rays,
        s.rays as f64 / (s.gpu_ms() * 1e3).max(1e-9)
    );
    println!(
        "non-finite samples dropped: {}, BVH stack overflows: {}",
        s.nonfinite_samples, s.stack_overflows
    );
    let written = output::write_frame(&frame, &args.out)?;
    for path in written {
        println!("wrote {}", path.display());
    }
    drop(renderer);
    check_validation(&ctx)?;
    if s.stack_overflows > 0 {
        bail!(
            "{} BVH traversals overflowed their stack: the image is missing geometry",
            s.stack_overflows
        );
    }
    Ok(())
}

/// Msamples/s for every built-in scene on the current device, at the given settings.
fn bench(ctx: &Arc<GpuContext>, settings: &RenderSettings) -> Result<()> {
    println!(
        "{:<12} {:>10} {:>10} {:>12} {:>12}",
        "scene", "gpu ms", "Msamples/s", "Mrays/s", "rays/path"
    );
    let aspect = settings.width as f32 / settings.height as f32;
    for (name, _) in BUILTIN_SCENES {
        let scene = scene::builtin::builtin(name, aspect)?;
        let mut renderer = Renderer::new(ctx, &scene)?;
        // Drivers may finish compiling a pipeline lazily at its first dispatch: a tiny warm-up
        // frame keeps any such cost out of the measurement.
        let warm_up = RenderSettings {
            width: 8,
            height: 8,
            spp: 1,
            ..*settings
        };
        renderer
            .render(&scene.camera, &warm_up)
            .with_context(|| format!("warming up {name}"))?;
        let frame = renderer
            .render(&scene.camera, settings)
            .with_context(|| format!("rendering {name}"))?;
        let s = &frame.stats;
        println!(
            "{:<12} {:>10.1} {:>10.2} {:>12.2} {:>12.2}",
            name,
            s.gpu_ms(),
            s.msamples_per_s(),
            s.rays as f64 / (s.gpu_ms() * 1e3).max(1e-9),
            s.rays as f64 / s.paths.max(1) as f64
        );
    }
    check_validation(ctx)
}

fn scenes() -> Result<()> {
    println!(
        "{:<12} {:>9}  {:<40} description",
        "name", "triangles", "needs"
    );
    for (name, description) in BUILTIN_SCENES {
        let scene = scene::builtin::builtin(name, 1.0)?;
        let features = SceneFeatures::of(&scene);
        println!(
            "{:<12} {:>9}  {:<40} {}",
            name,
            scene.triangle_count(),
            features.describe(),
            description
        );
    }
    Ok(())
}

fn main() {
    tracing_subscriber::fmt()
        .with_env_filter(
            tracing_subscriber::EnvFilter::try_from_default_env().unwrap_or_else(|_| "warn".into()),
        )
        .with_writer(std::io::stderr)
        .init();
    let cli = Cli::parse();
    let result = match &cli.command {
        Command::Render(args) => render(args),
        Command::Scenes => scenes(),
    };
    if let Err(e) = result {
        eprintln!("error: {e:#}");
        std::process::exit(1);
    }
}
