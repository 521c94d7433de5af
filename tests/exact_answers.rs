//! Scenes whose radiance is known in closed form, for both integrators. Tolerances are several
//! standard errors of the image mean at the sample counts used (stated per test).

mod common;

use fovea::check::scale::quad;
use fovea::render::Integrator;
use fovea::scene::{Camera, Environment, Instance, Material, Scene, Sphere};
use glam::{Mat4, Vec3};

fn empty_scene(name: &str, camera: Camera, environment: Environment) -> Scene {
    Scene {
        name: name.into(),
        meshes: vec![],
        instances: vec![],
        boxes: vec![],
        spheres: vec![],
        materials: vec![],
        textures: Vec::new(),
        camera,
        environment,
        lights: Vec::new(),
        environment_map: None,
        light_selection: Default::default(),
    }
}

/// A large horizontal quad seen from above so that it fills the whole frame.
fn plane_scene(material: Material, environment: Environment) -> Scene {
    let camera = Camera::look_at(Vec3::new(0.0, 2.0, 0.5), Vec3::ZERO, Vec3::Y, 30.0, 1.0);
    let mut s = empty_scene("plane", camera, environment);
    s.meshes.push(quad());
    s.materials.push(material);
    s.instances.push(Instance {
        mesh: 0,
        material: 0,
        transform: Mat4::from_scale(Vec3::new(50.0, 1.0, 50.0)),
    });
    s
}

#[test]
fn diffuse_plane_under_uniform_sky_shows_albedo_times_sky() {
    // L_o = ∫ (a/π) L cos θ dω = a·L for every point, whatever the bounce limit (≥ 1).
    let ctx = common::context();
    let (a, l) = (0.6f32, Vec3::new(1.0, 0.5, 0.25));
    let scene = plane_scene(Material::diffuse(Vec3::splat(a)), Environment::uniform(l));
    for integrator in [Integrator::Pt, Integrator::Seed] {
        let frame = common::render(&ctx, &scene, &common::settings(32, 32, 256, 3, integrator));
        let mean = frame.mean();
        for c in 0..3 {
            let expected = (a * l[c]) as f64;
            // Per-sample σ ≤ a·L for seed (uniform hemisphere weight 2cosθ); 262 144 samples
            // give a standard error < 0.2% of the value: 1% is > 5σ.
            assert!(
                (mean[c] - expected).abs() < 0.01 * expected,
                "{integrator:?} channel {c}: {} vs {expected}",
                mean[c]
            );
        }
    }
}

#[test]
fn white_furnace_converges_to_the_bounce_limited_sum() {
    // Inside a closed sphere of albedo a emitting E everywhere, a path gathers E at vertices
    // 0..k, each weighted by a^i in expectation: L = E(1 − a^(k+1)) / (1 − a).
    let ctx = common::context();
    let (a, e) = (0.5f32, 1.0f32);
    for k in [0u32, 1, 3, 8] {
        let expected = (e * (1.0 - a.powi(k as i32 + 1)) / (1.0 - a)) as f64;
        let camera = Camera::look_at(Vec3::ZERO, Vec3::new(0.0, 0.0, -1.0), Vec3::Y, 60.0, 1.0);
        let mut scene = empty_scene("furnace", camera, Environment::black());
        scene
            .materials
            .push(Material::emitter(Vec3::splat(a), Vec3::splat(e)));
        scene.spheres.push(Sphere {
            center: Vec3::new(0.3, -0.2, 0.1),
            radius: 2.0,
            material: 0,
        });
        for integrator in [Integrator::Pt, Integrator::Seed] {
            let mut s = common::settings(32, 32, 64, 5, integrator);
            s.max_bounces = k;
            let frame = common::render(&ctx, &scene, &s);
            let mean = frame.mean();
            for (c, m) in mean.iter().enumerate() {
                assert!(
                    (m - expected).abs() < 0.01 * expected,
                    "k={k} {integrator:?} channel {c}: {m} vs {expected}"
                );
            }
        }
    }
}

/// CPU copy of glsl/integrators.glsl's environment(), for the mirror test.
fn sky(env: &Environment, d: Vec3) -> Vec3 {
    let y = d.y / d.length();
    if y >= 0.0 {
        env.horizon.lerp(env.zenith, y)
    } else {
        env.horizon.lerp(env.ground, (-8.0 * y).min(1.0))
    }
}

#[test]
fn perfect_mirror_reflects_the_sky_exactly() {
    let ctx = common::context();
    let env = Environment::sky();
    let ks = Vec3::new(0.9, 0.8, 0.7);
    let scene = plane_scene(Material::mirror(ks), env);
    let (w, h) = (32u32, 32u32);
    for integrator in [Integrator::Pt, Integrator::Seed] {
        let frame = common::render(&ctx, &scene, &common::settings(w, h, 16, 9, integrator));
        let cam = &scene.camera;
        let (r, u, f) = cam.basis();
        let mut worst = 0.0f32;
        for y in 0..h {
            for x in 0..w {
                // The pixel centre's reflected direction; the sky varies little across a pixel.
                let tx = cam.angle_left.tan()
                    + (x as f32 + 0.5) / w as f32 * (cam.angle_right.tan() - cam.angle_left.tan());
                let ty = cam.angle_up.tan()
                    + (y as f32 + 0.5) / h as f32 * (cam.angle_down.tan() - cam.angle_up.tan());
                let d = (f + tx * r + ty * u).normalize();
                let reflected = Vec3::new(d.x, -d.y, d.z);
                let expected = ks * sky(&env, reflected);
                let got = Vec3::from(frame.pixel(x, y));
                worst = worst.max(((got - expected) / expected).abs().max_element());
            }
        }
        // Within a pixel the reflected direction spans < 1°; the gradient changes < 1% there.
        assert!(worst < 0.01, "{integrator:?}: worst relative error {worst}");
    }
}
