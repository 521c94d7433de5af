//! Random probe rays around a scene's geometry, for tests that compare traversals: origins
//! scattered around the region the objects occupy, half the directions aimed at a random
//! triangle centre or small box or sphere centre (so most rays hit), half uniform.

use fovea::scene::Scene;
use fovea::shader_layout::GpuProbeRay;
use glam::DVec3;

/// A 64-bit LCG: the same rays on every machine.
pub struct Lcg(pub u64);

impl Lcg {
    pub fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }

    pub fn unit(&mut self) -> DVec3 {
        let z = 2.0 * self.next() - 1.0;
        let phi = std::f64::consts::TAU * self.next();
        let r = (1.0 - z * z).max(0.0).sqrt();
        DVec3::new(r * phi.cos(), r * phi.sin(), z)
    }
}

/// Every triangle of every instance, in world space.
pub fn world_triangles(scene: &Scene) -> Vec<[DVec3; 3]> {
    let mut out = Vec::new();
    for inst in &scene.instances {
        let mesh = &scene.meshes[inst.mesh as usize];
        for t in &mesh.indices {
            out.push(t.map(|i| {
                inst.transform
                    .transform_point3(mesh.positions[i as usize])
                    .as_dvec3()
            }));
        }
    }
    out
}

/// `n` rays (t from 0 to infinity) around `scene`'s objects.
pub fn random_rays(scene: &Scene, n: usize, seed: u64) -> Vec<GpuProbeRay> {
    let mut targets: Vec<DVec3> = world_triangles(scene)
        .iter()
        .map(|t| (t[0] + t[1] + t[2]) / 3.0)
        .collect();
    targets.extend(
        scene
            .boxes
            .iter()
            .filter(|b| (b.max - b.min).max_element() < 10.0)
            .map(|b| ((b.min + b.max) * 0.5).as_dvec3()),
    );
    targets.extend(
        scene
            .spheres
            .iter()
            .filter(|s| s.radius < 10.0)
            .map(|s| s.center.as_dvec3()),
    );
    let lo = targets
        .iter()
        .fold(DVec3::splat(f64::INFINITY), |a, b| a.min(*b));
    let hi = targets
        .iter()
        .fold(DVec3::splat(f64::NEG_INFINITY), |a, b| a.max(*b));
    let centre = (lo + hi) * 0.5;
    let radius = (hi - lo).length().max(1.0);
    let mut rng = Lcg(seed);
    (0..n)
        .map(|i| {
            let o = centre + rng.unit() * radius * (0.6 + rng.next());
            let d = if i % 2 == 0 {
                (targets[(rng.next() * targets.len() as f64) as usize % targets.len()] - o)
                    .normalize()
            } else {
                rng.unit()
            };
            let (of, df) = (o.as_vec3(), d.as_vec3());
            GpuProbeRay {
                origin: [of.x, of.y, of.z, 0.0],
                direction: [df.x, df.y, df.z, f32::INFINITY],
            }
        })
        .collect()
}

/// The distance along o + t*d (t > 0) to the triangle, in f64, or infinity; `edge_slack`
/// widens its barycentric bounds (to accept a ray through an edge that rounding puts outside).
pub fn triangle_t(o: DVec3, d: DVec3, [a, b, c]: [DVec3; 3], edge_slack: f64) -> f64 {
    let (e1, e2) = (b - a, c - a);
    let p = d.cross(e2);
    let det = e1.dot(p);
    if det.abs() < 1e-300 {
        return f64::INFINITY;
    }
    let s = o - a;
    let u = s.dot(p) / det;
    let q = s.cross(e1);
    let v = d.dot(q) / det;
    let t = e2.dot(q) / det;
    if u < -edge_slack || v < -edge_slack || u + v > 1.0 + edge_slack || t <= 0.0 {
        f64::INFINITY
    } else {
        t
    }
}

/// The distance to a box's surface (its far side from inside), in f64, or infinity.
pub fn box_t(o: DVec3, d: DVec3, min: DVec3, max: DVec3) -> f64 {
    let (t0, t1) = ((min - o) / d, (max - o) / d);
    let (near, far) = (t0.min(t1).max_element(), t0.max(t1).min_element());
    if near > far || far <= 0.0 {
        f64::INFINITY
    } else if near > 0.0 {
        near
    } else {
        far
    }
}

/// The distance to a sphere's surface (its far side from inside), in f64, or infinity.
pub fn sphere_t(o: DVec3, d: DVec3, centre: DVec3, radius: f64) -> f64 {
    let oc = o - centre;
    let (a, b, c) = (d.dot(d), oc.dot(d), oc.dot(oc) - radius * radius);
    let disc = b * b - a * c;
    if disc < 0.0 {
        return f64::INFINITY;
    }
    let (near, far) = ((-b - disc.sqrt()) / a, (-b + disc.sqrt()) / a);
    if near > 0.0 {
        near
    } else if far > 0.0 {
        far
    } else {
        f64::INFINITY
    }
}
