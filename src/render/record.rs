//! The frame, as DESIGN.md draws it: record every pass for every eye into the next frame
//! slot (counters zeroed → plan → dispatch sizes → trace → lattice filter → resolve →
//! temporal → denoise → output image → the caller's copy → counters read back), then latch
//! the gaze, plan each eye for it on the CPU (O(layers) numbers, eye_params.rs), write the layers where the
//! recorded commands read them, and submit. The frame is left in flight (in_flight.rs).

use super::eye_params::{eye_layers, eye_push, EyeLayers, EyePlanInput};
use super::graph::FrameGraph;
use super::in_flight::{FrameKnown, PendingFrame};
use super::passes::FramePasses;
use super::renderer::Renderer;
use super::request::{AfterFrame, FrameOptions, FrameRequest};
use super::RenderError;
use crate::foveation::Gaze;
use crate::gpu::{Commands, GpuContext};
use crate::shader_layout::{EyePush, PushCamera};
use std::sync::Arc;
use std::time::Instant;

impl Renderer {
    /// Records, latches and submits a prepared frame. `traced`: false when a test gave the
    /// lattice values (`compose`), which skips plan and trace and leaves the history alone.
    pub(super) fn submit(
        &mut self,
        request: &FrameRequest,
        options: FrameOptions,
        traced: bool,
    ) -> Result<(), RenderError> {
        let slot = self.ring.next_slot(&self.counters)?;
        let recording = Instant::now();
        let pushes = self.eye_pushes(request, slot, traced);
        let mut commands = self.record(request, slot, &pushes, traced, options.after)?;
        let record_ms = recording.elapsed().as_secs_f64() * 1e3;

        // The latch: the newest gaze, planned and written where the recorded commands read it.
        let gazes = match options.latch {
            Some(latch) => latch(),
            None => request.eyes.iter().map(|e| e.gaze).collect(),
        };
        let (eyes, plan_ms) = self.plan_eyes(request, &gazes);
        let targets = self.targets.current_mut().expect("prepared");
        targets.write_layers(slot, &eyes)?;
        if let Some(history) = self.history.as_mut().filter(|_| traced) {
            let cameras: Vec<PushCamera> = pushes.iter().map(|p| p.cam).collect();
            // What the eyes keep (`advance` leaves out the carried bits).
            let albedo = pushes.iter().fold(0, |word, p| word | p.albedo);
            history.advance(slot, &cameras, albedo)?;
        }
        let busy_at_submit = self.ring.busy()?;
        let submitted_at = Instant::now();
        commands.submit()?;
        self.ring.push(PendingFrame {
            commands,
            slot,
            known: FrameKnown {
                width: request.settings.width,
                height: request.settings.height,
                eyes,
                layer_spp: request.foveation.layers.iter().map(|l| l.spp).collect(),
                plan_ms,
                record_ms,
                profile_traversal: self.profile_traversal,
                traced_with: self.traversal,
                busy_at_submit,
                submitted_at,
            },
        });
        Ok(())
    }

    /// Every eye's push constants for a frame in `slot` (camera, image, the slot's layers and
    /// history planes).
    fn eye_pushes(&self, request: &FrameRequest, slot: usize, traced: bool) -> Vec<EyePush> {
        let targets = self.targets.current().expect("prepared");
        let history = self.history.as_ref().filter(|_| traced);
        (0..request.eyes.len())
            .map(|e| {
                let mut push = eye_push(
                    request,
                    e,
                    &targets.buffer,
                    targets.strides,
                    history.is_some(),
                );
                push.eye.layer_base = targets.layer_base(slot);
                push.eye.history = history.map_or(0, |h| h.push_word(slot));
                push.albedo = history.map_or(push.albedo, |h| h.albedo_word(push.albedo));
                push
            })
            .collect()
    }

    /// The frame's commands, in order, in slot `slot`'s command buffer (not submitted).
    fn record(
        &mut self,
        request: &FrameRequest,
        slot: usize,
        pushes: &[EyePush],
        traced: bool,
        after: Option<&mut AfterFrame<'_>>,
    ) -> Result<Commands<Arc<GpuContext>>, RenderError> {
        let targets = self.targets.current().expect("prepared");
        let history = self.history.as_ref().filter(|_| traced);
        let iterations = request.foveation.denoise_iterations();
        let trace = self.trace_key(request);
        let passes = FramePasses {
            pipelines: self.pipelines.frame(
                trace,
                history.is_some(),
                request.foveation.fractional(),
                request.foveation.filters(),
                iterations,
            ),
            scene: &self.scene,
            traversal: self.traversal,
            counters: &self.counters,
            targets,
            visibility: &self.visibility.buffer,
            history,
            eyes: pushes,
            slot,
        };
        let frame_slot = &mut self.ring.slots[slot];
        let display = self.display.as_ref().filter(|_| targets.output.is_some());
        frame_slot
            .timestamps
            .ensure_passes(passes.timed_passes(traced) + display.is_some() as u32)?;
        let (ctx, layout) = (&self.ctx, &self.pipelines.layout);
        let mut recorded = Ok(());
        let commands = ctx.record_owned("frame", |cmd| {
            let (descriptors, timestamps) =
                (&mut frame_slot.descriptors, &mut frame_slot.timestamps);
            recorded =
                FrameGraph::begin(ctx, cmd, layout, descriptors, timestamps).and_then(|mut g| {
                    record_passes(&passes, &mut g, traced);
                    let mut shown = targets.output.as_ref();
                    if let (Some(stage), Some(output)) = (display, shown) {
                        stage.record(&mut g, output);
                        shown = stage.image();
                    }
                    // The caller's commands (a copy into a swapchain image), which order
                    // their own reads of the image shown.
                    if let (Some(after), Some(image)) = (after, shown) {
                        after(cmd, image);
                    }
                    passes.collect_counters(&mut g);
                    g.finish()
                });
        })?;
        recorded?;
        Ok(commands)
    }

    /// Each eye's layers for `gazes` (one per eye of `request`), and the CPU ms it took.
    pub(super) fn plan_eyes(
        &self,
        request: &FrameRequest,
        gazes: &[Gaze],
    ) -> (Vec<EyeLayers>, f64) {
        let planning = Instant::now();
        let targets = self.targets.current().expect("prepared");
        let history_frame = self.history.as_ref().map_or(0, |h| h.frame());
        let eyes = (0..request.eyes.len())
            .map(|e| {
                let gaze = gazes.get(e).copied().unwrap_or(request.eyes[e].gaze);
                let input = EyePlanInput {
                    buffer: &targets.buffer,
                    lattice_stride: targets.strides.lattice,
                    image: &targets.images[e],
                    history_frame,
                    layer_lanes: &targets.layer_lanes,
                };
                eye_layers(request, e, gaze, &input)
            })
            .collect();
        (eyes, planning.elapsed().as_secs_f64() * 1e3)
    }
}

/// The frame's passes before the caller's commands, in order.
fn record_passes(passes: &FramePasses, g: &mut FrameGraph, traced: bool) {
    passes.reset_counters(g);
    if traced {
        passes.plan(g);
        passes.dispatch_sizes(g);
        passes.trace(g);
        passes.fill_lattice(g);
        passes.filter_lattice(g);
    }
    passes.resolve(g);
    passes.temporal(g);
    passes.denoise(g);
    passes.output_image(g);
}
