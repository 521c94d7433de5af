//! `--max-texture-size N`: textures larger than N texels on a side are downscaled at load (by
//! whole mip levels, the chain's own filter) instead of refused. For files whose images the
//! device cannot hold, or to save GPU memory.

use std::sync::OnceLock;

use super::mipmaps::fitted;
use super::Scene;

/// The process's limit: set once, by the command line, before any scene loads.
static MAX_TEXTURE_SIZE: OnceLock<u32> = OnceLock::new();

/// Sets the largest texture side every scene loaded from now on keeps. Returns false when a
/// limit was already set (the first one stays).
pub fn set_max_texture_size(max_side: u32) -> bool {
    MAX_TEXTURE_SIZE.set(max_side.max(1)).is_ok()
}

/// The limit set by [`set_max_texture_size`], if any.
pub fn max_texture_size() -> Option<u32> {
    MAX_TEXTURE_SIZE.get().copied()
}

/// Downscales every texture of `scene` with a side over `max_side` by halving (so its uv
/// mapping is unchanged), and says which, with their sizes before and after.
pub fn downscale_textures(scene: &mut Scene, max_side: u32) -> Vec<String> {
    let mut changed = Vec::new();
    for t in &mut scene.textures {
        if let Some(level) = fitted(t, max_side) {
            changed.push(format!(
                "'{}' {}×{} → {}×{}",
                t.name, t.width, t.height, level.width, level.height
            ));
            (t.width, t.height, t.rgba8) = (level.width, level.height, level.rgba8);
        }
    }
    changed
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::builtin::builtin;
    use crate::scene::{TexelEncoding, Texture, TextureSampler};

    fn texture(name: &str, width: u32, height: u32) -> Texture {
        Texture {
            name: name.into(),
            width,
            height,
            rgba8: [200, 100, 50, 255].repeat((width * height) as usize),
            encoding: TexelEncoding::Srgb,
            sampler: TextureSampler::DEFAULT,
        }
    }

    #[test]
    fn only_textures_over_the_limit_are_halved_until_they_fit() {
        let mut scene = builtin("cornell", 1.0).unwrap();
        scene.textures = vec![texture("big", 8, 5), texture("small", 3, 3)];
        let changed = downscale_textures(&mut scene, 3);
        assert_eq!(changed, vec!["'big' 8×5 → 2×1".to_string()]);
        let [big, small] = &scene.textures[..] else {
            panic!("two textures")
        };
        assert_eq!((big.width, big.height, big.rgba8.len()), (2, 1, 8));
        // A uniform texture stays that colour (averaged as light, encoded again).
        assert_eq!(&big.rgba8[..4], &[200, 100, 50, 255]);
        assert_eq!((small.width, small.height), (3, 3));
        assert!(downscale_textures(&mut scene, 3).is_empty());
    }
}
