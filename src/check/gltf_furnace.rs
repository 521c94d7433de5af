//! glTF's BRDF under a white furnace: a sphere of one metallic-roughness material inside a
//! uniform sky of radiance 1. Every reflected ray escapes, so a pixel shows the material's
//! directional albedo at its view angle, which the CPU reference computes by quadrature
//! ([`super::gltf_brdf`]): the image must equal that prediction within noise — for a white
//! metal at most 1 and exactly the single-scattering GGX albedo, not more, not less.

use std::sync::Arc;

use glam::{DVec3, Vec3};

use super::gltf_brdf::GltfBrdf;
use super::materials::{furnace_scene, object_mask};
use crate::gpu::GpuContext;
use crate::render::{regular_frame, Integrator, RenderError, RenderSettings, Renderer};
use crate::scene::{Camera, Coverage, Material, MetallicRoughness};

/// The furnace's glTF materials: white metals and white dielectrics, a glossy and a rough one.
pub fn gltf_furnace_materials() -> Vec<(String, MetallicRoughness)> {
    let white = |metallic: f32, roughness: f32| MetallicRoughness {
        base_color: Vec3::ONE,
        metallic,
        roughness,
        emission: Vec3::ZERO,
        textures: Default::default(),
        coverage: Coverage::SOLID,
    };
    [(1.0, 0.5), (1.0, 1.0), (0.0, 0.5), (0.0, 1.0)]
        .into_iter()
        .map(|(m, r)| {
            (
                format!("gltf white metallic={m} roughness={r}"),
                white(m, r),
            )
        })
        .collect()
}

/// One material with one integrator: the object's mean against the CPU's prediction.
#[derive(Clone, Debug, serde::Serialize)]
pub struct GltfFurnaceResult {
    pub material: String,
    pub integrator: Integrator,
    pub mean: f64,
    pub std_error: f64,
    /// The mean over the same pixels of the CPU reference's directional albedo.
    pub expected: f64,
    pub nonfinite_samples: u64,
}

impl GltfFurnaceResult {
    /// How many standard errors the mean lies from the prediction.
    pub fn sigmas(&self) -> f64 {
        (self.mean - self.expected).abs() / self.std_error.max(1e-12)
    }
}

/// Quadrature rows for the albedo table (enough for roughness ≥ 0.5: < 0.1% error).
const ALBEDO_ROWS: usize = 400;
/// Entries of the albedo table over cos θ_o in (0, 1].
const TABLE: usize = 64;

/// Directional albedo (mean of the channels) at `TABLE` view cosines, for interpolation.
fn albedo_table(brdf: &GltfBrdf) -> Vec<f64> {
    (0..TABLE)
        .map(|i| {
            let e = brdf.albedo((i as f64 + 0.5) / TABLE as f64, ALBEDO_ROWS);
            e.element_sum() / 3.0
        })
        .collect()
}

fn interpolate(table: &[f64], cos: f64) -> f64 {
    let x = (cos * TABLE as f64 - 0.5).clamp(0.0, (TABLE - 1) as f64);
    let i = (x as usize).min(TABLE - 2);
    let t = x - i as f64;
    table[i] * (1.0 - t) + table[i + 1] * t
}

/// The prediction: the albedo at each masked pixel centre's view angle on the unit sphere at
/// the origin, averaged.
fn expected_mean(brdf: &GltfBrdf, camera: &Camera, size: u32, mask: &[bool]) -> f64 {
    let table = albedo_table(brdf);
    let (r, u, f) = camera.basis();
    let (r, u, f) = (r.as_dvec3(), u.as_dvec3(), f.as_dvec3());
    let (l, rt) = (
        camera.angle_left.tan() as f64,
        camera.angle_right.tan() as f64,
    );
    let (up, dn) = (camera.angle_up.tan() as f64, camera.angle_down.tan() as f64);
    let o = camera.position.as_dvec3();
    let (mut sum, mut n) = (0.0, 0usize);
    for (k, _) in mask.iter().enumerate().filter(|(_, &m)| m) {
        let (x, y) = ((k as u32 % size) as f64, (k as u32 / size) as f64);
        let tx = l + (x + 0.5) / size as f64 * (rt - l);
        let ty = up + (y + 0.5) / size as f64 * (dn - up);
        let d = (f + tx * r + ty * u).normalize();
        // The nearer intersection with the unit sphere, and the normal there.
        let b = o.dot(d);
        let t = -b - (b * b - o.length_squared() + 1.0).max(0.0).sqrt();
        let normal: DVec3 = (o + t * d).normalize();
        sum += interpolate(&table, normal.dot(-d).clamp(0.0, 1.0));
        n += 1;
    }
    sum / n.max(1) as f64
}

/// Every glTF furnace material on the analytic sphere with both integrators.
pub fn gltf_furnace(
    ctx: &Arc<GpuContext>,
    size: u32,
    spp: u32,
) -> Result<Vec<GltfFurnaceResult>, RenderError> {
    let mut out = Vec::new();
    for (name, material) in gltf_furnace_materials() {
        let scene = furnace_scene(Material::MetallicRoughness(material), false);
        let mask = object_mask(&scene.camera, size);
        let brdf = GltfBrdf {
            base_color: material.base_color.as_dvec3(),
            metallic: material.metallic as f64,
            roughness: material.roughness as f64,
        };
        let expected = expected_mean(&brdf, &scene.camera, size, &mask);
        let mut renderer = Renderer::new(ctx, &scene)?;
        for integrator in [Integrator::Pt, Integrator::Seed] {
            let settings = RenderSettings {
                sampler: crate::render::Sampler::chosen(),
                width: size,
                height: size,
                spp,
                seed: 11,
                integrator,
                max_bounces: 8,
            };
            let frame = regular_frame(&mut renderer, &scene.camera, &settings)?;
            let (mean, std_error) = super::materials::masked_mean(&frame.rgb, &mask);
            out.push(GltfFurnaceResult {
                material: name.clone(),
                integrator,
                mean,
                std_error,
                expected,
                nonfinite_samples: frame.stats.nonfinite_samples,
            });
        }
    }
    Ok(out)
}
