//! A motion run's summary.json, report.md and plots, from its rows (motion.csv) alone.

use super::script::{MotionScript, Sequence};
use crate::bench::error::BenchError;
use crate::bench::files::{
    animation_path, ANIMATION_FRAME_MS, COMMANDS_FILE, MOTION_FILE, PLAN_FILE,
};
use crate::bench::plots::{per_frame_lines, Series};
use crate::bench::protocol::{flag_value, BenchPlan, EYES};
use crate::bench::report_head::{header, layers_text, ReportHead};
use crate::bench::rows::{MotionJodRow, MotionRow};
use crate::bench::summary::{mean, utc_now, Device};
use crate::gpu::DeviceInfo;
use crate::metrics::BANDS;
use serde::Serialize;
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::Path;

#[derive(Clone, Debug, Serialize)]
pub struct MotionSummary {
    pub fovea_version: String,
    pub commands: Vec<String>,
    pub written_at: String,
    /// Every sequence of every scene was measured.
    pub complete: bool,
    pub rows: u64,
    pub expected_rows: u64,
    pub device: Device,
    pub parameters: BenchPlan,
    pub scenes: Vec<MotionScene>,
}

#[derive(Clone, Debug, Serialize)]
pub struct MotionScene {
    pub scene: String,
    pub sequences: Vec<SequenceSummary>,
}

#[derive(Clone, Debug, Serialize)]
pub struct SequenceSummary {
    pub sequence: String,
    pub temporal: bool,
    pub spp: u32,
    pub frames: u32,
    /// Mean GPU ms of a frame (both eyes), and of its temporal and denoise passes.
    pub gpu_ms: f64,
    pub temporal_ms: f64,
    pub regions: Vec<RegionSummary>,
    /// FovVideoVDP's JOD of the sequence as a video, mean of both eyes (None where it was
    /// not measured: no venv).
    pub jod: Option<f64>,
}

/// Means over the sequence's frames and both eyes; a region no frame saw is left out.
#[derive(Clone, Debug, Serialize)]
pub struct RegionSummary {
    pub region: String,
    pub rel_mse: f64,
    /// Over the second half of the frames: after the history has had time to fill.
    pub rel_mse_settled: f64,
    /// Over frames 1 onwards (frame 0 has no frame before it).
    pub flicker: f64,
}

/// Regions in reading order: the whole image, then the bands outward.
fn region_names() -> Vec<&'static str> {
    std::iter::once("whole")
        .chain(BANDS.iter().map(|b| b.name))
        .collect()
}

pub fn summarize(
    plan: &BenchPlan,
    device: &DeviceInfo,
    commands: &[&str],
    rows: &[MotionRow],
    jods: &[MotionJodRow],
) -> MotionSummary {
    let sequences = Sequence::all(plan.spp);
    let scenes = plan
        .scenes
        .iter()
        .map(|scene| MotionScene {
            scene: scene.clone(),
            sequences: sequences
                .iter()
                .filter_map(|s| {
                    let name = s.name();
                    let mine: Vec<&MotionRow> = rows
                        .iter()
                        .filter(|r| r.scene == *scene && r.sequence == name)
                        .collect();
                    let jod: Vec<f64> = (jods.iter())
                        .filter(|j| j.scene == *scene && j.sequence == name)
                        .map(|j| j.jod)
                        .collect();
                    (!mine.is_empty()).then(|| SequenceSummary {
                        jod: (jod.len() as u32 == EYES).then(|| mean(jod.iter().copied())),
                        ..sequence_summary(s, plan.frames, &mine)
                    })
                })
                .collect(),
        })
        .collect();
    let expected = plan.scenes.len() as u64
        * sequences.len() as u64
        * (plan.frames * EYES) as u64
        * region_names().len() as u64;
    MotionSummary {
        fovea_version: crate::build_version(),
        commands: commands.iter().map(|c| c.to_string()).collect(),
        written_at: utc_now(),
        complete: rows.len() as u64 == expected,
        rows: rows.len() as u64,
        expected_rows: expected,
        device: Device::from(device),
        parameters: plan.clone(),
        scenes,
    }
}

fn sequence_summary(s: &Sequence, frames: u32, rows: &[&MotionRow]) -> SequenceSummary {
    // One timing per frame: the whole image's left-eye row carries it.
    let per_frame: Vec<&&MotionRow> = rows
        .iter()
        .filter(|r| r.region == "whole" && r.eye == "left")
        .collect();
    let regions = region_names()
        .into_iter()
        .filter_map(|region| {
            let seen: Vec<&&MotionRow> = rows
                .iter()
                .filter(|r| r.region == region && r.pixels > 0)
                .collect();
            (!seen.is_empty()).then(|| RegionSummary {
                region: region.to_string(),
                rel_mse: mean(seen.iter().map(|r| r.rel_mse)),
                rel_mse_settled: mean(
                    seen.iter()
                        .filter(|r| r.frame >= frames / 2)
                        .map(|r| r.rel_mse),
                ),
                flicker: mean(seen.iter().filter_map(|r| r.flicker)),
            })
        })
        .collect();
    SequenceSummary {
        sequence: s.name(),
        temporal: s.temporal,
        spp: s.spp,
        frames: per_frame.len() as u32,
        gpu_ms: mean(per_frame.iter().map(|r| r.frame_gpu_ms)),
        temporal_ms: mean(per_frame.iter().map(|r| r.temporal_ms)),
        regions,
        jod: None,
    }
}

/// Writes summary.json, report.md and the plots of a motion run into `dir`.
pub fn write_all(
    dir: &Path,
    plan: &BenchPlan,
    script: &MotionScript,
    device: &DeviceInfo,
    commands: &[&str],
    rows: &[MotionRow],
    jods: &[MotionJodRow],
) -> Result<(), BenchError> {
    let summary = summarize(plan, device, commands, rows, jods);
    let path = dir.join("summary.json");
    let json = serde_json::to_string_pretty(&summary).expect("summaries serialize");
    std::fs::write(&path, json).map_err(|e| BenchError::file(&path, e))?;
    write_plots(dir, plan, rows)?;
    let path = dir.join("report.md");
    std::fs::write(&path, markdown(dir, script, &summary)).map_err(|e| BenchError::file(&path, e))
}

/// Per scene and region: error and flicker over the frames, a line per sequence (the mean
/// of both eyes).
fn write_plots(dir: &Path, plan: &BenchPlan, rows: &[MotionRow]) -> Result<(), BenchError> {
    let plots = dir.join("plots");
    for scene in &plan.scenes {
        for region in region_names() {
            for (what, file, value) in [
                (
                    "relMSE",
                    "error",
                    (|r: &MotionRow| Some(r.rel_mse)) as fn(&MotionRow) -> Option<f64>,
                ),
                ("flicker", "flicker", |r: &MotionRow| r.flicker),
            ] {
                let series: Vec<Series> = Sequence::all(plan.spp)
                    .iter()
                    .map(|s| {
                        let name = s.name();
                        let mut per_frame: BTreeMap<u32, Vec<f64>> = BTreeMap::new();
                        for r in rows.iter().filter(|r| {
                            r.scene == *scene
                                && r.sequence == name
                                && r.region == region
                                && r.pixels > 0
                        }) {
                            per_frame.entry(r.frame).or_default().extend(value(r));
                        }
                        Series {
                            label: name,
                            values: (0..plan.frames)
                                .map(|k| {
                                    per_frame
                                        .get(&k)
                                        .map_or(f64::NAN, |v| mean(v.iter().copied()))
                                })
                                .collect(),
                        }
                    })
                    .collect();
                let band = if region == "whole" {
                    "whole image".to_string()
                } else {
                    format!("{region}° from the gaze")
                };
                per_frame_lines(
                    &plots.join(format!("{scene}-motion-{file}-{region}")),
                    &format!("{scene}: {what} per frame, {band}"),
                    what,
                    &series,
                )?;
            }
        }
    }
    Ok(())
}

fn fmt(v: f64) -> String {
    if v.is_finite() {
        format!("{v:.3e}")
    } else {
        "–".into()
    }
}

/// The report: what ran, then per scene the sequences' cost, error and flicker per band, the
/// history's effect as ratios, the plots and the animation.
pub fn markdown(dir: &Path, script: &MotionScript, s: &MotionSummary) -> String {
    let p = &s.parameters;
    let mut md = String::new();
    header(
        &mut md,
        &ReportHead {
            title: "fovea bench report: motion",
            written_at: &s.written_at,
            fovea_version: &s.fovea_version,
            device: &s.device,
            commands: &s.commands,
            missing: (!s.complete)
                .then(|| format!("{} of {} rows measured", s.rows, s.expected_rows)),
        },
        dir,
    );
    let _ = writeln!(
        md,
        "Protocol: {} frames at {} Hz ({:.0} ms), both eyes at {}×{} per eye, field of view {}, {} bounces, \
         integrator {}, {} traversal. Head: yaw {}° and pitch {}° sinusoids, period {} s and {} s (up to {:.0}°/s). \
         Eye: fixations of {} ms on the scene directions {:?} (yaw, pitch °), counter-rotating with the head; \
         saccades between them on the main sequence (21 ms + 2.2 ms/°). Sequences: the layers {} with the \
         temporal history off and on at {} spp, and off at {} spp. Every frame is compared with a {}-spp \
         reference of its own pose, inside the occlusion mask, per eccentricity band around that frame's gaze; \
         flicker = mean of ((t_k − t_k−1) − (r_k − r_k−1))² / (r_k² + 0.01), the frame-to-frame change beyond \
         the reference's own, on relMSE's scale.\n",
        p.frames,
        script.frame_rate_hz,
        p.frames as f64 / script.frame_rate_hz * 1e3,
        p.width,
        p.height,
        flag_value(&p.fov),
        p.max_bounces,
        flag_value(&p.integrator),
        p.traversal.name(),
        script.head_yaw_deg,
        script.head_pitch_deg,
        script.head_period_s,
        1.5 * script.head_period_s,
        std::f64::consts::TAU * script.head_yaw_deg / script.head_period_s,
        script.fixation_ms,
        script.targets_deg,
        layers_text(&p.foveation),
        p.spp,
        2 * p.spp,
        p.reference_spp
    );
    for scene in &s.scenes {
        scene_section(&mut md, p, scene);
    }
    let _ = writeln!(md, "## Files\n");
    let _ = writeln!(
        md,
        "`{MOTION_FILE}` (a row per scene, sequence, frame, eye and region), `summary.json` (these means, the \
         device and every parameter), `{PLAN_FILE}` (`fovea bench --resume DIR` completes an interrupted run; \
         a sequence is its unit), `{COMMANDS_FILE}`, `plots/` (error and flicker per frame, per region), \
         `images/*-motion.png` (animated PNG, the left eye, {ANIMATION_FRAME_MS} ms a frame: a third of real time)."
    );
    md
}

fn scene_section(md: &mut String, p: &BenchPlan, scene: &MotionScene) {
    let name = &scene.scene;
    let _ = writeln!(md, "## {name}\n");
    let regions = region_names();
    sequence_table(md, scene, &regions);
    history_ratios(md, p, scene, &regions);
    let _ = writeln!(md);
    for region in ["whole", "0-6", "20+"] {
        let _ = writeln!(
            md,
            "![relMSE {region}](plots/{name}-motion-error-{region}.png) ![flicker {region}](plots/{name}-motion-flicker-{region}.png)\n"
        );
    }
    let animation = animation_path(Path::new(""), name);
    let _ = writeln!(
        md,
        "![reference, each sequence and the error of history on, animated]({})\n",
        animation.display()
    );
}

/// `f` of the sequence's summary of `region`; NaN if it has none.
fn region_value(seq: &SequenceSummary, region: &str, f: fn(&RegionSummary) -> f64) -> f64 {
    seq.regions
        .iter()
        .find(|r| r.region == region)
        .map_or(f64::NAN, f)
}

/// Each sequence's cost, JOD, and error and flicker per region.
fn sequence_table(md: &mut String, scene: &MotionScene, regions: &[&str]) {
    let _ = writeln!(
        md,
        "| sequence | GPU ms | of it temporal ms | JOD (video) | {} | {} |",
        regions
            .iter()
            .map(|r| format!("relMSE {r}"))
            .collect::<Vec<_>>()
            .join(" | "),
        regions
            .iter()
            .map(|r| format!("flicker {r}"))
            .collect::<Vec<_>>()
            .join(" | ")
    );
    let _ = writeln!(md, "|---|---|---|---|{}", "---|".repeat(2 * regions.len()));
    for seq in &scene.sequences {
        let errors: Vec<String> = regions
            .iter()
            .map(|r| fmt(region_value(seq, r, |x| x.rel_mse)))
            .collect();
        let flickers: Vec<String> = regions
            .iter()
            .map(|r| fmt(region_value(seq, r, |x| x.flicker)))
            .collect();
        let _ = writeln!(
            md,
            "| {} | {:.2} | {:.2} | {} | {} | {} |",
            seq.sequence,
            seq.gpu_ms,
            seq.temporal_ms,
            seq.jod.map_or("–".to_string(), |j| format!("{j:.2}")),
            errors.join(" | "),
            flickers.join(" | ")
        );
    }
}

/// The history's effect: the history-on sequence against off at the same and at twice the
/// spp, as ratios per region (when all three were measured).
fn history_ratios(md: &mut String, p: &BenchPlan, scene: &MotionScene, regions: &[&str]) {
    let find = |s: Sequence| scene.sequences.iter().find(|x| x.sequence == s.name());
    let [off, on, off_2x] = Sequence::all(p.spp);
    let (Some(on), Some(off), Some(off_2x)) = (find(on), find(off), find(off_2x)) else {
        return;
    };
    let _ = writeln!(
        md,
        "\nHistory on against off (ratio < 1: on is better), per region {}:\n",
        regions.join(", ")
    );
    for (against, label) in [(off, "the same spp"), (off_2x, "twice the spp")] {
        let ratios = |f: fn(&RegionSummary) -> f64| -> String {
            regions
                .iter()
                .map(|r| {
                    format!(
                        "{:.2}",
                        region_value(on, r, f) / region_value(against, r, f)
                    )
                })
                .collect::<Vec<_>>()
                .join(" / ")
        };
        let _ = writeln!(
            md,
            "- against {} at {label} ({:.2} ms against {:.2} ms GPU): relMSE ×{}, settled (second half) ×{}, \
             flicker ×{}",
            against.sequence,
            on.gpu_ms,
            against.gpu_ms,
            ratios(|x| x.rel_mse),
            ratios(|x| x.rel_mse_settled),
            ratios(|x| x.flicker)
        );
    }
}
