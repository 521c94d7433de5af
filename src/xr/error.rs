//! What can go wrong in an OpenXR session, each with what to do about it.

use crate::gpu::GpuError;
use crate::render::RenderError;
use openxr as xr;

#[derive(Debug, thiserror::Error)]
pub enum XrError {
    #[error(
        "could not load the OpenXR loader ({0}). Install it (Debian: apt install libopenxr-loader1) \
         or run `fovea xr --simulated` to use the built-in simulated headset"
    )]
    NoLoader(String),
    #[error(
        "no OpenXR runtime is active ({0}). Start SteamVR (or another runtime), or point \
         XR_RUNTIME_JSON at a runtime manifest, e.g. tools/sim-headset/manifest.json for the \
         simulated headset, or run `fovea xr --simulated`"
    )]
    NoRuntime(String),
    #[error(
        "the OpenXR runtime '{runtime}' does not offer XR_KHR_vulkan_enable2, which fovea needs to \
         share its Vulkan device with the compositor; update the runtime (SteamVR supports it)"
    )]
    NoVulkanEnable2 { runtime: String },
    #[error(
        "no head-mounted display is available ({0}): connect and switch on the headset and \
         check that the runtime (SteamVR) sees it"
    )]
    NoHeadset(String),
    #[error(
        "the runtime needs Vulkan {min} to {max}, and fovea uses Vulkan 1.2: update the runtime \
         or the graphics driver"
    )]
    VulkanVersion { min: String, max: String },
    #[error("OpenXR call {call} failed: {result}")]
    Call {
        call: &'static str,
        result: xr::sys::Result,
    },
    #[error("the session was lost ({0}); the headset may have been disconnected or the runtime restarted")]
    SessionLost(String),
    #[error(
        "none of the runtime's swapchain formats can be written by fovea (offered: {offered}); \
         fovea needs an 8-bit or 16-bit float RGBA/BGRA format"
    )]
    NoSwapchainFormat { offered: String },
    #[error("{0}")]
    Gpu(#[from] GpuError),
    #[error("{0}")]
    Render(#[from] RenderError),
    #[error("{0}")]
    Output(String),
}

/// Attaches the name of the OpenXR call to its error code.
pub(crate) trait XrContext<T> {
    fn xr(self, call: &'static str) -> Result<T, XrError>;
}

impl<T> XrContext<T> for Result<T, xr::sys::Result> {
    fn xr(self, call: &'static str) -> Result<T, XrError> {
        self.map_err(|result| match result {
            xr::sys::Result::ERROR_SESSION_LOST => XrError::SessionLost(call.to_string()),
            result => XrError::Call { call, result },
        })
    }
}
