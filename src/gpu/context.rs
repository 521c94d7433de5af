//! The Vulkan instance, the chosen device and its compute queue, the memory allocator and a
//! command pool: everything else in gpu/ borrows from a `GpuContext`.

use super::crash_markers::{create_marker_buffer, InjectedLoss, MarkerSet, Markers, MARKER_SETS};
use super::device_pick::{
    driver_env, pick_device, DeviceInfo, DeviceWanted, Picked, RAY_QUERY_EXTENSIONS,
};
use super::error::{human_bytes, GpuError, VkContext};
use super::memory_budget::{memory_facts, MemoryFacts};
use super::options::{GpuOptions, RayQueries, INJECT_DEVICE_LOST_VAR};
use super::validation::{debug_callback, ValidationLog};
use ash::vk;
use gpu_allocator::vulkan::{Allocator, AllocatorCreateDesc};
use std::ffi::{c_char, CStr};
use std::mem::ManuallyDrop;
use std::sync::atomic::AtomicU64;
use std::sync::{Arc, Mutex};

const VALIDATION_LAYER: &CStr = c"VK_LAYER_KHRONOS_validation";

pub struct GpuContext {
    entry: ash::Entry,
    pub(crate) instance: ash::Instance,
    debug: Option<(ash::ext::debug_utils::Instance, vk::DebugUtilsMessengerEXT)>,
    validation_log: Arc<ValidationLog>,
    pub(crate) device: ash::Device,
    pub(crate) queue: vk::Queue,
    /// vkCmdPipelineBarrier2 (VK_KHR_synchronization2: every barrier fovea records).
    pub(super) sync2: ash::khr::synchronization2::Device,
    pub(crate) command_pool: vk::CommandPool,
    /// Command buffers and fences of finished submissions, reused by the next ones: a
    /// headset session submits every frame, and new handles each time make the validation
    /// layer's bookkeeping (and some drivers') grow.
    pub(super) spare: Mutex<Vec<(vk::CommandBuffer, vk::Fence)>>,
    pub(crate) allocator: ManuallyDrop<Mutex<Allocator>>,
    pub(super) markers: Mutex<Markers>,
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

/// An instance (and its debug messenger) whose device set-up failed, with the reason.
type PartialInstance = (
    GpuError,
    ash::Instance,
    Option<(ash::ext::debug_utils::Instance, vk::DebugUtilsMessengerEXT)>,
);

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

    pub fn new_with(options: &GpuOptions, needs: &ContextNeeds) -> Result<Self, GpuError> {
        if let Some((var, value, problem)) = &options.env_problem {
            return Err(GpuError::BadEnvironment {
                var,
                value: value.clone(),
                problem: problem.clone(),
            });
        }
        if let Some(Err(problem)) = options
            .inject_device_lost
            .as_deref()
            .map(InjectedLoss::parse)
        {
            return Err(GpuError::BadEnvironment {
                var: INJECT_DEVICE_LOST_VAR,
                value: options.inject_device_lost.clone().unwrap_or_default(),
                problem,
            });
        }
        // SAFETY: loading the system Vulkan loader; its symbols are used only through ash.
        let entry = unsafe { ash::Entry::load() }.map_err(|e| GpuError::NoLoader(e.to_string()))?;
        let mut layers: Vec<*const c_char> = Vec::new();
        let mut extensions: Vec<*const c_char> = Vec::new();
        if options.validation {
            // SAFETY: plain enumeration call on a loaded entry.
            let available = unsafe { entry.enumerate_instance_layer_properties() }
                .vk("vkEnumerateInstanceLayerProperties")?;
            if !available
                .iter()
                .any(|l| l.layer_name_as_c_str() == Ok(VALIDATION_LAYER))
            {
                return Err(GpuError::NoValidationLayer);
            }
            layers.push(VALIDATION_LAYER.as_ptr());
            extensions.push(ash::ext::debug_utils::NAME.as_ptr());
        }
        extensions.extend(needs.instance_extensions.iter().map(|e| e.as_ptr()));
        let checks = validation_features(options);
        if !checks.is_empty() {
            // SAFETY: plain enumeration call on a loaded entry, for a layer that is present.
            let offered =
                unsafe { entry.enumerate_instance_extension_properties(Some(VALIDATION_LAYER)) }
                    .vk("vkEnumerateInstanceExtensionProperties")?;
            if !offered
                .iter()
                .any(|e| e.extension_name_as_c_str() == Ok(ash::ext::validation_features::NAME))
            {
                return Err(GpuError::NoValidationFeatures);
            }
            extensions.push(ash::ext::validation_features::NAME.as_ptr());
        }
        let mut features =
            vk::ValidationFeaturesEXT::default().enabled_validation_features(&checks);
        let app = vk::ApplicationInfo::default()
            .application_name(c"fovea")
            .engine_name(c"fovea")
            .api_version(vk::API_VERSION_1_2);
        let mut create = vk::InstanceCreateInfo::default()
            .application_info(&app)
            .enabled_layer_names(&layers)
            .enabled_extension_names(&extensions);
        if !checks.is_empty() {
            create = create.push_next(&mut features);
        }
        let created = match needs.creator {
            Some(creator) => creator.create_instance(&entry, &create).map(|handle| {
                // SAFETY: the creator returned a live instance made from this entry's loader.
                unsafe { ash::Instance::load(entry.static_fn(), handle) }
            }),
            // SAFETY: the create info and the arrays it points to live until the call returns.
            None => {
                unsafe { entry.create_instance(&create, None) }.map_err(|result| GpuError::Vulkan {
                    call: "vkCreateInstance",
                    result,
                })
            }
        };
        let instance = match created {
            Ok(instance) => instance,
            // What the loader returns when it finds no driver at all.
            Err(GpuError::Vulkan {
                result: result @ vk::Result::ERROR_INCOMPATIBLE_DRIVER,
                ..
            }) => {
                return Err(GpuError::NoDevice {
                    detail: format!(
                        "the Vulkan loader found no driver (vkCreateInstance: {result}){}",
                        driver_env()
                    ),
                })
            }
            Err(e) => return Err(e),
        };
        let validation_log = Arc::<ValidationLog>::default();
        let debug = if options.validation {
            let loader = ash::ext::debug_utils::Instance::new(&entry, &instance);
            let info = vk::DebugUtilsMessengerCreateInfoEXT::default()
                .message_severity(
                    vk::DebugUtilsMessageSeverityFlagsEXT::ERROR
                        | vk::DebugUtilsMessageSeverityFlagsEXT::WARNING,
                )
                .message_type(
                    vk::DebugUtilsMessageTypeFlagsEXT::VALIDATION
                        | vk::DebugUtilsMessageTypeFlagsEXT::GENERAL,
                )
                .pfn_user_callback(Some(debug_callback))
                .user_data(Arc::as_ptr(&validation_log) as *mut std::ffi::c_void);
            // SAFETY: the context holds an Arc of the log and destroys the messenger before dropping it.
            match unsafe { loader.create_debug_utils_messenger(&info, None) } {
                Ok(messenger) => Some((loader, messenger)),
                Err(result) => {
                    // SAFETY: nothing else was created from the instance.
                    unsafe { instance.destroy_instance(None) };
                    return Err(GpuError::Vulkan {
                        call: "vkCreateDebugUtilsMessengerEXT",
                        result,
                    });
                }
            }
        } else {
            None
        };
        // The entry (the loaded library) must outlive the instance on the error path too.
        match Self::with_instance(
            entry.clone(),
            instance,
            debug,
            validation_log,
            options,
            needs,
        ) {
            Ok(ctx) => Ok(ctx),
            Err(failed) => {
                let (e, instance, debug) = *failed;
                // SAFETY: nothing was created from the instance but the messenger.
                unsafe {
                    if let Some((loader, messenger)) = debug {
                        loader.destroy_debug_utils_messenger(messenger, None);
                    }
                    instance.destroy_instance(None);
                }
                Err(e)
            }
        }
    }

    /// Finishes set-up on a created instance; on failure hands the instance (and messenger)
    /// back so the caller destroys them.
    fn with_instance(
        entry: ash::Entry,
        instance: ash::Instance,
        debug: Option<(ash::ext::debug_utils::Instance, vk::DebugUtilsMessengerEXT)>,
        validation_log: Arc<ValidationLog>,
        options: &GpuOptions,
        needs: &ContextNeeds,
    ) -> Result<Self, Box<PartialInstance>> {
        let required = match needs.creator {
            Some(creator) => match creator.physical_device(instance.handle()) {
                Ok(pd) => Some(pd),
                Err(e) => return Err(Box::new((e, instance, debug))),
            },
            None => None,
        };
        let wanted = DeviceWanted {
            name: options.device.as_deref(),
            physical_device: required,
            graphics: needs.graphics_queue,
            extensions: &needs.device_extensions,
        };
        let picked = match pick_device(&instance, &wanted) {
            Ok(p) => p,
            Err(e) => return Err(Box::new((e, instance, debug))),
        };
        let Picked {
            physical_device,
            family: queue_family,
            mut info,
            budget,
            amd_marker,
        } = picked;
        match options.ray_queries {
            RayQueries::Off => info.ray_query = None,
            RayQueries::Required if info.ray_query.is_none() => {
                let e = GpuError::NoRayQueries {
                    device: info.name.clone(),
                };
                return Err(Box::new((e, instance, debug)));
            }
            _ => {}
        }
        let ray_query = info.ray_query.is_some();
        // On a CPU driver ray queries run the driver's traversal on the same cores as ours,
        // and lavapipe's measured 2.3-5.9x slower than fovea's (README, "Ray queries"): there
        // `auto` keeps the software traversal (both stay available, e.g. to render --bench).
        let prefers_ray_queries =
            ray_query && (options.ray_queries == RayQueries::Required || info.kind != "CPU");
        let priorities = [1.0f32];
        let queue_info = [vk::DeviceQueueCreateInfo::default()
            .queue_family_index(queue_family)
            .queue_priorities(&priorities)];
        let mut device_extensions = Vec::new();
        if budget {
            device_extensions.push(ash::ext::memory_budget::NAME.as_ptr());
        }
        if amd_marker {
            device_extensions.push(ash::amd::buffer_marker::NAME.as_ptr());
        }
        device_extensions.push(ash::khr::synchronization2::NAME.as_ptr());
        if ray_query {
            device_extensions.extend(RAY_QUERY_EXTENSIONS.iter().map(|e| e.as_ptr()));
        }
        device_extensions.extend(needs.device_extensions.iter().map(|e| e.as_ptr()));
        let mut features12 = vk::PhysicalDeviceVulkan12Features::default()
            .host_query_reset(true)
            .buffer_device_address(ray_query);
        let mut sync2 =
            vk::PhysicalDeviceSynchronization2Features::default().synchronization2(true);
        let mut accel_features = vk::PhysicalDeviceAccelerationStructureFeaturesKHR::default()
            .acceleration_structure(true);
        let mut query_features = vk::PhysicalDeviceRayQueryFeaturesKHR::default().ray_query(true);
        let mut device_info = vk::DeviceCreateInfo::default()
            .queue_create_infos(&queue_info)
            .enabled_extension_names(&device_extensions)
            .push_next(&mut features12)
            .push_next(&mut sync2);
        if ray_query {
            device_info = device_info
                .push_next(&mut accel_features)
                .push_next(&mut query_features);
        }
        let created = match needs.creator {
            Some(creator) => creator
                .create_device(&entry, physical_device, &device_info)
                .map(|handle| {
                    // SAFETY: the creator returned a live device of this instance.
                    unsafe { ash::Device::load(instance.fp_v1_0(), handle) }
                }),
            // SAFETY: physical_device came from this instance; the create info outlives the call.
            None => unsafe { instance.create_device(physical_device, &device_info, None) }.map_err(
                |result| GpuError::Vulkan {
                    call: "vkCreateDevice",
                    result,
                },
            ),
        };
        let device = match created {
            Ok(d) => d,
            Err(e) => return Err(Box::new((e, instance, debug))),
        };
        // SAFETY: queue 0 of a family we requested.
        let queue = unsafe { device.get_device_queue(queue_family, 0) };
        let sync2 = ash::khr::synchronization2::Device::new(&instance, &device);
        let pool_info = vk::CommandPoolCreateInfo::default()
            .queue_family_index(queue_family)
            .flags(vk::CommandPoolCreateFlags::RESET_COMMAND_BUFFER);
        // SAFETY: valid device and create info.
        let command_pool = match unsafe { device.create_command_pool(&pool_info, None) } {
            Ok(p) => p,
            Err(result) => {
                // SAFETY: the device has no child objects yet.
                unsafe { device.destroy_device(None) };
                return Err(Box::new((
                    GpuError::Vulkan {
                        call: "vkCreateCommandPool",
                        result,
                    },
                    instance,
                    debug,
                )));
            }
        };
        let mut allocator = match Allocator::new(&AllocatorCreateDesc {
            instance: instance.clone(),
            device: device.clone(),
            physical_device,

            debug_settings: Default::default(),
            // Acceleration-structure build inputs and instances are given by device address.
            buffer_device_address: ray_query,
            allocation_sizes: Default::default(),
        }) {
            Ok(a) => a,
            Err(e) => {
                // SAFETY: only the pool was created on the device.
                unsafe {
                    device.destroy_command_pool(command_pool, None);
                    device.destroy_device(None);
                }
                let err = GpuError::Allocation {
                    what: "allocator".into(),
                    detail: e.to_string(),
                };
                return Err(Box::new((err, instance, debug)));
            }
        };
        let (buffer, allocation) = match create_marker_buffer(&device, &mut allocator) {
            Ok(b) => b,
            Err(err) => {
                drop(allocator);
                // SAFETY: the allocator (which freed its memory) and the pool are all that was
                // created on the device.
                unsafe {
                    device.destroy_command_pool(command_pool, None);
                    device.destroy_device(None);
                }
                return Err(Box::new((err, instance, debug)));
            }
        };
        let markers = Markers {
            buffer,
            allocation: Some(allocation),
            amd: amd_marker.then(|| ash::amd::buffer_marker::Device::new(&instance, &device)),
            sets: (0..MARKER_SETS).map(|_| MarkerSet::default()).collect(),
            recording: None,
            // Checked by new_with.
            inject: (options.inject_device_lost.as_deref())
                .and_then(|t| InjectedLoss::parse(t).ok()),
            inject_seen: 0,
        };
        let memory = memory_facts(&instance, physical_device, budget, options.memory_limit);
        tracing::info!(
            "Vulkan device: {} ({}, {}); heap {} of {}",
            info.name,
            info.kind,
            info.driver,
            memory.device_heap,
            human_bytes(memory.heaps[memory.device_heap])
        );
        Ok(Self {
            entry,
            instance,
            debug,
            validation_log,

            device,
            queue,
            sync2,
            command_pool,
            spare: Mutex::new(Vec::new()),
            allocator: ManuallyDrop::new(Mutex::new(allocator)),
            markers: Mutex::new(markers),
            memory,
            allocated: [AtomicU64::new(0), AtomicU64::new(0)],
            peak_allocated: AtomicU64::new(0),
            info,
            prefers_ray_queries,
            physical_device,
            queue_family,
        })
    }

    /// Whether frames trace with ray queries by default: they are enabled, and either asked
    /// for (`--traversal rayquery`) or the device is a GPU (`auto`).
    pub fn prefers_ray_queries(&self) -> bool {
        self.prefers_ray_queries
    }

    pub(crate) fn entry(&self) -> &ash::Entry {
        &self.entry
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

    pub fn validation_enabled(&self) -> bool {
        self.debug.is_some()
    }

    pub(crate) fn allocator(&self) -> std::sync::MutexGuard<'_, Allocator> {
        self.allocator.lock().unwrap_or_else(|e| e.into_inner())
    }
}

/// The validation layer's optional checks that `options` asks for (none without validation).
fn validation_features(options: &GpuOptions) -> Vec<vk::ValidationFeatureEnableEXT> {
    let checks = &options.checks;
    let mut enabled = Vec::new();
    if options.validation && checks.synchronization {
        enabled.push(vk::ValidationFeatureEnableEXT::SYNCHRONIZATION_VALIDATION);
    }
    if options.validation && checks.gpu_assisted {
        enabled.push(vk::ValidationFeatureEnableEXT::GPU_ASSISTED);
    }
    enabled
}

impl Drop for GpuContext {
    fn drop(&mut self) {
        let markers = self.markers.get_mut().unwrap_or_else(|e| e.into_inner());
        // SAFETY: all resources created from the device were dropped before the context (they
        // borrow it); wait for idle, then destroy in reverse order of creation.
        unsafe {
            let _ = self.device.device_wait_idle();
            if let Some(allocation) = markers.allocation.take() {
                let _ = self
                    .allocator
                    .get_mut()
                    .unwrap_or_else(|e| e.into_inner())
                    .free(allocation);
            }
            self.device.destroy_buffer(markers.buffer, None);
            ManuallyDrop::drop(&mut self.allocator);
            for (_, fence) in self
                .spare
                .get_mut()
                .unwrap_or_else(|e| e.into_inner())
                .drain(..)
            {
                self.device.destroy_fence(fence, None);
            }
            // Frees the spare command buffers too.
            self.device.destroy_command_pool(self.command_pool, None);
            self.device.destroy_device(None);
            if let Some((loader, messenger)) = self.debug.take() {
                loader.destroy_debug_utils_messenger(messenger, None);
            }
            self.instance.destroy_instance(None);
        }
    }
}
