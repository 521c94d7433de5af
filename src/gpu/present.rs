//! Copying a rendered frame into an image fovea does not own: a window's swapchain image or
//! an OpenXR swapchain image. A blit, not a copy: it converts the RGBA32F linear radiance to
//! the target's format (an *_SRGB target gets the sRGB encoding from the hardware) and scales
//! when the sizes differ.

use super::error::GpuError;
use super::memory::StorageImage;
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

    /// Copies `rect` of `src` (a frame in GENERAL layout after compute writes) into all of
    /// `dst`, converting format and scaling, in one submission that is waited for.
    pub fn copy_to_external(
        &self,
        src: &StorageImage,
        rect: SourceRect,
        dst: &ExternalImage,
    ) -> Result<(), GpuError> {
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
        // Linear filtering only when scaling, and only where the source format allows it.
        let scaling = rect.extent != dst.extent;
        // SAFETY: the physical device belongs to this instance.
        let src_features = unsafe {
            self.instance
                .get_physical_device_format_properties(self.physical_device(), StorageImage::FORMAT)
        };
        let filter = match scaling
            && src_features
                .optimal_tiling_features
                .contains(vk::FormatFeatureFlags::SAMPLED_IMAGE_FILTER_LINEAR)
        {
            true => vk::Filter::LINEAR,
            false => vk::Filter::NEAREST,
        };
        self.submit_and_wait("present copy", |cmd| {
            let range = vk::ImageSubresourceRange {
                aspect_mask: vk::ImageAspectFlags::COLOR,
                base_mip_level: 0,
                level_count: 1,
                base_array_layer: dst.array_layer,
                layer_count: 1,
            };
            let src_range = vk::ImageSubresourceRange {
                base_array_layer: 0,
                ..range
            };
            let before = [
                // The frame's compute writes must land before the blit reads them.
                vk::ImageMemoryBarrier::default()
                    .src_access_mask(vk::AccessFlags::SHADER_WRITE)
                    .dst_access_mask(vk::AccessFlags::TRANSFER_READ)
                    .old_layout(vk::ImageLayout::GENERAL)
                    .new_layout(vk::ImageLayout::GENERAL)
                    .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                    .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                    .image(src.image)
                    .subresource_range(src_range),
                vk::ImageMemoryBarrier::default()
                    .src_access_mask(vk::AccessFlags::empty())
                    .dst_access_mask(vk::AccessFlags::TRANSFER_WRITE)
                    .old_layout(dst.layout_before)
                    .new_layout(vk::ImageLayout::TRANSFER_DST_OPTIMAL)
                    .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                    .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                    .image(dst.image)
                    .subresource_range(range),
            ];
            let corner = |x: u32, y: u32| vk::Offset3D {
                x: x as i32,
                y: y as i32,
                z: 0,
            };
            let layers = |layer: u32| vk::ImageSubresourceLayers {
                aspect_mask: vk::ImageAspectFlags::COLOR,
                mip_level: 0,
                base_array_layer: layer,
                layer_count: 1,
            };
            let region = [vk::ImageBlit::default()
                .src_subresource(layers(0))
                .src_offsets([
                    corner(rect.offset[0], rect.offset[1]),
                    vk::Offset3D {
                        z: 1,
                        ..corner(
                            rect.offset[0] + rect.extent[0],
                            rect.offset[1] + rect.extent[1],
                        )
                    },
                ])
                .dst_subresource(layers(dst.array_layer))
                .dst_offsets([
                    corner(0, 0),
                    vk::Offset3D {
                        z: 1,
                        ..corner(dst.extent[0], dst.extent[1])
                    },
                ])];
            let after = [vk::ImageMemoryBarrier::default()
                .src_access_mask(vk::AccessFlags::TRANSFER_WRITE)
                .dst_access_mask(vk::AccessFlags::MEMORY_READ)
                .old_layout(vk::ImageLayout::TRANSFER_DST_OPTIMAL)
                .new_layout(dst.layout_after)
                .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                .image(dst.image)
                .subresource_range(range)];
            // SAFETY: cmd is recording outside a render pass; both images live until the
            // submission is waited for; the caller owns dst for the duration (acquired).
            unsafe {
                self.device.cmd_pipeline_barrier(
                    cmd,
                    vk::PipelineStageFlags::COMPUTE_SHADER | vk::PipelineStageFlags::TOP_OF_PIPE,
                    vk::PipelineStageFlags::TRANSFER,
                    vk::DependencyFlags::empty(),
                    &[],
                    &[],
                    &before,
                );
                self.device.cmd_blit_image(
                    cmd,
                    src.image,
                    vk::ImageLayout::GENERAL,
                    dst.image,
                    vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                    &region,
                    filter,
                );
                self.device.cmd_pipeline_barrier(
                    cmd,
                    vk::PipelineStageFlags::TRANSFER,
                    vk::PipelineStageFlags::BOTTOM_OF_PIPE,
                    vk::DependencyFlags::empty(),
                    &[],
                    &[],
                    &after,
                );
            }
        })
    }
}
