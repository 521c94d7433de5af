//! Loading OpenXR and creating the instance: the extensions fovea needs (XR_KHR_vulkan_enable2)
//! and those it uses where offered (eye gaze, visibility mask), and the headset system.

use super::error::{XrContext, XrError};
use openxr as xr;

/// Where the OpenXR runtime comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RuntimeSource {
    /// The system's OpenXR loader, which finds the active runtime (SteamVR, or the one
    /// `XR_RUNTIME_JSON` names).
    Loader,
    /// The simulated headset (tools/sim-headset), linked into fovea and called directly.
    Simulated,
}

/// An instance and the headset system, with what the runtime offers.
pub struct XrInstance {
    pub instance: xr::Instance,
    pub system: xr::SystemId,
    pub runtime: String,
    pub eye_gaze_extension: bool,
    pub visibility_mask: bool,
    /// XR_FB_display_refresh_rate is offered (and enabled): the display's rates can be read.
    pub refresh_rates: bool,
    /// Every extension the runtime offers, by name.
    pub offered: Vec<String>,
}

fn load_entry(source: RuntimeSource) -> Result<xr::Entry, XrError> {
    match source {
        // SAFETY: loads the Khronos loader library; its functions are called only through the
        // openxr crate, with the ABI the OpenXR headers define.
        RuntimeSource::Loader => {
            unsafe { xr::Entry::load(&()) }.map_err(|e| XrError::NoLoader(e.to_string()))
        }
        // SAFETY: the simulated runtime's xrGetInstanceProcAddr follows the OpenXR ABI.
        RuntimeSource::Simulated => unsafe {
            xr::Entry::from_get_instance_proc_addr(sim_headset::get_instance_proc_addr(), &())
        }
        .map_err(|e| XrError::NoLoader(e.to_string())),
    }
}

impl XrInstance {
    pub fn new(source: RuntimeSource) -> Result<Self, XrError> {
        let entry = load_entry(source)?;
        let offered = entry.enumerate_extensions().map_err(|e| {
            XrError::NoRuntime(format!("xrEnumerateInstanceExtensionProperties: {e}"))
        })?;
        let mut wanted = xr::ExtensionSet::default();
        wanted.khr_vulkan_enable2 = true;
        wanted.ext_eye_gaze_interaction = offered.ext_eye_gaze_interaction;
        wanted.khr_visibility_mask = offered.khr_visibility_mask;
        wanted.fb_display_refresh_rate = offered.fb_display_refresh_rate;
        let app = xr::ApplicationInfo {
            application_name: "fovea",
            application_version: 1,
            engine_name: "fovea",
            engine_version: 1,
            api_version: xr::Version::new(1, 0, 0),
        };
        if !offered.khr_vulkan_enable2 {
            let runtime = entry
                .create_instance(&app, &xr::ExtensionSet::default(), &[], &())
                .and_then(|i| i.properties())
                .map(|p| p.runtime_name)
                .unwrap_or_else(|_| "unknown".into());
            return Err(XrError::NoVulkanEnable2 { runtime });
        }
        let instance = entry
            .create_instance(&app, &wanted, &[], &())
            .map_err(|e| XrError::NoRuntime(format!("xrCreateInstance: {e}")))?;
        let props = instance.properties().xr("xrGetInstanceProperties")?;
        let runtime = format!("{} {}", props.runtime_name, props.runtime_version);
        let system = match instance.system(xr::FormFactor::HEAD_MOUNTED_DISPLAY) {
            Ok(system) => system,
            Err(e) => return Err(XrError::NoHeadset(format!("xrGetSystem: {e}"))),
        };
        tracing::info!(
            "OpenXR runtime {runtime}: eye gaze extension {}, visibility mask {}",
            offered_word(wanted.ext_eye_gaze_interaction),
            offered_word(wanted.khr_visibility_mask)
        );
        Ok(Self {
            instance,
            system,
            runtime,
            eye_gaze_extension: wanted.ext_eye_gaze_interaction,
            visibility_mask: wanted.khr_visibility_mask,
            refresh_rates: wanted.fb_display_refresh_rate,
            offered: offered
                .names()
                .iter()
                .map(|n| String::from_utf8_lossy(n.strip_suffix(&[0]).unwrap_or(n)).into_owned())
                .collect(),
        })
    }

    /// `supportsEyeGazeInteraction` of the system (chained into xrGetSystemProperties): the
    /// extension alone does not mean the headset delivers gaze.
    pub fn supports_eye_gaze(&self) -> Result<bool, XrError> {
        if !self.eye_gaze_extension {
            return Ok(false);
        }
        let mut gaze = xr::sys::SystemEyeGazeInteractionPropertiesEXT {
            ty: xr::sys::SystemEyeGazeInteractionPropertiesEXT::TYPE,
            next: std::ptr::null_mut(),
            supports_eye_gaze_interaction: false.into(),
        };
        let mut props = xr::sys::SystemProperties {
            ty: xr::sys::SystemProperties::TYPE,
            next: &mut gaze as *mut _ as *mut _,
            // SAFETY: plain C struct of integers, arrays and floats; the runtime fills it.
            ..unsafe { std::mem::zeroed() }
        };
        // SAFETY: valid instance and system; `props` and the chained struct outlive the call.
        let result = unsafe {
            (self.instance.fp().get_system_properties)(
                self.instance.as_raw(),
                self.system,
                &mut props,
            )
        };
        if result.into_raw() < 0 {
            return Err(XrError::Call {
                call: "xrGetSystemProperties",
                result,
            });
        }
        Ok(gaze.supports_eye_gaze_interaction.into())
    }
}

fn offered_word(offered: bool) -> &'static str {
    match offered {
        true => "offered",
        false => "not offered",
    }
}
