//! What a viewer run did, handed back when the window closes.

use std::path::PathBuf;

/// What a run did, for the command to print and tests to check.
#[derive(Clone, Debug, Default)]
pub struct ViewSummary {
    pub frames: u64,
    pub rendered: u64,
    pub presented: u64,
    /// Frames not shown: the window had no area, was occluded or the swapchain was out of date.
    pub not_shown: u64,
    pub swapchain_recreations: u64,
    /// Frames in the running mean when the viewer ended.
    pub accumulated: u32,
    pub screenshots: Vec<PathBuf>,
    /// The device the frames were rendered on.
    pub device: String,
    /// The swapchain's format and present mode.
    pub swapchain: String,
    /// What the window showed of the last scene's radiance (exposure, tone mapper).
    pub display: String,
    /// What the validation layer reported (nothing without validation), read after the GPU
    /// context is gone so that leaks reported at destruction are in it.
    pub validation_messages: Vec<String>,
}
