//! What importance sampling an HDR environment buys, per environment of `assets/env/`: a
//! diffuse floor with a sphere on it (as tests/environment.rs), rendered at `--spp` with the
//! environment sampled by luminance × sin θ and uniformly over the sphere, each against the
//! importance-sampled image at `--reference-spp`. Prints, per environment, the share of its
//! light in its 40 brightest texels, both relative RMS errors and their ratio.
//!
//!   cargo run --release --example env_sampling_gain -- [--size N] [--spp N] [--reference-spp N]

use std::path::Path;
use std::sync::Arc;

use fovea::gpu::{GpuContext, GpuOptions};
use fovea::scene::lights::luminance;
use fovea::scene::{
    Camera, EnvSampling, Environment, EnvironmentLight, EnvironmentMap, Instance, Material, Scene,
    Sphere,
};
use glam::{Mat4, Vec3};
use shared::{arg, relative_error, render_rgb};

mod shared;

const ENVIRONMENTS: [&str; 8] = [
    "city",
    "courtyard",
    "forest",
    "interior",
    "night",
    "studio",
    "sunrise",
    "sunset",
];

fn floor_and_sphere(map: &Arc<EnvironmentMap>, sampling: EnvSampling) -> Scene {
    Scene {
        name: "floor-and-sphere".into(),
        meshes: vec![fovea::check::scale::quad()],
        instances: vec![Instance {
            mesh: 0,
            material: 0,
            transform: Mat4::from_scale(Vec3::new(20.0, 1.0, 20.0)),
        }],
        boxes: vec![],
        spheres: vec![Sphere {
            center: Vec3::new(0.0, 0.5, 0.0),
            radius: 0.5,
            material: 0,
        }],
        materials: vec![Material::diffuse(Vec3::splat(0.6))],
        textures: vec![],
        camera: Camera::look_at(Vec3::new(0.0, 1.5, 3.0), Vec3::ZERO, Vec3::Y, 40.0, 1.0),
        environment: Environment::black(),
        lights: vec![],
        environment_map: Some(EnvironmentLight {
            map: map.clone(),
            rotate_deg: 0.0,
            intensity: 1.0,
            sampling,
        }),
        light_selection: Default::default(),
    }
}

/// The share of the map's luminance × sin θ in its 40 brightest texels.
fn concentration(map: &EnvironmentMap) -> f64 {
    let (w, h) = (map.width as usize, map.height as usize);
    let mut weights: Vec<f64> = (0..w * h)
        .map(|i| {
            let theta = ((i / w) as f64 + 0.5) / h as f64 * std::f64::consts::PI;
            luminance(map.texels[i]) as f64 * theta.sin()
        })
        .collect();
    let total: f64 = weights.iter().sum();
    weights.sort_by(|a, b| b.total_cmp(a));
    weights.iter().take(40).sum::<f64>() / total
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    shared::choose_sampler()?;
    let (size, spp, reference_spp) = (
        arg("--size", 24),
        arg("--spp", 16),
        arg("--reference-spp", 4096),
    );
    let ctx = Arc::new(GpuContext::new(&GpuOptions::default())?);
    let render = |scene: &Scene, spp, seed| render_rgb(&ctx, scene, size, spp, seed);
    println!("{size}×{size}, {spp} spp against {reference_spp} spp (importance sampled)");
    println!("| environment | light in 40 brightest texels | rel. error, importance | rel. error, uniform | ratio |");
    println!("|---|---:|---:|---:|---:|");
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/env");
    for name in ENVIRONMENTS {
        let map = Arc::new(EnvironmentMap::load(&root.join(format!("{name}.exr")))?);
        let importance = floor_and_sphere(&map, EnvSampling::Importance);
        let uniform = floor_and_sphere(&map, EnvSampling::Uniform);
        let reference = render(&importance, reference_spp, 13)?;
        let ei = relative_error(&render(&importance, spp, 21)?, &reference);
        let eu = relative_error(&render(&uniform, spp, 21)?, &reference);
        println!(
            "| {name} | {:.1}% | {ei:.4} | {eu:.4} | {:.1}× |",
            100.0 * concentration(&map),
            eu / ei
        );
    }
    Ok(())
}
