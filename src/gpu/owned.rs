//! Owners of the Vulkan objects a [`GpuContext`](super::GpuContext) is made of, one type per
//! object, each destroying its object when dropped. A context whose set-up fails half-way so
//! destroys exactly what it made, last made first (locals drop in reverse order), and a
//! finished context does the same through its fields (declared in the order they drop).
//!
//! [`Pending`] covers the objects made while another owner is being built (a buffer before
//! its memory is bound): destroyed if set-up fails before the owner takes them.

use super::error::{GpuError, VkContext};
use super::validation::ValidationLog;
use ash::vk;
use std::ops::Deref;
use std::sync::Arc;

/// The Vulkan instance, and the loaded library its functions come from (unloaded after the
/// instance is destroyed: the `entry` field drops after `Drop::drop`).
pub(crate) struct Instance {
    instance: ash::Instance,
    entry: ash::Entry,
}

impl Instance {
    /// Takes ownership of `instance`, made from `entry`'s loader.
    pub(super) fn new(entry: ash::Entry, instance: ash::Instance) -> Self {
        Self { instance, entry }
    }

    pub(super) fn entry(&self) -> &ash::Entry {
        &self.entry
    }
}

impl Deref for Instance {
    type Target = ash::Instance;
    fn deref(&self) -> &ash::Instance {
        &self.instance
    }
}

impl Drop for Instance {
    fn drop(&mut self) {
        // SAFETY: every object made from the instance (messenger, device) has an owner that
        // borrows it or is dropped before it (see GpuContext's field order).
        unsafe { self.instance.destroy_instance(None) };
    }
}

/// The validation layer's debug messenger, which reports into `log`.
pub(super) struct Messenger {
    loader: ash::ext::debug_utils::Instance,
    messenger: vk::DebugUtilsMessengerEXT,
    /// The layer's callback is handed a pointer to this log: holding it here keeps it alive
    /// for as long as the messenger exists.
    _log: Arc<ValidationLog>,
}

impl Messenger {
    /// A messenger for errors and warnings of `instance` (created with VK_EXT_debug_utils),
    /// each pushed into `log`.
    pub(super) fn new(instance: &Instance, log: Arc<ValidationLog>) -> Result<Self, GpuError> {
        let loader = ash::ext::debug_utils::Instance::new(instance.entry(), instance);
        let info = vk::DebugUtilsMessengerCreateInfoEXT::default()
            .message_severity(
                vk::DebugUtilsMessageSeverityFlagsEXT::ERROR
                    | vk::DebugUtilsMessageSeverityFlagsEXT::WARNING,
            )
            .message_type(
                vk::DebugUtilsMessageTypeFlagsEXT::VALIDATION
                    | vk::DebugUtilsMessageTypeFlagsEXT::GENERAL,
            )
            .pfn_user_callback(Some(super::validation::debug_callback))
            .user_data(Arc::as_ptr(&log) as *mut std::ffi::c_void);
        // SAFETY: the user data is the log this messenger holds an Arc of until it is
        // destroyed; the instance has VK_EXT_debug_utils (validation is on).
        let messenger = unsafe { loader.create_debug_utils_messenger(&info, None) }
            .vk("vkCreateDebugUtilsMessengerEXT")?;
        Ok(Self {
            loader,
            messenger,
            _log: log,
        })
    }
}

impl Drop for Messenger {
    fn drop(&mut self) {
        // SAFETY: the messenger was made by this loader and is destroyed once; its instance
        // outlives it (dropped after it, see GpuContext's field order).
        unsafe {
            self.loader
                .destroy_debug_utils_messenger(self.messenger, None)
        };
    }
}

/// The logical device.
pub(crate) struct Device {
    device: ash::Device,
}

impl Device {
    /// Takes ownership of `device`.
    pub(super) fn new(device: ash::Device) -> Self {
        Self { device }
    }
}

impl Deref for Device {
    type Target = ash::Device;
    fn deref(&self) -> &ash::Device {
        &self.device
    }
}

impl Drop for Device {
    fn drop(&mut self) {
        // SAFETY: every object made from the device is destroyed before it (owners borrow it,
        // hold the context, or are fields dropped earlier), and the context waited for the
        // device to idle before destroying any of them.
        unsafe { self.device.destroy_device(None) };
    }
}

/// A command pool; destroying it frees every command buffer allocated from it.
pub(super) struct CommandPool {
    /// A copy of the device's function table, to destroy the pool with.
    device: ash::Device,
    pub(super) handle: vk::CommandPool,
}

impl CommandPool {
    /// A pool for `queue_family` whose command buffers can be reset one by one (spares are
    /// reused).
    pub(super) fn new(device: &ash::Device, queue_family: u32) -> Result<Self, GpuError> {
        let info = vk::CommandPoolCreateInfo::default()
            .queue_family_index(queue_family)
            .flags(vk::CommandPoolCreateFlags::RESET_COMMAND_BUFFER);
        // SAFETY: valid device and create info.
        let handle =
            unsafe { device.create_command_pool(&info, None) }.vk("vkCreateCommandPool")?;
        Ok(Self {
            device: device.clone(),
            handle,
        })
    }
}

impl Drop for CommandPool {
    fn drop(&mut self) {
        // SAFETY: no command buffer of the pool is pending (the context waited for idle), and
        // the device is destroyed after the pool.
        unsafe { self.device.destroy_command_pool(self.handle, None) };
    }
}

/// A device object that can be destroyed with the device alone.
pub(super) trait DeviceObject: Copy {
    /// # Safety
    /// The object was made from `device`, is not in use, and is destroyed once.
    unsafe fn destroy(self, device: &ash::Device);
}

impl DeviceObject for vk::Buffer {
    unsafe fn destroy(self, device: &ash::Device) {
        // SAFETY: as the trait requires.
        unsafe { device.destroy_buffer(self, None) }
    }
}

impl DeviceObject for vk::Image {
    unsafe fn destroy(self, device: &ash::Device) {
        // SAFETY: as the trait requires.
        unsafe { device.destroy_image(self, None) }
    }
}

impl DeviceObject for vk::Fence {
    unsafe fn destroy(self, device: &ash::Device) {
        // SAFETY: as the trait requires.
        unsafe { device.destroy_fence(self, None) }
    }
}

/// An object made while its owner is set up, destroyed on drop unless the owner takes it
/// ([`Self::keep`]) once nothing can fail any more.
pub(super) struct Pending<'d, H: DeviceObject> {
    device: &'d ash::Device,
    handle: Option<H>,
}

impl<'d, H: DeviceObject> Pending<'d, H> {
    pub(super) fn new(device: &'d ash::Device, handle: H) -> Self {
        Self {
            device,
            handle: Some(handle),
        }
    }

    /// The handle, which stays owned here.
    pub(super) fn get(&self) -> H {
        self.handle.expect("a pending object is owned until kept")
    }

    /// Hands the object to its owner, which destroys it from now on.
    pub(super) fn keep(mut self) -> H {
        self.handle.take().expect("a pending object is kept once")
    }
}

impl<H: DeviceObject> Drop for Pending<'_, H> {
    fn drop(&mut self) {
        if let Some(handle) = self.handle.take() {
            // SAFETY: set-up failed before an owner took the object: nothing else has it,
            // and nothing used it on the GPU (set-up submits no work with it).
            unsafe { handle.destroy(self.device) };
        }
    }
}
