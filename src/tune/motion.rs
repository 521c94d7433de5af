//! `--objective motion`: a config judged on what the headset shows while the head turns and
//! the eye saccades, with the temporal history on, as a short FovVideoVDP video (foveated at
//! each frame's fixation) against each frame's converged reference.
//!
//! The sequence follows the bench's motion script (`MotionScript::head_and_saccades`: the head
//! turning up to 31°/s, saccades of 10–23° between fixations of 250 ms). It is rendered from
//! [`WARM_UP`] frames before the first scored one, which is the frame before a saccade
//! starts, and scored for [`SCORED`] frames: the history has had time to build up, and the
//! video holds a fixation, a saccade and the landing after it. Every config gets the history,
//! the uniform baselines too, so foveation is compared with the best uniform frame at each
//! cost.

use super::error::TuneError;
use super::plan::TunePlan;
use crate::bench::motion::MotionScript;
use crate::bench::{quality, BenchPlan};
use crate::foveation::{FoveationConfig, Gaze, ImageGeometry};
use crate::metrics::hidden_black;
use crate::metrics::jod::{Fvvdp, JodInput};
use crate::render::display::DisplayTransform;
use crate::render::{
    DebugView, EyeView, FrameOptions, FrameRequest, RenderSettings, Renderer, TemporalSettings,
};
use crate::scene::Scene;
use std::path::Path;

// The warm-up is a plan field (plans before it rendered fewer); its value lives with the plan.
pub use super::plan::{warm_up_before_the_field, WARM_UP};

/// Frames scored: about 130 ms at 90 Hz, holding the end of a fixation, a saccade and the
/// landing.
pub const SCORED: u32 = 12;

/// One scene's judged sequence: each frame's eye (the head's pose, the gaze at the script's
/// fixation) and, for the scored frames, its reference.
pub struct MotionJudge {
    name: String,
    frames: Vec<EyeView>,
    /// How many of `frames` come before the scored ones.
    warm_up: u32,
    references: Vec<Vec<f32>>,
    fixations: Vec<[f64; 2]>,
    /// The script's frame rate, which the video plays at.
    fps: f64,
}

impl MotionJudge {
    /// The sequence of `scene` (loaded as `name`) at `plan`'s image, and each scored frame's
    /// reference from `cache` (or rendered into it by `renderer`).
    pub fn new(
        renderer: &mut Renderer,
        plan: &TunePlan,
        bench: &BenchPlan,
        scene: &Scene,
        name: &str,
        cache: &Path,
        visible: &[bool],
    ) -> Result<Self, TuneError> {
        let script = MotionScript::head_and_saccades();
        let warm_up = plan.motion_warm_up;
        let first = first_scored_frame(&script, warm_up);
        let frames: Vec<EyeView> = (first - warm_up..first + SCORED)
            .map(|k| frame_eye(scene, plan, &script, k))
            .collect();
        let mut references = Vec::new();
        let mut fixations = Vec::new();
        for eye in &frames[warm_up as usize..] {
            let eyes = std::slice::from_ref(eye);
            let path = quality::ReferenceKey::new(renderer, bench, name, eyes).path(cache);
            let rgb = quality::reference_image(renderer, bench, name, eyes, &path, &mut |_, _| {})?;
            references.push(hidden_black(rgb, visible));
            let Gaze::Pixel(x, y) = eye.gaze else {
                unreachable!("frame_eye gives every frame a gaze pixel")
            };
            fixations.push([x, y]);
        }
        Ok(Self {
            name: name.to_string(),
            frames,
            warm_up,
            references,
            fixations,
            fps: script.frame_rate_hz,
        })
    }

    /// `config`'s video JOD: the sequence rendered from an empty history (kept when
    /// `history`, as the headset does), its scored frames against their references.
    #[allow(clippy::too_many_arguments)]
    pub fn score(
        &self,
        renderer: &mut Renderer,
        settings: RenderSettings,
        config: &FoveationConfig,
        history: bool,
        image: &ImageGeometry,
        visible: &[bool],
        display: &DisplayTransform,
        metric: &mut Fvvdp,
    ) -> Result<f64, TuneError> {
        let name = self.name.as_str();
        renderer
            .set_temporal(history.then(TemporalSettings::default))
            .map_err(TuneError::render(name))?;
        renderer.reset_history();
        let mut tests = Vec::new();
        for (k, eye) in self.frames.iter().enumerate() {
            let request = FrameRequest {
                settings: RenderSettings {
                    seed: settings.seed.wrapping_add(k as u32),
                    ..settings
                },
                foveation: config,
                eyes: std::slice::from_ref(eye),
                debug: DebugView::None,
            };
            let frame = renderer
                .frame(&request, FrameOptions::pixels())
                .map(Option::unwrap)
                .map_err(TuneError::render(name))?;
            if k >= self.warm_up as usize {
                tests.push(hidden_black(frame.rgb, visible));
            }
        }
        let tests: Vec<&[f32]> = tests.iter().map(Vec::as_slice).collect();
        let references: Vec<&[f32]> = self.references.iter().map(Vec::as_slice).collect();
        Ok(metric.score(&JodInput {
            test: &tests,
            reference: &references,
            image,
            fixation: &self.fixations,
            fps: self.fps,
            display,
        })?)
    }
}

/// The first scored frame: the one before the first saccade that starts at least
/// `warm_up` + 1 frames into the script.
fn first_scored_frame(script: &MotionScript, warm_up: u32) -> u32 {
    (warm_up + 1..warm_up + 10_000)
        .find(|&k| script.gaze_deg(k).1 && !script.gaze_deg(k - 1).1)
        .expect("the script has saccades")
        - 1
}

/// One eye (the left, mono) at frame `k`: the scene camera turned by the script's head, the
/// gaze at the script's fixation.
fn frame_eye(scene: &Scene, plan: &TunePlan, script: &MotionScript, k: u32) -> EyeView {
    let head = script.head_pose(k).apply(&scene.camera);
    let eye = plan.eye(&head);
    let image = eye.image(plan.width, plan.height);
    let [x, y] = script.gaze_pixel(k, &scene.camera, &eye.camera, &image);
    EyeView {
        gaze: Gaze::Pixel(x, y),
        ..eye
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_scored_window_holds_a_saccade_after_a_fixation() {
        let script = MotionScript::head_and_saccades();
        for warm_up in [warm_up_before_the_field(), WARM_UP, 40] {
            let first = first_scored_frame(&script, warm_up);
            assert!(first >= warm_up, "{warm_up}: {first}");
            assert!(!script.gaze_deg(first).1, "the window starts fixating");
            assert!(script.gaze_deg(first + 1).1, "then the saccade");
            let landed = (first..first + SCORED)
                .filter(|&k| !script.gaze_deg(k).1)
                .count();
            assert!(landed >= 3, "{landed} fixating frames in the window");
        }
        // The plans before the field and now score the same frames: only the warm-up grew,
        // from the script's first frame on (the whole first fixation).
        let first = first_scored_frame(&script, WARM_UP);
        assert_eq!(
            first,
            first_scored_frame(&script, warm_up_before_the_field())
        );
        assert_eq!(first, WARM_UP);
    }
}
