//! Material extremes under a white furnace: a convex object inside a uniform sky of radiance 1.
//! Every ray it reflects escapes to the sky, so each pixel on it estimates the material's
//! directional albedo, which an energy-conserving BRDF keeps ≤ 1 — at every Phong exponent from
//! 0 to 1e6 and ∞, at grazing angles (the silhouette), on analytic spheres and on triangles.
//! Degenerate triangles and enormous emission ride along: nothing may become NaN or ∞.

use crate::gpu::GpuContext;
use crate::render::regular_frame;
use crate::render::{Integrator, RenderError, RenderSettings, Renderer};
use crate::scene::validate::MAX_EMISSION;
use crate::scene::{Camera, Environment, Instance, Material, Mesh, Scene, Sphere};
use glam::{Mat4, Vec3};
use std::sync::Arc;

use super::closed_meshes::icosphere;

/// The materials of the furnace: pure Lambert, pure Phong across its exponent range and the
/// mirror, and even Lambert/Phong mixtures, each with `k_d + k_s = 1` (the most a valid
/// material may reflect).
pub fn furnace_materials() -> Vec<(String, Material)> {
    let mut out = vec![("lambert kd=1".to_owned(), Material::diffuse(Vec3::ONE))];
    for alpha in [0.0, 1.0, 10.0, 100.0, 1e3, 1e4, 1e6, f32::INFINITY] {
        out.push((
            format!("phong ks=1 alpha={alpha:e}"),
            Material::phong(Vec3::ZERO, Vec3::ONE, alpha, Vec3::ZERO),
        ));
    }
    for alpha in [0.0, 20.0, 1e6, f32::INFINITY] {
        out.push((
            format!("kd=ks=0.5 alpha={alpha:e}"),
            Material::phong(Vec3::splat(0.5), Vec3::splat(0.5), alpha, Vec3::ZERO),
        ));
    }
    out
}

/// The furnace measurement of one material on one shape with one integrator.
#[derive(Clone, Debug, serde::Serialize)]
pub struct FurnaceResult {
    pub material: String,
    /// "sphere" (analytic) or "icosphere" (1280 flat triangles, plus degenerate ones).
    pub shape: &'static str,
    pub integrator: Integrator,
    /// Mean radiance over the object's pixels (the mean directional albedo it shows).
    pub mean: f64,
    /// Standard error of that mean, from the spread of the pixels.
    pub std_error: f64,
    /// Brightest single pixel channel.
    pub max_pixel: f64,
    pub nonfinite_samples: u64,
    pub stack_overflows: u64,
    /// Pixels whose value is NaN or ∞ in the written image (must be 0: the shaders drop such
    /// samples and count them).
    pub nonfinite_pixels: u64,
}

impl FurnaceResult {
    /// How many standard errors the mean lies above 1 (≤ 0 when it does not).
    pub fn excess_sigmas(&self) -> f64 {
        (self.mean - 1.0) / self.std_error.max(1e-12)
    }
}

/// A mesh of zero-area triangles of every kind: repeated vertices, collinear vertices, and a
/// sliver whose third vertex lies on its first edge. Placed inside the object, where rays from
/// the camera never reach them but the BVH must still be built and traversed around them.
fn degenerate_triangles() -> Mesh {
    Mesh {
        name: "degenerate".into(),
        positions: vec![
            Vec3::ZERO,
            Vec3::new(0.3, 0.0, 0.0),
            Vec3::new(0.6, 0.0, 0.0),
            Vec3::new(0.1, 0.2, 0.0),
        ],
        indices: vec![[0, 0, 0], [0, 1, 1], [0, 1, 2], [1, 2, 0], [3, 3, 1]],
        shading: Default::default(),
    }
}

/// A furnace scene: the object at the origin seen from 3 units, filling ~40% of the image, so
/// both face-on and grazing views of the surface are in the picture.
pub(super) fn furnace_scene(material: Material, triangles: bool) -> Scene {
    let mut scene = Scene {
        name: "white-furnace".into(),
        meshes: vec![],
        instances: vec![],
        boxes: vec![],
        spheres: vec![],
        materials: vec![
            material,
            Material::emitter(Vec3::ZERO, Vec3::splat(MAX_EMISSION)),
        ],
        textures: Vec::new(),
        camera: Camera::look_at(Vec3::new(0.0, 1.0, 3.0), Vec3::ZERO, Vec3::Y, 40.0, 1.0),
        environment: Environment::uniform(Vec3::ONE),
        lights: Vec::new(),
        environment_map: None,
        light_selection: Default::default(),
    };
    if triangles {
        scene.meshes = vec![icosphere(3), degenerate_triangles()];
        scene.instances = vec![
            Instance {
                mesh: 0,
                material: 0,
                transform: Mat4::IDENTITY,
            },
            // Degenerate triangles that emit the largest radiance allowed: their area is 0, so
            // next-event estimation must give them no light (and no NaN).
            Instance {
                mesh: 1,
                material: 1,
                transform: Mat4::from_scale(Vec3::splat(0.5)),
            },
        ];
    } else {
        scene.spheres.push(Sphere {
            center: Vec3::ZERO,
            radius: 1.0,
            material: 0,
        });
    }
    scene
}

/// The pixels that show the object: those whose camera ray through the pixel centre hits the
/// unit sphere (the icosphere is inscribed in it; its few rim pixels that see the sky read 1).
pub(super) fn object_mask(camera: &Camera, size: u32) -> Vec<bool> {
    let (r, u, f) = camera.basis();
    let (l, rt) = (camera.angle_left.tan(), camera.angle_right.tan());
    let (up, dn) = (camera.angle_up.tan(), camera.angle_down.tan());
    let mut mask = Vec::with_capacity((size * size) as usize);
    for y in 0..size {
        for x in 0..size {
            let tx = l + (x as f32 + 0.5) / size as f32 * (rt - l);
            let ty = up + (y as f32 + 0.5) / size as f32 * (dn - up);
            let d = (f + tx * r + ty * u).normalize();
            // Distance of the sphere centre (origin) from the ray.
            let o = camera.position;
            let closest = o - o.dot(d) * d;
            mask.push(closest.length() < 0.98);
        }
    }
    mask
}

/// The mean over the masked pixels of an RGB image (channels averaged), and its standard error
/// from the pixels' spread.
pub(super) fn masked_mean(rgb: &[f32], mask: &[bool]) -> (f64, f64) {
    let values: Vec<f64> = rgb
        .chunks_exact(3)
        .zip(mask)
        .filter(|(_, &m)| m)
        .map(|(p, _)| p.iter().map(|&v| v as f64).sum::<f64>() / 3.0)
        .collect();
    let n = values.len().max(1) as f64;
    let mean = values.iter().sum::<f64>() / n;
    let var = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0).max(1.0);
    (mean, (var / n).sqrt())
}

/// Every furnace material on both shapes with both integrators.
pub fn white_furnace(
    ctx: &Arc<GpuContext>,
    size: u32,
    spp: u32,
) -> Result<Vec<FurnaceResult>, RenderError> {
    let mut out = Vec::new();
    for (name, material) in furnace_materials() {
        for triangles in [false, true] {
            let scene = furnace_scene(material, triangles);
            let mask = object_mask(&scene.camera, size);
            let mut renderer = Renderer::new(ctx, &scene)?;
            for integrator in [Integrator::Pt, Integrator::Seed] {
                let settings = RenderSettings {
                    sampler: crate::render::Sampler::chosen(),
                    width: size,
                    height: size,
                    spp,
                    seed: 7,
                    integrator,
                    max_bounces: 8,
                };
                let frame = regular_frame(&mut renderer, &scene.camera, &settings)?;
                let (mean, std_error) = masked_mean(&frame.rgb, &mask);
                out.push(FurnaceResult {
                    material: name.clone(),
                    shape: if triangles { "icosphere" } else { "sphere" },
                    integrator,
                    mean,
                    std_error,
                    max_pixel: frame.rgb.iter().fold(0.0f64, |a, &v| a.max(v as f64)),
                    nonfinite_samples: frame.stats.nonfinite_samples,
                    stack_overflows: frame.stats.stack_overflows,
                    nonfinite_pixels: frame.rgb.iter().filter(|v| !v.is_finite()).count() as u64,
                });
            }
        }
    }
    Ok(out)
}

/// Very large emission: the scene's emitters scaled by `factor` must scale the image by exactly
/// that factor (radiance is linear in emission) and produce no NaN or ∞.
#[derive(Clone, Debug, serde::Serialize)]
pub struct EmissionScaling {
    pub scene: String,
    pub factor: f32,
    /// Image mean with scaled emission / (factor · image mean at the original emission).
    pub ratio: f64,
    pub nonfinite_samples: u64,
    pub nonfinite_pixels: u64,
}

/// Renders `scene` (which must have emitters) at its own emission and with every emitter
/// scaled by each of `factors`, same seed, `pt`.
pub fn emission_scaling(
    ctx: &Arc<GpuContext>,
    scene: &Scene,
    size: u32,
    spp: u32,
    factors: &[f32],
) -> Result<Vec<EmissionScaling>, RenderError> {
    let settings = RenderSettings {
        sampler: crate::render::Sampler::chosen(),
        width: size,
        height: size,
        spp,
        seed: 3,
        integrator: Integrator::Pt,
        max_bounces: 8,
    };
    // Frame::mean per channel, averaged: the image's mean radiance.
    let mean = |frame: &crate::render::Frame| frame.mean().iter().sum::<f64>() / 3.0;
    let base = regular_frame(&mut Renderer::new(ctx, scene)?, &scene.camera, &settings)?;
    let base_mean = mean(&base);
    let mut out = Vec::new();
    for &factor in factors {
        let mut bright = scene.clone();
        for m in &mut bright.materials {
            *m.emission_mut() *= factor;
        }
        let frame = regular_frame(&mut Renderer::new(ctx, &bright)?, &bright.camera, &settings)?;
        out.push(EmissionScaling {
            scene: scene.name.clone(),
            factor,
            ratio: mean(&frame) / (factor as f64 * base_mean),
            nonfinite_samples: frame.stats.nonfinite_samples,
            nonfinite_pixels: frame.rgb.iter().filter(|v| !v.is_finite()).count() as u64,
        });
    }
    Ok(out)
}
