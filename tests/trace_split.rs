//! The trace's threads per lattice point (`Renderer::set_trace_lanes`): a GPU spreads each
//! point's samples over several threads so that a sparse layer still fills it. Lavapipe runs
//! one thread per point by default; here it runs several rules, and the frame must be the
//! same: the same counts and traversal work, the same bits where each layer's spp is at most
//! its lanes, the same image up to rounding where it is more.

mod common;

use fovea::foveation::{FoveationConfig, Gaze, GazeChoice};
use fovea::render::{
    eye_views, DebugView, FovChoice, Frame, FrameOptions, FrameRequest, Integrator, Renderer,
    TraceLanes,
};

const SIZE: u32 = 48;
const WORKGROUP: u64 = fovea::shader_layout::TRACE_WORKGROUP_SIZE as u64;

/// The thesis' layers with the fovea at 8 spp and the background at 1 (the others at 4):
/// layers of 8, 4 and 1 lanes side by side, whose work-list runs are padded.
fn config() -> FoveationConfig {
    let mut config = FoveationConfig::thesis();
    config.layers[0].spp = 8;
    config.layers[3].spp = 1;
    config
}

/// One frame of `config` traced with `lanes`, history on (the trace also writes each
/// point's surface) and the traversal counted.
fn frame(renderer: &mut Renderer, lanes: TraceLanes, config: &FoveationConfig) -> Frame {
    renderer.set_trace_lanes(lanes);
    renderer.reset_history();
    let camera = fovea::scene::load("cornell", 1.0).unwrap().camera;
    let forward = GazeChoice {
        left: Gaze::Forward,
        right: Gaze::Forward,
    };
    let eyes = eye_views(&camera, 1.0, FovChoice::Scene, false, forward);
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

/// The largest difference between two images, relative where a value exceeds 1.
fn worst_difference(a: &Frame, b: &Frame) -> f32 {
    a.rgb
        .iter()
        .zip(&b.rgb)
        .map(|(x, y)| (x - y).abs() / y.abs().max(1.0))
        .fold(0.0, f32::max)
}

#[test]
fn spreading_a_points_samples_over_threads_changes_no_count_and_the_image_at_most_by_rounding() {
    let ctx = common::context();
    let scene = fovea::scene::load("cornell", 1.0).unwrap();
    let mut renderer = common::renderer_with_history(&ctx, &scene);
    renderer.set_traversal_profile(true);
    renderer.set_output_image(true);
    assert_eq!(
        renderer.trace_lanes(),
        TraceLanes::ONE,
        "lavapipe's default"
    );
    let config = config();

    let one = frame(&mut renderer, TraceLanes::ONE, &config);
    let points: Vec<u64> = one
        .stats
        .layer_samples
        .iter()
        .zip(&config.layers)
        .map(|(samples, layer)| samples / layer.spp as u64)
        .collect();
    let all_points: u64 = points.iter().sum();
    assert!(all_points > 0 && one.stats.paths > 0);
    assert_eq!(one.stats.trace_workgroups, all_points.div_ceil(WORKGROUP));
    assert!(one.rgb.iter().all(|v| v.is_finite()));
    let work = one.stats.traversal.unwrap();
    let spp: Vec<u32> = config.layers.iter().map(|l| l.spp).collect();
    let rules = [
        (2, 1, 0),
        (4, 1, 0),
        (8, 1, 0),
        (64, 1, 0),
        (8, 2, 0),
        (16, 4, 1 << 30),
    ];
    for (max_lanes, samples_per_lane, fill) in rules {
        let lanes = TraceLanes::new(max_lanes, samples_per_lane)
            .unwrap()
            .with_fill_threads(fill);
        let what =
            format!("at most {max_lanes} lanes of {samples_per_lane}+ samples, {fill} threads");
        let f = frame(&mut renderer, lanes, &config);
        // Each point has its layer's lanes; runs are padded to the most lanes of a layer.
        let layer_lanes = lanes.of_layers(&spp, &points);
        if fill > 0 {
            assert_eq!(layer_lanes, spp, "{what}: filled up to one sample a lane");
        }
        let slots: u64 = points
            .iter()
            .zip(&layer_lanes)
            .map(|(&p, &l)| p * l as u64)
            .sum();
        let unit = *layer_lanes.iter().max().unwrap() as u64;
        assert!(
            f.stats.trace_workgroups >= slots.div_ceil(WORKGROUP)
                && f.stats.trace_workgroups <= (all_points * unit).div_ceil(WORKGROUP),
            "{what}: {} trace workgroups for {slots} lanes",
            f.stats.trace_workgroups
        );
        assert_eq!(f.stats.paths, one.stats.paths, "{what}: paths");
        assert_eq!(f.stats.rays, one.stats.rays, "{what}: rays");
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
            "{what}: the same traversal work, lane by lane"
        );
        if spp.iter().zip(&layer_lanes).all(|(s, l)| s <= l) {
            assert!(
                f.rgb == one.rgb,
                "{what}: each spp within its lanes: same bits"
            );
        } else {
            let worst = worst_difference(&f, &one);
            assert!(worst < 1e-5, "{what}: differs by {worst}, not rounding");
        }
    }
    drop(renderer);
    common::assert_no_validation_messages(&ctx);
}
