//! The `extern "system"` functions handed out by `xrGetInstanceProcAddr`. Each one only
//! turns raw pointers into references, takes the registry lock and calls the module that
//! does the work, inside [`ffi::call`] (panic containment and error bookkeeping).

#![allow(clippy::too_many_arguments)]

use std::ffi::c_char;

use openxr_sys as xr;
use openxr_sys::platform::{VkDevice, VkInstance, VkPhysicalDevice, VkResult};
use openxr_sys::Handle as _;

use crate::ffi::{self, call};
use crate::registry::lock;
use crate::{
    actions, frame, instance, paths, session, spaces, swapchain, system, views, visibility_mask,
    vulkan_enable,
};

/// Borrows an input structure the app passed by pointer.
///
/// # Safety
/// `p` must be null or point to a valid `T` for the duration of the call.
unsafe fn input<'a, T>(p: *const T) -> Result<&'a T, xr::Result> {
    ffi::non_null(p)?;
    // SAFETY: non-null and valid per the caller's contract.
    Ok(unsafe { &*p })
}

/// Borrows an output structure the app passed by pointer.
///
/// # Safety
/// `p` must be null or point to a valid, writable `T` for the duration of the call.
unsafe fn output<'a, T>(p: *mut T) -> Result<&'a mut T, xr::Result> {
    ffi::non_null(p)?;
    // SAFETY: non-null, valid and exclusive per the caller's contract.
    Ok(unsafe { &mut *p })
}

// SAFETY (for every function below): these are OpenXR entry points; the app guarantees the
// pointer arguments are valid as the spec describes, null pointers are rejected before use.

pub unsafe extern "system" fn enumerate_api_layer_properties(
    capacity: u32,
    count: *mut u32,
    props: *mut xr::ApiLayerProperties,
) -> xr::Result {
    // The runtime has no API layers of its own.
    // SAFETY: the app's pointer arguments are valid as the spec requires; null is rejected.
    call("xrEnumerateApiLayerProperties", 0, || unsafe {
        ffi::two_call(capacity, count, props, 0, |_, _| Ok(()))
    })
}

pub unsafe extern "system" fn enumerate_instance_extension_properties(
    layer: *const c_char,
    capacity: u32,
    count: *mut u32,
    props: *mut xr::ExtensionProperties,
) -> xr::Result {
    call("xrEnumerateInstanceExtensionProperties", 0, || {
        instance::enumerate_extensions(layer, capacity, count, props)
    })
}

pub unsafe extern "system" fn create_instance(
    info: *const xr::InstanceCreateInfo,
    out: *mut xr::Instance,
) -> xr::Result {
    call("xrCreateInstance", 0, || {
        // SAFETY: the app's pointer arguments are valid as the spec requires; null is rejected.
        instance::create_instance(unsafe { input(info)? }, out)
    })
}

pub unsafe extern "system" fn destroy_instance(i: xr::Instance) -> xr::Result {
    call("xrDestroyInstance", i.into_raw(), || {
        instance::destroy_instance(i)
    })
}

pub unsafe extern "system" fn get_instance_properties(
    i: xr::Instance,
    props: *mut xr::InstanceProperties,
) -> xr::Result {
    call("xrGetInstanceProperties", i.into_raw(), || {
        // SAFETY: the app's pointer arguments are valid as the spec requires; null is rejected.
        instance::get_instance_properties(&lock(), i, unsafe { output(props)? })
    })
}

pub unsafe extern "system" fn poll_event(
    i: xr::Instance,
    buffer: *mut xr::EventDataBuffer,
) -> xr::Result {
    call("xrPollEvent", i.into_raw(), || {
        // SAFETY: the app's pointer arguments are valid as the spec requires; null is rejected.
        instance::poll_event(&mut lock(), i, unsafe { output(buffer)? })
    })
}

pub unsafe extern "system" fn result_to_string(
    i: xr::Instance,
    value: xr::Result,
    buffer: *mut c_char,
) -> xr::Result {
    call("xrResultToString", i.into_raw(), || {
        // SAFETY: the app's pointer arguments are valid as the spec requires; null is rejected.
        let buffer = unsafe { output(buffer as *mut [c_char; xr::MAX_RESULT_STRING_SIZE])? };
        instance::result_to_string(&lock(), i, value, buffer)
    })
}

pub unsafe extern "system" fn structure_type_to_string(
    i: xr::Instance,
    value: xr::StructureType,
    buffer: *mut c_char,
) -> xr::Result {
    call("xrStructureTypeToString", i.into_raw(), || {
        // SAFETY: the app's pointer arguments are valid as the spec requires; null is rejected.
        let buffer = unsafe { output(buffer as *mut [c_char; xr::MAX_STRUCTURE_NAME_SIZE])? };
        instance::structure_type_to_string(&lock(), i, value, buffer)
    })
}

pub unsafe extern "system" fn string_to_path(
    i: xr::Instance,
    s: *const c_char,
    out: *mut xr::Path,
) -> xr::Result {
    call("xrStringToPath", i.into_raw(), || {
        paths::string_to_path(&mut lock(), i, s, out)
    })
}

pub unsafe extern "system" fn path_to_string(
    i: xr::Instance,
    path: xr::Path,
    capacity: u32,
    count: *mut u32,
    buf: *mut c_char,
) -> xr::Result {
    call("xrPathToString", i.into_raw(), || {
        paths::path_to_string(&lock(), i, path, capacity, count, buf)
    })
}

pub unsafe extern "system" fn get_system(
    i: xr::Instance,
    info: *const xr::SystemGetInfo,
    out: *mut xr::SystemId,
) -> xr::Result {
    call("xrGetSystem", i.into_raw(), || {
        // SAFETY: the app's pointer arguments are valid as the spec requires; null is rejected.
        system::get_system(&lock(), i, unsafe { input(info)? }, out)
    })
}

pub unsafe extern "system" fn get_system_properties(
    i: xr::Instance,
    system_id: xr::SystemId,
    props: *mut xr::SystemProperties,
) -> xr::Result {
    call("xrGetSystemProperties", i.into_raw(), || {
        // SAFETY: the app's pointer arguments are valid as the spec requires; null is rejected.
        system::get_system_properties(&lock(), i, system_id, unsafe { output(props)? })
    })
}

pub unsafe extern "system" fn enumerate_view_configurations(
    i: xr::Instance,
    system_id: xr::SystemId,
    capacity: u32,
    count: *mut u32,
    out: *mut xr::ViewConfigurationType,
) -> xr::Result {
    call("xrEnumerateViewConfigurations", i.into_raw(), || {
        system::enumerate_view_configurations(&lock(), i, system_id, capacity, count, out)
    })
}

pub unsafe extern "system" fn get_view_configuration_properties(
    i: xr::Instance,
    system_id: xr::SystemId,
    ty: xr::ViewConfigurationType,
    props: *mut xr::ViewConfigurationProperties,
) -> xr::Result {
    call("xrGetViewConfigurationProperties", i.into_raw(), || {
        // SAFETY: the app's pointer arguments are valid as the spec requires; null is rejected.
        system::get_view_configuration_properties(&lock(), i, system_id, ty, unsafe {
            output(props)?
        })
    })
}

pub unsafe extern "system" fn enumerate_view_configuration_views(
    i: xr::Instance,
    system_id: xr::SystemId,
    ty: xr::ViewConfigurationType,
    capacity: u32,
    count: *mut u32,
    out: *mut xr::ViewConfigurationView,
) -> xr::Result {
    call("xrEnumerateViewConfigurationViews", i.into_raw(), || {
        system::enumerate_view_configuration_views(&lock(), i, system_id, ty, capacity, count, out)
    })
}

pub unsafe extern "system" fn enumerate_environment_blend_modes(
    i: xr::Instance,
    system_id: xr::SystemId,
    ty: xr::ViewConfigurationType,
    capacity: u32,
    count: *mut u32,
    out: *mut xr::EnvironmentBlendMode,
) -> xr::Result {
    call("xrEnumerateEnvironmentBlendModes", i.into_raw(), || {
        system::enumerate_environment_blend_modes(&lock(), i, system_id, ty, capacity, count, out)
    })
}

pub unsafe extern "system" fn create_session(
    i: xr::Instance,
    info: *const xr::SessionCreateInfo,
    out: *mut xr::Session,
) -> xr::Result {
    call("xrCreateSession", i.into_raw(), || {
        // SAFETY: the app's pointer arguments are valid as the spec requires; null is rejected.
        session::create_session(&mut lock(), i, unsafe { input(info)? }, out)
    })
}

pub unsafe extern "system" fn destroy_session(s: xr::Session) -> xr::Result {
    call("xrDestroySession", s.into_raw(), || {
        session::destroy_session(&mut lock(), s)
    })
}

pub unsafe extern "system" fn begin_session(
    s: xr::Session,
    info: *const xr::SessionBeginInfo,
) -> xr::Result {
    call("xrBeginSession", s.into_raw(), || {
        // SAFETY: the app's pointer arguments are valid as the spec requires; null is rejected.
        session::begin_session(&mut lock(), s, unsafe { input(info)? })
    })
}

pub unsafe extern "system" fn end_session(s: xr::Session) -> xr::Result {
    call("xrEndSession", s.into_raw(), || {
        session::end_session(&mut lock(), s)
    })
}

pub unsafe extern "system" fn request_exit_session(s: xr::Session) -> xr::Result {
    call("xrRequestExitSession", s.into_raw(), || {
        session::request_exit_session(&mut lock(), s)
    })
}

pub unsafe extern "system" fn enumerate_reference_spaces(
    s: xr::Session,
    capacity: u32,
    count: *mut u32,
    out: *mut xr::ReferenceSpaceType,
) -> xr::Result {
    call("xrEnumerateReferenceSpaces", s.into_raw(), || {
        spaces::enumerate_reference_spaces(&lock(), s, capacity, count, out)
    })
}

pub unsafe extern "system" fn create_reference_space(
    s: xr::Session,
    info: *const xr::ReferenceSpaceCreateInfo,
    out: *mut xr::Space,
) -> xr::Result {
    call("xrCreateReferenceSpace", s.into_raw(), || {
        // SAFETY: the app's pointer arguments are valid as the spec requires; null is rejected.
        spaces::create_reference_space(&mut lock(), s, unsafe { input(info)? }, out)
    })
}

pub unsafe extern "system" fn get_reference_space_bounds_rect(
    s: xr::Session,
    ty: xr::ReferenceSpaceType,
    bounds: *mut xr::Extent2Df,
) -> xr::Result {
    call("xrGetReferenceSpaceBoundsRect", s.into_raw(), || {
        // SAFETY: the app's pointer arguments are valid as the spec requires; null is rejected.
        spaces::get_reference_space_bounds_rect(&lock(), s, ty, unsafe { output(bounds)? })
    })
}

pub unsafe extern "system" fn create_action_space(
    s: xr::Session,
    info: *const xr::ActionSpaceCreateInfo,
    out: *mut xr::Space,
) -> xr::Result {
    call("xrCreateActionSpace", s.into_raw(), || {
        // SAFETY: the app's pointer arguments are valid as the spec requires; null is rejected.
        spaces::create_action_space(&mut lock(), s, unsafe { input(info)? }, out)
    })
}

pub unsafe extern "system" fn locate_space(
    space: xr::Space,
    base: xr::Space,
    time: xr::Time,
    location: *mut xr::SpaceLocation,
) -> xr::Result {
    call("xrLocateSpace", space.into_raw(), || {
        // SAFETY: the app's pointer arguments are valid as the spec requires; null is rejected.
        spaces::locate_space(&lock(), space, base, time, unsafe { output(location)? })
    })
}

pub unsafe extern "system" fn destroy_space(space: xr::Space) -> xr::Result {
    call("xrDestroySpace", space.into_raw(), || {
        spaces::destroy_space(&mut lock(), space)
    })
}

pub unsafe extern "system" fn enumerate_swapchain_formats(
    s: xr::Session,
    capacity: u32,
    count: *mut u32,
    out: *mut i64,
) -> xr::Result {
    call("xrEnumerateSwapchainFormats", s.into_raw(), || {
        swapchain::enumerate_formats(&lock(), s, capacity, count, out)
    })
}

pub unsafe extern "system" fn create_swapchain(
    s: xr::Session,
    info: *const xr::SwapchainCreateInfo,
    out: *mut xr::Swapchain,
) -> xr::Result {
    call("xrCreateSwapchain", s.into_raw(), || {
        // SAFETY: the app's pointer arguments are valid as the spec requires; null is rejected.
        swapchain::create_swapchain(&mut lock(), s, unsafe { input(info)? }, out)
    })
}

pub unsafe extern "system" fn destroy_swapchain(sc: xr::Swapchain) -> xr::Result {
    call("xrDestroySwapchain", sc.into_raw(), || {
        swapchain::destroy_swapchain(&mut lock(), sc)
    })
}

pub unsafe extern "system" fn enumerate_swapchain_images(
    sc: xr::Swapchain,
    capacity: u32,
    count: *mut u32,
    out: *mut xr::SwapchainImageBaseHeader,
) -> xr::Result {
    call("xrEnumerateSwapchainImages", sc.into_raw(), || {
        swapchain::enumerate_images(&lock(), sc, capacity, count, out)
    })
}

pub unsafe extern "system" fn acquire_swapchain_image(
    sc: xr::Swapchain,
    info: *const xr::SwapchainImageAcquireInfo,
    index: *mut u32,
) -> xr::Result {
    call("xrAcquireSwapchainImage", sc.into_raw(), || {
        swapchain::acquire_image(&mut lock(), sc, info, index)
    })
}

pub unsafe extern "system" fn wait_swapchain_image(
    sc: xr::Swapchain,
    info: *const xr::SwapchainImageWaitInfo,
) -> xr::Result {
    call("xrWaitSwapchainImage", sc.into_raw(), || {
        // SAFETY: the app's pointer arguments are valid as the spec requires; null is rejected.
        swapchain::wait_image(&mut lock(), sc, unsafe { input(info)? })
    })
}

pub unsafe extern "system" fn release_swapchain_image(
    sc: xr::Swapchain,
    info: *const xr::SwapchainImageReleaseInfo,
) -> xr::Result {
    call("xrReleaseSwapchainImage", sc.into_raw(), || {
        swapchain::release_image(&mut lock(), sc, info)
    })
}

pub unsafe extern "system" fn wait_frame(
    s: xr::Session,
    info: *const xr::FrameWaitInfo,
    state: *mut xr::FrameState,
) -> xr::Result {
    call("xrWaitFrame", s.into_raw(), || {
        // SAFETY: the app's pointer arguments are valid as the spec requires; null is rejected.
        frame::wait_frame(&mut lock(), s, info, unsafe { output(state)? })
    })
}

pub unsafe extern "system" fn begin_frame(
    s: xr::Session,
    info: *const xr::FrameBeginInfo,
) -> xr::Result {
    call("xrBeginFrame", s.into_raw(), || {
        frame::begin_frame(&mut lock(), s, info)
    })
}

pub unsafe extern "system" fn end_frame(
    s: xr::Session,
    info: *const xr::FrameEndInfo,
) -> xr::Result {
    call("xrEndFrame", s.into_raw(), || {
        // SAFETY: the app's pointer arguments are valid as the spec requires; null is rejected.
        frame::end_frame(&mut lock(), s, unsafe { input(info)? })
    })
}

pub unsafe extern "system" fn locate_views(
    s: xr::Session,
    info: *const xr::ViewLocateInfo,
    state: *mut xr::ViewState,
    capacity: u32,
    count: *mut u32,
    out: *mut xr::View,
) -> xr::Result {
    call("xrLocateViews", s.into_raw(), || {
        views::locate_views(
            &lock(),
            s,
            // SAFETY: the app's pointer arguments are valid as the spec requires; null is rejected.
            unsafe { input(info)? },
            // SAFETY: the app's pointer arguments are valid as the spec requires; null is rejected.
            unsafe { output(state)? },
            capacity,
            count,
            out,
        )
    })
}

pub unsafe extern "system" fn create_action_set(
    i: xr::Instance,
    info: *const xr::ActionSetCreateInfo,
    out: *mut xr::ActionSet,
) -> xr::Result {
    call("xrCreateActionSet", i.into_raw(), || {
        // SAFETY: the app's pointer arguments are valid as the spec requires; null is rejected.
        actions::create_action_set(&mut lock(), i, unsafe { input(info)? }, out)
    })
}

pub unsafe extern "system" fn destroy_action_set(set: xr::ActionSet) -> xr::Result {
    call("xrDestroyActionSet", set.into_raw(), || {
        actions::destroy_action_set(&mut lock(), set)
    })
}

pub unsafe extern "system" fn create_action(
    set: xr::ActionSet,
    info: *const xr::ActionCreateInfo,
    out: *mut xr::Action,
) -> xr::Result {
    call("xrCreateAction", set.into_raw(), || {
        // SAFETY: the app's pointer arguments are valid as the spec requires; null is rejected.
        actions::create_action(&mut lock(), set, unsafe { input(info)? }, out)
    })
}

pub unsafe extern "system" fn destroy_action(action: xr::Action) -> xr::Result {
    call("xrDestroyAction", action.into_raw(), || {
        actions::destroy_action(&mut lock(), action)
    })
}

pub unsafe extern "system" fn suggest_interaction_profile_bindings(
    i: xr::Instance,
    info: *const xr::InteractionProfileSuggestedBinding,
) -> xr::Result {
    call("xrSuggestInteractionProfileBindings", i.into_raw(), || {
        // SAFETY: the app's pointer arguments are valid as the spec requires; null is rejected.
        actions::suggest_bindings(&mut lock(), i, unsafe { input(info)? })
    })
}

pub unsafe extern "system" fn attach_session_action_sets(
    s: xr::Session,
    info: *const xr::SessionActionSetsAttachInfo,
) -> xr::Result {
    call("xrAttachSessionActionSets", s.into_raw(), || {
        // SAFETY: the app's pointer arguments are valid as the spec requires; null is rejected.
        actions::attach_action_sets(&mut lock(), s, unsafe { input(info)? })
    })
}

pub unsafe extern "system" fn get_current_interaction_profile(
    s: xr::Session,
    top_level: xr::Path,
    out: *mut xr::InteractionProfileState,
) -> xr::Result {
    call("xrGetCurrentInteractionProfile", s.into_raw(), || {
        // SAFETY: the app's pointer arguments are valid as the spec requires; null is rejected.
        actions::get_current_interaction_profile(&lock(), s, top_level, unsafe { output(out)? })
    })
}

pub unsafe extern "system" fn sync_actions(
    s: xr::Session,
    info: *const xr::ActionsSyncInfo,
) -> xr::Result {
    call("xrSyncActions", s.into_raw(), || {
        // SAFETY: the app's pointer arguments are valid as the spec requires; null is rejected.
        actions::sync_actions(&mut lock(), s, unsafe { input(info)? })
    })
}

pub unsafe extern "system" fn get_action_state_boolean(
    s: xr::Session,
    info: *const xr::ActionStateGetInfo,
    state: *mut xr::ActionStateBoolean,
) -> xr::Result {
    call("xrGetActionStateBoolean", s.into_raw(), || {
        // SAFETY: the app's pointer arguments are valid as the spec requires; null is rejected.
        actions::get_state_boolean(&lock(), s, unsafe { input(info)? }, unsafe {
            output(state)?
        })
    })
}

pub unsafe extern "system" fn get_action_state_float(
    s: xr::Session,
    info: *const xr::ActionStateGetInfo,
    state: *mut xr::ActionStateFloat,
) -> xr::Result {
    call("xrGetActionStateFloat", s.into_raw(), || {
        // SAFETY: the app's pointer arguments are valid as the spec requires; null is rejected.
        actions::get_state_float(&lock(), s, unsafe { input(info)? }, unsafe {
            output(state)?
        })
    })
}

pub unsafe extern "system" fn get_action_state_vector2f(
    s: xr::Session,
    info: *const xr::ActionStateGetInfo,
    state: *mut xr::ActionStateVector2f,
) -> xr::Result {
    call("xrGetActionStateVector2f", s.into_raw(), || {
        // SAFETY: the app's pointer arguments are valid as the spec requires; null is rejected.
        actions::get_state_vector2f(&lock(), s, unsafe { input(info)? }, unsafe {
            output(state)?
        })
    })
}

pub unsafe extern "system" fn get_action_state_pose(
    s: xr::Session,
    info: *const xr::ActionStateGetInfo,
    state: *mut xr::ActionStatePose,
) -> xr::Result {
    call("xrGetActionStatePose", s.into_raw(), || {
        // SAFETY: the app's pointer arguments are valid as the spec requires; null is rejected.
        actions::get_state_pose(&lock(), s, unsafe { input(info)? }, unsafe {
            output(state)?
        })
    })
}

pub unsafe extern "system" fn enumerate_bound_sources_for_action(
    s: xr::Session,
    info: *const xr::BoundSourcesForActionEnumerateInfo,
    capacity: u32,
    count: *mut u32,
    out: *mut xr::Path,
) -> xr::Result {
    call("xrEnumerateBoundSourcesForAction", s.into_raw(), || {
        actions::enumerate_bound_sources(
            &mut lock(),
            s,
            // SAFETY: the app's pointer arguments are valid as the spec requires; null is rejected.
            unsafe { input(info)? },
            capacity,
            count,
            out,
        )
    })
}

pub unsafe extern "system" fn get_input_source_localized_name(
    s: xr::Session,
    info: *const xr::InputSourceLocalizedNameGetInfo,
    capacity: u32,
    count: *mut u32,
    buf: *mut c_char,
) -> xr::Result {
    call("xrGetInputSourceLocalizedName", s.into_raw(), || {
        actions::get_input_source_localized_name(
            &lock(),
            s,
            // SAFETY: the app's pointer arguments are valid as the spec requires; null is rejected.
            unsafe { input(info)? },
            capacity,
            count,
            buf,
        )
    })
}

pub unsafe extern "system" fn apply_haptic_feedback(
    s: xr::Session,
    info: *const xr::HapticActionInfo,
    feedback: *const xr::HapticBaseHeader,
) -> xr::Result {
    call("xrApplyHapticFeedback", s.into_raw(), || {
        ffi::non_null(feedback)?;
        // SAFETY: the app's pointer arguments are valid as the spec requires; null is rejected.
        actions::haptic(&lock(), s, unsafe { input(info)? })
    })
}

pub unsafe extern "system" fn stop_haptic_feedback(
    s: xr::Session,
    info: *const xr::HapticActionInfo,
) -> xr::Result {
    call("xrStopHapticFeedback", s.into_raw(), || {
        // SAFETY: the app's pointer arguments are valid as the spec requires; null is rejected.
        actions::haptic(&lock(), s, unsafe { input(info)? })
    })
}

// --- XR_KHR_vulkan_enable2 / XR_KHR_vulkan_enable ---

pub unsafe extern "system" fn get_vulkan_graphics_requirements(
    i: xr::Instance,
    system_id: xr::SystemId,
    out: *mut xr::GraphicsRequirementsVulkanKHR,
) -> xr::Result {
    call("xrGetVulkanGraphicsRequirements2KHR", i.into_raw(), || {
        // SAFETY: the app's pointer arguments are valid as the spec requires; null is rejected.
        vulkan_enable::get_requirements(&mut lock(), i, system_id, unsafe { output(out)? })
    })
}

pub unsafe extern "system" fn create_vulkan_instance(
    i: xr::Instance,
    info: *const xr::VulkanInstanceCreateInfoKHR,
    vk_instance: *mut VkInstance,
    vk_result: *mut VkResult,
) -> xr::Result {
    call("xrCreateVulkanInstanceKHR", i.into_raw(), || {
        vulkan_enable::create_vulkan_instance(
            &mut lock(),
            i,
            // SAFETY: the app's pointer arguments are valid as the spec requires; null is rejected.
            unsafe { input(info)? },
            vk_instance,
            vk_result,
        )
    })
}

pub unsafe extern "system" fn create_vulkan_device(
    i: xr::Instance,
    info: *const xr::VulkanDeviceCreateInfoKHR,
    vk_device: *mut VkDevice,
    vk_result: *mut VkResult,
) -> xr::Result {
    call("xrCreateVulkanDeviceKHR", i.into_raw(), || {
        vulkan_enable::create_vulkan_device(
            &mut lock(),
            i,
            // SAFETY: the app's pointer arguments are valid as the spec requires; null is rejected.
            unsafe { input(info)? },
            vk_device,
            vk_result,
        )
    })
}

pub unsafe extern "system" fn get_vulkan_graphics_device2(
    i: xr::Instance,
    info: *const xr::VulkanGraphicsDeviceGetInfoKHR,
    out: *mut VkPhysicalDevice,
) -> xr::Result {
    call("xrGetVulkanGraphicsDevice2KHR", i.into_raw(), || {
        // SAFETY: the app's pointer arguments are valid as the spec requires; null is rejected.
        vulkan_enable::get_graphics_device2(&mut lock(), i, unsafe { input(info)? }, out)
    })
}

pub unsafe extern "system" fn get_vulkan_graphics_device(
    i: xr::Instance,
    system_id: xr::SystemId,
    vk_instance: VkInstance,
    out: *mut VkPhysicalDevice,
) -> xr::Result {
    call("xrGetVulkanGraphicsDeviceKHR", i.into_raw(), || {
        vulkan_enable::get_graphics_device(&mut lock(), i, system_id, vk_instance, out)
    })
}

pub unsafe extern "system" fn get_vulkan_extensions(
    i: xr::Instance,
    system_id: xr::SystemId,
    capacity: u32,
    count: *mut u32,
    buf: *mut c_char,
) -> xr::Result {
    call("xrGetVulkanInstanceExtensionsKHR", i.into_raw(), || {
        vulkan_enable::get_extensions(&lock(), i, system_id, capacity, count, buf)
    })
}

// --- XR_KHR_visibility_mask ---

pub unsafe extern "system" fn get_visibility_mask(
    s: xr::Session,
    ty: xr::ViewConfigurationType,
    view_index: u32,
    mask_type: xr::VisibilityMaskTypeKHR,
    out: *mut xr::VisibilityMaskKHR,
) -> xr::Result {
    call("xrGetVisibilityMaskKHR", s.into_raw(), || {
        ffi::non_null(out)?;
        visibility_mask::get_visibility_mask(&lock(), s, ty, view_index, mask_type, out)
    })
}
