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
use crate::bench::setup::{perceptual_metric, progress_bar};
use crate::foveation::{Gaze, GazeChoice};
use crate::gpu::GpuContext;
use crate::metrics::jod::VideoJod;
use crate::metrics::{self, hidden_black, visible_pixels, BANDS};
use crate::render::accumulate::frame_seed;
use crate::render::{
    eye_views, DebugView, EyeView, Frame, FrameRequest, RenderSettings, Renderer, TemporalSettings,
};
use crate::scene::{self, Scene};
use std::collections::{HashMap, HashSet};
use std::path::Path;
use std::sync::Arc;

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

pub fn run(
    ctx: &Arc<GpuContext>,
    plan: &BenchPlan,
    script: &MotionScript,
    dir: &Path,
    options: &RunOptions,
    commands: &str,
) -> Result<(), BenchError> {
    let per_sequence = plan.frames * EYES * REGIONS;
    let (mut log, rows) = CsvLog::<MotionRow>::open_keeping(&dir.join(MOTION_FILE), |rows| {
        let mut count: HashMap<(String, String), u32> = HashMap::new();
        for r in &rows {
            *count
                .entry((r.scene.clone(), r.sequence.clone()))
                .or_default() += 1;
        }
        rows.into_iter()
            .filter(|r| count[&(r.scene.clone(), r.sequence.clone())] == per_sequence)
            .collect()
    })?;
    let done: HashSet<(String, String)> = rows
        .iter()
        .map(|r| (r.scene.clone(), r.sequence.clone()))
        .collect();
    let (mut jod_log, _) = CsvLog::<MotionJodRow>::open(&dir.join(MOTION_JOD_FILE))?;
    let mut metric = perceptual_metric()?;
    let sequences = Sequence::all(plan.spp);
    let bar = progress_bar(plan.scenes.len() as u64 * 4 * plan.frames as u64);
    let aspect = plan.width as f32 / plan.height as f32;
    for scene_name in &plan.scenes {
        let animation_file = animation_path(dir, scene_name);
        let pending = |s: &Sequence| !done.contains(&(scene_name.clone(), s.name()));
        if !sequences.iter().any(pending) && animation_file.exists() {
            bar.inc(4 * plan.frames as u64);
            continue;
        }
        let scene = scene::load(scene_name, aspect)?;
        let mut renderer = Renderer::new(ctx, &scene).map_err(BenchError::render(scene_name))?;
        renderer
            .set_traversal(plan.traversal)
            .map_err(BenchError::render(scene_name))?;
        let eyes: Vec<Vec<EyeView>> = (0..plan.frames)
            .map(|k| frame_eyes(&scene, plan, script, k))
            .collect();
        let reference = |renderer: &mut Renderer, k: u32| {
            let eyes = &eyes[k as usize];
            // Frames of one pose share a reference (a still sequence renders one).
            let path = quality::ReferenceKey::new(renderer, plan, scene_name, eyes)
                .path(&options.reference_cache);
            quality::reference_image(renderer, plan, scene_name, eyes, &path, &mut |_, _| {})
        };
        let mut animation = Animation::new(plan.width, plan.height, plan.reference_spp, &sequences);
        // References first, with the history off (they are regular frames).
        renderer
            .set_temporal(None)
            .map_err(BenchError::render(scene_name))?;
        for k in 0..plan.frames {
            bar.set_message(format!("{scene_name}: reference of frame {k}"));
            let rgb = reference(&mut renderer, k)?;
            animation.add_reference(k, &eye_image(&rgb, EYES, plan.width, plan.height, 0));
            bar.inc(1);
        }
        for (index, sequence) in sequences.iter().enumerate() {
            let measured = !pending(sequence);
            if measured && animation_file.exists() {
                bar.inc(plan.frames as u64);
                continue;
            }
            renderer
                .set_temporal(sequence.temporal.then(TemporalSettings::default))
                .map_err(BenchError::render(scene_name))?;
            let config = sequence.config(&plan.foveation);
            let request = |k: u32| FrameRequest {
                settings: RenderSettings {
                    seed: frame_seed(plan.seed, k),
                    ..quality::settings(plan, sequence.spp)
                },
                foveation: &config,
                eyes: &eyes[k as usize],
                debug: DebugView::None,
            };
            // One warm-up frame, forgotten: the first dispatch of a pipeline (on lavapipe,
            // its compilation) must not count as the sequence's first frame.
            renderer
                .measure_frame(&request(0))
                .map_err(BenchError::render(scene_name))?;
            renderer.reset_history();
            let mut before: Option<(Vec<f32>, Vec<f32>)> = None;
            // Each eye's sequence as a video for FovVideoVDP (when its venv is there).
            let mut videos: Vec<VideoJod> = match (&metric, measured) {
                (Some(_), false) => (eyes[0].iter())
                    .map(|e| VideoJod::new(e.image(plan.width, plan.height)))
                    .collect::<Result<_, _>>()?,
                _ => Vec::new(),
            };
            for k in 0..plan.frames {
                bar.set_message(format!("{scene_name}: {} frame {k}", sequence.name()));
                let truth = reference(&mut renderer, k)?;
                let frame = renderer
                    .render_frame(&request(k))
                    .map_err(BenchError::render(scene_name))?;
                if !measured {
                    let at = FrameAt {
                        scene: scene_name,
                        sequence,
                        frame: k,
                        eyes: &eyes[k as usize],
                    };
                    for row in measure_frame(plan, script, &at, &frame, &truth, before.as_ref())? {
                        log.append(&row)?;
                    }
                }
                let (w, h) = (plan.width, plan.height);
                let occlusion = plan.foveation.occlusion_deg;
                for (e, video) in videos.iter_mut().enumerate() {
                    let visible = visible_pixels(&eyes[k as usize][e].image(w, h), occlusion);
                    let eye_of =
                        |rgb: &[f32]| hidden_black(eye_image(rgb, EYES, w, h, e as u32), &visible);
                    video.push(&eye_of(&frame.rgb), &eye_of(&truth), frame.gazes[e].0)?;
                }
                animation.add_sequence(
                    k,
                    index,
                    sequence,
                    &eye_image(&frame.rgb, EYES, w, h, 0),
                    &eye_image(&truth, EYES, w, h, 0),
                    &visible_pixels(&eyes[k as usize][0].image(w, h), occlusion),
                    frame.gazes[0].0,
                )?;
                before = Some((truth, frame.rgb));
                bar.inc(1);
            }
            if let Some(metric) = metric.as_mut() {
                for (e, video) in videos.iter().enumerate() {
                    bar.set_message(format!("{scene_name}: {} JOD", sequence.name()));
                    jod_log.append(&MotionJodRow {
                        scene: scene_name.clone(),
                        sequence: sequence.name(),
                        eye: EYE_NAMES[e].to_string(),
                        frames: video.frames() as u32,
                        jod: video.score(metric, script.frame_rate_hz)?,
                    })?;
                }
            }
        }
        animation.write(&animation_file, plan.frames)?;
    }
    bar.finish_and_clear();
    drop(log);
    drop(jod_log);
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
        let scene = scene::load("control", plan.width as f32 / plan.height as f32).unwrap();
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
