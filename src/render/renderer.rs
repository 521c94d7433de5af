//! The per-frame driver: scene buffers uploaded once, pipelines specialised per scene and
//! integrator, one timed trace pass per frame, stats read back with the image.

use super::frame::{Frame, FrameStats};
use super::settings::RenderSettings;
use super::RenderError;
use crate::gpu::shared::*;
use crate::gpu::{
    shaders, vk, Buffer, ComputePipeline, GpuContext, PipelineLayout, StorageImage, TimestampPool,
};
use crate::scene::gpu_layout::GpuScene;
use crate::scene::{Camera, Scene, SceneFeatures};
use gpu_allocator::MemoryLocation;
use std::collections::HashMap;
use std::sync::Arc;

/// Static scene data on the GPU, one buffer per binding.
struct SceneBuffers {
    blas_nodes: Buffer,
    tlas_nodes: Buffer,
    triangles: Buffer,
    objects: Buffer,
    materials: Buffer,
    emitters: Buffer,
    info: Buffer,
}

pub struct Renderer {
    // Field order is drop order: every resource before the context it borrows.
    pipelines: HashMap<(u32, u32), ComputePipeline>,
    raycast: Option<ComputePipeline>,
    timestamps: TimestampPool,
    image: Option<StorageImage>,
    probe: Option<(Buffer, Buffer)>,
    stats: Buffer,
    buffers: SceneBuffers,
    layout: PipelineLayout,
    features: SceneFeatures,
    ctx: Arc<GpuContext>,
}

impl Renderer {
    /// Builds the BVHs and uploads the scene once.
    pub fn new(ctx: &Arc<GpuContext>, scene: &Scene) -> Result<Self, RenderError> {
        let gpu = GpuScene::build(scene)?;
        let limit = ctx.info.max_storage_buffer_range;
        let largest = [
            std::mem::size_of_val(gpu.blas_nodes.as_slice()),
            std::mem::size_of_val(gpu.triangles.as_slice()),
            std::mem::size_of_val(gpu.emitters.as_slice()),
        ]
        .into_iter()
        .max()
        .unwrap_or(0) as u64;
        if largest > limit {
            return Err(RenderError::Settings(format!(
                "scene '{}' needs a {largest}-byte buffer but the device allows {limit} bytes per buffer (total scene {} bytes); simplify the scene",
                scene.name,
                gpu.byte_size()
            )));
        }
        let upload = |name: &str, bytes: &[u8]| Buffer::with_data(ctx, name, bytes);
        let buffers = SceneBuffers {
            blas_nodes: upload("blas nodes", bytemuck::cast_slice(&gpu.blas_nodes))?,
            tlas_nodes: upload("tlas nodes", bytemuck::cast_slice(&gpu.tlas_nodes))?,
            triangles: upload("triangles", bytemuck::cast_slice(&gpu.triangles))?,
            objects: upload("objects", bytemuck::cast_slice(&gpu.objects))?,
            materials: upload("materials", bytemuck::cast_slice(&gpu.materials))?,
            emitters: upload("emitters", bytemuck::cast_slice(&gpu.emitters))?,
            info: upload("scene info", bytemuck::bytes_of(&gpu.info))?,
        };
        let stats = Buffer::new(
            ctx,
            "stats",
            STAT_COUNT as u64 * 4,
            vk::BufferUsageFlags::STORAGE_BUFFER,
            MemoryLocation::GpuToCpu,
        )?;
        Ok(Self {
            pipelines: HashMap::new(),
            raycast: None,
            timestamps: TimestampPool::new(ctx, 8)?,
            image: None,
            probe: None,
            stats,
            buffers,
            layout: PipelineLayout::new(ctx)?,
            features: gpu.features,
            ctx: ctx.clone(),
        })
    }

    pub fn features(&self) -> SceneFeatures {
        self.features
    }

    pub fn context(&self) -> &Arc<GpuContext> {
        &self.ctx
    }

    fn specialization(&self, integrator: u32, max_bounces: u32) -> Vec<(u32, u32)> {
        let f = self.features;
        vec![
            (SPEC_HAS_TRIANGLES, f.triangles as u32),
            (SPEC_HAS_BOXES, f.boxes as u32),
            (SPEC_HAS_SPHERES, f.spheres as u32),
            (SPEC_HAS_SPECULAR, f.specular as u32),
            (SPEC_HAS_EMITTERS, f.emitters as u32),
            (SPEC_MAX_BOUNCES, max_bounces),
            (SPEC_INTEGRATOR, integrator),
        ]
    }

    fn bind(&self, image: &StorageImage) {
        let b = &self.buffers;
        let mut list: Vec<(u32, &Buffer)> = vec![
            (BINDING_BLAS_NODES, &b.blas_nodes),
            (BINDING_TLAS_NODES, &b.tlas_nodes),
            (BINDING_TRIANGLES, &b.triangles),
            (BINDING_OBJECTS, &b.objects),
            (BINDING_MATERIALS, &b.materials),
            (BINDING_EMITTERS, &b.emitters),
            (BINDING_SCENE_INFO, &b.info),
            (BINDING_STATS, &self.stats),
        ];
        // The probe bindings must be valid even for trace.comp; reuse the stats buffer until
        // raycast() creates real ones.
        match &self.probe {
            Some((rays, hits)) => {
                list.extend([(BINDING_PROBE_RAYS, rays), (BINDING_PROBE_HITS, hits)])
            }
            None => list.extend([
                (BINDING_PROBE_RAYS, &self.stats),
                (BINDING_PROBE_HITS, &self.stats),
            ]),
        }
        self.layout.bind(&list, image);
    }

    fn ensure_image(&mut self, width: u32, height: u32) -> Result<(), RenderError> {
        if self
            .image
            .as_ref()
            .is_none_or(|i| i.width != width || i.height != height)
        {
            self.image = None;
            self.image = Some(StorageImage::new(&self.ctx, "frame", width, height)?);
        }
        Ok(())
    }

    fn reset_stats(&mut self) -> Result<(), RenderError> {
        self.stats.write(0, &[0u8; STAT_COUNT as usize * 4])?;
        Ok(())
    }

    fn read_stats(&self) -> Result<[u32; STAT_COUNT as usize], RenderError> {
        let bytes = self.stats.read()?;
        let mut out = [0u32; STAT_COUNT as usize];
        out.copy_from_slice(bytemuck::cast_slice(&bytes[..STAT_COUNT as usize * 4]));
        Ok(out)
    }

    /// Renders one frame of `camera` and reads it back.
    pub fn render(
        &mut self,
        camera: &Camera,
        settings: &RenderSettings,
    ) -> Result<Frame, RenderError> {
        settings.validate().map_err(RenderError::Settings)?;
        let key = (settings.integrator.id(), settings.max_bounces);
        if !self.pipelines.contains_key(&key) {
            let spec = self.specialization(key.0, key.1);
            let p = ComputePipeline::new(&self.ctx, &self.layout, "trace", shaders::TRACE, &spec)?;
            self.pipelines.insert(key, p);
        }
        self.ensure_image(settings.width, settings.height)?;
        self.reset_stats()?;
        let image = self.image.as_ref().expect("ensured above");
        self.bind(image);
        let push = push_constants(camera, settings);
        let groups = [
            settings.width.div_ceil(WORKGROUP_SIZE_X),
            settings.height.div_ceil(WORKGROUP_SIZE_Y),
            1,
        ];
        let pipeline = &self.pipelines[&key];
        let timestamps = &mut self.timestamps;
        let layout = &self.layout;
        self.ctx.submit_and_wait("trace", |cmd| {
            timestamps.cmd_reset(cmd);
            image.cmd_prepare_for_write(cmd);
            timestamps.cmd_timed(cmd, "trace", || {
                pipeline.cmd_dispatch(cmd, layout, &push, groups)
            });
        })?;
        let pass_ms = self.timestamps.read_ms()?;
        let counters = self.read_stats()?;
        let rgba = image.read_back()?;
        let rgb = rgba
            .chunks_exact(4)
            .flat_map(|p| [p[0], p[1], p[2]])
            .collect();
        Ok(Frame {
            width: settings.width,
            height: settings.height,
            rgb,
            stats: FrameStats {
                nonfinite_samples: counters[STAT_NONFINITE as usize] as u64,
                stack_overflows: counters[STAT_STACK_OVERFLOW as usize] as u64,
                paths: counters[STAT_PATHS as usize] as u64,
                rays: counters[STAT_RAYS as usize] as u64,
                pass_ms,
            },
        })
    }

    /// Closest hits of arbitrary rays through the GPU traversal (for tests and tools).
    /// Returns the hits and the number of stack overflows.
    pub fn raycast(
        &mut self,
        rays: &[GpuProbeRay],
    ) -> Result<(Vec<GpuProbeHit>, u64), RenderError> {
        if self.raycast.is_none() {
            let spec = self.specialization(INTEGRATOR_PT, 0);
            self.raycast = Some(ComputePipeline::new(
                &self.ctx,
                &self.layout,
                "raycast",
                shaders::RAYCAST,
                &spec,
            )?);
        }
        let hit_bytes = std::mem::size_of_val(rays) as u64 / 2;
        self.probe = None;
        let ray_buffer = Buffer::with_data(&self.ctx, "probe rays", bytemuck::cast_slice(rays))?;
        let hit_buffer = Buffer::new(
            &self.ctx,
            "probe hits",
            hit_bytes,
            vk::BufferUsageFlags::STORAGE_BUFFER,
            MemoryLocation::GpuToCpu,
        )?;
        self.probe = Some((ray_buffer, hit_buffer));
        self.ensure_image(1, 1)?;
        self.reset_stats()?;
        let image = self.image.as_ref().expect("ensured above");
        self.bind(image);
        let push = PushConstants {
            probe_count: rays.len() as u32,
            ..Default::default()
        };
        let groups = [(rays.len() as u32).div_ceil(PROBE_WORKGROUP_SIZE), 1, 1];
        let pipeline = self.raycast.as_ref().expect("created above");
        let layout = &self.layout;
        self.ctx.submit_and_wait("raycast", |cmd| {
            image.cmd_prepare_for_write(cmd);
            pipeline.cmd_dispatch(cmd, layout, &push, groups)
        })?;
        let overflows = self.read_stats()?[STAT_STACK_OVERFLOW as usize] as u64;
        let (_, hits) = self.probe.as_ref().expect("set above");
        let hits: Vec<GpuProbeHit> = bytemuck::pod_collect_to_vec(&hits.read()?[..rays.len() * 16]);
        Ok((hits, overflows))
    }
}

fn push_constants(camera: &Camera, s: &RenderSettings) -> PushConstants {
    let (r, u, f) = camera.basis();
    let v = |v: glam::Vec3| [v.x, v.y, v.z, 0.0];
    PushConstants {
        cam_position: v(camera.position),
        cam_right: v(r),
        cam_up: v(u),
        cam_forward: v(f),
        // Image row 0 is the top edge, so the shader goes from the "up" tangent to "down".
        cam_tan: [
            camera.angle_left.tan(),
            camera.angle_right.tan(),
            camera.angle_up.tan(),
            camera.angle_down.tan(),
        ],
        width: s.width,
        height: s.height,
        spp: s.spp,
        seed: s.seed,
        sample_offset: 0,
        probe_count: 0,
        pad0: 0,
        pad1: 0,
    }
}
