//! The per-frame driver. Scene buffers are uploaded once and pipelines specialised per scene
//! and integrator. Every frame, of every layer config (regular rendering is the one-layer
//! config), records the same passes for both eyes in one submission (`passes`): plan, trace
//! and resolve, each timed; then plans each eye for its gaze on the CPU (O(layers) numbers,
//! `eye_params`), writes them where the commands read them, and submits: the gaze is latched
//! after recording. Frames may be left in flight (`in_flight`): submitted, read back later.

use super::counters::FrameCounters;
use super::eye_params::{eye_layers, eye_push, EyeLayers};
use super::frame::Frame;
use super::graph::FrameGraph;
use super::history::{History, HistoryKey, TemporalSettings};
use super::in_flight::{frame_results, FrameKnown, PendingFrame, MAX_FRAMES_IN_FLIGHT};
use super::passes::{FramePasses, FramePipelines};
use super::request::{DebugView, EyeView, FrameRequest};
use super::scene_buffers::SceneBuffers;
use super::settings::{RenderSettings, Traversal};
use super::targets::{FrameTargets, TargetKey};
use super::RenderError;
use crate::foveation::{FoveationConfig, Gaze, VisibilityMask};
use crate::gpu::shared::*;
use crate::gpu::{
    shaders, vk, Buffer, ComputePipeline, DescriptorArena, GpuContext, PipelineLayout,
    StorageImage, TimestampPool,
};
use crate::scene::{Camera, Scene, SceneFeatures};
use gpu_allocator::MemoryLocation;
use std::collections::{HashMap, VecDeque};
use std::sync::Arc;
use std::time::Instant;

/// A lattice point whose value [`Renderer::compose`] asks for: eye, layer (innermost first)
/// and the point's pixel (which may lie off the image; those are never read).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LatticePoint {
    pub eye: usize,
    pub layer: usize,
    pub x: i32,
    pub y: i32,
}

pub struct Renderer {
    // Field order is drop order: every resource before the context it borrows, and frames
    // in flight (whose drop waits for them) before everything they use.
    /// Submitted frames not read back yet, oldest first.
    in_flight: VecDeque<PendingFrame>,
    /// Frames read back (their fences signalled) that the caller has not taken yet.
    finished: VecDeque<Frame>,
    /// The most frames left in flight (1: every frame waited for before the next).
    frames_in_flight: usize,
    /// The slot of the next submitted frame (round the ring of MAX_FRAMES_IN_FLIGHT).
    next_slot: usize,
    /// Trace pipelines by (integrator, max bounces, profiling, traversal, surfaces).
    trace: HashMap<TraceKey, ComputePipeline>,
    /// Whether the trace counts its traversal work (FrameStats::traversal).
    profile_traversal: bool,
    traversal: Traversal,
    /// Whether frames also land in an image (`output_image`).
    output_image: bool,
    plan: Option<ComputePipeline>,
    plan_args: Option<ComputePipeline>,
    resolve: Option<ComputePipeline>,
    temporal_pass: Option<ComputePipeline>,
    denoise: Option<ComputePipeline>,
    /// Temporal rendering (`set_temporal`): its settings, and the history once a frame
    /// needed it.
    temporal: Option<TemporalSettings>,
    history: Option<History>,
    raycast: HashMap<Traversal, ComputePipeline>,
    /// One pool per frame slot.
    timestamps: Vec<TimestampPool>,
    targets: Option<FrameTargets>,
    /// The targets used before the current ones, kept so that alternating between two
    /// configs (regular and foveated frames of a bench) does not rebuild the ray buffer and
    /// reallocate the images every frame.
    spare_targets: Option<FrameTargets>,
    /// Per eye, the lens's visibility mask (OpenXR): hidden pixels are never traced, and
    /// resolve makes them black.
    masks: Vec<VisibilityMask>,
    /// The masks as bit planes for plan and resolve (BINDING_VISIBILITY), and the eye size
    /// and layer spacings they were made for (`None`: no mask).
    visibility: Buffer,
    visibility_key: Option<([u32; 2], Vec<u32>)>,
    visibility_stale: bool,
    counters: FrameCounters,
    /// Per frame slot, the descriptor sets of its frame's passes.
    descriptors: Vec<DescriptorArena>,
    scene: SceneBuffers,
    layout: PipelineLayout,
    ctx: Arc<GpuContext>,
}

type TraceKey = (u32, u32, bool, Traversal, bool);

/// Commands recorded at the end of a frame's submission, reading its output image (a copy
/// into a headset's swapchain images).
pub type AfterFrame<'a> = dyn FnMut(vk::CommandBuffer, &StorageImage) + 'a;

/// Timed passes a frame slot's timestamp pool starts with: a stereo frame's plan, trace and
/// resolve, the dispatch sizes and the output image. A frame with more passes (history,
/// denoise iterations) grows its slot's pool first (`FramePasses::size_timestamps`).
const TIMED_PASSES: u32 = 8;

impl Renderer {
    /// Builds the BVHs and uploads the scene once.
    pub fn new(ctx: &Arc<GpuContext>, scene: &Scene) -> Result<Self, RenderError> {
        let scene = SceneBuffers::upload(ctx, scene)?;
        let layout = PipelineLayout::new(ctx)?;
        Ok(Self {
            in_flight: VecDeque::new(),
            finished: VecDeque::new(),
            frames_in_flight: 1,
            next_slot: 0,
            trace: HashMap::new(),
            profile_traversal: false,
            traversal: Traversal::preferred(ctx),
            output_image: false,
            plan: None,
            plan_args: None,
            resolve: None,
            temporal_pass: None,
            denoise: None,
            temporal: None,
            history: None,
            raycast: HashMap::new(),
            timestamps: (0..MAX_FRAMES_IN_FLIGHT)
                .map(|_| TimestampPool::new(ctx, TIMED_PASSES))
                .collect::<Result<_, _>>()?,
            targets: None,
            spare_targets: None,
            masks: Vec::new(),
            visibility: Buffer::with_data(ctx, "visibility mask", &0u32.to_le_bytes())?,
            visibility_key: None,
            visibility_stale: false,
            counters: FrameCounters::new(ctx)?,
            descriptors: (0..MAX_FRAMES_IN_FLIGHT)
                .map(|_| DescriptorArena::new(ctx))
                .collect::<Result<_, _>>()?,
            scene,
            layout,
            ctx: ctx.clone(),
        })
    }

    /// A fingerprint of the scene as this renderer uploaded it: a changed scene file or
    /// built-in changes it.
    pub fn scene_fingerprint(&self) -> u64 {
        self.scene.fingerprint
    }

    pub fn features(&self) -> SceneFeatures {
        self.scene.features
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

    /// Uploads the masks' bit planes when they, the eye size or the layer spacings changed:
    /// per eye the shown pixels and each layer's needed lattice points when all eyes have a
    /// mask of the frame's size, else the one-word "no mask".
    fn ensure_visibility(
        &mut self,
        eyes: usize,
        size: [u32; 2],
        config: &FoveationConfig,
    ) -> Result<(), RenderError> {
        let applies = self.masks.len() >= eyes
            && self.masks[..eyes]
                .iter()
                .all(|m| [m.width, m.height] == size);
        let spacings: Vec<u32> = config.layers.iter().map(|l| l.spacing).collect();
        let wanted = applies.then(|| (size, spacings.clone()));
        if wanted == self.visibility_key && !self.visibility_stale {
            return Ok(());
        }
        // The buffer is replaced: no frame in flight may still read it.
        self.wait_all()?;
        // shared.h's layout: words per plane (0: no mask), then each eye's planes.
        let words: Vec<u32> = match applies {
            true => {
                let per_plane = (size[0] as usize * size[1] as usize).div_ceil(32) as u32;
                let mut words = vec![per_plane];
                for mask in &mut self.masks[..eyes] {
                    words.extend(mask.bits());
                    for &d in &spacings {
                        words.extend(mask.needed_bits(d));
                    }
                }
                words
            }
            false => vec![0],
        };
        self.visibility =
            Buffer::with_data(&self.ctx, "visibility mask", bytemuck::cast_slice(&words))?;
        self.visibility_key = wanted;
        self.visibility_stale = false;
        Ok(())
    }

    /// From the next frame on, every frame also ends by copying its pixels into an image
    /// (`output_image`), for whoever presents frames or accumulates them on the GPU. Off by
    /// default: rendering to files and measuring frames need no image.
    pub fn set_output_image(&mut self, on: bool) {
        self.output_image = on;
    }

    /// The last frame's output on the GPU (eyes side by side, RGBA32F linear radiance, GENERAL
    /// layout), for passes that follow the frame (accumulation) and for presenting it; None
    /// before the first frame and unless `set_output_image(true)` came before it.
    pub fn output_image(&self) -> Option<&StorageImage> {
        self.targets.as_ref().and_then(|t| t.output.as_ref())
    }

    /// From the next frame on, frames keep a temporal history (`Some`) or not (`None`, the
    /// default): every pixel accumulates the samples traced at it over the frames, carried
    /// by reprojection while the camera moves, and the sparse layers' lattices shift every
    /// frame so that every pixel is traced in turn (render/history.rs, glsl/temporal.comp).
    /// Frames of one sequence must differ in seed (`accumulate::frame_seed`).
    pub fn set_temporal(&mut self, settings: Option<TemporalSettings>) -> Result<(), RenderError> {
        if settings == self.temporal {
            return Ok(());
        }
        // The history's buffers go: no frame in flight may still use them.
        self.wait_all()?;
        self.history = None;
        self.temporal = settings;
        Ok(())
    }

    /// Forgets the history: the next frame starts a new one (a cut in a sequence, a jump
    /// that reprojection should not bridge).
    pub fn reset_history(&mut self) {
        if let Some(history) = &mut self.history {
            history.reset();
        }
    }

    /// From the next frame on, the trace counts its BVH traversal's work (nodes, triangle and
    /// primitive tests, loop steps per lane and per subgroup) into `FrameStats::traversal`: a
    /// second trace pipeline, specialised with SPEC_PROFILE; the image is the same.
    pub fn set_traversal_profile(&mut self, on: bool) {
        self.profile_traversal = on;
    }

    /// The traversal the next frames (and ray casts) use. Ray queries need a context that
    /// enabled them (GpuOptions::ray_queries) on a device that has them.
    pub fn set_traversal(&mut self, traversal: Traversal) -> Result<(), RenderError> {
        if traversal == Traversal::RayQuery && self.scene.accel.is_none() {
            return Err(RenderError::Settings(format!(
                "the ray-query traversal needs ray queries, which the device '{}' does not \
                 offer (or --traversal software turned off): use the software traversal",
                self.ctx.info.name
            )));
        }
        self.traversal = traversal;
        Ok(())
    }

    pub fn traversal(&self) -> Traversal {
        self.traversal
    }

    /// The traversals this renderer can run: software, and ray queries where enabled.
    pub fn traversals(&self) -> Vec<Traversal> {
        let mut all = vec![Traversal::Software];
        if self.scene.accel.is_some() {
            all.push(Traversal::RayQuery);
        }
        all
    }

    fn specialization(&self, integrator: u32, max_bounces: u32) -> Vec<(u32, u32)> {
        let f = self.scene.features;
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

    fn trace_key(&self, settings: &RenderSettings) -> TraceKey {
        let s = settings;
        (
            s.integrator.id(),
            s.max_bounces,
            self.profile_traversal,
            self.traversal,
            // With history the trace also writes the points' surfaces.
            self.temporal.is_some(),
        )
    }

    fn ensure_pipelines(&mut self, settings: &RenderSettings) -> Result<(), RenderError> {
        let key = self.trace_key(settings);
        if key.2 && key.3 == Traversal::RayQuery {
            return Err(RenderError::Settings(
                "the traversal profile counts the software traversal's work (the driver's \
                 ray queries have no counters of ours): use --traversal software with it"
                    .into(),
            ));
        }
        if !self.trace.contains_key(&key) {
            let mut spec = self.specialization(key.0, key.1);
            spec.push((SPEC_PROFILE, key.2 as u32));
            let spirv = match (key.3, key.4) {
                (Traversal::Software, false) => shaders::TRACE,
                (Traversal::RayQuery, false) => shaders::TRACE_RQ,
                (Traversal::Software, true) => shaders::TRACE_SURFACES,
                (Traversal::RayQuery, true) => shaders::TRACE_RQ_SURFACES,
            };
            let p = ComputePipeline::new(&self.ctx, &self.layout, "trace", spirv, &spec)?;
            self.trace.insert(key, p);
        }
        let temporal = self.temporal.is_some();
        for (slot, name, spirv, wanted) in [
            (&mut self.plan, "plan", shaders::PLAN, true),
            (
                &mut self.plan_args,
                "dispatch sizes",
                shaders::PLAN_ARGS,
                true,
            ),
            (&mut self.resolve, "resolve", shaders::RESOLVE, true),
            (
                &mut self.temporal_pass,
                "temporal",
                shaders::TEMPORAL,
                temporal,
            ),
            (&mut self.denoise, "denoise", shaders::DENOISE, temporal),
        ] {
            if slot.is_none() && wanted {
                *slot = Some(ComputePipeline::new(
                    &self.ctx,
                    &self.layout,
                    name,
                    spirv,
                    &[],
                )?);
            }
        }
        Ok(())
    }

    fn ensure_targets(&mut self, key: TargetKey) -> Result<(), RenderError> {
        if self.targets.as_ref().is_some_and(|t| t.key == key) {
            return Ok(());
        }
        // Other targets: no frame in flight may still use the current ones.
        self.wait_all()?;
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
        self.run_frame(request, None, true, None)
    }

    /// Renders one frame like [`Self::render_frame`] but leaves the image on the GPU: the
    /// returned frame has no pixels (`rgb` is empty), only its gazes and stats. Frame-time
    /// measurements use this so that the read-back, which a headset frame never does, is not
    /// counted.
    pub fn measure_frame(&mut self, request: &FrameRequest) -> Result<Frame, RenderError> {
        self.run_frame(request, None, false, None)
    }

    /// Like [`Self::measure_frame`], but every eye's gaze (the request's are not used) comes
    /// from `latch`, which is called after the frame's commands are recorded, as the last
    /// thing before they are submitted: the gaze is the latest the caller can give. Planning
    /// from it (O(layers) numbers per eye, `FrameStats::plan_ms`) is all that happens on the
    /// CPU between the two.
    pub fn measure_frame_latched(
        &mut self,
        request: &FrameRequest,
        latch: &mut dyn FnMut() -> Vec<Gaze>,
    ) -> Result<Frame, RenderError> {
        self.run_frame(request, None, false, Some(latch))
    }

    /// How many frames may be in flight at once (1..=MAX_FRAMES_IN_FLIGHT; 1 by default):
    /// [`Self::submit_frame_latched`] waits for the oldest only when that many are.
    pub fn set_frames_in_flight(&mut self, frames: usize) -> Result<(), RenderError> {
        if !(1..=MAX_FRAMES_IN_FLIGHT).contains(&frames) {
            return Err(RenderError::Settings(format!(
                "{frames} frames in flight: give 1 (each frame finished before the next) to \
                 {MAX_FRAMES_IN_FLIGHT}"
            )));
        }
        self.frames_in_flight = frames;
        Ok(())
    }

    /// Submits a frame like [`Self::measure_frame_latched`] and returns without waiting for
    /// it; its results come from [`Self::next_finished`], in submission order. When the frames
    /// in flight are already as many as allowed, the oldest is waited for first. `after`
    /// records commands that read the frame's output image (a copy into a swapchain image)
    /// into the frame's own submission; it is not called without an output image
    /// (`set_output_image`).
    pub fn submit_frame_latched(
        &mut self,
        request: &FrameRequest,
        latch: &mut dyn FnMut() -> Vec<Gaze>,
        after: &mut AfterFrame<'_>,
    ) -> Result<(), RenderError> {
        self.submit(request, None, Some(latch), Some(after))
    }

    /// Frames submitted and not finished yet (as far as the renderer has looked).
    pub fn in_flight(&self) -> usize {
        self.in_flight.len()
    }

    /// The oldest submitted frame not taken yet, if it has finished; with `wait`, waits for
    /// it. None when no frame is left.
    pub fn next_finished(&mut self, wait: bool) -> Result<Option<Frame>, RenderError> {
        if self.finished.is_empty() {
            let done = match self.in_flight.front() {
                None => return Ok(None),
                Some(oldest) => wait || oldest.commands.is_done()?,
            };
            if done {
                self.retire_oldest()?;
            }
        }
        Ok(self.finished.pop_front())
    }

    /// Runs only the resolve pass of `request`, on lattice values given by the caller
    /// (`value` of every lattice point of every eye and layer) instead of traced ones. For
    /// testing the pass against CPU references on data with known answers.
    pub fn compose(
        &mut self,
        request: &FrameRequest,
        value: impl Fn(LatticePoint) -> [f32; 4],
    ) -> Result<Frame, RenderError> {
        self.run_frame(request, Some(&value), true, None)
    }

    /// Each eye's layers for `gazes` (one per eye of `request`), and the CPU ms it took.
    fn plan_eyes(&self, request: &FrameRequest, gazes: &[Gaze]) -> (Vec<EyeLayers>, f64) {
        let planning = Instant::now();
        let targets = self.targets.as_ref().expect("prepared");
        let history_frame = self.history.as_ref().map_or(0, History::frame);
        let eyes = (0..request.eyes.len())
            .map(|e| {
                let gaze = gazes.get(e).copied().unwrap_or(request.eyes[e].gaze);
                eye_layers(
                    request,
                    e,
                    gaze,
                    &targets.buffer,
                    &targets.images[e],
                    history_frame,
                )
            })
            .collect();
        (eyes, planning.elapsed().as_secs_f64() * 1e3)
    }

    /// One frame from submission to results: submit, wait for every frame in flight, and
    /// take this one (the last) with its pixels when asked.
    fn run_frame(
        &mut self,
        request: &FrameRequest,
        given: Option<&dyn Fn(LatticePoint) -> [f32; 4]>,
        read_output: bool,
        latch: Option<&mut dyn FnMut() -> Vec<Gaze>>,
    ) -> Result<Frame, RenderError> {
        self.submit(request, given, latch, None)?;
        self.wait_all()?;
        let mut frame = self.finished.pop_back().expect("the frame just submitted");
        if read_output {
            // The pixels are this frame's: nothing was submitted after it.
            frame.rgb = self.targets.as_ref().expect("prepared").read_pixels()?;
        }
        Ok(frame)
    }

    /// The frame: prepare, record (plan → trace → resolve → output image → `after`) into
    /// the next slot, then latch the gaze (the slot's layers) and submit.
    fn submit(
        &mut self,
        request: &FrameRequest,
        given: Option<&dyn Fn(LatticePoint) -> [f32; 4]>,
        latch: Option<&mut dyn FnMut() -> Vec<Gaze>>,
        after: Option<&mut AfterFrame<'_>>,
    ) -> Result<(), RenderError> {
        if self.in_flight.len() >= self.frames_in_flight {
            self.retire_oldest()?;
        }
        self.prepare(request)?;
        let request_gazes: Vec<Gaze> = request.eyes.iter().map(|e| e.gaze).collect();
        if let Some(value) = given {
            self.wait_all()?;
            let (eyes, _) = self.plan_eyes(request, &request_gazes);
            let targets = self.targets.as_mut().expect("prepared");
            let lattice = given_lattice(&self.ctx, targets, &eyes, value)?;
            targets.replace_lattice(lattice)?;
        }
        let slot = self.next_slot;
        let recording = Instant::now();
        let targets = self.targets.as_ref().expect("prepared");
        // Given lattice values (compose) have no surfaces: history is left alone.
        let history = self.history.as_ref().filter(|_| given.is_none());
        let pushes: Vec<EyePush> = (0..request.eyes.len())
            .map(|e| {
                let mut push = eye_push(request, e, &targets.buffer);
                push.eye.layer_base = targets.layer_base(slot);
                push.eye.history = history.as_ref().map_or(0, |h| h.push_word(slot));
                push
            })
            .collect();
        let passes = FramePasses {
            pipelines: FramePipelines {
                plan: self.plan.as_ref().expect("prepared"),
                plan_args: self.plan_args.as_ref().expect("prepared"),
                trace: &self.trace[&self.trace_key(&request.settings)],
                resolve: self.resolve.as_ref().expect("prepared"),
                temporal: history.and(self.temporal_pass.as_ref()),
                denoise: match (
                    history,
                    &self.denoise,
                    request.foveation.denoise_iterations(),
                ) {
                    (Some(_), Some(pipeline), n) if n > 0 => Some((pipeline, n)),
                    _ => None,
                },
            },
            scene: &self.scene,
            traversal: self.traversal,
            counters: &self.counters,
            targets,
            visibility: &self.visibility,
            history,
            eyes: &pushes,
            slot,
        };
        let traced = given.is_none();
        let timestamps = &mut self.timestamps[slot];
        timestamps.ensure_passes(passes.timed_passes(traced))?;
        let descriptors = &mut self.descriptors[slot];
        let (ctx, layout) = (&self.ctx, &self.layout);
        let mut recorded = Ok(());
        let mut commands = ctx.record_owned("frame", |cmd| {
            recorded = (|| {
                let mut g = FrameGraph::begin(ctx, cmd, layout, descriptors, timestamps)?;
                passes.reset_counters(&mut g);
                if traced {
                    passes.plan(&mut g);
                    passes.dispatch_sizes(&mut g);
                    passes.trace(&mut g);
                }
                passes.resolve(&mut g);
                passes.temporal(&mut g);
                passes.denoise(&mut g);
                passes.output_image(&mut g);
                // Commands of the caller's (a copy into a headset's swapchain image), which
                // order their own reads of the output image.
                if let (Some(after), Some(image)) = (after, &targets.output) {
                    after(cmd, image);
                }
                passes.collect_counters(&mut g);
                g.finish()
            })();
        })?;
        recorded?;
        let record_ms = recording.elapsed().as_secs_f64() * 1e3;

        // The latch: the newest gaze, planned and written where the recorded commands read it.
        let gazes = match latch {
            Some(latch) => latch(),
            None => request_gazes,
        };
        let (eyes, plan_ms) = self.plan_eyes(request, &gazes);
        self.targets
            .as_mut()
            .expect("prepared")
            .write_layers(slot, &eyes)?;
        if let Some(history) = self.history.as_mut().filter(|_| given.is_none()) {
            let cameras: Vec<PushCamera> = pushes.iter().map(|p| p.cam).collect();
            history.advance(slot, &cameras)?;
        }
        let mut busy_at_submit = 0;
        for frame in &self.in_flight {
            busy_at_submit += !frame.commands.is_done()? as u32;
        }
        let submitted_at = Instant::now();
        commands.submit()?;
        self.next_slot = (slot + 1) % MAX_FRAMES_IN_FLIGHT;
        self.in_flight.push_back(PendingFrame {
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

    /// Waits for the oldest frame in flight and reads its results into `finished`, which
    /// frees its slot.
    fn retire_oldest(&mut self) -> Result<(), RenderError> {
        let Some(mut frame) = self.in_flight.pop_front() else {
            return Ok(());
        };
        frame.commands.wait()?;
        let slot = frame.slot;
        let results = frame_results(frame.known, &self.timestamps[slot], &self.counters, slot)?;
        self.finished.push_back(results);
        Ok(())
    }

    /// Waits for every frame in flight (their results wait in `finished`): before anything
    /// they use is replaced or rebound.
    fn wait_all(&mut self) -> Result<(), RenderError> {
        while !self.in_flight.is_empty() {
            self.retire_oldest()?;
        }
        Ok(())
    }

    /// Validates the request and makes pipelines, targets and masks ready for it.
    fn prepare(&mut self, request: &FrameRequest) -> Result<(), RenderError> {
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
            image: self.output_image,
        })?;
        self.ensure_visibility(request.eyes.len(), [s.width, s.height], request.foveation)?;
        self.ensure_history(request)
    }

    /// Makes the history ready for `request`'s image when temporal rendering is on: a new
    /// (empty) one when the image size, the eyes or the lattice changed.
    fn ensure_history(&mut self, request: &FrameRequest) -> Result<(), RenderError> {
        let Some(settings) = self.temporal else {
            if let Some(k) = request.foveation.layers.iter().position(|l| l.denoise > 0) {
                return Err(RenderError::Settings(format!(
                    "layer {} asks for denoise, which is guided by the temporal history's \
                     surfaces: turn history on (fovea render --camera-path, fovea xr \
                     --temporal on) or set the layer's denoise to 0",
                    k + 1
                )));
            }
            return Ok(());
        };
        let targets = self.targets.as_ref().expect("prepared");
        let key = HistoryKey {
            width: request.settings.width,
            height: request.settings.height,
            eyes: request.eyes.len() as u32,
            lattice_len: targets.lattice_len() as u64,
        };
        if self.history.as_ref().is_some_and(|h| h.key == key) {
            return Ok(());
        }
        self.wait_all()?;
        self.history = None;
        self.history = Some(History::new(&self.ctx, key, settings)?);
        Ok(())
    }

    /// Closest hits of arbitrary rays through the GPU traversal (for tests and tools).
    /// Returns the hits and the number of stack overflows.
    pub fn raycast(
        &mut self,
        rays: &[GpuProbeRay],
    ) -> Result<(Vec<GpuProbeHit>, u64), RenderError> {
        if !self.raycast.contains_key(&self.traversal) {
            let spec = self.specialization(INTEGRATOR_PT, 0);
            let spirv = match self.traversal {
                Traversal::Software => shaders::RAYCAST,
                Traversal::RayQuery => shaders::RAYCAST_RQ,
            };
            let pipeline = ComputePipeline::new(&self.ctx, &self.layout, "raycast", spirv, &spec)?;
            self.raycast.insert(self.traversal, pipeline);
        }
        let hit_bytes = std::mem::size_of_val(rays) as u64 / 2;
        // The counters are reused: nothing may be in flight.
        self.wait_all()?;
        let ray_buffer = Buffer::with_data(&self.ctx, "probe rays", bytemuck::cast_slice(rays))?;
        let hit_buffer = Buffer::new(
            &self.ctx,
            "probe hits",
            hit_bytes,
            vk::BufferUsageFlags::STORAGE_BUFFER,
            MemoryLocation::GpuToCpu,
        )?;
        let push = RaycastPush {
            probe_count: rays.len() as u32,
        };
        let groups = [(rays.len() as u32).div_ceil(PROBE_WORKGROUP_SIZE), 1, 1];
        let pipeline = &self.raycast[&self.traversal];
        let (ctx, layout, counters, scene) = (&self.ctx, &self.layout, &self.counters, &self.scene);
        let traversal = self.traversal;
        let mut descriptors = DescriptorArena::new(ctx)?;
        let mut timestamps = TimestampPool::new(ctx, 1)?;
        let mut recorded = Ok(());
        ctx.submit_and_wait("raycast", |cmd| {
            recorded = (|| {
                let mut g = FrameGraph::begin(ctx, cmd, layout, &mut descriptors, &mut timestamps)?;
                let stats = &counters.device;
                g.pass()
                    .fills(stats)
                    .record(|r| stats.cmd_zero(r.cmd, stats.size));
                scene
                    .declare(g.pass(), traversal)
                    .reads(BINDING_PROBE_RAYS, &ray_buffer)
                    .writes(BINDING_PROBE_HITS, &hit_buffer)
                    .reads_writes(BINDING_STATS, stats)
                    .record(|r| r.dispatch("raycast", pipeline, &push, groups));
                g.host_reads(&hit_buffer);
                let host = counters.read_back(0);
                g.pass()
                    .copies_from(stats)
                    .copies_into(host)
                    .record(|r| stats.cmd_copy_to(r.cmd, host, stats.size));
                g.host_reads(host);
                g.finish()
            })();
        })?;
        recorded?;
        let overflows = self.counters.read(0)?.eyes[0].stack_overflows;
        let hits: Vec<GpuProbeHit> =
            bytemuck::pod_collect_to_vec(&hit_buffer.read()?[..rays.len() * 16]);
        Ok((hits, overflows))
    }
}

/// The lattice values `value` gives every lattice point of every eye and layer, uploaded
/// in place of the frame's traced ones.
fn given_lattice(
    ctx: &Arc<GpuContext>,
    targets: &FrameTargets,
    eyes: &[EyeLayers],
    value: &dyn Fn(LatticePoint) -> [f32; 4],
) -> Result<Buffer, RenderError> {
    let mut values = vec![0.0f32; eyes.len() * targets.lattice_len() * 4];
    for (e, eye) in eyes.iter().enumerate() {
        for (k, (layer, lattice)) in eye.layers.iter().zip(&targets.buffer.layers).enumerate() {
            for j in lattice.row_min..=lattice.row_max {
                for i in lattice.col_min..=lattice.col_max {
                    let point = LatticePoint {
                        eye: e,
                        layer: k,
                        x: layer.anchor_x + i * layer.spacing,
                        y: layer.anchor_y + j * layer.spacing,
                    };
                    let at = e * targets.lattice_len() + lattice.index(i, j) as usize;
                    values[at * 4..at * 4 + 4].copy_from_slice(&value(point));
                }
            }
        }
    }
    Ok(Buffer::with_data(
        ctx,
        "lattice values",
        bytemuck::cast_slice(&values),
    )?)
}
