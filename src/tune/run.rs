//! Runs a tune plan: the baselines, then configs drawn from the seed, then mutations of the
//! best ones within the budget, each judged on every scene and gaze and appended to the
//! candidates log as soon as it is measured (an interrupted run resumes from there); then
//! the front, its plot and the chosen config's TOML.

use super::cost::{costs, pace_config};
use super::error::TuneError;
use super::files::{CandidateRow, TuneFiles};
use super::finish::{finish, TuneOutcome};
use super::measure::{SceneJudge, Timing};
use super::plan::{Budget, Objective, TuneGaze, TuneOptions, TunePlan};
use super::search::{candidate, first_configs, random_configs};
use super::space::describe;
use crate::bench::csv_log::CsvLog;
use crate::foveation::FoveationConfig;
use crate::gpu::GpuContext;
use crate::metrics::jod::Fvvdp;
use indicatif::{ProgressBar, ProgressStyle};
use std::sync::Arc;

/// A drawn config timed at more than this many budgets on the first scene is not judged
/// further: it cannot be chosen, and judging a slow config costs the most.
pub const OVER_BUDGET: f64 = 3.0;

pub fn run(
    ctx: &Arc<GpuContext>,
    plan: &TunePlan,
    files: &TuneFiles,
    options: &TuneOptions,
) -> Result<TuneOutcome, TuneError> {
    plan.validate().map_err(TuneError::Plan)?;
    open_plan(plan, files)?;
    // Started first, so that a missing venv stops the run before anything is rendered.
    let mut metric = Fvvdp::start_for(plan.profile)?;
    let (mut log, mut rows) = CsvLog::<CandidateRow>::open(&files.candidates)?;
    rows.sort_by_key(|r| r.index);

    let bar = ProgressBar::new(plan.candidates as u64);
    bar.set_style(
        ProgressStyle::with_template("{bar:40} {pos}/{len} {elapsed_precise} (eta {eta}) {msg}")
            .expect("a valid template"),
    );
    bar.set_position(rows.len() as u64);
    let mut judges: Vec<SceneJudge> = Vec::new();
    let randoms = random_configs(plan);
    for index in 0..plan.candidates {
        if rows.iter().any(|r| r.index == index) {
            continue;
        }
        if judges.is_empty() {
            judges = scene_judges(ctx, plan, options, &bar)?;
        }
        let (config, origin) = candidate(plan, index, &randoms, &rows);
        bar.set_message(describe(&config));
        let measured = match over_budget(plan, index, &origin, &config, &mut judges[0], &rows) {
            Ok(Some(row)) => Ok(row),
            Ok(None) => judge(
                plan,
                index,
                origin.clone(),
                &config,
                &mut judges,
                &mut metric,
            ),
            Err(e) => Err(e),
        };
        let row = match measured {
            // A drawn or included config the device cannot render (a buffer over its
            // limits) is a measurement too: it is out of the search, its row says why. A
            // baseline that fails is not: without the baselines nothing can be chosen.
            Err(TuneError::Render { scene, problem })
                if index as usize >= plan.space.baselines().len() =>
            {
                unjudged(
                    index,
                    format!("{origin}; cannot render on {scene}: {problem}"),
                    &config,
                    f64::NAN,
                    f64::NAN,
                )
            }
            other => other?,
        };
        log.append(&row)?;
        rows.push(row);
        bar.inc(1);
    }
    bar.finish_and_clear();
    drop(log);
    finish(ctx, plan, files, options, rows)
}

/// Every scene of the plan, loaded with its reference (the first config to measure loads
/// them: a finished run that resumes renders nothing).
fn scene_judges(
    ctx: &Arc<GpuContext>,
    plan: &TunePlan,
    options: &TuneOptions,
    bar: &ProgressBar,
) -> Result<Vec<SceneJudge>, TuneError> {
    let mut judges = Vec::new();
    for name in &plan.scenes {
        bar.set_message(format!("{name}: reference"));
        judges.push(SceneJudge::new(
            ctx,
            plan,
            name,
            &options.reference_cache,
            &mut |done, all| bar.set_message(format!("{name}: reference {done}/{all}")),
        )?);
    }
    Ok(judges)
}

/// Writes the plan beside the results, or checks that the one there is this one.
fn open_plan(plan: &TunePlan, files: &TuneFiles) -> Result<(), TuneError> {
    let file_error =
        |e: &dyn std::fmt::Display| TuneError::File(format!("{}: {e}", files.plan.display()));
    if let Some(dir) = files.config.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir)
            .map_err(|e| TuneError::File(format!("{}: {e}", dir.display())))?;
    }
    if files.plan.exists() {
        let text = std::fs::read_to_string(&files.plan).map_err(|e| file_error(&e))?;
        let earlier: Option<TunePlan> = serde_json::from_str(&text).ok();
        if earlier.as_ref() != Some(plan) {
            return Err(TuneError::Plan(format!(
                "{} holds another search's results (a different plan: scenes, size, budget, \
                 seed, candidates or space); give another --out, or delete {} and {} to start \
                 over",
                files.candidates.display(),
                files.plan.display(),
                files.candidates.display()
            )));
        }
        return Ok(());
    }
    let text = serde_json::to_string_pretty(plan).map_err(|e| file_error(&e))?;
    std::fs::write(&files.plan, text).map_err(|e| file_error(&e))
}

/// A drawn (not baseline or included) config that, timed alone on the first scene, takes
/// more than [`OVER_BUDGET`] budgets: its row, with no JOD. None: judge it.
fn over_budget(
    plan: &TunePlan,
    index: u32,
    origin: &str,
    config: &FoveationConfig,
    judge: &mut SceneJudge,
    rows: &[CandidateRow],
) -> Result<Option<CandidateRow>, TuneError> {
    let drawn = index as usize >= first_configs(plan).len();
    let (_, Some(budget)) = costs(plan, rows) else {
        return Ok(None);
    };
    if !drawn {
        return Ok(None);
    }
    let pace = pace_config(plan);
    let timing = judge.time(plan, config, pace.as_ref())?;
    let ratio = Timing::ratio(&[timing], plan.cost);
    let (cost, limit) = match plan.budget {
        Budget::Regular(_) => (ratio, OVER_BUDGET),
        Budget::Ms(_) => (timing.ms, OVER_BUDGET * budget),
    };
    if cost <= limit {
        return Ok(None);
    }
    let why = format!(
        "{origin}; over {OVER_BUDGET}x the budget on {}: not judged",
        judge.name
    );
    Ok(Some(unjudged(index, why, config, timing.ms, ratio)))
}

/// The row of a config measured without a JOD, saying why.
fn unjudged(
    index: u32,
    origin: String,
    config: &FoveationConfig,
    gpu_ms: f64,
    pace_ratio: f64,
) -> CandidateRow {
    CandidateRow {
        index,
        origin,
        config: describe(config),
        gpu_ms,
        pace_ratio,
        jod: f64::NAN,
        jod_motion: f64::NAN,
        jod_forward: f64::NAN,
        jod_off_axis: f64::NAN,
        jod_corner: f64::NAN,
        paths_per_pixel: f64::NAN,
        rays_per_pixel: f64::NAN,
        scenes_json: String::new(),
        config_json: serde_json::to_string(config).unwrap_or_default(),
    }
}

/// Judges `config` on every scene: JOD averaged over scenes and gazes, time the mean of the
/// scenes' medians.
fn judge(
    plan: &TunePlan,
    index: u32,
    origin: String,
    config: &FoveationConfig,
    judges: &mut [SceneJudge],
    metric: &mut Fvvdp,
) -> Result<CandidateRow, TuneError> {
    let pace = pace_config(plan);
    let mut per_gaze = vec![0.0; TuneGaze::ALL.len()];
    let mut motion = 0.0;
    let mut timings = Vec::new();
    let (mut paths_per_pixel, mut rays_per_pixel) = (f64::NAN, f64::NAN);
    let mut scenes = serde_json::Map::new();
    for (s, judge) in judges.iter_mut().enumerate() {
        let score = judge.judge(plan, config, pace.as_ref(), metric)?;
        scenes.insert(
            judge.name.clone(),
            serde_json::json!({
                "gpu_ms": score.timing.ms,
                "pace_ms": score.timing.pace_ms,
                "paths": score.timing.samples,
                "pace_paths": score.timing.pace_samples,
                "jod": score.jod,
                "jod_motion": score.motion_jod
            }),
        );
        motion += score.motion_jod / plan.scenes.len() as f64;
        for (sum, jod) in per_gaze.iter_mut().zip(&score.jod) {
            *sum += jod / plan.scenes.len() as f64;
        }
        timings.push(score.timing);
        if s == 0 {
            (paths_per_pixel, rays_per_pixel) = (score.paths_per_pixel, score.rays_per_pixel);
        }
    }
    // Over the scenes together, as a session mixing them would spend it: a ratio per scene
    // and the worst of them would let one scene's timing noise decide.
    let gpu_ms = timings.iter().map(|t| t.ms).sum::<f64>() / plan.scenes.len() as f64;
    let pace_ratio = Timing::ratio(&timings, plan.cost);
    Ok(CandidateRow {
        index,
        origin,
        config: describe(config),
        gpu_ms,
        pace_ratio,
        jod: match plan.objective {
            Objective::Still => per_gaze.iter().sum::<f64>() / per_gaze.len() as f64,
            Objective::Motion => motion,
        },
        jod_motion: motion,
        jod_forward: per_gaze[0],
        jod_off_axis: per_gaze[1],
        jod_corner: per_gaze[2],
        paths_per_pixel,
        rays_per_pixel,
        scenes_json: serde_json::Value::Object(scenes).to_string(),
        config_json: serde_json::to_string(config).unwrap_or_default(),
    })
}
