//! The per-frame driver. Scene buffers are uploaded once and pipelines specialised per scene
//! and integrator. Every frame, of every layer config (regular rendering is the one-layer
//! config), runs the same passes per eye: trace (the planned rays of every layer), fill
//! (Catmull-Rom for layers with spacing > 1) and merge (blend masks), each timed.

use super::frame::{EyeCounters, Frame, FrameStats};
use super::request::{DebugView, EyeView, FrameRequest};
use super::settings::RenderSettings;
use super::targets::{FrameTargets, TargetKey};
use super::RenderError;
use crate::foveation::gaze::GazeFix;
use crate::foveation::{EyePlan, FoveationConfig, Gaze, RayBuffer, VisibilityMask};
use crate::gpu::shared::*;
use crate::gpu::{
    shaders, vk, Buffer, ComputePipeline, GpuContext, PipelineLayout, PlannedAllocation, Scope,
    StorageImage, TimestampPool,
};
use crate::scene::gpu_layout::GpuScene;
use crate::scene::{Camera, Scene, SceneFeatures};
use gpu_allocator::MemoryLocation;
use std::collections::HashMap;
use std::sync::Arc;
use std::time::Instant;

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

/// One eye's planned frame, ready to record.
struct EyeFrame {
    push: PushConstants,
    /// Threads of the trace dispatch (target pixels).
    threads: u64,
    /// `(layer index in LAYERS, fill size)` of every layer with pixels to fill.
    fills: Vec<(u32, [u32; 2])>,
}

pub struct Renderer {
    // Field order is drop order: every resource before the context it borrows.
    trace: HashMap<(u32, u32), ComputePipeline>,
    interpolate: Option<ComputePipeline>,
    merge: Option<ComputePipeline>,
    raycast: Option<ComputePipeline>,
    timestamps: TimestampPool,
    targets: Option<FrameTargets>,
    /// The targets used before the current ones, kept so that alternating between two
    /// configs (regular and foveated frames of a bench) does not rebuild the ray buffer and
    /// reallocate the images every frame.
    spare_targets: Option<FrameTargets>,
    probe: Option<(Buffer, Buffer)>,
    /// Per eye, the lens's visibility mask (OpenXR): hidden pixels are never traced, and
    /// merge makes them black.
    masks: Vec<VisibilityMask>,
    /// The masks as bits for merge (BINDING_VISIBILITY), and the eye size they were made
    /// for (`None`: no mask).
    visibility: Buffer,
    visibility_size: Option<[u32; 2]>,
    visibility_stale: bool,
    stats: Buffer,
    buffers: SceneBuffers,
    layout: PipelineLayout,
    features: SceneFeatures,
    ctx: Arc<GpuContext>,
}

/// Timed passes per frame: trace, fill and merge for each of two eyes, with room to spare.
const TIMED_PASSES: u32 = 16;

impl Renderer {
    /// Builds the BVHs and uploads the scene once.
    pub fn new(ctx: &Arc<GpuContext>, scene: &Scene) -> Result<Self, RenderError> {
        let gpu = GpuScene::build(scene)?;
        ctx.check_memory(
            &format!("scene '{}'", scene.name),
            &scene_plan(&gpu),
            "simplify the scene (fewer or smaller meshes)",
        )?;
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
            (STAT_COUNT * STAT_EYES) as u64 * 4,
            vk::BufferUsageFlags::STORAGE_BUFFER,
            MemoryLocation::GpuToCpu,
        )?;
        Ok(Self {
            trace: HashMap::new(),
            interpolate: None,
            merge: None,
            raycast: None,
            timestamps: TimestampPool::new(ctx, TIMED_PASSES)?,
            targets: None,
            spare_targets: None,
            probe: None,
            masks: Vec::new(),
            visibility: Buffer::with_data(ctx, "visibility mask", &0u32.to_le_bytes())?,
            visibility_size: None,
            visibility_stale: false,
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

    /// Sets each eye's visibility mask (eye order as in the frame's eyes; empty for none). A
    /// mask applies to frames whose eye image has the mask's size.
    pub fn set_visibility_masks(&mut self, masks: Vec<VisibilityMask>) {
        self.masks = masks;
        self.visibility_stale = true;
    }

    /// Uploads the masks' bits for merge when they or the eye size changed: every eye's mask
    /// when all eyes have one of the frame's size, else the one-word "no mask".
    fn ensure_visibility(&mut self, eyes: usize, size: [u32; 2]) -> Result<(), RenderError> {
        let applies = self.masks.len() >= eyes
            && self.masks[..eyes]
                .iter()
                .all(|m| [m.width, m.height] == size);
        let wanted = applies.then_some(size);
        if wanted == self.visibility_size && !self.visibility_stale {
            return Ok(());
        }
        // shared.h's layout: words per eye (0: no mask), then each eye's bits.
        let words: Vec<u32> = match applies {
            true => {
                let per_eye = (size[0] as usize * size[1] as usize).div_ceil(32) as u32;
                std::iter::once(per_eye)
                    .chain(self.masks[..eyes].iter().flat_map(|m| m.bits()))
                    .collect()
            }
            false => vec![0],
        };
        self.visibility =
            Buffer::with_data(&self.ctx, "visibility mask", bytemuck::cast_slice(&words))?;
        self.visibility_size = wanted;
        self.visibility_stale = false;
        Ok(())
    }

    /// The last frame's output on the GPU (eyes side by side, RGBA32F linear radiance, GENERAL
    /// layout), for passes that follow the frame (accumulation) and for presenting it.
    pub fn output_image(&self) -> Option<&StorageImage> {
        self.targets.as_ref().map(|t| &t.output)
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

    fn ensure_pipelines(&mut self, settings: &RenderSettings) -> Result<(), RenderError> {
        let key = (settings.integrator.id(), settings.max_bounces);
        if !self.trace.contains_key(&key) {
            let spec = self.specialization(key.0, key.1);
            let p = ComputePipeline::new(&self.ctx, &self.layout, "trace", shaders::TRACE, &spec)?;
            self.trace.insert(key, p);
        }
        if self.interpolate.is_none() {
            self.interpolate = Some(ComputePipeline::new(
                &self.ctx,
                &self.layout,
                "interpolate",
                shaders::INTERPOLATE,
                &[],
            )?);
        }
        if self.merge.is_none() {
            self.merge = Some(ComputePipeline::new(
                &self.ctx,
                &self.layout,
                "merge",
                shaders::MERGE,
                &[],
            )?);
        }
        Ok(())
    }

    /// Points every binding at this renderer's buffers and the current targets.
    fn bind(&self) {
        let b = &self.buffers;
        let t = self
            .targets
            .as_ref()
            .expect("targets are ensured before binding");
        let mut list: Vec<(u32, &Buffer)> = vec![
            (BINDING_BLAS_NODES, &b.blas_nodes),
            (BINDING_TLAS_NODES, &b.tlas_nodes),
            (BINDING_TRIANGLES, &b.triangles),
            (BINDING_OBJECTS, &b.objects),
            (BINDING_MATERIALS, &b.materials),
            (BINDING_EMITTERS, &b.emitters),
            (BINDING_SCENE_INFO, &b.info),
            (BINDING_STATS, &self.stats),
            (BINDING_RAY_BUFFER, &t.ray_buffer),
            (BINDING_SPANS, &t.spans),
            (BINDING_LAYERS, &t.layers),
            (BINDING_VISIBILITY, &self.visibility),
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
        self.layout.bind(
            &list,
            &[
                (BINDING_OUTPUT, &t.output),
                (BINDING_LAYER_IMAGES, &t.layer_images),
            ],
        );
    }

    fn ensure_targets(&mut self, key: TargetKey) -> Result<(), RenderError> {
        if self.targets.as_ref().is_some_and(|t| t.key == key) {
            return Ok(());
        }
        if self.spare_targets.as_ref().is_some_and(|t| t.key == key) {
            std::mem::swap(&mut self.targets, &mut self.spare_targets);
            return Ok(());
        }
        // Make room before anything is built: drop the spare targets, then the current ones,
        // if the new ones would not fit beside them; if they still do not, say why (sizes).
        if key.check_images(&self.ctx).is_err() {
            self.spare_targets = None;
        }
        if key.check_images(&self.ctx).is_err() {
            self.targets = None;
        }
        key.check_images(&self.ctx)?;
        let eyes = key.fovs.len() as u64;
        if key.width as u64 * eyes > super::settings::MAX_SIDE as u64 {
            return Err(RenderError::Settings(format!(
                "{eyes} eyes of width {} do not fit one {}-pixel-wide image; use a smaller --width",
                key.width,
                super::settings::MAX_SIDE
            )));
        }
        self.spare_targets = self.targets.take();
        self.targets = Some(FrameTargets::new(&self.ctx, key)?);
        Ok(())
    }

    fn reset_stats(&mut self) -> Result<(), RenderError> {
        self.stats
            .write(0, &[0u8; (STAT_COUNT * STAT_EYES) as usize * 4])?;
        Ok(())
    }

    /// The counters of every eye (shared.h's STAT_EYES blocks of STAT_COUNT).
    fn read_stats(&self) -> Result<Vec<EyeCounters>, RenderError> {
        let bytes = self.stats.read()?;
        let words: &[u32] = bytemuck::cast_slice(&bytes[..(STAT_COUNT * STAT_EYES) as usize * 4]);
        Ok(words
            .chunks_exact(STAT_COUNT as usize)
            .map(|c| EyeCounters {
                nonfinite_samples: c[STAT_NONFINITE as usize] as u64,
                stack_overflows: c[STAT_STACK_OVERFLOW as usize] as u64,
                paths: c[STAT_PATHS as usize] as u64,
                rays: c[STAT_RAYS as usize] as u64,
            })
            .collect())
    }

    /// Renders one regular (non-foveated) mono frame of `camera`: the one-layer config with
    /// `settings.spp` samples per pixel, through the same passes as a foveated frame.
    pub fn render(
        &mut self,
        camera: &Camera,
        settings: &RenderSettings,
    ) -> Result<Frame, RenderError> {
        let config = FoveationConfig::regular(settings.spp);
        let eyes = [EyeView {
            camera: *camera,
            gaze: Gaze::Forward,
        }];
        self.render_frame(&FrameRequest {
            settings: *settings,
            foveation: &config,
            eyes: &eyes,
            debug: DebugView::None,
        })
    }

    /// Renders one frame, foveated by `request.foveation`, for one or two eyes (side by side).
    pub fn render_frame(&mut self, request: &FrameRequest) -> Result<Frame, RenderError> {
        self.run_frame(request, None, true).map(|(frame, _)| frame)
    }

    /// Renders one frame like [`Self::render_frame`] but leaves the image on the GPU: the
    /// returned frame has no pixels (`rgb` is empty), only its gazes and stats. Frame-time
    /// measurements use this so that the read-back, which a headset frame never does, is not
    /// counted.
    pub fn measure_frame(&mut self, request: &FrameRequest) -> Result<Frame, RenderError> {
        self.run_frame(request, None, false).map(|(frame, _)| frame)
    }

    /// Runs only the fill and merge passes of `request` on layer images given by the caller
    /// (`eyes × layers` RGBA images of the eye's size, eye-major) instead of traced ones, and
    /// returns the frame and the filled layer images. For testing the passes against CPU
    /// references on data with known answers.
    pub fn compose(
        &mut self,
        request: &FrameRequest,
        layer_rgba: &[f32],
    ) -> Result<(Frame, Vec<f32>), RenderError> {
        let (frame, layers) = self.run_frame(request, Some(layer_rgba), true)?;
        Ok((frame, layers.unwrap_or_default()))
    }

    fn run_frame(
        &mut self,
        request: &FrameRequest,
        given_layers: Option<&[f32]>,
        read_output: bool,
    ) -> Result<(Frame, Option<Vec<f32>>), RenderError> {
        let s = &request.settings;
        s.validate().map_err(RenderError::Settings)?;
        request
            .foveation
            .validate()
            .map_err(|e| RenderError::Settings(e.to_string()))?;
        if request.eyes.is_empty() || request.eyes.len() > 2 {
            return Err(RenderError::Settings(format!(
                "a frame has one or two eyes, not {}",
                request.eyes.len()
            )));
        }
        self.ensure_pipelines(s)?;
        self.ensure_targets(TargetKey {
            config: request.foveation.clone(),
            width: s.width,
            height: s.height,
            fovs: request.eyes.iter().map(|e| e.fov()).collect(),
        })?;

        // Plan every eye on the CPU: gaze → spans of the ray buffer, layer parameters.
        let planning = Instant::now();
        let targets = self.targets.as_ref().expect("ensured above");
        let layer_count = targets.buffer.layers.len() as u32;
        let mut spans = Vec::new();
        let mut layers = Vec::new();
        let mut eyes = Vec::new();
        let mut gazes = Vec::new();
        let mut layer_samples = vec![0u64; layer_count as usize];
        for (e, eye) in request.eyes.iter().enumerate() {
            let image = &targets.images[e];
            let (gaze_px, fix) = eye.gaze.resolve(image);
            match fix {
                GazeFix::None => {}
                GazeFix::NotFinite => tracing::warn!(
                    "eye {e}: gaze {:?} is not finite; foveating around the view axis",
                    eye.gaze
                ),
                GazeFix::Clamped => tracing::info!(
                    "eye {e}: gaze {:?} is off the image; clamped to its border",
                    eye.gaze
                ),
            }
            gazes.push((gaze_px, fix));
            let mask = self
                .masks
                .get_mut(e)
                .filter(|m| m.width == image.width && m.height == image.height);
            let mask = mask.map(|m| {
                for l in &targets.buffer.layers {
                    m.prepare(l.spacing);
                }
                &*m
            });
            let plan = EyePlan::masked(&targets.buffer, image, gaze_px, mask);
            for (k, l) in plan.layers.iter().enumerate() {
                layer_samples[k] += l.targets * targets.buffer.layers[k].spp as u64;
            }
            let span_first = spans.len() as u32;
            let mut prefix = 0u32;
            for span in &plan.spans {
                spans.push(GpuSpan {
                    first: span.first,
                    count: span.count,
                    prefix,
                    layer: e as u32 * layer_count + span.layer,
                });
                prefix += span.count;
            }
            let base = e as u32 * layer_count;
            layers.extend(gpu_layers(
                &targets.buffer,
                &plan,
                image,
                request.foveation,
                base,
            ));
            let fills = plan
                .layers
                .iter()
                .enumerate()
                .filter(|(_, l)| !l.fill_is_empty())
                .map(|(k, l)| {
                    (
                        base + k as u32,
                        [
                            (l.fill_max[0] - l.fill_min[0]) as u32,
                            (l.fill_max[1] - l.fill_min[1]) as u32,
                        ],
                    )
                })
                .collect();
            let mut push = push_constants(&eye.camera, s);
            push.eye = e as u32;
            push.span_first = span_first;
            push.span_count = plan.spans.len() as u32;
            push.layer_count = layer_count;
            push.debug = request.debug.id();
            eyes.push(EyeFrame {
                push,
                threads: prefix as u64,
                fills,
            });
        }
        let plan_ms = planning.elapsed().as_secs_f64() * 1e3;
        let targets = self.targets.as_mut().expect("ensured above");
        targets.write_frame(&self.ctx, &spans, &layers)?;
        if let Some(rgba) = given_layers {
            targets.layer_images.upload(rgba)?;
        }
        self.ensure_visibility(request.eyes.len(), [s.width, s.height])?;
        self.reset_stats()?;
        self.bind();

        let targets = self.targets.as_ref().expect("ensured above");
        let trace = &self.trace[&(s.integrator.id(), s.max_bounces)];
        let interpolate = self.interpolate.as_ref().expect("ensured above");
        let merge = self.merge.as_ref().expect("ensured above");
        let timestamps = &mut self.timestamps;
        let layout = &self.layout;
        let ctx = &self.ctx;
        let stereo = eyes.len() == 2;
        let name = |e: usize, pass: &str| match (stereo, e) {
            (false, _) => pass.to_string(),
            (true, 0) => format!("left {pass}"),
            (true, _) => format!("right {pass}"),
        };
        ctx.submit_and_wait("frame", |cmd| {
            timestamps.cmd_reset(cmd);
            if given_layers.is_none() {
                targets.layer_images.cmd_prepare_for_write(cmd);
            }
            targets.output.cmd_prepare_for_write(cmd);
            for (e, eye) in eyes.iter().enumerate() {
                if e > 0 {
                    // The eyes share the layer images and the output (each eye its own layers
                    // and half): the previous eye's merge has read the layers this eye's trace
                    // overwrites, and written the output this eye's merge writes.
                    ctx.cmd_barrier(cmd, Scope::COMPUTE_WRITE, Scope::COMPUTE_WRITE);
                }
                if given_layers.is_none() && eye.threads > 0 {
                    timestamps.cmd_timed(cmd, &name(e, "trace"), || {
                        trace.cmd_dispatch(cmd, layout, &eye.push, groups_1d(eye.threads))
                    });
                    // Fill reads the traced lattice points and writes the pixels between them.
                    ctx.cmd_barrier(cmd, Scope::COMPUTE_WRITE, Scope::COMPUTE_READ_WRITE);
                }
                if !eye.fills.is_empty() {
                    timestamps.cmd_timed(cmd, &name(e, "fill"), || {
                        for (layer, size) in &eye.fills {
                            let push = PushConstants {
                                layer: *layer,
                                ..eye.push
                            };
                            let groups = [
                                size[0].div_ceil(WORKGROUP_SIZE_X),
                                size[1].div_ceil(WORKGROUP_SIZE_Y),
                                1,
                            ];
                            interpolate.cmd_dispatch(cmd, layout, &push, groups);
                        }
                    });
                    // Merge reads the filled layers.
                    ctx.cmd_barrier(cmd, Scope::COMPUTE_WRITE, Scope::COMPUTE_READ);
                }
                timestamps.cmd_timed(cmd, &name(e, "merge"), || {
                    let groups = [
                        s.width.div_ceil(WORKGROUP_SIZE_X * PIXELS_PER_INVOCATION),
                        s.height.div_ceil(WORKGROUP_SIZE_Y),
                        1,
                    ];
                    merge.cmd_dispatch(cmd, layout, &eye.push, groups)
                });
            }
            // The trace's counters, read by the host after the fence.
            ctx.cmd_barrier(cmd, Scope::COMPUTE_WRITE, Scope::HOST_READ);
        })?;
        let passes = self.timestamps.read()?;
        let mut counters = self.read_stats()?;
        counters.truncate(request.eyes.len());
        let rgba = match read_output {
            true => targets.output.read_back()?,
            false => Vec::new(),
        };
        let layer_images = match given_layers {
            Some(_) => Some(targets.layer_images.read_back()?),
            None => None,
        };
        let rgb = rgba
            .chunks_exact(4)
            .flat_map(|p| [p[0], p[1], p[2]])
            .collect();
        let frame = Frame {
            width: s.width * request.eyes.len() as u32,
            height: s.height,
            rgb,
            gazes,
            stats: FrameStats {
                nonfinite_samples: counters.iter().map(|c| c.nonfinite_samples).sum(),
                stack_overflows: counters.iter().map(|c| c.stack_overflows).sum(),
                paths: counters.iter().map(|c| c.paths).sum(),
                rays: counters.iter().map(|c| c.rays).sum(),
                eyes: counters,
                pass_ms: passes.iter().map(|p| (p.name.clone(), p.ms)).collect(),
                pass_start_ms: passes.iter().map(|p| p.start_ms).collect(),
                layer_samples,
                plan_ms,
            },
        };
        Ok((frame, layer_images))
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
        // Every binding must be valid: any targets will do, the smallest if there are none.
        if self.targets.is_none() {
            self.ensure_targets(TargetKey {
                config: FoveationConfig::regular(1),
                width: 1,
                height: 1,
                fovs: vec![crate::foveation::EyeFov {
                    left: -0.5,
                    right: 0.5,
                    up: 0.5,
                    down: -0.5,
                }],
            })?;
        }
        self.reset_stats()?;
        self.bind();
        let push = PushConstants {
            probe_count: rays.len() as u32,
            ..Default::default()
        };
        let groups = [(rays.len() as u32).div_ceil(PROBE_WORKGROUP_SIZE), 1, 1];
        let pipeline = self.raycast.as_ref().expect("created above");
        let layout = &self.layout;
        let ctx = &self.ctx;
        ctx.submit_and_wait("raycast", |cmd| {
            pipeline.cmd_dispatch(cmd, layout, &push, groups);
            // The hits and counters, read by the host after the fence.
            ctx.cmd_barrier(cmd, Scope::COMPUTE_WRITE, Scope::HOST_READ);
        })?;
        let overflows = self.read_stats()?[0].stack_overflows;
        let (_, hits) = self.probe.as_ref().expect("set above");
        let hits: Vec<GpuProbeHit> = bytemuck::pod_collect_to_vec(&hits.read()?[..rays.len() * 16]);
        Ok((hits, overflows))
    }
}

/// Every allocation [`Renderer::new`] makes for a scene, for the memory check before them.
fn scene_plan(gpu: &GpuScene) -> Vec<PlannedAllocation> {
    use std::mem::size_of_val;
    // Buffer::new gives an empty array one 16-byte element.
    let bytes = |b: usize| (b as u64).max(16);
    let buffers = [
        ("blas nodes", bytes(size_of_val(gpu.blas_nodes.as_slice()))),
        ("tlas nodes", bytes(size_of_val(gpu.tlas_nodes.as_slice()))),
        ("triangles", bytes(size_of_val(gpu.triangles.as_slice()))),
        ("objects", bytes(size_of_val(gpu.objects.as_slice()))),
        ("materials", bytes(size_of_val(gpu.materials.as_slice()))),
        ("emitters", bytes(size_of_val(gpu.emitters.as_slice()))),
        ("scene info", bytes(size_of_val(&gpu.info))),
    ];
    let largest = buffers.iter().map(|b| b.1).max().unwrap_or(0);
    let mut plan: Vec<PlannedAllocation> = buffers
        .iter()
        .map(|(name, b)| PlannedAllocation::storage(name, *b))
        .collect();
    // Each buffer is uploaded through its own staging buffer, freed before the next.
    plan.push(PlannedAllocation::host("upload staging", largest, false));
    plan.push(PlannedAllocation::host(
        "stats",
        (STAT_COUNT * STAT_EYES) as u64 * 4,
        true,
    ));
    plan
}

/// Workgroups for `threads` threads of a 1D pass: x up to the guaranteed limit, then rows.
fn groups_1d(threads: u64) -> [u32; 3] {
    let groups = threads.div_ceil(TRACE_WORKGROUP_SIZE as u64);
    let x = groups.min(MAX_GROUPS_X as u64);
    [x as u32, groups.div_ceil(x.max(1)) as u32, 1]
}

/// Clamps an angle to the range the shaders use for "no limit".
fn angle(a: f64) -> f32 {
    a.clamp(-NO_LIMIT as f64, NO_LIMIT as f64) as f32
}

/// The cosine of an angle limit as the shaders test it (`dot > cos`): -2 when everything is
/// within (a limit of π or more), 2 when nothing is (a limit of 0 or less).
pub(super) fn cos_limit(a: f64) -> f32 {
    if a >= std::f64::consts::PI {
        -2.0
    } else if a <= 0.0 {
        2.0
    } else {
        a.cos() as f32
    }
}

/// The GPU's view of one eye's layers for this frame.
fn gpu_layers(
    buffer: &RayBuffer,
    plan: &EyePlan,
    image: &crate::foveation::ImageGeometry,
    config: &FoveationConfig,
    base: u32,
) -> Vec<GpuLayer> {
    let slack = image.max_radians_per_pixel();
    let blend = (config.blend_deg as f64).to_radians();
    let gaze = [
        plan.gaze_tan[0] as f32,
        plan.gaze_tan[1] as f32,
        slack as f32,
        blend as f32,
    ];
    buffer
        .layers
        .iter()
        .zip(&plan.layers)
        .enumerate()
        .map(|(k, (l, p))| GpuLayer {
            gaze,
            fill_cos: [
                cos_limit(l.outer + slack),
                cos_limit(l.inner - slack),
                cos_limit(buffer.occlusion + slack),
                0.0,
            ],
            merge_cos: [
                cos_limit(l.outer),
                cos_limit(l.outer - blend),
                cos_limit(buffer.occlusion),
                0.0,
            ],
            anchor_x: p.anchor[0],
            anchor_y: p.anchor[1],
            spacing: l.spacing as i32,
            spp: l.spp,
            lattice_min_x: p.lattice_min[0],
            lattice_min_y: p.lattice_min[1],
            lattice_max_x: p.lattice_max[0],
            lattice_max_y: p.lattice_max[1],
            fill_min_x: p.fill_min[0],
            fill_min_y: p.fill_min[1],
            fill_max_x: p.fill_max[0],
            fill_max_y: p.fill_max[1],
            outer: angle(l.outer),
            image_layer: base + k as u32,
            pad0: 0,
            pad1: 0,
        })
        .collect()
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
        seed: s.seed,
        ..Default::default()
    }
}
