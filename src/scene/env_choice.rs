//! `--env FILE` (with `--env-rotate`, `--env-intensity`, `--env-sampling`): the HDR environment
//! every scene of the process is lit by, in place of its own sky. Read once, before any scene
//! loads, and shared by every scene (the viewer's scene switches, a bench's scenes).

use std::sync::OnceLock;

use super::{EnvironmentLight, Scene};

static ENVIRONMENT: OnceLock<EnvironmentLight> = OnceLock::new();

/// Sets the environment of every scene loaded from now on. Returns false when one was already
/// set (the first one stays).
pub fn set_environment(light: EnvironmentLight) -> bool {
    ENVIRONMENT.set(light).is_ok()
}

/// The environment set by [`set_environment`], if any.
pub fn environment() -> Option<&'static EnvironmentLight> {
    ENVIRONMENT.get()
}

/// Gives `scene` the chosen environment, if one was chosen.
pub fn apply(scene: &mut Scene) {
    if let Some(light) = environment() {
        scene.environment_map = Some(light.clone());
    }
}
