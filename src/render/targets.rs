//! GPU resources of one (layer config, resolution, eyes' fields of view): the ray buffer,
//! built and uploaded once; a full-size image per eye and layer; the merged output; and the
//! small host-visible buffers the CPU rewrites every frame (spans and layer parameters).

use super::RenderError;
use crate::foveation::{EyeFov, FoveationConfig, ImageGeometry, RayBuffer};
use crate::gpu::shared::{GpuLayer, GpuSpan};
use crate::gpu::{vk, Buffer, GpuContext, StorageImage};
use gpu_allocator::MemoryLocation;
use std::sync::Arc;

/// What the targets were built for; a frame asking for anything else rebuilds them.
#[derive(Clone, Debug, PartialEq)]
pub struct TargetKey {
    pub config: FoveationConfig,
    pub width: u32,
    pub height: u32,
    pub fovs: Vec<EyeFov>,
}

pub struct FrameTargets {
    pub key: TargetKey,
    pub buffer: RayBuffer,
    pub images: Vec<ImageGeometry>,
    pub ray_buffer: Buffer,
    pub layer_images: StorageImage,
    pub output: StorageImage,
    pub spans: Buffer,
    pub layers: Buffer,
}

fn host_buffer(ctx: &Arc<GpuContext>, name: &str, bytes: u64) -> Result<Buffer, RenderError> {
    Ok(Buffer::new(
        ctx,
        name,
        bytes.max(16),
        vk::BufferUsageFlags::STORAGE_BUFFER,
        MemoryLocation::CpuToGpu,
    )?)
}

impl FrameTargets {
    pub fn new(ctx: &Arc<GpuContext>, key: TargetKey) -> Result<Self, RenderError> {
        let images: Vec<ImageGeometry> = key
            .fovs
            .iter()
            .map(|f| ImageGeometry::new(key.width, key.height, *f))
            .collect();
        let buffer = RayBuffer::build(&key.config, &images);
        let eyes = images.len() as u32;
        let layer_count = buffer.layers.len() as u32;
        let limit = ctx.info.max_storage_buffer_range;
        let bytes = std::mem::size_of_val(buffer.offsets.as_slice()) as u64;
        if bytes > limit {
            return Err(RenderError::Settings(format!(
                "the ray buffer for this layer config at {}x{} needs {bytes} bytes but the device allows {limit} per buffer; use fewer or coarser layers or a smaller image",
                key.width, key.height
            )));
        }
        let ray_buffer =
            Buffer::with_data(ctx, "ray buffer", bytemuck::cast_slice(&buffer.offsets))?;
        let layer_images = StorageImage::new_array(
            ctx,
            "layer images",
            key.width,
            key.height,
            eyes * layer_count,
        )?;
        let output = StorageImage::new(ctx, "frame", key.width * eyes, key.height)?;
        let layers = host_buffer(
            ctx,
            "frame layers",
            (eyes * layer_count) as u64 * std::mem::size_of::<GpuLayer>() as u64,
        )?;
        let spans = host_buffer(
            ctx,
            "frame spans",
            4096 * std::mem::size_of::<GpuSpan>() as u64,
        )?;
        Ok(Self {
            key,
            buffer,
            images,
            ray_buffer,
            layer_images,
            output,
            spans,
            layers,
        })
    }

    /// Writes this frame's spans and layers, growing the span buffer when a frame needs more.
    pub fn write_frame(
        &mut self,
        ctx: &Arc<GpuContext>,
        spans: &[GpuSpan],
        layers: &[GpuLayer],
    ) -> Result<(), RenderError> {
        let span_bytes: &[u8] = bytemuck::cast_slice(spans);
        if span_bytes.len() as u64 > self.spans.size {
            self.spans = host_buffer(ctx, "frame spans", span_bytes.len() as u64 * 2)?;
        }
        self.spans.write(0, span_bytes)?;
        self.layers.write(0, bytemuck::cast_slice(layers))?;
        Ok(())
    }
}
