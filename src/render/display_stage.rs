//! The display transform on the GPU (glsl/display.comp): the frame image (scene-referred)
//! through exposure and the tone mapper into an image of its own, which the window or the
//! headset's swapchains show. The frame image stays scene-referred, so screenshots, the
//! running mean and EXRs are unchanged. Not needed for `clamp` at exposure 0: the blits into
//! the sRGB swapchains clip just the same.

use super::display::{DisplayTransform, Tonemap};
use super::graph::FrameGraph;
use super::RenderError;
use crate::gpu::{shaders, ComputePipeline, GpuContext, PipelineLayout, StorageImage};
use crate::shader_layout::*;
use std::sync::Arc;

/// The pass and the image it writes.
pub struct DisplayStage {
    pipeline: ComputePipeline,
    image: Option<StorageImage>,
    pub transform: DisplayTransform,
}

impl DisplayStage {
    /// A stage for `transform`, or None when the swapchain blit alone shows the same.
    pub fn for_transform(
        ctx: &Arc<GpuContext>,
        layout: &PipelineLayout,
        transform: DisplayTransform,
    ) -> Result<Option<Self>, RenderError> {
        if transform == DisplayTransform::CLAMP {
            return Ok(None);
        }
        let pipeline = ComputePipeline::new(ctx, layout, "display", shaders::DISPLAY, &[])?;
        Ok(Some(Self {
            pipeline,
            image: None,
            transform,
        }))
    }

    /// Makes the image the size of `frame`.
    pub fn ensure_image(
        &mut self,
        ctx: &Arc<GpuContext>,
        frame: &StorageImage,
    ) -> Result<(), RenderError> {
        if (self.image.as_ref()).is_some_and(|i| (i.width, i.height) == (frame.width, frame.height))
        {
            return Ok(());
        }
        self.image = None;
        self.image = Some(StorageImage::new(
            ctx,
            "display",
            frame.width,
            frame.height,
        )?);
        Ok(())
    }

    /// The image the last pass wrote, if any.
    pub fn image(&self) -> Option<&StorageImage> {
        self.image.as_ref()
    }

    /// Records the pass: `frame` (read) through the transform into the image
    /// ([`Self::ensure_image`] first).
    pub fn record(&self, g: &mut FrameGraph, frame: &StorageImage) {
        let image = self.image.as_ref().expect("ensure_image before record");
        let push = DisplayPush {
            width: frame.width,
            height: frame.height,
            scale: self.transform.exposure.exp2(),
            tonemap: match self.transform.tonemap {
                Tonemap::Clamp => TONEMAP_CLAMP,
                Tonemap::PbrNeutral => TONEMAP_PBR_NEUTRAL,
            },
        };
        let groups = [
            frame.width.div_ceil(WORKGROUP_SIZE_X),
            frame.height.div_ceil(WORKGROUP_SIZE_Y),
            1,
        ];
        g.pass()
            .reads(BINDING_OUTPUT, frame)
            .writes(BINDING_DISPLAY, image)
            .record(|r| {
                // After every earlier use of the image (the last frame's blits into the
                // swapchains, which the graph does not see): its contents are all replaced.
                r.untimed(|cmd| image.cmd_prepare_for_write(cmd));
                r.dispatch("display", &self.pipeline, &push, groups)
            });
    }
}
