//! HDR environment maps: an equirectangular (latitude-longitude) image of the radiance that
//! arrives from every direction, read from OpenEXR (`exr`) or Radiance HDR (`image`), lighting
//! a scene in place of its sky.
//!
//! Orientation: Blender's Environment Texture with its default mapping, for a glTF file brought
//! into Blender by its glTF importer (glTF's +Y up is Blender's +Z; glTF's −Z is Blender's +Y).
//! In glTF's (and fovea's) axes, a direction d = (x, y, z) reads the image at column
//! u = 0.5 + atan2(z, x) / 2π (of the width, from the left) and row t = acos(y) / π (of the
//! height, from the top): the image's centre is seen looking along +X, its left and right
//! edges along −X, its quarter and three-quarter columns along −Z and +Z, its top row
//! straight up. `rotate_deg` turns the environment about +Y by that angle (right-handed: a
//! feature seen along +X at 0 is seen along −Z at 90).

use std::path::{Path, PathBuf};
use std::sync::Arc;

use glam::Vec3;

use super::SceneError;

/// The largest environment accepted, in texels (16384 × 8192): beyond that the sampling
/// table alone would need gigabytes.
pub const MAX_ENV_TEXELS: usize = 16384 * 8192;

/// An equirectangular radiance image, rows from the top, linear RGB.
#[derive(Debug, PartialEq)]
pub struct EnvironmentMap {
    /// Where it was read from (messages, reports).
    pub path: PathBuf,
    pub width: u32,
    pub height: u32,
    pub texels: Vec<Vec3>,
    /// Texels that were negative and were set to 0 (some HDR tools' filtering leaves them).
    pub clamped_negative: usize,
}

/// An environment lighting a scene: the map, turned about +Y and scaled.
#[derive(Clone, Debug, PartialEq)]
pub struct EnvironmentLight {
    pub map: Arc<EnvironmentMap>,
    /// Degrees about +Y, right-handed (module docs).
    pub rotate_deg: f32,
    /// Multiplies every texel.
    pub intensity: f32,
    /// How next-event estimation picks directions of it.
    pub sampling: EnvSampling,
}

/// How next-event estimation chooses environment texels.
#[derive(
    Clone,
    Copy,
    Debug,
    Default,
    PartialEq,
    Eq,
    clap::ValueEnum,
    serde::Serialize,
    serde::Deserialize,
)]
#[serde(rename_all = "kebab-case")]
pub enum EnvSampling {
    /// In proportion to luminance × sin θ: where the light comes from.
    #[default]
    Importance,
    /// In proportion to sin θ alone: directions uniform over the sphere (for comparison).
    Uniform,
}

impl EnvironmentMap {
    /// Reads `.exr` or `.hdr` (by extension) and checks what the renderer needs: an image of
    /// 2:1 texels, finite. Negative texels are set to 0 (counted in `clamped_negative`).
    pub fn load(path: &Path) -> Result<Self, SceneError> {
        let problem = |problem: String| SceneError::Load {
            path: path.to_owned(),
            problem,
        };
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        let (width, height, texels) = match ext.as_deref() {
            Some("exr") => read_exr(path).map_err(problem)?,
            Some("hdr") => read_hdr(path).map_err(problem)?,
            _ => {
                return Err(problem(
                    "an environment map must be an equirectangular .exr or .hdr image".into(),
                ))
            }
        };
        Self::from_texels(path, width, height, texels).map_err(problem)
    }

    /// An environment of the given texels, checked as [`EnvironmentMap::load`] checks a file.
    pub fn from_texels(
        path: &Path,
        width: u32,
        height: u32,
        mut texels: Vec<Vec3>,
    ) -> Result<Self, String> {
        if width != 2 * height || height == 0 {
            return Err(format!(
                "it is {width} × {height} texels; an equirectangular environment is twice as \
                 wide as it is tall (e.g. 1024 × 512): convert it to a latitude-longitude map"
            ));
        }
        if texels.len() != (width as usize) * (height as usize) {
            return Err(format!(
                "it holds {} texels for {width} × {height}",
                texels.len()
            ));
        }
        if texels.len() > MAX_ENV_TEXELS {
            return Err(format!(
                "it is {width} × {height} texels, more than the {MAX_ENV_TEXELS} fovea takes; \
                 downscale it (e.g. to 4096 × 2048)"
            ));
        }
        if let Some(i) = texels.iter().position(|t| !t.is_finite()) {
            let bad = texels.iter().filter(|t| !t.is_finite()).count();
            return Err(format!(
                "{bad} texel(s) are NaN or infinite, the first at column {}, row {} ({}): \
                 the file is damaged; re-export it",
                i as u32 % width,
                i as u32 / width,
                texels[i]
            ));
        }
        let mut clamped_negative = 0;
        for t in &mut texels {
            if t.min_element() < 0.0 {
                clamped_negative += 1;
                *t = t.max(Vec3::ZERO);
            }
        }
        Ok(Self {
            path: path.to_owned(),
            width,
            height,
            texels,
            clamped_negative,
        })
    }
}

/// The direction at (u, t): column u from the left, row t from the top (module docs).
pub fn uv_to_direction(u: f32, t: f32) -> Vec3 {
    let phi = (u - 0.5) * 2.0 * std::f32::consts::PI;
    let theta = t * std::f32::consts::PI;
    Vec3::new(
        theta.sin() * phi.cos(),
        theta.cos(),
        theta.sin() * phi.sin(),
    )
}

type Texels = (u32, u32, Vec<Vec3>);

fn read_exr(path: &Path) -> Result<Texels, String> {
    let image = exr::prelude::read_first_rgba_layer_from_file(
        path,
        |size, _| (size.width(), vec![Vec3::ZERO; size.width() * size.height()]),
        |(w, texels), pos, (r, g, b, _a): (f32, f32, f32, f32)| {
            texels[pos.y() * *w + pos.x()] = Vec3::new(r, g, b);
        },
    )
    .map_err(|e| format!("not a readable OpenEXR image with R, G and B channels ({e})"))?;
    let size = image.layer_data.size;
    let (_, texels) = image.layer_data.channel_data.pixels;
    Ok((size.width() as u32, size.height() as u32, texels))
}

fn read_hdr(path: &Path) -> Result<Texels, String> {
    let file = std::fs::File::open(path).map_err(|e| format!("cannot open it ({e})"))?;
    let decoder = image::codecs::hdr::HdrDecoder::new(std::io::BufReader::new(file))
        .map_err(|e| format!("not a readable Radiance HDR image ({e})"))?;
    let meta = decoder.metadata();
    let pixels = decoder
        .read_image_hdr()
        .map_err(|e| format!("not a readable Radiance HDR image ({e})"))?;
    let texels = pixels.iter().map(|p| Vec3::from(p.0)).collect();
    Ok((meta.width, meta.height, texels))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The inverse of [`uv_to_direction`], as glsl/environment.glsl's env_uv: (u, t) in [0, 1]² of a direction: column from the left, row from the top (module docs).
    fn direction_to_uv(d: Vec3) -> (f32, f32) {
        let d = d.normalize();
        let u = 0.5 + d.z.atan2(d.x) / (2.0 * std::f32::consts::PI);
        let t = d.y.clamp(-1.0, 1.0).acos() / std::f32::consts::PI;
        (u.rem_euclid(1.0), t)
    }

    #[test]
    fn the_orientation_is_blenders_for_gltf_axes() {
        // The image's centre along +X, a quarter along −Z, three quarters along +Z, top up.
        let (u, _) = direction_to_uv(Vec3::X);
        assert!((u - 0.5).abs() < 1e-6);
        let (u, t) = direction_to_uv(Vec3::NEG_Z);
        assert!((u - 0.25).abs() < 1e-6 && (t - 0.5).abs() < 1e-6);
        let (u, _) = direction_to_uv(Vec3::Z);
        assert!((u - 0.75).abs() < 1e-6);
        let (_, t) = direction_to_uv(Vec3::Y);
        assert!(t.abs() < 1e-6);
        for (u, t) in [(0.1, 0.2), (0.6, 0.7), (0.9, 0.45)] {
            let (u2, t2) = direction_to_uv(uv_to_direction(u, t));
            assert!((u - u2).abs() < 1e-5 && (t - t2).abs() < 1e-5, "{u} {t}");
        }
    }

    #[test]
    fn bad_environments_say_what_is_wrong() {
        let path = Path::new("sky.exr");
        let square = EnvironmentMap::from_texels(path, 4, 4, vec![Vec3::ONE; 16]);
        assert!(square.unwrap_err().contains("twice as wide"));
        let mut texels = vec![Vec3::ONE; 8];
        texels[5] = Vec3::new(1.0, f32::NAN, 0.0);
        let nan = EnvironmentMap::from_texels(path, 4, 2, texels).unwrap_err();
        assert!(nan.contains("column 1, row 1"), "{nan}");
        let mut texels = vec![Vec3::ONE; 8];
        texels[2] = Vec3::new(-1.0, 0.5, 0.5);
        let clamped = EnvironmentMap::from_texels(path, 4, 2, texels).unwrap();
        assert_eq!(clamped.clamped_negative, 1);
        assert_eq!(clamped.texels[2], Vec3::new(0.0, 0.5, 0.5));
    }
}
