//! An application for the simulated headset: the `openxr` crate on the in-process entry
//! point, Vulkan (lavapipe here) through ash with the Khronos validation layer, and a frame
//! loop that clears each eye to a known colour. Validation messages fail the test.

#![allow(dead_code)]

use std::ffi::{c_void, CStr};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

use ash::vk;
use ash::vk::Handle as _;
use openxr as xr;

/// Validation errors and warnings seen by any harness in this test binary.
pub static VALIDATION_MESSAGES: AtomicUsize = AtomicUsize::new(0);
static VALIDATION_LOG: Mutex<Vec<String>> = Mutex::new(Vec::new());

unsafe extern "system" fn on_validation(
    severity: vk::DebugUtilsMessageSeverityFlagsEXT,
    _ty: vk::DebugUtilsMessageTypeFlagsEXT,
    data: *const vk::DebugUtilsMessengerCallbackDataEXT<'_>,
    _user: *mut c_void,
) -> vk::Bool32 {
    // SAFETY: the layer passes a valid callback data structure with a C string message.
    let message = unsafe { CStr::from_ptr((*data).p_message) }
        .to_string_lossy()
        .into_owned();
    if severity.intersects(
        vk::DebugUtilsMessageSeverityFlagsEXT::ERROR
            | vk::DebugUtilsMessageSeverityFlagsEXT::WARNING,
    ) {
        eprintln!("VALIDATION: {message}");
        VALIDATION_MESSAGES.fetch_add(1, Ordering::SeqCst);
        VALIDATION_LOG.lock().unwrap().push(message);
    }
    vk::FALSE
}

pub fn validation_log() -> Vec<String> {
    VALIDATION_LOG.lock().unwrap().clone()
}

pub const EYE_SIZE: u32 = 64;

pub struct Vulkan {
    pub entry: ash::Entry,
    pub instance: ash::Instance,
    pub messenger: vk::DebugUtilsMessengerEXT,
    pub debug_utils: ash::ext::debug_utils::Instance,
    pub physical_device: vk::PhysicalDevice,
    pub device: ash::Device,
    pub queue_family: u32,
    pub queue: vk::Queue,
    pub pool: vk::CommandPool,
}

pub struct App {
    pub xr_instance: xr::Instance,
    pub system: xr::SystemId,
    pub vk: Vulkan,
    pub session: xr::Session<xr::Vulkan>,
    pub waiter: xr::FrameWaiter,
    pub stream: xr::FrameStream<xr::Vulkan>,
    pub states: Vec<xr::SessionState>,
}

pub fn entry() -> xr::Entry {
    // SAFETY: the simulated headset implements every core function.
    unsafe { xr::Entry::from_get_instance_proc_addr(sim_headset::get_instance_proc_addr(), &()) }
        .expect("entry")
}

/// Creates the XR instance (with every extension the headset offers), the Vulkan instance
/// and device through the runtime, and the session.
pub fn start(config: sim_headset::Config) -> App {
    sim_headset::set_config_override(Some(config));
    let entry = entry();
    let available = entry.enumerate_extensions().expect("extensions");
    let mut exts = xr::ExtensionSet::default();
    exts.khr_vulkan_enable2 = true;
    exts.ext_eye_gaze_interaction = available.ext_eye_gaze_interaction;
    exts.khr_visibility_mask = available.khr_visibility_mask;
    let xr_instance = entry
        .create_instance(
            &xr::ApplicationInfo {
                application_name: "sim-headset test",
                ..Default::default()
            },
            &exts,
            &[],
            &(),
        )
        .expect("xrCreateInstance");
    let system = xr_instance
        .system(xr::FormFactor::HEAD_MOUNTED_DISPLAY)
        .expect("system");
    let reqs = xr_instance
        .graphics_requirements::<xr::Vulkan>(system)
        .expect("requirements");
    assert!(reqs.min_api_version_supported.major() == 1);

    // SAFETY: Vulkan set-up through the runtime, following XR_KHR_vulkan_enable2; every
    // handle is destroyed in `finish` in reverse order.
    let vk = unsafe {
        let entry = ash::Entry::load().expect("Vulkan loader");
        let app = vk::ApplicationInfo::default().api_version(vk::API_VERSION_1_1);
        let layers = [c"VK_LAYER_KHRONOS_validation".as_ptr()];
        let extensions = [ash::ext::debug_utils::NAME.as_ptr()];
        let info = vk::InstanceCreateInfo::default()
            .application_info(&app)
            .enabled_layer_names(&layers)
            .enabled_extension_names(&extensions);
        let gipa = std::mem::transmute::<
            vk::PFN_vkGetInstanceProcAddr,
            openxr::sys::platform::VkGetInstanceProcAddr,
        >(entry.static_fn().get_instance_proc_addr);
        let raw = xr_instance
            .create_vulkan_instance(system, gipa, &info as *const _ as *const _)
            .expect("xrCreateVulkanInstanceKHR")
            .map_err(vk::Result::from_raw)
            .expect("vkCreateInstance");
        let instance = ash::Instance::load(entry.static_fn(), vk::Instance::from_raw(raw as u64));
        let debug_utils = ash::ext::debug_utils::Instance::new(&entry, &instance);
        let messenger = debug_utils
            .create_debug_utils_messenger(
                &vk::DebugUtilsMessengerCreateInfoEXT::default()
                    .message_severity(
                        vk::DebugUtilsMessageSeverityFlagsEXT::ERROR
                            | vk::DebugUtilsMessageSeverityFlagsEXT::WARNING,
                    )
                    .message_type(
                        vk::DebugUtilsMessageTypeFlagsEXT::GENERAL
                            | vk::DebugUtilsMessageTypeFlagsEXT::VALIDATION
                            | vk::DebugUtilsMessageTypeFlagsEXT::PERFORMANCE,
                    )
                    .pfn_user_callback(Some(on_validation)),
                None,
            )
            .expect("messenger");
        let physical_device = vk::PhysicalDevice::from_raw(
            xr_instance
                .vulkan_graphics_device(system, raw)
                .expect("xrGetVulkanGraphicsDevice2KHR") as u64,
        );
        let queue_family = instance
            .get_physical_device_queue_family_properties(physical_device)
            .iter()
            .position(|f| f.queue_flags.contains(vk::QueueFlags::GRAPHICS))
            .expect("graphics queue") as u32;
        let priorities = [1.0];
        let queues = [vk::DeviceQueueCreateInfo::default()
            .queue_family_index(queue_family)
            .queue_priorities(&priorities)];
        let device_info = vk::DeviceCreateInfo::default().queue_create_infos(&queues);
        let raw_device = xr_instance
            .create_vulkan_device(
                system,
                gipa,
                physical_device.as_raw() as _,
                &device_info as *const _ as *const _,
            )
            .expect("xrCreateVulkanDeviceKHR")
            .map_err(vk::Result::from_raw)
            .expect("vkCreateDevice");
        let device = ash::Device::load(instance.fp_v1_0(), vk::Device::from_raw(raw_device as u64));
        let queue = device.get_device_queue(queue_family, 0);
        let pool = device
            .create_command_pool(
                &vk::CommandPoolCreateInfo::default()
                    .queue_family_index(queue_family)
                    .flags(vk::CommandPoolCreateFlags::RESET_COMMAND_BUFFER),
                None,
            )
            .expect("pool");
        Vulkan {
            entry,
            instance,
            messenger,
            debug_utils,
            physical_device,
            device,
            queue_family,
            queue,
            pool,
        }
    };

    // SAFETY: the handles are live and were made for this system.
    let (session, waiter, stream) = unsafe {
        xr_instance.create_session::<xr::Vulkan>(
            system,
            &xr::vulkan::SessionCreateInfo {
                instance: vk.instance.handle().as_raw() as _,
                physical_device: vk.physical_device.as_raw() as _,
                device: vk.device.handle().as_raw() as _,
                queue_family_index: vk.queue_family,
                queue_index: 0,
            },
        )
    }
    .expect("xrCreateSession");
    App {
        xr_instance,
        system,
        vk,
        session,
        waiter,
        stream,
        states: Vec::new(),
    }
}

impl App {
    /// Drains the event queue, recording session states.
    pub fn poll(&mut self) {
        let mut buffer = xr::EventDataBuffer::new();
        while let Some(event) = self
            .xr_instance
            .poll_event(&mut buffer)
            .expect("xrPollEvent")
        {
            if let xr::Event::SessionStateChanged(e) = event {
                self.states.push(e.state());
            }
        }
    }

    pub fn swapchain(&self, format: vk::Format) -> (xr::Swapchain<xr::Vulkan>, Vec<vk::Image>) {
        let swapchain = self
            .session
            .create_swapchain(&xr::SwapchainCreateInfo {
                create_flags: xr::SwapchainCreateFlags::EMPTY,
                usage_flags: xr::SwapchainUsageFlags::COLOR_ATTACHMENT
                    | xr::SwapchainUsageFlags::TRANSFER_DST,
                format: format.as_raw() as u32,
                sample_count: 1,
                width: EYE_SIZE,
                height: EYE_SIZE,
                face_count: 1,
                array_size: 1,
                mip_count: 1,
            })
            .expect("xrCreateSwapchain");
        let images = swapchain
            .enumerate_images()
            .expect("images")
            .into_iter()
            .map(vk::Image::from_raw)
            .collect();
        (swapchain, images)
    }

    /// Clears `image` (in COLOR_ATTACHMENT_OPTIMAL, as handed over) to `colour` and returns
    /// it to COLOR_ATTACHMENT_OPTIMAL, waiting for completion.
    pub fn clear(&self, image: vk::Image, colour: [f32; 4]) {
        let d = &self.vk.device;
        let range = vk::ImageSubresourceRange {
            aspect_mask: vk::ImageAspectFlags::COLOR,
            base_mip_level: 0,
            level_count: 1,
            base_array_layer: 0,
            layer_count: 1,
        };
        let barrier = |old, new, src, dst| {
            vk::ImageMemoryBarrier::default()
                .old_layout(old)
                .new_layout(new)
                .src_access_mask(src)
                .dst_access_mask(dst)
                .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                .image(image)
                .subresource_range(range)
        };
        // SAFETY: our own command buffer and fence; the image is acquired and waited on.
        unsafe {
            let cmd = d
                .allocate_command_buffers(
                    &vk::CommandBufferAllocateInfo::default()
                        .command_pool(self.vk.pool)
                        .command_buffer_count(1),
                )
                .unwrap()[0];
            d.begin_command_buffer(cmd, &vk::CommandBufferBeginInfo::default())
                .unwrap();
            d.cmd_pipeline_barrier(
                cmd,
                vk::PipelineStageFlags::ALL_COMMANDS,
                vk::PipelineStageFlags::TRANSFER,
                vk::DependencyFlags::empty(),
                &[],
                &[],
                &[barrier(
                    vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL,
                    vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                    vk::AccessFlags::MEMORY_READ | vk::AccessFlags::MEMORY_WRITE,
                    vk::AccessFlags::TRANSFER_WRITE,
                )],
            );
            d.cmd_clear_color_image(
                cmd,
                image,
                vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                &vk::ClearColorValue { float32: colour },
                &[range],
            );
            d.cmd_pipeline_barrier(
                cmd,
                vk::PipelineStageFlags::TRANSFER,
                vk::PipelineStageFlags::COLOR_ATTACHMENT_OUTPUT,
                vk::DependencyFlags::empty(),
                &[],
                &[],
                &[barrier(
                    vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                    vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL,
                    vk::AccessFlags::TRANSFER_WRITE,
                    vk::AccessFlags::COLOR_ATTACHMENT_WRITE,
                )],
            );
            d.end_command_buffer(cmd).unwrap();
            let fence = d
                .create_fence(&vk::FenceCreateInfo::default(), None)
                .unwrap();
            let cmds = [cmd];
            d.queue_submit(
                self.vk.queue,
                &[vk::SubmitInfo::default().command_buffers(&cmds)],
                fence,
            )
            .unwrap();
            d.wait_for_fences(&[fence], true, u64::MAX).unwrap();
            d.destroy_fence(fence, None);
            d.free_command_buffers(self.vk.pool, &cmds);
        }
    }

    /// Destroys the XR objects (the caller must have dropped its swapchains and spaces),
    /// then Vulkan, then the XR instance (which writes the report).
    pub fn finish(self) {
        let App {
            xr_instance,
            vk,
            session,
            waiter,
            stream,
            ..
        } = self;
        drop((stream, waiter, session));
        // SAFETY: every object made from the device and instance is gone; the runtime
        // released its own objects when the session was destroyed.
        unsafe {
            vk.device.device_wait_idle().unwrap();
            vk.device.destroy_command_pool(vk.pool, None);
            vk.device.destroy_device(None);
        }
        drop(xr_instance);
        // SAFETY: as above, for the instance.
        unsafe {
            vk.debug_utils
                .destroy_debug_utils_messenger(vk.messenger, None);
            vk.instance.destroy_instance(None);
        }
    }
}

/// Rotates -Z by a unit quaternion: the direction a pose "looks" along.
pub fn forward(q: xr::Quaternionf) -> [f32; 3] {
    let (x, y, z, w) = (q.x, q.y, q.z, q.w);
    // Third column of the rotation matrix, negated.
    [
        -(2.0 * (x * z + w * y)),
        -(2.0 * (y * z - w * x)),
        -(1.0 - 2.0 * (x * x + y * y)),
    ]
}

/// The direction of a gaze `yaw` degrees right and `pitch` degrees up.
pub fn direction(yaw_deg: f32, pitch_deg: f32) -> [f32; 3] {
    let (y, p) = (yaw_deg.to_radians(), pitch_deg.to_radians());
    [p.cos() * y.sin(), p.sin(), -p.cos() * y.cos()]
}

/// `supportsEyeGazeInteraction`, read through the raw call with the chained structure.
pub fn supports_eye_gaze(instance: &xr::Instance, system: xr::SystemId) -> bool {
    let mut gaze = xr::sys::SystemEyeGazeInteractionPropertiesEXT {
        ty: xr::sys::StructureType::SYSTEM_EYE_GAZE_INTERACTION_PROPERTIES_EXT,
        next: std::ptr::null_mut(),
        supports_eye_gaze_interaction: xr::sys::FALSE,
    };
    // SAFETY: zeroed is a valid bit pattern for this plain C structure; the chain is valid.
    let mut props: xr::sys::SystemProperties = unsafe { std::mem::zeroed() };
    props.ty = xr::sys::StructureType::SYSTEM_PROPERTIES;
    props.next = &mut gaze as *mut _ as *mut _;
    // SAFETY: valid instance, system and output chain.
    let r = unsafe { (instance.fp().get_system_properties)(instance.as_raw(), system, &mut props) };
    assert_eq!(r, xr::sys::Result::SUCCESS);
    gaze.supports_eye_gaze_interaction.into()
}
