//! XR_KHR_vulkan_enable2 (and the older XR_KHR_vulkan_enable): the runtime creates or learns
//! the app's Vulkan instance and device, and remembers them for the session.

use std::ffi::{c_char, c_void};

use openxr_sys as xr;
use openxr_sys::platform::{VkDevice, VkInstance, VkPhysicalDevice, VkResult};

use crate::ffi::{self, XrResult};
use crate::registry::Runtime;
use crate::system::check_system;
use crate::vulkan::{lookup, pick_physical_device};

/// Vulkan versions the runtime works with: it only needs Vulkan 1.0 commands itself.
const MIN_VULKAN: xr::Version = xr::Version::new(1, 0, 0);
const MAX_VULKAN: xr::Version = xr::Version::new(1, 4, 0);

pub fn get_requirements(
    rt: &mut Runtime,
    instance: xr::Instance,
    system: xr::SystemId,
    out: &mut xr::GraphicsRequirementsVulkanKHR,
) -> XrResult {
    let inst = rt.instance_mut(instance)?;
    check_system(system)?;
    ffi::check_type(out.ty, xr::StructureType::GRAPHICS_REQUIREMENTS_VULKAN_KHR)?;
    out.min_api_version_supported = MIN_VULKAN;
    out.max_api_version_supported = MAX_VULKAN;
    inst.requirements_queried = true;
    Ok(xr::Result::SUCCESS)
}

pub fn create_vulkan_instance(
    rt: &mut Runtime,
    instance: xr::Instance,
    info: &xr::VulkanInstanceCreateInfoKHR,
    vk_instance: *mut VkInstance,
    vk_result: *mut VkResult,
) -> XrResult {
    let inst = rt.instance_mut(instance)?;
    ffi::check_type(info.ty, xr::StructureType::VULKAN_INSTANCE_CREATE_INFO_KHR)?;
    check_system(info.system_id)?;
    ffi::non_null(vk_instance)?;
    ffi::non_null(vk_result)?;
    ffi::non_null(info.vulkan_create_info)?;
    let gipa = info
        .pfn_get_instance_proc_addr
        .ok_or(xr::Result::ERROR_VALIDATION_FAILURE)?;
    // SAFETY: vkCreateInstance is a global command, looked up with a null instance; the
    // app's create info and allocator are passed through untouched (the runtime needs no
    // instance extensions or layers of its own).
    unsafe {
        let f = lookup(gipa, std::ptr::null(), c"vkCreateInstance")
            .ok_or(xr::Result::ERROR_RUNTIME_FAILURE)?;
        let create: ash::vk::PFN_vkCreateInstance = std::mem::transmute(f);
        let mut handle = ash::vk::Instance::null();
        let r = create(
            info.vulkan_create_info as *const ash::vk::InstanceCreateInfo,
            info.vulkan_allocator as *const ash::vk::AllocationCallbacks,
            &mut handle,
        );
        *vk_result = r.as_raw();
        *vk_instance = ash::vk::Handle::as_raw(handle) as VkInstance;
    }
    inst.vk.get_instance_proc_addr = Some(gipa);
    Ok(xr::Result::SUCCESS)
}

fn graphics_device(
    rt: &mut Runtime,
    instance: xr::Instance,
    vk_instance: VkInstance,
    out: *mut VkPhysicalDevice,
) -> XrResult {
    let inst = rt.instance_mut(instance)?;
    ffi::non_null(out)?;
    ffi::non_null(vk_instance)?;
    let device = pick_physical_device(inst.vk.get_instance_proc_addr, vk_instance as u64)?;
    inst.vk.instance = vk_instance as u64;
    inst.vk.physical_device = device;
    // SAFETY: checked non-null.
    unsafe { *out = device as VkPhysicalDevice };
    Ok(xr::Result::SUCCESS)
}

pub fn get_graphics_device2(
    rt: &mut Runtime,
    instance: xr::Instance,
    info: &xr::VulkanGraphicsDeviceGetInfoKHR,
    out: *mut VkPhysicalDevice,
) -> XrResult {
    ffi::check_type(
        info.ty,
        xr::StructureType::VULKAN_GRAPHICS_DEVICE_GET_INFO_KHR,
    )?;
    check_system(info.system_id)?;
    graphics_device(rt, instance, info.vulkan_instance, out)
}

pub fn get_graphics_device(
    rt: &mut Runtime,
    instance: xr::Instance,
    system: xr::SystemId,
    vk_instance: VkInstance,
    out: *mut VkPhysicalDevice,
) -> XrResult {
    check_system(system)?;
    graphics_device(rt, instance, vk_instance, out)
}

pub fn create_vulkan_device(
    rt: &mut Runtime,
    instance: xr::Instance,
    info: &xr::VulkanDeviceCreateInfoKHR,
    vk_device: *mut VkDevice,
    vk_result: *mut VkResult,
) -> XrResult {
    let inst = rt.instance_mut(instance)?;
    ffi::check_type(info.ty, xr::StructureType::VULKAN_DEVICE_CREATE_INFO_KHR)?;
    check_system(info.system_id)?;
    ffi::non_null(vk_device)?;
    ffi::non_null(vk_result)?;
    ffi::non_null(info.vulkan_create_info)?;
    let gipa = info
        .pfn_get_instance_proc_addr
        .ok_or(xr::Result::ERROR_VALIDATION_FAILURE)?;
    // vkCreateDevice is an instance command: it needs the instance the physical device
    // came from, which xrGetVulkanGraphicsDevice2KHR told us.
    if inst.vk.instance == 0 {
        return Err(xr::Result::ERROR_CALL_ORDER_INVALID);
    }
    if info.vulkan_physical_device as u64 != inst.vk.physical_device {
        return Err(xr::Result::ERROR_VALIDATION_FAILURE);
    }
    // SAFETY: the instance is the app's live VkInstance; create info and allocator are the
    // app's, passed through untouched.
    unsafe {
        let f = lookup(gipa, inst.vk.instance as *const c_void, c"vkCreateDevice")
            .ok_or(xr::Result::ERROR_RUNTIME_FAILURE)?;
        let create: ash::vk::PFN_vkCreateDevice = std::mem::transmute(f);
        let mut handle = ash::vk::Device::null();
        let r = create(
            ash::vk::Handle::from_raw(info.vulkan_physical_device as u64),
            info.vulkan_create_info as *const ash::vk::DeviceCreateInfo,
            info.vulkan_allocator as *const ash::vk::AllocationCallbacks,
            &mut handle,
        );
        *vk_result = r.as_raw();
        *vk_device = ash::vk::Handle::as_raw(handle) as VkDevice;
    }
    inst.vk.get_instance_proc_addr = Some(gipa);
    Ok(xr::Result::SUCCESS)
}

/// XR_KHR_vulkan_enable's extension lists: the runtime needs no Vulkan extensions, so both
/// are the empty space-separated list.
pub fn get_extensions(
    rt: &Runtime,
    instance: xr::Instance,
    system: xr::SystemId,
    capacity: u32,
    count: *mut u32,
    buf: *mut c_char,
) -> XrResult {
    rt.instance(instance)?;
    check_system(system)?;
    // SAFETY: the app's buffer per the two-call idiom.
    unsafe { ffi::two_call_string(capacity, count, buf, "") }
}
