//! The one place the XR session calls the renderer: every call into `Renderer` a headset
//! session makes is in this file (set-up, visibility masks, a frame's submission, finished
//! frames), so a change of the renderer's API changes this file and nothing else in xr/.
//!
//! Frames overlap: a frame is submitted and handed to the runtime, and its results (GPU
//! timings, counters) are recorded once its fence has signalled, oldest first.

use super::error::XrError;
use super::frame_record::{FrameRecord, Record};
use super::options::XrOptions;
use super::views::EyeViews;
use crate::foveation::gaze_filter::FilteredGaze;
use crate::foveation::{FoveationConfig, Gaze, ImageGeometry, VisibilityMask};
use crate::gpu::{ExternalImage, GpuContext, SourceRect};
use crate::render::FrameOptions;
use crate::render::{FrameRequest, RenderSettings, Renderer};
use std::collections::VecDeque;
use std::sync::Arc;
use std::time::Instant;

/// The renderer of a headset session, and the frames it has in flight.
pub(super) struct HeadsetRenderer<'a> {
    renderer: Renderer,
    /// Submitted frames whose results have not been recorded yet, oldest first.
    submitted: VecDeque<SubmittedFrame>,
    ctx: &'a Arc<GpuContext>,
    options: &'a XrOptions,
    /// The layers every frame renders (options.foveation resolved for the runtime's headset).
    foveation: FoveationConfig,
}

/// A frame submitted and handed to the runtime, whose GPU work may still be running.
pub(super) struct SubmittedFrame {
    pub(super) index: u64,
    pub(super) display_time_s: f64,
    pub(super) display_period_s: f64,
    pub(super) gaze_time_s: f64,
    pub(super) gaze_sampled: bool,
    pub(super) gaze: FilteredGaze,
    pub(super) images: Vec<ImageGeometry>,
    /// The end of its xrWaitFrame.
    pub(super) started: Instant,
    pub(super) cpu_ms: f64,
    pub(super) latch_ms: f64,
}

impl<'a> HeadsetRenderer<'a> {
    /// A renderer of `options.scene` whose frames are copied from its output image into the
    /// swapchains, with `options.frames_in_flight` and temporal history as asked.
    pub(super) fn new(
        ctx: &'a Arc<GpuContext>,
        options: &'a XrOptions,
        foveation: FoveationConfig,
    ) -> Result<Self, XrError> {
        let mut renderer = Renderer::new(ctx, &options.scene)?;
        renderer.set_output_image(true);
        renderer.set_frames_in_flight(options.frames_in_flight)?;
        renderer.set_temporal(options.temporal)?;
        renderer.set_display(options.display)?;
        Ok(Self {
            renderer,
            submitted: VecDeque::new(),
            ctx,
            options,
            foveation,
        })
    }

    pub(super) fn set_visibility_masks(&mut self, masks: Vec<VisibilityMask>) {
        self.renderer.set_visibility_masks(masks);
    }

    /// Submits frame `index` of `views` and returns without waiting for it. After its
    /// commands are recorded, `latch` gives the eyes' gaze (the last step before the
    /// submission), the frame is planned from it, and the copies of its output image into
    /// `targets` (the eyes' swapchain images) end the same submission.
    pub(super) fn submit(
        &mut self,
        index: u64,
        views: &EyeViews,
        latch: &mut dyn FnMut() -> Vec<Gaze>,
        targets: &[(SourceRect, ExternalImage)],
    ) -> Result<(), XrError> {
        let options = self.options;
        let settings = RenderSettings {
            width: views.size[0],
            height: views.size[1],
            spp: self.foveation.layers[0].spp,
            seed: options.settings.seed.wrapping_add(index as u32),
            ..options.settings
        };
        let request = FrameRequest {
            settings,
            foveation: &self.foveation,
            eyes: &views.eyes,
            debug: options.debug,
        };
        let ctx = self.ctx;
        let mut copy = |cmd, output: &_| ctx.cmd_copy_to_external(cmd, output, targets);
        let options = FrameOptions {
            latch: Some(latch),
            after: Some(&mut copy),
            ..Default::default()
        };
        self.renderer.frame(&request, options)?;
        Ok(())
    }

    /// Keeps `frame`, just submitted, until its results are recorded.
    pub(super) fn sent(&mut self, frame: SubmittedFrame) {
        self.submitted.push_back(frame);
    }

    /// Records the submitted frames whose GPU work has finished, oldest first, after
    /// waiting for the oldest ones until at most `keep` are left in flight.
    pub(super) fn record_finished(
        &mut self,
        record: &mut Record,
        keep: usize,
    ) -> Result<(), XrError> {
        let renderer = &mut self.renderer;
        while let Some(frame) = renderer.next_finished(renderer.in_flight() > keep)? {
            let sent = self
                .submitted
                .pop_front()
                .expect("every finished frame was submitted by this loop");
            let done = frame.stats.completed_at.unwrap_or_else(Instant::now);
            record(&FrameRecord {
                index: sent.index,
                display_time_s: sent.display_time_s,
                display_period_s: sent.display_period_s,
                gaze_time_s: sent.gaze_time_s,
                gaze_sampled: sent.gaze_sampled,
                frame: &frame,
                gaze: &sent.gaze,
                images: &sent.images,
                cpu_ms: sent.cpu_ms,
                latch_ms: sent.latch_ms,
                gpu_done_ms: done.duration_since(sent.started).as_secs_f64() * 1e3,
                gpu_bytes: self.ctx.memory_in_use(),
            })?;
        }
        Ok(())
    }
}
