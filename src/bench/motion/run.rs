//! Runs a motion plan: per scene, the converged reference of every frame's pose (cached like
//! the still references), then each sequence ([`Sequence::all`]: history off, on, off at twice
//! the spp) frame by frame, every frame measured against its own reference per eccentricity
//! band around that frame's gaze, and its flicker against the frame before.
//!
//! A sequence is the unit of resume: one whose rows are all in motion.csv is not rendered
//! again; a partial one starts over (its history cannot be restored mid-sequence).

use super::images::Animation;
use super::script::{MotionScript, Sequence};
use crate::bench::csv_log::CsvLog;
use crate::bench::error::BenchError;
use crate::bench::files::{animation_path, MOTION_FILE, MOTION_JOD_FILE};
use crate::bench::protocol::{BenchPlan, RunOptions, EYES};
use crate::bench::quality::{self, eye_image};
use crate::bench::rows::{MotionJodRow, MotionRow, EYE_NAMES};
use crate::bench::setup::{perceptual_metric, progress_bar, scene_renderer};
use crate::foveation::{FoveationConfig, Gaze, GazeChoice};
use crate::gpu::GpuContext;
use crate::metrics::jod::{Fvvdp, VideoJod};
use crate::metrics::{self, hidden_black, visible_pixels, BANDS};
use crate::render::accumulate::frame_seed;
use crate::render::FrameOptions;
use crate::render::{
    eye_views, DebugView, EyeView, Frame, FrameRequest, RenderSettings, Renderer, TemporalSettings,
};
use crate::scene::Scene;
use indicatif::ProgressBar;
use std::collections::{HashMap, HashSet};
use std::path::Path;
use std::sync::Arc;

/// A sequence of a scene: (scene, sequence name).
type SequenceKey = (String, String);

/// Regions measured per eye: the whole visible image, then each eccentricity band.
const REGIONS: u32 = 1 + BANDS.len() as u32;

/// Both eyes at frame `frame`: the scene camera turned by the script's head, each eye's gaze
/// at the script's fixation.
pub fn frame_eyes(
    scene: &Scene,
    plan: &BenchPlan,
    script: &MotionScript,
    frame: u32,
) -> Vec<EyeView> {
    let head = script.head_pose(frame).apply(&scene.camera);
    let aspect = plan.width as f32 / plan.height as f32;
    let forward = GazeChoice {
        left: Gaze::Forward,
        right: Gaze::Forward,
    };
    eye_views(&head, aspect, plan.fov, true, forward)
        .into_iter()
        .map(|eye| {
            let image = eye.image(plan.width, plan.height);
            let [x, y] = script.gaze_pixel(frame, &scene.camera, &eye.camera, &image);
            EyeView {
                gaze: Gaze::Pixel(x, y),
                ..eye
            }
        })
        .collect()
}

/// Runs the motion `plan` into `dir` (opened by the caller, whose command lines so far are
/// `commands`) and writes its summary, report, plots and animations.
pub fn run(
    ctx: &Arc<GpuContext>,
    plan: &BenchPlan,
    script: &MotionScript,
    dir: &Path,
    options: &RunOptions,
    commands: &str,
) -> Result<(), BenchError> {
    let (log, done) = open_motion_log(dir, plan)?;
    let (jod_log, _) = CsvLog::<MotionJodRow>::open(&dir.join(MOTION_JOD_FILE))?;
    let metric = perceptual_metric(plan.profile)?;
    let mut run = MotionRun {
        ctx,
        plan,
        script,
        options,
        sequences: Sequence::all(plan.spp),
        done,
        bar: progress_bar(plan.scenes.len() as u64 * 4 * plan.frames as u64),
        log,
        jod_log,
        metric,
    };
    for scene_name in &plan.scenes {
        run.scene(scene_name, &animation_path(dir, scene_name))?;
    }
    run.finish();
    write_report(ctx, plan, script, dir, commands)
}

/// motion.csv, keeping the sequences whose rows are all there (a partial one starts over),
/// and those sequences as (scene, sequence name).
fn open_motion_log(
    dir: &Path,
    plan: &BenchPlan,
) -> Result<(CsvLog<MotionRow>, HashSet<SequenceKey>), BenchError> {
    let per_sequence = plan.frames * EYES * REGIONS;
    let (log, rows) = CsvLog::<MotionRow>::open_keeping(&dir.join(MOTION_FILE), |rows| {
        let mut count: HashMap<SequenceKey, u32> = HashMap::new();
        for r in &rows {
            *count
                .entry((r.scene.clone(), r.sequence.clone()))
                .or_default() += 1;
        }
        rows.into_iter()
            .filter(|r| count[&(r.scene.clone(), r.sequence.clone())] == per_sequence)
            .collect()
    })?;
    let done = rows
        .iter()
        .map(|r| (r.scene.clone(), r.sequence.clone()))
        .collect();
    Ok((log, done))
}

/// Reads back everything the directory holds and writes the summary, report and plots.
fn write_report(
    ctx: &GpuContext,
    plan: &BenchPlan,
    script: &MotionScript,
    dir: &Path,
    commands: &str,
) -> Result<(), BenchError> {
    let (_, rows) = CsvLog::<MotionRow>::open(&dir.join(MOTION_FILE))?;
    let (_, jods) = CsvLog::<MotionJodRow>::open(&dir.join(MOTION_JOD_FILE))?;
    super::report::write_all(
        dir,
        plan,
        script,
        &ctx.info,
        &commands.lines().collect::<Vec<_>>(),
        &rows,
        &jods,
    )
}

/// What the motion run carries from scene to scene.
struct MotionRun<'a> {
    ctx: &'a Arc<GpuContext>,
    plan: &'a BenchPlan,
    script: &'a MotionScript,
    options: &'a RunOptions,
    sequences: [Sequence; 3],
    /// (scene, sequence) whose rows are all in motion.csv.
    done: HashSet<SequenceKey>,
    bar: ProgressBar,
    log: CsvLog<MotionRow>,
    jod_log: CsvLog<MotionJodRow>,
    metric: Option<Fvvdp>,
}

/// One scene, loaded: its renderer and both eyes of every frame.
struct MotionScene<'a> {
    name: &'a str,
    renderer: Renderer,
    eyes: Vec<Vec<EyeView>>,
}

impl MotionRun<'_> {
    /// The scene's references, then each sequence not yet measured, then its animation at
    /// `animation_file` (a sequence already measured is rendered again when the animation is
    /// missing, for its panels). A scene with nothing left is not loaded.
    fn scene(&mut self, scene_name: &str, animation_file: &Path) -> Result<(), BenchError> {
        let plan = self.plan;
        let pending = |s: &Sequence| !self.done.contains(&(scene_name.to_string(), s.name()));
        if !self.sequences.iter().any(pending) && animation_file.exists() {
            self.bar.inc(4 * plan.frames as u64);
            return Ok(());
        }
        let measured: Vec<bool> = self.sequences.iter().map(|s| !pending(s)).collect();
        let mut scene = self.load(scene_name)?;
        let mut animation =
            Animation::new(plan.width, plan.height, plan.reference_spp, &self.sequences);
        // References first, with the history off (they are regular frames).
        scene
            .renderer
            .set_temporal(None)
            .map_err(BenchError::render(scene_name))?;
        for k in 0..plan.frames {
            self.bar
                .set_message(format!("{scene_name}: reference of frame {k}"));
            let rgb = self.reference(&mut scene, k)?;
            animation.add_reference(k, &eye_image(&rgb, EYES, plan.width, plan.height, 0));
            self.bar.inc(1);
        }
        for (index, measured) in measured.into_iter().enumerate() {
            if measured && animation_file.exists() {
                self.bar.inc(plan.frames as u64);
                continue;
            }
            self.sequence(&mut scene, index, measured, &mut animation)?;
        }
        animation.write(animation_file, plan.frames)?;
        Ok(())
    }

    /// Loads the scene and works out both eyes of every frame.
    fn load<'n>(&self, scene_name: &'n str) -> Result<MotionScene<'n>, BenchError> {
        let plan = self.plan;
        let (scene, renderer) = scene_renderer(self.ctx, plan, scene_name)?;
        let eyes = (0..plan.frames)
            .map(|k| frame_eyes(&scene, plan, self.script, k))
            .collect();
        Ok(MotionScene {
            name: scene_name,
            renderer,
            eyes,
        })
    }

    /// The converged reference of frame `k`'s pose (from the cache, or rendered into it).
    /// Frames of one pose share a reference (a still sequence renders one).
    fn reference(&self, scene: &mut MotionScene, k: u32) -> Result<Vec<f32>, BenchError> {
        let (plan, name) = (self.plan, scene.name);
        let eyes = &scene.eyes[k as usize];
        let path = quality::ReferenceKey::new(&scene.renderer, plan, name, eyes)
            .path(&self.options.reference_cache);
        quality::reference_image(&mut scene.renderer, plan, name, eyes, &path, &mut |_, _| {})
    }

    /// Renders sequence `index` frame by frame: its rows (unless `measured` already), each
    /// eye's video for FovVideoVDP and its JOD rows, and its panels of the animation.
    fn sequence(
        &mut self,
        scene: &mut MotionScene,
        index: usize,
        measured: bool,
        animation: &mut Animation,
    ) -> Result<(), BenchError> {
        let (plan, sequence) = (self.plan, self.sequences[index]);
        scene
            .renderer
            .set_temporal(sequence.temporal.then(TemporalSettings::default))
            .map_err(BenchError::render(scene.name))?;
        let config = sequence.config(&plan.foveation);
        // One warm-up frame, forgotten: the first dispatch of a pipeline (on lavapipe, its
        // compilation) must not count as the sequence's first frame.
        scene
            .renderer
            .frame(
                &frame_request(plan, &sequence, &config, &scene.eyes[0], 0),
                FrameOptions::measure(),
            )
            .map(Option::unwrap)
            .map_err(BenchError::render(scene.name))?;
        scene.renderer.reset_history();
        let mut before: Option<(Vec<f32>, Vec<f32>)> = None;
        // Each eye's sequence as a video for FovVideoVDP (when its venv is there).
        let display = plan.display.transform(scene.name);
        let mut videos: Vec<VideoJod> = match (&self.metric, measured) {
            (Some(_), false) => (scene.eyes[0].iter())
                .map(|e| VideoJod::new(e.image(plan.width, plan.height), display))
                .collect::<Result<_, _>>()?,
            _ => Vec::new(),
        };
        for k in 0..plan.frames {
            self.bar
                .set_message(format!("{}: {} frame {k}", scene.name, sequence.name()));
            let truth = self.reference(scene, k)?;
            let eyes = &scene.eyes[k as usize];
            let frame = scene
                .renderer
                .frame(
                    &frame_request(plan, &sequence, &config, eyes, k),
                    FrameOptions::pixels(),
                )
                .map(Option::unwrap)
                .map_err(BenchError::render(scene.name))?;
            if !measured {
                let at = FrameAt {
                    scene: scene.name,
                    sequence: &sequence,
                    frame: k,
                    eyes,
                };
                let rows = measure_frame(plan, self.script, &at, &frame, &truth, before.as_ref())?;
                for row in rows {
                    self.log.append(&row)?;
                }
            }
            add_to_videos(plan, eyes, &frame, &truth, &mut videos)?;
            animation.add_sequence(
                k,
                index,
                &sequence,
                &eye_image(&frame.rgb, EYES, plan.width, plan.height, 0),
                &eye_image(&truth, EYES, plan.width, plan.height, 0),
                &visible_pixels(
                    &eyes[0].image(plan.width, plan.height),
                    plan.foveation.occlusion_deg,
                ),
                frame.gazes[0].0,
            )?;
            before = Some((truth, frame.rgb));
            self.bar.inc(1);
        }
        self.score_videos(scene.name, &sequence, &videos)
    }

    /// Appends each eye's JOD of the sequence to motion_jod.csv (with FovVideoVDP).
    fn score_videos(
        &mut self,
        scene_name: &str,
        sequence: &Sequence,
        videos: &[VideoJod],
    ) -> Result<(), BenchError> {
        let Some(metric) = self.metric.as_mut() else {
            return Ok(());
        };
        for (e, video) in videos.iter().enumerate() {
            self.bar
                .set_message(format!("{scene_name}: {} JOD", sequence.name()));
            self.jod_log.append(&MotionJodRow {
                scene: scene_name.to_string(),
                sequence: sequence.name(),
                eye: EYE_NAMES[e].to_string(),
                frames: video.frames() as u32,
                jod: video.score(metric, self.script.frame_rate_hz)?,
            })?;
        }
        Ok(())
    }

    /// Closes the progress bar and the logs.
    fn finish(self) {
        self.bar.finish_and_clear();
        drop(self.log);
        drop(self.jod_log);
    }
}

/// The request of frame `k` of `sequence`: its own seed, the sequence's spp and layers.
fn frame_request<'a>(
    plan: &BenchPlan,
    sequence: &Sequence,
    config: &'a FoveationConfig,
    eyes: &'a [EyeView],
    k: u32,
) -> FrameRequest<'a> {
    FrameRequest {
        settings: RenderSettings {
            seed: frame_seed(plan.seed, k),
            ..quality::settings(plan, sequence.spp)
        },
        foveation: config,
        eyes,
        debug: DebugView::None,
    }
}

/// Adds the frame and its reference, each eye's visible pixels, to that eye's video.
fn add_to_videos(
    plan: &BenchPlan,
    eyes: &[EyeView],
    frame: &Frame,
    truth: &[f32],
    videos: &mut [VideoJod],
) -> Result<(), BenchError> {
    let (w, h) = (plan.width, plan.height);
    for (e, video) in videos.iter_mut().enumerate() {
        let visible = visible_pixels(&eyes[e].image(w, h), plan.foveation.occlusion_deg);
        let eye_of = |rgb: &[f32]| hidden_black(eye_image(rgb, EYES, w, h, e as u32), &visible);
        video.push(&eye_of(&frame.rgb), &eye_of(truth), frame.gazes[e].0)?;
    }
    Ok(())
}

/// Which frame of which sequence a measurement belongs to.
struct FrameAt<'a> {
    scene: &'a str,
    sequence: &'a Sequence,
    frame: u32,
    eyes: &'a [EyeView],
}

/// The rows of one rendered frame: per eye and region, error against `truth` (this frame's
/// reference, both eyes side by side) and flicker against `before` (the frame before's
/// reference and render).
fn measure_frame(
    plan: &BenchPlan,
    script: &MotionScript,
    at: &FrameAt,
    frame: &Frame,
    truth: &[f32],
    before: Option<&(Vec<f32>, Vec<f32>)>,
) -> Result<Vec<MotionRow>, BenchError> {
    let (w, h) = (plan.width, plan.height);
    let s = &frame.stats;
    let temporal_ms = s
        .pass_ms
        .iter()
        .filter(|(name, _)| name.ends_with("temporal") || name.ends_with("denoise"))
        .fold(0.0, |sum, (_, ms)| sum + ms);
    let saccade = script.gaze_deg(at.frame).1;
    let mut rows = Vec::new();
    for (e, eye) in at.eyes.iter().enumerate() {
        let image = eye.image(w, h);
        let eye_of = |rgb: &[f32]| eye_image(rgb, EYES, w, h, e as u32);
        let (test, reference) = (eye_of(&frame.rgb), eye_of(truth));
        let earlier = before.map(|(r, t)| (eye_of(r), eye_of(t)));
        let visible = visible_pixels(&image, plan.foveation.occlusion_deg);
        let gaze = frame.gazes[e].0;
        let mut regions = vec![("whole".to_string(), visible.clone())];
        for (band, mut mask) in BANDS.iter().zip(metrics::band_masks(&image, gaze)?) {
            for (m, v) in mask.iter_mut().zip(&visible) {
                *m &= v;
            }
            regions.push((band.name.to_string(), mask));
        }
        for (region, mask) in regions {
            let error = metrics::image_error(&reference, &test, w, h, Some(&mask))?;
            let flicker = match &earlier {
                Some((r, t)) => metrics::flicker(&reference, r, &test, t, w, h, Some(&mask))?,
                None => None,
            };
            rows.push(MotionRow {
                scene: at.scene.to_string(),
                sequence: at.sequence.name(),
                temporal: at.sequence.temporal,
                spp: at.sequence.spp,
                frame: at.frame,
                time_ms: script.time_s(at.frame) * 1e3,
                eye: EYE_NAMES[e].to_string(),
                region,
                pixels: error.pixels,
                rel_mse: error.rel_mse,
                mse: error.mse,
                flicker,
                frame_gpu_ms: s.gpu_ms(),
                temporal_ms,
                gaze_x: gaze[0],
                gaze_y: gaze[1],
                saccade,
            });
        }
    }
    Ok(rows)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frames_of_one_pose_share_a_reference_and_other_poses_do_not() {
        let plan = BenchPlan {
            motion: Some(MotionScript::head_and_saccades()),
            ..BenchPlan::quick()
        };
        let scene = crate::scene::load("control", plan.width as f32 / plan.height as f32).unwrap();
        let cache = Path::new("refs");
        let path = |script: &MotionScript, k| {
            let eyes = frame_eyes(&scene, &plan, script, k);
            quality::ReferenceKey {
                scene: "control",
                scene_contents: 1,
                renderer: 2,
                plan: &plan,
                eyes: &eyes,
            }
            .path(cache)
        };
        let moving = MotionScript::head_and_saccades();
        assert_ne!(path(&moving, 1), path(&moving, 2));
        let still = MotionScript::still();
        assert_eq!(path(&still, 1), path(&still, 30));
        // The gaze is not part of a reference: frame 0 of both scripts has the same pose.
        assert_eq!(path(&moving, 0), path(&still, 0));
        assert!(path(&still, 0)
            .to_string_lossy()
            .starts_with("refs/control-360x400x2-256spp-"));
    }
}
