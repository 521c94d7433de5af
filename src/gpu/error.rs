/// What went wrong on the GPU side, each with what to do about it.
#[derive(Debug, thiserror::Error)]
pub enum GpuError {
    #[error("cannot load the Vulkan loader (libvulkan.so.1): {0}. Install it and a driver: `sudo apt-get install -t bookworm-backports libvulkan1 mesa-vulkan-drivers` (or run tools/setup.sh)")]
    NoLoader(String),
    /// No usable device: the loader found no driver, or no device that fovea can use.
    /// `detail` says which, and names driver-selecting environment variables that are set.
    #[error("no Vulkan device with compute support was found: {detail}. For CPU rendering install Mesa's lavapipe: `sudo apt-get install -t bookworm-backports mesa-vulkan-drivers` (or run tools/setup.sh); for a GPU install its vendor driver. `vulkaninfo --summary` lists the devices the Vulkan loader sees")]
    NoDevice { detail: String },
    #[error("no Vulkan device matches --device '{wanted}'; available: {available}")]
    DeviceNotFound { wanted: String, available: String },
    #[error("the validation layer VK_LAYER_KHRONOS_validation is not installed: `sudo apt-get install -t bookworm-backports vulkan-validationlayers`, or run without validation")]
    NoValidationLayer,
    #[error("the validation layer does not offer VK_EXT_validation_features, which fovea needs to turn on its synchronization checks: install a newer vulkan-validationlayers (`sudo apt-get install -t bookworm-backports vulkan-validationlayers`), or set FOVEA_VALIDATION=core for the core checks only")]
    NoValidationFeatures,
    #[error("--traversal rayquery needs ray queries, and the Vulkan device '{device}' does not offer them (VK_KHR_ray_query and VK_KHR_acceleration_structure with their features): use --traversal software, or --traversal auto to use them where they exist")]
    NoRayQueries { device: String },
    /// An environment variable fovea reads has a value it cannot use.
    #[error("{var}='{value}' {problem}")]
    BadEnvironment {
        var: &'static str,
        value: String,
        problem: String,
    },
    #[error("Vulkan call {call} failed: {result}")]
    Vulkan {
        call: &'static str,
        result: ash::vk::Result,
    },
    /// VK_ERROR_DEVICE_LOST. The crash markers the command buffer wrote after each pass say
    /// which pass completed last (`completed`) and which was running (`running`, the one
    /// recorded after it). `injected`: the loss was simulated by `FOVEA_INJECT_DEVICE_LOST`.
    #[error(
        "the GPU was lost (VK_ERROR_DEVICE_LOST{}) in the '{submission}' submission: {}; the driver may have reset a shader that ran too long: try a smaller --width/--height/--spp",
        if *.injected { ", injected by FOVEA_INJECT_DEVICE_LOST" } else { "" },
        lost_where(.completed, .running)
    )]
    DeviceLost {
        submission: String,
        completed: Option<String>,
        running: Option<String>,
        injected: bool,
    },
    /// A frame recorded more timed passes than its timestamp pool had room for.
    #[error(
        "the frame's timestamp pool had room for {room} passes but the frame recorded more; \
         these passes were not timed: {untimed:?}. The pool is sized from the frame's pass \
         list, so this is a bug: please report it with the command that ran"
    )]
    UntimedPasses { room: u32, untimed: Vec<String> },
    /// Every crash-marker set is held by a command buffer whose work is not done.
    #[error(
        "more than {limit} command buffers were recorded and not finished at once; fovea keeps \
         at most 3 frames in flight and finishes its uploads before the next: this is a bug, \
         please report it with the command that ran"
    )]
    TooManyCommandBuffers { limit: usize },
    #[error("out of GPU memory allocating {what} ({bytes} bytes): {detail}. Try a smaller scene or resolution")]
    OutOfMemory {
        what: String,
        bytes: u64,
        detail: String,
    },
    /// A set of allocations checked before any was made does not fit the memory the device
    /// (or `FOVEA_GPU_MEMORY_LIMIT`) offers. Every size is in the message.
    #[error("not enough GPU memory for {}: {} on top of the {} fovea already holds, but {}; {}", .0.what, .0.needed, .0.in_use, .0.offered, .0.advice)]
    NotEnoughMemory(Box<MemoryShortfall>),
    /// One buffer or image is larger than a per-resource device limit.
    #[error("{}: the {} would be one {} of {}, more than the device allows ({} = {}); {}", .0.what, .0.item, .0.kind, .0.bytes, .0.limit_name, .0.limit, .0.advice)]
    ResourceTooLarge(Box<ResourceLimit>),
    #[error("GPU memory allocation for {what} failed: {detail}")]
    Allocation { what: String, detail: String },
    #[error("{0}")]
    Limit(String),
    /// A failure in whoever created the instance or device for fovea (an OpenXR runtime).
    #[error("{0}")]
    External(String),
}

/// What a plan of allocations needs and what the device offers (see
/// [`GpuError::NotEnoughMemory`]); sizes are written out, exact and readable.
#[derive(Debug)]
pub struct MemoryShortfall {
    /// The plan: "scene 'bunny-high'", "the frame targets of a 512x512 stereo frame ...".
    pub what: String,
    /// Total and breakdown by buffer and image.
    pub needed: String,
    /// What fovea holds already.
    pub in_use: String,
    /// What the device offers: heap size, budget, `FOVEA_GPU_MEMORY_LIMIT`.
    pub offered: String,
    /// What to change.
    pub advice: String,
}

/// A buffer or image larger than a per-resource device limit (see
/// [`GpuError::ResourceTooLarge`]).
#[derive(Debug)]
pub struct ResourceLimit {
    pub what: String,
    /// The buffer or image, e.g. "ray buffer".
    pub item: String,
    /// "storage buffer" or "allocation".
    pub kind: &'static str,
    pub bytes: String,
    pub limit: String,
    /// The Vulkan limit, e.g. "maxStorageBufferRange".
    pub limit_name: &'static str,
    pub advice: String,
}

/// The part of a device-lost message that says where the GPU was.
fn lost_where(completed: &Option<String>, running: &Option<String>) -> String {
    match (completed, running) {
        (Some(done), Some(next)) => format!(
            "the last pass that completed was '{done}', so '{next}' was running (crash markers)"
        ),
        (None, Some(next)) => {
            format!("no pass had completed, so the first one, '{next}', was running (crash markers)")
        }
        (Some(done), None) => format!(
            "every pass had completed, the last one '{done}'; the loss came after it (crash markers)"
        ),
        (None, None) => "it recorded no pass markers".to_owned(),
    }
}

/// `bytes` in the largest binary unit that keeps it at 1 or more, e.g. "1.50 GiB".
pub(crate) fn human_bytes(bytes: u64) -> String {
    const UNITS: [&str; 5] = ["B", "KiB", "MiB", "GiB", "TiB"];
    let mut value = bytes as f64;
    let mut unit = 0;
    while value >= 1024.0 && unit + 1 < UNITS.len() {
        value /= 1024.0;
        unit += 1;
    }
    match unit {
        0 => format!("{bytes} B"),
        _ => format!("{value:.2} {}", UNITS[unit]),
    }
}

/// `bytes` as "1.50 GiB (1610612736 bytes)": readable and exact.
pub(crate) fn exact_bytes(bytes: u64) -> String {
    if bytes < 1024 {
        format!("{bytes} bytes")
    } else {
        format!("{} ({bytes} bytes)", human_bytes(bytes))
    }
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn byte_sizes_read_well() {
        assert_eq!(human_bytes(0), "0 B");
        assert_eq!(human_bytes(1023), "1023 B");
        assert_eq!(human_bytes(1536), "1.50 KiB");
        assert_eq!(human_bytes(64 << 20), "64.00 MiB");
        assert_eq!(human_bytes(32 << 30), "32.00 GiB");
        assert_eq!(exact_bytes(12), "12 bytes");
        assert_eq!(exact_bytes(1 << 30), "1.00 GiB (1073741824 bytes)");
    }

    #[test]
    fn device_lost_names_the_passes() {
        let e = GpuError::DeviceLost {
            submission: "frame".into(),
            completed: Some("left trace".into()),
            running: Some("left resolve".into()),
            injected: false,
        }
        .to_string();
        assert!(
            e.contains("'left trace'") && e.contains("'left resolve' was running"),
            "{e}"
        );
        assert!(!e.contains("injected"), "{e}");
    }
}
