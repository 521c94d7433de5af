//! Runs a bench plan into a results directory: times every frame of every unit (modes
//! interleaved), then sweeps spp for run time against error, writing each measurement as it
//! is taken. Whatever the directory already holds is kept and not measured again, which is
//! how `--resume` completes an interrupted run. A plan with a motion script goes to
//! [`motion::run`](super::motion::run()) once its directory is open.

use super::csv_log::CsvLog;
use super::error::BenchError;
use super::files::{strip_path, FRAMES_FILE, QUALITY_FILE, TRACE_FILE};
use super::perfetto::TraceWriter;
use super::protocol::{BenchPlan, FrameKey, Mode, RunOptions, Unit, EYES};
use super::quality::{self, Point};
use super::rows::{FrameRow, QualityRow};
use super::setup::{open_run_dir, perceptual_metric, progress_bar, scene_renderer};
use super::{images, report};
use crate::foveation::{FoveationConfig, Gaze, GazeChoice, GazeTrace};
use crate::gpu::GpuContext;
use crate::metrics::jod::Fvvdp;
use crate::render::FrameOptions;
use crate::render::{eye_views, DebugView, EyeView, Frame, FrameRequest, Renderer};
use crate::scene::Scene;
use indicatif::ProgressBar;
use std::collections::{BTreeMap, HashMap, HashSet};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::{Instant, SystemTime, UNIX_EPOCH};

/// One point of the quality sweep: scene, mode, spp.
type PointKey = (String, Mode, u32);

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
    let (frames_log, done_frames) = open_frames_log(dir)?;
    let (quality_log, done_points) = open_quality_log(dir)?;
    let metric = perceptual_metric(plan.profile)?;
    let trace_path = dir.join(TRACE_FILE);
    let trace = TraceWriter::open(&trace_path).map_err(|e| BenchError::file(&trace_path, e))?;
    let pending_frames = pending_frames(plan, &done_frames);
    let pending_points = pending_points(plan, &done_points);
    let mut run = StillRun {
        ctx,
        plan,
        options,
        gaze_trace: gaze_trace.as_ref(),
        bar: progress_bar((pending_frames.len() + pending_points.len()) as u64),
        frames_log,
        quality_log,
        trace,
        trace_path,
        metric,
        measured: 0,
    };
    for scene_name in &plan.scenes {
        let frames: Vec<&FrameKey> = pending_frames
            .iter()
            .filter(|k| k.scene == *scene_name)
            .collect();
        let points: Vec<&PointKey> = pending_points
            .iter()
            .filter(|p| p.0 == *scene_name)
            .collect();
        run.scene(scene_name, &strip_path(dir, scene_name), &frames, &points)?;
    }
    run.finish()?;
    write_report(ctx, plan, dir, &commands)
}

/// frames.csv, keeping the frames whose two eye rows are both there (a lone eye row is
/// measured again), and those frames.
fn open_frames_log(dir: &Path) -> Result<(CsvLog<FrameRow>, HashSet<FrameKey>), BenchError> {
    let (log, rows) = CsvLog::<FrameRow>::open_keeping(&dir.join(FRAMES_FILE), |rows| {
        let mut eyes: HashMap<FrameKey, u32> = HashMap::new();
        for r in &rows {
            *eyes.entry(r.key()).or_default() += 1;
        }
        rows.into_iter()
            .filter(|r| eyes[&r.key()] == EYES)
            .collect()
    })?;
    let done = rows.iter().map(FrameRow::key).collect();
    Ok((log, done))
}

/// quality.csv, keeping the points whose rows (every eye, the whole image and each band)
/// are all there, and those points.
fn open_quality_log(dir: &Path) -> Result<(CsvLog<QualityRow>, HashSet<PointKey>), BenchError> {
    let point_rows = 1 + crate::metrics::BANDS.len() as u32;
    let (log, rows) = CsvLog::<QualityRow>::open_keeping(&dir.join(QUALITY_FILE), |rows| {
        let mut count: HashMap<PointKey, u32> = HashMap::new();
        for r in &rows {
            *count.entry((r.scene.clone(), r.mode, r.spp)).or_default() += 1;
        }
        rows.into_iter()
            .filter(|r| count[&(r.scene.clone(), r.mode, r.spp)] == EYES * point_rows)
            .collect()
    })?;
    let done = rows
        .iter()
        .map(|r| (r.scene.clone(), r.mode, r.spp))
        .collect();
    Ok((log, done))
}

/// The plan's timed frames not yet measured.
fn pending_frames(plan: &BenchPlan, done: &HashSet<FrameKey>) -> Vec<FrameKey> {
    plan.frame_keys()
        .into_iter()
        .filter(|k| !done.contains(k))
        .collect()
}

/// The plan's sweep points not yet measured, scene by scene.
fn pending_points(plan: &BenchPlan, done: &HashSet<PointKey>) -> Vec<PointKey> {
    plan.scenes
        .iter()
        .flat_map(|s| {
            plan.sweep()
                .into_iter()
                .flat_map(move |spp| plan.modes().into_iter().map(move |m| (s.clone(), m, spp)))
        })
        .filter(|p| !done.contains(p))
        .collect()
}

/// Reads back everything the directory holds and writes the summary, report and plots.
fn write_report(
    ctx: &GpuContext,
    plan: &BenchPlan,
    dir: &Path,
    commands: &str,
) -> Result<(), BenchError> {
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

/// What the still run carries from scene to scene.
struct StillRun<'a> {
    ctx: &'a Arc<GpuContext>,
    plan: &'a BenchPlan,
    options: &'a RunOptions,
    gaze_trace: Option<&'a GazeTrace>,
    bar: ProgressBar,
    frames_log: CsvLog<FrameRow>,
    quality_log: CsvLog<QualityRow>,
    trace: TraceWriter,
    trace_path: PathBuf,
    metric: Option<Fvvdp>,
    /// Frames timed by this process, for [`RunOptions::abort_after_frames`].
    measured: u64,
}

/// One scene, loaded: its renderer, and each mode's eyes and layer config.
struct SceneBench<'a> {
    name: &'a str,
    renderer: Renderer,
    eyes: BTreeMap<Mode, Vec<EyeView>>,
    configs: BTreeMap<Mode, FoveationConfig>,
}

impl StillRun<'_> {
    /// Times the scene's pending `frames`, measures its pending sweep `points`, and writes its
    /// strip at `strip` if it is missing. A scene with nothing left is not loaded.
    fn scene(
        &mut self,
        scene_name: &str,
        strip: &Path,
        frames: &[&FrameKey],
        points: &[&PointKey],
    ) -> Result<(), BenchError> {
        if frames.is_empty() && points.is_empty() && strip.exists() {
            return Ok(());
        }
        self.bar.set_message(format!("{scene_name}: loading"));
        let mut scene = self.load(scene_name)?;
        let plan = self.plan;
        for unit in plan.units().iter().filter(|u| u.scene == *scene_name) {
            self.time_unit(&mut scene, unit, frames)?;
        }
        // Quality: the reference, then every pending point of the sweep.
        self.bar.set_message(format!("{scene_name}: reference"));
        let reference = self.reference(&mut scene)?;
        let shown = self.measure_points(&mut scene, points, &reference)?;
        if !strip.exists() {
            self.write_strip(&mut scene, strip, &reference, shown)?;
        }
        Ok(())
    }

    /// Loads the scene and works out each mode's eyes and config.
    fn load<'n>(&self, scene_name: &'n str) -> Result<SceneBench<'n>, BenchError> {
        let plan = self.plan;
        let (scene, renderer) = scene_renderer(self.ctx, plan, scene_name)?;
        // The trace mode's entry is its first row's eyes: its warm-up and quality frames.
        let eyes = plan
            .modes()
            .into_iter()
            .map(|m| {
                let eyes = mode_eyes(&scene, plan, m);
                match (m, self.gaze_trace) {
                    (Mode::Trace, Some(trace)) => (m, trace_eyes(&eyes, plan, trace, 0)),
                    _ => (m, eyes),
                }
            })
            .collect();
        let configs = plan
            .modes()
            .into_iter()
            .map(|m| (m, plan.config(m, plan.spp)))
            .collect();
        Ok(SceneBench {
            name: scene_name,
            renderer,
            eyes,
            configs,
        })
    }

    /// Timing of one unit: one warm-up frame per mode (pipeline compilation, first touch of
    /// memory), then the unit's pending frames, modes interleaved.
    fn time_unit(
        &mut self,
        scene: &mut SceneBench,
        unit: &Unit,
        frames: &[&FrameKey],
    ) -> Result<(), BenchError> {
        let todo: Vec<&FrameKey> = frames
            .iter()
            .copied()
            .filter(|k| k.repeat == unit.repeat)
            .collect();
        if todo.is_empty() {
            return Ok(());
        }
        self.bar
            .set_message(format!("{}: repeat {}", scene.name, unit.repeat + 1));
        for &mode in &unit.modes {
            let eyes = scene.eyes[&mode].clone();
            scene.measure(self.plan, mode, &eyes)?;
        }
        for key in todo {
            self.time_frame(scene, key)?;
        }
        Ok(())
    }

    /// Times frame `key` and appends its rows to frames.csv and its passes to the trace.
    fn time_frame(&mut self, scene: &mut SceneBench, key: &FrameKey) -> Result<(), BenchError> {
        let eyes = match (key.mode, self.gaze_trace) {
            (Mode::Trace, Some(t)) => {
                trace_eyes(&scene.eyes[&key.mode], self.plan, t, key.frame as u64)
            }
            _ => scene.eyes[&key.mode].clone(),
        };
        let wall_us = SystemTime::now()
            .duration_since(UNIX_EPOCH)
            .map_or(0, |d| d.as_micros() as u64);
        let start = Instant::now();
        let frame = scene.measure(self.plan, key.mode, &eyes)?;
        let cpu_ms = start.elapsed().as_secs_f64() * 1e3;
        let rows = FrameRow::from_frame(key, &frame, cpu_ms, wall_us);
        for row in &rows {
            self.frames_log.append(row)?;
        }
        let passes: Vec<(String, f64, f64)> = frame
            .stats
            .pass_ms
            .iter()
            .zip(&frame.stats.pass_start_ms)
            .map(|((name, ms), start)| (name.clone(), *start, *ms))
            .collect();
        self.trace
            .frame(&rows[0], &passes)
            .map_err(|e| BenchError::file(&self.trace_path, e))?;
        self.bar.inc(1);
        self.measured += 1;
        if self.options.abort_after_frames == Some(self.measured) {
            // As a kill would: no clean-up, nothing written after this point.
            std::process::abort();
        }
        Ok(())
    }

    /// The scene's converged reference (from the cache, or rendered into it).
    fn reference(&self, scene: &mut SceneBench) -> Result<Vec<f32>, BenchError> {
        let (plan, name) = (self.plan, scene.name);
        let eyes = &scene.eyes[&Mode::Regular];
        let path = quality::ReferenceKey::new(&scene.renderer, plan, name, eyes)
            .path(&self.options.reference_cache);
        let bar = &self.bar;
        quality::reference_image(
            &mut scene.renderer,
            plan,
            name,
            eyes,
            &path,
            &mut |done, all| bar.set_message(format!("{name}: reference {done}/{all}")),
        )
    }

    /// Measures the pending sweep points and appends their rows to quality.csv. Returns the
    /// points at the protocol's spp, whose images the strip shows.
    fn measure_points(
        &mut self,
        scene: &mut SceneBench,
        points: &[&PointKey],
        reference: &[f32],
    ) -> Result<BTreeMap<Mode, Point>, BenchError> {
        let plan = self.plan;
        let mut shown = BTreeMap::new();
        for &&(_, mode, spp) in points {
            self.bar
                .set_message(format!("{}: {} at {spp} spp", scene.name, mode.name()));
            let point = quality::measure_point(
                &mut scene.renderer,
                plan,
                scene.name,
                mode,
                spp,
                &scene.eyes[&mode],
                reference,
                self.metric.as_mut(),
            )?;
            for row in &point.rows {
                self.quality_log.append(row)?;
            }
            self.bar.inc(1);
            if spp == plan.spp {
                shown.insert(mode, point);
            }
        }
        Ok(shown)
    }

    /// Writes the scene's strip of the protocol's spp. Images measured in an earlier,
    /// interrupted run are rendered again (their numbers are already in quality.csv).
    fn write_strip(
        &self,
        scene: &mut SceneBench,
        strip: &Path,
        reference: &[f32],
        mut shown: BTreeMap<Mode, Point>,
    ) -> Result<(), BenchError> {
        let plan = self.plan;
        for mode in plan.modes() {
            if let std::collections::btree_map::Entry::Vacant(slot) = shown.entry(mode) {
                slot.insert(quality::measure_point(
                    &mut scene.renderer,
                    plan,
                    scene.name,
                    mode,
                    plan.spp,
                    &scene.eyes[&mode],
                    reference,
                    None,
                )?);
            }
        }
        images::write_strip(strip, plan, scene.name, reference, &shown)
    }

    /// Closes the progress bar, the trace and the logs.
    fn finish(self) -> Result<(), BenchError> {
        self.bar.finish_and_clear();
        self.trace
            .finish()
            .map_err(|e| BenchError::file(&self.trace_path, e))?;
        drop(self.frames_log);
        drop(self.quality_log);
        Ok(())
    }
}

impl SceneBench<'_> {
    /// Times one frame of `mode` seen by `eyes`, at the protocol's spp.
    fn measure(
        &mut self,
        plan: &BenchPlan,
        mode: Mode,
        eyes: &[EyeView],
    ) -> Result<Frame, BenchError> {
        self.renderer
            .frame(
                &FrameRequest {
                    settings: quality::settings(plan, plan.spp),
                    foveation: &self.configs[&mode],
                    eyes,
                    debug: DebugView::None,
                },
                FrameOptions::measure(),
            )
            .map(Option::unwrap)
            .map_err(BenchError::render(self.name))
    }
}
