//! `fovea xr --probe`: what a headset user needs to diagnose a set-up, gathered from a real
//! session that renders nothing: the runtime and headset, the extensions offered and which
//! fovea uses, whether eye gaze is offered, supported and delivered (the gaze action active
//! in focused frames), the view configuration, refresh rates, swapchain formats and the
//! Vulkan device the runtime picked.

use super::error::{XrContext, XrError};
use super::headset_gaze::GazeActivity;
use super::instance::XrInstance;
use openxr as xr;
use std::fmt;

/// Frames the probe submits (empty) after the session starts: a third of a second at 90 Hz,
/// enough for a runtime to give the session focus and activate its actions.
pub const PROBE_FRAMES: u64 = 30;

/// One view's image sizes.
#[derive(Clone, Copy, Debug)]
pub struct ViewSizes {
    pub recommended: [u32; 2],
    pub max: [u32; 2],
}

/// What the probe found.
#[derive(Clone, Debug)]
pub struct ProbeReport {
    pub runtime: String,
    pub system: String,
    pub offered: Vec<String>,
    pub eye_gaze_extension: bool,
    /// `supportsEyeGazeInteraction` (false where the extension is not offered).
    pub supports_eye_gaze: bool,
    pub gaze: GazeActivity,
    pub visibility_mask: bool,
    pub views: Vec<ViewSizes>,
    /// The display's refresh rates (XR_FB_display_refresh_rate); None where not offered.
    pub refresh_rates: Option<Vec<f32>>,
    pub swapchain_formats: Vec<String>,
    pub chosen_format: String,
    pub vulkan_device: String,
    pub frames: u64,
}

/// The extensions fovea uses: (name, required).
const USED: [(&str, bool); 4] = [
    ("XR_KHR_vulkan_enable2", true),
    ("XR_EXT_eye_gaze_interaction", false),
    ("XR_KHR_visibility_mask", false),
    ("XR_FB_display_refresh_rate", false),
];

impl ProbeReport {
    /// The facts known once the session and its swapchain formats exist.
    pub(super) fn new(
        xr_instance: &XrInstance,
        views: &[xr::ViewConfigurationView],
        session: &xr::Session<xr::Vulkan>,
        formats: &[u32],
        chosen: ash::vk::Format,
        device: &crate::gpu::DeviceInfo,
    ) -> Result<Self, XrError> {
        let props = xr_instance
            .instance
            .system_properties(xr_instance.system)
            .xr("xrGetSystemProperties")?;
        let refresh_rates = match xr_instance.refresh_rates {
            true => Some(
                session
                    .enumerate_display_refresh_rates()
                    .xr("xrEnumerateDisplayRefreshRatesFB")?,
            ),
            false => None,
        };
        Ok(Self {
            runtime: xr_instance.runtime.clone(),
            system: format!("{} (vendor id {:#x})", props.system_name, props.vendor_id),
            offered: xr_instance.offered.clone(),
            eye_gaze_extension: xr_instance.eye_gaze_extension,
            supports_eye_gaze: xr_instance.supports_eye_gaze()?,
            gaze: GazeActivity::default(),
            visibility_mask: xr_instance.visibility_mask,
            views: views
                .iter()
                .map(|v| ViewSizes {
                    recommended: [
                        v.recommended_image_rect_width,
                        v.recommended_image_rect_height,
                    ],
                    max: [v.max_image_rect_width, v.max_image_rect_height],
                })
                .collect(),
            refresh_rates,
            swapchain_formats: formats
                .iter()
                .map(|&f| format!("{:?}", ash::vk::Format::from_raw(f as i32)))
                .collect(),
            chosen_format: format!("{chosen:?}"),
            vulkan_device: format!(
                "{} ({}; {}, Vulkan {})",
                device.name, device.kind, device.driver, device.api_version
            ),
            frames: 0,
        })
    }

    /// One line on eye gaze: what a user checks first.
    pub fn eye_gaze_verdict(&self) -> String {
        if !self.eye_gaze_extension {
            return "not offered: the runtime lists no XR_EXT_eye_gaze_interaction (install and \
                    start the headset's eye-tracking runtime, e.g. HTC's for SteamVR)"
                .into();
        }
        if !self.supports_eye_gaze {
            return "not supported: the runtime offers XR_EXT_eye_gaze_interaction but the \
                    headset reports supportsEyeGazeInteraction false (SteamVR without HTC's \
                    eye-tracking runtime does this)"
                .into();
        }
        let GazeActivity {
            focused_frames,
            active_frames,
        } = self.gaze;
        match (focused_frames, active_frames) {
            (0, _) => "offered and supported; not judged: the session never had input focus \
                       (put the headset on, or close the dashboard)"
                .into(),
            (_, 0) => format!(
                "offered and supported, but not delivered: the gaze action was inactive in all \
                 {focused_frames} focused frames (is the eye-tracking runtime running and \
                 calibrated?)"
            ),
            (f, a) => format!("delivered: the gaze action was active in {a} of {f} focused frames"),
        }
    }
}

impl fmt::Display for ProbeReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(f, "OpenXR runtime:    {}", self.runtime)?;
        writeln!(f, "system:            {}", self.system)?;
        writeln!(f, "Vulkan device:     {}", self.vulkan_device)?;
        writeln!(f, "extensions fovea uses:")?;
        for (name, required) in USED {
            let offered = self.offered.iter().any(|o| o == name);
            let role = match required {
                true => "required",
                false => "used where offered",
            };
            let state = match offered {
                true => "offered",
                false => "NOT offered",
            };
            writeln!(f, "  {name:<32} {state} ({role})")?;
        }
        writeln!(f, "eye gaze:          {}", self.eye_gaze_verdict())?;
        let mask = match self.visibility_mask {
            true => "offered: hidden pixels are never traced",
            false => "not offered: every pixel is traced",
        };
        writeln!(f, "visibility mask:   {mask}")?;
        writeln!(
            f,
            "view configuration: primary stereo, {} views",
            self.views.len()
        )?;
        for (e, v) in self.views.iter().enumerate() {
            writeln!(
                f,
                "  eye {e}: recommended {}x{}, max {}x{}",
                v.recommended[0], v.recommended[1], v.max[0], v.max[1]
            )?;
        }
        match &self.refresh_rates {
            Some(rates) => writeln!(f, "refresh rates:     {rates:?} Hz")?,
            None => writeln!(
                f,
                "refresh rates:     not reported (no XR_FB_display_refresh_rate)"
            )?,
        }
        writeln!(
            f,
            "swapchain formats: {} (fovea uses {})",
            self.swapchain_formats.join(", "),
            self.chosen_format
        )?;
        writeln!(f, "probed over {} empty frames", self.frames)?;
        writeln!(f, "all extensions offered: {}", self.offered.join(" "))
    }
}
