//! `fovea bench`: the thesis' evaluation, unattended. Builds the plan from a preset and the
//! flags given (or from the directory being resumed), runs it, and prints where the results are.

use super::{check_validation, gpu_context, DisplayArgs, GpuArgs};
use anyhow::{Context, Result};
use clap::Args;
use fovea::bench::motion::{MotionChoice, Sequence};
use fovea::bench::summary::utc_stamp;
use fovea::bench::{self, BenchPlan, RunOptions};
use fovea::foveation::{DisplayProfile, FoveationConfig, GazeTrace};
use fovea::render::{FovChoice, Integrator, Traversal};
use std::path::PathBuf;

/// Flags that set the plan; none may be given with --resume.
const PLAN_FLAGS: [&str; 20] = [
    "quick",
    "display_profile",
    "scenes",
    "frames",
    "repeats",
    "regular_repeats",
    "width",
    "height",
    "fov",
    "spp",
    "foveation",
    "integrator",
    "max_bounces",
    "seed",
    "reference_spp",
    "sweep_spp",
    "sweep_frames",
    "gaze_trace",
    "traversal",
    "motion",
];

#[derive(Args)]
pub struct BenchArgs {
    /// A small preset that finishes in a few minutes on lavapipe (360x400 per eye, 10 frames,
    /// 2 repeats, 256-spp references). Other flags still override it.
    #[arg(long)]
    pub quick: bool,
    /// Scenes, comma-separated: built-in names or .gltf/.glb files. Default: the thesis' five.
    #[arg(long, value_delimiter = ',')]
    pub scenes: Option<Vec<String>>,
    /// Measured frames per repeat (default 100).
    #[arg(long)]
    pub frames: Option<u32>,
    /// Repeats of each foveated mode (default 10).
    #[arg(long)]
    pub repeats: Option<u32>,
    /// Repeats of regular rendering (default 1).
    #[arg(long)]
    pub regular_repeats: Option<u32>,
    /// The headset: its eye image's size (a quarter of it each way with --quick) and field of
    /// view, unless --width, --height or --fov say otherwise, and its display's photometry
    /// for FovVideoVDP (default vive-pro-eye).
    #[arg(long = "display", value_name = "HEADSET", value_enum)]
    pub display_profile: Option<DisplayProfile>,
    /// Width of one eye's image (default 1440, the Vive Pro Eye's).
    #[arg(long)]
    pub width: Option<u32>,
    /// Height of one eye's image (default 1600).
    #[arg(long)]
    pub height: Option<u32>,
    /// Field of view of the eyes (default vive-pro-eye).
    #[arg(long, value_enum)]
    pub fov: Option<FovChoice>,
    /// Samples per target pixel, regular and foveated (default 4).
    #[arg(long)]
    pub spp: Option<u32>,
    /// Foveation layers: thesis (default) or a TOML file (see assets/foveation/).
    #[arg(long)]
    pub foveation: Option<String>,
    #[arg(long, value_enum)]
    pub integrator: Option<Integrator>,
    #[arg(long)]
    pub max_bounces: Option<u32>,
    #[arg(long)]
    pub seed: Option<u32>,
    /// Samples per pixel of the converged reference images are compared with (default 1024).
    #[arg(long)]
    pub reference_spp: Option<u32>,
    /// Samples per pixel of the run-time-against-error sweep (default 1,2,4,8,16).
    #[arg(long, value_delimiter = ',')]
    pub sweep_spp: Option<Vec<u32>>,
    /// Frames timed per sweep point; the median is used (default 3).
    #[arg(long)]
    pub sweep_frames: Option<u32>,
    /// Adds a fourth mode, `trace`, whose gaze follows this recorded trace (CSV, as
    /// `--record-gaze` writes): frame k of each repeat takes row k.
    #[arg(long, value_name = "FILE")]
    pub gaze_trace: Option<PathBuf>,
    /// Measure sequences instead of still frames: the head turns and the eye fixates and
    /// saccades (head-and-saccades, the default script) or both stay still (still); each scene
    /// is rendered with the temporal history off, on, and off at twice the spp, every frame
    /// against its own reference, per eccentricity band, with flicker. --frames is the
    /// sequence's length at 90 Hz (default 100; with --quick 45 frames at 180x200 per eye
    /// against 128-spp references).
    #[arg(long, value_enum, num_args = 0..=1, default_missing_value = "head-and-saccades", value_name = "SCRIPT")]
    pub motion: Option<MotionChoice>,
    /// Directory under which each run gets its own bench-results/<UTC time>/.
    #[arg(long, default_value = "bench-results")]
    pub out: PathBuf,
    /// Measure into exactly this directory instead of a new time-stamped one.
    #[arg(long, conflicts_with = "resume")]
    pub dir: Option<PathBuf>,
    /// Complete the interrupted run in DIR with the parameters it was started with.
    #[arg(long, value_name = "DIR")]
    pub resume: Option<PathBuf>,
    /// Where converged references are cached (default: <out>/references).
    #[arg(long)]
    pub reference_cache: Option<PathBuf>,
    /// Abort the process after this many measured frames, as a kill would (for testing
    /// --resume).
    #[arg(long, hide = true)]
    pub abort_after_frames: Option<u64>,
    #[command(flatten)]
    pub gpu: GpuArgs,
    #[command(flatten)]
    pub display: DisplayArgs,
}

impl BenchArgs {
    fn plan(&self) -> Result<BenchPlan> {
        let mut plan = match self.quick {
            true => BenchPlan::quick(),
            false => BenchPlan::thesis(),
        };
        if let Some(profile) = self.display_profile {
            let (w, h) = profile.eye_size();
            let scale = if self.quick { 4 } else { 1 };
            (plan.profile, plan.fov) = (profile, profile.fov());
            (plan.width, plan.height) = (w / scale, h / scale);
        }
        macro_rules! set {
            ($($field:ident => $target:ident),*) => {
                $(if let Some(v) = &self.$field { plan.$target = v.clone(); })*
            };
        }
        set!(scenes => scenes, frames => frames, repeats => repeats_foveated,
             regular_repeats => repeats_regular, width => width, height => height, fov => fov,
             spp => spp, integrator => integrator, max_bounces => max_bounces, seed => seed,
             reference_spp => reference_spp, sweep_spp => sweep_spp, sweep_frames => sweep_frames);
        plan.display = self.display.choice();
        plan.environment = fovea::scene::env_choice::chosen().cloned();
        plan.sampler = fovea::render::Sampler::chosen();
        if let Some(f) = &self.foveation {
            plan.foveation = FoveationConfig::from_arg(f)?.ok_or_else(|| {
                anyhow::anyhow!(
                    "--foveation off leaves nothing to compare; the bench needs a layer config \
                     (thesis or a TOML file)"
                )
            })?;
        }
        if let Some(choice) = self.motion {
            plan.motion = Some(choice.script());
            if self.quick {
                // A reference per frame makes a sequence costly on lavapipe: half a second
                // (two fixations and the saccade between them) at 180x200 with 128-spp
                // references, about 2 minutes a scene once, seconds once they are cached.
                plan.frames = self.frames.unwrap_or(45);
                plan.width = self.width.unwrap_or(180);
                plan.height = self.height.unwrap_or(200);
                plan.reference_spp = self.reference_spp.unwrap_or(128);
            }
        }
        if let Some(path) = &self.gaze_trace {
            // Checked now, before any GPU work; stored absolute so --resume finds it anywhere.
            GazeTrace::read(path)?;
            plan.gaze_trace = Some(
                std::fs::canonicalize(path)
                    .with_context(|| format!("gaze trace {}", path.display()))?,
            );
        }
        plan.validate().map_err(anyhow::Error::msg)?;
        Ok(plan)
    }
}

pub fn run(args: &BenchArgs, matches: &clap::ArgMatches) -> Result<()> {
    let (mut plan, dir) = match &args.resume {
        Some(dir) => {
            let given: Vec<String> = PLAN_FLAGS
                .iter()
                .filter(|f| matches.value_source(f) == Some(clap::parser::ValueSource::CommandLine))
                .map(|f| match *f {
                    "display_profile" => "--display".to_string(), // the flag's own name
                    f => format!("--{}", f.replace('_', "-")),
                })
                .collect();
            if !given.is_empty() {
                anyhow::bail!(
                    "--resume takes every parameter from {}/plan.json; drop {}",
                    dir.display(),
                    given.join(", ")
                );
            }
            let plan = bench::read_plan(dir)?;
            fovea::scene::env_choice::adopt(plan.environment.as_ref())
                .map_err(anyhow::Error::msg)?;
            fovea::render::Sampler::adopt(plan.sampler).map_err(anyhow::Error::msg)?;
            (plan, dir.clone())
        }
        None => {
            let dir = args
                .dir
                .clone()
                .unwrap_or_else(|| args.out.join(utc_stamp()));
            (args.plan()?, dir)
        }
    };
    let ctx = gpu_context(&args.gpu)?;
    if args.resume.is_none() {
        plan.traversal = Traversal::preferred(&ctx);
    }
    match plan.motion {
        Some(_) => println!(
            "fovea bench --motion: {} scene(s) × {} sequences ({}) of {} frames on {} ({} traversal) into {}",
            plan.scenes.len(),
            Sequence::all(plan.spp).len(),
            Sequence::all(plan.spp).map(|s| s.name()).join(", "),
            plan.frames,
            ctx.info.name,
            plan.traversal.name(),
            dir.display()
        ),
        None => println!(
            "fovea bench: {} scene(s), {} frame rows and {} sweep points on {} ({} traversal) into {}",
            plan.scenes.len(),
            plan.expected_frame_rows(),
            plan.scenes.len() * plan.sweep().len() * 3,
            ctx.info.name,
            plan.traversal.name(),
            dir.display()
        ),
    }
    let options = RunOptions {
        reference_cache: args
            .reference_cache
            .clone()
            .unwrap_or_else(|| args.out.join("references")),
        abort_after_frames: args.abort_after_frames,
        command_line: std::env::args().collect::<Vec<_>>().join(" "),
    };
    bench::run(&ctx, &plan, &dir, &options)
        .with_context(|| format!("bench run in {} (finish it with --resume)", dir.display()))?;
    check_validation(&ctx)?;
    match plan.motion {
        Some(_) => print_motion(&dir),
        None => print_impacts(&dir),
    }
}

/// Per scene and sequence of the finished motion run: GPU ms, whole-image and peripheral
/// (20°+) error and flicker, read back from its summary.
fn print_motion(dir: &std::path::Path) -> Result<()> {
    let text = std::fs::read_to_string(dir.join("summary.json"))?;
    let summary: serde_json::Value = serde_json::from_str(&text)?;
    println!(
        "{:<14} {:<20} {:>9} {:>12} {:>12} {:>12} {:>12}",
        "scene", "sequence", "GPU ms", "relMSE", "relMSE 20+", "flicker", "flicker 20+"
    );
    for scene in summary["scenes"].as_array().into_iter().flatten() {
        for seq in scene["sequences"].as_array().into_iter().flatten() {
            let region = |name: &str, field: &str| {
                seq["regions"]
                    .as_array()
                    .into_iter()
                    .flatten()
                    .find(|r| r["region"] == name)
                    .and_then(|r| r[field].as_f64())
                    .map_or("-".to_string(), |v| format!("{v:.3e}"))
            };
            println!(
                "{:<14} {:<20} {:>9.2} {:>12} {:>12} {:>12} {:>12}",
                scene["scene"].as_str().unwrap_or("?"),
                seq["sequence"].as_str().unwrap_or("?"),
                seq["gpu_ms"].as_f64().unwrap_or(f64::NAN),
                region("whole", "rel_mse"),
                region("20+", "rel_mse"),
                region("whole", "flicker"),
                region("20+", "flicker"),
            );
        }
    }
    println!("report: {}", dir.join("report.md").display());
    Ok(())
}

/// The impact factors of the finished run, read back from its rows.
fn print_impacts(dir: &std::path::Path) -> Result<()> {
    let text = std::fs::read_to_string(dir.join("summary.json"))?;
    let summary: serde_json::Value = serde_json::from_str(&text)?;
    let traced = !summary["parameters"]["gaze_trace"].is_null();
    println!(
        "{:<14} {:>18} {:>18}{}",
        "scene",
        "impact forward",
        "impact corner",
        if traced {
            format!(" {:>18}", "impact trace")
        } else {
            String::new()
        }
    );
    for scene in summary["scenes"].as_array().into_iter().flatten() {
        let impact = |i: usize| {
            scene["modes"][i]["impact"]["factor"]
                .as_f64()
                .map_or("-".to_string(), |f| format!("{f:.2}"))
        };
        println!(
            "{:<14} {:>18} {:>18}{}",
            scene["scene"].as_str().unwrap_or("?"),
            impact(1),
            impact(2),
            if traced {
                format!(" {:>18}", impact(3))
            } else {
                String::new()
            }
        );
    }
    println!("report: {}", dir.join("report.md").display());
    Ok(())
}
