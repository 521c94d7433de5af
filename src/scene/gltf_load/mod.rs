//! glTF 2.0 loading: `.gltf` (external `.bin` files or `data:` URIs) and `.glb`.
//!
//! What is read: triangle geometry (lists, strips and fans) with its shading normals, tangents
//! and two sets of texture coordinates, the node hierarchy of the default scene with its
//! transforms, metallic-roughness materials (as glTF's own BRDF,
//! [`crate::scene::MetallicRoughness`]) with their textures (`KHR_texture_transform`), alpha
//! modes, double-sidedness and emission (`KHR_materials_emissive_strength`), punctual lights
//! (`KHR_lights_punctual`) and the first perspective camera. Everything else (skins, morph
//! targets, animations, other extensions, points and lines, orthographic cameras) is ignored
//! with one warning per kind, not per occurrence.
//!
//! # Robustness
//!
//! No byte of the file is trusted. The `gltf` crate's accessor readers slice buffers unchecked
//! and its validator indexes arrays unchecked in a few places, so this module
//! - splits the GLB container itself with checked arithmetic,
//! - checks the known validator traps before validation runs (`document::precheck`),
//! - reads every accessor (dense and sparse) with checked offsets (`accessors::read_accessor`),
//! - walks the node graph iteratively and rejects cycles and shared children,
//! - bounds every vertex, instance and camera coordinate by [`MAX_COORDINATE`], so that
//!   framing, BVH bounds and ray arithmetic cannot overflow to ±∞ or NaN,
//! - checks file sizes before reading anything.

mod accessors;
mod document;
mod framing;
mod lights;
mod limits;
mod materials;
mod origin;
mod primitive;
mod sources;
mod textures;
mod walk;

use std::borrow::Cow;
use std::path::{Path, PathBuf};

use document::{note_ignored_features, parse_document};
use framing::frame_bounds;
use origin::{Origin, Warnings};
use sources::{load_buffers, read_file};
use walk::{walk, Walked};

pub use limits::{MAX_COORDINATE, MAX_FILE_BYTES};
pub use materials::default_material;

use super::{Environment, Mesh, Scene, SceneError};

/// Loads a `.gltf` or `.glb` file as a [`Scene`] (see the module docs for what is read).
///
/// Every primitive of the walked node tree becomes one object-space [`Mesh`] (shared by all
/// nodes that use the same glTF mesh, and by all primitives that read the same accessors in
/// the same mode, and by equal geometry) and one [`Instance`] per node. Triangles no ray can
/// hit (zero area, or a repeat with the same winding) are dropped with a warning. The camera is the first
/// perspective camera in depth-first node order, with the vertical field of view of the file
/// and the horizontal one from `aspect` (width / height); without one the scene's bounding
/// box is framed from +Z, slightly above, with a 40° vertical field of view. The environment
/// is [`Environment::sky`]; the scene is named after the file stem.
///
/// Mirrored instances (negative determinant) are returned as they are: their triangles'
/// winding is reversed in world space, as glTF prescribes for the renderer to handle.
pub fn load_gltf(path: &Path, aspect: f32) -> Result<Scene, SceneError> {
    let origin = Origin { path };
    check_aspect(aspect, &origin)?;
    let bytes = read_file(path).map_err(|problem| origin.load(problem))?;
    let base_dir = path.parent().unwrap_or_else(|| Path::new(""));
    scene_from_bytes(bytes.into(), &origin, Some(base_dir), aspect)
}

/// Loads a `.glb`, or a `.gltf` whose buffers are all embedded (`data:` URIs), held in memory:
/// the same parsing, validation and result as [`load_gltf`], with `what` standing for the path
/// (errors name it, the scene is named after its stem, and a name ending in `.glb` requires
/// the GLB container). Buffers in external files are an error, as there is no directory to
/// find them in.
pub fn load_gltf_bytes(bytes: &[u8], what: &str, aspect: f32) -> Result<Scene, SceneError> {
    let path = PathBuf::from(what);
    let origin = Origin { path: &path };
    check_aspect(aspect, &origin)?;
    check_size(bytes, &origin)?;
    scene_from_bytes(bytes.into(), &origin, None, aspect)
}

/// Parses a `.glb` held in memory (e.g. from `include_bytes!`) and merges all its triangles,
/// with node transforms applied, into one [`Mesh`] named `what`. Materials and cameras are
/// dropped; mirrored nodes get their winding flipped so front faces stay front faces. Only the
/// GLB binary chunk and `data:` URIs can be used as buffers. Errors name `what` as the path.
pub fn mesh_from_glb_bytes(bytes: &[u8], what: &str) -> Result<Mesh, SceneError> {
    let path = PathBuf::from(what);
    let origin = Origin { path: &path };
    check_size(bytes, &origin)?;
    let walked = walk_bytes(bytes.into(), &origin, true, None)?;

    let mut merged = Mesh {
        name: what.to_owned(),
        ..Mesh::default()
    };
    for instance in &walked.instances {
        let Some(mesh) = walked.meshes.get(instance.mesh as usize) else {
            continue;
        };
        let base = u32::try_from(merged.positions.len())
            .ok()
            .filter(|_| u32::try_from(merged.positions.len() + mesh.positions.len()).is_ok())
            .ok_or_else(|| origin.invalid("the merged mesh has more than 2³² vertices".into()))?;
        let mirrored = instance.transform.determinant() < 0.0;
        merged.positions.extend(
            mesh.positions
                .iter()
                .map(|&p| instance.transform.transform_point3(p)),
        );
        merged.indices.extend(mesh.indices.iter().map(|&[a, b, c]| {
            if mirrored {
                [base + a, base + c, base + b]
            } else {
                [base + a, base + b, base + c]
            }
        }));
    }
    if merged.indices.is_empty() {
        return Err(origin.invalid("the data contains no triangles".into()));
    }
    Ok(merged)
}

/// Refuses an aspect ratio that is not a positive number.
fn check_aspect(aspect: f32, origin: &Origin) -> Result<(), SceneError> {
    if aspect.is_finite() && aspect > 0.0 {
        Ok(())
    } else {
        Err(origin.invalid(format!(
            "the image aspect ratio {aspect} is not a positive number; give a width and height > 0"
        )))
    }
}

/// Refuses in-memory data over [`MAX_FILE_BYTES`], as [`read_file`] refuses such files.
fn check_size(bytes: &[u8], origin: &Origin) -> Result<(), SceneError> {
    if bytes.len() as u64 > MAX_FILE_BYTES {
        return Err(origin.load(format!(
            "the data is {} bytes; glTF data over 2 GiB is not supported (simplify the model)",
            bytes.len()
        )));
    }
    Ok(())
}

/// The one path from the bytes of a `.gltf`/`.glb` to a [`Scene`], shared by [`load_gltf`]
/// and [`load_gltf_bytes`]: parse, load buffers, walk, then pick or make up the camera.
fn scene_from_bytes(
    bytes: Cow<[u8]>,
    origin: &Origin,
    base_dir: Option<&Path>,
    aspect: f32,
) -> Result<Scene, SceneError> {
    let path = origin.path;
    let binary_by_name = path
        .extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("glb"));
    let walked = walk_bytes(bytes, origin, binary_by_name, base_dir)?;

    let triangles: usize = walked
        .instances
        .iter()
        .filter_map(|i| walked.meshes.get(i.mesh as usize))
        .map(|m| m.indices.len())
        .sum();
    let camera = match walked.camera {
        Some(node_camera) => node_camera.to_camera(aspect),
        None if triangles == 0 => {
            let skipped = if walked.skipped_primitives > 0 {
                format!(
                    " ({} point or line primitive(s) were skipped: only triangles are rendered)",
                    walked.skipped_primitives
                )
            } else {
                String::new()
            };
            return Err(origin.invalid(format!(
                "the scene contains no triangles and no camera{skipped}; \
                 export the meshes as triangles"
            )));
        }
        None => frame_bounds(&walked.meshes, &walked.instances, aspect),
    };
    tracing::info!(
        "{}: {} meshes, {} instances, {} triangles, {} materials",
        path.display(),
        walked.meshes.len(),
        walked.instances.len(),
        triangles,
        walked.materials.len()
    );
    Ok(Scene {
        name: path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "gltf".to_owned()),
        meshes: walked.meshes,
        instances: walked.instances,
        boxes: Vec::new(),
        spheres: Vec::new(),
        materials: walked.materials,
        textures: walked.textures,
        camera,
        environment: Environment::sky(),
        lights: walked.lights,
        environment_map: None,
        light_selection: Default::default(),
    })
}

/// Parses the document, loads its buffers (external files relative to `base_dir`; `None`
/// forbids them) and walks the node tree, reporting ignored features once per kind. The
/// file's bytes are released once parsed, before the buffers are loaded.
fn walk_bytes(
    bytes: Cow<[u8]>,
    origin: &Origin,
    binary_expected: bool,
    base_dir: Option<&Path>,
) -> Result<Walked, SceneError> {
    let parsed = parse_document(&bytes, origin, binary_expected)?;
    drop(bytes);
    let buffers = load_buffers(&parsed.document, parsed.blob, base_dir, origin)?;
    let mut warnings = Warnings::default();
    note_ignored_features(&parsed.document, &mut warnings);
    let walked = walk(&parsed.document, &buffers, base_dir, origin, &mut warnings)?;
    warnings.emit(origin);
    Ok(walked)
}
