//! What picking lights by power buys against picking them uniformly, at equal samples per
//! pixel: relative RMS error against a 4096-spp render (power), over 8 seeds, for
//! `assets/gltf/punctual-lights.glb`, the same geometry lit by one bright point light and 50
//! dim ones, and cornell; under the gradient sky (which is not a light for next-event
//! estimation). Also the two references' means, which must agree (both are unbiased).
//!
//!   cargo run --release --example light_selection_gain -- [--size N]

use std::sync::Arc;

use fovea::gpu::{GpuContext, GpuOptions};
use fovea::scene::gltf_samples::punctual_lights;
use fovea::scene::{LightKind, LightSelection, PunctualLight, Scene};
use glam::Vec3;
use shared::{arg, relative_error, render_rgb};

mod shared;

/// punctual-lights' geometry lit by one bright warm point light and 50 dim tinted ones on a
/// spiral around it (0.02–0.2 cd; the bright one (20, 15, 10) cd).
fn many_lights() -> Scene {
    let mut scene = punctual_lights();
    scene.name = "many-lights".into();
    scene.lights.clear();
    let point = |intensity: Vec3, position: Vec3| PunctualLight {
        kind: LightKind::Point,
        intensity,
        position,
        direction: Vec3::NEG_Z,
        range: None,
    };
    scene.lights.push(point(
        Vec3::new(20.0, 15.0, 10.0),
        Vec3::new(-1.5, 2.2, 1.5),
    ));
    for k in 0..50u32 {
        let angle = k as f32 * 2.39996; // the golden angle
        let radius = 2.2 + 1.5 * k as f32 / 50.0;
        let height = 0.25 + 1.5 * ((k * 7) % 11) as f32 / 10.0;
        let level = 0.02 + 0.18 * ((k * 13) % 17) as f32 / 16.0;
        let tint = [
            Vec3::new(1.0, 0.6, 0.3),
            Vec3::new(0.3, 0.6, 1.0),
            Vec3::new(0.5, 1.0, 0.5),
        ];
        let at = Vec3::new(radius * angle.cos(), height, radius * angle.sin());
        scene.lights.push(point(tint[k as usize % 3] * level, at));
    }
    scene
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    shared::choose_sampler()?;
    let size = arg("--size", 128);
    let ctx = Arc::new(GpuContext::new(&GpuOptions::default())?);
    let render = |scene: &Scene, selection, spp, seed| {
        let scene = Scene {
            light_selection: selection,
            ..scene.clone()
        };
        render_rgb(&ctx, &scene, size, spp, seed)
    };
    let mean = |image: &[f32]| image.iter().map(|&v| v as f64).sum::<f64>() / image.len() as f64;
    let sample = fovea::scene::load(
        concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/assets/gltf/punctual-lights.glb"
        ),
        1.0,
    )?;
    let cornell = fovea::scene::builtin::builtin("cornell", 1.0)?;
    println!("{size}×{size}, relative RMS error over seeds 1–8 against 4096 spp (power)");
    println!("| scene | spp | power | uniform | uniform ÷ power |");
    println!("|---|---:|---:|---:|---:|");
    for scene in [sample, many_lights(), cornell] {
        let reference = render(&scene, LightSelection::Power, 4096, 99)?;
        let other = render(&scene, LightSelection::Uniform, 4096, 98)?;
        for spp in [4, 16, 64] {
            let rms = |selection| -> Result<f64, Box<dyn std::error::Error>> {
                let mut squares = 0.0;
                for seed in 1..=8 {
                    squares +=
                        relative_error(&render(&scene, selection, spp, seed)?, &reference).powi(2);
                }
                Ok((squares / 8.0).sqrt())
            };
            let (p, u) = (rms(LightSelection::Power)?, rms(LightSelection::Uniform)?);
            println!(
                "| {} | {spp} | {p:.3} | {u:.3} | {:.2}× |",
                scene.name,
                u / p
            );
        }
        println!(
            "| {} | means at 4096 spp: power {:.5}, uniform {:.5} | | | |",
            scene.name,
            mean(&reference),
            mean(&other)
        );
    }
    Ok(())
}
