//! Runs a bench plan into a results directory: times every frame of every unit (modes
//! interleaved), then sweeps spp for run time against error, writing each measurement as it
//! is taken. Whatever the directory already holds is kept and not measured again, which is
//! how `--resume` completes an interrupted run. A plan with a motion script goes to
//! [`motion::run`](super::motion::run) once its directory is open.

use super::csv_log::CsvLog;
use super::error::BenchError;
use super::files::{strip_path, FRAMES_FILE, QUALITY_FILE, TRACE_FILE};
use super::perfetto::TraceWriter;
use super::protocol::{BenchPlan, FrameKey, Mode, RunOptions, EYES};
use super::quality::{self, Point};
use super::rows::{FrameRow, QualityRow};
use super::setup::{open_run_dir, perceptual_metric, progress_bar};
use super::{images, report};
use crate::foveation::{Gaze, GazeChoice, GazeTrace};
use crate::gpu::GpuContext;
use crate::render::{eye_views, DebugView, EyeView, FrameRequest, Renderer};
use crate::scene::{self, Scene};
use std::collections::{BTreeMap, HashMap, HashSet};
use std::path::Path;
use std::sync::Arc;
use std::time::{Instant, SystemTime, UNIX_EPOCH};

/// The eyes of a mode's frames: both eyes, gaze on the view axis or the top-left corner.
pub fn mode_eyes(scene: &Scene, plan: &BenchPlan, mode: Mode) -> Vec<EyeView> {
    let gaze = match mode {
        Mode::Corner => Gaze::Corner,
        _ => Gaze::Forward,
    };
    let aspect = plan.width as f32 / plan.height as f32;
    eye_views(
        &scene.camera,
        aspect,
        plan.fov,
        true,
        GazeChoice {
            left: gaze,
            right: gaze,
        },
    )
}

/// The eyes of frame `frame` of the trace mode: `eyes` with each eye's gaze from row `frame`
/// of the trace (its last row past its end).
pub fn trace_eyes(
    eyes: &[EyeView],
    plan: &BenchPlan,
    trace: &GazeTrace,
    frame: u64,
) -> Vec<EyeView> {
    let images: Vec<_> = eyes
        .iter()
        .map(|e| e.image(plan.width, plan.height))
        .collect();
    let (row, _) = trace.row(frame);
    eyes.iter()
        .zip(row.gazes(&images))
        .map(|(e, gaze)| EyeView { gaze, ..*e })
        .collect()
}

/// Reads the plan's gaze trace, if it has one, and says once if it is shorter than a repeat.
fn read_trace(plan: &BenchPlan) -> Result<Option<GazeTrace>, BenchError> {
    let Some(path) = &plan.gaze_trace else {
        return Ok(None);
    };
    let trace = GazeTrace::read(path).map_err(|e| BenchError::Plan(e.to_string()))?;
    if trace.rows.len() < plan.frames as usize {
        tracing::warn!(
            "gaze trace {} has {} rows for {} frames per repeat: the trace mode's later frames \
             hold its last row",
            path.display(),
            trace.rows.len(),
            plan.frames
        );
    }
    Ok(Some(trace))
}

/// Runs `plan` into `dir` (created if missing) and writes the summary, report and plots.
pub fn run(
    ctx: &Arc<GpuContext>,
    plan: &BenchPlan,
    dir: &Path,
    options: &RunOptions,
) -> Result<(), BenchError> {
    let gaze_trace = read_trace(plan)?;
    let commands = open_run_dir(plan, dir, options)?;
    if let Some(script) = &plan.motion {
        return super::motion::run(ctx, plan, script, dir, options, &commands);
    }
    let aspect = plan.width as f32 / plan.height as f32;

    // Frames whose two eye rows are both there are done; a lone eye row is measured again.
    let (mut frames_log, frame_rows) =
        CsvLog::<FrameRow>::open_keeping(&dir.join(FRAMES_FILE), |rows| {
            let mut eyes: HashMap<FrameKey, u32> = HashMap::new();
            for r in &rows {
                *eyes.entry(r.key()).or_default() += 1;
            }
            rows.into_iter()
                .filter(|r| eyes[&r.key()] == EYES)
                .collect()
        })?;
    let done_frames: HashSet<FrameKey> = frame_rows.iter().map(FrameRow::key).collect();
    let point_rows = 1 + crate::metrics::BANDS.len() as u32;
    let (mut quality_log, quality_rows) =
        CsvLog::<QualityRow>::open_keeping(&dir.join(QUALITY_FILE), |rows| {
            let mut count: HashMap<(String, Mode, u32), u32> = HashMap::new();
            for r in &rows {
                *count.entry((r.scene.clone(), r.mode, r.spp)).or_default() += 1;
            }
            rows.into_iter()
                .filter(|r| count[&(r.scene.clone(), r.mode, r.spp)] == EYES * point_rows)
                .collect()
        })?;
    let done_points: HashSet<(String, Mode, u32)> = quality_rows
        .iter()
        .map(|r| (r.scene.clone(), r.mode, r.spp))
        .collect();
    let mut metric = perceptual_metric()?;
    let trace_path = dir.join(TRACE_FILE);
    let mut trace = TraceWriter::open(&trace_path).map_err(|e| BenchError::file(&trace_path, e))?;

    let pending_frames: Vec<FrameKey> = plan
        .frame_keys()
        .into_iter()
        .filter(|k| !done_frames.contains(k))
        .collect();
    let pending_points: Vec<(String, Mode, u32)> = plan
        .scenes
        .iter()
        .flat_map(|s| {
            plan.sweep()
                .into_iter()
                .flat_map(move |spp| plan.modes().into_iter().map(move |m| (s.clone(), m, spp)))
        })
        .filter(|p| !done_points.contains(p))
        .collect();
    let bar = progress_bar((pending_frames.len() + pending_points.len()) as u64);
    let mut measured = 0u64;

    for scene_name in &plan.scenes {
        let strip = strip_path(dir, scene_name);
        let frames: Vec<&FrameKey> = pending_frames
            .iter()
            .filter(|k| k.scene == *scene_name)
            .collect();
        let points: Vec<&(String, Mode, u32)> = pending_points
            .iter()
            .filter(|p| p.0 == *scene_name)
            .collect();
        if frames.is_empty() && points.is_empty() && strip.exists() {
            continue;
        }
        bar.set_message(format!("{scene_name}: loading"));
        let scene = scene::load(scene_name, aspect)?;
        let mut renderer = Renderer::new(ctx, &scene).map_err(BenchError::render(scene_name))?;
        renderer
            .set_traversal(plan.traversal)
            .map_err(BenchError::render(scene_name))?;
        // The trace mode's entry is its first row's eyes: its warm-up and quality frames.
        let eyes: BTreeMap<Mode, Vec<EyeView>> = plan
            .modes()
            .into_iter()
            .map(|m| {
                let eyes = mode_eyes(&scene, plan, m);
                match (m, &gaze_trace) {
                    (Mode::Trace, Some(trace)) => (m, trace_eyes(&eyes, plan, trace, 0)),
                    _ => (m, eyes),
                }
            })
            .collect();
        let configs: BTreeMap<Mode, _> = plan
            .modes()
            .into_iter()
            .map(|m| (m, plan.config(m, plan.spp)))
            .collect();

        // Timing: per unit, one warm-up frame per mode (pipeline compilation, first touch of
        // memory), then the pending frames, modes interleaved.
        for unit in plan.units().iter().filter(|u| u.scene == *scene_name) {
            let todo: Vec<&&FrameKey> = frames.iter().filter(|k| k.repeat == unit.repeat).collect();
            if todo.is_empty() {
                continue;
            }
            bar.set_message(format!("{scene_name}: repeat {}", unit.repeat + 1));
            let settings = quality::settings(plan, plan.spp);
            let mut measure = |m: Mode, eyes: &[EyeView]| {
                renderer
                    .measure_frame(&FrameRequest {
                        settings,
                        foveation: &configs[&m],
                        eyes,
                        debug: DebugView::None,
                    })
                    .map_err(BenchError::render(scene_name))
            };
            for &mode in &unit.modes {
                measure(mode, &eyes[&mode])?;
            }
            for key in todo {
                let traced;
                let key_eyes = match (key.mode, &gaze_trace) {
                    (Mode::Trace, Some(t)) => {
                        traced = trace_eyes(&eyes[&key.mode], plan, t, key.frame as u64);
                        &traced[..]
                    }
                    _ => &eyes[&key.mode][..],
                };
                let wall_us = SystemTime::now()
                    .duration_since(UNIX_EPOCH)
                    .map_or(0, |d| d.as_micros() as u64);
                let start = Instant::now();
                let frame = measure(key.mode, key_eyes)?;
                let cpu_ms = start.elapsed().as_secs_f64() * 1e3;
                let rows = FrameRow::from_frame(key, &frame, cpu_ms, wall_us);
                for row in &rows {
                    frames_log.append(row)?;
                }
                let passes: Vec<(String, f64, f64)> = frame
                    .stats
                    .pass_ms
                    .iter()
                    .zip(&frame.stats.pass_start_ms)
                    .map(|((name, ms), start)| (name.clone(), *start, *ms))
                    .collect();
                trace
                    .frame(&rows[0], &passes)
                    .map_err(|e| BenchError::file(&trace_path, e))?;
                bar.inc(1);
                measured += 1;
                if options.abort_after_frames == Some(measured) {
                    // As a kill would: no clean-up, nothing written after this point.
                    std::process::abort();
                }
            }
        }

        // Quality: the reference, then every pending point of the sweep.
        bar.set_message(format!("{scene_name}: reference"));
        let reference_path =
            quality::ReferenceKey::new(&renderer, plan, scene_name, &eyes[&Mode::Regular])
                .path(&options.reference_cache);
        let reference = quality::reference_image(
            &mut renderer,
            plan,
            scene_name,
            &eyes[&Mode::Regular],
            &reference_path,
            &mut |done, all| bar.set_message(format!("{scene_name}: reference {done}/{all}")),
        )?;
        let mut shown: BTreeMap<Mode, Point> = BTreeMap::new();
        for &(_, mode, spp) in &points {
            bar.set_message(format!("{scene_name}: {} at {spp} spp", mode.name()));
            let point = quality::measure_point(
                &mut renderer,
                plan,
                scene_name,
                *mode,
                *spp,
                &eyes[mode],
                &reference,
                metric.as_mut(),
            )?;
            for row in &point.rows {
                quality_log.append(row)?;
            }
            bar.inc(1);
            if *spp == plan.spp {
                shown.insert(*mode, point);
            }
        }
        if !strip.exists() {
            // Images of the protocol's spp measured in an earlier, interrupted run are
            // rendered again (their numbers are already in quality.csv).
            for mode in plan.modes() {
                if let std::collections::btree_map::Entry::Vacant(slot) = shown.entry(mode) {
                    slot.insert(quality::measure_point(
                        &mut renderer,
                        plan,
                        scene_name,
                        mode,
                        plan.spp,
                        &eyes[&mode],
                        &reference,
                        None,
                    )?);
                }
            }
            images::write_strip(&strip, plan, &reference, &shown)?;
        }
    }
    bar.finish_and_clear();
    trace
        .finish()
        .map_err(|e| BenchError::file(&trace_path, e))?;
    drop(frames_log);
    drop(quality_log);

    let (_, frame_rows) = CsvLog::<FrameRow>::open(&dir.join(FRAMES_FILE))?;
    let (_, quality_rows) = CsvLog::<QualityRow>::open(&dir.join(QUALITY_FILE))?;
    report::write_all(
        dir,
        plan,
        &ctx.info,
        &commands.lines().collect::<Vec<_>>(),
        &frame_rows,
        &quality_rows,
    )
}
