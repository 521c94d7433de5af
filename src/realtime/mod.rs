//! `fovea gpu-report`: is fovea real-time on this device? Per scene, regular and foveated
//! frames (mono and stereo, every traversal the device has) timed pass by pass; the largest
//! fovea spp whose stereo frame fits 90 Hz's and 120 Hz's frame time; headset sessions on the
//! simulated headset with 1, 2 and 3 frames in flight. Made for a GPU lent for minutes
//! (tools/gpu-bundle.sh packs it with what it needs), run on lavapipe in CI.

pub mod frames;
pub mod plan;
pub mod report;
pub mod run;
pub mod sessions;
pub mod spp_search;

pub use plan::RealtimePlan;
pub use run::run;
