//! glTF's BRDF as the GPU samples and evaluates it (the BRDF probe, the integrators' own
//! functions), checked three ways: the directions it samples follow the density it reports
//! (a chi-square test over the hemisphere), its values equal the CPU reference's
//! ([`super::gltf_brdf`]), and it is reciprocal.

use std::f64::consts::PI;
use std::sync::Arc;

use glam::{DVec3, Vec3};

use super::chi_square::{chi_square, ChiSquare};
use super::gltf_brdf::GltfBrdf;
use super::rng::Rng;
use crate::gpu::GpuContext;
use crate::render::{RenderError, Renderer};
use crate::scene::{Camera, Environment, Material, MetallicRoughness, Scene, Sphere};
use crate::shader_layout::{GpuBrdfAnswer, GpuBrdfQuery};

/// Cells of the chi-square test: cos θ in [0, 1] by this many rows, φ by twice as many.
pub const THETA_CELLS: usize = 10;
/// Each cell's expected count integrates the density at this many × this many points.
const SUBDIVISIONS: usize = 16;

/// A renderer over a scene that holds `materials` (on spheres nobody looks at): what the
/// probe needs to read them from the GPU's material buffer.
pub fn probe_renderer(
    ctx: &Arc<GpuContext>,
    materials: &[MetallicRoughness],
) -> Result<Renderer, RenderError> {
    let scene = Scene {
        name: "brdf-probe".into(),
        meshes: vec![],
        instances: vec![],
        boxes: vec![],
        spheres: (0..materials.len() as u32)
            .map(|i| Sphere {
                center: Vec3::new(3.0 * i as f32, 0.0, 0.0),
                radius: 1.0,
                material: i,
            })
            .collect(),
        materials: materials
            .iter()
            .map(|m| Material::MetallicRoughness(*m))
            .collect(),
        textures: Vec::new(),
        camera: Camera::look_at(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO, Vec3::Y, 40.0, 1.0),
        environment: Environment::black(),
        lights: Vec::new(),
        environment_map: None,
        light_selection: Default::default(),
    };
    Renderer::new(ctx, &scene)
}

fn query(material: u32, wo: DVec3, wi: DVec3, u: [f64; 3]) -> GpuBrdfQuery {
    let v4 = |v: DVec3| [v.x as f32, v.y as f32, v.z as f32, 0.0];
    GpuBrdfQuery {
        wo: v4(wo),
        wi: v4(wi),
        u: [u[0] as f32, u[1] as f32, u[2] as f32, 0.0],
        material,
        ..Default::default()
    }
}

/// The viewer's direction at `theta_o_deg` from the normal (+z), in the xz plane.
pub fn view_direction(theta_o_deg: f64) -> DVec3 {
    let t = theta_o_deg.to_radians();
    DVec3::new(t.sin(), 0.0, t.cos())
}

fn direction(cos_theta: f64, phi: f64) -> DVec3 {
    let sin = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
    DVec3::new(sin * phi.cos(), sin * phi.sin(), cos_theta)
}

/// The cell of a direction above the surface: row by cos θ, column by φ.
fn cell_of(d: [f32; 4]) -> usize {
    let phi_cells = 2 * THETA_CELLS;
    let row = ((d[2] as f64 * THETA_CELLS as f64) as usize).min(THETA_CELLS - 1);
    let phi = (d[1] as f64).atan2(d[0] as f64).rem_euclid(2.0 * PI);
    let col = ((phi / (2.0 * PI) * phi_cells as f64) as usize).min(phi_cells - 1);
    row * phi_cells + col
}

/// One chi-square test of the sampler of material `material` seen from `theta_o_deg`.
#[derive(Clone, Copy, Debug, serde::Serialize)]
pub struct SamplingTest {
    pub theta_o_deg: f64,
    pub samples: usize,
    /// The density integrated over the hemisphere: 1 minus the share sampled below it.
    pub density_integral: f64,
    /// Samples that fell below the surface (absorbed).
    pub absorbed: usize,
    pub chi_square: ChiSquare,
}

/// Draws `samples` directions from the GPU's sampler of `material` and tests them against
/// the GPU's density of the same material, integrated per cell. The last cell is "below the
/// surface", whose expected share is what the integrated density leaves.
pub fn sampling_test(
    renderer: &mut Renderer,
    material: u32,
    theta_o_deg: f64,
    samples: usize,
    seed: u64,
) -> Result<SamplingTest, RenderError> {
    sampling_test_against(renderer, material, material, theta_o_deg, samples, seed)
}

/// [`sampling_test`] with the directions drawn from one material and tested against the
/// density of another: what shows that the test can reject a sampler.
pub fn sampling_test_against(
    renderer: &mut Renderer,
    drawn_from: u32,
    density_of: u32,
    theta_o_deg: f64,
    samples: usize,
    seed: u64,
) -> Result<SamplingTest, RenderError> {
    let wo = view_direction(theta_o_deg);
    let mut rng = Rng::new(seed);
    let draws: Vec<GpuBrdfQuery> = (0..samples)
        .map(|_| query(drawn_from, wo, wo, [rng.unit(), rng.unit(), rng.unit()]))
        .collect();
    let cells = THETA_CELLS * 2 * THETA_CELLS;
    let mut observed = vec![0.0; cells + 1];
    for a in renderer.brdf_probe(&draws)? {
        let i = if a.sampled[3] > 0.0 {
            cell_of(a.sampled)
        } else {
            cells
        };
        observed[i] += 1.0;
    }
    let expected_share = cell_integrals(renderer, density_of, wo)?;
    let density_integral: f64 = expected_share.iter().sum();
    let mut expected: Vec<f64> = expected_share.iter().map(|p| p * samples as f64).collect();
    expected.push((1.0 - density_integral).max(0.0) * samples as f64);
    Ok(SamplingTest {
        theta_o_deg,
        samples,
        density_integral,
        absorbed: observed[cells] as usize,
        chi_square: chi_square(&observed, &expected),
    })
}

/// The GPU's density integrated over each cell by the midpoint rule in (cos θ, φ), whose
/// area element is the solid angle.
fn cell_integrals(
    renderer: &mut Renderer,
    material: u32,
    wo: DVec3,
) -> Result<Vec<f64>, RenderError> {
    let (rows, cols) = (THETA_CELLS * SUBDIVISIONS, 2 * THETA_CELLS * SUBDIVISIONS);
    let (d_cos, d_phi) = (1.0 / rows as f64, 2.0 * PI / cols as f64);
    let mut points = Vec::with_capacity(rows * cols);
    for r in 0..rows {
        for c in 0..cols {
            let wi = direction((r as f64 + 0.5) * d_cos, (c as f64 + 0.5) * d_phi);
            points.push(query(material, wo, wi, [0.5; 3]));
        }
    }
    let answers = renderer.brdf_probe(&points)?;
    let mut cells = vec![0.0; THETA_CELLS * 2 * THETA_CELLS];
    for (k, a) in answers.iter().enumerate() {
        let (r, c) = (k / cols, k % cols);
        cells[(r / SUBDIVISIONS) * 2 * THETA_CELLS + c / SUBDIVISIONS] += a.value[3] as f64;
    }
    Ok(cells.into_iter().map(|p| p * d_cos * d_phi).collect())
}

/// The GPU's f(wo, wi) and f(wi, wo) against the CPU reference's, over `pairs` random pairs
/// of directions above the surface.
#[derive(Clone, Copy, Debug, serde::Serialize)]
pub struct EvaluationTest {
    pub pairs: usize,
    /// Largest |f_gpu − f_cpu| / max(f_cpu, 1e-3) over pairs and channels.
    pub worst_relative_error: f64,
    /// Largest |f(wo, wi) − f(wi, wo)| / max(f, 1e-3) on the GPU.
    pub worst_reciprocity_error: f64,
}

pub fn evaluation_test(
    renderer: &mut Renderer,
    material: u32,
    reference: &GltfBrdf,
    pairs: usize,
    seed: u64,
) -> Result<EvaluationTest, RenderError> {
    let mut rng = Rng::new(seed);
    let mut random_direction = || direction(rng.unit().max(0.02), 2.0 * PI * rng.unit());
    let pairs_of: Vec<(DVec3, DVec3)> = (0..pairs)
        .map(|_| (random_direction(), random_direction()))
        .collect();
    let queries: Vec<GpuBrdfQuery> = pairs_of
        .iter()
        .flat_map(|&(a, b)| {
            [
                query(material, a, b, [0.5; 3]),
                query(material, b, a, [0.5; 3]),
            ]
        })
        .collect();
    let answers = renderer.brdf_probe(&queries)?;
    let value =
        |a: &GpuBrdfAnswer| DVec3::new(a.value[0] as f64, a.value[1] as f64, a.value[2] as f64);
    let relative =
        |x: DVec3, y: DVec3| ((x - y).abs() / y.abs().max(DVec3::splat(1e-3))).max_element();
    let (mut worst, mut worst_reciprocity) = (0.0f64, 0.0f64);
    for (pair, (wo, wi)) in answers.chunks_exact(2).zip(&pairs_of) {
        let (forward, backward) = (value(&pair[0]), value(&pair[1]));
        worst = worst.max(relative(forward, reference.eval(*wo, *wi)));
        worst_reciprocity = worst_reciprocity.max(relative(backward, forward));
    }
    Ok(EvaluationTest {
        pairs,
        worst_relative_error: worst,
        worst_reciprocity_error: worst_reciprocity,
    })
}
