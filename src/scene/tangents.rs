//! Tangents for normal maps where a glTF file has none: glTF 2.0 (3.7.2.1) asks for
//! MikkTSpace, the tangent space Blender and the common bakers use, so a normal map baked
//! there reads the same here. MikkTSpace gives each triangle corner its own tangent (corners
//! that share a vertex may differ across a UV seam), so the mesh is unwelded: each corner
//! becomes a vertex of its own.
//!
//! MikkTSpace's bitangent points where its v grows; a glTF normal texel's +Y points up the
//! image (glTF 2.0, 3.9.3), where glTF's v shrinks (its origin is the top left). So the
//! texture coordinates go in as (u, 1 − v), as Blender's own (v up) do, and the bitangent
//! B = w · (N × T) points up the image, as glTF's TANGENT defines it.

use glam::{Vec2, Vec3, Vec4};

use super::{Mesh, VertexShading};

/// The mesh with one vertex per triangle corner and MikkTSpace tangents, or None when it
/// lacks what they are made from (normals and TEXCOORD_0) or MikkTSpace finds no usable
/// triangle.
pub fn with_generated_tangents(mesh: &Mesh) -> Option<Mesh> {
    let s = &mesh.shading;
    if s.normals.is_empty() || s.uv[0].is_empty() {
        return None;
    }
    let corners: Vec<usize> = mesh.indices.iter().flatten().map(|&i| i as usize).collect();
    // An absent attribute (an empty list) stays absent.
    let gather = |list: &[Vec2]| {
        corners
            .iter()
            .filter_map(|&i| list.get(i).copied())
            .collect()
    };
    let mut unwelded = Mesh {
        name: mesh.name.clone(),
        positions: corners.iter().map(|&i| mesh.positions[i]).collect(),
        indices: (0..mesh.indices.len() as u32)
            .map(|t| [3 * t, 3 * t + 1, 3 * t + 2])
            .collect(),
        shading: VertexShading {
            normals: corners.iter().map(|&i| s.normals[i]).collect(),
            uv: [gather(&s.uv[0]), gather(&s.uv[1])],
            tangents: vec![Vec4::ZERO; corners.len()],
        },
    };
    let mut geometry = Corners(&mut unwelded);
    mikktspace::generate_tangents(&mut geometry).then_some(unwelded)
}

/// An unwelded mesh as MikkTSpace sees it: face f's vertex v is vertex 3f + v.
struct Corners<'m>(&'m mut Mesh);

impl mikktspace::Geometry for Corners<'_> {
    fn num_faces(&self) -> usize {
        self.0.indices.len()
    }
    fn num_vertices_of_face(&self, _face: usize) -> usize {
        3
    }
    fn position(&self, face: usize, vert: usize) -> [f32; 3] {
        self.0.positions[3 * face + vert].to_array()
    }
    fn normal(&self, face: usize, vert: usize) -> [f32; 3] {
        self.0.shading.normals[3 * face + vert].to_array()
    }
    fn tex_coord(&self, face: usize, vert: usize) -> [f32; 2] {
        let uv = self.0.shading.uv[0][3 * face + vert];
        [uv.x, 1.0 - uv.y]
    }
    fn set_tangent_encoded(&mut self, tangent: [f32; 4], face: usize, vert: usize) {
        let t = Vec4::from(tangent);
        // A degenerate corner gets a zero tangent: its triangle is not normal-mapped.
        let unit = Vec3::from(tangent[..3].try_into().unwrap_or([0.0; 3])).try_normalize();
        self.0.shading.tangents[3 * face + vert] = match unit {
            Some(u) => u.extend(t.w.signum()),
            None => Vec4::ZERO,
        };
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_quad_mapped_along_x_gets_tangents_along_x_and_bitangents_up_the_image() {
        // u grows with x, glTF's v with -y (the image's top is at +y): the tangent is +x and
        // the bitangent w · (n × t), up the image, is +y.
        let mut quad = crate::scene::shapes::quad();
        quad.shading.tangents.clear(); // generated, not given
        let m = with_generated_tangents(&quad).unwrap();
        assert_eq!(m.positions.len(), 6);
        for t in &m.shading.tangents {
            assert!(t.truncate().abs_diff_eq(Vec3::X, 1e-5), "{t}");
            let bitangent = t.w * Vec3::Z.cross(t.truncate());
            assert!(
                bitangent.abs_diff_eq(Vec3::Y, 1e-5),
                "{t}: the image's up is +y"
            );
        }
    }
}
