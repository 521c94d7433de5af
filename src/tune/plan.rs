//! What a `fovea tune` run searches and measures, as data: written next to its results
//! (`<out>-tune.json`) so that an interrupted run resumes only with the same plan.

use super::space::Space;
use crate::foveation::{Gaze, ImageGeometry};
use crate::render::display::DisplayChoice;
use crate::render::{FovChoice, Integrator, Traversal};
use crate::scene::env_choice::EnvChoice;
use serde::{Deserialize, Serialize};
use std::path::PathBuf;

/// The GPU time a config may take.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Budget {
    /// Milliseconds of one eye's frame.
    Ms(f64),
    /// Whatever regular rendering at this spp measures in the same run.
    Regular(u32),
}

/// What a config's cost against the budget is measured in.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Cost {
    /// GPU time from the frames' timestamps: what the headset pays.
    #[default]
    GpuTime,
    /// Camera paths traced per frame, as the GPU counts them, over regular rendering's: the
    /// same on every machine and under any load, so a search (a test's, or one to compare
    /// across machines) decides the same. It leaves out what costs per pixel rather than per
    /// path (resolve, history, denoiser); GPU time is still measured and recorded.
    Samples,
}

/// `--objective`: what a config's JOD is.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "kebab-case")]
pub enum Objective {
    /// The first frame after the eye lands at each gaze, no history (the worst case).
    #[default]
    Still,
    /// A video of the head turning and the eye saccading, history on (tune/motion.rs); the
    /// first-frame scores are kept beside it.
    Motion,
}

/// Where the eye looks while a config is judged: the three positions.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum TuneGaze {
    /// The view axis.
    Forward,
    /// 15° right of and 10° below the view axis: a typical look away from the centre.
    OffAxis,
    /// The top-left pixel (the thesis' corner gaze; the lens hides it on a headset).
    Corner,
}

impl TuneGaze {
    pub const ALL: [TuneGaze; 3] = [TuneGaze::Forward, TuneGaze::OffAxis, TuneGaze::Corner];

    pub fn name(self) -> &'static str {
        match self {
            TuneGaze::Forward => "forward",
            TuneGaze::OffAxis => "off-axis",
            TuneGaze::Corner => "corner",
        }
    }

    /// The gaze on `image`.
    pub fn gaze(self, image: &ImageGeometry) -> Gaze {
        match self {
            TuneGaze::Forward => Gaze::Forward,
            TuneGaze::Corner => Gaze::Corner,
            TuneGaze::OffAxis => {
                let [x, y] =
                    image.pixel_of([15f64.to_radians().tan(), -(10f64.to_radians().tan())]);
                Gaze::Pixel(x, y)
            }
        }
    }
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TunePlan {
    /// Scenes every config is judged on: JOD is the mean over scenes and gazes, GPU time the
    /// mean of the scenes' medians.
    pub scenes: Vec<String>,
    /// One eye's image size and field of view.
    pub width: u32,
    pub height: u32,
    pub fov: FovChoice,
    /// `--display`: the headset whose photometry FovVideoVDP judges on. Absent from older
    /// plans: the Vive Pro Eye.
    #[serde(default)]
    pub profile: crate::foveation::DisplayProfile,
    pub budget: Budget,
    /// What the budget is compared with.
    #[serde(default)]
    pub cost: Cost,
    /// Configs measured, the baselines included.
    pub candidates: u32,
    /// Seeds the search (which configs are drawn and mutated).
    pub seed: u64,
    /// Timed frames per gaze after the judged one (their median is the config's time).
    pub frames: u32,
    pub reference_spp: u32,
    pub integrator: Integrator,
    pub max_bounces: u32,
    pub traversal: Traversal,
    pub space: Space,
    /// Configs measured right after the baselines (`--include`): the user's own, or ones to
    /// compare in a run with no search (`--candidates` = baselines + these).
    #[serde(default)]
    pub include: Vec<crate::foveation::FoveationConfig>,
    /// `--exposure` and `--tonemap`: what FovVideoVDP is shown of each scene.
    #[serde(default, skip_serializing_if = "DisplayChoice::is_default")]
    pub display: DisplayChoice,
    /// `--env` and its options. Absent from the plan without one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub environment: Option<EnvChoice>,
    /// `--objective`. Absent from older plans: still.
    #[serde(default)]
    pub objective: Objective,
    /// `--objective motion`: frames rendered before the scored ones (tune/motion.rs's
    /// WARM_UP). Plans written before the field rendered 8.
    #[serde(default = "crate::tune::motion::warm_up_before_the_field")]
    pub motion_warm_up: u32,
    /// `--sampler`. Plans written before the flag ran with the independent sampler.
    #[serde(default = "crate::render::Sampler::before_the_flag")]
    pub sampler: crate::render::Sampler,
}

impl TunePlan {
    /// Rejects plans that cannot run, saying which flag to change.
    pub fn validate(&self) -> Result<(), String> {
        if self.scenes.is_empty() {
            return Err(
                "no scene to tune on; give --scene NAME (or several, comma-separated)".into(),
            );
        }
        if self.width < 16 || self.height < 16 {
            return Err(format!(
                "{}x{} is too small to judge foveation; give --width and --height of at least 16",
                self.width, self.height
            ));
        }
        if self.frames == 0 || self.reference_spp == 0 {
            return Err("--frames and --reference-spp must be at least 1".into());
        }
        let largest = self.space.spp.iter().copied().max().unwrap_or(1);
        if self.reference_spp < 8 * largest {
            return Err(format!(
                "--reference-spp {} is not converged enough to judge configs of up to {largest} \
                 spp; give at least {}",
                self.reference_spp,
                8 * largest
            ));
        }
        match self.budget {
            Budget::Ms(ms) if !(ms.is_finite() && ms > 0.0) => {
                return Err(format!(
                    "--budget-ms {ms} must be a positive number of milliseconds"
                ))
            }
            Budget::Ms(_) if self.cost == Cost::Samples => {
                return Err(
                    "--cost samples counts traced paths, which have no milliseconds: \
                     give --budget-of-regular SPP with it, or --cost gpu-time"
                        .into(),
                )
            }
            Budget::Regular(spp) if !self.space.baseline_spp.contains(&spp) => {
                return Err(format!(
                    "--budget-of-regular {spp}: the search measures regular rendering at {:?} \
                     spp only; give one of those",
                    self.space.baseline_spp
                ))
            }
            _ => {}
        }
        let baselines = self.space.baselines().len() as u32;
        let first = baselines + self.include.len() as u32;
        if self.candidates < first {
            return Err(format!(
                "--candidates {} is fewer than the {baselines} baselines every search measures \
                 (regular, the thesis' layers and full-resolution foveae at each spp) and the {} \
                 --include config(s); give at least {first}",
                self.candidates,
                self.include.len()
            ));
        }
        Ok(())
    }
}

/// How a run is carried out, beside what it measures (not in the plan).
pub struct TuneOptions {
    /// Where converged references are cached, shared between runs.
    pub reference_cache: PathBuf,
    /// The command line, written into the chosen config's header.
    pub command_line: String,
}
