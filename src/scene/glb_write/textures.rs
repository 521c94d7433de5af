//! The scene's textures as glTF images (PNG in the binary chunk), samplers and textures: one
//! of each per texture, in order, so a material's texture index is the glTF texture's.

use image::ImageEncoder;
use serde_json::{json, Value};

use super::super::{Texture, TextureSampler, Wrap};

/// The glTF arrays for `textures`: images, samplers, textures. Each image is appended to `bin`
/// as a PNG with a buffer view of its own.
pub(super) fn write_textures(
    textures: &[Texture],
    bin: &mut Vec<u8>,
    views: &mut Vec<Value>,
) -> Result<[Vec<Value>; 3], String> {
    let (mut images, mut samplers, mut gltf_textures) = (Vec::new(), Vec::new(), Vec::new());
    for (i, t) in textures.iter().enumerate() {
        let png = png_bytes(t).map_err(|e| format!("texture '{}': {e}", t.name))?;
        // Buffer views of vertex data stay 4-byte aligned after an image of any length.
        while !bin.len().is_multiple_of(4) {
            bin.push(0);
        }
        views.push(json!({ "buffer": 0, "byteOffset": bin.len(), "byteLength": png.len() }));
        bin.extend_from_slice(&png);
        images.push(json!({
            "name": t.name, "bufferView": views.len() - 1, "mimeType": "image/png",
        }));
        samplers.push(sampler_json(&t.sampler));
        gltf_textures.push(json!({ "source": i, "sampler": i }));
    }
    Ok([images, samplers, gltf_textures])
}

fn png_bytes(t: &Texture) -> Result<Vec<u8>, String> {
    if t.rgba8.len() as u64 != 4 * t.width as u64 * t.height as u64 {
        return Err(format!(
            "{}×{} texels need {} bytes, it has {}",
            t.width,
            t.height,
            4 * t.width as u64 * t.height as u64,
            t.rgba8.len()
        ));
    }
    let mut png = Vec::new();
    image::codecs::png::PngEncoder::new(&mut png)
        .write_image(&t.rgba8, t.width, t.height, image::ColorType::Rgba8)
        .map_err(|e| format!("cannot encode it as PNG: {e}"))?;
    Ok(png)
}

/// glTF's sampler numbers for ours (the loader's reading inverted).
fn sampler_json(s: &TextureSampler) -> Value {
    const NEAREST: u32 = 9728;
    const LINEAR: u32 = 9729;
    const NEAREST_MIPMAP_LINEAR: u32 = 9986;
    const LINEAR_MIPMAP_LINEAR: u32 = 9987;
    let wrap = |w: Wrap| match w {
        Wrap::Repeat => 10497,
        Wrap::MirroredRepeat => 33648,
        Wrap::ClampToEdge => 33071,
    };
    let min = match (s.min_linear, s.mipmaps) {
        (false, false) => NEAREST,
        (true, false) => LINEAR,
        (false, true) => NEAREST_MIPMAP_LINEAR,
        (true, true) => LINEAR_MIPMAP_LINEAR,
    };
    json!({
        "magFilter": if s.mag_linear { LINEAR } else { NEAREST },
        "minFilter": min,
        "wrapS": wrap(s.wrap_u),
        "wrapT": wrap(s.wrap_v),
    })
}
