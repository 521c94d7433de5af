//! What ray-cone texture filtering costs and buys, measured: a glTF file (or, without one, a
//! floor with a 2048² checkerboard repeated 50 times, seen at a grazing angle) rendered with
//! every texture's mip chain (the level from the ray cone) and with level 0 only (the same
//! scene with its samplers' mipmaps off), alternately, at 1 spp. Prints the median GPU ms,
//! Msamples/s, and the RMSE of each against a 64-spp render at level 0 (the pixel's true
//! average of the texels it covers, which the cones' prefiltering only approximates).
//!
//!   cargo run --release --example texture_lod -- [FILE.gltf|.glb] [--size N] [--frames N]

use std::sync::Arc;

use fovea::gpu::{GpuContext, GpuOptions};
use fovea::render::{regular_frame, Frame, Integrator, RenderSettings, Renderer};
use fovea::scene::gltf_load::load_gltf;
use fovea::scene::{
    Camera, Environment, Instance, Material, MaterialTextures, Mesh, MetallicRoughness, Scene,
    TexelEncoding, Texture, TextureRef, TextureSampler, VertexShading,
};
use glam::{Mat4, Vec2, Vec3};

fn floor() -> Scene {
    let n = 2048u32;
    let rgba8 = (0..n * n)
        .flat_map(|i| {
            let (x, y) = (i % n, i / n);
            let v = if (x / 4 + y / 4) % 2 == 0 { 230 } else { 25 };
            [v, ((x * 255) / n) as u8, ((y * 255) / n) as u8, 255]
        })
        .collect();
    let repeats = 50.0;
    let uv = |u: f32, v: f32| Vec2::new(u * repeats, v * repeats);
    Scene {
        name: "checker-floor".into(),
        meshes: vec![Mesh {
            name: "floor".into(),
            positions: vec![
                Vec3::new(-1.0, -1.0, 0.0),
                Vec3::new(1.0, -1.0, 0.0),
                Vec3::new(1.0, 1.0, 0.0),
                Vec3::new(-1.0, 1.0, 0.0),
            ],
            indices: vec![[0, 1, 2], [0, 2, 3]],
            shading: VertexShading {
                normals: vec![],
                uv: [
                    vec![uv(0.0, 1.0), uv(1.0, 1.0), uv(1.0, 0.0), uv(0.0, 0.0)],
                    vec![],
                ],
                tangents: vec![],
            },
        }],
        instances: vec![Instance {
            mesh: 0,
            material: 0,
            transform: Mat4::from_scale(Vec3::new(50.0, 50.0, 1.0)),
        }],
        boxes: vec![],
        spheres: vec![],
        materials: vec![Material::MetallicRoughness(MetallicRoughness {
            textures: MaterialTextures {
                base_color: Some(TextureRef {
                    texture: 0,
                    texcoord: 0,
                    transform: TextureRef::IDENTITY,
                }),
                ..MaterialTextures::NONE
            },
            ..MetallicRoughness::factors(Vec3::ONE, 0.0, 0.6, Vec3::ZERO)
        })],
        textures: vec![Texture {
            name: "checkerboard 2048²".into(),
            width: n,
            height: n,
            rgba8,
            encoding: TexelEncoding::Srgb,
            sampler: TextureSampler::DEFAULT,
        }],
        camera: Camera::look_at(
            Vec3::new(0.0, -45.0, 1.5),
            Vec3::new(0.0, 20.0, 0.0),
            Vec3::Z,
            50.0,
            1.0,
        ),
        environment: Environment::sky(),
        lights: Vec::new(),
        environment_map: None,
        light_selection: Default::default(),
    }
}

fn rmse(a: &Frame, b: &Frame) -> f64 {
    let n = a.rgb.len() as f64;
    (a.rgb
        .iter()
        .zip(&b.rgb)
        .map(|(x, y)| ((x - y) as f64).powi(2))
        .sum::<f64>()
        / n)
        .sqrt()
}

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let value = |flag: &str, default: u32| {
        args.iter()
            .position(|a| a == flag)
            .and_then(|i| args.get(i + 1))
            .map_or(Ok(default), |v| v.parse())
    };
    let (size, frames) = (value("--size", 512)?, value("--frames", 5)?);
    let file = args
        .iter()
        .find(|a| a.ends_with(".gltf") || a.ends_with(".glb"));
    let mipmapped = match file {
        Some(path) => load_gltf(path.as_ref(), 1.0)?,
        None => floor(),
    };
    let mut finest = mipmapped.clone();
    for t in &mut finest.textures {
        t.sampler.mipmaps = false;
    }
    let ctx = Arc::new(GpuContext::new(&GpuOptions::default())?);
    let settings = |spp, seed| RenderSettings {
        sampler: Default::default(),
        width: size,
        height: size,
        spp,
        seed,
        integrator: Integrator::Pt,
        max_bounces: 8,
    };
    let mut with_cones = Renderer::new(&ctx, &mipmapped)?;
    let mut level_0 = Renderer::new(&ctx, &finest)?;
    let reference = regular_frame(&mut level_0, &finest.camera, &settings(64, 99))?;
    let (mut cone_ms, mut level_0_ms) = (Vec::new(), Vec::new());
    let (mut cone_error, mut level_0_error) = (0.0, 0.0);
    for f in 0..frames {
        let a = regular_frame(&mut with_cones, &mipmapped.camera, &settings(1, f))?;
        let b = regular_frame(&mut level_0, &finest.camera, &settings(1, f))?;
        cone_ms.push(a.stats.gpu_ms());
        level_0_ms.push(b.stats.gpu_ms());
        cone_error += rmse(&a, &reference) / frames as f64;
        level_0_error += rmse(&b, &reference) / frames as f64;
    }
    let median = |v: &mut Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let paths = (size * size) as f64;
    for (what, ms, error) in [
        ("ray-cone LOD", median(&mut cone_ms), cone_error),
        ("level 0 only", median(&mut level_0_ms), level_0_error),
    ] {
        println!(
            "{}: {what}: {ms:.1} ms GPU, {:.2} Msamples/s, RMSE at 1 spp against 64 spp {error:.4}",
            mipmapped.name,
            paths / (ms * 1e3)
        );
    }
    Ok(())
}
