//! Uniform texel buffer views of buffers: the whole of one (the scene's arrays, a frame's
//! pixels), or one per eye of a frame's lattice (`EyeTexels`).

use super::context::GpuContext;
use super::error::{GpuError, VkContext};
use super::memory::Buffer;
use ash::vk;
use std::sync::Arc;

/// A buffer, or one eye's part of it ([`EyeTexels`]), seen as a uniform texel buffer of
/// RGBA32UI texels (`utextureBuffer` in GLSL). Lavapipe fetches a 16-byte texel per lane with one
/// vector load, where it splits a storage-buffer `uvec4` load into four bounds-checked scalar
/// loads per lane: the scene's arrays and the lattice values go this way.
pub struct TexelView {
    ctx: Arc<GpuContext>,
    pub(crate) view: vk::BufferView,
    /// The buffer it views (the memory a pass reading the view accesses).
    pub(crate) buffer: vk::Buffer,
}

impl TexelView {
    /// A view of one of the scene's arrays.
    pub fn new(buffer: &Buffer, what: &str) -> Result<Self, GpuError> {
        Self::with_fix(buffer, what, "simplify the scene (fewer or smaller meshes)")
    }

    /// A view of a buffer sized by the frame (pixels, lattice points).
    pub fn of_frame(buffer: &Buffer, what: &str) -> Result<Self, GpuError> {
        Self::with_fix(buffer, what, "use a smaller --width/--height")
    }

    fn with_fix(buffer: &Buffer, what: &str, fix: &str) -> Result<Self, GpuError> {
        Self::part(buffer, what, fix, 0, buffer.size / 16)
    }

    /// A view of texels `first..first + count` of `buffer`.
    fn part(
        buffer: &Buffer,
        what: &str,
        fix: &str,
        first: u64,
        count: u64,
    ) -> Result<Self, GpuError> {
        let ctx = &buffer.ctx;
        let limit = ctx.info.max_texel_buffer_elements;
        if count > limit {
            return Err(GpuError::Limit(format!(
                "{what}: {count} 16-byte texels, more than this device's \
                 maxTexelBufferElements ({limit}); {fix}"
            )));
        }
        let (offset, range) = (first * 16, count * 16);
        let alignment = ctx.info.min_texel_buffer_offset_alignment.max(1);
        if offset % alignment != 0 || offset + range > buffer.size {
            return Err(GpuError::Limit(format!(
                "{what}: a texel view of bytes {offset}..{} of a {}-byte buffer (views start at \
                 multiples of {alignment} bytes); this is a bug in fovea",
                offset + range,
                buffer.size
            )));
        }
        let info = vk::BufferViewCreateInfo::default()
            .buffer(buffer.buffer)
            .format(vk::Format::R32G32B32A32_UINT)
            .offset(offset)
            .range(range);
        // SAFETY: the buffer was created with UNIFORM_TEXEL_BUFFER usage, R32G32B32A32_UINT
        // supports it on every Vulkan device, and the range lies inside the buffer, starting
        // at a multiple of minTexelBufferOffsetAlignment (both checked above).
        let view =
            unsafe { ctx.device.create_buffer_view(&info, None) }.vk("vkCreateBufferView")?;
        Ok(Self {
            ctx: ctx.clone(),
            view,
            buffer: buffer.buffer,
        })
    }
}

/// One texel view per eye of a frame-sized buffer whose eyes' parts lie `stride` texels apart
/// (the lattice's values and surfaces). Each view spans one eye's part, so
/// maxTexelBufferElements bounds one eye's lattice, not the whole frame's; shaders index the
/// array by the dispatch's eye (shared.h's EYE_TEXEL_VIEWS).
pub struct EyeTexels {
    pub(crate) views: Vec<TexelView>,
}

impl EyeTexels {
    /// Views of `eyes` parts of `stride` texels each; `stride * 16` must be a multiple of
    /// minTexelBufferOffsetAlignment ([`EyeTexels::stride`] rounds a part up to one).
    pub fn of_frame(buffer: &Buffer, what: &str, eyes: u64, stride: u64) -> Result<Self, GpuError> {
        // One eye's part: stereo needs no more of a view than mono.
        let fix = "use a smaller --width/--height or fewer layers";
        let views = (0..eyes)
            .map(|e| TexelView::part(buffer, what, fix, e * stride, stride))
            .collect::<Result<_, _>>()?;
        Ok(Self { views })
    }

    /// Texels from one eye's part to the next for parts of `texels`: rounded up so that every
    /// part starts where a view may (`alignment`: minTexelBufferOffsetAlignment, bytes).
    pub fn stride(texels: u64, alignment: u64) -> u64 {
        texels.next_multiple_of(alignment.div_ceil(16).max(1))
    }

    /// The buffer they view (the memory a pass reading them accesses).
    pub(crate) fn buffer(&self) -> vk::Buffer {
        self.views[0].buffer
    }
}

impl Drop for TexelView {
    fn drop(&mut self) {
        // SAFETY: users wait for the GPU before dropping the resources they used.
        unsafe { self.ctx.device.destroy_buffer_view(self.view, None) };
    }
}
