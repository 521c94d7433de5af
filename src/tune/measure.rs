//! Judging one config: per scene and gaze, a first frame (no history: what the eye sees when
//! it lands somewhere new) scored by FovVideoVDP against the scene's converged reference,
//! then the timed frames whose median GPU time is the config's cost.

use super::error::TuneError;
use super::motion::MotionJudge;
use super::plan::{Budget, Cost, Objective, TuneGaze, TunePlan};
use crate::bench::quality;
use crate::bench::BenchPlan;
use crate::foveation::{FoveationConfig, ImageGeometry};
use crate::gpu::GpuContext;
use crate::metrics::jod::Fvvdp;
use crate::metrics::{hidden_black, visible_pixels};
use crate::render::FrameOptions;
use crate::render::{
    DebugView, EyeView, FrameRequest, FrameStats, RenderSettings, Renderer, TemporalSettings,
};
use std::path::Path;
use std::sync::Arc;

/// The reference's seed, whatever `--render-seed` is: the reference cache is shared between
/// runs (and the reference's own passes take seeds far from the judged frames').
const REFERENCE_SEED: u32 = super::plan::FIRST_RENDER_SEED;

/// One scene, ready to judge configs on.
pub struct SceneJudge {
    pub name: String,
    renderer: Renderer,
    /// Renders the pace frames (see [`SceneJudge::judge`]), without history: only with a
    /// budget of regular rendering's time.
    pacer: Option<Renderer>,
    /// One eye per gaze of [`TuneGaze::ALL`].
    eyes: Vec<EyeView>,
    image: ImageGeometry,
    reference: Vec<f32>,
    /// Pixels the lens shows (the space's occlusion mask); the rest is black in both images.
    visible: Vec<bool>,
    /// With `--objective motion`: the judged sequence.
    motion: Option<MotionJudge>,
}

/// What one config measured on one scene.
pub struct SceneScore {
    /// Per gaze of [`TuneGaze::ALL`]: the first frame after the eye lands there.
    pub jod: Vec<f64>,
    /// With `--objective motion`: the video's JOD (NaN otherwise).
    pub motion_jod: f64,
    pub timing: Timing,
    pub paths_per_pixel: f64,
    pub rays_per_pixel: f64,
}

/// A config's timed frames: the medians of its GPU time and traced paths per frame, and of
/// the pace frames' between them (NaN without a pace).
#[derive(Clone, Copy, Debug)]
pub struct Timing {
    pub ms: f64,
    pub pace_ms: f64,
    pub samples: f64,
    pub pace_samples: f64,
}

impl Timing {
    /// The config's cost over the pace's, in what `cost` measures; `totals` sums several
    /// scenes' timings first (see `run::judge`).
    pub fn ratio(totals: &[Timing], cost: Cost) -> f64 {
        let sum = |f: fn(&Timing) -> f64| totals.iter().map(f).sum::<f64>();
        match cost {
            Cost::GpuTime => sum(|t| t.ms) / sum(|t| t.pace_ms),
            Cost::Samples => sum(|t| t.samples) / sum(|t| t.pace_samples),
        }
    }
}

/// The bench's plan for the same image, which the reference is rendered from.
fn reference_plan(plan: &TunePlan) -> BenchPlan {
    BenchPlan {
        scenes: plan.scenes.clone(),
        width: plan.width,
        height: plan.height,
        fov: plan.fov,
        reference_spp: plan.reference_spp,
        integrator: plan.integrator,
        max_bounces: plan.max_bounces,
        seed: REFERENCE_SEED,
        traversal: plan.traversal,
        ..BenchPlan::quick()
    }
}

impl SceneJudge {
    /// Loads `name`, and its reference (from `cache`, or rendered into it).
    pub fn new(
        ctx: &Arc<GpuContext>,
        plan: &TunePlan,
        name: &str,
        cache: &Path,
        progress: &mut dyn FnMut(u32, u32),
    ) -> Result<Self, TuneError> {
        let scene = crate::scene::load(name, plan.width as f32 / plan.height as f32)
            .map_err(crate::bench::BenchError::from)?;
        let mut renderer = Renderer::new(ctx, &scene).map_err(TuneError::render(name))?;
        renderer
            .set_traversal(plan.traversal)
            .map_err(TuneError::render(name))?;
        let pacer = match plan.budget {
            Budget::Regular(_) => {
                let mut pacer = Renderer::new(ctx, &scene).map_err(TuneError::render(name))?;
                pacer
                    .set_traversal(plan.traversal)
                    .map_err(TuneError::render(name))?;
                Some(pacer)
            }
            Budget::Ms(_) => None,
        };
        let mono = plan.eye(&scene.camera);
        let image = mono.image(plan.width, plan.height);
        let eyes: Vec<EyeView> = TuneGaze::ALL
            .iter()
            .map(|g| EyeView {
                gaze: g.gaze(&image),
                ..mono
            })
            .collect();
        let bench = reference_plan(plan);
        let path = quality::ReferenceKey::new(&renderer, &bench, name, &eyes[..1]).path(cache);
        let reference =
            quality::reference_image(&mut renderer, &bench, name, &eyes[..1], &path, progress)?;
        let visible = visible_pixels(&image, plan.space.occlusion_deg);
        let motion = match plan.objective {
            Objective::Still => None,
            Objective::Motion => Some(MotionJudge::new(
                &mut renderer,
                plan,
                &bench,
                &scene,
                name,
                cache,
                &visible,
            )?),
        };
        Ok(Self {
            name: name.to_string(),
            renderer,
            pacer,
            eyes,
            image,
            reference: hidden_black(reference, &visible),
            visible,
            motion,
        })
    }

    /// Scores `config` at every gaze and times it. With a `pace` config, each timed frame
    /// follows a frame of it: on a machine whose speed drifts (other work, clocks), the ratio
    /// of the two medians holds where either alone does not.
    pub fn judge(
        &mut self,
        plan: &TunePlan,
        config: &FoveationConfig,
        pace: Option<&FoveationConfig>,
        metric: &mut Fvvdp,
    ) -> Result<SceneScore, TuneError> {
        let name = self.name.clone();
        // A history that starts empty for every judged frame (see keeps_history).
        let temporal = keeps_history(plan, config).then(TemporalSettings::default);
        self.renderer
            .set_temporal(temporal)
            .map_err(TuneError::render(&name))?;
        let settings = settings(plan);
        let mut jod = Vec::new();
        let (mut paths_per_pixel, mut rays_per_pixel) = (f64::NAN, f64::NAN);
        let mut timed = TimedFrames::default();
        let display = plan.display.transform(&name);
        let eyes = self.eyes.clone();
        for (g, eye) in eyes.iter().enumerate() {
            let request = FrameRequest {
                settings,
                foveation: config,
                eyes: std::slice::from_ref(eye),
                debug: DebugView::None,
            };
            self.renderer.reset_history();
            let frame = self
                .renderer
                .frame(&request, FrameOptions::pixels())
                .map(Option::unwrap)
                .map_err(TuneError::render(&name))?;
            if g == 0 {
                let visible = self.visible.iter().filter(|v| **v).count().max(1);
                let eye = frame.stats.eyes.first();
                let per_pixel = |n: u64| n as f64 / visible as f64;
                paths_per_pixel = per_pixel(eye.map_or(0, |c| c.paths));
                rays_per_pixel = per_pixel(eye.map_or(0, |c| c.rays));
            }
            let test = hidden_black(frame.rgb, &self.visible);
            let gaze = frame.gazes[0].0;
            jod.push(metric.image(&test, &self.reference, &self.image, gaze, &display)?);
            self.timed_frames(plan, &request, pace, &mut timed)?;
        }
        let motion_jod = match self.motion.is_some() {
            true => self.motion_jod(plan, config, true, metric)?,
            false => f64::NAN,
        };
        Ok(SceneScore {
            jod,
            motion_jod,
            timing: timed.medians(),
            paths_per_pixel,
            rays_per_pixel,
        })
    }

    /// `config`'s JOD on the motion sequence (with `--objective motion`; NaN without), the
    /// history kept or not.
    pub fn motion_jod(
        &mut self,
        plan: &TunePlan,
        config: &FoveationConfig,
        history: bool,
        metric: &mut Fvvdp,
    ) -> Result<f64, TuneError> {
        let Some(motion) = &self.motion else {
            return Ok(f64::NAN);
        };
        motion.score(
            &mut self.renderer,
            settings(plan),
            config,
            history,
            &self.image,
            &self.visible,
            &plan.display.transform(&self.name),
            metric,
        )
    }

    /// `config`'s time alone, gaze forward: the medians of its timed frames (after one
    /// untimed), and of the pace frames between them.
    pub fn time(
        &mut self,
        plan: &TunePlan,
        config: &FoveationConfig,
        pace: Option<&FoveationConfig>,
    ) -> Result<Timing, TuneError> {
        let temporal = keeps_history(plan, config).then(TemporalSettings::default);
        self.renderer
            .set_temporal(temporal)
            .map_err(TuneError::render(&self.name))?;
        let eye = self.eyes[0];
        let request = FrameRequest {
            settings: settings(plan),
            foveation: config,
            eyes: std::slice::from_ref(&eye),
            debug: DebugView::None,
        };
        self.renderer
            .frame(&request, FrameOptions::measure())
            .map(Option::unwrap)
            .map_err(TuneError::render(&self.name))?;
        let mut timed = TimedFrames::default();
        self.timed_frames(plan, &request, pace, &mut timed)?;
        Ok(timed.medians())
    }

    /// Times `plan.frames` frames of `request`, each after a frame of `pace` when given.
    fn timed_frames(
        &mut self,
        plan: &TunePlan,
        request: &FrameRequest,
        pace: Option<&FoveationConfig>,
        timed: &mut TimedFrames,
    ) -> Result<(), TuneError> {
        for _ in 0..plan.frames {
            if let (Some(pace), Some(pacer)) = (pace, self.pacer.as_mut()) {
                let frame = pacer
                    .frame(
                        &FrameRequest {
                            foveation: pace,
                            eyes: &self.eyes[..1],
                            ..*request
                        },
                        FrameOptions::measure(),
                    )
                    .map(Option::unwrap)
                    .map_err(TuneError::render(&self.name))?;
                timed.pace.push(frame.stats);
            }
            let frame = self
                .renderer
                .frame(request, FrameOptions::measure())
                .map(Option::unwrap)
                .map_err(TuneError::render(&self.name))?;
            timed.config.push(frame.stats);
        }
        Ok(())
    }
}

/// The stats of a config's timed frames and of the pace frames between them.
#[derive(Default)]
struct TimedFrames {
    config: Vec<FrameStats>,
    pace: Vec<FrameStats>,
}

impl TimedFrames {
    fn medians(&self) -> Timing {
        let of = |frames: &[FrameStats], f: fn(&FrameStats) -> f64| {
            median(&frames.iter().map(f).collect::<Vec<_>>())
        };
        let paths = |s: &FrameStats| s.paths as f64;
        Timing {
            ms: of(&self.config, FrameStats::gpu_ms),
            pace_ms: of(&self.pace, FrameStats::gpu_ms),
            samples: of(&self.config, paths),
            pace_samples: of(&self.pace, paths),
        }
    }
}

/// Whether `config` is timed (and its still frames judged) with the temporal history: with
/// `--objective motion`, which judges it with one, always; else when it denoises or filters
/// its lattices (both are guided by the history's surfaces).
fn keeps_history(plan: &TunePlan, config: &FoveationConfig) -> bool {
    plan.objective == Objective::Motion || config.needs_history()
}

/// The settings of every frame of the plan (the layers carry the spp).
fn settings(plan: &TunePlan) -> RenderSettings {
    RenderSettings {
        sampler: crate::render::Sampler::chosen(),
        width: plan.width,
        height: plan.height,
        spp: 1,
        seed: plan.frame_seed(),
        integrator: plan.integrator,
        max_bounces: plan.max_bounces,
    }
}

fn median(values: &[f64]) -> f64 {
    crate::bench::stats::summarize(values).map_or(f64::NAN, |s| s.median)
}
