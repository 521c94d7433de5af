//! One OpenXR swapchain per eye, of real VkImages the runtime owns. fovea renders into its
//! own storage image and blits each eye's half into the eye's acquired swapchain image (a
//! blit converts RGBA32F radiance to the swapchain's format; most runtimes offer no format
//! our compute passes could write directly).

use super::error::{XrContext, XrError};
use crate::gpu::{vk, ExternalImage, GpuContext};
use openxr as xr;

/// Formats fovea can fill, best first: sRGB formats get the encoding from the blit; a float
/// format holds linear radiance as it is.
const PREFERRED: [vk::Format; 4] = [
    vk::Format::R8G8B8A8_SRGB,
    vk::Format::B8G8R8A8_SRGB,
    vk::Format::R16G16B16A16_SFLOAT,
    vk::Format::A2B10G10R10_UNORM_PACK32,
];

pub struct EyeSwapchain {
    pub handle: xr::Swapchain<xr::Vulkan>,
    pub images: Vec<vk::Image>,
    pub format: vk::Format,
    pub size: [u32; 2],
}

pub fn choose_format(offered: &[u32], ctx: &GpuContext) -> Result<vk::Format, XrError> {
    PREFERRED
        .iter()
        .copied()
        .find(|f| offered.contains(&(f.as_raw() as u32)) && ctx.check_blit_target(*f).is_ok())
        .ok_or_else(|| XrError::NoSwapchainFormat {
            offered: offered
                .iter()
                .map(|f| format!("{:?}", vk::Format::from_raw(*f as i32)))
                .collect::<Vec<_>>()
                .join(", "),
        })
}

impl EyeSwapchain {
    pub fn new(
        session: &xr::Session<xr::Vulkan>,
        format: vk::Format,
        size: [u32; 2],
    ) -> Result<Self, XrError> {
        let handle = session
            .create_swapchain(&xr::SwapchainCreateInfo {
                create_flags: xr::SwapchainCreateFlags::EMPTY,
                usage_flags: xr::SwapchainUsageFlags::COLOR_ATTACHMENT
                    | xr::SwapchainUsageFlags::TRANSFER_DST,
                format: format.as_raw() as u32,
                sample_count: 1,
                width: size[0],
                height: size[1],
                face_count: 1,
                array_size: 1,
                mip_count: 1,
            })
            .xr("xrCreateSwapchain")?;
        let images = handle
            .enumerate_images()
            .xr("xrEnumerateSwapchainImages")?
            .into_iter()
            .map(vk::Handle::from_raw)
            .collect();
        Ok(Self {
            handle,
            images,
            format,
            size,
        })
    }

    /// Acquires the next image and waits until it may be written. The OpenXR Vulkan binding
    /// hands images over in COLOR_ATTACHMENT_OPTIMAL and takes them back in it.
    pub fn acquire(&mut self) -> Result<ExternalImage, XrError> {
        let index = self.handle.acquire_image().xr("xrAcquireSwapchainImage")?;
        self.handle
            .wait_image(xr::Duration::INFINITE)
            .xr("xrWaitSwapchainImage")?;
        Ok(ExternalImage {
            image: self.images[index as usize],
            format: self.format,
            extent: self.size,
            array_layer: 0,
            layout_before: vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL,
            layout_after: vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL,
        })
    }

    pub fn release(&mut self) -> Result<(), XrError> {
        self.handle.release_image().xr("xrReleaseSwapchainImage")
    }

    pub fn sub_image(&self) -> xr::SwapchainSubImage<'_, xr::Vulkan> {
        xr::SwapchainSubImage::new()
            .swapchain(&self.handle)
            .image_array_index(0)
            .image_rect(xr::Rect2Di {
                offset: xr::Offset2Di { x: 0, y: 0 },
                extent: xr::Extent2Di {
                    width: self.size[0] as i32,
                    height: self.size[1] as i32,
                },
            })
    }
}
