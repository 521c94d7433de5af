//! glTF textures: each (texture, colour space) a material uses becomes one [`Texture`],
//! decoded from the GLB binary chunk, a `data:` URI or a file beside the `.gltf` (PNG or JPEG,
//! as glTF's core allows), with its sampler; a material's use of it becomes a [`TextureRef`]
//! with its texture coordinate set and `KHR_texture_transform`.

use std::collections::HashMap;
use std::path::Path;

use super::origin::Origin;
use super::sources::{decode_data_uri, external_path, read_file, short};
use crate::scene::{SceneError, TexelEncoding, Texture, TextureRef, TextureSampler, Wrap};

/// The textures of a file, loaded once each as the materials ask for them.
pub(super) struct TextureLoader<'d> {
    buffers: &'d [Vec<u8>],
    base_dir: Option<&'d Path>,
    pub(super) textures: Vec<Texture>,
    ids: HashMap<(usize, TexelEncoding), u32>,
}

impl<'d> TextureLoader<'d> {
    pub(super) fn new(buffers: &'d [Vec<u8>], base_dir: Option<&'d Path>) -> Self {
        Self {
            buffers,
            base_dir,
            textures: Vec::new(),
            ids: HashMap::new(),
        }
    }

    /// A material's use of a texture (`info`), its texels read as `encoding`.
    pub(super) fn reference(
        &mut self,
        info: &gltf::texture::Info,
        encoding: TexelEncoding,
        origin: &Origin,
    ) -> Result<TextureRef, SceneError> {
        let transform = info.texture_transform().map(|t| UvTransform {
            offset: t.offset(),
            rotation: t.rotation(),
            scale: t.scale(),
            texcoord: t.tex_coord(),
        });
        self.slot(
            &info.texture(),
            info.tex_coord(),
            transform,
            encoding,
            origin,
        )
    }

    /// A material's normal texture (linear texels); its KHR_texture_transform is read from
    /// the JSON (the gltf crate gives normal textures none).
    pub(super) fn normal_reference(
        &mut self,
        normal: &gltf::material::NormalTexture,
        origin: &Origin,
    ) -> Result<TextureRef, SceneError> {
        let transform = normal
            .extension_value("KHR_texture_transform")
            .map(UvTransform::from_json);
        let (texture, set) = (normal.texture(), normal.tex_coord());
        self.slot(&texture, set, transform, TexelEncoding::Linear, origin)
    }

    fn slot(
        &mut self,
        texture: &gltf::Texture,
        texcoord: u32,
        transform: Option<UvTransform>,
        encoding: TexelEncoding,
        origin: &Origin,
    ) -> Result<TextureRef, SceneError> {
        let texcoord = transform.and_then(|t| t.texcoord).unwrap_or(texcoord);
        if texcoord > 1 {
            return Err(origin.invalid(format!(
                "texture #{} is read with TEXCOORD_{texcoord}; only TEXCOORD_0 and TEXCOORD_1 \
                 are supported (re-export with at most two UV sets)",
                texture.index()
            )));
        }
        let id = match self.ids.get(&(texture.index(), encoding)) {
            Some(&id) => id,
            None => {
                let loaded = self.load(texture, encoding).map_err(|p| origin.load(p))?;
                self.textures.push(loaded);
                let id = (self.textures.len() - 1) as u32;
                self.ids.insert((texture.index(), encoding), id);
                id
            }
        };
        Ok(TextureRef {
            texture: id,
            texcoord,
            transform: transform.map_or(TextureRef::IDENTITY, |t| {
                uv_transform(t.offset, t.rotation, t.scale)
            }),
        })
    }

    /// Decodes the texture's image; the error names the image and says what to do.
    fn load(&self, texture: &gltf::Texture, encoding: TexelEncoding) -> Result<Texture, String> {
        let image = texture.source();
        let name = image_label(&image);
        let bytes = self
            .image_bytes(&image)
            .map_err(|p| format!("{name}: {p}"))?;
        let rgba = decode(&bytes).map_err(|p| format!("{name}: {p}"))?;
        Ok(Texture {
            name,
            width: rgba.width(),
            height: rgba.height(),
            rgba8: rgba.into_raw(),
            encoding,
            sampler: sampler(&texture.sampler()),
        })
    }

    /// The encoded image: a buffer view's bytes, a `data:` URI or a file.
    fn image_bytes(&self, image: &gltf::Image) -> Result<Vec<u8>, String> {
        match image.source() {
            gltf::image::Source::View { view, .. } => {
                let buffer = self
                    .buffers
                    .get(view.buffer().index())
                    .ok_or("its buffer view refers to a missing buffer")?;
                let start = view.offset();
                start
                    .checked_add(view.length())
                    .and_then(|end| buffer.get(start..end))
                    .map(<[u8]>::to_vec)
                    .ok_or_else(|| {
                        "its buffer view lies outside its buffer (truncated file?)".to_owned()
                    })
            }
            gltf::image::Source::Uri { uri, .. } if uri.starts_with("data:") => {
                decode_data_uri(uri).map_err(|e| format!("its data: URI cannot be decoded ({e})"))
            }
            gltf::image::Source::Uri { uri, .. } => {
                let file = external_path(uri, self.base_dir)?;
                read_file(&file).map_err(|p| {
                    format!(
                        "the image file '{}' at '{}': {p}; keep the images next to the .gltf, \
                         or use a .glb",
                        short(uri),
                        file.display()
                    )
                })
            }
        }
    }
}

/// KHR_texture_transform's values (glTF's defaults where absent).
#[derive(Clone, Copy)]
struct UvTransform {
    offset: [f32; 2],
    rotation: f32,
    scale: [f32; 2],
    texcoord: Option<u32>,
}

impl UvTransform {
    fn from_json(v: &gltf::json::Value) -> Self {
        let pair = |key: &str, default: [f32; 2]| {
            v.get(key)
                .and_then(|p| Some([p.get(0)?.as_f64()? as f32, p.get(1)?.as_f64()? as f32]))
                .unwrap_or(default)
        };
        Self {
            offset: pair("offset", [0.0, 0.0]),
            rotation: v.get("rotation").and_then(|r| r.as_f64()).unwrap_or(0.0) as f32,
            scale: pair("scale", [1.0, 1.0]),
            texcoord: v.get("texCoord").and_then(|t| t.as_u64()).map(|t| t as u32),
        }
    }
}

/// "image #i ('name')" for messages.
fn image_label(image: &gltf::Image) -> String {
    match image.name() {
        Some(name) => format!("image #{} ('{name}')", image.index()),
        None => format!("image #{}", image.index()),
    }
}

/// PNG or JPEG bytes as RGBA8; anything else is refused with what it is.
fn decode(bytes: &[u8]) -> Result<image::RgbaImage, String> {
    let format = image::guess_format(bytes).map_err(|_| {
        "it is not a PNG or JPEG image (glTF's core formats); convert it to PNG or JPEG".to_owned()
    })?;
    if !matches!(format, image::ImageFormat::Png | image::ImageFormat::Jpeg) {
        return Err(format!(
            "it is a {format:?} image; only PNG and JPEG (glTF's core formats) are read: convert it"
        ));
    }
    let decoded = image::load_from_memory_with_format(bytes, format).map_err(|e| {
        format!("it cannot be decoded ({e}); the image is corrupt or truncated: re-export it")
    })?;
    Ok(decoded.to_rgba8())
}

/// A glTF sampler as fovea samples it (the default sampler where none is named).
fn sampler(s: &gltf::texture::Sampler) -> TextureSampler {
    use gltf::texture::{MagFilter, MinFilter, WrappingMode};
    let wrap = |w: WrappingMode| match w {
        WrappingMode::ClampToEdge => Wrap::ClampToEdge,
        WrappingMode::MirroredRepeat => Wrap::MirroredRepeat,
        WrappingMode::Repeat => Wrap::Repeat,
    };
    let (min_linear, mipmaps) = match s.min_filter() {
        None => (true, true),
        Some(MinFilter::Nearest) => (false, false),
        Some(MinFilter::Linear) => (true, false),
        Some(MinFilter::NearestMipmapNearest | MinFilter::NearestMipmapLinear) => (false, true),
        Some(MinFilter::LinearMipmapNearest | MinFilter::LinearMipmapLinear) => (true, true),
    };
    TextureSampler {
        wrap_u: wrap(s.wrap_s()),
        wrap_v: wrap(s.wrap_t()),
        mag_linear: s.mag_filter() != Some(MagFilter::Nearest),
        min_linear,
        mipmaps,
    }
}

/// `KHR_texture_transform`'s matrix T(offset) · R(rotation) · S(scale) as the rows of a 2×3
/// matrix, with R as the ratified extension's sample code and Khronos' glTF Sample Viewer
/// build it (`mat3(cos, −sin, 0, sin, cos, 0, 0, 0, 1)`, column-major): u' = cos·u + sin·v,
/// v' = −sin·u + cos·v before the offset. (An older draft's code had the sign the other way;
/// the TextureTransformTest sample's "Rotation" quad tells them apart.)
pub(super) fn uv_transform(offset: [f32; 2], rotation: f32, scale: [f32; 2]) -> [[f32; 3]; 2] {
    let (sin, cos) = rotation.sin_cos();
    [
        [cos * scale[0], sin * scale[1], offset[0]],
        [-sin * scale[0], cos * scale[1], offset[1]],
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_transform_moves_scales_and_rotates_as_the_extension_says() {
        let apply = |m: [[f32; 3]; 2], u: f32, v: f32| {
            (
                m[0][0] * u + m[0][1] * v + m[0][2],
                m[1][0] * u + m[1][1] * v + m[1][2],
            )
        };
        assert_eq!(
            apply(uv_transform([0.5, 0.25], 0.0, [1.0, 1.0]), 0.1, 0.2),
            (0.6, 0.45)
        );
        assert_eq!(
            apply(uv_transform([0.0, 0.0], 0.0, [1.5, 2.0]), 1.0, 1.0),
            (1.5, 2.0)
        );
        let (u, v) = apply(
            uv_transform([0.0, 0.0], std::f32::consts::FRAC_PI_2, [1.0, 1.0]),
            1.0,
            0.0,
        );
        assert!(
            (u - 0.0).abs() < 1e-6 && (v + 1.0).abs() < 1e-6,
            "({u}, {v})"
        );
    }
}
