//! The runtime's own Vulkan work on the application's device: swapchain images, their
//! memory, layout transitions and one-shot command submissions.
//!
//! Function pointers come from the app's `vkGetInstanceProcAddr` (handed to
//! xrCreateVulkanInstanceKHR / xrCreateVulkanDeviceKHR) so our calls go through the same
//! loader and layers as the app's, validation included; apps using XR_KHR_vulkan_enable
//! never give us one, and then the system loader's is used.

use std::ffi::c_void;

use ash::vk;
use ash::vk::Handle as _;
use openxr_sys as xr;
use openxr_sys::platform::VkGetInstanceProcAddr;

/// Per-instance Vulkan facts learned before a session exists.
#[derive(Default)]
pub struct VkBootstrap {
    /// The app's `vkGetInstanceProcAddr`, from xrCreateVulkanInstanceKHR/DeviceKHR.
    pub get_instance_proc_addr: Option<VkGetInstanceProcAddr>,
    /// The VkInstance / VkPhysicalDevice pair from xrGetVulkanGraphicsDevice(2)KHR (raw).
    pub instance: u64,
    pub physical_device: u64,
}

/// The session's view of the app's device.
pub struct VkContext {
    /// Keeps the system loader loaded when it supplied the function pointers.
    _entry: Option<ash::Entry>,
    pub instance: ash::Instance,
    pub device: ash::Device,
    pub physical_device: vk::PhysicalDevice,
    pub queue: vk::Queue,
    pool: vk::CommandPool,
    memory_properties: vk::PhysicalDeviceMemoryProperties,
}

/// A swapchain's images and the memory bound to each.
pub struct SwapchainImages {
    pub images: Vec<vk::Image>,
    pub memory: Vec<vk::DeviceMemory>,
}

/// What the app asked for in xrCreateSwapchain, in Vulkan terms.
pub struct ImageRequest {
    pub format: vk::Format,
    pub width: u32,
    pub height: u32,
    pub layers: u32,
    pub mip_levels: u32,
    pub usage: vk::ImageUsageFlags,
    pub flags: vk::ImageCreateFlags,
    pub count: u32,
}

/// Maps OpenXR swapchain usage to Vulkan usage. COLOR_ATTACHMENT and TRANSFER_SRC are
/// always added: the spec hands images over in COLOR_ATTACHMENT_OPTIMAL, which Vulkan only
/// allows for images with that usage, and the runtime copies images out to save them.
pub fn image_usage(flags: xr::SwapchainUsageFlags) -> (vk::ImageUsageFlags, vk::ImageCreateFlags) {
    let map = [
        (
            xr::SwapchainUsageFlags::COLOR_ATTACHMENT,
            vk::ImageUsageFlags::COLOR_ATTACHMENT,
        ),
        (
            xr::SwapchainUsageFlags::UNORDERED_ACCESS,
            vk::ImageUsageFlags::STORAGE,
        ),
        (
            xr::SwapchainUsageFlags::TRANSFER_SRC,
            vk::ImageUsageFlags::TRANSFER_SRC,
        ),
        (
            xr::SwapchainUsageFlags::TRANSFER_DST,
            vk::ImageUsageFlags::TRANSFER_DST,
        ),
        (
            xr::SwapchainUsageFlags::SAMPLED,
            vk::ImageUsageFlags::SAMPLED,
        ),
        (
            xr::SwapchainUsageFlags::INPUT_ATTACHMENT,
            vk::ImageUsageFlags::INPUT_ATTACHMENT,
        ),
    ];
    let mut usage = vk::ImageUsageFlags::COLOR_ATTACHMENT | vk::ImageUsageFlags::TRANSFER_SRC;
    for (x, v) in map {
        if flags.contains(x) {
            usage |= v;
        }
    }
    let mut create = vk::ImageCreateFlags::empty();
    if flags.contains(xr::SwapchainUsageFlags::MUTABLE_FORMAT) {
        create |= vk::ImageCreateFlags::MUTABLE_FORMAT;
    }
    (usage, create)
}

fn to_xr(e: vk::Result) -> xr::Result {
    match e {
        vk::Result::ERROR_OUT_OF_HOST_MEMORY | vk::Result::ERROR_OUT_OF_DEVICE_MEMORY => {
            xr::Result::ERROR_OUT_OF_MEMORY
        }
        vk::Result::ERROR_DEVICE_LOST => xr::Result::ERROR_SESSION_LOST,
        _ => xr::Result::ERROR_RUNTIME_FAILURE,
    }
}

/// A `StaticFn` from the app's `vkGetInstanceProcAddr`, or the system loader's.
pub fn static_fn(
    gipa: Option<VkGetInstanceProcAddr>,
) -> Result<(ash::StaticFn, Option<ash::Entry>), xr::Result> {
    match gipa {
        Some(f) => {
            // SAFETY: XR's VkGetInstanceProcAddr and ash's PFN have the same C signature;
            // dispatchable Vulkan handles are pointers in both.
            let f: vk::PFN_vkGetInstanceProcAddr = unsafe { std::mem::transmute(f) };
            Ok((
                ash::StaticFn {
                    get_instance_proc_addr: f,
                },
                None,
            ))
        }
        None => {
            // SAFETY: loading the system Vulkan loader runs its initialisers; it is the
            // loader the app uses too (same soname, so the same already-loaded library).
            let entry = unsafe { ash::Entry::load() }.map_err(|e| {
                eprintln!("sim-headset: cannot load the Vulkan loader: {e}");
                xr::Result::ERROR_RUNTIME_FAILURE
            })?;
            Ok((entry.static_fn().clone(), Some(entry)))
        }
    }
}

/// Calls a global or instance-level Vulkan function looked up through `gipa`.
///
/// # Safety
/// `instance` must be null or a live VkInstance of the loader behind `gipa`.
pub unsafe fn lookup(
    gipa: VkGetInstanceProcAddr,
    instance: *const c_void,
    name: &std::ffi::CStr,
) -> Option<unsafe extern "system" fn()> {
    // SAFETY: per the caller's contract.
    unsafe { gipa(instance, name.as_ptr()) }
}

/// The device the headset is "plugged into": the first discrete GPU, else the first
/// integrated, virtual or CPU device (lavapipe on a machine without a GPU).
pub fn pick_physical_device(
    gipa: Option<VkGetInstanceProcAddr>,
    instance: u64,
) -> Result<u64, xr::Result> {
    let (static_fn, _entry) = static_fn(gipa)?;
    // SAFETY: `instance` is the app's live VkInstance of the loader behind `gipa`.
    unsafe {
        let instance = ash::Instance::load(&static_fn, vk::Instance::from_raw(instance));
        let devices = instance
            .enumerate_physical_devices()
            .map_err(|_| xr::Result::ERROR_RUNTIME_FAILURE)?;
        let rank = |t: vk::PhysicalDeviceType| match t {
            vk::PhysicalDeviceType::DISCRETE_GPU => 0,
            vk::PhysicalDeviceType::INTEGRATED_GPU => 1,
            vk::PhysicalDeviceType::VIRTUAL_GPU => 2,
            vk::PhysicalDeviceType::CPU => 3,
            _ => 4,
        };
        devices
            .iter()
            .min_by_key(|&&d| rank(instance.get_physical_device_properties(d).device_type))
            .map(|d| d.as_raw())
            .ok_or_else(|| {
                eprintln!("sim-headset: the Vulkan instance has no physical device");
                xr::Result::ERROR_RUNTIME_FAILURE
            })
    }
}

impl VkContext {
    /// Loads the app's instance and device functions and makes a command pool on the
    /// queue family it named in the graphics binding.
    ///
    /// # Safety
    /// The binding's handles must be live and belong to the loader behind `gipa`.
    pub unsafe fn new(
        gipa: Option<VkGetInstanceProcAddr>,
        binding: &xr::GraphicsBindingVulkanKHR,
    ) -> Result<Self, xr::Result> {
        let (static_fn, entry) = static_fn(gipa)?;
        let raw_instance = vk::Instance::from_raw(binding.instance as u64);
        let physical_device = vk::PhysicalDevice::from_raw(binding.physical_device as u64);
        let raw_device = vk::Device::from_raw(binding.device as u64);
        // SAFETY: the handles are the app's live handles (caller's contract).
        unsafe {
            let instance = ash::Instance::load(&static_fn, raw_instance);
            let families = instance.get_physical_device_queue_family_properties(physical_device);
            let family = families
                .get(binding.queue_family_index as usize)
                .ok_or(xr::Result::ERROR_VALIDATION_FAILURE)?;
            if binding.queue_index >= family.queue_count {
                return Err(xr::Result::ERROR_VALIDATION_FAILURE);
            }
            let device = ash::Device::load(instance.fp_v1_0(), raw_device);
            let queue = device.get_device_queue(binding.queue_family_index, binding.queue_index);
            let pool = device
                .create_command_pool(
                    &vk::CommandPoolCreateInfo::default()
                        .queue_family_index(binding.queue_family_index)
                        .flags(vk::CommandPoolCreateFlags::TRANSIENT),
                    None,
                )
                .map_err(to_xr)?;
            let memory_properties = instance.get_physical_device_memory_properties(physical_device);
            Ok(Self {
                _entry: entry,
                instance,
                device,
                physical_device,
                queue,
                pool,
                memory_properties,
            })
        }
    }

    /// Destroys the command pool. The app's device must still be alive, as the spec
    /// requires until the session is destroyed.
    pub fn destroy(&self) {
        // SAFETY: the pool is ours and idle (every submission waits for its fence).
        unsafe { self.device.destroy_command_pool(self.pool, None) };
    }

    /// Records commands with `record`, submits them on the app's queue and waits. The queue
    /// is only used inside this call, so the single-threaded app never sees it busy with us.
    pub fn submit_once(&self, record: impl FnOnce(vk::CommandBuffer)) -> Result<(), xr::Result> {
        // SAFETY: the pool, queue and device are live; the command buffer and fence are
        // created, used and destroyed here, after the fence signals.
        unsafe {
            let cmd = self
                .device
                .allocate_command_buffers(
                    &vk::CommandBufferAllocateInfo::default()
                        .command_pool(self.pool)
                        .level(vk::CommandBufferLevel::PRIMARY)
                        .command_buffer_count(1),
                )
                .map_err(to_xr)?[0];
            let result = (|| {
                self.device.begin_command_buffer(
                    cmd,
                    &vk::CommandBufferBeginInfo::default()
                        .flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT),
                )?;
                record(cmd);
                self.device.end_command_buffer(cmd)?;
                let fence = self
                    .device
                    .create_fence(&vk::FenceCreateInfo::default(), None)?;
                let cmds = [cmd];
                let submit = vk::SubmitInfo::default().command_buffers(&cmds);
                let submitted = self.device.queue_submit(self.queue, &[submit], fence);
                let waited =
                    submitted.and_then(|_| self.device.wait_for_fences(&[fence], true, u64::MAX));
                self.device.destroy_fence(fence, None);
                waited
            })();
            self.device.free_command_buffers(self.pool, &[cmd]);
            result.map_err(to_xr)
        }
    }

    pub fn memory_type(&self, type_bits: u32, wanted: vk::MemoryPropertyFlags) -> Option<u32> {
        (0..self.memory_properties.memory_type_count).find(|&i| {
            type_bits & (1 << i) != 0
                && self.memory_properties.memory_types[i as usize]
                    .property_flags
                    .contains(wanted)
        })
    }

    /// Whether this device can make an image of the request's format and usage.
    pub fn supports(&self, req: &ImageRequest) -> bool {
        // SAFETY: plain query on the app's live physical device.
        let props = unsafe {
            self.instance.get_physical_device_image_format_properties(
                self.physical_device,
                req.format,
                vk::ImageType::TYPE_2D,
                vk::ImageTiling::OPTIMAL,
                req.usage,
                req.flags,
            )
        };
        match props {
            Ok(p) => {
                p.max_extent.width >= req.width
                    && p.max_extent.height >= req.height
                    && p.max_array_layers >= req.layers
                    && p.max_mip_levels >= req.mip_levels
            }
            Err(_) => false,
        }
    }

    /// Creates the swapchain's images in device-local memory and moves every one to
    /// COLOR_ATTACHMENT_OPTIMAL, the layout in which the spec hands them to the app.
    pub fn create_images(&self, req: &ImageRequest) -> Result<SwapchainImages, xr::Result> {
        let mut out = SwapchainImages {
            images: Vec::new(),
            memory: Vec::new(),
        };
        let made = self.create_images_into(req, &mut out);
        if let Err(e) = made {
            self.destroy_images(&mut out);
            return Err(e);
        }
        Ok(out)
    }

    fn create_images_into(
        &self,
        req: &ImageRequest,
        out: &mut SwapchainImages,
    ) -> Result<(), xr::Result> {
        let info = vk::ImageCreateInfo::default()
            .flags(req.flags)
            .image_type(vk::ImageType::TYPE_2D)
            .format(req.format)
            .extent(vk::Extent3D {
                width: req.width,
                height: req.height,
                depth: 1,
            })
            .mip_levels(req.mip_levels)
            .array_layers(req.layers)
            .samples(vk::SampleCountFlags::TYPE_1)
            .tiling(vk::ImageTiling::OPTIMAL)
            .usage(req.usage)
            .sharing_mode(vk::SharingMode::EXCLUSIVE)
            .initial_layout(vk::ImageLayout::UNDEFINED);
        for _ in 0..req.count {
            // SAFETY: valid create info on the app's live device; every object made here is
            // recorded in `out` at once so a failure part-way can release it.
            unsafe {
                let image = self.device.create_image(&info, None).map_err(to_xr)?;
                out.images.push(image);
                let needs = self.device.get_image_memory_requirements(image);
                let type_index = self
                    .memory_type(
                        needs.memory_type_bits,
                        vk::MemoryPropertyFlags::DEVICE_LOCAL,
                    )
                    .or_else(|| {
                        self.memory_type(needs.memory_type_bits, vk::MemoryPropertyFlags::empty())
                    })
                    .ok_or(xr::Result::ERROR_RUNTIME_FAILURE)?;
                let memory = self
                    .device
                    .allocate_memory(
                        &vk::MemoryAllocateInfo::default()
                            .allocation_size(needs.size)
                            .memory_type_index(type_index),
                        None,
                    )
                    .map_err(to_xr)?;
                out.memory.push(memory);
                self.device
                    .bind_image_memory(image, memory, 0)
                    .map_err(to_xr)?;
            }
        }
        let range = full_range(req.mip_levels, req.layers);
        self.submit_once(|cmd| {
            let barriers: Vec<_> = out
                .images
                .iter()
                .map(|&image| {
                    vk::ImageMemoryBarrier::default()
                        .src_access_mask(vk::AccessFlags::empty())
                        .dst_access_mask(
                            vk::AccessFlags::COLOR_ATTACHMENT_WRITE
                                | vk::AccessFlags::TRANSFER_WRITE,
                        )
                        .old_layout(vk::ImageLayout::UNDEFINED)
                        .new_layout(vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL)
                        .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                        .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                        .image(image)
                        .subresource_range(range)
                })
                .collect();
            // SAFETY: recording into our command buffer; images are ours and unused.
            unsafe {
                self.device.cmd_pipeline_barrier(
                    cmd,
                    vk::PipelineStageFlags::TOP_OF_PIPE,
                    vk::PipelineStageFlags::ALL_COMMANDS,
                    vk::DependencyFlags::empty(),
                    &[],
                    &[],
                    &barriers,
                )
            };
        })
    }

    /// Destroys images and frees their memory; the app must no longer use them (it
    /// destroyed the swapchain, so the spec says it does not).
    pub fn destroy_images(&self, images: &mut SwapchainImages) {
        // SAFETY: the images and memory are ours; waiting for the queue first makes sure no
        // submitted work (ours or the app's) still references them.
        unsafe {
            let _ = self.device.queue_wait_idle(self.queue);
            for image in images.images.drain(..) {
                self.device.destroy_image(image, None);
            }
            for memory in images.memory.drain(..) {
                self.device.free_memory(memory, None);
            }
        }
    }
}

pub fn full_range(mip_levels: u32, layers: u32) -> vk::ImageSubresourceRange {
    vk::ImageSubresourceRange {
        aspect_mask: vk::ImageAspectFlags::COLOR,
        base_mip_level: 0,
        level_count: mip_levels,
        base_array_layer: 0,
        layer_count: layers,
    }
}
