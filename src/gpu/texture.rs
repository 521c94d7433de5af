//! Sampled textures: RGBA8 mip chains uploaded once, left in SHADER_READ_ONLY_OPTIMAL layout,
//! each with its sampler, bound together as one array of combined image samplers
//! (shared.h's BINDING_TEXTURES, partially bound: a scene without textures binds none).

use super::context::GpuContext;
use super::error::{GpuError, VkContext};
use super::memory::{bound_image, Buffer};
use super::sync::{ImageTransition, Scope};
use ash::vk;
use gpu_allocator::vulkan::Allocation;
use gpu_allocator::MemoryLocation;
use std::sync::Arc;

/// One mip level: its size and its RGBA8 texels, rows from the top.
pub struct MipLevel {
    pub width: u32,
    pub height: u32,
    pub rgba8: Vec<u8>,
}

/// A texture to upload: its levels (finest first), how its texels are read, its sampler.
pub struct TextureUpload {
    pub name: String,
    pub levels: Vec<MipLevel>,
    /// R8G8B8A8_SRGB (colours) or R8G8B8A8_UNORM (data).
    pub srgb: bool,
    pub sampler: SamplerDesc,
}

/// A sampler's wrap modes and filters.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct SamplerDesc {
    pub address_u: vk::SamplerAddressMode,
    pub address_v: vk::SamplerAddressMode,
    pub mag: vk::Filter,
    pub min: vk::Filter,
    /// Between mip levels (the level itself comes from the shader's explicit LOD).
    pub mipmap: vk::SamplerMipmapMode,
    /// The finest level only (glTF's non-mipmap minification filters).
    pub level_0_only: bool,
}

/// One uploaded texture: image, view and sampler.
struct SampledImage {
    ctx: Arc<GpuContext>,
    image: vk::Image,
    view: vk::ImageView,
    sampler: vk::Sampler,
    allocation: Option<Allocation>,
    counted: u64,
}

/// Every texture of a scene, in its order.
pub struct TextureSet {
    images: Vec<SampledImage>,
}

impl TextureSet {
    /// Uploads `textures` (one submission, waited for).
    pub fn upload(ctx: &Arc<GpuContext>, textures: &[TextureUpload]) -> Result<Self, GpuError> {
        let images = textures
            .iter()
            .map(|t| SampledImage::new(ctx, t))
            .collect::<Result<Vec<_>, _>>()?;
        let staged: Vec<u8> = textures
            .iter()
            .flat_map(|t| t.levels.iter().flat_map(|l| l.rgba8.iter().copied()))
            .collect();
        if !staged.is_empty() {
            let mut staging = Buffer::new(
                ctx,
                "texture upload",
                staged.len() as u64,
                vk::BufferUsageFlags::TRANSFER_SRC,
                MemoryLocation::CpuToGpu,
            )?;
            staging.write(0, &staged)?;
            ctx.submit_and_wait("texture upload", |cmd| {
                let mut offset = 0u64;
                for (image, t) in images.iter().zip(textures) {
                    image.cmd_upload(cmd, &staging, offset, &t.levels);
                    offset += t.levels.iter().map(|l| l.rgba8.len() as u64).sum::<u64>();
                }
            })?;
        }
        Ok(Self { images })
    }

    pub fn is_empty(&self) -> bool {
        self.images.is_empty()
    }

    /// (view, sampler) per texture, for the descriptor writes.
    pub(crate) fn descriptors(&self) -> Vec<vk::DescriptorImageInfo> {
        self.images
            .iter()
            .map(|i| {
                vk::DescriptorImageInfo::default()
                    .image_view(i.view)
                    .sampler(i.sampler)
                    .image_layout(vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL)
            })
            .collect()
    }

    /// A number that stands for the set in the frame graph's access tracking (it is never
    /// written after the upload, so no pass waits for it).
    pub(crate) fn resource(&self) -> u64 {
        use ash::vk::Handle;
        self.images.first().map_or(0, |i| i.image.as_raw())
    }
}

/// The bytes of every level of an RGBA8 texture of `width × height` with `levels` levels
/// (each half the one before, rounded down, at least 1): what the memory plan counts.
pub fn mip_chain_bytes(width: u32, height: u32, levels: u32) -> u64 {
    (0..levels)
        .map(|l| 4 * (width >> l).max(1) as u64 * (height >> l).max(1) as u64)
        .sum()
}

impl SampledImage {
    fn new(ctx: &Arc<GpuContext>, t: &TextureUpload) -> Result<Self, GpuError> {
        let format = if t.srgb {
            vk::Format::R8G8B8A8_SRGB
        } else {
            vk::Format::R8G8B8A8_UNORM
        };
        let base = &t.levels[0];
        let info = vk::ImageCreateInfo::default()
            .image_type(vk::ImageType::TYPE_2D)
            .format(format)
            .extent(vk::Extent3D {
                width: base.width,
                height: base.height,
                depth: 1,
            })
            .mip_levels(t.levels.len() as u32)
            .array_layers(1)
            .samples(vk::SampleCountFlags::TYPE_1)
            .tiling(vk::ImageTiling::OPTIMAL)
            .usage(vk::ImageUsageFlags::SAMPLED | vk::ImageUsageFlags::TRANSFER_DST)
            .initial_layout(vk::ImageLayout::UNDEFINED);
        let (image, allocation, counted) = bound_image(ctx, &t.name, &info)?;
        // Owned from here: drop frees the image and its memory if the view or sampler fails.
        let mut this = Self {
            ctx: ctx.clone(),
            image,
            view: vk::ImageView::null(),
            sampler: vk::Sampler::null(),
            allocation: Some(allocation),
            counted,
        };
        this.view = view(ctx, image, format, t.levels.len() as u32)?;
        this.sampler = sampler(ctx, &t.sampler, t.levels.len() as u32)?;
        Ok(this)
    }

    /// Records copying every level from `staging` (from `offset`, levels one after another)
    /// and leaving the image readable by compute shaders.
    fn cmd_upload(
        &self,
        cmd: vk::CommandBuffer,
        staging: &Buffer,
        offset: u64,
        levels: &[MipLevel],
    ) {
        let range = levels_range(levels.len() as u32);
        let transition = |from, to| ImageTransition {
            image: self.image,
            range,
            from,
            to,
        };
        let dst = vk::ImageLayout::TRANSFER_DST_OPTIMAL;
        self.ctx.cmd_image_barriers(
            cmd,
            &[transition(
                (Scope::NOTHING, vk::ImageLayout::UNDEFINED),
                (Scope::COPY_WRITE, dst),
            )],
        );
        let mut at = offset;
        let regions: Vec<vk::BufferImageCopy> = (levels.iter().enumerate())
            .map(|(mip, l)| {
                let region = vk::BufferImageCopy::default()
                    .buffer_offset(at)
                    .image_subresource(vk::ImageSubresourceLayers {
                        aspect_mask: vk::ImageAspectFlags::COLOR,
                        mip_level: mip as u32,
                        base_array_layer: 0,
                        layer_count: 1,
                    })
                    .image_extent(vk::Extent3D {
                        width: l.width,
                        height: l.height,
                        depth: 1,
                    });
                at += l.rgba8.len() as u64;
                region
            })
            .collect();
        // SAFETY: cmd is recording; the image (TRANSFER_DST_OPTIMAL) and the staging buffer
        // live until the submission completes; every region lies inside both.
        unsafe {
            self.ctx
                .device
                .cmd_copy_buffer_to_image(cmd, staging.buffer, self.image, dst, &regions)
        };
        self.ctx.cmd_image_barriers(
            cmd,
            &[transition(
                (Scope::COPY_WRITE, dst),
                (
                    Scope::COMPUTE_READ,
                    vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL,
                ),
            )],
        );
    }
}

/// A 2D view of all `levels` of `image`.
fn view(
    ctx: &GpuContext,
    image: vk::Image,
    format: vk::Format,
    levels: u32,
) -> Result<vk::ImageView, GpuError> {
    let info = vk::ImageViewCreateInfo::default()
        .image(image)
        .view_type(vk::ImageViewType::TYPE_2D)
        .format(format)
        .subresource_range(levels_range(levels));
    // SAFETY: the image is bound to memory.
    unsafe { ctx.device.create_image_view(&info, None) }.vk("vkCreateImageView")
}

/// The sampler of `desc` over `levels` mip levels (level 0 alone without mipmaps).
fn sampler(ctx: &GpuContext, desc: &SamplerDesc, levels: u32) -> Result<vk::Sampler, GpuError> {
    let max_lod = if desc.level_0_only {
        0.0
    } else {
        levels as f32
    };
    let info = vk::SamplerCreateInfo::default()
        .mag_filter(desc.mag)
        .min_filter(desc.min)
        .mipmap_mode(desc.mipmap)
        .address_mode_u(desc.address_u)
        .address_mode_v(desc.address_v)
        .address_mode_w(vk::SamplerAddressMode::REPEAT)
        .min_lod(0.0)
        .max_lod(max_lod);
    // SAFETY: valid device and create info.
    unsafe { ctx.device.create_sampler(&info, None) }.vk("vkCreateSampler")
}

fn levels_range(levels: u32) -> vk::ImageSubresourceRange {
    vk::ImageSubresourceRange {
        aspect_mask: vk::ImageAspectFlags::COLOR,
        base_mip_level: 0,
        level_count: levels,
        base_array_layer: 0,
        layer_count: 1,
    }
}

impl Drop for SampledImage {
    fn drop(&mut self) {
        // SAFETY: users wait for the GPU before dropping; sampler and view before image
        // before memory.
        unsafe {
            let d = &self.ctx.device;
            if self.sampler != vk::Sampler::null() {
                d.destroy_sampler(self.sampler, None);
            }
            if self.view != vk::ImageView::null() {
                d.destroy_image_view(self.view, None);
            }
            d.destroy_image(self.image, None);
        }
        if let Some(allocation) = self.allocation.take() {
            let _ = self.ctx.allocator().free(allocation);
            self.ctx.memory.release(self.counted, false);
        }
    }
}
