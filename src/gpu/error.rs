/// What went wrong on the GPU side, each with what to do about it.
#[derive(Debug, thiserror::Error)]
pub enum GpuError {
    #[error("cannot load the Vulkan loader (libvulkan.so.1): {0}. Install it and a driver: `sudo apt-get install -t bookworm-backports libvulkan1 mesa-vulkan-drivers` (or run tools/setup.sh)")]
    NoLoader(String),
    #[error("no Vulkan device with compute support was found. For CPU rendering install Mesa's lavapipe: `sudo apt-get install -t bookworm-backports mesa-vulkan-drivers` (or run tools/setup.sh); for a GPU install its vendor driver")]
    NoDevice,
    #[error("no Vulkan device matches --device '{wanted}'; available: {available}")]
    DeviceNotFound { wanted: String, available: String },
    #[error("the validation layer VK_LAYER_KHRONOS_validation is not installed: `sudo apt-get install -t bookworm-backports vulkan-validationlayers`, or run without validation")]
    NoValidationLayer,
    #[error("Vulkan call {call} failed: {result}")]
    Vulkan {
        call: &'static str,
        result: ash::vk::Result,
    },
    #[error("the GPU was lost (VK_ERROR_DEVICE_LOST) during pass '{last_pass}'; the driver may have reset a shader that ran too long: try a smaller --width/--height/--spp")]
    DeviceLost { last_pass: String },
    #[error("out of GPU memory allocating {what} ({bytes} bytes): {detail}. Try a smaller scene or resolution")]
    OutOfMemory {
        what: String,
        bytes: u64,
        detail: String,
    },
    #[error("GPU memory allocation for {what} failed: {detail}")]
    Allocation { what: String, detail: String },
    #[error("{0}")]
    Limit(String),
}

/// Adds the name of the failing call to an ash result.
pub(crate) trait VkContext<T> {
    fn vk(self, call: &'static str) -> Result<T, GpuError>;
}

impl<T> VkContext<T> for Result<T, ash::vk::Result> {
    fn vk(self, call: &'static str) -> Result<T, GpuError> {
        self.map_err(|result| GpuError::Vulkan { call, result })
    }
}
