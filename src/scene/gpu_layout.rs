//! Scene → the flat arrays the shaders read: one CWBVH per mesh (BLAS, concatenated), one over
//! all objects (TLAS), triangles and objects reordered into their BVH's leaf order (so a leaf's
//! primitive index is a direct array index), materials, and the emitter list for NEE.

use super::area_emitters::{collect_emitters, emits_unevenly};
use super::env_sampling::GpuEnvironment;
use super::gpu_materials::{gpu_material, surface_flags};
use super::light_selection::add_lights_and_select_by_power;
use super::{Mesh, Scene, SceneError, SceneFeatures};
use crate::shader_layout::*;
use glam::{Mat4, Vec3, Vec3A};
use obvhs::aabb::Aabb;
use obvhs::cwbvh::builder::{build_cwbvh, build_cwbvh_from_tris};
use obvhs::cwbvh::CwBvh;
use obvhs::triangle::Triangle;
use obvhs::BvhBuildParams;
use std::time::Duration;

pub struct GpuScene {
    pub blas_nodes: Vec<GpuNode>,
    pub tlas_nodes: Vec<GpuNode>,
    pub triangles: Vec<GpuTriangle>,
    /// One per triangle, in `triangles`' order, when some mesh has shading attributes
    /// (`features.shading`); else empty.
    pub shading: Vec<GpuTriangleShading>,
    pub objects: Vec<GpuObject>,
    pub materials: Vec<GpuMaterial>,
    pub emitters: Vec<GpuEmitter>,
    /// The HDR environment's texels and sampling table (env_sampling.rs); empty without one.
    pub environment: Vec<[u32; 4]>,
    pub info: GpuSceneInfo,
    pub features: SceneFeatures,
}

fn v4(v: Vec3, w: f32) -> [f32; 4] {
    [v.x, v.y, v.z, w]
}

fn rows(m: Mat4) -> [[f32; 4]; 3] {
    let t = m.transpose();
    [
        t.x_axis.to_array(),
        t.y_axis.to_array(),
        t.z_axis.to_array(),
    ]
}

fn node_words(bvh: &CwBvh) -> Vec<GpuNode> {
    bvh.nodes.iter().map(|n| bytemuck::cast(*n)).collect()
}

pub(crate) fn build_params() -> BvhBuildParams {
    // PLOC with reinsertion: obvhs' "medium" preset, close to Embree's build time with faster
    // traversal; leaves hold at most 3 primitives in a CWBVH.
    BvhBuildParams::medium_build()
}

/// A mesh's triangles as obvhs builds BVHs of them (object space, index order); the GPU
/// layout and the CPU ray cast build the same trees from these.
pub(crate) fn mesh_triangles(mesh: &Mesh) -> Vec<Triangle> {
    let p = |i: u32| Vec3A::from(mesh.positions[i as usize]);
    mesh.indices
        .iter()
        .map(|t| Triangle {
            v0: p(t[0]),
            v1: p(t[1]),
            v2: p(t[2]),
        })
        .collect()
}

/// What shading interpolates across the triangle with corners `corners` of `mesh`.
fn triangle_shading(mesh: &Mesh, corners: [u32; 3]) -> GpuTriangleShading {
    let vertex = |k: usize| corners[k] as usize;
    let attributes = &mesh.shading;
    let normals: Option<Vec<Vec3>> = (0..3)
        .map(|k| attributes.normals.get(vertex(k)).copied())
        .collect::<Option<_>>()
        .filter(|n: &Vec<Vec3>| n.iter().all(|n| *n != Vec3::ZERO));
    let mut packed = [0u32; 4];
    if let Some(normals) = normals {
        for (slot, n) in packed.iter_mut().zip(&normals) {
            *slot = octahedral_snorm(*n);
        }
        packed[3] = SHADING_NORMALS;
    }
    let uv = |set: usize, k: usize| {
        (attributes.uv[set].get(vertex(k)).copied()).unwrap_or(glam::Vec2::ZERO)
    };
    let pair = |a: glam::Vec2, b: glam::Vec2| [a.x, a.y, b.x, b.y];
    GpuTriangleShading {
        normals: packed,
        uv0_01: pair(uv(0, 0), uv(0, 1)),
        uv0_2_uv1_0: pair(uv(0, 2), uv(1, 0)),
        uv1_12: pair(uv(1, 1), uv(1, 2)),
        tangents: packed_tangents(mesh, corners),
    }
}

/// The corners' tangents (octahedral) and bitangent signs (bit k set: corner k's is
/// negative), with SHADING_TANGENTS; all zero when a corner has none or a zero one.
fn packed_tangents(mesh: &Mesh, corners: [u32; 3]) -> [u32; 4] {
    let tangents: Option<Vec<glam::Vec4>> = (corners.iter())
        .map(|&c| mesh.shading.tangents.get(c as usize).copied())
        .collect::<Option<_>>()
        .filter(|t: &Vec<glam::Vec4>| t.iter().all(|t| t.truncate() != Vec3::ZERO));
    let Some(tangents) = tangents else {
        return [0; 4];
    };
    let mut packed = [0, 0, 0, SHADING_TANGENTS];
    for (k, t) in tangents.iter().enumerate() {
        packed[k] = octahedral_snorm(t.truncate());
        if t.w < 0.0 {
            packed[3] |= 1 << k;
        }
    }
    packed
}

/// A unit vector as glsl/surface.glsl's `packSnorm2x16(to_octahedral(n))`.
fn octahedral_snorm(n: Vec3) -> u32 {
    let n = n / (n.x.abs() + n.y.abs() + n.z.abs());
    let sign = |x: f32| if x >= 0.0 { 1.0 } else { -1.0 };
    let (x, y) = if n.z < 0.0 {
        ((1.0 - n.y.abs()) * sign(n.x), (1.0 - n.x.abs()) * sign(n.y))
    } else {
        (n.x, n.y)
    };
    let snorm = |c: f32| ((c.clamp(-1.0, 1.0) * 32767.0).round() as i16) as u16 as u32;
    snorm(x) | (snorm(y) << 16)
}

impl GpuScene {
    pub fn build(scene: &Scene) -> Result<Self, SceneError> {
        super::validate::validate(scene)?;
        let invalid = |problem: String| SceneError::Invalid {
            scene: scene.name.clone(),
            problem,
        };
        let materials: Vec<GpuMaterial> = scene.materials.iter().map(gpu_material).collect();
        let check_material = |m: u32, what: &str| {
            if (m as usize) < materials.len() {
                Ok(())
            } else {
                Err(invalid(format!(
                    "{what} uses material {m} but the scene has {}",
                    materials.len()
                )))
            }
        };

        // BLAS per mesh, triangles (and their shading) stored in leaf order.
        let features = SceneFeatures::of(scene);
        let mut blas_nodes = Vec::new();
        let mut triangles = Vec::new();
        let mut shading = Vec::new();
        let mut mesh_roots = Vec::with_capacity(scene.meshes.len());
        for mesh in &scene.meshes {
            let tris = mesh_triangles(mesh);
            if tris.is_empty() {
                mesh_roots.push(None);
                continue;
            }
            let bvh = build_cwbvh_from_tris(&tris, build_params(), &mut Duration::default());
            let root = blas_nodes.len() as u32;
            let base = triangles.len() as u32;
            blas_nodes.extend(node_words(&bvh));
            triangles.extend(bvh.primitive_indices.iter().map(|&i| {
                let t = tris[i as usize];
                GpuTriangle {
                    v0: v4(t.v0.into(), 0.0),
                    v1: v4(t.v1.into(), 0.0),
                    v2: v4(t.v2.into(), 0.0),
                }
            }));
            if features.shading {
                shading.extend(
                    (bvh.primitive_indices.iter())
                        .map(|&i| triangle_shading(mesh, mesh.indices[i as usize])),
                );
            }
            mesh_roots.push(Some((
                root,
                base,
                bvh.primitive_indices.len() as u32,
                bvh.total_aabb,
            )));
        }

        // Objects in input order, with world-space bounds for the TLAS.
        let mut objects = Vec::new();
        let mut bounds = Vec::new();
        for (i, inst) in scene.instances.iter().enumerate() {
            check_material(inst.material, &format!("instance {i}"))?;
            let Some(Some((root, base, count, aabb))) = mesh_roots.get(inst.mesh as usize) else {
                if inst.mesh as usize >= scene.meshes.len() {
                    return Err(invalid(format!(
                        "instance {i} refers to mesh {} which does not exist",
                        inst.mesh
                    )));
                }
                continue; // an instance of an empty mesh has nothing to trace
            };
            let det = inst.transform.determinant();
            if !det.is_finite() || det.abs() < 1e-30 {
                return Err(invalid(format!(
                    "instance {i} has a singular or non-finite transform"
                )));
            }
            let to_world = rows(inst.transform);
            let to_object = rows(inst.transform.inverse());
            let (surface, alpha_cutoff) = surface_flags(&scene.materials[inst.material as usize]);
            bounds.push(transform_aabb(aabb, inst.transform));
            objects.push(GpuObject {
                world_to_object0: to_object[0],
                world_to_object1: to_object[1],
                world_to_object2: to_object[2],
                object_to_world0: to_world[0],
                object_to_world1: to_world[1],
                object_to_world2: to_world[2],
                kind: KIND_INSTANCE,
                material: inst.material,
                blas_root: *root,
                triangle_base: *base,
                triangle_count: *count,
                emitter: NO_EMITTER,
                surface,
                alpha_cutoff,
                ..Default::default()
            });
        }
        for (i, b) in scene.boxes.iter().enumerate() {
            check_material(b.material, &format!("box {i}"))?;
            if !(b.min.is_finite() && b.max.is_finite() && b.min.cmple(b.max).all()) {
                return Err(invalid(format!(
                    "box {i} has min {} > max {} or a non-finite corner",
                    b.min, b.max
                )));
            }
            bounds.push(Aabb::new(b.min.into(), b.max.into()));
            objects.push(GpuObject {
                a: v4(b.min, 0.0),
                b: v4(b.max, 0.0),
                kind: KIND_BOX,
                material: b.material,
                emitter: NO_EMITTER,
                ..identity_object()
            });
        }
        for (i, s) in scene.spheres.iter().enumerate() {
            check_material(s.material, &format!("sphere {i}"))?;
            if !(s.center.is_finite() && s.radius.is_finite() && s.radius > 0.0) {
                return Err(invalid(format!(
                    "sphere {i} needs a finite centre and a radius > 0 (got {})",
                    s.radius
                )));
            }
            let r = Vec3A::splat(s.radius);
            bounds.push(Aabb::new(
                Vec3A::from(s.center) - r,
                Vec3A::from(s.center) + r,
            ));
            objects.push(GpuObject {
                a: v4(s.center, s.radius),
                kind: KIND_SPHERE,
                material: s.material,
                emitter: NO_EMITTER,
                ..identity_object()
            });
        }

        // TLAS over objects; objects reordered into its leaf order.
        let (tlas_nodes, objects) = if objects.is_empty() {
            (Vec::new(), objects)
        } else {
            let tlas = build_cwbvh(&bounds, build_params(), &mut Duration::default());
            let ordered: Vec<GpuObject> = tlas
                .primitive_indices
                .iter()
                .map(|&i| objects[i as usize])
                .collect();
            (node_words(&tlas), ordered)
        };
        let mut objects = objects;
        let mut emitters = collect_emitters(&mut objects, &triangles, &scene.materials);
        // A black environment (all texels 0, or intensity 0) is no light: a share of the shadow
        // rays would be spent on it for nothing.
        let has_map = (scene.environment_map.as_ref()).is_some_and(|m| {
            m.intensity > 0.0 && m.map.texels.iter().any(|t| t.max_element() > 0.0)
        });
        let env_pmf = add_lights_and_select_by_power(
            &mut emitters,
            &scene.lights,
            has_map,
            scene.light_selection,
        );
        let environment = GpuEnvironment::of(scene.environment_map.as_ref());

        let env = &scene.environment;
        let info = GpuSceneInfo {
            sky_zenith: v4(env.zenith, 0.0),
            sky_horizon: v4(env.horizon, 0.0),
            sky_ground: v4(env.ground, 0.0),
            emitter_count: emitters.len() as u32,
            object_count: objects.len() as u32,
            tlas_node_count: tlas_nodes.len() as u32,
            // The renderer uploads the BLAS nodes and then the TLAS's into one buffer.
            tlas_root: blas_nodes.len() as u32,
            env_width: environment.width,
            env_height: environment.height,
            env_rotate_cos: environment.rotate_deg.to_radians().cos(),
            env_rotate_sin: environment.rotate_deg.to_radians().sin(),
            env_pmf,
            ..Default::default()
        };
        let mut features = features;
        // Zero-area emitters are dropped (they emit nothing); uneven ones are not NEE's but
        // still emit where a path hits them.
        let uneven_emission = (objects.iter()).any(|o| {
            let m = &scene.materials[o.material as usize];
            m.is_emissive() && emits_unevenly(m)
        });
        features.emitters = !emitters.is_empty() || uneven_emission;
        Ok(Self {
            blas_nodes,
            tlas_nodes,
            triangles,
            shading,
            objects,
            materials,
            emitters,
            environment: environment.texels,
            info,
            features,
        })
    }

    /// Every BLAS's nodes, then the TLAS's: the GPU's one node array (the TLAS's root at
    /// `info.tlas_root`).
    /// What the GPU is given of the scene, as one fingerprint: its BVHs, triangles, objects,
    /// materials, emitters, info (sky, camera-independent counts) and shading attributes.
    pub fn fingerprint(&self) -> u64 {
        use bytemuck::cast_slice;
        let fingerprint = super::fingerprint::Fingerprint::default()
            .bytes(cast_slice(&self.blas_nodes))
            .bytes(cast_slice(&self.tlas_nodes))
            .bytes(cast_slice(&self.triangles))
            .bytes(cast_slice(&self.objects))
            .bytes(cast_slice(&self.materials))
            .bytes(cast_slice(&self.emitters))
            .bytes(bytemuck::bytes_of(&self.info));
        // Scenes without shading attributes keep the fingerprints they had before there were
        // any (reference caches are keyed by them).
        let fingerprint = match self.shading.is_empty() {
            true => fingerprint,
            false => fingerprint.bytes(cast_slice(&self.shading)),
        };
        let fingerprint = match self.environment.is_empty() {
            true => fingerprint,
            false => fingerprint.bytes(cast_slice(&self.environment)),
        };
        fingerprint.value()
    }

    pub fn nodes(&self) -> Vec<GpuNode> {
        [self.blas_nodes.as_slice(), self.tlas_nodes.as_slice()].concat()
    }

    /// The objects as the ray-query traversal's acceleration structures hold them (in
    /// OBJECTS' order: an instance's custom index is its object index).
    pub fn accel_objects(&self) -> Vec<AccelObject> {
        self.objects
            .iter()
            .map(|ob| match ob.kind {
                KIND_INSTANCE => AccelObject::Mesh {
                    first: ob.triangle_base,
                    count: ob.triangle_count,
                    to_world: [
                        ob.object_to_world0,
                        ob.object_to_world1,
                        ob.object_to_world2,
                    ],
                    surface: ob.surface,
                },
                KIND_BOX => padded_bounds([ob.a[0], ob.a[1], ob.a[2]], [ob.b[0], ob.b[1], ob.b[2]]),
                _ => {
                    let (c, r) = ([ob.a[0], ob.a[1], ob.a[2]], ob.a[3]);
                    padded_bounds(c.map(|x| x - r), c.map(|x| x + r))
                }
            })
            .collect()
    }

    /// Bytes the scene occupies on the GPU.
    pub fn byte_size(&self) -> u64 {
        (std::mem::size_of_val(self.blas_nodes.as_slice())
            + std::mem::size_of_val(self.tlas_nodes.as_slice())
            + std::mem::size_of_val(self.triangles.as_slice())
            + std::mem::size_of_val(self.objects.as_slice())
            + std::mem::size_of_val(self.materials.as_slice())
            + std::mem::size_of_val(self.emitters.as_slice())) as u64
    }
}

/// A box or sphere's bounds for the ray-query traversal, grown by a little more than float
/// rounding (of c - r, and of the driver's slab test on a flat box), so the driver reports
/// every ray that the shader's exact test would hit; a few more candidates cost nothing.
fn padded_bounds(min: [f32; 3], max: [f32; 3]) -> AccelObject {
    let scale = min.iter().chain(&max).fold(1.0f32, |m, x| m.max(x.abs()));
    let pad = scale * 1e-5;
    AccelObject::Bounds {
        min: min.map(|x| x - pad),
        max: max.map(|x| x + pad),
    }
}

fn identity_object() -> GpuObject {
    let id = rows(Mat4::IDENTITY);
    GpuObject {
        world_to_object0: id[0],
        world_to_object1: id[1],
        world_to_object2: id[2],
        object_to_world0: id[0],
        object_to_world1: id[1],
        object_to_world2: id[2],
        ..Default::default()
    }
}

/// The world box of an object-space box under `m` (its eight corners transformed).
pub(crate) fn transform_aabb(aabb: &Aabb, m: Mat4) -> Aabb {
    let mut out = Aabb::empty();
    for i in 0..8 {
        let corner = Vec3::new(
            if i & 1 == 0 { aabb.min.x } else { aabb.max.x },
            if i & 2 == 0 { aabb.min.y } else { aabb.max.y },
            if i & 4 == 0 { aabb.min.z } else { aabb.max.z },
        );
        out.extend(m.transform_point3(corner).into());
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{Camera, Environment, Instance, Material, Mesh};

    #[test]
    fn a_gpu_node_is_obvhs_node_field_for_field() {
        // Many triangles, so the root has inner children as well as leaves.
        let tris: Vec<Triangle> = (0..200)
            .map(|i| {
                let o = Vec3A::new((i % 10) as f32, (i / 10) as f32 * 0.7, (i % 7) as f32 * 0.3);
                Triangle {
                    v0: o,
                    v1: o + Vec3A::X * 0.5,
                    v2: o + Vec3A::Y * 0.5,
                }
            })
            .collect();
        let bvh = build_cwbvh_from_tris(&tris, build_params(), &mut Duration::default());
        let nodes = node_words(&bvh);
        assert_eq!(nodes.len(), bvh.nodes.len());
        assert_eq!(
            std::mem::size_of::<GpuNode>(),
            TEXELS_PER_NODE as usize * 16
        );
        for (gpu, cpu) in nodes.iter().zip(&bvh.nodes) {
            assert_eq!(gpu.origin, cpu.p.to_array());
            assert_eq!(gpu.exponents, cpu.e);
            assert_eq!(gpu.inner_mask, cpu.imask);
            assert_eq!(gpu.child_base, cpu.child_base_idx);
            assert_eq!(gpu.primitive_base, cpu.primitive_base_idx);
            assert_eq!(gpu.child_meta, cpu.child_meta);
            assert_eq!(
                [gpu.child_min_x, gpu.child_max_x, gpu.child_min_y],
                [cpu.child_min_x, cpu.child_max_x, cpu.child_min_y]
            );
            assert_eq!(
                [gpu.child_max_y, gpu.child_min_z, gpu.child_max_z],
                [cpu.child_max_y, cpu.child_min_z, cpu.child_max_z]
            );
        }
        assert!(nodes[0].inner_mask != 0, "the root has inner children");
    }

    fn emissive_triangle_scene(transform: Mat4) -> Scene {
        Scene {
            name: "t".into(),
            meshes: vec![Mesh {
                name: "tri".into(),
                positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y],
                indices: vec![[0, 1, 2]],
                shading: Default::default(),
            }],
            instances: vec![Instance {
                mesh: 0,
                material: 0,
                transform,
            }],
            boxes: vec![],
            spheres: vec![],
            materials: vec![Material::emitter(Vec3::ZERO, Vec3::ONE)],
            textures: Vec::new(),
            camera: Camera::look_at(Vec3::Z, Vec3::ZERO, Vec3::Y, 40.0, 1.0),
            environment: Environment::black(),
            lights: Vec::new(),
            environment_map: None,
            light_selection: Default::default(),
        }
    }

    fn emitter_normal(e: &GpuEmitter) -> Vec3 {
        let p = |v: [f32; 4]| Vec3::new(v[0], v[1], v[2]);
        (p(e.p1) - p(e.p0)).cross(p(e.p2) - p(e.p0)).normalize()
    }

    #[test]
    fn emitter_front_side_follows_the_inverse_transpose_normal_even_when_mirrored() {
        // Object-space front normal is +Z. A mirror in z maps the front side to -Z.
        for (transform, expected) in [
            (Mat4::from_translation(Vec3::new(1.0, 2.0, 3.0)), Vec3::Z),
            (Mat4::from_scale(Vec3::new(1.0, 1.0, -1.0)), -Vec3::Z),
            (Mat4::from_scale(Vec3::new(-2.0, 1.0, 1.0)), Vec3::Z),
        ] {
            let gpu = GpuScene::build(&emissive_triangle_scene(transform)).unwrap();
            assert_eq!(gpu.emitters.len(), 1);
            let n = emitter_normal(&gpu.emitters[0]);
            let shader_normal = transform
                .inverse()
                .transpose()
                .transform_vector3(Vec3::Z)
                .normalize();
            assert!((shader_normal - expected).length() < 1e-6, "{transform:?}");
            assert!(
                (n - expected).length() < 1e-6,
                "{transform:?}: emitter normal {n}, expected {expected}"
            );
            assert!(
                (gpu.emitters[0].emission[3] - 0.5 * transform.determinant().abs()).abs() < 1e-6
            );
        }
    }
}
