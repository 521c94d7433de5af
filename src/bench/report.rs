//! summary.json, report.md and the plots of a run, all from its rows.

use super::error::BenchError;
use super::files::{strip_path, COMMANDS_FILE, FRAMES_FILE, PLAN_FILE, QUALITY_FILE, TRACE_FILE};
use super::protocol::flag_value;
use super::protocol::{BenchPlan, Mode};
use super::report_head::{header, layers_text, ReportHead};
use super::report_plots::write_plots;
use super::rows::{FrameRow, QualityRow};
use super::summary::{summarize_run, ModeSummary, SceneSummary, Summary};
use crate::gpu::DeviceInfo;
use std::fmt::Write as _;
use std::path::Path;

/// The thesis' impact factors (forward, corner), §5.1, for the table beside ours.
pub const THESIS_IMPACT: [(&str, f64, f64); 5] = [
    ("control", 1.0, 1.0),
    ("bunny-low", 1.99, 3.99),
    ("bunny-high", 1.75, 8.83),
    ("cubes-441", 5.11, 7.99),
    ("mirror-room", 5.30, 5.49),
];

/// Writes summary.json, report.md and plots/ into `dir`.
pub fn write_all(
    dir: &Path,
    plan: &BenchPlan,
    device: &DeviceInfo,
    commands: &[&str],
    frames: &[FrameRow],
    quality: &[QualityRow],
) -> Result<(), BenchError> {
    let summary = summarize_run(plan, device, commands, frames, quality);
    let path = dir.join("summary.json");
    let json = serde_json::to_string_pretty(&summary).expect("summaries serialize");
    std::fs::write(&path, json).map_err(|e| BenchError::file(&path, e))?;
    write_plots(dir, plan, frames, &summary)?;
    let path = dir.join("report.md");
    std::fs::write(&path, markdown(dir, &summary)).map_err(|e| BenchError::file(&path, e))
}

fn fmt_impact(m: &ModeSummary) -> String {
    match m.impact {
        Some(i) if i.max.is_finite() => format!("{:.2} ({:.2}–{:.2})", i.factor, i.min, i.max),
        Some(i) => format!("{:.2} ({:.2}–∞)", i.factor, i.min),
        None => "–".into(),
    }
}

fn ms(s: Option<super::stats::Summary>) -> String {
    s.map_or("–".into(), |s| format!("{:.2}", s.mean))
}

/// The report: what ran where, impact factors beside the thesis', per-scene statistics,
/// quality, and links to every plot and picture.
pub fn markdown(dir: &Path, s: &Summary) -> String {
    let mut md = String::new();
    header(
        &mut md,
        &ReportHead {
            title: "fovea bench report",
            written_at: &s.written_at,
            fovea_version: &s.fovea_version,
            device: &s.device,
            commands: &s.commands,
            missing: (!s.complete).then(|| {
                format!(
                    "{} of {} frame rows measured",
                    s.frame_rows, s.expected_frame_rows
                )
            }),
        },
        dir,
    );
    protocol_paragraph(&mut md, &s.parameters);
    impact_section(&mut md, s);
    for scene in &s.scenes {
        scene_section(&mut md, s, scene);
    }
    files_paragraph(&mut md);
    md
}

/// What the run measured and how, in one paragraph.
fn protocol_paragraph(md: &mut String, p: &BenchPlan) {
    let _ = writeln!(
        md,
        "Protocol (thesis §3.1): {} frames × {} repeats foveated, {} regular, both eyes at {}×{} per eye, \
         field of view {}, {} spp, integrator {}, {} bounces, layers {}, occlusion mask {}, {} traversal. Modes of a repeat run interleaved \
         frame by frame after one warm-up frame each. fps per frame = 1000 / GPU time of both eyes' passes \
         (timestamp queries); the thesis' impact factor = mean foveated fps / mean regular fps, its range \
         (μf − σf)/(μr + σr) … (μf + σf)/(μr − σr).\n",
        p.frames,
        p.repeats_foveated,
        p.repeats_regular,
        p.width,
        p.height,
        flag_value(&p.fov),
        p.spp,
        flag_value(&p.integrator),
        p.max_bounces,
        layers_text(&p.foveation),
        p.foveation
            .occlusion_deg
            .map_or("none".to_string(), |d| format!("{d}° (error is measured inside it only)")),
        p.traversal.name()
    );
}

/// The impact factors per scene beside the thesis', and the trace mode's.
fn impact_section(md: &mut String, s: &Summary) {
    let _ = writeln!(md, "## Impact factors beside the thesis'\n");
    let mut trace_impacts = Vec::new();
    let _ = writeln!(
        md,
        "| scene | forward (range) | corner (range) | thesis forward | thesis corner |"
    );
    let _ = writeln!(md, "|---|---|---|---|---|");
    for scene in &s.scenes {
        let thesis = THESIS_IMPACT.iter().find(|t| t.0 == scene.scene);
        if let Some(trace) = scene.modes.iter().find(|m| m.mode == Mode::Trace) {
            trace_impacts.push(format!("{} {}", scene.scene, fmt_impact(trace)));
        }
        let _ = writeln!(
            md,
            "| {} | {} | {} | {} | {} |",
            scene.scene,
            fmt_impact(&scene.modes[1]),
            fmt_impact(&scene.modes[2]),
            thesis.map_or("–".into(), |t| format!("{:.2}", t.1)),
            thesis.map_or("–".into(), |t| format!("{:.2}", t.2)),
        );
    }
    let _ = writeln!(md);
    if let Some(path) = &s.parameters.gaze_trace {
        let _ = writeln!(
            md,
            "Mode `trace` follows the gaze trace `{}` (frame k of a repeat takes its row k); \
             its impact (range): {}.\n",
            path.display(),
            trace_impacts.join(", ")
        );
    }
}

/// What each file of the directory holds.
fn files_paragraph(md: &mut String) {
    let _ = writeln!(md, "## Files\n");
    let _ = writeln!(
        md,
        "`{}` (a row per frame and eye), `{}` (a row per scene, mode, spp, eye and region), `summary.json` \
         (these statistics, the device and every parameter), `{}` (open in ui.perfetto.dev), `{}` (the plan; \
         `fovea bench --resume DIR` completes an interrupted run), `{}` (every command that measured here).",
        FRAMES_FILE,
        QUALITY_FILE,
        TRACE_FILE,
        PLAN_FILE,
        COMMANDS_FILE
    );
}

fn scene_section(md: &mut String, s: &Summary, scene: &SceneSummary) {
    let name = &scene.scene;
    let _ = writeln!(md, "## {name}\n");
    timing_table(md, scene);
    quality_table(md, s, scene);
    error_time_pictures(md, s, name);
}

/// Each mode's frame rates, times and impact, and the frame-rate plots.
fn timing_table(md: &mut String, scene: &SceneSummary) {
    let name = &scene.scene;
    let _ = writeln!(
        md,
        "| mode | frames | fps mean ± std | median ms | p99 ms | plan / trace / resolve ms per eye | CPU ms | paths per frame | Msamples/s | impact (range) |"
    );
    let _ = writeln!(md, "|---|---|---|---|---|---|---|---|---|---|");
    for m in &scene.modes {
        let Some(r) = m.rates else {
            let _ = writeln!(
                md,
                "| {} | 0 | – | – | – | – | – | – | – | – |",
                m.mode.name()
            );
            continue;
        };
        let _ = writeln!(
            md,
            "| {} | {} | {:.2} ± {:.2} | {:.2} | {:.2} | {} / {} / {} | {} | {:.0} | {:.2} | {} |",
            m.mode.name(),
            m.frames,
            r.fps.mean,
            r.fps.std,
            r.ms.median,
            r.ms.p99,
            ms(m.gpu_plan_ms),
            ms(m.trace_ms),
            ms(m.resolve_ms),
            ms(m.cpu_ms),
            m.paths_per_frame,
            m.msamples_per_s.unwrap_or(0.0),
            fmt_impact(m)
        );
    }
    let problems: u64 = scene
        .modes
        .iter()
        .map(|m| m.nonfinite_samples + m.stack_overflows)
        .sum();
    let _ = writeln!(
        md,
        "\nNon-finite samples and stack overflows: {problems}.\n"
    );
    let _ = writeln!(
        md,
        "![frame rate per frame](plots/{name}-frames.png) ![mean and standard deviation](plots/{name}-mean-std.png)\n"
    );
}

/// Each mode's error at the protocol's spp, over the whole image and per band.
fn quality_table(md: &mut String, s: &Summary, scene: &SceneSummary) {
    let spp = s.parameters.spp;
    let _ = writeln!(
        md,
        "Error against a {}-spp reference at {spp} spp (mean of both eyes; bands are degrees from each eye's gaze; \
         relMSE = (x − r)² / (r² + 0.01); PSNR and FLIP on the sRGB image; JOD: FovVideoVDP, foveated \
         at the gaze, on the Vive Pro's photometry, whole image only, 10 = as the reference):\n",
        s.parameters.reference_spp
    );
    let _ = writeln!(
        md,
        "| mode | region | pixels | relMSE | MSE | PSNR dB | FLIP | JOD |"
    );
    let _ = writeln!(md, "|---|---|---|---|---|---|---|---|");
    for q in scene.quality.iter().filter(|q| q.spp == spp) {
        if q.pixels == 0 {
            let _ = writeln!(
                md,
                "| {} | {} | 0 (none visible) | – | – | – | – | – |",
                q.mode.name(),
                q.region
            );
            continue;
        }
        let _ = writeln!(
            md,
            "| {} | {} | {} | {:.3e} | {:.3e} | {:.2} | {:.4} | {} |",
            q.mode.name(),
            q.region,
            q.pixels,
            q.rel_mse,
            q.mse,
            q.psnr_db,
            q.flip,
            q.jod.map_or("–".to_string(), |j| format!("{j:.2}"))
        );
    }
}

/// The run-time-against-error plots and the strip of pictures.
fn error_time_pictures(md: &mut String, s: &Summary, name: &str) {
    let _ = writeln!(
        md,
        "\nRun time against error, spp {:?}:\n",
        s.parameters.sweep()
    );
    let _ = writeln!(
        md,
        "![whole image](plots/{name}-error-time-whole.png) ![fovea](plots/{name}-error-time-fovea.png) \
         ![perceptual quality](plots/{name}-jod-time.png)\n"
    );
    let strip = strip_path(Path::new(""), name);
    let _ = writeln!(
        md,
        "![reference, regular, forward, corner, FLIP]({})\n",
        strip.display()
    );
}
