//! The glTF document: JSON or the GLB container split with checked arithmetic, the validator's
//! known traps checked before it runs, and the document-level content that is ignored.

use gltf::json;
use gltf::json::validation::Checked;

use super::origin::{Origin, Warnings};
use crate::scene::SceneError;

/// Extensions whose content this loader reads.
const READ_EXTENSIONS: &[&str] = &[
    "KHR_lights_punctual",
    "KHR_materials_emissive_strength",
    "KHR_mesh_quantization",
    "KHR_texture_transform",
];
/// A validated glTF document and the GLB binary chunk, if any.
pub(super) struct Parsed {
    pub(super) document: gltf::Document,
    pub(super) blob: Option<Vec<u8>>,
}

/// Parses glTF JSON or a GLB container and validates it. `binary_expected` makes a missing
/// `glTF` magic an error (a `.glb` that is something else); otherwise content decides.
pub(super) fn parse_document(
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
/// those this loader reads are removed from `extensionsRequired` (the validator rejects every
/// required extension it does not know), any other is an error naming it.
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
    // A required extension changes what the file means: one this loader does not read
    // refuses the file (merely used ones are listed once, note_ignored_features).
    if let Some(name) =
        (root.extensions_required.iter()).find(|n| !READ_EXTENSIONS.contains(&n.as_str()))
    {
        return Err(format!(
            "the file requires the extension {name}, which fovea cannot read; \
             re-export without it (e.g. `gltf-transform copy` decompresses Draco/meshopt)"
        ));
    }
    root.extensions_required.clear();
    Ok(())
}
/// Records the kinds of ignored content that can be seen at the document level.
pub(super) fn note_ignored_features(document: &gltf::Document, warnings: &mut Warnings) {
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
