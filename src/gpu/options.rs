//! How to pick and set up the device: the options and the environment variables they come from.

use super::error::GpuError;

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
    /// Which of the layer's optional checks run with it (synchronization by default).
    pub checks: ValidationChecks,
    /// The most GPU memory fovea may use, in bytes, all buffers and images together; None =
    /// whatever the device offers. For sharing the GPU with other programs (the SteamVR
    /// compositor, a game engine). Scene uploads and frame targets are checked against it
    /// (and against the device's heap and, with VK_EXT_memory_budget, its budget) before
    /// anything is allocated, and every allocation is refused past it, so running out gives a
    /// message with the sizes instead of a driver error. Set by `FOVEA_GPU_MEMORY_LIMIT`:
    /// bytes with an optional K, M, G or T suffix (powers of 1024), e.g. `6G` or `512M`.
    pub memory_limit: Option<u64>,
    /// Testing only: the name of a pass (as the GPU timestamps name it, e.g. `trace` or
    /// `left trace`) after which every command buffer containing it ends, and whose submission
    /// then reports VK_ERROR_DEVICE_LOST as a driver would. The error is built by the real
    /// crash-marker read-back, so tests exercise that path on lavapipe, which never loses its
    /// device. A real device loss was not reproduced while writing this. Set by
    /// `FOVEA_INJECT_DEVICE_LOST`.
    pub inject_device_lost: Option<String>,
    /// Whether to enable ray queries (VK_KHR_ray_query, for `--traversal rayquery|auto`).
    pub ray_queries: RayQueries,
    /// A bad environment value seen by [`Self::from_env`]: (variable, value, problem).
    /// [`GpuContext::new`](super::GpuContext::new) reports it before touching Vulkan.
    pub(super) env_problem: Option<(&'static str, String, String)>,
}

/// Whether the context enables ray queries (and acceleration structures) on its device.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum RayQueries {
    /// Not enabled: only the software traversal can run.
    Off,
    /// Enabled when the device has them (`--traversal auto`); the renderer traces with them
    /// by default on a GPU, not on a CPU driver (see GpuContext::prefers_ray_queries).
    #[default]
    IfAvailable,
    /// Enabled, and a device without them is an error that says so (`--traversal rayquery`).
    Required,
}

/// The validation layer's optional checks, switched on through VK_EXT_validation_features
/// when fovea creates the instance with validation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ValidationChecks {
    /// Synchronization validation: hazards between commands (a read after a write, a write
    /// after a read, a layout transition) that no barrier orders. Lavapipe runs dispatches
    /// one after another, so on it only this check sees a missing barrier.
    pub synchronization: bool,
    /// GPU-assisted validation: shaders are instrumented to report out-of-bounds descriptor
    /// accesses (slow: for tests at small sizes).
    pub gpu_assisted: bool,
}

impl Default for ValidationChecks {
    fn default() -> Self {
        Self {
            synchronization: true,
            gpu_assisted: false,
        }
    }
}

impl ValidationChecks {
    /// The checks `FOVEA_VALIDATION=VALUE` asks for, or None when it asks for no validation:
    /// `1` the default checks, `core` none of the optional ones (to measure what they cost),
    /// `gpu-assisted` the default checks and GPU-assisted validation.
    fn from_env_value(value: &str) -> Option<Self> {
        match value {
            "1" => Some(Self::default()),
            "core" => Some(Self {
                synchronization: false,
                gpu_assisted: false,
            }),
            "gpu-assisted" => Some(Self {
                gpu_assisted: true,
                ..Self::default()
            }),
            _ => None,
        }
    }
}

impl GpuOptions {
    /// Options from the environment: `FOVEA_VALIDATION=1` turns validation on with its
    /// synchronization checks (tests use it; `core` and `gpu-assisted`: see
    /// [`ValidationChecks`]),
    /// `FOVEA_DEVICE` picks a device, `FOVEA_GPU_MEMORY_LIMIT` caps GPU memory and
    /// `FOVEA_INJECT_DEVICE_LOST` injects a device loss (see the fields). A value that cannot
    /// be used is reported by [`GpuContext::new`](super::GpuContext::new).
    pub fn from_env() -> Self {
        let checks = std::env::var("FOVEA_VALIDATION")
            .ok()
            .and_then(|v| ValidationChecks::from_env_value(&v));
        let mut options = Self {
            device: std::env::var("FOVEA_DEVICE").ok(),
            validation: checks.is_some(),
            checks: checks.unwrap_or_default(),
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

    /// The bad environment value [`Self::from_env`] saw, if any, as the error that names it.
    pub(super) fn check_environment(&self) -> Result<(), GpuError> {
        match &self.env_problem {
            Some((var, value, problem)) => Err(GpuError::BadEnvironment {
                var,
                value: value.clone(),
                problem: problem.clone(),
            }),
            None => Ok(()),
        }
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
