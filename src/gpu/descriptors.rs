//! Descriptor sets made per pass: a pass names exactly the resources it touches (its
//! bindings of shared.h), and gets a set with those and nothing else. A binding the pass's
//! shader uses but did not name is left unwritten, which the validation layer reports at the
//! dispatch: declarations cannot silently fall behind the shaders, and no pass needs a
//! stand-in buffer for a binding it never reads.
//!
//! Sets come from an arena (a descriptor pool) that is reset as a whole once the work that
//! used them has completed: a frame slot's arena when the slot is reused, a one-off
//! submission's right after it.

use super::accel::AccelStructures;
use super::context::GpuContext;
use super::error::{GpuError, VkContext};
use super::memory::{Buffer, StorageImage};
use super::pipeline::{PipelineLayout, EYE_TEXEL_BINDINGS};
use super::texel_view::{EyeTexels, TexelView};
use super::texture::TextureSet;
use crate::shader_layout::{BINDING_COUNT, EYE_TEXEL_VIEWS, MAX_TEXTURES};
use ash::vk;
use std::sync::Arc;

/// What a binding points at.
#[derive(Clone, Copy)]
pub enum Bound<'a> {
    /// A storage buffer.
    Storage(&'a Buffer),
    /// A uniform texel buffer (see TexelView).
    Texels(&'a TexelView),
    /// An array of uniform texel buffers, one per eye (shared.h's EYE_TEXEL_VIEWS).
    EyeTexels(&'a EyeTexels),
    /// A storage image (GENERAL layout).
    Image(&'a StorageImage),
    /// The top-level acceleration structure.
    Tlas(&'a AccelStructures),
    /// The scene's textures (combined image samplers, read only).
    Textures(&'a TextureSet),
}

impl Bound<'_> {
    /// The memory behind the binding, for tracking accesses: a texel view is its buffer.
    pub fn resource(&self) -> u64 {
        use ash::vk::Handle;
        match self {
            Bound::Storage(b) => b.buffer.as_raw(),
            Bound::Texels(t) => t.buffer.as_raw(),
            Bound::EyeTexels(t) => t.buffer().as_raw(),
            Bound::Image(i) => i.image.as_raw(),
            Bound::Tlas(a) => a.tlas.as_raw(),
            Bound::Textures(t) => t.resource(),
        }
    }
}

impl<'a> From<&'a Buffer> for Bound<'a> {
    fn from(b: &'a Buffer) -> Self {
        Bound::Storage(b)
    }
}

impl<'a> From<&'a TexelView> for Bound<'a> {
    fn from(t: &'a TexelView) -> Self {
        Bound::Texels(t)
    }
}

impl<'a> From<&'a EyeTexels> for Bound<'a> {
    fn from(t: &'a EyeTexels) -> Self {
        Bound::EyeTexels(t)
    }
}

impl<'a> From<&'a StorageImage> for Bound<'a> {
    fn from(i: &'a StorageImage) -> Self {
        Bound::Image(i)
    }
}

/// Sets per arena: the most passes one frame records (plan, dispatch sizes, trace, resolve,
/// temporal, denoise: one set each; their eyes and iterations share it), with room to spare.
const SETS: u32 = 32;
/// Descriptors of each type per set, at most: one per binding of shared.h, and the rest of
/// each per-eye array of texel views.
const PER_SET: u32 = BINDING_COUNT + EYE_TEXEL_BINDINGS.len() as u32 * (EYE_TEXEL_VIEWS - 1);

pub struct DescriptorArena {
    ctx: Arc<GpuContext>,
    pool: vk::DescriptorPool,
    made: u32,
}

impl DescriptorArena {
    pub fn new(ctx: &Arc<GpuContext>) -> Result<Self, GpuError> {
        let size = |ty| vk::DescriptorPoolSize {
            ty,
            descriptor_count: SETS * PER_SET,
        };
        let mut sizes = vec![
            size(vk::DescriptorType::STORAGE_BUFFER),
            size(vk::DescriptorType::STORAGE_IMAGE),
            size(vk::DescriptorType::UNIFORM_TEXEL_BUFFER),
            vk::DescriptorPoolSize {
                ty: vk::DescriptorType::COMBINED_IMAGE_SAMPLER,
                descriptor_count: SETS * MAX_TEXTURES,
            },
        ];
        if ctx.info.ray_query.is_some() {
            sizes.push(vk::DescriptorPoolSize {
                ty: vk::DescriptorType::ACCELERATION_STRUCTURE_KHR,
                descriptor_count: SETS,
            });
        }
        let info = vk::DescriptorPoolCreateInfo::default()
            .max_sets(SETS)
            .pool_sizes(&sizes);
        // SAFETY: valid device and create info.
        let pool = unsafe { ctx.device.create_descriptor_pool(&info, None) }
            .vk("vkCreateDescriptorPool")?;
        Ok(Self {
            ctx: ctx.clone(),
            pool,
            made: 0,
        })
    }

    /// Frees every set made since the last reset. The caller guarantees that no pending
    /// command buffer uses them (their submission completed, or was never made).
    pub fn reset(&mut self) -> Result<(), GpuError> {
        // SAFETY: per the caller's guarantee no set of this pool is in use.
        unsafe {
            self.ctx
                .device
                .reset_descriptor_pool(self.pool, vk::DescriptorPoolResetFlags::empty())
        }
        .vk("vkResetDescriptorPool")?;
        self.made = 0;
        Ok(())
    }

    /// A new set of `layout` with exactly `bindings` written.
    pub fn set(
        &mut self,
        layout: &PipelineLayout,
        bindings: &[(u32, Bound)],
    ) -> Result<vk::DescriptorSet, GpuError> {
        if self.made == SETS {
            return Err(GpuError::Limit(format!(
                "one submission asked for more than {SETS} descriptor sets (one per pass): \
                 a frame records fewer passes; this is a bug in fovea"
            )));
        }
        // A per-eye array takes per-eye views, and only it does: a single view there would
        // leave the other eye's element unwritten.
        for (binding, bound) in bindings {
            let per_eye = matches!(bound, Bound::EyeTexels(_));
            if EYE_TEXEL_BINDINGS.contains(binding) != per_eye {
                let what = match per_eye {
                    true => "was given per-eye texel views, which only the per-eye arrays take",
                    false => "is an array of one texel view per eye and was given something else",
                };
                return Err(GpuError::Limit(format!(
                    "binding {binding} {what} (shared.h); this is a bug in fovea"
                )));
            }
        }
        let layouts = [layout.set_layout];
        let info = vk::DescriptorSetAllocateInfo::default()
            .descriptor_pool(self.pool)
            .set_layouts(&layouts);
        // SAFETY: the pool has room for the set (counted above; every type sized for a full
        // set of shared.h's bindings).
        let set = unsafe { self.ctx.device.allocate_descriptor_sets(&info) }
            .vk("vkAllocateDescriptorSets")?[0];
        self.made += 1;
        write_set(&self.ctx, set, bindings);
        Ok(set)
    }
}

impl Drop for DescriptorArena {
    fn drop(&mut self) {
        // SAFETY: no pending command buffer uses its sets (owners wait for their work before
        // dropping); destroying the pool frees them.
        unsafe { self.ctx.device.destroy_descriptor_pool(self.pool, None) };
    }
}

/// Writes each binding of a set that no pending command buffer uses.
fn write_set(ctx: &GpuContext, set: vk::DescriptorSet, bindings: &[(u32, Bound)]) {
    // The infos each write points at, kept alive until the update.
    let buffers: Vec<[vk::DescriptorBufferInfo; 1]> = bindings
        .iter()
        .map(|(_, bound)| match bound {
            Bound::Storage(b) => [vk::DescriptorBufferInfo::default()
                .buffer(b.buffer)
                .range(vk::WHOLE_SIZE)],
            _ => [vk::DescriptorBufferInfo::default()],
        })
        .collect();
    let images: Vec<[vk::DescriptorImageInfo; 1]> = bindings
        .iter()
        .map(|(_, bound)| match bound {
            Bound::Image(i) => [vk::DescriptorImageInfo::default()
                .image_view(i.view)
                .image_layout(vk::ImageLayout::GENERAL)],
            _ => [vk::DescriptorImageInfo::default()],
        })
        .collect();
    let views: Vec<Vec<vk::BufferView>> = bindings
        .iter()
        .map(|(_, bound)| match bound {
            Bound::Texels(t) => vec![t.view],
            Bound::EyeTexels(t) => eye_views(t),
            _ => vec![vk::BufferView::null()],
        })
        .collect();
    let tlases: Vec<[vk::AccelerationStructureKHR; 1]> = bindings
        .iter()
        .map(|(_, bound)| match bound {
            Bound::Tlas(a) => [a.tlas],
            _ => [vk::AccelerationStructureKHR::null()],
        })
        .collect();
    let samplers: Vec<Vec<vk::DescriptorImageInfo>> = bindings
        .iter()
        .map(|(_, bound)| match bound {
            Bound::Textures(t) => t.descriptors(),
            _ => Vec::new(),
        })
        .collect();
    let mut tlas_writes: Vec<vk::WriteDescriptorSetAccelerationStructureKHR> = tlases
        .iter()
        .map(|t| {
            vk::WriteDescriptorSetAccelerationStructureKHR::default().acceleration_structures(t)
        })
        .collect();
    let mut writes = Vec::with_capacity(bindings.len());
    for (i, ((binding, bound), tlas)) in bindings.iter().zip(&mut tlas_writes).enumerate() {
        // An empty texture array writes nothing (the binding is partially bound).
        if matches!(bound, Bound::Textures(t) if t.is_empty()) {
            continue;
        }
        let write = vk::WriteDescriptorSet::default()
            .dst_set(set)
            .dst_binding(*binding);
        writes.push(match bound {
            Bound::Storage(_) => write
                .descriptor_type(vk::DescriptorType::STORAGE_BUFFER)
                .buffer_info(&buffers[i]),
            Bound::Image(_) => write
                .descriptor_type(vk::DescriptorType::STORAGE_IMAGE)
                .image_info(&images[i]),
            Bound::Texels(_) | Bound::EyeTexels(_) => write
                .descriptor_type(vk::DescriptorType::UNIFORM_TEXEL_BUFFER)
                .texel_buffer_view(&views[i]),
            Bound::Textures(_) => write
                .descriptor_type(vk::DescriptorType::COMBINED_IMAGE_SAMPLER)
                .image_info(&samplers[i]),
            Bound::Tlas(_) => {
                let mut write = write
                    .descriptor_type(vk::DescriptorType::ACCELERATION_STRUCTURE_KHR)
                    .push_next(tlas);
                // The count is the chained structure's; the builder leaves it at 0.
                write.descriptor_count = 1;
                write
            }
        });
    }
    // SAFETY: the set is new (no command buffer uses it); every resource is alive, and the
    // infos outlive the call.
    unsafe { ctx.device.update_descriptor_sets(&writes, &[]) };
}

/// Every element of a per-eye array of views: each eye's own, and a mono frame's one view in
/// the elements of eyes it does not have (shaders index only the eyes there are).
fn eye_views(t: &EyeTexels) -> Vec<vk::BufferView> {
    let last = t.views.len() - 1;
    (0..EYE_TEXEL_VIEWS as usize)
        .map(|e| t.views[e.min(last)].view)
        .collect()
}
