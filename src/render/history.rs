//! Temporal history (glsl/temporal.comp): per eye and pixel, the mean and count of the
//! samples traced at that pixel over the frames, and the surface they belong to, in two
//! planes that frames take turns reading and writing; the lattice points' surfaces the trace
//! writes for it; and, per frame slot and eye, the view of the frame before (its camera,
//! whether the camera moved), written with the gaze right before submission; the denoiser's
//! second buffer of pixels and the lattice filter's values, which both follow the history's
//! surfaces. The history's frame count also shifts the sparse layers' lattices
//! (`lattice_shift`).

use super::slots::MAX_FRAMES_IN_FLIGHT;
use super::RenderError;
use crate::gpu::{vk, Buffer, EyeTexels, GpuContext, PlannedAllocation, TexelView};
use crate::shader_layout::{
    GpuHistoryView, PushCamera, ALBEDO_CARRIED, ALBEDO_DIVIDED, ALBEDO_MOMENTS_CARRIED, ALBEDO_ON,
    HISTORY_ON, STAT_EYES,
};
use gpu_allocator::MemoryLocation;
use std::sync::Arc;

/// How history is kept (`Renderer::set_temporal`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TemporalSettings {
    /// While the camera moves, a pixel's history counts at most this many samples: beyond
    /// it, new samples are blended in exponentially, so history follows what changed (view-
    /// dependent shading, resampling blur) within about `cap / spp` frames. A still camera
    /// is never capped: its history is the plain mean of every sample.
    pub cap: u32,
}

impl Default for TemporalSettings {
    fn default() -> Self {
        Self { cap: 64 }
    }
}

/// What the history's buffers were made for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct HistoryKey {
    pub width: u32,
    pub height: u32,
    pub eyes: u32,
    /// Entries from one eye's lattice points to the next (`FrameTargets::lattice_len`).
    pub lattice_len: u64,
}

impl HistoryKey {
    /// Every allocation of [`History::new`], for the memory check before it (all but the
    /// views and the albedos are also read through texel views).
    pub fn allocations(&self) -> Vec<PlannedAllocation> {
        let plane = self.width as u64 * self.height as u64 * self.eyes as u64 * 16;
        // Read through one texel view per eye (EyeTexels).
        let eye_lattice = self.lattice_len * 16;
        let lattice = self.eyes as u64 * eye_lattice;
        vec![
            PlannedAllocation::storage_with_texels("history plane 0", plane),
            PlannedAllocation::storage_with_texels("history plane 1", plane),
            PlannedAllocation::storage_with_texels("history surfaces plane 0", plane),
            PlannedAllocation::storage_with_texels("history surfaces plane 1", plane),
            PlannedAllocation::storage_with_views("lattice surfaces", lattice, eye_lattice),
            PlannedAllocation::host("history views", views_bytes(), true),
            PlannedAllocation::storage_with_texels("denoiser pixels", plane),
            PlannedAllocation::storage_with_views("filtered lattice values", lattice, eye_lattice),
            PlannedAllocation::storage("lattice albedos", self.eyes as u64 * self.lattice_len * 4),
            PlannedAllocation::storage("history albedos plane 0", plane / 16 * GUIDE_BYTES),
            PlannedAllocation::storage("history albedos plane 1", plane / 16 * GUIDE_BYTES),
        ]
    }
}

/// Bytes a pixel of a history albedo plane: bindings.glsl's HistoryGuide (the packed albedo
/// and the two moments of the illumination's luminance, three 4-byte words).
const GUIDE_BYTES: u64 = 12;

/// A frame that keeps albedos (`albedo` has ALBEDO_ON) carries the pixels' albedos only when
/// the frame before kept them (`before`, its albedo word, has ALBEDO_ON): else its albedo
/// plane holds another frame's, or nothing, and temporal starts afresh from this frame's. So
/// with the illumination's moments, which temporal keeps only while a layer denoises
/// (ALBEDO_DIVIDED).
fn albedo_word(albedo: u32, before: u32) -> u32 {
    let both = |bit: u32| albedo & before & bit != 0;
    let carried = if both(ALBEDO_ON) { ALBEDO_CARRIED } else { 0 };
    let moments = if both(ALBEDO_DIVIDED) {
        ALBEDO_MOMENTS_CARRIED
    } else {
        0
    };
    albedo | carried | moments
}

fn views_bytes() -> u64 {
    (MAX_FRAMES_IN_FLIGHT * STAT_EYES as usize * std::mem::size_of::<GpuHistoryView>()) as u64
}

pub struct History {
    pub key: HistoryKey,
    pub settings: TemporalSettings,
    /// Two planes of every eye's pixels' history and surfaces: a frame writes one
    /// (BINDING_HISTORY, BINDING_HISTORY_SURFACE) and reads the other as texels
    /// (BINDING_HISTORY_TEXELS, BINDING_SURFACE_TEXELS); the denoiser reads the surfaces it
    /// wrote as texels.
    pub pixels: [Buffer; 2],
    pub pixel_texels: [TexelView; 2],
    pub surfaces: [Buffer; 2],
    pub surface_texels: [TexelView; 2],
    /// BINDING_LATTICE_SURFACE: the surface at every lattice point traced this frame, and the
    /// same as texels, which is how temporal and the lattice filter read them
    /// (BINDING_LATTICE_SURFACE_TEXELS).
    pub lattice_surfaces: Buffer,
    pub lattice_surface_texels: EyeTexels,
    /// BINDING_HISTORY_VIEWS: per frame slot and eye.
    pub views: Buffer,
    /// BINDING_DENOISE: the denoiser's second buffer of pixels (it ping-pongs with the
    /// frame's), and the same as texels, which is how the iteration after reads it
    /// (BINDING_DENOISE_INPUT).
    pub denoise: Buffer,
    pub denoise_texels: TexelView,
    /// BINDING_LATTICE_FILTERED: the lattice filter's values (in the lattice's layout), and
    /// the same as texels, which resolve then reads in place of the traced values.
    pub filtered: Buffer,
    pub filtered_texels: EyeTexels,
    /// BINDING_LATTICE_ALBEDO: the albedo at every lattice point traced this frame, while a
    /// layer denoises.
    pub lattice_albedos: Buffer,
    /// BINDING_HISTORY_ALBEDO: two planes of every pixel's mean albedo over its history and
    /// the moments of its illumination (the denoiser's noise estimate), while albedos are
    /// kept; a frame writes one and reads the other (BINDING_ALBEDO_BEFORE), and the denoiser
    /// reads the one it wrote.
    pub albedos: [Buffer; 2],
    /// The frame before's albedo word (ALBEDO_ON, ALBEDO_DIVIDED): a frame carries the albedos
    /// and moments it kept (`albedo_word`).
    albedo_before: u32,
    /// Frames added since the history started (the lattice shift's frame).
    frame: u32,
    /// The plane the next frame reads (the one the frame before wrote).
    read_plane: u32,
    /// Every eye's camera in the frame before; None: no history to carry.
    cameras: Option<Vec<PushCamera>>,
}

impl History {
    pub fn new(
        ctx: &Arc<GpuContext>,
        key: HistoryKey,
        settings: TemporalSettings,
    ) -> Result<Self, RenderError> {
        ctx.check_memory(
            &format!(
                "the temporal history of {}x{} pixels",
                key.width, key.height
            ),
            &key.allocations(),
            "turn --temporal off or use a smaller --width/--height",
        )?;
        let device = |name: &str, bytes: u64| {
            Buffer::new(
                ctx,
                name,
                bytes,
                vk::BufferUsageFlags::STORAGE_BUFFER,
                MemoryLocation::GpuOnly,
            )
        };
        let plan = key.allocations();
        // Buffers also read through texel views: a whole pixel plane's view (temporal, the
        // denoiser), or one view per eye of the lattice's (temporal, the lattice filter,
        // resolve).
        let texel_buffer = |item: &PlannedAllocation, usage: vk::BufferUsageFlags| {
            let usage = vk::BufferUsageFlags::STORAGE_BUFFER
                | vk::BufferUsageFlags::UNIFORM_TEXEL_BUFFER
                | usage;
            Buffer::new(ctx, &item.name, item.bytes, usage, MemoryLocation::GpuOnly)
        };
        let plane = |item: &PlannedAllocation, usage: vk::BufferUsageFlags| {
            let buffer = texel_buffer(item, usage)?;
            let texels = TexelView::of_frame(&buffer, &item.name)?;
            Ok::<_, RenderError>((buffer, texels))
        };
        let (eyes, stride) = (key.eyes as u64, key.lattice_len);
        let per_eye = |item: &PlannedAllocation| {
            let buffer = texel_buffer(item, vk::BufferUsageFlags::empty())?;
            let texels = EyeTexels::of_frame(&buffer, &item.name, eyes, stride)?;
            Ok::<_, RenderError>((buffer, texels))
        };
        let none = vk::BufferUsageFlags::empty();
        let (pixels0, pixel_texels0) = plane(&plan[0], none)?;
        let (pixels1, pixel_texels1) = plane(&plan[1], none)?;
        let (surfaces0, surface_texels0) = plane(&plan[2], none)?;
        let (surfaces1, surface_texels1) = plane(&plan[3], none)?;
        let (lattice_surfaces, lattice_surface_texels) = per_eye(&plan[4])?;
        let (denoise, denoise_texels) = plane(&plan[6], vk::BufferUsageFlags::TRANSFER_SRC)?;
        let (filtered, filtered_texels) = per_eye(&plan[7])?;
        Ok(Self {
            key,
            settings,
            pixels: [pixels0, pixels1],
            pixel_texels: [pixel_texels0, pixel_texels1],
            surfaces: [surfaces0, surfaces1],
            surface_texels: [surface_texels0, surface_texels1],
            lattice_surfaces,
            lattice_surface_texels,
            views: Buffer::new(
                ctx,
                "history views",
                views_bytes(),
                vk::BufferUsageFlags::STORAGE_BUFFER,
                MemoryLocation::CpuToGpu,
            )?,
            denoise,
            denoise_texels,
            filtered,
            filtered_texels,
            lattice_albedos: device(&plan[8].name, plan[8].bytes)?,
            albedos: [
                device(&plan[9].name, plan[9].bytes)?,
                device(&plan[10].name, plan[10].bytes)?,
            ],
            albedo_before: 0,
            frame: 0,
            read_plane: 0,
            cameras: None,
        })
    }

    /// Forgets everything accumulated: the next frame starts afresh (and unshifted).
    pub fn reset(&mut self) {
        self.frame = 0;
        self.albedo_before = 0;
        self.cameras = None;
    }

    /// The lattice shift's frame for the next frame.
    pub fn frame(&self) -> u32 {
        self.frame
    }

    /// The plane a frame with PushEye::history `push_word` reads (the frame before wrote it),
    /// and the one it writes (temporal writes it, the denoiser reads its surfaces).
    pub fn read_plane(push_word: u32) -> usize {
        ((push_word >> 1) & 1) as usize
    }

    pub fn written_plane(push_word: u32) -> usize {
        1 - Self::read_plane(push_word)
    }

    /// PushEye::history of the next frame, submitted in frame slot `slot`.
    pub fn push_word(&self, slot: usize) -> u32 {
        HISTORY_ON | self.read_plane << 1 | (slot as u32) << 2
    }

    /// EyePush::albedo of the next frame, whose own is `albedo` (ALBEDO_ON while a layer
    /// denoises).
    pub fn albedo_word(&self, albedo: u32) -> u32 {
        albedo_word(albedo, self.albedo_before)
    }

    /// Writes slot `slot`'s views for the next frame, whose eyes' cameras are `cameras` and
    /// whose albedo word (ALBEDO_ON, ALBEDO_DIVIDED: what it keeps) is `albedo`, and moves on to the frame after it
    /// (called once per submitted frame, in order).
    pub fn advance(
        &mut self,
        slot: usize,
        cameras: &[PushCamera],
        albedo: u32,
    ) -> Result<(), RenderError> {
        let now = cameras.to_vec();
        let views: Vec<GpuHistoryView> = now
            .iter()
            .enumerate()
            .map(|(e, camera)| {
                let before = self.cameras.as_ref().and_then(|c| c.get(e));
                let PushCamera {
                    position,
                    right,
                    up,
                    forward,
                    tan,
                } = *before.unwrap_or(camera);
                GpuHistoryView {
                    position,
                    right,
                    up,
                    forward,
                    tan,
                    valid: before.is_some() as u32,
                    moved: before.is_some_and(|b| b != camera) as u32,
                    cap: self.settings.cap,
                    pad0: 0,
                }
            })
            .collect();
        let at = slot * STAT_EYES as usize * std::mem::size_of::<GpuHistoryView>();
        self.views.write(at, bytemuck::cast_slice(&views))?;
        self.cameras = Some(now);
        self.albedo_before = albedo & (ALBEDO_ON | ALBEDO_DIVIDED);
        self.read_plane = 1 - self.read_plane;
        self.frame = self.frame.wrapping_add(1);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two eyes of 64x48 pixels, 1000 lattice entries each.
    fn stereo_key() -> HistoryKey {
        HistoryKey {
            width: 64,
            height: 48,
            eyes: 2,
            lattice_len: 1000,
        }
    }

    #[test]
    fn albedos_are_carried_only_from_a_frame_that_kept_them() {
        assert_eq!(
            albedo_word(ALBEDO_ON, ALBEDO_ON),
            ALBEDO_ON | ALBEDO_CARRIED
        );
        assert_eq!(albedo_word(ALBEDO_ON, 0), ALBEDO_ON);
        assert_eq!(
            albedo_word(0, ALBEDO_ON),
            0,
            "a frame that keeps none carries none"
        );
        assert_eq!(albedo_word(0, 0), 0);
    }

    #[test]
    fn moments_are_carried_only_between_frames_that_divide() {
        let divides = ALBEDO_ON | ALBEDO_DIVIDED;
        let carried = ALBEDO_CARRIED | ALBEDO_MOMENTS_CARRIED;
        assert_eq!(albedo_word(divides, divides), divides | carried);
        assert_eq!(
            albedo_word(divides, ALBEDO_ON),
            divides | ALBEDO_CARRIED,
            "the frame before kept albedos but no moments"
        );
        assert_eq!(
            albedo_word(ALBEDO_ON, divides),
            ALBEDO_ON | ALBEDO_CARRIED,
            "a frame that does not divide keeps no moments"
        );
    }

    #[test]
    fn the_albedo_planes_hold_three_words_a_pixel() {
        let plan = stereo_key().allocations();
        let bytes = |name: &str| plan.iter().find(|p| p.name == name).unwrap().bytes;
        for name in ["history albedos plane 0", "history albedos plane 1"] {
            assert_eq!(
                bytes(name),
                64 * 48 * 2 * 12,
                "{name}: a HistoryGuide (albedo, two moments) per pixel of each eye"
            );
        }
        // A history plane's vec4 is 16 bytes a pixel.
        assert_eq!(
            12 * bytes("history plane 0"),
            16 * bytes("history albedos plane 0")
        );
    }

    #[test]
    fn the_lattice_buffers_are_read_one_eye_at_a_time() {
        let plan = stereo_key().allocations();
        for name in ["lattice surfaces", "filtered lattice values"] {
            let item = plan.iter().find(|p| p.name == name).unwrap();
            assert_eq!(item.bytes, 2 * 1000 * 16, "{name}: both eyes' entries");
            assert_eq!(item.texel_view, Some(1000 * 16), "{name}: one view per eye");
        }
        let plane = plan.iter().find(|p| p.name == "history plane 0").unwrap();
        assert_eq!(
            plane.texel_view,
            Some(plane.bytes),
            "a plane: one view of all of it"
        );
    }
}
