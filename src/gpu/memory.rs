//! Buffers and storage images with gpu-allocator memory. Each holds an `Arc<GpuContext>` so
//! the context outlives every resource, and frees itself on drop.

use super::context::GpuContext;
use super::error::{GpuError, VkContext};
use super::owned::Pending;
use super::sync::{ImageTransition, Scope};
use ash::vk;
use gpu_allocator::vulkan::{Allocation, AllocationCreateDesc, AllocationScheme};
use gpu_allocator::MemoryLocation;
use std::sync::Arc;

/// An image made from `info`, bound to device-local memory of its own, counted against the
/// context's memory use (the bytes returned, which the owner releases with the allocation).
/// On any failure nothing is left behind: the image and the memory are freed here.
pub(super) fn bound_image(
    ctx: &Arc<GpuContext>,
    name: &str,
    info: &vk::ImageCreateInfo,
) -> Result<(vk::Image, Allocation, u64), GpuError> {
    let device = &ctx.device;
    // SAFETY: valid device and create info.
    let image = unsafe { device.create_image(info, None) }.vk("vkCreateImage")?;
    let image = Pending::new(device, image);
    let (allocation, counted) = image_memory(ctx, name, image.get())?;
    // SAFETY: the allocation satisfies the image's requirements.
    let bound =
        unsafe { device.bind_image_memory(image.get(), allocation.memory(), allocation.offset()) };
    if let Err(e) = bound {
        let _ = ctx.allocator().free(allocation);
        ctx.memory.release(counted, false);
        return Err(e).vk("vkBindImageMemory"); // the pending image is destroyed on return
    }
    Ok((image.keep(), allocation, counted))
}

/// Device-local memory for `image`, counted against the context's memory use (as the bytes
/// returned, which the owner releases with the allocation). The caller binds it.
fn image_memory(
    ctx: &Arc<GpuContext>,
    name: &str,
    image: vk::Image,
) -> Result<(Allocation, u64), GpuError> {
    // SAFETY: image from this device.
    let requirements = unsafe { ctx.device.get_image_memory_requirements(image) };
    ctx.memory.reserve(name, requirements.size, false)?;
    ctx.allocator()
        .allocate(&AllocationCreateDesc {
            name,
            requirements,
            location: MemoryLocation::GpuOnly,
            linear: false,
            allocation_scheme: AllocationScheme::GpuAllocatorManaged,
        })
        .map(|a| (a, requirements.size))
        .map_err(|e| {
            ctx.memory.release(requirements.size, false);
            allocation_error(name, requirements.size, e)
        })
}

fn allocation_error(what: &str, bytes: u64, e: gpu_allocator::AllocationError) -> GpuError {
    match e {
        gpu_allocator::AllocationError::OutOfMemory => GpuError::OutOfMemory {
            what: what.into(),
            bytes,
            detail: e.to_string(),
        },
        other => GpuError::Allocation {
            what: what.into(),
            detail: other.to_string(),
        },
    }
}

pub struct Buffer {
    pub(super) ctx: Arc<GpuContext>,
    pub(crate) buffer: vk::Buffer,
    allocation: Option<Allocation>,
    pub size: u64,
    /// (bytes, host-visible) counted against the context's memory use.
    counted: (u64, bool),
}

impl Buffer {
    pub fn new(
        ctx: &Arc<GpuContext>,
        name: &str,
        size: u64,
        usage: vk::BufferUsageFlags,
        location: MemoryLocation,
    ) -> Result<Self, GpuError> {
        // Zero-sized buffers are invalid in Vulkan; empty scene arrays get one 16-byte element.
        let size = size.max(16);
        let info = vk::BufferCreateInfo::default().size(size).usage(usage);
        let device = &ctx.device;
        // SAFETY: valid device and create info.
        let buffer = unsafe { device.create_buffer(&info, None) }.vk("vkCreateBuffer")?;
        let buffer = Pending::new(device, buffer);
        // SAFETY: buffer was created from this device.
        let requirements = unsafe { device.get_buffer_memory_requirements(buffer.get()) };
        let host_visible = location != MemoryLocation::GpuOnly;
        let allocation = ctx
            .memory
            .reserve(name, requirements.size, host_visible)
            .and_then(|()| {
                ctx.allocator()
                    .allocate(&AllocationCreateDesc {
                        name,
                        requirements,
                        location,
                        linear: true,
                        allocation_scheme: AllocationScheme::GpuAllocatorManaged,
                    })
                    .map_err(|e| {
                        ctx.memory.release(requirements.size, host_visible);
                        allocation_error(name, size, e)
                    })
            })?;
        // SAFETY: the allocation satisfies the buffer's requirements and is not bound elsewhere.
        let bound = unsafe {
            device.bind_buffer_memory(buffer.get(), allocation.memory(), allocation.offset())
        };
        // Built before the bind is checked so that drop frees both on failure.
        let this = Self {
            ctx: ctx.clone(),
            buffer: buffer.keep(),
            allocation: Some(allocation),
            size,
            counted: (requirements.size, host_visible),
        };
        bound.vk("vkBindBufferMemory")?;
        Ok(this)
    }

    /// A device-local storage buffer holding `data`, uploaded once through a staging buffer.
    pub fn with_data(ctx: &Arc<GpuContext>, name: &str, data: &[u8]) -> Result<Self, GpuError> {
        // Also a texel buffer: the scene's arrays are read through TexelView.
        let usage = vk::BufferUsageFlags::STORAGE_BUFFER
            | vk::BufferUsageFlags::UNIFORM_TEXEL_BUFFER
            | vk::BufferUsageFlags::TRANSFER_DST;
        let buffer = Self::new(ctx, name, data.len() as u64, usage, MemoryLocation::GpuOnly)?;
        if data.is_empty() {
            return Ok(buffer);
        }
        let mut staging = Self::new(
            ctx,
            &format!("{name} (staging)"),
            data.len() as u64,
            vk::BufferUsageFlags::TRANSFER_SRC,
            MemoryLocation::CpuToGpu,
        )?;
        staging.write(0, data)?;
        let region = [vk::BufferCopy::default().size(data.len() as u64)];
        ctx.submit_and_wait(&format!("upload {name}"), |cmd| {
            // SAFETY: both buffers are alive until the wait returns; sizes match the region.
            unsafe {
                ctx.device
                    .cmd_copy_buffer(cmd, staging.buffer, buffer.buffer, &region)
            };
        })?;
        Ok(buffer)
    }

    /// The buffer's GPU address (it needs SHADER_DEVICE_ADDRESS usage, and the context ray
    /// queries, which enable buffer device addresses).
    pub(crate) fn device_address(&self) -> vk::DeviceAddress {
        let info = vk::BufferDeviceAddressInfo::default().buffer(self.buffer);
        // SAFETY: the buffer is alive, created with SHADER_DEVICE_ADDRESS usage by its caller,
        // and bound to memory allocated with the device-address flag (see GpuContext).
        unsafe { self.ctx.device.get_buffer_device_address(&info) }
    }

    /// Host-visible buffers only: copies `data` at `offset`.
    pub fn write(&mut self, offset: usize, data: &[u8]) -> Result<(), GpuError> {
        let slice = self
            .allocation
            .as_mut()
            .and_then(|a| a.mapped_slice_mut())
            .ok_or_else(|| GpuError::Limit("buffer is not host-visible".into()))?;
        slice
            .get_mut(offset..offset + data.len())
            .ok_or_else(|| GpuError::Limit("write past the end of a buffer".into()))?
            .copy_from_slice(data);
        Ok(())
    }

    /// Host-visible buffers only: the mapped bytes.
    pub fn read(&self) -> Result<&[u8], GpuError> {
        self.allocation
            .as_ref()
            .and_then(|a| a.mapped_slice())
            .ok_or_else(|| GpuError::Limit("buffer is not host-visible".into()))
    }

    /// Records filling the first `bytes` bytes with zeros (the buffer needs TRANSFER_DST).
    pub fn cmd_zero(&self, cmd: vk::CommandBuffer, bytes: u64) {
        // SAFETY: cmd is recording; the buffer is alive until the submission completes.
        unsafe {
            self.ctx
                .device
                .cmd_fill_buffer(cmd, self.buffer, 0, bytes, 0)
        };
    }

    /// Copies the whole buffer (made with TRANSFER_SRC usage, last written by compute shaders)
    /// to the host, through a staging buffer.
    pub fn read_back(&self) -> Result<Vec<u8>, GpuError> {
        let staging = Buffer::new(
            &self.ctx,
            "buffer read-back",
            self.size,
            vk::BufferUsageFlags::TRANSFER_DST,
            MemoryLocation::GpuToCpu,
        )?;
        self.ctx.submit_and_wait("buffer read-back", |cmd| {
            self.ctx
                .cmd_barrier(cmd, Scope::COMPUTE_WRITE, Scope::COPY_READ);
            self.cmd_copy_to(cmd, &staging, self.size);
            self.ctx
                .cmd_barrier(cmd, Scope::COPY_WRITE, Scope::HOST_READ);
        })?;
        Ok(staging.read()?.to_vec())
    }

    /// Records copying the first `bytes` bytes into `to` (TRANSFER_SRC here, TRANSFER_DST there).
    pub fn cmd_copy_to(&self, cmd: vk::CommandBuffer, to: &Buffer, bytes: u64) {
        let region = [vk::BufferCopy::default().size(bytes)];
        // SAFETY: cmd is recording; both buffers are alive until the submission completes.
        unsafe {
            self.ctx
                .device
                .cmd_copy_buffer(cmd, self.buffer, to.buffer, &region)
        };
    }
}

impl Drop for Buffer {
    fn drop(&mut self) {
        if let Some(allocation) = self.allocation.take() {
            let _ = self.ctx.allocator().free(allocation);
            self.ctx.memory.release(self.counted.0, self.counted.1);
        }
        // SAFETY: users wait for the GPU before dropping the resources they used.
        unsafe { self.ctx.device.destroy_buffer(self.buffer, None) };
    }
}

/// An RGBA32F storage image: a frame (`new`, a 2D view) or a stack of equally sized layer
/// images (`new_array`, a 2D-array view).
pub struct StorageImage {
    ctx: Arc<GpuContext>,
    pub(crate) image: vk::Image,
    pub(crate) view: vk::ImageView,
    allocation: Option<Allocation>,
    /// Bytes counted against the context's memory use.
    counted: u64,
    pub width: u32,
    pub height: u32,
    pub layers: u32,
}

impl StorageImage {
    pub const FORMAT: vk::Format = vk::Format::R32G32B32A32_SFLOAT;

    pub fn new(
        ctx: &Arc<GpuContext>,
        name: &str,
        width: u32,
        height: u32,
    ) -> Result<Self, GpuError> {
        Self::create(ctx, name, width, height, 1, vk::ImageViewType::TYPE_2D)
    }

    /// `layers` images of `width × height` behind one 2D-array view.
    pub fn new_array(
        ctx: &Arc<GpuContext>,
        name: &str,
        width: u32,
        height: u32,
        layers: u32,
    ) -> Result<Self, GpuError> {
        Self::create(
            ctx,
            name,
            width,
            height,
            layers,
            vk::ImageViewType::TYPE_2D_ARRAY,
        )
    }

    fn create(
        ctx: &Arc<GpuContext>,
        name: &str,
        width: u32,
        height: u32,
        layers: u32,
        view_type: vk::ImageViewType,
    ) -> Result<Self, GpuError> {
        let info = vk::ImageCreateInfo::default()
            .image_type(vk::ImageType::TYPE_2D)
            .format(Self::FORMAT)
            .extent(vk::Extent3D {
                width,
                height,
                depth: 1,
            })
            .mip_levels(1)
            .array_layers(layers)
            .samples(vk::SampleCountFlags::TYPE_1)
            .tiling(vk::ImageTiling::OPTIMAL)
            .usage(
                vk::ImageUsageFlags::STORAGE
                    | vk::ImageUsageFlags::TRANSFER_SRC
                    | vk::ImageUsageFlags::TRANSFER_DST,
            )
            .initial_layout(vk::ImageLayout::UNDEFINED);
        let device = &ctx.device;
        let (image, allocation, counted) = bound_image(ctx, name, &info)?;
        // Owned from here: drop frees the image and its memory if the view fails.
        let mut this = Self {
            ctx: ctx.clone(),
            image,
            view: vk::ImageView::null(),
            allocation: Some(allocation),
            counted,
            width,
            height,
            layers,
        };
        let view_info = vk::ImageViewCreateInfo::default()
            .image(image)
            .view_type(view_type)
            .format(Self::FORMAT)
            .subresource_range(color_range());
        // SAFETY: the image is bound to memory.
        this.view =
            unsafe { device.create_image_view(&view_info, None) }.vk("vkCreateImageView")?;
        Ok(this)
    }

    /// Records a transition from UNDEFINED to GENERAL (contents discarded) for compute writes,
    /// after whatever used the image before (an earlier frame's passes, its read-back, a blit
    /// of it into a swapchain image, an upload).
    pub(crate) fn cmd_prepare_for_write(&self, cmd: vk::CommandBuffer) {
        self.cmd_transition(cmd, (EARLIER_USES, UNDEFINED), COMPUTE_WRITING);
    }

    /// Records replacing the image (one layer) with `tiles` equal parts side by side, which
    /// `src` holds one after another, each as rows of `width / tiles` RGBA f32 pixels (a
    /// frame's eyes as resolve writes them). `src` must be complete (its writers ordered before
    /// with a COPY_READ barrier). Leaves the image in GENERAL layout, its pixels visible to
    /// every later compute pass, copy and blit.
    pub(crate) fn cmd_copy_tiles_from(&self, cmd: vk::CommandBuffer, src: &Buffer, tiles: u32) {
        let tile_width = self.width / tiles.max(1);
        let regions: Vec<vk::BufferImageCopy> = (0..tiles)
            .map(|t| {
                vk::BufferImageCopy::default()
                    .buffer_offset(t as u64 * tile_width as u64 * self.height as u64 * 16)
                    .image_subresource(vk::ImageSubresourceLayers {
                        aspect_mask: vk::ImageAspectFlags::COLOR,
                        mip_level: 0,
                        base_array_layer: 0,
                        layer_count: 1,
                    })
                    .image_offset(vk::Offset3D {
                        x: (t * tile_width) as i32,
                        y: 0,
                        z: 0,
                    })
                    .image_extent(vk::Extent3D {
                        width: tile_width,
                        height: self.height,
                        depth: 1,
                    })
            })
            .collect();
        let copying = (Scope::COPY_WRITE, GENERAL);
        self.cmd_transition(cmd, (EARLIER_USES, UNDEFINED), copying);
        // SAFETY: cmd is recording; the image (GENERAL layout, which copies may write) and the
        // buffer live until the submission completes; the regions lie inside both.
        unsafe {
            self.ctx
                .device
                .cmd_copy_buffer_to_image(cmd, src.buffer, self.image, GENERAL, &regions)
        };
        self.cmd_transition(cmd, copying, (LATER_USES, GENERAL));
    }

    /// Records a layout transition of the whole image between two (accesses, layout)s.
    fn cmd_transition(&self, cmd: vk::CommandBuffer, from: Use, to: Use) {
        self.ctx.cmd_image_barriers(
            cmd,
            &[ImageTransition {
                image: self.image,
                range: color_range(),
                from,
                to,
            }],
        );
    }

    /// Copies the image (in GENERAL layout after compute writes) to the host: RGBA f32 rows,
    /// layer after layer.
    pub fn read_back(&self) -> Result<Vec<f32>, GpuError> {
        let bytes = self.width as u64 * self.height as u64 * 16 * self.layers as u64;
        let staging = Buffer::new(
            &self.ctx,
            "image readback",
            bytes,
            vk::BufferUsageFlags::TRANSFER_DST,
            MemoryLocation::GpuToCpu,
        )?;
        let copying = (Scope::COPY_READ, SRC);
        self.ctx.submit_and_wait("readback", |cmd| {
            self.cmd_transition(cmd, COMPUTE_WRITING, copying);
            // SAFETY: cmd is recording; the image and staging buffer live until the wait returns.
            unsafe {
                self.ctx.device.cmd_copy_image_to_buffer(
                    cmd,
                    self.image,
                    SRC,
                    staging.buffer,
                    &self.whole_copy(),
                )
            };
            // Back to GENERAL for the next frame's compute passes, after the copy has read it.
            self.cmd_transition(cmd, copying, COMPUTE_WRITING);
            // The copied rows, read by the host after the fence.
            self.ctx
                .cmd_barrier(cmd, Scope::COPY_WRITE, Scope::HOST_READ);
        })?;
        Ok(bytemuck::pod_collect_to_vec(staging.read()?))
    }

    /// A buffer ↔ image copy of every layer, rows packed.
    fn whole_copy(&self) -> [vk::BufferImageCopy; 1] {
        [vk::BufferImageCopy::default()
            .image_subresource(vk::ImageSubresourceLayers {
                aspect_mask: vk::ImageAspectFlags::COLOR,
                mip_level: 0,
                base_array_layer: 0,
                layer_count: self.layers,
            })
            .image_extent(vk::Extent3D {
                width: self.width,
                height: self.height,
                depth: 1,
            })]
    }

    /// Replaces the whole image (all layers, RGBA f32 rows) with `rgba` and leaves it in
    /// GENERAL layout for compute reads and writes.
    pub fn upload(&self, rgba: &[f32]) -> Result<(), GpuError> {
        let expected = self.width as usize * self.height as usize * 4 * self.layers as usize;
        if rgba.len() != expected {
            return Err(GpuError::Limit(format!(
                "image upload of {} floats into a {}x{}x{} RGBA image ({expected} floats)",
                rgba.len(),
                self.width,
                self.height,
                self.layers
            )));
        }
        let mut staging = Buffer::new(
            &self.ctx,
            "image upload",
            (rgba.len() * 4) as u64,
            vk::BufferUsageFlags::TRANSFER_SRC,
            MemoryLocation::CpuToGpu,
        )?;
        staging.write(0, bytemuck::cast_slice(rgba))?;
        let copying = (Scope::COPY_WRITE, DST);
        self.ctx.submit_and_wait("upload", |cmd| {
            self.cmd_transition(cmd, (Scope::NOTHING, UNDEFINED), copying);
            // SAFETY: cmd is recording; the image and staging buffer live until the wait returns.
            unsafe {
                self.ctx.device.cmd_copy_buffer_to_image(
                    cmd,
                    staging.buffer,
                    self.image,
                    DST,
                    &self.whole_copy(),
                )
            };
            self.cmd_transition(cmd, copying, (Scope::COMPUTE_READ_WRITE, GENERAL));
        })?;
        Ok(())
    }
}

/// The accesses on one side of a layout transition and the layout they need.
type Use = (Scope, vk::ImageLayout);
/// Compute passes writing the image in GENERAL layout (what a frame's passes do).
const COMPUTE_WRITING: Use = (Scope::COMPUTE_WRITE, GENERAL);
/// Every way fovea uses a storage image: compute passes, copies and blits (its writes, which
/// a layout transition must follow; reads need only the execution dependency).
const EARLIER_USES: Scope = Scope::COMPUTE_WRITE
    .and(Scope::COPY_WRITE)
    .and(Scope::BLIT_READ);
/// Everything that reads or writes a frame image after it was filled (accumulation, read-
/// backs, blits into swapchain images).
const LATER_USES: Scope = Scope::COMPUTE_READ_WRITE
    .and(Scope::COPY_READ)
    .and(Scope::BLIT_READ);
const UNDEFINED: vk::ImageLayout = vk::ImageLayout::UNDEFINED;
const GENERAL: vk::ImageLayout = vk::ImageLayout::GENERAL;
const SRC: vk::ImageLayout = vk::ImageLayout::TRANSFER_SRC_OPTIMAL;
const DST: vk::ImageLayout = vk::ImageLayout::TRANSFER_DST_OPTIMAL;

fn color_range() -> vk::ImageSubresourceRange {
    vk::ImageSubresourceRange {
        aspect_mask: vk::ImageAspectFlags::COLOR,
        base_mip_level: 0,
        level_count: 1,
        base_array_layer: 0,
        layer_count: vk::REMAINING_ARRAY_LAYERS,
    }
}

impl Drop for StorageImage {
    fn drop(&mut self) {
        // SAFETY: users wait for the GPU before dropping; view before image before memory.
        unsafe {
            if self.view != vk::ImageView::null() {
                self.ctx.device.destroy_image_view(self.view, None);
            }
            self.ctx.device.destroy_image(self.image, None);
        }
        if let Some(allocation) = self.allocation.take() {
            let _ = self.ctx.allocator().free(allocation);
            self.ctx.memory.release(self.counted, false);
        }
    }
}
