//! The simulated headset: an OpenXR 1.0 runtime with a Vive Pro Eye-like HMD, a scripted
//! eye tracker and real Vulkan swapchains, for testing `fovea xr` without hardware.
//!
//! Two ways in:
//! - in-process: `openxr::Entry::from_get_instance_proc_addr(sim_headset::get_instance_proc_addr(), &())`;
//! - through the Khronos loader: point `XR_RUNTIME_JSON` at `manifest.json` (debug build) or
//!   `manifest-release.json`; the cdylib exports `xrNegotiateLoaderRuntimeInterface`.
//!
//! Configuration: `SIM_HEADSET_*` environment variables read at `xrCreateInstance`, or
//! [`set_config_override`] for the calling thread (see README.md).

mod actions;
mod clock;
mod config;
mod dispatch;
mod entry_points;
mod ffi;
mod frame;
mod gaze_script;
mod instance;
mod interaction_profiles;
mod negotiate;
mod paths;
mod pose;
mod readback;
mod registry;
mod report;
mod session;
mod spaces;
mod swapchain;
mod system;
mod views;
mod visibility_mask;
mod vulkan;
mod vulkan_enable;

pub use config::{set_config_override, Config, ConfigError, EyeGazeMode};
pub use gaze_script::{GazeKeyframe, GazeScript, GazeScriptError, SampleStatus};
pub use negotiate::xrNegotiateLoaderRuntimeInterface;

use openxr_sys as xr;

/// The name the runtime reports in `xrGetInstanceProperties` and in its report.
pub const RUNTIME_NAME: &str = "fovea simulated headset";
/// The OpenXR version implemented.
pub const API_VERSION: xr::Version = xr::Version::new(1, 0, 34);

/// The runtime's `xrGetInstanceProcAddr`, for `openxr::Entry::from_get_instance_proc_addr`.
pub fn get_instance_proc_addr() -> xr::pfn::GetInstanceProcAddr {
    dispatch::get_instance_proc_addr
}

/// Per-eye field of view (0 = left, 1 = right) the headset reports, in radians.
pub fn eye_fov(eye: usize) -> xr::Fovf {
    views::eye_fov(eye)
}

pub use clock::{FRAME_PERIOD_NS, GAZE_PERIOD_NS, LEAD_NS};
