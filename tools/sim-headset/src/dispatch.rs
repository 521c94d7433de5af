//! `xrGetInstanceProcAddr`: name → entry point. Every core OpenXR 1.0 function is served
//! (the `openxr` crate loads them all eagerly); extension functions only for instances
//! that enabled their extension.

use std::ffi::c_char;

use openxr_sys as xr;
use openxr_sys::pfn;
use openxr_sys::Handle as _;

use crate::entry_points as e;
use crate::ffi::{self, call};
use crate::registry::{self, Extensions};

/// Which extension a function belongs to (None: core).
#[derive(Clone, Copy)]
enum Needs {
    Core,
    VulkanEnable2,
    VulkanEnable,
    VisibilityMask,
}

/// Casts a typed entry point to the untyped pointer xrGetInstanceProcAddr returns; the
/// `$ty` annotation makes the compiler check each function against its pfn signature.
macro_rules! fp {
    ($ty:ty, $f:expr) => {{
        let f: $ty = $f;
        // SAFETY: function pointers are all the same size; the app casts it back to `$ty`.
        unsafe { std::mem::transmute::<$ty, pfn::VoidFunction>(f) }
    }};
}

fn lookup(name: &str) -> Option<(pfn::VoidFunction, Needs)> {
    use Needs::*;
    let f = match name {
        "xrGetInstanceProcAddr" => (fp!(pfn::GetInstanceProcAddr, get_instance_proc_addr), Core),
        "xrEnumerateApiLayerProperties" => (
            fp!(
                pfn::EnumerateApiLayerProperties,
                e::enumerate_api_layer_properties
            ),
            Core,
        ),
        "xrEnumerateInstanceExtensionProperties" => (
            fp!(
                pfn::EnumerateInstanceExtensionProperties,
                e::enumerate_instance_extension_properties
            ),
            Core,
        ),
        "xrCreateInstance" => (fp!(pfn::CreateInstance, e::create_instance), Core),
        "xrDestroyInstance" => (fp!(pfn::DestroyInstance, e::destroy_instance), Core),
        "xrGetInstanceProperties" => (
            fp!(pfn::GetInstanceProperties, e::get_instance_properties),
            Core,
        ),
        "xrPollEvent" => (fp!(pfn::PollEvent, e::poll_event), Core),
        "xrResultToString" => (fp!(pfn::ResultToString, e::result_to_string), Core),
        "xrStructureTypeToString" => (
            fp!(pfn::StructureTypeToString, e::structure_type_to_string),
            Core,
        ),
        "xrGetSystem" => (fp!(pfn::GetSystem, e::get_system), Core),
        "xrGetSystemProperties" => (
            fp!(pfn::GetSystemProperties, e::get_system_properties),
            Core,
        ),
        "xrEnumerateEnvironmentBlendModes" => (
            fp!(
                pfn::EnumerateEnvironmentBlendModes,
                e::enumerate_environment_blend_modes
            ),
            Core,
        ),
        "xrCreateSession" => (fp!(pfn::CreateSession, e::create_session), Core),
        "xrDestroySession" => (fp!(pfn::DestroySession, e::destroy_session), Core),
        "xrEnumerateReferenceSpaces" => (
            fp!(pfn::EnumerateReferenceSpaces, e::enumerate_reference_spaces),
            Core,
        ),
        "xrCreateReferenceSpace" => (
            fp!(pfn::CreateReferenceSpace, e::create_reference_space),
            Core,
        ),
        "xrGetReferenceSpaceBoundsRect" => (
            fp!(
                pfn::GetReferenceSpaceBoundsRect,
                e::get_reference_space_bounds_rect
            ),
            Core,
        ),
        "xrCreateActionSpace" => (fp!(pfn::CreateActionSpace, e::create_action_space), Core),
        "xrLocateSpace" => (fp!(pfn::LocateSpace, e::locate_space), Core),
        "xrDestroySpace" => (fp!(pfn::DestroySpace, e::destroy_space), Core),
        "xrEnumerateViewConfigurations" => (
            fp!(
                pfn::EnumerateViewConfigurations,
                e::enumerate_view_configurations
            ),
            Core,
        ),
        "xrGetViewConfigurationProperties" => (
            fp!(
                pfn::GetViewConfigurationProperties,
                e::get_view_configuration_properties
            ),
            Core,
        ),
        "xrEnumerateViewConfigurationViews" => (
            fp!(
                pfn::EnumerateViewConfigurationViews,
                e::enumerate_view_configuration_views
            ),
            Core,
        ),
        "xrEnumerateSwapchainFormats" => (
            fp!(
                pfn::EnumerateSwapchainFormats,
                e::enumerate_swapchain_formats
            ),
            Core,
        ),
        "xrCreateSwapchain" => (fp!(pfn::CreateSwapchain, e::create_swapchain), Core),
        "xrDestroySwapchain" => (fp!(pfn::DestroySwapchain, e::destroy_swapchain), Core),
        "xrEnumerateSwapchainImages" => (
            fp!(pfn::EnumerateSwapchainImages, e::enumerate_swapchain_images),
            Core,
        ),
        "xrAcquireSwapchainImage" => (
            fp!(pfn::AcquireSwapchainImage, e::acquire_swapchain_image),
            Core,
        ),
        "xrWaitSwapchainImage" => (fp!(pfn::WaitSwapchainImage, e::wait_swapchain_image), Core),
        "xrReleaseSwapchainImage" => (
            fp!(pfn::ReleaseSwapchainImage, e::release_swapchain_image),
            Core,
        ),
        "xrBeginSession" => (fp!(pfn::BeginSession, e::begin_session), Core),
        "xrEndSession" => (fp!(pfn::EndSession, e::end_session), Core),
        "xrRequestExitSession" => (fp!(pfn::RequestExitSession, e::request_exit_session), Core),
        "xrWaitFrame" => (fp!(pfn::WaitFrame, e::wait_frame), Core),
        "xrBeginFrame" => (fp!(pfn::BeginFrame, e::begin_frame), Core),
        "xrEndFrame" => (fp!(pfn::EndFrame, e::end_frame), Core),
        "xrLocateViews" => (fp!(pfn::LocateViews, e::locate_views), Core),
        "xrStringToPath" => (fp!(pfn::StringToPath, e::string_to_path), Core),
        "xrPathToString" => (fp!(pfn::PathToString, e::path_to_string), Core),
        "xrCreateActionSet" => (fp!(pfn::CreateActionSet, e::create_action_set), Core),
        "xrDestroyActionSet" => (fp!(pfn::DestroyActionSet, e::destroy_action_set), Core),
        "xrCreateAction" => (fp!(pfn::CreateAction, e::create_action), Core),
        "xrDestroyAction" => (fp!(pfn::DestroyAction, e::destroy_action), Core),
        "xrSuggestInteractionProfileBindings" => (
            fp!(
                pfn::SuggestInteractionProfileBindings,
                e::suggest_interaction_profile_bindings
            ),
            Core,
        ),
        "xrAttachSessionActionSets" => (
            fp!(pfn::AttachSessionActionSets, e::attach_session_action_sets),
            Core,
        ),
        "xrGetCurrentInteractionProfile" => (
            fp!(
                pfn::GetCurrentInteractionProfile,
                e::get_current_interaction_profile
            ),
            Core,
        ),
        "xrSyncActions" => (fp!(pfn::SyncActions, e::sync_actions), Core),
        "xrGetActionStateBoolean" => (
            fp!(pfn::GetActionStateBoolean, e::get_action_state_boolean),
            Core,
        ),
        "xrGetActionStateFloat" => (
            fp!(pfn::GetActionStateFloat, e::get_action_state_float),
            Core,
        ),
        "xrGetActionStateVector2f" => (
            fp!(pfn::GetActionStateVector2f, e::get_action_state_vector2f),
            Core,
        ),
        "xrGetActionStatePose" => (fp!(pfn::GetActionStatePose, e::get_action_state_pose), Core),
        "xrEnumerateBoundSourcesForAction" => (
            fp!(
                pfn::EnumerateBoundSourcesForAction,
                e::enumerate_bound_sources_for_action
            ),
            Core,
        ),
        "xrGetInputSourceLocalizedName" => (
            fp!(
                pfn::GetInputSourceLocalizedName,
                e::get_input_source_localized_name
            ),
            Core,
        ),
        "xrApplyHapticFeedback" => (
            fp!(pfn::ApplyHapticFeedback, e::apply_haptic_feedback),
            Core,
        ),
        "xrStopHapticFeedback" => (fp!(pfn::StopHapticFeedback, e::stop_haptic_feedback), Core),
        "xrGetVulkanGraphicsRequirements2KHR" => (
            fp!(
                pfn::GetVulkanGraphicsRequirements2KHR,
                e::get_vulkan_graphics_requirements
            ),
            VulkanEnable2,
        ),
        "xrCreateVulkanInstanceKHR" => (
            fp!(pfn::CreateVulkanInstanceKHR, e::create_vulkan_instance),
            VulkanEnable2,
        ),
        "xrCreateVulkanDeviceKHR" => (
            fp!(pfn::CreateVulkanDeviceKHR, e::create_vulkan_device),
            VulkanEnable2,
        ),
        "xrGetVulkanGraphicsDevice2KHR" => (
            fp!(
                pfn::GetVulkanGraphicsDevice2KHR,
                e::get_vulkan_graphics_device2
            ),
            VulkanEnable2,
        ),
        "xrGetVulkanGraphicsRequirementsKHR" => (
            fp!(
                pfn::GetVulkanGraphicsRequirementsKHR,
                e::get_vulkan_graphics_requirements
            ),
            VulkanEnable,
        ),
        "xrGetVulkanGraphicsDeviceKHR" => (
            fp!(
                pfn::GetVulkanGraphicsDeviceKHR,
                e::get_vulkan_graphics_device
            ),
            VulkanEnable,
        ),
        "xrGetVulkanInstanceExtensionsKHR" => (
            fp!(
                pfn::GetVulkanInstanceExtensionsKHR,
                e::get_vulkan_extensions
            ),
            VulkanEnable,
        ),
        "xrGetVulkanDeviceExtensionsKHR" => (
            fp!(pfn::GetVulkanDeviceExtensionsKHR, e::get_vulkan_extensions),
            VulkanEnable,
        ),
        "xrGetVisibilityMaskKHR" => (
            fp!(pfn::GetVisibilityMaskKHR, e::get_visibility_mask),
            VisibilityMask,
        ),
        _ => return None,
    };
    Some(f)
}

fn enabled(needs: Needs, exts: &Extensions) -> bool {
    match needs {
        Needs::Core => true,
        Needs::VulkanEnable2 => exts.vulkan_enable2,
        Needs::VulkanEnable => exts.vulkan_enable,
        Needs::VisibilityMask => exts.visibility_mask,
    }
}

/// Functions that may be looked up without an instance.
const GLOBAL: [&str; 3] = [
    "xrEnumerateInstanceExtensionProperties",
    "xrEnumerateApiLayerProperties",
    "xrCreateInstance",
];

/// The runtime's `xrGetInstanceProcAddr`.
///
/// # Safety
/// `name` must be a NUL-terminated string and `function` valid for writes (null pointers
/// are rejected with XR_ERROR_VALIDATION_FAILURE).
pub unsafe extern "system" fn get_instance_proc_addr(
    instance: xr::Instance,
    name: *const c_char,
    function: *mut Option<pfn::VoidFunction>,
) -> xr::Result {
    call("xrGetInstanceProcAddr", instance.into_raw(), || {
        ffi::non_null(function)?;
        // SAFETY: checked non-null; the app's output slot.
        unsafe { *function = None };
        // SAFETY: the app passes a NUL-terminated name.
        let name = unsafe { ffi::read_cstr(name)? };
        let found = if instance == xr::Instance::NULL {
            if !GLOBAL.contains(&name) {
                return Err(xr::Result::ERROR_HANDLE_INVALID);
            }
            lookup(name)
        } else {
            let rt = registry::lock();
            let exts = rt.instance(instance)?.extensions;
            lookup(name).filter(|(_, needs)| enabled(*needs, &exts))
        };
        let (f, _) = found.ok_or(xr::Result::ERROR_FUNCTION_UNSUPPORTED)?;
        // SAFETY: checked non-null above.
        unsafe { *function = Some(f) };
        Ok(xr::Result::SUCCESS)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every core function the `openxr` crate loads must resolve.
    #[test]
    fn every_core_function_is_served() {
        let core = [
            "xrGetInstanceProcAddr",
            "xrEnumerateApiLayerProperties",
            "xrEnumerateInstanceExtensionProperties",
            "xrCreateInstance",
            "xrDestroyInstance",
            "xrResultToString",
            "xrStructureTypeToString",
            "xrGetInstanceProperties",
            "xrGetSystem",
            "xrGetSystemProperties",
            "xrCreateSession",
            "xrDestroySession",
            "xrDestroySpace",
            "xrEnumerateSwapchainFormats",
            "xrCreateSwapchain",
            "xrDestroySwapchain",
            "xrEnumerateSwapchainImages",
            "xrAcquireSwapchainImage",
            "xrWaitSwapchainImage",
            "xrReleaseSwapchainImage",
            "xrBeginSession",
            "xrEndSession",
            "xrRequestExitSession",
            "xrEnumerateReferenceSpaces",
            "xrCreateReferenceSpace",
            "xrCreateActionSpace",
            "xrLocateSpace",
            "xrEnumerateViewConfigurations",
            "xrEnumerateEnvironmentBlendModes",
            "xrGetViewConfigurationProperties",
            "xrEnumerateViewConfigurationViews",
            "xrBeginFrame",
            "xrLocateViews",
            "xrEndFrame",
            "xrWaitFrame",
            "xrApplyHapticFeedback",
            "xrStopHapticFeedback",
            "xrPollEvent",
            "xrStringToPath",
            "xrPathToString",
            "xrGetReferenceSpaceBoundsRect",
            "xrGetActionStateBoolean",
            "xrGetActionStateFloat",
            "xrGetActionStateVector2f",
            "xrGetActionStatePose",
            "xrCreateActionSet",
            "xrDestroyActionSet",
            "xrCreateAction",
            "xrDestroyAction",
            "xrSuggestInteractionProfileBindings",
            "xrAttachSessionActionSets",
            "xrGetCurrentInteractionProfile",
            "xrSyncActions",
            "xrEnumerateBoundSourcesForAction",
            "xrGetInputSourceLocalizedName",
        ];
        for name in core {
            assert!(matches!(lookup(name), Some((_, Needs::Core))), "{name}");
        }
    }
}
