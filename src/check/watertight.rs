//! Watertightness of the GPU traversal and triangle test: rays from points inside closed meshes,
//! aimed exactly at vertices and at points on edges — where a non-watertight test lets rays slip
//! between neighbouring triangles — must all hit the mesh no farther than their target.

use super::closed_meshes::{closed_bunny, icosphere, subdivided_cube, winding_number};
use super::rng::Rng;
use crate::gpu::GpuContext;
use crate::render::{RenderError, Renderer, Traversal};
use crate::scene::{Camera, Environment, Instance, Material, Mesh, Scene};
use crate::shader_layout::GpuProbeRay;
use glam::{DMat4, DVec3, Mat4, Quat, Vec3};
use std::sync::Arc;

/// Rays per GPU dispatch: bounded so the probe buffers stay a few MiB.
const RAYS_PER_BATCH: usize = 1 << 18;
/// Inside points per mesh that rays start from.
const ORIGINS_PER_MESH: usize = 64;

/// The outcome for one closed mesh.
#[derive(Clone, Debug, serde::Serialize)]
pub struct MeshWatertightness {
    pub mesh: String,
    pub triangles: usize,
    pub rays: u64,
    /// Rays that hit nothing: they left a closed surface through a crack.
    pub escapes: u64,
    /// Rays whose first hit lies beyond the point they were aimed at on the surface: they
    /// slipped through there and hit the far side. Counted on convex meshes only: inside a
    /// non-convex one, a target on a fold seen edge-on is only touched, and a ray rounded
    /// 1e-7 to the side of it rightly goes on.
    pub overshoots: Option<u64>,
    pub stack_overflows: u64,
}

impl MeshWatertightness {
    pub fn leaks(&self) -> u64 {
        self.escapes + self.overshoots.unwrap_or(0)
    }
}

/// One mesh placed in the world: its triangles pass through this object-to-world transform on
/// the GPU, as every instance does.
struct Placed {
    mesh: Mesh,
    transform: Mat4,
    convex: bool,
}

/// The closed meshes: an icosphere, a finely subdivided cube under a rotation, scale and
/// translation (so the instance transform is exercised), and the closed bunny.
fn meshes() -> Result<Vec<Placed>, RenderError> {
    Ok(vec![
        Placed {
            mesh: icosphere(5),
            transform: Mat4::IDENTITY,
            convex: true,
        },
        Placed {
            mesh: subdivided_cube(24),
            transform: Mat4::from_scale_rotation_translation(
                Vec3::new(2.0, 0.5, 1.0),
                Quat::from_euler(glam::EulerRot::YXZ, 0.7, 0.3, 0.1),
                Vec3::new(3.0, -1.0, 2.0),
            ),
            convex: true,
        },
        Placed {
            mesh: closed_bunny()?,
            transform: Mat4::IDENTITY,
            convex: false,
        },
    ])
}

/// Casts `rays_total` rays, split evenly over the closed meshes, and counts what leaks.
/// `traversal` is the one that casts them.
pub fn run(
    ctx: &Arc<GpuContext>,
    rays_total: u64,
    seed: u64,
    traversal: Traversal,
) -> Result<Vec<MeshWatertightness>, RenderError> {
    let placed = meshes()?;
    let per_mesh = rays_total.div_ceil(placed.len() as u64);
    let mut out = Vec::new();
    for (k, p) in placed.into_iter().enumerate() {
        let seed = seed.wrapping_add(k as u64);
        out.push(check_mesh(ctx, p, per_mesh, seed, traversal)?);
    }
    Ok(out)
}

fn check_mesh(
    ctx: &Arc<GpuContext>,
    placed: Placed,
    rays: u64,
    seed: u64,
    traversal: Traversal,
) -> Result<MeshWatertightness, RenderError> {
    let to_world = placed.transform.as_dmat4();
    let world: Vec<DVec3> = placed
        .mesh
        .positions
        .iter()
        .map(|p| to_world.transform_point3(p.as_dvec3()))
        .collect();
    let mut rng = Rng::new(seed);
    let origins = inside_points(&placed.mesh, to_world, &mut rng);
    let scene = single_mesh_scene(&placed);
    let mut renderer = Renderer::new(ctx, &scene)?;
    renderer.set_traversal(traversal)?;
    let mut result = MeshWatertightness {
        mesh: placed.mesh.name.clone(),
        triangles: placed.mesh.indices.len(),
        rays,
        escapes: 0,
        overshoots: placed.convex.then_some(0),
        stack_overflows: 0,
    };
    let mut remaining = rays;
    while remaining > 0 {
        let batch = remaining.min(RAYS_PER_BATCH as u64) as usize;
        remaining -= batch as u64;
        let mut probes = Vec::with_capacity(batch);
        let mut distances = Vec::with_capacity(batch);
        for _ in 0..batch {
            let o = origins[rng.below(origins.len())];
            let target = aim_point(&placed.mesh, &world, &mut rng);
            let (of, d) = (o.as_vec3(), (target - o).normalize().as_vec3());
            // The distance to the target from the origin as the GPU sees it (f32 origin).
            distances.push(target.distance(of.as_dvec3()));
            probes.push(GpuProbeRay {
                origin: [of.x, of.y, of.z, 0.0],
                direction: [d.x, d.y, d.z, f32::INFINITY],
            });
        }
        let (hits, overflows) = renderer.raycast(&probes)?;
        result.stack_overflows += overflows;
        for (hit, distance) in hits.iter().zip(&distances) {
            if hit.t.is_infinite() {
                result.escapes += 1;
            } else if hit.t as f64 > distance * (1.0 + 1e-4) {
                if let Some(n) = result.overshoots.as_mut() {
                    *n += 1;
                }
            }
        }
    }
    Ok(result)
}

/// A vertex (half the rays) or a point on an edge (a random position along it, or exactly its
/// midpoint), in world space.
fn aim_point(mesh: &Mesh, world: &[DVec3], rng: &mut Rng) -> DVec3 {
    let tri = mesh.indices[rng.below(mesh.indices.len())];
    let corner = rng.below(3);
    let a = world[tri[corner] as usize];
    match rng.below(4) {
        0 | 1 => a,
        kind => {
            let b = world[tri[(corner + 1) % 3] as usize];
            let t = if kind == 2 { 0.5 } else { rng.unit() };
            a.lerp(b, t)
        }
    }
}

/// Points strictly inside the mesh (winding number ≈ 1), drawn uniformly from the middle of its
/// bounding box, as world-space points.
fn inside_points(mesh: &Mesh, to_world: DMat4, rng: &mut Rng) -> Vec<DVec3> {
    let (lo, hi) = mesh.positions.iter().fold(
        (DVec3::splat(f64::MAX), DVec3::splat(f64::MIN)),
        |(lo, hi), p| (lo.min(p.as_dvec3()), hi.max(p.as_dvec3())),
    );
    let mut points = Vec::with_capacity(ORIGINS_PER_MESH);
    while points.len() < ORIGINS_PER_MESH {
        let u = DVec3::new(rng.unit(), rng.unit(), rng.unit());
        let p = lo + (hi - lo) * (0.1 + 0.8 * u);
        if winding_number(mesh, p) > 0.99 {
            points.push(to_world.transform_point3(p));
        }
    }
    points
}

fn single_mesh_scene(placed: &Placed) -> Scene {
    Scene {
        name: placed.mesh.name.clone(),
        meshes: vec![placed.mesh.clone()],
        instances: vec![Instance {
            mesh: 0,
            material: 0,
            transform: placed.transform,
        }],
        boxes: vec![],
        spheres: vec![],
        materials: vec![Material::diffuse(Vec3::splat(0.5))],
        textures: Vec::new(),
        camera: Camera::look_at(Vec3::splat(5.0), Vec3::ZERO, Vec3::Y, 40.0, 1.0),
        environment: Environment::black(),
        lights: Vec::new(),
        environment_map: None,
        light_selection: Default::default(),
    }
}
