//! Runs a tune plan: the baselines, then configs drawn from the seed, then mutations of the
//! best ones within the budget, each judged on every scene and gaze and appended to the
//! candidates log as soon as it is measured (an interrupted run resumes from there); then
//! the front, its plot and the chosen config's TOML.

use super::files::{config_toml, write_rows, CandidateRow, FrontRow, TuneFiles};
use super::front::{best_within, pareto_front, Measured};
use super::measure::{SceneJudge, Timing};
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
    pub chosen: FrontRow,
    /// Fastest first.
    pub front: Vec<FrontRow>,
    pub rows: Vec<CandidateRow>,
}

/// A measured config as the front sees it: its cost in ms (see [`costs`]) and its JOD.
#[derive(Clone, Copy)]
struct Point {
    cost_ms: f64,
    jod: f64,
}

impl Measured for Point {
    fn ms(&self) -> f64 {
        self.cost_ms
    }
    fn jod(&self) -> f64 {
        self.jod
    }
}

/// Each row's cost in ms and the budget: raw GPU ms against a budget in ms; with a budget of
/// regular rendering's time, each row's pace ratio (its time over the regular frames
/// interleaved with it) times regular rendering's own measured ms, which is the budget.
/// None while a regular budget's own row is not measured.
fn costs(plan: &TunePlan, rows: &[CandidateRow]) -> (Vec<Point>, Option<f64>) {
    let (scale, budget) = match plan.budget {
        Budget::Ms(ms) => (None, Some(ms)),
        Budget::Regular(spp) => {
            let name = describe(&FoveationConfig::regular(spp));
            let ms = rows.iter().find(|r| r.config == name).map(|r| r.gpu_ms);
            (Some(ms.unwrap_or(f64::NAN)), ms)
        }
    };
    let points = rows
        .iter()
        .map(|r| Point {
            cost_ms: scale.map_or(r.gpu_ms, |s| r.pace_ratio * s),
            jod: r.jod,
        })
        .collect();
    (points, budget)
}

/// A drawn config timed at more than this many budgets on the first scene is not judged
/// further: it cannot be chosen, and judging a slow config costs the most.
pub const OVER_BUDGET: f64 = 3.0;

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
            // A drawn config the device cannot render (a buffer over its limits) is a
            // measurement too: it is out of the search. A baseline that fails is not.
            Err(TuneError::Render { scene, problem })
                if index as usize >= first_configs(plan).len() =>
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
    let first = first_configs(plan);
    let count = (plan.candidates as usize - first.len()) / 2;
    let mut seen: Vec<String> = first.iter().map(|(c, _)| describe(c)).collect();
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

/// What every search measures first: the baselines, then the `--include` configs.
fn first_configs(plan: &TunePlan) -> Vec<(FoveationConfig, &'static str)> {
    let baselines = plan.space.baselines().into_iter().map(|c| (c, "baseline"));
    let included = plan.include.iter().map(|c| (c.clone(), "included"));
    baselines.chain(included).collect()
}

/// Candidate `index` of the search: a baseline, a random draw, or a mutation of one of the
/// best configs measured before it (so the same seed and measurements give the same one).
fn candidate(
    plan: &TunePlan,
    index: u32,
    randoms: &[FoveationConfig],
    rows: &[CandidateRow],
) -> (FoveationConfig, String) {
    let first = first_configs(plan);
    let i = index as usize;
    if let Some((config, origin)) = first.get(i) {
        return (config.clone(), origin.to_string());
    }
    if let Some(config) = randoms.get(i - first.len()) {
        return (config.clone(), "random".into());
    }
    let earlier: Vec<CandidateRow> = rows.iter().filter(|r| r.index < index).cloned().collect();
    let (points, budget) = costs(plan, &earlier);
    let budget = budget.unwrap_or(f64::INFINITY);
    let mut parents: Vec<usize> = (0..earlier.len())
        .filter(|&i| points[i].cost_ms <= budget && points[i].jod.is_finite())
        .collect();
    parents.sort_by(|&a, &b| points[b].jod.total_cmp(&points[a].jod));
    if parents.is_empty() {
        parents = (0..earlier.len()).collect();
        parents.sort_by(|&a, &b| points[a].cost_ms.total_cmp(&points[b].cost_ms));
    }
    parents.truncate(PARENTS);
    let parents: Vec<&CandidateRow> = parents.iter().map(|&i| &earlier[i]).collect();
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
    let pace = match plan.budget {
        Budget::Regular(spp) => Some(FoveationConfig::regular(spp)),
        Budget::Ms(_) => None,
    };
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
        jod_forward: f64::NAN,
        jod_off_axis: f64::NAN,
        jod_corner: f64::NAN,
        paths_per_pixel: f64::NAN,
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
    let pace = match plan.budget {
        Budget::Regular(spp) => Some(FoveationConfig::regular(spp)),
        Budget::Ms(_) => None,
    };
    let mut per_gaze = vec![0.0; TuneGaze::ALL.len()];
    let mut timings = Vec::new();
    let mut paths_per_pixel = f64::NAN;
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
                "jod": score.jod
            }),
        );
        for (sum, jod) in per_gaze.iter_mut().zip(&score.jod) {
            *sum += jod / plan.scenes.len() as f64;
        }
        timings.push(score.timing);
        if s == 0 {
            paths_per_pixel = score.paths_per_pixel;
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
        jod: per_gaze.iter().sum::<f64>() / per_gaze.len() as f64,
        jod_forward: per_gaze[0],
        jod_off_axis: per_gaze[1],
        jod_corner: per_gaze[2],
        paths_per_pixel,
        scenes_json: serde_json::Value::Object(scenes).to_string(),
        config_json: serde_json::to_string(config).unwrap_or_default(),
    })
}

/// The front, its plot, and the chosen config.
fn finish(
    ctx: &Arc<GpuContext>,
    plan: &TunePlan,
    files: &TuneFiles,
    options: &TuneOptions,
    rows: Vec<CandidateRow>,
) -> Result<TuneOutcome, TuneError> {
    let (points, budget) = costs(plan, &rows);
    let budget = budget.unwrap_or(f64::NAN);
    let front: Vec<FrontRow> = pareto_front(&points)
        .into_iter()
        .map(|i| FrontRow::new(&rows[i], points[i].cost_ms))
        .collect();
    write_rows(&files.front, &front).map_err(TuneError::File)?;
    let chosen = best_within(&points, budget).map(|i| FrontRow::new(&rows[i], points[i].cost_ms));
    plot(plan, files, &rows, &points, &front, budget, chosen.as_ref())?;
    let Some(chosen) = chosen else {
        return Err(TuneError::NothingWithin {
            budget_ms: budget,
            fastest_ms: front.first().map_or(f64::NAN, |r| r.cost_ms),
            front: files.front.display().to_string(),
        });
    };
    let config: FoveationConfig = serde_json::from_str(&chosen.config_json)
        .map_err(|e| TuneError::File(format!("the chosen config does not read back ({e})")))?;
    let regular = |spp: u32| {
        let name = describe(&FoveationConfig::regular(spp));
        rows.iter().find(|r| r.config == name)
    };
    let mut header = vec![
        format!("Tuned by: {}", options.command_line),
        format!(
            "On {} ({}), {}, by fovea {}",
            ctx.info.name,
            ctx.info.driver,
            crate::bench::summary::utc_now(),
            crate::build_version()
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
            "JOD {:.3} (forward {:.3}, off-axis {:.3}, corner {:.3}) at {:.2} ms GPU per eye; budget {:.2} ms{}.",
            chosen.jod,
            chosen.jod_forward,
            chosen.jod_off_axis,
            chosen.jod_corner,
            chosen.cost_ms,
            budget,
            match plan.budget {
                Budget::Regular(spp) => format!(
                    " (regular {spp} spp's; {:.3}x its {}, interleaved)",
                    chosen.pace_ratio,
                    match plan.cost {
                        super::plan::Cost::GpuTime => "time",
                        super::plan::Cost::Samples => "traced paths",
                    }
                ),
                Budget::Ms(_) => String::new(),
            }
        ),
    ];
    header.extend(
        plan.space
            .baseline_spp
            .iter()
            .filter_map(|&s| regular(s))
            .map(|r| {
                format!(
                    "Same run, regular {}: JOD {:.3} at {:.2} ms.",
                    r.config, r.jod, r.gpu_ms
                )
            }),
    );
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
    points: &[Point],
    front: &[FrontRow],
    budget: f64,
    chosen: Option<&FrontRow>,
) -> Result<(), TuneError> {
    let curve = |label: &str, configs: Vec<FoveationConfig>| Curve {
        label: label.to_string(),
        points: configs
            .iter()
            .zip(&plan.space.baseline_spp)
            .filter_map(|(c, &spp)| {
                let name = describe(c);
                let i = rows.iter().position(|r| r.config == name)?;
                Some(CurvePoint {
                    ms: points[i].cost_ms,
                    error: points[i].jod,
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
        (plan.space.baseline_spp.iter())
            .map(|&s| FoveationConfig::thesis().with_spp(s))
            .collect(),
    );
    let front_curve = Curve {
        label: "Pareto front".into(),
        points: front
            .iter()
            .map(|r| CurvePoint {
                ms: r.cost_ms,
                error: r.jod,
                spp: 0,
            })
            .collect(),
    };
    let scatter: Vec<(f64, f64)> = points.iter().map(|p| (p.cost_ms, p.jod)).collect();
    let scenes = match plan.scenes.len() {
        1 | 2 => plan.scenes.join(", "),
        n => format!("{n} scenes"),
    };
    let title = format!(
        "{scenes} at {}x{} per eye: JOD against GPU time",
        plan.width, plan.height
    );
    plots::jod_vs_time(
        &files.plot,
        &JodChart {
            title: &title,
            curves: &[regular, thesis, front_curve],
            scatter: &scatter,
            budget_ms: budget.is_finite().then_some(budget),
            chosen: chosen.map(|r| (r.cost_ms, r.jod)),
        },
    )?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::{FovChoice, Integrator, Traversal};

    fn plan(seed: u64) -> TunePlan {
        TunePlan {
            scenes: vec!["cornell".into()],
            width: 64,
            height: 72,
            fov: FovChoice::ViveProEye,
            budget: Budget::Regular(1),
            cost: super::super::plan::Cost::GpuTime,
            candidates: 20,
            seed,
            frames: 1,
            reference_spp: 256,
            integrator: Integrator::Pt,
            max_bounces: 8,
            traversal: Traversal::Software,
            space: super::super::space::Space::standard(),
            include: vec![FoveationConfig::thesis().with_spp(8)],
        }
    }

    fn row(index: u32, config: &FoveationConfig, pace_ratio: f64, jod: f64) -> CandidateRow {
        CandidateRow {
            index,
            origin: String::new(),
            config: describe(config),
            gpu_ms: 100.0 * pace_ratio,
            pace_ratio,
            jod,
            jod_forward: jod,
            jod_off_axis: jod,
            jod_corner: jod,
            paths_per_pixel: 1.0,
            scenes_json: String::new(),
            config_json: serde_json::to_string(config).unwrap(),
        }
    }

    #[test]
    fn the_seed_decides_the_search_and_measurements_steer_it() {
        let (a, b) = (plan(1), plan(2));
        assert!(a.validate().is_ok());
        // Baselines, then the included config, then seeded draws.
        let first = first_configs(&a);
        assert_eq!(first.len(), 7);
        assert_eq!(
            first[6],
            (FoveationConfig::thesis().with_spp(8), "included")
        );
        assert_eq!(random_configs(&a), random_configs(&a));
        assert_ne!(random_configs(&a), random_configs(&b));
        assert_eq!(random_configs(&a).len(), (20 - 7) / 2);

        // Measured so far: regular 1 spp (the budget) and two configs, one within it.
        let cheap = FoveationConfig::thesis().with_spp(2);
        let dear = FoveationConfig::thesis().with_spp(16);
        let rows = vec![
            row(0, &FoveationConfig::regular(1), 1.0, 8.0),
            row(1, &cheap, 0.5, 8.5),
            row(2, &dear, 1.5, 9.5),
        ];
        let (points, budget) = costs(&a, &rows);
        assert_eq!(budget, Some(100.0));
        assert_eq!(points[1].cost_ms, 50.0);
        // A mutation's parent is the best within the budget (regular or cheap), never dear;
        // the same seed and rows give the same child.
        let index = 19;
        let (child, origin) = candidate(&a, index, &random_configs(&a), &rows);
        assert_eq!(candidate(&a, index, &random_configs(&a), &rows).0, child);
        assert!(
            origin == "mutation of 0" || origin == "mutation of 1",
            "{origin}"
        );
        assert!(rows.iter().all(|r| r.config != describe(&child)));
    }
}
