//! `fovea tune`: picks the foveation layers with the best perceptual quality (FovVideoVDP)
//! within a GPU time budget, and writes them as a foveation TOML beside the Pareto front.

use super::{check_validation, gpu_context, DisplayArgs, GpuArgs};
use anyhow::Result;
use clap::{Args, ValueEnum};
use fovea::foveation::{DisplayProfile, FoveationConfig};
use fovea::render::{FovChoice, Integrator, Traversal};
use fovea::tune::files::TuneFiles;
use fovea::tune::space::Space;
use fovea::tune::{self, Budget, Cost, Objective, TuneOptions, TunePlan};
use std::path::PathBuf;

/// Which grid the search draws configs from.
#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum SpaceChoice {
    /// Up to 3 layers and a background: radii 3-40 deg, spacings 1-6, 1-16 spp, 0-3 denoiser
    /// iterations, lattice filters 0.5-2 minimum angles of resolution; baselines at 1, 2 and
    /// 4 spp, regular ones also with uniform lattice filters 1 and 2 pixels wide.
    Standard,
    /// One layer and a background, radii 6/15 deg, spacings 1/2/4, 1-2 spp, no denoiser, no
    /// lattice filter.
    Small,
}

/// `--cost`: see [`Cost`].
#[derive(Clone, Copy, ValueEnum)]
pub enum CostChoice {
    GpuTime,
    Samples,
}

#[derive(Args)]
pub struct TuneArgs {
    /// Scene(s) to judge configs on, comma-separated (JOD and GPU time are averaged).
    #[arg(long, value_delimiter = ',', required = true)]
    pub scene: Vec<String>,
    /// The headset: its eye image's size and field of view (unless --width, --height or --fov
    /// say otherwise) and its display's photometry, which FovVideoVDP judges on.
    #[arg(long = "display", value_name = "HEADSET", value_enum, default_value_t = DisplayProfile::ViveProEye)]
    pub display_profile: DisplayProfile,
    /// What a config's JOD is: `still`, the first frame after the eye lands at each gaze with
    /// no history; or `motion`, a video of the head turning and the eye saccading with the
    /// history on (every config, the uniform baselines too), the first-frame scores kept
    /// beside it.
    #[arg(long, value_enum, default_value_t = Objective::Still)]
    pub objective: Objective,
    /// One eye's field of view. Default: the --display's.
    #[arg(long, value_enum)]
    pub fov: Option<FovChoice>,
    /// One eye's image size. Default: the --display's (1440×1600 for the Vive Pro Eye).
    #[arg(long)]
    pub width: Option<u32>,
    #[arg(long)]
    pub height: Option<u32>,
    /// Judge the central WIDTHxHEIGHT pixels of the --display's eye image, at its pixel
    /// density over the part of its field of view they see: a high-density headset measured
    /// where its whole panel would take hours (foveation saves most in the periphery left out).
    #[arg(long, value_name = "WIDTHxHEIGHT", value_parser = super::parse_size, conflicts_with_all = ["width", "height", "fov"])]
    pub window: Option<[u32; 2]>,
    /// GPU milliseconds one eye's frame may take (median of the timed frames).
    #[arg(
        long,
        required_unless_present = "budget_of_regular",
        conflicts_with = "budget_of_regular"
    )]
    pub budget_ms: Option<f64>,
    /// The budget is whatever regular rendering at this spp takes, measured in the same run
    /// (robust to a machine's speed).
    #[arg(long, value_name = "SPP")]
    pub budget_of_regular: Option<u32>,
    /// What a config's cost is: `gpu-time` (its timestamps; what the headset pays), or
    /// `samples` (camera paths traced, over regular rendering's: the same on any machine and
    /// under any load, for reproducible searches; needs --budget-of-regular). GPU time is
    /// recorded either way.
    #[arg(long, value_enum, default_value_t = CostChoice::GpuTime)]
    pub cost: CostChoice,
    /// Where the chosen config goes; FILE-candidates.csv, FILE-front.csv, FILE-front.svg/.png
    /// and FILE-tune.json are written beside it. Running again with the same flags resumes.
    #[arg(long, value_name = "FILE.toml")]
    pub out: PathBuf,
    /// Configs to measure, the baselines (regular and the thesis' layers at each spp) included.
    #[arg(long, default_value_t = 48)]
    pub candidates: u32,
    #[arg(long, value_enum, default_value_t = SpaceChoice::Standard)]
    pub space: SpaceChoice,
    /// Foveation TOML(s) measured right after the baselines, comma-separated: your own
    /// starting points, or configs to compare without a search (--candidates = baselines +
    /// these).
    #[arg(long, value_delimiter = ',', value_name = "FILE.toml")]
    pub include: Vec<PathBuf>,
    /// Seeds the search: the same seed draws the same configs.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Which samples the judged and timed frames draw (not the reference's): rerun with 2,
    /// 3, … to see how much each config's JOD moves with its noise alone.
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..65536))]
    pub render_seed: u32,
    /// Timed frames per gaze after the judged one.
    #[arg(long, default_value_t = 3)]
    pub frames: u32,
    /// `--objective motion`: frames rendered before the scored ones, from an empty history.
    /// The scored frames are the ones before the first saccade that starts after them.
    #[arg(long, value_name = "FRAMES", default_value_t = fovea::tune::motion::WARM_UP)]
    pub warm_up: u32,
    /// Samples per pixel of the converged reference.
    #[arg(long, default_value_t = 256)]
    pub reference_spp: u32,
    #[arg(long, value_enum, default_value_t = Integrator::Pt)]
    pub integrator: Integrator,
    #[arg(long, default_value_t = 8)]
    pub max_bounces: u32,
    /// Where converged references are cached (default: beside --out, in references/).
    #[arg(long)]
    pub reference_cache: Option<PathBuf>,
    #[command(flatten)]
    pub gpu: GpuArgs,
    #[command(flatten)]
    pub display: DisplayArgs,
}

impl TuneArgs {
    /// The plan these flags ask for, on a device whose preferred traversal is `traversal`.
    fn plan(&self, traversal: Traversal) -> Result<TunePlan> {
        let space = match self.space {
            SpaceChoice::Standard => Space::standard(),
            SpaceChoice::Small => Space::small(),
        };
        let (panel_width, panel_height) = self.display_profile.eye_size();
        let [width, height] = (self.window).unwrap_or([
            (self.width).unwrap_or(panel_width),
            (self.height).unwrap_or(panel_height),
        ]);
        Ok(TunePlan {
            scenes: self.scene.clone(),
            width,
            height,
            fov: (self.fov).unwrap_or(self.display_profile.fov()),
            window_of: self.window.map(|_| [panel_width, panel_height]),
            profile: self.display_profile,
            objective: self.objective,
            budget: match (self.budget_ms, self.budget_of_regular) {
                (_, Some(spp)) => Budget::Regular(spp),
                (Some(ms), None) => Budget::Ms(ms),
                (None, None) => unreachable!("clap requires one of the two"),
            },
            cost: match self.cost {
                CostChoice::GpuTime => Cost::GpuTime,
                CostChoice::Samples => Cost::Samples,
            },
            candidates: self.candidates,
            seed: self.seed,
            frames: self.frames,
            reference_spp: self.reference_spp,
            integrator: self.integrator,
            max_bounces: self.max_bounces,
            traversal,
            space,
            include: (self.include.iter())
                .map(|p| FoveationConfig::load(p))
                .collect::<Result<_, _>>()?,
            display: self.display.choice(),
            environment: fovea::scene::env_choice::chosen().cloned(),
            sampler: fovea::render::Sampler::chosen(),
            motion_warm_up: self.warm_up,
            render_seed: self.render_seed,
        })
    }
}

pub fn run(args: &TuneArgs) -> Result<()> {
    let ctx = gpu_context(&args.gpu)?;
    let plan = args.plan(Traversal::preferred(&ctx))?;
    let files = TuneFiles::new(&args.out);
    let cache = args.reference_cache.clone().unwrap_or_else(|| {
        (args.out.parent())
            .filter(|p| !p.as_os_str().is_empty())
            .map_or_else(|| PathBuf::from("references"), |p| p.join("references"))
    });
    println!(
        "fovea tune: {} configs on {} at {}x{} per eye ({} photometry){}, {} on {}",
        plan.candidates,
        plan.scenes.join(", "),
        plan.width,
        plan.height,
        plan.profile.name(),
        plan.window_phrase(),
        match plan.budget {
            Budget::Ms(ms) => format!("budget {ms} ms"),
            Budget::Regular(spp) => format!("budget = regular {spp} spp's time"),
        },
        ctx.info.name
    );
    let outcome = tune::run(
        &ctx,
        &plan,
        &files,
        &TuneOptions {
            reference_cache: cache,
            command_line: std::env::args().collect::<Vec<_>>().join(" "),
        },
    )?;
    check_validation(&ctx)?;
    let c = &outcome.chosen;
    let first_frames = match plan.objective {
        Objective::Still => "",
        Objective::Motion => "in motion with history; first frames: ",
    };
    println!(
        "chosen: {} — JOD {:.3} ({first_frames}forward {:.3}, off-axis {:.3}, corner {:.3}) at {:.2} ms per eye (budget {:.2} ms)",
        c.config, c.jod, c.jod_forward, c.jod_off_axis, c.jod_corner, c.cost_ms, outcome.budget_ms
    );
    println!(
        "wrote {} (the front: {} of {} configs in {}, plot {}.svg/.png; every config in {})",
        files.config.display(),
        outcome.front.len(),
        outcome.rows.len(),
        files.front.display(),
        files.plot.display(),
        files.candidates.display()
    );
    Ok(())
}
