//! Frames in flight: a frame is submitted without waiting for the one before it, so the CPU
//! plans and records frame N+1 while the GPU runs frame N. What the host writes or reads per
//! frame — its layer parameters and plan dispatch (in the targets, at the slot's offset), its
//! timestamps and its counters' read-back — lives in one of MAX_FRAMES_IN_FLIGHT slots,
//! reused round the ring once the slot's frame has been read back. The GPU-only buffers
//! (lattice, work lists, pixels, the output image) are shared: each frame's first barrier
//! waits for the frames before it (`FramePasses::begin`), which the queue runs in order anyway.

use super::counters::FrameCounters;
use super::eye_params::EyeLayers;
use super::frame::{Frame, FrameStats, TraversalCounts};
use super::settings::Traversal;
use super::RenderError;
use crate::gpu::{Commands, GpuContext, TimestampPool};
use std::sync::Arc;
use std::time::Instant;

/// Frame slots: the most frames a renderer keeps in flight. Two let the CPU's and the GPU's
/// work overlap; a third absorbs a frame whose CPU side runs long (a slow xrWaitFrame).
pub const MAX_FRAMES_IN_FLIGHT: usize = 3;

/// A submitted frame whose results have not been read yet.
pub(super) struct PendingFrame {
    /// Dropped (which waits for its fence) before the renderer's buffers: the renderer's
    /// first field holds these.
    pub commands: Commands<Arc<GpuContext>>,
    pub slot: usize,
    pub known: FrameKnown,
}

/// What is known of a frame when it is submitted.
pub(super) struct FrameKnown {
    pub width: u32,
    pub height: u32,
    pub eyes: Vec<EyeLayers>,
    /// Samples per lattice point of every layer, innermost first.
    pub layer_spp: Vec<u32>,
    pub plan_ms: f64,
    pub record_ms: f64,
    pub profile_traversal: bool,
    pub traced_with: Traversal,
    pub busy_at_submit: u32,
    pub submitted_at: Instant,
}

/// The finished frame of `known` from its slot's timestamps and counters (its fence has
/// signalled); no pixels.
pub(super) fn frame_results(
    known: FrameKnown,
    timestamps: &TimestampPool,
    counters: &FrameCounters,
    slot: usize,
) -> Result<Frame, RenderError> {
    let completed_at = Instant::now();
    let passes = timestamps.read()?;
    let counted = counters.read(slot)?;
    let eyes = known.eyes.len();
    let mut counters = counted.eyes;
    counters.truncate(eyes);
    let layer_samples = known
        .layer_spp
        .iter()
        .enumerate()
        .map(|(k, &spp)| {
            let points: u64 = counted.layer_points[..eyes].iter().map(|p| p[k]).sum();
            points * spp as u64
        })
        .collect();
    Ok(Frame {
        width: known.width * eyes as u32,
        height: known.height,
        rgb: Vec::new(),
        gazes: known.eyes.iter().map(|e| e.gaze).collect(),
        stats: FrameStats {
            nonfinite_samples: counters.iter().map(|c| c.nonfinite_samples).sum(),
            stack_overflows: counters.iter().map(|c| c.stack_overflows).sum(),
            paths: counters.iter().map(|c| c.paths).sum(),
            rays: counters.iter().map(|c| c.rays).sum(),
            eyes: counters,
            pass_ms: passes.iter().map(|p| (p.name.clone(), p.ms)).collect(),
            pass_start_ms: passes.iter().map(|p| p.start_ms).collect(),
            layer_samples,
            plan_ms: known.plan_ms,
            record_ms: known.record_ms,
            traversal: known.profile_traversal.then(|| {
                counted.traversal[..eyes]
                    .iter()
                    .fold(TraversalCounts::default(), |a, &b| a + b)
            }),
            traced_with: known.traced_with,
            busy_at_submit: known.busy_at_submit,
            submitted_at: Some(known.submitted_at),
            completed_at: Some(completed_at),
        },
    })
}
