//! One report: the frames of every scene, its fovea spp search, then the headset sessions.
//! The files are rewritten after each scene, so an interrupted run keeps what it measured.

use super::frames::{eyes, fovea_spp_ms, time_case};
use super::plan::RealtimePlan;
use super::report::{OverLimit, RealtimeReport, SppResult};
use super::sessions::run_sessions;
use super::spp_search::Probes;
use crate::gpu::{GpuContext, GpuError};
use crate::render::{RenderError, Renderer, TemporalSettings};
use std::path::Path;
use std::sync::Arc;

/// The goal the report checks: 90 Hz stereo with at least this many spp in the fovea.
pub const GOAL_SPP: u32 = 16;

/// Measures `plan` on `ctx`'s device into `dir`; `progress` hears what is being measured.
pub fn run(
    ctx: &Arc<GpuContext>,
    plan: &RealtimePlan,
    dir: &Path,
    command: String,
    progress: &mut dyn FnMut(&str),
) -> Result<(), String> {
    std::fs::create_dir_all(dir).map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
    let mut report = RealtimeReport {
        device: &ctx.info,
        command,
        written_at: crate::bench::summary::utc_now(),
        display: plan.display,
        width: plan.width,
        height: plan.height,
        quick: plan.quick,
        history: plan.history,
        trace_lanes: plan
            .trace_lanes
            .unwrap_or(crate::render::preferred_trace_lanes(ctx)),
        cases: Vec::new(),
        spp: Vec::new(),
        sessions: Vec::new(),
        over_limits: Vec::new(),
        peak_memory: 0,
        goal_spp: GOAL_SPP,
    };
    for name in &plan.scenes {
        measure_scene(ctx, plan, name, &mut report, progress)
            .map_err(|e| format!("{name}: {e}"))?;
        report.peak_memory = ctx.memory_peak();
        report.write(dir)?;
    }
    progress("headset sessions");
    report.sessions = run_sessions(plan, dir)?;
    report.write(dir)
}

/// Whether `error` says the case's buffers or images exceed what the device holds (a
/// per-resource limit, texel views' included, or its memory), checked before anything is
/// allocated: the report records the case and goes on with the others, as a headset at a
/// display's full size meets it. Other errors (bad input, a bug) stop the report.
fn over_device_limits(error: &RenderError) -> bool {
    matches!(
        error,
        RenderError::Gpu(
            GpuError::ResourceTooLarge(_)
                | GpuError::NotEnoughMemory(_)
                | GpuError::OutOfMemory { .. }
        )
    )
}

/// Every case of one scene, then its fovea spp search, per traversal.
fn measure_scene(
    ctx: &Arc<GpuContext>,
    plan: &RealtimePlan,
    name: &str,
    report: &mut RealtimeReport,
    progress: &mut dyn FnMut(&str),
) -> Result<(), String> {
    let aspect = plan.width as f32 / plan.height as f32;
    let scene = crate::scene::load(name, aspect).map_err(|e| e.to_string())?;
    let mut renderer = Renderer::new(ctx, &scene).map_err(|e| e.to_string())?;
    if let Some(lanes) = plan.trace_lanes {
        renderer.set_trace_lanes(lanes);
    }
    if plan.history {
        renderer
            .set_temporal(Some(TemporalSettings::default()))
            .map_err(|e| e.to_string())?;
    }
    for traversal in renderer.traversals() {
        renderer
            .set_traversal(traversal)
            .map_err(|e| e.to_string())?;
        for stereo in [false, true] {
            let eyes = eyes(&scene, plan, stereo);
            for mode in &plan.modes {
                progress(&format!(
                    "{name}: {} {}, {}",
                    mode.name,
                    if stereo { "stereo" } else { "mono" },
                    traversal.name()
                ));
                match time_case(&mut renderer, plan, name, &mode.name, &mode.config, &eyes) {
                    Ok(case) => report.cases.push(case),
                    Err(e) if over_device_limits(&e) => {
                        progress(&format!("{name}: {} not timed: {e}", mode.name));
                        report.over_limits.push(OverLimit {
                            scene: name.to_string(),
                            mode: mode.name.clone(),
                            eyes: eyes.len(),
                            why: e.to_string(),
                        });
                    }
                    Err(e) => return Err(e.to_string()),
                }
            }
        }
        progress(&format!("{name}: fovea spp search, {}", traversal.name()));
        let eyes = eyes(&scene, plan, true);
        let mut probes = Probes::default();
        let mut cost = |spp| fovea_spp_ms(&mut renderer, plan, &eyes, spp);
        let answers = plan
            .budgets_ms
            .iter()
            .map(|&budget| probes.largest_within(budget, plan.max_spp, &mut cost))
            .collect::<Result<Vec<_>, _>>()
            .map_err(|e| e.to_string())?;
        report.spp.push(SppResult {
            scene: name.to_string(),
            traversal,
            answers,
            probes,
        });
    }
    Ok(())
}
