//! Actions: sets, actions, suggested bindings, attachment, sync and state queries. Only the
//! eye-gaze pose can ever be active; controller actions exist but stay inactive, like a
//! headset whose controllers are switched off.

use std::ffi::c_char;

use openxr_sys as xr;
use openxr_sys::Handle as _;

use crate::config::EyeGazeMode;
use crate::ffi::{self, XrResult};
use crate::interaction_profiles::{
    self as profiles, EYES_USER_PATH, EYE_GAZE_PROFILE, GAZE_POSE_PATH,
};
use crate::registry::{Action, ActionSet, Event, Instance, Runtime};
use crate::system::eye_gaze_supported;

/// Action and action-set names: non-empty, `[a-z0-9-_.]`.
fn check_name(name: Option<String>) -> Result<String, xr::Result> {
    match name {
        Some(n)
            if !n.is_empty()
                && n.chars()
                    .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || "-_.".contains(c)) =>
        {
            Ok(n)
        }
        _ => Err(xr::Result::ERROR_PATH_FORMAT_INVALID),
    }
}

fn check_localized(name: Option<String>) -> Result<(), xr::Result> {
    match name {
        Some(n) if !n.is_empty() => Ok(()),
        _ => Err(xr::Result::ERROR_LOCALIZED_NAME_INVALID),
    }
}

/// The id of an already interned path string, if the app ever made it.
fn path_id(inst: &Instance, s: &str) -> Option<u64> {
    inst.paths.iter().position(|p| p == s).map(|k| k as u64 + 1)
}

fn path_is(inst: &Instance, id: u64, s: &str) -> bool {
    id != 0 && inst.paths.get(id as usize - 1).is_some_and(|p| p == s)
}

pub fn create_action_set(
    rt: &mut Runtime,
    instance: xr::Instance,
    info: &xr::ActionSetCreateInfo,
    out: *mut xr::ActionSet,
) -> XrResult {
    rt.instance(instance)?;
    ffi::check_type(info.ty, xr::StructureType::ACTION_SET_CREATE_INFO)?;
    ffi::non_null(out)?;
    let name = check_name(ffi::read_fixed(&info.action_set_name))?;
    check_localized(ffi::read_fixed(&info.localized_action_set_name))?;
    let owner = instance.into_raw();
    if rt
        .action_sets
        .values()
        .any(|s| s.instance == owner && s.name == name)
    {
        return Err(xr::Result::ERROR_NAME_DUPLICATED);
    }
    let id = rt.new_id();
    rt.action_sets.insert(
        id,
        ActionSet {
            instance: owner,
            name,
            attached: false,
        },
    );
    // SAFETY: checked non-null.
    unsafe { *out = xr::ActionSet::from_raw(id) };
    Ok(xr::Result::SUCCESS)
}

/// Destroys an action set and (as OpenXR does) its actions; actions the app had not
/// destroyed are reported as destroyed with their parent.
pub fn destroy_action_set(rt: &mut Runtime, set: xr::ActionSet) -> XrResult {
    let s = rt
        .action_sets
        .remove(&set.into_raw())
        .ok_or(xr::Result::ERROR_HANDLE_INVALID)?;
    let before = rt.actions.len();
    rt.actions.retain(|_, a| a.set != set.into_raw());
    let orphans = (before - rt.actions.len()) as u64;
    if let Some(inst) = rt.instances.get_mut(&s.instance) {
        inst.log.destroyed_with_parent.actions += orphans;
    }
    Ok(xr::Result::SUCCESS)
}

pub fn create_action(
    rt: &mut Runtime,
    set: xr::ActionSet,
    info: &xr::ActionCreateInfo,
    out: *mut xr::Action,
) -> XrResult {
    let s = rt.action_set(set)?;
    ffi::check_type(info.ty, xr::StructureType::ACTION_CREATE_INFO)?;
    ffi::non_null(out)?;
    if s.attached {
        return Err(xr::Result::ERROR_ACTIONSETS_ALREADY_ATTACHED);
    }
    let instance = s.instance;
    let name = check_name(ffi::read_fixed(&info.action_name))?;
    check_localized(ffi::read_fixed(&info.localized_action_name))?;
    let known_types = [
        xr::ActionType::BOOLEAN_INPUT,
        xr::ActionType::FLOAT_INPUT,
        xr::ActionType::VECTOR2F_INPUT,
        xr::ActionType::POSE_INPUT,
        xr::ActionType::VIBRATION_OUTPUT,
    ];
    if !known_types.contains(&info.action_type) {
        return Err(xr::Result::ERROR_VALIDATION_FAILURE);
    }
    if rt
        .actions
        .values()
        .any(|a| a.set == set.into_raw() && a.name == name)
    {
        return Err(xr::Result::ERROR_NAME_DUPLICATED);
    }
    let mut subaction_paths = Vec::new();
    for k in 0..info.count_subaction_paths as usize {
        // SAFETY: the app passes `count_subaction_paths` paths.
        let p = unsafe { *info.subaction_paths.add(k) };
        let s = rt.path_str(instance, p)?;
        if !profiles::TOP_LEVEL_PATHS.contains(&s) {
            return Err(xr::Result::ERROR_PATH_UNSUPPORTED);
        }
        if subaction_paths.contains(&p.into_raw()) {
            return Err(xr::Result::ERROR_PATH_UNSUPPORTED);
        }
        subaction_paths.push(p.into_raw());
    }
    let id = rt.new_id();
    rt.actions.insert(
        id,
        Action {
            instance,
            set: set.into_raw(),
            name,
            ty: info.action_type,
            subaction_paths,
        },
    );
    // SAFETY: checked non-null.
    unsafe { *out = xr::Action::from_raw(id) };
    Ok(xr::Result::SUCCESS)
}

pub fn destroy_action(rt: &mut Runtime, action: xr::Action) -> XrResult {
    rt.actions
        .remove(&action.into_raw())
        .ok_or(xr::Result::ERROR_HANDLE_INVALID)?;
    Ok(xr::Result::SUCCESS)
}

pub fn suggest_bindings(
    rt: &mut Runtime,
    instance: xr::Instance,
    info: &xr::InteractionProfileSuggestedBinding,
) -> XrResult {
    let owner = instance.into_raw();
    let inst = rt.instance(instance)?;
    ffi::check_type(
        info.ty,
        xr::StructureType::INTERACTION_PROFILE_SUGGESTED_BINDING,
    )?;
    if rt
        .action_sets
        .values()
        .any(|s| s.instance == owner && s.attached)
    {
        return Err(xr::Result::ERROR_ACTIONSETS_ALREADY_ATTACHED);
    }
    let eye_gaze = inst.extensions.eye_gaze;
    let profile = rt.path_str(owner, info.interaction_profile)?;
    if profiles::user_paths(profile, eye_gaze).is_none() {
        return Err(xr::Result::ERROR_PATH_UNSUPPORTED);
    }
    if info.count_suggested_bindings > 0 {
        ffi::non_null(info.suggested_bindings)?;
    }
    let mut bindings = Vec::new();
    for k in 0..info.count_suggested_bindings as usize {
        // SAFETY: the app passes `count_suggested_bindings` bindings.
        let b = unsafe { *info.suggested_bindings.add(k) };
        let action = rt.action(b.action)?;
        if action.instance != owner {
            return Err(xr::Result::ERROR_HANDLE_INVALID);
        }
        let path = rt.path_str(owner, b.binding)?;
        if !profiles::binding_allowed(profile, path, eye_gaze) {
            return Err(xr::Result::ERROR_PATH_UNSUPPORTED);
        }
        bindings.push((b.action.into_raw(), b.binding.into_raw()));
    }
    // A new suggestion for a profile replaces the previous one, as the spec says.
    rt.instance_mut(instance)?
        .suggested
        .insert(info.interaction_profile.into_raw(), bindings);
    Ok(xr::Result::SUCCESS)
}

/// Whether `action` is bound to the gaze pose in the eye-gaze profile.
fn bound_to_gaze(inst: &Instance, action: u64) -> bool {
    let Some(profile) = path_id(inst, EYE_GAZE_PROFILE) else {
        return false;
    };
    inst.suggested.get(&profile).is_some_and(|bindings| {
        bindings.iter().any(|&(a, p)| {
            a == action
                && (path_is(inst, p, GAZE_POSE_PATH)
                    || path_is(inst, p, "/user/eyes_ext/input/gaze_ext"))
        })
    })
}

/// The eye tracker delivers to this instance's bindings at all (independent of syncing).
fn gaze_delivering(inst: &Instance) -> bool {
    eye_gaze_supported(inst) && inst.config.eye_gaze == EyeGazeMode::On
}

/// Whether the gaze pose `action` is active for `subaction` in `session` now: bound,
/// attached, synced while FOCUSED, and the tracker configured to deliver.
pub fn gaze_pose_active(
    rt: &Runtime,
    session: xr::Session,
    action: u64,
    subaction: u64,
) -> Result<bool, xr::Result> {
    let s = rt.session(session)?;
    let inst = rt.instance(xr::Instance::from_raw(s.instance))?;
    let a = rt
        .actions
        .get(&action)
        .ok_or(xr::Result::ERROR_HANDLE_INVALID)?;
    let subaction_ok = subaction == 0 || path_is(inst, subaction, EYES_USER_PATH);
    Ok(a.ty == xr::ActionType::POSE_INPUT
        && subaction_ok
        && gaze_delivering(inst)
        && bound_to_gaze(inst, action)
        && s.attached_sets.contains(&a.set)
        && s.synced_focused
        && s.synced_sets.contains(&a.set))
}

pub fn attach_action_sets(
    rt: &mut Runtime,
    session: xr::Session,
    info: &xr::SessionActionSetsAttachInfo,
) -> XrResult {
    let s = rt.live_session(session)?;
    ffi::check_type(info.ty, xr::StructureType::SESSION_ACTION_SETS_ATTACH_INFO)?;
    if !s.attached_sets.is_empty() {
        return Err(xr::Result::ERROR_ACTIONSETS_ALREADY_ATTACHED);
    }
    if info.count_action_sets > 0 {
        ffi::non_null(info.action_sets)?;
    }
    let instance = s.instance;
    let mut sets = Vec::new();
    for k in 0..info.count_action_sets as usize {
        // SAFETY: the app passes `count_action_sets` handles.
        let h = unsafe { *info.action_sets.add(k) };
        if rt.action_set(h)?.instance != instance {
            return Err(xr::Result::ERROR_HANDLE_INVALID);
        }
        sets.push(h.into_raw());
    }
    for id in &sets {
        if let Some(set) = rt.action_sets.get_mut(id) {
            set.attached = true;
        }
    }
    let inst = &rt.instances[&instance];
    let gaze_bound = rt
        .actions
        .iter()
        .any(|(id, a)| sets.contains(&a.set) && bound_to_gaze(inst, *id));
    let announce = gaze_bound && gaze_delivering(inst);
    rt.session_mut(session)?.attached_sets = sets;
    if announce {
        // The eye tracker's profile is now current for /user/eyes_ext.
        rt.instance_mut(xr::Instance::from_raw(instance))?
            .events
            .push_back(Event::InteractionProfileChanged {
                session: session.into_raw(),
            });
    }
    Ok(xr::Result::SUCCESS)
}

pub fn sync_actions(
    rt: &mut Runtime,
    session: xr::Session,
    info: &xr::ActionsSyncInfo,
) -> XrResult {
    let s = rt.live_session(session)?;
    ffi::check_type(info.ty, xr::StructureType::ACTIONS_SYNC_INFO)?;
    if info.count_active_action_sets > 0 {
        ffi::non_null(info.active_action_sets)?;
    }
    let mut synced = std::collections::HashSet::new();
    for k in 0..info.count_active_action_sets as usize {
        // SAFETY: the app passes `count_active_action_sets` entries.
        let a = unsafe { *info.active_action_sets.add(k) };
        rt.action_set(a.action_set)?;
        if !s.attached_sets.contains(&a.action_set.into_raw()) {
            return Err(xr::Result::ERROR_ACTIONSET_NOT_ATTACHED);
        }
        let sub = a.subaction_path.into_raw();
        if sub != 0
            && !profiles::TOP_LEVEL_PATHS.contains(&rt.path_str(s.instance, a.subaction_path)?)
        {
            return Err(xr::Result::ERROR_PATH_UNSUPPORTED);
        }
        synced.insert(a.action_set.into_raw());
    }
    let focused = s.state == xr::SessionState::FOCUSED;
    let s = rt.session_mut(session)?;
    s.synced_sets = synced;
    s.synced_focused = focused;
    Ok(if focused {
        xr::Result::SUCCESS
    } else {
        xr::Result::SESSION_NOT_FOCUSED
    })
}

/// Common checks of the xrGetActionState* functions; returns the action's id.
fn state_query(
    rt: &Runtime,
    session: xr::Session,
    info: &xr::ActionStateGetInfo,
    types: &[xr::ActionType],
) -> Result<u64, xr::Result> {
    let s = rt.live_session(session)?;
    ffi::check_type(info.ty, xr::StructureType::ACTION_STATE_GET_INFO)?;
    let a = rt.action(info.action)?;
    if !types.contains(&a.ty) {
        return Err(xr::Result::ERROR_ACTION_TYPE_MISMATCH);
    }
    if !s.attached_sets.contains(&a.set) {
        return Err(xr::Result::ERROR_ACTIONSET_NOT_ATTACHED);
    }
    let sub = info.subaction_path.into_raw();
    if sub != 0 && !a.subaction_paths.contains(&sub) {
        return Err(xr::Result::ERROR_PATH_UNSUPPORTED);
    }
    Ok(info.action.into_raw())
}

pub fn get_state_boolean(
    rt: &Runtime,
    session: xr::Session,
    info: &xr::ActionStateGetInfo,
    state: &mut xr::ActionStateBoolean,
) -> XrResult {
    state_query(rt, session, info, &[xr::ActionType::BOOLEAN_INPUT])?;
    ffi::check_type(state.ty, xr::StructureType::ACTION_STATE_BOOLEAN)?;
    state.current_state = xr::FALSE;
    state.changed_since_last_sync = xr::FALSE;
    state.last_change_time = xr::Time::from_nanos(0);
    state.is_active = xr::FALSE;
    Ok(xr::Result::SUCCESS)
}

pub fn get_state_float(
    rt: &Runtime,
    session: xr::Session,
    info: &xr::ActionStateGetInfo,
    state: &mut xr::ActionStateFloat,
) -> XrResult {
    state_query(rt, session, info, &[xr::ActionType::FLOAT_INPUT])?;
    ffi::check_type(state.ty, xr::StructureType::ACTION_STATE_FLOAT)?;
    state.current_state = 0.0;
    state.changed_since_last_sync = xr::FALSE;
    state.last_change_time = xr::Time::from_nanos(0);
    state.is_active = xr::FALSE;
    Ok(xr::Result::SUCCESS)
}

pub fn get_state_vector2f(
    rt: &Runtime,
    session: xr::Session,
    info: &xr::ActionStateGetInfo,
    state: &mut xr::ActionStateVector2f,
) -> XrResult {
    state_query(rt, session, info, &[xr::ActionType::VECTOR2F_INPUT])?;
    ffi::check_type(state.ty, xr::StructureType::ACTION_STATE_VECTOR2F)?;
    state.current_state = xr::Vector2f::default();
    state.changed_since_last_sync = xr::FALSE;
    state.last_change_time = xr::Time::from_nanos(0);
    state.is_active = xr::FALSE;
    Ok(xr::Result::SUCCESS)
}

pub fn get_state_pose(
    rt: &Runtime,
    session: xr::Session,
    info: &xr::ActionStateGetInfo,
    state: &mut xr::ActionStatePose,
) -> XrResult {
    let action = state_query(rt, session, info, &[xr::ActionType::POSE_INPUT])?;
    ffi::check_type(state.ty, xr::StructureType::ACTION_STATE_POSE)?;
    state.is_active = gaze_pose_active(rt, session, action, info.subaction_path.into_raw())?.into();
    Ok(xr::Result::SUCCESS)
}

pub fn haptic(rt: &Runtime, session: xr::Session, info: &xr::HapticActionInfo) -> XrResult {
    let s = rt.live_session(session)?;
    ffi::check_type(info.ty, xr::StructureType::HAPTIC_ACTION_INFO)?;
    let a = rt.action(info.action)?;
    if a.ty != xr::ActionType::VIBRATION_OUTPUT {
        return Err(xr::Result::ERROR_ACTION_TYPE_MISMATCH);
    }
    if !s.attached_sets.contains(&a.set) {
        return Err(xr::Result::ERROR_ACTIONSET_NOT_ATTACHED);
    }
    // No controller is connected, so there is nothing to vibrate.
    Ok(xr::Result::SUCCESS)
}

pub fn get_current_interaction_profile(
    rt: &Runtime,
    session: xr::Session,
    top_level: xr::Path,
    out: &mut xr::InteractionProfileState,
) -> XrResult {
    let s = rt.live_session(session)?;
    ffi::check_type(out.ty, xr::StructureType::INTERACTION_PROFILE_STATE)?;
    if s.attached_sets.is_empty() {
        return Err(xr::Result::ERROR_ACTIONSET_NOT_ATTACHED);
    }
    let user = rt.path_str(s.instance, top_level)?;
    if !profiles::TOP_LEVEL_PATHS.contains(&user) {
        return Err(xr::Result::ERROR_PATH_UNSUPPORTED);
    }
    let inst = &rt.instances[&s.instance];
    let gaze_current = user == EYES_USER_PATH
        && gaze_delivering(inst)
        && rt
            .actions
            .iter()
            .any(|(id, a)| s.attached_sets.contains(&a.set) && bound_to_gaze(inst, *id));
    out.interaction_profile = if gaze_current {
        xr::Path::from_raw(path_id(inst, EYE_GAZE_PROFILE).unwrap_or(0))
    } else {
        xr::Path::NULL
    };
    Ok(xr::Result::SUCCESS)
}

pub fn enumerate_bound_sources(
    rt: &mut Runtime,
    session: xr::Session,
    info: &xr::BoundSourcesForActionEnumerateInfo,
    capacity: u32,
    count: *mut u32,
    out: *mut xr::Path,
) -> XrResult {
    let s = rt.live_session(session)?;
    ffi::check_type(
        info.ty,
        xr::StructureType::BOUND_SOURCES_FOR_ACTION_ENUMERATE_INFO,
    )?;
    let a = rt.action(info.action)?;
    if !s.attached_sets.contains(&a.set) {
        return Err(xr::Result::ERROR_ACTIONSET_NOT_ATTACHED);
    }
    let instance = s.instance;
    let inst = &rt.instances[&instance];
    let bound = gaze_delivering(inst) && bound_to_gaze(inst, info.action.into_raw());
    let sources = if bound {
        vec![rt.intern_path(instance, GAZE_POSE_PATH)?]
    } else {
        Vec::new()
    };
    // SAFETY: the app's output array per the two-call idiom.
    unsafe {
        ffi::two_call(capacity, count, out, sources.len(), |i, p| {
            *p = sources[i];
            Ok(())
        })
    }
}

pub fn get_input_source_localized_name(
    rt: &Runtime,
    session: xr::Session,
    info: &xr::InputSourceLocalizedNameGetInfo,
    capacity: u32,
    count: *mut u32,
    buf: *mut c_char,
) -> XrResult {
    let s = rt.live_session(session)?;
    ffi::check_type(
        info.ty,
        xr::StructureType::INPUT_SOURCE_LOCALIZED_NAME_GET_INFO,
    )?;
    if info.which_components.is_empty() {
        return Err(xr::Result::ERROR_VALIDATION_FAILURE);
    }
    let path = rt.path_str(s.instance, info.source_path)?;
    let is_gaze = path.starts_with(EYES_USER_PATH);
    let mut parts = Vec::new();
    let c = info.which_components;
    if c.contains(xr::InputSourceLocalizedNameFlags::USER_PATH) {
        parts.push(if is_gaze { "Eyes" } else { "Hand" });
    }
    if c.contains(xr::InputSourceLocalizedNameFlags::INTERACTION_PROFILE) {
        parts.push(if is_gaze { "Eye Tracker" } else { "Controller" });
    }
    if c.contains(xr::InputSourceLocalizedNameFlags::COMPONENT) {
        parts.push(if is_gaze { "Gaze" } else { "Input" });
    }
    // SAFETY: the app's buffer per the two-call idiom.
    unsafe { ffi::two_call_string(capacity, count, buf, &parts.join(" ")) }
}
