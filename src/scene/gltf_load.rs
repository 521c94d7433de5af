//! glTF 2.0 loading: `.gltf` (external `.bin` files or `data:` URIs) and `.glb`.
//!
//! What is read: triangle geometry (lists, strips and fans), the node hierarchy of the default
//! scene with its transforms, metallic-roughness material *factors*, emission (with
//! `KHR_materials_emissive_strength`) and the first perspective camera. Everything else
//! (textures, skins, morph targets, animations, other extensions, points and lines,
//! orthographic cameras, transparency) is ignored with one warning per kind, not per occurrence.
//!
//! # Robustness
//!
//! No byte of the file is trusted. The `gltf` crate's accessor readers slice buffers unchecked
//! and its validator indexes arrays unchecked in a few places, so this module
//! - splits the GLB container itself with checked arithmetic,
//! - checks the known validator traps before validation runs ([`precheck`]),
//! - reads every accessor (dense and sparse) with checked offsets ([`read_accessor`]),
//! - walks the node graph iteratively and rejects cycles and shared children,
//! - bounds every vertex, instance and camera coordinate by [`MAX_COORDINATE`], so that
//!   framing, BVH bounds and ray arithmetic cannot overflow to ±∞ or NaN,
//! - checks file sizes before reading anything.
//!
//! # Material mapping (metallic-roughness → the thesis' Lambert + Phong BRDF)
//!
//! See [`material_from_metallic_roughness`]: `k_s = mix(0.04, base, metallic)` per channel,
//! `k_d = base · (1 − metallic) · (1 − 0.04)`, Phong `α = 2/r⁴ − 2` (Walter et al. 2007's
//! Beckmann/GGX ↔ Blinn-Phong equivalence with GGX `α = r²`), `r = max(roughness, 10⁻³)`,
//! clamped to `[0, 10⁶]`; roughness 0 on a full metal is a perfect mirror (`α = ∞`).
//! For `base ≤ 1`, `k_d + k_s = (1−m)(0.96·base + 0.04) + m·base ≤ 1` per channel, so the
//! mapping conserves energy by construction (it is still enforced against rounding).

use std::borrow::Cow;
use std::collections::{BTreeSet, HashMap, HashSet};
use std::path::{Path, PathBuf};

use glam::{Mat4, Quat, Vec3, Vec4};
use gltf::json;
use gltf::json::validation::Checked;

use super::{Camera, Environment, Instance, Material, Mesh, Scene, SceneError};

/// Largest file (glTF JSON, GLB or external buffer) the loader accepts, checked before reading.
pub const MAX_FILE_BYTES: u64 = 2 * 1024 * 1024 * 1024;
/// Normal-incidence Fresnel reflectance of dielectrics assumed by glTF's metallic-roughness model.
pub const DIELECTRIC_F0: f32 = 0.04;
/// Largest finite Phong exponent the mapping produces; sharper lobes are mirrors in practice.
pub const MAX_PHONG_ALPHA: f32 = 1e6;
/// Roughness floor of the α mapping (`2/r⁴` overflows the useful range below it).
const MIN_ROUGHNESS: f32 = 1e-3;
/// Largest coordinate magnitude accepted for vertices (object and world space) and cameras:
/// a terametre, far beyond any real scene, yet far enough below `f32::MAX` (~3.4·10³⁸) that
/// bounding boxes, their extents and the ray arithmetic (squared lengths, cross products, BVH
/// slab tests) stay finite.
pub const MAX_COORDINATE: f32 = 1e12;
/// An accessor without a buffer view is all zeros; refuse absurd counts rather than allocate them.
const MAX_VIEWLESS_COUNT: usize = 1 << 24;
/// Vertical field of view of the camera made up when the file has none.
const FRAMING_FOV_Y_DEG: f32 = 40.0;
/// Extensions whose content this loader reads.
const READ_EXTENSIONS: &[&str] = &["KHR_materials_emissive_strength", "KHR_mesh_quantization"];

/// The material given to primitives that have none: diffuse grey 0.8.
pub fn default_material() -> Material {
    Material::diffuse(Vec3::splat(0.8))
}

/// Phong exponent for a glTF (perceptual) roughness: `α = 2/r⁴ − 2` with `r = max(roughness,
/// 10⁻³)`, clamped to `[0, 10⁶]`. GGX uses `α_g = r²` and Walter et al. (2007) relate Beckmann
/// (≈ GGX) and Blinn-Phong lobes by `α_p = 2/α_g² − 2`.
pub fn phong_alpha_from_roughness(roughness: f32) -> f32 {
    let r = roughness.clamp(MIN_ROUGHNESS, 1.0);
    (2.0 / r.powi(4) - 2.0).clamp(0.0, MAX_PHONG_ALPHA)
}

/// The inverse of [`phong_alpha_from_roughness`] (`∞` → 0); exact up to rounding for
/// α ≤ [`MAX_PHONG_ALPHA`].
pub fn roughness_from_phong_alpha(alpha: f32) -> f32 {
    if alpha == f32::INFINITY {
        return 0.0;
    }
    (2.0 / (alpha.max(0.0) + 2.0)).powf(0.25).clamp(0.0, 1.0)
}

/// The loader's material mapping from glTF metallic-roughness factors to the thesis' BRDF:
/// `k_s = mix(0.04, base, metallic)`, `k_d = base·(1−metallic)·(1−0.04)`,
/// `α =` [`phong_alpha_from_roughness`]`(roughness)`, except roughness 0 with metallic 1, which
/// is a perfect mirror (`α = ∞`). Inputs are clamped to `[0, 1]` (NaN counts as 0);
/// `k_d + k_s ≤ 1` holds per channel. `emission` is passed through.
pub fn material_from_metallic_roughness(
    base_color: Vec3,
    metallic: f32,
    roughness: f32,
    emission: Vec3,
) -> Material {
    let unit = |x: f32| if x.is_nan() { 0.0 } else { x.clamp(0.0, 1.0) };
    let base = Vec3::new(unit(base_color.x), unit(base_color.y), unit(base_color.z));
    let metallic = unit(metallic);
    let roughness = unit(roughness);
    let ks = Vec3::splat(DIELECTRIC_F0).lerp(base, metallic);
    let kd = base * (1.0 - metallic) * (1.0 - DIELECTRIC_F0);
    // Holds analytically for base ≤ 1; guard the rounding so the BRDF never creates energy.
    let kd = kd.min((Vec3::ONE - ks).max(Vec3::ZERO));
    let alpha = if roughness == 0.0 && metallic == 1.0 {
        f32::INFINITY
    } else {
        phong_alpha_from_roughness(roughness)
    };
    Material {
        kd,
        ks,
        alpha,
        emission,
    }
}

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
        camera,
        environment: Environment::sky(),
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
    let walked = walk(&parsed.document, &buffers, origin, &mut warnings)?;
    warnings.emit(origin);
    Ok(walked)
}

/// Where the data came from; turns problems into errors that name it.
struct Origin<'a> {
    path: &'a Path,
}

impl Origin<'_> {
    /// A problem with the file itself (missing, unreadable, not glTF, truncated, missing buffers).
    fn load(&self, problem: String) -> SceneError {
        SceneError::Load {
            path: self.path.to_path_buf(),
            problem,
        }
    }
    /// A problem with the content (bad indices, NaN vertices, nothing to render).
    fn invalid(&self, problem: String) -> SceneError {
        SceneError::Invalid {
            scene: self.path.display().to_string(),
            problem,
        }
    }
}

/// Kinds of ignored features, reported once each at the end of a load.
#[derive(Default)]
struct Warnings(BTreeSet<String>);

impl Warnings {
    fn add(&mut self, kind: impl Into<String>) {
        self.0.insert(kind.into());
    }
    fn emit(&self, origin: &Origin) {
        for kind in &self.0 {
            tracing::warn!("{}: ignoring {kind}", origin.path.display());
        }
    }
}

/// Reads a whole file after checking that it exists, is a file and is at most 2 GiB.
/// The error is a sentence about the file, to be wrapped by the caller.
fn read_file(path: &Path) -> Result<Vec<u8>, String> {
    let meta = std::fs::metadata(path).map_err(|e| match e.kind() {
        std::io::ErrorKind::NotFound => "file not found: check the path".to_owned(),
        _ => format!("cannot read the file: {e}"),
    })?;
    if meta.is_dir() {
        return Err("it is a directory, not a .gltf or .glb file".to_owned());
    }
    if meta.len() > MAX_FILE_BYTES {
        return Err(format!(
            "the file is {:.1} GiB; files over 2 GiB are not supported (simplify the model)",
            meta.len() as f64 / (1u64 << 30) as f64
        ));
    }
    std::fs::read(path).map_err(|e| format!("cannot read the file: {e}"))
}

/// A validated glTF document and the GLB binary chunk, if any.
struct Parsed {
    document: gltf::Document,
    blob: Option<Vec<u8>>,
}

/// Parses glTF JSON or a GLB container and validates it. `binary_expected` makes a missing
/// `glTF` magic an error (a `.glb` that is something else); otherwise content decides.
fn parse_document(
    bytes: &[u8],
    origin: &Origin,
    binary_expected: bool,
) -> Result<Parsed, SceneError> {
    let (json_bytes, blob) = if bytes.starts_with(b"glTF") {
        let (json_bytes, bin) = split_glb(bytes).map_err(|p| origin.load(p))?;
        (json_bytes, bin.map(<[u8]>::to_vec))
    } else if binary_expected {
        return Err(origin.load(
            "not a binary glTF (.glb) file: it does not start with the 'glTF' magic bytes \
             (is it truncated, or another format renamed to .glb?)"
                .to_owned(),
        ));
    } else {
        (bytes, None)
    };
    let mut root: json::Root = json::deserialize::from_slice(json_bytes)
        .map_err(|e| origin.load(describe_json_error(json_bytes, &e)))?;
    precheck(&mut root).map_err(|p| origin.invalid(p))?;
    let document = gltf::Document::from_json(root).map_err(|e| match e {
        gltf::Error::Validation(errors) => {
            let list: Vec<String> = errors
                .iter()
                .take(5)
                .map(|(path, error)| format!("{path}: {error}"))
                .collect();
            let more = errors.len().saturating_sub(5);
            let more = if more > 0 {
                format!(" (and {more} more)")
            } else {
                String::new()
            };
            origin.invalid(format!(
                "the glTF document is invalid: {}{more}; check it with the Khronos glTF validator",
                list.join("; ")
            ))
        }
        other => origin.load(format!("not a valid glTF document: {other}")),
    })?;
    Ok(Parsed { document, blob })
}

/// Explains a JSON deserialisation failure: malformed JSON, a glTF 1.0 file, or JSON that is
/// not a glTF 2.0 document.
fn describe_json_error(json_bytes: &[u8], e: &json::Error) -> String {
    match serde_json_category(e) {
        Category::Syntax | Category::Eof => format!(
            "not glTF: malformed JSON ({e}); the file is damaged or not a glTF file \
             (re-export it as glTF 2.0)"
        ),
        Category::Data => {
            // A glTF 1.0 file is valid JSON with a different schema: say so rather than
            // reporting the first field that does not fit the 2.0 schema.
            let version = json::deserialize::from_slice::<json::Value>(json_bytes)
                .ok()
                .and_then(|v| v.get("asset")?.get("version")?.as_str().map(str::to_owned));
            match version {
                Some(v) if !v.starts_with('2') => format!(
                    "glTF version {v} is not supported, only 2.0; convert the file to glTF 2.0"
                ),
                _ => format!("the JSON is not a glTF 2.0 document ({e}); re-export it"),
            }
        }
        Category::Io => format!("cannot read the JSON: {e}"),
    }
}

/// serde_json's error category, via the re-exported error type (no direct serde_json use).
enum Category {
    Io,
    Syntax,
    Data,
    Eof,
}

fn serde_json_category(e: &json::Error) -> Category {
    if e.is_io() {
        Category::Io
    } else if e.is_syntax() {
        Category::Syntax
    } else if e.is_eof() {
        Category::Eof
    } else {
        Category::Data
    }
}

/// Splits a GLB container into its JSON chunk and optional BIN chunk, with checked arithmetic
/// (the `gltf` crate's GLB reader underflows on a header length below 12).
fn split_glb(bytes: &[u8]) -> Result<(&[u8], Option<&[u8]>), String> {
    const JSON: u32 = 0x4E4F_534A;
    const BIN: u32 = 0x004E_4942;
    let word = |at: usize| -> Option<u32> {
        let b = bytes.get(at..at.checked_add(4)?)?;
        Some(u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    };
    let truncated = |what: &str| {
        format!(
            "truncated GLB file: it ends inside {what} ({} bytes in the file); \
             the file was cut short (incomplete download or copy?)",
            bytes.len()
        )
    };
    let version = word(4).ok_or_else(|| truncated("the header"))?;
    let declared = word(8).ok_or_else(|| truncated("the header"))? as usize;
    if version != 2 {
        return Err(format!(
            "GLB version {version} is not supported, only 2 (glTF 2.0)"
        ));
    }
    if declared > bytes.len() {
        return Err(format!(
            "truncated GLB file: its header declares {declared} bytes but the file has only {}; \
             the file was cut short (incomplete download or copy?)",
            bytes.len()
        ));
    }
    if declared < 20 {
        return Err(format!(
            "corrupt GLB file: its header declares a length of {declared} bytes"
        ));
    }
    let mut at = 12usize;
    let mut json_chunk = None;
    let mut bin_chunk = None;
    while at < declared {
        let length = word(at).ok_or_else(|| truncated("a chunk header"))? as usize;
        let kind = word(at + 4).ok_or_else(|| truncated("a chunk header"))?;
        let start = at + 8;
        let end = start
            .checked_add(length)
            .filter(|&end| end <= declared)
            .ok_or_else(|| truncated("a chunk"))?;
        let data = bytes.get(start..end).ok_or_else(|| truncated("a chunk"))?;
        match kind {
            JSON if json_chunk.is_none() && at == 12 => json_chunk = Some(data),
            BIN if bin_chunk.is_none() && json_chunk.is_some() => bin_chunk = Some(data),
            // Unknown chunk types must be ignored (glTF 2.0 §4.4.3.3).
            _ if at > 12 => {}
            _ => return Err("corrupt GLB file: the first chunk is not the JSON chunk".to_owned()),
        }
        // Chunks are 4-byte aligned; tolerate writers that forgot the padding of the last one.
        at = end.checked_add(3).map_or(usize::MAX, |e| e & !3);
    }
    let json_chunk = json_chunk.ok_or_else(|| truncated("the header"))?;
    Ok((json_chunk, bin_chunk))
}

/// Checks what the `gltf` 1.4 validator would panic on, and handles required extensions:
/// those this loader reads or may safely ignore are removed from `extensionsRequired` (the
/// validator rejects every required extension it does not know), the others are an error.
fn precheck(root: &mut json::Root) -> Result<(), String> {
    // The validator's primitive hook indexes `accessors[POSITION]` before bounds are checked.
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, primitive) in mesh.primitives.iter().enumerate() {
            let key = Checked::Valid(json::mesh::Semantic::Positions);
            if let Some(index) = primitive.attributes.get(&key) {
                if index.value() >= root.accessors.len() {
                    return Err(format!(
                        "mesh #{m} primitive #{p}: POSITION refers to accessor #{}, but the file \
                         has only {} accessors; re-export the file",
                        index.value(),
                        root.accessors.len()
                    ));
                }
            }
        }
    }
    let ignorable = |name: &str| {
        READ_EXTENSIONS.contains(&name)
            || name.starts_with("KHR_materials_")
            || matches!(
                name,
                "KHR_texture_transform"
                    | "KHR_texture_basisu"
                    | "EXT_texture_webp"
                    | "MSFT_texture_dds"
            )
    };
    if let Some(name) = root.extensions_required.iter().find(|n| !ignorable(n)) {
        return Err(format!(
            "the file requires the extension {name}, which fovea cannot read; \
             re-export without it (e.g. `gltf-transform copy` decompresses Draco/meshopt)"
        ));
    }
    root.extensions_required.clear();
    Ok(())
}

/// Loads every buffer: the GLB binary chunk, `data:` URIs, or files relative to `base_dir`
/// (`None`: external files are not allowed, e.g. for in-memory data).
fn load_buffers(
    document: &gltf::Document,
    mut blob: Option<Vec<u8>>,
    base_dir: Option<&Path>,
    origin: &Origin,
) -> Result<Vec<Vec<u8>>, SceneError> {
    let mut buffers = Vec::new();
    for buffer in document.buffers() {
        let i = buffer.index();
        let data = match buffer.source() {
            gltf::buffer::Source::Bin => blob.take().ok_or_else(|| {
                origin.load(format!(
                    "buffer #{i} refers to the GLB binary chunk, but the file has none \
                     (truncated or corrupt file)"
                ))
            })?,
            gltf::buffer::Source::Uri(uri) if uri.starts_with("data:") => decode_data_uri(uri)
                .map_err(|e| {
                    origin.load(format!(
                        "buffer #{i}: its data: URI cannot be decoded ({e}); \
                         it must be base64 (data:application/octet-stream;base64,...)"
                    ))
                })?,
            gltf::buffer::Source::Uri(uri) => {
                let file = external_path(uri, base_dir)
                    .map_err(|p| origin.load(format!("buffer #{i} ('{}'): {p}", short(uri))))?;
                read_file(&file).map_err(|p| {
                    origin.load(format!(
                        "external buffer '{}' (buffer #{i}) at '{}': {p}; keep the .bin files \
                         next to the .gltf, or use a .glb",
                        short(uri),
                        file.display()
                    ))
                })?
            }
        };
        if data.len() < buffer.length() {
            return Err(origin.load(format!(
                "buffer #{i} has {} bytes but the file declares {}: the data is truncated",
                data.len(),
                buffer.length()
            )));
        }
        buffers.push(data);
    }
    Ok(buffers)
}

/// Shortens a URI for messages (a huge `data:` URI must not flood the log).
fn short(uri: &str) -> String {
    match uri.char_indices().nth(60) {
        Some((cut, _)) => format!("{}…", &uri[..cut]),
        None => uri.to_owned(),
    }
}

/// Resolves a buffer URI that is not a `data:` URI to a file path.
fn external_path(uri: &str, base_dir: Option<&Path>) -> Result<PathBuf, String> {
    let Some(base_dir) = base_dir else {
        return Err(
            "the buffer is an external file, which cannot be found for glTF data loaded from \
             memory (there is no directory to look in); embed the buffers as data: URIs or \
             use a .glb"
                .into(),
        );
    };
    let has_scheme = uri.split_once(':').is_some_and(|(scheme, _)| {
        scheme.len() > 1
            && scheme
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || "+-.".contains(c))
    });
    let (relative, text) = if let Some(rest) = uri.strip_prefix("file://") {
        (false, rest)
    } else if let Some(rest) = uri.strip_prefix("file:") {
        (false, rest)
    } else if has_scheme {
        return Err(
            "only local files and data: URIs are supported; download the file \
                    next to the .gltf and refer to it by a relative path"
                .into(),
        );
    } else {
        (true, uri)
    };
    let decoded = percent_decode(text).ok_or("the URI is not valid UTF-8 after %-decoding")?;
    Ok(if relative {
        base_dir.join(decoded)
    } else {
        PathBuf::from(decoded)
    })
}

/// Decodes `%XX` escapes of a URI (invalid escapes are kept literally).
fn percent_decode(text: &str) -> Option<String> {
    let bytes = text.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while let Some(&b) = bytes.get(i) {
        if b == b'%' {
            let hex = bytes
                .get(i + 1..i + 3)
                .filter(|h| h.iter().all(u8::is_ascii_hexdigit));
            if let Some(value) = hex
                .and_then(|h| std::str::from_utf8(h).ok())
                .and_then(|h| u8::from_str_radix(h, 16).ok())
            {
                out.push(value);
                i += 3;
                continue;
            }
        }
        out.push(b);
        i += 1;
    }
    String::from_utf8(out).ok()
}

/// Records the kinds of ignored content that can be seen at the document level.
fn note_ignored_features(document: &gltf::Document, warnings: &mut Warnings) {
    if document.textures().len() > 0 || document.images().len() > 0 {
        warnings.add("textures (only base colour and emissive factors are used)");
    }
    if document.skins().len() > 0 {
        warnings.add("skins (meshes are used in their bind pose)");
    }
    if document.animations().len() > 0 {
        warnings.add("animations (the scene is loaded at rest)");
    }
    let morphs = document
        .meshes()
        .any(|m| m.primitives().any(|p| p.morph_targets().len() > 0));
    if morphs {
        warnings.add("morph targets (the base shapes are used)");
    }
    for name in document.extensions_used() {
        if !READ_EXTENSIONS.contains(&name) {
            warnings.add(format!("the extension {name} (not supported)"));
        }
    }
}

/// The result of walking the node tree.
struct Walked {
    meshes: Vec<Mesh>,
    instances: Vec<Instance>,
    materials: Vec<Material>,
    camera: Option<NodeCamera>,
    /// Distinct primitives skipped because they are points or lines.
    skipped_primitives: usize,
}

/// A perspective camera and the world transform of its node.
#[derive(Clone, Copy)]
struct NodeCamera {
    position: Vec3,
    forward: Vec3,
    up: Vec3,
    yfov: f32,
}

impl NodeCamera {
    fn to_camera(self, aspect: f32) -> Camera {
        let half_y = (0.5 * self.yfov).tan();
        let half_x = (half_y * aspect).atan();
        let half_y = half_y.atan();
        Camera {
            position: self.position,
            forward: self.forward,
            up: self.up,
            angle_left: -half_x,
            angle_right: half_x,
            angle_up: half_y,
            angle_down: -half_y,
        }
    }
}

/// Walks the default scene (or the first; or, with no scenes, every root node) depth first,
/// composing transforms, building deduplicated meshes, materials and instances.
fn walk(
    document: &gltf::Document,
    buffers: &[Vec<u8>],
    origin: &Origin,
    warnings: &mut Warnings,
) -> Result<Walked, SceneError> {
    let node_count = document.nodes().len();
    let roots: Vec<gltf::Node> = match document
        .default_scene()
        .or_else(|| document.scenes().next())
    {
        Some(scene) => scene.nodes().collect(),
        None => {
            let mut is_child = vec![false; node_count];
            for node in document.nodes() {
                for child in node.children() {
                    if let Some(flag) = is_child.get_mut(child.index()) {
                        *flag = true;
                    }
                }
            }
            document
                .nodes()
                .filter(|n| !is_child.get(n.index()).copied().unwrap_or(true))
                .collect()
        }
    };

    let mut walked = Walked {
        meshes: Vec::new(),
        instances: Vec::new(),
        materials: Vec::new(),
        camera: None,
        skipped_primitives: 0,
    };
    // (POSITION accessor, indices accessor, mode) → Mesh index, or None when the primitive has
    // no triangles.
    let mut mesh_ids: HashMap<(Option<usize>, Option<usize>, u32), Option<u32>> = HashMap::new();
    // glTF material index (None: the default material) → Scene material index.
    let mut material_ids: HashMap<Option<usize>, u32> = HashMap::new();
    let mut meshes_by_content = MeshDedup::default();
    let mut materials_by_value: HashMap<([[u32; 3]; 3], u32), u32> = HashMap::new();
    let mut visited = vec![false; node_count];
    let mut stack: Vec<(gltf::Node, Mat4)> = roots
        .into_iter()
        .rev()
        .map(|n| (n, Mat4::IDENTITY))
        .collect();

    while let Some((node, parent)) = stack.pop() {
        let label = node_label(&node);
        match visited.get_mut(node.index()) {
            Some(seen) if !*seen => *seen = true,
            _ => {
                return Err(origin.invalid(format!(
                    "{label} is reached twice: the node hierarchy has a cycle or a node with \
                     two parents, which glTF forbids; re-export the file"
                )))
            }
        }
        let world =
            parent * local_transform(&node).map_err(|p| origin.invalid(format!("{label}: {p}")))?;
        if !world.is_finite() {
            return Err(origin.invalid(format!(
                "{label}: its world transform is not finite (NaN or ±∞); fix the node transforms"
            )));
        }

        if let Some(camera) = node.camera() {
            let json_camera = document.as_json().cameras.get(camera.index());
            match json_camera.map(|c| (&c.type_, c.perspective.as_ref())) {
                Some((Checked::Valid(json::camera::Type::Perspective), Some(p))) => {
                    if walked.camera.is_none() {
                        walked.camera = Some(node_camera(world, p.yfov).map_err(|p| {
                            origin.invalid(format!("{label}, camera #{}: {p}", camera.index()))
                        })?);
                    }
                }
                Some((Checked::Valid(json::camera::Type::Orthographic), _)) => {
                    warnings.add("orthographic cameras (only perspective cameras are used)")
                }
                _ => {
                    return Err(origin.invalid(format!(
                        "camera #{} has no data for its projection type; re-export the file",
                        camera.index()
                    )))
                }
            }
        }

        if let Some(mesh) = node.mesh() {
            for primitive in mesh.primitives() {
                // Primitives that read the same accessors in the same mode are one mesh.
                let key = (
                    primitive.get(&gltf::Semantic::Positions).map(|a| a.index()),
                    primitive.indices().map(|a| a.index()),
                    primitive.mode().as_gl_enum(),
                );
                let mesh_id = match mesh_ids.get(&key) {
                    Some(&id) => id,
                    None => {
                        let built = build_primitive(&mesh, &primitive, buffers, warnings)
                            .map_err(|p| origin.invalid(p))?;
                        let id = match built {
                            Some(m) => Some(meshes_by_content.add(m, &mut walked.meshes)),
                            None => {
                                if !is_triangles(primitive.mode()) {
                                    walked.skipped_primitives += 1;
                                }
                                None
                            }
                        };
                        mesh_ids.insert(key, id);
                        id
                    }
                };
                let Some(mesh_id) = mesh_id else { continue };
                let reach = world_reach(meshes_by_content.reach(mesh_id), world);
                if !reach.is_finite() || reach.max_element() > MAX_COORDINATE {
                    return Err(origin.invalid(format!(
                        "{label}: it places mesh #{} where its vertices reach coordinates up to \
                         {:e}, beyond ±{MAX_COORDINATE:e} (where f32 ray arithmetic \
                         overflows); the node transforms or the export scale are wrong",
                        mesh.index(),
                        reach.max_element()
                    )));
                }
                let gltf_material = primitive.material();
                let material_id = match material_ids.get(&gltf_material.index()) {
                    Some(&id) => id,
                    None => {
                        let material = match gltf_material.index() {
                            Some(_) => convert_material(&gltf_material, warnings)
                                .map_err(|p| origin.invalid(p))?,
                            None => default_material(),
                        };
                        // Materials with equal values are one material.
                        let bits = [
                            material.kd.to_array(),
                            material.ks.to_array(),
                            material.emission.to_array(),
                        ]
                        .map(|v| v.map(f32::to_bits));
                        let id = *materials_by_value
                            .entry((bits, material.alpha.to_bits()))
                            .or_insert_with(|| {
                                walked.materials.push(material);
                                (walked.materials.len() - 1) as u32
                            });
                        material_ids.insert(gltf_material.index(), id);
                        id
                    }
                };
                walked.instances.push(Instance {
                    mesh: mesh_id,
                    material: material_id,
                    transform: world,
                });
            }
        }

        let children: Vec<gltf::Node> = node.children().collect();
        stack.extend(children.into_iter().rev().map(|c| (c, world)));
    }
    Ok(walked)
}

fn node_label(node: &gltf::Node) -> String {
    match node.name() {
        Some(name) => format!("node '{name}' (#{})", node.index()),
        None => format!("node #{}", node.index()),
    }
}

fn is_triangles(mode: gltf::mesh::Mode) -> bool {
    use gltf::mesh::Mode;
    matches!(
        mode,
        Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan
    )
}

/// The node's local transform (matrix or TRS). A matrix must be affine (glTF requires it to be
/// decomposable into TRS); a rotation quaternion is normalised (exporters round it).
fn local_transform(node: &gltf::Node) -> Result<Mat4, String> {
    match node.transform() {
        gltf::scene::Transform::Matrix { matrix } => {
            let m = Mat4::from_cols_array_2d(&matrix);
            if !m.is_finite() {
                return Err("its matrix is not finite (NaN or ±∞)".into());
            }
            if !m.row(3).abs_diff_eq(Vec4::W, 1e-6) {
                return Err(
                    "its matrix is projective (last row is not 0 0 0 1); glTF node \
                            matrices must be affine"
                        .into(),
                );
            }
            Ok(m)
        }
        gltf::scene::Transform::Decomposed {
            translation,
            rotation,
            scale,
        } => {
            let (t, r, s) = (
                Vec3::from(translation),
                Quat::from_array(rotation),
                Vec3::from(scale),
            );
            if !(t.is_finite() && r.is_finite() && s.is_finite()) {
                return Err("its translation, rotation or scale is not finite (NaN or ±∞)".into());
            }
            let length = r.length();
            if length < 1e-6 {
                return Err("its rotation quaternion has zero length".into());
            }
            Ok(Mat4::from_scale_rotation_translation(s, r / length, t))
        }
    }
}

/// Adds meshes to a scene's list, reusing an equal mesh (same positions and triangles) when
/// there is one, so identical geometry is stored and BVH-built once. Also keeps each mesh's
/// reach (the largest magnitude per axis of its vertices, object space) for [`world_reach`].
#[derive(Default)]
struct MeshDedup {
    /// Hash of positions and triangles → indices of the meshes with that hash.
    by_hash: HashMap<u64, Vec<u32>>,
    reaches: Vec<Vec3>,
}

impl MeshDedup {
    fn add(&mut self, mesh: Mesh, meshes: &mut Vec<Mesh>) -> u32 {
        use std::hash::{Hash, Hasher};
        let mut hasher = std::collections::hash_map::DefaultHasher::new();
        for p in &mesh.positions {
            p.to_array().map(f32::to_bits).hash(&mut hasher);
        }
        mesh.indices.hash(&mut hasher);
        let same = self.by_hash.entry(hasher.finish()).or_default();
        if let Some(&id) = same.iter().find(|&&id| {
            meshes
                .get(id as usize)
                .is_some_and(|m| m.positions == mesh.positions && m.indices == mesh.indices)
        }) {
            return id;
        }
        let id = meshes.len() as u32;
        same.push(id);
        self.reaches.push(
            mesh.positions
                .iter()
                .fold(Vec3::ZERO, |r, p| r.max(p.abs())),
        );
        meshes.push(mesh);
        id
    }

    fn reach(&self, id: u32) -> Vec3 {
        self.reaches.get(id as usize).copied().unwrap_or(Vec3::ZERO)
    }
}

/// An upper bound, per world axis, of `|world · p|` over vertices whose per-axis magnitudes
/// are at most `r` ([`MeshDedup::reach`]): interval arithmetic, so it costs nothing per instance
/// vertex, and it is finite only if every transformed vertex is.
fn world_reach(r: Vec3, world: Mat4) -> Vec3 {
    let axis = |v: Vec4| v.truncate().abs();
    axis(world.x_axis) * r.x
        + axis(world.y_axis) * r.y
        + axis(world.z_axis) * r.z
        + axis(world.w_axis)
}

/// A camera at the node's world transform looking down its −Z with +Y up.
fn node_camera(world: Mat4, yfov: f32) -> Result<NodeCamera, String> {
    if !(yfov.is_finite() && yfov > 0.0 && yfov < std::f32::consts::PI) {
        return Err(format!(
            "its vertical field of view {yfov} rad is not in (0, π)"
        ));
    }
    let position = world.transform_point3(Vec3::ZERO);
    if !position.is_finite() || position.abs().max_element() > MAX_COORDINATE {
        return Err(format!(
            "it is at a coordinate of {:e}, beyond ±{MAX_COORDINATE:e} (where f32 ray \
             arithmetic overflows); fix the node transforms",
            position.abs().max_element()
        ));
    }
    let forward = world.transform_vector3(Vec3::NEG_Z).normalize_or_zero();
    let up = world.transform_vector3(Vec3::Y);
    // Non-uniform scale or shear can tilt +Y off the image plane: re-orthogonalise.
    let up = (up - forward * up.dot(forward)).normalize_or_zero();
    if forward == Vec3::ZERO || up == Vec3::ZERO {
        return Err("its node transform is degenerate (zero scale)".into());
    }
    Ok(NodeCamera {
        position,
        forward,
        up,
        yfov,
    })
}

/// Frames the world bounding box of all instances: from +Z, slightly above, 40° vertical field
/// of view, far enough back that the bounding sphere fits both fields of view.
fn frame_bounds(meshes: &[Mesh], instances: &[Instance], aspect: f32) -> Camera {
    let mut min = Vec3::splat(f32::INFINITY);
    let mut max = Vec3::splat(f32::NEG_INFINITY);
    for instance in instances {
        let Some(mesh) = meshes.get(instance.mesh as usize) else {
            continue;
        };
        for &p in &mesh.positions {
            let w = instance.transform.transform_point3(p);
            min = min.min(w);
            max = max.max(w);
        }
    }
    let (centre, radius) = if min.cmple(max).all() {
        (0.5 * (min + max), (0.5 * (max - min).length()).max(1e-3))
    } else {
        (Vec3::ZERO, 1.0)
    };
    let half_y = (0.5 * FRAMING_FOV_Y_DEG).to_radians();
    let half_x = (half_y.tan() * aspect).atan();
    let distance = 1.05 * radius / half_y.min(half_x).sin();
    let direction = Vec3::new(0.0, 0.35, 1.0).normalize();
    Camera::look_at(
        centre + direction * distance,
        centre,
        Vec3::Y,
        FRAMING_FOV_Y_DEG,
        aspect,
    )
}

/// Converts a glTF material's factors with [`material_from_metallic_roughness`].
fn convert_material(
    material: &gltf::Material,
    warnings: &mut Warnings,
) -> Result<Material, String> {
    let label = match (material.name(), material.index()) {
        (Some(name), Some(i)) => format!("material '{name}' (#{i})"),
        (_, i) => format!("material #{}", i.unwrap_or(0)),
    };
    let pbr = material.pbr_metallic_roughness();
    let [r, g, b, a] = pbr.base_color_factor();
    let metallic = pbr.metallic_factor();
    let roughness = pbr.roughness_factor();
    let strength = material.emissive_strength().unwrap_or(1.0);
    let emissive = Vec3::from(material.emissive_factor());
    let values = [r, g, b, a, metallic, roughness, strength];
    if !values
        .iter()
        .chain(emissive.as_ref())
        .all(|x| x.is_finite() && *x >= 0.0)
    {
        return Err(format!(
            "{label} has a negative or non-finite factor (NaN or ±∞); fix the material"
        ));
    }
    if a < 1.0 && material.alpha_mode() != gltf::material::AlphaMode::Opaque {
        warnings.add("transparency (alpha; materials are opaque)");
    }
    let emission = emissive * strength;
    if !emission.is_finite() {
        return Err(format!(
            "{label}: its emission (emissiveFactor up to {:e} × emissiveStrength {strength:e}) \
             overflows to infinity; use a finite light intensity",
            emissive.max_element()
        ));
    }
    Ok(material_from_metallic_roughness(
        Vec3::new(r, g, b),
        metallic,
        roughness,
        emission,
    ))
}

/// Builds the object-space mesh of one primitive, or `None` when it has no triangles (points
/// and lines are skipped with a warning). Only referenced vertices are kept (primitives often
/// share one big vertex array), and they must be finite.
fn build_primitive(
    mesh: &gltf::Mesh,
    primitive: &gltf::Primitive,
    buffers: &[Vec<u8>],
    warnings: &mut Warnings,
) -> Result<Option<Mesh>, String> {
    use gltf::mesh::Mode;
    let mesh_name = match mesh.name() {
        Some(name) => format!("mesh '{name}' (#{})", mesh.index()),
        None => format!("mesh #{}", mesh.index()),
    };
    let label = format!("{mesh_name}, primitive #{}", primitive.index());
    let mode = primitive.mode();
    if !is_triangles(mode) {
        warnings.add("point and line primitives (only triangles are rendered)");
        return Ok(None);
    }
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
    let positions = read_accessor(&accessor, buffers, Vec3::ZERO, |bytes| {
        let c =
            |k: usize| component_f32(data_type, normalized, bytes.get(k * size..(k + 1) * size)?);
        Some(Vec3::new(c(0)?, c(1)?, c(2)?))
    })
    .map_err(|p| format!("{label}: POSITION {p}"))?;
    let vertex_count = positions.len();
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

    let triangles: Vec<[u32; 3]> = match mode {
        Mode::TriangleStrip => (0..indices.len().saturating_sub(2))
            .filter_map(|i| {
                // glTF 2.0 §3.7.2.1: triangle i is (v_i, v_{i+1+i%2}, v_{i+2-i%2}).
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
    };
    if triangles.is_empty() {
        return Ok(None);
    }

    // Every referenced vertex must be finite and in range. Triangles that no ray can hit are
    // dropped: zero-area ones (coincident or collinear corners) and repeats of a triangle with
    // the same winding. Both are useless to render, and large numbers of identical primitives
    // make BVH construction quadratic (a file of a few kilobytes could stall it for hours).
    // Only vertices of kept triangles are kept, in first-use order.
    let mut remap = vec![u32::MAX; vertex_count];
    let mut kept = Vec::new();
    let mut compact = Vec::with_capacity(triangles.len());
    let mut seen: HashSet<[u32; 3]> = HashSet::with_capacity(triangles.len());
    for tri in &triangles {
        let mut corners = [Vec3::ZERO; 3];
        for (corner, &v) in corners.iter_mut().zip(tri) {
            let p = *positions
                .get(v as usize)
                .ok_or_else(|| format!("{label}: index {v} out of range"))?;
            if !p.is_finite() {
                return Err(format!(
                    "{mesh_name}: vertex {v} of primitive #{} has a non-finite position \
                     {p} (NaN or ±∞); repair the mesh and re-export it",
                    primitive.index()
                ));
            }
            if p.abs().max_element() > MAX_COORDINATE {
                return Err(format!(
                    "{mesh_name}: vertex {v} of primitive #{} has a coordinate of {:e}, \
                     beyond ±{MAX_COORDINATE:e} (where f32 ray arithmetic overflows); the mesh \
                     is corrupt or its export scale is wrong",
                    primitive.index(),
                    p.abs().max_element()
                ));
            }
            *corner = p;
        }
        let [a, b, c] = corners;
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
                .ok_or_else(|| format!("{label}: index {v} out of range"))?;
            if *entry == u32::MAX {
                *entry = kept.len() as u32;
                kept.push(positions[v as usize]);
            }
            *slot = *entry;
        }
        compact.push(out);
    }
    if compact.is_empty() {
        return Ok(None);
    }
    let name = match (mesh.name(), mesh.primitives().len()) {
        (Some(name), 1) => name.to_owned(),
        (Some(name), _) => format!("{name}/{}", primitive.index()),
        (None, 1) => format!("mesh{}", mesh.index()),
        (None, _) => format!("mesh{}/{}", mesh.index(), primitive.index()),
    };
    Ok(Some(Mesh {
        name,
        positions: kept,
        indices: compact,
    }))
}

/// One component as f32, normalised as glTF 2.0 §3.11 prescribes when `normalized`
/// (KHR_mesh_quantization allows integer positions).
fn component_f32(data_type: gltf::accessor::DataType, normalized: bool, b: &[u8]) -> Option<f32> {
    use gltf::accessor::DataType as T;
    Some(match (data_type, normalized) {
        (T::F32, _) => f32::from_le_bytes(b.try_into().ok()?),
        (T::I8, false) => i8::from_le_bytes(b.try_into().ok()?) as f32,
        (T::I8, true) => (i8::from_le_bytes(b.try_into().ok()?) as f32 / 127.0).max(-1.0),
        (T::U8, false) => u8::from_le_bytes(b.try_into().ok()?) as f32,
        (T::U8, true) => u8::from_le_bytes(b.try_into().ok()?) as f32 / 255.0,
        (T::I16, false) => i16::from_le_bytes(b.try_into().ok()?) as f32,
        (T::I16, true) => (i16::from_le_bytes(b.try_into().ok()?) as f32 / 32767.0).max(-1.0),
        (T::U16, false) => u16::from_le_bytes(b.try_into().ok()?) as f32,
        (T::U16, true) => u16::from_le_bytes(b.try_into().ok()?) as f32 / 65535.0,
        (T::U32, _) => u32::from_le_bytes(b.try_into().ok()?) as f32,
    })
}

/// One unsigned integer component (indices); `None` for other types or short data.
fn component_u32(data_type: gltf::accessor::DataType, b: &[u8]) -> Option<u32> {
    use gltf::accessor::DataType as T;
    Some(match data_type {
        T::U8 => u8::from_le_bytes(b.try_into().ok()?) as u32,
        T::U16 => u16::from_le_bytes(b.try_into().ok()?) as u32,
        T::U32 => u32::from_le_bytes(b.try_into().ok()?),
        _ => return None,
    })
}

/// The bytes of a buffer view, checked to lie inside its loaded buffer.
fn view_bytes<'b>(view: &gltf::buffer::View, buffers: &'b [Vec<u8>]) -> Result<&'b [u8], String> {
    let buffer = buffers
        .get(view.buffer().index())
        .ok_or_else(|| format!("buffer view #{} refers to a missing buffer", view.index()))?;
    view.offset()
        .checked_add(view.length())
        .and_then(|end| buffer.get(view.offset()..end))
        .ok_or_else(|| {
            format!(
                "reads buffer view #{} (bytes {}..{}), which lies outside buffer #{} ({} bytes): \
                 accessor out of bounds; the file is corrupt or truncated",
                view.index(),
                view.offset(),
                view.offset().saturating_add(view.length()),
                view.buffer().index(),
                buffer.len()
            )
        })
}

/// Reads every element of an accessor (dense data, then sparse substitutions) with checked
/// offsets; `decode` turns one element's bytes into a value. Errors are phrases to prefix with
/// what was being read.
fn read_accessor<T: Copy>(
    accessor: &gltf::Accessor,
    buffers: &[Vec<u8>],
    zero: T,
    decode: impl Fn(&[u8]) -> Option<T>,
) -> Result<Vec<T>, String> {
    let index = accessor.index();
    let count = accessor.count();
    let element = accessor.size();
    let mut values =
        match accessor.view() {
            Some(view) => {
                let data = view_bytes(&view, buffers)?;
                let stride = view.stride().unwrap_or(element);
                if stride < element {
                    return Err(format!(
                    "accessor #{index}: byteStride {stride} of buffer view #{} is smaller than \
                     one element ({element} bytes)",
                    view.index()
                ));
                }
                let start = accessor.offset();
                if count > 0 {
                    let needed = stride
                        .checked_mul(count - 1)
                        .and_then(|x| x.checked_add(start))
                        .and_then(|x| x.checked_add(element));
                    if needed.is_none_or(|n| n > data.len()) {
                        return Err(format!(
                        "accessor #{index} is out of bounds: {count} elements of {element} bytes \
                         (stride {stride}, offset {start}) do not fit in buffer view #{} \
                         ({} bytes); the file is corrupt or truncated",
                        view.index(),
                        data.len()
                    ));
                    }
                }
                let mut values = Vec::with_capacity(count);
                for i in 0..count {
                    let at = start + i * stride;
                    let bytes = data.get(at..at + element).ok_or_else(|| {
                        format!("accessor #{index}: element {i} lies outside its buffer view")
                    })?;
                    values.push(decode(bytes).ok_or_else(|| {
                        format!("accessor #{index}: element {i} cannot be decoded")
                    })?);
                }
                values
            }
            None if count > MAX_VIEWLESS_COUNT => {
                return Err(format!(
                "accessor #{index} has no data but claims {count} elements; the file is corrupt"
            ))
            }
            None => vec![zero; count],
        };
    if let Some(sparse) = accessor.sparse() {
        let n = sparse.count();
        let index_type = sparse.indices().index_type();
        let index_size = index_type.size();
        let index_data = view_bytes(&sparse.indices().view(), buffers)?;
        let value_data = view_bytes(&sparse.values().view(), buffers)?;
        let (index_start, value_start) = (sparse.indices().offset(), sparse.values().offset());
        for j in 0..n {
            let out_of_bounds = || format!("accessor #{index}: sparse entry {j} is out of bounds");
            let ib = index_start
                .checked_add(j.checked_mul(index_size).ok_or_else(out_of_bounds)?)
                .and_then(|at| index_data.get(at..at.checked_add(index_size)?))
                .ok_or_else(out_of_bounds)?;
            let target = match index_type {
                gltf::accessor::sparse::IndexType::U8 => ib.first().map(|&b| b as usize),
                gltf::accessor::sparse::IndexType::U16 => {
                    ib.try_into().ok().map(|b| u16::from_le_bytes(b) as usize)
                }
                gltf::accessor::sparse::IndexType::U32 => {
                    ib.try_into().ok().map(|b| u32::from_le_bytes(b) as usize)
                }
            }
            .ok_or_else(out_of_bounds)?;
            let vb = value_start
                .checked_add(j.checked_mul(element).ok_or_else(out_of_bounds)?)
                .and_then(|at| value_data.get(at..at.checked_add(element)?))
                .ok_or_else(out_of_bounds)?;
            let value = decode(vb).ok_or_else(out_of_bounds)?;
            *values.get_mut(target).ok_or_else(|| {
                format!(
                    "accessor #{index}: sparse index {target} is out of range ({count} elements)"
                )
            })? = value;
        }
    }
    Ok(values)
}

/// The bytes of a base64 `data:` URI (the only encoding glTF allows for buffers).
fn decode_data_uri(uri: &str) -> Result<Vec<u8>, String> {
    use base64::Engine;
    let (header, payload) = uri.split_once(',').ok_or("no ',' after the media type")?;
    if !header.ends_with(";base64") {
        return Err("not base64-encoded".into());
    }
    base64::engine::general_purpose::STANDARD
        .decode(payload)
        .map_err(|e| e.to_string())
}
