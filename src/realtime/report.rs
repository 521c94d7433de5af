//! The report's files: frames.csv (per case), passes.csv (per case and pass), spp.csv (the
//! largest fovea spp per scene and budget) and spp-probes.csv (every spp measured),
//! sessions.csv (per frames-in-flight setting), report.json (all of it) and report.md.

use super::frames::CaseTiming;
use super::sessions::SessionTiming;
use super::spp_search::{Probes, SppAnswer};
use crate::bench::stats::Summary;
use crate::foveation::DisplayProfile;
use crate::gpu::DeviceInfo;
use crate::render::{TraceLanes, Traversal};
use serde::Serialize;
use std::fmt::Write as _;
use std::path::Path;

/// One scene's fovea spp search (per traversal).
#[derive(Clone, Debug)]
pub struct SppResult {
    pub scene: String,
    pub traversal: Traversal,
    pub answers: Vec<SppAnswer>,
    pub probes: Probes,
}

/// A case not timed because its buffers or images exceed what the device holds.
#[derive(Clone, Debug, Serialize)]
pub struct OverLimit {
    pub scene: String,
    pub mode: String,
    pub eyes: usize,
    /// The renderer's message: which limit, by how much, and what to change.
    pub why: String,
}

/// Everything one run measured.
pub struct RealtimeReport<'a> {
    pub device: &'a DeviceInfo,
    pub command: String,
    pub written_at: String,
    /// The headset whose fields of view the frames cover.
    pub display: DisplayProfile,
    pub width: u32,
    pub height: u32,
    pub quick: bool,
    /// Whether the frames ran with the temporal history on.
    pub history: bool,
    /// The trace's lanes per lattice point.
    pub trace_lanes: TraceLanes,
    pub cases: Vec<CaseTiming>,
    pub spp: Vec<SppResult>,
    pub sessions: Vec<SessionTiming>,
    /// The cases the device could not hold (in no other file's rows).
    pub over_limits: Vec<OverLimit>,
    /// The most GPU memory fovea held while timing frames, bytes.
    pub peak_memory: u64,
    /// The goal: at 90 Hz stereo, at least this many spp in the fovea in every scene.
    pub goal_spp: u32,
}

#[derive(Serialize)]
struct FrameCsv<'a> {
    scene: &'a str,
    mode: &'a str,
    eyes: usize,
    traversal: &'a str,
    frames: usize,
    median_ms: f64,
    p99_ms: f64,
    mean_ms: f64,
    paths: u64,
    msamples_per_s: f64,
}

#[derive(Serialize)]
struct PassCsv<'a> {
    scene: &'a str,
    mode: &'a str,
    eyes: usize,
    traversal: &'a str,
    pass: &'a str,
    median_ms: f64,
    p99_ms: f64,
}

#[derive(Serialize)]
struct SppCsv<'a> {
    scene: &'a str,
    traversal: &'a str,
    budget_ms: f64,
    fovea_spp: u32,
    median_ms: f64,
    first_over_spp: Option<u32>,
}

#[derive(Serialize)]
struct ProbeCsv<'a> {
    scene: &'a str,
    traversal: &'a str,
    budget_ms: f64,
    /// The order in which the budget's search visited it.
    step: usize,
    fovea_spp: u32,
    median_ms: f64,
}

#[derive(Serialize)]
struct SessionCsv {
    frames_in_flight: u32,
    frames: usize,
    frame_period_median_ms: Option<f64>,
    frame_period_p99_ms: Option<f64>,
    missed_frames: u64,
    missed_after_start: u64,
    gaze_to_photon_median_ms: Option<f64>,
    gaze_to_photon_p99_ms: Option<f64>,
    overlapped: f64,
    gpu_median_ms: Option<f64>,
    gpu_p99_ms: Option<f64>,
    gpu_mib_max: f64,
}

fn write_csv<T: Serialize>(path: &Path, rows: impl IntoIterator<Item = T>) -> Result<(), String> {
    let fail = |e: &dyn std::fmt::Display| format!("cannot write {}: {e}", path.display());
    let mut writer = csv::Writer::from_path(path).map_err(|e| fail(&e))?;
    for row in rows {
        writer.serialize(row).map_err(|e| fail(&e))?;
    }
    writer.flush().map_err(|e| fail(&e))
}

impl RealtimeReport<'_> {
    /// Writes every file into `dir` (which exists).
    pub fn write(&self, dir: &Path) -> Result<(), String> {
        write_csv(&dir.join("frames.csv"), self.cases.iter().map(frame_row))?;
        write_csv(
            &dir.join("passes.csv"),
            self.cases.iter().flat_map(|c| {
                c.passes.iter().map(move |(pass, s)| PassCsv {
                    scene: &c.scene,
                    mode: &c.mode,
                    eyes: c.eyes,
                    traversal: c.traversal.name(),
                    pass,
                    median_ms: s.median,
                    p99_ms: s.p99,
                })
            }),
        )?;
        write_csv(
            &dir.join("spp.csv"),
            self.spp.iter().flat_map(|r| {
                r.answers.iter().map(move |a| SppCsv {
                    scene: &r.scene,
                    traversal: r.traversal.name(),
                    budget_ms: a.budget_ms,
                    fovea_spp: a.spp,
                    median_ms: a.ms,
                    first_over_spp: a.first_over,
                })
            }),
        )?;
        write_csv(
            &dir.join("spp-probes.csv"),
            self.spp.iter().flat_map(|r| {
                r.answers.iter().flat_map(move |a| {
                    a.visited
                        .iter()
                        .enumerate()
                        .map(move |(step, spp)| ProbeCsv {
                            scene: &r.scene,
                            traversal: r.traversal.name(),
                            budget_ms: a.budget_ms,
                            step,
                            fovea_spp: *spp,
                            median_ms: r.probes.ms[spp],
                        })
                })
            }),
        )?;
        write_csv(
            &dir.join("sessions.csv"),
            self.sessions.iter().map(session_row),
        )?;
        let json = serde_json::to_string_pretty(&self.json()).map_err(|e| e.to_string())?;
        std::fs::write(dir.join("report.json"), json)
            .map_err(|e| format!("cannot write report.json: {e}"))?;
        std::fs::write(dir.join("report.md"), self.markdown())
            .map_err(|e| format!("cannot write report.md: {e}"))
    }

    fn json(&self) -> serde_json::Value {
        let d = self.device;
        serde_json::json!({
            "device": {
                "name": d.name, "kind": d.kind, "driver": d.driver,
                "vulkan": d.api_version, "ray_queries": d.ray_query.is_some(),
                "subgroup_size": d.subgroup_size,
            },
            "fovea": crate::build_version(),
            "command": self.command,
            "written_at": self.written_at,
            "display": self.display.name(),
            "eye_size": [self.width, self.height],
            "quick": self.quick,
            "history": self.history,
            "trace_lanes": {
                "max_lanes": self.trace_lanes.max_lanes,
                "samples_per_lane": self.trace_lanes.samples_per_lane,
                "fill_threads": self.trace_lanes.fill_threads,
            },
            "peak_gpu_memory_bytes": self.peak_memory,
            "frames": self.cases.iter().map(|c| serde_json::json!({
                "scene": c.scene, "mode": c.mode, "eyes": c.eyes,
                "traversal": c.traversal.name(), "frame_ms": c.frame_ms,
                "passes": c.passes.iter().map(|(p, s)| serde_json::json!({"pass": p, "ms": s}))
                    .collect::<Vec<_>>(),
                "paths": c.paths, "msamples_per_s": c.msamples_per_s,
            })).collect::<Vec<_>>(),
            "fovea_spp": self.spp.iter().map(|r| serde_json::json!({
                "scene": r.scene, "traversal": r.traversal.name(),
                "answers": r.answers.iter().map(|a| serde_json::json!({
                    "budget_ms": a.budget_ms, "spp": a.spp, "ms": a.ms,
                    "first_over_spp": a.first_over, "visited": a.visited,
                })).collect::<Vec<_>>(),
                "probes": r.probes.ms.iter().map(|(s, ms)| serde_json::json!([s, ms]))
                    .collect::<Vec<_>>(),
            })).collect::<Vec<_>>(),
            "sessions": self.sessions,
            "over_limits": self.over_limits,
        })
    }

    fn markdown(&self) -> String {
        let d = self.device;
        let mut md = String::new();
        let _ = writeln!(md, "# fovea on {}: is it real-time?\n", d.name);
        let _ = writeln!(
            md,
            "Written {} by fovea {}. Device: **{}** ({}, driver {}, Vulkan {}, ray queries: {}).\n",
            self.written_at,
            crate::build_version(),
            d.name,
            d.kind,
            d.driver,
            d.api_version,
            if d.ray_query.is_some() { "yes" } else { "no" }
        );
        let _ = writeln!(md, "Command: `{}`\n", self.command);
        let _ = writeln!(
            md,
            "Each eye {}x{} ({} field of view), path tracer, 8 bounces, gaze forward, \
             {}, trace lanes per lattice point: spp / {}, at most {}, doubled while an eye has \
             fewer than {} threads. \
             GPU time from timestamps around every pass, median and p99 over the timed frames \
             after warm-up{}. Peak GPU memory held by fovea while timing: {:.1} MiB.\n",
            self.width,
            self.height,
            self.display.name(),
            match self.history {
                true => "temporal history on (camera still)",
                false => "no history",
            },
            self.trace_lanes.samples_per_lane,
            self.trace_lanes.max_lanes,
            self.trace_lanes.fill_threads,
            if self.quick { " (--quick)" } else { "" },
            self.peak_memory as f64 / (1024.0 * 1024.0)
        );
        self.markdown_spp(&mut md);
        self.markdown_frames(&mut md);
        self.markdown_over_limits(&mut md);
        self.markdown_sessions(&mut md);
        md
    }

    fn markdown_spp(&self, md: &mut String) {
        let _ = writeln!(
            md,
            "## The largest fovea spp that fits (stereo frame)\n\nThe thesis' layers \
             (6°/10°/20°/background at spacings 1/2/3/4, the outer ones at 4 spp), the fovea's \
             spp searched by doubling, then bisection; the searches share measurements \
             (spp-probes.csv: what each visited, in order).\n"
        );
        let budgets: Vec<String> = (self.spp.first().map(|r| r.answers.clone()))
            .unwrap_or_default()
            .iter()
            .map(|a| format!("{:.1} ms", a.budget_ms))
            .collect();
        let _ = writeln!(md, "| scene | traversal | {} |", budgets.join(" | "));
        let _ = writeln!(md, "|---|---|{}", "---|".repeat(budgets.len()));
        for r in &self.spp {
            let cells: Vec<String> = r
                .answers
                .iter()
                .map(|a| match a.spp {
                    0 => "none (1 spp takes longer)".to_string(),
                    spp => format!("{spp} spp ({:.2} ms)", a.ms),
                })
                .collect();
            let _ = writeln!(
                md,
                "| {} | {} | {} |",
                r.scene,
                r.traversal.name(),
                cells.join(" | ")
            );
        }
        let at_90 = |r: &SppResult| r.answers.first().map_or(0, |a| a.spp);
        let met = !self.spp.is_empty() && self.spp.iter().all(|r| at_90(r) >= self.goal_spp);
        let _ = writeln!(
            md,
            "\nGoal: 90 Hz stereo with ≥ {} spp in the fovea in every scene: **{}**.\n",
            self.goal_spp,
            if met { "met" } else { "not met" }
        );
    }

    fn markdown_frames(&self, md: &mut String) {
        let _ = writeln!(
            md,
            "## Frames\n\nGPU ms per frame (median / p99), Msamples/s at the median. Every \
             pass: passes.csv.\n"
        );
        let _ = writeln!(
            md,
            "| scene | mode | eyes | traversal | median ms | p99 ms | Msamples/s |"
        );
        let _ = writeln!(md, "|---|---|---|---|---|---|---|");
        for c in &self.cases {
            let _ = writeln!(
                md,
                "| {} | {} | {} | {} | {:.3} | {:.3} | {:.1} |",
                c.scene,
                c.mode,
                if c.eyes == 2 { "stereo" } else { "mono" },
                c.traversal.name(),
                c.frame_ms.median,
                c.frame_ms.p99,
                c.msamples_per_s
            );
        }
        let _ = writeln!(md);
    }

    fn markdown_over_limits(&self, md: &mut String) {
        if self.over_limits.is_empty() {
            return;
        }
        let _ = writeln!(
            md,
            "## Cases this device cannot hold (not timed)\n\n| scene | config | eyes | why |\n|---|---|---:|---|"
        );
        for o in &self.over_limits {
            let _ = writeln!(md, "| {} | {} | {} | {} |", o.scene, o.mode, o.eyes, o.why);
        }
        let _ = writeln!(md);
    }

    fn markdown_sessions(&self, md: &mut String) {
        let _ = writeln!(
            md,
            "## Headset sessions (simulated headset, paced in real time at 90 Hz)\n\n\
             `fovea xr --simulated` at the same size (the simulated headset's Vive Pro Eye field \
             of view, whatever the report's display), thesis layers, temporal history on, a \
             scripted gaze with saccades; files in session-K-in-flight/. Missed frames in \
             brackets: after the second frame, leaving out the periods that wait for the first \
             frame's pipelines.\n"
        );
        let _ = writeln!(
            md,
            "| frames in flight | frames | frame period ms (median / p99) | missed (after the second frame) | gaze-to-photon ms (median / p99) | overlapped | GPU ms (median / p99) | GPU MiB |"
        );
        let _ = writeln!(md, "|---|---|---|---|---|---|---|---|");
        let pair = |s: &Option<Summary>| {
            s.map_or("–".to_string(), |s| {
                format!("{:.2} / {:.2}", s.median, s.p99)
            })
        };
        for s in &self.sessions {
            let _ = writeln!(
                md,
                "| {} | {} | {} | {} ({}) | {} | {:.0}% | {} | {:.1} |",
                s.frames_in_flight,
                s.frames,
                pair(&s.frame_period_ms),
                s.missed_frames,
                s.missed_after_start,
                pair(&s.gaze_to_photon_ms),
                100.0 * s.overlapped,
                pair(&s.gpu_ms),
                s.gpu_mib_max
            );
        }
    }
}

fn frame_row(c: &CaseTiming) -> FrameCsv<'_> {
    FrameCsv {
        scene: &c.scene,
        mode: &c.mode,
        eyes: c.eyes,
        traversal: c.traversal.name(),
        frames: c.frame_ms.n,
        median_ms: c.frame_ms.median,
        p99_ms: c.frame_ms.p99,
        mean_ms: c.frame_ms.mean,
        paths: c.paths,
        msamples_per_s: c.msamples_per_s,
    }
}

fn session_row(s: &SessionTiming) -> SessionCsv {
    let median = |s: &Option<Summary>| s.map(|s| s.median);
    let p99 = |s: &Option<Summary>| s.map(|s| s.p99);
    SessionCsv {
        frames_in_flight: s.frames_in_flight,
        frames: s.frames,
        frame_period_median_ms: median(&s.frame_period_ms),
        frame_period_p99_ms: p99(&s.frame_period_ms),
        missed_frames: s.missed_frames,
        missed_after_start: s.missed_after_start,
        gaze_to_photon_median_ms: median(&s.gaze_to_photon_ms),
        gaze_to_photon_p99_ms: p99(&s.gaze_to_photon_ms),
        overlapped: s.overlapped,
        gpu_median_ms: median(&s.gpu_ms),
        gpu_p99_ms: p99(&s.gpu_ms),
        gpu_mib_max: s.gpu_mib_max,
    }
}
