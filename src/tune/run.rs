//! Runs a tune plan: the baselines, then configs drawn from the seed, then mutations of the
//! best ones within the budget, each judged on every scene and gaze and appended to the
//! candidates log as soon as it is measured (an interrupted run resumes from there); then
//! the front, its plot and the chosen config's TOML.

use super::files::{config_toml, write_rows, CandidateRow, TuneFiles};
use super::front::{best_within, pareto_front};
use super::measure::SceneJudge;
use super::plan::{Budget, TuneGaze, TunePlan};
use super::space::describe;
use super::TuneError;
use crate::bench::csv_log::CsvLog;
use crate::bench::plots::{self, Curve, CurvePoint, JodChart};
use crate::check::rng::Rng;
use crate::foveation::FoveationConfig;
use crate::gpu::GpuContext;
use crate::metrics::jod::Fvvdp;
use indicatif::{ProgressBar, ProgressStyle};
use std::path::PathBuf;
use std::sync::Arc;

/// How a run is carried out, beside what it measures (not in the plan).
pub struct TuneOptions {
    /// Where converged references are cached, shared between runs.
    pub reference_cache: PathBuf,
    /// The command line, written into the chosen config's header.
    pub command_line: String,
}

/// What a finished run found.
pub struct TuneOutcome {
    pub budget_ms: f64,
    pub chosen: CandidateRow,
    /// Fastest first.
    pub front: Vec<CandidateRow>,
    pub rows: Vec<CandidateRow>,
}

/// Parents a mutation picks from: this many of the best within the budget.
const PARENTS: usize = 3;
/// Draws before a mutation gives up finding a config not yet measured.
const FRESH_TRIES: usize = 32;

pub fn run(
    ctx: &Arc<GpuContext>,
    plan: &TunePlan,
    files: &TuneFiles,
    options: &TuneOptions,
) -> Result<TuneOutcome, TuneError> {
    plan.validate().map_err(TuneError::Plan)?;
    open_plan(plan, files)?;
    // Started first, so that a missing venv stops the run before anything is rendered.
    let mut metric = Fvvdp::start()?;
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
        }
        let (config, origin) = candidate(plan, index, &randoms, &rows);
        bar.set_message(describe(&config));
        let row = judge(plan, index, origin, &config, &mut judges, &mut metric)?;
        log.append(&row)?;
        rows.push(row);
        bar.inc(1);
    }
    bar.finish_and_clear();
    drop(log);
    finish(ctx, plan, files, options, rows)
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

/// The configs drawn at random from the seed, none a baseline or drawn twice.
fn random_configs(plan: &TunePlan) -> Vec<FoveationConfig> {
    let baselines = plan.space.baselines();
    let count = (plan.candidates as usize - baselines.len()) / 2;
    let mut seen: Vec<String> = baselines.iter().map(describe).collect();
    let mut rng = Rng::new(plan.seed);
    let mut out = Vec::new();
    for _ in 0..count * FRESH_TRIES {
        if out.len() == count {
            break;
        }
        let config = plan.space.random(&mut rng);
        let name = describe(&config);
        if !seen.contains(&name) {
            seen.push(name);
            out.push(config);
        }
    }
    out
}

/// Candidate `index` of the search: a baseline, a random draw, or a mutation of one of the
/// best configs measured before it (so the same seed and measurements give the same one).
fn candidate(
    plan: &TunePlan,
    index: u32,
    randoms: &[FoveationConfig],
    rows: &[CandidateRow],
) -> (FoveationConfig, String) {
    let baselines = plan.space.baselines();
    let i = index as usize;
    if let Some(config) = baselines.get(i) {
        return (config.clone(), "baseline".into());
    }
    if let Some(config) = randoms.get(i - baselines.len()) {
        return (config.clone(), "random".into());
    }
    let earlier: Vec<&CandidateRow> = rows.iter().filter(|r| r.index < index).collect();
    let budget = budget_ms(plan, rows).unwrap_or(f64::INFINITY);
    let mut parents: Vec<&CandidateRow> = earlier
        .iter()
        .copied()
        .filter(|r| r.gpu_ms <= budget && r.jod.is_finite())
        .collect();
    parents.sort_by(|a, b| b.jod.total_cmp(&a.jod));
    if parents.is_empty() {
        parents = earlier.clone();
        parents.sort_by(|a, b| a.gpu_ms.total_cmp(&b.gpu_ms));
    }
    parents.truncate(PARENTS);
    let mut rng = Rng::new(plan.seed ^ (index as u64).wrapping_mul(0x2545_f491_4f6c_dd1d));
    let mut fallback = None;
    for _ in 0..FRESH_TRIES {
        let parent = parents[rng.below(parents.len())];
        let Ok(config) = parent.foveation() else {
            continue;
        };
        let child = plan.space.mutate(&config, &mut rng);
        let name = describe(&child);
        let origin = format!("mutation of {}", parent.index);
        if !rows.iter().any(|r| r.config == name) {
            return (child, origin);
        }
        fallback.get_or_insert((child, origin));
    }
    // Every neighbour was measured: a fresh random draw instead.
    let fresh = plan.space.random(&mut rng);
    match rows.iter().any(|r| r.config == describe(&fresh)) {
        false => (fresh, "random".into()),
        true => fallback.unwrap_or((fresh, "random".into())),
    }
}

/// Judges `config` on every scene: JOD averaged over scenes and gazes, time the slowest
/// scene's median.
fn judge(
    plan: &TunePlan,
    index: u32,
    origin: String,
    config: &FoveationConfig,
    judges: &mut [SceneJudge],
    metric: &mut Fvvdp,
) -> Result<CandidateRow, TuneError> {
    let mut per_gaze = vec![0.0; TuneGaze::ALL.len()];
    let mut gpu_ms = f64::NAN;
    let mut paths_per_pixel = f64::NAN;
    for (s, judge) in judges.iter_mut().enumerate() {
        let score = judge.judge(plan, config, metric)?;
        for (sum, jod) in per_gaze.iter_mut().zip(&score.jod) {
            *sum += jod / plan.scenes.len() as f64;
        }
        gpu_ms = match s {
            0 => score.median_ms,
            _ => gpu_ms.max(score.median_ms),
        };
        if s == 0 {
            paths_per_pixel = score.paths_per_pixel;
        }
    }
    Ok(CandidateRow {
        index,
        origin,
        config: describe(config),
        gpu_ms,
        jod: per_gaze.iter().sum::<f64>() / per_gaze.len() as f64,
        jod_forward: per_gaze[0],
        jod_off_axis: per_gaze[1],
        jod_corner: per_gaze[2],
        paths_per_pixel,
        config_json: serde_json::to_string(config).unwrap_or_default(),
    })
}

/// The budget in milliseconds, once it is known (a regular budget needs its measurement).
pub fn budget_ms(plan: &TunePlan, rows: &[CandidateRow]) -> Option<f64> {
    match plan.budget {
        Budget::Ms(ms) => Some(ms),
        Budget::Regular(spp) => {
            let name = describe(&FoveationConfig::regular(spp));
            rows.iter().find(|r| r.config == name).map(|r| r.gpu_ms)
        }
    }
}

/// The front, its plot, and the chosen config.
fn finish(
    ctx: &Arc<GpuContext>,
    plan: &TunePlan,
    files: &TuneFiles,
    options: &TuneOptions,
    rows: Vec<CandidateRow>,
) -> Result<TuneOutcome, TuneError> {
    let budget = budget_ms(plan, &rows).unwrap_or(f64::NAN);
    let front: Vec<CandidateRow> = pareto_front(&rows)
        .into_iter()
        .map(|i| rows[i].clone())
        .collect();
    write_rows(&files.front, &front.iter().collect::<Vec<_>>()).map_err(TuneError::File)?;
    let chosen = best_within(&rows, budget).map(|i| rows[i].clone());
    plot(plan, files, &rows, &front, budget, chosen.as_ref())?;
    let Some(chosen) = chosen else {
        return Err(TuneError::NothingWithin {
            budget_ms: budget,
            fastest_ms: front.first().map_or(f64::NAN, |r| r.gpu_ms),
            front: files.front.display().to_string(),
        });
    };
    let config = chosen.foveation().map_err(TuneError::File)?;
    let regular = |spp: u32| {
        let name = describe(&FoveationConfig::regular(spp));
        rows.iter().find(|r| r.config == name)
    };
    let mut header = vec![
        format!("Tuned by: {}", options.command_line),
        format!(
            "On {} ({}), {}",
            ctx.info.name,
            ctx.info.driver,
            crate::bench::summary::utc_now()
        ),
        format!(
            "Judged on {} at {}x{} per eye ({}), gaze forward / off-axis (15 deg right, 10 down) / corner,",
            plan.scenes.join(", "),
            plan.width,
            plan.height,
            crate::bench::protocol::flag_value(&plan.fov)
        ),
        format!(
            "by FovVideoVDP (foveated, HTC Vive Pro photometry) against {}-spp references.",
            plan.reference_spp
        ),
        format!(
            "JOD {:.3} (forward {:.3}, off-axis {:.3}, corner {:.3}) at {:.2} ms GPU per eye; budget {:.2} ms.",
            chosen.jod, chosen.jod_forward, chosen.jod_off_axis, chosen.jod_corner, chosen.gpu_ms, budget
        ),
    ];
    header.extend(plan.space.spp.iter().filter_map(|&s| regular(s)).map(|r| {
        format!(
            "Same run, regular {}: JOD {:.3} at {:.2} ms.",
            r.config, r.jod, r.gpu_ms
        )
    }));
    std::fs::write(&files.config, config_toml(&config, &header))
        .map_err(|e| TuneError::File(format!("{}: {e}", files.config.display())))?;
    Ok(TuneOutcome {
        budget_ms: budget,
        chosen,
        front,
        rows,
    })
}

/// JOD against GPU ms: regular rendering and the thesis' layers as curves over spp, the
/// front as a line, every other config as a dot, the budget and the chosen config marked.
fn plot(
    plan: &TunePlan,
    files: &TuneFiles,
    rows: &[CandidateRow],
    front: &[CandidateRow],
    budget: f64,
    chosen: Option<&CandidateRow>,
) -> Result<(), TuneError> {
    let curve = |label: &str, configs: Vec<FoveationConfig>| Curve {
        label: label.to_string(),
        points: configs
            .iter()
            .zip(&plan.space.spp)
            .filter_map(|(c, &spp)| {
                let name = describe(c);
                rows.iter().find(|r| r.config == name).map(|r| CurvePoint {
                    ms: r.gpu_ms,
                    error: r.jod,
                    spp,
                })
            })
            .collect(),
    };
    let regular = curve(
        "regular (spp)",
        plan.space
            .spp
            .iter()
            .map(|&s| FoveationConfig::regular(s))
            .collect(),
    );
    let thesis = curve(
        "thesis layers (spp)",
        (plan.space.spp.iter())
            .map(|&s| FoveationConfig::thesis().with_spp(s))
            .collect(),
    );
    let front_curve = Curve {
        label: "Pareto front".into(),
        points: front
            .iter()
            .map(|r| CurvePoint {
                ms: r.gpu_ms,
                error: r.jod,
                spp: 0,
            })
            .collect(),
    };
    let scatter: Vec<(f64, f64)> = rows.iter().map(|r| (r.gpu_ms, r.jod)).collect();
    let title = format!(
        "{} at {}x{} per eye: JOD against GPU time",
        plan.scenes.join(", "),
        plan.width,
        plan.height
    );
    plots::jod_vs_time(
        &files.plot,
        &JodChart {
            title: &title,
            curves: &[regular, thesis, front_curve],
            scatter: &scatter,
            budget_ms: budget.is_finite().then_some(budget),
            chosen: chosen.map(|r| (r.gpu_ms, r.jod)),
        },
    )?;
    Ok(())
}
