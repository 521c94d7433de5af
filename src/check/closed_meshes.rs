//! Closed triangle meshes for the watertightness check: an icosphere, a subdivided cube and the
//! bunny, plus the topology tools that prove them closed (every directed edge has exactly one
//! opposite) and tell inside from outside (generalized winding number).

use crate::scene::{gltf_load, Mesh, SceneError};
use glam::{DVec3, Vec3};
use std::collections::HashMap;

/// A unit icosphere: the icosahedron with each triangle split into four `subdivisions` times,
/// new vertices shared between neighbours (so shared edges are bit-identical) and pushed out
/// to the unit sphere. `20 · 4^subdivisions` triangles, counter-clockwise seen from outside.
pub fn icosphere(subdivisions: u32) -> Mesh {
    let t = (1.0 + 5f32.sqrt()) / 2.0;
    let mut positions: Vec<Vec3> = [
        [-1.0, t, 0.0],
        [1.0, t, 0.0],
        [-1.0, -t, 0.0],
        [1.0, -t, 0.0],
        [0.0, -1.0, t],
        [0.0, 1.0, t],
        [0.0, -1.0, -t],
        [0.0, 1.0, -t],
        [t, 0.0, -1.0],
        [t, 0.0, 1.0],
        [-t, 0.0, -1.0],
        [-t, 0.0, 1.0],
    ]
    .iter()
    .map(|p| Vec3::from(*p).normalize())
    .collect();
    let mut indices: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..subdivisions {
        let mut midpoints: HashMap<(u32, u32), u32> = HashMap::new();
        let mut midpoint = |a: u32, b: u32, positions: &mut Vec<Vec3>| -> u32 {
            *midpoints.entry((a.min(b), a.max(b))).or_insert_with(|| {
                let m = (positions[a as usize] + positions[b as usize]).normalize();
                positions.push(m);
                positions.len() as u32 - 1
            })
        };
        let mut next = Vec::with_capacity(indices.len() * 4);
        for [a, b, c] in indices {
            let ab = midpoint(a, b, &mut positions);
            let bc = midpoint(b, c, &mut positions);
            let ca = midpoint(c, a, &mut positions);
            next.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        indices = next;
    }
    Mesh {
        name: format!("icosphere-{subdivisions}"),
        positions,
        indices,
        shading: Default::default(),
    }
}

/// The cube [-1, 1]³ with each face an `n × n` grid of quads (two triangles each), grid
/// vertices shared across faces along the cube's edges. `12 n²` triangles, outward winding.
pub fn subdivided_cube(n: u32) -> Mesh {
    let n = n.max(1);
    let mut positions = Vec::new();
    // Vertices keyed by integer lattice coordinates in 0..=n, so edge vertices are shared.
    let mut lattice: HashMap<[u32; 3], u32> = HashMap::new();
    let mut vertex = |q: [u32; 3], positions: &mut Vec<Vec3>| -> u32 {
        *lattice.entry(q).or_insert_with(|| {
            positions.push(Vec3::from(q.map(|c| 2.0 * c as f32 / n as f32 - 1.0)));
            positions.len() as u32 - 1
        })
    };
    let mut indices = Vec::with_capacity(12 * (n * n) as usize);
    for axis in 0..3 {
        for side in [0, n] {
            // (u, v) span the face; (u × v) points along +axis, so flip the winding on the
            // lower face to keep every normal pointing out.
            let (u_axis, v_axis) = ((axis + 1) % 3, (axis + 2) % 3);
            for i in 0..n {
                for j in 0..n {
                    let mut corner = |du: u32, dv: u32| {
                        let mut q = [0; 3];
                        q[axis] = side;
                        q[u_axis] = i + du;
                        q[v_axis] = j + dv;
                        vertex(q, &mut positions)
                    };
                    let (a, b, c, d) = (corner(0, 0), corner(1, 0), corner(1, 1), corner(0, 1));
                    if side == n {
                        indices.extend([[a, b, c], [a, c, d]]);
                    } else {
                        indices.extend([[a, c, b], [a, d, c]]);
                    }
                }
            }
        }
    }
    Mesh {
        name: format!("cube-{n}x{n}"),
        positions,
        indices,
        shading: Default::default(),
    }
}

/// The 4968-triangle bunny of the bundled asset. It is already closed (genus 0: V − E + F = 2),
/// which this checks rather than assumes: a mesh with holes would make "escapes" meaningless.
pub fn closed_bunny() -> Result<Mesh, SceneError> {
    let mut bunny = gltf_load::mesh_from_glb_bytes(
        include_bytes!("../../assets/bunny-high.glb"),
        "bunny-high.glb",
    )?;
    let open = boundary_edges(&bunny).len() + non_manifold_edges(&bunny);
    if open > 0 {
        return Err(SceneError::Invalid {
            scene: "bunny-high.glb".into(),
            problem: format!("{open} open or non-manifold edges: it no longer encloses a volume"),
        });
    }
    bunny.name = "bunny-high".into();
    Ok(bunny)
}

/// Directed edges (a → b) that have no opposite (b → a): the rims of holes. Empty for a closed,
/// consistently oriented mesh.
pub fn boundary_edges(mesh: &Mesh) -> Vec<(u32, u32)> {
    let mut count: HashMap<(u32, u32), i32> = HashMap::new();
    for &[a, b, c] in &mesh.indices {
        for (p, q) in [(a, b), (b, c), (c, a)] {
            *count.entry((p, q)).or_default() += 1;
        }
    }
    let mut open: Vec<(u32, u32)> = count
        .iter()
        .filter(|(&(p, q), &n)| n > count.get(&(q, p)).copied().unwrap_or(0))
        .map(|(&e, _)| e)
        .collect();
    open.sort_unstable();
    open
}

/// Edges used by anything other than exactly one triangle in each direction: 0 for a closed
/// two-manifold with consistent winding.
pub fn non_manifold_edges(mesh: &Mesh) -> usize {
    let mut count: HashMap<(u32, u32), u32> = HashMap::new();
    for &[a, b, c] in &mesh.indices {
        for (p, q) in [(a, b), (b, c), (c, a)] {
            *count.entry((p, q)).or_default() += 1;
        }
    }
    count
        .iter()
        .filter(|(&(p, q), &n)| n != 1 || count.get(&(q, p)) != Some(&1))
        .count()
}

/// The generalized winding number of `p` with respect to the mesh (Jacobson et al. 2013): the
/// sum of the signed solid angles of its triangles over 4π (Van Oosterom & Strackee 1983), in
/// f64. 1 inside a closed outward-wound mesh, 0 outside.
pub fn winding_number(mesh: &Mesh, p: DVec3) -> f64 {
    let mut total = 0.0;
    for t in &mesh.indices {
        let [a, b, c] = t.map(|i| mesh.positions[i as usize].as_dvec3() - p);
        let (la, lb, lc) = (a.length(), b.length(), c.length());
        let numerator = a.dot(b.cross(c));
        let denominator = la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
        total += 2.0 * numerator.atan2(denominator);
    }
    total / (4.0 * std::f64::consts::PI)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn icosphere_and_cube_are_closed_with_the_expected_counts() {
        for (mesh, triangles) in [
            (icosphere(0), 20),
            (icosphere(3), 1280),
            (subdivided_cube(1), 12),
            (subdivided_cube(7), 588),
        ] {
            assert_eq!(mesh.indices.len(), triangles, "{}", mesh.name);
            assert!(boundary_edges(&mesh).is_empty(), "{}", mesh.name);
            assert_eq!(non_manifold_edges(&mesh), 0, "{}", mesh.name);
            // Euler characteristic of a sphere: V − E + F = 2, with E = 3F/2.
            let (v, f) = (mesh.positions.len() as i64, mesh.indices.len() as i64);
            assert_eq!(v - 3 * f / 2 + f, 2, "{}", mesh.name);
        }
    }

    #[test]
    fn a_missing_triangle_shows_as_three_boundary_edges() {
        let mut mesh = subdivided_cube(2);
        mesh.indices.remove(5);
        assert_eq!(boundary_edges(&mesh).len(), 3);
        assert_eq!(non_manifold_edges(&mesh), 3);
    }

    #[test]
    fn the_bundled_bunny_is_closed() {
        let bunny = closed_bunny().unwrap();
        assert_eq!(bunny.indices.len(), 4968);
        let (v, f) = (bunny.positions.len() as i64, bunny.indices.len() as i64);
        assert_eq!(v - 3 * f / 2 + f, 2);
    }

    #[test]
    fn winding_number_is_one_inside_and_zero_outside() {
        for mesh in [icosphere(2), subdivided_cube(3), closed_bunny().unwrap()] {
            let (lo, hi) = mesh
                .positions
                .iter()
                .fold((DVec3::MAX, DVec3::MIN), |(lo, hi), p| {
                    (lo.min(p.as_dvec3()), hi.max(p.as_dvec3()))
                });
            let outside = hi + (hi - lo);
            assert!(winding_number(&mesh, outside).abs() < 1e-9, "{}", mesh.name);
        }
        for mesh in [icosphere(2), subdivided_cube(3)] {
            let w = winding_number(&mesh, DVec3::new(0.1, -0.2, 0.05));
            assert!((w - 1.0).abs() < 1e-9, "{}: {w}", mesh.name);
        }
    }
}
