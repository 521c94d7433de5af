//! What a headset run is asked for.

use super::instance::RuntimeSource;
use crate::foveation::FoveationConfig;
use crate::gpu::GpuOptions;
use crate::render::display::DisplayTransform;
use crate::render::{DebugView, RenderSettings, TemporalSettings};
use crate::scene::Scene;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

pub struct XrOptions {
    pub source: RuntimeSource,
    pub gpu: GpuOptions,
    pub scene: Scene,
    /// Per-eye image size; `None`: the runtime's recommended size.
    pub size: Option<[u32; 2]>,
    /// Seed, integrator and bounces (width and height come from the swapchains).
    pub settings: RenderSettings,
    pub foveation: FoveationConfig,
    pub debug: DebugView,
    /// End the session cleanly after this many rendered frames.
    pub frames: Option<u64>,
    /// Seconds a lost gaze is held before falling back to the centre.
    pub gaze_hold_s: f64,
    /// Use the runtime's visibility mask where offered.
    pub visibility_mask: bool,
    /// Render nothing: set everything up, submit empty frames until `frames`, and report
    /// what the runtime offers ([`XrSummary::probe`](super::XrSummary::probe)).
    pub probe: bool,
    /// Set (by a Ctrl+C or termination handler) to end the session as `frames` does: the
    /// runtime is asked to stop, and everything is torn down and recorded.
    pub stop: Arc<AtomicBool>,
    /// Frames submitted before the CPU waits for the oldest one's GPU work (1: each frame
    /// finished before the next is planned; at most MAX_FRAMES_IN_FLIGHT).
    pub frames_in_flight: usize,
    /// Temporal history (`Renderer::set_temporal`); None: off.
    pub temporal: Option<TemporalSettings>,
    /// What the swapchains show of the scene-referred frames (exposure, tone mapper).
    pub display: DisplayTransform,
}
