//! One rendered headset frame as the session's recorder sees it, and the callback that sees
//! each.

use super::error::XrError;
use crate::foveation::gaze_filter::FilteredGaze;
use crate::foveation::ImageGeometry;
use crate::render::Frame;

/// What sees every rendered frame ([`run`](super::run)'s `record`).
pub(super) type Record<'r> = dyn FnMut(&FrameRecord) -> Result<(), XrError> + 'r;

/// One rendered frame, for whoever records the session.
pub struct FrameRecord<'a> {
    pub index: u64,
    /// Predicted display time, seconds (the runtime's clock).
    pub display_time_s: f64,
    /// The runtime's display period, seconds.
    pub display_period_s: f64,
    /// When the eye tracker took the gaze sample (XrEyeGazeSampleTimeEXT), else the display
    /// time.
    pub gaze_time_s: f64,
    /// Whether the eye tracker gave a sample (its time) for the frame.
    pub gaze_sampled: bool,
    /// GPU timings and counters of both eyes (no pixels: the image went to the headset).
    pub frame: &'a Frame,
    pub gaze: &'a FilteredGaze,
    pub images: &'a [ImageGeometry],
    /// CPU milliseconds from the end of xrWaitFrame to the end of xrEndFrame.
    pub cpu_ms: f64,
    /// CPU milliseconds from the end of xrWaitFrame to the gaze latch (right before the
    /// frame's submission) and to the end of its GPU work (when fovea saw its fence
    /// signalled: it looks after every xrWaitFrame and xrEndFrame).
    pub latch_ms: f64,
    pub gpu_done_ms: f64,
    /// fovea's GPU memory in use after the frame, bytes.
    pub gpu_bytes: u64,
}
