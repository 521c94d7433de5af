//! The Vulkan instance, the chosen device and its queue, the memory allocator and a command
//! pool: everything else in gpu/ borrows from a `GpuContext`. Set-up is in instance.rs and
//! device.rs; each object is held by its owner (owned.rs), so a set-up that fails half-way
//! destroys what it made.

use super::context_needs::ContextNeeds;
use super::crash_markers::{CrashMarkers, InjectedLoss};
use super::device::{create_device, RayQueryUse};
use super::device_pick::{pick_device, DeviceInfo, DeviceWanted, Picked};
use super::error::{human_bytes, GpuError};
use super::instance::create_instance;
use super::memory_budget::{memory_facts, MemoryBudget, PlannedAllocation};
use super::options::GpuOptions;
use super::owned::{CommandPool, Device, Instance, Messenger};
use super::sync::{Barriers, ImageTransition, Scope};
use super::validation::ValidationLog;
use ash::vk;
use gpu_allocator::vulkan::{Allocator, AllocatorCreateDesc};
use std::sync::{Arc, Mutex};

/// The fields that own Vulkan objects are declared in the order they are destroyed, the
/// reverse of their creation (Rust drops fields in declaration order, after `Drop::drop`).
pub struct GpuContext {
    pub(super) markers: CrashMarkers,
    /// Command buffers and fences of finished submissions, reused by the next ones: a
    /// headset session submits every frame, and new handles each time make the validation
    /// layer's bookkeeping (and some drivers') grow.
    pub(super) spare: Mutex<Vec<(vk::CommandBuffer, vk::Fence)>>,
    allocator: Mutex<Allocator>,
    pub(super) command_pool: CommandPool,
    /// vkCmdPipelineBarrier2 (VK_KHR_synchronization2: every barrier fovea records).
    barriers: Barriers,
    pub(crate) queue: vk::Queue,
    pub(crate) device: Device,
    /// Held for its drop: validation messages are reported until it is destroyed.
    _messenger: Option<Messenger>,
    pub(crate) instance: Instance,
    validation_log: Arc<ValidationLog>,
    /// What the device offers and fovea holds of it (memory.rs counts each allocation).
    pub(super) memory: MemoryBudget,
    pub info: DeviceInfo,
    /// Whether the renderer traces with ray queries unless told otherwise.
    prefers_ray_queries: bool,
    physical_device: vk::PhysicalDevice,
    queue_family: u32,
}

impl GpuContext {
    pub fn new(options: &GpuOptions) -> Result<Self, GpuError> {
        Self::new_with(options, &ContextNeeds::default())
    }

    /// Sets up instance, device, queue, command pool, allocator and crash markers, in that
    /// order; an error on the way destroys what was made (each has its owner).
    pub fn new_with(options: &GpuOptions, needs: &ContextNeeds) -> Result<Self, GpuError> {
        options.check_environment()?;
        let inject = InjectedLoss::from_options(options)?;
        let validation_log = Arc::<ValidationLog>::default();
        let (instance, messenger) = create_instance(options, needs, &validation_log)?;
        let mut picked = pick(&instance, options, needs)?;
        let ray_query = RayQueryUse::decide(options, &mut picked.info)?;
        let device = create_device(&instance, &picked, ray_query.enabled, needs)?;
        // SAFETY: queue 0 of the family the device was created with.
        let queue = unsafe { device.get_device_queue(picked.family, 0) };
        let command_pool = CommandPool::new(&device, picked.family)?;
        let mut allocator = create_allocator(&instance, &device, &picked, ray_query.enabled)?;
        let markers = CrashMarkers::new(
            &instance,
            &device,
            &mut allocator,
            picked.amd_marker,
            inject,
        )?;
        let memory = memory_facts(&instance, &picked, options.memory_limit);
        tracing::info!(
            "Vulkan device: {} ({}, {}); heap {} of {}",
            picked.info.name,
            picked.info.kind,
            picked.info.driver,
            memory.device_heap,
            human_bytes(memory.heaps[memory.device_heap])
        );
        Ok(Self {
            markers,
            spare: Mutex::new(Vec::new()),
            allocator: Mutex::new(allocator),
            command_pool,
            barriers: Barriers::new(&instance, &device),
            queue,
            device,
            _messenger: messenger,
            instance,
            validation_log,
            memory: MemoryBudget::new(memory),
            info: picked.info,
            prefers_ray_queries: ray_query.preferred,
            physical_device: picked.physical_device,
            queue_family: picked.family,
        })
    }

    /// Whether frames trace with ray queries by default: they are enabled, and either asked
    /// for (`--traversal rayquery`) or the device is a GPU (`auto`).
    pub fn prefers_ray_queries(&self) -> bool {
        self.prefers_ray_queries
    }

    pub(crate) fn entry(&self) -> &ash::Entry {
        self.instance.entry()
    }

    pub(crate) fn physical_device(&self) -> vk::PhysicalDevice {
        self.physical_device
    }

    /// The family of [`Self::queue`], the one queue fovea submits to.
    pub fn queue_family(&self) -> u32 {
        self.queue_family
    }

    /// Raw handles, for an OpenXR graphics binding.
    pub fn raw_handles(&self) -> (vk::Instance, vk::PhysicalDevice, vk::Device, vk::Queue) {
        (
            self.instance.handle(),
            self.physical_device,
            self.device.handle(),
            self.queue,
        )
    }

    /// Every validation message reported since the last call (empty without validation).
    pub fn take_validation_messages(&self) -> Vec<String> {
        self.validation_log.take()
    }

    /// The log itself, which outlives the context: messages reported while the context is
    /// destroyed (leaked objects) can be read after it is gone.
    pub fn validation_log(&self) -> Arc<ValidationLog> {
        self.validation_log.clone()
    }

    pub(crate) fn allocator(&self) -> std::sync::MutexGuard<'_, Allocator> {
        self.allocator.lock().unwrap_or_else(|e| e.into_inner())
    }
}

/// What the context does through the parts it holds (barriers in sync.rs, crash markers in
/// crash_markers.rs, memory checks in memory_budget.rs), said once here so that those files
/// need not know the context.
impl GpuContext {
    /// Records a memory barrier: the accesses in `before` (and everything earlier in their
    /// stages) happen before, and are visible to, the accesses in `after`.
    pub fn cmd_barrier(&self, cmd: vk::CommandBuffer, before: Scope, after: Scope) {
        self.barriers.memory(cmd, before, after);
    }

    /// Records image barriers (layout transitions with the accesses they order), all in one
    /// call.
    pub(crate) fn cmd_image_barriers(
        &self,
        cmd: vk::CommandBuffer,
        transitions: &[ImageTransition],
    ) {
        self.barriers.images(cmd, transitions);
    }

    /// Registers the pass `name` of the command buffer being recorded (call before recording
    /// it, and [`Self::cmd_pass_done`] after). False when an injected device loss has ended
    /// the recording: the pass must not be recorded.
    pub(crate) fn begin_pass(&self, name: &str) -> bool {
        self.markers.begin_pass(name)
    }

    /// Records the crash marker of the pass begun last (see [`CrashMarkers::cmd_pass_done`]).
    pub(crate) fn cmd_pass_done(&self, cmd: vk::CommandBuffer) {
        self.markers
            .cmd_pass_done(&self.device, &self.barriers, cmd);
    }

    /// The GPU memory cap from
    /// [`GpuOptions::memory_limit`](super::GpuOptions::memory_limit), if any.
    pub fn memory_limit(&self) -> Option<u64> {
        self.memory.limit()
    }

    /// Bytes of GPU memory fovea's buffers and images hold now.
    pub fn memory_in_use(&self) -> u64 {
        self.memory.in_use()
    }

    /// The most bytes fovea's buffers and images held at once since the context was made.
    pub fn memory_peak(&self) -> u64 {
        self.memory.peak()
    }

    /// Checks, before anything is allocated, that `plan` fits the device's memory beside what
    /// fovea holds and the memory limit, and each item the per-resource limits (see
    /// [`MemoryBudget::check`]). `what` names the plan ("scene 'bunny'", "frame targets of
    /// ..."); `advice` says what to change.
    pub fn check_memory(
        &self,
        what: &str,
        plan: &[PlannedAllocation],
        advice: &str,
    ) -> Result<(), GpuError> {
        self.memory.check(&self.instance, what, plan, advice)
    }
}

/// The physical device: the creator's (an OpenXR runtime names the GPU driving the headset),
/// else the best one that can run fovea and matches `--device`.
fn pick(
    instance: &Instance,
    options: &GpuOptions,
    needs: &ContextNeeds,
) -> Result<Picked, GpuError> {
    let required = match needs.creator {
        Some(creator) => Some(creator.physical_device(instance.handle())?),
        None => None,
    };
    pick_device(
        instance,
        &DeviceWanted {
            name: options.device.as_deref(),
            physical_device: required,
            graphics: needs.graphics_queue,
            extensions: &needs.device_extensions,
        },
    )
}

fn create_allocator(
    instance: &Instance,
    device: &Device,
    picked: &Picked,
    ray_query: bool,
) -> Result<Allocator, GpuError> {
    Allocator::new(&AllocatorCreateDesc {
        instance: ash::Instance::clone(instance),
        device: ash::Device::clone(device),
        physical_device: picked.physical_device,
        debug_settings: Default::default(),
        // Acceleration-structure build inputs and instances are given by device address.
        buffer_device_address: ray_query,
        allocation_sizes: Default::default(),
    })
    .map_err(|e| GpuError::Allocation {
        what: "allocator".into(),
        detail: e.to_string(),
    })
}

impl Drop for GpuContext {
    fn drop(&mut self) {
        // Everything made from the device holds the context (or borrows it), so it is gone;
        // what it submitted may still run.
        // SAFETY: the queue is used from this thread only, and nothing submits any more.
        let _ = unsafe { self.device.device_wait_idle() };
        let allocator = self.allocator.get_mut().unwrap_or_else(|e| e.into_inner());
        self.markers.destroy(&self.device, allocator);
        self.destroy_spares();
        // The fields drop next, in declaration order: the allocator (its memory), the
        // command pool (the spare command buffers with it), the device, the messenger, the
        // instance.
    }
}
