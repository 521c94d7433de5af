//! The interaction profiles the headset accepts bindings for, and which input/output paths
//! belong to each. Controllers are known (so apps like hello_xr can suggest their bindings)
//! but never connected; only the eye tracker delivers input.

/// The eye tracker's profile (XR_EXT_eye_gaze_interaction).
pub const EYE_GAZE_PROFILE: &str = "/interaction_profiles/ext/eye_gaze_interaction";
pub const EYES_USER_PATH: &str = "/user/eyes_ext";
pub const GAZE_POSE_PATH: &str = "/user/eyes_ext/input/gaze_ext/pose";

const HANDS: &[&str] = &["/user/hand/left", "/user/hand/right"];

/// Profile path and the top-level user paths it may be bound under.
const PROFILES: &[(&str, &[&str])] = &[
    ("/interaction_profiles/khr/simple_controller", HANDS),
    ("/interaction_profiles/htc/vive_controller", HANDS),
    ("/interaction_profiles/htc/vive_pro", &["/user/head"]),
    ("/interaction_profiles/htc/vive_cosmos_controller", HANDS),
    ("/interaction_profiles/htc/vive_focus3_controller", HANDS),
    ("/interaction_profiles/valve/index_controller", HANDS),
    ("/interaction_profiles/oculus/touch_controller", HANDS),
    ("/interaction_profiles/oculus/go_controller", HANDS),
    ("/interaction_profiles/microsoft/motion_controller", HANDS),
    (
        "/interaction_profiles/microsoft/xbox_controller",
        &["/user/gamepad"],
    ),
    ("/interaction_profiles/google/daydream_controller", HANDS),
    (EYE_GAZE_PROFILE, &[EYES_USER_PATH]),
];

/// Top-level user paths the spec defines (valid as subaction paths).
pub const TOP_LEVEL_PATHS: &[&str] = &[
    "/user/hand/left",
    "/user/hand/right",
    "/user/head",
    "/user/gamepad",
    "/user/treadmill",
    EYES_USER_PATH,
];

/// The user paths of a known profile; `eye_gaze` says whether the eye-gaze extension is
/// enabled (its profile does not exist otherwise).
pub fn user_paths(profile: &str, eye_gaze: bool) -> Option<&'static [&'static str]> {
    if profile == EYE_GAZE_PROFILE && !eye_gaze {
        return None;
    }
    PROFILES
        .iter()
        .find(|(p, _)| *p == profile)
        .map(|(_, u)| *u)
}

/// Whether `binding` is a plausible input/output path of `profile`: under one of its user
/// paths, then `/input/...` or `/output/...`. The eye tracker has exactly one input.
pub fn binding_allowed(profile: &str, binding: &str, eye_gaze: bool) -> bool {
    if profile == EYE_GAZE_PROFILE {
        return eye_gaze
            && (binding == GAZE_POSE_PATH || binding == "/user/eyes_ext/input/gaze_ext");
    }
    let Some(users) = user_paths(profile, eye_gaze) else {
        return false;
    };
    users.iter().any(|u| {
        binding
            .strip_prefix(u)
            .is_some_and(|rest| rest.starts_with("/input/") || rest.starts_with("/output/"))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hello_xr_bindings_are_accepted() {
        let vive = "/interaction_profiles/htc/vive_controller";
        assert!(binding_allowed(
            vive,
            "/user/hand/left/input/trigger/click",
            false
        ));
        assert!(binding_allowed(
            vive,
            "/user/hand/right/output/haptic",
            false
        ));
        assert!(!binding_allowed(
            vive,
            "/user/head/input/system/click",
            false
        ));
        assert!(user_paths("/interaction_profiles/acme/unknown", true).is_none());
    }

    #[test]
    fn eye_gaze_profile_needs_the_extension_and_the_gaze_path() {
        assert!(binding_allowed(EYE_GAZE_PROFILE, GAZE_POSE_PATH, true));
        assert!(!binding_allowed(EYE_GAZE_PROFILE, GAZE_POSE_PATH, false));
        assert!(!binding_allowed(
            EYE_GAZE_PROFILE,
            "/user/eyes_ext/input/select/click",
            true
        ));
        assert!(user_paths(EYE_GAZE_PROFILE, false).is_none());
    }
}
