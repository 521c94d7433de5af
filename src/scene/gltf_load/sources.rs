//! Where a file's bytes come from: the file itself, the GLB binary chunk, `data:` URIs and
//! external files next to the `.gltf`, each read with size and path checks.

use std::path::{Path, PathBuf};

use super::limits::MAX_FILE_BYTES;
use super::origin::Origin;
use crate::scene::SceneError;

/// Reads a whole file after checking that it exists, is a file and is at most 2 GiB.
/// The error is a sentence about the file, to be wrapped by the caller.
pub(super) fn read_file(path: &Path) -> Result<Vec<u8>, String> {
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
/// Loads every buffer: the GLB binary chunk, `data:` URIs, or files relative to `base_dir`
/// (`None`: external files are not allowed, e.g. for in-memory data).
pub(super) fn load_buffers(
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
pub(super) fn short(uri: &str) -> String {
    match uri.char_indices().nth(60) {
        Some((cut, _)) => format!("{}…", &uri[..cut]),
        None => uri.to_owned(),
    }
}

/// Resolves a buffer or image URI that is not a `data:` URI to a file path.
pub(super) fn external_path(uri: &str, base_dir: Option<&Path>) -> Result<PathBuf, String> {
    let Some(base_dir) = base_dir else {
        return Err(
            "it is an external file, which cannot be found for glTF data loaded from \
             memory (there is no directory to look in); embed it as a data: URI or \
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
/// The bytes of a base64 `data:` URI (the only encoding glTF allows for buffers).
pub(super) fn decode_data_uri(uri: &str) -> Result<Vec<u8>, String> {
    use base64::Engine;
    let (header, payload) = uri.split_once(',').ok_or("no ',' after the media type")?;
    if !header.ends_with(";base64") {
        return Err("not base64-encoded".into());
    }
    base64::engine::general_purpose::STANDARD
        .decode(payload)
        .map_err(|e| e.to_string())
}
