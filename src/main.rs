//! The `fovea` command line: `render` one frame (mono or stereo, regular or foveated), `bench`
//! the thesis' evaluation, `check` the numerics, `view` in a window, `xr` in a headset, list
//! `scenes`, `tune` the foveation layers. Each command lives in commands/.

mod commands;

use clap::{CommandFactory, FromArgMatches, Parser, Subcommand};

#[derive(Parser)]
#[command(
    name = "fovea",
    version,
    about = "A foveated path tracer for eye-tracked VR headsets"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
    /// Downscale (by halving) every texture of a glTF file wider or taller than N texels,
    /// instead of refusing one larger than the device's largest image.
    #[arg(long, global = true, value_name = "N", value_parser = clap::value_parser!(u32).range(1..))]
    max_texture_size: Option<u32>,
    #[command(flatten)]
    env: commands::EnvArgs,
    /// How next-event estimation picks lights: `power` (local lights by power, each sun or
    /// environment an equal share beside them) or `uniform` (every emitter alike; for
    /// comparison).
    #[arg(long, global = true, value_enum, default_value_t = fovea::scene::LightSelection::Power)]
    light_selection: fovea::scene::LightSelection,
    /// Where the paths' random numbers come from: `zsobol` (Owen-scrambled Sobol in Morton
    /// order: the error is blue noise over the screen) or `independent` (a random stream per
    /// pixel: white-noise error; fovea's first sampler, for comparison). Default: zsobol (a
    /// bench run resumed with --resume: the one it began with).
    #[arg(long, global = true, value_enum)]
    sampler: Option<fovea::render::Sampler>,
}

#[derive(Subcommand)]
enum Command {
    /// Render one frame headless and write it as PNG (+ linear EXR) or EXR.
    Render(Box<commands::render::RenderArgs>),
    /// The thesis' evaluation, unattended: scenes x regular/forward/corner x frames x repeats,
    /// GPU timestamps, error against converged references, CSV/JSON/Markdown/plots/trace.
    Bench(Box<commands::bench::BenchArgs>),
    /// Numerical stress report: watertightness, scale invariance, white furnace, emission,
    /// convergence; prints the counts that must be zero and fails if any check does.
    Check(Box<commands::check::CheckArgs>),
    /// List the built-in scenes with their triangle counts and what they need (or, given
    /// .gltf/.glb files, what those hold and need).
    Scenes(commands::scenes::ScenesArgs),
    /// A desktop window: the mouse is the gaze, live foveation controls, progressive refinement.
    View(Box<commands::view::ViewArgs>),
    /// An OpenXR headset session (SteamVR, Vive Pro Eye): the eye tracker moves each eye's
    /// foveation; --simulated runs it on the built-in simulated headset.
    Xr(Box<commands::xr::XrArgs>),
    /// Search foveation layers for the best perceptual quality (FovVideoVDP JOD) within a GPU
    /// time budget; writes the winner as a foveation TOML and the Pareto front (CSV, plot).
    Tune(Box<commands::tune::TuneArgs>),
    /// Is fovea real-time on this device? Pass times of regular and foveated frames per scene,
    /// the largest fovea spp that fits 90 and 120 Hz, headset sessions with 1-3 frames in
    /// flight; CSV, JSON and report.md (tools/gpu-bundle.sh packs it for a GPU machine).
    GpuReport(Box<commands::gpu_report::GpuReportArgs>),
}

fn main() {
    tracing_subscriber::fmt()
        .with_env_filter(
            tracing_subscriber::EnvFilter::try_from_default_env().unwrap_or_else(|_| "warn".into()),
        )
        .with_writer(std::io::stderr)
        .init();
    let matches = Cli::command().get_matches();
    let cli = Cli::from_arg_matches(&matches).unwrap_or_else(|e| e.exit());
    if let Some(n) = cli.max_texture_size {
        fovea::scene::texture_size::set_max_texture_size(n);
    }
    fovea::scene::light_choice::set_light_selection(cli.light_selection);
    if let Some(sampler) = cli.sampler {
        fovea::render::Sampler::choose_for_process(sampler);
    }
    if let Err(e) = cli.env.apply() {
        eprintln!("error: {e}");
        std::process::exit(1);
    }
    let result = match &cli.command {
        Command::Render(args) => commands::render::run(args),
        Command::Bench(args) => {
            let sub = matches
                .subcommand_matches("bench")
                .expect("the bench subcommand was parsed");
            commands::bench::run(args, sub)
        }
        Command::Check(args) => commands::check::run(args),
        Command::Scenes(args) => commands::scenes::run(args),
        Command::View(args) => commands::view::run(args),
        Command::Xr(args) => commands::xr::run(args),
        Command::Tune(args) => commands::tune::run(args),
        Command::GpuReport(args) => commands::gpu_report::run(args),
    };
    if let Err(e) = result {
        // Output piped into a reader that stopped (`fovea scenes | head`) is not an error.
        let closed_pipe = (e.downcast_ref::<std::io::Error>())
            .is_some_and(|io| io.kind() == std::io::ErrorKind::BrokenPipe);
        if closed_pipe {
            return;
        }
        eprintln!("error: {}", commands::error_text(&e));
        std::process::exit(1);
    }
}
