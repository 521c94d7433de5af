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
use super::slots::MAX_FRAMES_IN_FLIGHT;
use super::RenderError;
use crate::gpu::{Commands, DescriptorArena, GpuContext, TimestampPool};
use std::collections::VecDeque;
use std::sync::Arc;
use std::time::Instant;

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
            filled_points: counted.filled_points[..eyes].iter().sum(),
            trace_workgroups: counted.trace_workgroups[..eyes].iter().sum(),
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

/// What each frame slot holds for its frame: timings and the passes' descriptor sets.
pub(super) struct FrameSlot {
    pub timestamps: TimestampPool,
    pub descriptors: DescriptorArena,
}

/// The frames in flight, in submission order, and the slots they use round the ring.
pub(super) struct FrameRing {
    // Field order is drop order: frames in flight (whose drop waits for them) first.
    /// Submitted frames not read back yet, oldest first.
    in_flight: VecDeque<PendingFrame>,
    /// Frames read back (their fences signalled) that the caller has not taken yet.
    finished: VecDeque<Frame>,
    /// The most frames left in flight (1: every frame waited for before the next).
    limit: usize,
    /// The slot of the next submitted frame.
    next_slot: usize,
    pub slots: Vec<FrameSlot>,
}

/// Timed passes a frame slot's timestamp pool starts with: a stereo frame's plan, trace and
/// resolve, the dispatch sizes and the output image. A frame with more passes (history,
/// denoise iterations) grows its slot's pool first (`FramePasses::timed_passes`).
const TIMED_PASSES: u32 = 8;

impl FrameRing {
    pub fn new(ctx: &Arc<GpuContext>) -> Result<Self, RenderError> {
        let slot = || -> Result<FrameSlot, RenderError> {
            Ok(FrameSlot {
                timestamps: TimestampPool::new(ctx, TIMED_PASSES)?,
                descriptors: DescriptorArena::new(ctx)?,
            })
        };
        Ok(Self {
            in_flight: VecDeque::new(),
            finished: VecDeque::new(),
            limit: 1,
            next_slot: 0,
            slots: (0..MAX_FRAMES_IN_FLIGHT)
                .map(|_| slot())
                .collect::<Result<_, _>>()?,
        })
    }

    /// How many frames may be in flight at once (1..=MAX_FRAMES_IN_FLIGHT).
    pub fn set_limit(&mut self, frames: usize) -> Result<(), RenderError> {
        if !(1..=MAX_FRAMES_IN_FLIGHT).contains(&frames) {
            return Err(RenderError::Settings(format!(
                "{frames} frames in flight: give 1 (each frame finished before the next) to \
                 {MAX_FRAMES_IN_FLIGHT}"
            )));
        }
        self.limit = frames;
        Ok(())
    }

    pub fn len(&self) -> usize {
        self.in_flight.len()
    }

    /// The slot the next frame is recorded into, its frame retired first when as many
    /// frames as allowed are in flight.
    pub fn next_slot(&mut self, counters: &FrameCounters) -> Result<usize, RenderError> {
        if self.in_flight.len() >= self.limit {
            self.retire_oldest(counters)?;
        }
        Ok(self.next_slot)
    }

    /// Frames still running on the GPU.
    pub fn busy(&self) -> Result<u32, RenderError> {
        let mut busy = 0;
        for frame in &self.in_flight {
            busy += !frame.commands.is_done()? as u32;
        }
        Ok(busy)
    }

    /// A frame just submitted into the next slot.
    pub fn push(&mut self, frame: PendingFrame) {
        self.next_slot = (frame.slot + 1) % MAX_FRAMES_IN_FLIGHT;
        self.in_flight.push_back(frame);
    }

    /// Waits for the oldest frame in flight and reads its results into `finished`, which
    /// frees its slot.
    fn retire_oldest(&mut self, counters: &FrameCounters) -> Result<(), RenderError> {
        let Some(mut frame) = self.in_flight.pop_front() else {
            return Ok(());
        };
        frame.commands.wait()?;
        let slot = frame.slot;
        let timestamps = &self.slots[slot].timestamps;
        let results = frame_results(frame.known, timestamps, counters, slot)?;
        self.finished.push_back(results);
        Ok(())
    }

    /// Waits for every frame in flight (their results wait in `finished`): before anything
    /// they use is replaced.
    pub fn wait_all(&mut self, counters: &FrameCounters) -> Result<(), RenderError> {
        while !self.in_flight.is_empty() {
            self.retire_oldest(counters)?;
        }
        Ok(())
    }

    /// The oldest submitted frame not taken yet, if it has finished; with `wait`, waits for
    /// it. None when no frame is left.
    pub fn next_finished(
        &mut self,
        counters: &FrameCounters,
        wait: bool,
    ) -> Result<Option<Frame>, RenderError> {
        if self.finished.is_empty() {
            let done = match self.in_flight.front() {
                None => return Ok(None),
                Some(oldest) => wait || oldest.commands.is_done()?,
            };
            if done {
                self.retire_oldest(counters)?;
            }
        }
        Ok(self.finished.pop_front())
    }

    /// Waits for every frame and takes the newest (the one just submitted).
    pub fn wait_newest(&mut self, counters: &FrameCounters) -> Result<Frame, RenderError> {
        self.wait_all(counters)?;
        Ok(self.finished.pop_back().expect("a frame was submitted"))
    }
}
