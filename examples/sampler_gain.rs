//! What the blue-noise sampler (`--sampler zsobol`) buys against the independent one at equal
//! samples per pixel, with nothing else changed: relative MSE against a 512-spp reference, and
//! FovVideoVDP's JOD (foveated at the image centre, the Vive Pro's photometry) of the image as
//! the display transform shows it, each the mean over seeds 1–4, at 1 and 4 spp. The image is
//! `--size` pixels square over the scene camera's own field of view (cornell's 39°: 13 px/° at
//! 512, the Vive Pro Eye's density).
//!
//!   cargo run --release --example sampler_gain -- [--size N]   (needs tools/setup-fvvdp.sh)

use std::sync::Arc;

use fovea::foveation::{EyeFov, ImageGeometry};
use fovea::gpu::{GpuContext, GpuOptions};
use fovea::metrics::jod::Fvvdp;
use fovea::render::display::DisplayTransform;
use fovea::render::{regular_frame, RenderSettings, Renderer, Sampler};
use fovea::scene::Scene;
use shared::{arg, square};

mod shared;

/// Mean squared error over mean squared reference (per pixel and channel, the reference
/// floored at 0.01 so that black pixels do not dominate).
fn relative_mse(image: &[f32], reference: &[f32]) -> f64 {
    let sum: f64 = (image.iter().zip(reference))
        .map(|(a, b)| ((a - b) as f64).powi(2) / ((*b as f64).powi(2) + 0.01))
        .sum();
    sum / image.len() as f64
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let size = arg("--size", 512);
    let ctx = Arc::new(GpuContext::new(&GpuOptions::default())?);
    let mut metric = Fvvdp::start()?;
    let scenes = [
        "cornell",
        "bunny-high",
        concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/assets/gltf/punctual-lights.glb"
        ),
    ];
    println!("{size}×{size}; relMSE against 512 spp and JOD, means over seeds 1–4");
    println!("| scene | spp | relMSE independent | relMSE zsobol | ratio | JOD independent | JOD zsobol |");
    println!("|---|---:|---:|---:|---:|---:|---:|");
    for name in scenes {
        let mut scene: Scene = fovea::scene::load(name, 1.0)?;
        scene.camera = scene.camera.with_aspect(1.0);
        let c = scene.camera;
        let geometry = ImageGeometry::new(
            size,
            size,
            EyeFov {
                left: c.angle_left,
                right: c.angle_right,
                up: c.angle_up,
                down: c.angle_down,
            },
        );
        let display = DisplayTransform::for_scene(name, 0.0, None);
        let mut renderer = Renderer::new(&ctx, &scene)?;
        let mut render = |spp, seed, sampler| -> Result<Vec<f32>, Box<dyn std::error::Error>> {
            let settings = RenderSettings {
                sampler,
                ..square(size, spp, seed)
            };
            Ok(regular_frame(&mut renderer, &scene.camera, &settings)?.rgb)
        };
        let reference = render(512, 99, Sampler::Independent)?;
        let centre = [size as f64 / 2.0; 2];
        let short = name.rsplit('/').next().unwrap_or(name);
        for spp in [1, 4] {
            let mut row = Vec::new();
            for measure in ["relmse", "jod"] {
                for sampler in [Sampler::Independent, Sampler::Zsobol] {
                    let mut total = 0.0;
                    for seed in 1..=4 {
                        let image = render(spp, seed, sampler)?;
                        total += match measure {
                            "relmse" => relative_mse(&image, &reference),
                            _ => metric.image(&image, &reference, &geometry, centre, &display)?,
                        };
                    }
                    row.push(total / 4.0);
                }
            }
            println!(
                "| {short} | {spp} | {:.4} | {:.4} | {:.2}× | {:.3} | {:.3} |",
                row[0],
                row[1],
                row[0] / row[1],
                row[2],
                row[3]
            );
        }
    }
    Ok(())
}
