//! The frame's passes, each a short function that declares what it reads and writes and
//! records its dispatches (graph.rs derives the bindings and barriers): counters zeroed, plan
//! (which lattice points every layer traces, decided on the GPU, compacted into work lists),
//! dispatch sizes, trace (the work lists, through indirect dispatches the GPU sized), the fill
//! of the points a fractional layer skipped (the fill lists, likewise), the
//! lattice filter (the same work lists, when a layer asks for it), resolve (every pixel
//! once), then with history temporal and denoise, and for whoever presents or accumulates
//! frames a copy of the pixels into an image; last the counters copied where the
//! host reads them. Each pass records every eye's dispatch: the eyes have their own lattice
//! values, work lists and halves of the output, so nothing orders one eye after the other and
//! a GPU may run them side by side.

use super::counters::FrameCounters;
use super::graph::{FrameGraph, Recorder};
use super::history::History;
use super::scene_buffers::SceneBuffers;
use super::settings::Traversal;
use super::targets::FrameTargets;
use crate::gpu::{Buffer, ComputePipeline};
use crate::shader_layout::*;

/// The frame's pipelines (trace specialised for the scene, integrator and depth).
pub struct FramePipelines<'a> {
    pub plan: &'a ComputePipeline,
    pub plan_args: &'a ComputePipeline,
    pub trace: &'a ComputePipeline,
    /// When a layer traces only a fraction of its points (with history on, the variant that
    /// also fills their surfaces).
    pub fill: Option<&'a ComputePipeline>,
    /// With history on and a layer that asks for the lattice filter.
    pub lattice_filter: Option<&'a ComputePipeline>,
    pub resolve: &'a ComputePipeline,
    /// With history on (render/history.rs).
    pub temporal: Option<&'a ComputePipeline>,
    /// With history on and a layer that asks for denoising: the pipeline and the most
    /// iterations any layer asks for.
    pub denoise: Option<(&'a ComputePipeline, u32)>,
}

/// Everything one frame's passes use.
pub struct FramePasses<'a> {
    pub pipelines: FramePipelines<'a>,
    pub scene: &'a SceneBuffers,
    /// How the trace finds the scene (the TLAS or the BVH nodes it binds).
    pub traversal: Traversal,
    pub counters: &'a FrameCounters,
    pub targets: &'a FrameTargets,
    /// The lens's visibility masks (BINDING_VISIBILITY).
    pub visibility: &'a Buffer,
    /// The temporal history, when on (temporal and denoise need it; trace then also writes
    /// the lattice points' surfaces).
    pub history: Option<&'a History>,
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
    /// (a test may give the lattice instead), the lattice filter, resolve, temporal, each
    /// denoise iteration and its copy back, the output image. The timestamp pool is sized
    /// from it.
    pub fn timed_passes(&self, traced: bool) -> u32 {
        let eyes = self.eyes.len() as u32;
        let denoise = self.pipelines.denoise.map_or(0, |(_, n)| n);
        let per_eye = 2 * traced as u32 // plan, trace
            + (traced && self.pipelines.fill.is_some()) as u32
            + self.lattice_filter().is_some() as u32
            + 1 // resolve
            + self.pipelines.temporal.is_some() as u32
            + denoise;
        eyes * per_eye
            + traced as u32 // dispatch sizes
            + denoise % 2 // the denoiser's copy back into the pixels
            + self.targets.output.is_some() as u32
    }

    /// Records `pipeline` once per eye, each dispatch sized by the GPU: by the eye's block of
    /// four counters (x, y, z, list length) at STATS[`block` + eye * 4] (the work list's or
    /// the fill list's, which the dispatch-sizes pass wrote).
    fn each_eye_indirect(
        &self,
        r: &mut Recorder,
        pass: &str,
        pipeline: &ComputePipeline,
        block: u32,
    ) {
        let stats = &self.counters.device;
        for (e, push) in self.eyes.iter().enumerate() {
            let offset = (block + e as u32 * 4) as u64 * 4;
            r.dispatch_indirect(&self.name(e, pass), pipeline, push, stats, offset);
        }
    }

    /// Workgroups of a pass over every pixel of an eye, `per_x` pixels per invocation in x.
    fn pixel_groups(&self, per_x: u32) -> [u32; 3] {
        let key = &self.targets.key;
        [
            key.width.div_ceil(WORKGROUP_SIZE_X * per_x),
            key.height.div_ceil(WORKGROUP_SIZE_Y),
            1,
        ]
    }

    /// Zeroes every counter before the passes that add to them.
    pub fn reset_counters(&self, g: &mut FrameGraph) {
        self.counters.reset(g);
    }

    /// Plan: per eye, one thread per run of lattice points of every layer's box decides which
    /// are traced and appends them to the eye's work list. The plan's own workgroup counts
    /// depend on the gaze, so they are read from the buffer the CPU writes with it, at
    /// submission.
    pub fn plan(&self, g: &mut FrameGraph) {
        let t = self.targets;
        g.pass()
            .reads(BINDING_LAYERS, &t.layers)
            .reads(BINDING_VISIBILITY, self.visibility)
            .writes(BINDING_WORK, &t.work)
            .reads_writes(BINDING_STATS, &self.counters.device)
            .indirect_args(&t.plan_dispatch)
            .record(|r| {
                for (e, push) in self.eyes.iter().enumerate() {
                    let offset = t.plan_dispatch_offset(self.slot, e);
                    let (name, plan) = (self.name(e, "plan"), self.pipelines.plan);
                    r.dispatch_indirect(&name, plan, push, &t.plan_dispatch, offset);
                }
            });
    }

    /// Dispatch sizes: one tiny dispatch turns each eye's work-list length into the trace's
    /// workgroup counts.
    pub fn dispatch_sizes(&self, g: &mut FrameGraph) {
        let eyes = self.eyes.len() as u32;
        g.pass()
            .reads_writes(BINDING_STATS, &self.counters.device)
            .record(|r| {
                r.dispatch(
                    "dispatch sizes",
                    self.pipelines.plan_args,
                    &(),
                    [eyes, 1, 1],
                )
            });
    }

    /// Trace: per eye, one thread per work-list entry writes the point's lattice value (and
    /// with history its surface).
    pub fn trace(&self, g: &mut FrameGraph) {
        let (t, stats) = (self.targets, &self.counters.device);
        let mut pass = self
            .scene
            .declare(g.pass(), self.traversal)
            .reads(BINDING_WORK, &t.work)
            .reads(BINDING_LAYERS, &t.layers)
            .writes(BINDING_LATTICE, &t.lattice)
            .reads_writes(BINDING_STATS, stats)
            .indirect_args(stats);
        if let Some(h) = self.history {
            pass = pass
                .writes(BINDING_LATTICE_SURFACE, &h.lattice_surfaces)
                .writes(BINDING_LATTICE_ALBEDO, &h.lattice_albedos);
        }
        pass.record(|r| self.each_eye_indirect(r, "trace", self.pipelines.trace, STAT_DISPATCH));
    }

    /// Fill (when a layer traces a fraction of its points; after trace): per eye, one thread
    /// per entry of the fill list writes the skipped point's value from its traced
    /// neighbours (and with history its owner's surface and albedo).
    pub fn fill_lattice(&self, g: &mut FrameGraph) {
        let Some(pipeline) = self.pipelines.fill else {
            return;
        };
        let (t, stats) = (self.targets, &self.counters.device);
        let mut pass = g
            .pass()
            .reads(BINDING_WORK, &t.work)
            .reads(BINDING_LAYERS, &t.layers)
            .reads(BINDING_VISIBILITY, self.visibility)
            .reads_writes(BINDING_LATTICE, &t.lattice)
            .reads(BINDING_STATS, stats)
            .indirect_args(stats);
        if let Some(h) = self.history {
            pass = pass
                .reads_writes(BINDING_LATTICE_SURFACE, &h.lattice_surfaces)
                .reads_writes(BINDING_LATTICE_ALBEDO, &h.lattice_albedos);
        }
        pass.record(|r| self.each_eye_indirect(r, "lattice fill", pipeline, STAT_FILL_DISPATCH));
    }

    /// The lattice filter's pipeline and the history that holds its buffer, when the frame
    /// filters (never when a test gives the lattice: such a frame has no history).
    fn lattice_filter(&self) -> Option<(&ComputePipeline, &History)> {
        self.pipelines.lattice_filter.zip(self.history)
    }

    /// Lattice filter (when a layer asks for it; after trace): per eye, one thread per
    /// work-list entry writes the point's filtered value, which resolve reads in place of the
    /// traced one.
    pub fn filter_lattice(&self, g: &mut FrameGraph) {
        let Some((pipeline, h)) = self.lattice_filter() else {
            return;
        };
        let (t, stats) = (self.targets, &self.counters.device);
        g.pass()
            .reads(BINDING_WORK, &t.work)
            .reads(BINDING_LAYERS, &t.layers)
            .reads(BINDING_VISIBILITY, self.visibility)
            .reads(BINDING_LATTICE_TEXELS, &t.lattice_texels)
            .reads(BINDING_LATTICE_SURFACE_TEXELS, &h.lattice_surface_texels)
            .reads(BINDING_STATS, stats)
            .writes(BINDING_LATTICE_FILTERED, &h.filtered)
            .indirect_args(stats)
            .record(|r| self.each_eye_indirect(r, "lattice filter", pipeline, STAT_DISPATCH));
    }

    /// Resolve: per eye, every output pixel from its one or two layers, reading the lattice
    /// filter's values when the frame filters, else the traced ones.
    pub fn resolve(&self, g: &mut FrameGraph) {
        let t = self.targets;
        let groups = self.pixel_groups(PIXELS_PER_INVOCATION);
        let lattice = match self.lattice_filter() {
            Some((_, h)) => &h.filtered_texels,
            None => &t.lattice_texels,
        };
        g.pass()
            .reads(BINDING_LAYERS, &t.layers)
            .reads(BINDING_VISIBILITY, self.visibility)
            .reads(BINDING_LATTICE_TEXELS, lattice)
            .writes(BINDING_PIXELS, &t.pixels)
            .record(|r| {
                for (e, push) in self.eyes.iter().enumerate() {
                    let name = self.name(e, "resolve");
                    r.dispatch(&name, self.pipelines.resolve, push, groups);
                }
            });
    }

    /// Temporal (with history on): per eye, every pixel's history carried into this frame,
    /// its own new samples added, and what is shown rewritten from it.
    pub fn temporal(&self, g: &mut FrameGraph) {
        let (Some(pipeline), Some(h)) = (self.pipelines.temporal, self.history) else {
            return;
        };
        let t = self.targets;
        let groups = self.pixel_groups(1);
        // Every eye's push has the same history word: one plane read, the other written.
        let word = self.eyes[0].eye.history;
        let (read, written) = (History::read_plane(word), History::written_plane(word));
        g.pass()
            .reads(BINDING_LATTICE_TEXELS, &t.lattice_texels)
            .reads(BINDING_LAYERS, &t.layers)
            .reads(BINDING_VISIBILITY, self.visibility)
            .reads(BINDING_LATTICE_SURFACE_TEXELS, &h.lattice_surface_texels)
            .reads(BINDING_LATTICE_FILTERED, &h.filtered)
            .reads(BINDING_LATTICE_ALBEDO, &h.lattice_albedos)
            .reads(BINDING_HISTORY_VIEWS, &h.views)
            .reads(BINDING_HISTORY_TEXELS, &h.pixel_texels[read])
            .reads(BINDING_SURFACE_TEXELS, &h.surface_texels[read])
            .reads_writes(BINDING_PIXELS, &t.pixels)
            .writes(BINDING_HISTORY, &h.pixels[written])
            .writes(BINDING_HISTORY_SURFACE, &h.surfaces[written])
            .reads(BINDING_ALBEDO_BEFORE, &h.albedos[read])
            .writes(BINDING_HISTORY_ALBEDO, &h.albedos[written])
            .record(|r| {
                for (e, push) in self.eyes.iter().enumerate() {
                    r.dispatch(&self.name(e, "temporal"), pipeline, push, groups);
                }
            });
    }

    /// Denoise (when a layer asks for it): iterations of the a-trous filter, each over every
    /// pixel of each eye, alternating between the pixels and the denoiser's buffer; an odd
    /// count ends with a copy back into the pixels.
    pub fn denoise(&self, g: &mut FrameGraph) {
        let (Some((pipeline, iterations)), Some(h)) = (self.pipelines.denoise, self.history) else {
            return;
        };
        let t = self.targets;
        let groups = self.pixel_groups(1);
        // Every eye's push has the same history word: one plane for the frame.
        let written = History::written_plane(self.eyes[0].eye.history);
        let (surfaces, albedos) = (&h.surface_texels[written], &h.albedos[written]);
        for i in 0..iterations {
            let (from, into) = match i % 2 {
                0 => (&t.pixels_texels, &h.denoise),
                _ => (&h.denoise_texels, &t.pixels),
            };
            g.pass()
                .reads(BINDING_LAYERS, &t.layers)
                .reads(BINDING_SURFACE_TEXELS, surfaces)
                .reads(BINDING_ALBEDO_BEFORE, albedos)
                .reads(BINDING_DENOISE_INPUT, from)
                .writes(BINDING_DENOISE, into)
                .record(|r| {
                    for (e, push) in self.eyes.iter().enumerate() {
                        let push = DenoisePush {
                            cam: push.cam,
                            eye: push.eye,
                            iteration: i,
                            pad0: 0,
                            last: (i + 1 == iterations) as u32,
                        };
                        r.dispatch(&self.name(e, "denoise"), pipeline, &push, groups);
                    }
                });
        }
        if iterations % 2 == 1 {
            g.pass()
                .copies_from(&h.denoise)
                .copies_into(&t.pixels)
                .record(|r| {
                    r.timed("denoise copy", |cmd| {
                        h.denoise.cmd_copy_to(cmd, &t.pixels, t.pixels.size)
                    })
                });
        }
    }

    /// Output image (when the targets have one): the eyes' pixels copied side by side into it.
    /// A copy, not resolve's stores: on lavapipe an imageStore per pixel cost more than a
    /// storage-buffer store plus this copy (about 31 ms per 1440x1600 eye against 16 + 7).
    pub fn output_image(&self, g: &mut FrameGraph) {
        let t = self.targets;
        let Some(image) = &t.output else { return };
        let eyes = self.eyes.len() as u32;
        g.pass()
            .copies_from(&t.pixels)
            .copies_into(image)
            .record(|r| {
                r.timed("output image", |cmd| {
                    image.cmd_copy_tiles_from(cmd, &t.pixels, eyes)
                })
            });
    }

    /// The counters copied into the frame slot's read-back, which the host reads after the
    /// fence.
    pub fn collect_counters(&self, g: &mut FrameGraph) {
        self.counters.collect(g, self.slot);
    }
}
