//! The end of a search: the Pareto front and its plot, and the chosen config written as a
//! foveation TOML whose header says how it was chosen.

use super::cost::{costs, Point};
use super::error::TuneError;
use super::files::{config_toml, write_rows, CandidateRow, FrontRow, TuneFiles};
use super::front::{best_within, pareto_front};
use super::plan::{Budget, Cost, Objective, TuneOptions, TunePlan};
use super::space::describe;
use crate::bench::plots::{self, Curve, CurvePoint, JodChart};
use crate::foveation::FoveationConfig;
use crate::gpu::GpuContext;
use std::sync::Arc;

/// What a finished run found.
pub struct TuneOutcome {
    pub budget_ms: f64,
    pub chosen: FrontRow,
    /// Fastest first.
    pub front: Vec<FrontRow>,
    pub rows: Vec<CandidateRow>,
}

/// The front, its plot, and the chosen config.
pub fn finish(
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
    let header = config_header(ctx, plan, options, &rows, &chosen, budget);
    std::fs::write(&files.config, config_toml(&config, &header))
        .map_err(|e| TuneError::File(format!("{}: {e}", files.config.display())))?;
    Ok(TuneOutcome {
        budget_ms: budget,
        chosen,
        front,
        rows,
    })
}

/// The chosen config's header: how it was tuned, on what, by what measure, what it scored
/// and cost, and what regular rendering scored in the same run.
fn config_header(
    ctx: &GpuContext,
    plan: &TunePlan,
    options: &TuneOptions,
    rows: &[CandidateRow],
    chosen: &FrontRow,
    budget: f64,
) -> Vec<String> {
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
            "Judged on {} at {}x{} per eye ({}{}), gaze forward / off-axis (15 deg right, 10 down) / corner,",
            plan.scenes.join(", "),
            plan.width,
            plan.height,
            crate::bench::protocol::flag_value(&plan.fov),
            plan.window_phrase()
        ),
        format!(
            "by FovVideoVDP (foveated, {} photometry) against {}-spp references.",
            plan.profile.name(),
            plan.reference_spp
        ),
        chosen_line(plan, chosen, budget),
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
    header
}

/// What the chosen config scored and cost, against the budget.
fn chosen_line(plan: &TunePlan, chosen: &FrontRow, budget: f64) -> String {
    format!(
        "JOD {:.3} ({}forward {:.3}, off-axis {:.3}, corner {:.3}) at {:.2} ms GPU per eye; budget {:.2} ms{}.",
        chosen.jod,
        match plan.objective {
            Objective::Still => "",
            Objective::Motion => "in motion with history; first frames: ",
        },
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
                    Cost::GpuTime => "time",
                    Cost::Samples => "traced paths",
                }
            ),
            Budget::Ms(_) => String::new(),
        }
    )
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
