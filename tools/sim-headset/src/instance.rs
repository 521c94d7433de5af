//! Instance life cycle, extensions, events and the `*ToString` functions.

use std::collections::{HashMap, VecDeque};
use std::ffi::c_char;

use openxr_sys as xr;
use openxr_sys::Handle as _;

use crate::config::{self, Config, EyeGazeMode};
use crate::ffi::{self, XrResult};
use crate::registry::{self, Event, Extensions, Instance, Runtime};
use crate::report::{HandleCounts, Report, ReportLog, VulkanCounts};
use crate::vulkan::VkBootstrap;

pub const KHR_VULKAN_ENABLE2: &str = "XR_KHR_vulkan_enable2";
pub const KHR_VULKAN_ENABLE: &str = "XR_KHR_vulkan_enable";
pub const EXT_EYE_GAZE: &str = "XR_EXT_eye_gaze_interaction";
pub const KHR_VISIBILITY_MASK: &str = "XR_KHR_visibility_mask";

/// The extensions offered under `config`, with their spec versions.
pub fn offered_extensions(config: &Config) -> Vec<(&'static str, u32)> {
    let mut exts = vec![(KHR_VULKAN_ENABLE2, 2), (KHR_VULKAN_ENABLE, 8)];
    if config.eye_gaze != EyeGazeMode::Off {
        exts.push((EXT_EYE_GAZE, 2));
    }
    if config.visibility_mask {
        exts.push((KHR_VISIBILITY_MASK, 2));
    }
    exts
}

/// `XR_SUCCESS`-style name of a result, or the spec's `XR_UNKNOWN_*` form.
pub fn result_name(r: xr::Result) -> String {
    let debug = format!("{r:?}");
    if debug.parse::<i32>().is_ok() {
        let kind = if r.into_raw() >= 0 {
            "SUCCESS"
        } else {
            "FAILURE"
        };
        format!("XR_UNKNOWN_{kind}_{}", r.into_raw())
    } else {
        format!("XR_{debug}")
    }
}

fn config_or_report() -> Result<Config, xr::Result> {
    config::current().map_err(|e| {
        eprintln!("{e}");
        xr::Result::ERROR_INITIALIZATION_FAILED
    })
}

pub fn enumerate_extensions(
    layer: *const c_char,
    capacity: u32,
    count: *mut u32,
    props: *mut xr::ExtensionProperties,
) -> XrResult {
    if !layer.is_null() {
        return Err(xr::Result::ERROR_API_LAYER_NOT_PRESENT);
    }
    // A bad configuration is reported here already, where the app first meets the runtime.
    let config = config_or_report().map_err(|_| xr::Result::ERROR_RUNTIME_FAILURE)?;
    let exts = offered_extensions(&config);
    // SAFETY: the app's output arrays per the two-call idiom.
    unsafe {
        ffi::two_call(capacity, count, props, exts.len(), |i, p| {
            ffi::check_type(p.ty, xr::StructureType::EXTENSION_PROPERTIES)?;
            ffi::write_fixed(&mut p.extension_name, exts[i].0);
            p.extension_version = exts[i].1;
            Ok(())
        })
    }
}

pub fn create_instance(info: &xr::InstanceCreateInfo, out: *mut xr::Instance) -> XrResult {
    ffi::check_type(info.ty, xr::StructureType::INSTANCE_CREATE_INFO)?;
    ffi::non_null(out)?;
    let version = info.application_info.api_version;
    if version.major() != 1 || version.minor() != 0 {
        return Err(xr::Result::ERROR_API_VERSION_UNSUPPORTED);
    }
    if info.enabled_api_layer_count > 0 {
        return Err(xr::Result::ERROR_API_LAYER_NOT_PRESENT);
    }
    if ffi::read_fixed(&info.application_info.application_name).is_none_or(|n| n.is_empty()) {
        return Err(xr::Result::ERROR_NAME_INVALID);
    }
    let config = config_or_report()?;
    let offered = offered_extensions(&config);
    let mut extensions = Extensions::default();
    for k in 0..info.enabled_extension_count as usize {
        // SAFETY: the app passes `enabled_extension_count` valid C strings.
        let name = unsafe { ffi::read_cstr(*info.enabled_extension_names.add(k))? };
        if !offered.iter().any(|(n, _)| *n == name) {
            eprintln!("sim-headset: extension {name} is not offered (see SIM_HEADSET_* settings)");
            return Err(xr::Result::ERROR_EXTENSION_NOT_PRESENT);
        }
        match name {
            KHR_VULKAN_ENABLE2 => extensions.vulkan_enable2 = true,
            KHR_VULKAN_ENABLE => extensions.vulkan_enable = true,
            EXT_EYE_GAZE => extensions.eye_gaze = true,
            _ => extensions.visibility_mask = true,
        }
    }
    let mut rt = registry::lock();
    let id = rt.new_id();
    rt.instances.insert(
        id,
        Instance {
            config,
            extensions,
            paths: Vec::new(),
            events: VecDeque::new(),
            requirements_queried: false,
            vk: VkBootstrap::default(),
            suggested: HashMap::new(),
            log: ReportLog::default(),
        },
    );
    // SAFETY: checked non-null above.
    unsafe { *out = xr::Instance::from_raw(id) };
    Ok(xr::Result::SUCCESS)
}

/// Destroys the instance and, as OpenXR requires, everything created from it; what the app
/// had not destroyed itself is counted as leaked in the report.
pub fn destroy_instance(instance: xr::Instance) -> XrResult {
    let mut rt = registry::lock();
    let id = instance.into_raw();
    rt.instance(instance)?;
    let sessions: Vec<u64> = ids(&rt.sessions, |s| s.instance == id);
    let swapchains: Vec<u64> = ids(&rt.swapchains, |s| sessions.contains(&s.session));
    let alive = HandleCounts {
        sessions: sessions.len() as u64,
        swapchains: swapchains.len() as u64,
        spaces: ids(&rt.spaces, |s| sessions.contains(&s.session)).len() as u64,
        actions: ids(&rt.actions, |a| a.instance == id).len() as u64,
        action_sets: ids(&rt.action_sets, |a| a.instance == id).len() as u64,
    };
    let vulkan = swapchains.iter().map(|s| &rt.swapchains[s].images).fold(
        VulkanCounts::default(),
        |mut c, i| {
            c.images += i.images.len() as u64;
            c.memory_allocations += i.memory.len() as u64;
            c
        },
    );
    for s in sessions {
        crate::session::destroy_session_tree(&mut rt, s, false);
    }
    rt.actions.retain(|_, a| a.instance != id);
    rt.action_sets.retain(|_, a| a.instance != id);
    let inst = rt.instances.remove(&id).expect("checked above");
    drop(rt);
    if let Some(path) = &inst.config.report_path {
        Report::new(inst.log, alive, vulkan).write(path);
    }
    Ok(xr::Result::SUCCESS)
}

fn ids<T>(map: &HashMap<u64, T>, keep: impl Fn(&T) -> bool) -> Vec<u64> {
    map.iter()
        .filter(|(_, v)| keep(v))
        .map(|(k, _)| *k)
        .collect()
}

pub fn get_instance_properties(
    rt: &Runtime,
    instance: xr::Instance,
    props: &mut xr::InstanceProperties,
) -> XrResult {
    rt.instance(instance)?;
    ffi::check_type(props.ty, xr::StructureType::INSTANCE_PROPERTIES)?;
    props.runtime_version = xr::Version::new(0, 1, 0);
    ffi::write_fixed(&mut props.runtime_name, crate::RUNTIME_NAME);
    Ok(xr::Result::SUCCESS)
}

pub fn poll_event(
    rt: &mut Runtime,
    instance: xr::Instance,
    buffer: &mut xr::EventDataBuffer,
) -> XrResult {
    ffi::check_type(buffer.ty, xr::StructureType::EVENT_DATA_BUFFER)?;
    let inst = rt.instance_mut(instance)?;
    let Some(event) = inst.events.pop_front() else {
        return Ok(xr::Result::EVENT_UNAVAILABLE);
    };
    let out = buffer as *mut xr::EventDataBuffer;
    // SAFETY: XrEventDataBuffer is large enough for every event structure (that is its
    // purpose) and suitably aligned for them.
    unsafe {
        match event {
            Event::SessionStateChanged {
                session,
                state,
                time,
            } => {
                *(out as *mut xr::EventDataSessionStateChanged) = xr::EventDataSessionStateChanged {
                    ty: xr::StructureType::EVENT_DATA_SESSION_STATE_CHANGED,
                    next: std::ptr::null(),
                    session: xr::Session::from_raw(session),
                    state,
                    time,
                }
            }
            Event::InteractionProfileChanged { session } => {
                *(out as *mut xr::EventDataInteractionProfileChanged) =
                    xr::EventDataInteractionProfileChanged {
                        ty: xr::StructureType::EVENT_DATA_INTERACTION_PROFILE_CHANGED,
                        next: std::ptr::null(),
                        session: xr::Session::from_raw(session),
                    }
            }
        }
    }
    Ok(xr::Result::SUCCESS)
}

pub fn result_to_string(
    rt: &Runtime,
    instance: xr::Instance,
    value: xr::Result,
    buffer: &mut [c_char; xr::MAX_RESULT_STRING_SIZE],
) -> XrResult {
    rt.instance(instance)?;
    ffi::write_fixed(buffer, &result_name(value));
    Ok(xr::Result::SUCCESS)
}

pub fn structure_type_to_string(
    rt: &Runtime,
    instance: xr::Instance,
    value: xr::StructureType,
    buffer: &mut [c_char; xr::MAX_STRUCTURE_NAME_SIZE],
) -> XrResult {
    rt.instance(instance)?;
    let debug = format!("{value:?}");
    let name = if debug.parse::<i32>().is_ok() {
        format!("XR_UNKNOWN_STRUCTURE_TYPE_{}", value.into_raw())
    } else {
        format!("XR_TYPE_{debug}")
    };
    ffi::write_fixed(buffer, &name);
    Ok(xr::Result::SUCCESS)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn result_names_follow_the_spec() {
        assert_eq!(result_name(xr::Result::SUCCESS), "XR_SUCCESS");
        assert_eq!(
            result_name(xr::Result::ERROR_CALL_ORDER_INVALID),
            "XR_ERROR_CALL_ORDER_INVALID"
        );
        assert_eq!(
            result_name(xr::Result::from_raw(-999_999)),
            "XR_UNKNOWN_FAILURE_-999999"
        );
    }

    #[test]
    fn eye_gaze_off_hides_the_extension() {
        let mut c = Config::default();
        assert!(offered_extensions(&c).iter().any(|e| e.0 == EXT_EYE_GAZE));
        c.eye_gaze = EyeGazeMode::Off;
        c.visibility_mask = false;
        let names: Vec<_> = offered_extensions(&c).iter().map(|e| e.0).collect();
        assert_eq!(names, [KHR_VULKAN_ENABLE2, KHR_VULKAN_ENABLE]);
    }
}
