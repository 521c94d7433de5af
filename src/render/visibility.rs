//! The lenses' visibility masks (OpenXR) on the GPU: hidden pixels are never traced, and
//! resolve makes them black. Plan and resolve read them as bit planes (BINDING_VISIBILITY).

use super::RenderError;
use crate::foveation::{FoveationConfig, VisibilityMask};
use crate::gpu::{Buffer, GpuContext};
use std::sync::Arc;

pub struct Visibility {
    /// Per eye, the lens's mask (eye order as in the frame's eyes; empty for none).
    masks: Vec<VisibilityMask>,
    /// The masks' bit planes, in shared.h's layout.
    pub buffer: Buffer,
    /// The eye size and layer spacings the planes were made for (`None`: no mask).
    key: Option<([u32; 2], Vec<u32>)>,
    /// The masks changed since the planes were made.
    stale: bool,
}

impl Visibility {
    pub fn new(ctx: &Arc<GpuContext>) -> Result<Self, RenderError> {
        Ok(Self {
            masks: Vec::new(),
            buffer: Buffer::with_data(ctx, "visibility mask", &0u32.to_le_bytes())?,
            key: None,
            stale: false,
        })
    }

    /// Sets each eye's mask; a mask applies to frames whose eye image has the mask's size.
    pub fn set_masks(&mut self, masks: Vec<VisibilityMask>) {
        self.masks = masks;
        self.stale = true;
    }

    /// The planes a frame of `eyes` eyes of `size` with `config`'s layers wants: per eye
    /// the shown pixels and each layer's needed lattice points when all eyes have a mask of
    /// the frame's size, else none.
    fn wanted(
        &self,
        eyes: usize,
        size: [u32; 2],
        config: &FoveationConfig,
    ) -> Option<([u32; 2], Vec<u32>)> {
        let applies = self.masks.len() >= eyes
            && self.masks[..eyes]
                .iter()
                .all(|m| [m.width, m.height] == size);
        let spacings = config.layers.iter().map(|l| l.spacing).collect();
        applies.then_some((size, spacings))
    }

    /// Whether the planes must be made again for such a frame (which replaces the buffer:
    /// no frame in flight may still read it).
    pub fn needs_upload(&self, eyes: usize, size: [u32; 2], config: &FoveationConfig) -> bool {
        self.stale || self.wanted(eyes, size, config) != self.key
    }

    /// Makes the planes for such a frame (no frame in flight reads the buffer).
    pub fn upload(
        &mut self,
        ctx: &Arc<GpuContext>,
        eyes: usize,
        size: [u32; 2],
        config: &FoveationConfig,
    ) -> Result<(), RenderError> {
        let wanted = self.wanted(eyes, size, config);
        // shared.h's layout: words per plane (0: no mask), then each eye's planes.
        let words: Vec<u32> = match &wanted {
            Some((size, spacings)) => {
                let per_plane = (size[0] as usize * size[1] as usize).div_ceil(32) as u32;
                let mut words = vec![per_plane];
                for mask in &mut self.masks[..eyes] {
                    words.extend(mask.bits());
                    for &d in spacings {
                        words.extend(mask.needed_bits(d));
                    }
                }
                words
            }
            None => vec![0],
        };
        self.buffer = Buffer::with_data(ctx, "visibility mask", bytemuck::cast_slice(&words))?;
        self.key = wanted;
        self.stale = false;
        Ok(())
    }
}
