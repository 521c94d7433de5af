//! The Vulkan instance, the chosen device and its queue, the memory allocator and a command
//! pool: everything else in gpu/ borrows from a `GpuContext`. Set-up is in instance.rs and
//! device.rs; each object is held by its owner (owned.rs), so a set-up that fails half-way
//! destroys what it made.

use super::crash_markers::{InjectedLoss, Markers};
use super::device::{create_device, RayQueryUse};
use super::device_pick::{pick_device, DeviceInfo, DeviceWanted, Picked};
use super::error::{human_bytes, GpuError};
use super::instance::create_instance;
use super::memory_budget::{memory_facts, MemoryFacts};
use super::options::GpuOptions;
use super::owned::{CommandPool, Device, Instance, Messenger};
use super::validation::ValidationLog;
use ash::vk;
use gpu_allocator::vulkan::{Allocator, AllocatorCreateDesc};
use std::ffi::CStr;
use std::sync::atomic::AtomicU64;
use std::sync::{Arc, Mutex};

/// The fields that own Vulkan objects are declared in the order they are destroyed, the
/// reverse of their creation (Rust drops fields in declaration order, after `Drop::drop`).
pub struct GpuContext {
    pub(super) markers: Mutex<Markers>,
    /// Command buffers and fences of finished submissions, reused by the next ones: a
    /// headset session submits every frame, and new handles each time make the validation
    /// layer's bookkeeping (and some drivers') grow.
    pub(super) spare: Mutex<Vec<(vk::CommandBuffer, vk::Fence)>>,
    allocator: Mutex<Allocator>,
    pub(super) command_pool: CommandPool,
    /// vkCmdPipelineBarrier2 (VK_KHR_synchronization2: every barrier fovea records).
    pub(super) sync2: ash::khr::synchronization2::Device,
    pub(crate) queue: vk::Queue,
    pub(crate) device: Device,
    /// Held for its drop: validation messages are reported until it is destroyed.
    _messenger: Option<Messenger>,
    pub(crate) instance: Instance,
    validation_log: Arc<ValidationLog>,
    pub(super) memory: MemoryFacts,
    /// Bytes fovea holds now: [device-local, host-visible].
    pub(super) allocated: [AtomicU64; 2],
    /// The most of `allocated` held at once.
    pub(super) peak_allocated: AtomicU64,
    pub info: DeviceInfo,
    /// Whether the renderer traces with ray queries unless told otherwise.
    prefers_ray_queries: bool,
    physical_device: vk::PhysicalDevice,
    queue_family: u32,
}

/// What a caller beyond headless rendering needs from the context: a window needs surface
/// extensions and a queue that can present; an OpenXR session needs the runtime to create the
/// instance and the device (XR_KHR_vulkan_enable2) and a graphics queue.
#[derive(Default)]
pub struct ContextNeeds<'a> {
    pub instance_extensions: Vec<&'static CStr>,
    pub device_extensions: Vec<&'static CStr>,
    /// The queue must support graphics (blits into swapchain images need it), not only compute.
    pub graphics_queue: bool,
    /// Creates the instance and device in place of fovea (an OpenXR runtime does).
    pub creator: Option<&'a dyn VulkanCreator>,
}

/// Creates the Vulkan instance and device on fovea's behalf, with the create infos fovea
/// built (an OpenXR runtime adds what it needs, e.g. XR_KHR_vulkan_enable2).
pub trait VulkanCreator {
    fn create_instance(
        &self,
        entry: &ash::Entry,
        info: &vk::InstanceCreateInfo,
    ) -> Result<vk::Instance, GpuError>;
    /// The one physical device the creator requires fovea to use.
    fn physical_device(&self, instance: vk::Instance) -> Result<vk::PhysicalDevice, GpuError>;
    fn create_device(
        &self,
        entry: &ash::Entry,
        physical_device: vk::PhysicalDevice,
        info: &vk::DeviceCreateInfo,
    ) -> Result<vk::Device, GpuError>;
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
        let markers = Markers::new(
            &instance,
            &device,
            &mut allocator,
            picked.amd_marker,
            inject,
        )?;
        let memory = memory_facts(
            &instance,
            picked.physical_device,
            picked.budget,
            options.memory_limit,
        );
        tracing::info!(
            "Vulkan device: {} ({}, {}); heap {} of {}",
            picked.info.name,
            picked.info.kind,
            picked.info.driver,
            memory.device_heap,
            human_bytes(memory.heaps[memory.device_heap])
        );
        Ok(Self {
            markers: Mutex::new(markers),
            spare: Mutex::new(Vec::new()),
            allocator: Mutex::new(allocator),
            command_pool,
            sync2: ash::khr::synchronization2::Device::new(&instance, &device),
            queue,
            device,
            _messenger: messenger,
            instance,
            validation_log,
            memory,
            allocated: [AtomicU64::new(0), AtomicU64::new(0)],
            peak_allocated: AtomicU64::new(0),
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
        let markers = self.markers.get_mut().unwrap_or_else(|e| e.into_inner());
        markers.destroy(&self.device, allocator);
        self.destroy_spares();
        // The fields drop next, in declaration order: the allocator (its memory), the
        // command pool (the spare command buffers with it), the device, the messenger, the
        // instance.
    }
}
