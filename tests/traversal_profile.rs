//! The traversal profile (`Renderer::set_traversal_profile`, `fovea render
//! --profile-traversal`): it leaves the image alone, and its counts are consistent with the
//! scene's geometry and with each other.

mod common;

use fovea::render::regular_frame;
use fovea::render::{Frame, Integrator, Renderer, TraversalCounts};
use fovea::scene::builtin::builtin;

fn render(name: &str, profile: bool) -> Frame {
    let ctx = common::context();
    let scene = builtin(name, 1.0).expect("built-in scene");
    let settings = common::settings(48, 48, 2, 7, Integrator::Pt);
    let mut renderer = Renderer::new(&ctx, &scene).expect("scene upload");
    renderer.set_traversal_profile(profile);
    let frame = regular_frame(&mut renderer, &scene.camera, &settings).expect("render");
    drop(renderer);
    common::assert_no_validation_messages(&ctx);
    frame
}

/// Renders with and without the profile; returns the counts after checking that the image
/// and the ray count are the same and that only the profiled frame has counts.
fn profile(name: &str) -> (TraversalCounts, u64, u32) {
    let plain = render(name, false);
    let profiled = render(name, true);
    assert!(
        plain.stats.traversal.is_none(),
        "{name}: counts without profiling"
    );
    assert_eq!(
        plain.rgb, profiled.rgb,
        "{name}: profiling changed the image"
    );
    assert_eq!(plain.stats.rays, profiled.stats.rays, "{name}");
    let subgroup = common::context().info.subgroup_size;
    (
        profiled.stats.traversal.expect("profiled counts"),
        profiled.stats.rays,
        subgroup,
    )
}

/// Every ray enters the TLAS root; a step intersects at most one node; a subgroup step has
/// between one and subgroup-size lanes busy.
fn assert_consistent(name: &str, t: &TraversalCounts, rays: u64, subgroup: u32) {
    assert!(t.tlas_nodes >= rays, "{name}: {t:?} for {rays} rays");
    assert!(t.tlas_lane_steps >= t.tlas_nodes, "{name}: {t:?}");
    assert!(t.blas_lane_steps >= t.blas_nodes, "{name}: {t:?}");
    for (lane, group) in [
        (t.tlas_lane_steps, t.tlas_group_steps),
        (t.blas_lane_steps, t.blas_group_steps),
    ] {
        assert!(
            group <= lane && lane <= group * subgroup as u64,
            "{name}: {t:?}"
        );
    }
}

#[test]
fn a_mesh_scene_counts_triangles_and_blas_nodes_but_no_primitives() {
    let (t, rays, subgroup) = profile("cornell");
    assert_consistent("cornell", &t, rays, subgroup);
    assert!(t.triangles > 0 && t.blas_nodes > 0, "{t:?}");
    assert_eq!(t.primitives, 0, "cornell has no boxes or spheres: {t:?}");
}

#[test]
fn an_analytic_scene_counts_primitives_and_no_triangles() {
    let (t, rays, subgroup) = profile("cubes-441");
    assert_consistent("cubes-441", &t, rays, subgroup);
    assert!(t.primitives > 0, "{t:?}");
    assert_eq!(
        (t.triangles, t.blas_nodes, t.blas_lane_steps),
        (0, 0, 0),
        "cubes-441 has no meshes: {t:?}"
    );
}

#[test]
fn an_empty_scene_traverses_nothing() {
    let (t, rays, _) = profile("control");
    assert!(rays > 0);
    assert_eq!(t, TraversalCounts::default(), "control has no geometry");
}
