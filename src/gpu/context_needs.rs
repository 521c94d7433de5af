//! What a caller beyond headless rendering asks of the context it sets up (extensions, a
//! graphics queue, someone else creating the instance and device), on its own so that
//! instance.rs and device.rs read it without depending on the context they help build.

use super::error::GpuError;
use ash::vk;
use std::ffi::CStr;

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
