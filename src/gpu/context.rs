//! The Vulkan instance, the chosen device and its compute queue, the memory allocator and a
//! command pool: everything else in gpu/ borrows from a `GpuContext`.

use super::error::{exact_bytes, human_bytes, GpuError, MemoryShortfall, ResourceLimit, VkContext};
use super::validation::{debug_callback, ValidationLog};
use ash::vk;
use gpu_allocator::vulkan::{
    Allocation, AllocationCreateDesc, AllocationScheme, Allocator, AllocatorCreateDesc,
};
use gpu_allocator::MemoryLocation;
use std::ffi::{c_char, CStr};
use std::mem::ManuallyDrop;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex};

const VALIDATION_LAYER: &CStr = c"VK_LAYER_KHRONOS_validation";

/// The environment variable that caps fovea's GPU memory (see [`GpuOptions::memory_limit`]).
pub const MEMORY_LIMIT_VAR: &str = "FOVEA_GPU_MEMORY_LIMIT";
/// The environment variable that injects a device loss (see [`GpuOptions::inject_device_lost`]).
pub const INJECT_DEVICE_LOST_VAR: &str = "FOVEA_INJECT_DEVICE_LOST";

/// How to pick and set up the device.
#[derive(Clone, Debug, Default)]
pub struct GpuOptions {
    /// A case-insensitive substring of the device name (`--device`); None picks the best.
    pub device: Option<String>,
    /// Enable VK_LAYER_KHRONOS_validation and record its messages.
    pub validation: bool,
    /// The most GPU memory fovea may use, in bytes, all buffers and images together; None =
    /// whatever the device offers. For sharing the GPU with other programs (the SteamVR
    /// compositor, a game engine). Scene uploads and frame targets are checked against it
    /// (and against the device's heap and, with VK_EXT_memory_budget, its budget) before
    /// anything is allocated, and every allocation is refused past it, so running out gives a
    /// message with the sizes instead of a driver error. Set by `FOVEA_GPU_MEMORY_LIMIT`:
    /// bytes with an optional K, M, G or T suffix (powers of 1024), e.g. `6G` or `512M`.
    pub memory_limit: Option<u64>,
    /// Testing only: the name of a pass (as the GPU timestamps name it, e.g. `trace` or
    /// `left fill`) after which every command buffer containing it ends, and whose submission
    /// then reports VK_ERROR_DEVICE_LOST as a driver would. The error is built by the real
    /// crash-marker read-back, so tests exercise that path on lavapipe, which never loses its
    /// device. A real device loss was not reproduced while writing this. Set by
    /// `FOVEA_INJECT_DEVICE_LOST`.
    pub inject_device_lost: Option<String>,
    /// A bad environment value seen by [`Self::from_env`]: (variable, value, problem).
    /// [`GpuContext::new`] reports it before touching Vulkan.
    env_problem: Option<(&'static str, String, String)>,
}

impl GpuOptions {
    /// Options from the environment: `FOVEA_VALIDATION=1` turns validation on (tests use it),
    /// `FOVEA_DEVICE` picks a device, `FOVEA_GPU_MEMORY_LIMIT` caps GPU memory and
    /// `FOVEA_INJECT_DEVICE_LOST` injects a device loss (see the fields). A value that cannot
    /// be used is reported by [`GpuContext::new`].
    pub fn from_env() -> Self {
        let mut options = Self {
            device: std::env::var("FOVEA_DEVICE").ok(),
            validation: std::env::var("FOVEA_VALIDATION").is_ok_and(|v| v == "1"),
            inject_device_lost: std::env::var(INJECT_DEVICE_LOST_VAR)
                .ok()
                .filter(|v| !v.is_empty()),
            ..Self::default()
        };
        match std::env::var(MEMORY_LIMIT_VAR) {
            Ok(value) if !value.trim().is_empty() => match parse_byte_size(&value) {
                Ok(bytes) => options.memory_limit = Some(bytes),
                Err(problem) => options.env_problem = Some((MEMORY_LIMIT_VAR, value, problem)),
            },
            Ok(_) => {}
            Err(std::env::VarError::NotPresent) => {}
            Err(std::env::VarError::NotUnicode(value)) => {
                options.env_problem = Some((
                    MEMORY_LIMIT_VAR,
                    value.to_string_lossy().into_owned(),
                    "is not text: give a size such as 6G or 512M, or unset it for no limit".into(),
                ))
            }
        }
        options
    }
}

/// Parses a memory size: bytes with an optional K, M, G or T suffix (powers of 1024, "KB",
/// "KiB" and lower case accepted too) and an optional fraction ("1.5G"). Zero is refused: a
/// limit of nothing is a mistake. The error says what is wrong, for `VAR='value' <error>`.
pub(crate) fn parse_byte_size(text: &str) -> Result<u64, String> {
    const HOW: &str = "give bytes with an optional K, M, G or T suffix (powers of 1024), \
         e.g. 6G or 512M, or unset it for no limit";
    let text = text.trim();
    let split = text
        .find(|c: char| !(c.is_ascii_digit() || c == '.'))
        .unwrap_or(text.len());
    let (number, unit) = text.split_at(split);
    let scale: u64 = match unit.trim().to_ascii_uppercase().as_str() {
        "" | "B" => 1,
        "K" | "KB" | "KIB" => 1 << 10,
        "M" | "MB" | "MIB" => 1 << 20,
        "G" | "GB" | "GIB" => 1 << 30,
        "T" | "TB" | "TIB" => 1 << 40,
        _ => return Err(format!("is not a memory size: {HOW}")),
    };
    let bytes = if number.contains('.') {
        match number.parse::<f64>() {
            Ok(n) if (n * scale as f64) < u64::MAX as f64 => Some((n * scale as f64) as u64),
            Ok(_) => None,
            Err(_) => return Err(format!("is not a memory size: {HOW}")),
        }
    } else {
        match number.parse::<u64>() {
            Ok(n) => n.checked_mul(scale),
            Err(e) if *e.kind() == std::num::IntErrorKind::PosOverflow => None,
            Err(_) => return Err(format!("is not a memory size: {HOW}")),
        }
    };
    match bytes {
        None => Err(format!("is larger than any memory (over 16 EiB): {HOW}")),
        Some(0) => Err(format!("leaves fovea no GPU memory at all: {HOW}")),
        Some(bytes) => Ok(bytes),
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

/// One allocation of a plan checked by [`GpuContext::check_memory`] before any is made.
#[derive(Clone, Debug)]
pub struct PlannedAllocation {
    /// As the message should name it, e.g. "layer images".
    pub name: String,
    pub bytes: u64,
    /// In host-visible memory (staging, per-frame uploads, read-backs), not device-local.
    pub host_visible: bool,
    /// Bound as one storage buffer, so also limited by maxStorageBufferRange.
    pub storage_buffer: bool,
}

impl PlannedAllocation {
    /// A device-local storage buffer.
    pub fn storage(name: &str, bytes: u64) -> Self {
        Self {
            name: name.into(),
            bytes,
            host_visible: false,
            storage_buffer: true,
        }
    }

    /// A device-local image.
    pub fn image(name: &str, bytes: u64) -> Self {
        Self {
            name: name.into(),
            bytes,
            host_visible: false,
            storage_buffer: false,
        }
    }

    /// A host-visible buffer (`storage_buffer`: bound to a shader, not only copied).
    pub fn host(name: &str, bytes: u64, storage_buffer: bool) -> Self {
        Self {
            name: name.into(),
            bytes,
            host_visible: true,
            storage_buffer,
        }
    }
}

/// Memory facts of the device, fixed at creation.
struct MemoryFacts {
    physical_device: vk::PhysicalDevice,
    /// Size of every heap.
    heaps: Vec<u64>,
    /// The largest heap with a device-local memory type (where images and static buffers go).
    device_heap: usize,
    /// The largest heap with a host-visible memory type (staging, read-backs). The same as
    /// `device_heap` on unified-memory devices (integrated GPUs, lavapipe).
    host_heap: usize,
    /// VK_EXT_memory_budget is enabled: the current budget can be asked for.
    budget: bool,
    max_memory_allocation_size: u64,
    limit: Option<u64>,
}

/// Crash markers, in the style of kajiya: after every pass the command buffer writes the
/// pass's index into its own slot of a small host-visible buffer; on VK_ERROR_DEVICE_LOST the
/// slots that were written say which pass completed last and so which one was running.
struct Markers {
    buffer: vk::Buffer,
    allocation: Option<Allocation>,
    /// VK_AMD_buffer_marker where the device offers it (a write that the GPU performs once
    /// all earlier work is done, without a barrier); otherwise a barrier and vkCmdFillBuffer.
    amd: Option<ash::amd::buffer_marker::Device>,
    /// The passes of the submission being recorded or run, in order; slot i belongs to pass i.
    names: Vec<String>,
    /// An injected loss ended the recording: later passes are named but not recorded.
    cut: bool,
}

/// Passes per submission that get a crash marker; later ones are not tracked.
const MARKER_SLOTS: usize = 256;

pub struct GpuContext {
    _entry: ash::Entry,
    pub(crate) instance: ash::Instance,
    debug: Option<(ash::ext::debug_utils::Instance, vk::DebugUtilsMessengerEXT)>,
    validation_log: Arc<ValidationLog>,
    pub(crate) device: ash::Device,
    pub(crate) queue: vk::Queue,
    pub(crate) command_pool: vk::CommandPool,
    pub(crate) allocator: ManuallyDrop<Mutex<Allocator>>,
    markers: Mutex<Markers>,
    memory: MemoryFacts,
    /// Bytes fovea holds now: [device-local, host-visible].
    allocated: [AtomicU64; 2],
    inject_device_lost: Option<String>,
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

/// The loader's driver-selecting environment variables that are set, for a no-device message.
fn driver_env() -> String {
    let set: Vec<String> = [
        "VK_DRIVER_FILES",
        "VK_ICD_FILENAMES",
        "VK_ADD_DRIVER_FILES",
        "VK_LOADER_DRIVERS_SELECT",
        "VK_LOADER_DRIVERS_DISABLE",
    ]
    .iter()
    .filter_map(|var| std::env::var(var).ok().map(|v| format!("{var}={v}")))
    .collect();
    match set.is_empty() {
        true => String::new(),
        false => format!(
            " ({} is set and limits the drivers the loader tries: unset it to use the installed ones)",
            set.join(", ")
        ),
    }
}

impl GpuContext {
    pub fn new(options: &GpuOptions) -> Result<Self, GpuError> {
        if let Some((var, value, problem)) = &options.env_problem {
            return Err(GpuError::BadEnvironment {
                var,
                value: value.clone(),
                problem: problem.clone(),
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
        let app = vk::ApplicationInfo::default()
            .application_name(c"fovea")
            .engine_name(c"fovea")
            .api_version(vk::API_VERSION_1_2);
        let create = vk::InstanceCreateInfo::default()
            .application_info(&app)
            .enabled_layer_names(&layers)
            .enabled_extension_names(&extensions);
        // SAFETY: the create info and the arrays it points to live until the call returns.
        let instance = match unsafe { entry.create_instance(&create, None) } {
            Ok(instance) => instance,
            // What the loader returns when it finds no driver at all.
            Err(result @ vk::Result::ERROR_INCOMPATIBLE_DRIVER) => {
                return Err(GpuError::NoDevice {
                    detail: format!(
                        "the Vulkan loader found no driver (vkCreateInstance: {result}){}",
                        driver_env()
                    ),
                })
            }
            Err(result) => {
                return Err(GpuError::Vulkan {
                    call: "vkCreateInstance",
                    result,
                })
            }
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
        let Picked {
            physical_device,
            family: queue_family,
            info,
            budget,
            amd_marker,
        } = picked;
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
        let mut features12 = vk::PhysicalDeviceVulkan12Features::default().host_query_reset(true);
        let device_info = vk::DeviceCreateInfo::default()
            .queue_create_infos(&queue_info)
            .enabled_extension_names(&device_extensions)
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
        let mut allocator = match Allocator::new(&AllocatorCreateDesc {
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
            names: Vec::new(),
            cut: false,
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
            _entry: entry,
            instance,
            debug,
            validation_log,

            device,
            queue,
            command_pool,
            allocator: ManuallyDrop::new(Mutex::new(allocator)),
            markers: Mutex::new(markers),
            memory,
            allocated: [AtomicU64::new(0), AtomicU64::new(0)],
            inject_device_lost: options.inject_device_lost.clone(),
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

    fn markers(&self) -> std::sync::MutexGuard<'_, Markers> {
        self.markers.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// The GPU memory cap from [`GpuOptions::memory_limit`], if any.
    pub fn memory_limit(&self) -> Option<u64> {
        self.memory.limit
    }

    /// Bytes of GPU memory fovea's buffers and images hold now.
    pub fn memory_in_use(&self) -> u64 {
        self.allocated
            .iter()
            .map(|a| a.load(Ordering::Relaxed))
            .sum()
    }

    fn heap_of(&self, host_visible: bool) -> usize {
        match host_visible {
            true => self.memory.host_heap,
            false => self.memory.device_heap,
        }
    }

    /// (budget, usage) of every heap now, with VK_EXT_memory_budget.
    fn budget_now(&self) -> Option<Vec<(u64, u64)>> {
        if !self.memory.budget {
            return None;
        }
        let mut budget = vk::PhysicalDeviceMemoryBudgetPropertiesEXT::default();
        let mut props = vk::PhysicalDeviceMemoryProperties2::default().push_next(&mut budget);
        // SAFETY: VK_EXT_memory_budget is enabled on the device; the chain lives for the call.
        unsafe {
            self.instance
                .get_physical_device_memory_properties2(self.memory.physical_device, &mut props)
        };
        Some(
            (0..self.memory.heaps.len())
                .map(|h| (budget.heap_budget[h], budget.heap_usage[h]))
                .collect(),
        )
    }

    /// Checks, before anything is allocated, that `plan` fits: the total against the memory
    /// the device offers (heap size, and the budget with VK_EXT_memory_budget) beside what
    /// fovea already holds and against [`GpuOptions::memory_limit`]; each item against
    /// maxMemoryAllocationSize, and storage buffers against maxStorageBufferRange. `what`
    /// names the plan ("scene 'bunny'", "frame targets of ..."); `advice` says what to change.
    pub fn check_memory(
        &self,
        what: &str,
        plan: &[PlannedAllocation],
        advice: &str,
    ) -> Result<(), GpuError> {
        let needed: u64 = plan.iter().map(|p| p.bytes).sum();
        let in_use = self.memory_in_use();
        let heaps = &self.memory.heaps;
        let mut needed_on = vec![0u64; heaps.len()];
        for p in plan {
            needed_on[self.heap_of(p.host_visible)] += p.bytes;
        }
        let mut held_on = vec![0u64; heaps.len()];
        for (host, held) in [(false, &self.allocated[0]), (true, &self.allocated[1])] {
            held_on[self.heap_of(host)] += held.load(Ordering::Relaxed);
        }
        let budget = self.budget_now();
        let mut fits = true;
        let mut offered = Vec::new();
        for (h, &size) in heaps.iter().enumerate() {
            if needed_on[h] == 0 {
                continue;
            }
            let kind = match (h == self.memory.device_heap, h == self.memory.host_heap) {
                (true, true) => "device-local, also host-visible",
                (true, false) => "device-local",
                _ => "host-visible",
            };
            let mut free = size.saturating_sub(held_on[h]);
            let mut text = format!("memory heap {h} ({kind}) has {}", exact_bytes(size));
            if let Some((heap_budget, usage)) = budget.as_ref().map(|b| b[h]) {
                let within = heap_budget.saturating_sub(usage);
                free = free.min(within);
                text += &format!(
                    ", {} of it free within the driver's budget (VK_EXT_memory_budget)",
                    exact_bytes(within)
                );
            }
            fits &= needed_on[h] <= free;
            offered.push(text);
        }
        if let Some(limit) = self.memory.limit {
            fits &= in_use.saturating_add(needed) <= limit;
            offered.push(format!(
                "{MEMORY_LIMIT_VAR} caps fovea at {}",
                exact_bytes(limit)
            ));
        }
        if !fits {
            let mut items: Vec<&PlannedAllocation> = plan.iter().filter(|p| p.bytes > 0).collect();
            items.sort_by_key(|p| std::cmp::Reverse(p.bytes));
            let breakdown = items
                .iter()
                .map(|p| format!("{} {}", p.name, human_bytes(p.bytes)))
                .collect::<Vec<_>>()
                .join(", ");
            let mut advice = advice.to_owned();
            if self.memory.limit.is_some() {
                advice += &format!(", or raise or unset {MEMORY_LIMIT_VAR}");
            }
            return Err(GpuError::NotEnoughMemory(Box::new(MemoryShortfall {
                what: what.to_owned(),
                needed: format!(
                    "it needs {}, {needed} bytes ({breakdown})",
                    human_bytes(needed)
                ),
                in_use: human_bytes(in_use),
                offered: offered.join(" and "),
                advice,
            })));
        }
        for p in plan {
            let limits = [
                (
                    p.storage_buffer,
                    "storage buffer",
                    self.info.max_storage_buffer_range,
                    "maxStorageBufferRange",
                ),
                (
                    true,
                    "allocation",
                    self.memory.max_memory_allocation_size,
                    "maxMemoryAllocationSize",
                ),
            ];
            for (applies, kind, limit, limit_name) in limits {
                if applies && p.bytes > limit {
                    return Err(GpuError::ResourceTooLarge(Box::new(ResourceLimit {
                        what: what.to_owned(),
                        item: p.name.clone(),
                        kind,
                        bytes: exact_bytes(p.bytes),
                        limit: exact_bytes(limit),
                        limit_name,
                        advice: advice.to_owned(),
                    })));
                }
            }
        }
        Ok(())
    }

    /// Counts an allocation of `bytes` that memory.rs is about to make, refusing one that
    /// would take fovea past [`GpuOptions::memory_limit`].
    pub(crate) fn reserve(
        &self,
        name: &str,
        bytes: u64,
        host_visible: bool,
    ) -> Result<(), GpuError> {
        let in_use = self.memory_in_use();
        if let Some(limit) = self.memory.limit {
            if in_use.saturating_add(bytes) > limit {
                return Err(GpuError::NotEnoughMemory(Box::new(MemoryShortfall {
                    what: name.to_owned(),
                    needed: format!("it needs {}", exact_bytes(bytes)),
                    in_use: human_bytes(in_use),
                    offered: format!("{MEMORY_LIMIT_VAR} caps fovea at {}", exact_bytes(limit)),
                    advice: format!(
                        "raise or unset {MEMORY_LIMIT_VAR}, or use a smaller scene or resolution"
                    ),
                })));
            }
        }
        self.allocated[host_visible as usize].fetch_add(bytes, Ordering::Relaxed);
        Ok(())
    }

    /// Uncounts an allocation counted by [`Self::reserve`] once it is freed (or failed).
    pub(crate) fn release(&self, bytes: u64, host_visible: bool) {
        self.allocated[host_visible as usize].fetch_sub(bytes, Ordering::Relaxed);
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
            // SAFETY: cmd is recording outside a render pass; the barrier makes the fill wait
            // for every earlier command; offset and size are multiples of 4 inside the buffer.
            None => unsafe {
                self.device.cmd_pipeline_barrier(
                    cmd,
                    vk::PipelineStageFlags::ALL_COMMANDS,
                    vk::PipelineStageFlags::TRANSFER,
                    vk::DependencyFlags::empty(),
                    &[],
                    &[],
                    &[],
                );
                self.device.cmd_fill_buffer(cmd, m.buffer, offset, 4, value);
            },
        }
        if self.inject_device_lost.as_deref() == m.names.last().map(String::as_str) {
            m.cut = true;
        }
    }

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

    /// Records commands with `record`, submits them and waits for completion. `submission`
    /// names the work; passes recorded through the timestamp pool get crash markers, so a
    /// device loss says which pass completed last and which was running.
    pub fn submit_and_wait(
        &self,
        submission: &str,
        record: impl FnOnce(vk::CommandBuffer),
    ) -> Result<(), GpuError> {
        let alloc = vk::CommandBufferAllocateInfo::default()
            .command_pool(self.command_pool)
            .level(vk::CommandBufferLevel::PRIMARY)
            .command_buffer_count(1);
        // SAFETY: the pool belongs to this device and is only used from this thread.
        let cmd = unsafe { self.device.allocate_command_buffers(&alloc) }
            .vk("vkAllocateCommandBuffers")?[0];
        let result = self.record_submit_wait(cmd, submission, record);
        // SAFETY: the submission has completed (or failed) so the buffer is no longer in use.
        unsafe { self.device.free_command_buffers(self.command_pool, &[cmd]) };
        result
    }

    fn record_submit_wait(
        &self,
        cmd: vk::CommandBuffer,
        submission: &str,
        record: impl FnOnce(vk::CommandBuffer),
    ) -> Result<(), GpuError> {
        {
            let mut m = self.markers();
            m.names.clear();
            m.cut = false;
            if let Some(slots) = m.allocation.as_mut().and_then(|a| a.mapped_slice_mut()) {
                slots.fill(0);
            }
        }
        let begin = vk::CommandBufferBeginInfo::default()
            .flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT);
        // SAFETY: cmd is a fresh primary command buffer of this device.
        unsafe { self.device.begin_command_buffer(cmd, &begin) }.vk("vkBeginCommandBuffer")?;
        record(cmd);
        if !self.markers().names.is_empty() {
            let to_host = [vk::MemoryBarrier::default()
                .src_access_mask(vk::AccessFlags::TRANSFER_WRITE)
                .dst_access_mask(vk::AccessFlags::HOST_READ)];
            // SAFETY: cmd is recording outside a render pass.
            unsafe {
                self.device.cmd_pipeline_barrier(
                    cmd,
                    vk::PipelineStageFlags::ALL_COMMANDS,
                    vk::PipelineStageFlags::HOST,
                    vk::DependencyFlags::empty(),
                    &to_host,
                    &[],
                    &[],
                )
            };
        }
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
        let injected = self.markers().cut;
        let waited = match (waited, injected) {
            // The command buffer ended after the injected pass: fail as a driver would.
            (Ok(()), true) => Err(vk::Result::ERROR_DEVICE_LOST),
            (waited, _) => waited,
        };
        match waited {
            Err(vk::Result::ERROR_DEVICE_LOST) => Err(self.device_lost(submission, injected)),
            other => other.vk("vkQueueSubmit/vkWaitForFences"),
        }
    }

    /// Reads the crash markers of the failed submission into a device-lost error.
    fn device_lost(&self, submission: &str, injected: bool) -> GpuError {
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

/// The crash-marker buffer: MARKER_SLOTS u32s in host-visible memory, written by transfers.
fn create_marker_buffer(
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

/// The heaps, where allocations go, and the per-allocation limit of a device.
fn memory_facts(
    instance: &ash::Instance,
    physical_device: vk::PhysicalDevice,
    budget: bool,
    limit: Option<u64>,
) -> MemoryFacts {
    // SAFETY: physical_device was enumerated from this instance.
    let props = unsafe { instance.get_physical_device_memory_properties(physical_device) };
    let heaps: Vec<u64> = props
        .memory_heaps_as_slice()
        .iter()
        .map(|h| h.size)
        .collect();
    let largest_with = |flag: vk::MemoryPropertyFlags| {
        props
            .memory_types_as_slice()
            .iter()
            .filter(|t| t.property_flags.contains(flag))
            .map(|t| t.heap_index as usize)
            .max_by_key(|&h| heaps.get(h).copied().unwrap_or(0))
            .unwrap_or(0)
    };
    let mut maintenance3 = vk::PhysicalDeviceMaintenance3Properties::default();
    let mut props2 = vk::PhysicalDeviceProperties2::default().push_next(&mut maintenance3);
    // SAFETY: a Vulkan 1.2 device: properties2 and maintenance3 are core.
    unsafe { instance.get_physical_device_properties2(physical_device, &mut props2) };
    MemoryFacts {
        physical_device,
        device_heap: largest_with(vk::MemoryPropertyFlags::DEVICE_LOCAL),
        host_heap: largest_with(vk::MemoryPropertyFlags::HOST_VISIBLE),
        heaps,
        budget,
        max_memory_allocation_size: maintenance3.max_memory_allocation_size,
        limit,
    }
}

/// An instance (and its debug messenger) whose device set-up failed, with the reason.
type PartialInstance = (
    GpuError,
    ash::Instance,
    Option<(ash::ext::debug_utils::Instance, vk::DebugUtilsMessengerEXT)>,
);

/// The chosen device, its compute queue family and what it offers.
struct Picked {
    physical_device: vk::PhysicalDevice,
    family: u32,
    info: DeviceInfo,
    /// VK_EXT_memory_budget is supported.
    budget: bool,
    /// VK_AMD_buffer_marker is supported.
    amd_marker: bool,
}

fn pick_device(instance: &ash::Instance, wanted: Option<&str>) -> Result<Picked, GpuError> {
    // SAFETY: enumeration on a valid instance.
    let devices = match unsafe { instance.enumerate_physical_devices() } {
        Ok(devices) => devices,
        Err(result @ vk::Result::ERROR_INITIALIZATION_FAILED) => {
            return Err(GpuError::NoDevice {
                detail: format!(
                    "the Vulkan loader found drivers but none found a device (vkEnumeratePhysicalDevices: {result}){}",
                    driver_env()
                ),
            })
        }
        Err(result) => {
            return Err(GpuError::Vulkan {
                call: "vkEnumeratePhysicalDevices",
                result,
            })
        }
    };
    let mut candidates = Vec::new();
    let mut unusable = Vec::new();
    for pd in devices {
        // SAFETY: pd was just enumerated from this instance.
        let (props, families) = unsafe {
            (
                instance.get_physical_device_properties(pd),
                instance.get_physical_device_queue_family_properties(pd),
            )
        };
        let name = cstr_to_string(&props.device_name);
        if props.api_version < vk::API_VERSION_1_2 {
            unusable.push(format!(
                "{name} (Vulkan 1.{}, fovea needs 1.2)",
                vk::api_version_minor(props.api_version)
            ));
            continue;
        }
        let Some(family) = families.iter().position(|f| {
            f.queue_flags.contains(vk::QueueFlags::COMPUTE) && f.timestamp_valid_bits > 0
        }) else {
            unusable.push(format!("{name} (no compute queue with timestamps)"));
            continue;
        };
        let mut driver = vk::PhysicalDeviceDriverProperties::default();
        let mut props2 = vk::PhysicalDeviceProperties2::default().push_next(&mut driver);
        // SAFETY: Vulkan 1.2 device, properties2 is core.
        unsafe { instance.get_physical_device_properties2(pd, &mut props2) };
        // SAFETY: pd was enumerated from this instance.
        let extensions =
            unsafe { instance.enumerate_device_extension_properties(pd) }.unwrap_or_default();
        let has = |wanted: &CStr| {
            extensions
                .iter()
                .any(|e| e.extension_name_as_c_str() == Ok(wanted))
        };
        let info = DeviceInfo {
            name,
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
        candidates.push((
            device_rank(props.device_type),
            Picked {
                physical_device: pd,
                family: family as u32,
                info,
                budget: has(ash::ext::memory_budget::NAME),
                amd_marker: has(ash::amd::buffer_marker::NAME),
            },
        ));
    }
    if candidates.is_empty() {
        let detail = match unusable.is_empty() {
            true => format!("the Vulkan loader lists no device{}", driver_env()),
            false => format!("none of the devices can run fovea: {}", unusable.join(", ")),
        };
        return Err(GpuError::NoDevice { detail });
    }
    if let Some(wanted) = wanted {
        let needle = wanted.to_lowercase();
        let available = candidates
            .iter()
            .map(|c| c.1.info.name.clone())
            .collect::<Vec<_>>()
            .join(", ");
        candidates.retain(|c| c.1.info.name.to_lowercase().contains(&needle));
        if candidates.is_empty() {
            return Err(GpuError::DeviceNotFound {
                wanted: wanted.to_string(),
                available,
            });
        }
    }
    candidates.sort_by_key(|c| c.0);
    Ok(candidates.swap_remove(0).1)
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
            self.device.destroy_command_pool(self.command_pool, None);
            self.device.destroy_device(None);
            if let Some((loader, messenger)) = self.debug.take() {
                loader.destroy_debug_utils_messenger(messenger, None);
            }
            self.instance.destroy_instance(None);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::parse_byte_size;

    #[test]
    fn memory_sizes_parse() {
        assert_eq!(parse_byte_size("1024"), Ok(1024));
        assert_eq!(parse_byte_size("64M"), Ok(64 << 20));
        assert_eq!(parse_byte_size(" 6g "), Ok(6 << 30));
        assert_eq!(parse_byte_size("512KiB"), Ok(512 << 10));
        assert_eq!(parse_byte_size("1.5G"), Ok(3 << 29));
        assert_eq!(parse_byte_size("2T"), Ok(2 << 40));
    }

    #[test]
    fn bad_memory_sizes_say_why() {
        for bad in ["", "G", "abc", "-5G", "12X", "1.2.3M", "5 GB extra"] {
            let e = parse_byte_size(bad).unwrap_err();
            assert!(
                e.contains("not a memory size") && e.contains("6G"),
                "{bad}: {e}"
            );
        }
        assert!(parse_byte_size("0").unwrap_err().contains("no GPU memory"));
        assert!(parse_byte_size("99999999999T")
            .unwrap_err()
            .contains("16 EiB"));
        assert!(parse_byte_size("18446744073709551616")
            .unwrap_err()
            .contains("16 EiB"));
    }
}
