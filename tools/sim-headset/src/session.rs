//! Sessions and their state machine:
//! IDLE → READY (on create) → [xrBeginSession] → SYNCHRONIZED (first xrWaitFrame) →
//! VISIBLE → FOCUSED (as frames are submitted) → … exit request (app or script) walks back
//! down to STOPPING → [xrEndSession] → IDLE → EXITING. A scripted loss queues LOSS_PENDING
//! and from then on the session answers XR_ERROR_SESSION_LOST.

use openxr_sys as xr;
use openxr_sys::Handle as _;

use crate::ffi::{self, XrResult};
use crate::registry::{Event, FrameLoop, Instance, Runtime, Session};
use crate::vulkan::VkContext;

/// Moves `session` (id `id`) to `state`, queueing the event and logging it for the report.
pub fn transition(inst: &mut Instance, session: &mut Session, id: u64, state: xr::SessionState) {
    session.state = state;
    inst.events.push_back(Event::SessionStateChanged {
        session: id,
        state,
        time: xr::Time::from_nanos(session.frames.clock.display_ns()),
    });
    inst.log.record_state(state);
}

/// Runs `f` on a session and its instance together (they live in different maps).
pub fn with_both<R>(
    rt: &mut Runtime,
    session: xr::Session,
    f: impl FnOnce(&mut Instance, &mut Session, u64) -> Result<R, xr::Result>,
) -> Result<R, xr::Result> {
    let id = session.into_raw();
    let s = rt
        .sessions
        .get_mut(&id)
        .ok_or(xr::Result::ERROR_HANDLE_INVALID)?;
    let inst = rt
        .instances
        .get_mut(&s.instance)
        .ok_or(xr::Result::ERROR_HANDLE_INVALID)?;
    f(inst, s, id)
}

/// Walks a running session down to STOPPING through the states the spec's diagram allows.
pub fn stop(inst: &mut Instance, s: &mut Session, id: u64) {
    s.exit_requested = true;
    use xr::SessionState as S;
    let path: &[S] = match s.state {
        S::FOCUSED => &[S::VISIBLE, S::SYNCHRONIZED, S::STOPPING],
        S::VISIBLE => &[S::SYNCHRONIZED, S::STOPPING],
        S::SYNCHRONIZED => &[S::STOPPING],
        S::READY => &[S::SYNCHRONIZED, S::STOPPING],
        _ => &[],
    };
    for &state in path {
        transition(inst, s, id, state);
    }
}

/// The scripted session loss: LOSS_PENDING now, XR_ERROR_SESSION_LOST from then on.
pub fn lose(inst: &mut Instance, s: &mut Session, id: u64) {
    transition(inst, s, id, xr::SessionState::LOSS_PENDING);
    s.lost = true;
    s.running = false;
}

pub fn create_session(
    rt: &mut Runtime,
    instance: xr::Instance,
    info: &xr::SessionCreateInfo,
    out: *mut xr::Session,
) -> XrResult {
    let inst = rt.instance(instance)?;
    ffi::check_type(info.ty, xr::StructureType::SESSION_CREATE_INFO)?;
    ffi::non_null(out)?;
    crate::system::check_system(info.system_id)?;
    if !(inst.extensions.vulkan_enable2 || inst.extensions.vulkan_enable) {
        return Err(xr::Result::ERROR_GRAPHICS_DEVICE_INVALID);
    }
    // XrGraphicsBindingVulkan2KHR is the same structure (and type value) as the KHR one.
    // SAFETY: `next` is the app's chain of input structures.
    let binding =
        unsafe { ffi::find_in_chain(info.next, xr::StructureType::GRAPHICS_BINDING_VULKAN_KHR) }
            .ok_or(xr::Result::ERROR_GRAPHICS_DEVICE_INVALID)?;
    // SAFETY: the chain entry has this structure's type, so it is this structure.
    let binding = unsafe { *(binding as *const xr::GraphicsBindingVulkanKHR) };
    if !inst.requirements_queried {
        return Err(xr::Result::ERROR_GRAPHICS_REQUIREMENTS_CALL_MISSING);
    }
    if binding.instance.is_null() || binding.physical_device.is_null() || binding.device.is_null() {
        return Err(xr::Result::ERROR_GRAPHICS_DEVICE_INVALID);
    }
    if inst.vk.physical_device != 0 && inst.vk.physical_device != binding.physical_device as u64 {
        eprintln!("sim-headset: the session's VkPhysicalDevice is not the one xrGetVulkanGraphicsDevice returned");
        return Err(xr::Result::ERROR_GRAPHICS_DEVICE_INVALID);
    }
    let id_instance = instance.into_raw();
    if rt.sessions.values().any(|s| s.instance == id_instance) {
        // Like real runtimes: one session per instance at a time.
        return Err(xr::Result::ERROR_LIMIT_REACHED);
    }
    // SAFETY: the binding names the app's live Vulkan objects, created through the loader
    // behind the function pointer it gave us (or the system loader).
    let vk = unsafe { VkContext::new(inst.vk.get_instance_proc_addr, &binding)? };
    let frames = FrameLoop::new(&inst.config);
    let id = rt.new_id();
    let mut session = Session {
        instance: id_instance,
        state: xr::SessionState::UNKNOWN,
        running: false,
        exit_requested: false,
        lost: false,
        frames,
        vk,
        attached_sets: Vec::new(),
        synced_sets: Default::default(),
        synced_focused: false,
    };
    let inst = rt.instance_mut(instance)?;
    transition(inst, &mut session, id, xr::SessionState::IDLE);
    transition(inst, &mut session, id, xr::SessionState::READY);
    rt.sessions.insert(id, session);
    // SAFETY: checked non-null.
    unsafe { *out = xr::Session::from_raw(id) };
    Ok(xr::Result::SUCCESS)
}

pub fn begin_session(
    rt: &mut Runtime,
    session: xr::Session,
    info: &xr::SessionBeginInfo,
) -> XrResult {
    rt.live_session(session)?;
    ffi::check_type(info.ty, xr::StructureType::SESSION_BEGIN_INFO)?;
    if info.primary_view_configuration_type != xr::ViewConfigurationType::PRIMARY_STEREO {
        return Err(xr::Result::ERROR_VIEW_CONFIGURATION_TYPE_UNSUPPORTED);
    }
    with_both(rt, session, |_, s, _| {
        if s.running {
            return Err(xr::Result::ERROR_SESSION_RUNNING);
        }
        if s.state != xr::SessionState::READY {
            return Err(xr::Result::ERROR_SESSION_NOT_READY);
        }
        s.running = true;
        s.frames.wait_pending = false;
        s.frames.frame_begun = false;
        Ok(xr::Result::SUCCESS)
    })
}

pub fn end_session(rt: &mut Runtime, session: xr::Session) -> XrResult {
    rt.live_session(session)?;
    with_both(rt, session, |inst, s, id| {
        if !s.running {
            return Err(xr::Result::ERROR_SESSION_NOT_RUNNING);
        }
        if s.state != xr::SessionState::STOPPING {
            return Err(xr::Result::ERROR_SESSION_NOT_STOPPING);
        }
        s.running = false;
        transition(inst, s, id, xr::SessionState::IDLE);
        if s.exit_requested {
            transition(inst, s, id, xr::SessionState::EXITING);
        }
        Ok(xr::Result::SUCCESS)
    })
}

pub fn request_exit_session(rt: &mut Runtime, session: xr::Session) -> XrResult {
    rt.live_session(session)?;
    with_both(rt, session, |inst, s, id| {
        if !s.running {
            return Err(xr::Result::ERROR_SESSION_NOT_RUNNING);
        }
        stop(inst, s, id);
        Ok(xr::Result::SUCCESS)
    })
}

pub fn destroy_session(rt: &mut Runtime, session: xr::Session) -> XrResult {
    rt.session(session)?;
    destroy_session_tree(rt, session.into_raw(), true);
    Ok(xr::Result::SUCCESS)
}

/// Destroys a session with its swapchains and spaces (OpenXR destroys children with their
/// parent). `count_leaks`: children still alive are app leaks to report; false when the
/// caller (instance destruction) has counted them already.
pub fn destroy_session_tree(rt: &mut Runtime, id: u64, count_leaks: bool) {
    let Some(session) = rt.sessions.remove(&id) else {
        return;
    };
    let swapchains: Vec<u64> = rt
        .swapchains
        .iter()
        .filter(|(_, s)| s.session == id)
        .map(|(k, _)| *k)
        .collect();
    for k in &swapchains {
        let mut sc = rt.swapchains.remove(k).expect("listed above");
        session.vk.destroy_images(&mut sc.images);
    }
    let spaces_before = rt.spaces.len();
    rt.spaces.retain(|_, s| s.session != id);
    let spaces = spaces_before - rt.spaces.len();
    session.vk.destroy();
    if count_leaks {
        if let Some(inst) = rt.instances.get_mut(&session.instance) {
            inst.log.destroyed_with_parent.swapchains += swapchains.len() as u64;
            inst.log.destroyed_with_parent.spaces += spaces as u64;
        }
    }
}
