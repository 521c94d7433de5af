//! The ray-cast probe: closest hits of arbitrary rays through the renderer's GPU traversal
//! (software or ray queries), for tests and tools (gaze ray casts, traversal checks).

use super::graph::FrameGraph;
use super::renderer::Renderer;
use super::RenderError;
use crate::gpu::{vk, Buffer, DescriptorArena, TimestampPool};
use crate::shader_layout::*;
use gpu_allocator::MemoryLocation;

impl Renderer {
    /// Closest hits of `rays` through the traversal the frames use. Returns the hits and the
    /// number of BVH stack overflows.
    pub fn raycast(
        &mut self,
        rays: &[GpuProbeRay],
    ) -> Result<(Vec<GpuProbeHit>, u64), RenderError> {
        // The counters are reused: nothing may be in flight.
        self.ring.wait_all(&self.counters)?;
        let ctx = &self.ctx;
        let ray_buffer = Buffer::with_data(ctx, "probe rays", bytemuck::cast_slice(rays))?;
        let hit_buffer = Buffer::new(
            ctx,
            "probe hits",
            std::mem::size_of_val(rays) as u64 / 2,
            vk::BufferUsageFlags::STORAGE_BUFFER,
            MemoryLocation::GpuToCpu,
        )?;
        let push = RaycastPush {
            probe_count: rays.len() as u32,
        };
        let groups = [(rays.len() as u32).div_ceil(PROBE_WORKGROUP_SIZE), 1, 1];
        let traversal = self.traversal;
        self.pipelines.ensure_raycast(traversal)?;
        let pipeline = self.pipelines.raycast(traversal);
        let (layout, counters, scene) = (&self.pipelines.layout, &self.counters, &self.scene);
        let mut descriptors = DescriptorArena::new(ctx)?;
        let mut timestamps = TimestampPool::new(ctx, 1)?;
        let mut recorded = Ok(());
        ctx.submit_and_wait("raycast", |cmd| {
            recorded = FrameGraph::begin(ctx, cmd, layout, &mut descriptors, &mut timestamps)
                .and_then(|mut g| {
                    counters.reset(&mut g);
                    scene
                        .declare(g.pass(), traversal)
                        .reads(BINDING_PROBE_RAYS, &ray_buffer)
                        .writes(BINDING_PROBE_HITS, &hit_buffer)
                        .reads_writes(BINDING_STATS, &counters.device)
                        .record(|r| r.dispatch("raycast", pipeline, &push, groups));
                    g.host_reads(&hit_buffer);
                    counters.collect(&mut g, 0);
                    g.finish()
                });
        })?;
        recorded?;
        let overflows = self.counters.read(0)?.eyes[0].stack_overflows;
        let hits = bytemuck::pod_collect_to_vec(&hit_buffer.read()?[..rays.len() * 16]);
        Ok((hits, overflows))
    }
}
