//! Mip chains of textures, built at load: each level half the one before (rounded down, at
//! least 1 texel), every texel the mean of the 2×2 (or, at an odd edge, 2×1, 1×2) texels it
//! covers. sRGB-encoded colours are averaged as light (decoded, averaged, encoded again), so
//! a distant checkerboard of black and white reads 0.5 linear, not 0.5 encoded.

use super::{TexelEncoding, Texture};

/// One level of a chain: its size and RGBA8 texels.
pub struct Level {
    pub width: u32,
    pub height: u32,
    pub rgba8: Vec<u8>,
}

/// The number of levels of a full chain for `width × height`.
pub fn level_count(width: u32, height: u32) -> u32 {
    32 - width.max(height).max(1).leading_zeros()
}

/// The texture's levels, finest first: the whole chain when its sampler uses mipmaps, else
/// the texture alone.
pub fn mip_chain(t: &Texture) -> Vec<Level> {
    let mut levels = vec![Level {
        width: t.width,
        height: t.height,
        rgba8: t.rgba8.clone(),
    }];
    if !t.sampler.mipmaps {
        return levels;
    }
    let decode = decoding_table(t.encoding);
    while let Some(last) = levels.last().filter(|l| l.width > 1 || l.height > 1) {
        levels.push(halve(last, t.encoding, &decode));
    }
    levels
}

/// The first level of the texture's chain whose sides are at most `max_side` (≥ 1), by the
/// same filter as the chain; `None` when the texture already fits.
pub fn fitted(t: &Texture, max_side: u32) -> Option<Level> {
    if t.width.max(t.height) <= max_side {
        return None;
    }
    let decode = decoding_table(t.encoding);
    let mut level = Level {
        width: t.width,
        height: t.height,
        rgba8: t.rgba8.clone(),
    };
    while level.width.max(level.height) > max_side.max(1) {
        level = halve(&level, t.encoding, &decode);
    }
    Some(level)
}

/// Texel byte → linear value, per channel kind (colour channels of an sRGB texture are
/// decoded; alpha and linear data are not).
fn decoding_table(encoding: TexelEncoding) -> [f32; 256] {
    std::array::from_fn(|v| {
        let x = v as f32 / 255.0;
        match encoding {
            TexelEncoding::Linear => x,
            TexelEncoding::Srgb if x <= 0.04045 => x / 12.92,
            TexelEncoding::Srgb => ((x + 0.055) / 1.055).powf(2.4),
        }
    })
}

fn encode(linear: f32, encoding: TexelEncoding) -> u8 {
    let x = linear.clamp(0.0, 1.0);
    let e = match encoding {
        TexelEncoding::Linear => x,
        TexelEncoding::Srgb if x <= 0.003_130_8 => 12.92 * x,
        TexelEncoding::Srgb => 1.055 * x.powf(1.0 / 2.4) - 0.055,
    };
    (e * 255.0 + 0.5) as u8
}

fn halve(l: &Level, encoding: TexelEncoding, decode: &[f32; 256]) -> Level {
    let (w, h) = ((l.width / 2).max(1), (l.height / 2).max(1));
    let mut rgba8 = Vec::with_capacity((4 * w * h) as usize);
    for y in 0..h {
        for x in 0..w {
            let xs = [2 * x, (2 * x + 1).min(l.width - 1)];
            let ys = [2 * y, (2 * y + 1).min(l.height - 1)];
            for c in 0..4 {
                let mut sum = 0.0;
                for &sy in &ys {
                    for &sx in &xs {
                        let byte = l.rgba8[(4 * (sy * l.width + sx) + c) as usize];
                        sum += if c == 3 {
                            byte as f32 / 255.0
                        } else {
                            decode[byte as usize]
                        };
                    }
                }
                let mean = 0.25 * sum;
                rgba8.push(match c {
                    3 => encode(mean, TexelEncoding::Linear),
                    _ => encode(mean, encoding),
                });
            }
        }
    }
    Level {
        width: w,
        height: h,
        rgba8,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::TextureSampler;

    fn checker(encoding: TexelEncoding) -> Texture {
        let rgba8 = (0..16)
            .flat_map(|i| {
                let v = if (i % 4 + i / 4) % 2 == 0 { 255 } else { 0 };
                [v, v, v, 255]
            })
            .collect();
        Texture {
            name: "checker".into(),
            width: 4,
            height: 4,
            rgba8,
            encoding,
            sampler: TextureSampler::DEFAULT,
        }
    }

    #[test]
    fn a_chain_halves_to_one_texel() {
        let levels = mip_chain(&checker(TexelEncoding::Linear));
        let sizes: Vec<_> = levels.iter().map(|l| (l.width, l.height)).collect();
        assert_eq!(sizes, [(4, 4), (2, 2), (1, 1)]);
        assert_eq!(level_count(4, 4), 3);
        assert_eq!(level_count(5, 1), 3);
    }

    #[test]
    fn srgb_colours_are_averaged_as_light() {
        // Black and white average to linear 0.5, which sRGB encodes as 188; linear data to 128.
        let srgb = mip_chain(&checker(TexelEncoding::Srgb));
        assert_eq!(&srgb[2].rgba8, &[188, 188, 188, 255]);
        let linear = mip_chain(&checker(TexelEncoding::Linear));
        assert_eq!(&linear[2].rgba8, &[128, 128, 128, 255]);
    }

    #[test]
    fn a_sampler_without_mipmaps_keeps_one_level() {
        let mut t = checker(TexelEncoding::Srgb);
        t.sampler.mipmaps = false;
        assert_eq!(mip_chain(&t).len(), 1);
    }
}
