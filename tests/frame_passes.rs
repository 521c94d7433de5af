//! What a frame reports of its passes (issue 34): every pass of both eyes is timed, however
//! many the frame has (history, the lattice filter and five denoise iterations are 23), and a device loss with
//! frames in flight names the pass of the frame that was lost, not of the one recorded after.

mod common;

use fovea::foveation::{FoveationConfig, Gaze, GazeChoice};
use fovea::gpu::{GpuContext, GpuError, GpuOptions};
use fovea::render::FrameOptions;
use fovea::render::{
    eye_views, DebugView, FovChoice, FrameRequest, Integrator, RenderError, Renderer,
};
use std::sync::Arc;

const WIDTH: u32 = 24;
const HEIGHT: u32 = 24;

fn stereo_request<'a>(
    config: &'a FoveationConfig,
    eyes: &'a [fovea::render::EyeView],
    seed: u32,
) -> FrameRequest<'a> {
    FrameRequest {
        settings: common::settings(WIDTH, HEIGHT, 1, seed, Integrator::Pt),
        foveation: config,
        eyes,
        debug: DebugView::None,
    }
}

fn stereo_eyes(scene: &fovea::scene::Scene) -> Vec<fovea::render::EyeView> {
    let forward = GazeChoice {
        left: Gaze::Forward,
        right: Gaze::Forward,
    };
    eye_views(&scene.camera, 1.0, FovChoice::Scene, true, forward)
}

#[test]
fn a_stereo_frame_with_history_a_lattice_filter_and_five_denoise_iterations_times_every_pass() {
    let ctx = common::context();
    let scene = fovea::scene::load("cornell", 1.0).unwrap();
    let mut renderer = common::renderer_with_history(&ctx, &scene);
    renderer.set_output_image(true);
    let mut config = FoveationConfig::regular(1);
    config.layers[0].denoise = 5;
    config.layers[0].filter_px = 1.0;
    let eyes = stereo_eyes(&scene);
    // The second frame has a history to carry.
    let mut frame = None;
    for seed in 1..=2 {
        frame = Some(
            renderer
                .frame(
                    &stereo_request(&config, &eyes, seed),
                    FrameOptions::measure(),
                )
                .map(Option::unwrap)
                .unwrap(),
        );
    }
    let stats = frame.unwrap().stats;

    let mut expected: Vec<String> = Vec::new();
    let both = |pass: &str| ["left", "right"].map(|eye| format!("{eye} {pass}"));
    expected.extend(both("plan"));
    expected.push("dispatch sizes".into());
    expected.extend(both("trace"));
    expected.extend(both("lattice filter"));
    expected.extend(both("resolve"));
    expected.extend(both("temporal"));
    for _ in 0..5 {
        expected.extend(both("denoise"));
    }
    expected.push("denoise copy".into());
    expected.push("output image".into());
    let names: Vec<&str> = stats.pass_ms.iter().map(|(n, _)| n.as_str()).collect();
    eprintln!(
        "stereo frame, history, lattice filter, 5 denoise iterations: {} timed passes, {:.3} GPU ms",
        names.len(),
        stats.gpu_ms()
    );
    assert_eq!(names, expected, "every pass of both eyes, in order");
    assert_eq!(names.len(), 23);

    // The frame's GPU time is its passes' sum, each pass measured (none left at zero
    // because it was dropped), and each pass starts no earlier than the one recorded before.
    let sum: f64 = stats.pass_ms.iter().map(|(_, ms)| ms).sum();
    assert!(
        (stats.gpu_ms() - sum).abs() < 1e-9,
        "{} {sum}",
        stats.gpu_ms()
    );
    assert!(stats
        .pass_ms
        .iter()
        .all(|(_, ms)| ms.is_finite() && *ms >= 0.0));
    assert!(stats.gpu_ms() > 0.0);
    assert_eq!(stats.pass_start_ms.len(), 23);
    assert!(
        stats.pass_start_ms.windows(2).all(|w| w[0] <= w[1]),
        "{:?}",
        stats.pass_start_ms
    );
    drop(renderer);
    common::assert_no_validation_messages(&ctx);
}

#[test]
fn a_device_loss_with_two_frames_in_flight_names_the_lost_frames_pass() {
    // The second command buffer that records 'right trace' (frame 2) ends after it and its
    // submission reports a device loss; frame 3 is recorded and submitted before frame 2 is
    // waited for, so frame 2's markers must survive frame 3's recording.
    let mut options = GpuOptions::from_env();
    options.validation = true;
    options.inject_device_lost = Some("right trace@2".into());
    let ctx = Arc::new(GpuContext::new(&options).unwrap());
    let scene = fovea::scene::load("bunny-low", 1.0).unwrap();
    let mut renderer = Renderer::new(&ctx, &scene).unwrap();
    renderer.set_output_image(true);
    renderer.set_frames_in_flight(2).unwrap();
    let config = FoveationConfig::thesis();
    let eyes = stereo_eyes(&scene);
    let gazes: Vec<Gaze> = eyes.iter().map(|e| e.gaze).collect();
    let mut latch = || gazes.clone();
    let mut copies = 0;
    let mut after =
        |_cmd: fovea::gpu::vk::CommandBuffer, _image: &fovea::gpu::StorageImage| copies += 1;
    for seed in 1..=3 {
        renderer
            .frame(
                &stereo_request(&config, &eyes, seed),
                FrameOptions {
                    latch: Some(&mut latch),
                    after: Some(&mut after),
                    ..Default::default()
                },
            )
            .map(|_| ())
            .unwrap();
    }
    assert_eq!(renderer.in_flight(), 2, "frames 2 and 3 in flight");
    let first = renderer
        .next_finished(true)
        .unwrap()
        .expect("frame 1 finished");
    assert!(first.stats.gpu_ms() > 0.0);
    let lost = renderer.next_finished(true).unwrap_err();
    let RenderError::Gpu(GpuError::DeviceLost {
        completed,
        running,
        injected,
        ..
    }) = &lost
    else {
        panic!("expected a device loss, got {lost}");
    };
    assert!(injected);
    assert_eq!(completed.as_deref(), Some("right trace"), "{lost}");
    assert_eq!(running.as_deref(), Some("left resolve"), "{lost}");
}
