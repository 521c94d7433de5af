//! GPU resources of one (layer config, resolution, eyes' fields of view): per eye, a lattice
//! value for every entry of the ray buffer (the layers at lattice resolution) and a work list
//! as long; the resolved pixels (and, for whoever presents or accumulates frames, an image
//! they are copied into); and the small host-visible buffer of layer parameters the CPU
//! rewrites every frame.

use super::eye_params::{EyeLayers, EyeStrides};
use super::settings::MAX_SIDE;
use super::slots::MAX_FRAMES_IN_FLIGHT;
use super::trace_lanes::{lane_unit, TraceLanes};
use super::RenderError;
use crate::foveation::{EyeFov, EyePlan, FoveationConfig, ImageGeometry, RayBuffer};
use crate::gpu::{vk, Buffer, EyeTexels, GpuContext, PlannedAllocation, StorageImage, TexelView};
use crate::shader_layout::{
    GpuLayer, MAX_GROUPS_X, PLAN_RUN, PLAN_WORKGROUP_SIZE, WORK_LAYER_SHIFT,
};
use gpu_allocator::MemoryLocation;
use std::sync::Arc;

/// What the targets were built for; a frame asking for anything else rebuilds them.
#[derive(Clone, Debug, PartialEq)]
pub struct TargetKey {
    pub config: FoveationConfig,
    pub width: u32,
    pub height: u32,
    pub fovs: Vec<EyeFov>,
    /// Whether frames also land in an image (`FrameTargets::output`).
    pub image: bool,
    /// How many trace threads each layer's points get (`FrameTargets::layer_lanes`).
    pub lanes: TraceLanes,
}

pub struct FrameTargets {
    pub key: TargetKey,
    pub buffer: RayBuffer,
    pub images: Vec<ImageGeometry>,
    /// Trace threads per point of each layer (GpuLayer::lanes): `key.lanes`' rule for the
    /// points each layer traces with the gaze ahead.
    pub layer_lanes: Vec<u32>,
    /// Where each eye's part of the lattice and the work lists starts (EyePush): lattice
    /// entries, the ray buffer's rounded up to where a texel view may start
    /// (`EyeTexels::stride`), and work-list slots (`work_slots`; checked to fit a u32).
    pub strides: EyeStrides,
    /// `vec4` per lattice point, eye after eye (shared.h's BINDING_LATTICE).
    pub lattice: Buffer,
    /// The same values as texels, one view per eye, which is how resolve reads them
    /// (BINDING_LATTICE_TEXELS).
    pub lattice_texels: EyeTexels,
    /// The plan pass's work lists, eye after eye (BINDING_WORK).
    pub work: Buffer,
    /// The resolved frame: RGBA f32, eye after eye, rows of `key.width` (BINDING_PIXELS).
    pub pixels: Buffer,
    /// The same as texels, which is how the denoiser reads them (BINDING_DENOISE_INPUT).
    pub pixels_texels: TexelView,
    /// The frame as an image, eyes side by side, when `key.image`: copied from `pixels` at
    /// the end of every frame.
    pub output: Option<StorageImage>,
    /// Per frame slot, the frame's layers, every eye's (BINDING_LAYERS), and each eye's plan
    /// dispatch (workgroup counts): host-visible, written with the gaze right before
    /// submission, into the slot's part so that frames in flight keep theirs.
    pub layers: Buffer,
    pub plan_dispatch: Buffer,
}

fn host_buffer(ctx: &Arc<GpuContext>, name: &str, bytes: u64) -> Result<Buffer, RenderError> {
    Ok(Buffer::new(
        ctx,
        name,
        bytes.max(16),
        vk::BufferUsageFlags::STORAGE_BUFFER,
        MemoryLocation::CpuToGpu,
    )?)
}

/// What to change when a frame's targets do not fit the device.
const ADVICE: &str = "use a smaller --width/--height, mono instead of --stereo, or fewer \
     layers (a layer anchored at the gaze keeps a lattice value for every offset a gaze anywhere \
     on the image could need, up to 4 per pixel for a wide one at spacing 1: a smaller \
     radius_deg or a larger spacing needs fewer)";

impl TargetKey {
    /// The frame these targets are for, for messages: "the frame targets of a 512x512 stereo
    /// frame with 4 layers".
    pub fn describe(&self) -> String {
        let eyes = match self.fovs.len() {
            1 => "mono".to_owned(),
            2 => "stereo".to_owned(),
            n => format!("{n}-eye"),
        };
        let layers = self.config.layers.len();
        format!(
            "the frame targets of a {}x{} {eyes} frame with {layers} layer{}",
            self.width,
            self.height,
            if layers == 1 { "" } else { "s" }
        )
    }

    /// Every allocation of [`FrameTargets::new`] but the lattice buffers (whose size is
    /// known only once the ray buffer is built), plus the read-back of the frame: cheap to
    /// compute, so a frame far too large for the device is refused before anything is built.
    pub fn image_plan(&self) -> Vec<PlannedAllocation> {
        let (w, h) = (self.width as u64, self.height as u64);
        let eyes = self.fovs.len() as u64;
        let layers = self.config.layers.len() as u64;
        let slots = MAX_FRAMES_IN_FLIGHT as u64;
        let texel = 16; // RGBA32F, StorageImage::FORMAT
        let mut plan = vec![
            PlannedAllocation::storage_with_texels("frame pixels", w * eyes * h * texel),
            PlannedAllocation::host("frame read-back", w * eyes * h * texel, false),
            PlannedAllocation::host(
                "frame layers",
                slots * eyes * layers * std::mem::size_of::<GpuLayer>() as u64,
                true,
            ),
            PlannedAllocation::host("plan dispatch", slots * eyes * PLAN_DISPATCH_BYTES, false),
        ];
        if self.image {
            plan.push(PlannedAllocation::image(
                "frame image",
                w * eyes * h * texel,
            ));
        }
        plan
    }

    /// Checks that the eyes' lattice points (`stride` entries apart) can be addressed by a
    /// work list, that `work_slots` (all eyes') can be indexed, and that their buffers fit the
    /// device beside the images: each eye's texel view holds one eye's points.
    fn check_lattice(
        &self,
        ctx: &GpuContext,
        stride: u64,
        work_slots: u64,
    ) -> Result<(), RenderError> {
        let entries = self.fovs.len() as u64 * stride;
        if entries >= 1 << WORK_LAYER_SHIFT {
            return Err(RenderError::Settings(format!(
                "{} need {entries} lattice points, more than a work list can address (2^{WORK_LAYER_SHIFT}); {ADVICE}",
                self.describe()
            )));
        }
        if work_slots > u32::MAX as u64 {
            return Err(RenderError::Settings(format!(
                "{} need {work_slots} work-list slots (lattice points times their trace \
                 lanes), more than a 32-bit index reaches; use a smaller --trace-split or \
                 {ADVICE}",
                self.describe()
            )));
        }
        let plan = self.lattice_plan(stride, work_slots);
        Ok(ctx.check_memory(&self.describe(), &plan, ADVICE)?)
    }

    /// Every allocation of [`FrameTargets::new`]: the images' and the eyes' lattice values
    /// (`stride` entries apart, read through one texel view per eye) and work lists.
    fn lattice_plan(&self, stride: u64, work_slots: u64) -> Vec<PlannedAllocation> {
        let entries = self.fovs.len() as u64 * stride;
        let mut plan = self.image_plan();
        plan.push(PlannedAllocation::storage_with_views(
            "lattice values",
            entries * 16,
            stride * 16,
        ));
        plan.push(PlannedAllocation::storage("work lists", work_slots * 4));
        plan
    }

    /// Checks that the targets' images fit the device beside what fovea already holds.
    pub fn check_images(&self, ctx: &GpuContext) -> Result<(), RenderError> {
        Ok(ctx.check_memory(&self.describe(), &self.image_plan(), ADVICE)?)
    }
}

impl FrameTargets {
    /// Builds the ray buffer, checks that everything fits the device (sizes, per-buffer and
    /// per-allocation limits) and only then allocates.
    pub fn new(ctx: &Arc<GpuContext>, key: TargetKey) -> Result<Self, RenderError> {
        key.check_images(ctx)?;
        let images: Vec<ImageGeometry> = key
            .fovs
            .iter()
            .map(|f| ImageGeometry::new(key.width, key.height, *f))
            .collect();
        let buffer = RayBuffer::build(&key.config, &images);
        let layer_lanes = layer_lanes(&key.lanes, &buffer, &images);
        let work_stride = work_slots(&buffer, &layer_lanes);
        let eyes = images.len() as u64;
        let alignment = ctx.info.min_texel_buffer_offset_alignment;
        let lattice_stride = EyeTexels::stride(buffer.offsets.len() as u64, alignment);
        key.check_lattice(ctx, lattice_stride, eyes * work_stride)?;
        let lattice = Buffer::new(
            ctx,
            "lattice values",
            eyes * lattice_stride * 16,
            vk::BufferUsageFlags::STORAGE_BUFFER
                | vk::BufferUsageFlags::UNIFORM_TEXEL_BUFFER
                | vk::BufferUsageFlags::TRANSFER_DST,
            MemoryLocation::GpuOnly,
        )?;
        let lattice_texels = EyeTexels::of_frame(&lattice, "lattice values", eyes, lattice_stride)?;
        let work = Buffer::new(
            ctx,
            "work lists",
            eyes * work_stride * 4,
            vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::TRANSFER_DST,
            MemoryLocation::GpuOnly,
        )?;
        let pixels = Buffer::new(
            ctx,
            "frame pixels",
            eyes * key.width as u64 * key.height as u64 * 16,
            // TRANSFER_DST: the denoiser's last iteration may be copied back into it.
            vk::BufferUsageFlags::STORAGE_BUFFER
                | vk::BufferUsageFlags::UNIFORM_TEXEL_BUFFER
                | vk::BufferUsageFlags::TRANSFER_SRC
                | vk::BufferUsageFlags::TRANSFER_DST,
            MemoryLocation::GpuOnly,
        )?;
        let pixels_texels = TexelView::of_frame(&pixels, "frame pixels")?;
        let output = match key.image {
            true => Some(StorageImage::new(
                ctx,
                "frame",
                key.width * eyes as u32,
                key.height,
            )?),
            false => None,
        };
        let (layers, plan_dispatch) = slot_buffers(ctx, eyes, buffer.layers.len() as u64)?;
        Ok(Self {
            key,
            buffer,
            images,
            layer_lanes,
            strides: EyeStrides {
                lattice: lattice_stride as u32,
                work: work_stride as u32,
            },
            lattice,
            lattice_texels,
            work,
            pixels,
            pixels_texels,
            output,
            layers,
            plan_dispatch,
        })
    }

    #[cfg(any(test, feature = "test-hooks"))]
    /// Puts `lattice` (made with UNIFORM_TEXEL_BUFFER usage; eye after eye, `lattice_len()`
    /// entries apart) in place of the lattice values, and its texel views in place of theirs.
    pub fn replace_lattice(&mut self, lattice: Buffer) -> Result<(), RenderError> {
        let eyes = self.images.len() as u64;
        self.lattice_texels =
            EyeTexels::of_frame(&lattice, "lattice values", eyes, self.lattice_len() as u64)?;
        self.lattice = lattice;
        Ok(())
    }

    /// Writes frame slot `slot`'s layer parameters (every eye's, eye after eye) and each
    /// eye's plan dispatch for its `plan_runs()` threads.
    pub fn write_layers(&mut self, slot: usize, eyes: &[EyeLayers]) -> Result<(), RenderError> {
        let layers: Vec<GpuLayer> = eyes.iter().flat_map(|e| e.layers.iter().copied()).collect();
        let at = self.layer_base(slot) as usize * std::mem::size_of::<GpuLayer>();
        self.layers.write(at, bytemuck::cast_slice(&layers))?;
        let dispatch: Vec<[u32; 4]> = eyes
            .iter()
            .map(|e| {
                let [x, y, z] = groups_1d(e.plan_runs() as u64, PLAN_WORKGROUP_SIZE);
                [x, y, z, 0]
            })
            .collect();
        self.plan_dispatch.write(
            self.plan_dispatch_offset(slot, 0) as usize,
            bytemuck::cast_slice(&dispatch),
        )?;
        Ok(())
    }

    /// The most trace lanes of a layer (`trace_lanes::lane_unit`).
    pub fn lane_unit(&self) -> u32 {
        lane_unit(&self.layer_lanes)
    }

    /// Frame slot `slot`'s first entry of the layer buffer (PushEye::layer_base).
    pub fn layer_base(&self, slot: usize) -> u32 {
        (slot * self.key.fovs.len() * self.buffer.layers.len()) as u32
    }

    /// Byte offset of eye `eye`'s plan dispatch of frame slot `slot`.
    pub fn plan_dispatch_offset(&self, slot: usize, eye: usize) -> u64 {
        (slot * self.key.fovs.len() + eye) as u64 * PLAN_DISPATCH_BYTES
    }

    /// The resolved frame on the host: linear RGB, eyes side by side, row-major.
    pub fn read_pixels(&self) -> Result<Vec<f32>, RenderError> {
        let rgba: Vec<f32> = bytemuck::pod_collect_to_vec(&self.pixels.read_back()?);
        let (w, h) = (self.key.width as usize, self.key.height as usize);
        let eyes = self.key.fovs.len();
        let mut rgb = Vec::with_capacity(w * h * eyes * 3);
        for y in 0..h {
            for e in 0..eyes {
                let row = &rgba[(e * h + y) * w * 4..][..w * 4];
                rgb.extend(row.chunks_exact(4).flat_map(|p| [p[0], p[1], p[2]]));
            }
        }
        Ok(rgb)
    }

    /// Entries from one eye's lattice points to the next: the ray buffer's entries, and
    /// padding up to where a texel view may start (`EyeTexels::stride`).
    pub fn lattice_len(&self) -> usize {
        self.strides.lattice as usize
    }
}

/// The current frame targets, and the ones used before them, kept so that alternating
/// between two configs (regular and foveated frames of a bench) does not rebuild the ray
/// buffer and reallocate the images every frame.
#[derive(Default)]
pub struct TargetCache {
    current: Option<FrameTargets>,
    spare: Option<FrameTargets>,
}

impl TargetCache {
    /// Whether the current targets are `key`'s.
    pub fn holds(&self, key: &TargetKey) -> bool {
        self.current.as_ref().is_some_and(|t| t.key == *key)
    }

    /// Makes `key`'s targets current: the spare ones if they are, else new ones (no frame in
    /// flight may use the current ones).
    pub fn switch(&mut self, ctx: &Arc<GpuContext>, key: TargetKey) -> Result<(), RenderError> {
        if self.spare.as_ref().is_some_and(|t| t.key == key) {
            std::mem::swap(&mut self.current, &mut self.spare);
            return Ok(());
        }
        // Make room before anything is built: drop the spare targets, then the current ones,
        // if the new ones would not fit beside them; if they still do not, say why (sizes).
        if key.check_images(ctx).is_err() {
            self.spare = None;
        }
        if key.check_images(ctx).is_err() {
            self.current = None;
        }
        key.check_images(ctx)?;
        let eyes = key.fovs.len() as u64;
        if key.width as u64 * eyes > MAX_SIDE as u64 {
            return Err(RenderError::Settings(format!(
                "{eyes} eyes of width {} do not fit one {MAX_SIDE}-pixel-wide image; use a \
                 smaller --width",
                key.width
            )));
        }
        self.spare = self.current.take();
        self.current = Some(FrameTargets::new(ctx, key)?);
        Ok(())
    }

    /// The current targets, if a frame made any.
    pub fn current(&self) -> Option<&FrameTargets> {
        self.current.as_ref()
    }

    pub fn current_mut(&mut self) -> Option<&mut FrameTargets> {
        self.current.as_mut()
    }
}

/// Work-list slots one eye may fill: each lattice point of layer k traced in `lanes[k]` slots
/// (or filled from a neighbour, in one slot from the list's top: never both), and each plan
/// run's reservation padded by at most `unit - lanes[k]` to a multiple of the most lanes
/// (glsl/plan.comp; lanes are powers of two, so the padding is that at most).
fn work_slots(buffer: &RayBuffer, lanes: &[u32]) -> u64 {
    let unit = lane_unit(lanes) as u64;
    buffer
        .layers
        .iter()
        .zip(lanes)
        .map(|(l, &lanes)| {
            let runs = (l.cols() as u64).div_ceil(PLAN_RUN as u64) * l.rows() as u64;
            l.len() as u64 * lanes as u64 + runs * (unit - lanes as u64)
        })
        .sum()
}

/// `lanes`' rule for the layers of `buffer`: its filling counts the points each layer traces
/// with the gaze ahead, in the eye that traces most.
fn layer_lanes(lanes: &TraceLanes, buffer: &RayBuffer, images: &[ImageGeometry]) -> Vec<u32> {
    let spp: Vec<u32> = buffer.layers.iter().map(|l| l.spp).collect();
    let mut points = vec![0u64; spp.len()];
    if lanes.fill_threads > 0 {
        for image in images {
            let ahead = [image.width as f64 / 2.0, image.height as f64 / 2.0];
            let plan = EyePlan::new(buffer, image, ahead);
            for (p, layer) in points.iter_mut().zip(&plan.layers) {
                *p = (*p).max(layer.targets);
            }
        }
    }
    lanes.of_layers(&spp, &points)
}

/// Bytes of one eye's plan dispatch in `FrameTargets::plan_dispatch` (VkDispatchIndirectCommand
/// and a pad).
const PLAN_DISPATCH_BYTES: u64 = 16;

/// Workgroups for `threads` threads of a 1D pass: x up to the guaranteed limit, then rows.
fn groups_1d(threads: u64, workgroup: u32) -> [u32; 3] {
    let groups = threads.div_ceil(workgroup as u64);
    let x = groups.min(MAX_GROUPS_X as u64);
    [x as u32, groups.div_ceil(x.max(1)) as u32, 1]
}

/// Per frame slot, every eye's layers and plan dispatches (host-visible, written right
/// before each submission).
fn slot_buffers(
    ctx: &Arc<GpuContext>,
    eyes: u64,
    layers: u64,
) -> Result<(Buffer, Buffer), RenderError> {
    let slots = MAX_FRAMES_IN_FLIGHT as u64;
    let layer_bytes = std::mem::size_of::<GpuLayer>() as u64;
    let layers = host_buffer(ctx, "frame layers", slots * eyes * layers * layer_bytes)?;
    let plan_dispatch = Buffer::new(
        ctx,
        "plan dispatch",
        slots * eyes * PLAN_DISPATCH_BYTES,
        vk::BufferUsageFlags::INDIRECT_BUFFER,
        MemoryLocation::CpuToGpu,
    )?;
    Ok((layers, plan_dispatch))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::foveation::EyeFov;

    /// Every lattice point traced, in the plan pass's runs of PLAN_RUN points per box row,
    /// each reservation padded to the most lanes: the most a frame can put in a work list.
    fn every_point_traced(buffer: &RayBuffer, lanes: &[u32]) -> u64 {
        let unit = *lanes.iter().max().unwrap() as u64;
        let mut slots = 0;
        for (l, &lanes) in buffer.layers.iter().zip(lanes) {
            for _row in 0..l.rows() {
                let mut left = l.cols() as u64;
                while left > 0 {
                    let run = left.min(PLAN_RUN as u64);
                    slots += (run * lanes as u64).div_ceil(unit) * unit;
                    left -= run;
                }
            }
        }
        slots
    }

    #[test]
    fn each_eyes_lattice_values_are_one_texel_view() {
        let key = TargetKey {
            config: FoveationConfig::thesis(),
            width: 64,
            height: 48,
            fovs: vec![EyeFov::VIVE_PRO_EYE_LEFT; 2],
            image: false,
            lanes: TraceLanes::ONE,
        };
        let plan = key.lattice_plan(1000, 5000);
        let lattice = plan.iter().find(|p| p.name == "lattice values").unwrap();
        assert_eq!(lattice.bytes, 2 * 1000 * 16, "both eyes' entries");
        assert_eq!(lattice.texel_view, Some(1000 * 16), "one view per eye");
        // Parts start where a view may: whole entries for lavapipe's and NVIDIA's 16 bytes,
        // rounded up to 16 entries for the most any device may ask (256 bytes).
        assert_eq!(EyeTexels::stride(1001, 16), 1001);
        assert_eq!(EyeTexels::stride(1001, 4), 1001);
        assert_eq!(EyeTexels::stride(1001, 256), 1008);
    }

    #[test]
    fn work_lists_hold_every_point_with_its_lanes_and_padding_and_no_more_than_that() {
        let mut config = FoveationConfig::thesis();
        config.layers[0].spp = 64;
        let image = ImageGeometry::new(200, 180, EyeFov::VIVE_PRO_EYE_LEFT);
        let buffer = RayBuffer::build(&config, &[image]);
        let entries = buffer.offsets.len() as u64;
        for lanes in [vec![1, 1, 1, 1], vec![16, 4, 4, 1], vec![16, 1, 1, 1]] {
            let worst = every_point_traced(&buffer, &lanes);
            let slots = work_slots(&buffer, &lanes);
            assert!(
                worst <= slots,
                "{lanes:?}: {worst} slots used, {slots} held"
            );
            let unit = *lanes.iter().max().unwrap() as u64;
            assert!(
                slots <= entries * unit,
                "{lanes:?}: more than every point at the most lanes"
            );
            if lanes == [1, 1, 1, 1] {
                assert_eq!(slots, entries, "one lane: one slot a point");
            }
        }
        // A fovea of 16 lanes in a background of one: far fewer slots than every point at 16.
        let mixed = work_slots(&buffer, &[16, 1, 1, 1]);
        assert!(mixed * 2 < entries * 16, "{mixed} of {}", entries * 16);
    }
}
