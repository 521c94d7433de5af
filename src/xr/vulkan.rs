//! XR_KHR_vulkan_enable2: the runtime creates fovea's Vulkan instance and device, with the
//! create infos fovea built plus whatever the compositor needs, on the GPU that drives the
//! headset.

use crate::gpu::{vk, GpuError, VulkanCreator};
use openxr as xr;

pub(super) struct RuntimeVulkan<'a> {
    pub(super) instance: &'a xr::Instance,
    pub(super) system: xr::SystemId,
}

/// Vulkan's vkGetInstanceProcAddr in the type OpenXR's bindings name it by.
fn get_instance_proc_addr(entry: &ash::Entry) -> xr::sys::platform::VkGetInstanceProcAddr {
    // SAFETY: both types are `extern "system" fn(instance handle, *const c_char) -> function
    // pointer`, with the handle pointer-sized in both: the same ABI under two names.
    unsafe { std::mem::transmute(entry.static_fn().get_instance_proc_addr) }
}

fn failed(call: &'static str, e: xr::sys::Result) -> GpuError {
    GpuError::External(format!("{call} failed: {e}"))
}

impl VulkanCreator for RuntimeVulkan<'_> {
    fn create_instance(
        &self,
        entry: &ash::Entry,
        info: &vk::InstanceCreateInfo,
    ) -> Result<vk::Instance, GpuError> {
        // SAFETY: the create info (and all it points to) lives until the call returns; the
        // proc-addr function comes from the loaded Vulkan loader.
        let created = unsafe {
            self.instance.create_vulkan_instance(
                self.system,
                get_instance_proc_addr(entry),
                info as *const vk::InstanceCreateInfo as *const _,
            )
        }
        .map_err(|e| failed("xrCreateVulkanInstanceKHR", e))?;
        match created {
            Ok(handle) => Ok(vk::Handle::from_raw(handle as u64)),
            Err(code) => Err(GpuError::Vulkan {
                call: "vkCreateInstance (through xrCreateVulkanInstanceKHR)",
                result: vk::Result::from_raw(code),
            }),
        }
    }

    fn physical_device(&self, instance: vk::Instance) -> Result<vk::PhysicalDevice, GpuError> {
        // SAFETY: the instance was created through xrCreateVulkanInstanceKHR just before.
        let pd = unsafe {
            self.instance
                .vulkan_graphics_device(self.system, vk::Handle::as_raw(instance) as _)
        }
        .map_err(|e| failed("xrGetVulkanGraphicsDevice2KHR", e))?;
        Ok(vk::Handle::from_raw(pd as u64))
    }

    fn create_device(
        &self,
        entry: &ash::Entry,
        physical_device: vk::PhysicalDevice,
        info: &vk::DeviceCreateInfo,
    ) -> Result<vk::Device, GpuError> {
        // SAFETY: the physical device is the one the runtime named; the create info outlives
        // the call.
        let created = unsafe {
            self.instance.create_vulkan_device(
                self.system,
                get_instance_proc_addr(entry),
                vk::Handle::as_raw(physical_device) as _,
                info as *const vk::DeviceCreateInfo as *const _,
            )
        }
        .map_err(|e| failed("xrCreateVulkanDeviceKHR", e))?;
        match created {
            Ok(handle) => Ok(vk::Handle::from_raw(handle as u64)),
            Err(code) => Err(GpuError::Vulkan {
                call: "vkCreateDevice (through xrCreateVulkanDeviceKHR)",
                result: vk::Result::from_raw(code),
            }),
        }
    }
}
