//! What a `fovea tune` run searches and measures, as data: written next to its results
//! (`<out>-tune.json`) so that an interrupted run resumes only with the same plan.

use super::space::Space;
use crate::foveation::{EyeFov, Gaze, GazeChoice, ImageGeometry};
use crate::render::display::DisplayChoice;
use crate::render::{eye_views, EyeView, FovChoice, Integrator, Traversal};
use crate::scene::env_choice::EnvChoice;
use crate::scene::Camera;
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

/// `--objective motion`: frames rendered (not scored) before the scored ones, so that the
/// history has built up: the script's whole first fixation (250 ms), as on a headset that has
/// been running. Eight, as before, scored histories still growing, which flattered sparse
/// layers (theirs stop growing sooner): from 8 to 22 frames regular 1 spp gained 0.23 JOD on
/// cornell at 720x800, the thesis' layers 0.11-0.20.
pub const WARM_UP: u32 = 22;

/// The warm-up of plans written before it was a plan field.
pub fn warm_up_before_the_field() -> u32 {
    8
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
    /// `--window`: the eye image is the central width×height of the display's eye image of
    /// this size, its field of view cut to match: the display's pixel density over a smaller
    /// field. Absent: the whole field of view.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub window_of: Option<[u32; 2]>,
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
    /// `--objective motion`: frames rendered before the scored ones ([`WARM_UP`]). Plans
    /// written before the field rendered 8.
    #[serde(default = "warm_up_before_the_field")]
    pub motion_warm_up: u32,
    /// `--sampler`. Plans written before the flag ran with the independent sampler.
    #[serde(default = "crate::render::Sampler::before_the_flag")]
    pub sampler: crate::render::Sampler,
    /// `--render-seed`: which samples the judged and timed frames draw (see
    /// [`TunePlan::frame_seed`]); not the reference's. Runs that differ only in it measure how
    /// much a config's JOD moves with its noise. Absent: 1.
    #[serde(
        default = "first_render_seed",
        skip_serializing_if = "is_first_render_seed"
    )]
    pub render_seed: u32,
}

/// The judged frames' seed of plans written before `--render-seed`, and its default.
pub const FIRST_RENDER_SEED: u32 = 1;

fn first_render_seed() -> u32 {
    FIRST_RENDER_SEED
}

fn is_first_render_seed(seed: &u32) -> bool {
    *seed == FIRST_RENDER_SEED
}

impl TunePlan {
    /// One eye (mono) where `camera` looks, gaze forward, with the plan's field of view cut
    /// to its window.
    pub fn eye(&self, camera: &Camera) -> EyeView {
        let forward = GazeChoice {
            left: Gaze::Forward,
            right: Gaze::Forward,
        };
        let aspect = self.width as f32 / self.height as f32;
        let eye = eye_views(camera, aspect, self.fov, false, forward)[0];
        let fov = self.in_window(eye.fov());
        EyeView {
            camera: Camera {
                angle_left: fov.left,
                angle_right: fov.right,
                angle_up: fov.up,
                angle_down: fov.down,
                ..eye.camera
            },
            ..eye
        }
    }

    /// The first judged frame's seed; frame k of a sequence takes it + k. Render seeds are
    /// 2^16 seeds apart, so no two seeds' sequences share a frame's samples, and render seed 1
    /// keeps the seeds of plans written before the flag.
    pub fn frame_seed(&self) -> u32 {
        (self.render_seed.wrapping_sub(FIRST_RENDER_SEED) << 16).wrapping_add(FIRST_RENDER_SEED)
    }

    /// `fov`, the eye image's field, cut to the plan's window (itself without one).
    fn in_window(&self, fov: EyeFov) -> EyeFov {
        match self.window_of {
            Some(full) => fov.central_window(full, [self.width, self.height]),
            None => fov,
        }
    }

    /// What the run line and the configs' header say of a window: where the judged pixels lie.
    pub fn window_phrase(&self) -> String {
        match self.window_of {
            Some([w, h]) => format!(", the centre of its {w}x{h} eye image"),
            None => String::new(),
        }
    }

    /// A window must lie within the display's eye image and see the off-axis gaze every
    /// config is judged at.
    fn validate_window(&self, [w, h]: [u32; 2]) -> Result<(), String> {
        let profile = self.profile.name();
        if self.width > w || self.height > h {
            return Err(format!(
                "--window {}x{} is larger than the {profile}'s {w}x{h} eye image; give at most that",
                self.width, self.height,
            ));
        }
        let Some((fov, _)) = self.fov.display_fovs() else {
            return Err(format!(
                "--window {}x{} needs the {profile}'s field of view, not the scene camera's",
                self.width, self.height
            ));
        };
        // The window the frames are rendered in: the plan's (mono) field, as `eye` cuts it.
        let image = ImageGeometry::new(self.width, self.height, self.in_window(fov));
        let Gaze::Pixel(x, y) = TuneGaze::OffAxis.gaze(&image) else {
            unreachable!("the off-axis gaze is a pixel")
        };
        if !(0.0..self.width as f64).contains(&x) || !(0.0..self.height as f64).contains(&y) {
            return Err(format!(
                "--window {}x{} sees too little of the {profile}'s field: it does not hold the \
                 off-axis gaze (15 deg right, 10 deg down) every config is judged at; give a \
                 larger window (a third of the eye image each way holds it)",
                self.width, self.height
            ));
        }
        Ok(())
    }

    /// Rejects plans that cannot run, saying which flag to change.
    pub fn validate(&self) -> Result<(), String> {
        if let Some(full) = self.window_of {
            self.validate_window(full)?;
        }
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

#[cfg(test)]
impl TunePlan {
    /// A plan of the standard space on cornell at 64x72 with the Vive Pro Eye's field of view.
    pub(crate) fn for_tests(seed: u64) -> TunePlan {
        TunePlan {
            scenes: vec!["cornell".into()],
            width: 64,
            height: 72,
            fov: FovChoice::ViveProEye,
            window_of: None,
            profile: Default::default(),
            objective: Default::default(),
            budget: Budget::Regular(1),
            cost: Cost::GpuTime,
            candidates: 24,
            seed,
            frames: 1,
            reference_spp: 256,
            integrator: Integrator::Pt,
            max_bounces: 8,
            traversal: Traversal::Software,
            space: Space::standard(),
            include: vec![crate::foveation::FoveationConfig::thesis().with_spp(8)],
            display: Default::default(),
            environment: None,
            sampler: Default::default(),
            motion_warm_up: WARM_UP,
            render_seed: FIRST_RENDER_SEED,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::foveation::DisplayProfile;
    use glam::Vec3;

    #[test]
    fn a_window_sees_the_centre_of_the_display_at_its_density() {
        let camera = Camera::look_at(Vec3::ZERO, Vec3::NEG_Z, Vec3::Y, 60.0, 1.0);
        let whole = TunePlan {
            width: 3840,
            height: 3744,
            fov: FovChoice::VarjoXr4,
            profile: DisplayProfile::VarjoXr4,
            ..TunePlan::for_tests(1)
        };
        let window = TunePlan {
            width: 1600,
            height: 1560,
            window_of: Some([3840, 3744]),
            ..whole.clone()
        };
        let (a, b) = (whole.eye(&camera), window.eye(&camera));
        assert_eq!(
            (a.camera.position, a.camera.forward),
            (b.camera.position, b.camera.forward)
        );
        let (a, b) = (a.image(3840, 3744), b.image(1600, 1560));
        assert!((a.max_radians_per_pixel() - b.max_radians_per_pixel()).abs() < 1e-7);
        // 71.7 deg of the XR-4's 120 across: tan 35.8 deg = 1600/3840 tan 60 deg.
        assert!(
            (b.tan_right - 1600.0 / 3840.0 * 3f64.sqrt()).abs() < 1e-5,
            "{b:?}"
        );
        assert_eq!(window.validate(), Ok(()));

        let refused = |w, h| {
            TunePlan {
                width: w,
                height: h,
                ..window.clone()
            }
            .validate()
        };
        assert!(refused(4000, 1560).unwrap_err().contains("larger than"));
        assert!(refused(400, 1560).unwrap_err().contains("off-axis gaze"));
        assert!(refused(1600, 300).unwrap_err().contains("off-axis gaze"));
        // The check sees the field the frames are rendered in (the plan's), not the profile's.
        let scene_field = TunePlan {
            fov: FovChoice::Scene,
            ..window.clone()
        };
        assert!(scene_field
            .validate()
            .unwrap_err()
            .contains("field of view"));
        assert_eq!(
            window.window_phrase(),
            ", the centre of its 3840x3744 eye image"
        );
        assert_eq!(whole.window_phrase(), "");
    }
}
