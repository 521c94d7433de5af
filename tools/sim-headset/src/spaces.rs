//! Reference and action spaces. The head never moves, so VIEW, LOCAL and STAGE coincide
//! with the world origin; the only moving thing is the eye-gaze pose.

use openxr_sys as xr;
use openxr_sys::Handle as _;

use crate::ffi::{self, XrResult};
use crate::gaze_script::SampleStatus;
use crate::pose;
use crate::registry::{Runtime, Space, SpaceKind};

const REFERENCE_SPACES: [xr::ReferenceSpaceType; 3] = [
    xr::ReferenceSpaceType::VIEW,
    xr::ReferenceSpaceType::LOCAL,
    xr::ReferenceSpaceType::STAGE,
];
/// The play area reported for STAGE, in metres (a small room-scale area).
const STAGE_SIZE: (f32, f32) = (3.0, 3.0);

fn fully_tracked() -> xr::SpaceLocationFlags {
    xr::SpaceLocationFlags::ORIENTATION_VALID
        | xr::SpaceLocationFlags::POSITION_VALID
        | xr::SpaceLocationFlags::ORIENTATION_TRACKED
        | xr::SpaceLocationFlags::POSITION_TRACKED
}

/// A sample the tracker still reports but no longer tracks (e.g. held through a blink).
fn valid_untracked() -> xr::SpaceLocationFlags {
    xr::SpaceLocationFlags::ORIENTATION_VALID | xr::SpaceLocationFlags::POSITION_VALID
}

/// A space's pose in the world at the current frame.
pub struct Located {
    pub pose: xr::Posef,
    pub flags: xr::SpaceLocationFlags,
    /// For eye-gaze samples: when the sample was taken.
    pub sample_time: Option<xr::Time>,
}

/// Locates `space`, which must belong to `session`.
pub fn locate_in_world(
    rt: &Runtime,
    space: xr::Space,
    session: xr::Session,
) -> Result<Located, xr::Result> {
    let sp = rt.space(space)?;
    if sp.session != session.into_raw() {
        return Err(xr::Result::ERROR_VALIDATION_FAILURE);
    }
    match sp.kind {
        SpaceKind::Reference(_) => Ok(Located {
            pose: sp.offset,
            flags: fully_tracked(),
            sample_time: None,
        }),
        SpaceKind::Action { action, subaction } => {
            let not_located = Located {
                pose: pose::IDENTITY,
                flags: xr::SpaceLocationFlags::EMPTY,
                sample_time: None,
            };
            if !crate::actions::gaze_pose_active(rt, session, action, subaction)? {
                return Ok(not_located);
            }
            let s = rt.session(session)?;
            let inst = rt.instance(xr::Instance::from_raw(s.instance))?;
            let frame = s.frames.waits.saturating_sub(1);
            let sample = inst.config.gaze.sample(frame);
            let flags = match sample.status {
                SampleStatus::Valid => fully_tracked(),
                SampleStatus::Untracked => valid_untracked(),
                SampleStatus::Invalid => return Ok(not_located),
            };
            // The gaze ray starts at the head centre, pointing where the script says.
            let gaze = xr::Posef {
                orientation: pose::gaze_orientation(
                    sample.yaw_deg.to_radians(),
                    sample.pitch_deg.to_radians(),
                ),
                position: pose::IDENTITY.position,
            };
            Ok(Located {
                pose: pose::compose(gaze, sp.offset),
                flags,
                sample_time: Some(xr::Time::from_nanos(s.frames.clock.gaze_sample_ns())),
            })
        }
    }
}

pub fn enumerate_reference_spaces(
    rt: &Runtime,
    session: xr::Session,
    capacity: u32,
    count: *mut u32,
    out: *mut xr::ReferenceSpaceType,
) -> XrResult {
    rt.session(session)?;
    // SAFETY: the app's output array per the two-call idiom.
    unsafe {
        ffi::two_call(capacity, count, out, REFERENCE_SPACES.len(), |i, t| {
            *t = REFERENCE_SPACES[i];
            Ok(())
        })
    }
}

fn insert_space(rt: &mut Runtime, space: Space, out: *mut xr::Space) -> XrResult {
    ffi::non_null(out)?;
    let id = rt.new_id();
    rt.spaces.insert(id, space);
    // SAFETY: checked non-null.
    unsafe { *out = xr::Space::from_raw(id) };
    Ok(xr::Result::SUCCESS)
}

pub fn create_reference_space(
    rt: &mut Runtime,
    session: xr::Session,
    info: &xr::ReferenceSpaceCreateInfo,
    out: *mut xr::Space,
) -> XrResult {
    rt.live_session(session)?;
    ffi::check_type(info.ty, xr::StructureType::REFERENCE_SPACE_CREATE_INFO)?;
    if !REFERENCE_SPACES.contains(&info.reference_space_type) {
        return Err(xr::Result::ERROR_REFERENCE_SPACE_UNSUPPORTED);
    }
    if !pose::is_valid(&info.pose_in_reference_space) {
        return Err(xr::Result::ERROR_POSE_INVALID);
    }
    let space = Space {
        session: session.into_raw(),
        kind: SpaceKind::Reference(info.reference_space_type),
        offset: info.pose_in_reference_space,
    };
    insert_space(rt, space, out)
}

pub fn create_action_space(
    rt: &mut Runtime,
    session: xr::Session,
    info: &xr::ActionSpaceCreateInfo,
    out: *mut xr::Space,
) -> XrResult {
    let s = rt.live_session(session)?;
    ffi::check_type(info.ty, xr::StructureType::ACTION_SPACE_CREATE_INFO)?;
    let action = rt.action(info.action)?;
    if action.instance != s.instance {
        return Err(xr::Result::ERROR_HANDLE_INVALID);
    }
    if action.ty != xr::ActionType::POSE_INPUT {
        return Err(xr::Result::ERROR_ACTION_TYPE_MISMATCH);
    }
    let sub = info.subaction_path.into_raw();
    if sub != 0 && !action.subaction_paths.contains(&sub) {
        return Err(xr::Result::ERROR_PATH_UNSUPPORTED);
    }
    if !pose::is_valid(&info.pose_in_action_space) {
        return Err(xr::Result::ERROR_POSE_INVALID);
    }
    let space = Space {
        session: session.into_raw(),
        kind: SpaceKind::Action {
            action: info.action.into_raw(),
            subaction: sub,
        },
        offset: info.pose_in_action_space,
    };
    insert_space(rt, space, out)
}

pub fn destroy_space(rt: &mut Runtime, space: xr::Space) -> XrResult {
    rt.spaces
        .remove(&space.into_raw())
        .ok_or(xr::Result::ERROR_HANDLE_INVALID)?;
    Ok(xr::Result::SUCCESS)
}

pub fn get_reference_space_bounds_rect(
    rt: &Runtime,
    session: xr::Session,
    ty: xr::ReferenceSpaceType,
    bounds: &mut xr::Extent2Df,
) -> XrResult {
    rt.live_session(session)?;
    if !REFERENCE_SPACES.contains(&ty) {
        return Err(xr::Result::ERROR_REFERENCE_SPACE_UNSUPPORTED);
    }
    if ty == xr::ReferenceSpaceType::STAGE {
        *bounds = xr::Extent2Df {
            width: STAGE_SIZE.0,
            height: STAGE_SIZE.1,
        };
        Ok(xr::Result::SUCCESS)
    } else {
        *bounds = xr::Extent2Df::default();
        Ok(xr::Result::SPACE_BOUNDS_UNAVAILABLE)
    }
}

pub fn locate_space(
    rt: &Runtime,
    space: xr::Space,
    base: xr::Space,
    time: xr::Time,
    location: &mut xr::SpaceLocation,
) -> XrResult {
    ffi::check_type(location.ty, xr::StructureType::SPACE_LOCATION)?;
    let session = xr::Session::from_raw(rt.space(space)?.session);
    rt.live_session(session)?;
    if time.as_nanos() <= 0 {
        return Err(xr::Result::ERROR_TIME_INVALID);
    }
    let a = locate_in_world(rt, space, session)?;
    let b = locate_in_world(rt, base, session)?;
    let flags = xr::SpaceLocationFlags::from_raw(a.flags.into_raw() & b.flags.into_raw());
    location.location_flags = flags;
    location.pose = if flags.is_empty() {
        pose::IDENTITY
    } else {
        pose::compose(pose::inverse(b.pose), a.pose)
    };
    if let Some(t) = a.sample_time.filter(|_| !flags.is_empty()) {
        // SAFETY: `next` is the app's chain of output structures.
        if let Some(p) = unsafe {
            ffi::find_in_chain(location.next, xr::StructureType::EYE_GAZE_SAMPLE_TIME_EXT)
        } {
            // SAFETY: the chain entry has this structure's type, so it is this structure.
            unsafe { (*(p as *mut xr::EyeGazeSampleTimeEXT)).time = t };
        }
    }
    Ok(xr::Result::SUCCESS)
}
