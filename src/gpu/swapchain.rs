//! A window's Vulkan surface (through ash-window: Xlib/XCB on X11, Wayland, Win32, Metal) and
//! its swapchain: creation, recreation after a resize, and acquire → copy → present of one
//! frame. Presentation is synchronous like the rest of fovea: the image is acquired with a
//! fence that is waited for, the frame is blitted into it in a submission that is waited for
//! (`GpuContext::copy_to_external`), and then presented, so no semaphores are needed.

use super::context::GpuContext;
use super::error::{GpuError, VkContext};
use super::memory::StorageImage;
use super::present::{ExternalImage, SourceRect};
use ash::vk;
use raw_window_handle::{RawDisplayHandle, RawWindowHandle};
use std::ffi::CStr;
use std::sync::Arc;

/// The instance extensions a surface on `display` needs (VK_KHR_surface plus the platform's),
/// for `ContextNeeds::instance_extensions`.
pub fn surface_instance_extensions(
    display: RawDisplayHandle,
) -> Result<Vec<&'static CStr>, GpuError> {
    let names = ash_window::enumerate_required_extensions(display).map_err(|result| {
        GpuError::Limit(format!(
            "this window system has no Vulkan surface support in ash-window ({result}); \
             fovea view runs on X11, Wayland, Windows and macOS"
        ))
    })?;
    Ok(names
        .iter()
        // SAFETY: ash-window returns pointers to ash's `NAME` constants: static, NUL-terminated.
        .map(|&p| unsafe { CStr::from_ptr(p) })
        .collect())
}

/// The device extensions presenting needs, for `ContextNeeds::device_extensions`.
pub fn swapchain_device_extensions() -> Vec<&'static CStr> {
    vec![ash::khr::swapchain::NAME]
}

/// Which presentation mode to ask for; the first one the surface offers of the preference
/// list is used (FIFO, which every surface supports, is the last resort).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum PresentPreference {
    /// MAILBOX, then IMMEDIATE, then FIFO: never wait for the display, so a progressive
    /// image converges as fast as the GPU renders.
    #[default]
    Fastest,
    /// FIFO: wait for vertical blank, no tearing, no frames rendered that are never seen.
    Vsync,
}

impl PresentPreference {
    fn order(self) -> &'static [vk::PresentModeKHR] {
        match self {
            PresentPreference::Fastest => &[
                vk::PresentModeKHR::MAILBOX,
                vk::PresentModeKHR::IMMEDIATE,
                vk::PresentModeKHR::FIFO,
            ],
            PresentPreference::Vsync => &[vk::PresentModeKHR::FIFO],
        }
    }
}

/// What became of a frame handed to [`Swapchain::present`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Presented {
    /// On screen (or queued for it).
    Shown,
    /// Shown, but the swapchain no longer matches the surface exactly: recreate it.
    Suboptimal,
    /// Not shown: the swapchain is out of date (the window changed size) and must be recreated.
    OutOfDate,
    /// Not shown: the window has no area (minimised); nothing to present to.
    NoSurfaceArea,
}

/// A surface and its swapchain. The window the surface was made for must outlive it: drop
/// this before the window.
pub struct Swapchain {
    ctx: Arc<GpuContext>,
    swapchain_fn: ash::khr::swapchain::Device,
    /// A field, so destroyed after `Drop::drop` has destroyed the swapchain made on it.
    surface: Surface,
    swapchain: vk::SwapchainKHR,
    images: Vec<vk::Image>,
    format: vk::SurfaceFormatKHR,
    present_mode: vk::PresentModeKHR,
    preference: PresentPreference,
    extent: [u32; 2],
    acquire_fence: vk::Fence,
}

impl Swapchain {
    /// Makes a surface for the window and a swapchain of `size` (the window's inner size in
    /// pixels; the surface's own extent wins where it has one). A window of no area gets no
    /// swapchain until [`Self::recreate`] is called with a real size.
    pub fn new(
        ctx: &Arc<GpuContext>,
        display: RawDisplayHandle,
        window: RawWindowHandle,
        size: [u32; 2],
        preference: PresentPreference,
    ) -> Result<Self, GpuError> {
        let surface = Surface::new(ctx, display, window)?;
        let swapchain_fn = ash::khr::swapchain::Device::new(&ctx.instance, &ctx.device);
        // SAFETY: a valid device; default create info.
        let acquire_fence = unsafe {
            ctx.device
                .create_fence(&vk::FenceCreateInfo::default(), None)
        }
        .vk("vkCreateFence")?;
        // From here on, drop destroys what exists.
        let mut this = Self {
            ctx: ctx.clone(),
            swapchain_fn,
            surface,
            swapchain: vk::SwapchainKHR::null(),
            images: Vec::new(),
            format: vk::SurfaceFormatKHR::default(),
            present_mode: vk::PresentModeKHR::FIFO,
            preference,
            extent: [0, 0],
            acquire_fence,
        };
        // SAFETY: the physical device and the queue family are the context's; the surface is live.
        let supported = unsafe {
            this.surface.loader.get_physical_device_surface_support(
                ctx.physical_device(),
                ctx.queue_family(),
                this.surface.handle,
            )
        }
        .vk("vkGetPhysicalDeviceSurfaceSupportKHR")?;
        if !supported {
            return Err(GpuError::Limit(format!(
                "the Vulkan device '{}' cannot present to this window from its queue family {}; \
                 pick another device with --device",
                ctx.info.name,
                ctx.queue_family()
            )));
        }
        this.format = this.choose_format()?;
        ctx.check_blit_target(this.format.format)?;
        this.present_mode = this.choose_present_mode()?;
        tracing::info!(
            "swapchain: {:?} {:?}, {:?}",
            this.format.format,
            this.format.color_space,
            this.present_mode
        );
        this.recreate(size)?;
        Ok(this)
    }

    /// The swapchain's size in pixels; `[0, 0]` while the window has no area.
    pub fn extent(&self) -> [u32; 2] {
        self.extent
    }

    pub fn format(&self) -> vk::Format {
        self.format.format
    }

    pub fn present_mode(&self) -> vk::PresentModeKHR {
        self.present_mode
    }

    /// An 8-bit sRGB format, so the blit from linear radiance gets the sRGB encoding (the same
    /// transfer function as fovea's PNGs); a UNORM one as a fallback (the image then looks too
    /// dark, and a warning says so).
    fn choose_format(&self) -> Result<vk::SurfaceFormatKHR, GpuError> {
        // SAFETY: the surface and the physical device are live.
        let formats = unsafe {
            self.surface.loader.get_physical_device_surface_formats(
                self.ctx.physical_device(),
                self.surface.handle,
            )
        }
        .vk("vkGetPhysicalDeviceSurfaceFormatsKHR")?;
        let srgb = [vk::Format::B8G8R8A8_SRGB, vk::Format::R8G8B8A8_SRGB];
        let nonlinear = vk::ColorSpaceKHR::SRGB_NONLINEAR;
        if let Some(f) = srgb.iter().find_map(|want| {
            formats
                .iter()
                .find(|f| f.format == *want && f.color_space == nonlinear)
        }) {
            return Ok(*f);
        }
        let fallback = formats
            .first()
            .copied()
            .ok_or_else(|| GpuError::Limit("the window surface offers no image formats".into()))?;
        tracing::warn!(
            "the window surface offers no 8-bit sRGB format; using {:?}, so the image shows \
             without sRGB encoding (too dark)",
            fallback.format
        );
        Ok(fallback)
    }

    fn choose_present_mode(&self) -> Result<vk::PresentModeKHR, GpuError> {
        // SAFETY: the surface and the physical device are live.
        let modes = unsafe {
            self.surface
                .loader
                .get_physical_device_surface_present_modes(
                    self.ctx.physical_device(),
                    self.surface.handle,
                )
        }
        .vk("vkGetPhysicalDeviceSurfacePresentModesKHR")?;
        Ok(self
            .preference
            .order()
            .iter()
            .copied()
            .find(|m| modes.contains(m))
            // Every surface supports FIFO (Vulkan spec, vkGetPhysicalDeviceSurfacePresentModesKHR).
            .unwrap_or(vk::PresentModeKHR::FIFO))
    }

    /// Rebuilds the swapchain for a window of `size` pixels (its inner size now). Returns the
    /// new extent, `[0, 0]` when the window has no area (minimised): then no swapchain exists
    /// until the next call with a real size.
    pub fn recreate(&mut self, size: [u32; 2]) -> Result<[u32; 2], GpuError> {
        // SAFETY: the surface and the physical device are live.
        let caps = unsafe {
            self.surface
                .loader
                .get_physical_device_surface_capabilities(
                    self.ctx.physical_device(),
                    self.surface.handle,
                )
        }
        .vk("vkGetPhysicalDeviceSurfaceCapabilitiesKHR")?;
        let extent = extent_for(&caps, size);
        // Nothing may use the old images any more: every submission of fovea is waited for,
        // but the presentation engine may still read the last presented one.
        // SAFETY: the queue is only used from this thread.
        unsafe { self.ctx.device.queue_wait_idle(self.ctx.queue) }.vk("vkQueueWaitIdle")?;
        if extent[0] == 0 || extent[1] == 0 || size[0] == 0 || size[1] == 0 {
            self.destroy_swapchain();
            self.extent = [0, 0];
            return Ok(self.extent);
        }
        if !caps
            .supported_usage_flags
            .contains(vk::ImageUsageFlags::TRANSFER_DST)
        {
            return Err(GpuError::Limit(
                "the window surface's images cannot be copied into (no TRANSFER_DST usage)".into(),
            ));
        }
        let info = vk::SwapchainCreateInfoKHR::default()
            .surface(self.surface.handle)
            .min_image_count(image_count(&caps))
            .image_format(self.format.format)
            .image_color_space(self.format.color_space)
            .image_extent(vk::Extent2D {
                width: extent[0],
                height: extent[1],
            })
            .image_array_layers(1)
            .image_usage(vk::ImageUsageFlags::TRANSFER_DST)
            .image_sharing_mode(vk::SharingMode::EXCLUSIVE)
            .pre_transform(caps.current_transform)
            .composite_alpha(composite_alpha(&caps))
            .present_mode(self.present_mode)
            .clipped(true)
            .old_swapchain(self.swapchain);
        // SAFETY: the surface is live; the old swapchain (possibly null) is retired by this call
        // and destroyed below once nothing uses it (the queue is idle).
        let created = unsafe { self.swapchain_fn.create_swapchain(&info, None) };
        self.destroy_swapchain();
        self.swapchain = created.vk("vkCreateSwapchainKHR")?;
        // SAFETY: the swapchain was just created.
        self.images = unsafe { self.swapchain_fn.get_swapchain_images(self.swapchain) }
            .vk("vkGetSwapchainImagesKHR")?;
        self.extent = extent;
        Ok(extent)
    }

    fn destroy_swapchain(&mut self) {
        if self.swapchain != vk::SwapchainKHR::null() {
            // SAFETY: the queue is idle (callers wait) and no image of it is acquired.
            unsafe { self.swapchain_fn.destroy_swapchain(self.swapchain, None) };
            self.swapchain = vk::SwapchainKHR::null();
            self.images.clear();
        }
    }

    /// Acquires an image, blits `rect` of `frame` into all of it (scaling if the sizes differ)
    /// and presents it.
    pub fn present(
        &mut self,
        frame: &StorageImage,
        rect: SourceRect,
    ) -> Result<Presented, GpuError> {
        if self.swapchain == vk::SwapchainKHR::null() {
            return Ok(Presented::NoSurfaceArea);
        }
        let device = &self.ctx.device;
        // SAFETY: the swapchain and fence are live and the fence is unsignalled; an infinite
        // timeout is allowed (it waits for an image the presentation engine releases).
        let acquired = unsafe {
            self.swapchain_fn.acquire_next_image(
                self.swapchain,
                u64::MAX,
                vk::Semaphore::null(),
                self.acquire_fence,
            )
        };
        let (index, suboptimal) = match acquired {
            Ok(r) => r,
            Err(vk::Result::ERROR_OUT_OF_DATE_KHR) => return Ok(Presented::OutOfDate),
            Err(result) => {
                return Err(GpuError::Vulkan {
                    call: "vkAcquireNextImageKHR",
                    result,
                })
            }
        };
        // SAFETY: the fence was handed to the acquire that just succeeded, so it will signal.
        unsafe {
            device
                .wait_for_fences(&[self.acquire_fence], true, u64::MAX)
                .and_then(|()| device.reset_fences(&[self.acquire_fence]))
        }
        .vk("vkWaitForFences (acquire)")?;
        let target = ExternalImage {
            image: self.images[index as usize],
            format: self.format.format,
            extent: self.extent,
            array_layer: 0,
            // The whole image is overwritten, so its previous contents are discarded.
            layout_before: vk::ImageLayout::UNDEFINED,
            layout_after: vk::ImageLayout::PRESENT_SRC_KHR,
        };
        self.ctx.copy_to_external(frame, &[(rect, target)])?;
        let swapchains = [self.swapchain];
        let indices = [index];
        // The copy's submission was waited for, so the present needs no semaphore.
        let info = vk::PresentInfoKHR::default()
            .swapchains(&swapchains)
            .image_indices(&indices);
        // SAFETY: the image was acquired above and is in PRESENT_SRC_KHR layout; the queue is
        // only used from this thread.
        let presented = unsafe { self.swapchain_fn.queue_present(self.ctx.queue, &info) };
        match presented {
            Ok(false) if !suboptimal => Ok(Presented::Shown),
            Ok(_) => Ok(Presented::Suboptimal),
            Err(vk::Result::ERROR_OUT_OF_DATE_KHR) => Ok(Presented::OutOfDate),
            Err(result) => Err(GpuError::Vulkan {
                call: "vkQueuePresentKHR",
                result,
            }),
        }
    }
}

/// The swapchain's size for a window of `size` pixels: the surface's own where it has one;
/// u32::MAX means "the swapchain decides" (Wayland), then the window's, clamped.
fn extent_for(caps: &vk::SurfaceCapabilitiesKHR, size: [u32; 2]) -> [u32; 2] {
    if caps.current_extent.width == u32::MAX {
        [
            size[0].clamp(caps.min_image_extent.width, caps.max_image_extent.width),
            size[1].clamp(caps.min_image_extent.height, caps.max_image_extent.height),
        ]
    } else {
        [caps.current_extent.width, caps.current_extent.height]
    }
}

/// One more than the minimum, so acquiring never waits on the image being shown.
fn image_count(caps: &vk::SurfaceCapabilitiesKHR) -> u32 {
    let count = caps.min_image_count + 1;
    match caps.max_image_count > 0 {
        true => count.min(caps.max_image_count),
        false => count,
    }
}

/// Opaque where the surface allows it, else the first mode it supports.
fn composite_alpha(caps: &vk::SurfaceCapabilitiesKHR) -> vk::CompositeAlphaFlagsKHR {
    [
        vk::CompositeAlphaFlagsKHR::OPAQUE,
        vk::CompositeAlphaFlagsKHR::INHERIT,
        vk::CompositeAlphaFlagsKHR::PRE_MULTIPLIED,
        vk::CompositeAlphaFlagsKHR::POST_MULTIPLIED,
    ]
    .into_iter()
    .find(|a| caps.supported_composite_alpha.contains(*a))
    .unwrap_or(vk::CompositeAlphaFlagsKHR::OPAQUE)
}

impl Drop for Swapchain {
    fn drop(&mut self) {
        // SAFETY: the queue is only used from this thread.
        let _ = unsafe { self.ctx.device.queue_wait_idle(self.ctx.queue) };
        self.destroy_swapchain();
        // SAFETY: nothing uses the fence (no acquire is pending).
        unsafe { self.ctx.device.destroy_fence(self.acquire_fence, None) };
    }
}

/// A window's surface. The window must outlive it (see [`Swapchain`]).
struct Surface {
    loader: ash::khr::surface::Instance,
    handle: vk::SurfaceKHR,
    /// Keeps the instance the surface belongs to alive until it is destroyed.
    _ctx: Arc<GpuContext>,
}

impl Surface {
    fn new(
        ctx: &Arc<GpuContext>,
        display: RawDisplayHandle,
        window: RawWindowHandle,
    ) -> Result<Self, GpuError> {
        // SAFETY: the handles come from a live window that the caller keeps alive until the
        // swapchain is dropped (documented on Swapchain); the instance has the extensions
        // `surface_instance_extensions` named (the caller created the context with them).
        let handle = unsafe {
            ash_window::create_surface(ctx.entry(), &ctx.instance, display, window, None)
        }
        .vk("vkCreate*SurfaceKHR")?;
        Ok(Self {
            loader: ash::khr::surface::Instance::new(ctx.entry(), &ctx.instance),
            handle,
            _ctx: ctx.clone(),
        })
    }
}

impl Drop for Surface {
    fn drop(&mut self) {
        // SAFETY: no swapchain of the surface is left (Swapchain's drop destroyed it before
        // its fields drop), and the window is still alive (documented on Swapchain).
        unsafe { self.loader.destroy_surface(self.handle, None) };
    }
}
