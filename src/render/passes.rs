//! The frame's passes, each a short function over typed handles: plan (which lattice points
//! every layer traces, decided on the GPU, compacted into work lists), trace (the work lists,
//! through indirect dispatches the GPU sized), resolve (every pixel once) and, for whoever
//! presents or accumulates frames, a copy of the pixels into an image. Each pass
//! records every eye's dispatch before the next pass: the eyes have their own lattice values,
//! work lists and halves of the output, so nothing orders one eye after the other and a GPU
//! may run them side by side; the barriers order only the passes.

use super::counters::FrameCounters;
use super::targets::FrameTargets;
use crate::gpu::shared::*;
use crate::gpu::{vk, Buffer, ComputePipeline, GpuContext, PipelineLayout, Scope, TimestampPool};

/// The frame's pipelines (trace specialised for the scene, integrator and depth).
pub struct FramePipelines<'a> {
    pub plan: &'a ComputePipeline,
    pub plan_args: &'a ComputePipeline,
    pub trace: &'a ComputePipeline,
    pub resolve: &'a ComputePipeline,
    /// With history on (render/history.rs).
    pub temporal: Option<&'a ComputePipeline>,
    /// With history on and a layer that asks for denoising: the pipeline, the most
    /// iterations any layer asks for, and the buffer it ping-pongs with the pixels.
    pub denoise: Option<(&'a ComputePipeline, u32, &'a Buffer)>,
}

/// Everything one frame's commands use.
pub struct FramePasses<'a> {
    pub ctx: &'a GpuContext,
    pub layout: &'a PipelineLayout,
    pub pipelines: FramePipelines<'a>,
    pub timestamps: &'a mut TimestampPool,
    pub counters: &'a FrameCounters,
    pub targets: &'a FrameTargets,
    /// Every eye's push constants (camera, image, the slot's layers; the gaze is in the
    /// targets' layer buffer).
    pub eyes: &'a [EyePush],
    /// The frame slot: which of the targets' layer and plan-dispatch sets, and which counter
    /// read-back, are this frame's.
    pub slot: usize,
}

impl FramePasses<'_> {
    /// A pass's name in the timings: "trace", or "left trace" and "right trace" in stereo.
    fn name(&self, e: usize, pass: &str) -> String {
        match (self.eyes.len(), e) {
            (1, _) => pass.to_string(),
            (_, 0) => format!("left {pass}"),
            (_, _) => format!("right {pass}"),
        }
    }

    /// Every timed pass this frame records: plan, dispatch sizes and trace when `traced`
    /// (compose gives the lattice instead), resolve, temporal, each denoise iteration and its
    /// copy back, the output image. The timestamp pool is sized from it.
    pub fn timed_passes(&self, traced: bool) -> u32 {
        let eyes = self.eyes.len() as u32;
        let denoise = self.pipelines.denoise.map_or(0, |(_, n, _)| n);
        let per_eye = 2 * traced as u32 // plan, trace
            + 1 // resolve
            + self.pipelines.temporal.is_some() as u32
            + denoise;
        eyes * per_eye
            + traced as u32 // dispatch sizes
            + denoise % 2 // the denoiser's copy back into the pixels
            + self.targets.output.is_some() as u32
    }

    /// Makes the timestamp pool large enough for this frame's passes (its slot is free).
    pub fn size_timestamps(&mut self, traced: bool) -> Result<(), crate::gpu::GpuError> {
        let passes = self.timed_passes(traced);
        self.timestamps.ensure_passes(passes)
    }

    /// Starts the frame: the frames before it finished with the targets and counters they
    /// share with it (frames in flight), timings reset, counters zeroed.
    pub fn begin(&mut self, cmd: vk::CommandBuffer) {
        self.ctx
            .cmd_barrier(cmd, Scope::EARLIER_WORK, Scope::LATER_WORK);
        self.timestamps.cmd_reset(cmd);
        self.counters.cmd_reset(self.ctx, cmd);
    }

    /// Plan: per eye, one thread per run of lattice points of every layer's box decides which
    /// are traced and appends them to the eye's work list; then one tiny dispatch turns each
    /// list's length into the trace's workgroup counts. The plan's own workgroup counts depend
    /// on the gaze, so they are read from the buffer the CPU writes with it, at submission.
    pub fn plan(&mut self, cmd: vk::CommandBuffer) {
        let (p, layout) = (&self.pipelines, self.layout);
        let args = &self.targets.plan_dispatch;
        for (e, push) in self.eyes.iter().enumerate() {
            let name = self.name(e, "plan");
            let offset = self.targets.plan_dispatch_offset(self.slot, e);
            self.timestamps.cmd_timed(cmd, &name, || {
                p.plan
                    .cmd_dispatch_indirect(cmd, layout, push, args, offset)
            });
        }
        // The counts are complete only when every plan workgroup has added to them.
        self.ctx
            .cmd_barrier(cmd, Scope::COMPUTE_WRITE, Scope::COMPUTE_READ_WRITE);
        let eyes = self.eyes.len() as u32;
        self.timestamps.cmd_timed(cmd, "dispatch sizes", || {
            p.plan_args.cmd_dispatch(cmd, layout, &(), [eyes, 1, 1])
        });
        // The trace reads the work lists and the counts, and its dispatch sizes.
        self.ctx.cmd_barrier(
            cmd,
            Scope::COMPUTE_WRITE,
            Scope::COMPUTE_READ.and(Scope::INDIRECT_READ),
        );
    }

    /// Trace: per eye, one thread per work-list entry writes the point's lattice value.
    pub fn trace(&mut self, cmd: vk::CommandBuffer) {
        let (p, layout) = (&self.pipelines, self.layout);
        for (e, push) in self.eyes.iter().enumerate() {
            let name = self.name(e, "trace");
            let args = &self.counters.device;
            let offset = (STAT_DISPATCH + e as u32 * 4) as u64 * 4;
            self.timestamps.cmd_timed(cmd, &name, || {
                p.trace
                    .cmd_dispatch_indirect(cmd, layout, push, args, offset)
            });
        }
        // Resolve reads the lattice values.
        self.ctx
            .cmd_barrier(cmd, Scope::COMPUTE_WRITE, Scope::COMPUTE_READ);
    }

    /// Resolve: per eye, every output pixel from its one or two layers.
    pub fn resolve(&mut self, cmd: vk::CommandBuffer) {
        let (p, layout) = (&self.pipelines, self.layout);
        let t = self.targets;
        let groups = [
            t.key
                .width
                .div_ceil(WORKGROUP_SIZE_X * PIXELS_PER_INVOCATION),
            t.key.height.div_ceil(WORKGROUP_SIZE_Y),
            1,
        ];
        for (e, push) in self.eyes.iter().enumerate() {
            let name = self.name(e, "resolve");
            self.timestamps.cmd_timed(cmd, &name, || {
                p.resolve.cmd_dispatch(cmd, layout, push, groups)
            });
        }
    }

    /// Temporal (with history on): per eye, every pixel's history carried into this frame,
    /// its own new samples added, and what is shown rewritten from it.
    pub fn temporal(&mut self, cmd: vk::CommandBuffer) {
        let Some(pipeline) = self.pipelines.temporal else {
            return;
        };
        // It reads the resolved pixels and the lattice values and surfaces.
        self.ctx
            .cmd_barrier(cmd, Scope::COMPUTE_WRITE, Scope::COMPUTE_READ_WRITE);
        let t = self.targets;
        let groups = [
            t.key.width.div_ceil(WORKGROUP_SIZE_X),
            t.key.height.div_ceil(WORKGROUP_SIZE_Y),
            1,
        ];
        for (e, push) in self.eyes.iter().enumerate() {
            let name = self.name(e, "temporal");
            self.timestamps.cmd_timed(cmd, &name, || {
                pipeline.cmd_dispatch(cmd, self.layout, push, groups)
            });
        }
    }

    /// Denoise (when a layer asks for it): iterations of the a-trous filter, each over every
    /// pixel of each eye, alternating between the pixels and the denoiser's buffer; an odd
    /// count ends with a copy back into the pixels.
    pub fn denoise(&mut self, cmd: vk::CommandBuffer) {
        let Some((pipeline, iterations, other)) = self.pipelines.denoise else {
            return;
        };
        let t = self.targets;
        let groups = [
            t.key.width.div_ceil(WORKGROUP_SIZE_X),
            t.key.height.div_ceil(WORKGROUP_SIZE_Y),
            1,
        ];
        for i in 0..iterations {
            self.ctx
                .cmd_barrier(cmd, Scope::COMPUTE_WRITE, Scope::COMPUTE_READ_WRITE);
            for (e, push) in self.eyes.iter().enumerate() {
                let push = DenoisePush {
                    cam: push.cam,
                    eye: push.eye,
                    iteration: i,
                    reads_denoise: i % 2,
                    ..Default::default()
                };
                let name = self.name(e, "denoise");
                self.timestamps.cmd_timed(cmd, &name, || {
                    pipeline.cmd_dispatch(cmd, self.layout, &push, groups)
                });
            }
        }
        if iterations % 2 == 1 {
            // The copy reads the last iteration's output and overwrites what the one before
            // wrote into the pixels.
            self.ctx.cmd_barrier(
                cmd,
                Scope::COMPUTE_WRITE,
                Scope::COPY_READ.and(Scope::COPY_WRITE),
            );
            self.timestamps.cmd_timed(cmd, "denoise copy", || {
                other.cmd_copy_to(cmd, &t.pixels, t.pixels.size)
            });
            self.ctx.cmd_barrier(
                cmd,
                Scope::COPY_WRITE,
                Scope::COMPUTE_READ_WRITE.and(Scope::COPY_READ),
            );
        }
    }

    /// Output image (when the targets have one): the eyes' pixels copied side by side into it.
    /// A copy, not resolve's stores: on lavapipe an imageStore per pixel cost more than a
    /// storage-buffer store plus this copy (about 31 ms per 1440x1600 eye against 16 + 7).
    pub fn output_image(&mut self, cmd: vk::CommandBuffer) {
        let t = self.targets;
        let Some(image) = &t.output else { return };
        self.ctx
            .cmd_barrier(cmd, Scope::COMPUTE_WRITE, Scope::COPY_READ);
        let eyes = self.eyes.len() as u32;
        self.timestamps.cmd_timed(cmd, "output image", || {
            image.cmd_copy_tiles_from(cmd, &t.pixels, eyes)
        });
    }

    /// Ends the frame: the counters copied where the host reads them after the fence.
    pub fn finish(&mut self, cmd: vk::CommandBuffer) {
        self.counters.cmd_collect(self.ctx, cmd, self.slot);
    }
}

/// Bytes of one eye's plan dispatch in `FrameTargets::plan_dispatch` (VkDispatchIndirectCommand
/// and a pad).
pub const PLAN_DISPATCH_BYTES: u64 = 16;

/// Workgroups for `threads` threads of a 1D pass: x up to the guaranteed limit, then rows.
pub fn groups_1d(threads: u64, workgroup: u32) -> [u32; 3] {
    let groups = threads.div_ceil(workgroup as u64);
    let x = groups.min(MAX_GROUPS_X as u64);
    [x as u32, groups.div_ceil(x.max(1)) as u32, 1]
}
