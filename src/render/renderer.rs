//! The renderer: a scene on the GPU and everything its frames need, made ready per request.
//! Each job is a part of its own: the scene's buffers (scene_buffers.rs), the pipelines
//! (pipelines.rs), the frame targets (targets.rs), the lenses' masks (visibility.rs), the
//! temporal history (history.rs), the frames in flight (in_flight.rs). The frame itself is
//! record.rs; the ray-cast probe, probe.rs. One way in renders a frame: [`Renderer::frame`].

use super::counters::FrameCounters;
use super::display::DisplayTransform;
use super::display_stage::DisplayStage;
use super::frame::Frame;
use super::history::{History, HistoryKey, TemporalSettings};
use super::in_flight::FrameRing;
use super::pipelines::{Pipelines, TraceKey};
use super::request::{FrameOptions, FrameRequest};
use super::scene_buffers::{SceneBuffers, SceneMemory};
use super::settings::Traversal;
use super::targets::{TargetCache, TargetKey};
use super::trace_lanes::TraceLanes;
use super::visibility::Visibility;
use super::RenderError;
use crate::foveation::VisibilityMask;
use crate::gpu::{GpuContext, StorageImage};
use crate::scene::{Scene, SceneFeatures};
use std::sync::Arc;

pub struct Renderer {
    // Field order is drop order: frames in flight (whose drop waits for them) first, then
    // every resource before the context it borrows.
    pub(super) ring: FrameRing,
    pub(super) pipelines: Pipelines,
    pub(super) targets: TargetCache,
    pub(super) visibility: Visibility,
    /// Temporal rendering (`set_temporal`): its settings, and the history once a frame
    /// needed it.
    pub(super) temporal: Option<TemporalSettings>,
    pub(super) history: Option<History>,
    pub(super) counters: FrameCounters,
    pub(super) scene: SceneBuffers,
    /// Whether the trace counts its traversal work (FrameStats::traversal).
    pub(super) profile_traversal: bool,
    pub(super) traversal: Traversal,
    /// How many trace threads each layer's points get (`set_trace_lanes`).
    trace_lanes: TraceLanes,
    /// Whether frames also land in an image (`output_image`).
    output_image: bool,
    /// The display transform of what is presented (`set_display`), where it needs a pass.
    pub(super) display: Option<DisplayStage>,
    pub(super) ctx: Arc<GpuContext>,
}

impl Renderer {
    /// Builds the BVHs and uploads the scene once.
    pub fn new(ctx: &Arc<GpuContext>, scene: &Scene) -> Result<Self, RenderError> {
        let scene = SceneBuffers::upload(ctx, scene)?;
        Ok(Self {
            ring: FrameRing::new(ctx)?,
            pipelines: Pipelines::new(ctx, scene.features)?,
            targets: TargetCache::default(),
            visibility: Visibility::new(ctx)?,
            temporal: None,
            history: None,
            counters: FrameCounters::new(ctx)?,
            scene,
            profile_traversal: false,
            traversal: Traversal::preferred(ctx),
            trace_lanes: preferred_trace_lanes(ctx),
            output_image: false,
            display: None,
            ctx: ctx.clone(),
        })
    }

    /// Renders a frame of `request`, foveated by `request.foveation`, for one or two eyes
    /// (side by side): waited for and returned (`Some`) when `options.wait`, else left in
    /// flight (`None`; see [`Self::next_finished`]).
    pub fn frame(
        &mut self,
        request: &FrameRequest,
        options: FrameOptions,
    ) -> Result<Option<Frame>, RenderError> {
        let (wait, read_pixels) = (options.wait, options.read_pixels);
        self.prepare(request)?;
        self.submit(request, options, true)?;
        if !wait {
            return Ok(None);
        }
        let mut frame = self.ring.wait_newest(&self.counters)?;
        if read_pixels {
            // The pixels are this frame's: nothing was submitted after it.
            let targets = self.targets.current().expect("prepared");
            frame.rgb = targets.read_pixels()?;
        }
        Ok(Some(frame))
    }

    /// A fingerprint of the scene as this renderer uploaded it: a changed scene file or
    /// built-in changes it.
    pub fn scene_fingerprint(&self) -> u64 {
        self.scene.fingerprint
    }

    pub fn features(&self) -> SceneFeatures {
        self.scene.features
    }

    /// What the scene holds in device-local memory.
    pub fn scene_memory(&self) -> SceneMemory {
        self.scene.memory
    }

    pub fn context(&self) -> &Arc<GpuContext> {
        &self.ctx
    }

    /// Sets each eye's visibility mask (eye order as in the frame's eyes; empty for none). A
    /// mask applies to frames whose eye image has the mask's size.
    pub fn set_visibility_masks(&mut self, masks: Vec<VisibilityMask>) {
        self.visibility.set_masks(masks);
    }

    /// From the next frame on, every frame also ends by copying its pixels into an image
    /// (`output_image`), for whoever presents frames or accumulates them on the GPU. Off by
    /// default: rendering to files and measuring frames need no image.
    pub fn set_output_image(&mut self, on: bool) {
        self.output_image = on;
    }

    /// From the next frame on, the image the frame's `after` commands get (what a headset
    /// presents) is the output image through `transform` (glsl/display.comp).
    pub fn set_display(&mut self, transform: DisplayTransform) -> Result<(), RenderError> {
        self.display = DisplayStage::for_transform(&self.ctx, &self.pipelines.layout, transform)?;
        Ok(())
    }

    /// The last frame's output on the GPU (eyes side by side, RGBA32F linear radiance, GENERAL
    /// layout), for passes that follow the frame (accumulation) and for presenting it; None
    /// before the first frame and unless `set_output_image(true)` came before it.
    pub fn output_image(&self) -> Option<&StorageImage> {
        self.targets.current().and_then(|t| t.output.as_ref())
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
        self.ring.wait_all(&self.counters)?;
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

    /// How many threads trace each layer's lattice points from the next frame on
    /// (TraceLanes' rule): lane p traces samples p, p + lanes, ... and the point's first lane
    /// adds the lanes' sums in order. A layer whose spp is at most its lanes gets the same
    /// bits as with one; more, the same sum up to rounding.
    pub fn set_trace_lanes(&mut self, lanes: TraceLanes) {
        self.trace_lanes = lanes;
    }

    pub fn trace_lanes(&self) -> TraceLanes {
        self.trace_lanes
    }

    /// The traversals this renderer can run: software, and ray queries where enabled.
    pub fn traversals(&self) -> Vec<Traversal> {
        let mut all = vec![Traversal::Software];
        if self.scene.accel.is_some() {
            all.push(Traversal::RayQuery);
        }
        all
    }

    /// How many frames may be in flight at once (1..=MAX_FRAMES_IN_FLIGHT; 1 by default):
    /// a frame that does not wait waits for the oldest only when that many are.
    pub fn set_frames_in_flight(&mut self, frames: usize) -> Result<(), RenderError> {
        self.ring.set_limit(frames)
    }

    /// Frames submitted and not finished yet (as far as the renderer has looked).
    pub fn in_flight(&self) -> usize {
        self.ring.len()
    }

    /// The oldest submitted frame not taken yet, if it has finished; with `wait`, waits for
    /// it. None when no frame is left.
    pub fn next_finished(&mut self, wait: bool) -> Result<Option<Frame>, RenderError> {
        self.ring.next_finished(&self.counters, wait)
    }

    /// The trace pipeline a frame of `request` uses.
    pub(super) fn trace_key(&self, request: &FrameRequest) -> TraceKey {
        let history = self.temporal.is_some();
        TraceKey::new(
            &request.settings,
            self.profile_traversal,
            self.traversal,
            history,
            self.targets.current().is_some_and(|t| t.lane_unit() > 1),
        )
    }

    /// Validates the request and makes pipelines, targets, masks and history ready for it.
    pub(super) fn prepare(&mut self, request: &FrameRequest) -> Result<(), RenderError> {
        let s = &request.settings;
        s.validate().map_err(RenderError::Settings)?;
        if s.integrator == super::Integrator::Seed && self.scene.features.punctual_lights {
            return Err(RenderError::Settings(
                "the seed integrator (the thesis' estimator) finds light only where its paths \
                 hit an emitter, and nothing hits a punctual light (KHR_lights_punctual): \
                 render this scene with --integrator pt"
                    .to_owned(),
            ));
        }
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
        self.ensure_targets(TargetKey {
            config: request.foveation.clone(),
            width: s.width,
            height: s.height,
            fovs: request.eyes.iter().map(|e| e.fov()).collect(),
            image: self.output_image,
            lanes: self.trace_lanes,
        })?;
        // After the targets: whether the trace shares lanes follows their layers' lanes.
        self.pipelines.ensure(self.trace_key(request))?;
        if let (Some(stage), Some(output)) = (&mut self.display, self.targets.current()) {
            if let Some(frame) = &output.output {
                stage.ensure_image(&self.ctx, frame)?;
            }
        }
        let (eyes, size) = (request.eyes.len(), [s.width, s.height]);
        if self.visibility.needs_upload(eyes, size, request.foveation) {
            // The buffer is replaced: no frame in flight may still read it.
            self.ring.wait_all(&self.counters)?;
            self.visibility
                .upload(&self.ctx, eyes, size, request.foveation)?;
        }
        self.ensure_history(request)
    }

    /// Makes `key`'s targets current.
    pub(super) fn ensure_targets(&mut self, key: TargetKey) -> Result<(), RenderError> {
        if self.targets.holds(&key) {
            return Ok(());
        }
        // Other targets: no frame in flight may still use the current ones.
        self.ring.wait_all(&self.counters)?;
        self.targets.switch(&self.ctx, key)
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
            if let Some(k) = request.foveation.layers.iter().position(|l| l.filters()) {
                return Err(RenderError::Settings(format!(
                    "layer {} asks for the lattice filter (filter_mar or filter_px), which is \
                     guided by the temporal history's surfaces: turn history on (fovea render \
                     --camera-path, fovea xr --temporal on) or set the layer's filter_mar and \
                     filter_px to 0",
                    k + 1
                )));
            }
            return Ok(());
        };
        let targets = self.targets.current().expect("prepared");
        let key = HistoryKey {
            width: request.settings.width,
            height: request.settings.height,
            eyes: request.eyes.len() as u32,
            lattice_len: targets.lattice_len() as u64,
        };
        if self.history.as_ref().is_some_and(|h| h.key == key) {
            return Ok(());
        }
        self.ring.wait_all(&self.counters)?;
        self.history = None;
        self.history = Some(History::new(&self.ctx, key, settings)?);
        Ok(())
    }
}

/// The trace's lanes on `ctx`'s device. A CPU driver: one thread per point, which runs
/// best there. A GPU: up to 16 threads per point, each with at least 4 samples (measured on
/// an H100: reports/gpu-h100-lanes-1440x1600), more while an eye's trace has fewer than
/// GPU_FILL_THREADS threads.
pub fn preferred_trace_lanes(ctx: &GpuContext) -> TraceLanes {
    match ctx.info.kind.as_str() {
        "CPU" => TraceLanes::ONE,
        _ => TraceLanes {
            max_lanes: 16,
            samples_per_lane: 4,
            fill_threads: GPU_FILL_THREADS,
        },
    }
}

/// Threads per eye that keep a large GPU busy: about two waves of an H100's or H200's 132
/// SMs × 2048 resident threads. Regular 1 spp at 720×800 (576 000 points) already has them
/// (reports/gpu-h200-candidates-720x800: it traced at the rate of 288 000 points of 2 spp and
/// twice that of 144 000 points of 4).
pub const GPU_FILL_THREADS: u64 = 1 << 19;
