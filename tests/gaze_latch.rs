//! The gaze a frame is foveated around is the one its latch gives, right before submission:
//! what the request said is not used, and the frame plans and traces exactly what a frame
//! asked for that gaze up front does.

mod common;

use fovea::foveation::{FoveationConfig, Gaze, GazeChoice};
use fovea::render::FrameOptions;
use fovea::render::{eye_views, DebugView, FovChoice, FrameRequest, Renderer};

#[test]
fn a_latched_gaze_replaces_the_requested_one() {
    let ctx = common::context();
    let scene = fovea::scene::load("cornell", 1.0).unwrap();
    let mut renderer = Renderer::new(&ctx, &scene).unwrap();
    let thesis = FoveationConfig::thesis();
    let settings = common::settings(96, 96, 4, 2, fovea::render::Integrator::Pt);
    let views = |gaze: &str| {
        let choice: GazeChoice = gaze.parse().unwrap();
        eye_views(&scene.camera, 1.0, FovChoice::Scene, true, choice)
    };
    let (forward, corner) = (views("forward"), views("corner"));
    let request = |eyes| FrameRequest {
        settings,
        foveation: &thesis,
        eyes,
        debug: DebugView::None,
    };
    let asked_forward = renderer
        .frame(&request(&forward), FrameOptions::measure())
        .map(Option::unwrap)
        .unwrap();
    let asked_corner = renderer
        .frame(&request(&corner), FrameOptions::measure())
        .map(Option::unwrap)
        .unwrap();
    let mut latches = 0;
    let latched = renderer
        .frame(
            &request(&forward),
            FrameOptions {
                latch: Some(&mut || {
                    latches += 1;
                    vec![Gaze::Corner, Gaze::Corner]
                }),
                ..FrameOptions::measure()
            },
        )
        .map(Option::unwrap)
        .unwrap();
    assert_eq!(latches, 1, "the latch runs once per frame");
    // The two gazes plan differently, so the comparison can tell them apart.
    assert_ne!(
        asked_forward.stats.layer_samples,
        asked_corner.stats.layer_samples
    );
    assert_eq!(latched.gazes, asked_corner.gazes);
    assert_eq!(
        latched.stats.layer_samples,
        asked_corner.stats.layer_samples
    );
    assert_eq!(latched.stats.paths, asked_corner.stats.paths);
    common::assert_no_validation_messages(&ctx);
}
