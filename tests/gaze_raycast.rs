//! The CPU ray cast that finds the eye's fixation point agrees with the GPU traversal
//! (`Renderer::raycast`, the integrators' own code) on built-in scenes: same hit or miss,
//! distances within 1e-4 relative, and one query takes microseconds.

mod common;

use fovea::render::Renderer;
use fovea::scene::builtin::builtin;
use fovea::scene::CpuRaycaster;
use fovea::shader_layout::GpuProbeRay;
use glam::Vec3;
use std::time::Instant;

struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> f32 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 40) as f32 / (1u64 << 24) as f32
    }
    fn unit(&mut self) -> Vec3 {
        let z = 2.0 * self.next() - 1.0;
        let phi = std::f32::consts::TAU * self.next();
        let r = (1.0 - z * z).max(0.0).sqrt();
        Vec3::new(r * phi.cos(), r * phi.sin(), z)
    }
}

/// Gaze-like rays: from near the scene's camera, half into its view cone (where an eye
/// looks), half in any direction.
fn rays(scene: &fovea::scene::Scene, n: usize) -> Vec<(Vec3, Vec3)> {
    let mut rng = Lcg(0xfe11 ^ scene.name.len() as u64);
    let (_, _, forward) = scene.camera.basis();
    (0..n)
        .map(|i| {
            let o = scene.camera.position + rng.unit() * 0.3 * rng.next();
            let d = if i % 2 == 0 {
                (forward + 0.25 * rng.unit()).normalize()
            } else {
                rng.unit()
            };
            (o, d)
        })
        .collect()
}

fn check_scene(name: &str) {
    let scene = builtin(name, 1.0).unwrap();
    let started = Instant::now();
    let cpu = CpuRaycaster::new(&scene);
    let build_ms = started.elapsed().as_secs_f64() * 1e3;
    let rays = rays(&scene, 400);
    let probes: Vec<GpuProbeRay> = rays
        .iter()
        .map(|(o, d)| GpuProbeRay {
            origin: [o.x, o.y, o.z, 0.0],
            direction: [d.x, d.y, d.z, f32::INFINITY],
        })
        .collect();
    let ctx = common::context();
    let mut renderer = Renderer::new(&ctx, &scene).unwrap();
    let (hits, overflows) = renderer.raycast(&probes).unwrap();
    drop(renderer);
    common::assert_no_validation_messages(&ctx);
    assert_eq!(overflows, 0);

    let started = Instant::now();
    let (answers, tests): (Vec<Option<f32>>, Vec<u32>) = rays
        .iter()
        .map(|(o, d)| cpu.closest_hit_counted(*o, *d))
        .unzip();
    let per_ray_us = started.elapsed().as_secs_f64() * 1e6 / rays.len() as f64;

    let mut hit_count = 0;
    for ((o, d), (gpu, cpu)) in rays.iter().zip(hits.iter().zip(&answers)) {
        match (gpu.t.is_finite(), cpu) {
            (true, Some(t)) => {
                hit_count += 1;
                assert!(
                    (t - gpu.t).abs() <= 1e-4 * gpu.t,
                    "{name}: ray {o} {d}: CPU t = {t}, GPU t = {}",
                    gpu.t
                );
            }
            (false, None) => {}
            _ => panic!("{name}: ray {o} {d}: CPU {cpu:?}, GPU t = {}", gpu.t),
        }
    }
    eprintln!(
        "{name}: {hit_count} of {} rays hit; BVH build {build_ms:.1} ms, {per_ray_us:.2} µs per ray",
        rays.len()
    );
    assert!(
        hit_count > rays.len() / 4,
        "{name}: only {hit_count} rays hit; the test would prove little"
    );
    // The gaze ray runs on the CPU every frame, so it must not test the whole scene: the
    // BVHs leave a small fraction of the primitives to test (the time per ray is printed
    // above as a figure; on a busy machine it says nothing about the work).
    let primitives = scene.boxes.len()
        + scene.spheres.len()
        + scene.instances.len()
        + (scene.instances.iter())
            .map(|i| scene.meshes[i.mesh as usize].indices.len())
            .sum::<usize>();
    let mean_tests = tests.iter().map(|&t| t as f64).sum::<f64>() / tests.len() as f64;
    eprintln!("{name}: {mean_tests:.1} primitive tests per ray of {primitives} primitives");
    // A scene of a few dozen primitives may leave a handful to test.
    assert!(
        mean_tests > 0.0 && mean_tests < (0.05 * primitives as f64).max(8.0),
        "{name}: {mean_tests:.1} primitive tests per ray of {primitives}"
    );
}

#[test]
fn cpu_and_gpu_agree_on_a_triangle_mesh_over_an_analytic_ground() {
    check_scene("bunny-high");
}

#[test]
fn cpu_and_gpu_agree_on_many_boxes() {
    check_scene("cubes-441");
}

#[test]
fn cpu_and_gpu_agree_inside_a_closed_room_of_boxes_and_spheres() {
    check_scene("mirror-room");
}

#[test]
fn cpu_and_gpu_agree_on_the_cornell_box() {
    check_scene("cornell");
}
