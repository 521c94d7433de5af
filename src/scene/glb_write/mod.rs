//! Writing a [`Scene`] as a glTF 2.0 binary (`.glb`), the inverse of [`super::gltf_load`].
//!
//! Layout: one buffer (the GLB binary chunk); per [`Mesh`] used by an instance one POSITION
//! accessor (f32 VEC3 with min/max) and one u32 index accessor; per (mesh, material) pair one
//! glTF mesh (glTF puts materials on primitives, so a mesh placed with two materials becomes two
//! glTF meshes sharing the same accessors); per [`Instance`] one node with its column-major
//! matrix; one node with a perspective camera; one node per punctual light
//! (`KHR_lights_punctual`). All scene materials are written, in order.
//!
//! Not representable, hence not written: analytic boxes and spheres (a warning says how many),
//! the environment, and asymmetric camera frusta (the camera is written symmetric with the same
//! vertical extent and aspect ratio). Instance matrices with shear are written as they are;
//! this loader reads them, but strict glTF readers expect TRS-decomposable matrices (a warning
//! says so).
//!
//! # Materials and textures
//!
//! glTF materials are written as they are (factors, alpha, faces, texture slots with
//! `KHR_texture_transform` where not the identity); thesis materials as the nearest
//! metallic-roughness material ([`super::gltf_from_thesis`]). Emission is written as
//! `emissiveFactor`, with `KHR_materials_emissive_strength` carrying the maximum component
//! when it exceeds 1. Every texture becomes a PNG image in the binary chunk with a sampler and
//! a texture of its own, in order. Meshes keep their normals, tangents and texture coordinates.

use std::collections::HashMap;
use std::path::Path;

use glam::{Mat3, Quat, Vec3, Vec4};
use serde_json::{json, Value};

use super::{Camera, Scene, SceneError};
use materials::material_json;
use textures::write_textures;

mod lights;
mod materials;
mod textures;

const ARRAY_BUFFER: u32 = 34962;
const ELEMENT_ARRAY_BUFFER: u32 = 34963;
const FLOAT: u32 = 5126;
const UNSIGNED_INT: u32 = 5125;
/// Near plane written for the camera (glTF requires one; the path tracer has none).
const CAMERA_ZNEAR: f32 = 0.01;

/// Writes `scene` to `path` as a `.glb` (see the module docs for what is written).
/// A write failure is reported as [`SceneError::Load`] naming `path`.
pub fn write_glb(scene: &Scene, path: &Path) -> Result<(), SceneError> {
    let bytes = glb_bytes(scene)?;
    std::fs::write(path, bytes).map_err(|e| SceneError::Load {
        path: path.to_path_buf(),
        problem: format!("cannot write the .glb file: {e}"),
    })
}

/// The `.glb` bytes of `scene` (see the module docs for what is written). Fails on dangling
/// mesh/material references, out-of-range indices, non-finite values or a scene over 4 GiB.
pub fn glb_bytes(scene: &Scene) -> Result<Vec<u8>, SceneError> {
    let invalid = |problem: String| SceneError::Invalid {
        scene: scene.name.clone(),
        problem,
    };
    if !scene.boxes.is_empty() || !scene.spheres.is_empty() {
        tracing::warn!(
            "scene '{}': {} analytic boxes and {} spheres cannot be stored in glTF and are not \
             written",
            scene.name,
            scene.boxes.len(),
            scene.spheres.len()
        );
    }

    let mut bin: Vec<u8> = Vec::new();
    let mut views: Vec<Value> = Vec::new();
    let mut accessors: Vec<Value> = Vec::new();
    // Scene mesh → (its primitive's `attributes`, index accessor), written on first use.
    let mut mesh_accessors: HashMap<u32, (Value, usize)> = HashMap::new();
    // (scene mesh, material) → glTF mesh.
    let mut pair_ids: HashMap<(u32, u32), usize> = HashMap::new();
    let mut pairs: Vec<(u32, u32)> = Vec::new();
    let mut nodes: Vec<Value> = Vec::new();
    let mut sheared = 0usize;

    for (i, instance) in scene.instances.iter().enumerate() {
        let mesh = scene.meshes.get(instance.mesh as usize).ok_or_else(|| {
            invalid(format!(
                "instance {i} refers to mesh {}, which does not exist",
                instance.mesh
            ))
        })?;
        if instance.material as usize >= scene.materials.len() {
            return Err(invalid(format!(
                "instance {i} refers to material {}, which does not exist",
                instance.material
            )));
        }
        if !instance.transform.is_finite() {
            return Err(invalid(format!("instance {i} has a non-finite transform")));
        }
        if mesh.indices.is_empty() {
            continue; // glTF accessors cannot be empty, and there is nothing to place
        }
        if let std::collections::hash_map::Entry::Vacant(slot) = mesh_accessors.entry(instance.mesh)
        {
            let written = write_mesh_data(mesh, &mut bin, &mut views, &mut accessors)
                .map_err(|p| invalid(format!("mesh '{}': {p}", mesh.name)))?;
            slot.insert(written);
        }
        let key = (instance.mesh, instance.material);
        let gltf_mesh = *pair_ids.entry(key).or_insert_with(|| {
            pairs.push(key);
            pairs.len() - 1
        });
        if !is_trs_decomposable(&instance.transform) {
            sheared += 1;
        }
        nodes.push(json!({
            "name": format!("instance {i}"),
            "mesh": gltf_mesh,
            "matrix": instance.transform.to_cols_array().to_vec(),
        }));
    }
    if sheared > 0 {
        tracing::warn!(
            "scene '{}': {sheared} instance transforms have shear; they are written as matrices, \
             which strict glTF readers may reject",
            scene.name
        );
    }

    let meshes: Vec<Value> = pairs
        .iter()
        .map(|&(mesh, material)| {
            let (attributes, indices) = &mesh_accessors[&mesh];
            let name = &scene.meshes[mesh as usize].name;
            let uses = pairs.iter().filter(|(m, _)| *m == mesh).count();
            json!({
                "name": if uses > 1 { format!("{name} (material {material})") } else { name.clone() },
                "primitives": [{
                    "attributes": attributes,
                    "indices": indices,
                    "material": material,
                    "mode": 4,
                }],
            })
        })
        .collect();

    let mut extensions = std::collections::BTreeSet::new();
    let materials = scene
        .materials
        .iter()
        .enumerate()
        .map(|(i, m)| {
            let (value, used) =
                material_json(i, m).map_err(|p| invalid(format!("material {i}: {p}")))?;
            extensions.extend(used);
            Ok(value)
        })
        .collect::<Result<Vec<Value>, SceneError>>()?;
    let [images, samplers, textures] =
        write_textures(&scene.textures, &mut bin, &mut views).map_err(invalid)?;

    let (camera_node, camera) =
        camera_json(&scene.camera).map_err(|p| invalid(format!("camera: {p}")))?;
    nodes.push(camera_node);
    let (lights, light_nodes) = lights::lights_json(&scene.lights);
    nodes.extend(light_nodes);
    let node_ids: Vec<usize> = (0..nodes.len()).collect();

    let mut root = json!({
        "asset": { "version": "2.0", "generator": "fovea glb_write" },
        "scene": 0,
        "scenes": [{ "name": scene.name, "nodes": node_ids }],
        "nodes": nodes,
        "cameras": [camera],
    });
    let object = root
        .as_object_mut()
        .ok_or_else(|| invalid("internal: root is not an object".into()))?;
    // Arrays glTF forbids empty are left out (meshes and accessors, images, samplers and
    // textures, buffer views come and go together).
    let arrays = [
        ("materials", materials),
        ("meshes", meshes),
        ("accessors", accessors),
        ("images", images),
        ("samplers", samplers),
        ("textures", textures),
        ("bufferViews", views),
    ];
    for (key, array) in arrays.into_iter().filter(|(_, a)| !a.is_empty()) {
        object.insert(key.into(), Value::Array(array));
    }
    if !bin.is_empty() {
        object.insert("buffers".into(), json!([{ "byteLength": bin.len() }]));
    }
    if !lights.is_empty() {
        let lights = json!({ "KHR_lights_punctual": { "lights": lights } });
        object.insert("extensions".into(), lights);
        extensions.insert("KHR_lights_punctual");
    }
    if !extensions.is_empty() {
        object.insert("extensionsUsed".into(), json!(extensions));
    }

    let json_text = serde_json::to_vec(&root)
        .map_err(|e| invalid(format!("cannot encode the glTF JSON: {e}")))?;
    assemble_glb(json_text, bin)
        .ok_or_else(|| invalid("the scene is too large for a .glb (4 GiB)".into()))
}

/// Appends a mesh's positions, shading attributes (normals, texture coordinates) and indices
/// to the binary chunk with one buffer view and one accessor each; returns the primitive's
/// `attributes` object and its index accessor.
fn write_mesh_data(
    mesh: &super::Mesh,
    bin: &mut Vec<u8>,
    views: &mut Vec<Value>,
    accessors: &mut Vec<Value>,
) -> Result<(Value, usize), String> {
    let vertex_count = mesh.positions.len();
    if let Some((i, p)) = mesh
        .positions
        .iter()
        .enumerate()
        .find(|(_, p)| !p.is_finite())
    {
        return Err(format!("vertex {i} has a non-finite position {p}"));
    }
    if let Some((t, tri)) = mesh
        .indices
        .iter()
        .enumerate()
        .find(|(_, tri)| tri.iter().any(|&v| v as usize >= vertex_count))
    {
        return Err(format!(
            "triangle {t} {tri:?} refers to a vertex beyond its {vertex_count}"
        ));
    }
    let min = mesh
        .positions
        .iter()
        .fold(Vec3::splat(f32::INFINITY), |a, &p| a.min(p));
    let max = mesh
        .positions
        .iter()
        .fold(Vec3::splat(f32::NEG_INFINITY), |a, &p| a.max(p));

    // f32 and u32 data keep every view 4-byte aligned without padding.
    let start = bin.len();
    for p in &mesh.positions {
        for c in p.to_array() {
            bin.extend_from_slice(&c.to_le_bytes());
        }
    }
    views.push(json!({
        "buffer": 0, "byteOffset": start, "byteLength": bin.len() - start, "target": ARRAY_BUFFER,
    }));
    accessors.push(json!({
        "bufferView": views.len() - 1, "componentType": FLOAT, "count": vertex_count,
        "type": "VEC3", "min": min.to_array().to_vec(), "max": max.to_array().to_vec(),
    }));
    let mut attributes = json!({ "POSITION": accessors.len() - 1 });
    let shading = &mesh.shading;
    if !shading.normals.is_empty() {
        let floats = shading.normals.iter().flat_map(|n| n.to_array());
        let accessor = write_floats(floats, "VEC3", vertex_count, bin, views, accessors);
        attributes["NORMAL"] = json!(accessor);
    }
    if !shading.tangents.is_empty() {
        let floats = shading.tangents.iter().flat_map(|t| t.to_array());
        let accessor = write_floats(floats, "VEC4", vertex_count, bin, views, accessors);
        attributes["TANGENT"] = json!(accessor);
    }
    for (set, uv) in shading
        .uv
        .iter()
        .enumerate()
        .filter(|(_, uv)| !uv.is_empty())
    {
        let floats = uv.iter().flat_map(|c| c.to_array());
        let accessor = write_floats(floats, "VEC2", vertex_count, bin, views, accessors);
        attributes[format!("TEXCOORD_{set}")] = json!(accessor);
    }

    let start = bin.len();
    for v in mesh.indices.iter().flatten() {
        bin.extend_from_slice(&v.to_le_bytes());
    }
    views.push(json!({
        "buffer": 0, "byteOffset": start, "byteLength": bin.len() - start,
        "target": ELEMENT_ARRAY_BUFFER,
    }));
    accessors.push(json!({
        "bufferView": views.len() - 1, "componentType": UNSIGNED_INT,
        "count": mesh.indices.len() * 3, "type": "SCALAR",
    }));
    Ok((attributes, accessors.len() - 1))
}

/// Appends `count` vertices' float vectors of glTF `kind` as one buffer view and accessor;
/// returns the accessor's index.
fn write_floats(
    floats: impl Iterator<Item = f32>,
    kind: &str,
    count: usize,
    bin: &mut Vec<u8>,
    views: &mut Vec<Value>,
    accessors: &mut Vec<Value>,
) -> usize {
    let start = bin.len();
    for c in floats {
        bin.extend_from_slice(&c.to_le_bytes());
    }
    views.push(json!({
        "buffer": 0, "byteOffset": start, "byteLength": bin.len() - start, "target": ARRAY_BUFFER,
    }));
    accessors.push(json!({
        "bufferView": views.len() - 1, "componentType": FLOAT, "count": count, "type": kind,
    }));
    accessors.len() - 1
}

/// True when the upper 3×3 has orthogonal columns and the last row is (0, 0, 0, 1), i.e. the
/// matrix is translation · rotation · scale (possibly mirrored).
fn is_trs_decomposable(m: &glam::Mat4) -> bool {
    let (a, b, c) = (
        m.x_axis.truncate(),
        m.y_axis.truncate(),
        m.z_axis.truncate(),
    );
    let orthogonal = |u: Vec3, v: Vec3| u.dot(v).abs() <= 1e-5 * u.length() * v.length();
    m.row(3).abs_diff_eq(Vec4::W, 1e-6) && orthogonal(a, b) && orthogonal(b, c) && orthogonal(a, c)
}

/// The camera node (looking down its −Z, +Y up) and a symmetric perspective camera with the
/// same vertical extent and aspect ratio as `camera`'s (possibly asymmetric) frustum.
fn camera_json(camera: &Camera) -> Result<(Value, Value), String> {
    let (right, up, forward) = camera.basis();
    let (tan_up, tan_down) = (camera.angle_up.tan(), camera.angle_down.tan());
    let (tan_right, tan_left) = (camera.angle_right.tan(), camera.angle_left.tan());
    let yfov = 2.0 * (0.5 * (tan_up - tan_down)).atan();
    let aspect = (tan_right - tan_left) / (tan_up - tan_down);
    let rotation = Quat::from_mat3(&Mat3::from_cols(right, up, -forward)).normalize();
    let ok = camera.position.is_finite()
        && rotation.is_finite()
        && yfov.is_finite()
        && yfov > 0.0
        && aspect.is_finite()
        && aspect > 0.0;
    if !ok {
        return Err("its position, orientation or field of view is degenerate".into());
    }
    let node = json!({
        "name": "camera",
        "camera": 0,
        "translation": camera.position.to_array().to_vec(),
        "rotation": rotation.to_array().to_vec(),
    });
    let perspective = json!({
        "type": "perspective",
        "perspective": { "yfov": yfov, "aspectRatio": aspect, "znear": CAMERA_ZNEAR },
    });
    Ok((node, perspective))
}

/// The GLB container: 12-byte header, JSON chunk padded with spaces, BIN chunk padded with
/// zeros (omitted when empty). `None` when the total exceeds the format's 4 GiB limit.
fn assemble_glb(mut json_text: Vec<u8>, mut bin: Vec<u8>) -> Option<Vec<u8>> {
    while !json_text.len().is_multiple_of(4) {
        json_text.push(b' ');
    }
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
    let bin_chunk = if bin.is_empty() { 0 } else { 8 + bin.len() };
    let total = u32::try_from(12 + 8 + json_text.len() + bin_chunk).ok()?;
    let mut out = Vec::with_capacity(total as usize);
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&total.to_le_bytes());
    out.extend_from_slice(&u32::try_from(json_text.len()).ok()?.to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&json_text);
    if !bin.is_empty() {
        out.extend_from_slice(&u32::try_from(bin.len()).ok()?.to_le_bytes());
        out.extend_from_slice(b"BIN\0");
        out.extend_from_slice(&bin);
    }
    Some(out)
}
