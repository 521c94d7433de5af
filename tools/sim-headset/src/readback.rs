//! Saving a submitted eye image: copy the sub-image out of the swapchain image into a
//! host-visible buffer and write it as an 8-bit sRGB PNG.

use std::path::Path;

use ash::vk;
use openxr_sys as xr;

use crate::vulkan::VkContext;

pub const R8G8B8A8_UNORM: i64 = 37;
pub const R8G8B8A8_SRGB: i64 = 43;
pub const B8G8R8A8_UNORM: i64 = 44;
pub const B8G8R8A8_SRGB: i64 = 50;
pub const R16G16B16A16_SFLOAT: i64 = 97;

/// Bytes per texel of the formats the runtime offers.
pub fn texel_size(format: i64) -> Option<usize> {
    match format {
        R8G8B8A8_UNORM | R8G8B8A8_SRGB | B8G8R8A8_UNORM | B8G8R8A8_SRGB => Some(4),
        R16G16B16A16_SFLOAT => Some(8),
        _ => None,
    }
}

/// IEEE half to single precision.
pub fn f16_to_f32(h: u16) -> f32 {
    let sign = if h & 0x8000 != 0 { -1.0 } else { 1.0 };
    let exp = ((h >> 10) & 0x1f) as i32;
    let mant = (h & 0x3ff) as f32;
    match exp {
        0 => sign * mant * 2f32.powi(-24),
        31 if mant == 0.0 => sign * f32::INFINITY,
        31 => f32::NAN,
        _ => sign * (1.0 + mant / 1024.0) * 2f32.powi(exp - 15),
    }
}

/// Linear to 8-bit sRGB (IEC 61966-2-1), clamping out-of-range and NaN to [0, 1].
pub fn linear_to_srgb8(v: f32) -> u8 {
    let v = if v.is_nan() { 0.0 } else { v.clamp(0.0, 1.0) };
    let s = if v <= 0.003_130_8 {
        12.92 * v
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    };
    (s * 255.0 + 0.5) as u8
}

/// Tightly packed texels of `format` to RGB8. Alpha is dropped: the headset's only blend
/// mode is OPAQUE, so a compositor would ignore it too. 8-bit formats are written as stored
/// (sRGB formats already hold sRGB bytes); half floats are linear and get encoded.
pub fn to_rgb8(format: i64, texels: &[u8]) -> Vec<u8> {
    match format {
        R8G8B8A8_UNORM | R8G8B8A8_SRGB => texels
            .chunks_exact(4)
            .flat_map(|t| [t[0], t[1], t[2]])
            .collect(),
        B8G8R8A8_UNORM | B8G8R8A8_SRGB => texels
            .chunks_exact(4)
            .flat_map(|t| [t[2], t[1], t[0]])
            .collect(),
        R16G16B16A16_SFLOAT => texels
            .chunks_exact(8)
            .flat_map(|t| {
                let c =
                    |k: usize| linear_to_srgb8(f16_to_f32(u16::from_le_bytes([t[k], t[k + 1]])));
                [c(0), c(2), c(4)]
            })
            .collect(),
        _ => Vec::new(),
    }
}

pub fn write_png(path: &Path, width: u32, height: u32, rgb: &[u8]) -> std::io::Result<()> {
    let file = std::io::BufWriter::new(std::fs::File::create(path)?);
    let mut encoder = png::Encoder::new(file, width, height);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    encoder.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
    let mut writer = encoder.write_header().map_err(std::io::Error::other)?;
    writer
        .write_image_data(rgb)
        .map_err(std::io::Error::other)?;
    writer.finish().map_err(std::io::Error::other)
}

/// Copies `rect` of array layer `layer` (mip 0) of `image`, which is in
/// COLOR_ATTACHMENT_OPTIMAL, to host memory and returns the tightly packed texels. The
/// image is back in COLOR_ATTACHMENT_OPTIMAL afterwards.
pub fn read_rect(
    ctx: &VkContext,
    image: vk::Image,
    format: i64,
    layer: u32,
    rect: xr::Rect2Di,
) -> Result<Vec<u8>, xr::Result> {
    let texel = texel_size(format).ok_or(xr::Result::ERROR_RUNTIME_FAILURE)?;
    let (w, h) = (rect.extent.width as u32, rect.extent.height as u32);
    let size = (w as usize * h as usize * texel) as vk::DeviceSize;
    let dev = &ctx.device;
    // SAFETY: the buffer and memory are created, used and destroyed within this block, after
    // submit_once has waited for the copy; the image is the app's released swapchain image,
    // which the app may not touch until it acquires it again.
    unsafe {
        let buffer = dev
            .create_buffer(
                &vk::BufferCreateInfo::default()
                    .size(size)
                    .usage(vk::BufferUsageFlags::TRANSFER_DST)
                    .sharing_mode(vk::SharingMode::EXCLUSIVE),
                None,
            )
            .map_err(|_| xr::Result::ERROR_RUNTIME_FAILURE)?;
        let needs = dev.get_buffer_memory_requirements(buffer);
        let host = vk::MemoryPropertyFlags::HOST_VISIBLE | vk::MemoryPropertyFlags::HOST_COHERENT;
        let Some(type_index) = ctx.memory_type(needs.memory_type_bits, host) else {
            dev.destroy_buffer(buffer, None);
            return Err(xr::Result::ERROR_RUNTIME_FAILURE);
        };
        let memory = match dev.allocate_memory(
            &vk::MemoryAllocateInfo::default()
                .allocation_size(needs.size)
                .memory_type_index(type_index),
            None,
        ) {
            Ok(m) => m,
            Err(_) => {
                dev.destroy_buffer(buffer, None);
                return Err(xr::Result::ERROR_OUT_OF_MEMORY);
            }
        };
        let result = (|| {
            dev.bind_buffer_memory(buffer, memory, 0)
                .map_err(|_| xr::Result::ERROR_RUNTIME_FAILURE)?;
            ctx.submit_once(|cmd| record_copy(ctx, cmd, image, buffer, layer, rect))?;
            let ptr = dev
                .map_memory(memory, 0, size, vk::MemoryMapFlags::empty())
                .map_err(|_| xr::Result::ERROR_RUNTIME_FAILURE)?;
            let bytes = std::slice::from_raw_parts(ptr as *const u8, size as usize).to_vec();
            dev.unmap_memory(memory);
            Ok(bytes)
        })();
        dev.destroy_buffer(buffer, None);
        dev.free_memory(memory, None);
        result
    }
}

fn record_copy(
    ctx: &VkContext,
    cmd: vk::CommandBuffer,
    image: vk::Image,
    buffer: vk::Buffer,
    layer: u32,
    rect: xr::Rect2Di,
) {
    let range = vk::ImageSubresourceRange {
        aspect_mask: vk::ImageAspectFlags::COLOR,
        base_mip_level: 0,
        level_count: 1,
        base_array_layer: layer,
        layer_count: 1,
    };
    let barrier = |old, new, src, dst| {
        vk::ImageMemoryBarrier::default()
            .old_layout(old)
            .new_layout(new)
            .src_access_mask(src)
            .dst_access_mask(dst)
            .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
            .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
            .image(image)
            .subresource_range(range)
    };
    let region = vk::BufferImageCopy::default()
        .image_subresource(vk::ImageSubresourceLayers {
            aspect_mask: vk::ImageAspectFlags::COLOR,
            mip_level: 0,
            base_array_layer: layer,
            layer_count: 1,
        })
        .image_offset(vk::Offset3D {
            x: rect.offset.x,
            y: rect.offset.y,
            z: 0,
        })
        .image_extent(vk::Extent3D {
            width: rect.extent.width as u32,
            height: rect.extent.height as u32,
            depth: 1,
        });
    // SAFETY: recording into our own command buffer; the app's writes to the image were
    // submitted earlier on the same queue, and the first barrier's source scope (all
    // commands, all memory writes) orders them before the copy.
    unsafe {
        ctx.device.cmd_pipeline_barrier(
            cmd,
            vk::PipelineStageFlags::ALL_COMMANDS,
            vk::PipelineStageFlags::TRANSFER,
            vk::DependencyFlags::empty(),
            &[],
            &[],
            &[barrier(
                vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL,
                vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                vk::AccessFlags::MEMORY_WRITE,
                vk::AccessFlags::TRANSFER_READ,
            )],
        );
        ctx.device.cmd_copy_image_to_buffer(
            cmd,
            image,
            vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
            buffer,
            &[region],
        );
        ctx.device.cmd_pipeline_barrier(
            cmd,
            vk::PipelineStageFlags::TRANSFER,
            vk::PipelineStageFlags::ALL_COMMANDS,
            vk::DependencyFlags::empty(),
            &[],
            &[],
            &[barrier(
                vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL,
                vk::AccessFlags::TRANSFER_READ,
                vk::AccessFlags::MEMORY_READ | vk::AccessFlags::MEMORY_WRITE,
            )],
        );
        let host_barrier = vk::MemoryBarrier::default()
            .src_access_mask(vk::AccessFlags::TRANSFER_WRITE)
            .dst_access_mask(vk::AccessFlags::HOST_READ);
        ctx.device.cmd_pipeline_barrier(
            cmd,
            vk::PipelineStageFlags::TRANSFER,
            vk::PipelineStageFlags::HOST,
            vk::DependencyFlags::empty(),
            &[host_barrier],
            &[],
            &[],
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn half_floats_decode() {
        assert_eq!(f16_to_f32(0x3c00), 1.0);
        assert_eq!(f16_to_f32(0x3800), 0.5);
        assert_eq!(f16_to_f32(0xc000), -2.0);
        assert_eq!(f16_to_f32(0x0000), 0.0);
        assert!(f16_to_f32(0x7e00).is_nan());
    }

    #[test]
    fn srgb_encoding_matches_reference_points() {
        assert_eq!(linear_to_srgb8(0.0), 0);
        assert_eq!(linear_to_srgb8(1.0), 255);
        assert_eq!(linear_to_srgb8(0.5), 188); // 0.7354 * 255
        assert_eq!(linear_to_srgb8(0.18), 118); // photographic mid-grey
        assert_eq!(linear_to_srgb8(f32::NAN), 0);
        assert_eq!(linear_to_srgb8(7.0), 255);
    }

    #[test]
    fn bgra_is_swizzled_and_alpha_dropped() {
        assert_eq!(to_rgb8(B8G8R8A8_SRGB, &[1, 2, 3, 4]), vec![3, 2, 1]);
        assert_eq!(
            to_rgb8(R8G8B8A8_UNORM, &[1, 2, 3, 4, 5, 6, 7, 8]),
            vec![1, 2, 3, 5, 6, 7]
        );
        let half_one = 0x3c00u16.to_le_bytes();
        let texel = [half_one, [0, 0], half_one, half_one].concat();
        assert_eq!(to_rgb8(R16G16B16A16_SFLOAT, &texel), vec![255, 0, 255]);
    }
}
