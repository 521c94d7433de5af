//! The eyes: fixed poses around the head and the Vive Pro Eye's asymmetric fields of view.

use openxr_sys as xr;

use crate::ffi::{self, XrResult};
use crate::pose;
use crate::registry::Runtime;

/// Half the interpupillary distance (63 mm IPD), in metres.
pub const HALF_IPD: f32 = 0.0315;

/// Field of view of eye 0 (left) or 1 (right), in radians. The left eye sees further to the
/// left than to the right (its nose side); the right eye mirrors it.
pub fn eye_fov(eye: usize) -> xr::Fovf {
    let (outer, inner) = (0.9470, 0.8922);
    let (angle_left, angle_right) = if eye == 0 {
        (-outer, inner)
    } else {
        (-inner, outer)
    };
    xr::Fovf {
        angle_left,
        angle_right,
        angle_up: 0.9733,
        angle_down: -0.9700,
    }
}

/// The eye's pose in the head (= world, as the head sits at the origin looking down -Z).
pub fn eye_pose(eye: usize) -> xr::Posef {
    let mut p = pose::IDENTITY;
    p.position.x = if eye == 0 { -HALF_IPD } else { HALF_IPD };
    p
}

pub fn locate_views(
    rt: &Runtime,
    session: xr::Session,
    info: &xr::ViewLocateInfo,
    state: &mut xr::ViewState,
    capacity: u32,
    count: *mut u32,
    views: *mut xr::View,
) -> XrResult {
    rt.live_session(session)?;
    ffi::check_type(info.ty, xr::StructureType::VIEW_LOCATE_INFO)?;
    ffi::check_type(state.ty, xr::StructureType::VIEW_STATE)?;
    if info.view_configuration_type != xr::ViewConfigurationType::PRIMARY_STEREO {
        return Err(xr::Result::ERROR_VIEW_CONFIGURATION_TYPE_UNSUPPORTED);
    }
    if info.display_time.as_nanos() <= 0 {
        return Err(xr::Result::ERROR_TIME_INVALID);
    }
    let base = crate::spaces::locate_in_world(rt, info.space, session)?;
    let base_inv = pose::inverse(base.pose);
    // Space and view flags share their bit values.
    state.view_state_flags = xr::ViewStateFlags::from_raw(base.flags.into_raw());
    // SAFETY: the app's output array per the two-call idiom.
    unsafe {
        ffi::two_call(capacity, count, views, 2, |eye, v| {
            ffi::check_type(v.ty, xr::StructureType::VIEW)?;
            v.pose = pose::compose(base_inv, eye_pose(eye));
            v.fov = eye_fov(eye);
            Ok(())
        })
    }
}
