//! The trace's threads per lattice point (`Renderer::set_trace_split`): a GPU spreads each
//! point's samples over several threads so that a sparse layer still fills it. Lavapipe runs
//! one thread per point by default; here it runs every split, and the frame must be the
//! same: the same counts and traversal work, the same bits where a layer's spp is at most
//! the split, the same image up to rounding where it is more.

mod common;

use fovea::foveation::{FoveationConfig, Gaze, GazeChoice};
use fovea::render::{
    eye_views, DebugView, FovChoice, Frame, FrameOptions, FrameRequest, Integrator, Renderer,
    TemporalSettings,
};

const SIZE: u32 = 48;
const WORKGROUP: u64 = fovea::shader_layout::TRACE_WORKGROUP_SIZE as u64;

/// The thesis' layers with the fovea at 8 spp (the others at 4): one layer with more
/// samples than splits 2 and 4, every layer with fewer than 8.
fn config() -> FoveationConfig {
    let mut config = FoveationConfig::thesis();
    config.layers[0].spp = 8;
    config
}

/// One frame of `config` traced with `split` threads per point, history on (the trace also
/// writes each point's surface) and the traversal counted.
fn frame(renderer: &mut Renderer, split: u32, config: &FoveationConfig) -> Frame {
    renderer.set_trace_split(split).unwrap();
    renderer.reset_history();
    let scene_camera = fovea::scene::load("cornell", 1.0).unwrap().camera;
    let forward = GazeChoice {
        left: Gaze::Forward,
        right: Gaze::Forward,
    };
    let eyes = eye_views(&scene_camera, 1.0, FovChoice::Scene, false, forward);
    let request = FrameRequest {
        settings: common::settings(SIZE, SIZE, 1, 7, Integrator::Pt),
        foveation: config,
        eyes: &eyes,
        debug: DebugView::None,
    };
    renderer
        .frame(&request, FrameOptions::measure())
        .map(Option::unwrap)
        .unwrap()
}

#[test]
fn spreading_a_points_samples_over_threads_changes_no_count_and_the_image_at_most_by_rounding() {
    let ctx = common::context();
    let scene = fovea::scene::load("cornell", 1.0).unwrap();
    let mut renderer = Renderer::new(&ctx, &scene).unwrap();
    renderer
        .set_temporal(Some(TemporalSettings::default()))
        .unwrap();
    renderer.set_traversal_profile(true);
    renderer.set_output_image(true);
    assert_eq!(
        renderer.trace_split(),
        1,
        "the default: one thread per point"
    );
    let config = config();

    let one = frame(&mut renderer, 1, &config);
    let points: u64 = one
        .stats
        .layer_samples
        .iter()
        .zip(&config.layers)
        .map(|(samples, layer)| samples / layer.spp as u64)
        .sum();
    assert!(points > 0 && one.stats.paths > 0);
    assert!(one.rgb.iter().all(|v| v.is_finite()));
    let work = one.stats.traversal.unwrap();
    for split in [2u32, 4, 8, 64] {
        let f = frame(&mut renderer, split, &config);
        assert_eq!(
            f.stats.trace_workgroups,
            (points * split as u64).div_ceil(WORKGROUP),
            "split {split}: the trace ran {split} threads per traced point"
        );
        assert_eq!(f.stats.paths, one.stats.paths, "split {split}: paths");
        assert_eq!(f.stats.rays, one.stats.rays, "split {split}: rays");
        assert_eq!(f.stats.layer_samples, one.stats.layer_samples);
        assert_eq!(f.stats.nonfinite_samples, one.stats.nonfinite_samples);
        assert_eq!(f.stats.stack_overflows, one.stats.stack_overflows);
        let t = f.stats.traversal.unwrap();
        assert_eq!(
            (t.tlas_nodes, t.blas_nodes, t.triangles, t.tlas_lane_steps),
            (
                work.tlas_nodes,
                work.blas_nodes,
                work.triangles,
                work.tlas_lane_steps
            ),
            "split {split}: the same traversal work, lane by lane"
        );
        if split >= 8 {
            assert!(
                f.rgb == one.rgb,
                "split {split} >= every layer's spp: same bits"
            );
        } else {
            let worst = f
                .rgb
                .iter()
                .zip(&one.rgb)
                .map(|(a, b)| (a - b).abs() / b.abs().max(1.0))
                .fold(0.0f32, f32::max);
            assert!(
                worst < 1e-5,
                "split {split}: differs by {worst}, not rounding"
            );
        }
    }
    assert!(renderer.set_trace_split(3).is_err());
    let too_many = renderer.set_trace_split(128).unwrap_err().to_string();
    assert!(too_many.contains("power of two"), "{too_many}");
    drop(renderer);
    common::assert_no_validation_messages(&ctx);
}
