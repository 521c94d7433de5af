//! A scene's textures as the GPU samples them: mip chains built at load, glTF samplers as
//! Vulkan samplers, and what they take in the memory plan.

use crate::gpu::{mip_chain_bytes, vk, MipLevel, PlannedAllocation, SamplerDesc, TextureUpload};
use crate::scene::mipmaps::{level_count, mip_chain};
use crate::scene::{TexelEncoding, Texture, TextureSampler, Wrap};

/// The uploads of `textures`, in their order (BINDING_TEXTURES' indices).
pub fn uploads(textures: &[Texture]) -> Vec<TextureUpload> {
    textures
        .iter()
        .map(|t| TextureUpload {
            name: format!("texture '{}'", t.name),
            levels: mip_chain(t)
                .into_iter()
                .map(|l| MipLevel {
                    width: l.width,
                    height: l.height,
                    rgba8: l.rgba8,
                })
                .collect(),
            srgb: t.encoding == TexelEncoding::Srgb,
            sampler: sampler_desc(&t.sampler),
        })
        .collect()
}

/// What the textures take on the device (every level), and the staging buffer that uploads
/// them all at once.
pub fn allocations(textures: &[Texture]) -> Vec<PlannedAllocation> {
    let bytes = |t: &Texture| {
        let levels = match t.sampler.mipmaps {
            true => level_count(t.width, t.height),
            false => 1,
        };
        mip_chain_bytes(t.width, t.height, levels)
    };
    let mut plan: Vec<PlannedAllocation> = textures
        .iter()
        .map(|t| PlannedAllocation::image(&format!("texture '{}'", t.name), bytes(t)))
        .collect();
    let staging: u64 = textures.iter().map(bytes).sum();
    if staging > 0 {
        plan.push(PlannedAllocation::host("texture upload", staging, false));
    }
    plan
}

/// Refuses a texture the device cannot hold as one image, naming it.
pub fn check_sizes(textures: &[Texture], max_side: u32) -> Result<(), String> {
    match textures.iter().find(|t| t.width.max(t.height) > max_side) {
        Some(t) => Err(format!(
            "texture '{}' is {}×{} texels, larger than this device's largest image side \
             ({max_side}); run with --max-texture-size {max_side} to downscale it at load, \
             or downscale the image in the file",
            t.name, t.width, t.height
        )),
        None => Ok(()),
    }
}

fn sampler_desc(s: &TextureSampler) -> SamplerDesc {
    let address = |w: Wrap| match w {
        Wrap::Repeat => vk::SamplerAddressMode::REPEAT,
        Wrap::MirroredRepeat => vk::SamplerAddressMode::MIRRORED_REPEAT,
        Wrap::ClampToEdge => vk::SamplerAddressMode::CLAMP_TO_EDGE,
    };
    let filter = |linear: bool| match linear {
        true => vk::Filter::LINEAR,
        false => vk::Filter::NEAREST,
    };
    SamplerDesc {
        address_u: address(s.wrap_u),
        address_v: address(s.wrap_v),
        mag: filter(s.mag_linear),
        min: filter(s.min_linear),
        mipmap: vk::SamplerMipmapMode::LINEAR,
        level_0_only: !s.mipmaps,
    }
}
