//! Meshes made in code, for sample scenes and tests: a quad, a cube and a UV sphere, each
//! counter-clockwise from outside (glTF's front) with texture coordinates.

use std::f32::consts::{PI, TAU};

use glam::{Vec2, Vec3, Vec4};

use super::{Mesh, VertexShading};

/// A 2 × 2 quad in z = 0 facing +z, with normals, tangents (+x, so the normal map's x is +u)
/// and uv (0, 0) at its top left.
pub fn quad() -> Mesh {
    Mesh {
        name: "quad".into(),
        positions: vec![
            Vec3::new(-1.0, -1.0, 0.0),
            Vec3::new(1.0, -1.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(-1.0, 1.0, 0.0),
        ],
        indices: vec![[0, 1, 2], [0, 2, 3]],
        shading: VertexShading {
            normals: vec![Vec3::Z; 4],
            uv: [
                vec![
                    Vec2::new(0.0, 1.0),
                    Vec2::new(1.0, 1.0),
                    Vec2::new(1.0, 0.0),
                    Vec2::new(0.0, 0.0),
                ],
                vec![],
            ],
            tangents: vec![Vec4::new(1.0, 0.0, 0.0, 1.0); 4],
        },
    }
}

/// A unit sphere of `segments` × `rings` quads with smooth normals and uv.
pub fn uv_sphere(segments: u32, rings: u32) -> Mesh {
    let mut positions = Vec::new();
    let mut uv = Vec::new();
    for r in 0..=rings {
        let v = r as f32 / rings as f32;
        let (sin_t, cos_t) = (v * PI).sin_cos();
        for s in 0..=segments {
            let u = s as f32 / segments as f32;
            let (sin_p, cos_p) = (u * TAU).sin_cos();
            positions.push(Vec3::new(sin_t * cos_p, cos_t, -sin_t * sin_p));
            uv.push(Vec2::new(u, v));
        }
    }
    let row = segments + 1;
    let mut indices = Vec::new();
    for r in 0..rings {
        for s in 0..segments {
            let (a, b) = (r * row + s, (r + 1) * row + s);
            // Counter-clockwise seen from outside; the poles' degenerate halves are skipped.
            if r > 0 {
                indices.push([a, b, a + 1]);
            }
            if r + 1 < rings {
                indices.push([a + 1, b, b + 1]);
            }
        }
    }
    Mesh {
        name: "sphere".into(),
        shading: VertexShading {
            normals: positions.clone(),
            uv: [uv, vec![]],
            tangents: vec![],
        },
        positions,
        indices,
    }
}

/// A cube of side 2 around the origin: 6 faces of 2 triangles, each face's uv the whole
/// texture, counter-clockwise from outside.
pub fn cube() -> Mesh {
    let mut positions = Vec::new();
    let mut uv = Vec::new();
    let mut indices = Vec::new();
    // Each face: its normal, and two axes spanning it with u × v = normal.
    let faces = [
        (Vec3::X, Vec3::NEG_Z, Vec3::Y),
        (Vec3::NEG_X, Vec3::Z, Vec3::Y),
        (Vec3::Y, Vec3::X, Vec3::NEG_Z),
        (Vec3::NEG_Y, Vec3::X, Vec3::Z),
        (Vec3::Z, Vec3::X, Vec3::Y),
        (Vec3::NEG_Z, Vec3::NEG_X, Vec3::Y),
    ];
    for (n, u, v) in faces {
        let base = positions.len() as u32;
        for (su, sv) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
            positions.push(n + su * u + sv * v);
            uv.push(Vec2::new(0.5 + 0.5 * su, 0.5 - 0.5 * sv));
        }
        indices.extend([[base, base + 1, base + 2], [base, base + 2, base + 3]]);
    }
    Mesh {
        name: "cube".into(),
        positions,
        indices,
        shading: VertexShading {
            normals: vec![],
            uv: [uv, vec![]],
            tangents: vec![],
        },
    }
}
