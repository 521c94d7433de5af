//! The one system: a head-mounted display with a stereo view configuration.

use openxr_sys as xr;

use crate::config::EyeGazeMode;
use crate::ffi::{self, XrResult};
use crate::registry::{Instance, Runtime};

pub const SYSTEM_ID: u64 = 1;
/// Composition layers accepted per frame (the spec's minimum is 16).
pub const MAX_LAYERS: u32 = 16;

pub fn check_system(system: xr::SystemId) -> Result<(), xr::Result> {
    if system.into_raw() == SYSTEM_ID {
        Ok(())
    } else {
        Err(xr::Result::ERROR_SYSTEM_INVALID)
    }
}

fn check_view_config(ty: xr::ViewConfigurationType) -> Result<(), xr::Result> {
    if ty == xr::ViewConfigurationType::PRIMARY_STEREO {
        Ok(())
    } else {
        Err(xr::Result::ERROR_VIEW_CONFIGURATION_TYPE_UNSUPPORTED)
    }
}

/// Eye gaze is available to the app: the extension enabled and the tracker "present".
pub fn eye_gaze_supported(instance: &Instance) -> bool {
    instance.extensions.eye_gaze
        && matches!(
            instance.config.eye_gaze,
            EyeGazeMode::On | EyeGazeMode::Inactive
        )
}

pub fn get_system(
    rt: &Runtime,
    instance: xr::Instance,
    info: &xr::SystemGetInfo,
    out: *mut xr::SystemId,
) -> XrResult {
    rt.instance(instance)?;
    ffi::check_type(info.ty, xr::StructureType::SYSTEM_GET_INFO)?;
    ffi::non_null(out)?;
    match info.form_factor {
        xr::FormFactor::HEAD_MOUNTED_DISPLAY => {
            // SAFETY: checked non-null.
            unsafe { *out = xr::SystemId::from_raw(SYSTEM_ID) };
            Ok(xr::Result::SUCCESS)
        }
        xr::FormFactor::HANDHELD_DISPLAY => Err(xr::Result::ERROR_FORM_FACTOR_UNSUPPORTED),
        _ => Err(xr::Result::ERROR_VALIDATION_FAILURE),
    }
}

pub fn get_system_properties(
    rt: &Runtime,
    instance: xr::Instance,
    system: xr::SystemId,
    props: &mut xr::SystemProperties,
) -> XrResult {
    let inst = rt.instance(instance)?;
    check_system(system)?;
    ffi::check_type(props.ty, xr::StructureType::SYSTEM_PROPERTIES)?;
    props.system_id = system;
    props.vendor_id = 0;
    ffi::write_fixed(
        &mut props.system_name,
        "fovea simulated headset (Vive Pro Eye-like)",
    );
    props.graphics_properties = xr::SystemGraphicsProperties {
        max_swapchain_image_height: crate::config::MAX_IMAGE_SIZE,
        max_swapchain_image_width: crate::config::MAX_IMAGE_SIZE,
        max_layer_count: MAX_LAYERS,
    };
    props.tracking_properties = xr::SystemTrackingProperties {
        orientation_tracking: xr::TRUE,
        position_tracking: xr::TRUE,
    };
    if inst.extensions.eye_gaze {
        // SAFETY: `next` is the app's chain of output structures.
        if let Some(p) = unsafe {
            ffi::find_in_chain(
                props.next,
                xr::StructureType::SYSTEM_EYE_GAZE_INTERACTION_PROPERTIES_EXT,
            )
        } {
            // SAFETY: the chain entry has this structure's type, so it is this structure.
            let p = unsafe { &mut *(p as *mut xr::SystemEyeGazeInteractionPropertiesEXT) };
            p.supports_eye_gaze_interaction = eye_gaze_supported(inst).into();
        }
    }
    Ok(xr::Result::SUCCESS)
}

pub fn enumerate_view_configurations(
    rt: &Runtime,
    instance: xr::Instance,
    system: xr::SystemId,
    capacity: u32,
    count: *mut u32,
    out: *mut xr::ViewConfigurationType,
) -> XrResult {
    rt.instance(instance)?;
    check_system(system)?;
    // SAFETY: the app's output array per the two-call idiom.
    unsafe {
        ffi::two_call(capacity, count, out, 1, |_, t| {
            *t = xr::ViewConfigurationType::PRIMARY_STEREO;
            Ok(())
        })
    }
}

pub fn get_view_configuration_properties(
    rt: &Runtime,
    instance: xr::Instance,
    system: xr::SystemId,
    ty: xr::ViewConfigurationType,
    props: &mut xr::ViewConfigurationProperties,
) -> XrResult {
    rt.instance(instance)?;
    check_system(system)?;
    check_view_config(ty)?;
    ffi::check_type(props.ty, xr::StructureType::VIEW_CONFIGURATION_PROPERTIES)?;
    props.view_configuration_type = ty;
    props.fov_mutable = xr::FALSE;
    Ok(xr::Result::SUCCESS)
}

pub fn enumerate_view_configuration_views(
    rt: &Runtime,
    instance: xr::Instance,
    system: xr::SystemId,
    ty: xr::ViewConfigurationType,
    capacity: u32,
    count: *mut u32,
    out: *mut xr::ViewConfigurationView,
) -> XrResult {
    let inst = rt.instance(instance)?;
    check_system(system)?;
    check_view_config(ty)?;
    let (w, h) = inst.config.eye_size;
    let max = crate::config::MAX_IMAGE_SIZE;
    // SAFETY: the app's output array per the two-call idiom.
    unsafe {
        ffi::two_call(capacity, count, out, 2, |_, v| {
            ffi::check_type(v.ty, xr::StructureType::VIEW_CONFIGURATION_VIEW)?;
            v.recommended_image_rect_width = w;
            v.recommended_image_rect_height = h;
            v.max_image_rect_width = max;
            v.max_image_rect_height = max;
            v.recommended_swapchain_sample_count = 1;
            v.max_swapchain_sample_count = 1;
            Ok(())
        })
    }
}

pub fn enumerate_environment_blend_modes(
    rt: &Runtime,
    instance: xr::Instance,
    system: xr::SystemId,
    ty: xr::ViewConfigurationType,
    capacity: u32,
    count: *mut u32,
    out: *mut xr::EnvironmentBlendMode,
) -> XrResult {
    rt.instance(instance)?;
    check_system(system)?;
    check_view_config(ty)?;
    // SAFETY: the app's output array per the two-call idiom.
    unsafe {
        ffi::two_call(capacity, count, out, 1, |_, m| {
            *m = xr::EnvironmentBlendMode::OPAQUE;
            Ok(())
        })
    }
}
