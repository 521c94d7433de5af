//! GPU closest-hit distances through the CWBVH traversal equal a brute-force CPU reference
//! (f64 arithmetic over every world-space triangle, box and sphere) for 100 000 random rays.

mod common;

use common::rays::{box_t, triangle_t};
use fovea::render::Renderer;
use fovea::scene::builtin::builtin;
use fovea::scene::Scene;
use glam::{DVec3, Vec3};

fn reference_t(scene: &Scene, tris: &[[DVec3; 3]], o: DVec3, d: DVec3) -> f64 {
    let mut best = f64::INFINITY;
    for t in tris {
        best = best.min(triangle_t(o, d, *t, 0.0));
    }
    for b in &scene.boxes {
        best = best.min(box_t(o, d, b.min.as_dvec3(), b.max.as_dvec3()));
    }
    best
}

fn check_scene(name: &str) {
    let scene = builtin(name, 1.0).unwrap();
    let tris = common::rays::world_triangles(&scene);
    // Rays start around the scene's interesting region (the camera target area) and point in
    // random directions; half of them aim at a random triangle or box so most hit.
    let n = 100_000;
    let rays = common::rays::random_rays(&scene, n, 0x5eed ^ name.len() as u64);
    let ctx = common::context();
    let mut renderer = Renderer::new(&ctx, &scene).unwrap();
    let (hits, overflows) = renderer.raycast(&rays).unwrap();
    drop(renderer);
    common::assert_no_validation_messages(&ctx);
    assert_eq!(overflows, 0);
    let (mut hit_count, mut mismatches) = (0, 0);
    for (ray, hit) in rays.iter().zip(&hits) {
        let o = Vec3::from_slice(&ray.origin[..3]).as_dvec3();
        let d = Vec3::from_slice(&ray.direction[..3]).as_dvec3();
        let expected = reference_t(&scene, &tris, o, d);
        let got = hit.t as f64;
        let agree = if expected.is_finite() {
            hit_count += 1;
            (got - expected).abs() <= 1e-4 * expected.max(1.0)
        } else {
            got.is_infinite()
        };
        if !agree {
            mismatches += 1;
            if mismatches <= 5 {
                eprintln!("{name}: ray {o:?} {d:?}: GPU t = {got}, CPU t = {expected}");
            }
        }
    }
    eprintln!("{name}: {n} rays, {hit_count} hits, {mismatches} mismatches");
    assert!(
        hit_count > n / 3,
        "too few rays hit ({hit_count}): the test would prove little"
    );
    // Rays grazing an edge or corner within float rounding may legitimately differ between
    // the f32 watertight test and the f64 reference; anything beyond 1 in 10 000 is a bug.
    assert!(
        mismatches <= n / 10_000,
        "{mismatches} of {n} rays disagree with the CPU reference"
    );
}

#[test]
fn gpu_closest_hits_match_cpu_reference_on_bunny_high() {
    check_scene("bunny-high");
}

#[test]
fn gpu_closest_hits_match_cpu_reference_on_cubes_441() {
    check_scene("cubes-441");
}
