//! OpenXR: the headset session (XR_KHR_vulkan_enable2), per-eye swapchains, eye gaze
//! (XR_EXT_eye_gaze_interaction) and the lens's visibility mask (XR_KHR_visibility_mask).
//! With SteamVR on a Vive Pro Eye, or with the simulated headset in tools/sim-headset.

mod error;
mod eye_gaze;
mod frame_loop;
mod frame_record;
mod headset_gaze;
mod headset_renderer;
mod instance;
mod options;
pub mod poses;
mod probe;
mod recording;
mod session;
mod summary;
mod swapchains;
mod views;
mod vulkan;

pub use error::XrError;
pub use frame_record::FrameRecord;
pub use instance::RuntimeSource;
pub use options::{FoveationChoice, XrOptions};
pub use probe::{ProbeReport, PROBE_FRAMES};
pub use recording::SessionRecorder;
pub use session::{run, SESSION_RETRIES};
pub use summary::{SessionEnd, XrSummary};
