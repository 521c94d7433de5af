//! Closest hits on the CPU, for the one ray per frame that finds where the eye fixates (the
//! gaze ray of `foveation::fixation`). The same two-level structure and intersection tests as
//! the GPU traversal (glsl/bvh.glsl, glsl/geometry.glsl): a CWBVH per mesh (obvhs, nodes tested
//! with its SIMD code), one over all objects, watertight triangles (Woop, Benthin, Wald 2013),
//! slab boxes and robust spheres in f32, so both agree on hit or miss and on the distance.
//! Traversal keeps its stack in a `Vec`: unlike obvhs' fixed stack it never drops a node.

use super::gpu_layout::{build_params, mesh_triangles, transform_aabb};
use super::Scene;
use glam::{Mat4, UVec2, Vec3, Vec3A};
use obvhs::aabb::Aabb;
use obvhs::cwbvh::builder::{build_cwbvh, build_cwbvh_from_tris};
use obvhs::cwbvh::CwBvh;
use obvhs::ray::Ray;
use std::time::Duration;

/// One mesh's BVH with its triangles in leaf order (a leaf's primitive id indexes `tris`).
struct Blas {
    bvh: CwBvh,
    tris: Vec<[Vec3; 3]>,
}

enum Object {
    /// A mesh placed by `world_to_object` (the ray goes to object space, unnormalised, so t is
    /// the same in both spaces).
    Instance {
        blas: usize,
        world_to_object: Mat4,
    },
    Box {
        min: Vec3,
        max: Vec3,
    },
    Sphere {
        centre: Vec3,
        radius: f32,
    },
}

/// A scene's geometry ready for CPU closest-hit queries.
pub struct CpuRaycaster {
    blas: Vec<Blas>,
    /// Objects in input order; the TLAS' `primitive_indices` map its leaves here.
    objects: Vec<Object>,
    tlas: Option<CwBvh>,
}

impl CpuRaycaster {
    /// Builds the BVHs of `scene`. Geometry that `GpuScene::build` rejects (singular
    /// transforms, inverted boxes, non-positive radii, missing meshes) is left out: such a
    /// scene is never rendered, so there is nothing to fixate on.
    pub fn new(scene: &Scene) -> Self {
        let mut blas = Vec::new();
        let mut mesh_blas = Vec::with_capacity(scene.meshes.len());
        for mesh in &scene.meshes {
            let tris = mesh_triangles(mesh);
            if tris.is_empty() {
                mesh_blas.push(None);
                continue;
            }
            let bvh = build_cwbvh_from_tris(&tris, build_params(), &mut Duration::default());
            let ordered = bvh
                .primitive_indices
                .iter()
                .map(|&i| {
                    let t = tris[i as usize];
                    [t.v0.into(), t.v1.into(), t.v2.into()]
                })
                .collect();
            mesh_blas.push(Some((blas.len(), bvh.total_aabb)));
            blas.push(Blas { bvh, tris: ordered });
        }

        let mut objects = Vec::new();
        let mut bounds = Vec::new();
        for inst in &scene.instances {
            let Some(Some((index, aabb))) = mesh_blas.get(inst.mesh as usize) else {
                continue;
            };
            let det = inst.transform.determinant();
            if !det.is_finite() || det.abs() < 1e-30 {
                continue;
            }
            bounds.push(transform_aabb(aabb, inst.transform));
            objects.push(Object::Instance {
                blas: *index,
                world_to_object: inst.transform.inverse(),
            });
        }
        for b in &scene.boxes {
            if b.min.is_finite() && b.max.is_finite() && b.min.cmple(b.max).all() {
                bounds.push(Aabb::new(b.min.into(), b.max.into()));
                objects.push(Object::Box {
                    min: b.min,
                    max: b.max,
                });
            }
        }
        for s in &scene.spheres {
            if s.center.is_finite() && s.radius.is_finite() && s.radius > 0.0 {
                let r = Vec3A::splat(s.radius);
                let c = Vec3A::from(s.center);
                bounds.push(Aabb::new(c - r, c + r));
                objects.push(Object::Sphere {
                    centre: s.center,
                    radius: s.radius,
                });
            }
        }
        if objects.is_empty() {
            return Self {
                blas,
                objects,
                tlas: None,
            };
        }
        let tlas = build_cwbvh(&bounds, build_params(), &mut Duration::default());
        Self {
            blas,
            objects,
            tlas: Some(tlas),
        }
    }

    /// Distance along the normalised `dir` from `origin` to the closest surface, or `None`
    /// when the ray leaves the scene, or when `origin` or `dir` is not finite or `dir` is zero.
    pub fn closest_hit(&self, origin: Vec3, dir: Vec3) -> Option<f32> {
        self.closest_hit_counted(origin, dir).0
    }

    /// [`Self::closest_hit`], and how many primitives (objects and triangles) the ray was
    /// tested against: the work the BVHs saved is the scene's primitives less these.
    pub fn closest_hit_counted(&self, origin: Vec3, dir: Vec3) -> (Option<f32>, u32) {
        let Some(d) = dir.try_normalize() else {
            return (None, 0);
        };
        if !origin.is_finite() {
            return (None, 0);
        }
        let mut tests = 0;
        let t = self.closest_t(origin, d, f32::INFINITY, &mut tests);
        ((t < f32::INFINITY).then_some(t), tests)
    }

    /// Closest hit parameter in (0, t_max) along `o + t d` (`d` need not be normalised), or ∞;
    /// adds the primitives tested to `tests`.
    fn closest_t(&self, o: Vec3, d: Vec3, t_max: f32, tests: &mut u32) -> f32 {
        let Some(tlas) = &self.tlas else {
            return f32::INFINITY;
        };
        let d = safe_direction(d);
        let inv_d = d.recip();
        let mut best = t_max;
        traverse(tlas, o, d, &mut best, |id, best| {
            *tests += 1;
            let t = match &self.objects[tlas.primitive_indices[id] as usize] {
                Object::Instance {
                    blas,
                    world_to_object,
                } => {
                    let lo = world_to_object.transform_point3(o);
                    let ld = world_to_object.transform_vector3(d);
                    self.blas_t(&self.blas[*blas], lo, ld, *best, tests)
                }
                Object::Box { min, max } => intersect_box(o, inv_d, *min, *max, *best),
                Object::Sphere { centre, radius } => {
                    intersect_sphere(o, d, *centre, *radius, *best)
                }
            };
            if t < *best {
                *best = t;
            }
        });
        if best < t_max {
            best
        } else {
            f32::INFINITY
        }
    }

    fn blas_t(&self, blas: &Blas, o: Vec3, d: Vec3, t_max: f32, tests: &mut u32) -> f32 {
        let d = safe_direction(d);
        let w = WatertightRay::new(d);
        let mut best = t_max;
        traverse(&blas.bvh, o, d, &mut best, |id, best| {
            *tests += 1;
            let [a, b, c] = blas.tris[id];
            let t = w.intersect(o, a, b, c, *best);
            if t < *best {
                *best = t;
            }
        });
        best
    }
}

/// Walks a CWBVH front to back (Ylitie et al. 2017, the order of obvhs' `traverse!` and of
/// glsl/bvh.glsl), calling `leaf(primitive id, t_max)` for every primitive of every leaf whose
/// box the ray meets before `t_max`; `leaf` lowers `t_max` on a hit.
fn traverse(bvh: &CwBvh, o: Vec3, d: Vec3, t_max: &mut f32, mut leaf: impl FnMut(usize, &mut f32)) {
    if bvh.nodes.is_empty() {
        return;
    }
    let oct_inv4 = octant_inv4(d);
    let mut stack: Vec<UVec2> = Vec::with_capacity(32);
    let mut current = UVec2::new(0, 0x8000_0000);
    let mut prims = UVec2::ZERO;
    loop {
        while prims.y != 0 {
            let local = 31 - prims.y.leading_zeros();
            prims.y &= !(1 << local);
            leaf((prims.x + local) as usize, t_max);
        }
        if current.y & 0xff00_0000 != 0 {
            let hits = current.y;
            let child_offset = 31 - hits.leading_zeros();
            current.y &= !(1 << child_offset);
            if current.y & 0xff00_0000 != 0 {
                stack.push(current);
            }
            let slot = (child_offset - 24) ^ (oct_inv4 & 0xff);
            let relative = (hits & !(u32::MAX << slot)).count_ones();
            let node = &bvh.nodes[(current.x + relative) as usize];
            let ray = Ray::new(o.into(), d.into(), 0.0, *t_max);
            let mask = node.intersect_ray(&ray, oct_inv4);
            current = UVec2::new(
                node.child_base_idx,
                (mask & 0xff00_0000) | node.imask as u32,
            );
            prims = UVec2::new(node.primitive_base_idx, mask & 0x00ff_ffff);
        } else {
            current = UVec2::ZERO;
        }
        if prims.y == 0 && current.y & 0xff00_0000 == 0 {
            match stack.pop() {
                Some(next) => current = next,
                None => return,
            }
        }
    }
}

fn octant_inv4(d: Vec3) -> u32 {
    (if d.x < 0.0 { 0 } else { 0x0404_0404 })
        | (if d.y < 0.0 { 0 } else { 0x0202_0202 })
        | (if d.z < 0.0 { 0 } else { 0x0101_0101 })
}

/// Zero direction components become a tiny signed value, so 1/d is finite and slab tests
/// never compute 0·∞ (as glsl/geometry.glsl's `safe_direction`).
fn safe_direction(d: Vec3) -> Vec3 {
    const TINY: f32 = 1e-20;
    let fix = |v: f32| {
        if v.abs() < TINY {
            if v < 0.0 {
                -TINY
            } else {
                TINY
            }
        } else {
            v
        }
    };
    Vec3::new(fix(d.x), fix(d.y), fix(d.z))
}

/// Per-ray constants of the watertight test: the axis with the largest direction component
/// becomes z, and the shear that makes the ray (0, 0, 1).
struct WatertightRay {
    k: [usize; 3],
    s: Vec3,
}

impl WatertightRay {
    fn new(d: Vec3) -> Self {
        let a = d.abs();
        let kz = if a.x > a.y {
            if a.x > a.z {
                0
            } else {
                2
            }
        } else if a.y > a.z {
            1
        } else {
            2
        };
        let (mut kx, mut ky) = ((kz + 1) % 3, (kz + 2) % 3);
        if d[kz] < 0.0 {
            std::mem::swap(&mut kx, &mut ky);
        }
        Self {
            k: [kx, ky, kz],
            s: Vec3::new(d[kx] / d[kz], d[ky] / d[kz], 1.0 / d[kz]),
        }
    }

    /// Hit distance in (0, t_max), or ∞. Exact sign tests on the sheared 2D projection: an
    /// edge shared by two triangles is never missed by both.
    fn intersect(&self, o: Vec3, v0: Vec3, v1: Vec3, v2: Vec3, t_max: f32) -> f32 {
        let [kx, ky, kz] = self.k;
        let s = self.s;
        let (a, b, c) = (v0 - o, v1 - o, v2 - o);
        let (ax, ay) = (a[kx] - s.x * a[kz], a[ky] - s.y * a[kz]);
        let (bx, by) = (b[kx] - s.x * b[kz], b[ky] - s.y * b[kz]);
        let (cx, cy) = (c[kx] - s.x * c[kz], c[ky] - s.y * c[kz]);
        let u = cx * by - cy * bx;
        let v = ax * cy - ay * cx;
        let w = bx * ay - by * ax;
        if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
            return f32::INFINITY;
        }
        let det = u + v + w;
        if det == 0.0 {
            return f32::INFINITY;
        }
        let t = (u * (s.z * a[kz]) + v * (s.z * b[kz]) + w * (s.z * c[kz])) / det;
        if t > 0.0 && t < t_max {
            t
        } else {
            f32::INFINITY
        }
    }
}

/// Slab test: the entry distance, or the exit distance when the origin is inside.
fn intersect_box(o: Vec3, inv_d: Vec3, min: Vec3, max: Vec3, t_max: f32) -> f32 {
    let (t0, t1) = ((min - o) * inv_d, (max - o) * inv_d);
    let near = t0.min(t1).max_element();
    let far = t0.max(t1).min_element();
    if near > far {
        f32::INFINITY
    } else if near > 0.0 && near < t_max {
        near
    } else if far > 0.0 && far < t_max {
        far
    } else {
        f32::INFINITY
    }
}

/// Robust quadratic (Haines et al., Ray Tracing Gems ch. 7): the discriminant from the
/// perpendicular distance, the smaller root from Vieta's formula.
fn intersect_sphere(o: Vec3, d: Vec3, centre: Vec3, radius: f32, t_max: f32) -> f32 {
    let f = o - centre;
    let a = d.dot(d);
    let b = -f.dot(d);
    let l = f + (b / a) * d;
    let disc = a * (radius * radius - l.dot(l));
    if disc < 0.0 {
        return f32::INFINITY;
    }
    let sq = disc.sqrt();
    let q = b + if b >= 0.0 { sq } else { -sq };
    let c = f.dot(f) - radius * radius;
    let (t0, t1) = (c / q, q / a);
    let (near, far) = (t0.min(t1), t0.max(t1));
    if near > 0.0 && near < t_max {
        near
    } else if far > 0.0 && far < t_max {
        far
    } else {
        f32::INFINITY
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{AaBox, Camera, Environment, Instance, Material, Mesh, Sphere};

    /// A unit quad (two triangles) at z = 0 scaled by 2 and moved to z = -5, a box and a
    /// sphere, each where a ray along a known axis meets it at a known distance.
    fn simple_scene() -> Scene {
        Scene {
            name: "simple".into(),
            meshes: vec![Mesh {
                name: "quad".into(),
                positions: vec![
                    Vec3::new(-1.0, -1.0, 0.0),
                    Vec3::new(1.0, -1.0, 0.0),
                    Vec3::new(1.0, 1.0, 0.0),
                    Vec3::new(-1.0, 1.0, 0.0),
                ],
                indices: vec![[0, 1, 2], [0, 2, 3]],
                shading: Default::default(),
            }],
            instances: vec![Instance {
                mesh: 0,
                material: 0,
                transform: Mat4::from_translation(Vec3::new(0.0, 0.0, -5.0))
                    * Mat4::from_scale(Vec3::splat(2.0)),
            }],
            boxes: vec![AaBox {
                min: Vec3::new(3.0, -1.0, -1.0),
                max: Vec3::new(4.0, 1.0, 1.0),
                material: 0,
            }],
            spheres: vec![Sphere {
                center: Vec3::new(0.0, 10.0, 0.0),
                radius: 2.0,
                material: 0,
            }],
            materials: vec![Material::diffuse(Vec3::splat(0.5))],
            textures: Vec::new(),
            camera: Camera::look_at(Vec3::ZERO, -Vec3::Z, Vec3::Y, 60.0, 1.0),
            environment: Environment::black(),
            lights: Vec::new(),
            environment_map: None,
            light_selection: Default::default(),
        }
    }

    #[test]
    fn analytic_distances() {
        let rc = CpuRaycaster::new(&simple_scene());
        let close = |got: Option<f32>, want: f32| {
            let got = got.unwrap_or_else(|| panic!("miss, wanted {want}"));
            assert!((got - want).abs() <= 1e-5 * want, "{got} vs {want}");
        };
        // The quad spans ±2 at z = -5; the direction's length does not matter.
        close(rc.closest_hit(Vec3::ZERO, Vec3::new(0.0, 0.0, -3.0)), 5.0);
        close(rc.closest_hit(Vec3::new(1.5, -1.9, 0.0), -Vec3::Z), 5.0);
        // Oblique: (1, 0, -5)/|…| reaches z = -5 at x = 1, after √26.
        close(
            rc.closest_hit(Vec3::ZERO, Vec3::new(1.0, 0.0, -5.0)),
            26f32.sqrt(),
        );
        // Box face x = 3; from inside the box, its exit face x = 4.
        close(rc.closest_hit(Vec3::ZERO, Vec3::X), 3.0);
        close(rc.closest_hit(Vec3::new(3.5, 0.0, 0.0), Vec3::X), 0.5);
        // Sphere of radius 2 at y = 10: entry at 8; from its centre, 2.
        close(rc.closest_hit(Vec3::ZERO, Vec3::Y), 8.0);
        close(rc.closest_hit(Vec3::new(0.0, 10.0, 0.0), Vec3::Z), 2.0);
        // Past the quad's edge, away from everything, behind the eye.
        assert_eq!(rc.closest_hit(Vec3::new(2.5, 0.0, 0.0), -Vec3::Z), None);
        assert_eq!(rc.closest_hit(Vec3::ZERO, -Vec3::Y), None);
        assert_eq!(rc.closest_hit(Vec3::new(0.0, 0.0, -6.0), -Vec3::Z), None);
    }

    #[test]
    fn bad_rays_miss_instead_of_failing() {
        let rc = CpuRaycaster::new(&simple_scene());
        assert_eq!(rc.closest_hit(Vec3::ZERO, Vec3::ZERO), None);
        assert_eq!(
            rc.closest_hit(Vec3::ZERO, Vec3::new(f32::NAN, 0.0, 1.0)),
            None
        );
        assert_eq!(rc.closest_hit(Vec3::splat(f32::INFINITY), -Vec3::Z), None);
    }

    #[test]
    fn an_empty_scene_is_all_misses() {
        let scene = Scene {
            meshes: vec![],
            instances: vec![],
            boxes: vec![],
            spheres: vec![],
            ..simple_scene()
        };
        assert_eq!(
            CpuRaycaster::new(&scene).closest_hit(Vec3::ZERO, Vec3::X),
            None
        );
    }

    #[test]
    fn the_nearest_of_many_overlapping_objects_wins() {
        // 50 boxes one behind the other along -z: the first one's face is the hit.
        let mut scene = simple_scene();
        scene.boxes = (0..50)
            .map(|i| AaBox {
                min: Vec3::new(-0.5, -0.5, -20.0 - i as f32),
                max: Vec3::new(0.5, 0.5, -19.5 - i as f32),
                material: 0,
            })
            .collect();
        scene.instances.clear();
        let rc = CpuRaycaster::new(&scene);
        let t = rc.closest_hit(Vec3::ZERO, -Vec3::Z).unwrap();
        assert!((t - 19.5).abs() < 1e-5, "{t}");
    }
}
