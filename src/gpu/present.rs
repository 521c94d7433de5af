//! Copying a rendered frame into an image fovea does not own: a window's swapchain image or
//! an OpenXR swapchain image. A blit, not a copy: it converts the RGBA32F linear radiance to
//! the target's format (an *_SRGB target gets the sRGB encoding from the hardware) and scales
//! when the sizes differ.

use super::error::GpuError;
use super::memory::StorageImage;
use super::sync::{ImageTransition, Scope};
use super::GpuContext;
use ash::vk;

/// An image owned by someone else (a swapchain), and the layouts it is handed over in and
/// must be left in.
#[derive(Clone, Copy, Debug)]
pub struct ExternalImage {
    pub image: vk::Image,
    pub format: vk::Format,
    pub extent: [u32; 2],
    pub array_layer: u32,
    /// Layout the image is in when the copy starts (UNDEFINED discards its contents).
    pub layout_before: vk::ImageLayout,
    /// Layout it must be in afterwards (PRESENT_SRC_KHR for a window, COLOR_ATTACHMENT_OPTIMAL
    /// for OpenXR, whose Vulkan binding hands images over and takes them back in that layout).
    pub layout_after: vk::ImageLayout,
}

/// A rectangle of a storage image, in pixels.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SourceRect {
    pub offset: [u32; 2],
    pub extent: [u32; 2],
}

impl GpuContext {
    /// Can frames be blitted into images of `format`? Checked once when a swapchain is made,
    /// so a format that cannot work is refused with its name, not by a validation error.
    pub fn check_blit_target(&self, format: vk::Format) -> Result<(), GpuError> {
        // SAFETY: the physical device belongs to this instance.
        let dst = unsafe {
            self.instance
                .get_physical_device_format_properties(self.physical_device(), format)
        };
        // SAFETY: as above.
        let src = unsafe {
            self.instance
                .get_physical_device_format_properties(self.physical_device(), StorageImage::FORMAT)
        };
        if !dst
            .optimal_tiling_features
            .contains(vk::FormatFeatureFlags::BLIT_DST)
        {
            return Err(GpuError::Limit(format!(
                "the device cannot blit into {format:?} images; the swapchain needs another format"
            )));
        }
        if !src
            .optimal_tiling_features
            .contains(vk::FormatFeatureFlags::BLIT_SRC)
        {
            return Err(GpuError::Limit(
                "the device cannot blit from RGBA32F images, which presenting needs".into(),
            ));
        }
        Ok(())
    }

    /// Copies each `(rect, dst)`: `rect` of `src` (a frame in GENERAL layout) into all of
    /// `dst`, converting format and scaling. One submission for all the copies, waited for.
    pub fn copy_to_external(
        &self,
        src: &StorageImage,
        copies: &[(SourceRect, ExternalImage)],
    ) -> Result<(), GpuError> {
        check_copies(src, copies)?;
        self.submit_and_wait("present copy", |cmd| {
            self.cmd_copy_to_external(cmd, src, copies)
        })
    }

    /// Records the copies of [`Self::copy_to_external`] into `cmd`, after the commands that
    /// wrote `src` (both eyes of a headset frame, in the frame's own submission). The
    /// rectangles must have passed [`check_copies`].
    pub fn cmd_copy_to_external(
        &self,
        cmd: vk::CommandBuffer,
        src: &StorageImage,
        copies: &[(SourceRect, ExternalImage)],
    ) {
        // SAFETY: the physical device belongs to this instance.
        let src_features = unsafe {
            self.instance
                .get_physical_device_format_properties(self.physical_device(), StorageImage::FORMAT)
        };
        let linear = src_features
            .optimal_tiling_features
            .contains(vk::FormatFeatureFlags::SAMPLED_IMAGE_FILTER_LINEAR);
        // The frame's writes (a copy from the resolved pixels, or compute passes after it)
        // must land before the blits read them.
        self.cmd_image_barriers(
            cmd,
            &[ImageTransition {
                image: src.image,
                range: color_layer(0),
                from: (
                    Scope::COMPUTE_WRITE.and(Scope::COPY_WRITE),
                    vk::ImageLayout::GENERAL,
                ),
                to: (Scope::BLIT_READ, vk::ImageLayout::GENERAL),
            }],
        );
        for (rect, dst) in copies {
            // Linear filtering only when scaling, and only where the format allows it.
            let filter = match rect.extent != dst.extent && linear {
                true => vk::Filter::LINEAR,
                false => vk::Filter::NEAREST,
            };
            self.cmd_blit(cmd, src, *rect, dst, filter);
        }
    }

    /// Records one blit into `dst`, with its layout transitions before and after.
    fn cmd_blit(
        &self,
        cmd: vk::CommandBuffer,
        src: &StorageImage,
        rect: SourceRect,
        dst: &ExternalImage,
        filter: vk::Filter,
    ) {
        let range = color_layer(dst.array_layer);
        let transition = |from, to| {
            [ImageTransition {
                image: dst.image,
                range,
                from,
                to,
            }]
        };
        let corner = |x: u32, y: u32, z: i32| vk::Offset3D {
            x: x as i32,
            y: y as i32,
            z,
        };
        let layers = |layer: u32| vk::ImageSubresourceLayers {
            aspect_mask: vk::ImageAspectFlags::COLOR,
            mip_level: 0,
            base_array_layer: layer,
            layer_count: 1,
        };
        let [x, y] = rect.offset;
        let [w, h] = rect.extent;
        let region = [vk::ImageBlit::default()
            .src_subresource(layers(0))
            .src_offsets([corner(x, y, 0), corner(x + w, y + h, 1)])
            .dst_subresource(layers(dst.array_layer))
            .dst_offsets([corner(0, 0, 0), corner(dst.extent[0], dst.extent[1], 1)])];
        // The owner's reads of the image were waited for before it was handed to us
        // (xrWaitSwapchainImage, or the acquire fence), so the blit waits for nothing.
        let dst_ready = transition(
            (Scope::NOTHING, dst.layout_before),
            (Scope::BLIT_WRITE, vk::ImageLayout::TRANSFER_DST_OPTIMAL),
        );
        // Handed back after this submission's fence, which makes the blit's writes available.
        let handed_back = transition(
            (Scope::BLIT_WRITE, vk::ImageLayout::TRANSFER_DST_OPTIMAL),
            (Scope::HANDED_OVER, dst.layout_after),
        );
        self.cmd_image_barriers(cmd, &dst_ready);
        // SAFETY: cmd is recording outside a render pass; both images live until the
        // submission is waited for; the caller owns dst for the duration (acquired).
        unsafe {
            self.device.cmd_blit_image(
                cmd,
                src.image,
                vk::ImageLayout::GENERAL,
                dst.image,
                vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                &region,
                filter,
            )
        };
        self.cmd_image_barriers(cmd, &handed_back);
    }
}

/// One mip level and array layer of a colour image.
fn color_layer(layer: u32) -> vk::ImageSubresourceRange {
    vk::ImageSubresourceRange {
        aspect_mask: vk::ImageAspectFlags::COLOR,
        base_mip_level: 0,
        level_count: 1,
        base_array_layer: layer,
        layer_count: 1,
    }
}

/// Refuses a copy whose source rectangle is empty or not inside `src`.
pub fn check_copies(
    src: &StorageImage,
    copies: &[(SourceRect, ExternalImage)],
) -> Result<(), GpuError> {
    for (rect, _) in copies {
        if rect.extent[0] == 0
            || rect.extent[1] == 0
            || rect.offset[0] + rect.extent[0] > src.width
            || rect.offset[1] + rect.extent[1] > src.height
        {
            return Err(GpuError::Limit(format!(
                "copy of {rect:?} from a {}x{} image: the rectangle is empty or not inside it",
                src.width, src.height
            )));
        }
    }
    Ok(())
}
