//! `--env FILE` (with `--env-rotate`, `--env-intensity`, `--env-sampling`): the HDR environment
//! every scene of the process is lit by, in place of its own sky. Read once, before any scene
//! loads, and shared by every scene (the viewer's scene switches, a bench's scenes). Bench and
//! tune plans keep the choice ([`EnvChoice`]), so a resumed run is lit as it began.

use std::path::PathBuf;
use std::sync::{Arc, OnceLock};

use super::{EnvSampling, EnvironmentLight, EnvironmentMap, Scene, SceneError};

/// What the command line chose, as plans keep it.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct EnvChoice {
    /// The file, absolute (so a plan resumes from anywhere).
    pub path: PathBuf,
    pub rotate_deg: f32,
    pub intensity: f32,
    pub sampling: EnvSampling,
}

static ENVIRONMENT: OnceLock<(EnvChoice, EnvironmentLight)> = OnceLock::new();

/// Reads the environment `choice` names and lights every scene loaded from now on with it.
/// Returns the map's texels that were negative and set to 0. Errors when one was set already.
pub fn set_environment(choice: EnvChoice) -> Result<usize, SceneError> {
    let map = EnvironmentMap::load(&choice.path)?;
    let clamped = map.clamped_negative;
    let light = EnvironmentLight {
        map: Arc::new(map),
        rotate_deg: choice.rotate_deg,
        intensity: choice.intensity,
        sampling: choice.sampling,
    };
    ENVIRONMENT
        .set((choice, light))
        .map_err(|(choice, _)| SceneError::Load {
            path: choice.path,
            problem: "an environment was already chosen for this run".into(),
        })?;
    Ok(clamped)
}

/// The environment chosen for this process, if any.
pub fn chosen() -> Option<&'static EnvChoice> {
    ENVIRONMENT.get().map(|(choice, _)| choice)
}

/// Makes this process's environment the one a plan was measured with: sets it when the
/// command line gave none, and refuses a different one.
pub fn adopt(planned: Option<&EnvChoice>) -> Result<(), String> {
    match (planned, chosen()) {
        (None, None) => Ok(()),
        (Some(p), Some(c)) if p == c => Ok(()),
        (Some(p), None) => set_environment(p.clone())
            .map(|_| ())
            .map_err(|e| e.to_string()),
        (p, _) => Err(format!(
            "the run was measured {}; resume it without --env and its options (the plan \
             keeps them)",
            match p {
                Some(p) => format!("with --env {}", p.path.display()),
                None => "without --env".into(),
            }
        )),
    }
}

/// Gives `scene` the chosen environment, if one was chosen.
pub fn apply(scene: &mut Scene) {
    if let Some((_, light)) = ENVIRONMENT.get() {
        scene.environment_map = Some(light.clone());
    }
}
