//! The BRDF probe: glTF's BRDF as the integrators sample and evaluate it (gltf_brdf.glsl),
//! for the sampling and reciprocity checks of `check::gltf_brdf`.

use super::graph::FrameGraph;
use super::renderer::Renderer;
use super::RenderError;
use crate::gpu::{vk, Buffer, DescriptorArena, TimestampPool};
use crate::shader_layout::*;
use gpu_allocator::MemoryLocation;

/// The most queries one call answers: one invocation each, in one 1D dispatch.
pub const MAX_BRDF_QUERIES: usize = (MAX_GROUPS_X * PROBE_WORKGROUP_SIZE) as usize;

impl Renderer {
    /// Answers `queries` on the GPU; their materials are indices into the scene's.
    pub fn brdf_probe(
        &mut self,
        queries: &[GpuBrdfQuery],
    ) -> Result<Vec<GpuBrdfAnswer>, RenderError> {
        if queries.is_empty() || queries.len() > MAX_BRDF_QUERIES {
            return Err(RenderError::Settings(format!(
                "the BRDF probe takes 1 to {MAX_BRDF_QUERIES} queries per call, not {}",
                queries.len()
            )));
        }
        let ctx = &self.ctx;
        let query_buffer = Buffer::with_data(ctx, "brdf queries", bytemuck::cast_slice(queries))?;
        let answer_bytes = std::mem::size_of::<GpuBrdfAnswer>() * queries.len();
        let answer_buffer = Buffer::new(
            ctx,
            "brdf answers",
            answer_bytes as u64,
            vk::BufferUsageFlags::STORAGE_BUFFER,
            MemoryLocation::GpuToCpu,
        )?;
        let push = BrdfProbePush {
            query_count: queries.len() as u32,
        };
        let groups = [(queries.len() as u32).div_ceil(PROBE_WORKGROUP_SIZE), 1, 1];
        let (layout, pipeline) = self.pipelines.brdf_probe()?;
        let scene = &self.scene;
        let mut descriptors = DescriptorArena::new(ctx)?;
        let mut timestamps = TimestampPool::new(ctx, 1)?;
        let mut recorded = Ok(());
        ctx.submit_and_wait("brdf probe", |cmd| {
            recorded = FrameGraph::begin(ctx, cmd, layout, &mut descriptors, &mut timestamps)
                .and_then(|mut g| {
                    scene
                        .declare_materials(g.pass())
                        .reads(BINDING_BRDF_QUERIES, &query_buffer)
                        .writes(BINDING_BRDF_ANSWERS, &answer_buffer)
                        .record(|r| r.dispatch("brdf probe", pipeline, &push, groups));
                    g.host_reads(&answer_buffer);
                    g.finish()
                });
        })?;
        recorded?;
        Ok(bytemuck::pod_collect_to_vec(
            &answer_buffer.read()?[..answer_bytes],
        ))
    }
}
