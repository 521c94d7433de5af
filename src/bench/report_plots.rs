//! The plots of a still run, per scene: frame rate per frame, mean frame rate ± standard
//! deviation, relMSE against GPU time (whole image and fovea), and JOD against GPU time.

use super::error::BenchError;
use super::plots::{self, Curve, CurvePoint, DotWhisker, Series};
use super::protocol::{BenchPlan, Mode};
use super::rows::FrameRow;
use super::summary::{SceneSummary, Summary};
use std::collections::BTreeMap;
use std::path::Path;

/// Writes every scene's plots into `dir`/plots.
pub fn write_plots(
    dir: &Path,
    plan: &BenchPlan,
    frames: &[FrameRow],
    summary: &Summary,
) -> Result<(), BenchError> {
    let plots_dir = dir.join("plots");
    for scene in &summary.scenes {
        frame_rate_plot(&plots_dir, plan, frames, &scene.scene)?;
        mean_std_plot(&plots_dir, scene)?;
        error_time_plots(&plots_dir, plan, scene)?;
        jod_plot(&plots_dir, plan, scene)?;
    }
    Ok(())
}

/// The thesis' per-frame line graph: one line per mode and repeat.
fn frame_rate_plot(
    plots_dir: &Path,
    plan: &BenchPlan,
    frames: &[FrameRow],
    name: &str,
) -> Result<(), BenchError> {
    let mut runs: BTreeMap<(Mode, u32), Vec<(u32, f64)>> = BTreeMap::new();
    for r in frames
        .iter()
        .filter(|r| r.scene == *name && r.eye == "left")
    {
        runs.entry((r.mode, r.repeat))
            .or_default()
            .push((r.frame, 1000.0 / r.frame_gpu_ms));
    }
    let series: Vec<Series> = runs
        .into_iter()
        .map(|((mode, repeat), mut fps)| {
            fps.sort_by_key(|p| p.0);
            Series {
                label: match plan.repeats(mode) {
                    1 => mode.name().to_string(),
                    _ => format!("{} r{}", mode.name(), repeat + 1),
                },
                values: fps.into_iter().map(|p| p.1).collect(),
            }
        })
        .collect();
    plots::frame_rate_lines(
        &plots_dir.join(format!("{name}-frames")),
        &format!("{name}: frame rate per frame (GPU time of both eyes)"),
        &series,
    )?;
    Ok(())
}

/// The thesis' dot-and-whisker plot: each mode's mean frame rate ± its standard deviation.
fn mean_std_plot(plots_dir: &Path, scene: &SceneSummary) -> Result<(), BenchError> {
    let name = &scene.scene;
    let dots: Vec<DotWhisker> = scene
        .modes
        .iter()
        .filter_map(|m| {
            m.rates.map(|r| DotWhisker {
                label: m.mode.name().to_string(),
                mean: r.fps.mean,
                std: r.fps.std,
            })
        })
        .collect();
    plots::mean_std_dots(
        &plots_dir.join(format!("{name}-mean-std")),
        &format!("{name}: mean frame rate ± standard deviation"),
        "frames per second",
        &dots,
    )?;
    Ok(())
}

/// relMSE against GPU time over the sweep, one curve per mode: of the whole image, and of
/// the fovea (0-6°).
fn error_time_plots(
    plots_dir: &Path,
    plan: &BenchPlan,
    scene: &SceneSummary,
) -> Result<(), BenchError> {
    let name = &scene.scene;
    for (region, what) in [("whole", "whole image"), ("0-6", "fovea (0-6°)")] {
        let curves: Vec<Curve> = plan
            .modes()
            .into_iter()
            .map(|mode| Curve {
                label: mode.name().to_string(),
                points: scene
                    .quality
                    .iter()
                    .filter(|q| q.mode == mode && q.region == region && q.pixels > 0)
                    .map(|q| CurvePoint {
                        ms: q.frame_gpu_ms,
                        error: q.rel_mse,
                        spp: q.spp,
                    })
                    .collect(),
            })
            .collect();
        let file = if region == "whole" { "whole" } else { "fovea" };
        plots::error_vs_time(
            &plots_dir.join(format!("{name}-error-time-{file}")),
            &format!("{name}: relMSE of the {what} against GPU time"),
            "relMSE",
            &curves,
        )?;
    }
    Ok(())
}

/// Perceptual quality against GPU time: regular rendering over the sweep's spp is the
/// baseline curve, each foveated mode a curve of points beside it.
fn jod_plot(plots_dir: &Path, plan: &BenchPlan, scene: &SceneSummary) -> Result<(), BenchError> {
    let curves: Vec<Curve> = plan
        .modes()
        .into_iter()
        .map(|mode| Curve {
            label: mode.name().to_string(),
            points: (scene.quality.iter())
                .filter(|q| q.mode == mode && q.region == "whole")
                .filter_map(|q| {
                    q.jod.map(|jod| CurvePoint {
                        ms: q.frame_gpu_ms,
                        error: jod,
                        spp: q.spp,
                    })
                })
                .collect(),
        })
        .collect();
    let name = &scene.scene;
    plots::jod_vs_time(
        &plots_dir.join(format!("{name}-jod-time")),
        &plots::JodChart {
            title: &format!("{name}: FovVideoVDP JOD against GPU time (spp at each point)"),
            curves: &curves,
            scatter: &[],
            budget_ms: None,
            chosen: None,
        },
    )?;
    Ok(())
}
