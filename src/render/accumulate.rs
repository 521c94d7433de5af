//! Progressive refinement: the running mean of the frames rendered while the view stands
//! still, on the GPU (glsl/accumulate.comp), and the debug views computed from it: the
//! difference from regular rendering and a samples-per-pixel heat map. Frame `n` of a mean
//! must be rendered with seed `seed + n` (see [`frame_seed`]); the mean of `N` frames of `s`
//! samples per pixel is then an estimate with `N·s` samples per pixel.

use super::display::DisplayTransform;
use super::display_stage::DisplayStage;
use super::graph::FrameGraph;
use super::request::EyeView;
use super::RenderError;
use crate::foveation::plan::cos_limit;
use crate::foveation::view::direction;
use crate::foveation::{FoveationConfig, MAX_LAYERS};
use crate::gpu::{
    shaders, vk, Buffer, ComputePipeline, DescriptorArena, GpuContext, PipelineLayout,
    StorageImage, TimestampPool,
};
use crate::shader_layout::*;
use gpu_allocator::MemoryLocation;
use std::sync::Arc;

/// The seed of the `n`-th frame (from 0) of a running mean whose first frame uses `seed`:
/// frame 0 is exactly the frame `fovea render --seed SEED` makes.
pub fn frame_seed(seed: u32, n: u32) -> u32 {
    seed.wrapping_add(n)
}

/// Which running mean a frame goes into.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mean {
    /// The frames the viewer shows (foveated or not).
    Main,
    /// Regular frames at the same seeds, for the difference view.
    Regular,
}

impl Mean {
    fn layer(self) -> u32 {
        match self {
            Mean::Main => ACCUM_LAYER_MAIN,
            Mean::Regular => ACCUM_LAYER_REGULAR,
        }
    }
}

/// What the pass leaves in the frame image after adding it to a mean.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Show {
    /// The running mean.
    Mean,
    /// Nothing: the frame stays as rendered (the first half of a difference view).
    Nothing,
    /// |main mean − regular mean| × `ACCUM_DIFF_GAIN`.
    Difference,
    /// Camera samples per pixel so far, log2 on the turbo colour ramp.
    Heat,
}

impl Show {
    fn id(self) -> u32 {
        match self {
            Show::Mean => ACCUM_SHOW_MEAN,
            Show::Nothing => ACCUM_SHOW_NOTHING,
            Show::Difference => ACCUM_SHOW_DIFF,
            Show::Heat => ACCUM_SHOW_HEAT,
        }
    }
}

/// One frame handed to [`Accumulator::add`].
pub struct AccumulateRequest<'a> {
    /// The renderer's output (`Renderer::output_image`): eyes side by side, GENERAL layout.
    /// Overwritten with what `show` asks for.
    pub frame: &'a StorageImage,
    /// The eyes the frame was rendered for, left first, each `eye_size` pixels.
    pub eyes: &'a [EyeView],
    pub eye_size: [u32; 2],
    /// The layer config the frame was rendered with (the heat map shows its sample density).
    pub foveation: &'a FoveationConfig,
    pub into: Mean,
    pub show: Show,
}

/// The running means (one image of `ACCUM_LAYERS` layers, eyes side by side) and the pass.
pub struct Accumulator {
    // Field order is drop order: every resource before the context.
    pipeline: ComputePipeline,
    timestamps: TimestampPool,
    means: Option<StorageImage>,
    /// Whether `means` still has to be moved from UNDEFINED to GENERAL layout.
    fresh: bool,
    /// Per eye and layer, what the heat map needs (see [`gpu_layers`]).
    layers: Buffer,
    /// Frames in each mean (indexed by `ACCUM_LAYER_*`).
    counts: [u32; ACCUM_LAYERS as usize],
    layout: PipelineLayout,
    /// The pass's descriptor sets, made anew for every submission.
    descriptors: DescriptorArena,
    ctx: Arc<GpuContext>,
}

impl Accumulator {
    pub fn new(ctx: &Arc<GpuContext>) -> Result<Self, RenderError> {
        let layout = PipelineLayout::new(ctx)?;
        let pipeline = ComputePipeline::new(ctx, &layout, "accumulate", shaders::ACCUMULATE, &[])?;
        let layers = Buffer::new(
            ctx,
            "accumulate layers",
            (STAT_EYES as usize * MAX_LAYERS * std::mem::size_of::<GpuLayer>()) as u64,
            vk::BufferUsageFlags::STORAGE_BUFFER,
            MemoryLocation::CpuToGpu,
        )?;
        Ok(Self {
            pipeline,
            timestamps: TimestampPool::new(ctx, STAT_EYES)?,
            means: None,
            fresh: false,
            layers,
            counts: [0; ACCUM_LAYERS as usize],
            layout,
            descriptors: DescriptorArena::new(ctx)?,
            ctx: ctx.clone(),
        })
    }

    /// Starts new means: the next frame added replaces what was accumulated.
    pub fn reset(&mut self) {
        self.counts = [0; ACCUM_LAYERS as usize];
    }

    /// Frames in the main mean so far.
    pub fn frames(&self) -> u32 {
        self.counts[ACCUM_LAYER_MAIN as usize]
    }

    /// The seed for the next frame of `into`, the mean's first frame having `seed`.
    pub fn next_seed(&self, seed: u32, into: Mean) -> u32 {
        frame_seed(seed, self.counts[into.layer() as usize])
    }

    /// Adds the frame to its mean and overwrites it with what `request.show` asks for.
    /// Returns the GPU milliseconds of the pass (all eyes).
    pub fn add(&mut self, request: &AccumulateRequest) -> Result<f64, RenderError> {
        check_frame(request)?;
        self.ensure_means(request.frame.width, request.eye_size[1])?;
        let gpu: Vec<GpuLayer> = request
            .eyes
            .iter()
            .flat_map(|eye| gpu_layers(eye, request.eye_size, request.foveation))
            .collect();
        self.layers.write(0, bytemuck::cast_slice(&gpu))?;
        let index = request.into.layer();
        let pushes = pushes(request, self.counts[index as usize]);
        self.record(request, &pushes)?;
        self.counts[index as usize] += 1;
        Ok(self.timestamps.read()?.iter().map(|p| p.ms).sum())
    }

    /// A display stage for `transform` that [`Self::show`] can run (None: the blit alone
    /// shows the same).
    pub fn display_stage(
        &self,
        transform: DisplayTransform,
    ) -> Result<Option<DisplayStage>, RenderError> {
        DisplayStage::for_transform(&self.ctx, &self.layout, transform)
    }

    /// Runs `stage` on `frame` (what the last `add` left there, or a frame as rendered) and
    /// waits: its image is then what a window shows. Returns the pass's GPU milliseconds.
    pub fn show(
        &mut self,
        frame: &StorageImage,
        stage: &mut DisplayStage,
    ) -> Result<f64, RenderError> {
        stage.ensure_image(&self.ctx, frame)?;
        let (ctx, layout) = (&self.ctx, &self.layout);
        let (descriptors, timestamps) = (&mut self.descriptors, &mut self.timestamps);
        let mut recorded = Ok(());
        ctx.submit_and_wait("display", |cmd| {
            recorded =
                FrameGraph::begin(ctx, cmd, layout, descriptors, timestamps).and_then(|mut g| {
                    stage.record(&mut g, frame);
                    g.finish()
                });
        })?;
        recorded?;
        Ok(self.timestamps.read()?.iter().map(|p| p.ms).sum())
    }

    /// New (empty) means when the frame's size changed.
    fn ensure_means(&mut self, width: u32, height: u32) -> Result<(), RenderError> {
        if self
            .means
            .as_ref()
            .is_some_and(|m| m.width == width && m.height == height)
        {
            return Ok(());
        }
        self.means = None;
        let means =
            StorageImage::new_array(&self.ctx, "running means", width, height, ACCUM_LAYERS)?;
        self.means = Some(means);
        self.fresh = true;
        self.reset();
        Ok(())
    }

    /// Submits the pass, an eye at a time, and waits for it.
    fn record(
        &mut self,
        request: &AccumulateRequest,
        pushes: &[AccumulatePush],
    ) -> Result<(), RenderError> {
        let [w, h] = request.eye_size;
        let groups = [
            w.div_ceil(WORKGROUP_SIZE_X),
            h.div_ceil(WORKGROUP_SIZE_Y),
            1,
        ];
        let fresh = std::mem::take(&mut self.fresh);
        let means = self.means.as_ref().expect("ensured");
        let (ctx, pipeline, layout, layers) =
            (&self.ctx, &self.pipeline, &self.layout, &self.layers);
        let (descriptors, timestamps) = (&mut self.descriptors, &mut self.timestamps);
        let mut recorded = Ok(());
        ctx.submit_and_wait("accumulate", |cmd| {
            if fresh {
                means.cmd_prepare_for_write(cmd);
            }
            // The graph starts after the frame's own submission (which wrote the frame).
            recorded =
                FrameGraph::begin(ctx, cmd, layout, descriptors, timestamps).and_then(|mut g| {
                    // An eye per pass: the eyes write their own halves of the frame and the
                    // means, but a storage image is one resource to the synchronization checks.
                    for (e, push) in pushes.iter().enumerate() {
                        let name = match (pushes.len(), e) {
                            (1, _) => "accumulate",
                            (_, 0) => "left accumulate",
                            _ => "right accumulate",
                        };
                        g.pass()
                            .reads(BINDING_LAYERS, layers)
                            .reads_writes(BINDING_OUTPUT, request.frame)
                            .reads_writes(BINDING_LAYER_IMAGES, means)
                            .record(|r| r.dispatch(name, pipeline, push, groups));
                    }
                    g.finish()
                });
        })?;
        Ok(recorded?)
    }
}

/// The frame must be the request's eyes side by side.
fn check_frame(request: &AccumulateRequest) -> Result<(), RenderError> {
    let eyes = request.eyes.len() as u32;
    let [w, h] = request.eye_size;
    if eyes == 0 || eyes > STAT_EYES || request.frame.width != w * eyes || request.frame.height != h
    {
        return Err(RenderError::Settings(format!(
            "accumulate: a {}x{} frame is not {eyes} eye(s) of {w}x{h}",
            request.frame.width, request.frame.height
        )));
    }
    Ok(())
}

/// Each eye's push constants: its field of view, image and layers, the mean it goes into
/// and the frames already in it.
fn pushes(request: &AccumulateRequest, frames_before: u32) -> Vec<AccumulatePush> {
    let [w, h] = request.eye_size;
    request
        .eyes
        .iter()
        .enumerate()
        .map(|(e, eye)| AccumulatePush {
            cam: PushCamera {
                tan: [
                    eye.camera.angle_left.tan(),
                    eye.camera.angle_right.tan(),
                    eye.camera.angle_up.tan(),
                    eye.camera.angle_down.tan(),
                ],
                ..Default::default()
            },
            eye: PushEye {
                width: w,
                height: h,
                index: e as u32,
                layer_count: request.foveation.layers.len() as u32,
                debug: request.show.id(),
                ..Default::default()
            },
            mean_layer: request.into.layer(),
            frames_before,
            ..Default::default()
        })
        .collect()
}

/// What accumulate.comp's heat map reads of one eye's layers: the gaze direction, each
/// layer's radius and the occlusion radius as cosines, spacing and spp. The rest is unused.
fn gpu_layers(eye: &EyeView, size: [u32; 2], config: &FoveationConfig) -> Vec<GpuLayer> {
    let image = eye.image(size[0], size[1]);
    let (gaze_px, _) = eye.gaze.resolve(&image);
    let g = direction(image.tan_of(gaze_px[0], gaze_px[1]));
    let occlusion = config
        .occlusion_deg
        .map_or(f64::INFINITY, |o| (o as f64).to_radians());
    config
        .layers
        .iter()
        .map(|l| GpuLayer {
            gaze: [g[0] as f32, g[1] as f32, g[2] as f32, 0.0],
            resolve_cos: [
                cos_limit(
                    l.radius_deg
                        .map_or(f64::INFINITY, |r| (r as f64).to_radians()),
                ),
                0.0,
                cos_limit(occlusion),
                0.0,
            ],
            spacing: l.spacing as i32,
            spp: l.spp,
            ..Default::default()
        })
        .collect()
}
