//! GPU resources of one (layer config, resolution, eyes' fields of view): the ray buffer,
//! built and uploaded once; a full-size image per eye and layer; the merged output; and the
//! small host-visible buffers the CPU rewrites every frame (spans and layer parameters).

use super::RenderError;
use crate::foveation::{EyeFov, FoveationConfig, ImageGeometry, RayBuffer};
use crate::gpu::shared::{GpuLayer, GpuSpan};
use crate::gpu::{vk, Buffer, GpuContext, PlannedAllocation, StorageImage};
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

/// Room in the span buffer for this many spans before a frame has to grow it.
const INITIAL_SPANS: u64 = 4096;

/// What to change when a frame's targets do not fit the device.
const ADVICE: &str = "use a smaller --width/--height, mono instead of --stereo, or fewer \
     layers";

impl TargetKey {
    /// The frame these targets are for, for messages: "the frame targets of a 512x512 stereo
    /// frame with 4 layers".
    pub fn describe(&self) -> String {
        let eyes = match self.fovs.len() {
            1 => "mono".to_owned(),
            2 => "stereo".to_owned(),
            n => format!("{n}-eye"),
        };
        let layers = self.config.layers.len();
        format!(
            "the frame targets of a {}x{} {eyes} frame with {layers} layer{}",
            self.width,
            self.height,
            if layers == 1 { "" } else { "s" }
        )
    }

    /// Every allocation of [`FrameTargets::new`] but the ray buffer (whose size is known only
    /// once it is built), plus the read-back of the frame: cheap to compute, so a frame far
    /// too large for the device is refused before the ray buffer is built.
    pub fn image_plan(&self) -> Vec<PlannedAllocation> {
        let (w, h) = (self.width as u64, self.height as u64);
        let eyes = self.fovs.len() as u64;
        let layers = self.config.layers.len() as u64;
        let texel = 16; // RGBA32F, StorageImage::FORMAT
        vec![
            PlannedAllocation::image("layer images", w * h * texel * eyes * layers),
            PlannedAllocation::image("frame image", w * eyes * h * texel),
            PlannedAllocation::host("frame read-back", w * eyes * h * texel, false),
            PlannedAllocation::host(
                "frame layers",
                eyes * layers * std::mem::size_of::<GpuLayer>() as u64,
                true,
            ),
            PlannedAllocation::host(
                "frame spans",
                INITIAL_SPANS * std::mem::size_of::<GpuSpan>() as u64,
                true,
            ),
        ]
    }

    /// Checks that the targets' images fit the device beside what fovea already holds.
    pub fn check_images(&self, ctx: &GpuContext) -> Result<(), RenderError> {
        Ok(ctx.check_memory(&self.describe(), &self.image_plan(), ADVICE)?)
    }
}

impl FrameTargets {
    /// Builds the ray buffer, checks that everything fits the device (sizes, per-buffer and
    /// per-allocation limits) and only then allocates.
    pub fn new(ctx: &Arc<GpuContext>, key: TargetKey) -> Result<Self, RenderError> {
        key.check_images(ctx)?;
        let images: Vec<ImageGeometry> = key
            .fovs
            .iter()
            .map(|f| ImageGeometry::new(key.width, key.height, *f))
            .collect();
        let buffer = RayBuffer::build(&key.config, &images);
        let eyes = images.len() as u32;
        let layer_count = buffer.layers.len() as u32;
        // The ray buffer's upload staging is freed before the images are allocated, so it is
        // not part of the peak; the allocation itself is still checked against any limit.
        let mut plan = key.image_plan();
        plan.push(PlannedAllocation::storage(
            "ray buffer",
            std::mem::size_of_val(buffer.offsets.as_slice()) as u64,
        ));
        ctx.check_memory(&key.describe(), &plan, ADVICE)?;
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
            INITIAL_SPANS * std::mem::size_of::<GpuSpan>() as u64,
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
