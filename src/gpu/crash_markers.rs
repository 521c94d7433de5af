//! Crash markers: which pass of a submission completed last before a device loss, and the
//! injected device loss that tests use to exercise that path.
//!
//! Every recorded command buffer gets its own set of marker slots, held until its work is
//! done: with frames in flight, recording frame N+1 must not wipe the markers of frame N while
//! it still runs, or a loss in frame N would be reported with frame N+1's passes.

use super::error::{GpuError, VkContext};
use super::options::{GpuOptions, INJECT_DEVICE_LOST_VAR};
use super::owned::Pending;
use super::sync::{Barriers, Scope};
use ash::vk;
use gpu_allocator::vulkan::{Allocation, AllocationCreateDesc, AllocationScheme, Allocator};
use gpu_allocator::MemoryLocation;
use std::sync::{Mutex, MutexGuard};

/// Crash markers, in the style of kajiya: after every pass the command buffer writes the
/// pass's index into its own slot of a small host-visible buffer; on VK_ERROR_DEVICE_LOST the
/// slots that were written say which pass completed last and so which one was running.
/// Behind a lock: the context that holds them is shared by whoever records command buffers.
pub(super) struct CrashMarkers(Mutex<Markers>);

/// The marker buffer and its sets, as the lock of [`CrashMarkers`] guards them.
struct Markers {
    buffer: vk::Buffer,
    allocation: Option<Allocation>,
    /// VK_AMD_buffer_marker where the device offers it (a write that the GPU performs once
    /// all earlier work is done, without a barrier); otherwise a barrier and vkCmdFillBuffer.
    amd: Option<ash::amd::buffer_marker::Device>,
    /// One per command buffer that may be alive at once (see [`MARKER_SETS`]).
    sets: Vec<MarkerSet>,
    /// The set of the command buffer being recorded, if one is.
    recording: Option<usize>,
    /// The device loss to inject, and how many command buffers have recorded its pass.
    inject: Option<InjectedLoss>,
    inject_seen: u32,
}

/// The markers of one command buffer: its passes, in order (slot i belongs to pass i).
#[derive(Default)]
struct MarkerSet {
    names: Vec<String>,
    /// An injected loss ended the recording: later passes are named but not recorded.
    cut: bool,
    /// A command buffer owns this set (from its recording until its work is done).
    in_use: bool,
}

/// Passes per command buffer that get a crash marker; later ones are not tracked.
const MARKER_SLOTS: usize = 256;

/// Command buffers that can hold crash markers at once: frames in flight (3 at most) and the
/// uploads and read-backs recorded beside them, with room to spare. One more is an error
/// that says so, never a command buffer without markers.
const MARKER_SETS: usize = 16;

/// A device loss to inject (`FOVEA_INJECT_DEVICE_LOST=PASS` or `PASS@N`): the `nth` command
/// buffer that records `pass` (1: the first) ends after it, and its submission reports
/// VK_ERROR_DEVICE_LOST.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(super) struct InjectedLoss {
    pub(super) pass: String,
    pub(super) nth: u32,
}

impl InjectedLoss {
    /// Parses `PASS` or `PASS@N` (N ≥ 1); the error says what is wrong.
    pub(super) fn parse(text: &str) -> Result<Self, String> {
        let Some((pass, nth)) = text.rsplit_once('@') else {
            return Ok(Self {
                pass: text.to_owned(),
                nth: 1,
            });
        };
        match nth.trim().parse::<u32>() {
            Ok(nth) if nth >= 1 && !pass.is_empty() => Ok(Self {
                pass: pass.to_owned(),
                nth,
            }),
            _ => Err(format!(
                "is not PASS or PASS@N with N a whole number from 1 (e.g. 'left trace@2': the \
                 second command buffer that records 'left trace'); got pass '{pass}', N '{nth}'"
            )),
        }
    }

    /// The loss [`GpuOptions::inject_device_lost`] asks for, if any; a value that does not
    /// parse is refused (before anything touches Vulkan) with what is wrong.
    pub(super) fn from_options(options: &GpuOptions) -> Result<Option<Self>, GpuError> {
        let Some(text) = options.inject_device_lost.as_deref() else {
            return Ok(None);
        };
        Self::parse(text)
            .map(Some)
            .map_err(|problem| GpuError::BadEnvironment {
                var: INJECT_DEVICE_LOST_VAR,
                value: text.to_owned(),
                problem,
            })
    }
}

impl CrashMarkers {
    /// The marker buffer (MARKER_SETS × MARKER_SLOTS u32s in host-visible memory, written by
    /// transfers or AMD's buffer markers), every set free, and the loss to inject.
    pub(super) fn new(
        instance: &ash::Instance,
        device: &ash::Device,
        allocator: &mut Allocator,
        amd_marker: bool,
        inject: Option<InjectedLoss>,
    ) -> Result<Self, GpuError> {
        let info = vk::BufferCreateInfo::default()
            .size((MARKER_SETS * MARKER_SLOTS * 4) as u64)
            .usage(vk::BufferUsageFlags::TRANSFER_DST);
        // SAFETY: valid device and create info.
        let buffer = unsafe { device.create_buffer(&info, None) }.vk("vkCreateBuffer")?;
        let buffer = Pending::new(device, buffer);
        // SAFETY: buffer was created from this device.
        let requirements = unsafe { device.get_buffer_memory_requirements(buffer.get()) };
        let allocation = allocator
            .allocate(&AllocationCreateDesc {
                name: "crash markers",
                requirements,
                location: MemoryLocation::GpuToCpu,
                linear: true,
                allocation_scheme: AllocationScheme::GpuAllocatorManaged,
            })
            .map_err(|e| GpuError::Allocation {
                what: "crash markers".into(),
                detail: e.to_string(),
            })?;
        // SAFETY: the allocation satisfies the buffer's requirements and is not bound elsewhere.
        let bound = unsafe {
            device.bind_buffer_memory(buffer.get(), allocation.memory(), allocation.offset())
        };
        if let Err(result) = bound {
            let _ = allocator.free(allocation);
            return Err(GpuError::Vulkan {
                call: "vkBindBufferMemory",
                result,
            });
        }
        Ok(Self(Mutex::new(Markers {
            buffer: buffer.keep(),
            allocation: Some(allocation),
            amd: amd_marker.then(|| ash::amd::buffer_marker::Device::new(instance, device)),
            sets: (0..MARKER_SETS).map(|_| MarkerSet::default()).collect(),
            recording: None,
            inject,
            inject_seen: 0,
        })))
    }

    /// Frees the marker buffer's memory and destroys it (the context's drop, once the device
    /// is idle: the buffer needs the allocator, which the context holds beside it).
    pub(super) fn destroy(&mut self, device: &ash::Device, allocator: &mut Allocator) {
        let m = self.0.get_mut().unwrap_or_else(|e| e.into_inner());
        if let Some(allocation) = m.allocation.take() {
            let _ = allocator.free(allocation);
        }
        // SAFETY: the device is idle, so no command buffer writes the markers any more.
        unsafe { device.destroy_buffer(m.buffer, None) };
    }

    fn markers(&self) -> MutexGuard<'_, Markers> {
        self.0.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Takes a free marker set for a command buffer about to be recorded (cleared, its
    /// slots zeroed) and makes it the one passes are registered in.
    pub(super) fn begin(&self) -> Result<usize, GpuError> {
        let mut m = self.markers();
        let Some(set) = m.sets.iter().position(|s| !s.in_use) else {
            return Err(GpuError::TooManyCommandBuffers { limit: MARKER_SETS });
        };
        m.sets[set] = MarkerSet {
            in_use: true,
            ..MarkerSet::default()
        };
        m.recording = Some(set);
        if let Some(bytes) = m.allocation.as_mut().and_then(|a| a.mapped_slice_mut()) {
            bytes[set * MARKER_SLOTS * 4..(set + 1) * MARKER_SLOTS * 4].fill(0);
        }
        Ok(set)
    }

    /// The recording that began with [`Self::begin`] ended; whether it recorded any
    /// pass (then its markers need a barrier before the host reads them).
    pub(super) fn end(&self) -> bool {
        let mut m = self.markers();
        let set = m.recording.take();
        set.is_some_and(|s| !m.sets[s].names.is_empty())
    }

    /// The command buffer of `set` no longer runs: its set is free again.
    pub(super) fn release(&self, set: usize) {
        self.markers().sets[set].in_use = false;
    }

    /// Whether an injected loss ended the recording of `set`.
    pub(super) fn cut(&self, set: usize) -> bool {
        self.markers().sets[set].cut
    }

    /// Registers the pass `name` of the command buffer being recorded (call before recording
    /// it, and [`Self::cmd_pass_done`] after). False when an injected device loss has ended
    /// the recording: the pass must not be recorded.
    pub(super) fn begin_pass(&self, name: &str) -> bool {
        let mut m = self.markers();
        let Some(set) = m.recording else {
            return true;
        };
        let set = &mut m.sets[set];
        if set.names.len() < MARKER_SLOTS {
            set.names.push(name.to_owned());
        }
        !set.cut
    }

    /// Records the crash marker of the pass begun last: once all earlier commands have
    /// completed, the GPU writes the pass's index + 1 into the pass's slot of the recording's
    /// set. `device` and `barriers` are the context's, which records it.
    pub(super) fn cmd_pass_done(
        &self,
        device: &ash::Device,
        barriers: &Barriers,
        cmd: vk::CommandBuffer,
    ) {
        let mut m = self.markers();
        let Some(set) = m.recording else {
            return;
        };
        let Some(index) = m.sets[set].names.len().checked_sub(1) else {
            return;
        };
        let offset = ((set * MARKER_SLOTS + index) * 4) as vk::DeviceSize;
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
                barriers.memory(cmd, Scope::ALL_WORK, Scope::FILL_WRITE);
                // SAFETY: cmd is recording outside a render pass; offset and size are
                // multiples of 4 inside the marker buffer, which lives as long as the context.
                unsafe { device.cmd_fill_buffer(cmd, m.buffer, offset, 4, value) };
            }
        }
        let name_matches = matches!(
            (&m.inject, m.sets[set].names.last()),
            (Some(inject), Some(name)) if &inject.pass == name
        );
        if name_matches {
            m.inject_seen += 1;
            if m.inject.as_ref().is_some_and(|i| i.nth == m.inject_seen) {
                m.sets[set].cut = true;
            }
        }
    }

    /// Reads the crash markers of the failed submission (its marker `set`) into a
    /// device-lost error.
    pub(super) fn device_lost(&self, submission: &str, set: usize) -> GpuError {
        let m = self.markers();
        let markers = &m.sets[set];
        let slots: Vec<u32> = m
            .allocation
            .as_ref()
            .and_then(|a| a.mapped_slice())
            .map(|bytes| {
                bytemuck::pod_collect_to_vec(
                    &bytes[set * MARKER_SLOTS * 4..(set + 1) * MARKER_SLOTS * 4],
                )
            })
            .unwrap_or_default();
        // Passes complete in order, so the last slot written is the last pass completed.
        let completed = (0..markers.names.len())
            .rev()
            .find(|&i| slots.get(i) == Some(&(i as u32 + 1)));
        let running = completed.map_or(0, |i| i + 1);
        tracing::info!(
            "device lost in '{submission}'; crash markers {:?} for passes {:?}",
            &slots[..markers.names.len().min(slots.len())],
            markers.names
        );
        GpuError::DeviceLost {
            submission: submission.to_owned(),
            completed: completed.map(|i| markers.names[i].clone()),
            running: markers.names.get(running).cloned(),
            injected: markers.cut,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::InjectedLoss;

    #[test]
    fn an_injected_loss_names_a_pass_and_which_command_buffer() {
        let first = InjectedLoss::parse("left trace").unwrap();
        assert_eq!((first.pass.as_str(), first.nth), ("left trace", 1));
        let third = InjectedLoss::parse("right resolve@3").unwrap();
        assert_eq!((third.pass.as_str(), third.nth), ("right resolve", 3));
        for bad in ["trace@0", "trace@x", "@2", "trace@-1"] {
            let e = InjectedLoss::parse(bad).unwrap_err();
            assert!(e.contains("PASS@N"), "{bad}: {e}");
        }
    }
}
