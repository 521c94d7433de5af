//! Scale and self-intersection: the same scene at scales from 1e-3 to 1e5, or moved 1e5 units
//! from the origin, must give the same image. Ray origins are offset off surfaces by a few ulps
//! of the hit point's coordinates (Wächter & Binder), not by a fixed epsilon, so nothing here
//! should depend on the scale — acne shows as darkening, light leaks as brightening.

use crate::gpu::GpuContext;
use crate::metrics;
use crate::render::regular_frame;
use crate::render::{Frame, Integrator, RenderError, RenderSettings, Renderer};
use crate::scene::{Camera, Environment, Instance, Material, Mesh, Scene, Sphere};
use glam::{Mat4, Vec3};
use std::sync::Arc;

/// Albedo of the test plane and radiance of its light: the plane's radiance is their product.
const PLANE_ALBEDO: f32 = 0.5;
const LIGHT_RADIANCE: f32 = 1.0;

/// How the plane is lit; both light it with the same uniform radiance from every direction
/// above it, so it shows `PLANE_ALBEDO · LIGHT_RADIANCE` everywhere.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Lighting {
    /// A uniform sky: rays that leave the scene gather it (no shadow rays).
    Sky,
    /// An emissive sphere enclosing everything under a black sky: `pt` samples it by next-event
    /// estimation, so shadow rays leave the plane too.
    EnclosingEmitter,
}

/// The plane's measured radiance at one scale and offset.
#[derive(Clone, Debug, serde::Serialize)]
pub struct PlaneRadiance {
    pub scale: f32,
    pub offset: f32,
    pub lighting: Lighting,
    pub integrator: Integrator,
    pub expected: f64,
    /// Image mean (all channels are equal: the scene is grey).
    pub mean: f64,
    /// |mean − expected| / expected.
    pub relative_error: f64,
    /// Pixels more than 1% off the expected radiance. `pt` under the sky is a zero-variance
    /// estimator here (cosine sampling cancels the integrand), so any such pixel is acne or a
    /// leak; for the others it counts noise as well.
    pub pixels_off: u64,
    pub nonfinite_samples: u64,
    pub stack_overflows: u64,
}

/// A 2 × 2 quad in the y = 0 plane facing +Y (counter-clockwise seen from above).
pub fn quad() -> Mesh {
    Mesh {
        name: "plane".into(),
        positions: vec![
            Vec3::new(-1.0, 0.0, -1.0),
            Vec3::new(-1.0, 0.0, 1.0),
            Vec3::new(1.0, 0.0, 1.0),
            Vec3::new(1.0, 0.0, -1.0),
        ],
        indices: vec![[0, 1, 2], [0, 2, 3]],
        shading: Default::default(),
    }
}

/// A 100 × 100 diffuse plane seen from 2 units above, filling the view, at scale 1.
pub fn plane_scene(lighting: Lighting) -> Scene {
    let mut scene = Scene {
        name: "lit-plane".into(),
        meshes: vec![quad()],
        instances: vec![Instance {
            mesh: 0,
            material: 0,
            transform: Mat4::from_scale(Vec3::new(50.0, 1.0, 50.0)),
        }],
        boxes: vec![],
        spheres: vec![],
        materials: vec![Material::diffuse(Vec3::splat(PLANE_ALBEDO))],
        textures: Vec::new(),
        camera: Camera::look_at(Vec3::new(0.0, 2.0, 0.5), Vec3::ZERO, Vec3::Y, 30.0, 1.0),
        environment: Environment::uniform(Vec3::splat(LIGHT_RADIANCE)),
        lights: Vec::new(),
        environment_map: None,
        light_selection: Default::default(),
    };
    if lighting == Lighting::EnclosingEmitter {
        scene.environment = Environment::black();
        scene
            .materials
            .push(Material::emitter(Vec3::ZERO, Vec3::splat(LIGHT_RADIANCE)));
        scene.spheres.push(Sphere {
            center: Vec3::ZERO,
            radius: 200.0,
            material: 1,
        });
    }
    scene
}

/// The scene scaled by `scale` about the origin and then moved by `offset`: geometry and camera
/// together, so the image should not change. Emission is radiance, which does not depend on
/// scale; the sky is at infinity.
pub fn transformed(scene: &Scene, scale: f32, offset: Vec3) -> Scene {
    let m = Mat4::from_translation(offset) * Mat4::from_scale(Vec3::splat(scale));
    let mut out = scene.clone();
    out.name = format!("{} x{scale:e} +{offset}", scene.name);
    for inst in &mut out.instances {
        inst.transform = m * inst.transform;
    }
    for b in &mut out.boxes {
        b.min = m.transform_point3(b.min);
        b.max = m.transform_point3(b.max);
    }
    for s in &mut out.spheres {
        s.center = m.transform_point3(s.center);
        s.radius *= scale;
    }
    out.camera.position = m.transform_point3(scene.camera.position);
    out
}

/// The lit plane at every scale (about the origin) and, at the scales of 1 and above, also
/// moved `offset` units along each axis; both lightings, both integrators. Smaller scenes are
/// not moved: at 1e5 from the origin f32 coordinates are 0.008 apart, so a plane seen from
/// 0.002 above (scale 1e-3) cannot even be placed below its camera.
pub fn plane_radiance(
    ctx: &Arc<GpuContext>,
    size: u32,
    spp: u32,
    scales: &[f32],
    offset: f32,
) -> Result<Vec<PlaneRadiance>, RenderError> {
    let expected = (PLANE_ALBEDO * LIGHT_RADIANCE) as f64;
    let mut out = Vec::new();
    for lighting in [Lighting::Sky, Lighting::EnclosingEmitter] {
        let base = plane_scene(lighting);
        for &scale in scales {
            let shifts: &[f32] = if scale >= 1.0 { &[0.0, offset] } else { &[0.0] };
            for &shift in shifts {
                let scene = transformed(&base, scale, Vec3::splat(shift));
                let mut renderer = Renderer::new(ctx, &scene)?;
                for integrator in [Integrator::Pt, Integrator::Seed] {
                    let frame = regular_frame(
                        &mut renderer,
                        &scene.camera,
                        &settings(size, spp, integrator),
                    )?;
                    let mean = frame.mean().iter().sum::<f64>() / 3.0;
                    out.push(PlaneRadiance {
                        scale,
                        offset: shift,
                        lighting,
                        integrator,
                        expected,
                        mean,
                        relative_error: (mean - expected).abs() / expected,
                        pixels_off: frame
                            .rgb
                            .iter()
                            .step_by(3)
                            .filter(|&&v| (v as f64 - expected).abs() > 0.01 * expected)
                            .count() as u64,
                        nonfinite_samples: frame.stats.nonfinite_samples,
                        stack_overflows: frame.stats.stack_overflows,
                    });
                }
            }
        }
    }
    Ok(out)
}

/// A whole scene rendered at another scale, compared with the same scene at scale 1 and the
/// same seed.
#[derive(Clone, Debug, serde::Serialize)]
pub struct ScaledScene {
    pub scene: String,
    pub scale: f32,
    /// Image mean at this scale over the image mean at scale 1 (channel average).
    pub mean_ratio: f64,
    /// RMSE between this image and the scale-1 image of the same seed, over the RMSE between
    /// two scale-1 images of different seeds (the noise level). Rounding makes a few paths
    /// diverge, so it is not 0; acne or leaks would make it approach or pass 1.
    pub rmse_over_noise: f64,
    pub nonfinite_samples: u64,
    pub stack_overflows: u64,
}

/// `scene` at each of `scales`, rendered with `pt` and compared with scale 1.
pub fn scaled_scene(
    ctx: &Arc<GpuContext>,
    scene: &Scene,
    size: u32,
    spp: u32,
    scales: &[f32],
) -> Result<Vec<ScaledScene>, RenderError> {
    let s = settings(size, spp, Integrator::Pt);
    let mut renderer = Renderer::new(ctx, scene)?;
    let base = regular_frame(&mut renderer, &scene.camera, &s)?;
    let other_seed = regular_frame(
        &mut renderer,
        &scene.camera,
        &RenderSettings {
            seed: s.seed + 1,
            ..s
        },
    )?;
    drop(renderer);
    let noise = rmse(&base, &other_seed)?;
    let base_mean = channel_mean(&base);
    let mut out = Vec::new();
    for &scale in scales {
        let scaled = transformed(scene, scale, Vec3::ZERO);
        let frame = regular_frame(&mut Renderer::new(ctx, &scaled)?, &scaled.camera, &s)?;
        out.push(ScaledScene {
            scene: scene.name.clone(),
            scale,
            mean_ratio: channel_mean(&frame) / base_mean,
            rmse_over_noise: rmse(&base, &frame)? / noise,
            nonfinite_samples: frame.stats.nonfinite_samples,
            stack_overflows: frame.stats.stack_overflows,
        });
    }
    Ok(out)
}

fn settings(size: u32, spp: u32, integrator: Integrator) -> RenderSettings {
    RenderSettings {
        sampler: crate::render::Sampler::chosen(),
        width: size,
        height: size,
        spp,
        seed: 1,
        integrator,
        max_bounces: 8,
    }
}

fn channel_mean(frame: &Frame) -> f64 {
    frame.mean().iter().sum::<f64>() / 3.0
}

/// RMSE of `test` against `reference` over all pixels and channels.
fn rmse(reference: &Frame, test: &Frame) -> Result<f64, RenderError> {
    metrics::image_error(
        &reference.rgb,
        &test.rgb,
        reference.width,
        reference.height,
        None,
    )
    .map(|e| e.mse.sqrt())
    .map_err(|e| RenderError::Settings(e.to_string()))
}
