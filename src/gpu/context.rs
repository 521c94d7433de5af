//! The Vulkan instance, the chosen device and its compute queue, the memory allocator and a
//! command pool: everything else in gpu/ borrows from a `GpuContext`.

use super::error::{GpuError, VkContext};
use super::validation::{debug_callback, ValidationLog};
use ash::vk;
use gpu_allocator::vulkan::{Allocator, AllocatorCreateDesc};
use std::ffi::{c_char, CStr};
use std::mem::ManuallyDrop;
use std::sync::{Arc, Mutex};

const VALIDATION_LAYER: &CStr = c"VK_LAYER_KHRONOS_validation";

/// How to pick and set up the device.
#[derive(Clone, Debug, Default)]
pub struct GpuOptions {
    /// A case-insensitive substring of the device name (`--device`); None picks the best.
    pub device: Option<String>,
    /// Enable VK_LAYER_KHRONOS_validation and record its messages.
    pub validation: bool,
}

impl GpuOptions {
    /// Options from the environment: `FOVEA_VALIDATION=1` turns validation on (tests use it).
    pub fn from_env() -> Self {
        Self {
            device: std::env::var("FOVEA_DEVICE").ok(),
            validation: std::env::var("FOVEA_VALIDATION").is_ok_and(|v| v == "1"),
        }
    }
}

/// Facts about the chosen device, for reports.
#[derive(Clone, Debug)]
pub struct DeviceInfo {
    pub name: String,
    pub kind: String,
    pub driver: String,
    pub api_version: String,
    /// Nanoseconds per timestamp tick.
    pub timestamp_period_ns: f64,
    pub max_storage_buffer_range: u64,
}

pub struct GpuContext {
    _entry: ash::Entry,
    pub(crate) instance: ash::Instance,
    debug: Option<(ash::ext::debug_utils::Instance, vk::DebugUtilsMessengerEXT)>,
    validation_log: Arc<ValidationLog>,
    pub(crate) device: ash::Device,
    pub(crate) queue: vk::Queue,
    pub(crate) command_pool: vk::CommandPool,
    pub(crate) allocator: ManuallyDrop<Mutex<Allocator>>,
    pub info: DeviceInfo,
}

/// Device preference: a discrete GPU beats an integrated one, which beats a CPU driver.
fn device_rank(kind: vk::PhysicalDeviceType) -> u32 {
    match kind {
        vk::PhysicalDeviceType::DISCRETE_GPU => 0,
        vk::PhysicalDeviceType::INTEGRATED_GPU => 1,
        vk::PhysicalDeviceType::VIRTUAL_GPU => 2,
        vk::PhysicalDeviceType::CPU => 3,
        _ => 4,
    }
}

fn cstr_to_string(bytes: &[c_char]) -> String {
    // SAFETY: Vulkan fills these fixed arrays with NUL-terminated strings.
    unsafe { CStr::from_ptr(bytes.as_ptr()) }
        .to_string_lossy()
        .into_owned()
}

impl GpuContext {
    pub fn new(options: &GpuOptions) -> Result<Self, GpuError> {
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
        let app = vk::ApplicationInfo::default()
            .application_name(c"fovea")
            .engine_name(c"fovea")
            .api_version(vk::API_VERSION_1_2);
        let create = vk::InstanceCreateInfo::default()
            .application_info(&app)
            .enabled_layer_names(&layers)
            .enabled_extension_names(&extensions);
        // SAFETY: the create info and the arrays it points to live until the call returns.
        let instance = unsafe { entry.create_instance(&create, None) }.vk("vkCreateInstance")?;
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
            let messenger = unsafe { loader.create_debug_utils_messenger(&info, None) }
                .vk("vkCreateDebugUtilsMessengerEXT")?;
            Some((loader, messenger))
        } else {
            None
        };
        // The entry (the loaded library) must outlive the instance on the error path too.
        match Self::with_instance(entry.clone(), instance, debug, validation_log, options) {
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
    ) -> Result<Self, Box<PartialInstance>> {
        let picked = match pick_device(&instance, options.device.as_deref()) {
            Ok(p) => p,
            Err(e) => return Err(Box::new((e, instance, debug))),
        };
        let (physical_device, queue_family, info) = picked;
        let priorities = [1.0f32];
        let queue_info = [vk::DeviceQueueCreateInfo::default()
            .queue_family_index(queue_family)
            .queue_priorities(&priorities)];
        let mut features12 = vk::PhysicalDeviceVulkan12Features::default().host_query_reset(true);
        let device_info = vk::DeviceCreateInfo::default()
            .queue_create_infos(&queue_info)
            .push_next(&mut features12);
        // SAFETY: physical_device came from this instance; the create info outlives the call.
        let device = match unsafe { instance.create_device(physical_device, &device_info, None) } {
            Ok(d) => d,
            Err(result) => {
                return Err(Box::new((
                    GpuError::Vulkan {
                        call: "vkCreateDevice",
                        result,
                    },
                    instance,
                    debug,
                )));
            }
        };
        // SAFETY: queue 0 of a family we requested.
        let queue = unsafe { device.get_device_queue(queue_family, 0) };
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
        let allocator = match Allocator::new(&AllocatorCreateDesc {
            instance: instance.clone(),
            device: device.clone(),
            physical_device,

            debug_settings: Default::default(),
            buffer_device_address: false,
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
        tracing::info!(
            "Vulkan device: {} ({}, {})",
            info.name,
            info.kind,
            info.driver
        );
        Ok(Self {
            _entry: entry,
            instance,
            debug,
            validation_log,

            device,
            queue,
            command_pool,
            allocator: ManuallyDrop::new(Mutex::new(allocator)),
            info,
        })
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

    /// Records commands with `record`, submits them and waits for completion. `pass` names the
    /// work, so a device loss can say which pass was running.
    /// Records a barrier that makes every compute-shader write before it visible to every
    /// compute-shader read or write after it (images stay in GENERAL layout between passes).
    pub fn cmd_compute_barrier(&self, cmd: vk::CommandBuffer) {
        let barrier = [vk::MemoryBarrier::default()
            .src_access_mask(vk::AccessFlags::SHADER_WRITE)
            .dst_access_mask(vk::AccessFlags::SHADER_READ | vk::AccessFlags::SHADER_WRITE)];
        // SAFETY: cmd is a recording command buffer of this device, outside any render pass.
        unsafe {
            self.device.cmd_pipeline_barrier(
                cmd,
                vk::PipelineStageFlags::COMPUTE_SHADER,
                vk::PipelineStageFlags::COMPUTE_SHADER,
                vk::DependencyFlags::empty(),
                &barrier,
                &[],
                &[],
            )
        };
    }

    pub fn submit_and_wait(
        &self,
        pass: &str,
        record: impl FnOnce(vk::CommandBuffer),
    ) -> Result<(), GpuError> {
        let alloc = vk::CommandBufferAllocateInfo::default()
            .command_pool(self.command_pool)
            .level(vk::CommandBufferLevel::PRIMARY)
            .command_buffer_count(1);
        // SAFETY: the pool belongs to this device and is only used from this thread.
        let cmd = unsafe { self.device.allocate_command_buffers(&alloc) }
            .vk("vkAllocateCommandBuffers")?[0];
        let result = self.record_submit_wait(cmd, pass, record);
        // SAFETY: the submission has completed (or failed) so the buffer is no longer in use.
        unsafe { self.device.free_command_buffers(self.command_pool, &[cmd]) };
        result
    }

    fn record_submit_wait(
        &self,
        cmd: vk::CommandBuffer,
        pass: &str,
        record: impl FnOnce(vk::CommandBuffer),
    ) -> Result<(), GpuError> {
        let begin = vk::CommandBufferBeginInfo::default()
            .flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT);
        // SAFETY: cmd is a fresh primary command buffer of this device.
        unsafe { self.device.begin_command_buffer(cmd, &begin) }.vk("vkBeginCommandBuffer")?;
        record(cmd);
        // SAFETY: recording was begun above.
        unsafe { self.device.end_command_buffer(cmd) }.vk("vkEndCommandBuffer")?;
        // SAFETY: fence creation with default info.
        let fence = unsafe {
            self.device
                .create_fence(&vk::FenceCreateInfo::default(), None)
        }
        .vk("vkCreateFence")?;
        let cmds = [cmd];
        let submit = [vk::SubmitInfo::default().command_buffers(&cmds)];
        // SAFETY: the queue is used only from this thread; cmd and fence are valid.
        let waited = unsafe {
            self.device
                .queue_submit(self.queue, &submit, fence)
                .and_then(|_| self.device.wait_for_fences(&[fence], true, u64::MAX))
        };
        // SAFETY: the fence is signalled or the submission failed; either way it is unused now.
        unsafe { self.device.destroy_fence(fence, None) };
        match waited {
            Err(vk::Result::ERROR_DEVICE_LOST) => Err(GpuError::DeviceLost {
                last_pass: pass.to_string(),
            }),
            other => other.vk("vkQueueSubmit/vkWaitForFences"),
        }
    }
}

/// An instance (and its debug messenger) whose device set-up failed, with the reason.
type PartialInstance = (
    GpuError,
    ash::Instance,
    Option<(ash::ext::debug_utils::Instance, vk::DebugUtilsMessengerEXT)>,
);

type Picked = (vk::PhysicalDevice, u32, DeviceInfo);

fn pick_device(instance: &ash::Instance, wanted: Option<&str>) -> Result<Picked, GpuError> {
    // SAFETY: enumeration on a valid instance.
    let devices =
        unsafe { instance.enumerate_physical_devices() }.vk("vkEnumeratePhysicalDevices")?;
    let mut candidates = Vec::new();
    for pd in devices {
        // SAFETY: pd was just enumerated from this instance.
        let (props, families) = unsafe {
            (
                instance.get_physical_device_properties(pd),
                instance.get_physical_device_queue_family_properties(pd),
            )
        };
        if props.api_version < vk::API_VERSION_1_2 {
            continue;
        }
        let Some(family) = families.iter().position(|f| {
            f.queue_flags.contains(vk::QueueFlags::COMPUTE) && f.timestamp_valid_bits > 0
        }) else {
            continue;
        };
        let mut driver = vk::PhysicalDeviceDriverProperties::default();
        let mut props2 = vk::PhysicalDeviceProperties2::default().push_next(&mut driver);
        // SAFETY: Vulkan 1.2 device, properties2 is core.
        unsafe { instance.get_physical_device_properties2(pd, &mut props2) };
        let info = DeviceInfo {
            name: cstr_to_string(&props.device_name),
            kind: format!("{:?}", props.device_type),
            driver: format!(
                "{} {}",
                cstr_to_string(&driver.driver_name),
                cstr_to_string(&driver.driver_info)
            ),
            api_version: format!(
                "{}.{}.{}",
                vk::api_version_major(props.api_version),
                vk::api_version_minor(props.api_version),
                vk::api_version_patch(props.api_version)
            ),
            timestamp_period_ns: props.limits.timestamp_period as f64,
            max_storage_buffer_range: props.limits.max_storage_buffer_range as u64,
        };
        candidates.push((device_rank(props.device_type), pd, family as u32, info));
    }
    if candidates.is_empty() {
        return Err(GpuError::NoDevice);
    }
    if let Some(wanted) = wanted {
        let needle = wanted.to_lowercase();
        let available = candidates
            .iter()
            .map(|c| c.3.name.clone())
            .collect::<Vec<_>>()
            .join(", ");
        candidates.retain(|c| c.3.name.to_lowercase().contains(&needle));
        if candidates.is_empty() {
            return Err(GpuError::DeviceNotFound {
                wanted: wanted.to_string(),
                available,
            });
        }
    }
    candidates.sort_by_key(|c| c.0);
    let (_, pd, family, info) = candidates.swap_remove(0);
    Ok((pd, family, info))
}

impl Drop for GpuContext {
    fn drop(&mut self) {
        // SAFETY: all resources created from the device were dropped before the context (they
        // borrow it); wait for idle, then destroy in reverse order of creation.
        unsafe {
            let _ = self.device.device_wait_idle();
            ManuallyDrop::drop(&mut self.allocator);
            self.device.destroy_command_pool(self.command_pool, None);
            self.device.destroy_device(None);
            if let Some((loader, messenger)) = self.debug.take() {
                loader.destroy_debug_utils_messenger(messenger, None);
            }
            self.instance.destroy_instance(None);
        }
    }
}
