//! Crash markers: which pass of a submission completed last before a device loss, and the
//! injected device loss that tests use to exercise that path.

use super::context::GpuContext;
use super::error::{GpuError, VkContext};
use super::sync::Scope;
use ash::vk;
use gpu_allocator::vulkan::{Allocation, AllocationCreateDesc, AllocationScheme, Allocator};
use gpu_allocator::MemoryLocation;

/// Crash markers, in the style of kajiya: after every pass the command buffer writes the
/// pass's index into its own slot of a small host-visible buffer; on VK_ERROR_DEVICE_LOST the
/// slots that were written say which pass completed last and so which one was running.
pub(super) struct Markers {
    pub(super) buffer: vk::Buffer,
    pub(super) allocation: Option<Allocation>,
    /// VK_AMD_buffer_marker where the device offers it (a write that the GPU performs once
    /// all earlier work is done, without a barrier); otherwise a barrier and vkCmdFillBuffer.
    pub(super) amd: Option<ash::amd::buffer_marker::Device>,
    /// The passes of the submission being recorded or run, in order; slot i belongs to pass i.
    pub(super) names: Vec<String>,
    /// An injected loss ended the recording: later passes are named but not recorded.
    pub(super) cut: bool,
}

/// Passes per submission that get a crash marker; later ones are not tracked.
pub(super) const MARKER_SLOTS: usize = 256;

/// The crash-marker buffer: MARKER_SLOTS u32s in host-visible memory, written by transfers.
pub(super) fn create_marker_buffer(
    device: &ash::Device,
    allocator: &mut Allocator,
) -> Result<(vk::Buffer, Allocation), GpuError> {
    let info = vk::BufferCreateInfo::default()
        .size((MARKER_SLOTS * 4) as u64)
        .usage(vk::BufferUsageFlags::TRANSFER_DST);
    // SAFETY: valid device and create info.
    let buffer = unsafe { device.create_buffer(&info, None) }.vk("vkCreateBuffer")?;
    // SAFETY: buffer was created from this device.
    let requirements = unsafe { device.get_buffer_memory_requirements(buffer) };
    let allocation = allocator.allocate(&AllocationCreateDesc {
        name: "crash markers",
        requirements,
        location: MemoryLocation::GpuToCpu,
        linear: true,
        allocation_scheme: AllocationScheme::GpuAllocatorManaged,
    });
    let allocation = match allocation {
        Ok(a) => a,
        Err(e) => {
            // SAFETY: unbound, unused buffer.
            unsafe { device.destroy_buffer(buffer, None) };
            return Err(GpuError::Allocation {
                what: "crash markers".into(),
                detail: e.to_string(),
            });
        }
    };
    // SAFETY: the allocation satisfies the buffer's requirements and is not bound elsewhere.
    let bound =
        unsafe { device.bind_buffer_memory(buffer, allocation.memory(), allocation.offset()) };
    if let Err(result) = bound {
        let _ = allocator.free(allocation);
        // SAFETY: unused buffer.
        unsafe { device.destroy_buffer(buffer, None) };
        return Err(GpuError::Vulkan {
            call: "vkBindBufferMemory",
            result,
        });
    }
    Ok((buffer, allocation))
}

impl GpuContext {
    pub(super) fn markers(&self) -> std::sync::MutexGuard<'_, Markers> {
        self.markers.lock().unwrap_or_else(|e| e.into_inner())
    }
    /// Registers the pass `name` of the command buffer being recorded (call before recording
    /// it, and [`Self::cmd_pass_done`] after). False when an injected device loss has ended
    /// the recording: the pass must not be recorded.
    pub(crate) fn begin_pass(&self, name: &str) -> bool {
        let mut m = self.markers();
        if m.names.len() < MARKER_SLOTS {
            m.names.push(name.to_owned());
        }
        !m.cut
    }

    /// Records the crash marker of the pass begun last: once all earlier commands have
    /// completed, the GPU writes the pass's index + 1 into the pass's slot.
    pub(crate) fn cmd_pass_done(&self, cmd: vk::CommandBuffer) {
        let mut m = self.markers();
        let Some(index) = m.names.len().checked_sub(1) else {
            return;
        };
        let offset = (index * 4) as vk::DeviceSize;
        let value = index as u32 + 1;
        match &m.amd {
            // SAFETY: cmd is recording; the marker buffer lives as long as the context.
            Some(amd) => unsafe {
                amd.cmd_write_buffer_marker(
                    cmd,
                    vk::PipelineStageFlags::BOTTOM_OF_PIPE,
                    m.buffer,
                    offset,
                    value,
                )
            },
            None => {
                // The fill waits for every earlier command (an execution dependency only: the
                // marker says those commands completed, it reads nothing they wrote).
                self.cmd_barrier(cmd, Scope::ALL_WORK, Scope::FILL_WRITE);
                // SAFETY: cmd is recording outside a render pass; offset and size are
                // multiples of 4 inside the marker buffer, which lives as long as the context.
                unsafe { self.device.cmd_fill_buffer(cmd, m.buffer, offset, 4, value) };
            }
        }
        if self.inject_device_lost.as_deref() == m.names.last().map(String::as_str) {
            m.cut = true;
        }
    }

    /// Reads the crash markers of the failed submission into a device-lost error.
    pub(super) fn device_lost(&self, submission: &str, injected: bool) -> GpuError {
        let m = self.markers();
        let slots: Vec<u32> = m
            .allocation
            .as_ref()
            .and_then(|a| a.mapped_slice())
            .map(|bytes| bytemuck::pod_collect_to_vec(&bytes[..MARKER_SLOTS * 4]))
            .unwrap_or_default();
        // Passes complete in order, so the last slot written is the last pass completed.
        let completed = (0..m.names.len())
            .rev()
            .find(|&i| slots.get(i) == Some(&(i as u32 + 1)));
        let running = completed.map_or(0, |i| i + 1);
        tracing::info!(
            "device lost in '{submission}'; crash markers {:?} for passes {:?}",
            &slots[..m.names.len().min(slots.len())],
            m.names
        );
        GpuError::DeviceLost {
            submission: submission.to_owned(),
            completed: completed.map(|i| m.names[i].clone()),
            running: m.names.get(running).cloned(),
            injected,
        }
    }
}
