//! Pipeline barriers (VK_KHR_synchronization2): every barrier names the stages and accesses
//! it orders on each side, through a small set of [`Scope`]s, so that a pass's barrier says
//! exactly what it waits for and what waits on it. A GPU overlaps dispatches that no barrier
//! orders; lavapipe runs them one after another, so a missing barrier shows only under the
//! validation layer's synchronization checks, which the tests run (see `options.rs`).

use ash::vk;

/// The stages and access types on one side of a barrier.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Scope {
    pub(crate) stages: vk::PipelineStageFlags2,
    pub(crate) access: vk::AccessFlags2,
}

type Stage = vk::PipelineStageFlags2;
type Access = vk::AccessFlags2;

impl Scope {
    /// Nothing before: an image whose old contents are discarded (layout UNDEFINED).
    pub const NOTHING: Scope = Scope::new(Stage::NONE, Access::NONE);
    /// Compute shaders writing storage buffers or images (atomics included).
    pub const COMPUTE_WRITE: Scope =
        Scope::new(Stage::COMPUTE_SHADER, Access::SHADER_STORAGE_WRITE);
    /// Compute shaders reading storage buffers or images, or fetching from texel buffers.
    pub const COMPUTE_READ: Scope = Scope::new(
        Stage::COMPUTE_SHADER,
        Access::from_raw(
            Access::SHADER_STORAGE_READ.as_raw() | Access::SHADER_SAMPLED_READ.as_raw(),
        ),
    );
    /// Compute shaders reading and writing (a pass that accumulates into what it reads).
    pub const COMPUTE_READ_WRITE: Scope = Scope::new(
        Stage::COMPUTE_SHADER,
        Access::from_raw(
            Access::SHADER_STORAGE_READ.as_raw()
                | Access::SHADER_SAMPLED_READ.as_raw()
                | Access::SHADER_STORAGE_WRITE.as_raw(),
        ),
    );
    /// Every command recorded before, to its end, with no memory made visible: for work that
    /// must only follow it (a crash marker saying those commands completed).
    pub const ALL_WORK: Scope = Scope::new(Stage::ALL_COMMANDS, Access::NONE);
    /// vkCmdFillBuffer writing (a clear command).
    pub const FILL_WRITE: Scope = Scope::new(Stage::CLEAR, Access::TRANSFER_WRITE);
    /// Copies reading (image → buffer read-backs).
    pub const COPY_READ: Scope = Scope::new(Stage::COPY, Access::TRANSFER_READ);
    /// Copies and fills writing (uploads, crash markers).
    pub const COPY_WRITE: Scope = Scope::new(Stage::COPY, Access::TRANSFER_WRITE);
    /// Blits reading (a frame copied into a swapchain image).
    pub const BLIT_READ: Scope = Scope::new(Stage::BLIT, Access::TRANSFER_READ);
    /// Blits writing.
    pub const BLIT_WRITE: Scope = Scope::new(Stage::BLIT, Access::TRANSFER_WRITE);
    /// An indirect dispatch reading its workgroup counts.
    pub const INDIRECT_READ: Scope =
        Scope::new(Stage::DRAW_INDIRECT, Access::INDIRECT_COMMAND_READ);
    /// Acceleration-structure builds writing their structures (and scratch).
    pub const AS_BUILD_WRITE: Scope = Scope::new(
        Stage::ACCELERATION_STRUCTURE_BUILD_KHR,
        Access::ACCELERATION_STRUCTURE_WRITE_KHR,
    );
    /// Acceleration-structure builds reading built structures (a TLAS build its BLASes) and
    /// reusing scratch.
    pub const AS_BUILD_READ_WRITE: Scope = Scope::new(
        Stage::ACCELERATION_STRUCTURE_BUILD_KHR,
        Access::from_raw(
            Access::ACCELERATION_STRUCTURE_READ_KHR.as_raw()
                | Access::ACCELERATION_STRUCTURE_WRITE_KHR.as_raw(),
        ),
    );
    /// Compute shaders tracing ray queries through acceleration structures.
    pub const COMPUTE_AS_READ: Scope = Scope::new(
        Stage::COMPUTE_SHADER,
        Access::ACCELERATION_STRUCTURE_READ_KHR,
    );
    /// Every command submitted before, with its writes: what a frame starts by waiting for
    /// when the frames in flight share buffers and images (the queue runs them in order, but
    /// overlaps commands that no barrier orders, across submissions too).
    pub const EARLIER_WORK: Scope = Scope::new(Stage::ALL_COMMANDS, Access::MEMORY_WRITE);
    /// Every command after, reading or writing anything.
    pub const LATER_WORK: Scope = Scope::new(
        Stage::ALL_COMMANDS,
        Access::from_raw(Access::MEMORY_READ.as_raw() | Access::MEMORY_WRITE.as_raw()),
    );
    /// The host reading mapped memory after the submission's fence.
    pub const HOST_READ: Scope = Scope::new(Stage::HOST, Access::HOST_READ);
    /// An image handed to someone else (a compositor, a presentation engine), who orders its
    /// own reads with a semaphore or fence: the barrier only makes the writes available.
    pub const HANDED_OVER: Scope = Scope::new(Stage::NONE, Access::NONE);

    const fn new(stages: Stage, access: Access) -> Self {
        Self { stages, access }
    }

    /// Stages only, no memory access: what a write after reads waits for (their execution).
    pub const fn stages(stages: Stage) -> Scope {
        Scope::new(stages, Access::NONE)
    }

    /// The scope's writes alone: what a later access must wait for and see.
    pub const fn writes(self) -> Scope {
        let writes = Access::SHADER_STORAGE_WRITE.as_raw()
            | Access::TRANSFER_WRITE.as_raw()
            | Access::MEMORY_WRITE.as_raw()
            | Access::HOST_WRITE.as_raw()
            | Access::ACCELERATION_STRUCTURE_WRITE_KHR.as_raw();
        Scope::new(self.stages, Access::from_raw(self.access.as_raw() & writes))
    }

    /// Whether every stage and access of `other` is in this scope.
    pub const fn contains(self, other: Scope) -> bool {
        self.stages.as_raw() & other.stages.as_raw() == other.stages.as_raw()
            && self.access.as_raw() & other.access.as_raw() == other.access.as_raw()
    }

    /// The union of two scopes (a pass that ends several kinds of work).
    pub const fn and(self, other: Scope) -> Scope {
        Scope::new(
            Stage::from_raw(self.stages.as_raw() | other.stages.as_raw()),
            Access::from_raw(self.access.as_raw() | other.access.as_raw()),
        )
    }
}

/// An image barrier: the image, its subresources, and its layout on each side.
pub(crate) struct ImageTransition {
    pub image: vk::Image,
    pub range: vk::ImageSubresourceRange,
    pub from: (Scope, vk::ImageLayout),
    pub to: (Scope, vk::ImageLayout),
}

/// Records barriers through VK_KHR_synchronization2's vkCmdPipelineBarrier2, which every
/// barrier fovea records goes through (the context and its crash markers alike).
pub(super) struct Barriers {
    sync2: ash::khr::synchronization2::Device,
}

impl Barriers {
    /// The functions of `device`, created with synchronization2 enabled.
    pub(super) fn new(instance: &ash::Instance, device: &ash::Device) -> Self {
        Self {
            sync2: ash::khr::synchronization2::Device::new(instance, device),
        }
    }

    /// Records a memory barrier: the accesses in `before` (and everything earlier in their
    /// stages) happen before, and are visible to, the accesses in `after`.
    pub(super) fn memory(&self, cmd: vk::CommandBuffer, before: Scope, after: Scope) {
        let barrier = [vk::MemoryBarrier2::default()
            .src_stage_mask(before.stages)
            .src_access_mask(before.access)
            .dst_stage_mask(after.stages)
            .dst_access_mask(after.access)];
        let dependency = vk::DependencyInfo::default().memory_barriers(&barrier);
        // SAFETY: cmd is a recording command buffer of this device, outside any render pass;
        // synchronization2 was enabled at device creation.
        unsafe { self.sync2.cmd_pipeline_barrier2(cmd, &dependency) };
    }

    /// Records image barriers (layout transitions with the accesses they order), all in one
    /// call.
    pub(super) fn images(&self, cmd: vk::CommandBuffer, transitions: &[ImageTransition]) {
        let barriers: Vec<vk::ImageMemoryBarrier2> = transitions
            .iter()
            .map(|t| {
                vk::ImageMemoryBarrier2::default()
                    .src_stage_mask(t.from.0.stages)
                    .src_access_mask(t.from.0.access)
                    .old_layout(t.from.1)
                    .dst_stage_mask(t.to.0.stages)
                    .dst_access_mask(t.to.0.access)
                    .new_layout(t.to.1)
                    .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                    .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                    .image(t.image)
                    .subresource_range(t.range)
            })
            .collect();
        let dependency = vk::DependencyInfo::default().image_memory_barriers(&barriers);
        // SAFETY: cmd is a recording command buffer of this device, outside any render pass;
        // the images belong to this device; synchronization2 was enabled at device creation.
        unsafe { self.sync2.cmd_pipeline_barrier2(cmd, &dependency) };
    }
}
