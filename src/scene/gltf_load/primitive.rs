//! One glTF primitive as an object-space triangle mesh.

use std::collections::HashSet;

use glam::{Vec2, Vec3, Vec4};

use super::accessors::{component_f32, component_u32, read_accessor};
use super::limits::MAX_COORDINATE;
use super::origin::Warnings;
use crate::scene::{Mesh, VertexShading};

/// Builds the object-space mesh of one primitive, or `None` when it has no triangles (points
/// and lines are skipped with a warning). Only referenced vertices are kept (primitives often
/// share one big vertex array), and they must be finite.
pub(super) fn build_primitive(
    mesh: &gltf::Mesh,
    primitive: &gltf::Primitive,
    buffers: &[Vec<u8>],
    warnings: &mut Warnings,
) -> Result<Option<Mesh>, String> {
    let names = Names::of(mesh, primitive);
    if !is_triangles(primitive.mode()) {
        warnings.add("point and line primitives (only triangles are rendered)");
        return Ok(None);
    }
    let positions = read_positions(primitive, buffers, &names.label)?;
    let indices = read_indices(primitive, buffers, positions.len(), &names.label)?;
    let triangles = assemble_triangles(primitive.mode(), &indices, warnings);
    let Some(hittable) = hittable(&triangles, &positions, &names, warnings)? else {
        return Ok(None);
    };
    let shading = read_shading(primitive, buffers, positions.len(), &names.label, warnings)?;
    Ok(Some(Mesh {
        name: names.mesh_name_for(mesh, primitive),
        positions: gather(&positions, &hittable.vertices),
        indices: hittable.triangles,
        shading: VertexShading {
            normals: gather(&shading.normals, &hittable.vertices),
            uv: shading.uv.map(|uv| gather(&uv, &hittable.vertices)),
            tangents: gather(&shading.tangents, &hittable.vertices),
        },
    }))
}

/// How errors name a primitive: `mesh 'name' (#i)` and `…, primitive #j`.
struct Names {
    mesh: String,
    label: String,
    primitive: usize,
}

impl Names {
    fn of(mesh: &gltf::Mesh, primitive: &gltf::Primitive) -> Self {
        let mesh_name = match mesh.name() {
            Some(name) => format!("mesh '{name}' (#{})", mesh.index()),
            None => format!("mesh #{}", mesh.index()),
        };
        let label = format!("{mesh_name}, primitive #{}", primitive.index());
        Names {
            mesh: mesh_name,
            label,
            primitive: primitive.index(),
        }
    }

    /// The [`Mesh`]'s own name: the glTF mesh's, with `/primitive` when it has several.
    fn mesh_name_for(&self, mesh: &gltf::Mesh, primitive: &gltf::Primitive) -> String {
        match (mesh.name(), mesh.primitives().len()) {
            (Some(name), 1) => name.to_owned(),
            (Some(name), _) => format!("{name}/{}", primitive.index()),
            (None, 1) => format!("mesh{}", mesh.index()),
            (None, _) => format!("mesh{}/{}", mesh.index(), primitive.index()),
        }
    }
}

/// The POSITION attribute, a VEC3 of floats or (KHR_mesh_quantization) integers.
fn read_positions(
    primitive: &gltf::Primitive,
    buffers: &[Vec<u8>],
    label: &str,
) -> Result<Vec<Vec3>, String> {
    let accessor = primitive
        .get(&gltf::Semantic::Positions)
        .ok_or_else(|| format!("{label} has no POSITION attribute"))?;
    if accessor.dimensions() != gltf::accessor::Dimensions::Vec3 {
        return Err(format!(
            "{label}: POSITION is {:?}, not VEC3",
            accessor.dimensions()
        ));
    }
    let data_type = accessor.data_type();
    let normalized = accessor.normalized();
    let size = data_type.size();
    read_accessor(&accessor, buffers, Vec3::ZERO, |bytes| {
        let c =
            |k: usize| component_f32(data_type, normalized, bytes.get(k * size..(k + 1) * size)?);
        Some(Vec3::new(c(0)?, c(1)?, c(2)?))
    })
    .map_err(|p| format!("{label}: POSITION {p}"))
}

/// The index list (or `0..vertex_count` without one), every index checked to be in range.
fn read_indices(
    primitive: &gltf::Primitive,
    buffers: &[Vec<u8>],
    vertex_count: usize,
    label: &str,
) -> Result<Vec<u32>, String> {
    let vertex_count_u32 =
        u32::try_from(vertex_count).map_err(|_| format!("{label} has more than 2³² vertices"))?;
    let indices: Vec<u32> = match primitive.indices() {
        Some(accessor) => {
            let data_type = accessor.data_type();
            if accessor.dimensions() != gltf::accessor::Dimensions::Scalar
                || !matches!(
                    data_type,
                    gltf::accessor::DataType::U8
                        | gltf::accessor::DataType::U16
                        | gltf::accessor::DataType::U32
                )
            {
                return Err(format!(
                    "{label}: its indices are {:?} {:?}; glTF requires unsigned byte, short or \
                     int scalars",
                    accessor.dimensions(),
                    data_type
                ));
            }
            read_accessor(&accessor, buffers, 0u32, |bytes| {
                component_u32(data_type, bytes)
            })
            .map_err(|p| format!("{label}: indices {p}"))?
        }
        None => (0..vertex_count_u32).collect(),
    };
    if let Some((k, &i)) = indices
        .iter()
        .enumerate()
        .find(|(_, &i)| i >= vertex_count_u32)
    {
        return Err(format!(
            "{label}: index {i} (entry {k} of its index list) is out of range: the primitive has \
             {vertex_count} vertices; the file is corrupt, re-export it"
        ));
    }
    Ok(indices)
}

/// The triangles of a list, strip or fan (glTF 2.0 §3.7.2.1).
fn assemble_triangles(
    mode: gltf::mesh::Mode,
    indices: &[u32],
    warnings: &mut Warnings,
) -> Vec<[u32; 3]> {
    use gltf::mesh::Mode;
    match mode {
        Mode::TriangleStrip => (0..indices.len().saturating_sub(2))
            .filter_map(|i| {
                // Triangle i is (v_i, v_{i+1+i%2}, v_{i+2-i%2}).
                let tri = [
                    indices.get(i)?,
                    indices.get(i + 1 + i % 2)?,
                    indices.get(i + 2 - i % 2)?,
                ];
                Some([*tri[0], *tri[1], *tri[2]])
            })
            // Strips use repeated vertices to restart; those triangles have no area.
            .filter(|[a, b, c]| a != b && b != c && a != c)
            .collect(),
        Mode::TriangleFan => (0..indices.len().saturating_sub(2))
            .filter_map(|i| {
                Some([
                    *indices.get(i + 1)?,
                    *indices.get(i + 2)?,
                    *indices.first()?,
                ])
            })
            .filter(|[a, b, c]| a != b && b != c && a != c)
            .collect(),
        _ => {
            if !indices.len().is_multiple_of(3) {
                warnings.add("incomplete triangles at the end of index lists");
            }
            indices
                .chunks_exact(3)
                .map(|t| [t[0], t[1], t[2]])
                .collect()
        }
    }
}

/// The triangles a ray can hit, over the vertices they use (in first-use order), or `None`
/// when none is left. Every referenced vertex must be finite and in range. Zero-area triangles
/// (coincident or collinear corners) and repeats of a triangle with the same winding are
/// dropped: both are useless to render, and large numbers of identical primitives make BVH
/// construction quadratic (a file of a few kilobytes could stall it for hours).
fn hittable(
    triangles: &[[u32; 3]],
    positions: &[Vec3],
    names: &Names,
    warnings: &mut Warnings,
) -> Result<Option<Hittable>, String> {
    let mut remap = vec![u32::MAX; positions.len()];
    let mut kept = Vec::new();
    let mut compact = Vec::with_capacity(triangles.len());
    let mut seen: HashSet<[u32; 3]> = HashSet::with_capacity(triangles.len());
    for tri in triangles {
        let [a, b, c] = corners(tri, positions, names)?;
        if (b - a).cross(c - a) == Vec3::ZERO {
            warnings.add("zero-area triangles (no ray can hit them)");
            continue;
        }
        // The same triangle with the same winding, whichever corner comes first.
        let first = (0..3).min_by_key(|&k| tri[k]).unwrap_or(0);
        if !seen.insert([tri[first], tri[(first + 1) % 3], tri[(first + 2) % 3]]) {
            warnings.add("repeated triangles (each is kept once)");
            continue;
        }
        let mut out = [0u32; 3];
        for (slot, &v) in out.iter_mut().zip(tri) {
            let entry = remap
                .get_mut(v as usize)
                .ok_or_else(|| format!("{}: index {v} out of range", names.label))?;
            if *entry == u32::MAX {
                *entry = kept.len() as u32;
                kept.push(v);
            }
            *slot = *entry;
        }
        compact.push(out);
    }
    Ok((!compact.is_empty()).then_some(Hittable {
        vertices: kept,
        triangles: compact,
    }))
}

/// The triangles a ray can hit, renumbered to index `vertices`: the primitive's vertices they
/// use, in first-use order.
struct Hittable {
    vertices: Vec<u32>,
    triangles: Vec<[u32; 3]>,
}

/// `values` at `vertices` (empty stays empty: the attribute is absent).
fn gather<T: Copy>(values: &[T], vertices: &[u32]) -> Vec<T> {
    if values.is_empty() {
        return Vec::new();
    }
    vertices.iter().map(|&v| values[v as usize]).collect()
}

/// A triangle's corners, each checked to be finite and within [`MAX_COORDINATE`].
fn corners(tri: &[u32; 3], positions: &[Vec3], names: &Names) -> Result<[Vec3; 3], String> {
    let mut corners = [Vec3::ZERO; 3];
    for (corner, &v) in corners.iter_mut().zip(tri) {
        let p = *positions
            .get(v as usize)
            .ok_or_else(|| format!("{}: index {v} out of range", names.label))?;
        if !p.is_finite() {
            return Err(format!(
                "{}: vertex {v} of primitive #{} has a non-finite position \
                 {p} (NaN or ±∞); repair the mesh and re-export it",
                names.mesh, names.primitive
            ));
        }
        if p.abs().max_element() > MAX_COORDINATE {
            return Err(format!(
                "{}: vertex {v} of primitive #{} has a coordinate of {:e}, \
                 beyond ±{MAX_COORDINATE:e} (where f32 ray arithmetic overflows); the mesh \
                 is corrupt or its export scale is wrong",
                names.mesh,
                names.primitive,
                p.abs().max_element()
            ));
        }
        *corner = p;
    }
    Ok(corners)
}

/// The primitive's NORMAL, TEXCOORD_0, TEXCOORD_1 and TANGENT, each empty when absent. Normals are
/// normalised; one that is zero or not finite becomes the zero vector (its triangles are
/// shaded flat). A texture coordinate that is not finite is an error.
fn read_shading(
    primitive: &gltf::Primitive,
    buffers: &[Vec<u8>],
    vertex_count: usize,
    label: &str,
    warnings: &mut Warnings,
) -> Result<VertexShading, String> {
    let normals = read_floats::<3>(
        primitive,
        &gltf::Semantic::Normals,
        buffers,
        vertex_count,
        label,
        warnings,
    )?
    .into_iter()
    .map(|n| Vec3::from(n).try_normalize().unwrap_or(Vec3::ZERO))
    .collect();
    let mut uv = [Vec::new(), Vec::new()];
    for (set, list) in uv.iter_mut().enumerate() {
        let semantic = gltf::Semantic::TexCoords(set as u32);
        let values =
            read_floats::<2>(primitive, &semantic, buffers, vertex_count, label, warnings)?;
        if let Some(k) = values.iter().position(|c| !c.iter().all(|x| x.is_finite())) {
            return Err(format!(
                "{label}: TEXCOORD_{set} of vertex {k} is not finite (NaN or ±∞); repair the \
                 mesh's UVs and re-export it"
            ));
        }
        *list = values.into_iter().map(Vec2::from).collect();
    }
    // TANGENT: xyz a unit vector, w ±1 (the bitangent's sign). One that is not finite or
    // zero becomes the zero vector (its triangles are not normal-mapped).
    let tangents = read_floats::<4>(
        primitive,
        &gltf::Semantic::Tangents,
        buffers,
        vertex_count,
        label,
        warnings,
    )?
    .into_iter()
    .map(|t| match Vec3::new(t[0], t[1], t[2]).try_normalize() {
        Some(unit) if t[3].is_finite() => unit.extend(if t[3] < 0.0 { -1.0 } else { 1.0 }),
        _ => Vec4::ZERO,
    })
    .collect();
    Ok(VertexShading {
        normals,
        uv,
        tangents,
    })
}

/// An attribute of `N` components per vertex, as floats (normalised integers decoded as glTF
/// 2.0 §3.11 says); empty when the primitive has none. One of another shape is ignored with a
/// warning (the glTF validator rejects it); one whose count is not the vertex count is an error.
fn read_floats<const N: usize>(
    primitive: &gltf::Primitive,
    semantic: &gltf::Semantic,
    buffers: &[Vec<u8>],
    vertex_count: usize,
    label: &str,
    warnings: &mut Warnings,
) -> Result<Vec<[f32; N]>, String> {
    let Some(accessor) = primitive.get(semantic) else {
        return Ok(Vec::new());
    };
    let name = semantic.to_string();
    if accessor.dimensions().multiplicity() != N {
        warnings.add(format!(
            "{name} attributes that are not {N}-component vectors"
        ));
        return Ok(Vec::new());
    }
    if accessor.count() != vertex_count {
        return Err(format!(
            "{label}: {name} has {} entries but POSITION has {vertex_count}; glTF requires one \
             per vertex, re-export the file",
            accessor.count()
        ));
    }
    let data_type = accessor.data_type();
    let normalized = accessor.normalized();
    let size = data_type.size();
    read_accessor(&accessor, buffers, [0.0; N], |bytes| {
        let mut out = [0.0; N];
        for (k, c) in out.iter_mut().enumerate() {
            *c = component_f32(data_type, normalized, bytes.get(k * size..(k + 1) * size)?)?;
        }
        Some(out)
    })
    .map_err(|p| format!("{label}: {name} {p}"))
}

/// Whether the primitive is made of triangles (lists, strips or fans), not points or lines.
pub(super) fn is_triangles(mode: gltf::mesh::Mode) -> bool {
    use gltf::mesh::Mode;
    matches!(
        mode,
        Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan
    )
}
