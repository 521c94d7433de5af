//! XR_EXT_eye_gaze_interaction: a pose action bound to the eye tracker, its action space
//! located every frame at the predicted display time. Whether gaze arrives is decided at
//! three levels (extension offered, `supportsEyeGazeInteraction`, action active), and SteamVR
//! on the Vive Pro Eye often fails the last: each failure means fixed centre foveation.

use super::error::{XrContext, XrError};
use super::instance::XrInstance;
use openxr as xr;

const PROFILE: &str = "/interaction_profiles/ext/eye_gaze_interaction";
const GAZE_POSE: &str = "/user/eyes_ext/input/gaze_ext/pose";

/// Why there is no eye gaze, said once at the start of a session.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NoGaze {
    ExtensionMissing,
    NotSupported,
}

impl NoGaze {
    pub fn message(self) -> &'static str {
        match self {
            NoGaze::ExtensionMissing => {
                "the OpenXR runtime does not offer XR_EXT_eye_gaze_interaction: fixed centre foveation"
            }
            NoGaze::NotSupported => {
                "the headset reports no eye gaze support (supportsEyeGazeInteraction is false): fixed centre foveation"
            }
        }
    }
}

/// One located gaze sample.
#[derive(Clone, Copy, Debug)]
pub struct GazeSample {
    /// The gaze pose in the reference space, when valid and tracked.
    pub pose: Option<xr::Posef>,
    /// When the eye tracker took the sample (XrEyeGazeSampleTimeEXT), if the runtime said.
    pub sample_time: Option<xr::Time>,
    /// The action is active (bound to a device that delivers data).
    pub active: bool,
}

pub struct EyeGaze {
    set: xr::ActionSet,
    action: xr::Action<xr::Posef>,
    space: xr::Space,
}

impl EyeGaze {
    /// Sets up the action where the runtime supports eye gaze; `Err(NoGaze)` says why not.
    /// The action set must be attached before the first frame, so this runs right after
    /// the session is created.
    pub fn new(
        xr: &XrInstance,
        session: &xr::Session<xr::Vulkan>,
    ) -> Result<Result<Self, NoGaze>, XrError> {
        if !xr.eye_gaze_extension {
            return Ok(Err(NoGaze::ExtensionMissing));
        }
        if !xr.supports_eye_gaze()? {
            return Ok(Err(NoGaze::NotSupported));
        }
        let instance = &xr.instance;
        let set = instance
            .create_action_set("fovea_gaze", "fovea eye gaze", 0)
            .xr("xrCreateActionSet")?;
        let action = set
            .create_action::<xr::Posef>("eye_gaze", "eye gaze", &[])
            .xr("xrCreateAction")?;
        let profile = instance.string_to_path(PROFILE).xr("xrStringToPath")?;
        let pose = instance.string_to_path(GAZE_POSE).xr("xrStringToPath")?;
        instance
            .suggest_interaction_profile_bindings(profile, &[xr::Binding::new(&action, pose)])
            .xr("xrSuggestInteractionProfileBindings")?;
        session
            .attach_action_sets(&[&set])
            .xr("xrAttachSessionActionSets")?;
        let space = action
            .create_space(session, xr::Path::NULL, xr::Posef::IDENTITY)
            .xr("xrCreateActionSpace")?;
        Ok(Ok(Self { set, action, space }))
    }

    /// Syncs the action and locates the gaze in `base` at `time` (the predicted display
    /// time), with the sample time chained in.
    pub fn locate(
        &self,
        session: &xr::Session<xr::Vulkan>,
        base: &xr::Space,
        time: xr::Time,
    ) -> Result<GazeSample, XrError> {
        session
            .sync_actions(&[xr::ActiveActionSet::new(&self.set)])
            .xr("xrSyncActions")?;
        let active = self
            .action
            .is_active(session, xr::Path::NULL)
            .xr("xrGetActionStatePose")?;
        if !active {
            return Ok(GazeSample {
                pose: None,
                sample_time: None,
                active,
            });
        }
        let mut sample_time = xr::sys::EyeGazeSampleTimeEXT {
            ty: xr::sys::EyeGazeSampleTimeEXT::TYPE,
            next: std::ptr::null_mut(),
            time: xr::Time::from_nanos(0),
        };
        let mut location = xr::sys::SpaceLocation {
            ty: xr::sys::SpaceLocation::TYPE,
            next: &mut sample_time as *mut _ as *mut _,
            location_flags: xr::SpaceLocationFlags::EMPTY,
            pose: xr::Posef::IDENTITY,
        };
        // SAFETY: both spaces belong to this session; `location` and the chained sample-time
        // struct outlive the call.
        let result = unsafe {
            (session.instance().fp().locate_space)(
                self.space.as_raw(),
                base.as_raw(),
                time,
                &mut location,
            )
        };
        if result.into_raw() < 0 {
            return Err(XrError::Call {
                call: "xrLocateSpace (eye gaze)",
                result,
            });
        }
        let flags = location.location_flags;
        let usable = flags.contains(
            xr::SpaceLocationFlags::ORIENTATION_VALID
                | xr::SpaceLocationFlags::ORIENTATION_TRACKED
                | xr::SpaceLocationFlags::POSITION_VALID,
        );
        Ok(GazeSample {
            pose: usable.then_some(location.pose),
            sample_time: (sample_time.time.as_nanos() != 0).then_some(sample_time.time),
            active,
        })
    }
}
