//! Swapchains of real VkImages and the acquire → wait → release discipline.

use ash::vk;
use openxr_sys as xr;
use openxr_sys::Handle as _;

use crate::ffi::{self, XrResult};
use crate::readback::{
    B8G8R8A8_SRGB, B8G8R8A8_UNORM, R16G16B16A16_SFLOAT, R8G8B8A8_SRGB, R8G8B8A8_UNORM,
};
use crate::registry::{Runtime, Swapchain};
use crate::vulkan::{image_usage, ImageRequest};

/// Offered formats, most preferred first (sRGB 8-bit, as a compositor wants, then UNORM for
/// apps that encode themselves, then half float for HDR output).
pub const FORMATS: [i64; 5] = [
    R8G8B8A8_SRGB,
    B8G8R8A8_SRGB,
    R8G8B8A8_UNORM,
    B8G8R8A8_UNORM,
    R16G16B16A16_SFLOAT,
];
/// Images per swapchain: triple buffering, as most desktop runtimes.
const IMAGES_PER_SWAPCHAIN: u32 = 3;

pub fn enumerate_formats(
    rt: &Runtime,
    session: xr::Session,
    capacity: u32,
    count: *mut u32,
    out: *mut i64,
) -> XrResult {
    rt.session(session)?;
    // SAFETY: the app's output array per the two-call idiom.
    unsafe {
        ffi::two_call(capacity, count, out, FORMATS.len(), |i, f| {
            *f = FORMATS[i];
            Ok(())
        })
    }
}

pub fn create_swapchain(
    rt: &mut Runtime,
    session: xr::Session,
    info: &xr::SwapchainCreateInfo,
    out: *mut xr::Swapchain,
) -> XrResult {
    let s = rt.live_session(session)?;
    ffi::check_type(info.ty, xr::StructureType::SWAPCHAIN_CREATE_INFO)?;
    ffi::non_null(out)?;
    if !FORMATS.contains(&info.format) {
        return Err(xr::Result::ERROR_SWAPCHAIN_FORMAT_UNSUPPORTED);
    }
    let max = crate::config::MAX_IMAGE_SIZE;
    let sizes_ok = (1..=max).contains(&info.width)
        && (1..=max).contains(&info.height)
        && info.array_size >= 1
        && info.mip_count >= 1;
    if !sizes_ok {
        return Err(xr::Result::ERROR_VALIDATION_FAILURE);
    }
    if info.sample_count != 1 || info.face_count != 1 {
        return Err(xr::Result::ERROR_FEATURE_UNSUPPORTED);
    }
    if info
        .usage_flags
        .contains(xr::SwapchainUsageFlags::DEPTH_STENCIL_ATTACHMENT)
        || info
            .create_flags
            .contains(xr::SwapchainCreateFlags::PROTECTED_CONTENT)
    {
        return Err(xr::Result::ERROR_FEATURE_UNSUPPORTED);
    }
    let static_image = info
        .create_flags
        .contains(xr::SwapchainCreateFlags::STATIC_IMAGE);
    let (usage, flags) = image_usage(info.usage_flags);
    let req = ImageRequest {
        format: vk::Format::from_raw(info.format as i32),
        width: info.width,
        height: info.height,
        layers: info.array_size,
        mip_levels: info.mip_count,
        usage,
        flags,
        count: if static_image {
            1
        } else {
            IMAGES_PER_SWAPCHAIN
        },
    };
    if !s.vk.supports(&req) {
        eprintln!(
            "sim-headset: this device cannot make {:?} images with usage {:?} at {}x{}x{}; pick another swapchain format",
            req.format, req.usage, req.width, req.height, req.layers
        );
        return Err(xr::Result::ERROR_FEATURE_UNSUPPORTED);
    }
    let images = s.vk.create_images(&req)?;
    let id = rt.new_id();
    rt.swapchains.insert(
        id,
        Swapchain {
            session: session.into_raw(),
            format: info.format,
            width: info.width,
            height: info.height,
            array_size: info.array_size,
            images,
            acquired: Default::default(),
            next_acquire: 0,
            last_released: None,
        },
    );
    // SAFETY: checked non-null.
    unsafe { *out = xr::Swapchain::from_raw(id) };
    Ok(xr::Result::SUCCESS)
}

pub fn destroy_swapchain(rt: &mut Runtime, swapchain: xr::Swapchain) -> XrResult {
    let mut sc = rt
        .swapchains
        .remove(&swapchain.into_raw())
        .ok_or(xr::Result::ERROR_HANDLE_INVALID)?;
    if let Some(s) = rt.sessions.get(&sc.session) {
        s.vk.destroy_images(&mut sc.images);
    }
    Ok(xr::Result::SUCCESS)
}

pub fn enumerate_images(
    rt: &Runtime,
    swapchain: xr::Swapchain,
    capacity: u32,
    count: *mut u32,
    out: *mut xr::SwapchainImageBaseHeader,
) -> XrResult {
    let sc = rt.swapchain(swapchain)?;
    let images = &sc.images.images;
    // XrSwapchainImageVulkan2KHR is the same structure (and type value) as the KHR one.
    let out = out as *mut xr::SwapchainImageVulkanKHR;
    // SAFETY: the app passes an array of XrSwapchainImageVulkan(2)KHR per the two-call idiom.
    unsafe {
        ffi::two_call(capacity, count, out, images.len(), |i, img| {
            ffi::check_type(img.ty, xr::StructureType::SWAPCHAIN_IMAGE_VULKAN_KHR)?;
            img.image = ash::vk::Handle::as_raw(images[i]);
            Ok(())
        })
    }
}

fn live_swapchain(
    rt: &mut Runtime,
    swapchain: xr::Swapchain,
) -> Result<&mut Swapchain, xr::Result> {
    let session = xr::Session::from_raw(rt.swapchain(swapchain)?.session);
    rt.live_session(session)?;
    rt.swapchain_mut(swapchain)
}

pub fn acquire_image(
    rt: &mut Runtime,
    swapchain: xr::Swapchain,
    info: *const xr::SwapchainImageAcquireInfo,
    index: *mut u32,
) -> XrResult {
    ffi::non_null(index)?;
    if !info.is_null() {
        ffi::check_type(
            // SAFETY: non-null (checked above), the app's input structure.
            unsafe { (*info).ty },
            xr::StructureType::SWAPCHAIN_IMAGE_ACQUIRE_INFO,
        )?;
    }
    let sc = live_swapchain(rt, swapchain)?;
    let n = sc.images.images.len() as u32;
    let static_done = n == 1 && sc.last_released.is_some();
    if sc.acquired.len() as u32 >= n || static_done {
        return Err(xr::Result::ERROR_CALL_ORDER_INVALID);
    }
    let i = sc.next_acquire;
    sc.next_acquire = (i + 1) % n;
    sc.acquired.push_back((i, false));
    // SAFETY: checked non-null.
    unsafe { *index = i };
    Ok(xr::Result::SUCCESS)
}

pub fn wait_image(
    rt: &mut Runtime,
    swapchain: xr::Swapchain,
    info: &xr::SwapchainImageWaitInfo,
) -> XrResult {
    ffi::check_type(info.ty, xr::StructureType::SWAPCHAIN_IMAGE_WAIT_INFO)?;
    let sc = live_swapchain(rt, swapchain)?;
    // Images are waited in acquisition order, one at a time until released.
    if sc.acquired.iter().any(|&(_, waited)| waited) {
        return Err(xr::Result::ERROR_CALL_ORDER_INVALID);
    }
    let first = sc
        .acquired
        .front_mut()
        .ok_or(xr::Result::ERROR_CALL_ORDER_INVALID)?;
    // Our images are ready as soon as they are acquired (every runtime submission waits
    // for its fence), so no timeout can expire.
    first.1 = true;
    Ok(xr::Result::SUCCESS)
}

pub fn release_image(
    rt: &mut Runtime,
    swapchain: xr::Swapchain,
    info: *const xr::SwapchainImageReleaseInfo,
) -> XrResult {
    if !info.is_null() {
        ffi::check_type(
            // SAFETY: non-null (checked above), the app's input structure.
            unsafe { (*info).ty },
            xr::StructureType::SWAPCHAIN_IMAGE_RELEASE_INFO,
        )?;
    }
    let sc = live_swapchain(rt, swapchain)?;
    match sc.acquired.front() {
        Some(&(i, true)) => {
            sc.acquired.pop_front();
            sc.last_released = Some(i);
            Ok(xr::Result::SUCCESS)
        }
        _ => Err(xr::Result::ERROR_CALL_ORDER_INVALID),
    }
}
