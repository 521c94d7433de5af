//! The blue-noise sampler (glsl/sampler.glsl, `--sampler zsobol`) against fovea's first,
//! independent one: at one sample per pixel its error over a flat, evenly lit floor has far
//! less power at low spatial frequencies than white noise of the same variance, and its
//! converged images have the same mean, block by block.

mod common;

use std::path::Path;
use std::sync::Arc;

use fovea::render::{Integrator, RenderSettings, Sampler};
use fovea::scene::{
    Camera, EnvSampling, Environment, EnvironmentLight, EnvironmentMap, Instance, Material, Scene,
};
use glam::{Mat4, Vec3};

const ALBEDO: f32 = 0.6;
const SKY: Vec3 = Vec3::new(1.0, 0.8, 0.6);

/// A diffuse floor seen from straight above under a constant sky: every pixel's exact value
/// is albedo × sky, and its noise comes from next-event estimation of the sky and from BRDF
/// sampling, as on any lit surface.
fn floor_under_a_constant_sky() -> Scene {
    let map = EnvironmentMap::from_texels(Path::new("sky.exr"), 16, 8, vec![SKY; 128]).unwrap();
    Scene {
        name: "floor".into(),
        meshes: vec![fovea::check::scale::quad()],
        instances: vec![Instance {
            mesh: 0,
            material: 0,
            transform: Mat4::from_scale(Vec3::new(50.0, 1.0, 50.0)),
        }],
        boxes: vec![],
        spheres: vec![],
        materials: vec![Material::diffuse(Vec3::splat(ALBEDO))],
        textures: vec![],
        camera: Camera::look_at(Vec3::new(0.0, 2.0, 0.0), Vec3::ZERO, Vec3::Z, 40.0, 1.0),
        environment: Environment::black(),
        lights: vec![],
        environment_map: Some(EnvironmentLight {
            map: Arc::new(map),
            rotate_deg: 0.0,
            intensity: 1.0,
            sampling: EnvSampling::Importance,
        }),
        light_selection: Default::default(),
    }
}

fn settings(size: u32, spp: u32, seed: u32, sampler: Sampler) -> RenderSettings {
    RenderSettings {
        sampler,
        ..common::settings(size, size, spp, seed, Integrator::Pt)
    }
}

/// The error's power spectrum of an n × n image (a plain separable DFT), as the share of its
/// power at frequencies below a quarter of Nyquist on both axes (|f| < 1/8 cycle per pixel;
/// the mean is frequency 0 and counts). White noise puts 1/16 of its power there.
fn low_frequency_share(error: &[f64], n: usize) -> f64 {
    let tau = std::f64::consts::TAU;
    let twiddle = |k: usize, x: usize| {
        let a = -tau * (k * x % n) as f64 / n as f64;
        (a.cos(), a.sin())
    };
    // Rows, then columns.
    let mut rows = vec![(0.0, 0.0); n * n];
    for y in 0..n {
        for k in 0..n {
            rows[y * n + k] = (0..n).fold((0.0, 0.0), |(re, im), x| {
                let (c, s) = twiddle(k, x);
                (re + error[y * n + x] * c, im + error[y * n + x] * s)
            });
        }
    }
    let (mut low, mut total) = (0.0, 0.0);
    for k in 0..n {
        for l in 0..n {
            let (re, im) = (0..n).fold((0.0, 0.0), |(re, im), y| {
                let (c, s) = twiddle(l, y);
                let (a, b) = rows[y * n + k];
                (re + a * c - b * s, im + a * s + b * c)
            });
            let power = re * re + im * im;
            let freq = |i: usize| i.min(n - i) as f64 / n as f64;
            total += power;
            if freq(k) < 0.125 && freq(l) < 0.125 {
                low += power;
            }
        }
    }
    low / total
}

/// The low-frequency share of the 1-spp error over the floor, pooled over four seeds.
fn floor_error_share(ctx: &Arc<fovea::gpu::GpuContext>, sampler: Sampler) -> f64 {
    const N: usize = 64;
    let scene = floor_under_a_constant_sky();
    let exact = SKY * ALBEDO;
    let mut shares = Vec::new();
    for seed in 1..=4 {
        let frame = common::render(ctx, &scene, &settings(N as u32, 1, seed, sampler));
        // The error of the image's luminance-like sum, per pixel.
        let error: Vec<f64> = (0..N * N)
            .map(|i| {
                let got = Vec3::from(frame.pixel((i % N) as u32, (i / N) as u32));
                (got - exact).element_sum() as f64
            })
            .collect();
        shares.push(low_frequency_share(&error, N));
    }
    shares.iter().sum::<f64>() / shares.len() as f64
}

#[test]
fn one_sample_of_zsobol_puts_its_error_at_high_frequencies() {
    let ctx = common::context();
    let white = floor_error_share(&ctx, Sampler::Independent);
    let blue = floor_error_share(&ctx, Sampler::Zsobol);
    eprintln!("low-frequency share of the 1-spp error: independent {white:.4}, zsobol {blue:.4}");
    // The measurement itself: the independent sampler's error is white.
    assert!(
        (white - 1.0 / 16.0).abs() < 0.02,
        "the independent sampler's low-frequency share {white:.4}; white noise has 0.0625"
    );
    assert!(
        blue * 4.0 <= white,
        "zsobol's low-frequency share {blue:.4} against white noise's {white:.4}: not 4x less"
    );
    common::assert_no_validation_messages(&ctx);
}

/// Per 8 × 8 block and channel of `frames` (each `size` wide): the mean over the frames of
/// the block's mean, and its standard error from the frames' spread.
fn block_means(frames: &[Vec<f32>], size: usize) -> Vec<(f64, f64)> {
    let per_frame: Vec<Vec<f64>> = frames
        .iter()
        .map(|rgb| {
            common::block_stats(rgb, size, 8)
                .iter()
                .flat_map(|b| b.iter().map(|(mean, _)| *mean))
                .collect()
        })
        .collect();
    let n = frames.len() as f64;
    (0..per_frame[0].len())
        .map(|i| {
            let mean = per_frame.iter().map(|f| f[i]).sum::<f64>() / n;
            let var = per_frame.iter().map(|f| (f[i] - mean).powi(2)).sum::<f64>() / (n - 1.0);
            (mean, (var / n).sqrt())
        })
        .collect()
}

#[test]
fn zsobol_converges_to_the_same_image_block_by_block() {
    let ctx = common::context();
    let scene = fovea::scene::load("cornell", 1.0).unwrap();
    const SIZE: u32 = 32;
    let means = |sampler| {
        let frames: Vec<Vec<f32>> = (0..8)
            .map(|seed| common::render(&ctx, &scene, &settings(SIZE, 32, 100 + seed, sampler)).rgb)
            .collect();
        block_means(&frames, SIZE as usize)
    };
    let (blue, white) = (means(Sampler::Zsobol), means(Sampler::Independent));
    let z: Vec<f64> = blue
        .iter()
        .zip(&white)
        .map(|((m1, s1), (m2, s2))| (m1 - m2) / (s1 * s1 + s2 * s2).sqrt().max(1e-9))
        .collect();
    let worst = z.iter().fold(0.0f64, |w, z| w.max(z.abs()));
    let mean_z2 = z.iter().map(|z| z * z).sum::<f64>() / z.len() as f64;
    eprintln!("zsobol against independent: worst block {worst:.2}, mean z² {mean_z2:.2}");
    // 48 block-channels, each a difference of two means over 8 independent frames.
    assert!(
        worst < 5.0 && mean_z2 < 2.0,
        "zsobol and independent differ: worst block {worst:.2} standard errors, mean z² {mean_z2:.2}"
    );
    common::assert_no_validation_messages(&ctx);
}
