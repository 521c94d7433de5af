//! Timing frames: per case (scene, layer config, mono or stereo, traversal) the GPU time of
//! every pass over the timed frames, and the fovea spp search's stereo frames.

use super::plan::RealtimePlan;
use crate::bench::stats::{summarize, Summary};
use crate::foveation::{FoveationConfig, Gaze, GazeChoice};
use crate::render::FrameOptions;
use crate::render::{
    eye_views, DebugView, EyeView, FrameRequest, FrameStats, Integrator, RenderError,
    RenderSettings, Renderer, Traversal,
};
use crate::scene::Scene;

/// What one case measured.
#[derive(Clone, Debug)]
pub struct CaseTiming {
    pub scene: String,
    pub mode: String,
    pub eyes: usize,
    pub traversal: Traversal,
    /// The frame's GPU time (its passes' sum).
    pub frame_ms: Summary,
    /// Every pass, in the frame's order.
    pub passes: Vec<(String, Summary)>,
    /// Camera paths traced per frame (the median frame's).
    pub paths: u64,
    /// Millions of paths per second of GPU time, at the median frame time.
    pub msamples_per_s: f64,
}

/// The display's eyes (its fields of view, IPD apart) looking forward; one for mono.
pub fn eyes(scene: &Scene, plan: &RealtimePlan, stereo: bool) -> Vec<EyeView> {
    let forward = GazeChoice {
        left: Gaze::Forward,
        right: Gaze::Forward,
    };
    let aspect = plan.width as f32 / plan.height as f32;
    eye_views(&scene.camera, aspect, plan.display.fov(), stereo, forward)
}

/// A frame of the plan's size; the layers carry the spp.
pub fn settings(plan: &RealtimePlan) -> RenderSettings {
    RenderSettings {
        sampler: crate::render::Sampler::chosen(),
        width: plan.width,
        height: plan.height,
        spp: 1,
        seed: 1,
        integrator: Integrator::Pt,
        max_bounces: 8,
    }
}

/// Renders `warmup` untimed frames, then `frames` timed ones (left on the GPU, as a headset
/// frame is), and returns their stats.
pub fn timed_frames(
    renderer: &mut Renderer,
    request: &FrameRequest,
    warmup: u32,
    frames: u32,
) -> Result<Vec<FrameStats>, RenderError> {
    for _ in 0..warmup {
        renderer
            .frame(request, FrameOptions::measure())
            .map(Option::unwrap)?;
    }
    (0..frames)
        .map(|_| {
            renderer
                .frame(request, FrameOptions::measure())
                .map(Option::unwrap)
                .map(|f| f.stats)
        })
        .collect()
}

/// Times `config` on `scene` (the renderer's, with its traversal set) with `eyes`.
pub fn time_case(
    renderer: &mut Renderer,
    plan: &RealtimePlan,
    scene: &str,
    mode: &str,
    config: &FoveationConfig,
    eyes: &[EyeView],
) -> Result<CaseTiming, RenderError> {
    let request = FrameRequest {
        settings: settings(plan),
        foveation: config,
        eyes,
        debug: DebugView::None,
    };
    renderer.reset_history(); // each case's history is its own
    let stats = timed_frames(renderer, &request, plan.warmup, plan.frames)?;
    Ok(summarize_case(
        scene,
        mode,
        eyes.len(),
        renderer.traversal(),
        &stats,
    ))
}

/// The case's statistics from its frames' stats.
pub fn summarize_case(
    scene: &str,
    mode: &str,
    eyes: usize,
    traversal: Traversal,
    stats: &[FrameStats],
) -> CaseTiming {
    let of = |values: Vec<f64>| summarize(&values).expect("at least one timed frame");
    let frame_ms = of(stats.iter().map(FrameStats::gpu_ms).collect());
    let names: Vec<String> = stats
        .first()
        .map(|s| s.pass_ms.iter().map(|(n, _)| n.clone()).collect())
        .unwrap_or_default();
    let passes = names
        .iter()
        .enumerate()
        .map(|(i, name)| {
            (
                name.clone(),
                of(stats.iter().map(|s| s.pass_ms[i].1).collect()),
            )
        })
        .collect();
    let paths = stats.iter().map(|s| s.paths).max().unwrap_or(0);
    CaseTiming {
        scene: scene.to_string(),
        mode: mode.to_string(),
        eyes,
        traversal,
        frame_ms,
        passes,
        paths,
        msamples_per_s: paths as f64 / (frame_ms.median * 1e3),
    }
}

/// The median GPU ms of a stereo frame with the fovea at `spp` (the spp search's cost).
pub fn fovea_spp_ms(
    renderer: &mut Renderer,
    plan: &RealtimePlan,
    eyes: &[EyeView],
    spp: u32,
) -> Result<f64, RenderError> {
    let config = RealtimePlan::fovea_config(spp);
    let request = FrameRequest {
        settings: settings(plan),
        foveation: &config,
        eyes,
        debug: DebugView::None,
    };
    let stats = timed_frames(renderer, &request, 1, plan.search_frames)?;
    let ms: Vec<f64> = stats.iter().map(FrameStats::gpu_ms).collect();
    Ok(summarize(&ms).map_or(f64::NAN, |s| s.median))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::foveation::DisplayProfile;

    #[test]
    fn the_eyes_cover_the_plans_display() {
        let scene = crate::scene::load("cornell", 1.0).expect("a built-in scene loads");
        let mut plan = RealtimePlan::quick(64, 64);
        for display in [DisplayProfile::ViveProEye, DisplayProfile::VarjoXr4] {
            plan.display = display;
            let mono = eyes(&scene, &plan, false);
            assert_eq!(mono.len(), 1);
            assert_eq!(mono[0].fov(), display.left_eye_fov(), "{}", display.name());
            assert_eq!(eyes(&scene, &plan, true).len(), 2);
        }
        // The two fields differ, so the check above could fail.
        assert_ne!(
            DisplayProfile::ViveProEye.left_eye_fov(),
            DisplayProfile::VarjoXr4.left_eye_fov()
        );
    }
}
